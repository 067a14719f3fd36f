//! Building an octree in one pass: from a voxel list (Morton sort, then
//! bottom-up) or from dense data (cubes built in parallel, then assembled).

use glam::{IVec3, UVec3};
use rayon::prelude::*;

use super::counts::VoxelCounts;
use super::lod::{self, Summary};
use super::octree::{MAX_DEPTH, MIN_DEPTH, Octree, octant_offset};
use crate::gpu_pool::{Brick, Node, NodeSlot, POINTER_BIT, is_pointer, pointer_to, slot_of};

/// Why a tree could not be built.
#[derive(Clone, Debug, thiserror::Error, PartialEq, Eq)]
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

    /// An empty tree whose root cube is placed as [`Octree::from_voxels`]
    /// places it for voxels spanning `lo..=hi`.
    ///
    /// # Errors
    /// [`BuildError::TooWide`] past the largest root.
    pub fn empty_for(lo: IVec3, hi: IVec3) -> Result<Octree, BuildError> {
        let extent = (hi.as_i64vec3() - lo.as_i64vec3()).max_element() + 1;
        Ok(Octree::empty(lo, depth_for(extent)?))
    }

    /// Sets the given voxels (inside the root cube; others are skipped), a
    /// position listed twice keeping its last value, in one pass down the
    /// tree: a loader adds the models of a file one at a time this way. Only
    /// the cells holding a voxel are visited; collapse and summaries are kept.
    pub fn insert_voxels(&mut self, voxels: &[(IVec3, u8)]) {
        let mut keyed: Vec<(u64, u8)> = voxels
            .iter()
            .filter(|(p, _)| self.contains(*p))
            .map(|&(p, v)| (morton((p - self.origin).as_uvec3()), v))
            .collect();
        // Stable, so of two entries for one position the later stays later.
        keyed.sort_by_key(|k| k.0);
        self.root = self.insert_sorted(self.root, self.depth, &keyed);
    }

    /// [`Octree::insert_voxels`] under one cell: `keyed` holds its voxels
    /// in Morton order (codes relative to the root).
    fn insert_sorted(&mut self, word: u32, level: u32, keyed: &[(u64, u8)]) -> u32 {
        if keyed.is_empty() {
            return word;
        }
        if level == 1 {
            let old: Brick = if is_pointer(word) { *self.brick(word) } else { [word as u8; 8] };
            let mut new = old;
            for &(code, value) in keyed {
                new[(code & 7) as usize] = value;
            }
            old.iter().for_each(|v| self.counts.remove(*v, 1));
            new.iter().for_each(|v| self.counts.add(*v, 1));
            return self.make_brick(new, is_pointer(word).then_some(word));
        }
        let node = if is_pointer(word) { word } else { self.split(word, level) };
        let mut children: Node = *self.node(node);
        let shift = 3 * (level - 1);
        let mut rest = keyed;
        for (octant, child) in children.iter_mut().enumerate() {
            let n = rest.partition_point(|k| (k.0 >> shift) & 7 == octant as u64);
            *child = self.insert_sorted(*child, level - 1, &rest[..n]);
            rest = &rest[n..];
        }
        self.make_node(children, level, Some(node))
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
    /// whose cell (0, 0, 0) sits at world `origin`: cubes of
    /// [`BLOCK_LEVEL`] built in parallel, then assembled.
    pub fn from_dense(dims: UVec3, origin: IVec3, data: &[u8]) -> Result<Octree, BuildError> {
        let needed = u64::from(dims.x) * u64::from(dims.y) * u64::from(dims.z);
        if data.len() as u64 != needed {
            return Err(BuildError::DenseSize { len: data.len(), dims, needed });
        }
        let mut builder = BlockBuilder::new(origin, dims)?;
        let grid = Dense { dims: dims.as_ivec3(), data };
        let blocks = builder.blocks_in(dims);
        let built: Vec<(UVec3, Block)> =
            blocks.into_par_iter().map(|b| (b, BlockBuilder::build_block(&grid, b, builder.block_level))).collect();
        for (coord, block) in built {
            builder.add(coord, block);
        }
        Ok(builder.finish())
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

/// Level of the cubes a block build makes: 64³ voxels, 256 KiB of dense
/// bytes per cube, small enough for a thread each and large enough that
/// assembling them is a small part of the work.
pub const BLOCK_LEVEL: u32 = 6;

/// An octree assembled from cubes of 2^`block_level` voxels built
/// separately (in parallel, in any order) from dense data: `from_dense`,
/// and the streaming voxelizer, which fills one column of cubes at a time.
pub struct BlockBuilder {
    tree: Octree,
    pub block_level: u32,
    /// (Morton code of the cube, its word), non-empty cubes only.
    words: Vec<(u64, u32)>,
}

/// One cube's subtree, not yet in the tree.
pub struct Block(LocalArena);

impl BlockBuilder {
    /// A builder for a block of `dims` voxels with its min corner at `origin`.
    ///
    /// # Errors
    /// [`BuildError::TooWide`] past the largest root.
    pub fn new(origin: IVec3, dims: UVec3) -> Result<BlockBuilder, BuildError> {
        let depth = depth_for(i64::from(dims.max_element()))?;
        let tree = Octree::empty(origin, depth);
        Ok(BlockBuilder { tree, block_level: BLOCK_LEVEL.min(depth), words: Vec::new() })
    }

    /// How many cubes cover `dims` voxels along each axis.
    pub fn cubes_across(&self, dims: UVec3) -> UVec3 {
        (dims - UVec3::ONE) / (1 << self.block_level) + UVec3::ONE
    }

    /// The cube coordinates covering `dims` voxels.
    pub fn blocks_in(&self, dims: UVec3) -> Vec<UVec3> {
        let n = self.cubes_across(dims);
        (0..n.z).flat_map(|z| (0..n.y).flat_map(move |y| (0..n.x).map(move |x| UVec3::new(x, y, z)))).collect()
    }

    /// Builds cube `coord` of `grid`, whose cell (0, 0, 0) is the cube
    /// grid's origin.
    pub fn build_block(grid: &impl VoxelSource, coord: UVec3, block_level: u32) -> Block {
        let mut local = LocalArena::default();
        local.root = local.build(grid, (coord << block_level).as_ivec3(), block_level);
        Block(local)
    }

    /// Puts a built cube into the tree (each cube once).
    pub fn add(&mut self, coord: UVec3, block: Block) {
        self.tree.counts.add_counts(&block.0.counts);
        let word = self.tree.adopt(block.0);
        if word != 0 {
            self.words.push((morton(coord), word));
        }
    }

    /// Assembles the levels above the cubes.
    pub fn finish(mut self) -> Octree {
        self.words.sort_unstable_by_key(|w| w.0);
        let mut level = std::mem::take(&mut self.words);
        for node_level in self.block_level + 1..=self.tree.depth {
            level = self.tree.build_level(&level, node_level);
        }
        self.tree.root = level.first().map_or(0, |l| l.1);
        self.tree
    }
}

/// Local-arena tag on brick pointers, so `adopt` can tell them from node pointers.
const LOCAL_BRICK: u32 = 0x4000_0000;

/// Voxels a block build reads: block coordinates from 0, empty past the data.
pub trait VoxelSource: Sync {
    /// The palette index at `p` (0 empty).
    fn at(&self, p: IVec3) -> u8;
    /// The value of the whole cube at `min`, `size` wide, when it is uniform
    /// and cheap to tell; `None` to look inside.
    fn uniform(&self, min: IVec3, size: i32) -> Option<u8>;
}

struct Dense<'a> {
    dims: IVec3,
    data: &'a [u8],
}

impl VoxelSource for Dense<'_> {
    fn at(&self, p: IVec3) -> u8 {
        if p.cmplt(self.dims).all() { self.data[(p.x + self.dims.x * (p.y + self.dims.y * p.z)) as usize] } else { 0 }
    }

    fn uniform(&self, min: IVec3, _size: i32) -> Option<u8> {
        min.cmpge(self.dims).any().then_some(0)
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
    fn build(&mut self, grid: &impl VoxelSource, min: IVec3, level: u32) -> u32 {
        if let Some(value) = grid.uniform(min, 1 << level) {
            self.counts.add(value, 1 << (3 * level));
            return u32::from(value);
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
        let brick = |w: u32| self.bricks[(w & !(POINTER_BIT | LOCAL_BRICK)) as usize];
        lod::of_word(word, level, brick, |w| self.nodes[slot_of(w) as usize].lod)
    }
}
