//! Which WGSL files make which shader module: the one list the passes
//! build their modules from, and the layout test reads (`layout.rs`).

use super::prelude::with_prelude;

const COMMON: &str = include_str!("../../shaders/common.wgsl");
const SVO: &str = include_str!("../../shaders/trace_svo.wgsl");
const INSTANCES: &str = include_str!("../../shaders/instances.wgsl");
const GRID: &str = include_str!("../../shaders/trace_grid.wgsl");
const FLOOR: &str = include_str!("../../shaders/floor.wgsl");
const PATH: &str = include_str!("../../shaders/path.wgsl");
const DENOISE: &str = include_str!("../../shaders/denoise.wgsl");
const BLIT: &str = include_str!("../../shaders/blit.wgsl");

/// A shader module octovox compiles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Module {
    /// The preview's octree and instance walk (`TracePass`).
    TraceSvo,
    /// The dense grid's DDA baseline (`TracePass`).
    TraceGrid,
    /// Everything a frame does but the traversal (`TracePass`).
    Floor,
    /// The path tracer (`PathPass`).
    Path,
    /// The à-trous filter (`DenoisePass`).
    Denoise,
    /// The image onto the window (`BlitPass`).
    Blit,
}

impl Module {
    pub const ALL: [Module; 6] =
        [Module::TraceSvo, Module::TraceGrid, Module::Floor, Module::Path, Module::Denoise, Module::Blit];

    /// The label its shader carries (the file of its entry points).
    pub fn label(self) -> &'static str {
        match self {
            Module::TraceSvo => "trace_svo.wgsl",
            Module::TraceGrid => "trace_grid.wgsl",
            Module::Floor => "floor.wgsl",
            Module::Path => "path.wgsl",
            Module::Denoise => "denoise.wgsl",
            Module::Blit => "blit.wgsl",
        }
    }

    /// Its WGSL: the shared constants and overlay prelude (where it has
    /// one), then its files in order.
    pub fn source(self) -> String {
        match self {
            Module::TraceSvo => with_prelude(&[COMMON, SVO, INSTANCES]),
            Module::TraceGrid => with_prelude(&[COMMON, GRID]),
            Module::Floor => with_prelude(&[COMMON, FLOOR]),
            Module::Path => with_prelude(&[COMMON, SVO, INSTANCES, PATH]),
            Module::Denoise => with_prelude(&[DENOISE]),
            // The blit samples a texture: it shares nothing with the others.
            Module::Blit => BLIT.to_owned(),
        }
    }
}
