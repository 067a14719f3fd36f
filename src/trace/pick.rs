//! What lies under a pixel: the one CPU pick that the window's mouse and
//! replay's `click` share, walking the scene as the GPU draws it.

use glam::IVec3;

use super::instanced::Traced;
use super::{Footprint, Hit, Ray, TurnedFace};
use crate::camera::Camera;
use crate::scene::Scene;
use crate::scene::transform::{Placing, TurnedMap};

/// The voxel and face under pixel (x, y) of a `size` view, with the voxel in
/// world coordinates: the one CPU pick that the window's mouse and replay's
/// `click` share.
pub fn pick(scene: &Scene, camera: &Camera, size: (u32, u32), x: u32, y: u32) -> Result<Option<Hit>, GaveUp> {
    let basis = camera.basis(size.0, size.1, scene.origin());
    let (origin, dir) = basis.ray(x, y);
    let crossing = Traced::of(scene).trace_through(&Ray::new(origin, dir), 0, None, Footprint::EXACT);
    let hit = crossing.hit;
    if hit.gave_up() {
        return Err(GaveUp { iterations: hit.iterations });
    }
    if !hit.is_hit() {
        return Ok(None);
    }
    let world = Hit { voxel: hit.voxel + scene.origin(), ..hit };
    Ok(Some(match (crossing.instance, hit.turned) {
        (Some(index), Some(face)) => through_turn(scene, index as usize, face).map_or(world, |(voxel, normal)| Hit {
            voxel,
            normal: if normal == IVec3::ZERO { hit.normal } else { normal },
            ..world
        }),
        _ => world,
    }))
}

/// A hit on a freely turned object's model cell as the world cells edits
/// go through: the one its cell owns, and as the normal the step to the
/// one its neighbour across the face owns (so Attach lands there). A
/// world cell belongs to the model cell whose turned cube holds its centre
/// (`TurnedMap::invert`); a model cell whose cube holds no centre (at 45°
/// some do not) owns none, and the cell holding its turned centre stands in.
fn through_turn(scene: &Scene, index: usize, face: TurnedFace) -> Option<(IVec3, IVec3)> {
    let objects = scene.objects()?;
    let Placing::Turned(map) = objects.map(index) else { return None };
    let tree_origin = objects.models[objects.list()[index].placement.model].tree.origin();
    let cell = face.cell + tree_origin;
    let voxel = owned_cell(&map, cell);
    Some((voxel, owned_cell(&map, cell + face.cell_normal) - voxel))
}

/// The world cell model cell `m` owns: the one holding its turned centre
/// if that one's centre lies in `m`'s cube, else the nearest neighbour of
/// it that does, else the one holding its centre.
fn owned_cell(map: &TurnedMap, m: IVec3) -> IVec3 {
    let near = map.apply(m);
    let mut steps: Vec<IVec3> = (0..27).map(|k| IVec3::new(k % 3 - 1, k / 3 % 3 - 1, k / 9 - 1)).collect();
    steps.sort_by_key(|s| s.length_squared());
    steps.into_iter().map(|s| near + s).find(|&w| map.invert(w) == m).unwrap_or(near)
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
    let (origin, dir) = camera.basis(size.0, size.1, IVec3::ZERO).ray(x, y);
    let landing = super::ground::landing(&Ray::new(origin, dir), 0, hit.map(|h| h.voxel));
    let cells = -(crate::scene::octree::WORLD_LIMIT - 1)..crate::scene::octree::WORLD_LIMIT - 1;
    Ok(match landing {
        Some(land) if cells.contains(&land.cell.x) && cells.contains(&land.cell.z) => {
            Some(Hit { value: 0, voxel: land.cell, normal: IVec3::Y, ..Hit::default() })
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
