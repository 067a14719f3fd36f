//! Extrude (MagicaVoxel's face tool): the connected, coplanar region of
//! faces facing one way, pushed out by whole layers or pulled in, as one
//! undo step.

use glam::IVec3;

use super::fill::connected;
use crate::edit::Edit;
use crate::scene::shape::MAX_BRUSH_EXTENT;
use crate::scene::{EditError, Octree, Op, RegionError, Shape};

/// Most faces one extrude moves; a larger region is refused before anything
/// changes.
pub const MAX_EXTRUDE_FACES: usize = 1 << 20;

/// Whether voxel `p` shows a face toward `normal`: solid, with an empty
/// voxel in front.
fn shows_face(tree: &Octree, p: IVec3, normal: IVec3) -> bool {
    tree.get(p) != 0 && tree.get(p + normal) == 0
}

/// The voxels whose faces toward `normal` are connected (through edges, in
/// their plane) to the face of `start`, with their colours.
///
/// # Errors
/// A normal that is not one axis direction, no face at `start`, or more
/// than [`MAX_EXTRUDE_FACES`] faces.
pub fn face_region(tree: &Octree, start: IVec3, normal: IVec3) -> Result<Vec<(IVec3, u8)>, EditError> {
    if normal.abs().element_sum() != 1 {
        return Err(RegionError::NotAnAxis(normal).into());
    }
    if !shows_face(tree, start, normal) {
        return Err(RegionError::NoFace { voxel: start, normal }.into());
    }
    let in_plane: Vec<IVec3> = [IVec3::X, IVec3::Y, IVec3::Z]
        .into_iter()
        .filter(|axis| axis.dot(normal) == 0)
        .flat_map(|axis| [axis, -axis])
        .collect();
    let region = connected(start, &in_plane, MAX_EXTRUDE_FACES, |p| shows_face(tree, p, normal))
        .ok_or(RegionError::FaceTooLarge { start, limit: MAX_EXTRUDE_FACES })?;
    Ok(region.into_iter().map(|p| (p, tree.get(p))).collect())
}

/// The edits of an extrude by `layers` (> 0 pushes out, each new voxel the
/// colour of the face it grows from; < 0 pulls in, removing the face's voxel
/// and the ones behind it), applied together as one undo step.
///
/// # Errors
/// As [`face_region`], and 0 layers or more than the brush extent.
pub fn extrude_edits(tree: &Octree, start: IVec3, normal: IVec3, layers: i32) -> Result<Vec<Edit>, EditError> {
    if layers == 0 || layers.abs() > MAX_BRUSH_EXTENT {
        return Err(RegionError::ExtrudeLayers { layers, limit: MAX_BRUSH_EXTENT }.into());
    }
    let edits = face_region(tree, start, normal)?.into_iter().map(|(p, color)| {
        let (a, b, op) = if layers > 0 {
            (p + normal, p + normal * layers, Op::Place(color))
        } else {
            (p, p + normal * (layers + 1), Op::Remove)
        };
        Edit::Brush { shape: Shape::Box { min: a.min(b), max: a.max(b) }, op }
    });
    Ok(edits.collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_connected_coplanar_faces_move() {
        let mut tree = Octree::default();
        // A 4×1×4 slab and, on top of it, a 2×1×2 step: the slab's top face
        // is the ring around the step, the step's top is another plane.
        tree.apply_brush(&Shape::Box { min: IVec3::ZERO, max: IVec3::new(3, 0, 3) }, Op::Place(2)).ok();
        tree.apply_brush(&Shape::Box { min: IVec3::new(1, 1, 1), max: IVec3::new(2, 1, 2) }, Op::Place(5)).ok();
        assert_eq!(face_region(&tree, IVec3::ZERO, IVec3::Y).map(|r| r.len()), Ok(12));
        assert_eq!(face_region(&tree, IVec3::new(1, 1, 1), IVec3::Y).map(|r| r.len()), Ok(4));
        assert!(face_region(&tree, IVec3::new(1, 0, 1), IVec3::Y).is_err(), "covered: no face");
        assert!(face_region(&tree, IVec3::ZERO, IVec3::new(1, 1, 0)).is_err());
        assert!(extrude_edits(&tree, IVec3::ZERO, IVec3::Y, 0).is_err());
    }

    #[test]
    fn an_extrude_past_the_world_is_refused_and_changes_nothing() {
        use crate::edit::History;
        let mut scene = crate::scene::Scene::default();
        let edge = IVec3::new(crate::scene::octree::WORLD_LIMIT - 3, 0, 0);
        for x in 0..3 {
            scene.apply_brush(&Shape::Voxel(edge + IVec3::new(0, 0, x)), Op::Place(4)).ok();
        }
        let before = scene.voxels();
        let edits = extrude_edits(scene.drawn(), edge, IVec3::X, 10).unwrap_or_default();
        assert_eq!(edits.len(), 3);
        let mut history = History::default();
        assert!(history.apply_group(&mut scene, edits).is_err());
        assert_eq!(scene.voxels(), before);
        assert!(!history.can_undo());
    }
}
