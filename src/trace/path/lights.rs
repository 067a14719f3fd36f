//! Emissive voxels as lights: the list next-event estimation samples, one
//! entry per maximal uniform emissive cell, chosen by power. A freely
//! turned object's lamp is listed by its model cells and sampled in its
//! model's frame, so light sampling aims at the turned cubes the tracers
//! draw.

use bytemuck::{Pod, Zeroable};
use glam::{IVec3, Vec3};

use super::materials::{MATERIAL_EMIT, albedo, gpu_material};
use crate::scene::instances::NO_INSTANCE;
use crate::scene::objects::Objects;
use crate::scene::transform::Placing;
use crate::scene::{Octree, Palette, Scene};

/// Most emissive cells sampled as lights. A scene with more is still lit by
/// them (rays that hit an emitter see it), only without next-event
/// estimation toward them, so it converges more slowly.
pub const MAX_EMITTERS: usize = 4096;

/// How far (in voxels) a shadow ray's hit on a turned lamp may lie outside
/// the sampled model cell and still count as reaching it: the hit point is
/// worked out in f32 from the ray, not read from the walk.
pub const TURNED_EMITTER_SLACK: f32 = 1.0 / 1024.0;

/// One emissive cell (twin of `Emitter` in `shaders/path.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Emitter {
    /// Min corner, tree-local: the scene's, or where `instance` is a
    /// turned object's, its model tree's.
    pub min: [i32; 3],
    /// Side length in voxels.
    pub size: u32,
    /// Running sum of the weights up to and including this cell.
    pub cdf: f32,
    pub index: u32,
    /// The freely turned object whose model cell this is, or [`NO_INSTANCE`].
    pub instance: u32,
    pub _pad: u32,
}

/// Mean radiance of each emissive palette index, `None` for the others.
fn radiances(palette: &Palette) -> [Option<f32>; 256] {
    std::array::from_fn(|i| {
        let index = i as u8;
        let material = gpu_material(palette, index);
        (material.kind == MATERIAL_EMIT).then(|| albedo(palette, index).dot(Vec3::splat(1.0 / 3.0)) * material.emission)
    })
}

/// The list as it is filled: by power, empty once it overflows.
struct Listing {
    radiance: [Option<f32>; 256],
    out: Vec<Emitter>,
    total: f32,
    overflow: bool,
}

impl Listing {
    /// Lists the emissive cell `min` (`size` wide) of value `value`.
    fn add(&mut self, min: IVec3, size: i32, value: u8, instance: u32) {
        let Some(radiance) = self.radiance[usize::from(value)] else { return };
        if self.overflow || self.out.len() == MAX_EMITTERS {
            self.overflow = true;
            return;
        }
        // Power: radiance times surface area.
        self.total += radiance.max(1e-6) * (size * size) as f32;
        let (cdf, index) = (self.total, u32::from(value));
        self.out.push(Emitter { min: min.into(), size: size as u32, cdf, index, instance, _pad: 0 });
    }

    fn finish(self) -> Vec<Emitter> {
        if self.overflow { Vec::new() } else { self.out }
    }
}

/// The lights of a scene: empty when it has no emitters or more than
/// [`MAX_EMITTERS`] emissive cells. A scene drawn as instances lists each
/// object's own cells (as the tracers walk it), one of one model or
/// composed the cells of its octree.
pub fn emitters(scene: &Scene) -> Vec<Emitter> {
    let radiance = radiances(&scene.palette);
    if radiance.iter().all(Option::is_none) {
        return Vec::new();
    }
    let mut listing = Listing { radiance, out: Vec::new(), total: 0.0, overflow: false };
    match scene.instanced() {
        None => {
            let tree = scene.drawn();
            tree.for_each_solid_cell(|min, size, value| listing.add(min - tree.origin(), size, value, NO_INSTANCE));
        }
        Some(objects) => list_objects(objects, scene.origin(), &mut listing),
    }
    listing.finish()
}

/// Each shown object's emissive cells: an exactly placed one's as the
/// scene cells they land on, a turned one's as its model's cells.
fn list_objects(objects: &Objects, origin: IVec3, listing: &mut Listing) {
    // Each model's emissive cells, found once.
    let mut cells: Vec<Option<Option<Vec<Cell>>>> = vec![None; objects.models.len()];
    for (i, object) in objects.list().iter().enumerate().filter(|(_, o)| !o.hidden) {
        let model = object.placement.model;
        let tree: &Octree = &objects.models[model].tree;
        let Some(cells) = cells[model].get_or_insert_with(|| emissive_cells(tree, &listing.radiance)) else {
            listing.overflow = true;
            return;
        };
        if cells.is_empty() {
            continue;
        }
        match objects.map(i) {
            Placing::Cells(map) => {
                for &(min, size, value) in cells.iter() {
                    let (lo, _) = map.apply_box(min, min + IVec3::splat(size - 1));
                    listing.add(lo - origin, size, value, NO_INSTANCE);
                }
            }
            Placing::Turned(_) => {
                for &(min, size, value) in cells.iter() {
                    listing.add(min - tree.origin(), size, value, i as u32);
                }
            }
        }
    }
}

/// A uniform cell: its min corner, side and value.
type Cell = (IVec3, i32, u8);

/// A model's emissive cells, `None` past [`MAX_EMITTERS`] of them.
fn emissive_cells(tree: &Octree, radiance: &[Option<f32>; 256]) -> Option<Vec<Cell>> {
    let mut cells = Vec::new();
    if !tree.counts().present().any(|v| radiance[usize::from(v)].is_some()) {
        return Some(cells);
    }
    tree.for_each_solid_cell(|min, size, value| {
        if radiance[usize::from(value)].is_some() && cells.len() <= MAX_EMITTERS {
            cells.push((min, size, value));
        }
    });
    (cells.len() <= MAX_EMITTERS).then_some(cells)
}

/// The emitter whose weight interval holds `u · total` (binary search over
/// the running sums, as the shader does).
pub fn pick(lights: &[Emitter], u: f32) -> usize {
    let target = u * lights.last().map_or(0.0, |l| l.cdf);
    let (mut lo, mut hi) = (0usize, lights.len() - 1);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if lights[mid].cdf <= target {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Probability of picking light `i`.
pub fn pick_probability(lights: &[Emitter], i: usize) -> f32 {
    let before = if i == 0 { 0.0 } else { lights[i - 1].cdf };
    (lights[i].cdf - before) / lights[lights.len() - 1].cdf
}

/// Whether the model point `m` of a turned lamp's hit lies in the light's
/// cell, within [`TURNED_EMITTER_SLACK`].
pub fn holds_point(light: &Emitter, m: Vec3) -> bool {
    let lo = IVec3::from(light.min).as_vec3() - Vec3::splat(TURNED_EMITTER_SLACK);
    let hi = lo + Vec3::splat(light.size as f32 + 2.0 * TURNED_EMITTER_SLACK);
    m.cmpge(lo).all() && m.cmple(hi).all()
}

/// Whether `voxel` (tree-local) lies in the light's cell.
pub fn contains(light: &Emitter, voxel: IVec3) -> bool {
    let min = IVec3::from(light.min);
    (voxel - min).cmpge(IVec3::ZERO).all() && (voxel - min).cmplt(IVec3::splat(light.size as i32)).all()
}
