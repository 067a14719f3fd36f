//! Orbit, pan, zoom and fly on a plain [`Camera`] (eye + target). Angles are
//! in radians per pixel of mouse motion; distances scale with the distance to
//! the target so that small and huge scenes feel the same.

use glam::DVec3;

use octovox::camera::Camera;

/// Radians of orbit per pixel dragged.
const ORBIT_RAD_PER_PIXEL: f64 = 0.006;
/// Closest the eye may come to the target (voxels).
const MIN_DISTANCE: f64 = 0.5;
/// Farthest a zoom takes the eye from the target (voxels).
const MAX_DISTANCE: f64 = 1.0e6;
/// Fly speed in units of the current eye–target distance per second.
const FLY_DISTANCES_PER_SECOND: f64 = 0.6;

/// Turns the eye around the target: `dx` pixels of yaw, `dy` of pitch. Pitch
/// stops just short of straight up or down so the view never flips.
pub fn orbit(camera: &mut Camera, dx: f64, dy: f64) {
    let offset = camera.eye - camera.target;
    let distance = offset.length().max(MIN_DISTANCE);
    let yaw = offset.z.atan2(offset.x) + dx * ORBIT_RAD_PER_PIXEL;
    let pitch = ((offset.y / distance).clamp(-1.0, 1.0).asin() + dy * ORBIT_RAD_PER_PIXEL).clamp(-1.55, 1.55);
    let dir = DVec3::new(pitch.cos() * yaw.cos(), pitch.sin(), pitch.cos() * yaw.sin());
    camera.eye = camera.target + dir * distance;
}

/// Slides eye and target together so the scene follows the mouse; `height`
/// is the view's height in pixels.
pub fn pan(camera: &mut Camera, dx: f64, dy: f64, height: u32) {
    let (_, right, up) = camera.axes();
    let units_per_pixel = camera.view_height() / f64::from(height.max(1));
    let shift = (-right * dx + up * dy) * units_per_pixel;
    camera.eye += shift;
    camera.target += shift;
}

/// How much one wheel notch scales the view: eight notches halve it.
const ZOOM_PER_STEP: f64 = 0.917;

/// Zooms by wheel `steps` (positive = closer) toward `toward`, the point
/// under the cursor, which stays where it is on screen (the target when
/// the cursor is over the sky): the camera is scaled about that point, and
/// an orthographic view's height with it.
pub fn zoom(camera: &mut Camera, steps: f64, toward: Option<DVec3>) {
    let distance = (camera.eye - camera.target).length().max(MIN_DISTANCE);
    // The eye stays MIN_DISTANCE..=MAX_DISTANCE from the target.
    let factor = ZOOM_PER_STEP.powf(steps).clamp(MIN_DISTANCE / distance, MAX_DISTANCE / distance);
    let center = toward.unwrap_or(camera.target);
    camera.eye = center + (camera.eye - center) * factor;
    camera.target = center + (camera.target - center) * factor;
    if let Some(height) = camera.ortho {
        let (lo, hi) = (octovox::camera::ORTHO_RANGE.start(), octovox::camera::ORTHO_RANGE.end());
        camera.ortho = Some((f64::from(height) * factor).clamp(f64::from(*lo), f64::from(*hi)) as f32);
    }
}

/// Switches between perspective and an orthographic view that shows what
/// the perspective one shows at the target.
pub fn toggle_projection(camera: &mut Camera) {
    let (lo, hi) = (octovox::camera::ORTHO_RANGE.start(), octovox::camera::ORTHO_RANGE.end());
    camera.ortho = match camera.ortho {
        Some(_) => None,
        None => Some((camera.view_height() as f32).clamp(*lo, *hi)),
    };
}

/// Looks at the target from the side `from` (a world axis: +z is the
/// front, +x the right, +y the top), at the same distance.
pub fn view_from(camera: &mut Camera, from: DVec3) {
    let distance = (camera.eye - camera.target).length().max(MIN_DISTANCE);
    camera.eye = camera.target + from.normalize_or(DVec3::Z) * distance;
}

/// First-person move: `dir` is (right, up, forward) in -1..=1, `seconds` the
/// frame time.
pub fn fly(camera: &mut Camera, dir: DVec3, seconds: f64) {
    let (forward, right, _) = camera.axes();
    let distance = (camera.target - camera.eye).length().max(MIN_DISTANCE * 8.0);
    let step = (right * dir.x + DVec3::Y * dir.y + forward * dir.z) * distance * FLY_DISTANCES_PER_SECOND * seconds;
    camera.eye += step;
    camera.target += step;
}

/// A camera that shows the whole box `lo..=hi` (voxel corners), keeping the
/// current viewing direction when there is one.
pub fn frame_model(camera: &mut Camera, bounds: Option<(glam::IVec3, glam::IVec3)>) {
    if let Some((lo, hi)) = bounds {
        *camera = camera.reframed(lo, hi);
    }
}

/// The camera a new document starts with: the default view (perspective,
/// from the front-right-top) with `fov_y_deg`, framing `bounds` (a file's
/// voxels, or a new scene's working volume) so that it fills the view, as
/// MagicaVoxel opens on its volume. Nothing of the last document's view
/// (an orthographic top view, say) carries over.
pub fn fresh_camera(fov_y_deg: f32, bounds: Option<(glam::IVec3, glam::IVec3)>) -> Camera {
    let mut camera = Camera { fov_y_deg, ..Camera::default() };
    frame_model(&mut camera, bounds);
    camera
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 47, item 7: a new scene showed its 32³ volume with voxels about
    /// 8 px wide (it framed a box twice the volume); an orthographic view
    /// carried over into the next file. The volume now spans most of the
    /// view's height, in perspective.
    #[test]
    fn a_new_scene_fills_the_view_with_its_volume_in_perspective() {
        let state = super::super::state::EditorState::default();
        let (lo, hi) = state.working_volume();
        let camera = fresh_camera(50.0, Some((lo, hi)));
        assert_eq!(camera.ortho, None);
        let (width, height) = (1280, 720);
        let basis = camera.basis(width, height, glam::IVec3::ZERO);
        let ys: Vec<f32> = (0..8)
            .map(|k| {
                let corner = glam::IVec3::new(k & 1, (k >> 1) & 1, (k >> 2) & 1);
                let p = (lo + corner * (hi - lo + glam::IVec3::ONE)).as_vec3();
                basis.project(p).expect("in front of the eye").1
            })
            .collect();
        let span = ys.iter().copied().fold(f32::MIN, f32::max) - ys.iter().copied().fold(f32::MAX, f32::min);
        assert!(span > 0.6 * height as f32, "the volume spans {span} of {height} px");
        let per_voxel = span / state.volume as f32;
        assert!(per_voxel > 12.0, "{per_voxel} px per voxel");
    }

    #[test]
    fn orbit_keeps_distance_and_target() {
        let mut camera = Camera {
            eye: DVec3::new(10.0, 5.0, 20.0),
            target: DVec3::new(1.0, 2.0, 3.0),
            fov_y_deg: 50.0,
            ortho: None,
        };
        let before = (camera.eye - camera.target).length();
        orbit(&mut camera, 120.0, -40.0);
        assert!(((camera.eye - camera.target).length() - before).abs() < 1e-9);
        assert_eq!(camera.target, DVec3::new(1.0, 2.0, 3.0));
        orbit(&mut camera, 0.0, 10_000.0);
        assert!(camera.eye.is_finite() && (camera.eye - camera.target).normalize().y < 1.0);
    }

    #[test]
    fn zoom_and_pan_move_as_expected() {
        let mut camera = Camera { eye: DVec3::new(0.0, 0.0, 10.0), target: DVec3::ZERO, fov_y_deg: 50.0, ortho: None };
        zoom(&mut camera, 1.0, None);
        assert!((camera.eye.z - 10.0 * ZOOM_PER_STEP).abs() < 1e-9);
        zoom(&mut camera, -1000.0, None);
        assert!(((camera.eye - camera.target).length() - MAX_DISTANCE).abs() < 1e-3, "{camera:?}");
        zoom(&mut camera, 2000.0, None);
        assert!(((camera.eye - camera.target).length() - MIN_DISTANCE).abs() < 1e-6, "{camera:?}");
        let mut camera = Camera { eye: DVec3::new(0.0, 0.0, 10.0), target: DVec3::ZERO, fov_y_deg: 50.0, ortho: None };
        pan(&mut camera, 10.0, 0.0, 100);
        assert!(camera.target.x < 0.0 && (camera.eye - camera.target).z == 10.0);
    }

    /// Zooming toward the point under the cursor keeps that point on the
    /// same pixel, in perspective and orthographic views.
    #[test]
    fn zoom_toward_a_point_keeps_it_under_the_cursor() {
        let point = DVec3::new(3.0, 1.0, -2.0);
        for ortho in [None, Some(30.0)] {
            let mut camera = Camera { eye: DVec3::new(20.0, 15.0, 25.0), target: DVec3::ZERO, fov_y_deg: 50.0, ortho };
            let pixel = |c: &Camera| c.basis(200, 100, glam::IVec3::ZERO).project(point.as_vec3()).unwrap();
            let before = pixel(&camera);
            zoom(&mut camera, 3.0, Some(point));
            let after = pixel(&camera);
            assert!((before.0 - after.0).abs() < 1e-3 && (before.1 - after.1).abs() < 1e-3, "{before:?} {after:?}");
            if let Some(height) = camera.ortho {
                assert!((f64::from(height) - 30.0 * ZOOM_PER_STEP.powi(3)).abs() < 1e-3);
            }
        }
    }

    #[test]
    fn a_switch_of_projection_keeps_the_view_height() {
        let mut camera = Camera { eye: DVec3::new(0.0, 0.0, 10.0), target: DVec3::ZERO, fov_y_deg: 90.0, ortho: None };
        toggle_projection(&mut camera);
        assert!((camera.ortho.unwrap() - 20.0).abs() < 1e-4, "{camera:?}");
        toggle_projection(&mut camera);
        assert_eq!(camera.ortho, None);
        view_from(&mut camera, DVec3::Y);
        assert!((camera.eye - DVec3::new(0.0, 10.0, 0.0)).length() < 1e-9);
    }
}
