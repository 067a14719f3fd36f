//! `octovox render`: one image of a scene, on the GPU or the CPU reference.

use std::process::ExitCode;

use anyhow::Context;

use crate::cli::{RenderArgs, camera_or_framing};
use octovox::gpu::Renderer;
use octovox::io::atomic::WriteOptions;
use octovox::io::output::{OutputKind, check_output};
use octovox::io::png::save_png;
use octovox::scene::Scene;
use octovox::settings::{RenderSettings, TraceMode};
use octovox::trace::grid::DenseGrid;
use octovox::trace::render::render_scene_cpu;

/// Peak bytes per pixel of a CPU render: a hit record, a shadow flag, the
/// colour and the image (measured: 16384² pixels took about 12 GB).
const CPU_BYTES_PER_PIXEL: u64 = 48;
/// Bytes per pixel of a GPU render on the host: the read-back rows (padded)
/// and the image.
const GPU_BYTES_PER_PIXEL: u64 = 12;

/// Opens FILE, or the built-in demo scene when there is none.
pub fn open_scene(file: Option<&std::path::Path>, frame: usize) -> anyhow::Result<Scene> {
    match file {
        Some(path) => octovox::io::load_scene(path, frame).with_context(|| format!("cannot open {}", path.display())),
        None => Ok(octovox::scene::demo::demo_scene()),
    }
}

pub fn run(args: &RenderArgs) -> anyhow::Result<ExitCode> {
    let inputs: Vec<&std::path::Path> = args.file.iter().map(|p| p.as_path()).collect();
    check_output(&args.output, OutputKind::Image, &inputs, args.force)?;
    let pixels = u64::from(args.size.0) * u64::from(args.size.1);
    let per_pixel = if args.cpu { CPU_BYTES_PER_PIXEL } else { GPU_BYTES_PER_PIXEL };
    octovox::budget::check(|| format!("a {}x{} render", args.size.0, args.size.1), pixels * per_pixel)?;
    let mut scene = open_scene(args.file.as_deref(), args.frame)?;
    let camera = camera_or_framing(args.camera, args.fov, &scene);
    let settings = RenderSettings { mode: args.mode, view: args.view, shadows: !args.no_shadows, render_scale: 1.0 };
    let grid = match args.mode {
        TraceMode::Grid => Some(DenseGrid::from_octree(&scene.tree).map_err(anyhow::Error::msg)?),
        TraceMode::Svo => None,
    };
    let image = if args.cpu {
        render_scene_cpu(&scene, grid.as_ref(), &camera, args.size, &settings)
    } else {
        let mut renderer = Renderer::headless().context("no GPU for rendering (try --cpu)")?;
        log::info!("rendering on {}", renderer.gpu.adapter_name);
        renderer.sync(&mut scene.tree, &scene.palette);
        if let Some(grid) = &grid {
            renderer.set_grid(grid)?;
        }
        let ms = renderer.render(&scene.tree, &camera, args.size, &settings, None)?;
        log::info!("frame took {ms:.2} ms");
        renderer.read_image()?
    };
    save_png(&image, &args.output, WriteOptions { overwrite_read_only: args.force })?;
    say!("wrote {} ({}x{})", args.output.display(), args.size.0, args.size.1)?;
    Ok(ExitCode::SUCCESS)
}
