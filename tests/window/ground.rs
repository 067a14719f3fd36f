//! An empty scene in the real window: File ▸ New shows the ground grid; a
//! click on the ground and Save As give a file of one voxel (`dot_vox`
//! reads it) at y = 0 on the cell under the cursor.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use crate::common;

use std::time::Duration;

use common::window::*;
use glam::IVec3;
use octovox::camera::Camera;
use octovox::trace::pick;

/// The working volume of a new scene (`DEFAULT_VOLUME` in src/app/state.rs).
const VOLUME: i32 = 32;

/// The camera New leaves: the default one framing the working volume, then
/// panned by half the left panel's 236 points so the volume sits in the
/// view's middle (as src/app/files.rs and `App::frame_box` do).
fn new_scene_camera() -> Camera {
    let half = VOLUME / 2;
    let lo = IVec3::new(-half, 0, -half);
    let mut camera = Camera::default().reframed(lo, lo + IVec3::splat(VOLUME - 1));
    let (_, right, _) = camera.axes();
    let shift = -right * 118.0 * camera.view_height() / f64::from(HEIGHT);
    camera.eye += shift;
    camera.target += shift;
    camera
}

/// A pixel clear of the panels whose 5×5 neighbourhood lands on one ground
/// cell, and that cell.
fn stable_ground_pixel(camera: &Camera) -> (u32, u32, IVec3) {
    let empty = octovox::scene::Scene::default();
    let cell = |x: u32, y: u32| {
        pick::pick_with_ground(&empty, camera, (WIDTH, HEIGHT), (x, y), true).unwrap().map(|hit| hit.voxel)
    };
    for y in (HEIGHT / 2..HEIGHT - 40).step_by(7) {
        for x in (FREE_X + 60..WIDTH - 60).step_by(7) {
            let Some(at) = cell(x, y) else { continue };
            if (-2..=2).all(|d: i32| {
                (-2..=2).all(|e: i32| cell(x.wrapping_add_signed(d), y.wrapping_add_signed(e)) == Some(at))
            }) {
                return (x, y, at);
            }
        }
    }
    panic!("no pixel of the new scene's view lands steadily on one ground cell");
}

#[test]
fn new_then_a_click_on_the_ground_places_a_voxel_at_y_0() {
    require_window_tools();
    let dir = tempfile::tempdir().unwrap();
    let camera = new_scene_camera();
    let (x, y, ground) = stable_ground_pixel(&camera);
    assert_eq!((ground.y, ground.x.abs() < VOLUME, ground.z.abs() < VOLUME), (-1, true, true), "{ground}");

    let (_xvfb, display) = start_xvfb();
    let args = ["--size".to_owned(), format!("{WIDTH}x{HEIGHT}")];
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &args);
    let before = screenshot_x(&display, &dir.path().join("demo.png"));
    xdotool(&display, &["key", "ctrl+n"]);
    lines.wait_for("new: an empty scene on the ground", Duration::from_secs(30));
    let empty = resting_shot(&display, &window, dir.path(), "new-scene");
    // The grid's lines: lighter than the sky around them, along the ground.
    let (mean, variance) = grey_stats(&empty, FREE_X, HEIGHT / 2, WIDTH - 20, HEIGHT - 20);
    assert!(variance > 4.0, "the ground grid shows (grey mean {mean:.1}, variance {variance:.1})");
    assert_ne!(before, empty, "New changed the picture");

    click(&display, &window, &mut lines, x, y);
    let file = dir.path().join("first.vox");
    xdotool(&display, &["key", "ctrl+shift+s"]);
    answer_browser(&display, &window, &mut lines, (WIDTH, HEIGHT), &file);
    lines.wait_for("saved:", Duration::from_secs(30));

    // dot_vox's reading: one model of one voxel; where it is, octovox's.
    let data = dot_vox::load_bytes(&std::fs::read(&file).unwrap()).unwrap();
    assert_eq!(data.models.len(), 1);
    assert_eq!(data.models[0].voxels.len(), 1, "one voxel");
    let placed = octovox::io::load_scene(&file, 0).unwrap();
    assert_eq!(placed.voxels().into_iter().map(|(p, _)| p).collect::<Vec<_>>(), vec![ground + IVec3::Y]);
}

/// A dialog over the view holds the path tracer's accumulation where it is:
/// while the file browser is open no sample is added (on a loaded machine
/// the samples of a view on the ground made the browser miss the keys
/// typed into it), and once it is closed the accumulation goes on.
#[test]
fn a_dialog_holds_the_accumulation_and_closing_it_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let (_xvfb, display) = start_xvfb();
    let args = ["--size".to_owned(), format!("{WIDTH}x{HEIGHT}")];
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &args);
    lines.wait_for("noise:", Duration::from_secs(60));
    xdotool(&display, &["windowfocus", "--sync", &window]);
    xdotool(&display, &["key", "ctrl+shift+s"]);
    lines.wait_for("file dialog: browser", Duration::from_secs(30));
    // A sample already under way may still complete.
    std::thread::sleep(Duration::from_secs(1));
    let held_from = lines.seen.len();
    assert!(
        lines.try_wait_for("noise:", Duration::from_secs(4)).is_none(),
        "samples went on: {:?}",
        &lines.seen[held_from..]
    );
    xdotool(&display, &["key", "Escape"]);
    lines.wait_for("noise:", Duration::from_secs(60));
}
