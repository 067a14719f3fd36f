//! Box selection in the real window: B (once, though it was held as the
//! window got the focus), a mouse drag selects a block; the arrow keys move
//! it (one undo step each); a drag on a face of the box (its handle)
//! resizes it; Ctrl+C, Ctrl+V on another face and Delete.
//! Every stage is checked through the saved file against voxel sets this
//! test works out itself.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use crate::common;

use std::collections::HashSet;
use std::time::Duration;

use common::window::*;
use glam::{DVec3, IVec3, Vec3};
use octovox::camera::Camera;
use octovox::scene::{Op, Scene, Shape};

fn cells(min: IVec3, max: IVec3) -> HashSet<IVec3> {
    (min.x..=max.x)
        .flat_map(|x| (min.y..=max.y).flat_map(move |y| (min.z..=max.z).map(move |z| IVec3::new(x, y, z))))
        .collect()
}

fn shifted(set: &HashSet<IVec3>, by: IVec3) -> HashSet<IVec3> {
    set.iter().map(|p| *p + by).collect()
}

/// Presses the left button at `from`, drags to `to` in steps, releases.
fn drag(display: &str, window: &str, from: (f32, f32), to: (f32, f32)) {
    let at = |(x, y): (f32, f32)| [x.round().to_string(), y.round().to_string()];
    let [x, y] = at(from);
    xdotool(display, &["mousemove", "--window", window, &x, &y]);
    std::thread::sleep(Duration::from_millis(200));
    xdotool(display, &["mousedown", "1"]);
    for i in 1..=6 {
        let t = i as f32 / 6.0;
        let [x, y] = at((from.0 + t * (to.0 - from.0), from.1 + t * (to.1 - from.1)));
        xdotool(display, &["mousemove", "--window", window, &x, &y]);
        std::thread::sleep(Duration::from_millis(80));
    }
    xdotool(display, &["mouseup", "1"]);
}

#[test]
fn a_box_selection_moves_with_the_arrows_resizes_by_a_handle_and_copies() {
    require_window_tools();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("blocks.vox");
    let floor = cells(IVec3::ZERO, IVec3::new(15, 0, 15));
    let block = cells(IVec3::new(4, 1, 4), IVec3::new(5, 2, 5));
    let mut scene = Scene::default();
    scene.apply_brush(&Shape::Box { min: IVec3::ZERO, max: IVec3::new(15, 0, 15) }, Op::Place(20)).unwrap();
    scene.apply_brush(&Shape::Box { min: IVec3::new(4, 1, 4), max: IVec3::new(5, 2, 5) }, Op::Place(30)).unwrap();
    octovox::io::save_scene(&file, &scene, Default::default()).unwrap();
    // From the front (looking along -z): → is +x, ↑ is -z.
    let camera =
        Camera { eye: DVec3::new(8.0, 20.0, 24.0), target: DVec3::new(8.0, 0.0, 8.0), fov_y_deg: 50.0, ortho: None };
    let (xa, ya, ..) = stable_pixel(scene.drawn(), &camera, |v, n| v == IVec3::new(4, 2, 4) && n == IVec3::Y);
    let (xb, yb, ..) = stable_pixel(scene.drawn(), &camera, |v, n| v == IVec3::new(5, 1, 5) && n == IVec3::Z);
    let (xf, yf, ..) = stable_pixel(scene.drawn(), &camera, |v, n| v == IVec3::new(12, 0, 10) && n == IVec3::Y);

    let (_xvfb, display) = start_xvfb();
    let args = document_args(&file, &camera, &["--shading", "preview"]);
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &args);
    let window = find_window(&display, &mut app, &stderr_path);
    lines.wait_for("octovox: ready", Duration::from_secs(90));
    // B held down as the window gains the focus: winit reports it with a
    // synthetic press, which must not toggle the mode (the real press that
    // follows a key pressed just as the focus came would toggle it back).
    xdotool(&display, &["keydown", "b"]);
    xdotool(&display, &["windowfocus", "--sync", &window]);
    std::thread::sleep(Duration::from_millis(500));
    xdotool(&display, &["keyup", "b"]);
    xdotool(&display, &["key", "b"]);
    drag(&display, &window, (xa as f32, ya as f32), (xb as f32, yb as f32));
    assert_eq!(lines.wait_for("ran: select", Duration::from_secs(30)), "ran: select 4 1 4 5 2 5");

    for key in ["Right", "Right", "Up"] {
        xdotool(&display, &["key", key]);
        lines.wait_for("move:", Duration::from_secs(30));
    }
    save(&display, &mut lines, &file);
    let moved: HashSet<IVec3> = floor.union(&shifted(&block, IVec3::new(2, 0, -1))).copied().collect();
    assert_eq!(voxel_set(&file), moved, "two voxels right, one away");
    xdotool(&display, &["key", "ctrl+z"]);
    lines.wait_for("undo:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    let undone: HashSet<IVec3> = floor.union(&shifted(&block, IVec3::new(2, 0, 0))).copied().collect();
    assert_eq!(voxel_set(&file), undone, "one Ctrl+Z undoes one move");

    // The selection stayed at (6, 1, 3)..(7, 2, 4); its front face's handle
    // is dragged two voxel steps toward the camera.
    let basis = camera.basis(WIDTH, HEIGHT, IVec3::ZERO);
    let face = Vec3::new(7.0, 2.0, 5.0);
    let (a, b) = (basis.project(face).unwrap(), basis.project(face + Vec3::Z).unwrap());
    drag(&display, &window, a, (a.0 + 2.0 * (b.0 - a.0), a.1 + 2.0 * (b.1 - a.1)));
    assert_eq!(lines.wait_for("ran: select", Duration::from_secs(30)), "ran: select 6 1 3 7 2 6");

    // Copy, then paste on the floor's top face at (12, 0, 10): the block's
    // min corner (6, 1, 3) lands at (12, 1, 10).
    xdotool(&display, &["key", "ctrl+c"]);
    lines.wait_for("ran: copy", Duration::from_secs(30));
    xdotool(&display, &["mousemove", "--window", &window, &xf.to_string(), &yf.to_string()]);
    std::thread::sleep(Duration::from_millis(200));
    xdotool(&display, &["key", "ctrl+v"]);
    lines.wait_for("paste:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    let copy = shifted(&block, IVec3::new(2, 0, 0) + IVec3::new(12, 1, 10) - IVec3::new(6, 1, 3));
    let pasted: HashSet<IVec3> = undone.union(&copy).copied().collect();
    assert_eq!(voxel_set(&file), pasted, "the copy sits on the floor");

    // The pasted box is the selection: Delete takes the copy away.
    xdotool(&display, &["key", "Delete"]);
    lines.wait_for("delete:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    assert_eq!(voxel_set(&file), undone, "Delete removed the pasted block");
}
