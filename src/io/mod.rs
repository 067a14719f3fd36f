//! File formats: MagicaVoxel .vox in and out, .obj meshes in (voxelized).

pub mod atomic;
pub mod export;
mod guard;
pub mod input;
pub mod mesh;
pub mod output;
pub mod png;
pub mod vox;

use std::path::Path;

use crate::scene::{BuildError, Scene};

/// Why a scene could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    #[error(transparent)]
    Vox(#[from] vox::VoxError),
    #[error(transparent)]
    Mesh(#[from] mesh::MeshError),
    #[error("{}: {source}", path.display())]
    Build { path: std::path::PathBuf, source: BuildError },
}

/// Loads a .vox file, or an .obj mesh (voxelized solid, [`mesh::DEFAULT_MESH_SIZE`]
/// voxels on its longest side, y up), and builds its octree.
pub fn load_scene(path: &Path, frame: usize) -> Result<Scene, LoadError> {
    let build_error = |source| LoadError::Build { path: path.to_path_buf(), source };
    if is_mesh_path(path) {
        let dense = mesh::voxelize_obj(path, mesh::DEFAULT_MESH_SIZE, mesh::UpAxis::Y, mesh::MESH_COLOR)?;
        return Scene::from_dense(&dense).map_err(build_error);
    }
    let model = vox::load_vox_file(path, frame)?;
    for warning in &model.warnings {
        log::warn!("{}: {warning}", path.display());
    }
    Scene::from_model(&model).map_err(build_error)
}

/// Whether `path` names a mesh (.obj) rather than a .vox.
pub fn is_mesh_path(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"))
}

/// Saves a scene as .vox, one model at a time, atomically (the old file
/// survives a failed write; see [`atomic`]). A name that is not .vox is
/// refused, so an imported mesh is never overwritten with .vox bytes.
pub fn save_scene(path: &Path, scene: &Scene, options: atomic::WriteOptions) -> Result<(), vox::VoxError> {
    if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("vox")) {
        let reason = std::io::Error::new(std::io::ErrorKind::InvalidInput, "scenes are saved as .vox files");
        return Err(vox::VoxError::Write { path: path.to_path_buf(), source: reason });
    }
    vox::save_tree(path, &scene.palette, &scene.tree, options)
}
