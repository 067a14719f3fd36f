//! The WGSL tracers on the real GPU path (lavapipe on CI) against the CPU
//! references: same hit records, same hard cases.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use crate::common;

use common::{Agreement, cameras_for, sculpture};
use glam::{DVec3, IVec3};
use octovox::camera::Camera;
use octovox::gpu::{PathView, Renderer};
use octovox::io::mesh::{MESH_COLOR, UpAxis, voxelize_obj};
use octovox::scene::{Octree, Op, Palette, Scene, Shape};
use octovox::settings::{RenderSettings, TraceMode, View};
use octovox::trace::grid::DenseGrid;
use octovox::trace::instanced::Traced;
use octovox::trace::render::{Tracer, trace_image};
use octovox::trace::{Footprint, Ray};

fn renderer_for(scene: &mut Scene) -> Renderer {
    let mut renderer = Renderer::headless().expect("a GPU adapter (lavapipe on CI)");
    renderer.hit_records = true;
    renderer.sync(scene);
    if let Ok(grid) = DenseGrid::from_octree(scene.drawn()) {
        renderer.set_grid(&grid, scene.revision()).unwrap();
    }
    renderer
}

fn gpu_hits(
    renderer: &mut Renderer,
    scene: &Scene,
    camera: &Camera,
    size: (u32, u32),
    mode: TraceMode,
) -> Vec<octovox::trace::Hit> {
    let settings =
        RenderSettings { mode, view: View::Shaded, shadows: true, render_scale: 1.0, lod: 0.0, ground: None };
    renderer.render(scene, camera, size, &settings, None).unwrap();
    renderer.read_hits().unwrap()
}

/// GPU SVO, GPU grid, CPU SVO and CPU grid all agree on every camera. A
/// scene of objects is traced as instances by both SVO tracers, and the
/// grids hold the objects composed: those two may part where a ray grazes
/// an edge.
fn check_scene(scene: &mut Scene, cameras: &[Camera], size: (u32, u32)) {
    let mut renderer = renderer_for(scene);
    let grid = DenseGrid::from_octree(scene.drawn()).unwrap();
    let mut vs_cpu_svo = Agreement::default();
    let mut vs_cpu_grid = Agreement::default();
    let mut gpu_grid_vs_svo = Agreement::default();
    for camera in cameras {
        let basis = camera.basis(size.0, size.1, scene.origin());
        let gpu_svo = gpu_hits(&mut renderer, scene, camera, size, TraceMode::Svo);
        let gpu_grid = gpu_hits(&mut renderer, scene, camera, size, TraceMode::Grid);
        assert!(gpu_svo.iter().chain(&gpu_grid).all(|h| !h.gave_up()));
        vs_cpu_svo.add(&gpu_svo, &trace_image(&Tracer::Svo(Traced::of(scene)), &basis, Footprint::EXACT));
        let rays: Vec<Ray> = (0..size.0 * size.1)
            .map(|i| {
                let (origin, dir) = basis.ray(i % size.0, i / size.0);
                Ray::new(origin, dir)
            })
            .collect();
        vs_cpu_grid.add_grazing(&gpu_svo, &trace_image(&Tracer::Grid(&grid), &basis, Footprint::EXACT), &rays);
        gpu_grid_vs_svo.add_grazing(&gpu_grid, &gpu_svo, &rays);
    }
    vs_cpu_svo.assert_good("GPU SVO vs CPU SVO");
    vs_cpu_grid.assert_good("GPU SVO vs CPU grid");
    gpu_grid_vs_svo.assert_good("GPU grid vs GPU SVO");
}

#[test]
fn gpu_matches_cpu_on_sculpture() {
    let mut scene = Scene::new(Palette::default(), sculpture());
    let (lo, hi) = scene.solid_bounds().unwrap();
    check_scene(&mut scene, &cameras_for(lo, hi), (96, 72));
}

/// The trace runs only on the tiles the beam lists, in rows of 64 tiles: an
/// image with several rows of listed tiles, and partial tiles on its right
/// and bottom edges, is still traced on every pixel.
#[test]
fn gpu_traces_every_listed_tile() {
    let mut scene = Scene::new(Palette::default(), sculpture());
    let camera = Camera { eye: DVec3::new(-10.0, 25.0, -30.0), target: DVec3::ZERO, fov_y_deg: 60.0, ortho: None };
    let size = (333, 211);
    let cpu =
        trace_image(&Tracer::Svo(Traced::of(&scene)), &camera.basis(size.0, size.1, scene.origin()), Footprint::EXACT);
    let tiles_with_hits: std::collections::HashSet<(usize, usize)> = (0..cpu.len())
        .filter(|&i| cpu[i].is_hit())
        .map(|i| (i % size.0 as usize / 16, i / size.0 as usize / 16))
        .collect();
    assert!(tiles_with_hits.len() > 2 * 64, "only {} tiles to trace", tiles_with_hits.len());
    check_scene(&mut scene, &[camera], size);
}

#[test]
fn gpu_matches_cpu_on_a_voxelized_scan() {
    let path = common::assets().join("meshes/nefertiti.obj");
    let tree = voxelize_obj(&path, 96, UpAxis::Z, MESH_COLOR).unwrap();
    let mut scene = Scene::new(Palette::default(), tree);
    let (lo, hi) = scene.solid_bounds().unwrap();
    check_scene(&mut scene, &cameras_for(lo, hi), (96, 72));
}

#[test]
fn gpu_hard_cases() {
    // Axis-parallel rays along voxel faces, 45° diagonals from integer
    // positions, a grazing floor camera, a camera inside a voxel and one on a
    // boundary plane.
    let mut scene = Scene::new(Palette::default(), sculpture());
    let cameras = [
        Camera { eye: DVec3::new(4.0, 7.0, -40.0), target: DVec3::new(4.0, 7.0, 0.0), fov_y_deg: 30.0, ortho: None },
        Camera { eye: DVec3::new(-30.0, 30.0, 0.0), target: DVec3::new(0.0, 0.0, 0.0), fov_y_deg: 60.0, ortho: None },
        Camera { eye: DVec3::new(-30.0, 30.0, -30.0), target: DVec3::new(0.0, 0.0, 0.0), fov_y_deg: 60.0, ortho: None },
        Camera { eye: DVec3::new(-25.0, 0.0, 3.0), target: DVec3::new(25.0, 0.0, 3.0), fov_y_deg: 20.0, ortho: None },
        Camera { eye: DVec3::new(0.5, 5.5, 0.5), target: DVec3::new(3.0, 5.0, 9.0), fov_y_deg: 70.0, ortho: None },
        Camera { eye: DVec3::new(0.0, 25.0, 0.0), target: DVec3::new(1.0, 0.0, 2.0), fov_y_deg: 70.0, ortho: None },
        Camera {
            eye: DVec3::new(-20.0, 10.0, 30.0),
            target: DVec3::new(-20.0, 10.0, 0.0),
            fov_y_deg: 50.0,
            ortho: None,
        },
        Camera { eye: DVec3::new(7.0, 40.0, 7.0), target: DVec3::new(7.0, 0.0, 7.0), fov_y_deg: 50.0, ortho: None },
    ];
    check_scene(&mut scene, &cameras, (64, 64));
}

#[test]
fn gpu_far_camera_deep_tree_empty_and_full() {
    // One voxel 2^16 away from another: a deep, sparse tree, seen from 100 000 voxels.
    let mut scene = Scene::default();
    let far = IVec3::new(40_000, -20_000, 50_000);
    scene.apply_brush(&Shape::Voxel(IVec3::ZERO), Op::Place(4)).unwrap();
    scene.apply_brush(&Shape::Voxel(far), Op::Place(5)).unwrap();
    let camera = Camera {
        eye: far.as_dvec3() + DVec3::new(0.5, 100_000.0, 0.5),
        target: far.as_dvec3() + DVec3::splat(0.5),
        fov_y_deg: 0.01,
        ortho: None,
    };
    let mut renderer = renderer_for(&mut scene);
    let hits = gpu_hits(&mut renderer, &scene, &camera, (9, 9), TraceMode::Svo);
    assert_eq!(hits[4 * 9 + 4].value, 5);
    assert_eq!(hits[4 * 9 + 4].voxel + scene.origin(), far);

    let mut empty = Scene::default();
    let mut renderer = renderer_for(&mut empty);
    let hits = gpu_hits(&mut renderer, &empty, &Camera::default(), (16, 16), TraceMode::Svo);
    assert!(hits.iter().all(|h| !h.is_hit()));
    let image = renderer.read_image().unwrap();
    assert!(image.pixels().all(|p| p.0[3] == 255 && p.0[2] > 150), "sky everywhere");

    let mut full = Scene::new(Palette::default(), Octree::empty(IVec3::ZERO, 4));
    full.apply_brush(&Shape::Box { min: IVec3::ZERO, max: IVec3::splat(15) }, Op::Place(2)).unwrap();
    let cameras = cameras_for(IVec3::ZERO, IVec3::splat(15));
    check_scene(&mut full, &cameras, (32, 32));
}

#[test]
fn gpu_flat_wall_has_no_holes() {
    let mut scene = Scene::default();
    scene.apply_brush(&Shape::Box { min: IVec3::new(0, 0, 0), max: IVec3::new(63, 63, 0) }, Op::Place(9)).unwrap();
    let mut renderer = renderer_for(&mut scene);
    let mut seed = 99u64;
    let mut rand = move || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 33) as f64 / (1u64 << 31) as f64
    };
    for _ in 0..100 {
        let target = DVec3::new(16.0 + rand() * 32.0, 16.0 + rand() * 32.0, 0.0);
        let dir = DVec3::new(rand() - 0.5, rand() - 0.5, -0.3 - rand()).normalize();
        let camera = Camera { eye: target + dir * (10.0 + rand() * 50.0), target, fov_y_deg: 10.0, ortho: None };
        let hits = gpu_hits(&mut renderer, &scene, &camera, (8, 8), TraceMode::Svo);
        // The narrow view sees only wall: any miss is a hole.
        assert!(hits.iter().all(|h| h.is_hit() && h.normal == IVec3::new(0, 0, -1)), "hole from {camera:?}");
    }
}

/// Edits between frames that outgrow the GPU pool (nodes and bricks share one
/// buffer, bricks after nodes): after each regrowth and its GPU-side copy, the
/// GPU still sees exactly the tree the CPU sees.
#[test]
fn gpu_pool_growth_keeps_the_picture() {
    let mut scene = Scene::default();
    scene.apply_brush(&Shape::Sphere { center: IVec3::splat(8), radius: 6 }, Op::Place(3)).unwrap();
    let mut renderer = renderer_for(&mut scene);
    let camera = Camera {
        eye: DVec3::new(-150.0, 120.0, -160.0),
        target: DVec3::new(40.0, 10.0, 40.0),
        fov_y_deg: 60.0,
        ortho: None,
    };
    let size = (64, 48);
    let mut growths = 0;
    for i in 0..6 {
        // Scattered spheres add nodes and bricks in both regions.
        let center = IVec3::new(20 * i, (i * 7) % 13, 80 - 16 * i);
        scene.apply_brush(&Shape::Sphere { center, radius: 4 + 5 * i }, Op::Place(4 + i as u8)).unwrap();
        let stats = renderer.sync(&mut scene);
        let tree = scene.drawn();
        eprintln!("edit {i}: {} nodes, {} bricks, {stats:?}", tree.node_count(), tree.brick_count());
        growths += u32::from(stats.grew);
        let gpu = gpu_hits(&mut renderer, &scene, &camera, size, TraceMode::Svo);
        let cpu = trace_image(
            &Tracer::Svo(Traced::of(&scene)),
            &camera.basis(size.0, size.1, scene.origin()),
            Footprint::EXACT,
        );
        let mut agreement = Agreement::default();
        agreement.add(&gpu, &cpu);
        agreement.assert_good(&format!("after edit {i}"));
    }
    assert!(growths >= 1, "the edits never grew the pool");
}

/// Every shared .vox model, at least 8 cameras each (outside, inside the
/// bounding box, grazing): GPU SVO = CPU SVO = CPU grid = GPU grid.
#[test]
fn gpu_matches_cpu_on_every_shared_model() {
    let mut models = Vec::new();
    for dir in ["seed", "magicavoxel", "format"] {
        for entry in std::fs::read_dir(common::assets().join("vox").join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "vox") && !path.ends_with("not_a.vox") {
                models.push(path);
            }
        }
    }
    assert!(models.len() >= 14, "{models:?}");
    for path in models {
        let mut scene = octovox::io::load_scene(&path, 0).unwrap();
        let (lo, hi) = scene.solid_bounds().unwrap();
        let cameras = cameras_for(lo, hi);
        assert!(cameras.len() >= 8);
        eprintln!("{}", path.display());
        check_scene(&mut scene, &cameras, (64, 48));
    }
}

/// The shaded teapot is a picture (not blank, not one colour), and the
/// iteration counts show the SVO taking fewer steps than the grid.
#[test]
fn teapot_picture_and_iteration_counts() {
    let path = common::assets().join("vox/seed/teapot256.vox");
    let mut scene = octovox::io::load_scene(&path, 0).unwrap();
    let mut renderer = renderer_for(&mut scene);
    let (lo, hi) = scene.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    let settings = RenderSettings::default();
    renderer.render(&scene, &camera, (200, 150), &settings, None).unwrap();
    let image = renderer.read_image().unwrap();
    let distinct: std::collections::HashSet<[u8; 4]> = image.pixels().map(|p| p.0).collect();
    let teapot_pixels = renderer.read_hits().unwrap().iter().filter(|h| h.is_hit()).count();
    assert!(distinct.len() > 20, "only {} colours", distinct.len());
    assert!(teapot_pixels > 200 * 150 / 10, "teapot covers {teapot_pixels} pixels");
    let mut mean = |mode| {
        let hits = gpu_hits(&mut renderer, &scene, &camera, (200, 150), mode);
        hits.iter().map(|h| f64::from(h.iterations)).sum::<f64>() / hits.len() as f64
    };
    let (svo, grid) = (mean(TraceMode::Svo), mean(TraceMode::Grid));
    eprintln!("mean iterations per pixel: SVO {svo:.1}, grid {grid:.1}");
    assert!(svo < grid, "SVO {svo} vs grid {grid}");
}

/// The window's frames do not wait for the GPU: their times arrive a frame
/// or two later, the queries are skipped while a read-back is under way (no
/// validation error for a mapped buffer), and the images are the same as
/// those of frames that wait.
#[test]
fn frames_that_do_not_wait_report_their_times_later() {
    let mut scene = Scene::new(Palette::default(), sculpture());
    let (lo, hi) = scene.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    let settings = RenderSettings::default();
    let mut renderer = Renderer::headless().unwrap();
    renderer.wait_for_frames = false;
    renderer.sync(&mut scene);
    let mut times = Vec::new();
    for _ in 0..12 {
        times.push(renderer.render(&scene, &camera, (96, 64), &settings, None).unwrap());
    }
    assert!(times.iter().all(|ms| ms.is_finite() && *ms >= 0.0), "{times:?}");
    if renderer.gpu.timestamps {
        assert_eq!(times[0], 0.0, "the first frame cannot know its own time yet: {times:?}");
    }
    assert!(times.iter().any(|ms| *ms > 0.0), "no time ever arrived: {times:?}");
    let unwaited = renderer.read_image().unwrap();
    // Waiting again works after frames that did not, and draws the same.
    renderer.wait_for_frames = true;
    assert!(renderer.render(&scene, &camera, (96, 64), &settings, None).unwrap() > 0.0);
    assert_eq!(renderer.read_image().unwrap(), unwaited);
}

/// On lavapipe, once the path kernel has run, the timestamps of a grid
/// trace that ran before it come back near zero (a 25 ms trace read
/// 0.02 ms); the timer checks them against the wall clock and falls back to
/// it. (This test fails without that check.)
#[test]
fn frame_times_stay_plausible_after_path_traced_frames() {
    let mut scene = octovox::scene::demo::BuiltIn::Interior.scene();
    let camera = octovox::scene::showroom::interior_camera();
    let mut renderer = Renderer::headless().unwrap();
    renderer.sync(&mut scene);
    renderer.set_grid(&DenseGrid::from_octree(scene.drawn()).unwrap(), scene.revision()).unwrap();
    let settings = RenderSettings { mode: TraceMode::Grid, ..RenderSettings::default() };
    let size = (480, 270);
    renderer.render(&scene, &camera, size, &settings, None).unwrap();
    let path_settings = octovox::settings::PathSettings::default();
    let view = PathView { scene: &scene, camera: &camera, size, settings: &path_settings };
    renderer.render_path(&view, true).unwrap();
    for _ in 0..3 {
        let start = std::time::Instant::now();
        let ms = renderer.render(&scene, &camera, size, &settings, None).unwrap();
        let wall = start.elapsed().as_secs_f64() * 1e3;
        if wall > 10.0 {
            assert!(ms > wall * 0.05, "a {wall:.1} ms frame timed as {ms:.3} ms");
        }
    }
}

/// With a level-of-detail footprint the GPU stops at the same summarized
/// cells as the CPU reference, shadows included, and it does stop: fewer
/// steps than the exact walk, and some pixels change.
#[test]
fn gpu_level_of_detail_matches_cpu() {
    let path = common::assets().join("meshes/nefertiti.obj");
    let tree = voxelize_obj(&path, 96, UpAxis::Z, MESH_COLOR).unwrap();
    let mut scene = Scene::new(Palette::default(), tree);
    scene.apply_brush(&Shape::Sphere { center: IVec3::new(40, 60, 40), radius: 12 }, Op::Paint(9)).unwrap();
    let (lo, hi) = scene.solid_bounds().unwrap();
    let size = (96, 72);
    let mut renderer = renderer_for(&mut scene);
    renderer.sync(&mut scene);
    for lod in [4.0, 8.0] {
        let settings = RenderSettings { lod, ..RenderSettings::default() };
        let (mut vs_cpu, mut vs_exact) = (Agreement::default(), Agreement::default());
        let (mut steps, mut exact_steps) = (0u64, 0u64);
        for camera in cameras_for(lo, hi) {
            let basis = camera.basis(size.0, size.1, scene.origin());
            renderer.render(&scene, &camera, size, &settings, None).unwrap();
            let gpu = renderer.read_hits().unwrap();
            let cpu = trace_image(&Tracer::Svo(Traced::of(&scene)), &basis, Footprint::of_pixels(&basis, lod));
            let exact = trace_image(&Tracer::Svo(Traced::of(&scene)), &basis, Footprint::EXACT);
            vs_cpu.add(&gpu, &cpu);
            vs_exact.add(&gpu, &exact);
            steps += gpu.iter().map(|h| u64::from(h.iterations)).sum::<u64>();
            exact_steps += exact.iter().map(|h| u64::from(h.iterations)).sum::<u64>();
            // The shaded image, shadow rays included, as the CPU draws it.
            let image = renderer.read_image().unwrap();
            let reference = octovox::trace::render::render_scene_cpu(&scene, None, &camera, size, &settings);
            let differing = image.pixels().zip(reference.pixels()).filter(|(a, b)| a != b).count();
            assert!(differing <= 2, "lod {lod}: {differing} pixels differ from the CPU's");
        }
        vs_cpu.assert_good(&format!("GPU vs CPU at lod {lod}"));
        eprintln!(
            "lod {lod}: {} of {} pixels as exact, steps {steps} vs {exact_steps}",
            vs_exact.exact, vs_exact.pixels
        );
        assert!(vs_exact.exact_fraction() < 0.99, "lod {lod} changed nothing: {vs_exact:?}");
        assert!(steps * 10 < exact_steps * 9, "lod {lod}: {steps} steps, exact {exact_steps}");
    }
}
