//! A session recorded in the real window (`--record`) replays headless
//! (`octovox replay`) to the same voxels; and `--replay` plays a script in
//! the window through the same edit path.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use crate::common;

use std::process::Command;
use std::time::Duration;

use common::window::*;

fn wait_exit(app: &mut KillOnDrop) {
    let status = wait_for_exit(app, Duration::from_secs(30), "quit");
    assert!(status.success(), "octovox exited with {status}");
}

/// Issue 46: a drag is one undo step in the window, and its recording
/// wrote one line per edit with nothing grouping them, so `undo 1` after a
/// replayed recording took one voxel of the stroke away, not the stroke.
/// A stroke along the torus' top and a click are recorded with the real
/// mouse; the recording, with two `undo 1` lines after it, replays to the
/// original voxel count (and, after the first, to the count after the
/// stroke).
#[test]
fn a_recorded_stroke_replays_into_one_undo_step() {
    let (dir, file, original, camera) = torus_document();
    let hi = original.solid_bounds().unwrap().1;
    let (x, y, top, _) = stable_pixel(original.drawn(), &camera, |v, n| n == glam::IVec3::Y && v.y == hi.y);
    let mut stroked = original.drawn().clone();
    stroked.apply_brush(&octovox::scene::Shape::Voxel(top + glam::IVec3::Y), octovox::scene::Op::Place(1)).unwrap();
    let (ex, ey) = same_layer_pixel(&stroked, &camera, (x, y), top, glam::IVec3::Y);
    let (cx, cy, _, _) = stable_pixel(original.drawn(), &camera, |v, n| n == glam::IVec3::Z && v.y < hi.y - 4);

    let untouched = std::fs::read(&file).unwrap();
    let (_xvfb, display) = start_xvfb();
    let script = dir.path().join("stroke.ovr");
    let args = document_args(&file, &camera, &["--record", &script.display().to_string()]);
    let (mut app, mut lines, window) = open_ready(&display, dir.path(), &args);
    xdotool(&display, &["key", "t"]);
    drag(&display, &window, (x, y), (ex, ey));
    click(&display, &window, &mut lines, cx, cy);
    save(&display, &mut lines, &file);
    xdotool(&display, &["key", "ctrl+q"]);
    wait_exit(&mut app);

    let saved = octovox::io::load_scene(&file, 0).unwrap().solid_voxels();
    let stroke = saved - 1 - original.solid_voxels();
    assert!(stroke >= 2, "the drag placed {stroke} voxels");
    // The recording loads the document as it was before the session.
    std::fs::write(&file, &untouched).unwrap();
    let recorded = std::fs::read_to_string(&script).unwrap();
    eprintln!("recorded:\n{recorded}");
    let checks = format!(
        "expect count {saved}\nundo 1\nexpect count {}\nundo 1\nexpect count {}\n",
        saved - 1,
        original.solid_voxels()
    );
    std::fs::write(&script, format!("{recorded}{checks}")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_octovox")).args(["replay", "--cpu"]).arg(&script).output().unwrap();
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{report}{}", String::from_utf8_lossy(&out.stderr));
    assert!(report.contains("replay: 3 passed, 0 failed"), "{report}");
}

#[test]
fn recorded_window_session_replays_to_the_same_voxels() {
    let (dir, file, original, camera) = torus_document();
    let (x, y, _, _) = stable_pixel(original.drawn(), &camera, |_, _| true);

    let (_xvfb, display) = start_xvfb();
    let script = dir.path().join("session.ovr");
    let args = document_args(&file, &camera, &["--record", &script.display().to_string()]);
    let (mut app, mut lines, window) = open_ready(&display, dir.path(), &args);

    // Attach twice on the same spot (the second lands on the first), paint,
    // undo the paint, then save and quit.
    click(&display, &window, &mut lines, x, y);
    click(&display, &window, &mut lines, x, y);
    xdotool(&display, &["key", "g"]);
    click(&display, &window, &mut lines, x + 1, y);
    xdotool(&display, &["key", "ctrl+z"]);
    lines.wait_for("undo:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    xdotool(&display, &["key", "ctrl+q"]);
    wait_exit(&mut app);

    // Replay the recording headless and save what it built.
    let recorded = std::fs::read_to_string(&script).unwrap();
    eprintln!("recorded:\n{recorded}");
    assert!(recorded.lines().filter(|l| l.starts_with("place ")).count() == 2, "{recorded}");
    assert!(recorded.contains("\npaint ") && recorded.contains("\nundo 1"), "{recorded}");
    let replayed = dir.path().join("replayed.vox");
    std::fs::write(&script, format!("{recorded}save {}\n", replayed.display())).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_octovox")).args(["replay", "--cpu"]).arg(&script).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stdout));

    let window_scene = octovox::io::load_scene(&file, 0).unwrap();
    let replay_scene = octovox::io::load_scene(&replayed, 0).unwrap();
    assert_eq!(window_scene.solid_voxels(), original.solid_voxels() + 2);
    assert_eq!(window_scene.voxels(), replay_scene.voxels(), "replay differs from the window session");
}

#[test]
fn window_plays_a_script_through_the_edit_path() {
    require_tool("Xvfb");
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("play.ovr");
    std::fs::write(
        &script,
        "new\ncamera 20 15 25 0 0 0 50\ncolor 9\nbrush box 3 3 3\nplace 0 0 0\nexpect count 27\n\
         brush sphere 1\nremove 1 1 1\nexpect voxel 1 1 1 0\nexpect written <= 1024\nundo\nexpect count 27\n\
         expect voxel 0 0 0 9\nmaterial 9 metal _rough 0.2 _metal 1\nexpect effects sun sky metal\n\
         rgb 9 200 100 50\nmaterial 9 emit _emit 1\nundo\nexpect effects sun sky metal\nsave out.vox\n",
    )
    .unwrap();
    let (_xvfb, display) = start_xvfb();
    let recording = dir.path().join("rec.ovr");
    let args = [
        "--size".to_string(),
        "640x480".into(),
        "--replay".into(),
        script.display().to_string(),
        "--record".into(),
        recording.display().to_string(),
    ];
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &args);
    find_window(&display, &mut app, &stderr_path);
    let summary = lines.wait_for("replay:", Duration::from_secs(120));
    assert_eq!(summary, "replay: 7 passed, 0 failed", "{:?}", lines.seen);
    // The played lines went through the same path as the mouse, so the
    // recording (flushed per line) replays to the same scene.
    let mut recorded = std::fs::read_to_string(&recording).unwrap();
    recorded.push_str("save replayed.vox\n");
    std::fs::write(&recording, recorded).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_octovox"))
        .args(["replay", "--cpu", recording.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stdout));
    let replayed = octovox::io::load_scene(&dir.path().join("replayed.vox"), 0).unwrap();
    let saved = octovox::io::load_scene(&dir.path().join("out.vox"), 0).unwrap();
    assert_eq!(saved.solid_voxels(), 27);
    // Palette edits went through the window's edit path, undo included.
    assert_eq!(saved.palette.color(9), [200, 100, 50, 255]);
    assert_eq!(saved.palette.material(9).kind, octovox::scene::MaterialKind::Metal);
    assert_eq!(saved.palette.material(9).roughness(), 0.2);
    assert_eq!(replayed.voxels(), saved.voxels(), "the recording replays to the same voxels");
    assert_eq!(
        (replayed.palette.color(9), replayed.palette.material(9)),
        (saved.palette.color(9), saved.palette.material(9))
    );
}

/// One interpreter: a played script's `render` makes the image `octovox
/// replay` makes, so `expect image` is checked in the window (it was
/// skipped there), and `expect written` needs an edit in both hosts.
#[test]
fn a_played_script_renders_and_checks_images_as_octovox_replay_does() {
    require_tool("Xvfb");
    let dir = tempfile::tempdir().unwrap();
    let scene = "demo showroom\ncamera 30 22 34 8 4 8 50\nviewport 160 120\n";
    // The reference, headless on the GPU (lavapipe here).
    std::fs::write(dir.path().join("reference.ovr"), format!("{scene}render reference.png\n")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_octovox"))
        .arg("replay")
        .arg(dir.path().join("reference.ovr"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stdout));
    let reference = image::open(dir.path().join("reference.png")).unwrap().to_rgb8();
    assert_eq!(reference.dimensions(), (160, 120));
    let lit = reference.pixels().filter(|p| p.0.iter().any(|c| *c > 40)).count();
    assert!(lit > 160 * 120 / 4, "the reference is a real picture ({lit} lit pixels)");

    let script = dir.path().join("play.ovr");
    std::fs::write(
        &script,
        format!(
            "{scene}expect written <= 0\nrender window.png\nexpect image reference.png 0.002\nexpect effects none\n"
        ),
    )
    .unwrap();
    let (_xvfb, display) = start_xvfb();
    let args = ["--size".to_string(), "640x480".into(), "--replay".into(), script.display().to_string()];
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &args);
    find_window(&display, &mut app, &stderr_path);
    let summary = lines.wait_for("replay:", Duration::from_secs(120));
    // `expect written` before any edit is an error that stops the script
    // in both hosts; so the window runs the rest in a second script.
    assert_eq!(summary, "replay: 0 passed, 1 failed", "{:?}", lines.seen);
    drop(app);

    std::fs::write(&script, format!("{scene}render window.png\nexpect image reference.png 0.002\n")).unwrap();
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &args);
    find_window(&display, &mut app, &stderr_path);
    let summary = lines.wait_for("replay:", Duration::from_secs(120));
    assert_eq!(summary, "replay: 1 passed, 0 failed", "{:?}", lines.seen);
    let window = image::open(dir.path().join("window.png")).unwrap().to_rgb8();
    assert_eq!(window.dimensions(), (160, 120), "the script's viewport, not the window's size");
    drop(app);

    // The rule of every command that writes: `render` makes a .png and
    // never writes over a document (the window wrote its PNG bytes there).
    let document = dir.path().join("keep.vox");
    std::fs::write(&document, b"not an image").unwrap();
    std::fs::write(&script, format!("{scene}render keep.vox\n")).unwrap();
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &args);
    find_window(&display, &mut app, &stderr_path);
    let summary = lines.wait_for("replay:", Duration::from_secs(120));
    assert_eq!(summary, "replay: 0 passed, 1 failed", "{:?}", lines.seen);
    assert_eq!(std::fs::read(&document).unwrap(), b"not an image");
}
