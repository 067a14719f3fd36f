//! `render --frames`, `--turntable`, `--shard` and GIFs on the GPU (issue
//! 49, item 6): frames that show the motion, a shard that writes the same
//! bytes as a whole run, a GIF that loops with every frame, one `--stats`
//! line a frame, a bar with the time left on a terminal, and clear
//! refusals of what cannot be rendered.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use image::AnimationDecoder;

fn animation() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/vox/anim/animation.vox")
}

fn octovox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_octovox")).args(args).output().unwrap()
}

fn ok(out: &Output) -> String {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The pixels that are not the sky or the ground: where the model is.
fn model_pixels(image: &image::RgbaImage) -> Vec<(u32, u32)> {
    let sky_or_ground = |p: &image::Rgba<u8>| {
        let [r, _, b, _] = p.0;
        // The model is blue (animation.vox's colour), the ground grey and the sky bluish grey.
        !(i32::from(b) - i32::from(r) > 40 && b > 120)
    };
    image.enumerate_pixels().filter(|(_, _, p)| !sky_or_ground(p)).map(|(x, y, _)| (x, y)).collect()
}

#[test]
fn frames_show_the_motion_and_a_shard_writes_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let all = dir.path().join("all_%03d.png");
    let input = animation();
    let common = ["render", path(&input), "--frames", "0..30", "--size", "96x64"];
    let said = ok(&octovox(&[&common[..], &["-o", path(&all), "--stats"]].concat()));
    let lines: Vec<serde_json::Value> = said.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 31, "one --stats line a frame");
    assert_eq!(lines[7]["frame"], 7);
    assert!(lines[7]["file"].as_str().unwrap().ends_with("all_007.png"));
    let frame = |k: u32| image::open(dir.path().join(format!("all_{k:03}.png"))).unwrap().to_rgba8();
    // The object is in every frame (the camera frames the whole motion),
    // and where it is changes: its pixels' centre moves.
    let centre = |k: u32| {
        let pixels = model_pixels(&frame(k));
        assert!(pixels.len() > 50, "frame {k}: {} model pixels", pixels.len());
        let n = pixels.len() as f64;
        (pixels.iter().map(|p| f64::from(p.0)).sum::<f64>() / n, pixels.iter().map(|p| f64::from(p.1)).sum::<f64>() / n)
    };
    let (a, b, c) = (centre(0), centre(9), centre(30));
    assert!((a.0 - b.0).abs() + (a.1 - b.1).abs() > 5.0, "frames 0 and 9: {a:?} {b:?}");
    assert!((b.0 - c.0).abs() + (b.1 - c.1).abs() > 5.0, "frames 9 and 30: {b:?} {c:?}");
    // Shard 2 of 3 (frames 20..30: 31 frames split 10, 10, 11) writes the bytes the whole run wrote.
    let shard = dir.path().join("shard_%03d.png");
    ok(&octovox(&[&common[..], &["-o", path(&shard), "--shard", "2/3"]].concat()));
    for k in 0..=30u32 {
        let name = dir.path().join(format!("shard_{k:03}.png"));
        assert_eq!(name.exists(), k >= 20, "frame {k}");
        if k >= 20 {
            assert!(
                std::fs::read(&name).unwrap() == std::fs::read(dir.path().join(format!("all_{k:03}.png"))).unwrap()
            );
        }
    }
}

#[test]
fn a_gif_holds_every_frame_and_loops() {
    let dir = tempfile::tempdir().unwrap();
    let gif = dir.path().join("walk.gif");
    let pngs = dir.path().join("walk_%d.png");
    let input = animation();
    let common = ["render", path(&input), "--frames", "4..11", "--size", "64x48"];
    let said = ok(&octovox(&[&common[..], &["-o", path(&gif)]].concat()));
    assert!(said.contains("8 frames, 12 a second"), "{said}");
    ok(&octovox(&[&common[..], &["-o", path(&pngs)]].concat()));
    let bytes = std::fs::read(&gif).unwrap();
    // NETSCAPE2.0: the loop extension (0 = for ever).
    assert!(bytes.windows(11).any(|w| w == b"NETSCAPE2.0"), "a looping GIF");
    let decoder = image::codecs::gif::GifDecoder::new(std::io::Cursor::new(bytes)).unwrap();
    let frames = decoder.into_frames().collect_frames().unwrap();
    assert_eq!(frames.len(), 8);
    for (k, frame) in frames.iter().enumerate() {
        // 12 a second is 83 ms; a GIF counts hundredths of a second.
        assert_eq!(frame.delay().numer_denom_ms(), (80, 1));
        let png = image::open(dir.path().join(format!("walk_{}.png", k + 4))).unwrap().to_rgba8();
        let gif = frame.buffer();
        let diff: f64 = png
            .pixels()
            .zip(gif.pixels())
            .map(|(a, b)| (0..3).map(|c| f64::from(a[c].abs_diff(b[c]))).sum::<f64>())
            .sum();
        let mean = diff / (3.0 * f64::from(png.width() * png.height()));
        assert!(mean < 4.0, "frame {k}: the GIF's colours differ by {mean:.2} on average from the PNG's");
    }
}

#[test]
fn a_turntable_orbits_a_still_scene() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t%d.png");
    ok(&octovox(&["render", "--demo", "showroom", "--turntable", "4", "--size", "64x48", "-o", path(&out)]));
    let images: Vec<Vec<u8>> = (0..4).map(|k| std::fs::read(dir.path().join(format!("t{k}.png"))).unwrap()).collect();
    assert!(images.iter().enumerate().all(|(k, a)| images[k + 1..].iter().all(|b| a != b)), "four views");
    // Frames 1..2 of the same turntable are the same views.
    let part = dir.path().join("p%d.png");
    let args = ["render", "--demo", "showroom", "--turntable", "4", "--frames", "1..2", "--size", "64x48", "-o"];
    ok(&octovox(&[&args[..], &[path(&part)]].concat()));
    assert_eq!(std::fs::read(dir.path().join("p2.png")).unwrap(), images[2]);
}

/// Bad requests are refused before anything is rendered, with a reason.
#[test]
fn impossible_requests_are_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let input = animation();
    let one = dir.path().join("one.png");
    let many = dir.path().join("f%04d.png");
    let gif = dir.path().join("a.gif");
    let missing = dir.path().join("nowhere/f%d.png");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--frames", "5..2", "-o", path(&many)], "the first frame 5 is after the last 2"),
        (vec!["--frames", "0..3", "--shard", "4/4", "-o", path(&many)], "numbered 0 to 3"),
        (vec!["--frames", "0..3", "--shard", "0/0", "-o", path(&many)], "at least 1"),
        (vec!["--frames", "0..3", "-o", path(&one)], "names one file for 4 frames"),
        (vec!["--frames", "0..3", "--shard", "0/2", "-o", path(&gif)], "a shard cannot write one"),
        (vec!["--frames", "0..3", "-o", "f%s.png"], "%d or %0Nd"),
        (vec!["--frames", "0..3", "-o", path(&missing)], "does not exist"),
        (vec!["--shard", "0/2", "-o", path(&many)], "--frames A..B or --turntable N"),
        (vec!["--turntable", "8", "--frames", "3..9", "-o", path(&many)], "frames 0..7"),
        (vec!["--frames", "0..4294967296", "-o", path(&many)], "not a frame number"),
    ];
    for (args, why) in cases {
        let out = octovox(&[&["render", path(&input)][..], &args].concat());
        let said = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(said.contains(why), "{args:?}: {said}");
        assert!(!said.contains("panicked"), "{args:?}: {said}");
    }
    let plain = octovox(&["render", "--demo", "showroom", "--frames", "0..3", "-o", path(&many)]);
    assert!(String::from_utf8_lossy(&plain.stderr).contains("--turntable N orbits the camera"));
    assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none(), "nothing written");
}

/// On a terminal a render of frames shows how many are done and the time left.
#[test]
fn a_render_of_frames_shows_frames_and_time_left_on_a_terminal() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f%d.png");
    let input = animation();
    let command = format!(
        "{} render {} --frames 0..5 --size 64x48 -o {}",
        env!("CARGO_BIN_EXE_octovox"),
        input.display(),
        out.display()
    );
    let tty = Command::new("script").args(["-qec", &command, "/dev/null"]).output().unwrap();
    let said = String::from_utf8_lossy(&tty.stdout);
    assert!(tty.status.success(), "{said}");
    assert!(said.contains("frames, ") && said.contains(" left"), "{said}");
}

/// Frames played in a scene drawn as instances send only instance words
/// (the CPU's octree catches up later), and the GPU draws each exactly as
/// the scene loaded at that frame: the preview compared pixel for pixel.
#[test]
fn played_frames_draw_as_the_frame_loaded_afresh() {
    use octovox::camera::Camera;
    use octovox::gpu::Renderer;
    use octovox::settings::RenderSettings;
    let mut bytes = Vec::new();
    crate::common::written::herd(200).write_vox(&mut bytes).unwrap();
    let mut editor = octovox::editor::Editor::default();
    editor.set_scene(octovox::io::vox::load_vox_scene(&bytes, 0).unwrap().0);
    assert!(editor.scene.instanced().is_some());
    let (lo, hi) = editor.scene.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi + glam::IVec3::new(12, 0, 0), 50.0);
    let settings = RenderSettings::default();
    let size = (160, 120);
    let mut renderer = Renderer::headless().unwrap();
    renderer.sync(&mut editor.scene);
    for frame in [3u32, 8, 14] {
        editor.play_frame(frame).unwrap();
        let written = renderer.sync(&mut editor.scene).bytes;
        let words = octovox::scene::instances::word_bytes(200);
        assert!(written > 0 && written < words, "frame {frame}: {written} bytes written, the words are {words}");
        renderer.render(&editor.scene, &camera, size, &settings, None).unwrap();
        let played = renderer.read_image().unwrap();
        let mut fresh = octovox::io::vox::load_vox_scene(&bytes, frame as usize).unwrap().0;
        let mut other = Renderer::headless().unwrap();
        other.sync(&mut fresh);
        other.render(&fresh, &camera, size, &settings, None).unwrap();
        let loaded = other.read_image().unwrap();
        let differing = played.pixels().zip(loaded.pixels()).filter(|(a, b)| a != b).count();
        assert_eq!(differing, 0, "frame {frame}: {differing} pixels differ");
        assert_ne!(model_pixels_any(&played), 0, "frame {frame}: the herd shows");
    }
}

/// Pixels that are neither sky nor ground grey: the herd's colours.
fn model_pixels_any(image: &image::RgbaImage) -> usize {
    image.pixels().filter(|p| p[0].abs_diff(p[1]) > 30 || p[1].abs_diff(p[2]) > 30 && p[0] > p[2]).count()
}

/// A free turn (issue 49) is traced exactly in the turned object's frame:
/// the renderer that drew the herd draws it, one object turned by 30°, as
/// the CPU reference and a renderer given the saved and reloaded scene
/// afresh do, and as before after the undo, pixel for pixel.
#[test]
fn a_free_turn_draws_as_the_cpu_and_the_reloaded_file_and_undoes() {
    use octovox::camera::Camera;
    use octovox::gpu::Renderer;
    use octovox::settings::RenderSettings;
    let mut bytes = Vec::new();
    crate::common::written::herd(200).write_vox(&mut bytes).unwrap();
    let mut editor = octovox::editor::Editor::default();
    editor.set_scene(octovox::io::vox::load_vox_scene(&bytes, 0).unwrap().0);
    let (lo, hi) = editor.scene.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi + glam::IVec3::new(12, 0, 0), 50.0);
    let (settings, size) = (RenderSettings::default(), (160, 120));
    let mut renderer = Renderer::headless().unwrap();
    let draw = |scene: &mut octovox::scene::Scene, renderer: &mut Renderer| {
        renderer.sync(scene);
        renderer.render(scene, &camera, size, &settings, None).unwrap();
        renderer.read_image().unwrap()
    };
    let before = draw(&mut editor.scene, &mut renderer);
    let run = |editor: &mut octovox::editor::Editor, text: &str| {
        for line in octovox::script::parse_script(Path::new("t.ovr"), text).unwrap().lines {
            editor.run(&line.command).unwrap();
        }
    };
    run(&mut editor, "object 7\nobject turn y 30");
    assert!(editor.scene.instanced().is_some_and(|o| o.has_free_turns()), "traced as turned instances");
    let turned = draw(&mut editor.scene, &mut renderer);
    let cpu = octovox::trace::render::render_scene_cpu(&editor.scene, None, &camera, size, &settings);
    let saved = octovox::io::vox::encode_objects(&editor.scene.palette, editor.scene.objects().unwrap()).unwrap();
    let mut fresh = octovox::io::vox::load_vox_scene(&saved, 0).unwrap().0;
    let afresh = draw(&mut fresh, &mut Renderer::headless().unwrap());
    let differing =
        |a: &image::RgbaImage, b: &image::RgbaImage| a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
    assert_ne!(differing(&before, &turned), 0, "the turn shows");
    assert_eq!(differing(&turned, &cpu), 0, "as the CPU reference draws");
    assert_eq!(differing(&turned, &afresh), 0, "as the reloaded file draws");
    run(&mut editor, "undo 1");
    assert!(editor.scene.instanced().is_some_and(|o| !o.has_free_turns()), "no turn again");
    assert_eq!(differing(&before, &draw(&mut editor.scene, &mut renderer)), 0, "undone");
}
