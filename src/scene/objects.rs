//! A scene of several objects: the models (each its own octree, stored
//! once however often it is placed), the scene graph that places them, and
//! the file's chunks octovox keeps without reading.
//!
//! What is drawn is the scene's one octree, composed from the visible
//! objects in walk order (the later wins where two overlap, as loading
//! always composed them). The models are the truth: an edit goes into a
//! model through the inverse of its object's cell map, and every placement
//! of that model is composed again over the cells it covers. Hiding,
//! showing and moving an object compose the cells it left and reached.

use std::collections::HashMap;

use glam::IVec3;

use super::anim;
use super::graph::{
    self, GraphError, Layer, NameEntry, Node, NodeKind, Object, OutlineRow, SceneGraph, Walked, path_of,
};
use super::octree::{Octree, WORLD_LIMIT};
use super::transform::{Placing, Pose, Rotation, Transform, Turn, TurnedMap};
use super::{EditError, ObjectRefusal, Op, Patch, Shape};

/// Placements of one model beyond which an edit of it composes one box
/// around them all (see `Objects::recompose_model`).
const MANY_PLACEMENTS: usize = 64;

/// Most voxels a merge gathers into one model: a full 256³ model, the
/// largest a .vox file stores in one.
const MERGE_LIMIT: u64 = 1 << 24;

/// Single voxels composing gathers before writing them into the tree they
/// go to: 16 bytes each, 1 MiB a batch.
const PLACED_BATCH: usize = 1 << 16;

/// Largest box one removal covers while composing (a brush's widest).
const COMPOSE_BOX: i32 = super::shape::MAX_BRUSH_EXTENT;

/// One stored model: its voxels in its own grid (MagicaVoxel's axes, cells
/// `0..size` as loaded; edits may reach past them) and the size the file
/// gave it, whose half is the pivot its placements turn about.
#[derive(Clone, Debug)]
pub struct Model {
    pub size: [u32; 3],
    pub tree: Octree,
}

/// Models are equal when they hold the same voxels in the same grid,
/// however their pools are laid out.
impl PartialEq for Model {
    fn eq(&self, other: &Model) -> bool {
        self.size == other.size && self.tree.voxels() == other.tree.voxels()
    }
}

impl Eq for Model {}

/// A chunk octovox does not interpret (`rCAM`, `rOBJ`, `NOTE`, `META`,
/// `IMAP`, unknown ones), written back as read.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct KeptChunk {
    pub id: [u8; 4],
    pub content: Vec<u8>,
}

/// The objects of a scene and what they are made of.
#[derive(Clone, Debug)]
pub struct Objects {
    /// `None` for an old file of several models and no scene graph
    /// (animation frames): model `frame` is shown, in its own grid.
    pub graph: Option<SceneGraph>,
    pub models: Vec<Model>,
    pub kept: Vec<KeptChunk>,
    /// The animation frame shown (keyframes `_f`, or the model without a graph).
    pub frame: usize,
    /// The walk at `frame`, and each object's cell map.
    objects: Vec<Object>,
    outline: Vec<OutlineRow>,
    /// The walk's named transforms, which objects' paths are made of.
    names: Vec<NameEntry>,
    maps: Vec<Placing>,
    /// The object edits go to, by index in walk order.
    pub selected: Option<usize>,
    /// The layer `object new` puts objects on (`layer N active`); the
    /// first layer when unset or gone.
    pub new_layer: Option<u32>,
    /// While frames shown by [`Objects::show_frame`] are not composed: the
    /// placements the composed tree still holds, until [`Objects::catch_up`]
    /// composes what differs from them.
    behind: Option<Vec<(usize, Placing)>>,
    /// [`Objects::has_free_turns`], as the last walk found it.
    free_turns: bool,
}

/// Why the objects cannot be placed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ObjectsError {
    #[error(transparent)]
    Graph(#[from] GraphError),
    #[error(
        "a voxel of model {model} lands past the coordinate limit ±{WORLD_LIMIT} that edits and rendering keep exact"
    )]
    OutsideWorld { model: usize },
}

impl Objects {
    /// Places the models by `graph` at `frame`; the placed models may hold at
    /// most `voxel_limit` voxels together.
    pub fn new(
        graph: Option<SceneGraph>,
        models: Vec<Model>,
        kept: Vec<KeptChunk>,
        frame: usize,
        voxel_limit: usize,
    ) -> Result<Objects, ObjectsError> {
        let mut objects = Objects {
            graph,
            models,
            kept,
            frame,
            objects: Vec::new(),
            outline: Vec::new(),
            names: Vec::new(),
            maps: Vec::new(),
            selected: None,
            new_layer: None,
            behind: None,
            free_turns: false,
        };
        objects.walk(voxel_limit)?;
        Ok(objects)
    }

    /// Walks the graph again (after a change to it) and maps every object.
    fn walk(&mut self, voxel_limit: usize) -> Result<(), ObjectsError> {
        Walked { objects: self.objects, outline: self.outline, names: self.names } =
            self.walked_at(self.frame, voxel_limit)?;
        self.maps = self.placings(&self.objects)?;
        self.free_turns = self.freely_turned() > 0 || Objects::keys_turn_freely(self.graph.as_ref());
        // Each model's bounds once, however many objects place it (2,000
        // references of one tree spent 6 ms a played frame here).
        let mut bounds: Vec<Option<Option<(IVec3, IVec3)>>> = vec![None; self.models.len()];
        for (object, map) in self.objects.iter().zip(&self.maps) {
            let model = object.placement.model;
            if let Some((lo, hi)) = *bounds[model].get_or_insert_with(|| self.models[model].tree.solid_bounds()) {
                let (lo, hi) = map.apply_box(lo, hi);
                if lo.min_element() <= -WORLD_LIMIT || hi.max_element() >= WORLD_LIMIT {
                    return Err(ObjectsError::OutsideWorld { model: object.placement.model });
                }
            }
        }
        Ok(())
    }

    /// The graph walked at `frame`; without a graph, model `frame` as stored.
    fn walked_at(&self, frame: usize, voxel_limit: usize) -> Result<Walked, GraphError> {
        if let Some(graph) = &self.graph {
            let voxels: Vec<usize> =
                self.models.iter().map(|m| usize::try_from(m.tree.solid_voxels()).unwrap_or(usize::MAX)).collect();
            return graph.walk(&voxels, frame, voxel_limit);
        }
        if frame >= self.models.len() {
            return Err(GraphError::Bad(format!("frame {frame} requested but there are {} models", self.models.len())));
        }
        let outline = vec![OutlineRow::Object { index: 0, depth: 0 }];
        Ok(Walked { objects: vec![Object::frame(frame)], outline, names: Vec::new() })
    }

    /// How each of `objects` (a walk's) lands on world cells.
    fn placings(&self, objects: &[Object]) -> Result<Vec<Placing>, ObjectsError> {
        objects
            .iter()
            .map(|o| {
                let model = o.placement.model;
                o.placement.placing(self.models[model].size).ok_or(ObjectsError::OutsideWorld { model })
            })
            .collect()
    }

    /// Whether some keyframe, at any frame, turns freely: then objects land
    /// on cells through their centres, not exactly, and the scene is drawn
    /// and exported the same way whatever frame is shown. Found by the walk
    /// (read on every upload: no scan of the graph here).
    pub fn has_free_turns(&self) -> bool {
        self.free_turns
    }

    /// Whether a keyframe of `graph` holds a free turn.
    fn keys_turn_freely(graph: Option<&SceneGraph>) -> bool {
        graph.is_some_and(|g| {
            g.nodes.iter().any(|n| match &n.kind {
                NodeKind::Transform { frames, .. } => frames.iter().any(|k| k.contains_key(graph::TURN_KEY)),
                _ => false,
            })
        })
    }

    /// How many objects are turned by a free angle (or are in a group that is).
    pub fn freely_turned(&self) -> usize {
        self.maps.iter().filter(|m| m.cells().is_none()).count()
    }

    /// The objects in walk order.
    pub fn list(&self) -> &[Object] {
        &self.objects
    }

    /// Object `index`'s path: the names of the named transforms down to it,
    /// joined by `/` (built when asked: objects share their paths' beginnings).
    pub fn path(&self, index: usize) -> String {
        let (Some(graph), Some(object)) = (&self.graph, self.objects.get(index)) else { return String::new() };
        path_of(graph, &self.names, object.name)
    }

    /// The name of a group's transform `transform` (empty for none).
    pub fn group_name(&self, transform: u32) -> &str {
        self.graph.as_ref().and_then(|g| g.node(transform)).and_then(Node::name).unwrap_or_default()
    }

    /// The groups and objects in walk order, as the Outliner shows them.
    pub fn outline(&self) -> &[OutlineRow] {
        &self.outline
    }

    /// How object `index`'s model cells land on world cells.
    pub fn map(&self, index: usize) -> Placing {
        self.maps[index]
    }

    /// The world box of object `index`'s voxels; `None` when its model is empty.
    pub fn world_box(&self, index: usize) -> Option<(IVec3, IVec3)> {
        let (lo, hi) = self.models[self.objects[index].placement.model].tree.solid_bounds()?;
        Some(self.maps[index].apply_box(lo, hi))
    }

    /// The world box of object `index`'s model's root cube: it holds every
    /// voxel the object may show, and takes no walk of the model.
    fn reach(&self, index: usize) -> (IVec3, IVec3) {
        let tree = &self.models[self.objects[index].placement.model].tree;
        let lo = tree.origin();
        self.maps[index].apply_box(lo, lo + IVec3::splat(tree.size() - 1))
    }

    /// Builds the octree of every visible object, in walk order.
    pub fn compose(&self) -> Result<Octree, EditError> {
        let boxes: Vec<(IVec3, IVec3)> = self.visible().filter_map(|i| self.world_box(i)).collect();
        let Some(bounds) = boxes.iter().copied().reduce(|a, b| (a.0.min(b.0), a.1.max(b.1))) else {
            return Ok(Octree::default());
        };
        let mut tree = Octree::empty_for(bounds.0, bounds.1)?;
        for index in self.visible() {
            self.insert_placed(&mut tree, index, bounds);
        }
        Ok(tree)
    }

    fn visible(&self) -> impl DoubleEndedIterator<Item = usize> + '_ {
        (0..self.objects.len()).filter(|&i| !self.objects[i].hidden)
    }

    /// Writes object `index`'s voxels inside the world box `lo..=hi` into
    /// `tree` (which holds that box), over what is there.
    fn insert_placed(&self, tree: &mut Octree, index: usize, (lo, hi): (IVec3, IVec3)) {
        let model = &self.models[self.objects[index].placement.model].tree;
        match self.maps[index] {
            Placing::Cells(map) => copy_cells(model, map.invert_box(lo, hi), tree, |p| map.apply(p)),
            Placing::Turned(map) => resample_cells(model, &map, (lo, hi), tree),
        }
    }

    /// Composes the world cells `lo..=hi` of `tree` again from the objects.
    pub fn recompose(&self, tree: &mut Octree, (lo, hi): (IVec3, IVec3)) -> Result<(), EditError> {
        tree.grow_to_contain(lo, hi)?;
        for min in boxes_of(lo, hi) {
            let max = (min + IVec3::splat(COMPOSE_BOX - 1)).min(hi);
            tree.apply_brush(&Shape::Box { min, max }, Op::Remove)?;
        }
        for index in self.visible() {
            // The model's root cube, not its voxels' box: as good a test
            // (the copy below visits only cells in the box) at no cost.
            let (a, b) = self.reach(index);
            if a.cmple(hi).all() && b.cmpge(lo).all() {
                self.insert_placed(tree, index, (lo, hi));
            }
        }
        Ok(())
    }

    /// Whether object `index` is locked (`_lock` on its transform): its
    /// voxels, place and group are not to be changed, and a click does not
    /// pick it.
    pub fn locked(&self, index: usize) -> bool {
        self.transform_node(index).is_ok_and(|node| graph::is_set(&node.attributes, "_lock"))
    }

    /// Refuses a change to any of objects `indices` that is locked.
    fn unlocked(&self, indices: &[usize]) -> Result<(), EditError> {
        match indices.iter().find(|&&k| self.locked(k)) {
            Some(k) => Err(ObjectRefusal::Locked(*k).into()),
            None => Ok(()),
        }
    }

    /// Whether object `index` is shown and its model has a voxel in the
    /// world box `lo..=hi`.
    pub fn holds_voxels_in(&self, index: usize, lo: IVec3, hi: IVec3) -> bool {
        let Some(object) = self.objects.get(index).filter(|o| !o.hidden) else { return false };
        let (mlo, mhi) = self.maps[index].invert_box(lo, hi);
        let mut any = false;
        self.models[object.placement.model].tree.for_each_solid_cell_in(mlo, mhi, |_, _, _| any = true);
        any
    }

    /// The visible object drawn at world cell `at` (the last in walk order
    /// holding a voxel there), if any.
    pub fn owner_at(&self, at: IVec3) -> Option<usize> {
        self.visible()
            .rev()
            .find(|&i| self.models[self.objects[i].placement.model].tree.get(self.maps[i].invert(at)) != 0)
    }

    /// The object an edit at `at` goes to: the selected one, else the one
    /// drawn there, else the last visible one whose box holds it, else the
    /// first object.
    pub fn target_at(&self, at: IVec3) -> Option<usize> {
        self.selected
            .filter(|&i| i < self.objects.len())
            .or_else(|| self.owner_at(at))
            .or_else(|| {
                self.visible()
                    .rev()
                    .find(|&i| self.world_box(i).is_some_and(|(lo, hi)| at.cmpge(lo).all() && at.cmple(hi).all()))
            })
            .or((!self.objects.is_empty()).then_some(0))
    }

    /// Applies a world brush to object `index`'s model and composes every
    /// placement of it again; returns the model's undo patch.
    pub fn apply_brush(
        &mut self,
        tree: &mut Octree,
        index: usize,
        shape: &Shape,
        op: Op,
    ) -> Result<(usize, Patch), EditError> {
        let map = self.maps.get(index).ok_or(ObjectRefusal::NoObject(index))?;
        if map.cells().is_none() && matches!(shape, Shape::Box { .. }) {
            // A world box is no box of the turned model's cells, and the box
            // around them would reach past it.
            return Err(ObjectRefusal::FreelyTurned(index, "a box edit of").into());
        }
        let local = map.invert_shape(shape);
        self.apply_model_brush(tree, index, &local, op)
    }

    /// Applies a brush given in object `index`'s model cells (as its .vox
    /// numbers them: what a click on a freely turned object edits, where a
    /// model cell may stand for no world cell) and composes every
    /// placement of the model again; returns the model's undo patch.
    pub fn apply_model_brush(
        &mut self,
        tree: &mut Octree,
        index: usize,
        local: &Shape,
        op: Op,
    ) -> Result<(usize, Patch), EditError> {
        let model = self.objects.get(index).ok_or(ObjectRefusal::NoObject(index))?.placement.model;
        self.unlocked(&[index])?;
        self.catch_up(tree)?;
        // A reference shares the model: an edit through an unlocked
        // placement would change a locked one too (issue 48, item 11).
        if let Some(k) = (0..self.objects.len()).find(|&k| self.objects[k].placement.model == model && self.locked(k)) {
            return Err(ObjectRefusal::LockedReference { locked: k, index }.into());
        }
        let patch = self.models[model].tree.apply_brush(local, op)?;
        // Nothing changed (a delete over cells another placement of the
        // model already emptied): nothing to compose again.
        if patch.bounds().is_some() {
            self.recompose_model(tree, model, local.bounds())?;
        }
        Ok((model, patch))
    }

    /// Puts back a model's cells from an undo patch; returns the patch that
    /// undoes this.
    pub fn apply_patch(&mut self, tree: &mut Octree, model: usize, patch: &Patch) -> Result<Patch, EditError> {
        self.catch_up(tree)?;
        let inverse = self.models.get_mut(model).ok_or(ObjectRefusal::NoModel(model))?.tree.apply_patch(patch)?;
        if let Some(bounds) = patch.bounds() {
            self.recompose_model(tree, model, bounds)?;
        }
        Ok(inverse)
    }

    /// Composes the world cells every placement of `model` maps its cells
    /// `lo..=hi` to. Each region costs a pass over the objects, so a model
    /// placed more than [`MANY_PLACEMENTS`] times has the box around all its
    /// regions composed in one pass instead.
    fn recompose_model(&self, tree: &mut Octree, model: usize, (lo, hi): (IVec3, IVec3)) -> Result<(), EditError> {
        let regions: Vec<(IVec3, IVec3)> = (0..self.objects.len())
            .filter(|&i| self.objects[i].placement.model == model)
            .map(|i| self.maps[i].apply_box(lo, hi))
            .collect();
        if regions.len() > MANY_PLACEMENTS {
            let all = regions.iter().copied().reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)));
            return all.map_or(Ok(()), |all| self.recompose(tree, all));
        }
        regions.into_iter().try_for_each(|region| self.recompose(tree, region))
    }

    /// How many objects place each model.
    /// Whether some model is placed more than once (a reference): then the
    /// scene is drawn as instances, its models stored once on the GPU too.
    pub fn has_references(&self) -> bool {
        let mut placed = vec![false; self.models.len()];
        self.objects.iter().any(|o| std::mem::replace(&mut placed[o.placement.model], true))
    }

    pub fn placements_of(&self, model: usize) -> usize {
        self.objects.iter().filter(|o| o.placement.model == model).count()
    }

    /// Applies a change to the graph, walks it again and composes the cells
    /// of every object that moved, came, went, or was hidden or shown.
    /// Returns the change that undoes it; a change the walk refuses (a
    /// cycle) changes nothing.
    pub fn apply_change(&mut self, tree: &mut Octree, change: &GraphChange) -> Result<GraphChange, EditError> {
        self.catch_up(tree)?;
        let graph = self.graph.as_mut().ok_or(ObjectRefusal::NoGraph)?;
        let saved = graph.clone();
        let inverse = change.apply(graph);
        self.compose_rewalk(tree, |objects| objects.graph = Some(saved))?;
        Ok(inverse)
    }

    /// Shows frame `frame`: every key is sampled there, and the cells of
    /// every object that moved, came, went or shows another model are
    /// composed again. A frame the walk refuses changes nothing.
    pub fn set_frame(&mut self, tree: &mut Octree, frame: usize) -> Result<(), EditError> {
        self.catch_up(tree)?;
        let shown = std::mem::replace(&mut self.frame, frame);
        self.compose_rewalk(tree, |objects| objects.frame = shown)
    }

    /// Shows frame `frame` without composing it: every key sampled there
    /// and the objects walked, the world boxes of what moved kept until
    /// [`Objects::catch_up`]. For a scene drawn as instances, which the GPU
    /// draws from the objects, not from the composed tree: a played frame
    /// then writes instance words and nothing else, and the composed tree
    /// (which picking, checks and saving read) catches up before the next
    /// line or edit (`Editor::run`). A frame the walk refuses changes nothing.
    pub fn show_frame(&mut self, frame: usize) -> Result<(), EditError> {
        if self.behind.is_none() {
            self.behind = Some(self.drawn());
        }
        let shown = std::mem::replace(&mut self.frame, frame);
        if let Err(err) = self.walk(usize::MAX) {
            self.frame = shown;
            self.walk(usize::MAX)?;
            return Err(err.into());
        }
        Ok(())
    }

    /// Whether frames shown by [`Objects::show_frame`] are not composed yet.
    pub fn is_behind(&self) -> bool {
        self.behind.is_some()
    }

    /// Composes the cells of what differs between the placements the
    /// composed tree holds and the frame shown: however many frames were
    /// played, each moved object's boxes then and now, once.
    pub fn catch_up(&mut self, tree: &mut Octree) -> Result<(), EditError> {
        let Some(before) = self.behind.take() else { return Ok(()) };
        for region in self.changed_regions(&before) {
            if let Err(err) = self.recompose(tree, region) {
                // Composing a region again is harmless: the next try redoes them all.
                self.behind = Some(before);
                return Err(err);
            }
        }
        Ok(())
    }

    /// The world boxes of the placements that differ between `before` (a
    /// walk's [`Objects::drawn`]) and now.
    fn changed_regions(&self, before: &[(usize, Placing)]) -> Vec<(IVec3, IVec3)> {
        let mut counts: HashMap<(usize, Placing), i64> = HashMap::new();
        for key in before {
            *counts.entry(*key).or_default() += 1;
        }
        for key in &self.drawn() {
            *counts.entry(*key).or_default() -= 1;
        }
        counts
            .into_iter()
            .filter(|&(_, count)| count != 0)
            .filter_map(|((model, map), _)| {
                self.models[model].tree.solid_bounds().map(|(lo, hi)| map.apply_box(lo, hi))
            })
            .collect()
    }

    /// After a change to the graph or the frame (made on a composed tree:
    /// caught up first): walks again and composes the cells of every object
    /// drawn differently. Where the walk or the tree refuses, `undo` takes
    /// the change back and the scene is as it was.
    fn compose_rewalk(&mut self, tree: &mut Octree, undo: impl FnOnce(&mut Objects)) -> Result<(), EditError> {
        let before = self.drawn();
        if let Err(err) = self.walk(usize::MAX) {
            undo(self);
            self.walk(usize::MAX)?;
            return Err(err.into());
        }
        let regions = self.changed_regions(&before);
        for (done, &region) in regions.iter().enumerate() {
            if let Err(err) = self.recompose(tree, region) {
                // A region the tree cannot hold (a move past the world's
                // width): the change goes back, and so do the cells already
                // composed from it. A refused change leaves the scene as it was.
                undo(self);
                self.walk(usize::MAX)?;
                for &region in &regions[..done] {
                    self.recompose(tree, region)?;
                }
                // The failed one too, where its removal ran before the
                // refusal; where the refusal came first it refuses again.
                let _ = self.recompose(tree, regions[done]);
                return Err(err);
            }
        }
        Ok(())
    }

    /// A copy of the objects walked at frame `frame`: what a frame of a
    /// rendered animation composes from, the same whatever frame was shown
    /// before (so a frame is the same whichever process renders it).
    pub fn at_frame(&self, frame: usize) -> Result<Objects, ObjectsError> {
        let mut objects = self.clone();
        objects.frame = frame;
        // What it composes into is a tree of its own, composed whole.
        objects.behind = None;
        objects.walk(usize::MAX)?;
        Ok(objects)
    }

    /// How every object lands on world cells at frame `frame`, in walk order (the graph
    /// walked there, the models not copied): what an export samples.
    pub fn maps_at(&self, frame: usize) -> Result<Vec<Placing>, ObjectsError> {
        self.placings(&self.walked_at(frame, usize::MAX)?.objects)
    }

    /// The world box of every shown object's voxels at frame `frame`, the
    /// models not copied; `None` when none has any.
    pub fn bounds_at(&self, frame: usize) -> Result<Option<(IVec3, IVec3)>, ObjectsError> {
        let objects = self.walked_at(frame, usize::MAX)?.objects;
        let maps = self.placings(&objects)?;
        let boxes = objects.iter().zip(&maps).filter(|(o, _)| !o.hidden).filter_map(|(o, map)| {
            let (lo, hi) = self.models[o.placement.model].tree.solid_bounds()?;
            Some(map.apply_box(lo, hi))
        });
        Ok(boxes.reduce(|a, b| (a.0.min(b.0), a.1.max(b.1))))
    }

    /// The frame shown, as keys name frames.
    fn key_frame(&self) -> Result<u32, EditError> {
        u32::try_from(self.frame).map_err(|_| GraphError::FrameTooLate(self.frame).into())
    }

    /// The frames the document plays: its own range, else from the first
    /// key to the last, else every model of a file of animation frames.
    pub fn frame_range(&self) -> (u32, u32) {
        let last_model = u32::try_from(self.models.len().saturating_sub(1)).unwrap_or(u32::MAX);
        match &self.graph {
            None => (0, last_model),
            Some(graph) => {
                graph.animation.range.or_else(|| super::anim::keyed_range(graph).ok().flatten()).unwrap_or((0, 0))
            }
        }
    }

    /// (model, cell map) of every visible object.
    fn drawn(&self) -> Vec<(usize, Placing)> {
        self.visible().map(|i| (self.objects[i].placement.model, self.maps[i])).collect()
    }

    /// Adds a model at the end (what `object unique` and a duplicate that is
    /// not a reference store); nothing places it yet.
    pub fn push_model(&mut self, model: Model) -> usize {
        self.models.push(model);
        self.models.len() - 1
    }

    /// Takes the last model back out (the undo of [`Objects::push_model`]),
    /// unless an object still places it.
    pub fn pop_model(&mut self) -> Result<Model, EditError> {
        let last = self.models.len().checked_sub(1).ok_or(ObjectRefusal::NoModels)?;
        if self.placements_of(last) > 0 {
            return Err(ObjectRefusal::StillPlaced(last).into());
        }
        Ok(self.models.pop().expect("checked above"))
    }

    /// The transform node of object `index` (what moves, turns, hides and
    /// names it).
    pub fn transform_node(&self, index: usize) -> Result<&Node, EditError> {
        let graph = self.graph.as_ref().ok_or(ObjectRefusal::NoGraph)?;
        let object = self.objects.get(index).ok_or(ObjectRefusal::NoObject(index))?;
        object.transform_node.and_then(|id| graph.node(id)).ok_or(ObjectRefusal::NoTransform(index).into())
    }

    /// The index of the key of `node` a move or a turn changes: the one at
    /// the frame shown; for a node that moves and has none there, a new key
    /// there holding what the frame shows (a move in an animation keys the
    /// frame, as MagicaVoxel's does); for a node that does not move, its
    /// one key, so the object moves at every frame.
    fn key_to_change(&self, node: &mut Node) -> Result<usize, EditError> {
        let NodeKind::Transform { frames, .. } = &mut node.kind else {
            return Err(ObjectRefusal::NotATransform(node.id).into());
        };
        if frames.is_empty() {
            frames.push(graph::Attributes::new());
        }
        // A looping node shows, outside its keys, the frame its loop wraps
        // to: that frame is keyed (a key outside would lengthen the loop).
        let timed = anim::keys_in_time(frames.iter(), node.id)?;
        let (first, last) = (timed[0].0, timed[timed.len() - 1].0);
        let frame = match self.key_frame()? {
            frame if graph::is_set(&node.attributes, "_loop") => anim::looped(first, last, frame),
            frame => frame,
        };
        if let Some(k) = anim::key_at(frames, frame, node.id)? {
            return Ok(k);
        }
        if !anim::is_animated(frames, node.id)? {
            return Ok(anim::keys_in_time(frames.iter(), node.id)?[0].1);
        }
        let shown = anim::sample_transform(frames, &node.attributes, frame, node.id)?;
        Ok(insert_key(frames, frame, shown, node.id)?)
    }

    /// What object `index`'s own transform node places it by at the frame shown.
    fn own_pose(&self, node: &Node) -> Result<Pose, EditError> {
        let NodeKind::Transform { frames, .. } = &node.kind else {
            return Err(ObjectRefusal::NotATransform(node.id).into());
        };
        Ok(anim::sample_transform(frames, &node.attributes, self.key_frame()?, node.id)?)
    }

    /// The change that keys object `index`'s transform at the frame shown
    /// with what it shows there, the way to the next key eased by `ease`
    /// (`object key`); a key already there takes the easing.
    pub fn keyed(&self, index: usize, ease: anim::Ease) -> Result<GraphChange, EditError> {
        self.unlocked(&[index])?;
        let frame = self.key_frame()?;
        let mut node = self.transform_node(index)?.clone();
        let shown = self.own_pose(&node)?;
        let NodeKind::Transform { frames, .. } = &mut node.kind else { unreachable!("checked by own_pose") };
        let k = match anim::key_at(frames, frame, node.id)? {
            Some(k) => k,
            None => insert_key(frames, frame, shown, node.id)?,
        };
        // A key that had no frame (a still object's) is now at frame 0.
        frames[k].insert("_f".to_owned(), frame.to_string());
        ease.write(&mut frames[k]);
        Ok(GraphChange { nodes: vec![node], ..GraphChange::default() })
    }

    /// The change that takes object `index`'s key at the frame shown out
    /// (`object unkey`); the object then shows what its other keys give.
    pub fn unkeyed(&self, index: usize) -> Result<GraphChange, EditError> {
        self.unlocked(&[index])?;
        let frame = self.key_frame()?;
        let mut node = self.transform_node(index)?.clone();
        let NodeKind::Transform { frames, .. } = &mut node.kind else {
            return Err(ObjectRefusal::NotATransform(node.id).into());
        };
        let k = anim::key_at(frames, frame, node.id)?.ok_or(ObjectRefusal::NoKey { index, frame })?;
        if frames.len() == 1 {
            return Err(ObjectRefusal::LastKey(index).into());
        }
        frames.remove(k);
        Ok(GraphChange { nodes: vec![node], ..GraphChange::default() })
    }

    /// The change that sets the document's playback settings.
    pub fn with_animation(&self, animation: anim::Animation) -> Result<GraphChange, EditError> {
        self.graph.as_ref().ok_or(ObjectRefusal::NoGraph)?;
        Ok(GraphChange { animation: Some(animation), ..GraphChange::default() })
    }

    /// The change that moves object `index` by `by` world voxels.
    pub fn moved(&self, index: usize, by: IVec3) -> Result<GraphChange, EditError> {
        self.retransformed(index, "moving", |own, parent| {
            // World (x, y, z) is MagicaVoxel (x, −z, y); the parent's turn
            // is undone so that the object moves along world axes.
            let step = parent.inverse().apply([by.x, -by.z, by.y].map(i64::from));
            let translation = [0, 1, 2].map(|i| own.transform.translation[i] + step[i]);
            Pose { transform: Transform { translation, ..own.transform }, ..own }
        })
    }

    /// The change that turns object `index` `degrees` counter-clockwise
    /// (negative: clockwise) about world axis `axis` (0, 1, 2 = x, y, z),
    /// seen from its positive end, about its pivot. Whole quarter turns of
    /// an object without a free turn stay signed permutations, exactly;
    /// any other angle gives the keyframe a free turn (`_ov_turn`) and `_r`
    /// the nearest quarter turns.
    pub fn turned(&self, index: usize, axis: usize, degrees: f64) -> Result<GraphChange, EditError> {
        if !degrees.is_finite() {
            return Err(ObjectRefusal::BadAngle(degrees.to_string()).into());
        }
        // Exact, and keeps a huge angle's turn (1e17° in radians loses it).
        let degrees = degrees % 360.0;
        let quarters = degrees / 90.0;
        let own = self.own_pose(self.transform_node(index)?)?;
        if quarters.fract() == 0.0 && own.turn.is_none() {
            return self.rotated(index, axis, (quarters % 4.0) as i64);
        }
        // World x, y, z are MagicaVoxel +x, +z and −y.
        let about = [glam::DVec3::X, glam::DVec3::Z, glam::DVec3::NEG_Y][axis.min(2)];
        let turn = glam::DMat3::from_axis_angle(about, degrees.to_radians());
        self.retransformed(index, "turning", |own, parent| {
            let p = parent.matrix();
            Pose::of_matrix(p.transpose() * turn * p * own.matrix(), own.transform.translation)
        })
    }

    /// The change that turns object `index` `quarters` quarters
    /// counter-clockwise (negative: clockwise) about world axis `axis`
    /// (0, 1, 2 = x, y, z), seen from its positive end, about its pivot.
    pub fn rotated(&self, index: usize, axis: usize, quarters: i64) -> Result<GraphChange, EditError> {
        // World x, y, z are MagicaVoxel +x, +z and −y: a turn about world z
        // is three about MagicaVoxel y.
        let quarter = match axis {
            0 => Rotation::quarter_turn(0),
            1 => Rotation::quarter_turn(2),
            _ => {
                let back = Rotation::quarter_turn(1);
                back.times(back).times(back)
            }
        };
        let turn = (0..quarters.rem_euclid(4)).fold(Rotation::IDENTITY, |turn, _| quarter.times(turn));
        if turn != Rotation::IDENTITY && self.own_pose(self.transform_node(index)?)?.turn.is_some() {
            return self.turned(index, axis, 90.0 * quarters as f64);
        }
        self.retransformed(index, "turning", |own, parent| {
            let rotation = parent.inverse().times(turn).times(parent).times(own.transform.rotation);
            Pose { transform: Transform { rotation, ..own.transform }, ..own }
        })
    }

    /// The change that gives object `index`'s shown keyframe the pose
    /// `f(own, parent rotation)` makes. Refused (as `doing`) where a group
    /// above the object turns freely: its moves and turns would not follow
    /// the world's axes.
    fn retransformed(
        &self,
        index: usize,
        doing: &'static str,
        f: impl Fn(Pose, Rotation) -> Pose,
    ) -> Result<GraphChange, EditError> {
        self.unlocked(&[index])?;
        let mut node = self.transform_node(index)?.clone();
        let own = self.own_pose(&node)?;
        if self.group_turns_freely(index, &own) {
            return Err(ObjectRefusal::FreelyTurned(index, doing).into());
        }
        let k = self.key_to_change(&mut node)?;
        let NodeKind::Transform { frames, .. } = &mut node.kind else { unreachable!("checked by key_to_change") };
        // The whole transform is parent · own, so the parent's rotation is whole · own⁻¹.
        let parent = self.objects[index].placement.transform.rotation.times(own.transform.rotation.inverse());
        graph::write_pose(&mut frames[k], &f(own, parent));
        Ok(GraphChange { nodes: vec![node], ..GraphChange::default() })
    }

    /// Whether a group above object `index` (whose own pose is `own`) turns
    /// freely: the whole placement is not its own pose on a signed permutation.
    fn group_turns_freely(&self, index: usize, own: &Pose) -> bool {
        let Some(whole) = self.objects[index].placement.turned else { return false };
        let parent = whole.m * own.matrix().transpose();
        let nearest = Rotation::nearest(parent).matrix();
        (parent - nearest).to_cols_array().iter().any(|d| d.abs() > 1e-9)
    }

    /// The change that moves object `index` into the group of object
    /// `target`, right before it (or after), where it is drawn: its own
    /// transform, every keyframe of it, takes what the two groups' placements
    /// differ by (exact for groups without keyframes of their own).
    pub fn regrouped(&self, index: usize, target: usize, after: bool) -> Result<GraphChange, EditError> {
        if index == target || target >= self.objects.len() {
            return Err(ObjectRefusal::RegroupSelf.into());
        }
        self.unlocked(&[index])?;
        // The groups' places are signed permutations here: a freely turned
        // group would move the object.
        for k in [index, target] {
            if self.group_turns_freely(k, &self.own_pose(self.transform_node(k)?)?) {
                return Err(ObjectRefusal::FreelyTurned(k, "regrouping").into());
            }
        }
        let mut node = self.transform_node(index)?.clone();
        let target_id = self.transform_node(target)?.id;
        let delta = self.parent_placement(target)?.inverse().compose(self.parent_placement(index)?);
        if let NodeKind::Transform { frames, .. } = &mut node.kind {
            for frame in frames.iter_mut() {
                let own = graph::parse_pose(frame, node.id)?;
                // D · q · R = (D q Dᵀ) · (D R): the turn is conjugated.
                let d = delta.rotation.matrix();
                let turn = own.turn.map(|Turn(q)| {
                    let m = d * glam::DMat3::from_quat(q) * d.transpose();
                    Turn(glam::DQuat::from_mat3(&m).normalize())
                });
                graph::write_pose(frame, &Pose { transform: delta.compose(own.transform), turn });
            }
        }
        let mut old_group = self.parent_group(node.id)?.clone();
        if let NodeKind::Group { children } = &mut old_group.kind {
            children.retain(|&c| c != node.id);
        }
        let new_id = self.parent_group(target_id)?.id;
        let mut new_group =
            if new_id == old_group.id { old_group.clone() } else { self.parent_group(target_id)?.clone() };
        if let NodeKind::Group { children } = &mut new_group.kind {
            let at = children.iter().position(|&c| c == target_id).map_or(children.len(), |p| p + usize::from(after));
            children.insert(at, node.id);
        }
        let mut nodes = vec![node];
        if new_id != old_group.id {
            nodes.push(old_group);
        }
        nodes.push(new_group);
        Ok(GraphChange { nodes, ..GraphChange::default() })
    }

    /// Where object `index`'s group places it: its whole transform at the
    /// shown frame without its own.
    fn parent_placement(&self, index: usize) -> Result<Transform, EditError> {
        let own = self.own_pose(self.transform_node(index)?)?;
        Ok(self.objects[index].placement.transform.compose(own.transform.inverse()))
    }

    /// The change that sets an attribute of object `index`'s transform
    /// (`_name`, `_hidden`); `None` removes it.
    pub fn with_attribute(&self, index: usize, key: &str, value: Option<&str>) -> Result<GraphChange, EditError> {
        let mut node = self.transform_node(index)?.clone();
        match value {
            Some(value) => node.attributes.insert(key.to_owned(), value.to_owned()),
            None => node.attributes.remove(key),
        };
        Ok(GraphChange { nodes: vec![node], ..GraphChange::default() })
    }

    /// The change that puts object `index` on layer `layer`.
    pub fn on_layer(&self, index: usize, layer: u32) -> Result<GraphChange, EditError> {
        if !self.graph.as_ref().is_some_and(|g| g.layers.iter().any(|l| l.id == layer)) {
            return Err(ObjectRefusal::NoLayer(layer).into());
        }
        let mut node = self.transform_node(index)?.clone();
        if let NodeKind::Transform { layer: own, .. } = &mut node.kind {
            *own = layer;
        }
        Ok(GraphChange { nodes: vec![node], ..GraphChange::default() })
    }

    /// The change that sets layer `id`'s attribute `key` (adding the layer
    /// when there is none of that id).
    pub fn layer_with(&self, id: u32, key: &str, value: Option<&str>) -> Result<GraphChange, EditError> {
        let graph = self.graph.as_ref().ok_or(ObjectRefusal::NoGraph)?;
        let mut layer = graph.layers.iter().find(|l| l.id == id).cloned().unwrap_or(Layer {
            id,
            attributes: graph::Attributes::new(),
            reserved: u32::MAX,
        });
        match value {
            Some(value) => layer.attributes.insert(key.to_owned(), value.to_owned()),
            None => layer.attributes.remove(key),
        };
        Ok(GraphChange { layers: vec![layer], ..GraphChange::default() })
    }

    /// The change that places object `index` again, right after it in its
    /// group: showing the same model (a reference), or `model`. Returns it
    /// and the new transform node's id.
    pub fn duplicated(&self, index: usize, model: Option<usize>) -> Result<(GraphChange, u32), EditError> {
        let graph = self.graph.as_ref().ok_or(ObjectRefusal::NoGraph)?;
        let own = self.transform_node(index)?;
        let mut group = self.parent_group(own.id)?.clone();
        let shape = graph.node(self.objects[index].shape_node).ok_or(ObjectRefusal::NoShape)?;
        let next = graph.nodes.iter().map(|n| n.id).max().unwrap_or(0);
        let (transform_id, shape_id) = (next.checked_add(1), next.checked_add(2));
        let (Some(transform_id), Some(shape_id)) = (transform_id, shape_id) else {
            return Err(ObjectRefusal::NoNodeIds.into());
        };
        let mut transform = own.clone();
        transform.id = transform_id;
        if let NodeKind::Transform { child, .. } = &mut transform.kind {
            *child = shape_id;
        }
        let mut shape = shape.clone();
        shape.id = shape_id;
        if let (Some(model), NodeKind::Shape { models }) = (model, &mut shape.kind) {
            for (shown, _) in models.iter_mut() {
                *shown = u32::try_from(model).unwrap_or(u32::MAX);
            }
        }
        if let NodeKind::Group { children } = &mut group.kind {
            let at = children.iter().position(|&c| c == own.id).map_or(children.len(), |p| p + 1);
            children.insert(at, transform_id);
        }
        Ok((GraphChange { nodes: vec![group, transform, shape], ..GraphChange::default() }, transform_id))
    }

    /// A copy of object `index`'s model, and the index it gets when stored.
    pub fn model_copy(&self, index: usize) -> (Model, usize) {
        (self.models[self.objects[index].placement.model].clone(), self.models.len())
    }

    /// The change that points object `index`'s transform at a shape of its
    /// own showing `model` (`object unique`).
    pub fn made_unique(&self, index: usize, model: usize) -> Result<GraphChange, EditError> {
        let (mut change, _) = self.duplicated(index, Some(model))?;
        // Of the duplicate keep the shape; the object's own transform takes it.
        let shape = change.nodes.pop().ok_or(ObjectRefusal::NoShape)?;
        let mut own = self.transform_node(index)?.clone();
        if let NodeKind::Transform { child, .. } = &mut own.kind {
            *child = shape.id;
        }
        Ok(GraphChange { nodes: vec![own, shape], ..GraphChange::default() })
    }

    /// Merges objects `others` into object `index`, all shown: a new model
    /// (the last) holding every voxel of them all in `index`'s model grid
    /// (the later in walk order wins where two overlap, as drawn), shown by
    /// `index`, and the change that shows it and deletes the others.
    pub fn merged(&self, index: usize, others: &[usize]) -> Result<(Model, GraphChange), EditError> {
        let mut all: Vec<usize> = others.to_vec();
        all.push(index);
        all.sort_unstable();
        all.dedup();
        if all.len() != others.len() + 1 || all.iter().any(|&i| i >= self.objects.len()) {
            return Err(ObjectRefusal::MergeWhich(self.objects.len()).into());
        }
        self.unlocked(&all)?;
        // A turned object's cells are no box-by-box image of its model's.
        if let Some(&turned) = all.iter().find(|&&k| self.maps[k].cells().is_none()) {
            return Err(ObjectRefusal::FreelyTurned(turned, "merging").into());
        }
        if let Some(&hidden) = all.iter().find(|&&k| self.objects[k].hidden) {
            // Its voxels would show once part of a shown model.
            return Err(ObjectRefusal::MergeHidden(hidden).into());
        }
        let voxels: u64 = all.iter().map(|&k| self.models[self.objects[k].placement.model].tree.solid_voxels()).sum();
        if voxels > MERGE_LIMIT {
            return Err(ObjectRefusal::MergeTooLarge { voxels, limit: MERGE_LIMIT }.into());
        }
        // The new model's octree, before it is built: its sources' pools,
        // twice over for cells their grids cut differently, and the undo copy.
        let pools: u64 =
            all.iter().map(|&k| self.models[self.objects[k].placement.model].tree.pool().live_bytes()).sum();
        crate::budget::check(|| format!("merging {} objects", all.len()), 4 * pools)?;
        let target = self.maps[index];
        let boxes: Vec<(IVec3, IVec3)> =
            all.iter().filter_map(|&k| self.world_box(k)).map(|(lo, hi)| target.invert_box(lo, hi)).collect();
        let mut tree = match boxes.into_iter().reduce(|a, b| (a.0.min(b.0), a.1.max(b.1))) {
            Some((lo, hi)) => Octree::empty_for(lo, hi)?,
            None => Octree::default(),
        };
        // In walk order, so the later wins where two overlap, as drawn.
        for &k in &all {
            let (map, model) = (self.maps[k], &self.models[self.objects[k].placement.model].tree);
            if let Some(bounds) = model.solid_bounds() {
                copy_cells(model, bounds, &mut tree, |p| target.invert(map.apply(p)));
            }
        }
        let model = Model { size: self.models[self.objects[index].placement.model].size, tree };
        let mut change = self.made_unique(index, self.models.len())?;
        let gone = self.deleted_all(others)?;
        change.nodes.extend(gone.nodes);
        change.remove.extend(gone.remove);
        Ok((model, change))
    }

    /// An empty object named `name` in the top group: the empty model of
    /// one cell to store, the change that adds its shape and transform, and
    /// the new transform's id.
    pub fn created(&self, name: &str) -> Result<(Model, GraphChange, u32), EditError> {
        let graph = self.graph.as_ref().ok_or(ObjectRefusal::NoGraph)?;
        // The top group: the one under the root transform (node 0), where
        // the walk starts. The first group in file order may be one no walk
        // reaches (issue 48, item 12), and an object there is in no scene.
        let top = match graph.node(0).map(|root| &root.kind) {
            Some(NodeKind::Transform { child, .. }) => graph.node(*child),
            _ => None,
        };
        let mut group =
            top.filter(|n| matches!(n.kind, NodeKind::Group { .. })).cloned().ok_or(ObjectRefusal::NoTopGroup)?;
        let next = graph.nodes.iter().map(|n| n.id).max().unwrap_or(0);
        let ids = next.checked_add(1).zip(next.checked_add(2));
        let (transform_id, shape_id) = ids.ok_or(ObjectRefusal::NoNodeIds)?;
        let layer = self.layer_for_new().unwrap_or(u32::MAX);
        let attributes = [("_name".to_owned(), name.to_owned())].into();
        let transform = Node {
            id: transform_id,
            attributes,
            kind: NodeKind::Transform {
                child: shape_id,
                reserved: u32::MAX,
                layer,
                frames: vec![graph::Attributes::new()],
            },
        };
        let model = u32::try_from(self.models.len()).unwrap_or(u32::MAX);
        let shape = Node {
            id: shape_id,
            attributes: graph::Attributes::new(),
            kind: NodeKind::Shape { models: vec![(model, graph::Attributes::new())] },
        };
        if let NodeKind::Group { children } = &mut group.kind {
            children.push(transform_id);
        }
        let empty = Model { size: [1, 1, 1], tree: Octree::default() };
        let change = GraphChange { nodes: vec![group, transform, shape], ..GraphChange::default() };
        Ok((empty, change, transform_id))
    }

    /// The change that takes object `index` out of its group (its nodes go
    /// too; its model stays stored).
    pub fn deleted(&self, index: usize) -> Result<GraphChange, EditError> {
        self.deleted_all(&[index])
    }

    /// The change that takes objects `indices` out of their groups, with
    /// their shapes where no other object shows them.
    fn deleted_all(&self, indices: &[usize]) -> Result<GraphChange, EditError> {
        self.unlocked(indices)?;
        let mut change = GraphChange::default();
        for &k in indices {
            let own = self.transform_node(k)?.id;
            let parent = self.parent_group(own)?;
            let at = change.nodes.iter().position(|g| g.id == parent.id).unwrap_or_else(|| {
                change.nodes.push(parent.clone());
                change.nodes.len() - 1
            });
            if let NodeKind::Group { children } = &mut change.nodes[at].kind {
                children.retain(|&c| c != own);
            }
            change.remove.push(own);
            let shape = self.objects[k].shape_node;
            let shown_elsewhere =
                self.objects.iter().enumerate().any(|(i, o)| o.shape_node == shape && !indices.contains(&i));
            if !shown_elsewhere && !change.remove.contains(&shape) {
                change.remove.push(shape);
            }
        }
        Ok(change)
    }

    /// The group that holds transform `id`.
    fn parent_group(&self, id: u32) -> Result<&Node, EditError> {
        let graph = self.graph.as_ref().ok_or(ObjectRefusal::NoGraph)?;
        graph
            .nodes
            .iter()
            .find(|n| matches!(&n.kind, NodeKind::Group { children } if children.contains(&id)))
            .ok_or(ObjectRefusal::NotInGroup.into())
    }

    /// The index of the object placed by transform node `id`.
    pub fn index_of_transform(&self, id: u32) -> Option<usize> {
        self.objects.iter().position(|o| o.transform_node == Some(id))
    }

    /// Layers by id, and whether each is hidden, for listings.
    pub fn layers(&self) -> Vec<(u32, String, bool)> {
        self.graph.iter().flat_map(|g| &g.layers).map(|l| (l.id, l.name().to_owned(), l.hidden())).collect()
    }

    /// The layers as the graph holds them.
    pub fn layer_list(&self) -> &[Layer] {
        self.graph.as_ref().map_or(&[], |g| &g.layers)
    }

    /// The layer `object new` puts objects on: the one made active, while it
    /// exists, else the first; `None` without layers.
    pub fn layer_for_new(&self) -> Option<u32> {
        let layers = self.layer_list();
        self.new_layer.filter(|id| layers.iter().any(|l| l.id == *id)).or(layers.first().map(|l| l.id))
    }

    /// Makes layer `id` the one new objects go on.
    pub fn set_new_layer(&mut self, id: u32) -> Result<(), EditError> {
        if !self.layer_list().iter().any(|l| l.id == id) {
            return Err(ObjectRefusal::NoLayer(id).into());
        }
        self.new_layer = Some(id);
        Ok(())
    }

    /// Number of group nodes.
    pub fn group_count(&self) -> usize {
        self.graph.as_ref().map_or(0, SceneGraph::group_count)
    }

    /// Bytes of every model's node pool.
    pub fn pool_bytes(&self) -> u64 {
        self.models.iter().map(|m| m.tree.pool().live_bytes()).sum()
    }
}

/// A change to the scene graph, as data (an undoable edit): nodes and
/// layers to put in by id (replacing the one of that id, or added at the
/// end), and nodes and layers to take out.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct GraphChange {
    pub nodes: Vec<Node>,
    pub layers: Vec<Layer>,
    pub remove: Vec<u32>,
    pub remove_layers: Vec<u32>,
    /// The document's playback settings to put in.
    pub animation: Option<anim::Animation>,
}

/// Bytes a changed node or layer takes while a change is applied: it, the
/// node it replaces (the undo's copy) and their attribute maps.
const BYTES_PER_CHANGED_NODE: u64 = 2048;

impl GraphChange {
    /// Peak bytes applying it may take beyond the walk itself (whose
    /// placements the budget checks as it goes: `graph::BYTES_PER_PLACEMENT`).
    pub fn estimated_bytes(&self) -> u64 {
        let count = self.nodes.len() + self.layers.len() + self.remove.len() + self.remove_layers.len();
        count as u64 * BYTES_PER_CHANGED_NODE
    }

    /// Applies it to `graph`; returns the change that undoes it.
    fn apply(&self, graph: &mut SceneGraph) -> GraphChange {
        let mut inverse = GraphChange::default();
        if let Some(animation) = self.animation {
            inverse.animation = Some(std::mem::replace(&mut graph.animation, animation));
        }
        for id in &self.remove {
            if let Some(at) = graph.nodes.iter().position(|n| n.id == *id) {
                inverse.nodes.push(graph.nodes.remove(at));
            }
        }
        for id in &self.remove_layers {
            if let Some(at) = graph.layers.iter().position(|l| l.id == *id) {
                inverse.layers.push(graph.layers.remove(at));
            }
        }
        for node in &self.nodes {
            match graph.nodes.iter().position(|n| n.id == node.id) {
                Some(at) => inverse.nodes.push(std::mem::replace(&mut graph.nodes[at], node.clone())),
                None => {
                    graph.nodes.push(node.clone());
                    inverse.remove.push(node.id);
                }
            }
        }
        for layer in &self.layers {
            match graph.layers.iter().position(|l| l.id == layer.id) {
                Some(at) => inverse.layers.push(std::mem::replace(&mut graph.layers[at], layer.clone())),
                None => {
                    graph.layers.push(layer.clone());
                    inverse.remove_layers.push(layer.id);
                }
            }
        }
        inverse
    }

    /// Bytes its nodes and layers hold, roughly (undo memory).
    pub fn heap_bytes(&self) -> usize {
        let attributes = |a: &graph::Attributes| a.iter().map(|(k, v)| k.len() + v.len() + 48).sum::<usize>();
        let node = |n: &Node| {
            64 + attributes(&n.attributes)
                + match &n.kind {
                    NodeKind::Transform { frames, .. } => frames.iter().map(attributes).sum(),
                    NodeKind::Group { children } => 4 * children.len(),
                    NodeKind::Shape { models } => models.iter().map(|m| 4 + attributes(&m.1)).sum(),
                }
        };
        self.nodes.iter().map(node).sum::<usize>()
            + self.layers.iter().map(|l| 32 + attributes(&l.attributes)).sum::<usize>()
            + 4 * (self.remove.len() + self.remove_layers.len())
    }
}

/// Composes a freely turned model into the world cells `lo..=hi`: every
/// world cell takes the model cell that holds its centre's preimage. Each
/// uniform cell of the model gives the world cells of its turned cube's
/// box whose preimage it holds, so the work follows the model's cells
/// (a sparse model spread over a large box costs its cells, not its box)
/// and every world cell is written once, by its own model cell.
fn resample_cells(model: &Octree, map: &TurnedMap, (lo, hi): (IVec3, IVec3), to: &mut Octree) {
    let (mlo, mhi) = map.invert_box(lo, hi);
    let mut batch: Vec<(IVec3, u8)> = Vec::new();
    model.for_each_solid_cell_in(mlo, mhi, |min, size, value| {
        let max = min + IVec3::splat(size - 1);
        let (wlo, whi) = map.apply_box(min, max);
        let (wlo, whi) = (wlo.max(lo), whi.min(hi));
        for z in wlo.z..=whi.z {
            for y in wlo.y..=whi.y {
                for x in wlo.x..=whi.x {
                    let w = IVec3::new(x, y, z);
                    let m = map.invert(w);
                    if m.cmpge(min).all() && m.cmple(max).all() {
                        batch.push((w, value));
                    }
                }
            }
        }
        if batch.len() >= PLACED_BATCH {
            to.insert_voxels(&batch);
            batch.clear();
        }
    });
    to.insert_voxels(&batch);
}

/// Writes the solid cells of `from` inside its box `lo..=hi` into `to`
/// (which holds where they go), each cell `p` at `map(p)`, over what is
/// there; `map` is a signed permutation and a shift (a cell map or a chain
/// of them). The part of a uniform cell in the box goes in as one box (a
/// signed permutation maps a box onto a box), so a solid region costs its
/// surface; single voxels go in batches of at most [`PLACED_BATCH`], so
/// memory stays small whatever the model.
fn copy_cells(from: &Octree, (lo, hi): (IVec3, IVec3), to: &mut Octree, map: impl Fn(IVec3) -> IVec3) {
    let mut batch: Vec<(IVec3, u8)> = Vec::new();
    from.for_each_solid_cell_in(lo, hi, |min, size, value| {
        // The part of the cell in the box: one box of one value, which a
        // signed permutation maps onto a box.
        let (clo, chi) = (min.max(lo), (min + IVec3::splat(size - 1)).min(hi));
        if clo != chi {
            let (a, b) = (map(clo), map(chi));
            to.fill_box(a.min(b), a.max(b), value);
            return;
        }
        batch.push((map(clo), value));
        if batch.len() >= PLACED_BATCH {
            to.insert_voxels(&batch);
            batch.clear();
        }
    });
    to.insert_voxels(&batch);
}

/// Adds a key at `frame` holding `pose` among `keys`, before the
/// first key of a later frame (keys stay in the order of their frames, as
/// MagicaVoxel writes them); returns its index.
fn insert_key(keys: &mut Vec<graph::Attributes>, frame: u32, pose: Pose, node: u32) -> Result<usize, GraphError> {
    let mut key = graph::Attributes::new();
    key.insert("_f".to_owned(), frame.to_string());
    graph::write_pose(&mut key, &pose);
    let mut at = keys.len();
    for (k, other) in keys.iter().enumerate() {
        if anim::key_frame(other, node)? > frame {
            at = k;
            break;
        }
    }
    keys.insert(at, key);
    Ok(at)
}

/// Min corners of the boxes of at most [`COMPOSE_BOX`] a side that tile `lo..=hi`.
fn boxes_of(lo: IVec3, hi: IVec3) -> Vec<IVec3> {
    let steps = |a: i32, b: i32| (a..=b).step_by(COMPOSE_BOX as usize);
    let mut out = Vec::new();
    for z in steps(lo.z, hi.z) {
        for y in steps(lo.y, hi.y) {
            for x in steps(lo.x, hi.x) {
                out.push(IVec3::new(x, y, z));
            }
        }
    }
    out
}
