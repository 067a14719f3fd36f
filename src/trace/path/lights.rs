//! Emissive voxels as lights: the list next-event estimation samples, one
//! entry per maximal uniform emissive cell, chosen by power.

use bytemuck::{Pod, Zeroable};
use glam::IVec3;

use super::materials::{MATERIAL_EMIT, albedo, gpu_material};
use crate::scene::{Octree, Palette};

/// Most emissive cells sampled as lights. A scene with more is still lit by
/// them (rays that hit an emitter see it), only without next-event
/// estimation toward them, so it converges more slowly.
pub const MAX_EMITTERS: usize = 4096;

/// One emissive cell (twin of `Emitter` in `shaders/path.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Emitter {
    /// Min corner, tree-local.
    pub min: [i32; 3],
    /// Side length in voxels.
    pub size: u32,
    /// Running sum of the weights up to and including this cell.
    pub cdf: f32,
    pub index: u32,
    pub _pad: [u32; 2],
}

/// The lights of a scene: empty when it has no emitters or more than
/// [`MAX_EMITTERS`] emissive cells.
pub fn emitters(tree: &Octree, palette: &Palette) -> Vec<Emitter> {
    // Mean radiance of each emissive index present, worked out once.
    let mut radiance = [None; 256];
    for index in tree.counts().present() {
        let material = gpu_material(palette, index);
        if material.kind == MATERIAL_EMIT {
            radiance[usize::from(index)] =
                Some(albedo(palette, index).dot(glam::Vec3::splat(1.0 / 3.0)) * material.emission);
        }
    }
    if radiance.iter().all(Option::is_none) {
        return Vec::new();
    }
    let mut out = Vec::new();
    let mut total = 0.0f32;
    let mut overflow = false;
    tree.for_each_solid_cell(|min, size, value| {
        let Some(radiance) = radiance[usize::from(value)] else { return };
        if overflow {
            return;
        }
        if out.len() == MAX_EMITTERS {
            overflow = true;
            return;
        }
        // Power: radiance times surface area.
        total += radiance.max(1e-6) * (size * size) as f32;
        let min = min - tree.origin();
        out.push(Emitter { min: min.into(), size: size as u32, cdf: total, index: u32::from(value), _pad: [0; 2] });
    });
    if overflow { Vec::new() } else { out }
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

/// Whether `voxel` (tree-local) lies in the light's cell.
pub fn contains(light: &Emitter, voxel: IVec3) -> bool {
    let min = IVec3::from(light.min);
    (voxel - min).cmpge(IVec3::ZERO).all() && (voxel - min).cmplt(IVec3::splat(light.size as i32)).all()
}
