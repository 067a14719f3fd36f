//! Orbit, pan, zoom and fly on a plain [`Camera`] (eye + target). Angles are
//! in radians per pixel of mouse motion; distances scale with the distance to
//! the target so that small and huge scenes feel the same.

use glam::DVec3;

use octovox::camera::Camera;

/// Radians of orbit per pixel dragged.
const ORBIT_RAD_PER_PIXEL: f64 = 0.006;
/// Closest the eye may come to the target (voxels).
const MIN_DISTANCE: f64 = 0.5;
/// Fly speed in units of the current eye–target distance per second.
const FLY_DISTANCES_PER_SECOND: f64 = 0.6;

/// The camera's forward, right and up unit vectors.
fn frame(camera: &Camera) -> (DVec3, DVec3, DVec3) {
    let forward = (camera.target - camera.eye).try_normalize().unwrap_or(DVec3::NEG_Z);
    let world_up = if forward.y.abs() > 0.999 { DVec3::Z } else { DVec3::Y };
    let right = forward.cross(world_up).normalize();
    (forward, right, right.cross(forward))
}

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
    let (_, right, up) = frame(camera);
    let distance = (camera.target - camera.eye).length();
    let half_fov = f64::from(octovox::camera::clamp_fov(camera.fov_y_deg)).to_radians() * 0.5;
    let units_per_pixel = 2.0 * distance * half_fov.tan() / f64::from(height.max(1));
    let shift = (-right * dx + up * dy) * units_per_pixel;
    camera.eye += shift;
    camera.target += shift;
}

/// Moves the eye toward the target by wheel `steps` (positive = closer).
pub fn zoom(camera: &mut Camera, steps: f64) {
    let offset = camera.eye - camera.target;
    let distance = (offset.length() * 0.85_f64.powf(steps)).max(MIN_DISTANCE);
    camera.eye = camera.target + offset.normalize_or(DVec3::Z) * distance;
}

/// First-person move: `dir` is (right, up, forward) in -1..=1, `seconds` the
/// frame time.
pub fn fly(camera: &mut Camera, dir: DVec3, seconds: f64) {
    let (forward, right, _) = frame(camera);
    let distance = (camera.target - camera.eye).length().max(MIN_DISTANCE * 8.0);
    let step = (right * dir.x + DVec3::Y * dir.y + forward * dir.z) * distance * FLY_DISTANCES_PER_SECOND * seconds;
    camera.eye += step;
    camera.target += step;
}

/// A camera that shows the whole box `lo..=hi` (voxel corners), keeping the
/// current viewing direction when there is one.
pub fn frame_model(camera: &mut Camera, bounds: Option<(glam::IVec3, glam::IVec3)>) {
    let Some((lo, hi)) = bounds else { return };
    let framed = Camera::framing(lo, hi, camera.fov_y_deg);
    let distance = (framed.eye - framed.target).length();
    let back = (camera.eye - camera.target).try_normalize().unwrap_or((framed.eye - framed.target) / distance);
    camera.target = framed.target;
    camera.eye = framed.target + back * distance;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orbit_keeps_distance_and_target() {
        let mut camera =
            Camera { eye: DVec3::new(10.0, 5.0, 20.0), target: DVec3::new(1.0, 2.0, 3.0), fov_y_deg: 50.0 };
        let before = (camera.eye - camera.target).length();
        orbit(&mut camera, 120.0, -40.0);
        assert!(((camera.eye - camera.target).length() - before).abs() < 1e-9);
        assert_eq!(camera.target, DVec3::new(1.0, 2.0, 3.0));
        orbit(&mut camera, 0.0, 10_000.0);
        assert!(camera.eye.is_finite() && (camera.eye - camera.target).normalize().y < 1.0);
    }

    #[test]
    fn zoom_and_pan_move_as_expected() {
        let mut camera = Camera { eye: DVec3::new(0.0, 0.0, 10.0), target: DVec3::ZERO, fov_y_deg: 50.0 };
        zoom(&mut camera, 1.0);
        assert!((camera.eye.z - 8.5).abs() < 1e-9);
        zoom(&mut camera, -1000.0);
        assert!(camera.eye.is_finite());
        let mut camera = Camera { eye: DVec3::new(0.0, 0.0, 10.0), target: DVec3::ZERO, fov_y_deg: 50.0 };
        pan(&mut camera, 10.0, 0.0, 100);
        assert!(camera.target.x < 0.0 && (camera.eye - camera.target).z == 10.0);
    }
}
