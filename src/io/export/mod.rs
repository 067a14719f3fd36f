//! Mesh export: the scene's visible faces, greedy-meshed ([`greedy`]),
//! as Wavefront .obj (with an .mtl of one material per palette colour),
//! binary .ply (with vertex colours) or glTF binary .glb (with a PBR
//! material per palette entry used). One unit is one voxel times `scale`;
//! axes are octovox's (y up, right-handed), which all three formats expect.

mod gltf;
pub mod greedy;
mod obj;
mod ply;

use std::path::{Path, PathBuf};

pub use greedy::VoxelMesh;

use crate::io::atomic::{WriteOptions, write_atomically};
use crate::io::output::{OutputError, OutputKind, check_output};
use crate::scene::Scene;

/// The formats `export` writes, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    Obj,
    Ply,
    Glb,
}

impl MeshFormat {
    /// The format an output path names, if octovox writes it.
    pub fn of(path: &Path) -> Option<MeshFormat> {
        match path.extension()?.to_string_lossy().to_ascii_lowercase().as_str() {
            "obj" => Some(MeshFormat::Obj),
            "ply" => Some(MeshFormat::Ply),
            "glb" => Some(MeshFormat::Glb),
            _ => None,
        }
    }
}

/// Why an export failed.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("{}: octovox exports .obj, .ply and .glb meshes", path.display())]
    Format { path: PathBuf },
    #[error("{}: the mesh passes the 4 GiB a .glb can hold", path.display())]
    TooLarge { path: PathBuf },
    #[error("cannot write {}: {source}", path.display())]
    Write { path: PathBuf, source: std::io::Error },
    #[error(transparent)]
    OverBudget(#[from] crate::budget::OverBudget),
}

/// What an export wrote.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ExportStats {
    pub triangles: usize,
    pub vertices: usize,
    /// Triangles of a one-quad-per-face export of the same voxels.
    pub naive_triangles: u64,
    /// Files written (an .obj has its .mtl beside it).
    pub files: Vec<PathBuf>,
}

/// Checks the files an export to `path` writes (the mesh, and an .obj's
/// .mtl beside it) by the rule of every output (`crate::io::output`).
///
/// # Errors
/// The first file refused.
pub fn check_outputs(path: &Path, inputs: &[&Path], force: bool) -> Result<(), OutputError> {
    check_output(path, OutputKind::Mesh, inputs, force)?;
    if MeshFormat::of(path) == Some(MeshFormat::Obj) {
        check_output(&path.with_extension("mtl"), OutputKind::Materials, inputs, force)?;
    }
    Ok(())
}

/// Meshes `scene` and writes it to `path` in the format its extension names.
///
/// # Errors
/// [`ExportError::Format`] for another extension, [`ExportError::TooLarge`]
/// for a .glb past 4 GiB, the memory budget, and
/// any refusal of [`write_atomically`] (devices, read-only files, a missing
/// folder) naming the file.
pub fn export_mesh(path: &Path, scene: &Scene, scale: f32, options: WriteOptions) -> Result<ExportStats, ExportError> {
    let format = MeshFormat::of(path).ok_or_else(|| ExportError::Format { path: path.to_path_buf() })?;
    let dense = greedy::dense_bytes(&scene.tree);
    crate::budget::check(|| format!("meshing a {dense}-voxel bounding box"), dense.saturating_mul(2))?;
    let mesh = greedy::mesh(&scene.tree);
    let write = |target: &Path, bytes: Vec<u8>| {
        write_atomically(target, options, |file| std::io::Write::write_all(file, &bytes))
            .map_err(|source| ExportError::Write { path: target.to_path_buf(), source })
    };
    let mut files = vec![path.to_path_buf()];
    match format {
        MeshFormat::Obj => {
            let mtl = path.with_extension("mtl");
            let mtl_name = mtl.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
            write(&mtl, obj::mtl(&mesh, &scene.palette))?;
            write(path, obj::obj(&mesh, scale, &mtl_name))?;
            files.push(mtl);
        }
        MeshFormat::Ply => write(path, ply::ply(&mesh, &scene.palette, scale))?,
        MeshFormat::Glb => {
            let glb = gltf::glb(&mesh, &scene.palette, scale)
                .ok_or_else(|| ExportError::TooLarge { path: path.to_path_buf() })?;
            write(path, glb)?;
        }
    }
    Ok(ExportStats {
        triangles: mesh.triangles.len(),
        vertices: mesh.positions_x2.len(),
        naive_triangles: mesh.exposed_faces * 2,
        files,
    })
}
