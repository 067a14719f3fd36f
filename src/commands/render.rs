//! `octovox render`: one image of a scene, on the GPU or the CPU reference.

use std::process::ExitCode;

use anyhow::Context;

use crate::cli::{RenderArgs, camera_or_framing};
use octovox::gpu::Renderer;
use octovox::scene::Scene;
use octovox::settings::{RenderSettings, TraceMode};
use octovox::trace::grid::DenseGrid;
use octovox::trace::render::{Tracer, shade_image, shadow_ray, trace_image};

/// Opens FILE, or the built-in demo scene when there is none.
pub fn open_scene(file: Option<&std::path::Path>, frame: usize) -> anyhow::Result<Scene> {
    match file {
        Some(path) => octovox::io::load_scene(path, frame).with_context(|| format!("cannot open {}", path.display())),
        None => Ok(octovox::scene::demo::demo_scene()),
    }
}

pub fn run(args: &RenderArgs) -> anyhow::Result<ExitCode> {
    let mut scene = open_scene(args.file.as_deref(), args.frame)?;
    let camera = camera_or_framing(args.camera, args.fov, &scene);
    let settings = RenderSettings { mode: args.mode, view: args.view, shadows: !args.no_shadows, render_scale: 1.0 };
    let grid = match args.mode {
        TraceMode::Grid => Some(DenseGrid::from_octree(&scene.tree).context("the scene is too sparse and wide for a dense grid")?),
        TraceMode::Svo => None,
    };
    let image = if args.cpu {
        render_cpu(&scene, grid.as_ref(), &camera, args.size, &settings)
    } else {
        let mut renderer = Renderer::headless().context("no GPU for rendering (try --cpu)")?;
        log::info!("rendering on {}", renderer.gpu.adapter_name);
        renderer.sync(&mut scene.tree, &scene.palette);
        if let Some(grid) = &grid {
            renderer.set_grid(grid);
        }
        let ms = renderer.render(&scene.tree, &camera, args.size, &settings, None)?;
        log::info!("frame took {ms:.2} ms");
        renderer.read_image()?
    };
    save_png(&image, &args.output)?;
    println!("wrote {} ({}x{})", args.output.display(), args.size.0, args.size.1);
    Ok(ExitCode::SUCCESS)
}

/// The CPU reference renderer: same traversal, same shading.
pub fn render_cpu(
    scene: &Scene,
    grid: Option<&DenseGrid>,
    camera: &octovox::camera::Camera,
    size: (u32, u32),
    settings: &RenderSettings,
) -> image::RgbaImage {
    let tracer = match grid {
        Some(grid) => Tracer::Grid(grid),
        None => Tracer::Svo(&scene.tree),
    };
    let basis = camera.basis(size.0, size.1, scene.tree.origin());
    let hits = trace_image(tracer, &basis);
    let shadows: Vec<bool> = if settings.shadows {
        hits.iter().map(|hit| shadow_ray(hit).is_some_and(|ray| tracer.trace(&ray).is_hit())).collect()
    } else {
        Vec::new()
    };
    let pixels = shade_image(&hits, &basis, &scene.palette, settings.view, &shadows);
    let bytes: Vec<u8> = pixels.into_iter().flatten().collect();
    // shade_image returns exactly width * height pixels.
    image::RgbaImage::from_raw(basis.width, basis.height, bytes).unwrap_or_default()
}

/// Writes a PNG atomically (temporary file, then rename).
pub fn save_png(image: &image::RgbaImage, path: &std::path::Path) -> anyhow::Result<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let tmp = tempfile::Builder::new().suffix(".png").tempfile_in(dir).with_context(|| format!("cannot write in {}", dir.display()))?;
    image.write_to(&mut std::io::BufWriter::new(tmp.as_file()), image::ImageFormat::Png).with_context(|| format!("cannot encode {}", path.display()))?;
    tmp.persist(path).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}
