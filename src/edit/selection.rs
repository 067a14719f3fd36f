//! Box selection and its clipboard: the voxels of an inclusive box, copied
//! as runs of one colour along x, and put back anywhere as one group of
//! edits (paste, move). Cut, delete and move clear the box with one box
//! brush, so they cost the same whatever the box holds.

use glam::IVec3;

use crate::edit::Edit;
use crate::scene::shape::MAX_BRUSH_EXTENT;
use crate::scene::transform::CellMap;
use crate::scene::{EditError, Octree, Op, RegionError, Shape};

/// Most voxels one copy holds (16 Mi).
pub const MAX_CLIPBOARD_VOXELS: u64 = 1 << 24;

/// Peak bytes a copied voxel may take at worst (each its own run): the
/// clipped cell, its run, and the edit and undo patch a paste makes of it.
const BYTES_PER_COPIED_VOXEL: u64 = 160;

/// An inclusive box of cells, `min` ≤ `max` on every axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Region {
    pub min: IVec3,
    pub max: IVec3,
}

impl Region {
    /// The box with corners `a` and `b` (in any order), both included.
    ///
    /// # Errors
    /// A box wider than a brush may be ([`MAX_BRUSH_EXTENT`]): clearing it
    /// is one box brush.
    pub fn new(a: IVec3, b: IVec3) -> Result<Region, EditError> {
        let region = Region { min: a.min(b), max: a.max(b) };
        if (region.max - region.min).max_element() >= MAX_BRUSH_EXTENT {
            let (min, max) = (region.min, region.max);
            return Err(RegionError::SelectionTooWide { min, max, limit: MAX_BRUSH_EXTENT }.into());
        }
        Ok(region)
    }

    /// Cells per axis.
    pub fn size(&self) -> IVec3 {
        self.max - self.min + IVec3::ONE
    }

    pub fn shifted(&self, by: IVec3) -> Region {
        Region { min: self.min + by, max: self.max + by }
    }

    /// The box turned a quarter about `axis` (`flip`: mirrored along it)
    /// about its centre, and the map from cells of this box (relative to
    /// its min corner) to cells of the new one. A turned box whose two
    /// sizes differ by an odd count cannot keep its centre exactly: it
    /// moves half a cell away from it, and turning back returns it.
    pub fn turned(&self, axis: usize, flip: bool) -> (Region, CellMap) {
        let size = self.size();
        let (map, new_size) = if flip {
            (CellMap::flip_in(axis, size), size)
        } else {
            let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut turned = size;
            (turned[a], turned[b]) = (size[b], size[a]);
            (CellMap::quarter_turn_in(axis, size), turned)
        };
        // Half the size change, rounded away from zero: a turn and the turn
        // back shift the box by opposite amounts.
        let d = size - new_size;
        let min = self.min + (d + d.signum()) / 2;
        (Region { min, max: min + new_size - IVec3::ONE }, map)
    }

    /// The box as it may be placed: inside the world's limits.
    ///
    /// # Errors
    /// [`EditError::OutsideWorld`], as an edit there would get.
    pub fn inside_world(self) -> Result<Region, EditError> {
        let limit = crate::scene::octree::WORLD_LIMIT;
        if self.min.min_element() <= -limit || self.max.max_element() >= limit {
            return Err(EditError::OutsideWorld { min: self.min, max: self.max });
        }
        Ok(self)
    }

    /// The edit that empties the box.
    pub fn clear_edit(&self) -> Edit {
        Edit::Clear { min: self.min, max: self.max }
    }
}

/// An inclusive box of voxels of one colour: a run along x as copied, a
/// run along another axis once turned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Run {
    min: IVec3,
    max: IVec3,
    color: u8,
}

/// Copied voxels, relative to the copied box's min corner.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Block {
    /// The copied box's size (empty cells included).
    pub size: IVec3,
    runs: Vec<Run>,
    voxels: u64,
}

impl Block {
    /// Solid voxels it holds.
    pub fn voxels(&self) -> u64 {
        self.voxels
    }

    /// The region it covers when its min corner is at `at`.
    pub fn region_at(&self, at: IVec3) -> Region {
        Region { min: at, max: at + self.size - IVec3::ONE }
    }

    /// The edits that place its voxels with its min corner at `at`; the
    /// empty cells of the block leave the scene as it is.
    pub fn place_edits(&self, at: IVec3) -> Vec<Edit> {
        self.runs
            .iter()
            .map(|run| Edit::Brush {
                shape: Shape::Box { min: at + run.min, max: at + run.max },
                op: Op::Place(run.color),
            })
            .collect()
    }

    /// The block with its cells taken through `map` (a turn or a mirror
    /// image of its box, [`Region::turned`]), whose box is `size`.
    pub fn mapped(&self, map: &CellMap, size: IVec3) -> Block {
        let runs = self
            .runs
            .iter()
            .map(|run| {
                let (min, max) = map.apply_box(run.min, run.max);
                Run { min, max, color: run.color }
            })
            .collect();
        Block { size, runs, voxels: self.voxels }
    }
}

/// The solid voxels of `region`, as a block.
///
/// # Errors
/// More than [`MAX_CLIPBOARD_VOXELS`] voxels, counted before any is copied.
pub fn copy(tree: &Octree, region: Region) -> Result<Block, EditError> {
    // The tree's uniform cells clipped to the box, as (min, max) and colour.
    let mut pieces = Vec::new();
    let mut voxels = 0u64;
    tree.for_each_solid_cell_in(region.min, region.max, |min, size, color| {
        let (lo, hi) = (min.max(region.min), (min + IVec3::splat(size - 1)).min(region.max));
        if lo.cmple(hi).all() {
            voxels += (hi - lo + IVec3::ONE).as_u64vec3().element_product();
            if voxels <= MAX_CLIPBOARD_VOXELS {
                pieces.push((lo, hi, color));
            }
        }
    });
    if voxels > MAX_CLIPBOARD_VOXELS {
        return Err(RegionError::ClipboardTooLarge { voxels, limit: MAX_CLIPBOARD_VOXELS }.into());
    }
    let pieces_count = pieces.len() as u64;
    crate::budget::check(
        || format!("copying {voxels} voxels in {pieces_count} cells"),
        pieces_count.saturating_mul(BYTES_PER_COPIED_VOXEL),
    )?;
    let mut runs: Vec<Run> = pieces
        .into_iter()
        .flat_map(|(lo, hi, color)| {
            (lo.z..=hi.z).flat_map(move |z| {
                (lo.y..=hi.y).map(move |y| Run {
                    min: IVec3::new(lo.x, y, z) - region.min,
                    max: IVec3::new(hi.x, y, z) - region.min,
                    color,
                })
            })
        })
        .collect();
    runs.sort_unstable_by_key(|r| (r.min.z, r.min.y, r.min.x));
    // Neighbouring cells of one colour on a row become one run.
    runs.dedup_by(|next, run| {
        let joins = next.min == run.max + IVec3::X && next.color == run.color;
        if joins {
            run.max = next.max;
        }
        joins
    });
    Ok(Block { size: region.size(), runs, voxels })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copied_runs_hold_exactly_the_boxed_voxels() {
        let mut tree = Octree::default();
        tree.apply_brush(&Shape::Box { min: IVec3::ZERO, max: IVec3::splat(9) }, Op::Place(3)).unwrap();
        tree.apply_brush(&Shape::Voxel(IVec3::new(5, 5, 5)), Op::Place(7)).unwrap();
        let region = Region::new(IVec3::splat(8), IVec3::new(2, 4, 5)).unwrap();
        assert_eq!(region.min, IVec3::new(2, 4, 5));
        let block = copy(&tree, region).unwrap();
        assert_eq!(block.voxels(), 7 * 5 * 4);
        let mut pasted = Octree::default();
        for edit in block.place_edits(IVec3::new(100, 0, 0)) {
            let Edit::Brush { shape, op } = edit else { unreachable!() };
            pasted.apply_brush(&shape, op).unwrap();
        }
        assert_eq!(pasted.solid_voxels(), 140);
        assert_eq!(pasted.get(IVec3::new(103, 1, 0)), 7);
        assert_eq!(pasted.get(IVec3::new(100, 0, 0)), 3);
        assert_eq!(pasted.get(IVec3::new(106, 4, 3)), 3);
        // Rows of one colour merge into one run each; the 7 splits its row in three.
        assert_eq!(block.runs.len(), 5 * 4 + 2);
    }

    #[test]
    fn an_over_wide_selection_is_refused() {
        assert!(Region::new(IVec3::ZERO, IVec3::new(MAX_BRUSH_EXTENT, 0, 0)).is_err());
    }
}
