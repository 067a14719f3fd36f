//! Shared helpers of the integration tests: test scenes, cameras and hit
//! comparison.
#![allow(dead_code)] // each test binary uses a different subset

pub mod exact;
pub mod window;
pub mod written;

use std::path::PathBuf;

use glam::{DVec3, IVec3};
use octovox::camera::Camera;
use octovox::scene::{Octree, Op, Shape};
use octovox::trace::Hit;

/// `../shared/assets` beside the project root.
pub fn assets() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/assets")
}

/// Copies an asset into a test folder as a user's own file: writable,
/// whatever the read-only permissions of the shared assets.
pub fn copy_writable(source: &std::path::Path, target: &std::path::Path) {
    let bytes = std::fs::read(source).unwrap_or_else(|e| panic!("{}: {e}", source.display()));
    std::fs::write(target, bytes).unwrap_or_else(|e| panic!("{}: {e}", target.display()));
}

/// A scene of overlapping spheres, boxes and holes with several colours.
pub fn sculpture() -> Octree {
    let mut tree = Octree::default();
    let edits = [
        (Shape::Box { min: IVec3::new(-20, -4, -20), max: IVec3::new(19, -1, 19) }, Op::Place(3)),
        (Shape::Sphere { center: IVec3::new(0, 8, 0), radius: 9 }, Op::Place(17)),
        (Shape::Sphere { center: IVec3::new(6, 12, 3), radius: 5 }, Op::Remove),
        (Shape::Box { min: IVec3::new(-15, 0, 8), max: IVec3::new(-8, 20, 12) }, Op::Place(80)),
        (Shape::Sphere { center: IVec3::new(-12, 10, 10), radius: 4 }, Op::Paint(200)),
        (Shape::Box { min: IVec3::new(10, 0, -15), max: IVec3::new(11, 30, -14) }, Op::Place(255)),
        (Shape::Voxel(IVec3::new(12, 31, -14)), Op::Place(1)),
    ];
    for (shape, op) in edits {
        tree.apply_brush(&shape, op).unwrap();
    }
    tree
}

/// At least 8 cameras around a box: outside from several sides, inside it,
/// grazing along its floor, straight down an axis, from below.
pub fn cameras_for(min: IVec3, max: IVec3) -> Vec<Camera> {
    let lo = min.as_dvec3();
    let hi = max.as_dvec3() + DVec3::ONE;
    let c = (lo + hi) * 0.5;
    let r = (hi - lo).length() * 0.5 + 1.0;
    let around =
        |dir: DVec3, dist: f64| Camera { eye: c + dir.normalize() * dist, target: c, fov_y_deg: 55.0, ortho: None };
    vec![
        Camera::framing(min, max, 50.0),
        around(DVec3::new(-1.0, 0.6, 0.3), r * 1.8),
        around(DVec3::new(0.2, -0.7, -1.0), r * 1.6),
        around(DVec3::new(0.0, 0.0, 1.0), r * 2.2),
        around(DVec3::new(0.0, 1.0, 0.0), r * 2.0),
        around(DVec3::new(1.0, 0.0, 0.0), r * 1.4),
        Camera {
            eye: c + DVec3::new(0.31, 0.27, 0.23),
            target: c + DVec3::new(5.0, -1.0, 3.0),
            fov_y_deg: 90.0,
            ortho: None,
        },
        Camera {
            eye: DVec3::new(lo.x - 3.0, lo.y + 0.5, c.z + 0.25),
            target: DVec3::new(hi.x, lo.y + 0.6, c.z),
            fov_y_deg: 40.0,
            ortho: None,
        },
        Camera { eye: DVec3::new(hi.x + 2.5, hi.y + 1.5, lo.z - 2.0), target: c, fov_y_deg: 70.0, ortho: None },
        // Orthographic: from outside, and with the eye inside the model
        // (its rays start behind it all the same).
        Camera { ortho: Some((r * 1.5) as f32), ..around(DVec3::new(0.6, 0.5, 0.7), r * 2.0) },
        Camera { ortho: Some((r * 0.7) as f32), ..around(DVec3::new(-0.3, 0.8, -0.5), 0.5) },
    ]
}

/// Tally of how two hit images compare.
#[derive(Debug, Default, Clone, Copy)]
pub struct Agreement {
    pub pixels: usize,
    pub exact: usize,
    /// Differ, but both hit and the voxels touch (a ray along an edge or corner).
    pub adjacent: usize,
    /// Differ on a ray that grazes an edge of a voxel hit (see [`Agreement::add_grazing`]).
    pub grazing: usize,
    pub other: usize,
}

/// How near an edge a ray must pass to graze it, in voxels.
const GRAZE: f32 = 1e-3;

impl Agreement {
    pub fn add(&mut self, a: &[Hit], b: &[Hit]) {
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(b) {
            self.pixels += 1;
            if x.value == y.value && (x.voxel == y.voxel || !x.is_hit()) {
                self.exact += 1;
            } else if x.is_hit() && y.is_hit() && (x.voxel - y.voxel).abs().max_element() <= 1 {
                self.adjacent += 1;
            } else {
                self.other += 1;
            }
        }
    }

    /// [`Agreement::add`], where a difference on a ray that grazes an edge
    /// of the voxel either side hit (the ray meets it grown by [`GRAZE`] but
    /// not shrunk by it) counts as grazing: two structures that round one
    /// ray differently (instances against the composed tree) part there.
    pub fn add_grazing(&mut self, a: &[Hit], b: &[Hit], rays: &[octovox::trace::Ray]) {
        let grazes = |hit: &Hit, ray: &octovox::trace::Ray| {
            let meets = |margin: f32| {
                let lo = hit.voxel.as_vec3() - glam::Vec3::splat(margin);
                let (t0, t1, _) = ray.slab(lo, lo + glam::Vec3::splat(1.0 + 2.0 * margin));
                t0 <= t1 && t1 > 0.0
            };
            hit.is_hit() && meets(GRAZE) && !meets(-GRAZE)
        };
        for ((x, y), ray) in a.iter().zip(b).zip(rays) {
            let before = self.other;
            self.add(std::slice::from_ref(x), std::slice::from_ref(y));
            if self.other > before && (grazes(x, ray) || grazes(y, ray)) {
                self.other -= 1;
                self.grazing += 1;
            }
        }
    }

    pub fn exact_fraction(&self) -> f64 {
        self.exact as f64 / self.pixels.max(1) as f64
    }

    /// ≥ 99.99 % identical, and every difference is between touching voxels.
    pub fn assert_good(&self, what: &str) {
        eprintln!(
            "{what}: {:.4} % exact of {} pixels, {} adjacent, {} grazing",
            100.0 * self.exact_fraction(),
            self.pixels,
            self.adjacent,
            self.grazing
        );
        assert!(
            self.exact_fraction() >= 0.9999 && self.other == 0,
            "{what}: {self:?} ({:.4} % exact)",
            100.0 * self.exact_fraction()
        );
    }
}
