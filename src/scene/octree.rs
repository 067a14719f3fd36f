//! The CPU sparse voxel octree: an arena of nodes and bricks (the [`NodePool`])
//! under one root word.
//!
//! A cell of level `l` is a cube of `2^l` voxels. Its content is one child
//! word (see [`crate::gpu_pool`]): a uniform palette index (0 = empty) or a
//! pointer. A pointer at level 1 is a brick of 2×2×2 voxels; at level ≥ 2 it
//! is a node of eight level `l - 1` cells. Uniform regions always collapse:
//! no node holds eight equal uniform words and no brick eight equal values,
//! so the tree for a given set of voxels is unique.

use glam::IVec3;

use super::counts::VoxelCounts;
use super::lod::{self, Summary};
use crate::gpu_pool::{self, Brick, Node, NodePool, NodeSlot, is_pointer, pointer_to, slot_of};

/// What is wrong with a tree put together from outside (a .ovx file's
/// pool), or broken by a bug (the invariants tests check after every edit).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TreeError {
    #[error("its root cube at {0} reaches past the coordinate limit ±{WORLD_LIMIT} (±2^24)")]
    RootTooFar(IVec3),
    #[error("root depth {0} is outside {MIN_DEPTH}..={MAX_DEPTH}")]
    Depth(u32),
    #[error(
        "it holds voxels at {lo}..{hi}, past the coordinate limit ±{WORLD_LIMIT} (±2^24) that edits and rendering keep exact"
    )]
    VoxelsTooFar { lo: IVec3, hi: IVec3 },
    #[error("bad cell word {0:#x}")]
    BadWord(u32),
    #[error("pointer below level 1")]
    PointerInBrick,
    #[error("{what} {slot} is free but referenced")]
    FreeReferenced { what: &'static str, slot: u32 },
    #[error("{what} {slot} is past the {stored} stored")]
    PastStored { what: &'static str, slot: u32, stored: usize },
    #[error("{what} {slot} is used twice")]
    UsedTwice { what: &'static str, slot: u32 },
    #[error("{0} stored nodes or bricks are not in the tree")]
    Unused(usize),
    #[error("uncollapsed brick {0:?}")]
    UncollapsedBrick(Brick),
    #[error("uncollapsed node {node:?} at level {level}")]
    UncollapsedNode { node: Node, level: u32 },
    #[error("stale summary {summary:?} of node {slot} at level {level}")]
    StaleSummary { summary: Summary, slot: u32, level: u32 },
    #[error("reachable nodes/bricks {reached:?} != live {live:?}")]
    Leaked { reached: (usize, usize), live: (usize, usize) },
    #[error("cached voxel counts {cached} != counted {counted}")]
    Counts { cached: u64, counted: u64 },
}

/// Smallest root: a 4³ cube (the root is then a node of bricks).
pub const MIN_DEPTH: u32 = 2;
/// Largest root: 2^20 voxels per side; edits beyond it are refused.
pub const MAX_DEPTH: u32 = 20;
/// World coordinates must stay within ±2^24 so they are exact in f32.
pub const WORLD_LIMIT: i32 = 1 << 24;

/// The most loop iterations a ray may take in a tree `2^depth` voxels wide
/// (SVO and grid alike), chosen so that no valid ray reaches it.
///
/// Every iteration of the SVO loop descends a level, steps across a plane
/// into the next cell, or ends the ray. Inside the root a ray crosses at most
/// 3·2^depth planes (2^depth per axis), and after each crossing, or at the
/// start, it descends at most `depth` levels (a pop goes straight to the
/// common ancestor; the GPU's restart from the root re-descends at most
/// `depth` levels too). So a ray takes at most (3·2^depth + 1)·(depth + 1)
/// iterations. The grid DDA inside the same cube takes at most 3·2^depth + 1.
/// A ray that reaches the bound is a bug; it is reported as a give-up,
/// never as a miss.
pub fn iteration_bound(depth: u32) -> u32 {
    let planes = 3u64 << depth.min(40);
    let bound = (planes + 1) * (u64::from(depth) + 1);
    u32::try_from(bound).unwrap_or(u32::MAX)
}

/// Octant index of child offset bits: `x | y << 1 | z << 2`.
pub fn octant_offset(octant: usize) -> IVec3 {
    IVec3::new((octant & 1) as i32, ((octant >> 1) & 1) as i32, ((octant >> 2) & 1) as i32)
}

/// A sparse voxel octree over palette indices.
#[derive(Clone, Debug)]
pub struct Octree {
    pub(crate) pool: NodePool,
    pub(crate) root: u32,
    pub(crate) origin: IVec3,
    pub(crate) depth: u32,
    /// Voxels per palette index, kept by builds and edits.
    pub(crate) counts: VoxelCounts,
}

impl Default for Octree {
    fn default() -> Octree {
        Octree::empty(IVec3::ZERO, MIN_DEPTH)
    }
}

impl Octree {
    /// An empty tree whose root cube starts at `origin` with `2^depth` voxels per side.
    pub fn empty(origin: IVec3, depth: u32) -> Octree {
        Octree {
            pool: NodePool::default(),
            root: 0,
            origin,
            depth: depth.clamp(MIN_DEPTH, MAX_DEPTH),
            counts: VoxelCounts::default(),
        }
    }

    pub fn pool(&self) -> &NodePool {
        &self.pool
    }

    pub fn pool_mut(&mut self) -> &mut NodePool {
        &mut self.pool
    }

    /// The root child word (uniform value or pointer to a node).
    pub fn root_word(&self) -> u32 {
        self.root
    }

    /// Min corner of the root cube.
    pub fn origin(&self) -> IVec3 {
        self.origin
    }

    /// Level of the root: the root cube is `2^depth` voxels wide.
    pub fn depth(&self) -> u32 {
        self.depth
    }

    pub fn size(&self) -> i32 {
        1 << self.depth
    }

    /// Number of solid voxels.
    pub fn solid_voxels(&self) -> u64 {
        self.counts.solid()
    }

    /// Voxels per palette index.
    pub fn counts(&self) -> &VoxelCounts {
        &self.counts
    }

    /// Replaces the count of a cell's old content by its new content's.
    pub(crate) fn recount(&mut self, old: u32, new: u32, level: u32) {
        self.counts.remove_word(&self.pool, old, level);
        self.counts.add_word(&self.pool, new, level);
    }

    pub fn node_count(&self) -> usize {
        self.pool.nodes.live()
    }

    pub fn brick_count(&self) -> usize {
        self.pool.bricks.live()
    }

    pub(crate) fn node(&self, word: u32) -> &Node {
        &self.pool.nodes.get(slot_of(word)).children
    }

    /// What the cell of child word `word` at `level` looks like from far away.
    pub fn summary(&self, word: u32, level: u32) -> Summary {
        lod::of_word(word, level, |w| *self.brick(w), |w| self.pool.nodes.get(slot_of(w)).lod)
    }

    /// A node slot for children of a `level` node, with their summary.
    fn node_slot(&self, children: Node, level: u32) -> NodeSlot {
        let summary = lod::combine(children.map(|c| self.summary(c, level - 1)));
        NodeSlot { children, lod: summary.word() }
    }

    pub(crate) fn brick(&self, word: u32) -> &Brick {
        self.pool.bricks.get(slot_of(word))
    }

    /// True when `p` lies inside the root cube.
    pub fn contains(&self, p: IVec3) -> bool {
        let rel = p.as_i64vec3() - self.origin.as_i64vec3();
        rel.cmpge(glam::I64Vec3::ZERO).all() && rel.cmplt(glam::I64Vec3::splat(1 << self.depth)).all()
    }

    /// Palette index at `p` (0 when empty or outside the root).
    pub fn get(&self, p: IVec3) -> u8 {
        if !self.contains(p) {
            return 0;
        }
        let rel = p - self.origin;
        let mut word = self.root;
        let mut level = self.depth;
        while is_pointer(word) {
            let bit = level - 1;
            let octant = (((rel.x >> bit) & 1) | (((rel.y >> bit) & 1) << 1) | (((rel.z >> bit) & 1) << 2)) as usize;
            if level == 1 {
                return self.brick(word)[octant];
            }
            word = self.node(word)[octant];
            level -= 1;
        }
        word as u8
    }

    /// The largest uniform cell holding `p` as (min corner, level, value): a
    /// cell of level `l` is 2^l voxels wide. `None` outside the root.
    pub fn uniform_cell(&self, p: IVec3) -> Option<(IVec3, u32, u8)> {
        if !self.contains(p) {
            return None;
        }
        let rel = p - self.origin;
        let (mut word, mut level) = (self.root, self.depth);
        while is_pointer(word) {
            let bit = level - 1;
            let octant = (((rel.x >> bit) & 1) | (((rel.y >> bit) & 1) << 1) | (((rel.z >> bit) & 1) << 2)) as usize;
            if level == 1 {
                return Some((p, 0, self.brick(word)[octant]));
            }
            word = self.node(word)[octant];
            level -= 1;
        }
        let min = self.origin + ((rel >> level) << level);
        Some((min, level, word as u8))
    }

    /// Visits every maximal uniform solid cell as (min corner, size, value).
    pub fn for_each_solid_cell(&self, mut f: impl FnMut(IVec3, i32, u8)) {
        self.visit_cells(self.root, self.origin, self.depth, &mut f);
    }

    /// [`Octree::for_each_solid_cell`] for the cells that meet the box
    /// `lo..=hi`, skipping the subtrees outside it (a cell may reach past
    /// the box).
    pub fn for_each_solid_cell_in(&self, lo: IVec3, hi: IVec3, mut f: impl FnMut(IVec3, i32, u8)) {
        self.visit_cells_in(self.root, self.origin, self.depth, (lo, hi), &mut f);
    }

    fn visit_cells_in(
        &self,
        word: u32,
        min: IVec3,
        level: u32,
        (lo, hi): (IVec3, IVec3),
        f: &mut impl FnMut(IVec3, i32, u8),
    ) {
        let max = min + IVec3::splat((1 << level) - 1);
        if max.cmplt(lo).any() || min.cmpgt(hi).any() {
            return;
        }
        if !is_pointer(word) || level <= 1 {
            // A brick's voxels come one by one: only those that meet the box.
            let mut meeting = |cell: IVec3, edge: i32, value: u8| {
                if (cell + IVec3::splat(edge - 1)).cmpge(lo).all() && cell.cmple(hi).all() {
                    f(cell, edge, value);
                }
            };
            return self.visit_cells(word, min, level, &mut meeting);
        }
        let half = 1 << (level - 1);
        for octant in 0..8 {
            let child_min = min + octant_offset(octant) * half;
            self.visit_cells_in(self.node(word)[octant], child_min, level - 1, (lo, hi), f);
        }
    }

    /// The non-empty cells of level `level` (or the root, when the tree is no
    /// deeper) as (min corner, child word, level), in octant order: what a
    /// saver walks to write the scene one block at a time.
    pub(crate) fn blocks(&self, level: u32) -> Vec<(IVec3, u32, u32)> {
        self.blocks_at_most(level, usize::MAX).unwrap_or_default()
    }

    /// [`Octree::blocks`], or `None` (and the walk stopped) once there are
    /// more than `max` of them. At level 0 a block is a voxel, its word
    /// the voxel's value.
    pub(crate) fn blocks_at_most(&self, level: u32, max: usize) -> Option<Vec<(IVec3, u32, u32)>> {
        let mut out = Vec::new();
        self.collect_blocks(self.root, self.origin, self.depth, level, max, &mut out).then_some(out)
    }

    /// Appends the blocks under `word`; false once there are more than `max`.
    fn collect_blocks(
        &self,
        word: u32,
        min: IVec3,
        level: u32,
        target: u32,
        max: usize,
        out: &mut Vec<(IVec3, u32, u32)>,
    ) -> bool {
        if word == 0 {
            return true;
        }
        if level <= target {
            out.push((min, word, level));
            return out.len() <= max;
        }
        let half = 1 << (level - 1);
        (0..8).all(|octant| {
            // A uniform cell above the block level is cut into its blocks;
            // a brick's children are voxels.
            let child = match (is_pointer(word), level) {
                (false, _) => word,
                (true, 1) => u32::from(self.brick(word)[octant]),
                (true, _) => self.node(word)[octant],
            };
            self.collect_blocks(child, min + octant_offset(octant) * half, level - 1, target, max, out)
        })
    }

    /// Visits the maximal uniform solid cells under one child word.
    pub(crate) fn visit_cells(&self, word: u32, min: IVec3, level: u32, f: &mut impl FnMut(IVec3, i32, u8)) {
        if !is_pointer(word) {
            if word != 0 {
                f(min, 1 << level, word as u8);
            }
            return;
        }
        let half = 1 << (level - 1);
        for octant in 0..8 {
            let child_min = min + octant_offset(octant) * half;
            if level == 1 {
                let v = self.brick(word)[octant];
                if v != 0 {
                    f(child_min, 1, v);
                }
            } else {
                self.visit_cells(self.node(word)[octant], child_min, level - 1, f);
            }
        }
    }

    /// Every solid voxel as (position, palette index), uniform cells expanded.
    pub fn voxels(&self) -> Vec<(IVec3, u8)> {
        let mut out = Vec::with_capacity(usize::try_from(self.solid_voxels()).unwrap_or(0));
        self.for_each_solid_cell(|min, size, v| {
            for z in 0..size {
                for y in 0..size {
                    for x in 0..size {
                        out.push((min + IVec3::new(x, y, z), v));
                    }
                }
            }
        });
        out
    }

    /// Whether `other` holds the same voxels (same cells, same values),
    /// whatever either's root and pool: the counts first, then every solid
    /// cell of this tree against the cells of `other` in its box. No voxel
    /// list is made.
    pub fn same_voxels(&self, other: &Octree) -> bool {
        if self.counts() != other.counts() {
            return false;
        }
        let mut same = true;
        self.for_each_solid_cell(|min, size, value| {
            if !same {
                return;
            }
            let max = min + IVec3::splat(size - 1);
            let mut matching = 0i64;
            other.for_each_solid_cell_in(min, max, |cell, edge, found| {
                if found == value {
                    let (a, b) = (cell.max(min), (cell + IVec3::splat(edge - 1)).min(max));
                    matching += (b - a + IVec3::ONE).as_i64vec3().element_product();
                }
            });
            same = matching == i64::from(size).pow(3);
        });
        same
    }

    /// Inclusive bounds of the solid voxels, or `None` for an empty tree.
    pub fn solid_bounds(&self) -> Option<(IVec3, IVec3)> {
        let mut bounds: Option<(IVec3, IVec3)> = None;
        self.bounds_under(self.root, self.origin, self.depth, &mut bounds);
        bounds
    }

    /// Grows `bounds` by the solid cells under `word`, skipping every
    /// subtree whose cube lies inside the bounds found so far (it cannot
    /// widen them): a scene of objects asks for its models' bounds on every
    /// edit, and a walk of every cell made a one-voxel edit of a 17,000-voxel
    /// model take a millisecond.
    fn bounds_under(&self, word: u32, min: IVec3, level: u32, bounds: &mut Option<(IVec3, IVec3)>) {
        let max = min + IVec3::splat((1 << level) - 1);
        if word == 0 || bounds.is_some_and(|(lo, hi)| min.cmpge(lo).all() && max.cmple(hi).all()) {
            return;
        }
        if !is_pointer(word) || level <= 1 {
            return self.visit_cells(word, min, level, &mut |cell, edge, _| {
                let grown = super::grow_bounds(*bounds, cell);
                *bounds = Some(super::grow_bounds(Some(grown), cell + IVec3::splat(edge - 1)));
            });
        }
        let half = 1 << (level - 1);
        let children = *self.node(word);
        for (octant, child) in children.into_iter().enumerate() {
            self.bounds_under(child, min + octant_offset(octant) * half, level - 1, bounds);
        }
    }

    /// Frees every slot under `word`.
    pub(crate) fn release(&mut self, word: u32, level: u32) {
        if !is_pointer(word) {
            return;
        }
        if level == 1 {
            self.pool.bricks.free(slot_of(word));
            return;
        }
        let node = *self.node(word);
        self.pool.nodes.free(slot_of(word));
        for child in node {
            self.release(child, level - 1);
        }
    }

    /// Word for eight voxel values: uniform if all equal, else a brick.
    /// `reuse` is an existing brick word to overwrite in place.
    pub(crate) fn make_brick(&mut self, values: Brick, reuse: Option<u32>) -> u32 {
        if values.iter().all(|v| *v == values[0]) {
            if let Some(old) = reuse {
                self.pool.bricks.free(slot_of(old));
            }
            return u32::from(values[0]);
        }
        match reuse {
            Some(old) => {
                self.pool.bricks.set(slot_of(old), values);
                old
            }
            None => pointer_to(self.pool.bricks.alloc(values)),
        }
    }

    /// Word for the eight child words of a `level` node: collapsed if all are
    /// the same uniform value. `reuse` is an existing node word to overwrite
    /// in place; it is written (and uploaded) only if the slot changes, its
    /// summary included.
    pub(crate) fn make_node(&mut self, children: Node, level: u32, reuse: Option<u32>) -> u32 {
        if !is_pointer(children[0]) && children.iter().all(|c| *c == children[0]) {
            if let Some(old) = reuse {
                self.pool.nodes.free(slot_of(old));
            }
            return children[0];
        }
        let slot = self.node_slot(children, level);
        match reuse {
            Some(old) => {
                if self.pool.nodes.get(slot_of(old)) != &slot {
                    self.pool.nodes.set(slot_of(old), slot);
                }
                old
            }
            None => pointer_to(self.pool.nodes.alloc(slot)),
        }
    }

    /// A node slot of `word` repeated: a uniform cell split so its parts can
    /// be edited (a brush or undo then rewrites it through `make_node`).
    pub(crate) fn split(&mut self, word: u32, level: u32) -> u32 {
        pointer_to(self.pool.nodes.alloc(self.node_slot([word; 8], level)))
    }

    /// A tree from a stored pool (the native file): slots `0..` of `nodes` and
    /// `bricks`, each slot used exactly once. Checked before it is used, so a crafted pool gives
    /// an error, not a cycle or a shared subtree; then the invariants
    /// (collapse, summaries) are checked and the counts recomputed.
    ///
    /// # Errors
    /// What is wrong with the pool, in words.
    pub fn from_parts(
        origin: IVec3,
        depth: u32,
        root: u32,
        nodes: Vec<NodeSlot>,
        bricks: Vec<Brick>,
    ) -> Result<Octree, TreeError> {
        check_tree_shape(root, depth, &nodes, bricks.len())?;
        // The root cube may pass the coordinate limit by at most one world
        // width (a grown root is aligned), never so far that i32 wraps.
        let reach = i64::from(WORLD_LIMIT) + (1 << MAX_DEPTH);
        let far = origin.as_i64vec3().min_element() <= -reach
            || origin.as_i64vec3().max_element() + (1_i64 << depth.min(MAX_DEPTH)) >= reach;
        if far {
            return Err(TreeError::RootTooFar(origin));
        }
        let mut tree = Octree::empty(origin, depth);
        if tree.depth != depth {
            return Err(TreeError::Depth(depth));
        }
        tree.pool.nodes = gpu_pool::SlotArena::from_items(nodes);
        tree.pool.bricks = gpu_pool::SlotArena::from_items(bricks);
        tree.root = root;
        tree.counts.add_word(&tree.pool, root, depth);
        tree.check_invariants()?;
        if let Some((lo, hi)) = tree.solid_bounds()
            && (lo.min_element() <= -WORLD_LIMIT || hi.max_element() >= WORLD_LIMIT)
        {
            return Err(TreeError::VoxelsTooFar { lo, hi });
        }
        Ok(tree)
    }

    /// Checks the structural invariants: collapse, no dangling or leaked
    /// slots, and the cached voxel count. Returns a description of the first
    /// violation. Used by tests after every edit.
    pub fn check_invariants(&self) -> Result<(), TreeError> {
        let mut reached = (0usize, 0usize);
        self.check_word(self.root, self.depth, &mut reached)?;
        if reached != (self.pool.nodes.live(), self.pool.bricks.live()) {
            return Err(TreeError::Leaked { reached, live: (self.pool.nodes.live(), self.pool.bricks.live()) });
        }
        let mut counted = VoxelCounts::default();
        counted.add_word(&self.pool, self.root, self.depth);
        if counted != self.counts {
            return Err(TreeError::Counts { cached: self.solid_voxels(), counted: counted.solid() });
        }
        Ok(())
    }

    fn check_word(&self, word: u32, level: u32, reached: &mut (usize, usize)) -> Result<(), TreeError> {
        if !is_pointer(word) {
            return if word <= 255 { Ok(()) } else { Err(TreeError::BadWord(word)) };
        }
        if level == 0 {
            return Err(TreeError::PointerInBrick);
        }
        if level == 1 {
            if self.pool.bricks.is_free(slot_of(word)) {
                return Err(TreeError::FreeReferenced { what: "brick", slot: slot_of(word) });
            }
            reached.1 += 1;
            let b = self.brick(word);
            return if b.iter().all(|v| *v == b[0]) { Err(TreeError::UncollapsedBrick(*b)) } else { Ok(()) };
        }
        if self.pool.nodes.is_free(slot_of(word)) {
            return Err(TreeError::FreeReferenced { what: "node", slot: slot_of(word) });
        }
        reached.0 += 1;
        let node = *self.node(word);
        let stored = self.pool.nodes.get(slot_of(word)).lod;
        if stored != self.node_slot(node, level).lod {
            return Err(TreeError::StaleSummary { summary: Summary::from_word(stored), slot: slot_of(word), level });
        }
        if !is_pointer(node[0]) && node.iter().all(|c| *c == node[0]) {
            return Err(TreeError::UncollapsedNode { node, level });
        }
        node.iter().try_for_each(|&c| self.check_word(c, level - 1, reached))
    }
}

/// Checks that the pointers under `root` form a tree over exactly the given
/// slots: in range, each used once (so no cycle and no shared subtree), and
/// uniform words that are palette indices.
fn check_tree_shape(root: u32, depth: u32, nodes: &[NodeSlot], bricks: usize) -> Result<(), TreeError> {
    let mut used = (vec![false; nodes.len()], vec![false; bricks]);
    let mut stack = vec![(root, depth)];
    while let Some((word, level)) = stack.pop() {
        if !is_pointer(word) {
            if word > 255 {
                return Err(TreeError::BadWord(word));
            }
            continue;
        }
        let slot = slot_of(word);
        let (seen, what) = if level == 1 { (&mut used.1, "brick") } else { (&mut used.0, "node") };
        match seen.get_mut(slot as usize) {
            None => return Err(TreeError::PastStored { what, slot, stored: seen.len() }),
            Some(true) => return Err(TreeError::UsedTwice { what, slot }),
            Some(flag) => *flag = true,
        }
        if level == 1 {
            continue;
        }
        stack.extend(nodes[slot as usize].children.map(|child| (child, level - 1)));
    }
    let unused = used.0.iter().chain(&used.1).filter(|u| !**u).count();
    if unused > 0 {
        return Err(TreeError::Unused(unused));
    }
    Ok(())
}

/// Reads voxels back from raw GPU-layout bytes exactly as the shader walks
/// them. Tests use it on a mirror buffer fed only by flushed ranges.
pub fn decode_from_bytes(nodes: &[u8], bricks: &[u8], root: u32, origin: IVec3, depth: u32, p: IVec3) -> u8 {
    let rel = p - origin;
    if rel.cmplt(IVec3::ZERO).any() || rel.cmpge(IVec3::splat(1 << depth)).any() {
        return 0;
    }
    let word_at = |bytes: &[u8], index: usize| -> u32 {
        let at = index * 4;
        bytes.get(at..at + 4).map_or(0xdead_beef, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let mut word = root;
    let mut level = depth;
    while is_pointer(word) {
        let bit = level - 1;
        let octant = (((rel.x >> bit) & 1) | (((rel.y >> bit) & 1) << 1) | (((rel.z >> bit) & 1) << 2)) as usize;
        let slot = slot_of(word) as usize;
        if level == 1 {
            let packed = word_at(bricks, slot * 2 + octant / 4);
            return (packed >> (8 * (octant % 4))) as u8;
        }
        word = word_at(nodes, slot * gpu_pool::NODE_WORDS + octant);
        level -= 1;
    }
    word as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 24, item 8: an .ovx whose root sits past ±2^24 loaded (and one
    /// near i32's end made child positions wrap). `from_parts` is what the
    /// .ovx reader builds its tree with.
    #[test]
    fn a_tree_past_the_coordinate_limit_is_refused() {
        let solid = |origin: IVec3| Octree::from_parts(origin, MIN_DEPTH, 7, Vec::new(), Vec::new());
        let inside = IVec3::new(WORLD_LIMIT - 4, -WORLD_LIMIT + 1, 0);
        assert_eq!(solid(inside).map(|t| t.solid_voxels()), Ok(64));
        for origin in
            [IVec3::new(WORLD_LIMIT - 3, 0, 0), IVec3::new(0, -WORLD_LIMIT, 0), IVec3::new(i32::MAX - 1, 0, 0)]
        {
            let err = solid(origin).map(|t| t.solid_voxels()).unwrap_err();
            assert!(err.to_string().contains("past the coordinate limit"), "{origin}: {err}");
        }
    }

    /// The cells reported for a box are those that meet it, also inside a
    /// brick (whose voxels came all at once: a model cut into pieces on
    /// save then got a piece of size 0 from a neighbour's voxel).
    #[test]
    fn the_cells_in_a_box_are_only_those_that_meet_it() {
        let mut tree = Octree::default();
        for p in [IVec3::new(0, 0, 0), IVec3::new(1, 0, 0), IVec3::new(1, 1, 1), IVec3::new(9, 0, 0)] {
            tree.apply_brush(&super::super::Shape::Voxel(p), super::super::Op::Place(3)).unwrap();
        }
        let mut seen = Vec::new();
        tree.for_each_solid_cell_in(IVec3::new(1, 0, 0), IVec3::new(1, 0, 0), |min, edge, _| seen.push((min, edge)));
        assert_eq!(seen, [(IVec3::new(1, 0, 0), 1)]);
    }
}
