//! A model's hull: a few boxes of model cells whose convex hull holds all
//! its solid voxels, tighter than its one solid box. A freely turned object's scene
//! box is the box around its turned hull (`TurnedMap::cover_blocks`): a
//! turned solid box grows by its corners, which a round or thin model does
//! not fill, and the looser scene boxes cost the instance walk time.

use std::collections::HashSet;

use glam::IVec3;

use super::octree::Octree;

/// At most this many cells of one level are walked for a hull; only those
/// of its shell are kept, as turning them is per object and per frame played.
pub const HULL_BLOCKS: usize = 512;

impl Octree {
    /// Inclusive boxes of model cells, at most `max` of them, whose convex
    /// hull holds every solid voxel: of the non-empty cells of the finest
    /// level with no more than `max` of them, the [`shell`], each cut to the
    /// solid bounds. Empty for an empty tree.
    pub fn hull(&self, max: usize) -> Vec<(IVec3, IVec3)> {
        let Some((lo, hi)) = self.solid_bounds() else { return Vec::new() };
        let mut hull = vec![(lo, hi)];
        for level in (0..self.depth()).rev() {
            let Some(blocks) = self.blocks_at_most(level, max) else { break };
            let cells = blocks.into_iter().map(|(min, _, level)| (min, min + IVec3::splat((1 << level) - 1)));
            hull = shell(cells.collect()).map(|(min, max)| (min.max(lo), max.min(hi))).collect();
        }
        hull
    }
}

/// The cells of one level with a face open to no cell: a cell with a
/// neighbour across each of its six faces is never the farthest in any
/// direction (the neighbour along the direction's largest component
/// reaches farther), so it cannot widen a turned hull's box.
fn shell(cells: Vec<(IVec3, IVec3)>) -> impl Iterator<Item = (IVec3, IVec3)> {
    let mins: HashSet<IVec3> = cells.iter().map(|&(min, _)| min).collect();
    let open = move |&(min, max): &(IVec3, IVec3)| {
        let edge = max.x - min.x + 1;
        [IVec3::X, IVec3::NEG_X, IVec3::Y, IVec3::NEG_Y, IVec3::Z, IVec3::NEG_Z]
            .into_iter()
            .any(|step| !mins.contains(&(min + step * edge)))
    };
    cells.into_iter().filter(open)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball(radius: i32) -> Octree {
        let centre = IVec3::splat(radius);
        let voxels: Vec<(IVec3, u8)> = (0..=2 * radius)
            .flat_map(|z| (0..=2 * radius).flat_map(move |y| (0..=2 * radius).map(move |x| IVec3::new(x, y, z))))
            .filter(|p| (*p - centre).length_squared() <= radius * radius)
            .map(|p| (p, 1))
            .collect();
        Octree::from_voxels(&voxels).unwrap()
    }

    /// In every direction the hull reaches as far as the farthest voxel
    /// corner (so every turned box around it holds the model), it keeps to
    /// its count and the solid bounds, and a ball's hull leaves out its
    /// cube's empty corners and its inside.
    #[test]
    fn a_hull_reaches_as_far_as_the_voxels_in_every_direction() {
        let tree = ball(20);
        let hull = tree.hull(HULL_BLOCKS);
        let (lo, hi) = tree.solid_bounds().unwrap();
        assert!(!hull.is_empty() && hull.len() <= HULL_BLOCKS, "{} boxes", hull.len());
        assert!(hull.iter().all(|&(a, b)| a.cmpge(lo).all() && b.cmple(hi).all() && a.cmple(b).all()));
        // The farthest point of cells lo..=hi along d: a corner of their cube.
        let reach = |d: glam::DVec3, (a, b): (IVec3, IVec3)| {
            let (a, b) = (a.as_dvec3(), (b + IVec3::ONE).as_dvec3());
            d.x * if d.x > 0.0 { b.x } else { a.x }
                + d.y * if d.y > 0.0 { b.y } else { a.y }
                + d.z * if d.z > 0.0 { b.z } else { a.z }
        };
        for k in 0..200 {
            let (u, v) = (f64::from(k) * 0.7548, f64::from(k) * 0.5698);
            let d = glam::DVec3::new(u.cos() * v.sin(), u.sin() * v.sin(), v.cos());
            let hull_reach = hull.iter().map(|&b| reach(d, b)).fold(f64::MIN, f64::max);
            let mut voxel_reach = f64::MIN;
            tree.for_each_solid_cell(|min, edge, _| {
                voxel_reach = voxel_reach.max(reach(d, (min, min + IVec3::splat(edge - 1))));
            });
            assert!(hull_reach >= voxel_reach - 1e-9, "along {d}: hull {hull_reach}, voxels {voxel_reach}");
        }
        let inside = |p: IVec3| hull.iter().any(|&(a, b)| p.cmpge(a).all() && p.cmple(b).all());
        assert!(!inside(lo) && !inside(hi), "the cube's corners are empty");
        assert!(!inside(IVec3::splat(20)), "the ball's inside is no shell");
    }

    #[test]
    fn an_empty_tree_has_no_hull_and_one_voxel_a_box_of_itself() {
        assert!(Octree::empty(IVec3::ZERO, 4).hull(HULL_BLOCKS).is_empty());
        let p = IVec3::new(3, -2, 5);
        let one = Octree::from_voxels(&[(p, 9)]).unwrap();
        assert_eq!(one.hull(HULL_BLOCKS), [(p, p)]);
    }
}
