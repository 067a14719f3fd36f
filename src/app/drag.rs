//! What a drag on the screen means in voxels, as plain functions of the
//! camera's ray basis (tree-local) and the window pixels: how many layers a
//! Ctrl+drag extrudes, how far a selection's face moves, where an object
//! drag takes it over the ground. The window passes its basis in; the
//! tests here need no window.

use glam::{DVec2, IVec3, Vec3};
use octovox::camera::{Camera, RayBasis};
use octovox::edit::selection::Region;

/// The whole voxel steps along `normal` that a drag from window pixel
/// `start` to `end` covers, as the step from the (tree-local) point `face`
/// is drawn on screen: `None` where either end is behind the camera.
pub(super) fn screen_steps(
    basis: &RayBasis,
    face: Vec3,
    normal: IVec3,
    start: (f64, f64),
    end: (f64, f64),
) -> Option<i32> {
    let (a, b) = (basis.project(face)?, basis.project(face + normal.as_vec3())?);
    let step = DVec2::new(f64::from(b.0 - a.0), f64::from(b.1 - a.1));
    let drag = DVec2::new(end.0 - start.0, end.1 - start.1);
    Some((drag.dot(step) / step.length_squared().max(1e-6)).round() as i32)
}

/// The whole voxels along x and z that a drag from `start` to `end` covers
/// at the tree-local cell `at`: the drag in the screen's directions of
/// those two axes there; `None` where the ground is seen edge-on.
pub(super) fn ground_steps(basis: &RayBasis, at: IVec3, start: (f64, f64), end: (f64, f64)) -> Option<IVec3> {
    let at = at.as_vec3() + Vec3::splat(0.5);
    let screen = |p: Vec3| basis.project(p).map(|(x, y)| DVec2::new(f64::from(x), f64::from(y)));
    let origin = screen(at)?;
    let (sx, sz) = (screen(at + Vec3::X)? - origin, screen(at + Vec3::Z)? - origin);
    let det = sx.perp_dot(sz);
    if det.abs() < 1e-3 {
        return None;
    }
    let drag = DVec2::new(end.0 - start.0, end.1 - start.1);
    let (a, b) = (drag.perp_dot(sz) / det, sx.perp_dot(drag) / det);
    Some(IVec3::new(a.round() as i32, 0, b.round() as i32))
}

/// The selection with its face of outward `normal` moved `steps` along it:
/// the box never turns inside out.
pub(super) fn moved_face(region: &Region, normal: IVec3, steps: i32) -> Option<Region> {
    let (mut min, mut max) = (region.min, region.max);
    if normal.element_sum() > 0 {
        max = (max + normal * steps).max(min);
    } else {
        min = (min + normal * steps).min(max);
    }
    Region::new(min, max).ok()
}

/// Pixels either side of the rotation ring that a press grabs it within
/// (times the window's scale).
pub(super) const RING_GRAB: f64 = 8.0;
/// Points between the picked object's farthest corner and its ring.
const RING_MARGIN: f64 = 16.0;

/// The rotation ring around the picked object's box `lo..=hi` (tree-local
/// cells) as `basis` draws it: its centre and radius in the basis' pixels
/// (the box's centre, and [`RING_MARGIN`] past its farthest corner, times
/// `scale`, the basis' pixels per point).
pub(super) fn ring(basis: &RayBasis, lo: IVec3, hi: IVec3, scale: f64) -> Option<(DVec2, f64)> {
    let (a, b) = (lo.as_vec3(), (hi + IVec3::ONE).as_vec3());
    let screen = |p: Vec3| basis.project(p).map(|(x, y)| DVec2::new(f64::from(x), f64::from(y)));
    let centre = screen((a + b) * 0.5)?;
    let mut radius: f64 = 0.0;
    for k in 0..8 {
        let corner = Vec3::new([a.x, b.x][k & 1], [a.y, b.y][(k >> 1) & 1], [a.z, b.z][k >> 2]);
        radius = radius.max((screen(corner)? - centre).length());
    }
    Some((centre, radius + RING_MARGIN * scale))
}

/// The angle in degrees, counter-clockwise as seen on screen (y is down),
/// of pixel `at` about `centre`.
pub(super) fn screen_angle(centre: DVec2, at: (f64, f64)) -> f64 {
    (-(at.1 - centre.y)).atan2(at.0 - centre.x).to_degrees()
}

/// Whether `camera` sees the plane across `axis` at `middle` (the picked
/// box's middle) from the axis' negative side: a perspective eye below it,
/// or looking toward the positive axis (orthographic, or no box). Seen
/// from there, counter-clockwise on screen turns the other way.
pub(super) fn seen_from_below(camera: &Camera, axis: usize, middle: Option<f64>) -> bool {
    match (camera.ortho, middle) {
        (None, Some(middle)) => camera.eye[axis] < middle,
        _ => camera.target[axis] > camera.eye[axis],
    }
}

/// `by` degrees brought into −180..180 (a drag across the ring's left
/// side turns on, not back a whole turn).
pub(super) fn wrapped(by: f64) -> f64 {
    (by + 180.0).rem_euclid(360.0) - 180.0
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // in tests a panic is the failure report
mod tests {
    use glam::DVec3;
    use octovox::camera::Camera;
    use octovox::editor::Editor;
    use octovox::scene::{Octree, Op, Palette, Scene, Shape};
    use octovox::script::Line;

    use super::*;

    const SIZE: (u32, u32) = (800, 600);

    fn basis(eye: [f64; 3], ortho: Option<f32>) -> RayBasis {
        let camera = Camera { eye: DVec3::from_array(eye), target: DVec3::new(4.0, 0.0, 4.0), fov_y_deg: 50.0, ortho };
        camera.basis(SIZE.0, SIZE.1, IVec3::ZERO)
    }

    /// Where the tree-local point `p` is drawn.
    fn pixel(basis: &RayBasis, p: Vec3) -> (f64, f64) {
        let (x, y) = basis.project(p).unwrap();
        (f64::from(x), f64::from(y))
    }

    /// A drag from where a face is drawn to where the point `layers` voxels
    /// along its normal is drawn extrudes that many layers, out or in, from
    /// any camera; `extrude` runs as one undo step.
    #[test]
    fn a_ctrl_drag_extrudes_the_layers_it_covers_on_screen() {
        let mut tree = Octree::default();
        tree.apply_brush(&Shape::Box { min: IVec3::ZERO, max: IVec3::new(7, 0, 7) }, Op::Place(1)).unwrap();
        let mut editor = Editor::default();
        editor.set_scene(Scene::new(Palette::default(), tree));
        let face = Vec3::new(3.5, 1.0, 3.5);
        for view in
            [basis([20.0, 16.0, 24.0], None), basis([4.5, 30.0, 4.6], Some(20.0)), basis([-9.0, 6.0, 2.0], None)]
        {
            for layers in [-1, 1, 3] {
                let end = pixel(&view, face + Vec3::Y * layers as f32);
                assert_eq!(screen_steps(&view, face, IVec3::Y, pixel(&view, face), end), Some(layers));
            }
        }
        let layers = screen_steps(&view_from_above(), face, IVec3::Y, (400.0, 300.0), (400.0, 300.0)).unwrap();
        assert_eq!(layers, 0, "no drag, no layers");
        editor.run(&Line::Extrude(IVec3::new(3, 0, 3), IVec3::Y, 3)).unwrap();
        assert_eq!(editor.scene.solid_voxels(), 64 * 4);
        assert_eq!(editor.history.steps(), (1, 0), "one undo step");
    }

    fn view_from_above() -> RayBasis {
        basis([4.0, 40.0, 4.1], None)
    }

    /// A face of the selection dragged out grows it, dragged in past the
    /// opposite face stops there; the result is the `select` line's box.
    #[test]
    fn a_dragged_selection_face_moves_along_its_normal_and_never_turns_inside_out() {
        let region = Region::new(IVec3::ZERO, IVec3::new(3, 3, 3)).unwrap();
        assert_eq!(moved_face(&region, IVec3::X, 2).unwrap().max, IVec3::new(5, 3, 3));
        assert_eq!(moved_face(&region, IVec3::NEG_Z, 1).unwrap().min, IVec3::new(0, 0, -1));
        let squashed = moved_face(&region, IVec3::Y, -10).unwrap();
        assert_eq!((squashed.min, squashed.max), (IVec3::ZERO, IVec3::new(3, 0, 3)));
        let view = basis([20.0, 16.0, 24.0], None);
        let face = Vec3::new(4.0, 2.0, 2.0);
        let steps = screen_steps(&view, face, IVec3::X, pixel(&view, face), pixel(&view, face + Vec3::X * 2.0));
        assert_eq!(steps, Some(2));
    }

    /// An object dragged over the ground follows the pointer in whole
    /// voxels of x and z, from any camera that sees the ground; seen
    /// edge-on, the ground takes no drag.
    #[test]
    fn an_object_drag_follows_the_pointer_over_the_ground() {
        let at = IVec3::new(4, 0, 4);
        let centre = at.as_vec3() + Vec3::splat(0.5);
        for view in [basis([20.0, 16.0, 24.0], None), view_from_above(), basis([-12.0, 9.0, 30.0], Some(30.0))] {
            for by in [IVec3::new(3, 0, 0), IVec3::new(0, 0, -2), IVec3::new(-4, 0, 5)] {
                let end = pixel(&view, centre + by.as_vec3());
                assert_eq!(ground_steps(&view, at, pixel(&view, centre), end), Some(by));
            }
        }
        let level =
            Camera { eye: DVec3::new(30.0, 0.5, 4.5), target: DVec3::new(4.0, 0.5, 4.5), fov_y_deg: 50.0, ortho: None };
        let edge_on = level.basis(SIZE.0, SIZE.1, IVec3::ZERO);
        assert_eq!(ground_steps(&edge_on, at, (400.0, 300.0), (450.0, 300.0)), None);
    }

    /// The ring's turn is seen from the side of its axis the eye is on: a
    /// perspective eye by where it stands against the picked box's middle,
    /// an orthographic one (or one with no box) by the way it looks.
    #[test]
    fn the_ring_is_seen_from_the_eyes_side_of_its_axis() {
        let at = |eye: [f64; 3], ortho| Camera {
            eye: DVec3::from_array(eye),
            target: DVec3::new(4.0, 4.0, 4.0),
            fov_y_deg: 50.0,
            ortho,
        };
        let above = at([4.0, 20.0, 9.0], None);
        assert!(!seen_from_below(&above, 1, Some(4.0)), "from above, about y");
        assert!(seen_from_below(&above, 1, Some(30.0)), "an eye below a tall object's middle");
        // About x from the eye's side of x = 4 (the eye at x = 4.5 is on
        // the positive side of the middle, x = 4).
        let right = at([4.5, 5.0, 20.0], None);
        assert!(!seen_from_below(&right, 0, Some(4.0)));
        assert!(seen_from_below(&right, 0, Some(5.0)));
        assert!(seen_from_below(&right, 2, Some(30.0)) && !seen_from_below(&right, 2, Some(4.0)));
        // Orthographic, or nothing picked: by the way it looks.
        let looking_down_z = at([4.0, 4.0, -20.0], Some(10.0));
        assert!(seen_from_below(&looking_down_z, 2, Some(100.0)) && !seen_from_below(&looking_down_z, 0, Some(0.0)));
        assert!(seen_from_below(&at([4.0, -9.0, 4.0], None), 1, None), "looking up");
    }
}
