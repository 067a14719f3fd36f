//! Command-line interface: one enum variant per subcommand ([`CliCommand`]).
//! The browser page reads only the window's options, from its query; the
//! commands' helpers are the desktop's.
#![cfg_attr(target_arch = "wasm32", allow(dead_code))]

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};
use glam::DVec3;

use octovox::camera::Camera;
use octovox::settings::{TraceMode, View};

#[derive(Parser, Debug)]
#[command(name = "octovox", version, about = "Voxel sandbox with a GPU sparse-voxel-octree ray tracer")]
#[command(allow_negative_numbers = true)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<CliCommand>,
    #[command(flatten)]
    pub window: WindowArgs,
    /// Most memory one step may take (4G, 512M, …); larger loads, imports,
    /// brushes and renders are refused with a message (docs/limits.md).
    #[arg(long, global = true, value_name = "SIZE", value_parser = octovox::budget::parse_bytes,
          default_value = "4G")]
    pub memory_budget: u64,
}

/// Options of the sandbox window (`octovox [FILE]`).
#[derive(Args, Debug, Default)]
pub struct WindowArgs {
    /// A .vox file to open; without it, the built-in demo scene.
    pub file: Option<PathBuf>,
    /// Window size in pixels.
    #[arg(long, value_parser = parse_size, default_value = "1280x720")]
    pub size: (u32, u32),
    /// Initial camera as EX,EY,EZ:TX,TY,TZ (eye and target, world voxels).
    #[arg(long, value_parser = parse_camera, allow_hyphen_values = true)]
    pub camera: Option<(DVec3, DVec3)>,
    /// Draw N frames as fast as possible after the first, print the average
    /// frame rate and exit (a benchmark of the whole frame: trace, blit, egui).
    #[arg(long, value_name = "N")]
    pub bench_frames: Option<u32>,
    /// Fraction of the window's pixels traced per axis (0.25..=1; the UI can change it).
    #[arg(long, default_value_t = 1.0, value_parser = parse_render_scale)]
    pub render_scale: f32,
    /// Start with sun shadows off (the UI can turn them on).
    #[arg(long)]
    pub no_shadows: bool,
    /// Level of detail of the preview in pixels (0 = exact; the UI can change it).
    #[arg(long, default_value_t = 0.0, value_parser = parse_lod, value_name = "PIXELS")]
    pub lod: f32,
    /// Which built-in scene to open when there is no FILE.
    #[arg(long, value_enum, conflicts_with = "file")]
    pub demo: Option<octovox::scene::demo::BuiltIn>,
    /// Samples per pixel the path tracer accumulates once the camera rests
    /// (the UI can change it); `--samples` is the older name.
    #[arg(long = "spp", visible_alias = "samples", value_name = "N", default_value_t = octovox::settings::DEFAULT_SAMPLE_TARGET, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub samples: u32,
    /// Show the path tracer's raw samples, not the denoised image (the
    /// Render panel's Denoise box).
    #[arg(long)]
    pub no_denoise: bool,
    /// Preview shading only, the path tracer once the camera rests, or the
    /// path tracer always (the UI can change it).
    #[arg(long, value_enum, default_value_t = octovox::settings::Shading::Rest)]
    pub shading: octovox::settings::Shading,
    /// On exit, print the frame rate and the worst frame while the camera
    /// moved (benches/window_orbit.sh drags the real mouse and reads it).
    #[arg(long)]
    pub frame_stats: bool,
    /// Play a replay script visibly, one line per frame (docs/replay.md).
    #[arg(long, value_name = "SCRIPT")]
    pub replay: Option<PathBuf>,
    /// Record the session (camera, brush, colour, every edit) as a script.
    #[arg(long, value_name = "PATH")]
    pub record: Option<PathBuf>,
    /// Let --record replace an existing .vox/.obj/.ovr file or an input.
    #[arg(long)]
    pub force: bool,
}

#[derive(Subcommand, Debug)]
pub enum CliCommand {
    /// Print what a .vox file holds: models, voxels, extent, palette and materials used.
    Info {
        file: PathBuf,
        /// Machine-readable output.
        #[arg(long)]
        json: bool,
        /// One line per object: index, name path, model, layer, hidden, world box.
        #[arg(long)]
        objects: bool,
        /// The animation frame to read (every key sampled there; in a file of
        /// several models and no scene graph, the model shown).
        #[arg(long, default_value_t = 0)]
        frame: usize,
    },
    /// Load a .vox and save it again through octovox's scene model.
    #[command(allow_negative_numbers = true)]
    Convert {
        input: PathBuf,
        output: PathBuf,
        #[arg(long, default_value_t = 0)]
        frame: usize,
        /// Replace OUTPUT even if it exists or is the input.
        #[arg(long)]
        force: bool,
    },
    /// Voxelize a closed .obj mesh (solid inside) and save it as .vox.
    #[command(allow_negative_numbers = true)]
    Import(ImportArgs),
    /// Apply the crash-recovery journal the window left beside FILE (its
    /// unsaved edits), or FILE itself when it is a journal (an untitled
    /// scene's, in saves/), and save the result as OUT; FILE and the
    /// journal stay.
    Recover {
        file: PathBuf,
        #[arg(short, long)]
        output: PathBuf,
        /// Replace OUTPUT even if it exists or is FILE.
        #[arg(long)]
        force: bool,
    },
    /// Export the visible faces as a mesh (.obj with .mtl, .ply, or .glb with PBR materials), greedy-meshed.
    #[command(allow_negative_numbers = true)]
    Export {
        /// A .vox (or .obj, voxelized) scene.
        file: PathBuf,
        #[arg(short, long)]
        output: PathBuf,
        /// Mesh units per voxel.
        #[arg(long, default_value_t = 1.0, value_parser = parse_scale)]
        scale: f32,
        #[arg(long, default_value_t = 0)]
        frame: usize,
        /// Replace OUTPUT even if it exists or is the input.
        #[arg(long)]
        force: bool,
    },
    /// Ray-trace a scene to a PNG (GPU, or the CPU reference with --cpu).
    #[command(allow_negative_numbers = true)]
    Render(RenderArgs),
    /// Measure build, edit and render speed and memory; writes target/bench/ (or --out).
    Bench(BenchArgs),
    /// Run edit scripts headless and check their expectations (docs/replay.md).
    Replay {
        #[arg(required = true)]
        scripts: Vec<PathBuf>,
        /// Run without a GPU: flushes are counted, renders use the CPU tracer.
        #[arg(long)]
        cpu: bool,
        /// Let `save`, `render` and `palette save` lines replace existing
        /// .vox/.obj/.ovr and palette files and the run's inputs.
        #[arg(long)]
        force: bool,
    },
}

#[derive(Args, Debug)]
pub struct ImportArgs {
    /// A Wavefront .obj mesh.
    pub mesh: PathBuf,
    #[arg(short, long)]
    pub output: PathBuf,
    /// Voxels along the mesh's longest side.
    #[arg(long, default_value_t = octovox::io::mesh::DEFAULT_MESH_SIZE)]
    pub size: u32,
    /// Which mesh axis points up.
    #[arg(long, value_enum, default_value_t = octovox::io::mesh::UpAxis::Y)]
    pub up: octovox::io::mesh::UpAxis,
    /// Palette index of the voxels (1..=255, default palette).
    #[arg(long, default_value_t = octovox::io::mesh::MESH_COLOR, value_parser = clap::value_parser!(u8).range(1..))]
    pub color: u8,
    /// Replace OUTPUT even if it exists or is the mesh.
    #[arg(long)]
    pub force: bool,
    /// Print one JSON object: solid voxels, seconds, peak resident bytes.
    #[arg(long)]
    pub stats: bool,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// A .vox file; without it, the built-in demo scene.
    pub file: Option<PathBuf>,
    /// Which built-in scene to render when there is no FILE.
    #[arg(long, value_enum, conflicts_with = "file")]
    pub demo: Option<octovox::scene::demo::BuiltIn>,
    #[arg(short, long)]
    pub output: PathBuf,
    #[arg(long, value_parser = parse_size, default_value = "1280x720")]
    pub size: (u32, u32),
    /// EX,EY,EZ:TX,TY,TZ; without it, a camera from the front-right-top that
    /// brings the model as close as it can with all of it in the frame.
    #[arg(long, value_parser = parse_camera, allow_hyphen_values = true)]
    pub camera: Option<(DVec3, DVec3)>,
    /// Vertical field of view in degrees (1..=179).
    #[arg(long, default_value_t = 50.0, value_parser = parse_fov)]
    pub fov: f32,
    /// An orthographic view showing HEIGHT world voxels from the image's
    /// bottom to its top, looking from the camera's eye to its target
    /// (the eye's distance then changes nothing).
    #[arg(long, value_parser = parse_ortho, value_name = "HEIGHT", conflicts_with = "fov")]
    pub ortho: Option<f32>,
    #[arg(long, value_enum, default_value_t = TraceMode::Svo)]
    pub mode: TraceMode,
    #[arg(long, value_enum, default_value_t = View::Shaded)]
    pub view: View,
    /// Use the CPU reference tracer instead of the GPU.
    #[arg(long)]
    pub cpu: bool,
    /// Turn sun shadows off (preview shading).
    #[arg(long)]
    pub no_shadows: bool,
    /// Stand the model on a ground plane under its lowest voxel, which
    /// takes its shadow (the default; in the preview and the path tracer).
    #[arg(long, overrides_with = "no_ground")]
    pub ground: bool,
    /// Leave the model in the sky, with no ground under it.
    #[arg(long, overrides_with = "ground")]
    pub no_ground: bool,
    /// The animation frame shown (every key sampled there); with
    /// --turntable, the frame the scene stands at.
    #[arg(long, default_value_t = 0)]
    pub frame: usize,
    /// Render the animation's frames A to B (both included) into OUTPUT, a
    /// name with `%d` or `%0Nd` for the frame's number
    /// (`out/walk_%04d.png`), or one looping `.gif`.
    #[arg(long, value_parser = parse_frames, value_name = "A..B")]
    pub frames: Option<(u32, u32)>,
    /// Render N frames of the camera orbiting its target once, the scene
    /// standing still (--frames picks some of them, from 0..N-1).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000), value_name = "N")]
    pub turntable: Option<u32>,
    /// Render only shard K's share of the frames, of N shards (0 ≤ K < N):
    /// consecutive frames, the same whichever machine renders them, so a
    /// cluster's job array spreads an animation (docs/animation.md).
    #[arg(long, value_parser = parse_shard, value_name = "K/N")]
    pub shard: Option<(u32, u32)>,
    /// Replace OUTPUT even if it is the input or an existing .vox/.obj/.ovr.
    #[arg(long)]
    pub force: bool,
    /// Trace S × the image's pixels per axis (0.25..=1) and scale up.
    #[arg(long, default_value_t = 1.0, value_parser = parse_render_scale)]
    pub render_scale: f32,
    /// Level of detail: stop at octree cells narrower than PIXELS traced
    /// pixels and shade them by their summary (0 = exact; SVO preview only).
    #[arg(long, default_value_t = 0.0, value_parser = parse_lod, value_name = "PIXELS")]
    pub lod: f32,
    #[command(flatten)]
    pub path: PathArgs,
    /// Print one JSON object on stdout: effects, spp, ms_per_sample,
    /// denoise_ms, noise_estimate, adapter, lights.
    #[arg(long)]
    pub stats: bool,
}

impl RenderArgs {
    /// Whether it renders frames of an animation or a turntable, not one image.
    pub fn animates(&self) -> bool {
        self.frames.is_some() || self.turntable.is_some() || self.shard.is_some()
    }
}

/// Parses `A..B`, frames A to B, both included.
pub fn parse_frames(s: &str) -> Result<(u32, u32), String> {
    let (a, b) = s.split_once("..").ok_or_else(|| format!("'{s}' is not A..B (frames A to B, e.g. 0..47)"))?;
    let parse = |v: &str| {
        v.trim().parse::<u32>().map_err(|_| format!("'{s}': '{v}' is not a frame number (0 to {})", u32::MAX))
    };
    let (a, b) = (parse(a)?, parse(b.trim_start_matches('='))?);
    if a > b {
        return Err(format!("'{s}': the first frame {a} is after the last {b}"));
    }
    Ok((a, b))
}

/// Parses `K/N`: shard K of N, 0 ≤ K < N.
pub fn parse_shard(s: &str) -> Result<(u32, u32), String> {
    let (k, n) = s.split_once('/').ok_or_else(|| format!("'{s}' is not K/N (shard K of N, e.g. 0/4)"))?;
    let parse = |v: &str| v.trim().parse::<u32>().map_err(|_| format!("'{s}': '{v}' is not a whole number"));
    let (k, n) = (parse(k)?, parse(n)?);
    if n == 0 {
        return Err(format!("'{s}': N, the number of shards, is at least 1"));
    }
    if k >= n {
        return Err(format!("'{s}': the shards of {n} are numbered 0 to {}", n - 1));
    }
    Ok((k, n))
}

/// The path tracer's knobs on the command line.
#[derive(Args, Debug, Clone, Copy)]
pub struct PathArgs {
    /// Path trace with N samples per pixel (without it: the preview shading;
    /// with --target-error: at most N).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(octovox::settings::SEED_STRIDE)))]
    pub spp: Option<u32>,
    /// Path trace until the estimated noise (the RMS standard error of the
    /// displayed pixels, 0..1 or a percentage such as 1%) is below E; at
    /// most --spp samples (default 4096).
    #[arg(long, value_parser = parse_target_error, value_name = "E")]
    pub target_error: Option<f32>,
    /// Denoise the path-traced image (the edge-avoiding à-trous filter).
    #[arg(long)]
    pub denoise: bool,
    /// Denoise with Intel Open Image Denoise instead, on the CPU after the
    /// last sample (only in a build with the `oidn` feature).
    #[arg(long, conflicts_with = "denoise")]
    pub oidn: bool,
    /// Scattering events per path (passing through glass does not count).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(0..=i64::from(octovox::settings::MAX_BOUNCES)))]
    pub bounces: u32,
    /// Shadow rays toward the sun per diffuse hit.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=i64::from(octovox::settings::MAX_SHADOW_SAMPLES)))]
    pub shadow_samples: u32,
    /// Which effects the kernel simulates: what the scene calls for, or all.
    #[arg(long, value_enum, default_value_t = octovox::settings::EffectsChoice::Auto)]
    pub effects: octovox::settings::EffectsChoice,
    /// The sky's light.
    #[arg(long, value_enum, default_value_t = octovox::settings::Sky::Gradient)]
    pub sky: octovox::settings::Sky,
    /// No sunlight.
    #[arg(long)]
    pub no_sun: bool,
    /// Which sequence of samples (0 by default, below 4096): renders of
    /// different seeds are independent, so one can be the reference of
    /// another.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..i64::from(octovox::settings::SEEDS)))]
    pub seed: u32,
}

/// Samples `--target-error` takes at most when `--spp` does not say.
pub const TARGET_ERROR_CAP: u32 = 4096;

impl PathArgs {
    /// Whether the path tracer renders (`--spp` or `--target-error`).
    pub fn traced(&self) -> bool {
        self.spp.is_some() || self.target_error.is_some()
    }

    /// The samples to take, or at most to take with `--target-error`.
    pub fn samples(&self) -> u32 {
        self.spp.unwrap_or(TARGET_ERROR_CAP)
    }

    pub fn settings(&self) -> octovox::settings::PathSettings {
        octovox::settings::PathSettings {
            bounces: self.bounces,
            shadow_samples: self.shadow_samples,
            effects: self.effects,
            sun: !self.no_sun,
            sky: self.sky,
            seed: self.seed,
            ground: None,
        }
    }
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// What to measure.
    #[arg(value_enum)]
    pub what: BenchKind,
    /// Folder for the markdown and JSON results. The default is a build
    /// folder, not the checkout's committed tables: `--out docs/bench`
    /// updates those.
    #[arg(long, default_value = "target/bench")]
    pub out: PathBuf,
    /// Fewer repetitions and smaller images (a smoke run).
    #[arg(long)]
    pub quick: bool,
    /// `bench render` only: the SVO column at this level of detail
    /// (pixels, 0 = exact); `bench quality` measures several itself.
    #[arg(long, default_value_t = 0.0, value_parser = parse_lod, value_name = "PIXELS")]
    pub lod: f32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BenchKind {
    /// Octree build time and memory, dense grid memory.
    Build,
    /// Edit latency: apply + flush for one voxel and spheres.
    Edit,
    /// Grid DDA vs SVO frame time at 1700×900.
    Render,
    /// Path tracer time per sample: kernel per scene's effects vs all effects.
    Effects,
    /// Error (FLIP, PSNR) against time for each quality knob, and the plot.
    Quality,
    /// Nefertiti at 512 to 4096 voxels tall: import, memory, .ovx, frame, edit.
    Scale,
    /// A forest of 2,000 references of one tree against the merged model.
    Scene,
    /// Playing a forest of 2,000 moving references against it standing
    /// still; a turntable as 1, 2 and 4 shards.
    Anim,
}

/// Parses "WxH".
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("size '{s}' is not WxH, e.g. 1280x720"))?;
    let parse = |v: &str| v.trim().parse::<u32>().map_err(|_| format!("size '{s}': '{v}' is not a whole number"));
    let (w, h) = (parse(w)?, parse(h)?);
    if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
        return Err(format!("size '{s}' must be between 1x1 and 16384x16384"));
    }
    Ok((w, h))
}

/// Parses a positive, finite scale.
pub fn parse_scale(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("scale '{s}' must be a positive number")),
    }
}

/// Parses a field of view in degrees, within [`octovox::camera::FOV_RANGE_DEG`].
pub fn parse_fov(s: &str) -> Result<f32, String> {
    let fov: f32 = s.trim().parse().map_err(|_| format!("field of view '{s}' is not a number"))?;
    octovox::camera::check_fov(fov).map_err(|e| e.to_string())
}

/// Parses an orthographic view height, within [`octovox::camera::ORTHO_RANGE`].
pub fn parse_ortho(s: &str) -> Result<f32, String> {
    let height: f32 = s.trim().parse().map_err(|_| format!("orthographic height '{s}' is not a number"))?;
    octovox::camera::check_ortho(height).map_err(|e| e.to_string())
}

/// Parses a render scale in `MIN_RENDER_SCALE..=1`.
pub fn parse_render_scale(s: &str) -> Result<f32, String> {
    let range = octovox::settings::MIN_RENDER_SCALE..=1.0;
    match s.trim().parse::<f32>() {
        Ok(v) if range.contains(&v) => Ok(v),
        _ => Err(format!("render scale '{s}' is not a number in {}..=1", range.start())),
    }
}

/// Parses a noise target: a fraction in (0, 1), or a percentage ("1%").
pub fn parse_target_error(s: &str) -> Result<f32, String> {
    let t = s.trim();
    let value = match t.strip_suffix('%') {
        Some(percent) => percent.trim().parse::<f32>().map(|p| p / 100.0),
        None => t.parse::<f32>(),
    };
    match value {
        Ok(v) if v > 0.0 && v < 1.0 => Ok(v),
        _ => Err(format!("target error '{s}' is not a fraction in (0, 1) or a percentage such as 1%")),
    }
}

/// Parses a level-of-detail footprint in pixels (0..=MAX_LOD).
pub fn parse_lod(s: &str) -> Result<f32, String> {
    let max = octovox::settings::MAX_LOD;
    match s.trim().parse::<f32>() {
        Ok(v) if (0.0..=max).contains(&v) => Ok(v),
        _ => Err(format!("level of detail '{s}' is not a number of pixels in 0..={max}")),
    }
}

/// Parses "EX,EY,EZ:TX,TY,TZ".
pub fn parse_camera(s: &str) -> Result<(DVec3, DVec3), String> {
    let (eye, target) = s.split_once(':').ok_or_else(|| format!("camera '{s}' is not EX,EY,EZ:TX,TY,TZ"))?;
    let vec = |part: &str| -> Result<DVec3, String> {
        let v: Vec<f64> = part
            .split(',')
            .map(|c| c.trim().parse::<f64>().map_err(|_| format!("camera '{s}': '{c}' is not a number")))
            .collect::<Result<_, _>>()?;
        match v[..] {
            [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(DVec3::new(x, y, z)),
            _ => Err(format!("camera '{s}': '{part}' needs three finite numbers")),
        }
    };
    let (eye, target) = (vec(eye)?, vec(target)?);
    octovox::camera::check_camera(eye, target).map_err(|message| format!("camera '{s}': {message}"))?;
    Ok((eye, target))
}

/// The camera given on the command line, or one that fills an image of
/// `size` with the scene's box (what `render` takes by default).
pub fn camera_or_filling(
    camera: Option<(DVec3, DVec3)>,
    fov: f32,
    scene: &octovox::scene::Scene,
    (width, height): (u32, u32),
) -> Camera {
    /// Past this many cells the box's corners stand for the voxels'.
    const MOST_CELLS: usize = 1 << 18;
    let (None, Some((lo, hi))) = (camera, scene.solid_bounds()) else { return camera_or_framing(camera, fov, scene) };
    let mut points = Vec::new();
    let mut cells = 0usize;
    scene.drawn().for_each_solid_cell(|min, size, _| {
        cells += 1;
        if cells <= MOST_CELLS {
            points.extend(corners(min, min + glam::IVec3::splat(size)));
        }
    });
    if cells > MOST_CELLS {
        points = corners(lo, hi + glam::IVec3::ONE).collect();
    }
    Camera::filling(lo, hi, &points, fov, f64::from(width) / f64::from(height.max(1)))
}

/// The eight corners of the cells `lo..hi` (corner coordinates, `hi` one past).
pub fn corners(lo: glam::IVec3, hi: glam::IVec3) -> impl Iterator<Item = DVec3> {
    let (a, b) = (lo.as_dvec3(), hi.as_dvec3());
    (0..8).map(move |k| DVec3::new([a.x, b.x][k & 1], [a.y, b.y][(k >> 1) & 1], [a.z, b.z][(k >> 2) & 1]))
}

/// The camera given on the command line, or one framing the scene.
pub fn camera_or_framing(camera: Option<(DVec3, DVec3)>, fov: f32, scene: &octovox::scene::Scene) -> Camera {
    match camera {
        Some((eye, target)) => Camera { eye, target, fov_y_deg: fov, ortho: None },
        None => match scene.solid_bounds() {
            Some((lo, hi)) => Camera::framing(lo, hi, fov),
            None => Camera { fov_y_deg: fov, ..Camera::default() },
        },
    }
}
