//! The traversal against an exact reference (tests/common/exact.rs), on
//! thousands of rays from each hard class: the SVO tracer must hit what the
//! exact ray hits, through the same face, except where two plane crossings
//! lie within f32 rounding of each other (a near tie: then it may report a
//! voxel the exact ray also touches at the same t). Zero holes, zero rays
//! that give up. docs/traversal.md states the guarantee.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use crate::common;

use common::exact::{ExactRay, first_hit, gap_to_voxel};
use glam::{IVec3, Vec3};
use num_traits::ToPrimitive;
use octovox::camera::Camera;
use octovox::gpu::Renderer;
use octovox::scene::{Octree, Op, Shape};
use octovox::settings::RenderSettings;
use octovox::trace::{Hit, Ray, svo};

/// splitmix64: a fixed, portable sequence, so every run tests the same rays.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in lo..hi.
    fn int(&mut self, lo: i32, hi: i32) -> i32 {
        lo + (self.next() % (hi - lo) as u64) as i32
    }

    /// Uniform in -1..1 with 2^-12 steps (exact in f32).
    fn unit(&mut self) -> f32 {
        self.int(-4096, 4097) as f32 / 4096.0
    }

    fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[(self.next() % items.len() as u64) as usize]
    }
}

/// What the rays of one class did.
#[derive(Default, Debug)]
struct Tally {
    rays: usize,
    hits: usize,
    exact: usize,
    near_ties: usize,
    /// The largest distance (voxels along the ray) a near tie was off by.
    widest: f64,
    failures: Vec<String>,
}

impl Tally {
    /// Fails on any failure, or on more near ties than `max_percent` of the rays.
    fn assert_clean(&self, class: &str, max_percent: usize) {
        println!(
            "{class}: {} rays, {} hits, {} exactly as the reference, {} near ties (the widest {:.2e} voxels)",
            self.rays, self.hits, self.exact, self.near_ties, self.widest
        );
        assert!(
            self.failures.is_empty(),
            "{class}: {} failures, first: {:#?}",
            self.failures.len(),
            &self.failures[..self.failures.len().min(5)]
        );
        assert!(
            self.near_ties * 100 <= self.rays * max_percent,
            "{class}: {} near ties in {} rays",
            self.near_ties,
            self.rays
        );
    }
}

/// Tolerance, as a length along the ray, for a near tie: a few f32 ulps of
/// the coordinates the tracer computes with (the origin, the tree's width,
/// the distance travelled), plus a floor for small scenes.
fn tolerance(ray: &Ray, tree: &Octree, t: f64) -> f64 {
    let length = f64::from(ray.dir.length());
    let scale = f64::from(ray.origin.abs().max_element()) + f64::from(tree.size()) + t.abs() * length;
    2f64.powi(-12) + scale * 2f64.powi(-21)
}

/// Traces `ray` (tree-local) with the CPU SVO tracer and the reference, and
/// sorts the outcome: the same voxel and face as the reference; a near tie
/// (a different answer that f32 rounding explains: the tracer's voxel lies
/// within the tolerance of the exact ray and is not entered later than the
/// exact hit, or the exact ray only clips the voxel it hits by less than the
/// tolerance); or a failure.
fn check(tree: &Octree, origin: Vec3, dir: Vec3, tally: &mut Tally) {
    let ray = Ray::new(origin, dir);
    classify(tree, &ray, &svo::trace(tree, &ray), tally);
}

/// Sorts one traced hit of `ray` against the reference (see [`check`]).
fn classify(tree: &Octree, ray: &Ray, hit: &Hit, tally: &mut Tally) {
    let (origin, dir, ray) = (ray.origin, ray.dir, *ray);
    let hit = *hit;
    let reference = first_hit(tree, &ray);
    tally.rays += 1;
    let describe =
        |what: &str| format!("{what}: origin {origin:?} dir {dir:?}: tracer {hit:?}, reference {reference:?}");
    if hit.gave_up() {
        tally.failures.push(describe("gave up"));
        return;
    }
    tally.hits += usize::from(hit.is_hit());
    let length = f64::from(ray.dir.length());
    // (how far the exact ray misses the voxel's box, when it enters it), as lengths.
    let touch = |v: IVec3| {
        let (gap, near, far) = gap_to_voxel(&ray, v);
        (gap * length, near.max(0.0) * length, (far - near.max(0.0)) * length)
    };
    let near_tie = match (&reference, hit.is_hit()) {
        (None, false) => None,
        (Some(e), true) if e.voxel == hit.voxel && e.normal == hit.normal => None,
        (Some(e), true) if e.voxel == hit.voxel => {
            // Another face of the same voxel: the two planes are crossed at
            // about the same t.
            let t = e.t.to_f64().unwrap_or(f64::INFINITY);
            let face = (0..3).find(|&a| hit.normal[a] != 0).map_or(f64::INFINITY, |a| {
                let plane = hit.voxel[a] + i32::from(hit.normal[a] > 0);
                ExactRay::of(&ray).plane_t(a, i64::from(plane)).to_f64().unwrap_or(f64::INFINITY)
            });
            let off = (face - t).abs() * length;
            Some((off <= tolerance(&ray, tree, t), off))
        }
        (Some(e), traced) => {
            let t = e.t.to_f64().unwrap_or(f64::INFINITY);
            let tol = tolerance(&ray, tree, t);
            let (_, _, clip) = touch(e.voxel);
            let skipped_a_clip = clip <= tol;
            Some(if traced {
                let (gap, near, _) = touch(hit.voxel);
                (gap <= tol && (near <= t * length + tol || skipped_a_clip), gap.max(0.0))
            } else {
                (skipped_a_clip, clip)
            })
        }
        (None, true) => {
            let (gap, near, _) = touch(hit.voxel);
            Some((gap <= tolerance(&ray, tree, near / length), gap.max(0.0)))
        }
    };
    match near_tie {
        None => tally.exact += 1,
        Some((true, off)) => {
            tally.near_ties += 1;
            tally.widest = tally.widest.max(off);
        }
        Some((false, _)) => tally.failures.push(describe(if hit.is_hit() { "another voxel" } else { "a hole" })),
    }
}

/// A scene with spheres, boxes, holes, a thin wall and single voxels, in
/// a tree whose origin is not at the world origin.
fn scene() -> Octree {
    let mut tree = common::sculpture();
    let thin = Shape::Box { min: IVec3::new(-20, 5, 25), max: IVec3::new(19, 25, 25) };
    tree.apply_brush(&thin, Op::Place(4)).unwrap();
    tree
}

fn local(tree: &Octree, p: Vec3) -> Vec3 {
    p - tree.origin().as_vec3()
}

const AXES: [Vec3; 6] = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];

/// Sends `count` rays from `ray` (tree-local origin and direction; `None`
/// skips one) through the CPU tracer and checks them against the reference:
/// no failure, at most `max_percent` near ties, at least `min_hits` hits.
fn sweep(
    tree: &Octree,
    class: &str,
    (seed, count): (u64, usize),
    (max_percent, min_hits): (usize, usize),
    mut ray: impl FnMut(&mut Rng) -> Option<(Vec3, Vec3)>,
) {
    let mut rng = Rng(seed);
    let mut tally = Tally::default();
    for _ in 0..count {
        if let Some((origin, dir)) = ray(&mut rng) {
            check(tree, origin, dir, &mut tally);
        }
    }
    tally.assert_clean(class, max_percent);
    assert!(tally.hits >= min_hits, "{class}: {} hits", tally.hits);
}

#[test]
fn axis_parallel_rays_from_integer_and_half_integer_origins() {
    let tree = scene();
    sweep(&tree, "axis-parallel", (1, 3000), (0, 500), |rng| {
        let half = rng.pick(&[0.0, 0.5]);
        let p = Vec3::new(rng.int(-30, 30) as f32, rng.int(-10, 40) as f32, rng.int(-30, 30) as f32);
        let origin = p + Vec3::new(rng.pick(&[0.0, half]), rng.pick(&[0.0, half]), rng.pick(&[0.0, half]));
        // Exactly parallel, or off by a component too small to matter.
        let tiny = rng.pick(&[0.0, -0.0, 1e-30, -1e-30]);
        let dir = rng.pick(&AXES) + Vec3::splat(tiny) * rng.pick(&[Vec3::X, Vec3::Y, Vec3::Z]);
        Some((local(&tree, origin), dir))
    });
}

#[test]
fn rays_through_edges_and_corners() {
    let tree = scene();
    sweep(&tree, "edges and corners", (2, 3000), (0, 300), |rng| {
        // From a lattice point along small integer directions: every plane
        // it meets, it meets at an edge or a corner of the voxel grid.
        let origin = Vec3::new(rng.int(-40, 40) as f32, rng.int(-20, 50) as f32, rng.int(-40, 40) as f32);
        let dir = Vec3::new(rng.int(-3, 4) as f32, rng.int(-3, 4) as f32, rng.int(-3, 4) as f32);
        (dir != Vec3::ZERO).then(|| (local(&tree, origin), dir))
    });
}

#[test]
fn grazing_rays_along_faces() {
    let tree = scene();
    sweep(&tree, "grazing", (3, 3000), (1, 300), |rng| {
        // In a voxel face plane (one coordinate an integer, its direction
        // component zero or nearly), anywhere else.
        let axis = rng.int(0, 3) as usize;
        let mut origin = Vec3::new(rng.unit() * 40.0, rng.unit() * 30.0 + 10.0, rng.unit() * 40.0);
        origin[axis] = rng.int(-25, 35) as f32;
        let mut dir = Vec3::new(rng.unit(), rng.unit(), rng.unit());
        dir[axis] = rng.pick(&[0.0, 1e-7, -1e-7, 2f32.powi(-23)]);
        (dir.abs().max_element() >= 1e-3).then(|| (local(&tree, origin), dir))
    });
}

#[test]
fn cameras_inside_solid_voxels_and_on_boundaries() {
    let tree = scene();
    let solid: Vec<IVec3> = tree.voxels().into_iter().map(|(p, _)| p).collect();
    sweep(&tree, "inside and on boundaries", (4, 3000), (0, 2000), |rng| {
        let v = solid[(rng.next() % solid.len() as u64) as usize].as_vec3();
        // Inside the voxel, on one of its faces, edges or corners.
        let offset =
            Vec3::new(rng.pick(&[0.0, 0.25, 0.5, 1.0]), rng.pick(&[0.0, 0.5, 0.75, 1.0]), rng.pick(&[0.0, 0.5, 1.0]));
        let dir = Vec3::new(rng.unit(), rng.unit(), rng.unit());
        (dir.abs().max_element() >= 1e-3).then(|| (local(&tree, v + offset), dir))
    });
}

#[test]
fn cameras_a_million_voxels_away() {
    let tree = scene();
    let target = Vec3::new(0.0, 8.0, 0.0);
    sweep(&tree, "a million voxels away", (5, 2000), (5, 300), |rng| {
        let direction = Vec3::new(rng.unit(), rng.unit(), rng.unit()).normalize_or(Vec3::X);
        // The eye as the tracer sees it: tree-local and already f32.
        let eye = local(&tree, target + direction * 1.0e6);
        let aim = local(&tree, target + Vec3::new(rng.unit(), rng.unit(), rng.unit()) * 20.0);
        Some((eye, aim - eye))
    });
}

#[test]
fn a_tree_two_to_the_twenty_wide() {
    let mut tree = scene();
    let far = IVec3::new((1 << 20) - 40, 3, -7);
    tree.apply_brush(&Shape::Box { min: far, max: far + IVec3::new(3, 9, 5) }, Op::Place(8)).unwrap();
    assert_eq!(tree.depth(), 20);
    sweep(&tree, "2^20 wide", (6, 2000), (1, 300), |rng| {
        let origin = Vec3::new(rng.unit() * 30.0, rng.unit() * 20.0 + 8.0, rng.unit() * 30.0);
        let goal =
            if rng.next().is_multiple_of(2) { far.as_vec3() + Vec3::splat(2.0) } else { Vec3::new(0.0, 8.0, 0.0) };
        let aim = goal + Vec3::new(rng.unit(), rng.unit(), rng.unit()) * 4.0;
        Some((local(&tree, origin), aim - origin))
    });
}

/// Each pixel's GPU hit (SVO, no shadows) against the reference for that
/// pixel's ray as the CPU computes it.
fn gpu_tally(renderer: &mut Renderer, scene: &octovox::scene::Scene, camera: &Camera, size: (u32, u32)) -> Tally {
    let settings = RenderSettings { shadows: false, ..RenderSettings::default() };
    renderer.render(scene, camera, size, &settings, None).unwrap();
    let tree = scene.drawn();
    let basis = camera.basis(size.0, size.1, tree.origin());
    let mut tally = Tally::default();
    for (i, hit) in renderer.read_hits().unwrap().iter().enumerate() {
        let (origin, dir) = basis.ray(i as u32 % size.0, i as u32 / size.0);
        classify(tree, &Ray::new(origin, dir), hit, &mut tally);
    }
    tally
}

/// The same classes through the WGSL tracer, in batches: one camera a class,
/// each pixel's ray (as the CPU computes it) against the reference. The GPU
/// may fuse a multiply-add where the CPU rounds twice, so a near tie here
/// and there is expected even where the CPU tracer is exact.
#[test]
fn gpu_hard_cases_against_the_reference() {
    use glam::DVec3;

    let mut tree = octovox::scene::Scene::new(Default::default(), scene());
    let far = IVec3::new((1 << 20) - 40, 3, -7);
    tree.apply_brush(&Shape::Box { min: far, max: far + IVec3::new(3, 9, 5) }, Op::Place(8)).unwrap();
    let mut renderer = octovox::gpu::Renderer::headless().expect("a GPU adapter (lavapipe on CI)");
    renderer.hit_records = true;
    renderer.sync(&mut tree);
    let camera = |eye: [f64; 3], target: [f64; 3], fov: f32| Camera {
        eye: DVec3::from_array(eye),
        target: DVec3::from_array(target),
        fov_y_deg: fov,
        ortho: None,
    };
    let classes = [
        ("axis-parallel", camera([3.0, 9.0, -60.0], [3.0, 9.0, 0.0], 20.0), 1),
        ("edges and corners", camera([-30.0, -20.0, -30.0], [0.0, 10.0, 0.0], 40.0), 1),
        ("grazing", camera([-40.0, -1.0, 3.5], [0.0, -1.0, 3.5], 30.0), 1),
        ("inside a solid voxel", camera([0.5, 8.5, 0.5], [5.0, 12.0, 3.0], 90.0), 1),
        ("on a boundary", camera([-20.0, 0.0, 0.0], [20.0, 8.0, 1.0], 60.0), 1),
        ("2^20 wide", camera([f64::from(far.x) - 30.0, 12.0, 20.0], [f64::from(far.x) + 2.0, 5.0, -4.0], 40.0), 1),
    ];
    for (class, camera, max_percent) in classes {
        let tally = gpu_tally(&mut renderer, &tree, &camera, (96, 64));
        tally.assert_clean(&format!("GPU {class}"), max_percent);
        assert!(tally.hits > 100, "{class}: the camera sees too little ({} hits)", tally.hits);
    }
    // A million voxels away a 1° view is 17 000 voxels wide: a terrain of
    // 4096² voxels with bumps fills it (its slab aligned to 8-voxel cells,
    // so it costs nodes, not bricks).
    let mut terrain = Octree::default();
    let slab = Shape::Box { min: IVec3::new(-2048, -8, -2048), max: IVec3::new(2047, -1, 2047) };
    terrain.apply_brush(&slab, Op::Place(2)).unwrap();
    for i in 0..16 {
        let center = IVec3::new(i * 240 - 1900, 0, (i * 613) % 3800 - 1900);
        terrain.apply_brush(&Shape::Sphere { center, radius: 40 + i * 7 }, Op::Place(3)).unwrap();
    }
    let mut terrain = octovox::scene::Scene::new(Default::default(), terrain);
    renderer.sync(&mut terrain);
    let far_camera = camera([3.0e5, 9.0e5, 3.0e5], [0.0, 0.0, 0.0], 1.0);
    let tally = gpu_tally(&mut renderer, &terrain, &far_camera, (192, 128));
    tally.assert_clean("GPU a million voxels away", 5);
    assert!(tally.hits > 500, "the far camera sees too little ({} hits)", tally.hits);
}
