//! CPU reference tracers: the SVO stack traversal (the same algorithm as
//! `shaders/trace_svo.wgsl`) and Amanatides–Woo DDA over a dense grid (ground
//! truth, and the report's baseline). Both work in tree-local coordinates.

pub mod denoise;
pub mod grid;
pub mod ground;
pub mod instanced;
pub mod oidn;
pub mod path;
pub mod pick;
pub mod render;
pub mod svo;

use glam::{IVec3, Vec3};

pub use crate::scene::octree::iteration_bound;

/// The width in voxels below which a traversal stops at a node and shades
/// it by its level-of-detail summary (`crate::scene::lod`): `at_start +
/// per_t · t` at the ray's t. Zero is exact: every cell is at least one voxel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Footprint {
    pub at_start: f32,
    pub per_t: f32,
}

impl Footprint {
    pub const EXACT: Footprint = Footprint { at_start: 0.0, per_t: 0.0 };

    /// The footprint of `pixels` image pixels for the camera rays of
    /// `basis`: their t is the depth along the view axis, where one pixel is
    /// `2·|up| / height` voxels wide per unit of depth (orthographic: that
    /// wide at every depth).
    pub fn of_pixels(basis: &crate::camera::RayBasis, pixels: f32) -> Footprint {
        let width = pixels.max(0.0) * 2.0 * basis.up.length() / basis.height.max(1) as f32;
        if basis.ortho { Footprint { at_start: width, per_t: 0.0 } } else { Footprint { at_start: 0.0, per_t: width } }
    }

    /// The footprint a shadow ray from a hit at camera-ray `t` keeps.
    pub fn at(self, t: f32) -> Footprint {
        Footprint { at_start: self.at_start + self.per_t * t, per_t: 0.0 }
    }

    /// Whether a cell `size` voxels wide, entered at `t`, is below the
    /// footprint. Twin of `below_footprint` in `shaders/trace_svo.wgsl`.
    pub fn covers(self, size: u32, t: f32) -> bool {
        size as f32 <= self.at_start + self.per_t * t
    }
}

/// Entry axis of a ray that starts inside a cell (no face entered).
pub const NO_AXIS: usize = 3;

/// Direction components smaller than this are clamped to ±this, so no
/// division by zero can happen and slabs stay ordered.
pub const MIN_DIRECTION: f32 = 1.0 / 8_388_608.0; // 2^-23

/// What a ray found. `voxel` is tree-local; `normal` is the entered face
/// (zero when the ray starts inside a solid voxel). In a freely turned
/// object `voxel` is the cell holding the hit cell's turned centre, `normal`
/// the axis nearest the face's, and `turned` the face exactly.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Hit {
    pub value: u8,
    pub voxel: IVec3,
    pub normal: IVec3,
    /// Level of the uniform cell that was hit (0 = a single voxel); the
    /// node-depth debug view shows it.
    pub cell_level: u32,
    pub iterations: u32,
    /// The ray ran out of iterations ([`iteration_bound`]) before it hit a
    /// voxel or left the tree: not a miss, an unknown.
    pub gave_up: bool,
    pub turned: Option<TurnedFace>,
}

/// The face of a freely turned object's cell that a ray entered, in the
/// scene's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TurnedFace {
    pub normal: Vec3,
    /// The centre of the model cell in front of the face (where a shadow
    /// ray starts, as from the empty voxel in front of an unturned face).
    pub outside: Vec3,
    /// The model cell hit (tree-local) and the face's model normal.
    pub cell: IVec3,
    pub cell_normal: IVec3,
}

impl Hit {
    /// The face's normal as shading sees it (zero: none).
    pub fn shading_normal(&self) -> Vec3 {
        self.turned.map_or(self.normal.as_vec3(), |face| face.normal)
    }

    pub fn is_hit(&self) -> bool {
        self.value != 0
    }

    pub fn gave_up(&self) -> bool {
        self.gave_up
    }

    /// A miss after `iterations`, a give-up when they reached `bound`.
    pub fn miss(iterations: u32, bound: u32) -> Hit {
        Hit { iterations, gave_up: iterations >= bound, ..Hit::default() }
    }

    /// Inverse of the shader's hit record `[x, y, z, info]`.
    pub fn from_record(record: [u32; 4]) -> Hit {
        let info = record[3];
        Hit {
            value: info as u8,
            voxel: IVec3::new(record[0] as i32, record[1] as i32, record[2] as i32),
            normal: normal_from_code((info >> 8) & 7),
            cell_level: (info >> 11) & 31,
            iterations: info >> 16,
            gave_up: info >> 16 == GAVE_UP_RECORD,
            turned: None,
        }
    }
}

/// The iteration field of a hit record that marks a give-up (the shaders
/// get it from `crate::gpu::prelude`).
pub const GAVE_UP_RECORD: u32 = 0xffff;

/// The unit axis vector nearest `n` (ties to x, then y): a turned face's
/// normal as a code. Twin of `nearest_axis_code` in shaders/instances.wgsl.
pub fn nearest_axis(n: Vec3) -> IVec3 {
    let a = n.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    let mut out = IVec3::ZERO;
    out[axis] = if n[axis] < 0.0 { -1 } else { 1 };
    out
}

/// 0 = none, 1..=6 = +x, −x, +y, −y, +z, −z.
pub fn normal_code(n: IVec3) -> u32 {
    for axis in 0..3 {
        if n[axis] > 0 {
            return 1 + 2 * axis as u32;
        }
        if n[axis] < 0 {
            return 2 + 2 * axis as u32;
        }
    }
    0
}

/// The axis of [`normal_code`]'s code (zero for 0).
pub fn normal_from_code(code: u32) -> IVec3 {
    if code == 0 || code > 6 {
        return IVec3::ZERO;
    }
    let axis = ((code - 1) / 2) as usize;
    let mut n = IVec3::ZERO;
    n[axis] = if code % 2 == 1 { 1 } else { -1 };
    n
}

/// A ray prepared for traversal: tiny components clamped, reciprocal ready.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    pub inv: Vec3,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3) -> Ray {
        // -0.0 counts as positive, as `select` does in WGSL.
        let clamp = |d: f32| {
            if d.is_nan() {
                MIN_DIRECTION
            } else if d.abs() < MIN_DIRECTION {
                if d >= 0.0 { MIN_DIRECTION } else { -MIN_DIRECTION }
            } else {
                d
            }
        };
        let dir = Vec3::new(clamp(dir.x), clamp(dir.y), clamp(dir.z));
        Ray { origin, dir, inv: Vec3::ONE / dir }
    }

    /// Parameter t where the ray crosses the plane `coord` on `axis`.
    pub fn plane_t(&self, axis: usize, coord: f32) -> f32 {
        (coord - self.origin[axis]) * self.inv[axis]
    }

    /// Entry and exit t of the box `min..max` and the axis of the entry
    /// plane (of planes crossed at the same t, the last one: see [`argmin`]).
    pub fn slab(&self, min: Vec3, max: Vec3) -> (f32, f32, usize) {
        let t0 = (min - self.origin) * self.inv;
        let t1 = (max - self.origin) * self.inv;
        let near = t0.min(t1);
        let far = t0.max(t1);
        let axis = if near.z >= near.x && near.z >= near.y {
            2
        } else if near.y >= near.x {
            1
        } else {
            0
        };
        (near.max_element(), far.min_element(), axis)
    }

    /// Whether the ray, at `t` and having just entered a cell through a plane
    /// on `entry_axis` (3 when it started inside), is past the plane `coord`
    /// on `axis`. Planes crossed at the same t count as crossed in x, y, z
    /// order, so a plane tied with the entry plane is past only if its axis
    /// comes first. Every tracer decides cells with this one rule.
    pub fn crossed(&self, axis: usize, coord: f32, t: f32, entry_axis: usize) -> bool {
        let t_plane = self.plane_t(axis, coord);
        if axis <= entry_axis { t_plane <= t } else { t_plane < t }
    }

    /// The voxel coordinate on `axis` where the ray is at `t`: the last voxel
    /// whose entry plane it has crossed (rounding corrected with [`Ray::crossed`]).
    pub fn voxel_on_axis(&self, axis: usize, t: f32, entry_axis: usize) -> i32 {
        let p = self.origin[axis] + self.dir[axis] * t;
        let crossed = |k: i32| self.crossed(axis, k as f32, t, entry_axis);
        if self.dir[axis] > 0.0 {
            // Voxel k is entered through plane k.
            let k = p.floor() as i32;
            if !crossed(k) {
                k - 1
            } else if crossed(k + 1) {
                k + 1
            } else {
                k
            }
        } else {
            // Voxel k is entered through plane k + 1.
            let k = p.ceil() as i32 - 1;
            if !crossed(k + 1) {
                k + 1
            } else if crossed(k) {
                k - 1
            } else {
                k
            }
        }
    }

    /// The voxel of the box `lo..=hi` (inclusive) where the ray is at `t`,
    /// having entered the box through a plane on `entry_axis`: on that axis
    /// the entered face, on the others [`Ray::voxel_on_axis`] kept in the box.
    pub fn voxel_in_box(&self, lo: IVec3, hi: IVec3, t: f32, entry_axis: usize) -> IVec3 {
        let mut voxel = IVec3::ZERO;
        for b in 0..3 {
            voxel[b] = if b == entry_axis {
                if self.dir[b] > 0.0 { lo[b] } else { hi[b] }
            } else {
                self.voxel_on_axis(b, t, entry_axis).clamp(lo[b], hi[b])
            };
        }
        voxel
    }

    /// Face normal of the plane entered along `axis`.
    pub fn entry_normal(&self, axis: usize) -> IVec3 {
        let mut n = IVec3::ZERO;
        n[axis] = if self.dir[axis] > 0.0 { -1 } else { 1 };
        n
    }
}

/// Index of the smallest component; ties go to x, then y (the DDA's rule,
/// shared by every tracer so they step in the same order).
pub fn argmin(t: Vec3) -> usize {
    if t.x <= t.y && t.x <= t.z {
        0
    } else if t.y <= t.z {
        1
    } else {
        2
    }
}
