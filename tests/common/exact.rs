//! An exact reference for "which voxel does this ray hit first, through
//! which face": the tracers' rules (docs/traversal.md) evaluated in exact
//! rational arithmetic, so the answer needs no floating-point luck.
//!
//! The ray is the f32 ray the tracers use (origin and direction after
//! `Ray::new`'s clamping of tiny components), converted to rationals exactly.
//! Crossing parameters t = (plane − o) / d, positions o + d·t and every
//! comparison between them are exact. Ties follow the documented rule:
//! planes crossed at the same t count as crossed in x, y, z order (the DDA
//! steps x, then y, then z; a box's entry axis is the last tied one), and a
//! ray that starts exactly on a plane has crossed it in its direction of
//! travel. Empty space is skipped a uniform octree cell at a time, which
//! visits the same voxels as a voxel-by-voxel DDA under that rule.

use glam::IVec3;
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{Signed, Zero};
use octovox::scene::Octree;
use octovox::trace::Ray;

/// What the exact ray hits first (tree-local voxel), and when.
#[derive(Clone, Debug, PartialEq)]
pub struct ExactHit {
    pub voxel: IVec3,
    /// The entered face; zero when the ray starts inside the voxel.
    pub normal: IVec3,
    pub t: BigRational,
}

/// The ray in exact arithmetic.
pub struct ExactRay {
    pub o: [BigRational; 3],
    pub d: [BigRational; 3],
}

pub fn exact(v: f32) -> BigRational {
    BigRational::from_float(v).expect("a finite f32")
}

fn int(v: i64) -> BigRational {
    BigRational::from_integer(BigInt::from(v))
}

impl ExactRay {
    pub fn of(ray: &Ray) -> ExactRay {
        ExactRay { o: ray.origin.to_array().map(exact), d: ray.dir.to_array().map(exact) }
    }

    /// t where the ray crosses the plane `coord` on `axis`.
    pub fn plane_t(&self, axis: usize, coord: i64) -> BigRational {
        (int(coord) - &self.o[axis]) / &self.d[axis]
    }

    fn positive(&self, axis: usize) -> bool {
        self.d[axis].is_positive()
    }

    /// The voxel coordinate on `axis` at `t` after entering through a plane
    /// of `entry_axis` (3: started inside): the last voxel whose entry plane
    /// is crossed, planes on axes up to the entry axis counting when tied.
    pub fn voxel_on_axis(&self, axis: usize, t: &BigRational, entry_axis: usize) -> i64 {
        let p = &self.o[axis] + &self.d[axis] * t;
        let inclusive = axis <= entry_axis;
        let k = match (self.positive(axis), inclusive) {
            (true, true) | (false, false) => p.floor(),
            (true, false) | (false, true) => p.ceil() - int(1),
        };
        i64::try_from(k.to_integer()).expect("a voxel coordinate")
    }

    /// Entry and exit t of the box `min..max`, and the entry axis (of tied
    /// axes the last).
    pub fn slab(&self, min: [i64; 3], max: [i64; 3]) -> (BigRational, BigRational, usize) {
        let mut near: Option<(BigRational, usize)> = None;
        let mut far: Option<BigRational> = None;
        for axis in 0..3 {
            let (a, b) = (self.plane_t(axis, min[axis]), self.plane_t(axis, max[axis]));
            let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
            if near.as_ref().is_none_or(|(t, _)| lo >= *t) {
                near = Some((lo, axis));
            }
            if far.as_ref().is_none_or(|t| hi < *t) {
                far = Some(hi);
            }
        }
        let (near, axis) = near.expect("three axes");
        (near, far.expect("three axes"), axis)
    }
}

/// The first solid voxel along `ray` in `tree` (tree-local coordinates), or
/// `None` when the ray leaves the tree first.
pub fn first_hit(tree: &Octree, ray: &Ray) -> Option<ExactHit> {
    let r = ExactRay::of(ray);
    let n = i64::from(tree.size());
    let (t_enter, t_exit, slab_axis) = r.slab([0; 3], [n; 3]);
    // t_exit = 0: the ray starts on the root's face heading out; by the
    // crossing rule it has crossed that face, so it is outside.
    if t_enter > t_exit || !t_exit.is_positive() {
        return None;
    }
    let inside = t_enter.is_negative();
    let mut t = if inside { BigRational::zero() } else { t_enter };
    let mut axis = if inside { 3 } else { slab_axis };
    let mut voxel = [0i64; 3];
    for (b, v) in voxel.iter_mut().enumerate() {
        *v = if b == axis {
            if r.positive(b) { 0 } else { n - 1 }
        } else {
            r.voxel_on_axis(b, &t, axis).clamp(0, n - 1)
        };
    }
    loop {
        let world = IVec3::new(voxel[0] as i32, voxel[1] as i32, voxel[2] as i32) + tree.origin();
        let (cell_min, level, value) = tree.uniform_cell(world)?;
        if value != 0 {
            let mut normal = IVec3::ZERO;
            if axis < 3 {
                normal[axis] = if r.positive(axis) { -1 } else { 1 };
            }
            return Some(ExactHit { voxel: world - tree.origin(), normal, t });
        }
        // Leave the empty cell through its nearest exit plane (ties: x, y, z).
        let local = cell_min - tree.origin();
        let size = 1i64 << level;
        let mut best: Option<(BigRational, usize, i64)> = None;
        for b in 0..3 {
            let plane = i64::from(local[b]) + if r.positive(b) { size } else { 0 };
            let tb = r.plane_t(b, plane);
            if best.as_ref().is_none_or(|(t, _, _)| tb < *t) {
                best = Some((tb, b, plane));
            }
        }
        let (t_next, a, plane) = best.expect("three axes");
        t = t_next;
        axis = a;
        for (b, v) in voxel.iter_mut().enumerate() {
            *v = if b == a { if r.positive(b) { plane } else { plane - 1 } } else { r.voxel_on_axis(b, &t, a) };
        }
        if voxel.iter().any(|c| *c < 0 || *c >= n) {
            return None;
        }
    }
}

/// How far (in t) the exact ray stays from the box of voxel `v` (zero or
/// less when it passes through or touches the box), and the t where it
/// enters and leaves the box's slab.
pub fn gap_to_voxel(ray: &Ray, v: IVec3) -> (f64, f64, f64) {
    let r = ExactRay::of(ray);
    let min = v.to_array().map(i64::from);
    let (near, far, _) = r.slab(min, min.map(|c| c + 1));
    let f = |q: &BigRational| num_traits::ToPrimitive::to_f64(q).unwrap_or(f64::INFINITY);
    (f(&(&near - &far)), f(&near), f(&far))
}
