//! Issue 47, item 8: the ground plane in the WGSL preview and path tracer
//! against their CPU twins (`crate::trace::ground`): the same pixels land
//! on it and the same cells of it lie in shadow, in a scene of one model
//! and in one drawn as instances.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use glam::{DVec3, IVec3};
use octovox::camera::Camera;
use octovox::gpu::Renderer;
use octovox::io::png::differing_fraction;
use octovox::scene::{Op, Scene, Shape};
use octovox::settings::{PathSettings, RenderSettings};
use octovox::trace::path::render_cpu;
use octovox::trace::render::render_scene_cpu;

use crate::path_trace::{
    WHITE, assert_alike, build, instanced_material_scene, look, material, material_scene, mean, palette, render_gpu,
};

/// A slab held up by a leg, and the ground under the leg's foot.
fn table() -> (Scene, i32) {
    let tree = build(&[
        (Shape::Box { min: IVec3::new(-8, 6, -8), max: IVec3::new(8, 7, 8) }, Op::Place(WHITE)),
        (Shape::Box { min: IVec3::new(0, -2, 0), max: IVec3::new(1, 5, 1) }, Op::Place(2)),
    ]);
    (Scene::new(palette(), tree), -2)
}

fn cameras(centre: DVec3) -> Vec<Camera> {
    vec![
        look(centre + DVec3::new(-20.0, 24.0, 30.0), centre),
        look(centre + DVec3::new(30.0, 9.0, -22.0), centre),
        Camera { ortho: Some(60.0), ..look(centre + DVec3::new(-3.0, 50.0, 4.0), centre) },
    ]
}

/// The preview with its shadows, GPU against CPU, for every camera.
fn assert_preview_twins(scene: &mut Scene, ground: i32, cameras: &[Camera]) {
    let mut renderer = Renderer::headless().expect("a GPU adapter (lavapipe on CI)");
    renderer.sync(scene);
    let size = (96, 72);
    let settings = RenderSettings { ground: Some(ground), ..RenderSettings::default() };
    for camera in cameras {
        renderer.render(scene, camera, size, &settings, None).unwrap();
        let gpu = renderer.read_image().unwrap();
        let cpu = render_scene_cpu(scene, None, camera, size, &settings);
        let without = render_scene_cpu(scene, None, camera, size, &RenderSettings::default());
        let ground_share = differing_fraction(&cpu, &without);
        let differing = differing_fraction(&gpu, &cpu);
        println!("{camera:?}: the ground on {ground_share:.3} of the image, GPU and CPU differ on {differing:.4}");
        assert!(ground_share > 0.2, "the ground shows on {ground_share} of the image");
        assert!(differing < 0.003, "GPU and CPU differ on {differing} of the pixels");
    }
}

#[test]
fn the_gpu_preview_draws_the_ground_and_its_shadows_as_the_cpu_does() {
    let (mut scene, ground) = table();
    assert_preview_twins(&mut scene, ground, &cameras(DVec3::new(0.0, 2.0, 0.0)));
}

#[test]
fn a_scene_of_instances_stands_on_the_ground_alike_on_gpu_and_cpu() {
    let mut scene = instanced_material_scene();
    let (lo, hi) = scene.solid_bounds().unwrap();
    assert_preview_twins(&mut scene, lo.y, &cameras((lo + hi).as_dvec3() / 2.0));
}

/// Path tracing with the ground: GPU and CPU use the same random numbers,
/// so their means agree and few pixels part by more than the noise.
#[test]
fn gpu_and_cpu_path_trace_the_ground_alike() {
    for (mut scene, ground) in [table(), (material_scene(), -2)] {
        let camera = look(DVec3::new(-18.0, 20.0, 26.0), DVec3::new(0.0, 2.0, 0.0));
        let settings = PathSettings { bounces: 3, seed: 5, ground: Some(ground), ..PathSettings::default() };
        let (size, spp) = ((40, 30), 8);
        let cpu = render_cpu(&scene, &camera, size, &settings, spp).pixels;
        let (gpu, _) = render_gpu(&mut scene, &camera, size, &settings, spp);
        let sky = render_cpu(&scene, &camera, size, &PathSettings { ground: None, ..settings }, spp).pixels;
        let changed = cpu.iter().zip(&sky).filter(|(a, b)| (**a - **b).abs().max_element() > 0.05).count();
        assert!(changed * 5 > cpu.len(), "the ground changes {changed} of {} pixels", cpu.len());
        assert_alike("GPU over the ground", &cpu, &gpu);
    }
}

/// Glass resting on the ground: a path inside it that comes down to the
/// plane bounces off the ground on both tracers (the CPU's took the ground
/// for the glass's far side and let the sky in under it).
#[test]
fn glass_resting_on_the_ground_is_path_traced_alike_on_gpu_and_cpu() {
    let mut palette = palette();
    palette.materials[6] = material(octovox::scene::MaterialKind::Glass, &[("_ri", "1.5"), ("_trans", "1")]);
    let tree = build(&[(Shape::Box { min: IVec3::new(-4, 0, -4), max: IVec3::new(4, 5, 4) }, Op::Place(6))]);
    let mut scene = Scene::new(palette, tree);
    let camera = look(DVec3::new(-14.0, 12.0, 18.0), DVec3::new(0.0, 1.0, 0.0));
    let settings = PathSettings { bounces: 3, seed: 2, ground: Some(0), ..PathSettings::default() };
    let (size, spp) = ((40, 30), 8);
    let cpu = render_cpu(&scene, &camera, size, &settings, spp).pixels;
    let (gpu, effects) = render_gpu(&mut scene, &camera, size, &settings, spp);
    assert!(effects.glass, "{effects:?}");
    let (mc, mg) = (mean(&cpu), mean(&gpu));
    println!("CPU mean {mc}, GPU mean {mg}");
    assert!((mc - mg).abs().max_element() < 0.01, "CPU mean {mc}, GPU mean {mg}");
}
