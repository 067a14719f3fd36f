//! The report's baseline: a dense cubic grid indexed `x + size·y + size²·z`
//! (the report's layout; one byte per voxel here, four there) walked with
//! Amanatides–Woo DDA. `shaders/trace_grid.wgsl` is its twin.

use glam::{IVec3, UVec3, Vec3};

use super::{Hit, NO_AXIS, Ray, argmin};
use crate::scene::Octree;

/// Largest dense grid built (1 GiB): the baseline is for comparison, and a
/// sparse scene's bounding box can be far bigger than any memory.
pub const MAX_GRID_CELLS: u64 = 1 << 30;

/// The cube of side `max extent` at the scene's min corner, as a flat array
/// of palette indices (`dims` is that side on every axis).
#[derive(Clone, Debug, Default)]
pub struct DenseGrid {
    /// Min corner in tree-local coordinates.
    pub min: IVec3,
    pub dims: UVec3,
    pub data: Vec<u8>,
}

/// Why a scene has no dense grid.
#[derive(Clone, Debug, thiserror::Error)]
pub enum GridError {
    #[error("the scene's bounding cube of {0}³ voxels is larger than a dense grid may be ({MAX_GRID_CELLS} cells)")]
    TooLarge(u32),
    #[error(transparent)]
    OverBudget(#[from] crate::budget::OverBudget),
}

impl DenseGrid {
    /// Rasterizes the tree's solid voxels (tree-local coordinates), or
    /// says why not: a bounding cube of more than [`MAX_GRID_CELLS`], or
    /// more bytes than the memory budget allows.
    pub fn from_octree(tree: &Octree) -> Result<DenseGrid, GridError> {
        let Some((lo, hi)) = tree.solid_bounds() else {
            return Ok(DenseGrid::default());
        };
        let min = lo - tree.origin();
        let dims = UVec3::splat((hi - lo + IVec3::ONE).max_element() as u32);
        let cells = dims.as_u64vec3().element_product();
        if cells > MAX_GRID_CELLS {
            return Err(GridError::TooLarge(dims.x));
        }
        crate::budget::check(|| format!("a dense grid of {}³ voxels", dims.x), cells)?;
        let mut data = vec![0u8; dims.x as usize * dims.y as usize * dims.z as usize];
        let index = |p: IVec3| (p.x as usize) + dims.x as usize * (p.y as usize + dims.y as usize * p.z as usize);
        tree.for_each_solid_cell(|cell_min, size, value| {
            let base = cell_min - lo;
            for z in 0..size {
                for y in 0..size {
                    let row = index(base + IVec3::new(0, y, z));
                    data[row..row + size as usize].fill(value);
                }
            }
        });
        Ok(DenseGrid { min, dims, data })
    }

    /// Value at a tree-local position (0 outside).
    pub fn at(&self, p: IVec3) -> u8 {
        let rel = p - self.min;
        if rel.cmplt(IVec3::ZERO).any() || rel.as_uvec3().cmpge(self.dims).any() {
            return 0;
        }
        self.data[rel.x as usize + self.dims.x as usize * (rel.y as usize + self.dims.y as usize * rel.z as usize)]
    }

    pub fn bytes(&self) -> u64 {
        self.data.len() as u64
    }
}

/// The first solid voxel along `ray` (tree-local coordinates).
pub fn trace(grid: &DenseGrid, ray: &Ray) -> Hit {
    if grid.data.is_empty() {
        return Hit::default();
    }
    let lo = grid.min;
    let hi = grid.min + grid.dims.as_ivec3() - IVec3::ONE;
    let (t_enter, t_exit, entry_axis) = ray.slab(lo.as_vec3(), (hi + IVec3::ONE).as_vec3());
    // t_exit = 0: the ray starts on the cube's face and heads out.
    if t_enter > t_exit || t_exit <= 0.0 {
        return Hit::default();
    }
    let t = t_enter.max(0.0);
    let mut axis = if t_enter >= 0.0 { entry_axis } else { NO_AXIS };
    let mut voxel = ray.voxel_in_box(lo, hi, t, axis);
    let step = IVec3::select(ray.dir.cmpgt(Vec3::ZERO), IVec3::ONE, IVec3::NEG_ONE);
    let far_offset = Vec3::select(ray.dir.cmpgt(Vec3::ZERO), Vec3::ONE, Vec3::ZERO);
    // A DDA through a box crosses at most the box's planes.
    let bound = u32::try_from(grid.dims.as_u64vec3().element_sum() + 1).unwrap_or(u32::MAX);
    let mut iterations = 0;
    while iterations < bound {
        iterations += 1;
        let value = grid.at(voxel);
        if value != 0 {
            let normal = if axis == NO_AXIS { IVec3::ZERO } else { ray.entry_normal(axis) };
            return Hit { value, voxel, normal, cell_level: 0, iterations, gave_up: false, turned: None };
        }
        // Exit t of each plane, recomputed from the plane (not accumulated).
        let exits = (voxel.as_vec3() + far_offset - ray.origin) * ray.inv;
        let a = argmin(exits);
        voxel[a] += step[a];
        axis = a;
        if voxel[a] < lo[a] || voxel[a] > hi[a] {
            break;
        }
    }
    Hit::miss(iterations, bound)
}
