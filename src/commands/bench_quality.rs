//! `octovox bench quality`: what accuracy costs in time. For each scene a
//! reference image at the highest settings, then one knob at a time turned
//! down from a base setting; for each, the milliseconds a frame takes and
//! its error against the reference (mean FLIP and PSNR), measured in one
//! run. Writes `quality.md`, `quality.json` and `quality.png` (error against
//! time, log scale, the Pareto front of each scene joined).

use std::path::Path;

use glam::DVec3;
use serde::Serialize;

use octovox::camera::Camera;
use octovox::gpu::PathView;
use octovox::gpu::Renderer;
use octovox::quality::{REFERENCE_SEED, Setting, accumulate, flip, pareto_front, psnr, render_setting, rms_error};
use octovox::scene::Scene;
use octovox::scene::demo::BuiltIn;
use octovox::settings::{RenderSettings, TraceMode};
use octovox::trace::denoise::{Change, Frame, change_in_standard_errors, denoise};
use octovox::trace::oidn;

use super::bench::header;
use super::render::oidn_image;

#[derive(Serialize)]
struct QualityRow {
    scene: &'static str,
    /// The knob turned (its CLI flag) and its value; "base" for the base setting.
    knob: &'static str,
    value: String,
    ms_per_frame: f64,
    flip: f32,
    /// dB; `None` when identical to the reference.
    psnr: Option<f64>,
    /// The filter the row's samples went through.
    filter: Filter,
    /// Rows that differ from the base in their samples alone (raw or
    /// denoised): FLIP and RMS error (0..1 of full scale) against the base
    /// setting converged (the reference's samples, the base's bounces), so
    /// what is left is noise and what the filter did, not the bias of fewer
    /// bounces.
    noise_flip: Option<f32>,
    noise_rms: Option<f64>,
    /// Raw ones of those: the noise estimate at the last sample.
    noise_estimate: Option<f32>,
    /// On the Pareto front of its scene's rows of the same filter.
    pareto: bool,
}

/// What a row's samples went through before the image was measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
enum Filter {
    Raw,
    /// `--denoise`, the à-trous filter on the GPU.
    Atrous,
    /// `--oidn`, Open Image Denoise on the CPU (builds with the feature).
    Oidn,
}

impl Filter {
    fn label(self) -> &'static str {
        match self {
            Filter::Raw => "raw",
            Filter::Atrous => "denoised",
            Filter::Oidn => "OIDN",
        }
    }
}

struct Sizes {
    size: (u32, u32),
    reference_spp: u32,
    base_spp: u32,
}

/// The level-of-detail footprints measured, in pixels.
const LOD_PIXELS: [f32; 3] = [1.0, 2.0, 4.0];

/// The samples per pixel measured raw and denoised: the base's among them.
fn spp_values(sizes: &Sizes) -> Vec<u32> {
    let base = sizes.base_spp;
    let mut values = vec![1, 4, 8, base, base * 2, base * 4];
    values.sort_unstable();
    values.dedup();
    values
}

/// A row to measure: the knob's CLI flag and value, the setting, the filter.
type Knob = (&'static str, String, Setting, Filter);

/// The base setting and the knobs turned from it, by CLI flag; then every
/// spp of [`spp_values`] denoised (and through Open Image Denoise, in a
/// build that has it).
fn knobs(sizes: &Sizes) -> Vec<Knob> {
    let base = |spp, bounces, shadow_samples, render_scale| Setting::Path {
        spp,
        bounces,
        shadow_samples,
        render_scale,
        denoise: false,
        seed: 0,
    };
    let spp = sizes.base_spp;
    let raw = |knob, value, setting| (knob, value, setting, Filter::Raw);
    let mut out = vec![raw("base", format!("--spp {spp} --bounces 3"), base(spp, 3, 1, 1.0))];
    for s in spp_values(sizes).into_iter().filter(|&s| s != spp) {
        out.push(raw("--spp", s.to_string(), base(s, 3, 1, 1.0)));
    }
    for b in [0, 1, 6] {
        out.push(raw("--bounces", b.to_string(), base(spp, b, 1, 1.0)));
    }
    out.push(raw("--shadow-samples", "4".into(), base(spp, 3, 4, 1.0)));
    for r in [0.25, 0.5] {
        out.push(raw("--render-scale", r.to_string(), base(spp, 3, 1, r)));
    }
    let preview = |mode, lod| Setting::Preview { mode, render_scale: 1.0, lod };
    out.push(raw("--mode", "svo (preview)".into(), preview(TraceMode::Svo, 0.0)));
    out.push(raw("--mode", "grid (preview)".into(), preview(TraceMode::Grid, 0.0)));
    for lod in LOD_PIXELS {
        out.push(raw("--lod", format!("{lod} (preview)"), preview(TraceMode::Svo, lod)));
    }
    for s in spp_values(sizes) {
        let denoised =
            Setting::Path { spp: s, bounces: 3, shadow_samples: 1, render_scale: 1.0, denoise: true, seed: 0 };
        out.push(("--denoise", format!("--spp {s}"), denoised, Filter::Atrous));
    }
    if oidn::AVAILABLE {
        for s in spp_values(sizes) {
            out.push(("--oidn", format!("--spp {s}"), base(s, 3, 1, 1.0), Filter::Oidn));
        }
    }
    out
}

/// Draws one row's frame ([`render_setting`]); through Open Image Denoise
/// for [`Filter::Oidn`], whose readback and filter count in its time.
fn measure(
    renderer: &mut Renderer,
    scene: &Scene,
    camera: &Camera,
    size: (u32, u32),
    setting: Setting,
    filter: Filter,
) -> anyhow::Result<(f64, image::RgbaImage)> {
    let (ms, image) = render_setting(renderer, scene, camera, size, setting)?;
    if filter != Filter::Oidn {
        return Ok((ms, image));
    }
    let (image, oidn_ms) = oidn_image(renderer, size)?;
    Ok((ms + oidn_ms, image))
}

/// The small model, framed.
fn teapot() -> anyhow::Result<(Scene, Camera)> {
    let teapot = octovox::io::load_scene(&super::bench::assets().join("vox/seed/teapot256.vox"), 0)?;
    let camera = crate::cli::camera_or_framing(None, 50.0, &teapot);
    Ok((teapot, camera))
}

fn scenes(quick: bool) -> anyhow::Result<Vec<(&'static str, Scene, Camera)>> {
    let (teapot, teapot_camera) = teapot()?;
    let mut out = vec![("teapot256 (small)", teapot, teapot_camera)];
    if !quick {
        let sculpture = super::bench::sculpture_scene()?;
        let far = far_camera(&sculpture);
        out.push(("sculpture10M (far)", sculpture, far));
    }
    out.push(("interior (path traced)", BuiltIn::Interior.scene(), octovox::scene::showroom::interior_camera()));
    Ok(out)
}

pub fn bench_quality(quick: bool, out: &Path) -> anyhow::Result<(String, String)> {
    let sizes = if quick {
        Sizes { size: (64, 36), reference_spp: 8, base_spp: 2 }
    } else {
        Sizes { size: (320, 180), reference_spp: 256, base_spp: 16 }
    };
    let mut renderer = Renderer::headless()?;
    let (mut rows, mut unbiased, mut targets) = (Vec::new(), Vec::new(), Vec::new());
    for (name, mut scene, camera) in scenes(quick)? {
        renderer.sync(&mut scene);
        let reference = Setting::Path {
            spp: sizes.reference_spp,
            bounces: 8,
            shadow_samples: 4,
            render_scale: 1.0,
            denoise: false,
            seed: REFERENCE_SEED,
        };
        let (_, reference_image) = render_setting(&mut renderer, &scene, &camera, sizes.size, reference)?;
        let reference_noise = renderer.noise_estimate()?;
        let change = filter_change(&renderer, &scene, &camera, sizes.size)?;
        let oidn_reference = if oidn::AVAILABLE { Some(oidn_image(&renderer, sizes.size)?.0) } else { None };
        renderer.denoise_now()?;
        let denoised_reference = renderer.read_image()?;
        let converged_base = Setting::Path {
            spp: sizes.reference_spp,
            bounces: 3,
            shadow_samples: 1,
            render_scale: 1.0,
            denoise: false,
            seed: REFERENCE_SEED,
        };
        let (_, converged) = render_setting(&mut renderer, &scene, &camera, sizes.size, converged_base)?;
        unbiased.push(UnbiasedRow {
            scene: name,
            flip: flip(&reference_image, &denoised_reference),
            oidn_flip: oidn_reference.map(|image| flip(&reference_image, &image)),
            reference_noise,
            change,
        });
        let mut scene_rows = Vec::new();
        for (knob, value, setting, filter) in knobs(&sizes) {
            let (ms, image) = measure(&mut renderer, &scene, &camera, sizes.size, setting, filter)?;
            let spp_only = matches!(setting, Setting::Path { bounces: 3, shadow_samples: 1, render_scale, .. } if render_scale == 1.0);
            scene_rows.push(QualityRow {
                scene: name,
                knob,
                value,
                ms_per_frame: ms,
                flip: flip(&reference_image, &image),
                psnr: psnr(&reference_image, &image),
                filter,
                noise_flip: spp_only.then(|| flip(&converged, &image)),
                noise_rms: spp_only.then(|| rms_error(&converged, &image)),
                noise_estimate: if spp_only && filter == Filter::Raw { renderer.noise_estimate()? } else { None },
                pareto: false,
            });
        }
        for filter in [Filter::Raw, Filter::Atrous, Filter::Oidn] {
            let group: Vec<usize> = (0..scene_rows.len()).filter(|&i| scene_rows[i].filter == filter).collect();
            let points: Vec<(f64, f64)> =
                group.iter().map(|&i| (scene_rows[i].ms_per_frame, f64::from(scene_rows[i].flip))).collect();
            for (&i, on_front) in group.iter().zip(pareto_front(&points)) {
                scene_rows[i].pareto = on_front;
            }
        }
        rows.extend(scene_rows);
        targets.extend(target_rows(&mut renderer, &scene, &camera, name, &sizes, &converged)?);
    }
    std::fs::create_dir_all(out)?;
    super::quality_plot::plot(&rows_for_plot(&rows), &out.join("quality.png"))?;
    let lod_rows = level_of_detail(&mut renderer, quick)?;
    let mut md = markdown(&rows, &sizes, renderer.gpu.adapter_name.as_str());
    md += &denoise_markdown(&rows, &unbiased);
    md += &target_markdown(&targets);
    md += &lod_markdown(&lod_rows);
    let json = serde_json::json!({
        "knobs": rows,
        "denoised_reference": unbiased,
        "target_error": targets,
        "level_of_detail": lod_rows,
    });
    Ok((md, serde_json::to_string_pretty(&json)?))
}

/// The denoised reference against the raw one: what the filter's bias costs.
#[derive(Serialize)]
struct UnbiasedRow {
    scene: &'static str,
    flip: f32,
    /// The same through Open Image Denoise, in a build that has it.
    oidn_flip: Option<f32>,
    reference_noise: Option<f32>,
    /// The filter's change to the reference in standard errors of its raw
    /// pixels (the CPU twin on the reference's sums).
    change: Option<Change>,
}

/// How far the filter moves the pixels of the renderer's accumulation, in
/// their standard errors ([`change_in_standard_errors`]). The CPU twin
/// filters: the GPU's image is rounded to 8 bits, more than a standard
/// error of a converged pixel.
fn filter_change(
    renderer: &Renderer,
    scene: &Scene,
    camera: &Camera,
    size: (u32, u32),
) -> anyhow::Result<Option<Change>> {
    let (sums, guides) = renderer.read_samples()?;
    let frame = Frame::of(&camera.basis(size.0, size.1, scene.origin()));
    Ok(change_in_standard_errors(&sums, &guides, &denoise(&frame, &sums, &guides)))
}

/// One `--target-error` render.
#[derive(Serialize)]
struct TargetRow {
    scene: &'static str,
    target: f32,
    samples: u32,
    noise_estimate: Option<f32>,
    rms_error: f64,
    flip: f32,
}

/// The targets `--target-error` is measured at.
fn targets(quick: bool) -> [f32; 2] {
    if quick { [0.05, 0.03] } else { [0.02, 0.01] }
}

/// Renders the base setting until the noise estimate meets each target
/// (`render --target-error`), at most 16 times the reference's samples.
fn target_rows(
    renderer: &mut Renderer,
    scene: &Scene,
    camera: &Camera,
    name: &'static str,
    sizes: &Sizes,
    reference: &image::RgbaImage,
) -> anyhow::Result<Vec<TargetRow>> {
    let settings = octovox::settings::PathSettings { bounces: 3, ..Default::default() };
    let view = PathView { scene, camera, size: sizes.size, settings: &settings };
    let mut rows = Vec::new();
    for target in targets(sizes.reference_spp < 64) {
        let done = accumulate(renderer, &view, sizes.reference_spp * 16, Some(target), |_| ())?;
        let image = renderer.read_image()?;
        rows.push(TargetRow {
            scene: name,
            target,
            samples: done.last.samples,
            noise_estimate: renderer.noise_estimate()?,
            rms_error: rms_error(reference, &image),
            flip: flip(reference, &image),
        });
    }
    Ok(rows)
}

/// The raw FLIP against the converged base of `scene` at `ms`,
/// interpolated along its raw spp rows (log time); `None` outside them.
fn raw_flip_at(rows: &[QualityRow], scene: &str, ms: f64) -> Option<f64> {
    let mut curve: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.scene == scene && r.filter == Filter::Raw)
        .filter_map(|r| r.noise_flip.map(|f| (r.ms_per_frame.ln(), f64::from(f))))
        .collect();
    curve.sort_by(|a, b| a.0.total_cmp(&b.0));
    let t = ms.ln();
    curve.windows(2).find(|w| w[0].0 <= t && t <= w[1].0).map(|w| {
        let f = if w[1].0 > w[0].0 { (t - w[0].0) / (w[1].0 - w[0].0) } else { 0.0 };
        w[0].1 + f * (w[1].1 - w[0].1)
    })
}

/// The time and FLIP against the converged base of a spp row.
fn flip_of(rows: &[QualityRow], scene: &str, filter: Filter, spp: u32) -> Option<(f64, f32)> {
    rows.iter()
        .find(|r| {
            r.scene == scene && r.filter == filter && {
                let value = r.value.trim_start_matches("--spp ");
                value.split(' ').next() == Some(spp.to_string().as_str())
            }
        })
        .and_then(|r| Some((r.ms_per_frame, r.noise_flip?)))
}

fn denoise_markdown(rows: &[QualityRow], unbiased: &[UnbiasedRow]) -> String {
    let mut md = String::from(
        "\n## Denoised against raw\n\nThe rows that differ from the base in their samples alone, raw and denoised, against the base setting converged (the reference's samples and seed at the base's 3 bounces and 1 shadow sample): the error left is noise and what the filter did to it, not the bias of fewer bounces (which is in the table above). Each denoised row against the raw path tracer at the same wall time: the raw FLIP interpolated between its rows on a log time axis, blank where the denoised frame is faster than raw 1 spp or slower than the last raw row. Target: ratio ≤ 0.6 at 4–16 spp.\n\n| scene | filter | spp | ms | FLIP | raw FLIP at that time | ratio | RMS |\n|---|---|---|---|---|---|---|---|\n",
    );
    let mut scenes: Vec<&str> = rows.iter().map(|r| r.scene).collect();
    scenes.dedup();
    for scene in &scenes {
        for r in rows.iter().filter(|r| r.scene == *scene && r.filter != Filter::Raw) {
            let (Some(flip), Some(rms)) = (r.noise_flip, r.noise_rms) else { continue };
            let raw = raw_flip_at(rows, scene, r.ms_per_frame);
            md += &format!(
                "| {scene} | {} | {} | {:.1} | {flip:.4} | {} | {} | {rms:.4} |\n",
                r.filter.label(),
                r.value.trim_start_matches("--spp "),
                r.ms_per_frame,
                raw.map_or(String::new(), |f| format!("{f:.4}")),
                raw.map_or(String::new(), |f| format!("{:.2}", f64::from(flip) / f)),
            );
        }
    }
    md += "\nDenoised 8 spp against raw 32 spp (FLIP against the converged base; OIDN only in a build with it):\n\n| scene | denoised 8 spp: ms, FLIP | OIDN 8 spp: ms, FLIP | raw 32 spp: ms, FLIP |\n|---|---|---|---|\n";
    for scene in &scenes {
        let cell = |filter, spp| {
            flip_of(rows, scene, filter, spp).map_or("–".into(), |(ms, f)| format!("{ms:.1} ms, {f:.4}"))
        };
        md += &format!(
            "| {scene} | {} | {} | {} |\n",
            cell(Filter::Atrous, 8),
            cell(Filter::Oidn, 8),
            cell(Filter::Raw, 32)
        );
    }
    md += "\nNo bias: the reference's own samples denoised, against the raw reference (target FLIP ≤ 0.01). FLIP also sees the noise the filter took away, which the raw reference still has; the last columns tell the two apart: each filtered channel's change divided by the standard error of its raw mean, RMS and the share beyond 4. Removing noise alone moves a pixel by about its noise: RMS near 1 (a normal distribution puts 0.006 % beyond 4; path-traced noise has longer tails); bias moves it further.\n\n| scene | FLIP | OIDN FLIP | the reference's noise estimate | change, standard errors RMS | share beyond 4 |\n|---|---|---|---|---|---|\n";
    let cell = |v: Option<f32>| v.map_or("–".into(), |n| format!("{n:.4}"));
    for u in unbiased {
        md += &format!(
            "| {} | {:.4} | {} | {} | {} | {} |\n",
            u.scene,
            u.flip,
            cell(u.oidn_flip),
            cell(u.reference_noise),
            u.change.map_or("–".into(), |c| format!("{:.2}", c.rms)),
            cell(u.change.map(|c| c.beyond_four))
        );
    }
    md += "\nThe noise estimate against the measured error, raw rows: the estimate is the RMS standard error of the displayed pixels from each pixel's own samples; the measured error is the RMS difference from the converged base, which has noise of its own (about the estimate of the reference above) and 8-bit rounding.\n\n| scene | spp | estimate | measured RMS | measured / estimate |\n|---|---|---|---|---|\n";
    for r in rows.iter().filter(|r| r.filter == Filter::Raw) {
        let (Some(estimate), Some(measured)) = (r.noise_estimate, r.noise_rms) else { continue };
        let estimate = f64::from(estimate);
        md += &format!(
            "| {} | {} | {estimate:.4} | {measured:.4} | {:.2} |\n",
            r.scene,
            r.value.split(' ').nth(if r.knob == "base" { 1 } else { 0 }).unwrap_or(""),
            measured / estimate.max(1e-9)
        );
    }
    md
}

fn target_markdown(rows: &[TargetRow]) -> String {
    let mut md = String::from(
        "\n## Renders that stop at an error\n\n`render --target-error E` on the base setting: samples until the estimate is below E, and the error measured then against the converged base.\n\n| scene | target | samples | estimate at stop | measured RMS | measured / target | FLIP |\n|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        md += &format!(
            "| {} | {} | {} | {} | {:.4} | {:.2} | {:.4} |\n",
            r.scene,
            r.target,
            r.samples,
            r.noise_estimate.map_or("–".into(), |n| format!("{n:.4}")),
            r.rms_error,
            r.rms_error / f64::from(r.target),
            r.flip
        );
    }
    md
}

#[derive(Serialize)]
struct LodRow {
    view: &'static str,
    lod: f32,
    ms_per_frame: f64,
    speedup: f64,
    mean_steps: f64,
    /// Against the exact (LOD 0) preview of the same view.
    flip: f32,
    changed_pixels: f64,
}

const LOD_VALUES: [f32; 5] = [0.0, 1.0, 2.0, 4.0, 8.0];

/// The level of detail on its own: the preview of the 10 M-voxel sculpture
/// seen from far away, each footprint against the exact walk (time, steps,
/// FLIP of the picture against the exact one). Two views: the far camera of
/// the table above at 1280×720 (the statue a fifth of the height, the rest
/// sky) and the same camera through a long lens, the statue filling a
/// 320×180 image; in both a voxel is about a third of a pixel.
fn level_of_detail(renderer: &mut Renderer, quick: bool) -> anyhow::Result<Vec<LodRow>> {
    let (mut scene, views) = if quick {
        let (teapot, camera) = teapot()?;
        (teapot, vec![("teapot256 at 160×90", camera, (160, 90))])
    } else {
        let sculpture = super::bench::sculpture_scene()?;
        let far = far_camera(&sculpture);
        let lens = Camera { fov_y_deg: far.fov_y_deg / 5.0, ..far };
        let views = vec![
            ("far, 1280×720 (a fifth of the height)", far, (1280, 720)),
            ("far, long lens, 320×180 (fills the image)", lens, (320, 180)),
        ];
        (sculpture, views)
    };
    renderer.sync(&mut scene);
    let mut rows = Vec::new();
    for (view, camera, size) in views {
        rows.extend(lod_rows(renderer, &scene, view, &camera, size, if quick { 2 } else { 9 })?);
    }
    Ok(rows)
}

/// Each footprint of `LOD_VALUES` from one view.
fn lod_rows(
    renderer: &mut Renderer,
    scene: &Scene,
    view: &'static str,
    camera: &Camera,
    size: (u32, u32),
    frames: usize,
) -> anyhow::Result<Vec<LodRow>> {
    let settings = |lod| RenderSettings { lod, ..RenderSettings::default() };
    let mut measured = Vec::new();
    // The picture and the steps from one frame with hit records; the timed
    // frames below write none.
    renderer.hit_records = true;
    for lod in LOD_VALUES {
        renderer.render(scene, camera, size, &settings(lod), None)?;
        measured.push((lod, renderer.read_image()?, super::bench::mean_steps(&renderer.read_hits()?), Vec::new()));
    }
    renderer.hit_records = false;
    // Frames interleaved, so the machine's noise falls on every footprint alike.
    for _ in 0..frames {
        for (lod, _, _, times) in &mut measured {
            let start = std::time::Instant::now();
            renderer.render(scene, camera, size, &settings(*lod), None)?;
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
    }
    let exact = measured[0].1.clone();
    let exact_ms = super::bench::median(measured[0].3.clone());
    let pixels = (u64::from(size.0) * u64::from(size.1)) as f64;
    Ok(measured
        .into_iter()
        .map(|(lod, image, mean_steps, times)| {
            let ms = super::bench::median(times);
            let changed = image.pixels().zip(exact.pixels()).filter(|(a, b)| a != b).count();
            LodRow {
                view,
                lod,
                ms_per_frame: ms,
                speedup: exact_ms / ms,
                mean_steps,
                flip: flip(&exact, &image),
                changed_pixels: changed as f64 / pixels,
            }
        })
        .collect())
}

fn lod_markdown(rows: &[LodRow]) -> String {
    let mut md = String::from(
        "\n## Level of detail alone\n\nThe preview (sun shadows on) of the sculpture seen from far away, each `--lod` against the exact walk: wall time per frame (median of interleaved frames, the renderer waiting for each), the mean traversal steps per pixel, and the picture against the exact (LOD 0) one: FLIP and the share of pixels that changed at all.\n\n| view | --lod | ms/frame | speed-up | mean steps | FLIP vs exact | pixels changed |\n|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        md += &format!(
            "| {} | {} | {:.1} | {:.2}× | {:.1} | {:.4} | {:.1} % |\n",
            r.view,
            r.lod,
            r.ms_per_frame,
            r.speedup,
            r.mean_steps,
            r.flip,
            100.0 * r.changed_pixels
        );
    }
    md
}

/// Far away: the statue spans a fifth of the image's height.
fn far_camera(scene: &Scene) -> Camera {
    let (lo, hi) = scene.solid_bounds().unwrap_or_default();
    let centre = (lo + hi).as_dvec3() * 0.5;
    Camera { eye: centre + DVec3::new(1.0, 0.5, 1.4) * 2400.0, target: centre, fov_y_deg: 20.0, ortho: None }
}

fn rows_for_plot(rows: &[QualityRow]) -> Vec<super::quality_plot::Point> {
    rows.iter()
        .map(|r| super::quality_plot::Point {
            series: match r.filter {
                Filter::Raw => r.scene.to_string(),
                filter => format!("{}, {}", r.scene, filter.label()),
            },
            label: if r.knob == "base" { "base".to_string() } else { format!("{} {}", r.knob, r.value) },
            ms: r.ms_per_frame,
            error: f64::from(r.flip),
            pareto: r.pareto,
        })
        .collect()
}

fn markdown(rows: &[QualityRow], sizes: &Sizes, adapter: &str) -> String {
    let mut md = header("What accuracy costs in time");
    md += &format!(
        "On {adapter}, {}×{} pixels. The reference per scene: the path tracer at {} samples, 8 bounces, 4 shadow samples, full scale, from another seed than the rows' (`--seed {REFERENCE_SEED}`: none of its samples is one of theirs). \
         The base: {} samples, 3 bounces, 1 shadow sample, full scale; each other row turns one knob from the base (by its CLI flag). \
         `ms/frame` is the wall time from submitting the frame's first sample to the end of its last (the renderer waits for each); FLIP is the mean of NVIDIA's FLIP error map (0 = identical; lower is better); \
         PSNR over the 8-bit RGB. ★ marks the Pareto front: no other setting of that scene is both faster and closer. \
         Plot: [quality.png](quality.png).\n\n",
        sizes.size.0, sizes.size.1, sizes.reference_spp, sizes.base_spp
    );
    md += "| scene | knob | value | ms/frame | FLIP | PSNR (dB) | front |\n|---|---|---|---|---|---|---|\n";
    for r in rows {
        md += &format!(
            "| {} | {} | {} | {:.1} | {:.4} | {} | {} |\n",
            r.scene,
            r.knob,
            r.value,
            r.ms_per_frame,
            r.flip,
            r.psnr.map_or("∞".into(), |p| format!("{p:.1}")),
            if r.pareto { "★" } else { "" }
        );
    }
    md += "\nWhat these numbers say, scene by scene: [docs/rendering.md](../rendering.md#what-accuracy-costs).\n";
    md
}
