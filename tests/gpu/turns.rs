//! Freely turned objects on the GPU (issue 49, item 2): the shaders move
//! each ray into a turned object's frame as the CPU reference does
//! (`Turned` records), so the preview's hits, its shading and its shadows
//! agree with the CPU's on 100 objects under random rotations, with the
//! hard-case cameras (grazing rows, the eye inside an object).

use glam::DVec3;
use octovox::camera::Camera;
use octovox::gpu::Renderer;
use octovox::settings::{RenderSettings, TraceMode, View};
use octovox::trace::instanced::Traced;
use octovox::trace::render::{Tracer, render_scene_cpu, trace_image};
use octovox::trace::{Footprint, Ray};

use crate::common::{Agreement, cameras_for, written};

fn turned_herd() -> octovox::scene::Scene {
    let mut bytes = Vec::new();
    written::turned_herd(100, 49).write_vox(&mut bytes).unwrap();
    let scene = octovox::io::vox::load_vox_scene(&bytes, 0).unwrap().0;
    assert!(scene.instanced().is_some_and(|o| o.has_free_turns()), "traced as turned instances");
    scene
}

/// The hard-case cameras around the herd, and one inside object 0.
fn cameras(scene: &octovox::scene::Scene) -> Vec<Camera> {
    let (lo, hi) = scene.solid_bounds().unwrap();
    let mut cameras = cameras_for(lo, hi);
    let (a, b) = scene.objects().unwrap().world_box(0).unwrap();
    let inside = (a + b).as_dvec3() / 2.0 + DVec3::splat(0.5);
    cameras.push(Camera { eye: inside, target: inside + DVec3::new(3.0, -1.0, 2.0), fov_y_deg: 100.0, ortho: None });
    cameras
}

#[test]
fn a_hundred_turned_objects_trace_on_the_gpu_as_on_the_cpu() {
    let mut scene = turned_herd();
    let size = (96, 64);
    let mut renderer = Renderer::headless().expect("a GPU adapter (lavapipe on CI)");
    renderer.hit_records = true;
    renderer.sync(&mut scene);
    let settings =
        RenderSettings { mode: TraceMode::Svo, view: View::Shaded, shadows: true, ..RenderSettings::default() };
    let (mut agreement, mut hits) = (Agreement::default(), 0);
    let mut differing_pixels = 0;
    for camera in cameras(&scene) {
        let basis = camera.basis(size.0, size.1, scene.origin());
        renderer.render(&scene, &camera, size, &settings, None).unwrap();
        let gpu = renderer.read_hits().unwrap();
        let cpu = trace_image(&Tracer::Svo(Traced::of(&scene)), &basis, Footprint::EXACT);
        assert!(gpu.iter().chain(&cpu).all(|h| !h.gave_up()), "no give-ups");
        hits += cpu.iter().filter(|h| h.is_hit()).count();
        let rays: Vec<Ray> = (0..size.0 * size.1)
            .map(|i| {
                let (origin, dir) = basis.ray(i % size.0, i / size.0);
                Ray::new(origin, dir)
            })
            .collect();
        agreement.add_grazing(&gpu, &cpu, &rays);
        let (gpu_image, cpu_image) =
            (renderer.read_image().unwrap(), render_scene_cpu(&scene, None, &camera, size, &settings));
        differing_pixels += gpu_image.pixels().zip(cpu_image.pixels()).filter(|(a, b)| a != b).count();
    }
    let pixels = agreement.pixels;
    println!("{hits} hits; {differing_pixels} of {pixels} shaded pixels differ");
    assert!(hits * 6 > pixels, "{hits} of {pixels} rays hit");
    agreement.assert_good("GPU vs CPU, turned instances");
    assert!(differing_pixels * 500 < pixels, "{differing_pixels} of {pixels} shaded pixels differ");
}

/// Quarter turns and mirrors given as free turns (`_ov_turn` the identity
/// beside `_r`) take the general path on the GPU and find the same hits,
/// cell and face, as the integer path, on every pixel of the hard-case
/// cameras.
#[test]
fn quarter_turns_through_the_general_path_hit_as_the_integer_path_on_the_gpu() {
    use crate::path_trace::{instanced_material_scene, turned_material_scene};
    let (mut integer, mut general) = (instanced_material_scene(), turned_material_scene([Some("0 0 0 1"); 3]));
    assert!(general.instanced().is_some_and(|o| o.has_free_turns()));
    assert!(integer.instanced().is_some_and(|o| !o.has_free_turns()));
    assert_eq!(integer.origin(), general.origin());
    let size = (80, 60);
    let settings =
        RenderSettings { mode: TraceMode::Svo, view: View::Shaded, shadows: true, ..RenderSettings::default() };
    let mut renderer = Renderer::headless().expect("a GPU adapter (lavapipe on CI)");
    renderer.hit_records = true;
    let (lo, hi) = integer.solid_bounds().unwrap();
    let (mut pixels, mut hits) = (0, 0);
    for camera in cameras_for(lo, hi) {
        let mut draw = |scene: &mut octovox::scene::Scene| {
            renderer.sync(scene);
            renderer.render(scene, &camera, size, &settings, None).unwrap();
            renderer.read_hits().unwrap()
        };
        let (a, b) = (draw(&mut integer), draw(&mut general));
        for (x, y) in a.iter().zip(&b) {
            assert_eq!((x.value, x.voxel, x.normal), (y.value, y.voxel, y.normal), "camera {camera:?}");
        }
        pixels += a.len();
        hits += a.iter().filter(|h| h.is_hit()).count();
    }
    println!("{hits} hits of {pixels} pixels, all the same");
    assert!(hits * 10 > pixels, "{hits} hits");
}
