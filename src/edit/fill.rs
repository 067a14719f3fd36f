//! Flood fill: the 6-connected region of voxels of one colour around a
//! voxel, recoloured as one undo step.

use std::collections::{HashSet, VecDeque};

use glam::IVec3;

use crate::edit::Edit;
use crate::scene::{EditError, Octree, Op, RegionError, Shape};

/// Most voxels one fill recolours; a larger region is refused before
/// anything changes.
pub const MAX_FILL_VOXELS: usize = 1 << 20;

/// The voxels 6-connected to `start` that have its colour (`start` included).
///
/// # Errors
/// No voxel at `start`, or a region of more than [`MAX_FILL_VOXELS`].
pub fn fill_region(tree: &Octree, start: IVec3) -> Result<Vec<IVec3>, EditError> {
    let value = tree.get(start);
    if value == 0 {
        return Err(RegionError::NothingToFill(start).into());
    }
    let steps = [IVec3::X, IVec3::NEG_X, IVec3::Y, IVec3::NEG_Y, IVec3::Z, IVec3::NEG_Z];
    connected(start, &steps, MAX_FILL_VOXELS, |p| tree.get(p) == value)
        .ok_or_else(|| RegionError::FillTooLarge { start, limit: MAX_FILL_VOXELS }.into())
}

/// The cells reachable from `start` (itself included, breadth first) by
/// `steps` through cells that `accept` holds for; `None` past `limit` cells.
/// Flood fill and extrude's face region.
pub(crate) fn connected(
    start: IVec3,
    steps: &[IVec3],
    limit: usize,
    accept: impl Fn(IVec3) -> bool,
) -> Option<Vec<IVec3>> {
    let mut seen = HashSet::from([start]);
    let mut queue = VecDeque::from([start]);
    let mut region = Vec::new();
    while let Some(p) = queue.pop_front() {
        region.push(p);
        if region.len() > limit {
            return None;
        }
        for step in steps {
            let next = p + *step;
            if accept(next) && seen.insert(next) {
                queue.push_back(next);
            }
        }
    }
    Some(region)
}

/// The edits of a fill with `color`: one paint per voxel of the region,
/// applied together as one undo step (`History::apply_group`).
///
/// # Errors
/// As [`fill_region`], and colour 0.
pub fn fill_edits(tree: &Octree, start: IVec3, color: u8) -> Result<Vec<Edit>, EditError> {
    if color == 0 {
        return Err(EditError::ZeroColor);
    }
    Ok(fill_region(tree, start)?
        .into_iter()
        .map(|p| Edit::Brush { shape: Shape::Voxel(p), op: Op::Paint(color) })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edit::History;
    use crate::scene::Scene;

    #[test]
    fn a_fill_is_one_step_and_a_huge_region_is_refused() {
        let mut scene = Scene::default();
        scene.apply_brush(&Shape::Box { min: IVec3::ZERO, max: IVec3::splat(3) }, Op::Place(2)).ok();
        scene.apply_brush(&Shape::Voxel(IVec3::new(9, 9, 9)), Op::Place(2)).ok();
        assert_eq!(fill_region(scene.drawn(), IVec3::ONE).map(|r| r.len()), Ok(64));
        let mut history = History::default();
        let edits = fill_edits(scene.drawn(), IVec3::ONE, 6).unwrap_or_default();
        history.apply_group(&mut scene, edits).unwrap();
        assert_eq!((scene.voxel(IVec3::ZERO), scene.voxel(IVec3::splat(9))), (6, 2));
        assert!(history.undo(&mut scene).unwrap());
        assert_eq!(scene.voxel(IVec3::splat(3)), 2);
        assert!(!history.can_undo(), "the fill was one step");
        assert!(fill_region(scene.drawn(), IVec3::splat(5)).is_err(), "nothing to fill from");
        let big = Shape::Box { min: IVec3::new(20, 0, 0), max: IVec3::new(147, 127, 64) };
        scene.apply_brush(&big, Op::Place(4)).ok();
        let before = scene.voxels().len();
        let err = fill_edits(scene.drawn(), IVec3::new(20, 0, 0), 9).unwrap_err();
        assert!(err.to_string().contains("more than 1048576 voxels"), "{err}");
        assert_eq!(scene.voxels().len(), before);
    }
}
