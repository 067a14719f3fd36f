//! File formats: MagicaVoxel .vox in and out.

pub mod png;
pub mod vox;

use std::path::Path;

use crate::scene::{BuildError, Scene};

/// Why a scene could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    #[error(transparent)]
    Vox(#[from] vox::VoxError),
    #[error("{}: {source}", path.display())]
    Build { path: std::path::PathBuf, source: BuildError },
}

/// Loads a .vox file and builds its octree.
pub fn load_scene(path: &Path, frame: usize) -> Result<Scene, LoadError> {
    let model = vox::load_vox_file(path, frame)?;
    Scene::from_model(&model).map_err(|source| LoadError::Build { path: path.to_path_buf(), source })
}

/// Saves a scene as .vox (atomically: the old file survives a failed write).
pub fn save_scene(path: &Path, scene: &Scene) -> Result<(), vox::VoxError> {
    vox::save_vox(path, &scene.palette, &scene.tree.voxels())
}
