//! The path tracer against what physics says it must show: the white
//! furnace, a box lit only by an emitter, clear glass, a mirror; the GPU
//! kernel against the CPU reference; no NaN anywhere. CPU tests run
//! everywhere; GPU tests on lavapipe.

#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use crate::common;

use glam::{DVec3, IVec3, Vec3};
use octovox::camera::Camera;
use octovox::gpu::{FrameInput, PathOptions, PathView, Renderer};
use octovox::scene::{Material, MaterialKind, Octree, Op, Palette, Scene, Shape};
use octovox::settings::{PathSettings, Sky};
use octovox::trace::path::{CpuRender, render_cpu};

pub(crate) const WHITE: u8 = 1;
const RED: u8 = 2;
const GREEN: u8 = 3;
const SPECIAL: u8 = 4;

pub(crate) fn palette() -> Palette {
    let mut palette = Palette::default();
    palette.colors[usize::from(WHITE)] = [255, 255, 255, 255];
    palette.colors[usize::from(RED)] = [230, 40, 30, 255];
    palette.colors[usize::from(GREEN)] = [30, 200, 60, 255];
    palette.colors[usize::from(SPECIAL)] = [255, 255, 255, 255];
    palette
}

pub(crate) fn material(kind: MaterialKind, params: &[(&str, &str)]) -> Material {
    let mut m = Material::new(kind);
    for (k, v) in params {
        m.params.insert((*k).into(), (*v).into());
    }
    m
}

pub(crate) fn build(edits: &[(Shape, Op)]) -> Octree {
    let mut tree = Octree::default();
    for (shape, op) in edits {
        tree.apply_brush(shape, *op).unwrap();
    }
    tree
}

fn furnace() -> PathSettings {
    PathSettings { bounces: 32, sun: false, sky: Sky::White, ..PathSettings::default() }
}

pub(crate) fn mean(pixels: &[Vec3]) -> Vec3 {
    pixels.iter().sum::<Vec3>() / pixels.len() as f32
}

pub(crate) fn look(eye: DVec3, target: DVec3) -> Camera {
    Camera { eye, target, fov_y_deg: 40.0, ortho: None }
}

/// Each pixel's centre ray as the CPU tracer hits it.
fn centre_hits(tree: &Octree, camera: &Camera, size: (u32, u32)) -> Vec<octovox::trace::Hit> {
    let basis = camera.basis(size.0, size.1, tree.origin());
    let tracer = octovox::trace::render::Tracer::Svo(octovox::trace::instanced::Traced::Tree(tree));
    octovox::trace::render::trace_image(&tracer, &basis, octovox::trace::Footprint::EXACT)
}

/// Pixels whose hit (by the CPU tracer) is a voxel.
fn object_pixels(tree: &Octree, camera: &Camera, size: (u32, u32), pixels: &[Vec3]) -> Vec<Vec3> {
    let hits = centre_hits(tree, camera, size);
    hits.iter().zip(pixels).filter(|(h, _)| h.is_hit()).map(|(_, p)| *p).collect()
}

#[test]
fn white_furnace_converges_to_the_sky_on_the_cpu() {
    // Albedo 1 everywhere under a sky of radiance 1: every path carries 1,
    // however many times it bounces between the sphere's voxel steps and
    // the floor.
    let scene = Scene::new(palette(), furnace_tree());
    // The second camera sees the faces on the root cube's own faces.
    for camera in furnace_cameras() {
        let size = (48, 36);
        let CpuRender { pixels, effects, .. } = render_cpu(&scene, &camera, size, &furnace(), 16);
        assert_eq!(effects.names(), ["sky"]);
        assert_furnace(scene.drawn(), &camera, size, &pixels);
    }
}

/// A white sphere on a white floor.
fn furnace_tree() -> Octree {
    build(&[
        (Shape::Sphere { center: IVec3::new(0, 6, 0), radius: 6 }, Op::Place(WHITE)),
        (Shape::Box { min: IVec3::new(-12, -2, -12), max: IVec3::new(12, -1, 12) }, Op::Place(WHITE)),
    ])
}

fn furnace_cameras() -> [Camera; 2] {
    [
        look(DVec3::new(20.0, 16.0, 24.0), DVec3::new(0.0, 4.0, 0.0)),
        look(DVec3::new(-22.0, 8.0, -26.0), DVec3::new(0.0, 2.0, 0.0)),
    ]
}

fn assert_furnace(tree: &Octree, camera: &Camera, size: (u32, u32), pixels: &[Vec3]) {
    let object = object_pixels(tree, camera, size, pixels);
    assert!(object.len() > 500, "{} object pixels", object.len());
    let m = mean(&object);
    assert!((m - Vec3::ONE).abs().max_element() < 0.01, "object mean {m}");
    let worst = object.iter().map(|p| (*p - Vec3::ONE).abs().max_element()).fold(0.0, f32::max);
    assert!(worst < 0.08, "worst pixel off by {worst}");
}

/// A closed 9³ room (walls one voxel thick) with one lamp voxel on the
/// ceiling, seen from inside.
fn lamp_room(lamp: Material) -> (Scene, Camera) {
    let tree = build(&[
        (Shape::Box { min: IVec3::splat(-5), max: IVec3::splat(5) }, Op::Place(WHITE)),
        (Shape::Box { min: IVec3::splat(-4), max: IVec3::splat(4) }, Op::Remove),
        (Shape::Box { min: IVec3::new(-5, -4, -4), max: IVec3::new(-5, 4, 4) }, Op::Paint(RED)),
        (Shape::Voxel(IVec3::new(0, 4, 0)), Op::Place(SPECIAL)),
    ]);
    let mut palette = palette();
    palette.materials[usize::from(SPECIAL)] = lamp;
    (Scene::new(palette, tree), look(DVec3::new(3.5, 0.5, 3.5), DVec3::new(-3.0, -1.0, -2.0)))
}

#[test]
fn a_closed_room_is_lit_by_its_emitter_and_dark_without() {
    let settings = PathSettings { bounces: 4, ..PathSettings::default() };
    let emit = material(MaterialKind::Emit, &[("_emit", "1")]);
    let (scene, camera) = lamp_room(emit);
    let CpuRender { pixels: lit, effects, .. } = render_cpu(&scene, &camera, (32, 24), &settings, 8);
    assert_eq!(effects.names(), ["sun", "sky", "emit"]);
    let m = mean(&lit);
    assert!(m.min_element() > 0.05, "the lit room's mean {m}");
    // The red wall shows red.
    assert!(m.x > m.y, "{m}");
    let (scene, camera) = lamp_room(Material::new(MaterialKind::Diffuse));
    let CpuRender { pixels: dark, effects, .. } = render_cpu(&scene, &camera, (32, 24), &settings, 8);
    assert_eq!(effects.names(), ["sun", "sky"]);
    assert!(dark.iter().all(|p| *p == Vec3::ZERO), "sun and sky cannot reach into a closed box");
}

/// A backdrop of coloured stripes; in front of it, optionally, a pane.
fn stripes_with(pane: Option<u8>) -> Octree {
    let mut edits = vec![(Shape::Box { min: IVec3::new(-8, -8, -4), max: IVec3::new(8, 8, -4) }, Op::Place(GREEN))];
    for i in (-8..8).step_by(4) {
        edits.push((Shape::Box { min: IVec3::new(i, -8, -4), max: IVec3::new(i + 1, 8, -4) }, Op::Paint(RED)));
    }
    if let Some(index) = pane {
        edits.push((Shape::Box { min: IVec3::new(-6, -6, 2), max: IVec3::new(6, 6, 3) }, Op::Place(index)));
    }
    build(&edits)
}

#[test]
fn clear_glass_of_index_one_shows_what_is_behind_it_unchanged() {
    let settings = PathSettings { bounces: 2, sun: false, ..PathSettings::default() };
    let camera = look(DVec3::new(0.5, 0.5, 30.0), DVec3::new(0.5, 0.5, 0.0));
    let mut palette = palette();
    palette.materials[usize::from(SPECIAL)] = material(MaterialKind::Glass, &[("_ri", "1"), ("_trans", "1")]);
    let size = (32, 32);
    let CpuRender { pixels: without, .. } =
        render_cpu(&Scene::new(palette.clone(), stripes_with(None)), &camera, size, &settings, 64);
    let CpuRender { pixels: with, effects, .. } =
        render_cpu(&Scene::new(palette, stripes_with(Some(SPECIAL))), &camera, size, &settings, 64);
    assert_eq!(effects.names(), ["sky", "glass"]);
    // The pane covers the middle of the view: compare there.
    let centre = |v: &[Vec3]| -> Vec<Vec3> {
        (10..22).flat_map(|y| (10..22).map(move |x| (x, y))).map(|(x, y)| v[y * 32 + x]).collect()
    };
    let (a, b) = (centre(&without), centre(&with));
    // Glass draws random numbers of its own, so the two differ by noise
    // only: equal means, and every pixel within the noise of 64 samples.
    let (ma, mb) = (mean(&a), mean(&b));
    assert!((ma - mb).abs().max_element() < 0.01, "mean without {ma}, through the pane {mb}");
    let worst = a.iter().zip(&b).map(|(p, q)| (*p - *q).abs().max_element()).fold(0.0, f32::max);
    assert!(worst < 0.08, "largest difference through the pane {worst}");
    assert!(mean(&a).x > 0.05, "the backdrop is lit: {}", mean(&a));
}

#[test]
fn a_mirror_shows_the_reflected_colour() {
    // A white mirror floor seen from above reflects the sky: each pixel is
    // the sky's radiance in the mirrored direction, where a diffuse floor
    // would show the average of the whole sky.
    let mirror = material(MaterialKind::Metal, &[("_rough", "0"), ("_metal", "1")]);
    let mut palette = palette();
    palette.materials[usize::from(SPECIAL)] = mirror;
    let floor =
        build(&[(Shape::Box { min: IVec3::new(-40, -1, -40), max: IVec3::new(40, -1, 40) }, Op::Place(SPECIAL))]);
    let scene = Scene::new(palette, floor);
    let settings = PathSettings { bounces: 3, sun: false, ..PathSettings::default() };
    let camera = look(DVec3::new(0.5, 10.0, 6.0), DVec3::new(0.5, -1.0, -3.0));
    let size = (16, 16);
    let CpuRender { pixels, effects, .. } = render_cpu(&scene, &camera, size, &settings, 16);
    assert_eq!(effects.names(), ["sky", "metal"]);
    let basis = camera.basis(size.0, size.1, scene.origin());
    let (horizon, zenith) = Sky::Gradient.colors();
    for (x, y) in [(8, 8), (2, 13), (13, 3)] {
        let d = basis.ray(x, y).1.normalize();
        let r = Vec3::new(d.x, -d.y, d.z);
        let expected = Vec3::from(horizon).lerp(Vec3::from(zenith), r.y * 0.5 + 0.5);
        let got = pixels[(y * size.0 + x) as usize];
        assert!((got - expected).abs().max_element() < 0.01, "pixel ({x}, {y}): {got}, the sky says {expected}");
    }
}

/// Renders `spp` samples on the GPU and returns the mean radiance.
pub(crate) fn render_gpu(
    scene: &mut Scene,
    camera: &Camera,
    size: (u32, u32),
    settings: &PathSettings,
    spp: u32,
) -> (Vec<Vec3>, octovox::trace::path::materials::Effects) {
    let mut renderer = Renderer::headless().expect("a GPU adapter (lavapipe on CI)");
    renderer.sync(scene);
    let mut effects = None;
    let view = PathView { scene, camera, size, settings };
    for i in 0..spp {
        let frame = renderer.render_path(&view, i == 0).unwrap();
        assert_eq!(frame.samples, i + 1);
        effects = Some(frame.effects);
    }
    (renderer.read_radiance().unwrap(), effects.unwrap())
}

#[test]
fn gpu_white_furnace_converges_to_the_sky() {
    let mut scene = Scene::new(palette(), furnace_tree());
    for camera in furnace_cameras() {
        let size = (48, 36);
        let (pixels, effects) = render_gpu(&mut scene, &camera, size, &furnace(), 16);
        assert_eq!(effects.names(), ["sky"]);
        assert_furnace(scene.drawn(), &camera, size, &pixels);
    }
}

/// A scene with every material: diffuse floor, metal, glass, a lamp.
pub(crate) fn material_scene() -> Scene {
    let mut palette = palette();
    palette.materials[5] = material(MaterialKind::Metal, &[("_rough", "0.3"), ("_metal", "0.8")]);
    palette.materials[6] = material(MaterialKind::Glass, &[("_ri", "1.5"), ("_trans", "0.9"), ("_rough", "0.05")]);
    palette.materials[7] = material(MaterialKind::Emit, &[("_emit", "1"), ("_flux", "1")]);
    palette.colors[6] = [200, 230, 255, 255];
    palette.colors[7] = [255, 220, 160, 255];
    let tree = build(&[
        (Shape::Box { min: IVec3::new(-16, -2, -16), max: IVec3::new(16, -1, 16) }, Op::Place(WHITE)),
        (Shape::Box { min: IVec3::new(-16, 0, -16), max: IVec3::new(16, 12, -15) }, Op::Place(RED)),
        (Shape::Sphere { center: IVec3::new(-6, 5, -4), radius: 5 }, Op::Place(5)),
        (Shape::Box { min: IVec3::new(2, 0, -2), max: IVec3::new(10, 9, 1) }, Op::Place(6)),
        (Shape::Box { min: IVec3::new(-2, 0, 6), max: IVec3::new(0, 2, 8) }, Op::Place(7)),
    ]);
    Scene::new(palette, tree)
}

#[test]
fn gpu_and_cpu_path_tracers_agree() {
    // The same random numbers feed both; rounding differences (sin and cos
    // are not bit-identical) can send a path another way, so compare the
    // means and the share of pixels that differ by more than the noise.
    // A seed other than 0, so both must start its sequence at the same
    // place (with seed 0 on one side only, few pixels would agree).
    let mut scene = material_scene();
    let camera = look(DVec3::new(18.0, 14.0, 26.0), DVec3::new(0.0, 3.0, 0.0));
    let settings = PathSettings { bounces: 3, seed: 3, ..PathSettings::default() };
    let size = (40, 30);
    let spp = 8;
    let CpuRender { pixels: cpu, effects: cpu_effects, .. } = render_cpu(&scene, &camera, size, &settings, spp);
    let (gpu, gpu_effects) = render_gpu(&mut scene, &camera, size, &settings, spp);
    assert_eq!(cpu_effects, gpu_effects);
    assert_eq!(gpu_effects.names(), ["sun", "sky", "emit", "metal", "glass"]);
    assert_alike("GPU", &cpu, &gpu);
}

/// Two path-traced images of one view from the same random numbers: the
/// CPU reference's and `other`'s. Rounding differences (sin and cos are not
/// bit-identical) can send a path another way, so their means agree within
/// 0.01 and at most one pixel in 20 parts by more than 0.02.
pub(crate) fn assert_alike(what: &str, cpu: &[Vec3], other: &[Vec3]) {
    let (mc, mo) = (mean(cpu), mean(other));
    assert!((mc - mo).abs().max_element() < 0.01, "{what}: CPU mean {mc}, other {mo}");
    let differing = cpu.iter().zip(other).filter(|(a, b)| (**a - **b).abs().max_element() > 0.02).count();
    println!("{what}: CPU mean {mc}, other {mo}, {differing} of {} pixels differ by more than 0.02", cpu.len());
    assert!(differing * 20 <= cpu.len(), "{what}: {differing} of {} pixels differ by more than 0.02", cpu.len());
}

#[test]
fn renders_of_two_seeds_are_independent_and_one_seed_repeats() {
    // Each pixel's mean under seeds 0 and 1, in standard errors of their
    // difference: about 1 RMS for independent samples, 0 for the same ones.
    let mut scene = material_scene();
    let camera = look(DVec3::new(18.0, 14.0, 26.0), DVec3::new(0.0, 3.0, 0.0));
    let size = (40, 30);
    let mut renderer = Renderer::headless().expect("a GPU adapter (lavapipe on CI)");
    renderer.sync(&mut scene);
    let mut sums = |seed| {
        let settings = PathSettings { bounces: 3, seed, ..PathSettings::default() };
        let view = PathView { scene: &scene, camera: &camera, size, settings: &settings };
        octovox::quality::accumulate(&mut renderer, &view, 16, None, |_| ()).unwrap();
        renderer.read_samples().unwrap().0
    };
    let (first, again, other) = (sums(0), sums(0), sums(1));
    assert_eq!(first, again, "seed 0 drew other samples the second time");
    let z: Vec<f32> = first
        .iter()
        .zip(&other)
        .flat_map(|(a, b)| {
            let (d, v) = (a.mean() - b.mean(), a.variance_of_mean() + b.variance_of_mean());
            (0..3).filter(move |&c| v[c] > 0.0).map(move |c| d[c] / v[c].sqrt())
        })
        .collect();
    let rms = (z.iter().map(|z| z * z).sum::<f32>() / z.len() as f32).sqrt();
    println!("seeds 0 and 1: RMS {rms:.3} standard errors over {} channels", z.len());
    assert!(z.len() > 1000 && (0.8..1.3).contains(&rms), "seeds 0 and 1: RMS {rms} standard errors");
}

fn all_finite(pixels: &[Vec3]) -> bool {
    pixels.iter().all(|p| p.is_finite() && p.min_element() >= 0.0)
}

#[test]
fn no_nan_or_infinity_from_the_hard_case_cameras() {
    // Every effect on, cameras inside solid voxels, on boundaries, grazing,
    // from below and a million voxels away.
    let mut scene = material_scene();
    let (lo, hi) = scene.solid_bounds().unwrap();
    let mut cameras = common::cameras_for(lo, hi);
    cameras.push(look(DVec3::new(1.0e6, 3.0e5, -2.0e5), DVec3::new(0.0, 0.0, 0.0)));
    // On the floor's top plane, grazing along it; inside a solid voxel; on
    // an edge of the lattice inside the glass.
    cameras.push(look(DVec3::new(0.0, 0.0, 0.0), DVec3::new(0.0, 0.0, 5.0)));
    cameras.push(look(DVec3::new(0.5, -1.5, 0.5), DVec3::new(3.0, 2.0, 1.0)));
    cameras.push(look(DVec3::new(4.0, 3.0, -1.0), DVec3::new(-4.0, 3.0, 8.0)));
    let settings = PathSettings { bounces: 6, shadow_samples: 2, ..PathSettings::default() };
    let mut renderer = Renderer::headless().expect("a GPU adapter (lavapipe on CI)");
    renderer.sync(&mut scene);
    for (i, camera) in cameras.iter().enumerate() {
        let CpuRender { pixels: cpu, .. } = render_cpu(&scene, camera, (24, 18), &settings, 2);
        assert!(all_finite(&cpu), "camera {i}: the CPU's accumulation holds NaN, infinity or a negative");
        let view = PathView { scene: &scene, camera, size: (24, 18), settings: &settings };
        for sample in 0..2 {
            renderer.render_path(&view, sample == 0).unwrap();
        }
        let gpu = renderer.read_radiance().unwrap();
        assert!(all_finite(&gpu), "camera {i}: the GPU's accumulation holds NaN, infinity or a negative");
    }
}

#[test]
fn a_scene_of_255_emissive_materials_renders() {
    let mut palette = palette();
    for index in 1..=255u8 {
        palette.materials[usize::from(index)] = material(MaterialKind::Emit, &[("_emit", "1"), ("_flux", "4")]);
    }
    let mut edits = vec![(Shape::Box { min: IVec3::new(0, -1, 0), max: IVec3::new(31, -1, 31) }, Op::Place(1))];
    for index in 1..=255i32 {
        edits.push((Shape::Voxel(IVec3::new(index % 16 * 2, index / 16 * 2, 4)), Op::Place(index as u8)));
    }
    let mut scene = Scene::new(palette, build(&edits));
    let camera = look(DVec3::new(16.0, 20.0, 40.0), DVec3::new(16.0, 10.0, 4.0));
    let settings = PathSettings::default();
    let (gpu, effects) = render_gpu(&mut scene, &camera, (32, 24), &settings, 2);
    assert!(effects.emit);
    assert!(all_finite(&gpu));
    let lights = octovox::trace::path::lights::emitters(&scene);
    assert!(lights.len() >= 255, "{} lights", lights.len());
    assert!(mean(&gpu).min_element() > 0.1, "{}", mean(&gpu));
}

#[test]
fn a_new_effect_set_is_compiled_off_the_frame_path() {
    // A diffuse scene, then one glass voxel: until the glass kernel is
    // compiled (on a worker thread), frames run the all-effects kernel.
    let mut palette = palette();
    palette.materials[usize::from(SPECIAL)] = material(MaterialKind::Glass, &[("_ri", "1.5"), ("_trans", "1")]);
    let mut scene =
        Scene::new(palette, build(&[(Shape::Box { min: IVec3::ZERO, max: IVec3::splat(7) }, Op::Place(WHITE))]));
    let camera = look(DVec3::new(20.0, 16.0, 24.0), DVec3::new(4.0, 4.0, 4.0));
    let settings = PathSettings::default();
    let mut renderer = Renderer::headless().unwrap();
    renderer.sync(&mut scene);
    let size = (16, 12);
    let frame =
        renderer.render_path(&PathView { scene: &scene, camera: &camera, size, settings: &settings }, true).unwrap();
    assert_eq!((frame.effects.names(), frame.kernel), (vec!["sun", "sky"], frame.effects));
    let all = PathSettings { effects: octovox::settings::EffectsChoice::All, ..settings };
    renderer.compile_path_kernel(&scene, &all).unwrap();
    scene.apply_brush(&Shape::Voxel(IVec3::new(3, 8, 3)), Op::Place(SPECIAL)).unwrap();
    renderer.sync(&mut scene);
    let view = PathView { scene: &scene, camera: &camera, size, settings: &settings };
    let frame = renderer.render_path(&view, true).unwrap();
    assert_eq!(frame.effects.names(), ["sun", "sky", "glass"]);
    assert_eq!(frame.kernel, octovox::trace::path::materials::Effects::ALL, "the stand-in runs while glass compiles");
    renderer.compile_path_kernel(&scene, &settings).unwrap();
    let frame = renderer.render_path(&view, false).unwrap();
    assert_eq!(frame.kernel, frame.effects);
}

/// Issue 46: the window kept the revision its accumulation was made from
/// and told the renderer when the scene changed. The scene's revision is in
/// the accumulation's key: an edit (or an undo, or a palette change) starts
/// it over without the caller saying so; a frame of the same scene goes on.
#[test]
fn an_edit_starts_the_accumulation_over_by_the_scenes_revision() {
    let mut editor = octovox::editor::Editor::default();
    editor.set_scene(material_scene());
    let camera = look(DVec3::new(18.0, 14.0, 26.0), DVec3::new(0.0, 3.0, 0.0));
    let (size, settings, none) =
        ((24, 18), PathSettings { bounces: 1, ..PathSettings::default() }, PathOptions::default());
    let mut renderer = Renderer::headless().expect("a GPU adapter (lavapipe on CI)");
    let lines = ["place 0 13 0", "undo 1", "rgb 2 1 2 3"];
    renderer.sync(&mut editor.scene);
    for line in lines {
        let view = PathView { scene: &editor.scene, camera: &camera, size, settings: &settings };
        let first = renderer.render_path(&view, false).unwrap().samples;
        let frame = renderer.render_path(&view, false).unwrap();
        assert_eq!(frame.samples, first + 1, "the same scene goes on accumulating");
        assert!(!renderer.path_restarts(&view, false, &none));
        let before = editor.scene.revision();
        let script = octovox::script::parse_script(std::path::Path::new("t.ovr"), line).unwrap();
        editor.run(&script.lines[0].command).unwrap();
        assert_ne!(editor.scene.revision(), before, "`{line}` gives the scene a new revision");
        renderer.sync(&mut editor.scene);
        let view = PathView { scene: &editor.scene, camera: &camera, size, settings: &settings };
        assert!(renderer.path_restarts(&view, false, &none), "`{line}` starts the accumulation over");
        assert_eq!(renderer.render_path(&view, false).unwrap().samples, 1, "after `{line}`");
    }
}

#[test]
fn a_sample_split_in_bands_equals_a_whole_one() {
    // The window spreads a slow sample over frames (`Renderer::path_bands`):
    // each band traces its rows with the same random numbers, so the
    // accumulation is the whole-sample one, and a sample counts once all
    // its bands are in. A band of 9 or 10 rows does not fill its
    // workgroups, whose extra threads must not trace the next band's rows.
    let mut scene = material_scene();
    let camera = look(DVec3::new(3.0, 8.0, 14.0), DVec3::new(0.0, 1.0, 0.0));
    let (size, settings) = ((40, 37), PathSettings { bounces: 3, ..PathSettings::default() });
    let (whole, _) = render_gpu(&mut scene, &camera, size, &settings, 3);
    // A second renderer needs the whole pool: a sync uploads what changed since the last.
    let mut scene = material_scene();
    let mut renderer = Renderer::headless().expect("a GPU adapter (lavapipe on CI)");
    renderer.sync(&mut scene);
    // The window traces the preview first when an accumulation would start over.
    let view = PathView { scene: &scene, camera: &camera, size, settings: &settings };
    assert!(renderer.path_restarts(&view, false, &PathOptions::default()), "nothing accumulated yet");
    renderer.render_path(&view, true).unwrap();
    assert!(!renderer.path_restarts(&view, false, &PathOptions::default()), "the same accumulation goes on");
    assert!(renderer.path_restarts(&view, true, &PathOptions::default()), "the scene changed");
    let moved = look(DVec3::new(3.5, 8.0, 14.0), DVec3::new(0.0, 1.0, 0.0));
    assert!(
        renderer.path_restarts(&PathView { camera: &moved, ..view }, false, &PathOptions::default()),
        "the camera moved"
    );
    for bands in [4, 37, 100] {
        renderer.path_bands = bands;
        let used = bands.min(size.1);
        for sample in 0..3 {
            for band in 0..used {
                let first = sample == 0 && band == 0;
                let frame = renderer.render_path(&view, first).unwrap();
                assert_eq!(frame.added, band == used - 1, "{bands} bands: band {band} of sample {sample}");
                assert_eq!(frame.samples, sample + u32::from(frame.added));
            }
        }
        let banded = renderer.read_radiance().unwrap();
        assert!(all_finite(&banded) && mean(&banded).max_element() > 0.05, "{bands} bands: a dark image");
        let differing = banded.iter().zip(&whole).filter(|(a, b)| a != b).count();
        assert_eq!(differing, 0, "{bands} bands: {differing} of {} pixels differ", whole.len());
    }
}

/// Issue 27, bug 6: a long path-traced render said nothing until it was
/// done. On a terminal (a pty from `script`) it shows a bar; in a pipe it
/// stays quiet.
#[test]
fn a_path_traced_render_shows_progress_on_a_terminal_only() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.png");
    let args = ["render", "--demo", "showroom", "--spp", "8", "--size", "64x36", "-o"];
    let piped = std::process::Command::new(env!("CARGO_BIN_EXE_octovox")).args(args).arg(&out).output().unwrap();
    assert!(piped.status.success(), "{}", String::from_utf8_lossy(&piped.stderr));
    assert!(!String::from_utf8_lossy(&piped.stderr).contains("path tracing"), "no bar in a pipe");
    let command = format!("{} {} {} --force", env!("CARGO_BIN_EXE_octovox"), args.join(" "), out.display());
    let tty = std::process::Command::new("script").args(["-qec", &command, "/dev/null"]).output().unwrap();
    assert!(tty.status.success(), "{}", String::from_utf8_lossy(&tty.stdout));
    assert!(String::from_utf8_lossy(&tty.stdout).contains("path tracing ["), "a bar on a terminal");
}

/// `render --seed N` draws another sequence of samples: the same seed
/// gives the same image, another seed another one.
#[test]
fn render_seed_picks_the_sequence_of_samples() {
    let dir = tempfile::tempdir().unwrap();
    // The camera that frames the showroom's bounding sphere, where the sky
    // leaves under half the pixels deterministic (`render`'s own framing
    // now brings the model closer).
    let showroom = octovox::scene::demo::BuiltIn::Showroom.scene();
    let (lo, hi) = showroom.solid_bounds().unwrap();
    let camera = octovox::camera::Camera::framing(lo, hi, 50.0);
    let (e, t) = (camera.eye, camera.target);
    let camera = format!("--camera={},{},{}:{},{},{}", e.x, e.y, e.z, t.x, t.y, t.z);
    let render = |seed: &str, name: &str| {
        let out = dir.path().join(name);
        let args = ["render", "--demo", "showroom", "--spp", "4", "--size", "64x36", &camera, "--seed", seed, "-o"];
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_octovox")).args(args).arg(&out).output().unwrap();
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        image::open(&out).unwrap().to_rgba8()
    };
    let (one, again, zero) = (render("1", "a.png"), render("1", "b.png"), render("0", "c.png"));
    assert_eq!(one, again, "seed 1 twice");
    let differing = one.pixels().zip(zero.pixels()).filter(|(a, b)| a != b).count();
    assert!(differing * 2 > one.pixels().len(), "only {differing} pixels differ between seeds 1 and 0");
}

/// Issue 27, bug 7: the selection's tint showed in the preview only. In a
/// path-traced frame a pixel is tinted by the share of its samples whose
/// first hit is selected: the selected half of a box turns toward the tint,
/// the other half keeps its exact pixels, raw and denoised.
#[test]
fn the_selection_is_tinted_in_path_traced_frames() {
    let mut scene =
        Scene::new(palette(), build(&[(Shape::Box { min: IVec3::ZERO, max: IVec3::splat(7) }, Op::Place(WHITE))]));
    let camera = look(DVec3::new(20.0, 16.0, 24.0), DVec3::new(4.0, 4.0, 4.0));
    let (size, settings) = ((48, 36), PathSettings::default());
    let mut renderer = Renderer::headless().expect("a GPU adapter (lavapipe on CI)");
    renderer.sync(&mut scene);
    let view = PathView { scene: &scene, camera: &camera, size, settings: &settings };
    let render = |renderer: &mut Renderer, options: PathOptions| {
        for sample in 0..4 {
            renderer.render_path_with(&view, sample == 0, options).unwrap();
        }
        let raw = renderer.read_image().unwrap();
        renderer.denoise_now().unwrap();
        (raw, renderer.read_image().unwrap())
    };
    let (plain, plain_denoised) = render(&mut renderer, PathOptions::default());
    let selected = (IVec3::ZERO, IVec3::new(3, 7, 7));
    let options = PathOptions { highlight: Some(selected), ..PathOptions::default() };
    assert!(renderer.path_restarts(&view, false, &options), "a new selection starts the accumulation over");
    let (tinted, tinted_denoised) = render(&mut renderer, options);

    // Each pixel's first hit through its centre, and whether its
    // neighbours' agree about being selected (edges mix their samples).
    let tree = scene.drawn();
    let hits = centre_hits(tree, &camera, size);
    let class = |x: i64, y: i64| -> Option<bool> {
        let hit = hits.get((y * i64::from(size.0) + x) as usize).filter(|h| h.is_hit())?;
        let v = hit.voxel + tree.origin();
        Some(v.cmpge(selected.0).all() && v.cmple(selected.1).all())
    };
    let (mut inside, mut outside) = (Vec::new(), Vec::new());
    for y in 1..i64::from(size.1) - 1 {
        for x in 1..i64::from(size.0) - 1 {
            let around = [(0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)].map(|(dx, dy)| class(x + dx, y + dy));
            match around {
                [Some(true), ..] if around.iter().all(|c| *c == Some(true)) => inside.push((x as u32, y as u32)),
                [Some(false), ..] if around.iter().all(|c| *c == Some(false)) => outside.push((x as u32, y as u32)),
                _ => {}
            }
        }
    }
    assert!(inside.len() > 40 && outside.len() > 40, "{} selected and {} other pixels", inside.len(), outside.len());
    let blue = |image: &image::RgbaImage, pixels: &[(u32, u32)]| {
        pixels.iter().map(|&(x, y)| f64::from(image.get_pixel(x, y)[2])).sum::<f64>() / pixels.len() as f64
    };
    for &(x, y) in &outside {
        assert_eq!(tinted.get_pixel(x, y), plain.get_pixel(x, y), "an unselected pixel changed at ({x}, {y})");
    }
    for (label, before, after) in [("raw", &plain, &tinted), ("denoised", &plain_denoised, &tinted_denoised)] {
        let (was, is) = (blue(before, &inside), blue(after, &inside));
        println!("{label}: selected pixels' blue {was:.1} → {is:.1}");
        assert!(is < 0.8 * was, "{label}: the selection is not tinted (blue {was:.1} → {is:.1})");
        let (was, is) = (blue(before, &outside), blue(after, &outside));
        assert!((is - was).abs() < 0.05 * was, "{label}: the rest changed (blue {was:.1} → {is:.1})");
    }
}

/// Issue 27: the ground grid was an overlay drawn over the image, voxels
/// included. Traced with them, its lines change only pixels whose ray meets
/// the ground before any voxel, in the preview and in path-traced frames.
#[test]
fn the_ground_grid_is_hidden_by_the_voxels_in_front_of_it() {
    use octovox::settings::RenderSettings;
    let column = Shape::Box { min: IVec3::ZERO, max: IVec3::new(3, 9, 3) };
    let mut scene = Scene::new(palette(), build(&[(column, Op::Place(WHITE))]));
    let camera = look(DVec3::new(14.0, 10.0, 18.0), DVec3::new(1.0, 3.0, 1.0));
    let size = (64, 48);
    let grid = octovox::gpu::GroundGrid { y: 0, lo: [-8, -8], hi: [8, 8], step: 1 };
    let mut renderer = Renderer::headless().expect("a GPU adapter (lavapipe on CI)");
    renderer.sync(&mut scene);

    // Which pixels' centre rays hit the column (the CPU tracer).
    let tree = scene.drawn();
    let hits = centre_hits(tree, &camera, size);
    let on_column = |i: usize| hits[i].is_hit();
    let changed = |a: &image::RgbaImage, b: &image::RgbaImage| -> Vec<usize> {
        a.pixels().zip(b.pixels()).enumerate().filter(|(_, (p, q))| p != q).map(|(i, _)| i).collect()
    };

    let settings = RenderSettings { shadows: false, ..RenderSettings::default() };
    let preview = |renderer: &mut Renderer, grid| {
        renderer.render_frame(&FrameInput::preview(&scene, &camera, size, &settings, None, grid)).unwrap();
        renderer.read_image().unwrap()
    };
    let plain = preview(&mut renderer, None);
    let gridded = preview(&mut renderer, Some(grid));
    let lines = changed(&plain, &gridded);
    let over_column = lines.iter().filter(|&&i| on_column(i)).count();
    println!("preview: {} grid pixels, {over_column} of them on the column", lines.len());
    assert!(lines.len() > 150, "the grid shows: {} pixels", lines.len());
    assert!(over_column <= 2, "{over_column} grid pixels drawn over the column");

    let path_settings = PathSettings::default();
    let view = PathView { scene: &scene, camera: &camera, size, settings: &path_settings };
    let path = |renderer: &mut Renderer, grid| {
        for sample in 0..2 {
            renderer.render_path_with(&view, sample == 0, PathOptions { grid, ..PathOptions::default() }).unwrap();
        }
        renderer.read_image().unwrap()
    };
    let plain = path(&mut renderer, None);
    let gridded_options = PathOptions { grid: Some(grid), ..PathOptions::default() };
    assert!(renderer.path_restarts(&view, false, &gridded_options), "the grid starts the accumulation over");
    let gridded = path(&mut renderer, Some(grid));
    let lines = changed(&plain, &gridded);
    // A pixel on the column's edge mixes samples that miss it.
    let inside = |i: usize| {
        let (x, y) = ((i % size.0 as usize) as i64, (i / size.0 as usize) as i64);
        [(0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)].iter().all(|(dx, dy)| {
            let (x, y) = (x + dx, y + dy);
            (0..i64::from(size.0)).contains(&x)
                && (0..i64::from(size.1)).contains(&y)
                && on_column((y * i64::from(size.0) + x) as usize)
        })
    };
    let over_column = lines.iter().filter(|&&i| inside(i)).count();
    println!("path: {} grid pixels, {over_column} of them inside the column", lines.len());
    assert!(lines.len() > 150, "the grid shows in the path tracer: {} pixels", lines.len());
    assert_eq!(over_column, 0, "grid pixels inside the column");
}

/// The material scene as a model placed three times (a reference each:
/// turned, mirrored), a scene drawn as instances.
pub(crate) fn instanced_material_scene() -> Scene {
    turned_material_scene([None; 3])
}

/// [`instanced_material_scene`] with free turns (`_ov_turn` quaternions)
/// on the placements that have one.
pub(crate) fn turned_material_scene(turns: [Option<&str>; 3]) -> Scene {
    use octovox::scene::objects::Model;
    let single = material_scene();
    // MagicaVoxel's axes: z up, world (x, y, z) is model (x, −z, y).
    let voxels: Vec<(IVec3, u8)> = single.voxels().into_iter().map(|(p, v)| (IVec3::new(p.x, -p.z, p.y), v)).collect();
    let tree = Octree::from_voxels(&voxels).unwrap();
    let (lo, hi) = tree.solid_bounds().unwrap();
    let model = Model { size: (hi - lo + IVec3::ONE).as_uvec3().to_array(), tree };
    let placements: Vec<(u32, Vec<(&str, &str)>)> = [("0 0 0", "4"), ("40 0 0", "17"), ("0 44 0", "20")]
        .into_iter()
        .zip(turns)
        .map(|((t, r), turn)| (0, [("_t", t), ("_r", r)].into_iter().chain(turn.map(|q| ("_ov_turn", q))).collect()))
        .collect();
    let mut scene = objects_scene(vec![model], &placements, single.palette.clone());
    scene.set_instancing(octovox::scene::Instancing::References);
    assert!(scene.instanced().is_some());
    scene
}

/// Path tracing a scene of references (glass, metal and lamps in each):
/// the GPU against the CPU reference, and the CPU's instances against the
/// same voxels composed into one octree, with the same random numbers.
#[test]
fn gpu_and_cpu_path_trace_instances_alike_and_as_composed() {
    let mut scene = instanced_material_scene();
    let composed = Scene::new(scene.palette.clone(), scene.drawn().clone());
    // The first placement, as the composed material scene's test sees it.
    let (lo, hi) = scene.objects().unwrap().world_box(0).unwrap();
    let centre = (lo + hi).as_dvec3() / 2.0;
    let camera = look(centre + DVec3::new(18.0, 9.0, 26.0), centre - DVec3::new(0.0, 2.0, 0.0));
    let settings = PathSettings { bounces: 3, ..PathSettings::default() };
    let (size, spp) = ((48, 36), 8);
    let basis = camera.basis(size.0, size.1, scene.origin());
    let traced = octovox::trace::instanced::Traced::of(&scene);
    let hits = octovox::trace::render::trace_image(
        &octovox::trace::render::Tracer::Svo(traced),
        &basis,
        octovox::trace::Footprint::EXACT,
    );
    let seen = |index: u8| hits.iter().filter(|h| h.value == index).count();
    let shown = hits.iter().filter(|h| h.is_hit()).count();
    assert!(
        shown * 3 > hits.len() && seen(6) > 20 && seen(5) > 20,
        "{shown} hits, {} glass, {} metal",
        seen(6),
        seen(5)
    );
    let cpu = render_cpu(&scene, &camera, size, &settings, spp).pixels;
    let (gpu, effects) = render_gpu(&mut scene, &camera, size, &settings, spp);
    assert_eq!(effects.names(), ["sun", "sky", "emit", "metal", "glass"]);
    assert!(mean(&cpu).min_element() > 0.05, "a picture, not black: {}", mean(&cpu));
    assert_alike("GPU", &cpu, &gpu);
    // The composed octree lists its lamps by its own cells, the instances
    // by their models': other random numbers, the same picture converged.
    let cpu = render_cpu(&scene, &camera, size, &settings, CONVERGED_SPP).pixels;
    let flat = render_cpu(&composed, &camera, size, &settings, CONVERGED_SPP).pixels;
    assert_converged_alike("composed", &cpu, &flat);
}

/// Samples a pixel for [`assert_converged_alike`].
const CONVERGED_SPP: u32 = 64;

/// Two renders of one picture with other random numbers, at
/// [`CONVERGED_SPP`]: their means within 1 %, and each 12 × 12 block's
/// within 5 % of the picture's mean (at 64 samples they differ by up to 3.6 %;
/// a lamp sampled wrongly, or lost, moves them by more).
fn assert_converged_alike(what: &str, a: &[Vec3], b: &[Vec3]) {
    let (ma, mb) = (mean(a), mean(b));
    assert!((ma - mb).abs().max_element() < 0.01 * ma.max_element(), "{what}: means {ma} and {mb}");
    let block = |pixels: &[Vec3], bx: usize, by: usize| {
        let at = |x: usize, y: usize| pixels[(12 * by + y) * 48 + 12 * bx + x];
        (0..12).flat_map(|y| (0..12).map(move |x| (x, y))).map(|(x, y)| at(x, y)).sum::<Vec3>() / 144.0
    };
    let mut worst = 0f32;
    for (bx, by) in (0..4).flat_map(|bx| (0..3).map(move |by| (bx, by))) {
        worst = worst.max((block(a, bx, by) - block(b, bx, by)).abs().max_element() / ma.max_element());
    }
    println!("{what}: means {ma} and {mb}, blocks differ by at most {:.1} %", worst * 100.0);
    assert!(worst < 0.05, "{what}: a 12 × 12 block differs by {:.1} %", worst * 100.0);
}

/// Path tracing turned references (issue 49): glass, metal and lamps in
/// objects turned by 30° and by an oblique turn, their bounces, shadow
/// rays and refraction in each object's own frame: the GPU against the CPU
/// reference with the same random numbers; and objects turned by nothing
/// through the turned path as the same objects unturned.
#[test]
fn gpu_and_cpu_path_trace_turned_instances_alike() {
    // 30° about MagicaVoxel's z (world y), and an oblique unit quaternion.
    let (a, b) = ("0 0 0.25881904510252074 0.9659258262890683", "0.2 -0.4 0.1 0.8888194417315589");
    let mut scene = turned_material_scene([Some(a), None, Some(b)]);
    assert!(scene.instanced().is_some_and(|o| o.has_free_turns()));
    let (lo, hi) = scene.objects().unwrap().world_box(0).unwrap();
    let centre = (lo + hi).as_dvec3() / 2.0;
    let camera = look(centre + DVec3::new(18.0, 9.0, 26.0), centre - DVec3::new(0.0, 2.0, 0.0));
    let settings = PathSettings { bounces: 3, ..PathSettings::default() };
    let (size, spp) = ((48, 36), 8);
    let cpu = render_cpu(&scene, &camera, size, &settings, spp).pixels;
    let (gpu, effects) = render_gpu(&mut scene, &camera, size, &settings, spp);
    assert_eq!(effects.names(), ["sun", "sky", "emit", "metal", "glass"]);
    assert!(mean(&cpu).min_element() > 0.05, "a picture, not black: {}", mean(&cpu));
    assert_alike("GPU, turned", &cpu, &gpu);
    // A turn by nothing takes the turned path (its faces lifted off for
    // the next ray) and lights as the unturned scene does: no path ends
    // on the face it left, no glass is left where it was entered.
    let still = render_cpu(&instanced_material_scene(), &camera, size, &settings, CONVERGED_SPP).pixels;
    let none = render_cpu(&turned_material_scene([Some("0 0 0 1"); 3]), &camera, size, &settings, CONVERGED_SPP).pixels;
    assert_converged_alike("turned by nothing", &still, &none);
}

/// A floor of 41 × 41 voxels and over it one lamp voxel, turned by the
/// oblique unit quaternion `turn` (MagicaVoxel's `_ov_turn`): a scene of
/// two objects drawn as instances.
fn turned_lamp_over_a_floor(turn: &str) -> Scene {
    use octovox::scene::objects::Model;
    let floor: Vec<(IVec3, u8)> = (0..41).flat_map(|x| (0..41).map(move |y| (IVec3::new(x, y, 0), WHITE))).collect();
    let floor = Model { size: [41, 41, 1], tree: Octree::from_voxels(&floor).unwrap() };
    let lamp = Model { size: [1, 1, 1], tree: Octree::from_voxels(&[(IVec3::ZERO, SPECIAL)]).unwrap() };
    let mut palette = palette();
    palette.materials[usize::from(SPECIAL)] = material(MaterialKind::Emit, &[("_emit", "1")]);
    let placements = [(0, vec![("_t", "0 0 0")]), (1, vec![("_t", "0 0 9"), ("_ov_turn", turn)])];
    objects_scene(vec![floor, lamp], &placements, palette)
}

/// One object per entry of `placements` under the root's group: the model
/// it places and its keyframe's keys (`_t`, `_r`, `_ov_turn`).
pub(crate) fn objects_scene(
    models: Vec<octovox::scene::objects::Model>,
    placements: &[(u32, Vec<(&str, &str)>)],
    palette: Palette,
) -> Scene {
    use octovox::scene::graph::{Attributes, Layer, Node, NodeKind, SceneGraph};
    use octovox::scene::objects::Objects;
    let children = (0..placements.len() as u32).map(|k| 2 + 2 * k).collect();
    let mut nodes = vec![
        Node {
            id: 0,
            attributes: Attributes::new(),
            kind: NodeKind::Transform { child: 1, reserved: u32::MAX, layer: 0, frames: vec![] },
        },
        Node { id: 1, attributes: Attributes::new(), kind: NodeKind::Group { children } },
    ];
    for (k, (model, keys)) in placements.iter().enumerate() {
        let id = 2 + 2 * k as u32;
        let frame: Attributes = keys.iter().map(|(key, value)| ((*key).to_owned(), (*value).to_owned())).collect();
        let transform = NodeKind::Transform { child: id + 1, reserved: u32::MAX, layer: 0, frames: vec![frame] };
        nodes.push(Node { id, attributes: Attributes::new(), kind: transform });
        let shape = NodeKind::Shape { models: vec![(*model, Attributes::new())] };
        nodes.push(Node { id: id + 1, attributes: Attributes::new(), kind: shape });
    }
    let layers = vec![Layer { id: 0, attributes: Attributes::new(), reserved: u32::MAX }];
    let graph = SceneGraph { nodes, layers, ..SceneGraph::default() };
    let objects = Objects::new(Some(graph), models, Vec::new(), 0, usize::MAX).unwrap();
    Scene::compose(palette, objects).unwrap()
}

/// A turned lamp lights as its turned cube does (issue 49): the floor under
/// a one-voxel lamp turned obliquely, lit by it alone (no sky, no sun, one
/// bounce), against the irradiance this test works out itself, a point
/// light whose intensity toward each floor point is the lamp's radiance
/// times the area its turned cube shows that way (|ω·a₁| + |ω·a₂| + |ω·a₃|
/// for the cube's axes aᵢ), on the CPU and on the GPU (light sampling
/// that aimed at the axis-aligned cell holding the lamp's centre gave the
/// floor 0.62 of it); and with no list of lights, by bounces alone (those
/// that found a lamp were not counted, as if it had been sampled).
#[test]
fn a_turned_lamp_lights_the_floor_as_its_turned_cube() {
    use octovox::trace::path::materials::{albedo, gpu_material};
    let mut scene = turned_lamp_over_a_floor("0.2 -0.4 0.1 0.8888194417315589");
    let objects = scene.instanced().expect("a freely turned lamp is drawn as an instance");
    let table = octovox::scene::instances::InstanceTable::build(objects, scene.origin());
    let turned = table.instances[1].turned.expect("the lamp is turned");
    let cell = objects.models[1].tree.voxels()[0].0 - objects.models[1].tree.origin();
    let (centre, axes) =
        (turned.scene_point(cell.as_vec3() + 0.5), [Vec3::X, Vec3::Y, Vec3::Z].map(|a| turned.scene_dir(a)));
    let floor_cells: Vec<IVec3> = scene.voxels().into_iter().filter(|v| v.1 == WHITE).map(|v| v.0).collect();
    let lo = floor_cells.iter().fold(IVec3::MAX, |a, &b| a.min(b));
    let hi = floor_cells.iter().fold(IVec3::MIN, |a, &b| a.max(b));
    let top = (hi.y + 1 - scene.origin().y) as f32;
    let radiance = albedo(&scene.palette, SPECIAL) * gpu_material(&scene.palette, SPECIAL).emission;
    let reflectance = albedo(&scene.palette, WHITE) / std::f32::consts::PI;
    let floor_centre =
        (lo + hi + IVec3::ONE).as_dvec3() / 2.0 * DVec3::new(1.0, 0.0, 1.0) + DVec3::Y * f64::from(hi.y + 1);
    let camera = look(floor_centre + DVec3::new(0.0, 30.0, 24.0), floor_centre);
    let (size, spp) = ((48, 36), 32);
    let basis = camera.basis(size.0, size.1, scene.origin());
    // Each pixel whose every sample lands on the floor's top (its corners'
    // rays do: the lamp is wider than a pixel), and what the lamp gives it.
    let traced = octovox::trace::instanced::Traced::of(&scene);
    let on_floor = |x: f32, y: f32| {
        let (o, d) = basis.ray_through(x, y);
        let hit = traced.trace(&octovox::trace::Ray::new(o, d), octovox::trace::Footprint::EXACT);
        hit.value == WHITE && hit.normal == IVec3::Y
    };
    let pixels = (size.0 * size.1) as usize;
    let expected: Vec<Option<Vec3>> = (0..pixels)
        .map(|i| {
            let (x, y) = ((i % size.0 as usize) as f32, (i / size.0 as usize) as f32);
            let covered =
                [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)].iter().all(|(dx, dy)| on_floor(x + dx, y + dy));
            let (o, d) = basis.ray_through(x + 0.5, y + 0.5);
            let p = o + d * ((top - o.y) / d.y);
            let w = centre - p;
            let (dist2, l) = (w.length_squared(), w.normalize());
            let shown: f32 = axes.iter().map(|a| a.dot(l).abs()).sum();
            covered.then(|| reflectance * radiance * (shown * l.y / dist2))
        })
        .collect();
    let floor = expected.iter().flatten().count();
    assert!(floor * 5 > pixels * 4, "{floor} of {pixels} pixels show the floor alone");
    let check = |what: &str, pixels: &[Vec3], tolerance: f32| {
        // By quarter of the picture and whole: the sum rendered against
        // the sum expected.
        let ratio = |keep: &dyn Fn(usize) -> bool| {
            let (mut got, mut want) = (0.0, 0.0);
            for (i, e) in expected.iter().enumerate().filter(|(i, _)| keep(*i)) {
                if let Some(e) = e {
                    (got, want) = (got + pixels[i].element_sum(), want + e.element_sum());
                }
            }
            got / want
        };
        let whole = ratio(&|_| true);
        let quarters: Vec<f32> = (0..4)
            .map(|q| {
                let (x0, y0) = ((q % 2) * size.0 as usize / 2, (q / 2) * size.1 as usize / 2);
                ratio(&|i| {
                    let (x, y) = (i % size.0 as usize, i / size.0 as usize);
                    (x0..x0 + size.0 as usize / 2).contains(&x) && (y0..y0 + size.1 as usize / 2).contains(&y)
                })
            })
            .collect();
        println!("{what}: rendered / expected {whole:.4} whole, {quarters:.4?} by quarter");
        assert!((whole - 1.0).abs() < tolerance, "{what}: the floor gets {whole:.4} of the turned lamp's light");
        assert!(quarters.iter().all(|r| (r - 1.0).abs() < 2.0 * tolerance), "{what}: by quarter {quarters:.4?}");
    };
    let settings = PathSettings { bounces: 1, sun: false, sky: Sky::Black, ..PathSettings::default() };
    let cpu = render_cpu(&scene, &camera, size, &settings, spp);
    assert_eq!(cpu.effects.names(), ["emit"]);
    check("CPU", &cpu.pixels, 0.03);
    let (gpu, _) = render_gpu(&mut scene, &camera, size, &settings, spp);
    check("GPU", &gpu, 0.03);
    // With no list of lights (as when a scene has too many), the lamp is
    // found by the floor's bounces alone: the same light, noisier.
    let mut unsampled = octovox::trace::path::PathScene::new(&scene, &settings);
    unsampled.lights.clear();
    let bsdf_spp = 2048;
    let pixels: Vec<Vec3> = (0..size.0 * size.1)
        .map(|i| {
            (0..bsdf_spp).map(|k| unsampled.sample(&basis, i % size.0, i / size.0, k)).sum::<Vec3>() / bsdf_spp as f32
        })
        .collect();
    check("CPU, no light sampling", &pixels, 0.03);
}

/// Over 4096 lamps (a checkerboard of 4,141 lamp voxels, no two in one
/// cell) leave no list of lights: the floor under them is lit by the
/// bounces that find them, on the GPU as on the CPU (both counted such a
/// bounce as sampled, and drew the floor black).
#[test]
fn a_floor_under_too_many_lamps_to_sample_is_lit_by_its_bounces() {
    let mut voxels: Vec<(IVec3, u8)> =
        (0..91).flat_map(|x| (0..91).map(move |z| (IVec3::new(x, 0, z), WHITE))).collect();
    voxels.extend(
        (0..91)
            .flat_map(|x| (0..91).map(move |z| (x, z)))
            .filter(|(x, z)| (x + z) % 2 == 0)
            .map(|(x, z)| (IVec3::new(x, 6, z), SPECIAL)),
    );
    let mut palette = palette();
    palette.materials[usize::from(SPECIAL)] = material(MaterialKind::Emit, &[("_emit", "1")]);
    let mut scene = Scene::new(palette, Octree::from_voxels(&voxels).unwrap());
    let (lights, max) = (octovox::trace::path::lights::emitters(&scene), octovox::trace::path::lights::MAX_EMITTERS);
    assert!(lights.is_empty(), "{} lights listed, at most {max}", lights.len());
    // Under the lamps, looking down at the floor between them.
    let camera = look(DVec3::new(40.0, 4.5, 40.0), DVec3::new(50.0, 0.0, 45.0));
    let settings = PathSettings { bounces: 1, sun: false, sky: Sky::Black, ..PathSettings::default() };
    let (size, spp) = ((32, 24), 8);
    let cpu = render_cpu(&scene, &camera, size, &settings, spp).pixels;
    assert!(mean(&cpu).min_element() > 0.05, "the floor is lit: {}", mean(&cpu));
    let (gpu, _) = render_gpu(&mut scene, &camera, size, &settings, spp);
    assert_alike("GPU, no list of lights", &cpu, &gpu);
}
