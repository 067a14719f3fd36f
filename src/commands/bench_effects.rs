//! `octovox bench effects`: what simulating only the effects a scene calls
//! for saves. Per scene, the path tracer's time per sample with the kernel
//! compiled for the scene's effect set (`--effects auto`) against the kernel
//! with every effect (`--effects all`), runs interleaved, and the two
//! images compared: they must match, since an effect the scene lacks adds
//! nothing to the picture.

use glam::Vec3;
use octovox::trace::render::display_rgba;
use serde::Serialize;

use octovox::camera::Camera;
use octovox::gpu::{PathView, Renderer};
use octovox::scene::Scene;
use octovox::scene::demo::BuiltIn;
use octovox::settings::{EffectsChoice, PathSettings};

use super::bench::{header, median};

#[derive(Serialize)]
struct EffectsRow {
    scene: &'static str,
    adapter: String,
    width: u32,
    height: u32,
    samples: u32,
    effects_auto: Vec<&'static str>,
    auto_ms_per_sample: f64,
    all_ms_per_sample: f64,
    /// Largest difference of one channel between the two mean images.
    max_difference: f32,
    /// Pixels whose 8-bit colour differs between the two.
    pixels_differing: usize,
}

fn scenes() -> [(&'static str, Scene, Option<Camera>); 3] {
    [
        ("terrain (diffuse only)", BuiltIn::Terrain.scene(), None),
        ("showroom (mixed)", BuiltIn::Showroom.scene(), None),
        ("interior (emissive, closed)", BuiltIn::Interior.scene(), Some(octovox::scene::showroom::interior_camera())),
    ]
}

/// Renders `samples` samples; returns the median milliseconds per sample
/// and the mean radiance.
fn run(
    renderer: &mut Renderer,
    scene: &Scene,
    camera: &Camera,
    size: (u32, u32),
    settings: &PathSettings,
    samples: u32,
) -> anyhow::Result<(Vec<f64>, Vec<Vec3>)> {
    let mut times = Vec::new();
    let view = PathView { scene, camera, size, settings };
    for sample in 0..samples {
        let frame = renderer.render_path(&view, sample == 0)?;
        anyhow::ensure!(
            frame.kernel == frame.effects || settings.effects == EffectsChoice::All,
            "timed the stand-in kernel"
        );
        times.push(frame.ms);
    }
    Ok((times, renderer.read_radiance()?))
}

pub fn bench_effects(quick: bool) -> anyhow::Result<(String, String)> {
    let mut renderer = Renderer::headless()?;
    let (width, height, samples, rounds) = if quick { (160, 90, 3, 1) } else { (640, 360, 16, 2) };
    let mut rows = Vec::new();
    for (name, mut scene, camera) in scenes() {
        let camera = camera.unwrap_or_else(|| crate::cli::camera_or_framing(None, 50.0, &scene));
        renderer.sync(&mut scene);
        let auto = PathSettings::default();
        let all = PathSettings { effects: EffectsChoice::All, ..auto };
        let (mut auto_times, mut all_times) = (Vec::new(), Vec::new());
        let (mut auto_image, mut all_image) = (Vec::new(), Vec::new());
        // Compile both kernels before timing anything.
        renderer.compile_path_kernel(&scene, &auto)?;
        renderer.compile_path_kernel(&scene, &all)?;
        run(&mut renderer, &scene, &camera, (width, height), &auto, 1)?;
        run(&mut renderer, &scene, &camera, (width, height), &all, 1)?;
        // Interleaved, so that a noisy machine weighs on both alike.
        for _ in 0..rounds {
            let (times, image) = run(&mut renderer, &scene, &camera, (width, height), &auto, samples)?;
            auto_times.extend(times);
            auto_image = image;
            let (times, image) = run(&mut renderer, &scene, &camera, (width, height), &all, samples)?;
            all_times.extend(times);
            all_image = image;
        }
        let pairs = auto_image.iter().zip(&all_image);
        let max_difference = pairs.clone().map(|(a, b)| (*a - *b).abs().max_element()).fold(0.0, f32::max);
        let pixels_differing = pairs.filter(|(a, b)| display_rgba(**a) != display_rgba(**b)).count();
        let effects = octovox::trace::path::effects_for(&scene, &auto);
        rows.push(EffectsRow {
            scene: name,
            adapter: renderer.gpu.adapter_name.clone(),
            width,
            height,
            samples,
            effects_auto: effects.names(),
            auto_ms_per_sample: median(auto_times),
            all_ms_per_sample: median(all_times),
            max_difference,
            pixels_differing,
        });
    }
    Ok((markdown(&rows), serde_json::to_string_pretty(&rows)?))
}

fn markdown(rows: &[EffectsRow]) -> String {
    let mut md = header("Effects compiled per scene");
    md += "Time per path-traced sample (median) with the kernel built for the scene's effect set (`--effects auto`) and with every effect (`--effects all`), runs interleaved in one process; and how far the two mean images differ.\n\n";
    md += "| scene | adapter | size | samples | effects (auto) | auto ms/sample | all ms/sample | all ÷ auto | max difference | pixels differing |\n|---|---|---|---|---|---|---|---|---|---|\n";
    for r in rows {
        md += &format!(
            "| {} | {} | {}×{} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2e} | {} |\n",
            r.scene,
            r.adapter,
            r.width,
            r.height,
            r.samples,
            r.effects_auto.join(" "),
            r.auto_ms_per_sample,
            r.all_ms_per_sample,
            r.all_ms_per_sample / r.auto_ms_per_sample,
            r.max_difference,
            r.pixels_differing
        );
    }
    md += "\nThe kernels differ only in override constants (`shaders/path.wgsl`): code for an effect that is off is removed when the pipeline is compiled, and the random numbers an effect would draw are drawn only where it acts, so the images match where the effect is absent.\n";
    md
}
