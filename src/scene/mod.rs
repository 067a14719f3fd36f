//! The scene model: palette, materials and the voxels themselves.

pub mod anim;
pub mod apply;
pub mod build;
pub mod counts;
pub mod demo;
pub mod graph;
pub mod hull;
pub mod instances;
pub mod lod;
pub mod objects;
pub mod octree;
pub mod palette;
pub mod sculpture;
pub mod shape;
pub mod showroom;
pub mod transform;

pub use apply::{EditError, ObjectRefusal, Patch, RegionError, SceneUpload};
pub use build::BuildError;
pub use counts::VoxelCounts;
pub use octree::Octree;
pub use palette::{Material, MaterialKind, Palette};
pub use shape::{Op, Overlap, Shape};

use glam::IVec3;

/// One solid voxel: world position (y up) and palette index (1..=255).
pub type Voxel = (IVec3, u8);

/// What a loader yields: a flat list of solid voxels in world coordinates
/// plus the palette, before any octree is built.
#[derive(Clone, Debug, Default)]
pub struct VoxelModel {
    pub palette: Palette,
    pub voxels: Vec<Voxel>,
    /// Number of models placed (by the scene graph, or the one frame of a
    /// file without one).
    pub models: usize,
    /// Number of models (SIZE/XYZI pairs) stored in the file.
    pub stored_models: usize,
    /// What the loader accepted but the user should know (ignored bytes,
    /// clamped values), one sentence each.
    pub warnings: Vec<String>,
}

impl VoxelModel {
    /// Inclusive min and max corner of the voxels, or `None` when empty.
    pub fn bounds(&self) -> Option<(IVec3, IVec3)> {
        bounds_of(self.voxels.iter().map(|v| v.0))
    }
}

/// Inclusive bounding box of a set of positions, or `None` when empty.
pub fn bounds_of(points: impl Iterator<Item = IVec3>) -> Option<(IVec3, IVec3)> {
    points.fold(None, |acc, p| Some(grow_bounds(acc, p)))
}

/// Bounds that also hold `p`.
pub fn grow_bounds(bounds: Option<(IVec3, IVec3)>, p: IVec3) -> (IVec3, IVec3) {
    bounds.map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p)))
}

/// What the sandbox edits: a palette and the voxels, which are one model
/// or a scene of objects. The octree that is drawn is kept behind methods:
/// callers ask the scene for voxels, bounds and uploads, and edits go
/// through it, so what is drawn can change shape without touching them.
#[derive(Clone, Debug)]
pub struct Scene {
    pub palette: Palette,
    /// What is drawn: the one model, or the visible objects composed.
    tree: Octree,
    /// The objects and models of a scene of several (`None`: the tree is
    /// the one model).
    objects: Option<Box<objects::Objects>>,
    /// What the GPU holds of a scene of objects.
    gpu: instances::GpuCopy,
    /// When a scene of objects is drawn as instances.
    instancing: Instancing,
    /// Names the scene's content: every change to the voxels, the objects
    /// or the palette takes a number no scene had before, so two scenes of
    /// one revision draw alike (a renderer keeps what it made of one).
    revision: u64,
}

impl Default for Scene {
    /// An empty scene of the default palette, of a revision of its own.
    fn default() -> Scene {
        Scene::new(Palette::default(), Octree::default())
    }
}

/// A revision no scene has had.
fn fresh_revision() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// When a scene of objects is drawn as instances of its models rather than
/// composed into one octree ([`Scene::instanced`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Instancing {
    /// Where a model is placed twice and instances save at least half the
    /// bytes ([`INSTANCE_SAVING`]): composed is faster where it is small.
    #[default]
    Auto,
    /// Wherever a model is placed twice: to measure and test the instance
    /// walk on scenes that `Auto` draws composed.
    References,
}

/// Instances are drawn where they take at most 1/INSTANCE_SAVING of the
/// bytes the objects composed take.
pub const INSTANCE_SAVING: u64 = 2;

/// Whether `objects`, composed as `composed`, are drawn as instances: some
/// model is placed twice, and its pools and instance words take at most
/// 1/[`INSTANCE_SAVING`] of the composed tree's.
fn draws_instances(objects: &objects::Objects, composed: &Octree) -> bool {
    if !objects.has_references() {
        return false;
    }
    let instances = objects.pool_bytes() + instances::word_bytes(objects.list().len());
    composed.pool().live_bytes() > INSTANCE_SAVING.saturating_mul(instances)
}

impl Scene {
    /// A scene of one model.
    pub fn new(palette: Palette, tree: Octree) -> Scene {
        let (gpu, instancing, revision) = (instances::GpuCopy::default(), Instancing::Auto, fresh_revision());
        Scene { palette, tree, objects: None, gpu, instancing, revision }
    }

    /// A scene of objects whose visible ones `tree` draws, composed (what a
    /// loader that stores the composed tree reads back).
    pub fn with_objects(palette: Palette, tree: Octree, objects: objects::Objects) -> Scene {
        let (gpu, instancing, revision) = (instances::GpuCopy::default(), Instancing::Auto, fresh_revision());
        Scene { palette, tree, objects: Some(Box::new(objects)), gpu, instancing, revision }
    }

    /// A scene of objects, its drawn tree composed from them.
    pub fn compose(palette: Palette, objects: objects::Objects) -> Result<Scene, EditError> {
        let tree = objects.compose()?;
        Ok(Scene::with_objects(palette, tree, objects))
    }

    /// Builds the octree of a loaded model.
    pub fn from_model(model: &VoxelModel) -> Result<Scene, BuildError> {
        Ok(Scene::new(model.palette.clone(), Octree::from_voxels(&model.voxels)?))
    }

    /// The objects of a scene of several; `None` for one model.
    pub fn objects(&self) -> Option<&objects::Objects> {
        self.objects.as_deref()
    }

    /// The objects of a scene of several, to pick among. A scene of one
    /// object (kept whole for saving: its graph, layers and chunks) is
    /// shown and edited as one model: nothing to pick, its edits go to it.
    pub fn pickable_objects(&self) -> Option<&objects::Objects> {
        self.objects().filter(|objects| objects.list().len() > 1)
    }

    /// The objects when the scene is drawn as instances of its models: a
    /// scene where some model is placed more than once (a reference), and
    /// where that saves at least half of what its objects composed take
    /// (`draws_instances`, [`INSTANCE_SAVING`]). Then each model is stored once on the GPU
    /// too, and a move writes one record. Any other scene of objects (a big
    /// model saved in 256³ blocks, or a few small references) is drawn as
    /// its objects composed into one octree: CPU-emulated GPUs trace one
    /// octree 2.5–3.5x faster than instances (docs/bench/scene.md).
    /// A scene with a free turn is always drawn as instances: a turned
    /// object is traced exactly in its own frame (its record holds the
    /// rotation), while the composed tree, which checks, counts and saves
    /// read, holds the world cells its turned cells' centres fall in.
    pub fn instanced(&self) -> Option<&objects::Objects> {
        self.objects().filter(|o| match self.instancing {
            _ if o.has_free_turns() => true,
            Instancing::Auto => draws_instances(o, &self.tree),
            Instancing::References => o.has_references(),
        })
    }

    /// The revision of the scene's content (see the field): it changes with
    /// every edit, undo and redo.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// Gives the scene a new revision: its content changed.
    pub fn touch(&mut self) {
        self.revision = fresh_revision();
    }

    /// Sets when the scene is drawn as instances (the GPU copy follows at
    /// the next upload).
    pub fn set_instancing(&mut self, instancing: Instancing) {
        self.instancing = instancing;
    }

    /// Takes the objects out (a loader that keeps only them).
    pub fn into_objects(self) -> Option<objects::Objects> {
        self.objects.map(|o| *o)
    }

    /// The octree the renderers draw, read-only: the one model, or the
    /// visible objects composed. Its origin is where ray coordinates start.
    pub fn drawn(&self) -> &Octree {
        &self.tree
    }

    /// The palette index drawn at world cell `at` (0: empty).
    pub fn voxel(&self, at: IVec3) -> u8 {
        self.tree.get(at)
    }

    /// Every drawn solid voxel, in the tree's order.
    pub fn voxels(&self) -> Vec<Voxel> {
        self.tree.voxels()
    }

    /// How many voxels are drawn solid.
    pub fn solid_voxels(&self) -> u64 {
        self.tree.solid_voxels()
    }

    /// The inclusive box of the drawn voxels; `None` when there are none.
    pub fn solid_bounds(&self) -> Option<(IVec3, IVec3)> {
        self.tree.solid_bounds()
    }

    /// Drawn voxels per palette index.
    pub fn counts(&self) -> &VoxelCounts {
        self.tree.counts()
    }

    /// The world cell the drawn tree's corner is at: cameras give rays
    /// relative to it.
    pub fn origin(&self) -> IVec3 {
        self.tree.origin()
    }

    /// Makes layer `id` the one `object new` puts objects on.
    pub fn set_new_layer(&mut self, id: u32) -> Result<(), EditError> {
        match &mut self.objects {
            Some(objects) => objects.set_new_layer(id),
            None => Err(apply::ObjectRefusal::NoLayers.into()),
        }
    }

    /// Picks the object edits go to (no effect on a scene of one model).
    pub fn select_object(&mut self, index: Option<usize>) {
        if let Some(objects) = &mut self.objects {
            objects.selected = index;
        }
    }
}
