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

use glam::IVec3;

use super::graph::{self, GraphError, NodeKind, Object, SceneGraph};
use super::octree::{Octree, WORLD_LIMIT};
use super::transform::CellMap;
use super::{EditError, Op, Patch, Shape};

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
    maps: Vec<CellMap>,
    /// The object edits go to, by index in walk order.
    pub selected: Option<usize>,
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
        let mut objects = Objects { graph, models, kept, frame, objects: Vec::new(), maps: Vec::new(), selected: None };
        objects.walk(voxel_limit)?;
        Ok(objects)
    }

    /// Walks the graph again (after a change to it) and maps every object.
    fn walk(&mut self, voxel_limit: usize) -> Result<(), ObjectsError> {
        let voxels: Vec<usize> =
            self.models.iter().map(|m| usize::try_from(m.tree.solid_voxels()).unwrap_or(usize::MAX)).collect();
        self.objects = match &self.graph {
            Some(graph) => graph.objects(&voxels, self.frame, voxel_limit)?,
            None => self.frame_object()?,
        };
        self.maps = Vec::with_capacity(self.objects.len());
        for object in &self.objects {
            let model = &self.models[object.placement.model];
            let map = object
                .placement
                .cell_map(model.size)
                .ok_or(ObjectsError::OutsideWorld { model: object.placement.model })?;
            self.maps.push(map);
        }
        for (object, map) in self.objects.iter().zip(&self.maps) {
            if let Some((lo, hi)) = self.models[object.placement.model].tree.solid_bounds() {
                let (lo, hi) = map.apply_box(lo, hi);
                if lo.min_element() <= -WORLD_LIMIT || hi.max_element() >= WORLD_LIMIT {
                    return Err(ObjectsError::OutsideWorld { model: object.placement.model });
                }
            }
        }
        Ok(())
    }

    /// Without a graph: model `frame` as stored.
    fn frame_object(&self) -> Result<Vec<Object>, GraphError> {
        if self.frame >= self.models.len() {
            return Err(GraphError::Bad(format!(
                "frame {} requested but there are {} models",
                self.frame,
                self.models.len()
            )));
        }
        Ok(vec![Object::frame(self.frame)])
    }

    /// The objects in walk order.
    pub fn list(&self) -> &[Object] {
        &self.objects
    }

    /// The world box of object `index`'s voxels; `None` when its model is empty.
    pub fn world_box(&self, index: usize) -> Option<(IVec3, IVec3)> {
        let (lo, hi) = self.models[self.objects[index].placement.model].tree.solid_bounds()?;
        Some(self.maps[index].apply_box(lo, hi))
    }

    /// Builds the octree of every visible object, in walk order.
    pub fn compose(&self) -> Result<Octree, EditError> {
        let boxes: Vec<(IVec3, IVec3)> = self.visible().filter_map(|i| self.world_box(i)).collect();
        let Some(bounds) = boxes.iter().copied().reduce(|a, b| (a.0.min(b.0), a.1.max(b.1))) else {
            return Ok(Octree::default());
        };
        let mut tree = Octree::empty_for(bounds.0, bounds.1).map_err(|e| EditError::Brush(e.to_string()))?;
        for index in self.visible() {
            tree.insert_voxels(&self.placed(index, bounds));
        }
        Ok(tree)
    }

    fn visible(&self) -> impl DoubleEndedIterator<Item = usize> + '_ {
        (0..self.objects.len()).filter(|&i| !self.objects[i].hidden)
    }

    /// Object `index`'s voxels inside the world box `lo..=hi`, in world cells.
    fn placed(&self, index: usize, (lo, hi): (IVec3, IVec3)) -> Vec<(IVec3, u8)> {
        let map = self.maps[index];
        let (mlo, mhi) = map.invert_box(lo, hi);
        let mut out = Vec::new();
        self.models[self.objects[index].placement.model].tree.for_each_solid_cell_in(mlo, mhi, |min, size, value| {
            let (clo, chi) = (min.max(mlo), (min + IVec3::splat(size - 1)).min(mhi));
            for z in clo.z..=chi.z {
                for y in clo.y..=chi.y {
                    for x in clo.x..=chi.x {
                        out.push((map.apply(IVec3::new(x, y, z)), value));
                    }
                }
            }
        });
        out
    }

    /// Composes the world cells `lo..=hi` of `tree` again from the objects.
    pub fn recompose(&self, tree: &mut Octree, (lo, hi): (IVec3, IVec3)) -> Result<(), EditError> {
        tree.grow_to_contain(lo, hi)?;
        for min in boxes_of(lo, hi) {
            let max = (min + IVec3::splat(COMPOSE_BOX - 1)).min(hi);
            tree.apply_brush(&Shape::Box { min, max }, Op::Remove)?;
        }
        for index in self.visible() {
            let reaches = self.world_box(index).is_some_and(|(a, b)| a.cmple(hi).all() && b.cmpge(lo).all());
            if reaches {
                tree.insert_voxels(&self.placed(index, (lo, hi)));
            }
        }
        Ok(())
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
        let model = self
            .objects
            .get(index)
            .ok_or_else(|| EditError::Brush(format!("there is no object {index}")))?
            .placement
            .model;
        let local = self.maps[index].invert_shape(shape);
        let patch = self.models[model].tree.apply_brush(&local, op)?;
        self.recompose_model(tree, model, local.bounds())?;
        Ok((model, patch))
    }

    /// Puts back a model's cells from an undo patch; returns the patch that
    /// undoes this.
    pub fn apply_patch(&mut self, tree: &mut Octree, model: usize, patch: &Patch) -> Result<Patch, EditError> {
        let inverse = self
            .models
            .get_mut(model)
            .ok_or_else(|| EditError::Brush(format!("there is no model {model}")))?
            .tree
            .apply_patch(patch)?;
        if let Some(bounds) = patch.bounds() {
            self.recompose_model(tree, model, bounds)?;
        }
        Ok(inverse)
    }

    /// Composes the world cells every placement of `model` maps its cells `lo..=hi` to.
    fn recompose_model(&self, tree: &mut Octree, model: usize, (lo, hi): (IVec3, IVec3)) -> Result<(), EditError> {
        for index in 0..self.objects.len() {
            if self.objects[index].placement.model == model {
                self.recompose(tree, self.maps[index].apply_box(lo, hi))?;
            }
        }
        Ok(())
    }

    /// How many objects place each model.
    pub fn placements_of(&self, model: usize) -> usize {
        self.objects.iter().filter(|o| o.placement.model == model).count()
    }

    /// Sets object `index`'s own `_hidden` flag (on its transform node) and
    /// composes what it covers; the flag it had before.
    pub fn set_hidden(&mut self, tree: &mut Octree, index: usize, hidden: bool) -> Result<bool, EditError> {
        let node = self
            .objects
            .get(index)
            .and_then(|o| o.transform_node)
            .ok_or_else(|| EditError::Brush(format!("object {index} has no transform node to hide")))?;
        let graph = self
            .graph
            .as_mut()
            .ok_or_else(|| EditError::Brush("a file without a scene graph has nothing to hide".to_owned()))?;
        let Some(node) = graph.node_mut(node) else { return Err(EditError::Brush(format!("node {node} is missing"))) };
        let before = graph::is_set(&node.attributes, "_hidden");
        if hidden {
            node.attributes.insert("_hidden".to_owned(), "1".to_owned());
        } else {
            node.attributes.remove("_hidden");
        }
        self.changed_graph(tree, |o| o.world_box(index))?;
        Ok(before)
    }

    /// Sets layer `id`'s `_hidden` flag and composes its objects; the flag before.
    pub fn set_layer_hidden(&mut self, tree: &mut Octree, id: u32, hidden: bool) -> Result<bool, EditError> {
        let graph = self
            .graph
            .as_mut()
            .ok_or_else(|| EditError::Brush("a file without a scene graph has no layers".to_owned()))?;
        let layer = graph
            .layers
            .iter_mut()
            .find(|l| l.id == id)
            .ok_or_else(|| EditError::Brush(format!("there is no layer {id}")))?;
        let before = layer.hidden();
        if hidden {
            layer.attributes.insert("_hidden".to_owned(), "1".to_owned());
        } else {
            layer.attributes.remove("_hidden");
        }
        let on_layer: Vec<usize> = (0..self.objects.len()).filter(|&i| self.objects[i].layer == Some(id)).collect();
        self.changed_graph(tree, |o| union(on_layer.iter().filter_map(|&i| o.world_box(i))))?;
        Ok(before)
    }

    /// Walks the changed graph and composes the region `region` finds,
    /// before the change and after it.
    fn changed_graph(
        &mut self,
        tree: &mut Octree,
        region: impl Fn(&Objects) -> Option<(IVec3, IVec3)>,
    ) -> Result<(), EditError> {
        let before = region(self);
        self.walk(usize::MAX).map_err(|e| EditError::Brush(e.to_string()))?;
        let after = region(self);
        for bounds in [before, after].into_iter().flatten() {
            self.recompose(tree, bounds)?;
        }
        Ok(())
    }

    /// Layers by id, and whether each is hidden, for listings.
    pub fn layers(&self) -> Vec<(u32, String, bool)> {
        self.graph.iter().flat_map(|g| &g.layers).map(|l| (l.id, l.name().to_owned(), l.hidden())).collect()
    }

    /// Number of group nodes.
    pub fn group_count(&self) -> usize {
        self.graph.as_ref().map_or(0, SceneGraph::group_count)
    }

    /// Bytes of every model's node pool.
    pub fn pool_bytes(&self) -> u64 {
        self.models.iter().map(|m| m.tree.pool().live_bytes()).sum()
    }

    /// Whether the shape node of object `index` shows other models in other frames.
    pub fn animated_shape(&self, index: usize) -> bool {
        let Some(graph) = &self.graph else { return false };
        graph
            .node(self.objects[index].shape_node)
            .is_some_and(|n| matches!(&n.kind, NodeKind::Shape { models } if models.len() > 1))
    }
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

fn union(boxes: impl Iterator<Item = (IVec3, IVec3)>) -> Option<(IVec3, IVec3)> {
    boxes.reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
}
