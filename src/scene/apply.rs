//! Applying edits to a scene and its octree: brushes, restoring saved
//! cells (undo), growing or shrinking the root, and handing the changed
//! node slots on to the GPU.
//!
//! Every path visits only the cells a shape overlaps: a cell fully inside
//! becomes one uniform word, a cell outside is returned untouched. Every
//! replaced cell's old content goes into a [`Patch`], which is itself an edit.

use glam::IVec3;

use super::Scene;
use super::instances::ObjectsUpload;
use super::objects::{GraphChange, Model, Objects};
use super::octree::{MAX_DEPTH, Octree, WORLD_LIMIT, octant_offset};
use super::shape::{Op, Overlap, Shape};
use crate::gpu_pool::{Brick, Node, PoolTooLarge, Upload, is_pointer};

/// What a scene sends its GPU copy: see [`Scene::take_uploads_within`].
#[derive(Debug)]
pub enum SceneUpload {
    Tree(Upload),
    Objects(ObjectsUpload),
}

impl SceneUpload {
    pub fn byte_count(&self) -> u64 {
        match self {
            SceneUpload::Tree(upload) => upload.byte_count(),
            SceneUpload::Objects(upload) => upload.byte_count(),
        }
    }
}

/// Why an edit was refused. The tree is unchanged when one is returned.
#[derive(Debug, thiserror::Error, Clone, PartialEq, Eq)]
pub enum EditError {
    #[error("edit at {min}..{max} is outside the world (coordinates must stay within ±{WORLD_LIMIT})")]
    OutsideWorld { min: IVec3, max: IVec3 },
    #[error("edit at {min}..{max} would make the world wider than 2^{MAX_DEPTH} voxels")]
    TooWide { min: IVec3, max: IVec3 },
    #[error("invalid brush: {0}")]
    Shape(#[from] crate::scene::shape::ShapeError),
    /// A fill, extrude, selection or copy that cannot be made.
    #[error(transparent)]
    Region(#[from] RegionError),
    /// A change to a scene of objects that cannot be made (no such object
    /// or layer, a locked object, a file without a scene graph, …).
    #[error(transparent)]
    Objects(#[from] ObjectRefusal),
    /// The objects' scene graph, walked again after a change, refuses it.
    #[error(transparent)]
    Placement(#[from] super::objects::ObjectsError),
    /// A transform or keyframe of the graph that cannot be read.
    #[error(transparent)]
    Graph(#[from] super::graph::GraphError),
    /// A model's tree that cannot hold the cells asked for.
    #[error(transparent)]
    Build(#[from] super::build::BuildError),
    #[error("palette index 0 means empty; use remove, or a colour in 1..=255")]
    ZeroColor,
    #[error(transparent)]
    OverBudget(#[from] crate::budget::OverBudget),
}

/// Why a fill, an extrude, a selection or a copy was refused.
#[derive(Debug, thiserror::Error, Clone, PartialEq, Eq)]
pub enum RegionError {
    #[error("no voxel at {0} to fill from")]
    NothingToFill(IVec3),
    #[error("the region at {start} has more than {limit} voxels: fill refused, nothing changed")]
    FillTooLarge { start: IVec3, limit: usize },
    #[error("extrude normal {0} is not one of ±x, ±y, ±z")]
    NotAnAxis(IVec3),
    #[error("voxel {voxel} shows no face toward {normal}")]
    NoFace { voxel: IVec3, normal: IVec3 },
    #[error("the face at {start} has more than {limit} voxels: extrude refused, nothing changed")]
    FaceTooLarge { start: IVec3, limit: usize },
    #[error("extrude by {layers} layers: use 1..={limit} out or in")]
    ExtrudeLayers { layers: i32, limit: i32 },
    #[error("selection {min}..{max} is wider than {limit} voxels")]
    SelectionTooWide { min: IVec3, max: IVec3, limit: i32 },
    #[error("the selection holds {voxels} voxels; copy takes at most {limit}")]
    ClipboardTooLarge { voxels: u64, limit: u64 },
}

/// Why a change to a scene of objects was refused.
#[derive(Debug, thiserror::Error, Clone, PartialEq, Eq)]
pub enum ObjectRefusal {
    #[error("a file of animation frames has no scene graph to change")]
    NoGraph,
    #[error("the scene has no objects")]
    NoObjects,
    #[error("the scene has no object to edit: `object new NAME` makes one")]
    NothingToEdit,
    #[error("there is no object {0}")]
    NoObject(usize),
    #[error("there is no model {0}")]
    NoModel(usize),
    #[error("there are no models")]
    NoModels,
    #[error("the scene has no layer {0}")]
    NoLayer(u32),
    #[error("the scene has no layers")]
    NoLayers,
    #[error("object {0} is locked and stays as it is: `object unlock` first")]
    Locked(usize),
    #[error(
        "object {locked} is locked and places the same model as object {index} (a reference): `object unlock` it, \
         or `object unique` this one to edit a copy"
    )]
    LockedReference { locked: usize, index: usize },
    #[error("object {0} is locked and has voxels in the box: `object unlock` it, or select around it")]
    LockedInBox(usize),
    #[error("object {0} has no transform node")]
    NoTransform(usize),
    #[error("node {0} is not a transform")]
    NotATransform(u32),
    #[error("its shape is missing")]
    NoShape,
    #[error("model {0} is still placed")]
    StillPlaced(usize),
    #[error("merge needs other objects than the picked one, each once, of the {0} there are")]
    MergeWhich(usize),
    #[error("object {0} is hidden: show it (or its layer) to merge it")]
    MergeHidden(usize),
    #[error("object {0} is turned by a free angle, or in a group that is: {1} it is not done yet")]
    FreelyTurned(usize, &'static str),
    #[error("object turn by {0}°: an angle is a finite number of degrees")]
    BadAngle(String),
    #[error("the objects hold {voxels} voxels; a merge takes at most {limit} (one model of 256³)")]
    MergeTooLarge { voxels: u64, limit: u64 },
    #[error("an object goes before or after another object")]
    RegroupSelf,
    #[error("the scene graph has no top group to put an object in")]
    NoTopGroup,
    #[error("the object is not in a group (it is the whole scene)")]
    NotInGroup,
    #[error("no node ids are left")]
    NoNodeIds,
    #[error("object {index} has no key at frame {frame}")]
    NoKey { index: usize, frame: u32 },
    #[error("that is object {0}'s only key: an object keeps at least one")]
    LastKey(usize),
}

/// Peak bytes an edit takes per surface voxel of its shape: bricks and
/// nodes, the undo patch and the dirty lists (a radius-4096 sphere, 2·10^8
/// surface voxels, took 3.8 GB).
pub const EDIT_BYTES_PER_SURFACE_VOXEL: u64 = 24;

impl Scene {
    /// Bytes the GPU traces that are in use: the one model's pool, or every
    /// model's pool (each once) and the instance words.
    pub fn drawn_pool_bytes(&self) -> u64 {
        match self.instanced() {
            None => self.tree.pool().live_bytes(),
            Some(objects) => objects.pool_bytes() + super::instances::word_bytes(objects.list().len()),
        }
    }

    /// What changed since the last call, to send to the GPU.
    pub fn take_uploads(&mut self) -> SceneUpload {
        match self.take_uploads_within(u64::MAX) {
            Ok(upload) => upload,
            Err(_) => unreachable!("no pool exceeds u64::MAX bytes"),
        }
    }

    /// The same within `max_bytes` of pool, or the pool's size when larger.
    /// The drawn tree goes as its dirty slots; a scene drawn as instances
    /// ([`Scene::instanced`]) as its models' dirty slots and the instance
    /// words that changed (the composed tree stays on the CPU, for reading
    /// voxels).
    pub fn take_uploads_within(&mut self, max_bytes: u64) -> Result<SceneUpload, PoolTooLarge> {
        let origin = self.tree.origin();
        let instanced = self.instanced().is_some();
        match self.objects.as_deref_mut().filter(|_| instanced) {
            None => Ok(SceneUpload::Tree(self.tree.pool_mut().flush_within(max_bytes)?)),
            Some(objects) => Ok(SceneUpload::Objects(self.gpu.take(objects, origin, max_bytes)?)),
        }
    }

    /// Marks the whole pool as not uploaded (it goes to a new GPU buffer).
    pub fn forget_uploads(&mut self) {
        self.tree.pool_mut().forget_uploads();
        self.gpu.forget();
    }

    /// Applies a brush to the one model; returns the patch that undoes it.
    /// A scene of objects refuses it: a brush goes into an object's model.
    pub fn apply_brush(&mut self, shape: &Shape, op: Op) -> Result<Patch, EditError> {
        if self.objects.is_some() {
            return Err(ObjectRefusal::NothingToEdit.into());
        }
        let patch = self.tree.apply_brush(shape, op);
        self.touched(patch)
    }

    /// Puts back the one model's cells from an undo patch.
    pub fn apply_patch(&mut self, patch: &Patch) -> Result<Patch, EditError> {
        let undo = self.tree.apply_patch(patch);
        self.touched(undo)
    }

    /// Applies a world brush to object `index`'s model (every placement of
    /// it shows the change); returns the model and its undo patch.
    pub fn apply_in_object(&mut self, index: usize, shape: &Shape, op: Op) -> Result<(usize, Patch), EditError> {
        let (objects, tree) = self.objects_and_drawn_mut()?;
        let applied = objects.apply_brush(tree, index, shape, op);
        self.touched(applied)
    }

    /// Applies a brush given in object `index`'s model cells
    /// ([`Objects::apply_model_brush`]).
    ///
    /// [`Objects::apply_model_brush`]: super::objects::Objects::apply_model_brush
    pub fn apply_in_model(&mut self, index: usize, shape: &Shape, op: Op) -> Result<(usize, Patch), EditError> {
        let (objects, tree) = self.objects_and_drawn_mut()?;
        let applied = objects.apply_model_brush(tree, index, shape, op);
        self.touched(applied)
    }

    /// Puts back model `model`'s cells from an undo patch.
    pub fn apply_model_patch(&mut self, model: usize, patch: &Patch) -> Result<Patch, EditError> {
        let (objects, tree) = self.objects_and_drawn_mut()?;
        let undo = objects.apply_patch(tree, model, patch);
        self.touched(undo)
    }

    /// Changes the scene graph; returns the change that undoes it.
    pub fn apply_graph_change(&mut self, change: &GraphChange) -> Result<GraphChange, EditError> {
        let (objects, tree) = self.objects_and_drawn_mut()?;
        let undo = objects.apply_change(tree, change);
        self.touched(undo)
    }

    /// Shows frame `frame` of a scene of objects: its keys sampled there.
    pub fn set_frame(&mut self, frame: usize) -> Result<(), EditError> {
        let (objects, tree) = self.objects_and_drawn_mut()?;
        let shown = objects.set_frame(tree, frame);
        self.touched(shown)
    }

    /// Shows frame `frame` while it plays: composed at once in a scene
    /// drawn composed; in one drawn as instances (`Scene::instanced`), only
    /// walked, the composed tree catching up at [`Scene::catch_up`].
    pub fn show_frame(&mut self, frame: usize) -> Result<(), EditError> {
        if self.instanced().is_none() {
            return self.set_frame(frame);
        }
        let shown = self.objects_and_drawn_mut()?.0.show_frame(frame);
        self.touched(shown)
    }

    /// Composes the cells the frames [`Scene::show_frame`] showed left
    /// behind: what picking, checks and edits read is the frame shown again.
    pub fn catch_up(&mut self) -> Result<(), EditError> {
        if !self.objects().is_some_and(Objects::is_behind) {
            return Ok(());
        }
        let (objects, tree) = self.objects_and_drawn_mut()?;
        let caught = objects.catch_up(tree);
        self.touched(caught)
    }

    /// Stores a model that nothing places yet.
    pub fn push_model(&mut self, model: Model) -> Result<usize, EditError> {
        let index = self.objects_and_drawn_mut()?.0.push_model(model);
        self.touched(Ok(index))
    }

    /// Takes the last model out, unless it is placed.
    pub fn pop_model(&mut self) -> Result<Model, EditError> {
        let model = self.objects_and_drawn_mut()?.0.pop_model();
        self.touched(model)
    }

    /// `result`, after a new revision: a change made, or a refusal that
    /// may have changed cells before it came (a patch that cannot grow the
    /// root, a model that cannot be composed again).
    fn touched<T>(&mut self, result: Result<T, EditError>) -> Result<T, EditError> {
        self.touch();
        result
    }

    /// The objects and the drawn tree, for a change to the objects that
    /// composes what it changes; an error when the scene has none.
    fn objects_and_drawn_mut(&mut self) -> Result<(&mut Objects, &mut Octree), EditError> {
        let Scene { tree, objects, .. } = self;
        let objects = objects.as_deref_mut().ok_or(ObjectRefusal::NoObjects)?;
        Ok((objects, tree))
    }
}

/// Serialized-subtree tag for a node: eight child subtrees follow.
const NODE_TAG: u32 = 0x8000_0000;
/// Serialized-subtree tag for a brick: two little-endian words of values follow.
const BRICK_TAG: u32 = 0x8000_0001;

/// The previous contents of the cells an edit replaced, plus the root cube
/// before it; applying it restores them. Cells are disjoint.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Patch {
    /// (min corner, level, start of its subtree in `words`).
    cells: Vec<(IVec3, u32, usize)>,
    /// Subtrees in preorder: a uniform value, or a tag and its contents.
    words: Vec<u32>,
    root_before: (IVec3, u32),
}

impl Patch {
    fn new(tree: &Octree) -> Patch {
        Patch { cells: Vec::new(), words: Vec::new(), root_before: (tree.origin, tree.depth) }
    }

    /// Number of cells recorded.
    pub fn cell_count(&self) -> usize {
        self.cells.len()
    }

    /// Approximate heap size in bytes (history memory accounting).
    pub fn heap_bytes(&self) -> usize {
        self.cells.len() * std::mem::size_of::<(IVec3, u32, usize)>() + self.words.len() * 4
    }

    /// Inclusive box of the cells recorded; `None` when there are none.
    pub fn bounds(&self) -> Option<(IVec3, IVec3)> {
        self.cells.iter().fold(None, |acc, &(min, level, _)| {
            let max = min + IVec3::splat((1 << level) - 1);
            Some(acc.map_or((min, max), |(lo, hi): (IVec3, IVec3)| (lo.min(min), hi.max(max))))
        })
    }

    fn subtree(&self, cell: usize) -> &[u32] {
        let start = self.cells[cell].2;
        let end = self.cells.get(cell + 1).map_or(self.words.len(), |c| c.2);
        &self.words[start..end]
    }
}

impl Octree {
    /// Applies a brush. Grows the root first if the shape reaches outside it.
    /// Returns the patch that undoes the edit.
    pub fn apply_brush(&mut self, shape: &Shape, op: Op) -> Result<Patch, EditError> {
        shape.validate()?;
        if op.color() == Some(0) {
            return Err(EditError::ZeroColor);
        }
        let bytes = shape.surface_voxels().saturating_mul(EDIT_BYTES_PER_SURFACE_VOXEL);
        crate::budget::check(|| format!("an edit of about {} surface voxels", shape.surface_voxels()), bytes)?;
        let (lo, hi) = shape.bounds();
        let mut patch = Patch::new(self);
        self.grow_to_contain(lo, hi)?;
        self.root = self.brush_word(self.root, self.origin, self.depth, shape, op, &mut patch);
        Ok(patch)
    }

    /// Restores the cells a patch holds. Returns the patch that undoes this.
    pub fn apply_patch(&mut self, patch: &Patch) -> Result<Patch, EditError> {
        let mut inverse = Patch::new(self);
        for (i, &(min, level, _)) in patch.cells.iter().enumerate() {
            self.grow_to_contain(min, min + IVec3::splat((1 << level) - 1))?;
            let mut cursor = patch.subtree(i).iter().copied();
            self.root = self.replace_cell(self.root, self.origin, self.depth, (min, level), &mut cursor, &mut inverse);
        }
        let (origin, depth) = patch.root_before;
        self.shrink_to(origin, depth);
        Ok(inverse)
    }

    fn brush_word(&mut self, word: u32, min: IVec3, level: u32, shape: &Shape, op: Op, patch: &mut Patch) -> u32 {
        let overlap = shape.overlap(min, 1 << level);
        if overlap == Overlap::Outside {
            return word;
        }
        if level == 1 {
            return self.brush_brick(word, min, shape, op, patch);
        }
        if !is_pointer(word) {
            let new = u32::from(op.apply(word as u8));
            if new == word {
                return word;
            }
            if overlap == Overlap::Inside {
                return self.replace_with(word, min, level, new, patch);
            }
            // Partly covered uniform cell: split it, then edit the parts.
            let split = self.split(word, level);
            return self.brush_children(split, min, level, shape, op, patch);
        }
        match op {
            Op::Place(v) if overlap == Overlap::Inside => self.replace_with(word, min, level, u32::from(v), patch),
            Op::Remove if overlap == Overlap::Inside => self.replace_with(word, min, level, 0, patch),
            _ => self.brush_children(word, min, level, shape, op, patch),
        }
    }

    fn brush_children(&mut self, node: u32, min: IVec3, level: u32, shape: &Shape, op: Op, patch: &mut Patch) -> u32 {
        let mut children: Node = *self.node(node);
        let half = 1 << (level - 1);
        for (octant, child) in children.iter_mut().enumerate() {
            *child = self.brush_word(*child, min + octant_offset(octant) * half, level - 1, shape, op, patch);
        }
        self.make_node(children, level, Some(node))
    }

    fn brush_brick(&mut self, word: u32, min: IVec3, shape: &Shape, op: Op, patch: &mut Patch) -> u32 {
        let old: Brick = if is_pointer(word) { *self.brick(word) } else { [word as u8; 8] };
        let mut new = old;
        for (octant, value) in new.iter_mut().enumerate() {
            if shape.contains(min + octant_offset(octant)) {
                *value = op.apply(*value);
            }
        }
        if new == old {
            return word;
        }
        self.record(patch, min, 1, word);
        old.iter().for_each(|v| self.counts.remove(*v, 1));
        new.iter().for_each(|v| self.counts.add(*v, 1));
        self.make_brick(new, is_pointer(word).then_some(word))
    }

    /// Replaces a whole cell by a uniform word, recording the old content.
    fn replace_with(&mut self, old: u32, min: IVec3, level: u32, new: u32, patch: &mut Patch) -> u32 {
        self.record(patch, min, level, old);
        self.recount(old, new, level);
        self.release(old, level);
        new
    }

    /// Appends a cell's current subtree to a patch.
    fn record(&self, patch: &mut Patch, min: IVec3, level: u32, word: u32) {
        patch.cells.push((min, level, patch.words.len()));
        self.serialize(word, level, &mut patch.words);
    }

    fn serialize(&self, word: u32, level: u32, out: &mut Vec<u32>) {
        if !is_pointer(word) {
            out.push(word);
        } else if level == 1 {
            let b = self.brick(word);
            out.extend([
                BRICK_TAG,
                u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                u32::from_le_bytes([b[4], b[5], b[6], b[7]]),
            ]);
        } else {
            out.push(NODE_TAG);
            for child in *self.node(word) {
                self.serialize(child, level - 1, out);
            }
        }
    }

    /// Rebuilds a serialized subtree in the pool. A truncated stream reads as
    /// empty cells rather than panicking.
    fn deserialize(&mut self, words: &mut impl Iterator<Item = u32>, level: u32) -> u32 {
        match words.next().unwrap_or(0) {
            NODE_TAG if level >= 2 => {
                let mut children: Node = [0; 8];
                for child in &mut children {
                    *child = self.deserialize(words, level - 1);
                }
                self.make_node(children, level, None)
            }
            BRICK_TAG if level == 1 => {
                let lo = words.next().unwrap_or(0).to_le_bytes();
                let hi = words.next().unwrap_or(0).to_le_bytes();
                self.make_brick([lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]], None)
            }
            value if value <= 255 => value,
            _ => 0,
        }
    }

    /// Walks down to the target cell (splitting uniform cells on the way),
    /// swaps in the serialized subtree, and collapses on the way back up.
    fn replace_cell(
        &mut self,
        word: u32,
        min: IVec3,
        level: u32,
        target: (IVec3, u32),
        subtree: &mut impl Iterator<Item = u32>,
        inverse: &mut Patch,
    ) -> u32 {
        if level <= target.1 {
            self.record(inverse, min, level, word);
            let new = self.deserialize(subtree, level);
            self.recount(word, new, level);
            self.release(word, level);
            return new;
        }
        let node = if is_pointer(word) { word } else { self.split(word, level) };
        let half = 1 << (level - 1);
        let rel = (target.0 - min) / half;
        let octant = (rel.x | rel.y << 1 | rel.z << 2) as usize;
        let mut children: Node = *self.node(node);
        children[octant] = self.replace_cell(
            children[octant],
            min + octant_offset(octant) * half,
            level - 1,
            target,
            subtree,
            inverse,
        );
        self.make_node(children, level, Some(node))
    }

    /// Makes the root cube hold `lo..=hi`: adds root levels toward it, or,
    /// when that alignment would pass 2^[`MAX_DEPTH`] while the solid voxels
    /// and the edit together still fit in such a cube, moves the root.
    /// Nothing changes when the edit is refused.
    pub fn grow_to_contain(&mut self, lo: IVec3, hi: IVec3) -> Result<(), EditError> {
        if lo.min_element() <= -WORLD_LIMIT || hi.max_element() >= WORLD_LIMIT {
            return Err(EditError::OutsideWorld { min: lo, max: hi });
        }
        if self.grown_depth(lo, hi) <= MAX_DEPTH {
            self.add_root_levels(lo, hi);
            return Ok(());
        }
        let (union_lo, union_hi) = match self.solid_bounds() {
            Some((s_lo, s_hi)) => (s_lo.min(lo), s_hi.max(hi)),
            None => (lo, hi),
        };
        let extent = (union_hi.as_i64vec3() - union_lo.as_i64vec3()).max_element() + 1;
        if extent > 1 << MAX_DEPTH {
            return Err(EditError::TooWide { min: lo, max: hi });
        }
        self.move_root(union_lo, extent);
        Ok(())
    }

    /// The root depth that adding levels toward `lo..=hi` would reach.
    fn grown_depth(&self, lo: IVec3, hi: IVec3) -> u32 {
        let (mut origin, mut depth) = (self.origin.as_i64vec3(), self.depth);
        let inside = |origin: glam::I64Vec3, depth: u32, p: IVec3| {
            let rel = p.as_i64vec3() - origin;
            rel.cmpge(glam::I64Vec3::ZERO).all() && rel.cmplt(glam::I64Vec3::splat(1 << depth)).all()
        };
        while !(inside(origin, depth, lo) && inside(origin, depth, hi)) && depth <= MAX_DEPTH {
            let below = lo.as_i64vec3().cmplt(origin);
            let octant = usize::from(below.x) | usize::from(below.y) << 1 | usize::from(below.z) << 2;
            origin -= octant_offset(octant).as_i64vec3() * (1 << depth);
            depth += 1;
        }
        depth
    }

    /// Adds root levels until the root cube holds `lo..=hi`; the caller has
    /// checked with [`Octree::grown_depth`] that this stays within MAX_DEPTH.
    fn add_root_levels(&mut self, lo: IVec3, hi: IVec3) {
        while !(self.contains(lo) && self.contains(hi)) {
            let size = 1 << self.depth;
            // The old root becomes the child on the side away from the edit.
            let below = lo.cmplt(self.origin);
            let octant = usize::from(below.x) | usize::from(below.y) << 1 | usize::from(below.z) << 2;
            let mut children: Node = [0; 8];
            children[octant] = self.root;
            self.root = if self.root == 0 { 0 } else { self.make_node(children, self.depth + 1, None) };
            self.origin -= octant_offset(octant) * size;
            self.depth += 1;
        }
    }

    /// Makes every voxel of the box `min..=max` inside the root hold
    /// `value` (1..=255), writing uniform words where the box covers whole
    /// cells: what composing a scene of objects copies a model's uniform
    /// cells with, so that a big solid region costs its surface, not its
    /// volume. Nothing is recorded for undo (the models hold the truth).
    pub fn fill_box(&mut self, min: IVec3, max: IVec3, value: u8) {
        let shape = Shape::Box { min, max };
        let mut scratch = Patch::default();
        self.root = self.brush_word(self.root, self.origin, self.depth, &shape, Op::Place(value), &mut scratch);
    }

    /// Rebuilds the tree under a root cube at `origin`, `extent` voxels wide
    /// (at most 2^MAX_DEPTH), copying every solid cell. Every slot changes,
    /// so the next flush uploads the whole pool; this happens only when an
    /// edit would otherwise be refused.
    fn move_root(&mut self, origin: IVec3, extent: i64) {
        let depth = (extent.max(1) as u64).next_power_of_two().trailing_zeros();
        let mut moved = Octree::empty(origin, depth);
        // The copy keeps no undo record: the edit's patch holds the cells it changes.
        self.for_each_solid_cell(|min, size, value| moved.fill_box(min, min + IVec3::splat(size - 1), value));
        // New slots are all dirty, so the next flush uploads the whole tree.
        *self = moved;
    }

    /// Drops root levels down to the cube (`origin`, `depth`) while everything
    /// outside it is empty; undo uses this to take back a growth.
    fn shrink_to(&mut self, origin: IVec3, depth: u32) {
        while self.depth > depth {
            let half = 1 << (self.depth - 1);
            let rel = (origin - self.origin) / half;
            if rel.cmplt(IVec3::ZERO).any() || rel.cmpgt(IVec3::ONE).any() {
                return; // not a sub-cube of the current root
            }
            let octant = (rel.x | rel.y << 1 | rel.z << 2) as usize;
            if is_pointer(self.root) {
                let children = *self.node(self.root);
                if children.iter().enumerate().any(|(i, c)| i != octant && *c != 0) {
                    return;
                }
                self.pool.nodes.free(crate::gpu_pool::slot_of(self.root));
                self.root = children[octant];
            } else if self.root != 0 {
                return;
            }
            self.origin += octant_offset(octant) * half;
            self.depth -= 1;
        }
    }
}
