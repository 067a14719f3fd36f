//! Mesh export: the scene's visible faces, greedy-meshed ([`greedy`]) per
//! model and placed per object ([`parts`]), as Wavefront .obj (with an
//! .mtl of one material per palette colour), binary .ply (with vertex colours) or glTF binary .glb (with a PBR
//! material per palette entry used). One unit is one voxel times `scale`;
//! axes are octovox's (y up, right-handed), which all three formats expect.

mod gltf;
pub mod greedy;
mod obj;
mod parts;
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
    #[error(
        "--scale {scale:e} puts this scene's vertices past what a 32-bit float holds \
         (infinite, denormal or zero coordinates); this scene allows --scale {min:e} to {max:e}"
    )]
    Scale { scale: f32, min: f32, max: f32 },
    #[error("the animation plays {frames} frames; an export samples at most {most}: narrow it with `anim range`")]
    TooManyFrames { frames: u64, most: u32 },
    #[error("frame {frame} cannot be placed: {reason}")]
    Frame { frame: u32, reason: String },
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

/// The scales at which every vertex coordinate of `tree`'s mesh is a
/// normal f32, as (smallest, largest), or `None` for a scene without
/// vertices. A coordinate is a multiple of half a voxel within the solid
/// bounds widened by one, so the extremes decide: half a voxel times the
/// scale must be normal (not denormal, not zero), and the farthest
/// coordinate times the scale finite.
pub fn scale_range(tree: &crate::scene::Octree) -> Option<(f32, f32)> {
    let (lo, hi) = tree.solid_bounds()?;
    let farthest = lo.abs().max((hi + glam::IVec3::ONE).abs()).max_element() as f32;
    // 0.5 · s ≥ f32::MIN_POSITIVE, exactly (a power of two).
    let smallest = f32::MIN_POSITIVE * 2.0;
    let mut largest = f32::MAX / farthest.max(1.0);
    while !(farthest * largest).is_finite() {
        largest = largest.next_down();
    }
    Some((smallest, largest))
}

/// Refuses a scale that makes a vertex coordinate infinite, denormal or
/// zero (see [`scale_range`]); any positive finite scale suits an empty scene.
///
/// # Errors
/// [`ExportError::Scale`] naming the scale and the range this scene allows.
pub fn check_scale(tree: &crate::scene::Octree, scale: f32) -> Result<(), ExportError> {
    let (min, max) = scale_range(tree).unwrap_or((f32::MIN_POSITIVE, f32::MAX));
    if scale.is_finite() && (min..=max).contains(&scale) { Ok(()) } else { Err(ExportError::Scale { scale, min, max }) }
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
    // Only glTF holds motion.
    let exported = parts::Exported::of(scene, scale, format == MeshFormat::Glb)?;
    // Every file's bytes first, so that nothing is written when one of
    // them cannot be made.
    let mut outputs = Vec::new();
    match format {
        MeshFormat::Obj => {
            let mtl = path.with_extension("mtl");
            let mtl_name = mtl.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
            let obj = obj::obj(&exported, scale, &mtl_name);
            outputs.push((mtl, obj::mtl(&exported, &scene.palette)));
            outputs.push((path.to_path_buf(), obj));
        }
        MeshFormat::Ply => outputs.push((path.to_path_buf(), ply::ply(&exported, &scene.palette, scale))),
        MeshFormat::Glb => {
            let glb = gltf::glb(&exported, &scene.palette, scale)
                .ok_or_else(|| ExportError::TooLarge { path: path.to_path_buf() })?;
            outputs.push((path.to_path_buf(), glb));
        }
    }
    let mut files: Vec<PathBuf> = outputs.iter().map(|(target, _)| target.clone()).collect();
    // The mesh first in the list, as before.
    files.rotate_right(usize::from(format == MeshFormat::Obj));
    write_all_or_none(outputs, options)?;
    let (triangles, vertices, naive_triangles) = exported.counts();
    Ok(ExportStats { triangles, vertices, naive_triangles, files })
}

/// Writes each file atomically; when one fails, removes the files this
/// call created (never one that was there before), so a failed export
/// leaves no partial output behind and its rerun is not refused. New files
/// are written before those that replace existing ones, so a failure of a
/// new file leaves every existing file as it was.
fn write_all_or_none(outputs: Vec<(PathBuf, Vec<u8>)>, options: WriteOptions) -> Result<(), ExportError> {
    // A symlink's target is what a write creates or replaces.
    let mut outputs: Vec<(PathBuf, Vec<u8>, Option<PathBuf>)> = outputs
        .into_iter()
        .map(|(target, bytes)| {
            let file = crate::io::atomic::resolve_target(&target).ok();
            let new = file.filter(|file| std::fs::symlink_metadata(file).is_err());
            (target, bytes, new)
        })
        .collect();
    outputs.sort_by_key(|(_, _, new)| new.is_none());
    let mut created: Vec<PathBuf> = Vec::new();
    for (target, bytes, new) in outputs {
        let written = write_atomically(&target, options, |file| std::io::Write::write_all(file, &bytes));
        if let Err(source) = written {
            for file in created {
                // Best effort: the export's own error is the one to report.
                let _ = std::fs::remove_file(file);
            }
            return Err(ExportError::Write { path: target, source });
        }
        created.extend(new);
    }
    Ok(())
}
