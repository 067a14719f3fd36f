//! What lies under a pixel: the one CPU pick that the window's mouse and
//! replay's `click` share, walking the scene as the GPU draws it.

use super::instanced::Traced;
use super::{Footprint, Hit, Ray};
use crate::camera::Camera;
use crate::scene::Scene;

/// The voxel and face under pixel (x, y) of a `size` view, with the voxel in
/// world coordinates: the one CPU pick that the window's mouse and replay's
/// `click` share.
pub fn pick(scene: &Scene, camera: &Camera, size: (u32, u32), x: u32, y: u32) -> Result<Option<Hit>, GaveUp> {
    let basis = camera.basis(size.0, size.1, scene.origin());
    let (origin, dir) = basis.ray(x, y);
    let hit = Traced::of(scene).trace(&Ray::new(origin, dir), Footprint::EXACT);
    if hit.gave_up() {
        return Err(GaveUp { iterations: hit.iterations });
    }
    Ok(hit.is_hit().then(|| Hit { voxel: hit.voxel + scene.origin(), ..hit }))
}

/// [`pick`], and where `ground` is on and the ray comes down through the
/// plane y = 0 before it meets a voxel (none, or one below the plane, which
/// the drawn ground hides), the ground: the cell under the plane where the
/// ray crosses it (value 0, normal +y: Attach places on (x, 0, z)). The
/// ground of an empty scene is what a first click builds on.
pub fn pick_with_ground(
    scene: &Scene,
    camera: &Camera,
    size: (u32, u32),
    (x, y): (u32, u32),
    ground: bool,
) -> Result<Option<Hit>, GaveUp> {
    let hit = pick(scene, camera, size, x, y)?;
    if !ground {
        return Ok(hit);
    }
    // The rule the drawn ground follows (`ground::landing`), in world cells.
    let (origin, dir) = camera.basis(size.0, size.1, glam::IVec3::ZERO).ray(x, y);
    let landing = super::ground::landing(&Ray::new(origin, dir), 0, hit.map(|h| h.voxel));
    let cells = -(crate::scene::octree::WORLD_LIMIT - 1)..crate::scene::octree::WORLD_LIMIT - 1;
    Ok(match landing {
        Some(land) if cells.contains(&land.cell.x) && cells.contains(&land.cell.z) => {
            Some(Hit { value: 0, voxel: land.cell, normal: glam::IVec3::Y, ..Hit::default() })
        }
        _ => hit,
    })
}

/// A pick whose ray ran out of iterations: what lies under the pixel is
/// unknown, which is not the same as nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the ray under the cursor gave up after {iterations} steps without reaching a voxel or leaving the scene")]
pub struct GaveUp {
    pub iterations: u32,
}
