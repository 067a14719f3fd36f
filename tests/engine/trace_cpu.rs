//! The CPU SVO traversal against the CPU grid DDA, on a sculpted scene and on
//! the traversal's known hard cases.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use crate::common;

use common::{Agreement, cameras_for, sculpture};
use glam::{DVec3, IVec3, Vec3};
use octovox::camera::Camera;
use octovox::scene::{Octree, Op, Shape};
use octovox::trace::grid::{self, DenseGrid};
use octovox::trace::instanced::Traced;
use octovox::trace::render::{Tracer, trace_image};
use octovox::trace::{Footprint, Ray, svo};

fn compare(tree: &Octree, cameras: &[Camera], size: (u32, u32)) -> Agreement {
    let grid = DenseGrid::from_octree(tree).unwrap();
    let mut agreement = Agreement::default();
    for camera in cameras {
        let basis = camera.basis(size.0, size.1, tree.origin());
        let a = trace_image(&Tracer::Svo(Traced::Tree(tree)), &basis, Footprint::EXACT);
        let b = trace_image(&Tracer::Grid(&grid), &basis, Footprint::EXACT);
        assert!(a.iter().chain(&b).all(|h| !h.gave_up()));
        agreement.add(&a, &b);
    }
    agreement
}

#[test]
fn svo_matches_grid_on_sculpture() {
    let tree = sculpture();
    let (lo, hi) = tree.solid_bounds().unwrap();
    let agreement = compare(&tree, &cameras_for(lo, hi), (160, 120));
    agreement.assert_good("sculpture");
    assert!(agreement.exact > 0);
}

fn single(tree: &Octree, origin: Vec3, dir: Vec3) -> (octovox::trace::Hit, octovox::trace::Hit) {
    let ray = Ray::new(origin - tree.origin().as_vec3(), dir);
    (svo::trace(tree, &ray), grid::trace(&DenseGrid::from_octree(tree).unwrap_or_default(), &ray))
}

fn wall() -> Octree {
    let mut tree = Octree::default();
    tree.apply_brush(&Shape::Box { min: IVec3::new(0, 0, 0), max: IVec3::new(31, 31, 0) }, Op::Place(9)).unwrap();
    tree
}

#[test]
fn axis_parallel_rays_along_faces() {
    let tree = wall();
    for d in [0.0f32, 1e-30, -1e-30] {
        // Straight at the wall, exactly along voxel face planes (x = 4, y = 7).
        let (a, b) = single(&tree, Vec3::new(4.0, 7.0, -10.0), Vec3::new(d, d, 1.0));
        assert!(a.is_hit() && b.is_hit(), "{d}: {a:?} {b:?}");
        assert_eq!(a.voxel.z, 0);
        assert!((a.voxel - b.voxel).abs().max_element() <= 1);
        // Along the wall's front face plane z = 0: grazing, must not produce NaN.
        let (a, b) = single(&tree, Vec3::new(-5.0, 3.5, 0.0), Vec3::new(1.0, d, d));
        assert!(!a.gave_up() && !b.gave_up());
    }
}

#[test]
fn diagonals_through_edges_and_corners() {
    let tree = sculpture();
    let mut agreement = Agreement::default();
    for x in -6..6 {
        for y in 0..6 {
            for dir in [
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(1.0, -1.0, 1.0),
                Vec3::new(-1.0, 1.0, -1.0),
                Vec3::new(0.0, -1.0, 1.0),
            ] {
                let origin = Vec3::new(x as f32 * 4.0, y as f32 * 5.0 + 20.0, -30.0 + x as f32);
                let (a, b) = single(&tree, origin, dir);
                agreement.add(&[a], &[b]);
            }
        }
    }
    // Exact corner crossings may pick either of the touching voxels.
    assert_eq!(agreement.other, 0, "{agreement:?}");
}

#[test]
fn camera_inside_a_solid_voxel_and_on_a_boundary() {
    let tree = sculpture();
    let (a, b) = single(&tree, Vec3::new(0.5, 5.5, 0.5), Vec3::new(0.3, 0.2, 1.0));
    assert_eq!((a.value, a.voxel, a.normal), (b.value, b.voxel, b.normal));
    assert_eq!(a.voxel, IVec3::new(0, 5, 0) - tree.origin());
    assert_eq!(a.normal, IVec3::ZERO);
    let (a, b) = single(&tree, Vec3::new(0.0, 25.0, 0.0), Vec3::new(0.01, -1.0, 0.02));
    assert!(a.is_hit() && b.is_hit());
    assert!((a.voxel - b.voxel).abs().max_element() <= 1);
}

#[test]
fn far_camera_and_deep_sparse_tree() {
    let mut tree = Octree::default();
    let far = IVec3::new(40_000, -20_000, 50_000);
    tree.apply_brush(&Shape::Voxel(IVec3::ZERO), Op::Place(4)).unwrap();
    tree.apply_brush(&Shape::Voxel(far), Op::Place(5)).unwrap();
    assert!(tree.depth() >= 16);
    let camera = Camera {
        eye: far.as_dvec3() + DVec3::new(0.5, 100_000.0, 0.5),
        target: far.as_dvec3() + DVec3::splat(0.5),
        fov_y_deg: 0.01,
        ortho: None,
    };
    let basis = camera.basis(9, 9, tree.origin());
    let hits = trace_image(&Tracer::Svo(Traced::Tree(&tree)), &basis, Footprint::EXACT);
    let center = hits[4 * 9 + 4];
    assert_eq!(center.value, 5, "{center:?}");
    assert_eq!(center.voxel + tree.origin(), far);
    assert!(hits.iter().all(|h| !h.gave_up()));
}

#[test]
fn empty_and_full_scenes() {
    let empty = Octree::default();
    let (a, b) = single(&empty, Vec3::new(-3.0, 1.0, 2.0), Vec3::new(1.0, 0.1, 0.0));
    assert!(!a.is_hit() && !b.is_hit());
    let mut full = Octree::empty(IVec3::ZERO, 4);
    full.apply_brush(&Shape::Box { min: IVec3::ZERO, max: IVec3::splat(15) }, Op::Place(2)).unwrap();
    assert!(!octovox::gpu_pool::is_pointer(full.root_word()));
    let (a, b) = single(&full, Vec3::new(-3.0, 5.5, 7.25), Vec3::new(1.0, 0.1, 0.0));
    assert_eq!((a.value, a.voxel, a.normal), (b.value, b.voxel, b.normal));
    assert_eq!(a.normal, IVec3::new(-1, 0, 0));
}

#[test]
fn flat_wall_has_no_holes_from_random_directions() {
    let tree = wall();
    let mut seed = 12345u64;
    let mut rand = move || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((seed >> 33) as f64 / (1u64 << 31) as f64) as f32
    };
    for _ in 0..100 {
        // A direction in the front hemisphere, aimed at points well inside the wall.
        let dir = Vec3::new(rand() - 0.5, rand() - 0.5, 0.2 + rand()).normalize();
        let target = Vec3::new(2.0 + rand() * 28.0, 2.0 + rand() * 28.0, 0.0);
        let origin = target - dir * (5.0 + rand() * 60.0);
        let (a, b) = single(&tree, origin, dir);
        assert!(a.is_hit() && b.is_hit(), "hole at {origin} {dir}: {a:?} {b:?}");
        assert_eq!(a.normal, IVec3::new(0, 0, -1));
    }
}

/// `render --ortho`: two renders from one direction at distances ten times
/// apart are the same picture, on the GPU and on the CPU, and the two
/// agree; the perspective render from the nearer eye is another picture.
#[test]
fn orthographic_renders_do_not_depend_on_the_eye_distance() {
    let dir = tempfile::tempdir().unwrap();
    let model = common::assets().join("vox/seed/torus64.vox");
    let render = |name: &str, camera: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec!["render", model.to_str().unwrap(), "--size", "160x120", "--camera", camera];
        args.extend(extra);
        args.extend(["-o", out.to_str().unwrap()]);
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_octovox")).args(&args).output().unwrap();
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        octovox::io::png::load_png(&out).unwrap()
    };
    let (far, near) = ("60,45,80:0,0,0", "6,4.5,8:0,0,0");
    let gpu = [render("g1.png", far, &["--ortho", "70"]), render("g2.png", near, &["--ortho", "70"])];
    let cpu = [render("c1.png", far, &["--ortho", "70", "--cpu"]), render("c2.png", near, &["--ortho", "70", "--cpu"])];
    assert_eq!(gpu[0], gpu[1], "GPU: the same picture from both distances");
    assert_eq!(cpu[0], cpu[1], "CPU: the same picture from both distances");
    let differing = octovox::io::png::differing_fraction(&gpu[0], &cpu[0]);
    assert!(differing < 0.002, "GPU and CPU differ on {differing} of the pixels");
    // Not a blank picture: the torus covers a good part of it.
    let sky = *gpu[0].get_pixel(0, 0);
    let covered = gpu[0].pixels().filter(|p| **p != sky).count();
    assert!(covered > 160 * 120 / 5, "{covered} pixels show the torus");
    let perspective = render("p.png", near, &[]);
    assert!(octovox::io::png::differing_fraction(&perspective, &gpu[1]) > 0.1);
}

/// Issue 47, item 8: `render` without `--camera` framed the bounding
/// sphere, and the model filled about 40 % of the frame. It now frames the
/// voxels themselves: in a normals image (black where no voxel is), the
/// model spans at least 60 % of the frame's shorter side, and touches no
/// edge.
#[test]
fn a_default_render_fills_the_frame_with_the_model() {
    let dir = tempfile::tempdir().unwrap();
    for model in ["seed/torus64.vox", "seed/teapot256.vox", "magicavoxel/chr_knight.vox", "magicavoxel/monu1.vox"] {
        let out = dir.path().join("normals.png");
        let file = common::assets().join("vox").join(model);
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_octovox"))
            .args(["render", file.to_str().unwrap(), "--cpu", "--view", "normals", "--size", "160x90", "--force"])
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        assert!(run.status.success(), "{model}: {}", String::from_utf8_lossy(&run.stderr));
        let image = image::open(&out).unwrap().to_rgb8();
        let solid: Vec<(u32, u32)> =
            image.enumerate_pixels().filter(|(_, _, p)| p.0 != [0, 0, 0]).map(|(x, y, _)| (x, y)).collect();
        let span = |pick: fn(&(u32, u32)) -> u32| {
            solid.iter().map(pick).max().unwrap() - solid.iter().map(pick).min().unwrap() + 1
        };
        let (width, height) = (span(|p| p.0), span(|p| p.1));
        assert!(width.max(height) as f64 >= 0.6 * 90.0, "{model}: {width}×{height} of 160×90");
        let touches = solid.iter().any(|&(x, y)| x == 0 || y == 0 || x == 159 || y == 89);
        assert!(!touches, "{model} is cut by the frame's edge");
    }
}

/// Issue 47, item 8: `render` stands the model on a ground plane by
/// default, and the model's shadow falls on it. The pixels where no voxel
/// is (black in a normals image) show the ground instead of the sky that
/// `--no-ground` leaves there, and part of that ground is in shadow:
/// darker than 0.6 of the ground's median. (monu1's shadow falls behind
/// it, seen from the default camera, which stands on the sun's side.)
#[test]
fn a_default_render_stands_the_model_on_a_ground_that_takes_its_shadow() {
    let dir = tempfile::tempdir().unwrap();
    let render = |file: &std::path::Path, name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_octovox"))
            .args(["render", file.to_str().unwrap(), "--cpu", "--size", "160x90", "--force"])
            .args(extra)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        image::open(&out).unwrap().to_rgb8()
    };
    let models = [("seed/teapot256.vox", true), ("magicavoxel/chr_knight.vox", true), ("magicavoxel/monu1.vox", false)];
    for (model, shadow_in_view) in models {
        let file = common::assets().join("vox").join(model);
        let normals = render(&file, "normals.png", &["--view", "normals"]);
        let ground = render(&file, "ground.png", &[]);
        let sky = render(&file, "sky.png", &["--no-ground"]);
        let empty: Vec<(u32, u32)> =
            normals.enumerate_pixels().filter(|(_, _, p)| p.0 == [0, 0, 0]).map(|(x, y, _)| (x, y)).collect();
        assert!(empty.len() > 160 * 90 / 10, "{model}: {} pixels beside the model", empty.len());
        let changed = empty.iter().filter(|&&(x, y)| ground.get_pixel(x, y) != sky.get_pixel(x, y)).count();
        assert!(changed * 10 >= empty.len() * 9, "{model}: the ground shows on {changed} of {} pixels", empty.len());
        let mut greys: Vec<u32> =
            empty.iter().map(|&(x, y)| ground.get_pixel(x, y).0.iter().map(|&c| u32::from(c)).sum::<u32>()).collect();
        greys.sort_unstable();
        let median = greys[greys.len() / 2];
        let shadowed = greys.iter().filter(|&&g| f64::from(g) < 0.6 * f64::from(median)).count();
        println!("{model}: ground median {median}, {shadowed} of {} pixels in shadow", greys.len());
        if shadow_in_view {
            assert!(shadowed >= 30, "{model}: {shadowed} ground pixels in shadow");
        }
    }
}
