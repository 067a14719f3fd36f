//! The scene model: palette, materials and the voxels themselves.

pub mod apply;
pub mod build;
pub mod counts;
pub mod demo;
pub mod graph;
pub mod lod;
pub mod objects;
pub mod octree;
pub mod palette;
pub mod sculpture;
pub mod shape;
pub mod showroom;
pub mod transform;

pub use apply::{EditError, Patch};
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

/// What the sandbox edits: a palette and an octree of palette indices.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    pub palette: Palette,
    /// What is drawn: the one model, or the visible objects composed.
    pub tree: Octree,
    /// The objects and models of a scene of several (`None`: the tree is
    /// the one model).
    pub objects: Option<Box<objects::Objects>>,
}

impl Scene {
    /// A scene of one model.
    pub fn new(palette: Palette, tree: Octree) -> Scene {
        Scene { palette, tree, objects: None }
    }

    /// Builds the octree of a loaded model.
    pub fn from_model(model: &VoxelModel) -> Result<Scene, BuildError> {
        Ok(Scene::new(model.palette.clone(), Octree::from_voxels(&model.voxels)?))
    }
}
