//! The ground plane (`render --ground`, and the window's ground): the top
//! face of the cells below the plane y = `y`, seen from above. A ray that
//! comes down through the plane before it meets a voxel lands on the ground
//! instead of leaving the scene, so the model stands on something and its
//! shadow falls there. The ground receives light and shadows and casts
//! none: it lies under everything drawn with it (`render` puts it under
//! the lowest voxel; the window at y = 0, where its clicks build).
//!
//! Twin of `ground_landing` in `shaders/common.wgsl`. The test is on
//! integers where it can be: a voxel hit counts as behind the plane when
//! its cell lies below it, so the CPU and the GPU agree on which pixels
//! show the ground whatever their rounding of t.

use glam::{IVec3, Vec3};

use super::Ray;

/// The ground's colour (linear albedo): a light warm grey, as voxel editors
/// show their floor. The shaders get it from `crate::gpu::prelude`.
pub const GROUND_ALBEDO: [f32; 3] = [0.62, 0.6, 0.57];

/// Where a ray lands on the ground.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Landing {
    /// The ray's t on the plane.
    pub t: f32,
    /// The cell under the point, `(x, y - 1, z)`: the ground is its top face.
    pub cell: IVec3,
}

impl Landing {
    /// The point on the plane, its height exact.
    pub fn point(&self, ray: &Ray) -> Vec3 {
        let p = ray.origin + ray.dir * self.t;
        Vec3::new(p.x, (self.cell.y + 1) as f32, p.z)
    }
}

/// Where `ray` lands on the ground at tree-local height `y` before the voxel
/// it found (`hit`, `None` for a miss): only coming down from above the
/// plane, and only where that voxel's cell lies below the plane.
pub fn landing(ray: &Ray, y: i32, hit: Option<IVec3>) -> Option<Landing> {
    let plane = y as f32;
    if ray.dir.y >= 0.0 || ray.origin.y <= plane || hit.is_some_and(|voxel| voxel.y >= y) {
        return None;
    }
    let t = ray.plane_t(1, plane);
    let p = ray.origin + ray.dir * t;
    if !(t.is_finite() && p.x.is_finite() && p.z.is_finite()) {
        return None;
    }
    Some(Landing { t, cell: IVec3::new(p.x.floor() as i32, y - 1, p.z.floor() as i32) })
}

/// The preview's colour of the ground, lit as a voxel's top face is
/// (`shade` in `shaders/common.wgsl`): ambient, sky from straight above,
/// and the sun unless `in_shadow`.
pub fn shaded(in_shadow: bool) -> Vec3 {
    let sun = if in_shadow { 0.0 } else { crate::settings::SUN_DIR[1] };
    Vec3::from(GROUND_ALBEDO) * (0.25 + 0.15 + 0.6 * sun)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
        Ray::new(Vec3::from(o), Vec3::from(d))
    }

    #[test]
    fn a_ray_coming_down_lands_in_the_cell_under_its_point() {
        let r = ray([2.5, 10.0, -3.25], [0.5, -1.0, 0.0]);
        let land = landing(&r, 4, None).unwrap();
        assert_eq!(land.cell, IVec3::new(5, 3, -4));
        assert_eq!(land.point(&r).y, 4.0);
        assert!((land.t - 6.0).abs() < 1e-6);
    }

    #[test]
    fn voxels_above_the_plane_hide_it_and_voxels_below_do_not() {
        let r = ray([0.5, 10.0, 0.5], [0.0, -1.0, 0.0]);
        assert!(landing(&r, 0, Some(IVec3::new(0, 0, 0))).is_none());
        assert!(landing(&r, 0, Some(IVec3::new(0, -1, 0))).is_some());
    }

    #[test]
    fn the_ground_is_seen_from_above_only() {
        assert!(landing(&ray([0.0, 5.0, 0.0], [0.0, 1.0, 0.0]), 0, None).is_none());
        assert!(landing(&ray([0.0, -5.0, 0.0], [0.0, 1.0, 0.0]), 0, None).is_none());
        assert!(landing(&ray([0.0, 0.0, 0.0], [0.0, -1.0, 0.0]), 0, None).is_none());
        // Grazing: a slope clamped to the smallest one still lands, far off.
        let far = landing(&ray([0.0, 1.0, 0.0], [1.0, -1e-9, 0.0]), 0, None);
        assert!(far.is_some_and(|l| l.t > 1e6 && l.t.is_finite()), "{far:?}");
    }

    #[test]
    fn a_shadow_darkens_the_ground() {
        assert!(shaded(true).length() < shaded(false).length() * 0.6);
    }
}
