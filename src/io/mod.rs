//! File formats: MagicaVoxel .vox in and out, .obj meshes in (voxelized).

mod guard;
pub mod mesh;
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
    Scene::from_model(&model).map_err(build_error)
}

/// Whether `path` names a mesh (.obj) rather than a .vox.
pub fn is_mesh_path(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"))
}

/// Saves a scene as .vox (atomically: the old file survives a failed write).
/// A mesh's name is refused, so an imported mesh is never overwritten.
pub fn save_scene(path: &Path, scene: &Scene) -> Result<(), vox::VoxError> {
    if is_mesh_path(path) {
        let reason = std::io::Error::new(std::io::ErrorKind::InvalidInput, "scenes are saved as .vox, not .obj");
        return Err(vox::VoxError::Write { path: path.to_path_buf(), source: reason });
    }
    vox::save_vox(path, &scene.palette, &scene.tree.voxels())
}
