//! Building an octree in one pass: from a voxel list (Morton sort, then
//! bottom-up) or from a dense array (octants built in parallel, then merged).

use glam::{IVec3, UVec3};
use rayon::prelude::*;

use super::counts::VoxelCounts;
use super::octree::{MAX_DEPTH, MIN_DEPTH, Octree, octant_offset};
use super::lod::{self, Summary};
use crate::gpu_pool::{Brick, Node, NodeSlot, POINTER_BIT, is_pointer, pointer_to, slot_of};

/// Why a tree could not be built.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum BuildError {
    #[error("scene is {extent} voxels wide; the octree holds at most 2^{MAX_DEPTH}")]
    TooWide { extent: i64 },
    #[error("dense array holds {len} bytes but {dims} needs {needed}")]
    DenseSize { len: usize, dims: UVec3, needed: u64 },
}

/// Interleaves the low 21 bits of x, y, z: bit `3i` is x's bit i, `3i+1` y's, `3i+2` z's,
/// so three bits at a level are the octant `x | y << 1 | z << 2`.
pub fn morton(p: UVec3) -> u64 {
    spread(p.x) | spread(p.y) << 1 | spread(p.z) << 2
}

fn spread(v: u32) -> u64 {
    let mut x = u64::from(v) & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// Root level for a scene `extent` voxels wide.
fn depth_for(extent: i64) -> Result<u32, BuildError> {
    let depth = (extent.max(1) as u64).next_power_of_two().trailing_zeros().max(MIN_DEPTH);
    if depth > MAX_DEPTH { Err(BuildError::TooWide { extent }) } else { Ok(depth) }
}

impl Octree {
    /// Builds from solid voxels; a position listed twice keeps its last value.
    /// The root cube starts at the voxels' min corner.
    pub fn from_voxels(voxels: &[(IVec3, u8)]) -> Result<Octree, BuildError> {
        let Some((lo, hi)) = super::bounds_of(voxels.iter().filter(|v| v.1 != 0).map(|v| v.0)) else {
            return Ok(Octree::default());
        };
        let extent = (hi.as_i64vec3() - lo.as_i64vec3()).max_element() + 1;
        let mut tree = Octree::empty(lo, depth_for(extent)?);
        let mut keyed: Vec<(u64, u8)> =
            voxels.par_iter().filter(|v| v.1 != 0).map(|&(p, v)| (morton((p - lo).as_uvec3()), v)).collect();
        // Stable, so of two entries for one position the later stays later.
        keyed.par_sort_by_key(|k| k.0);
        let mut level: Vec<(u64, u32)> = Vec::with_capacity(keyed.len() / 2);
        let mut i = 0;
        while i < keyed.len() {
            let parent = keyed[i].0 >> 3;
            let mut values: Brick = [0; 8];
            while i < keyed.len() && keyed[i].0 >> 3 == parent {
                values[(keyed[i].0 & 7) as usize] = keyed[i].1;
                i += 1;
            }
            values.iter().for_each(|v| tree.counts.add(*v, 1));
            level.push((parent, tree.make_brick(values, None)));
        }
        for node_level in 2..=tree.depth {
            level = tree.build_level(&level, node_level);
        }
        tree.root = level.first().map_or(0, |l| l.1);
        Ok(tree)
    }

    /// Groups sorted (code, word) children by parent code into nodes of `level`.
    fn build_level(&mut self, children: &[(u64, u32)], level: u32) -> Vec<(u64, u32)> {
        let mut parents = Vec::with_capacity(children.len() / 4 + 1);
        let mut i = 0;
        while i < children.len() {
            let parent = children[i].0 >> 3;
            let mut node: Node = [0; 8];
            while i < children.len() && children[i].0 >> 3 == parent {
                node[(children[i].0 & 7) as usize] = children[i].1;
                i += 1;
            }
            parents.push((parent, self.make_node(node, level, None)));
        }
        parents
    }

    /// Builds from a dense array indexed `x + dims.x * (y + dims.y * z)`
    /// whose cell (0, 0, 0) sits at world `origin`. The root's eight octants
    /// are built in parallel into local arenas, then merged.
    pub fn from_dense(dims: UVec3, origin: IVec3, data: &[u8]) -> Result<Octree, BuildError> {
        let needed = u64::from(dims.x) * u64::from(dims.y) * u64::from(dims.z);
        if data.len() as u64 != needed {
            return Err(BuildError::DenseSize { len: data.len(), dims, needed });
        }
        let depth = depth_for(i64::from(dims.max_element()))?;
        let mut tree = Octree::empty(origin, depth);
        let grid = Dense { dims: dims.as_ivec3(), data };
        let half = 1 << (depth - 1);
        let parts: Vec<LocalArena> = (0..8)
            .into_par_iter()
            .map(|octant| {
                let mut local = LocalArena::default();
                local.root = local.build(&grid, octant_offset(octant) * half, depth - 1);
                local
            })
            .collect();
        let mut children: Node = [0; 8];
        for (octant, part) in parts.into_iter().enumerate() {
            tree.counts.add_counts(&part.counts);
            children[octant] = tree.adopt(part);
        }
        tree.root = tree.make_node(children, depth, None);
        Ok(tree)
    }

    /// Moves a local arena's slots into the pool, rewriting its pointers.
    fn adopt(&mut self, part: LocalArena) -> u32 {
        let node_base = self.pool.nodes.len() as u32;
        let brick_base = self.pool.bricks.len() as u32;
        let relocate = |w: u32| -> u32 {
            if !is_pointer(w) {
                w
            } else if w & LOCAL_BRICK != 0 {
                pointer_to((w & !(POINTER_BIT | LOCAL_BRICK)) + brick_base)
            } else {
                pointer_to(slot_of(w) + node_base)
            }
        };
        for brick in part.bricks {
            self.pool.bricks.alloc(brick);
        }
        for node in part.nodes {
            self.pool.nodes.alloc(NodeSlot { children: node.children.map(relocate), ..node });
        }
        relocate(part.root)
    }
}

/// Local-arena tag on brick pointers, so `adopt` can tell them from node pointers.
const LOCAL_BRICK: u32 = 0x4000_0000;

struct Dense<'a> {
    dims: IVec3,
    data: &'a [u8],
}

impl Dense<'_> {
    fn at(&self, p: IVec3) -> u8 {
        if p.cmplt(self.dims).all() { self.data[(p.x + self.dims.x * (p.y + self.dims.y * p.z)) as usize] } else { 0 }
    }
}

#[derive(Default)]
struct LocalArena {
    nodes: Vec<NodeSlot>,
    bricks: Vec<Brick>,
    root: u32,
    counts: VoxelCounts,
}

impl LocalArena {
    fn build(&mut self, grid: &Dense, min: IVec3, level: u32) -> u32 {
        if min.cmpge(grid.dims).any() {
            return 0;
        }
        if level == 1 {
            let values: Brick = std::array::from_fn(|o| grid.at(min + octant_offset(o)));
            values.iter().for_each(|v| self.counts.add(*v, 1));
            if values.iter().all(|v| *v == values[0]) {
                return u32::from(values[0]);
            }
            self.bricks.push(values);
            return pointer_to(self.bricks.len() as u32 - 1) | LOCAL_BRICK;
        }
        let half = 1 << (level - 1);
        let children: Node = std::array::from_fn(|o| self.build(grid, min + octant_offset(o) * half, level - 1));
        if !is_pointer(children[0]) && children.iter().all(|c| *c == children[0]) {
            return children[0];
        }
        let summary = lod::combine(children.map(|c| self.summary(c, level - 1)));
        self.nodes.push(NodeSlot { children, lod: summary.word() });
        pointer_to(self.nodes.len() as u32 - 1)
    }

    /// `Octree::summary` for this arena's local words.
    fn summary(&self, word: u32, level: u32) -> Summary {
        if !is_pointer(word) {
            Summary::uniform(word as u8)
        } else if level == 1 {
            Summary::of_brick(&self.bricks[(word & !(POINTER_BIT | LOCAL_BRICK)) as usize])
        } else {
            Summary::from_word(self.nodes[slot_of(word) as usize].lod)
        }
    }
}
