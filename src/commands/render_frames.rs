//! `octovox render --frames A..B`, `--turntable N`, `--shard K/N`: the
//! frames of an animation or of a camera orbit, as numbered PNG files or
//! one looping GIF, on one machine or spread over many.
//!
//! Every frame is made from the scene as loaded, walked at that frame and
//! composed afresh, with the path tracer's samples picked by the frame's
//! number: a frame is the same bytes whichever process renders it, so a
//! cluster's job array can split an animation into shards.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use glam::{DQuat, DVec3, IVec3};

use super::render::{Device, Shot, Stats, ground_height, open_scene, render_frame};
use crate::cli::{RenderArgs, camera_or_filling};
use octovox::camera::Camera;
use octovox::io::atomic::WriteOptions;
use octovox::io::output::{OutputKind, check_output};
use octovox::scene::Scene;
use octovox::scene::anim::DEFAULT_FPS;

/// Most frames one GIF holds (each is kept in memory until it is written).
const MAX_GIF_FRAMES: usize = 4096;

pub fn run(args: &RenderArgs) -> anyhow::Result<ExitCode> {
    let frames = frames_of(args)?;
    let ours = shard_of(&frames, args.shard);
    let output = Output::of(&args.output, frames.len(), args.shard.is_some())?;
    let inputs: Vec<&Path> = args.file.iter().map(|p| p.as_path()).collect();
    for &frame in &ours {
        output.check(frame, &inputs, args.force)?;
    }
    if ours.is_empty() {
        say!(
            "shard {}/{} has no frames of the {}",
            args.shard.map_or(0, |s| s.0),
            args.shard.map_or(1, |s| s.1),
            frames.len()
        )?;
        return Ok(ExitCode::SUCCESS);
    }
    // The scene stands at --frame for a turntable; an animation's camera and
    // ground are those of its first frame, whichever shard this is.
    let first = if args.turntable.is_some() { args.frame } else { frames[0] as usize };
    let mut scene = open_scene(args.file.as_deref(), first, args.demo)?;
    if args.turntable.is_none() && scene.objects().is_none() {
        anyhow::bail!("the scene is one model, which does not move: --turntable N orbits the camera around it");
    }
    let bounds = match args.turntable {
        Some(_) => scene.solid_bounds(),
        None => motion_bounds(&scene, &frames)?,
    };
    let camera = base_camera(args, &scene, bounds);
    let ground = ground_height(bounds, args);
    let mut device = Device::new(args)?;
    let bar = super::progress_bar::frames_bar(ours.len() as u64);
    let mut gif = Vec::new();
    for &frame in &ours {
        let start = Instant::now();
        let (camera, mut shown) = match args.turntable {
            Some(n) => (orbit(&camera, frame, n), None),
            None => (camera, Some(scene_at(&scene, frame)?)),
        };
        let scene = shown.as_mut().unwrap_or(&mut scene);
        let (image, stats) = render_frame(&mut device, scene, &camera, args, Shot { ground, number: frame })?;
        match &output {
            Output::Gif(_) => gif.push(image),
            Output::Files(pattern) => {
                let path = pattern.path(frame);
                octovox::io::png::save_png(&image, &path, WriteOptions::forced(args.force))?;
            }
        }
        if args.stats {
            let file = output.name(frame);
            let ms = start.elapsed().as_secs_f64() * 1e3;
            say!("{}", serde_json::to_string(&FrameStats { frame, file, ms, stats })?)?;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    match &output {
        Output::Gif(path) => {
            let fps = scene.objects().and_then(|o| o.graph.as_ref()).map_or(DEFAULT_FPS, |g| g.animation.fps());
            octovox::io::gif::save_gif(&gif, fps, path, WriteOptions::forced(args.force))?;
            if !args.stats {
                say!("wrote {} ({} frames, {fps} a second)", path.display(), gif.len())?;
            }
        }
        Output::Files(pattern) if !args.stats => {
            say!(
                "wrote {} frames: {} to {}",
                ours.len(),
                pattern.path(ours[0]).display(),
                pattern.path(ours[ours.len() - 1]).display()
            )?;
        }
        Output::Files(_) => {}
    }
    Ok(ExitCode::SUCCESS)
}

/// What `--stats` prints for each frame: its number and file, the
/// milliseconds it took (composing and rendering) and the render's stats.
#[derive(serde::Serialize)]
struct FrameStats {
    frame: u32,
    file: String,
    ms: f64,
    #[serde(flatten)]
    stats: Stats,
}

/// Every frame of the render, before sharding: `--frames A..B`, or the
/// turntable's 0..N-1 (of which `--frames` picks some).
fn frames_of(args: &RenderArgs) -> anyhow::Result<Vec<u32>> {
    match (args.turntable, args.frames) {
        (Some(n), None) => Ok((0..n).collect()),
        (Some(n), Some((a, b))) if b < n => Ok((a..=b).collect()),
        (Some(n), Some((a, b))) => anyhow::bail!("--frames {a}..{b}: a turntable of {n} has frames 0..{}", n - 1),
        (None, Some((a, b))) => {
            if args.frame != 0 {
                anyhow::bail!("--frame shows one frame and --frames renders several: give one of them");
            }
            let count = u64::from(b - a) + 1;
            octovox::budget::check(|| format!("a list of {count} frames"), count * 4)?;
            Ok((a..=b).collect())
        }
        (None, None) => anyhow::bail!("--shard splits the frames of --frames A..B or --turntable N: give one"),
    }
}

/// Shard `k` of `n`'s frames: the `k`-th of `n` runs of consecutive frames,
/// from `k·len/n` to `(k+1)·len/n` (rounded down): as even as they can be,
/// none more than one frame longer than another.
fn shard_of(frames: &[u32], shard: Option<(u32, u32)>) -> Vec<u32> {
    let Some((k, n)) = shard else { return frames.to_vec() };
    let (len, k, n) = (frames.len() as u64, u64::from(k), u64::from(n));
    let start = |k: u64| (k * len / n) as usize;
    frames[start(k)..start(k + 1)].to_vec()
}

/// Most frames whose boxes the camera of an animation is framed on: a
/// longer animation is sampled this many times, evenly.
const FRAMED_FRAMES: usize = 4096;

/// The world box every frame of the render shows voxels in (sampled
/// evenly where there are more than [`FRAMED_FRAMES`]): the camera and
/// the ground of an animation hold still and frame the whole motion.
fn motion_bounds(scene: &Scene, frames: &[u32]) -> anyhow::Result<Option<(IVec3, IVec3)>> {
    let objects = scene.objects().context("the scene has no objects")?;
    let step = frames.len().div_ceil(FRAMED_FRAMES).max(1);
    let mut bounds: Option<(IVec3, IVec3)> = None;
    for &frame in frames.iter().step_by(step).chain(frames.last()) {
        if let Some((lo, hi)) = objects.bounds_at(frame as usize).with_context(|| format!("frame {frame}"))? {
            bounds = Some(bounds.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))));
        }
    }
    Ok(bounds)
}

/// The camera of the render: `--camera`, else one that fills the frame
/// with `bounds` (an animation's whole motion), or whose view holds their
/// bounding sphere (a turntable, so that no angle crops the scene).
fn base_camera(args: &RenderArgs, scene: &Scene, bounds: Option<(IVec3, IVec3)>) -> Camera {
    let aspect = f64::from(args.size.0) / f64::from(args.size.1.max(1));
    let camera = match (args.camera, bounds, args.turntable) {
        (None, Some((lo, hi)), Some(_)) => Camera::framing(lo, hi, args.fov),
        (None, Some((lo, hi)), None) => {
            let corners: Vec<DVec3> = crate::cli::corners(lo, hi + IVec3::ONE).collect();
            Camera::filling(lo, hi, &corners, args.fov, aspect)
        }
        _ => camera_or_filling(args.camera, args.fov, scene, args.size),
    };
    Camera { ortho: args.ortho, ..camera }
}

/// Frame `k` of `n` of the turntable: the eye turned `k/n` of a full
/// circle counter-clockwise (seen from above) about the vertical through
/// the target.
fn orbit(camera: &Camera, k: u32, n: u32) -> Camera {
    let angle = std::f64::consts::TAU * f64::from(k) / f64::from(n);
    let turned = DQuat::from_axis_angle(DVec3::Y, angle) * (camera.eye - camera.target);
    Camera { eye: camera.target + turned, ..*camera }
}

/// The scene at `frame`, walked and composed afresh from the scene as
/// loaded (never from the frame before).
fn scene_at(loaded: &Scene, frame: u32) -> anyhow::Result<Scene> {
    let objects = loaded.objects().context("the scene has no objects")?;
    let walked = objects.at_frame(frame as usize).with_context(|| format!("frame {frame}"))?;
    Scene::compose(loaded.palette.clone(), walked).with_context(|| format!("frame {frame}"))
}

/// Where the frames go.
enum Output {
    /// One looping GIF of every frame.
    Gif(PathBuf),
    /// A PNG file a frame, named by the pattern.
    Files(Pattern),
}

impl Output {
    /// The output `path` names for `count` frames: a `.gif`, or PNG files
    /// by a pattern with one `%d` or `%0Nd` (a name without one holds one
    /// frame only).
    fn of(path: &Path, count: usize, sharded: bool) -> anyhow::Result<Output> {
        if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gif")) {
            if sharded {
                anyhow::bail!("a GIF holds every frame, so a shard cannot write one: render PNG frames per shard");
            }
            if count > MAX_GIF_FRAMES {
                anyhow::bail!("{count} frames: a GIF holds at most {MAX_GIF_FRAMES} here; render PNG frames");
            }
            return Ok(Output::Gif(path.to_path_buf()));
        }
        let pattern = Pattern::parse(path)?;
        if pattern.is_none() && count > 1 {
            anyhow::bail!(
                "{} names one file for {count} frames: put %04d (or %d) where the frame number goes, e.g. out/frame_%04d.png",
                path.display()
            );
        }
        Ok(Output::Files(pattern.unwrap_or_else(|| Pattern::single(path))))
    }

    /// Refuses a frame's file the way a render refuses its output, and a
    /// folder that is not there (before hours of rendering, not after).
    fn check(&self, frame: u32, inputs: &[&Path], force: bool) -> anyhow::Result<()> {
        let (path, kind) = match self {
            Output::Gif(path) => (path.clone(), OutputKind::Animation),
            Output::Files(pattern) => (pattern.path(frame), OutputKind::Image),
        };
        check_output(&path, kind, inputs, force)?;
        let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        if !folder.is_dir() {
            anyhow::bail!("cannot write {}: folder {} does not exist", path.display(), folder.display());
        }
        Ok(())
    }

    fn name(&self, frame: u32) -> String {
        match self {
            Output::Gif(path) => path.display().to_string(),
            Output::Files(pattern) => pattern.path(frame).display().to_string(),
        }
    }
}

/// A file name with the frame's number in it, printf-style: `%d`, or
/// `%0Nd` for at least N digits with leading zeros.
#[derive(Debug, PartialEq, Eq)]
struct Pattern {
    before: String,
    width: usize,
    after: String,
}

impl Pattern {
    /// The pattern in `path`; `None` when it has no `%`.
    fn parse(path: &Path) -> anyhow::Result<Option<Pattern>> {
        let text = path.to_str().with_context(|| format!("{} is not valid UTF-8", path.display()))?;
        let Some(at) = text.find('%') else { return Ok(None) };
        let rest = &text[at + 1..];
        let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
        let bad = || anyhow::anyhow!("{text}: the frame's number goes in as %d or %0Nd (such as %04d), once");
        if rest.as_bytes().get(digits) != Some(&b'd') || (digits > 0 && !rest.starts_with('0')) {
            return Err(bad());
        }
        let width = if digits == 0 { 0 } else { rest[..digits].parse::<usize>().map_err(|_| bad())? };
        let after = &rest[digits + 1..];
        if after.contains('%') || width > 10 {
            return Err(bad());
        }
        Ok(Some(Pattern { before: text[..at].to_owned(), width, after: after.to_owned() }))
    }

    /// A name for one frame, as it is.
    fn single(path: &Path) -> Pattern {
        Pattern { before: path.to_string_lossy().into_owned(), width: usize::MAX, after: String::new() }
    }

    fn path(&self, frame: u32) -> PathBuf {
        if self.width == usize::MAX {
            return PathBuf::from(&self.before);
        }
        PathBuf::from(format!("{}{frame:0width$}{}", self.before, self.after, width = self.width))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_name_frames_printf_style() {
        let p = |s: &str| Pattern::parse(Path::new(s));
        assert_eq!(p("out/walk_%04d.png").unwrap().unwrap().path(7), PathBuf::from("out/walk_0007.png"));
        assert_eq!(p("f%d.png").unwrap().unwrap().path(12345), PathBuf::from("f12345.png"));
        assert_eq!(p("a_%02d.png").unwrap().unwrap().path(123), PathBuf::from("a_123.png"));
        assert!(p("plain.png").unwrap().is_none());
        for bad in ["a%4d.png", "a%s.png", "a%d_%d.png", "a%.png", "a%011d.png"] {
            assert!(p(bad).is_err(), "{bad}");
        }
    }

    /// Shards cover every frame once, in order, as evenly as they can.
    #[test]
    fn shards_split_the_frames_into_runs() {
        let frames: Vec<u32> = (5..17).collect();
        let parts: Vec<Vec<u32>> = (0..4).map(|k| shard_of(&frames, Some((k, 4)))).collect();
        assert_eq!(parts, [vec![5, 6, 7], vec![8, 9, 10], vec![11, 12, 13], vec![14, 15, 16]]);
        let odd: Vec<usize> = (0..5).map(|k| shard_of(&frames, Some((k, 5))).len()).collect();
        assert_eq!(odd, [2, 2, 3, 2, 3]);
        // Two frames over four shards: two shards get none.
        let few: Vec<Vec<u32>> = (0..4).map(|k| shard_of(&frames[..2], Some((k, 4)))).collect();
        assert_eq!(few, [vec![], vec![5], vec![], vec![6]]);
        assert_eq!(shard_of(&frames, None), frames);
    }

    #[test]
    fn a_turntable_comes_back_where_it_started() {
        let camera = Camera { eye: DVec3::new(10.0, 5.0, 0.0), target: DVec3::new(0.0, 5.0, 0.0), ..Camera::default() };
        let quarter = orbit(&camera, 1, 4);
        assert!((quarter.eye - DVec3::new(0.0, 5.0, -10.0)).length() < 1e-9, "{:?}", quarter.eye);
        assert!((orbit(&camera, 4, 4).eye - camera.eye).length() < 1e-9);
    }
}
