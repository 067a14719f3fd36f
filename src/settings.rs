//! Render settings: plain data shared by the window, `render` and replay.

/// Which structure the rays walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum TraceMode {
    /// Sparse voxel octree, stack traversal.
    #[default]
    Svo,
    /// Dense grid, Amanatides–Woo DDA (the report's baseline).
    Grid,
}

/// What each pixel shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum View {
    /// Palette colour, Lambert sun light, sky gradient.
    #[default]
    Shaded,
    /// Heatmap of traversal steps per ray.
    Iterations,
    /// Level of the octree cell that was hit (bigger cells warmer).
    Depth,
    /// Face normals.
    Normals,
}

impl View {
    /// Code the shaders switch on (`FrameUniforms::view`).
    pub fn code(self) -> u32 {
        match self {
            View::Shaded => 0,
            View::Iterations => 1,
            View::Depth => 2,
            View::Normals => 3,
        }
    }

    /// Name of its code in WGSL (see `crate::gpu::prelude`).
    pub fn wgsl_name(self) -> &'static str {
        match self {
            View::Shaded => "VIEW_SHADED",
            View::Iterations => "VIEW_ITERATIONS",
            View::Depth => "VIEW_DEPTH",
            View::Normals => "VIEW_NORMALS",
        }
    }

    pub const ALL: [View; 4] = [View::Shaded, View::Iterations, View::Depth, View::Normals];
}

/// Smallest render scale accepted (the window's slider and `--render-scale`).
pub const MIN_RENDER_SCALE: f32 = 0.25;

/// The pixels traced for an image of `size` at `scale` per axis (at least one).
pub fn scaled_size(size: (u32, u32), scale: f32) -> (u32, u32) {
    let scale = scale.clamp(MIN_RENDER_SCALE, 1.0);
    let axis = |n: u32| ((n as f32 * scale).round() as u32).max(1);
    (axis(size.0), axis(size.1))
}

/// Knobs of the renderer, edited by the UI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    pub mode: TraceMode,
    pub view: View,
    /// Trace a shadow ray toward the sun for every hit.
    pub shadows: bool,
    /// Fraction of the window's pixels traced per axis (0.25..=1).
    pub render_scale: f32,
    /// Level of detail: camera rays stop at octree cells narrower than this
    /// many pixels (0 = exact; the SVO preview only).
    pub lod: f32,
    /// The world height of the ground plane drawn under the scene
    /// (`crate::trace::ground`), if one is.
    pub ground: Option<i32>,
}

impl Default for RenderSettings {
    fn default() -> RenderSettings {
        RenderSettings {
            mode: TraceMode::Svo,
            view: View::Shaded,
            shadows: true,
            render_scale: 1.0,
            lod: 0.0,
            ground: None,
        }
    }
}

/// Largest `--lod` accepted, in pixels.
pub const MAX_LOD: f32 = 64.0;

/// Direction toward the sun (normalised), shared with the shaders.
pub const SUN_DIR: [f32; 3] = [0.454_858_8, 0.796_002_9, 0.398_001_5];

/// The sky a path-traced frame sees.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Sky {
    /// Horizon to zenith, the preview's background.
    #[default]
    Gradient,
    /// Radiance 1 in every direction (the white furnace).
    White,
    /// No sky light.
    Black,
}

impl Sky {
    /// Radiance at the horizon and at the zenith.
    pub fn colors(self) -> ([f32; 3], [f32; 3]) {
        match self {
            Sky::Gradient => ([0.86, 0.89, 0.95], [0.32, 0.5, 0.82]),
            Sky::White => ([1.0; 3], [1.0; 3]),
            Sky::Black => ([0.0; 3], [0.0; 3]),
        }
    }
}

/// Which effects a path-traced frame is compiled with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum EffectsChoice {
    /// The effects the scene calls for (its materials, the lights on).
    #[default]
    Auto,
    /// Every effect, for comparison.
    All,
}

/// Knobs of the path tracer, shared by the window, `render` and replay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathSettings {
    /// Scattering events after the camera ray (passing through glass does
    /// not count).
    pub bounces: u32,
    /// Shadow rays toward the sun per diffuse hit.
    pub shadow_samples: u32,
    pub effects: EffectsChoice,
    pub sun: bool,
    pub sky: Sky,
    /// Which sequence of samples: renders of different seeds are
    /// independent of each other, so one can be the reference of another
    /// (a reference that shares the first samples of the image it measures
    /// flatters it: 64 of 256 shared take a quarter off its RMS error).
    pub seed: u32,
    /// The world height of the ground plane paths may land on
    /// (`crate::trace::ground`), if there is one.
    pub ground: Option<i32>,
}

impl Default for PathSettings {
    fn default() -> PathSettings {
        PathSettings {
            bounces: 4,
            shadow_samples: 1,
            effects: EffectsChoice::Auto,
            sun: true,
            sky: Sky::Gradient,
            seed: 0,
            ground: None,
        }
    }
}

/// Sample indices between the sequences of two seeds: an accumulation of
/// at most this many samples (`render --spp`'s limit) never reaches the
/// next seed's first.
pub const SEED_STRIDE: u32 = 1 << 20;
/// Seeds whose sequences differ: seed `SEEDS` would start where seed 0
/// does, the index wrapping at 2³².
pub const SEEDS: u32 = u32::MAX / SEED_STRIDE + 1;

impl PathSettings {
    /// The index, in the random sequences of the path tracer (CPU and GPU),
    /// of this accumulation's first sample.
    pub fn first_sample(&self) -> u32 {
        self.seed.wrapping_mul(SEED_STRIDE)
    }
}

/// Samples the window accumulates at rest unless told otherwise: noise is
/// below what 8-bit colour shows on most scenes well before this.
pub const DEFAULT_SAMPLE_TARGET: u32 = 256;

/// Most bounces and shadow samples accepted.
pub const MAX_BOUNCES: u32 = 64;
pub const MAX_SHADOW_SAMPLES: u32 = 64;

/// How the window shades its frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Shading {
    /// The preview only: colour, Lambert sun, optional shadow.
    Preview,
    /// The preview while the camera moves; the path tracer, accumulating,
    /// once the view rests.
    #[default]
    Rest,
    /// The path tracer on every frame, moving or not.
    Path,
}

impl Shading {
    pub const ALL: [Shading; 3] = [Shading::Preview, Shading::Rest, Shading::Path];

    pub fn label(self) -> &'static str {
        match self {
            Shading::Preview => "preview",
            Shading::Rest => "path trace at rest",
            Shading::Path => "path trace always",
        }
    }
}
