//! The top level of two-level ray tracing: one record per placed object
//! (its model, and the signed permutation and integer offset that take
//! scene cells to the model's cells, or for a free turn the rigid map of
//! points, [`Turned`]) and a bounding-volume tree over their boxes. The
//! GPU reads both as words ([`InstanceTable::words`]); the CPU reference
//! walks the same records (`crate::trace::instanced`).
//!
//! The tree is balanced over the objects in walk order: its shape depends
//! only on how many objects there are, so moving, turning or hiding one
//! changes its leaf and the boxes above it that change, nothing else. Walk
//! order follows the file's groups, which MagicaVoxel users build spatially.

use glam::{DMat3, DVec3, IVec3, Vec3};

use super::hull::HULL_BLOCKS;
use super::objects::{Model, Objects};
use super::transform::Placing;
use crate::gpu_pool::{BRICK_BYTES, NODE_BYTES, PoolTooLarge};

/// Words of one tree node on the GPU: the box's min corner and its max
/// corner (exclusive, scene-local cells), the index of the node after its
/// subtree ([`SKIP_WORD`]), and its instance ([`LEAF_WORD`]).
pub const BVH_NODE_WORDS: usize = 8;
/// Word of a tree node holding the index of the node after its subtree: an
/// inner node's right child is the node after its left child's subtree.
pub const SKIP_WORD: usize = 6;
/// Levels of the tree a traversal can keep on its stack: the balanced tree
/// over `n` objects has `ceil(log2 n)` levels below its root, so this holds
/// 2^24 objects, far past what a scene's memory allows.
pub const BVH_STACK: usize = 24;
/// Word of a tree node naming its instance (index + 1; 0: an inner node).
pub const LEAF_WORD: usize = 7;
/// Bit of [`LEAF_WORD`] marking a subtree with nothing drawn: every object
/// under it hidden or empty. A traversal skips it without a box test.
pub const EMPTY_BIT: u32 = 0x8000_0000;
/// Words of one instance record on the GPU (see [`InstanceTable::words`]).
pub const INSTANCE_WORDS: usize = 20;
/// Bit of a record's depth word marking a freely turned instance: the
/// words after it hold its map of points ([`Turned`]).
pub const TURNED_BIT: u32 = 0x8000_0000;
/// The instance of a hit in a scene of one model.
pub const NO_INSTANCE: u32 = u32::MAX;
// `load_node` and `load_instance` in shaders/instances.wgsl read a node and
// a record as two four-word loads, by these positions.
const _: () = assert!(BVH_NODE_WORDS == 8 && SKIP_WORD == 6 && LEAF_WORD == 7 && INSTANCE_WORDS == 20);

/// Two hits closer than this (in t, relative to t, at least 1) count as one
/// distance: the later object in walk order wins there, as composing gives.
/// Each object's ray is its own rounding of the scene ray, so faces that
/// coincide in the scene differ by a few ulps in t.
pub const TIE_T: f32 = 1.0 / 65536.0;

/// One placed object: scene-local cell `s` is model tree-local cell `m` with
/// `m[j] = sign[j] · s[src[j]] + offset[j]` (continuous points likewise),
/// unless it is freely turned (`turned`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    pub model: usize,
    pub src: [usize; 3],
    pub sign: [i32; 3],
    pub offset: IVec3,
    /// Inclusive scene-local box of its voxels; `None` when hidden or empty.
    pub bounds: Option<(IVec3, IVec3)>,
    pub turned: Option<Turned>,
}

/// A freely turned instance as the tracers move rays: tree-local model
/// point `m = rows · s + t` of scene-local point `s`, in f32 as the GPU
/// computes it (`rows` orthogonal, a mirror included). A quarter turn given
/// as a free one has rows of 0 and ±1 and a whole `t`, so it moves rays
/// exactly as the integer path does. Twin of `model_ray` in
/// shaders/instances.wgsl.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Turned {
    pub rows: [Vec3; 3],
    pub t: Vec3,
    /// The model's solid cells' box, tree-local and inclusive, where each
    /// corner fits 16 bits (the record's spare words hold it): a ray that
    /// meets the turned object's scene box but misses this is not walked
    /// (a turned box's scene box holds much empty space).
    pub solid: Option<(IVec3, IVec3)>,
}

/// How far the solid box is grown before a ray is tested against it, in
/// voxels: a ray that grazes it is walked (the walk decides).
pub const SOLID_BOX_SLACK: f32 = 1.0 / 256.0;

impl Turned {
    /// The turned map of model grid points `x = m · (w − shift) + c` of
    /// world points `w` (`TurnedMap::to_model`), for a scene whose local
    /// cells start at world cell `origin` and a tree whose cells start at
    /// model cell `tree_origin`. The translation is summed in f64 and
    /// rounded once.
    pub fn new(
        (m, shift, c): (DMat3, IVec3, DVec3),
        origin: IVec3,
        tree_origin: IVec3,
        solid: Option<(IVec3, IVec3)>,
    ) -> Turned {
        let t = m * (origin - shift).as_dvec3() + c - tree_origin.as_dvec3();
        let m = m.transpose();
        let fits = |v: IVec3| v.cmpge(IVec3::ZERO).all() && v.cmple(IVec3::splat(0xffff)).all();
        let solid = solid.map(|(lo, hi)| (lo - tree_origin, hi - tree_origin)).filter(|&(lo, hi)| fits(lo) && fits(hi));
        Turned { rows: [m.x_axis.as_vec3(), m.y_axis.as_vec3(), m.z_axis.as_vec3()], t: t.as_vec3(), solid }
    }

    /// Whether a ray in the model's frame (`model_ray`) misses the solid
    /// box, grown by [`SOLID_BOX_SLACK`], or enters it past `until` (where
    /// no hit of it can win). Twin of `misses_solid` in
    /// shaders/instances.wgsl.
    pub fn misses_solid(&self, ray: &crate::trace::Ray, until: f32) -> bool {
        let Some((lo, hi)) = self.solid else { return false };
        let slack = Vec3::splat(SOLID_BOX_SLACK);
        let (enter, exit, _) = ray.slab(lo.as_vec3() - slack, (hi + IVec3::ONE).as_vec3() + slack);
        !(enter <= exit && exit >= 0.0 && enter <= until)
    }

    /// `rows · v`, each row's products summed left to right (as the shader).
    fn times(&self, v: Vec3) -> Vec3 {
        Vec3::from_array(self.rows.map(|r| r.x * v.x + r.y * v.y + r.z * v.z))
    }

    /// `rowsᵀ · v`: the inverse, as the rows are orthogonal.
    fn times_transposed(&self, v: Vec3) -> Vec3 {
        let [a, b, c] = self.rows;
        a * v.x + b * v.y + c * v.z
    }

    /// The model tree-local point of scene-local point `p`.
    pub fn model_point(&self, p: Vec3) -> Vec3 {
        self.times(p) + self.t
    }

    /// The model direction of scene direction `d`.
    pub fn model_dir(&self, d: Vec3) -> Vec3 {
        self.times(d)
    }

    /// The scene-local point of model tree-local point `m`.
    pub fn scene_point(&self, m: Vec3) -> Vec3 {
        self.times_transposed(m - self.t)
    }

    /// The scene direction of model direction `n`.
    pub fn scene_dir(&self, n: Vec3) -> Vec3 {
        self.times_transposed(n)
    }

    /// The record's words after the header: `t`, then the rows as f32
    /// bits, each followed by one axis of the solid box (its low corner in
    /// the low 16 bits, its high corner above; none: low above high).
    fn words(&self) -> [u32; 15] {
        let mut words = [0; 15];
        words[..3].copy_from_slice(&self.t.to_array().map(f32::to_bits));
        for (i, row) in self.rows.iter().enumerate() {
            words[3 + 4 * i..6 + 4 * i].copy_from_slice(&row.to_array().map(f32::to_bits));
            words[6 + 4 * i] = self.solid.map_or(0xffff, |(lo, hi)| lo[i] as u32 | (hi[i] as u32) << 16);
        }
        words
    }
}

impl Instance {
    /// The scene cell of model tree-local cell `m`.
    pub fn cell_to_scene(&self, m: IVec3) -> IVec3 {
        let mut s = IVec3::ZERO;
        for j in 0..3 {
            // Cell m spans m..m + 1; mirrored, its low corner is the image of m + 1.
            let d = m[j] - self.offset[j];
            s[self.src[j]] = if self.sign[j] < 0 { -d - 1 } else { d };
        }
        s
    }

    /// The scene direction of a model direction (a normal).
    pub fn dir_to_scene(&self, n: IVec3) -> IVec3 {
        let mut s = IVec3::ZERO;
        for j in 0..3 {
            s[self.src[j]] = self.sign[j] * n[j];
        }
        s
    }
}

/// A node of the tree over instance boxes, in preorder: an inner node's
/// first child follows it, and `skip` is the node after its subtree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BvhNode {
    /// Inclusive scene-local cell box; `None`: nothing drawn below.
    pub bounds: Option<(IVec3, IVec3)>,
    pub skip: u32,
    pub leaf: Option<u32>,
}

/// The instances of a scene of objects and the tree over their boxes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InstanceTable {
    pub instances: Vec<Instance>,
    pub nodes: Vec<BvhNode>,
}

impl InstanceTable {
    /// The objects as instances, in a scene whose local cells start at
    /// world cell `origin`.
    pub fn build(objects: &Objects, origin: IVec3) -> InstanceTable {
        let model_bounds: Vec<Option<(IVec3, IVec3)>> = objects.models.iter().map(|m| m.tree.solid_bounds()).collect();
        // Hulls only of the models something turns freely, once each.
        let mut hulls: Vec<Option<Vec<(IVec3, IVec3)>>> = vec![None; objects.models.len()];
        let instances: Vec<Instance> = (0..objects.list().len())
            .map(|i| {
                let object = &objects.list()[i];
                let model = object.placement.model;
                let tree_origin = objects.models[model].tree.origin();
                let placing = objects.map(i);
                let bounds = model_bounds[model]
                    .filter(|_| !object.hidden)
                    .map(|(lo, hi)| match &placing {
                        Placing::Cells(map) => map.apply_box(lo, hi),
                        Placing::Turned(map) => map.cover_blocks(
                            hulls[model].get_or_insert_with(|| objects.models[model].tree.hull(HULL_BLOCKS)),
                        ),
                    })
                    .map(|(lo, hi)| (lo - origin, hi - origin));
                let mut instance =
                    Instance { model, src: [0; 3], sign: [1; 3], offset: IVec3::ZERO, bounds, turned: None };
                let map = match placing {
                    Placing::Cells(map) => map,
                    Placing::Turned(map) => {
                        instance.turned = Some(Turned::new(map.to_model(), origin, tree_origin, model_bounds[model]));
                        return instance;
                    }
                };
                for (row, (axis, sign, offset)) in map.rows().into_iter().enumerate() {
                    // w = sign · v + offset on cells; on points a mirrored
                    // axis adds one (cell v spans v..v + 1).
                    let corner = i32::from(sign < 0);
                    instance.src[axis] = row;
                    instance.sign[axis] = sign;
                    instance.offset[axis] = sign * (origin[row] - offset - corner) - tree_origin[axis];
                }
                instance
            })
            .collect();
        let mut nodes = Vec::with_capacity(2 * instances.len());
        if !instances.is_empty() {
            build_range(&instances, 0, instances.len(), &mut nodes);
        }
        InstanceTable { instances, nodes }
    }

    /// The table as the GPU reads it: the tree's nodes, then one record per
    /// instance, given where each model's pool lies in the pool buffer.
    /// A record: the model's root word, its first node slot, the word its
    /// bricks start at, its depth in the low byte with the axes above
    /// (`src[j]` in bits 8 + 2j, a mirrored `j` in bit 14 + j, and
    /// [`TURNED_BIT`]), its iteration bound, and the offset; a turned
    /// record has its map of points there instead ([`Turned::words`]).
    pub fn words(&self, models: &[Model], regions: &[ModelRegion], brick_words: u32) -> Vec<u32> {
        let mut words = Vec::with_capacity(self.nodes.len() * BVH_NODE_WORDS + self.instances.len() * INSTANCE_WORDS);
        for node in &self.nodes {
            let (lo, hi) = node.bounds.map_or((IVec3::ZERO, IVec3::ZERO), |(lo, hi)| (lo, hi + IVec3::ONE));
            words.extend(lo.to_array().map(|c| c as u32));
            words.extend(hi.to_array().map(|c| c as u32));
            words.push(node.skip);
            let empty = if node.bounds.is_none() { EMPTY_BIT } else { 0 };
            words.push(node.leaf.map_or(0, |i| i + 1) | empty);
        }
        for instance in &self.instances {
            let tree = &models[instance.model].tree;
            let region = regions[instance.model];
            let mut axes = 0;
            for j in 0..3 {
                axes |= (instance.src[j] as u32) << (2 * j);
                axes |= u32::from(instance.sign[j] < 0) << (6 + j);
            }
            let (turned, tail) = match &instance.turned {
                Some(turned) => (TURNED_BIT, turned.words()),
                None => {
                    let mut tail = [0; 15];
                    tail[..3].copy_from_slice(&instance.offset.to_array().map(|c| c as u32));
                    (0, tail)
                }
            };
            words.extend([
                tree.root_word(),
                region.node_base,
                brick_words + 2 * region.brick_base,
                tree.depth() | axes << 8 | turned,
                super::octree::iteration_bound(tree.depth()),
            ]);
            words.extend(tail);
        }
        words
    }
}

/// Bytes of the instance words of `objects` objects: the tree's nodes and
/// the records.
pub fn word_bytes(objects: usize) -> u64 {
    let nodes = (2 * objects).saturating_sub(1);
    4 * (nodes * BVH_NODE_WORDS + objects * INSTANCE_WORDS) as u64
}

/// Appends the subtree over instances `lo..hi` to `nodes`; returns its box.
fn build_range(instances: &[Instance], lo: usize, hi: usize, nodes: &mut Vec<BvhNode>) -> Option<(IVec3, IVec3)> {
    let at = nodes.len();
    nodes.push(BvhNode { bounds: None, skip: 0, leaf: None });
    let bounds = if hi - lo == 1 {
        nodes[at].leaf = Some(lo as u32);
        instances[lo].bounds
    } else {
        let mid = lo + (hi - lo) / 2;
        let a = build_range(instances, lo, mid, nodes);
        let b = build_range(instances, mid, hi, nodes);
        match (a, b) {
            (Some(a), Some(b)) => Some((a.0.min(b.0), a.1.max(b.1))),
            (a, b) => a.or(b),
        }
    };
    nodes[at].bounds = bounds;
    nodes[at].skip = nodes.len() as u32;
    bounds
}

/// Where one model's pool lies in the GPU pool buffer, in slots: its nodes
/// from `node_base` in the node region, its bricks from `brick_base` in the
/// brick region, each with room for `*_slots`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ModelRegion {
    pub node_base: u32,
    pub node_slots: u32,
    pub brick_base: u32,
    pub brick_slots: u32,
}

/// What the GPU holds of a scene of objects: where each model's pool lies
/// and the instance words last sent. [`GpuCopy::take`] sends what differs.
#[derive(Clone, Debug, Default)]
pub struct GpuCopy {
    /// Empty: nothing sent yet (or forgotten); the next take lays out afresh.
    regions: Vec<ModelRegion>,
    node_slots: u32,
    brick_slots: u32,
    words: Vec<u32>,
}

/// The writes of one [`GpuCopy::take`], as byte offsets into the two buffers.
#[derive(Clone, Debug, Default)]
pub struct ObjectsUpload {
    /// A new pool buffer of these node and brick region bytes, when the
    /// models were laid out afresh (then `pool` covers every model).
    pub pool_size: Option<(u64, u64)>,
    pub pool: Vec<(u64, Vec<u8>)>,
    /// A new instance buffer of this many bytes (then `instances` is all of it).
    pub instances_size: Option<u64>,
    pub instances: Vec<(u64, Vec<u8>)>,
    /// Tree nodes at the start of the instance words (0: nothing drawn).
    pub instance_nodes: u32,
}

impl ObjectsUpload {
    pub fn byte_count(&self) -> u64 {
        self.pool.iter().chain(&self.instances).map(|(_, bytes)| bytes.len() as u64).sum()
    }

    pub fn range_count(&self) -> usize {
        self.pool.len() + self.instances.len()
    }
}

impl GpuCopy {
    /// Forgets what the GPU holds: the next take sends everything.
    pub fn forget(&mut self) {
        *self = GpuCopy::default();
    }

    /// Takes every model's changed slots and the instance words that differ
    /// from those sent, for a scene whose local cells start at `origin`. A
    /// model that outgrew its region lays every model out afresh, each with
    /// half again its slots as room.
    ///
    /// # Errors
    /// [`PoolTooLarge`] when the models' pools do not fit `max_bytes`; the
    /// changes are kept for a later take.
    pub fn take(
        &mut self,
        objects: &mut Objects,
        origin: IVec3,
        max_bytes: u64,
    ) -> Result<ObjectsUpload, PoolTooLarge> {
        let fits = self.regions.len() == objects.models.len()
            && self.regions.iter().zip(&objects.models).all(|(r, m)| {
                m.tree.pool().nodes.len() <= r.node_slots as usize
                    && m.tree.pool().bricks.len() <= r.brick_slots as usize
            });
        let mut upload = ObjectsUpload::default();
        if fits {
            self.send_changes(objects, &mut upload);
        } else {
            self.lay_out(objects, max_bytes)?;
            upload.pool_size = Some((self.node_region_bytes(), u64::from(self.brick_slots) * BRICK_BYTES));
            self.send_all(objects, &mut upload);
        }
        let table = InstanceTable::build(objects, origin);
        let words = table.words(&objects.models, &self.regions, (self.node_region_bytes() / 4) as u32);
        upload.instance_nodes = table.nodes.len() as u32;
        if words.len() != self.words.len() {
            upload.instances_size = Some(4 * words.len() as u64);
            upload.instances.push((0, bytemuck::cast_slice(&words).to_vec()));
        } else {
            upload.instances = changed_runs(&self.words, &words);
        }
        self.words = words;
        Ok(upload)
    }

    fn node_region_bytes(&self) -> u64 {
        u64::from(self.node_slots) * NODE_BYTES
    }

    /// Where a model's nodes and bricks start in the pool buffer, in bytes.
    fn offsets(&self, region: &ModelRegion) -> (u64, u64) {
        let nodes = u64::from(region.node_base) * NODE_BYTES;
        (nodes, self.node_region_bytes() + u64::from(region.brick_base) * BRICK_BYTES)
    }

    /// Gives each model a region of half again its slots.
    fn lay_out(&mut self, objects: &Objects, max_bytes: u64) -> Result<(), PoolTooLarge> {
        let room = |n: usize| (n + n / 2).max(16);
        let (mut nodes, mut bricks) = (0u64, 0u64);
        let mut regions = Vec::with_capacity(objects.models.len());
        for model in &objects.models {
            let pool = model.tree.pool();
            let (n, b) = (room(pool.nodes.len()) as u64, room(pool.bricks.len()) as u64);
            regions.push((nodes, n, bricks, b));
            (nodes, bricks) = (nodes + n, bricks + b);
        }
        let needed = nodes * NODE_BYTES + bricks * BRICK_BYTES;
        if needed > max_bytes || nodes > u64::from(u32::MAX / 2) || bricks > u64::from(u32::MAX / 4) {
            return Err(PoolTooLarge { needed, limit: max_bytes });
        }
        let slot = |v: u64| v as u32;
        self.regions = regions
            .into_iter()
            .map(|(nb, n, bb, b)| ModelRegion {
                node_base: slot(nb),
                node_slots: slot(n),
                brick_base: slot(bb),
                brick_slots: slot(b),
            })
            .collect();
        (self.node_slots, self.brick_slots) = (slot(nodes), slot(bricks));
        Ok(())
    }

    /// Every model's pool, whole, and its dirty slots taken.
    fn send_all(&self, objects: &mut Objects, upload: &mut ObjectsUpload) {
        for (model, region) in objects.models.iter_mut().zip(&self.regions) {
            let pool = model.tree.pool_mut();
            pool.flush();
            let (nodes, bricks) = self.offsets(region);
            upload.pool.push((nodes, pool.nodes.bytes().to_vec()));
            upload.pool.push((bricks, pool.bricks.bytes().to_vec()));
        }
    }

    /// Each model's dirty slots, at its region.
    fn send_changes(&self, objects: &mut Objects, upload: &mut ObjectsUpload) {
        for (model, region) in objects.models.iter_mut().zip(&self.regions) {
            let pool = model.tree.pool_mut();
            let changes = pool.flush();
            let (nodes, bricks) = self.offsets(region);
            let pool = model.tree.pool();
            upload.pool.extend(changes.nodes.ranges(&pool.nodes).map(|(at, bytes)| (nodes + at, bytes.to_vec())));
            upload.pool.extend(changes.bricks.ranges(&pool.bricks).map(|(at, bytes)| (bricks + at, bytes.to_vec())));
        }
    }
}

/// Runs of changed words closer than this many words are sent as one:
/// each write is a call with its own cost (2,000 turning objects made
/// 2,000 writes, 22 ms a frame on lavapipe), and a record's unchanged
/// header between two changed records is cheaper to send again.
const RUN_GAP: usize = 2 * INSTANCE_WORDS;

/// The runs of words where `new` differs from `old` (of the same length),
/// as byte offsets and bytes; runs less than [`RUN_GAP`] apart are one.
fn changed_runs(old: &[u32], new: &[u32]) -> Vec<(u64, Vec<u8>)> {
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut i = 0;
    while i < new.len() {
        if old[i] == new[i] {
            i += 1;
            continue;
        }
        let start = i;
        while i < new.len() && old[i] != new[i] {
            i += 1;
        }
        match runs.last_mut() {
            Some(last) if start - last.1 < RUN_GAP => last.1 = i,
            _ => runs.push((start, i)),
        }
    }
    runs.into_iter().map(|(a, b)| (4 * a as u64, bytemuck::cast_slice(&new[a..b]).to_vec())).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Changed words closer than [`RUN_GAP`] go up as one write, the
    /// unchanged ones between them sent again; farther ones stay apart;
    /// every changed word is sent with its new value.
    #[test]
    fn changed_runs_merge_near_changes_and_keep_far_ones_apart() {
        let old = vec![0u32; 200];
        let mut new = old.clone();
        for i in [3, 4, 10, 30, 31, 150] {
            new[i] = i as u32 + 1;
        }
        let runs = changed_runs(&old, &new);
        let spans: Vec<(u64, usize)> = runs.iter().map(|(at, bytes)| (at / 4, bytes.len() / 4)).collect();
        assert_eq!(spans, [(3, 29), (150, 1)], "3..=31 in one write (gaps under {RUN_GAP} words), 150 alone");
        for (at, bytes) in &runs {
            let words: &[u32] = bytemuck::cast_slice(bytes);
            assert_eq!(words, &new[*at as usize / 4..*at as usize / 4 + words.len()]);
        }
        assert!(changed_runs(&old, &old).is_empty(), "nothing changed, nothing sent");
    }
}
