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

/// The pixels clear of the panels that show object `owner`, by the CPU
/// tracer (every other one each way).
fn pixels_of(scene: &octovox::scene::Scene, camera: &Camera, owner: usize) -> Vec<(u32, u32)> {
    use octovox::trace::{Ray, svo};
    let objects = scene.objects().unwrap();
    let basis = camera.basis(WIDTH, HEIGHT, scene.origin());
    (FREE_Y..HEIGHT)
        .step_by(2)
        .flat_map(|py| (FREE_X..OUTLINER_X).step_by(2).map(move |px| (px, py)))
        .filter(|&(px, py)| {
            let (o, d) = basis.ray(px, py);
            let hit = svo::trace(scene.drawn(), &Ray::new(o, d));
            hit.is_hit() && objects.owner_at(hit.voxel + scene.origin()) == Some(owner)
        })
        .collect()
}

/// The framing camera of `scene`, and a pixel that steadily shows a face
/// of an object that is not the last one (so that a pick is not the
/// default target by chance): the pixel and that object.
fn object_pixel(scene: &octovox::scene::Scene) -> (Camera, u32, u32, usize) {
    let objects = scene.objects().expect("a scene of objects");
    let (lo, hi) = scene.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    let last = objects.list().len() - 1;
    let (x, y, voxel, _) =
        stable_pixel_left_of(OUTLINER_X, scene.drawn(), &camera, |v, _| objects.owner_at(v).is_some_and(|o| o != last));
    (camera, x, y, objects.owner_at(voxel).unwrap())
}

/// Tab into object mode and a click at (x, y), which picks `owner`.
fn pick_in_object_mode(display: &str, window: &str, lines: &mut Lines, (x, y): (u32, u32), owner: usize) {
    xdotool(display, &["key", "Tab"]);
    xdotool(display, &["mousemove", "--window", window, &x.to_string(), &y.to_string()]);
    std::thread::sleep(Duration::from_millis(300));
    xdotool(display, &["click", "1"]);
    assert_eq!(lines.wait_for("ran: object", Duration::from_secs(30)), format!("ran: object {owner}"));
}

#[test]
fn a_click_picks_the_object_it_hits_and_edits_its_model() {
    let (dir, file, scene) = groups_document();
    let (camera, x, y, owner) = object_pixel(&scene);
    let model = scene.objects().unwrap().list()[owner].placement.model;
    let before = model_sizes(&file);

    let (_xvfb, display) = start_xvfb();
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &document_args(&file, &camera, &[]));
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
    let (dir, file, scene) = groups_document();
    let objects = scene.objects().unwrap();
    let (lo, hi) = scene.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    let (x, y, voxel, _) =
        stable_pixel_left_of(OUTLINER_X, scene.drawn(), &camera, |v, _| objects.owner_at(v).is_some());
    let owner = objects.owner_at(voxel).unwrap();
    let shows = pixels_of(&scene, &camera, owner);
    assert!(shows.len() > 20, "object {owner} covers {} pixels", shows.len());

    let (_xvfb, display) = start_xvfb();
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &document_args(&file, &camera, &[]));
    // Paint picks the object without changing its shape.
    xdotool(&display, &["key", "g"]);
    click(&display, &window, &mut lines, x, y);
    let before = resting_shot(&display, &window, dir.path(), "hide-before");
    xdotool(&display, &["key", "ctrl+h"]);
    lines.wait_for("object:", Duration::from_secs(30));
    let after = resting_shot(&display, &window, dir.path(), "hide-after");
    assert_gone(&shows, &before, &after);

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
    let (x, y, voxel, _) =
        stable_pixel_left_of(OUTLINER_X, scene.drawn(), &camera, |v, _| objects.owner_at(v).is_some());
    let owner = objects.owner_at(voxel).unwrap();
    let model = objects.list()[owner].placement.model;
    let before = model_sizes(&file);

    let (_xvfb, display) = start_xvfb();
    let (mut app, mut lines, window) = open_ready(&display, dir.path(), &document_args(&file, &camera, &[]));
    click(&display, &window, &mut lines, x, y);
    // Before object lines were journaled, this hide was lost at recovery.
    xdotool(&display, &["key", "ctrl+h"]);
    lines.wait_for("object:", Duration::from_secs(30));
    let recovered = kill_and_recover(&mut app, dir.path(), &file);
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
    let (camera, x, y, owner) = object_pixel(&scene);
    let node = objects.list()[owner].transform_node.expect("a transform above the object") as usize;
    let translation = |file: &std::path::Path| -> [i32; 3] {
        let data = dot_vox::load_bytes(&std::fs::read(file).unwrap()).unwrap();
        let dot_vox::SceneNode::Transform { frames, .. } = &data.scenes[node] else { panic!("node {node}") };
        let t = frames[0].attributes.get("_t").cloned().unwrap_or_default();
        let v: Vec<i32> = t.split_whitespace().map(|w| w.parse().unwrap()).collect();
        [v[0], v[1], v[2]]
    };
    let (before, sizes) = (translation(&file), model_sizes(&file));

    let (_xvfb, display) = start_xvfb();
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &document_args(&file, &camera, &[]));
    pick_in_object_mode(&display, &window, &mut lines, (x, y), owner);
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

/// Asserts that nine in ten of the pixels `shows` changed from `before` to
/// `after`, not counting those under the picked object's box (orange, drawn
/// hidden or not).
fn assert_gone(shows: &[(u32, u32)], before: &image::RgbImage, after: &image::RgbImage) {
    let boxed = |p: &image::Rgb<u8>| p[0] >= 200 && p[2] <= 130 && p[0] - p[2] >= 100;
    let seen: Vec<_> = shows.iter().filter(|&&(x, y)| !boxed(after.get_pixel(x, y))).collect();
    let changed = seen.iter().filter(|&&&(x, y)| before.get_pixel(x, y) != after.get_pixel(x, y)).count();
    assert!(seen.len() * 4 >= shows.len() * 3, "the box covers most of the object");
    assert!(changed * 10 >= seen.len() * 9, "{changed} of the object's {} pixels changed", seen.len());
}

/// Where the Outliner draws its rows in an 800×600 window at scale 1: the
/// first row's middle, the rows' pitch, a row's eye at depth 0, one level
/// of groups' indent, and how far right of the eye the name is. A click
/// that lands elsewhere fails on the `ran: object N` line it prints.
const FIRST_ROW_Y: u32 = 110;
const ROW_PITCH: u32 = 23;
const EYE_X: u32 = OUTLINER_X + 16;
const INDENT: u32 = 12;
const NAME_FROM_EYE: u32 = 146;
/// An object row's layer button (`L0`), and its menu's first entry below it.
const LAYER_FROM_EYE: u32 = 72;
const MENU_FIRST: u32 = 27;
/// The first layer's row in the Layers panel below the rows, and its name.
const FIRST_LAYER_Y: u32 = 500;
const LAYER_NAME_X: u32 = OUTLINER_X + 112;
/// Rows shown without scrolling the Outliner.
const ROWS_SHOWN: usize = 14;

/// A double click on the first layer's name in the Layers panel, `name`
/// typed over it and Enter; waits for the change.
fn rename_first_layer(display: &str, window: &str, lines: &mut Lines, name: &str) {
    let (x, y) = (LAYER_NAME_X.to_string(), FIRST_LAYER_Y.to_string());
    xdotool(display, &["mousemove", "--window", window, &x, &y]);
    std::thread::sleep(Duration::from_millis(300));
    xdotool(display, &["click", "--repeat", "2", "--delay", "80", "1"]);
    std::thread::sleep(Duration::from_millis(500));
    xdotool(display, &["key", "ctrl+a"]);
    xdotool(display, &["type", name]);
    xdotool(display, &["key", "Return"]);
    lines.wait_for("layer:", Duration::from_secs(30));
}

/// Kills the window (its journal stays) and runs `octovox recover` on
/// `file`; the recovered file's path.
fn kill_and_recover(app: &mut KillOnDrop, dir: &std::path::Path, file: &std::path::Path) -> std::path::PathBuf {
    app.0.kill().unwrap();
    app.0.wait().unwrap();
    let recovered = dir.join("recovered.vox");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_octovox"))
        .args(["recover", file.to_str().unwrap(), "-o", recovered.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(run.status.success(), "recover: {}", String::from_utf8_lossy(&run.stderr));
    recovered
}

/// Object `index`'s row in the Outliner (from the top), and its depth.
fn outline_row(objects: &octovox::scene::objects::Objects, index: usize) -> (u32, u32) {
    use octovox::scene::graph::OutlineRow;
    let at = objects.outline().iter().position(|r| matches!(r, OutlineRow::Object { index: i, .. } if *i == index));
    let at = at.unwrap();
    let OutlineRow::Object { depth, .. } = objects.outline()[at] else { unreachable!() };
    (at as u32, depth)
}

/// The nGRP whose children hold transform `node`, and those children, as
/// `dot_vox` reads `file`.
fn group_of(file: &std::path::Path, node: u32) -> (usize, Vec<u32>) {
    let data = dot_vox::load_bytes(&std::fs::read(file).unwrap()).unwrap();
    data.scenes
        .iter()
        .enumerate()
        .find_map(|(i, n)| match n {
            dot_vox::SceneNode::Group { children, .. } if children.contains(&node) => Some((i, children.clone())),
            _ => None,
        })
        .unwrap()
}

/// The Outliner with the real mouse: an object's eye hides it (its pixels
/// change on screen, the saved file keeps it with `_hidden`), and its name
/// dragged onto another group's row puts it there, after that row (read
/// back with `dot_vox`); one Ctrl+Z undoes each. A double click on a
/// layer's name renames it.
#[test]
fn the_outliner_eye_hides_an_object_and_a_drag_regroups_it() {
    let (dir, file, scene) = groups_document();
    let objects = scene.objects().unwrap();
    let (lo, hi) = scene.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    let count = objects.list().len();
    let visible: Vec<usize> = (0..count).filter(|&i| (outline_row(objects, i).0 as usize) < ROWS_SHOWN).collect();
    let (owner, shows) =
        visible.iter().map(|&i| (i, pixels_of(&scene, &camera, i))).max_by_key(|(_, p)| p.len()).unwrap();
    assert!(shows.len() > 20, "object {owner} covers {} pixels", shows.len());
    let node = objects.list()[owner].transform_node.unwrap();
    let hidden_flag = |file: &std::path::Path| {
        let data = dot_vox::load_bytes(&std::fs::read(file).unwrap()).unwrap();
        let dot_vox::SceneNode::Transform { attributes, .. } = &data.scenes[node as usize] else { panic!() };
        attributes.get("_hidden").cloned()
    };

    let (_xvfb, display) = start_xvfb();
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &document_args(&file, &camera, &[]));
    let before = resting_shot(&display, &window, dir.path(), "eye-before");
    let (row, depth) = outline_row(objects, owner);
    let (eye_x, y) = (EYE_X + INDENT * depth, FIRST_ROW_Y + ROW_PITCH * row);
    xdotool(&display, &["mousemove", "--window", &window, &eye_x.to_string(), &y.to_string()]);
    std::thread::sleep(Duration::from_millis(300));
    xdotool(&display, &["click", "1"]);
    assert_eq!(lines.wait_for("ran: object", Duration::from_secs(30)), format!("ran: object {owner}"));
    lines.wait_for("object:", Duration::from_secs(30));
    let after = resting_shot(&display, &window, dir.path(), "eye-after");
    assert_gone(&shows, &before, &after);
    save(&display, &mut lines, &file);
    assert_eq!(hidden_flag(&file).as_deref(), Some("1"), "saved hidden");
    assert_eq!(model_sizes(&file).len(), objects.models.len(), "every model is kept");
    xdotool(&display, &["key", "ctrl+z"]);
    lines.wait_for("undo:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    assert_eq!(hidden_flag(&file), None, "one Ctrl+Z shows it again");

    // A drag of the first shown object's name onto the lower half of the
    // last shown row of another group.
    let transform = |i: usize| objects.list()[i].transform_node.unwrap();
    let from = visible[0];
    let (group, children) = group_of(&file, transform(from));
    let onto = *visible.iter().rev().find(|&&i| group_of(&file, transform(i)).0 != group).unwrap();
    let (target_group, target_children) = group_of(&file, transform(onto));
    let (from_row, from_depth) = outline_row(objects, from);
    let (onto_row, _) = outline_row(objects, onto);
    let x = EYE_X + INDENT * from_depth + NAME_FROM_EYE;
    let (y0, y1) = (FIRST_ROW_Y + ROW_PITCH * from_row, FIRST_ROW_Y + ROW_PITCH * onto_row + 6);
    xdotool(&display, &["mousemove", "--window", &window, &x.to_string(), &y0.to_string()]);
    std::thread::sleep(Duration::from_millis(300));
    xdotool(&display, &["mousedown", "1"]);
    std::thread::sleep(Duration::from_millis(300));
    for step in 1..=8 {
        let y = y0 + (y1 - y0) * step / 8;
        xdotool(&display, &["mousemove", "--window", &window, &x.to_string(), &y.to_string()]);
        std::thread::sleep(Duration::from_millis(100));
    }
    std::thread::sleep(Duration::from_millis(300));
    xdotool(&display, &["mouseup", "1"]);
    assert_eq!(lines.wait_for("ran: object", Duration::from_secs(30)), format!("ran: object {from}"));
    lines.wait_for("object:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    let (now_group, now_children) = group_of(&file, transform(from));
    assert_eq!(now_group, target_group, "object {from} went into object {onto}'s group");
    let at = now_children.iter().position(|&c| c == transform(from)).unwrap();
    assert_eq!(now_children[at - 1], transform(onto), "right after object {onto}: {now_children:?}");
    assert_eq!(now_children.len(), target_children.len() + 1);
    assert_eq!(model_sizes(&file), model_sizes(&common::assets().join("vox/format/test_groups.vox")));
    xdotool(&display, &["key", "ctrl+z"]);
    lines.wait_for("undo:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    assert_eq!(group_of(&file, transform(from)), (group, children), "one Ctrl+Z puts it back");

    // A double click on the first layer's name, a new name and Enter.
    let layer_name = |file: &std::path::Path| {
        let data = dot_vox::load_bytes(&std::fs::read(file).unwrap()).unwrap();
        data.layers[0].attributes.get("_name").cloned()
    };
    assert_ne!(layer_name(&file).as_deref(), Some("forest"));
    rename_first_layer(&display, &window, &mut lines, "forest");
    save(&display, &mut lines, &file);
    assert_eq!(layer_name(&file).as_deref(), Some("forest"), "the layer is renamed in the file");
}

/// Issue 48, item 4, in the window: a layer renamed `color` (a word the
/// `layer` line reads as a keyword) was journaled as `layer 0 color`, which
/// does not parse, so `recover` refused the whole journal after a kill and
/// every edit in it was lost. The rename is journaled in quotes: after a
/// kill, `octovox recover` gives the file with the layer named `color`, as
/// `dot_vox` reads it.
#[test]
fn a_layer_renamed_to_a_keyword_survives_a_kill() {
    let (dir, file, scene) = groups_document();
    let (lo, hi) = scene.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    let (_xvfb, display) = start_xvfb();
    let (mut app, mut lines, window) = open_ready(&display, dir.path(), &document_args(&file, &camera, &[]));
    // Past the path tracer's first frames (whose kernels compile on
    // lavapipe): a double click must fall within egui's double-click time.
    lines.wait_for("noise: ", Duration::from_secs(90));
    rename_first_layer(&display, &window, &mut lines, "color");
    let recovered = kill_and_recover(&mut app, dir.path(), &file);
    let data = dot_vox::load_bytes(&std::fs::read(&recovered).unwrap()).unwrap();
    assert_eq!(data.layers[0].attributes.get("_name").map(String::as_str), Some("color"));
    assert_eq!(data.layers[0].attributes.get("_hidden"), None, "not read as `layer 0 hide`");
}

/// Issue 48, item 2, in the window: `object move 2000000 0 0` was refused,
/// but the scene graph kept the move, and the window's next Ctrl+S replaced
/// the document with a file octovox then refused to open. Played here in
/// the window (`--replay`), then Ctrl+S: the file opens, drawing what it
/// drew before.
#[test]
fn a_refused_move_in_the_window_saves_a_file_that_opens() {
    let (dir, file, scene) = groups_document();
    let (lo, hi) = scene.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    let script = dir.path().join("far.ovr");
    std::fs::write(&script, "object 0\nobject move 2000000 0 0\n").unwrap();
    let (_xvfb, display) = start_xvfb();
    let args = document_args(&file, &camera, &["--replay", script.to_str().unwrap()]);
    let (_app, mut lines, _window) = open_ready(&display, dir.path(), &args);
    let refused = lines.wait_for("replay: ", Duration::from_secs(60));
    assert!(refused.contains("1 failed"), "{refused}: {:?}", lines.seen);
    assert!(lines.seen.iter().any(|l| l.contains("wider than 2^20")), "{:?}", lines.seen);
    save(&display, &mut lines, &file);
    let saved = octovox::io::load_scene(&file, 0).unwrap_or_else(|e| panic!("the saved file does not open: {e}"));
    assert_eq!(saved.voxels(), scene.voxels(), "it draws what it drew");
}

/// Issue 47, item 5: each Outliner row shows its object's layer (`L0`), and
/// its menu moves the object to another layer: a click on object `k`'s `L0`
/// and on layer 2 in the menu, then Ctrl+S; `dot_vox` reads the transform
/// on layer 2.
#[test]
fn the_outliner_shows_an_objects_layer_and_moves_it() {
    let (dir, file, scene) = groups_document();
    let objects = scene.objects().unwrap();
    let (lo, hi) = scene.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    let index = (0..objects.list().len()).find(|&i| (outline_row(objects, i).0 as usize) < ROWS_SHOWN).unwrap();
    let node = objects.list()[index].transform_node.unwrap();
    let (_xvfb, display) = start_xvfb();
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &document_args(&file, &camera, &[]));
    // Past the first path-traced frames, whose kernels compile on lavapipe:
    // the menu must be up before the second click.
    lines.wait_for("noise: ", Duration::from_secs(90));
    let (row, depth) = outline_row(objects, index);
    let (x, y) = (EYE_X + INDENT * depth + LAYER_FROM_EYE, FIRST_ROW_Y + ROW_PITCH * row);
    xdotool(&display, &["mousemove", "--window", &window, &x.to_string(), &y.to_string()]);
    std::thread::sleep(Duration::from_millis(300));
    xdotool(&display, &["click", "1"]);
    std::thread::sleep(Duration::from_millis(700));
    let entry = y + MENU_FIRST + 2 * ROW_PITCH;
    xdotool(&display, &["mousemove", "--window", &window, &x.to_string(), &entry.to_string()]);
    std::thread::sleep(Duration::from_millis(300));
    xdotool(&display, &["click", "1"]);
    lines.wait_for("object:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    let data = dot_vox::load_bytes(&std::fs::read(&file).unwrap()).unwrap();
    let dot_vox::SceneNode::Transform { layer_id, .. } = &data.scenes[node as usize] else { panic!("node {node}") };
    assert_eq!(*layer_id, 2, "object {index} is on layer 2");
}

/// A real click on a freely turned object (issue 49) attaches across the
/// face of the model cell under the cursor, in model space (the window
/// runs `object place X Y Z` of that model's cell): the saved file, read
/// by dot_vox, holds exactly that cell more in that model.
#[test]
fn a_click_on_a_turned_object_attaches_across_its_model_face() {
    use octovox::trace::pick::pick;
    let (dir, file, _) = groups_document();
    // Object 3 of the file turned by 30° about MagicaVoxel's z (written
    // with dot_vox: `_ov_turn` beside its key).
    let mut data = dot_vox::load_bytes(&std::fs::read(&file).unwrap()).unwrap();
    let scene = octovox::io::load_scene(&file, 0).unwrap();
    let node = scene.objects().unwrap().list()[3].transform_node.unwrap() as usize;
    let dot_vox::SceneNode::Transform { frames, .. } = &mut data.scenes[node] else { panic!("a transform") };
    frames[0].attributes.insert("_ov_turn".into(), "0 0 0.25881904510252074 0.9659258262890683".into());
    let mut bytes = Vec::new();
    data.write_vox(&mut bytes).unwrap();
    std::fs::write(&file, &bytes).unwrap();
    let scene = octovox::io::load_scene(&file, 0).unwrap();
    let objects = scene.objects().unwrap();
    let model = objects.list()[3].placement.model;
    let size = data.models[model].size;
    // Inside the model's grid (a cell outside grows it, and the saved file
    // shifts its cells).
    let inside = |c: glam::IVec3| {
        c.cmpge(glam::IVec3::ZERO).all() && c.cmplt(glam::IVec3::new(size.x as i32, size.y as i32, size.z as i32)).all()
    };
    // The window's field of view (`--camera` sets the eye and target).
    let camera = Camera::framing(objects.world_box(3).unwrap().0, objects.world_box(3).unwrap().1, 50.0);
    // A pixel whose pick (and its neighbours') hits one model cell face of
    // object 3, clear of the panels.
    let at = |x: u32, y: u32| pick(&scene, &camera, (WIDTH, HEIGHT), x, y).unwrap().and_then(|p| p.model);
    let (x, y, face) = (FREE_Y + 4..HEIGHT - 4)
        .step_by(3)
        .flat_map(|y| (FREE_X + 4..OUTLINER_X - 4).step_by(3).map(move |x| (x, y)))
        .find_map(|(x, y)| {
            let face = at(x, y).filter(|m| m.object == 3 && inside(m.cell + m.normal))?;
            let steady = (-2..=2).all(|d: i32| {
                at(x.wrapping_add_signed(d), y) == Some(face) && at(x, y.wrapping_add_signed(d)) == Some(face)
            });
            steady.then_some((x, y, face))
        })
        .expect("a pixel on the turned object");
    let across = face.cell + face.normal;
    let cells = |file: &std::path::Path| -> std::collections::BTreeSet<[i32; 3]> {
        let data = dot_vox::load_bytes(&std::fs::read(file).unwrap()).unwrap();
        data.models[model].voxels.iter().map(|v| [v.x, v.y, v.z].map(i32::from)).collect()
    };
    let before = cells(&file);

    let (_xvfb, display) = start_xvfb();
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &document_args(&file, &camera, &[]));
    click(&display, &window, &mut lines, x, y);
    assert!(lines.seen.iter().any(|l| l == "ran: object 3"), "{:?}", lines.seen);
    save(&display, &mut lines, &file);
    let after = cells(&file);
    assert_eq!(after.difference(&before).collect::<Vec<_>>(), [&across.to_array()], "the cell across the face");
    assert_eq!(before.difference(&after).count(), 0);
}

/// Object mode's ring (issue 49): a real drag round the ring turns the
/// picked object freely about the up axis by the degrees dragged, K keys
/// it, and the saved file (read by dot_vox) holds the turn as `_ov_turn`
/// on the object's key, the angle the drag went round.
#[test]
fn the_ring_turns_the_picked_object_freely_and_k_keys_it() {
    let (q, turn) = ring_turn(None);
    // About MagicaVoxel's z (world y) only, by about the 40° dragged.
    assert!(q[0].abs() < 1e-9 && q[1].abs() < 1e-9, "about z: {turn}");
    let degrees = (2.0 * q[2].atan2(q[3])).to_degrees().abs();
    assert!((30.0..=50.0).contains(&degrees), "turned {degrees}° ({turn})");
}

/// Shift+X in object mode sets the ring's axis: the same drag turns the
/// object about world x (MagicaVoxel's x) instead.
#[test]
fn shift_x_makes_the_ring_turn_about_x() {
    let (q, turn) = ring_turn(Some("shift+x"));
    assert!(q[1].abs() < 1e-9 && q[2].abs() < 1e-9, "about x: {turn}");
    let degrees = (2.0 * q[0].atan2(q[3])).to_degrees().abs();
    assert!((30.0..=50.0).contains(&degrees), "turned {degrees}° ({turn})");
}

/// Picks an object in object mode, presses `axis_key` (if any), drags 40°
/// round the ring, keys (K) and saves: the saved `_ov_turn` quaternion of
/// the object's key, and its text.
fn ring_turn(axis_key: Option<&str>) -> (Vec<f64>, String) {
    let (dir, file, scene) = groups_document();
    let objects = scene.objects().unwrap();
    let (camera, x, y, owner) = object_pixel(&scene);
    let node = objects.list()[owner].transform_node.expect("a transform above the object") as usize;
    // The ring as the window draws it: about the picked box's centre on
    // screen, 16 pixels past its farthest corner.
    let basis = camera.basis(WIDTH, HEIGHT, scene.origin());
    let (blo, bhi) = objects.world_box(owner).unwrap();
    let (a, b) = ((blo - scene.origin()).as_vec3(), (bhi - scene.origin() + glam::IVec3::ONE).as_vec3());
    let (cx, cy) = basis.project((a + b) * 0.5).unwrap();
    let radius = (0..8)
        .map(|k| {
            let corner = glam::Vec3::new([a.x, b.x][k & 1], [a.y, b.y][(k >> 1) & 1], [a.z, b.z][k >> 2]);
            let (px, py) = basis.project(corner).unwrap();
            ((px - cx).powi(2) + (py - cy).powi(2)).sqrt()
        })
        .fold(0.0, f32::max)
        + 16.0;
    let on_ring = |degrees: f32| {
        let r = degrees.to_radians();
        ((cx + radius * r.cos()).round() as i32, (cy - radius * r.sin()).round() as i32)
    };

    let (_xvfb, display) = start_xvfb();
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &document_args(&file, &camera, &[]));
    pick_in_object_mode(&display, &window, &mut lines, (x, y), owner);
    if let Some(key) = axis_key {
        xdotool(&display, &["key", key]);
        lines.wait_for("the ring turns the object about", Duration::from_secs(30));
    }
    let (gx, gy) = on_ring(0.0);
    xdotool(&display, &["mousemove", "--window", &window, &gx.to_string(), &gy.to_string()]);
    std::thread::sleep(Duration::from_millis(300));
    xdotool(&display, &["mousedown", "1"]);
    for step in 1..=8 {
        let (px, py) = on_ring(5.0 * step as f32);
        xdotool(&display, &["mousemove", "--window", &window, &px.to_string(), &py.to_string()]);
        std::thread::sleep(Duration::from_millis(100));
    }
    xdotool(&display, &["mouseup", "1"]);
    // Each whole degree dragged is a turn written to the instance words.
    lines.wait_for("edit:", Duration::from_secs(30));
    std::thread::sleep(Duration::from_millis(500));
    xdotool(&display, &["key", "k"]);
    lines.wait_for("object:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    let data = dot_vox::load_bytes(&std::fs::read(&file).unwrap()).unwrap();
    let dot_vox::SceneNode::Transform { frames, .. } = &data.scenes[node] else { panic!("node {node}") };
    let turn = frames[0].attributes.get("_ov_turn").unwrap_or_else(|| panic!("a free turn in {frames:?}")).clone();
    (turn.split_whitespace().map(|v| v.parse().unwrap()).collect(), turn)
}
