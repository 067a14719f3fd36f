//! What lies under a pixel: the one CPU pick that the window's mouse and
//! replay's `click` share, walking the scene as the GPU draws it.

use glam::IVec3;

use super::instanced::Traced;
use super::{Footprint, Ray, TurnedFace, nearest_axis};
use crate::camera::Camera;
use crate::scene::Scene;
use crate::scene::transform::{Placing, TurnedMap};

/// What lies under a pixel: the world voxel and face a click names (the
/// voxel in world coordinates), its colour (0: the ground), and on a
/// freely turned object the model cell under the cursor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Picked {
    pub voxel: IVec3,
    pub normal: IVec3,
    pub value: u8,
    pub model: Option<ModelCell>,
}

/// A freely turned object's model cell hit and the face's normal, in the
/// model's own cells (as its .vox numbers them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ModelCell {
    pub object: usize,
    pub cell: IVec3,
    pub normal: IVec3,
}

impl Picked {
    /// The cell a selection starts or ends on: the voxel, or on the ground
    /// the cell on it.
    pub fn cell(&self) -> IVec3 {
        if self.value == 0 { self.voxel + self.normal } else { self.voxel }
    }

    /// The cell in front of the picked face: where a line drag starts or
    /// ends.
    pub fn in_front(&self) -> IVec3 {
        self.voxel + self.normal
    }
}

/// What lies under pixel (x, y) of a `size` view: the one CPU pick that the
/// window's mouse and replay's `click` share.
pub fn pick(scene: &Scene, camera: &Camera, size: (u32, u32), x: u32, y: u32) -> Result<Option<Picked>, GaveUp> {
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
    let world = Picked { voxel: hit.voxel + scene.origin(), normal: hit.normal, value: hit.value, model: None };
    Ok(Some(match (crossing.instance, hit.turned) {
        (Some(index), Some(face)) => through_turn(scene, index as usize, face, hit.value).unwrap_or(world),
        _ => world,
    }))
}

/// A hit on a freely turned object's model cell: the cell, and as world
/// cells the one the cell stands for and, as the normal, the step to the
/// one its neighbour across the face stands for. A world cell belongs to
/// the model cell whose turned cube holds its centre (`TurnedMap::invert`);
/// a model cell whose cube holds no centre (at 45° some do not) stands for
/// none, and the cell holding its turned centre stands in (a click edits
/// the model cell all the same: [`ModelCell`]).
fn through_turn(scene: &Scene, index: usize, face: TurnedFace, value: u8) -> Option<Picked> {
    let objects = scene.objects()?;
    let Placing::Turned(map) = objects.map(index) else { return None };
    let tree_origin = objects.models[objects.list()[index].placement.model].tree.origin();
    let cell = face.cell + tree_origin;
    let voxel = owned_cell(&map, cell);
    let step = owned_cell(&map, cell + face.cell_normal) - voxel;
    Some(Picked {
        voxel,
        normal: if step == IVec3::ZERO { nearest_axis(face.normal) } else { step },
        value,
        model: Some(ModelCell { object: index, cell, normal: face.cell_normal }),
    })
}

/// The world cell model cell `m` stands for: the one holding its turned
/// centre if that one's centre lies in `m`'s cube, else the nearest
/// neighbour of it that does, else the one holding its centre.
fn owned_cell(map: &TurnedMap, m: IVec3) -> IVec3 {
    let near = map.apply(m);
    (0..27)
        .map(|k| IVec3::new(k % 3 - 1, k / 3 % 3 - 1, k / 9 - 1))
        .filter(|&step| map.invert(near + step) == m)
        .min_by_key(|step| step.length_squared())
        .map_or(near, |step| near + step)
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
) -> Result<Option<Picked>, GaveUp> {
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
            Some(Picked { value: 0, voxel: land.cell, normal: IVec3::Y, model: None })
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
