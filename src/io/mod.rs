//! File formats: MagicaVoxel .vox and the native .ovx in and out, .obj
//! meshes in (voxelized).

pub mod atomic;
pub mod export;
pub mod gif;
mod guard;
pub mod input;
pub mod mesh;
pub mod output;
pub mod ovx;
#[cfg(target_arch = "wasm32")]
pub mod page_files;
pub mod palette_file;
pub mod png;
pub mod progress;
pub mod vox;
mod zstd_frame;

use std::path::Path;

use crate::scene::Scene;

/// Why a scene could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    #[error(transparent)]
    Vox(#[from] vox::VoxError),
    #[error(transparent)]
    Mesh(#[from] mesh::MeshError),
    #[error("{}: {source}", path.display())]
    Ovx { path: std::path::PathBuf, source: ovx::OvxError },
}

/// Loads a .vox file, or an .obj mesh (voxelized solid, [`mesh::DEFAULT_MESH_SIZE`]
/// voxels on its longest side, y up), and builds its octree; or reads an
/// .ovx file's octree back.
pub fn load_scene(path: &Path, frame: usize) -> Result<Scene, LoadError> {
    load_scene_with(path, frame, &progress::Progress::default())
}

/// [`load_scene`], reporting to `progress` as it goes (the tiles of an
/// .obj, the bytes of an .ovx; a .vox reports nothing).
pub fn load_scene_with(path: &Path, frame: usize, progress: &progress::Progress) -> Result<Scene, LoadError> {
    if is_ovx_path(path) {
        return ovx::load_ovx(path, progress).map_err(|source| LoadError::Ovx { path: path.to_path_buf(), source });
    }
    if is_mesh_path(path) {
        let tree = mesh::voxelize_obj_with(path, mesh::DEFAULT_MESH_SIZE, mesh::UpAxis::Y, mesh::MESH_COLOR, progress)?;
        return Ok(Scene::new(crate::scene::Palette::default(), tree));
    }
    let (scene, meta) = vox::load_vox_scene_file(path, frame)?;
    for warning in &meta.warnings {
        log::warn!("{}: {warning}", path.display());
    }
    Ok(scene)
}

/// Whether `path` names a mesh (.obj) rather than a .vox.
pub fn is_mesh_path(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"))
}

/// Whether `path` names a native octree file (.ovx).
pub fn is_ovx_path(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ovx"))
}

/// Why a scene could not be saved.
#[derive(Debug, thiserror::Error)]
pub enum SaveError {
    #[error(transparent)]
    Vox(#[from] vox::VoxError),
    #[error(transparent)]
    Ovx(#[from] ovx::OvxError),
}

/// What a save to `path` should tell the user MagicaVoxel will show
/// differently from octovox: objects turned by free angles, which a .vox
/// gives MagicaVoxel at their nearest quarter turns (octovox reads the
/// exact turn back from `_ov_turn`). `None` when it shows what octovox does.
pub fn magicavoxel_note(path: &Path, scene: &Scene) -> Option<String> {
    let turned = scene.objects().map_or(0, crate::scene::objects::Objects::freely_turned);
    let vox = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("vox"));
    (vox && turned > 0).then(|| {
        format!("MagicaVoxel shows the {turned} object(s) turned by free angles at their nearest quarter turns")
    })
}

/// Saves a scene as .ovx (the pool as it is) or as .vox (one model at a
/// time), atomically: the old file survives a failed write (see
/// [`atomic`]). Any other name is refused, so an imported mesh is never
/// overwritten with scene bytes.
pub fn save_scene(path: &Path, scene: &Scene, options: atomic::WriteOptions) -> Result<(), SaveError> {
    if is_ovx_path(path) {
        return Ok(ovx::save_ovx(path, scene, options)?);
    }
    if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("vox")) {
        let reason = std::io::Error::new(std::io::ErrorKind::InvalidInput, "scenes are saved as .vox or .ovx files");
        return Err(vox::VoxError::Write { path: path.to_path_buf(), source: reason }.into());
    }
    match scene.objects() {
        Some(objects) => Ok(vox::save_objects(path, &scene.palette, objects, options)?),
        None => Ok(vox::save_tree(path, &scene.palette, scene.drawn(), options)?),
    }
}
