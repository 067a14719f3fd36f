//! Extrude in the real window: Ctrl+drag from a face of torus64 pulls its
//! connected coplanar faces out by the layers the drag covers; the saved
//! file gains exactly the voxels worked out here (a region search of this
//! test's own), and Ctrl+Z takes them back in one step.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use crate::common;

use std::collections::{HashSet, VecDeque};
use std::time::Duration;

use common::window::*;
use glam::IVec3;

/// Voxels of `solid` showing a face toward `normal`, connected in their
/// plane to `start`'s.
fn face_region(solid: &HashSet<IVec3>, start: IVec3, normal: IVec3) -> HashSet<IVec3> {
    let shows = |p: IVec3| solid.contains(&p) && !solid.contains(&(p + normal));
    let steps: Vec<IVec3> = [IVec3::X, IVec3::NEG_X, IVec3::Y, IVec3::NEG_Y, IVec3::Z, IVec3::NEG_Z]
        .into_iter()
        .filter(|s| s.dot(normal) == 0)
        .collect();
    let mut region = HashSet::from([start]);
    let mut queue = VecDeque::from([start]);
    while let Some(p) = queue.pop_front() {
        for s in &steps {
            if shows(p + *s) && region.insert(p + *s) {
                queue.push_back(p + *s);
            }
        }
    }
    region
}

#[test]
fn ctrl_drag_extrudes_a_face_in_a_real_window() {
    let (dir, file, original, camera) = torus_document();
    let solid: HashSet<IVec3> = original.voxels().into_iter().map(|(p, _)| p).collect();
    // A face pointing up, seen from above, so the drag has room.
    let (x, y, voxel, normal) = stable_pixel(original.drawn(), &camera, |_, n| n == IVec3::Y);
    let region = face_region(&solid, voxel, normal);
    let layers = 2;
    let expected: HashSet<IVec3> =
        solid.iter().copied().chain(region.iter().flat_map(|v| (1..=layers).map(move |k| *v + normal * k))).collect();
    assert!(expected.len() > solid.len() + 2 * layers as usize, "a region of several faces");

    // The drag: two on-screen steps of the face's normal.
    let basis = camera.basis(WIDTH, HEIGHT, original.origin());
    let face = (voxel - original.origin()).as_vec3() + glam::Vec3::new(0.5, 1.0, 0.5);
    let (a, b) = (basis.project(face).unwrap(), basis.project(face + glam::Vec3::Y).unwrap());
    let end = (x as f32 + 2.0 * (b.0 - a.0), y as f32 + 2.0 * (b.1 - a.1));
    assert!(end.1 > 40.0, "the drag stays in the window: {end:?}");

    let (_xvfb, display) = start_xvfb();
    let args = document_args(&file, &camera, &[]);
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &args);
    xdotool(&display, &["mousemove", "--window", &window, &x.to_string(), &y.to_string()]);
    xdotool(&display, &["keydown", "ctrl"]);
    xdotool(&display, &["mousedown", "1"]);
    for i in 1..=8 {
        let t = i as f32 / 8.0;
        let (px, py) = (x as f32 + t * (end.0 - x as f32), y as f32 + t * (end.1 - y as f32));
        xdotool(&display, &["mousemove", "--window", &window, &format!("{}", px.round()), &format!("{}", py.round())]);
        std::thread::sleep(Duration::from_millis(40));
    }
    xdotool(&display, &["mouseup", "1"]);
    xdotool(&display, &["keyup", "ctrl"]);
    lines.wait_for("extrude:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    assert_eq!(voxel_set(&file), expected, "the face region moved out {layers} layers");
    xdotool(&display, &["key", "ctrl+z"]);
    lines.wait_for("undo:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    assert_eq!(voxel_set(&file), solid, "one Ctrl+Z takes the extrude back");
}
