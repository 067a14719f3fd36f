//! Crash recovery: the real window is killed with SIGKILL after a few
//! mouse edits; `octovox recover` then gives the document as it was after
//! the last of them (computed independently by replaying the same clicks
//! headless), and damaged or foreign journals are refused and left alone.
//!
//! Needs `Xvfb` and `xdotool`, like tests/window_e2e.rs.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

mod common;

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use common::window::*;
use glam::IVec3;

fn octovox(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_octovox")).args(args).output().unwrap()
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

#[test]
fn a_killed_window_loses_no_finished_edit() {
    let (dir, file, original, camera) = torus_document();
    // Three clicks on three different faces.
    let mut pixels: Vec<(u32, u32)> = Vec::new();
    let mut used: Vec<IVec3> = Vec::new();
    for _ in 0..3 {
        let (x, y, voxel, _) =
            stable_pixel(&original.tree, &camera, |v, _| !used.iter().any(|u| (*u - v).abs().max_element() < 3));
        used.push(voxel);
        pixels.push((x, y));
    }

    let (_xvfb, display) = start_xvfb(7);
    let args = document_args(&file, &camera, &[]);
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &args);
    let window = find_window(&display, &mut app, &stderr_path);
    lines.wait_for("octovox: ready", Duration::from_secs(90));
    let journal = octovox::journal::journal_path(&file);
    assert!(!journal.exists(), "no journal before the first edit");
    for &(x, y) in &pixels {
        click(&display, &window, &mut lines, x, y);
    }
    assert!(journal.is_file(), "unsaved edits have a journal beside the document");
    // A crash: no chance to clean up or save.
    app.0.kill().unwrap();
    app.0.wait().unwrap();
    assert_eq!(
        octovox::io::load_scene(&file, 0).unwrap().tree.voxels(),
        original.tree.voxels(),
        "the document is untouched"
    );

    // What the session held: the same clicks replayed headless.
    let expected_file = dir.path().join("expected.vox");
    let mut script = format!(
        "load {}\nviewport {WIDTH} {HEIGHT}\ncamera {} {} {} {} {} {}\n",
        s(&file),
        camera.eye.x,
        camera.eye.y,
        camera.eye.z,
        camera.target.x,
        camera.target.y,
        camera.target.z
    );
    for (x, y) in &pixels {
        script += &format!("click {x} {y} attach\n");
    }
    script += &format!("save {}\n", s(&expected_file));
    let script_path = dir.path().join("expected.ovr");
    std::fs::write(&script_path, script).unwrap();
    let run = octovox(&["replay", "--cpu", s(&script_path)]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stdout));

    let recovered = dir.path().join("recovered.vox");
    let run = octovox(&["recover", s(&file), "-o", s(&recovered)]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let voxels = |p: &Path| -> HashSet<(IVec3, u8)> {
        octovox::io::load_scene(p, 0).unwrap().tree.voxels().into_iter().collect()
    };
    assert_eq!(voxels(&recovered), voxels(&expected_file), "recover gives the session's voxels");
    assert_eq!(voxels(&recovered).len(), original.tree.voxels().len() + 3);
    assert!(journal.is_file(), "recover leaves the journal in place");

    // Opening the document again offers to recover; Recover applies it.
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &args);
    let window = find_window(&display, &mut app, &stderr_path);
    let asked = lines.wait_for("asking: recover", Duration::from_secs(90));
    assert!(asked.ends_with(&*journal.file_name().unwrap().to_string_lossy()), "{asked}");
    xdotool(&display, &["windowfocus", "--sync", &window]);
    // The modal's first button (Recover) has the keyboard focus after Tab.
    xdotool(&display, &["key", "Tab", "Return"]);
    lines.wait_for("recovered:", Duration::from_secs(30));
    // Escape takes the keyboard focus back from the panel for Ctrl+S.
    xdotool(&display, &["key", "Escape"]);
    std::thread::sleep(Duration::from_millis(500));
    save(&display, &mut lines, &file);
    assert_eq!(voxels(&file), voxels(&expected_file), "Recover then Save writes the session's voxels");
    assert!(!journal.exists(), "saving removes the journal");
}

#[test]
fn damaged_and_foreign_journals_are_refused_and_left_in_place() {
    let dir = tempfile::tempdir().unwrap();
    let source = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/vox/seed/torus16.vox");
    let file = dir.path().join("a.vox");
    let other = dir.path().join("b.vox");
    common::copy_writable(&source, &file);
    common::copy_writable(&source, &other);
    let out = dir.path().join("out.vox");
    let journal = octovox::journal::journal_path(&file);

    let message = String::from_utf8_lossy(&octovox(&["recover", s(&file), "-o", s(&out)]).stderr).into_owned();
    assert!(message.contains("has no journal"), "{message}");
    let cases = [
        ("place 1 2\n".to_string(), "journal"),
        (format!("load {}\nplace 0 40 0\n", s(&other)), "belongs to"),
        (format!("load {}\nundo\n", s(&file)), "nothing was applied"),
    ];
    for (text, expected) in cases {
        std::fs::write(&journal, &text).unwrap();
        let run = octovox(&["recover", s(&file), "-o", s(&out)]);
        let message = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success() && message.contains(expected), "{text}: {message}");
        assert_eq!(std::fs::read_to_string(&journal).unwrap(), text, "the journal is left as it was");
        assert!(!out.exists(), "nothing is written from a bad journal");
    }
}

/// An untitled scene is journaled in saves/ under the session's process
/// id; after a SIGKILL, `octovox recover JOURNAL` gives its voxels, and the
/// next window started without a file offers it back.
#[test]
fn an_untitled_scene_is_recovered_after_a_kill() {
    require_window_tools();
    let dir = tempfile::tempdir().unwrap();
    let edits = [IVec3::new(0, 100, 0), IVec3::new(1, 100, 0), IVec3::new(2, 101, 0)];
    let script: String = std::iter::once("color 5\n".to_string())
        .chain(edits.iter().map(|p| format!("place {} {} {}\n", p.x, p.y, p.z)))
        .collect();
    std::fs::write(dir.path().join("edits.ovr"), script).unwrap();
    let demo = octovox::scene::demo::BuiltIn::Terrain.scene();
    let mut expected: HashSet<(IVec3, u8)> = demo.tree.voxels().into_iter().collect();
    expected.extend(edits.iter().map(|p| (*p, 5)));

    let (_xvfb, display) = start_xvfb(11);
    let args = ["--size".to_string(), "640x480".into(), "--replay".into(), "edits.ovr".into()];
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &args);
    find_window(&display, &mut app, &stderr_path);
    lines.wait_for("replay:", Duration::from_secs(90));
    let journal = octovox::journal::untitled_journal_path(&dir.path().join("saves"), app.0.id());
    assert!(journal.is_file(), "the untitled scene's edits are journaled in saves/");
    app.0.kill().unwrap();
    app.0.wait().unwrap();

    let recovered = dir.path().join("recovered.vox");
    let run = octovox(&["recover", s(&journal), "-o", s(&recovered)]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let voxels = |p: &Path| -> HashSet<(IVec3, u8)> {
        octovox::io::load_scene(p, 0).unwrap().tree.voxels().into_iter().collect()
    };
    assert_eq!(voxels(&recovered), expected, "the demo plus the three edits");

    // A window started without a file offers the orphaned journal.
    let args = ["--size".to_string(), "640x480".into()];
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &args);
    let window = find_window(&display, &mut app, &stderr_path);
    let asked = lines.wait_for("asking: recover", Duration::from_secs(90));
    assert!(asked.ends_with(&*journal.file_name().unwrap().to_string_lossy()), "{asked}");
    lines.wait_for("octovox: ready", Duration::from_secs(90));
    xdotool(&display, &["windowfocus", "--sync", &window]);
    xdotool(&display, &["key", "Tab", "Return"]);
    assert_eq!(lines.wait_for("recovered:", Duration::from_secs(30)), "recovered: the untitled scene");
    assert!(!journal.exists(), "this session took the journal over");
    assert!(octovox::journal::untitled_journal_path(&dir.path().join("saves"), app.0.id()).is_file());
    xdotool(&display, &["key", "Escape"]);
    std::thread::sleep(Duration::from_millis(500));
    // Save asks for a path (the path field: no native dialogs in tests).
    xdotool(&display, &["key", "ctrl+s"]);
    std::thread::sleep(Duration::from_millis(700));
    xdotool(&display, &["key", "ctrl+a"]);
    xdotool(&display, &["type", "kept.vox"]);
    xdotool(&display, &["key", "Return"]);
    lines.wait_for("saved:", Duration::from_secs(30));
    assert_eq!(voxels(&dir.path().join("kept.vox")), expected, "Recover then Save keeps the session's voxels");
    let left = std::fs::read_dir(dir.path().join("saves")).unwrap().count();
    assert_eq!(left, 0, "saving removed the untitled journal");
}

/// Changes a journal cannot hold as lines still survive a kill: an undo
/// of a step saved before the journal started, a selection made while the
/// document was clean, a paste of a block copied before the journal
/// started. The window plays the script (its lines go the mouse's way,
/// saves included), is killed, and `recover` must equal the same script
/// run headless.
#[test]
fn undo_past_a_save_selections_and_old_clipboards_survive_a_kill() {
    require_window_tools();
    let script = "color 7\nplace 3 1 3\nsave doc.vox\n\
                  select 0 0 0 3 1 3\ncopy\ncut\npaste 8 0 8\nundo\npaste 9 0 9\n\
                  save doc.vox\nundo\nplace 5 2 5\n\
                  save doc.vox\npaste 12 0 12\nplace 6 3 6\n";
    let (window_dir, headless_dir) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    for dir in [window_dir.path(), headless_dir.path()] {
        let mut scene = octovox::scene::Scene::default();
        let floor = octovox::scene::Shape::Box { min: IVec3::ZERO, max: IVec3::new(15, 0, 15) };
        scene.tree.apply_brush(&floor, octovox::scene::Op::Place(20)).unwrap();
        octovox::io::save_scene(&dir.join("doc.vox"), &scene, Default::default()).unwrap();
    }
    std::fs::write(window_dir.path().join("play.ovr"), script).unwrap();
    std::fs::write(headless_dir.path().join("play.ovr"), format!("load doc.vox\n{script}save expected.vox\n")).unwrap();
    let run = octovox(&["replay", "--cpu", "--force", s(&headless_dir.path().join("play.ovr"))]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stdout));

    let (_xvfb, display) = start_xvfb(12);
    let args = ["doc.vox".to_string(), "--size".into(), "640x480".into(), "--replay".into(), "play.ovr".into()];
    let (mut app, mut lines, stderr_path) = spawn_app(&display, window_dir.path(), &args);
    find_window(&display, &mut app, &stderr_path);
    assert_eq!(lines.wait_for("replay:", Duration::from_secs(90)), "replay: 0 passed, 0 failed");
    app.0.kill().unwrap();
    app.0.wait().unwrap();

    let (doc, recovered) = (window_dir.path().join("doc.vox"), window_dir.path().join("recovered.vox"));
    let run = octovox(&["recover", s(&doc), "-o", s(&recovered)]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let voxels = |p: &Path| -> HashSet<(IVec3, u8)> {
        octovox::io::load_scene(p, 0).unwrap().tree.voxels().into_iter().collect()
    };
    assert_eq!(voxels(&recovered), voxels(&headless_dir.path().join("expected.vox")));
}
