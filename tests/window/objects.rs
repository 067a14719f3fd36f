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

#[test]
fn a_click_picks_the_object_it_hits_and_edits_its_model() {
    require_window_tools();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("groups.vox");
    common::copy_writable(&common::assets().join("vox/format/test_groups.vox"), &file);
    let scene = octovox::io::load_scene(&file, 0).unwrap();
    let objects = scene.objects.as_ref().expect("test_groups.vox is a scene of objects");
    let (lo, hi) = scene.tree.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    // A pixel on a face of an object that is not the last one (so that
    // the pick is not the default target by chance).
    let last = objects.list().len() - 1;
    let (x, y, voxel, _) = stable_pixel(&scene.tree, &camera, |v, _| objects.owner_at(v).is_some_and(|o| o != last));
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
