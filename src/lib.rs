//! octovox: an editable voxel sandbox that ray-traces a sparse voxel octree.
//!
//! The engine (scene, octree, edits, .vox I/O, replay) knows nothing of
//! windows; `gpu` holds the wgpu passes and `app` the winit/egui front end.

pub mod budget;
pub mod camera;
pub mod edit;
pub mod editor;
pub mod gpu;
pub mod gpu_pool;
pub mod io;
pub mod journal;
// NVIDIA's FLIP is C++: `bench quality` and the window's preset figures are
// the desktop's.
#[cfg(not(target_arch = "wasm32"))]
pub mod quality;
pub mod replay;
pub mod scene;
pub mod script;
pub mod settings;
pub mod trace;
