//! A scene of objects in the real window: a click on an object picks it
//! and its edit lands in that object's model (read back from the saved
//! file with `dot_vox`, not octovox's loader); one Ctrl+Z takes it back.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use crate::common;

use std::time::Duration;

use common::window::*;
use octovox::camera::Camera;

/// Voxels of each model as `dot_vox` reads the saved file.
fn model_sizes(file: &std::path::Path) -> Vec<usize> {
    let data = dot_vox::load_bytes(&std::fs::read(file).unwrap()).unwrap();
    data.models.iter().map(|m| m.voxels.len()).collect()
}

/// A writable copy of `test_groups.vox` in a new folder, and the scene it holds.
fn groups_document() -> (tempfile::TempDir, std::path::PathBuf, octovox::scene::Scene) {
    require_window_tools();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("groups.vox");
    common::copy_writable(&common::assets().join("vox/format/test_groups.vox"), &file);
    let scene = octovox::io::load_scene(&file, 0).unwrap();
    (dir, file, scene)
}

#[test]
fn a_click_picks_the_object_it_hits_and_edits_its_model() {
    let (dir, file, scene) = groups_document();
    let objects = scene.objects().expect("test_groups.vox is a scene of objects");
    let (lo, hi) = scene.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    // A pixel on a face of an object that is not the last one (so that
    // the pick is not the default target by chance).
    let last = objects.list().len() - 1;
    let (x, y, voxel, _) = stable_pixel(scene.drawn(), &camera, |v, _| objects.owner_at(v).is_some_and(|o| o != last));
    let owner = objects.owner_at(voxel).unwrap();
    let model = objects.list()[owner].placement.model;
    let before = model_sizes(&file);

    let (_xvfb, display) = start_xvfb(21);
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &document_args(&file, &camera, &[]));
    let window = find_window(&display, &mut app, &stderr_path);
    lines.wait_for("octovox: ready", Duration::from_secs(90));
    xdotool(&display, &["windowfocus", "--sync", &window]);
    click(&display, &window, &mut lines, x, y);
    assert!(lines.seen.iter().any(|l| *l == format!("ran: object {owner}")), "{:?}", lines.seen);
    save(&display, &mut lines, &file);
    let after = model_sizes(&file);
    let mut expected = before.clone();
    expected[model] += 1;
    assert_eq!(after, expected, "the voxel went into model {model} of object {owner}, and only there");

    xdotool(&display, &["key", "ctrl+z"]);
    lines.wait_for("undo:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    assert_eq!(model_sizes(&file), before, "one Ctrl+Z takes it back");
}

/// Ctrl+H hides the object a click picked: its pixels change on screen, the
/// saved file keeps it (hidden, its model whole); Ctrl+Z shows it again.
#[test]
fn ctrl_h_hides_the_picked_object_and_the_file_keeps_it() {
    use octovox::trace::{Ray, svo};
    let (dir, file, scene) = groups_document();
    let objects = scene.objects().unwrap();
    let (lo, hi) = scene.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    let (x, y, voxel, _) = stable_pixel(scene.drawn(), &camera, |v, _| objects.owner_at(v).is_some());
    let owner = objects.owner_at(voxel).unwrap();
    // The pixels that show the object, by the CPU tracer.
    let basis = camera.basis(WIDTH, HEIGHT, scene.origin());
    let shows: Vec<(u32, u32)> = (FREE_Y..HEIGHT)
        .step_by(2)
        .flat_map(|py| (FREE_X..WIDTH).step_by(2).map(move |px| (px, py)))
        .filter(|&(px, py)| {
            let (o, d) = basis.ray(px, py);
            let hit = svo::trace(scene.drawn(), &Ray::new(o, d));
            hit.is_hit() && objects.owner_at(hit.voxel + scene.origin()) == Some(owner)
        })
        .collect();
    assert!(shows.len() > 20, "object {owner} covers {} pixels", shows.len());

    let (_xvfb, display) = start_xvfb(22);
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &document_args(&file, &camera, &[]));
    let window = find_window(&display, &mut app, &stderr_path);
    lines.wait_for("octovox: ready", Duration::from_secs(90));
    xdotool(&display, &["windowfocus", "--sync", &window]);
    // Paint picks the object without changing its shape.
    xdotool(&display, &["key", "g"]);
    click(&display, &window, &mut lines, x, y);
    xdotool(&display, &["mousemove", "--window", &window, "790", "590"]);
    std::thread::sleep(Duration::from_millis(800));
    let before = screenshot_x(&display, &dir.path().join("before.png"));
    xdotool(&display, &["key", "ctrl+h"]);
    lines.wait_for("object:", Duration::from_secs(30));
    std::thread::sleep(Duration::from_millis(800));
    let after = screenshot_x(&display, &dir.path().join("after.png"));
    if let Ok(keep) = std::env::var("OCTOVOX_KEEP_SHOTS") {
        before.save(format!("{keep}/hide-before.png")).unwrap();
        after.save(format!("{keep}/hide-after.png")).unwrap();
    }
    let changed = shows.iter().filter(|&&(px, py)| before.get_pixel(px, py) != after.get_pixel(px, py)).count();
    assert!(changed * 10 >= shows.len() * 9, "{changed} of the object's {} pixels changed", shows.len());

    save(&display, &mut lines, &file);
    let data = dot_vox::load_bytes(&std::fs::read(&file).unwrap()).unwrap();
    let original =
        dot_vox::load_bytes(&std::fs::read(common::assets().join("vox/format/test_groups.vox")).unwrap()).unwrap();
    assert_eq!(data.models.len(), original.models.len(), "every model is kept");
    let node = objects.list()[owner].transform_node.unwrap() as usize;
    let dot_vox::SceneNode::Transform { attributes, .. } = &data.scenes[node] else { panic!("node {node}") };
    assert_eq!(attributes.get("_hidden").map(String::as_str), Some("1"), "saved hidden");

    xdotool(&display, &["key", "ctrl+z"]);
    lines.wait_for("undo:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    let data = dot_vox::load_bytes(&std::fs::read(&file).unwrap()).unwrap();
    let dot_vox::SceneNode::Transform { attributes, .. } = &data.scenes[node] else { panic!("node {node}") };
    assert_eq!(attributes.get("_hidden"), None, "one Ctrl+Z shows it again");
}

/// A click on an object and Ctrl+H, then a kill: `octovox recover` puts
/// the edit in that object's model (the journal starts with the object the
/// click picked) and keeps the object hidden, read back with `dot_vox`.
#[test]
fn object_edits_survive_a_kill() {
    let (dir, file, scene) = groups_document();
    let objects = scene.objects().unwrap();
    let (lo, hi) = scene.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    let (x, y, voxel, _) = stable_pixel(scene.drawn(), &camera, |v, _| objects.owner_at(v).is_some());
    let owner = objects.owner_at(voxel).unwrap();
    let model = objects.list()[owner].placement.model;
    let before = model_sizes(&file);

    let (_xvfb, display) = start_xvfb(23);
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &document_args(&file, &camera, &[]));
    let window = find_window(&display, &mut app, &stderr_path);
    lines.wait_for("octovox: ready", Duration::from_secs(90));
    xdotool(&display, &["windowfocus", "--sync", &window]);
    click(&display, &window, &mut lines, x, y);
    // Before object lines were journaled, this hide was lost at recovery.
    xdotool(&display, &["key", "ctrl+h"]);
    lines.wait_for("object:", Duration::from_secs(30));
    app.0.kill().unwrap();
    app.0.wait().unwrap();

    let recovered = dir.path().join("recovered.vox");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_octovox"))
        .args(["recover", file.to_str().unwrap(), "-o", recovered.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let mut expected = before;
    expected[model] += 1;
    assert_eq!(model_sizes(&recovered), expected, "the attached voxel is in model {model}");
    let data = dot_vox::load_bytes(&std::fs::read(&recovered).unwrap()).unwrap();
    let node = objects.list()[owner].transform_node.unwrap() as usize;
    let dot_vox::SceneNode::Transform { attributes, .. } = &data.scenes[node] else { panic!("node {node}") };
    assert_eq!(attributes.get("_hidden").map(String::as_str), Some("1"), "the Ctrl+H before the kill is kept");
}

/// Tab is object mode: a click picks the object it hits and edits nothing,
/// the arrow keys move it (`object move`), the saved file has its
/// transform moved by as much and no model changed; one Ctrl+Z undoes
/// each move; a drag moves it as one undo step; Y turns it and Delete
/// deletes it.
#[test]
fn tab_object_mode_picks_moves_drags_turns_and_deletes_objects() {
    let (dir, file, scene) = groups_document();
    let objects = scene.objects().unwrap();
    let (lo, hi) = scene.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    let last = objects.list().len() - 1;
    let (x, y, voxel, _) = stable_pixel(scene.drawn(), &camera, |v, _| objects.owner_at(v).is_some_and(|o| o != last));
    let owner = objects.owner_at(voxel).unwrap();
    let node = objects.list()[owner].transform_node.expect("a transform above the object") as usize;
    let translation = |file: &std::path::Path| -> [i32; 3] {
        let data = dot_vox::load_bytes(&std::fs::read(file).unwrap()).unwrap();
        let dot_vox::SceneNode::Transform { frames, .. } = &data.scenes[node] else { panic!("node {node}") };
        let t = frames[0].attributes.get("_t").cloned().unwrap_or_default();
        let v: Vec<i32> = t.split_whitespace().map(|w| w.parse().unwrap()).collect();
        [v[0], v[1], v[2]]
    };
    let (before, sizes) = (translation(&file), model_sizes(&file));

    let (_xvfb, display) = start_xvfb(23);
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &document_args(&file, &camera, &[]));
    let window = find_window(&display, &mut app, &stderr_path);
    lines.wait_for("octovox: ready", Duration::from_secs(90));
    xdotool(&display, &["windowfocus", "--sync", &window]);
    xdotool(&display, &["key", "Tab"]);
    xdotool(&display, &["mousemove", "--window", &window, &x.to_string(), &y.to_string()]);
    std::thread::sleep(Duration::from_millis(300));
    xdotool(&display, &["click", "1"]);
    assert_eq!(lines.wait_for("ran: object", Duration::from_secs(30)), format!("ran: object {owner}"));
    for _ in 0..2 {
        xdotool(&display, &["key", "Right"]);
        // A move composes the cells the object left and reached: `object: N bytes written`.
        lines.wait_for("object:", Duration::from_secs(30));
    }
    save(&display, &mut lines, &file);
    assert!(!lines.seen.iter().any(|l| l.starts_with("edit:")), "object mode edited: {:?}", lines.seen);
    assert_eq!(model_sizes(&file), sizes, "no model changed");
    let after = translation(&file);
    let moved: i32 = (0..3).map(|k| (after[k] - before[k]).abs()).sum();
    assert_eq!(moved, 2, "two steps along one axis: {before:?} → {after:?}");

    // One Ctrl+Z undoes each move.
    for _ in 0..2 {
        xdotool(&display, &["key", "ctrl+z"]);
        lines.wait_for("undo:", Duration::from_secs(30));
    }
    save(&display, &mut lines, &file);
    assert_eq!(translation(&file), before, "two Ctrl+Z put it back");

    // A drag from the object moves it, as one undo step.
    xdotool(&display, &["mousemove", "--window", &window, &x.to_string(), &y.to_string()]);
    std::thread::sleep(Duration::from_millis(300));
    xdotool(&display, &["mousedown", "1"]);
    for _ in 0..8 {
        xdotool(&display, &["mousemove_relative", "--", "12", "0"]);
        std::thread::sleep(Duration::from_millis(100));
    }
    xdotool(&display, &["mouseup", "1"]);
    lines.wait_for("edit:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    let dragged = translation(&file);
    assert_ne!(dragged, before, "the drag moved the object");
    assert_eq!(dragged[2], before[2], "along the ground only (MagicaVoxel's z is up)");
    xdotool(&display, &["key", "ctrl+z"]);
    lines.wait_for("undo:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    assert_eq!(translation(&file), before, "one Ctrl+Z undoes the whole drag");

    // Shift+D and Ctrl+D duplicate; Y turns the picked object a quarter
    // about y, Delete deletes it.
    let transforms = |file: &std::path::Path| {
        let data = dot_vox::load_bytes(&std::fs::read(file).unwrap()).unwrap();
        data.scenes.iter().filter(|n| matches!(n, dot_vox::SceneNode::Transform { .. })).count()
    };
    let count = transforms(&file);
    // Shift+D places the picked object's model again (a reference: no model
    // added), Ctrl+D copies it (one more model).
    let models = model_sizes(&file).len();
    xdotool(&display, &["key", "shift+d"]);
    lines.wait_for("object:", Duration::from_secs(30));
    xdotool(&display, &["key", "ctrl+d"]);
    lines.wait_for("object:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    assert_eq!(transforms(&file), count + 2, "two duplicates");
    assert_eq!(model_sizes(&file).len(), models + 1, "Shift+D added no model, Ctrl+D one");
    xdotool(&display, &["key", "y"]);
    lines.wait_for("object:", Duration::from_secs(30));
    xdotool(&display, &["key", "Delete"]);
    lines.wait_for("object:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    assert_eq!(transforms(&file), count + 1, "Delete deleted the object");
}
