//! Everything that talks to wgpu: device setup, the scene's GPU buffers, the
//! trace pass, timing and readback. The engine modules never import this.

pub mod bindings;
pub mod blit_pass;
pub mod context;
pub mod denoise_pass;
pub mod layout;
pub mod path_pass;
pub mod prelude;
pub mod readback;
pub mod renderer;
pub mod scene_buffers;
pub mod schedule;
pub mod shaders;
pub mod timer;
pub mod trace_pass;

pub use blit_pass::{BlitMode, BlitPass};
pub use context::{GpuContext, GpuError};
pub use denoise_pass::DenoisePass;
pub use layout::{FrameUniforms, GroundGrid, PathUniforms};
pub use path_pass::PathPass;
pub use renderer::{FrameInput, PathFrame, PathOptions, PathView, Preview, Renderer, Submitted};
pub use scene_buffers::SceneBuffers;
pub use trace_pass::{Kernel, TracePass};
