//! `octovox bench anim`: what playing an animation costs. A forest of
//! 2,000 references leaning by free turns, whose trees rise and fall and
//! turn, each frame shown by the editor's `frame N` (the window's path)
//! against the same forest standing still, with the bytes each frame
//! uploads, and the still forest against one of quarter turns only; a
//! turntable rendered as 1, 2 and 4 shards (`render --shard`), each shard
//! its own process; and a free turn against a quarter turn (`bench_turns`).

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use anyhow::Context;
use serde::Serialize;

use octovox::camera::Camera;
use octovox::editor::Editor;
use octovox::gpu::Renderer;
use octovox::scene::Scene;
use octovox::settings::RenderSettings;

use super::bench::{header, median};
use super::bench_scene::{MOVING_FRAMES, Stand, forest};

#[derive(Serialize)]
struct AnimRow {
    objects: usize,
    adapter: String,
    width: u32,
    height: u32,
    frames: u32,
    /// Drawn as instances (`Scene::instanced`).
    drawn_as: &'static str,
    /// Milliseconds a frame: `frame N`, the upload and the preview, playing.
    frame_ms_playing: f64,
    /// The same frame of the forest standing still: the upload (nothing)
    /// and the preview.
    frame_ms_still: f64,
    /// The playing forest's frame drawn again with nothing changed: the
    /// same frame standing still.
    frame_ms_held: f64,
    /// The still forest's frame with its trees by quarter turns only (no
    /// free turn: the integer instance path).
    frame_ms_aligned: f64,
    /// The still forest's frame with its trees turned freely about the up
    /// axis only (upright: no lean).
    frame_ms_upright: f64,
    /// Of a playing frame, showing it alone (`Editor::play_frame`).
    show_ms: f64,
    /// Composing the CPU's octree once playing stops halfway through the
    /// loop, every tree moved (`Scene::catch_up`).
    catch_up_ms: f64,
    upload_bytes_per_frame: u64,
    instance_bytes: u64,
    turntable: TurntableRow,
    turns: super::bench_turns::TurnsRow,
}

#[derive(Serialize)]
struct TurntableRow {
    frames: u32,
    width: u32,
    height: u32,
    spp: u32,
    /// Seconds of each shard's process, for 1, 2 and 4 shards.
    shards: Vec<(u32, Vec<f64>)>,
}

pub fn bench_anim(quick: bool) -> anyhow::Result<(String, String)> {
    let count = if quick { 200 } else { 2000 };
    let (width, height, rounds) = if quick { (320, 180, 6) } else { (1280, 720, MOVING_FRAMES) };
    let mut playing = Editor::default();
    let leaning = Stand { turned: true, lean: true, moving: false };
    playing.set_scene(forest(count, Stand { moving: true, ..leaning })?);
    let mut still = forest(count, leaning)?;
    let mut aligned = forest(count, Stand::ALIGNED)?;
    let mut upright = forest(count, Stand { lean: false, ..leaning })?;
    let renderer = || Renderer::headless().context("bench anim needs a GPU (lavapipe works)");
    let (mut playing_renderer, mut still_renderer, mut aligned_renderer) = (renderer()?, renderer()?, renderer()?);
    let mut upright_renderer = renderer()?;
    let (lo, hi) = still.solid_bounds().context("an empty forest")?;
    let camera = Camera::framing(lo, hi + glam::IVec3::new(0, 8, 0), 50.0);
    let settings = RenderSettings { shadows: false, ..RenderSettings::default() };
    // Milliseconds of a frame of `scene` standing still: the upload
    // (nothing after the first) and the preview.
    let still_frame = |renderer: &mut Renderer, scene: &mut Scene| -> anyhow::Result<f64> {
        let start = Instant::now();
        renderer.sync(scene);
        renderer.render(scene, &camera, (width, height), &settings, None)?;
        Ok(start.elapsed().as_secs_f64() * 1e3)
    };
    // One warm-up frame each, then the four alternate, frame by frame.
    still_frame(&mut playing_renderer, &mut playing.scene)?;
    still_frame(&mut still_renderer, &mut still)?;
    still_frame(&mut aligned_renderer, &mut aligned)?;
    still_frame(&mut upright_renderer, &mut upright)?;
    let (mut playing_ms, mut still_ms, mut show_ms, mut bytes) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut aligned_ms, mut upright_ms, mut held_ms) = (Vec::new(), Vec::new(), Vec::new());
    for frame in 1..=rounds {
        let start = Instant::now();
        playing.play_frame(frame)?;
        show_ms.push(start.elapsed().as_secs_f64() * 1e3);
        bytes.push(playing_renderer.sync(&mut playing.scene).bytes);
        playing_renderer.render(&playing.scene, &camera, (width, height), &settings, None)?;
        playing_ms.push(start.elapsed().as_secs_f64() * 1e3);
        // The same frame again, standing still: nothing to show or send.
        held_ms.push(still_frame(&mut playing_renderer, &mut playing.scene)?);
        still_ms.push(still_frame(&mut still_renderer, &mut still)?);
        aligned_ms.push(still_frame(&mut aligned_renderer, &mut aligned)?);
        upright_ms.push(still_frame(&mut upright_renderer, &mut upright)?);
    }
    // Stopped halfway, where every tree stands furthest from where the
    // composed octree holds it (the loop's last frame is its first again).
    playing.play_frame(MOVING_FRAMES / 2)?;
    let start = Instant::now();
    playing.scene.catch_up()?;
    let catch_up_ms = start.elapsed().as_secs_f64() * 1e3;
    let row = AnimRow {
        objects: count as usize,
        adapter: playing_renderer.gpu.adapter_name.clone(),
        width,
        height,
        frames: rounds,
        drawn_as: if playing.scene.instanced().is_some() { "instances" } else { "composed" },
        frame_ms_playing: median(playing_ms),
        frame_ms_still: median(still_ms),
        frame_ms_held: median(held_ms),
        frame_ms_aligned: median(aligned_ms),
        frame_ms_upright: median(upright_ms),
        show_ms: median(show_ms),
        catch_up_ms,
        upload_bytes_per_frame: bytes.iter().copied().max().unwrap_or(0),
        instance_bytes: octovox::scene::instances::word_bytes(count as usize),
        turntable: turntable(quick)?,
        turns: super::bench_turns::bench_turns(quick, (width, height))?,
    };
    Ok((report(&row), serde_json::to_string_pretty(&[row])?))
}

/// A turntable of the showroom rendered whole and as 2 and 4 shards, one
/// process after another (on a cluster the shards run at once: the longest
/// is what it waits for).
fn turntable(quick: bool) -> anyhow::Result<TurntableRow> {
    let (frames, width, height, spp) = if quick { (8, 160, 90, 2) } else { (48, 320, 180, 4) };
    let exe = std::env::current_exe().context("where octovox is")?;
    let dir = tempfile::tempdir()?;
    let pattern = dir.path().join("spin_%02d.png");
    // A first run fills the driver's shader cache, which later runs find.
    let warm = render_shard(&exe, &pattern, (frames, width, height, spp), (0, frames))?;
    anyhow::ensure!(warm.success(), "render --turntable failed: {warm}");
    let mut shards = Vec::new();
    for n in [1u32, 2, 4] {
        let mut seconds = Vec::new();
        for k in 0..n {
            let start = Instant::now();
            let status = render_shard(&exe, &pattern, (frames, width, height, spp), (k, n))?;
            anyhow::ensure!(status.success(), "render --shard {k}/{n} failed: {status}");
            seconds.push(start.elapsed().as_secs_f64());
        }
        shards.push((n, seconds));
    }
    Ok(TurntableRow { frames, width, height, spp, shards })
}

fn render_shard(
    exe: &Path,
    pattern: &Path,
    (frames, width, height, spp): (u32, u32, u32, u32),
    (k, n): (u32, u32),
) -> anyhow::Result<std::process::ExitStatus> {
    let size = format!("{width}x{height}");
    let args = ["render", "--demo", "showroom", "--turntable", &frames.to_string(), "--size", &size];
    let shard = format!("{k}/{n}");
    let out = pattern.to_str().context("a temporary path in UTF-8")?;
    let extra = ["--spp", &spp.to_string(), "--shard", &shard, "--force", "-o", out];
    Ok(Command::new(exe).args(args).args(extra).output()?.status)
}

/// A table row of two times, their ratio and the ratio's target.
fn ratio_row(what: &str, a: f64, b: f64, target: f64) -> String {
    format!("| {what} | {a:.2} | {b:.2} | {:.2} | ≤ {target} |\n", a / b.max(1e-9))
}

fn report(r: &AnimRow) -> String {
    let mut md = header(&format!("Playing an animation of {} references", r.objects));
    md += &format!(
        "Adapter: **{}**, {}×{}, SVO preview without shadows. The forest of `bench scene` ({} references of one \
         tree, drawn as **{}**), each tree leaning 12° and turned about the up axis by its own free angle \
         (`_ov_turn`, traced exactly in its own frame), keyed to rise 1 to 8 voxels and turn 40° (slerp) and come \
         back over {} frames, looping. A playing frame is the window's (`Editor::play_frame`: every key sampled; \
         a scene drawn as instances composes its CPU octree, which picking and checks read, only once playing \
         stops), the upload and the preview; a still frame is the same forest without keys (standing as at frame \
         0), upload and preview, and a held frame the playing frame drawn again with nothing changed; \
         an axis-aligned frame is the forest by quarter turns only (the integer instance path), an upright one \
         the forest turned by the same free angles about the up axis but not leaning. Median of {} frames, the \
         four alternating after one warm-up each.\n\n",
        r.adapter, r.width, r.height, r.objects, r.drawn_as, MOVING_FRAMES, r.frames
    );
    md += "| measure | playing | still | playing / still | target |\n|---|---|---|---|---|\n";
    md += &ratio_row("frame ms", r.frame_ms_playing, r.frame_ms_still, 1.1);
    md += &ratio_row(
        "frame ms, against the same frame drawn again standing still",
        r.frame_ms_playing,
        r.frame_ms_held,
        1.1,
    );
    md += &ratio_row(
        "still: leaning free turns against axis-aligned, frame ms",
        r.frame_ms_still,
        r.frame_ms_aligned,
        1.3,
    );
    md += &ratio_row(
        "still: upright free turns against axis-aligned, frame ms",
        r.frame_ms_upright,
        r.frame_ms_aligned,
        1.3,
    );
    md += &format!("| of which showing the frame, ms | {:.2} | | | |\n", r.show_ms);
    md += &format!(
        "| composing the CPU octree once, after playing stops halfway (every tree moved), ms | {:.1} | | | |\n",
        r.catch_up_ms
    );
    md += &format!(
        "| bytes uploaded a frame (most) | {} | 0 | | the instance words: {} |\n\n",
        r.upload_bytes_per_frame, r.instance_bytes
    );
    let t = &r.turntable;
    md += &format!(
        "## A turntable as shards\n\n`render --demo showroom --turntable {} --size {}x{} --spp {} --shard K/N`, \
         each shard its own process (the renderer starts, the scene loads and the kernel compiles in each, after \
         one run that fills the driver's shader cache), one after another on this machine. On a cluster the shards run at once, so the longest is what the animation \
         waits for.\n\n| shards | seconds of each | longest | all together |\n|---|---|---|---|\n",
        t.frames, t.width, t.height, t.spp
    );
    for (n, seconds) in &t.shards {
        let each: Vec<String> = seconds.iter().map(|s| format!("{s:.2}")).collect();
        let longest = seconds.iter().copied().fold(0.0, f64::max);
        md += &format!("| {n} | {} | {longest:.2} | {:.2} |\n", each.join(", "), seconds.iter().sum::<f64>());
    }
    md + "\n" + &super::bench_turns::report(&r.turns)
}
