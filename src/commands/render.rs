//! `octovox render`: one image of a scene, on the GPU or the CPU reference.

use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;

use crate::cli::{PathArgs, RenderArgs, camera_or_filling};
use octovox::camera::Camera;
use octovox::gpu::{PathView, Renderer};
use octovox::io::atomic::WriteOptions;
use octovox::io::output::{OutputKind, check_output};
use octovox::io::png::save_png;
use octovox::quality::{Accumulated, accumulate};
use octovox::scene::Scene;
use octovox::scene::demo::BuiltIn;
use octovox::settings::{PathSettings, RenderSettings, TraceMode, View};
use octovox::trace::denoise::{Frame, denoise, noise_estimate};
use octovox::trace::grid::DenseGrid;
use octovox::trace::path::{render_cpu, to_image};
use octovox::trace::render::render_scene_cpu;

/// Peak bytes per pixel of a CPU render: a hit record, a shadow flag, the
/// colour and the image (measured: 16384² pixels took about 12 GB).
const CPU_BYTES_PER_PIXEL: u64 = 48;
/// Bytes per pixel of a GPU render on the host: the read-back rows (padded)
/// and the image.
const GPU_BYTES_PER_PIXEL: u64 = 12;
/// A CPU path-traced render keeps the mean radiance (12 bytes), the sums
/// (40), the denoiser's guide (16) and two light buffers (32), and the image.
const CPU_PATH_BYTES_PER_PIXEL: u64 = 104;
/// A GPU path-traced render adds the accumulation buffer's readback.
const GPU_PATH_BYTES_PER_PIXEL: u64 = 28;

/// Opens FILE, or a built-in scene when there is none.
pub fn open_scene(file: Option<&std::path::Path>, frame: usize, demo: Option<BuiltIn>) -> anyhow::Result<Scene> {
    match file {
        Some(path) => octovox::io::load_scene(path, frame).with_context(|| format!("cannot open {}", path.display())),
        None => Ok(demo.unwrap_or_default().scene()),
    }
}

pub fn run(args: &RenderArgs) -> anyhow::Result<ExitCode> {
    check_args(args)?;
    if args.animates() {
        return super::render_frames::run(args);
    }
    let inputs: Vec<&std::path::Path> = args.file.iter().map(|p| p.as_path()).collect();
    check_output(&args.output, OutputKind::Image, &inputs, args.force)?;
    let mut scene = open_scene(args.file.as_deref(), args.frame, args.demo)?;
    let camera = Camera { ortho: args.ortho, ..camera_or_filling(args.camera, args.fov, &scene, args.size) };
    let ground = ground_height(scene.solid_bounds(), args);
    let mut device = Device::new(args)?;
    let (image, stats) =
        render_frame(&mut device, &mut scene, &camera, args, Shot { ground, number: frame_number(args.frame) })?;
    save_png(&image, &args.output, WriteOptions::forced(args.force))?;
    if args.stats {
        say!("{}", serde_json::to_string(&stats)?)?;
    } else {
        say!("wrote {} ({}x{})", args.output.display(), args.size.0, args.size.1)?;
    }
    Ok(ExitCode::SUCCESS)
}

/// Refuses flags that do not go together, and a picture larger than the
/// memory budget, before anything is loaded.
fn check_args(args: &RenderArgs) -> anyhow::Result<()> {
    let traced_path = args.path.traced();
    if traced_path && (args.mode != TraceMode::Svo || args.view != View::Shaded) {
        anyhow::bail!("the path tracer (--spp) walks the SVO and shades: it takes neither --mode grid nor --view");
    }
    if args.lod > 0.0 && (traced_path || args.mode != TraceMode::Svo) {
        anyhow::bail!("--lod applies to the SVO preview: the path tracer (--spp) and --mode grid trace exactly");
    }
    if (args.path.denoise || args.path.oidn) && !traced_path {
        anyhow::bail!("--denoise and --oidn filter the path tracer's samples: give --spp N or --target-error E");
    }
    if args.path.seed != 0 && !traced_path {
        anyhow::bail!("--seed picks the path tracer's samples: give --spp N or --target-error E");
    }
    if args.path.oidn && !octovox::trace::oidn::AVAILABLE {
        return Err(octovox::trace::oidn::OidnError::NotBuilt.into());
    }
    if args.cpu && args.path.target_error.is_some() {
        anyhow::bail!("--target-error samples on the GPU; the CPU reference renders a fixed --spp");
    }
    let pixels = u64::from(args.size.0) * u64::from(args.size.1);
    let per_pixel = match (args.cpu, traced_path) {
        (true, true) => CPU_PATH_BYTES_PER_PIXEL,
        (true, false) => CPU_BYTES_PER_PIXEL,
        (false, true) => GPU_PATH_BYTES_PER_PIXEL,
        (false, false) => GPU_BYTES_PER_PIXEL,
    };
    octovox::budget::check(|| format!("a {}x{} render", args.size.0, args.size.1), pixels * per_pixel)?;
    Ok(())
}

/// Where a render's frames are drawn: one GPU renderer for every frame,
/// or the CPU reference.
pub(super) enum Device {
    Gpu(Box<Renderer>),
    Cpu,
}

impl Device {
    pub(super) fn new(args: &RenderArgs) -> anyhow::Result<Device> {
        if args.cpu {
            return Ok(Device::Cpu);
        }
        let renderer = Renderer::headless().context("no GPU for rendering (try --cpu)")?;
        log::info!("rendering on {}", renderer.gpu.adapter_name);
        Ok(Device::Gpu(Box::new(renderer)))
    }
}

/// What differs between the frames of one render: the ground's height
/// (fixed for an animation, so it does not jump) and the frame's number,
/// which picks the path tracer's samples: a frame is the same bytes
/// whichever process renders it.
#[derive(Clone, Copy)]
pub(super) struct Shot {
    pub ground: Option<i32>,
    pub number: u32,
}

/// One picture of `scene`: the preview or the path tracer, at the render
/// scale, scaled up to `--size`.
pub(super) fn render_frame(
    device: &mut Device,
    scene: &mut Scene,
    camera: &Camera,
    args: &RenderArgs,
    frame: Shot,
) -> anyhow::Result<(image::RgbaImage, Stats)> {
    let traced = octovox::settings::scaled_size(args.size, args.render_scale);
    let (image, stats) = if args.path.traced() {
        path_traced(device, scene, camera, args, traced, frame)?
    } else {
        preview(device, scene, camera, args, traced, frame.ground)?
    };
    Ok((octovox::io::png::upscale(image, args.size), stats))
}

/// A frame's number as the path tracer's seeds take it (a frame past
/// 2^32 is refused when the scene is walked there).
pub(super) fn frame_number(frame: usize) -> u32 {
    u32::try_from(frame).unwrap_or(u32::MAX)
}

/// The world height of the ground plane (`--ground`, the default; none with
/// `--no-ground`): under the lowest voxel of `bounds` (the scene's, or an
/// animation's whole motion), or at 0 in an empty scene.
pub(super) fn ground_height(bounds: Option<(glam::IVec3, glam::IVec3)>, args: &RenderArgs) -> Option<i32> {
    (!args.no_ground).then_some(bounds.map_or(0, |(lo, _)| lo.y))
}

/// What `--stats` prints.
#[derive(serde::Serialize, Default)]
pub(super) struct Stats {
    effects: Vec<&'static str>,
    /// The samples taken (with `--target-error`, until the estimate met it).
    spp: u32,
    ms_per_sample: f64,
    /// The filter's milliseconds with `--denoise`.
    denoise_ms: Option<f64>,
    /// The raw image's estimated noise (`crate::trace::denoise::noise_estimate`).
    noise_estimate: Option<f32>,
    adapter: String,
    /// Emissive cells sampled as lights.
    lights: usize,
}

/// Today's deterministic shading (colour, Lambert, shadow), one frame.
fn preview(
    device: &mut Device,
    scene: &mut Scene,
    camera: &Camera,
    args: &RenderArgs,
    size: (u32, u32),
    ground: Option<i32>,
) -> anyhow::Result<(image::RgbaImage, Stats)> {
    let settings = RenderSettings {
        mode: args.mode,
        view: args.view,
        shadows: !args.no_shadows,
        render_scale: 1.0,
        lod: args.lod,
        ground,
    };
    let grid = match args.mode {
        TraceMode::Grid => Some(DenseGrid::from_octree(scene.drawn())?),
        TraceMode::Svo => None,
    };
    let stats = |ms, adapter| Stats { ms_per_sample: ms, adapter, ..Stats::default() };
    let Device::Gpu(renderer) = device else {
        let start = Instant::now();
        let image = render_scene_cpu(scene, grid.as_ref(), camera, size, &settings);
        return Ok((image, stats(start.elapsed().as_secs_f64() * 1e3, "cpu".into())));
    };
    renderer.sync(scene);
    if let Some(grid) = &grid {
        renderer.set_grid(grid, scene.revision())?;
    }
    let ms = renderer.render(scene, camera, size, &settings, None)?;
    log::info!("frame took {ms:.2} ms");
    Ok((renderer.read_image()?, stats(ms, renderer.gpu.adapter_name.clone())))
}

/// The path tracer, on the GPU or the CPU reference: `--spp` samples, or
/// until the noise estimate is below `--target-error`; denoised with
/// `--denoise`.
fn path_traced(
    device: &mut Device,
    scene: &mut Scene,
    camera: &Camera,
    args: &RenderArgs,
    size: (u32, u32),
    frame: Shot,
) -> anyhow::Result<(image::RgbaImage, Stats)> {
    // The frame's own sequence of samples (seed 0, frame 0: today's still images).
    let seed = (u64::from(args.path.seed) + u64::from(frame.number)) % u64::from(octovox::settings::SEEDS);
    let settings = PathSettings { ground: frame.ground, seed: seed as u32, ..args.path.settings() };
    let Device::Gpu(renderer) = device else {
        return path_traced_cpu(scene, camera, &settings, args, size);
    };
    renderer.sync(scene);
    let (cap, target) = (args.path.samples(), args.path.target_error);
    let view = PathView { scene, camera, size, settings: &settings };
    // One bar at a time: a render of many frames draws its own.
    let bar = if args.animates() {
        indicatif::ProgressBar::hidden()
    } else {
        super::progress_bar::bar("path tracing", u64::from(cap))
    };
    let Accumulated { last: frame, ms: total_ms } = accumulate(renderer, &view, cap, target, |_| bar.inc(1))?;
    bar.finish_and_clear();
    let noise = renderer.noise_estimate()?;
    let (image, denoise_ms) = finished_image(renderer, &args.path, size)?;
    let stats = Stats {
        effects: frame.effects.names(),
        spp: frame.samples,
        ms_per_sample: total_ms / f64::from(frame.samples.max(1)),
        denoise_ms,
        noise_estimate: noise,
        adapter: renderer.gpu.adapter_name.clone(),
        lights: frame.lights,
    };
    if let Some(target) = target
        && noise.is_none_or(|n| n >= target)
    {
        log::warn!("stopped at the {cap}-sample cap above the target error {target} (estimate {noise:?})");
    }
    log::info!("{} samples, {:.2} ms each", stats.spp, stats.ms_per_sample);
    Ok((image, stats))
}

/// The image of the accumulated samples: raw, or denoised by `--denoise`
/// (on the GPU) or `--oidn` (read back and filtered on the CPU), with the
/// filter's milliseconds.
fn finished_image(
    renderer: &mut Renderer,
    path: &PathArgs,
    size: (u32, u32),
) -> anyhow::Result<(image::RgbaImage, Option<f64>)> {
    if path.oidn {
        let (image, ms) = oidn_image(renderer, size)?;
        return Ok((image, Some(ms)));
    }
    let denoise_ms = if path.denoise { Some(renderer.denoise_now()?) } else { None };
    Ok((renderer.read_image()?, denoise_ms))
}

/// The GPU's accumulation read back and filtered by Open Image Denoise,
/// and the milliseconds both took (OIDN's cost includes the read-back).
pub(crate) fn oidn_image(renderer: &Renderer, size: (u32, u32)) -> anyhow::Result<(image::RgbaImage, f64)> {
    let start = Instant::now();
    let (sums, guides) = renderer.read_samples()?;
    let image = octovox::trace::oidn::denoised_image(&sums, &guides, size.0, size.1)?;
    Ok((image, start.elapsed().as_secs_f64() * 1e3))
}

/// `--spp` samples of the CPU reference, denoised by the filter's CPU twin
/// with `--denoise`, or by Open Image Denoise with `--oidn`.
fn path_traced_cpu(
    scene: &Scene,
    camera: &Camera,
    settings: &PathSettings,
    args: &RenderArgs,
    size: (u32, u32),
) -> anyhow::Result<(image::RgbaImage, Stats)> {
    let spp = args.path.samples();
    let start = Instant::now();
    let frame = render_cpu(scene, camera, size, settings, spp);
    let ms = start.elapsed().as_secs_f64() * 1e3 / f64::from(spp);
    let filter_start = Instant::now();
    let pixels = if args.path.oidn {
        octovox::trace::oidn::denoise(&frame.sums, &frame.guides, size.0, size.1)?
    } else if args.path.denoise {
        let basis = camera.basis(size.0, size.1, scene.origin());
        denoise(&Frame::of(&basis), &frame.sums, &frame.guides)
    } else {
        frame.pixels
    };
    let filtered = args.path.denoise || args.path.oidn;
    let denoise_ms = filtered.then(|| filter_start.elapsed().as_secs_f64() * 1e3);
    let stats = Stats {
        effects: frame.effects.names(),
        spp,
        ms_per_sample: ms,
        denoise_ms,
        noise_estimate: noise_estimate(&frame.sums),
        adapter: "cpu".into(),
        lights: frame.lights,
    };
    Ok((to_image(&pixels, size.0, size.1), stats))
}
