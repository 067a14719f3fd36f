//! The denoiser on the GPU against its CPU twin (`octovox::trace::denoise`),
//! the guides and the noise estimate against the CPU's, what the filter
//! must not change (a one-voxel checker, the pixels left to their samples),
//! and renders that stop at an error.

use glam::{DVec3, IVec3};
use octovox::camera::Camera;
use octovox::gpu::{PathView, Renderer};
use octovox::quality::{REFERENCE_SEED, accumulate, flip, rms_error};
use octovox::scene::{Octree, Op, Scene, Shape};
use octovox::settings::PathSettings;
use octovox::trace::denoise::{Frame, Guide, LUMINANCE, Sums, change_in_standard_errors, denoise, noise_estimate};
use octovox::trace::path::{render_cpu, to_image};

use crate::path_trace::{build, look, material_scene, palette};

fn renderer_for(scene: &mut Scene) -> Renderer {
    let mut renderer = Renderer::headless().expect("a GPU adapter (lavapipe on CI)");
    renderer.sync(scene);
    renderer
}

/// `spp` samples of `view` on the GPU, from a fresh accumulation.
fn sample(renderer: &mut Renderer, view: &PathView, spp: u32) {
    accumulate(renderer, view, spp, None, |_| ()).unwrap();
}

/// `spp` samples of `view` from the reference seed, which the samples
/// measured against them (seed 0) do not share.
fn reference_image(renderer: &mut Renderer, view: &PathView, spp: u32) -> image::RgbaImage {
    let settings = PathSettings { seed: REFERENCE_SEED, ..*view.settings };
    sample(renderer, &PathView { settings: &settings, ..*view }, spp);
    renderer.read_image().unwrap()
}

/// Channels that differ by more than `tolerance`, over all channels.
fn share_differing(a: &image::RgbaImage, b: &image::RgbaImage, tolerance: u8) -> f64 {
    let differing = a
        .pixels()
        .zip(b.pixels())
        .flat_map(|(p, q)| (0..3).map(move |c| p[c].abs_diff(q[c])))
        .filter(|d| *d > tolerance)
        .count();
    differing as f64 / (3 * a.width() * a.height()) as f64
}

fn grey_variance(image: &image::RgbaImage) -> f64 {
    let values: Vec<f64> = image.pixels().map(|p| f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])).collect();
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64
}

/// The scene of every effect, its view and settings: 48×32, 3 bounces.
fn every_effect() -> (Scene, Camera, PathSettings, (u32, u32)) {
    let camera = look(DVec3::new(18.0, 14.0, 26.0), DVec3::new(0.0, 3.0, 0.0));
    (material_scene(), camera, PathSettings { bounces: 3, ..PathSettings::default() }, (48, 32))
}

/// The CPU twin of the filter over samples of `scene` seen by `camera`.
fn cpu_filter(scene: &Scene, camera: &Camera, size: (u32, u32), sums: &[Sums], guides: &[Guide]) -> Vec<glam::Vec3> {
    denoise(&Frame::of(&camera.basis(size.0, size.1, scene.origin())), sums, guides)
}

#[test]
fn the_gpu_filter_matches_its_cpu_twin() {
    // Every effect in view, so some pixels are left to their samples; 3
    // samples take the variance from the neighbours, 6 from the pixel's own.
    let (mut scene, camera, settings, size) = every_effect();
    let mut renderer = renderer_for(&mut scene);
    let view = PathView { scene: &scene, camera: &camera, size, settings: &settings };
    for spp in [3, 6] {
        sample(&mut renderer, &view, spp);
        let raw = renderer.read_image().unwrap();
        renderer.denoise_now().unwrap();
        let gpu = renderer.read_image().unwrap();
        let (sums, guides) = renderer.read_samples().unwrap();
        let cpu = to_image(&cpu_filter(&scene, &camera, size, &sums, &guides), size.0, size.1);
        // exp and sqrt differ in their last bits; one byte of rounding.
        let off = share_differing(&gpu, &cpu, 1);
        println!("{spp} spp: {:.3} % of channels differ by more than 1", 100.0 * off);
        assert!(off < 0.002, "{spp} spp: {:.3} % of channels differ by more than 1", 100.0 * off);
        assert!(grey_variance(&gpu) > 100.0, "a flat or blank denoised image");
        assert!(share_differing(&raw, &gpu, 2) > 0.2, "the filter changed almost nothing");
        let left: Vec<usize> = (0..guides.len()).filter(|&i| !guides[i].is_filtered()).collect();
        assert!(left.len() > 50, "only {} pixels are left to their samples", left.len());
        for i in left {
            let (x, y) = (i as u32 % size.0, i as u32 / size.0);
            assert_eq!(gpu.get_pixel(x, y), raw.get_pixel(x, y), "pixel ({x}, {y}) is left to its samples");
        }
    }
}

#[test]
fn the_gpu_guides_and_noise_estimate_match_the_cpu() {
    let mut scene = material_scene();
    let camera = look(DVec3::new(-20.0, 10.0, 22.0), DVec3::new(0.0, 2.0, 0.0));
    let settings = PathSettings { bounces: 2, ..PathSettings::default() };
    let size = (40, 30);
    let cpu = render_cpu(&scene, &camera, size, &settings, 1);
    let mut renderer = renderer_for(&mut scene);
    let view = PathView { scene: &scene, camera: &camera, size, settings: &settings };
    sample(&mut renderer, &view, 1);
    let gpu = renderer.path.read_guides(&renderer.gpu).unwrap();
    let same = gpu.iter().zip(&cpu.guides).filter(|(g, c)| g.code == c.code).count();
    assert!(same * 100 >= gpu.len() * 99, "{same} of {} guides agree", gpu.len());
    let filtered = gpu.iter().filter(|g| g.is_filtered()).count();
    assert!(filtered * 4 > gpu.len(), "only {filtered} pixels are filtered");
    for (g, c) in gpu.iter().zip(&cpu.guides).filter(|(g, c)| g.code == c.code) {
        let d = glam::Vec3::from(g.point) - glam::Vec3::from(c.point);
        assert!(d.abs().max_element() < 1e-3, "guide points {:?} and {:?}", g.point, c.point);
    }
    assert_eq!(renderer.noise_estimate().unwrap(), None, "one sample has no variance");
    let mut estimates = Vec::new();
    for spp in [4, 16] {
        sample(&mut renderer, &view, spp);
        let gpu = renderer.noise_estimate().unwrap().unwrap();
        let cpu = noise_estimate(&renderer.path.read_sums(&renderer.gpu).unwrap()).unwrap();
        assert!((gpu / cpu - 1.0).abs() < 1e-3, "{spp} spp: GPU estimate {gpu}, CPU {cpu}");
        estimates.push(gpu);
    }
    // The standard error halves from 4 to 16 samples (give or take the
    // estimate's own noise).
    let ratio = estimates[0] / estimates[1];
    assert!((1.6..2.5).contains(&ratio), "estimates {estimates:?}");
}

/// A floor of one-voxel checker squares in two colours under the sun, seen
/// from straight above; the light and dark squares' cells.
fn checker() -> (Scene, Camera) {
    let mut palette = palette();
    palette.colors[8] = [110, 110, 110, 255];
    palette.colors[9] = [30, 30, 30, 255];
    let mut edits = Vec::new();
    for x in 0..24 {
        for z in 0..24 {
            edits.push((Shape::Voxel(IVec3::new(x, 0, z)), Op::Place(if (x + z) % 2 == 0 { 8 } else { 9 })));
        }
    }
    // A wall beside it, so the floor has soft light from the sky and bounces.
    edits.push((
        Shape::Box { min: IVec3::new(-2, 0, 0), max: IVec3::new(-1, 10, 23) },
        Op::Place(crate::path_trace::WHITE),
    ));
    let camera = Camera {
        eye: DVec3::new(12.0, 40.0, 12.001),
        target: DVec3::new(12.0, 0.0, 12.0),
        fov_y_deg: 50.0,
        ortho: Some(24.0),
    };
    (Scene::new(palette, build(&edits)), camera)
}

/// The checker, its view and settings: 96×96, 2 bounces.
fn checker_view() -> (Scene, Camera, PathSettings, (u32, u32)) {
    let (scene, camera) = checker();
    (scene, camera, PathSettings { bounces: 2, ..PathSettings::default() }, (96, 96))
}

/// (light − dark) / (light + dark) of the mean luminance of the squares.
fn contrast(image: &image::RgbaImage, tree: &Octree, camera: &Camera) -> f64 {
    let basis = camera.basis(image.width(), image.height(), tree.origin());
    let hits = octovox::trace::render::trace_image(
        &octovox::trace::render::Tracer::Svo(octovox::trace::instanced::Traced::Tree(tree)),
        &basis,
        octovox::trace::Footprint::EXACT,
    );
    let (mut sums, mut counts) = ([0.0f64; 2], [0usize; 2]);
    for (hit, pixel) in hits.iter().zip(image.pixels()) {
        let class = match hit.value {
            8 => 0,
            9 => 1,
            _ => continue,
        };
        let rgb = glam::Vec3::new(f32::from(pixel[0]), f32::from(pixel[1]), f32::from(pixel[2]));
        sums[class] += f64::from(rgb.dot(LUMINANCE));
        counts[class] += 1;
    }
    let (light, dark) = (sums[0] / counts[0] as f64, sums[1] / counts[1] as f64);
    (light - dark) / (light + dark)
}

#[test]
fn a_one_voxel_checker_keeps_its_contrast_and_the_filter_adds_no_bias() {
    let (mut scene, camera, settings, size) = checker_view();
    let mut renderer = renderer_for(&mut scene);
    let view = PathView { scene: &scene, camera: &camera, size, settings: &settings };
    // The converged image, and the one the filter is asked not to bias: 8
    // times fewer samples, raw and denoised.
    let converged = reference_image(&mut renderer, &view, 1024);
    sample(&mut renderer, &view, 128);
    let reference = renderer.read_image().unwrap();
    renderer.denoise_now().unwrap();
    let denoised_reference = renderer.read_image().unwrap();
    sample(&mut renderer, &view, 2);
    let raw = renderer.read_image().unwrap();
    renderer.denoise_now().unwrap();
    let denoised = renderer.read_image().unwrap();
    let (want, got) = (contrast(&converged, scene.drawn(), &camera), contrast(&denoised, scene.drawn(), &camera));
    println!("checker contrast: converged {want:.4}, denoised at 2 spp {got:.4}");
    assert!(want > 0.5, "the converged image shows no checker: {want}");
    assert!((got - want).abs() < 0.02 * want, "contrast {got} against the converged image's {want}");
    // What the filter takes from 128 samples is their noise, not light: the
    // denoised image is closer to the converged one than the raw is, and
    // no further by FLIP (which, in the dark squares, sees the 8-bit
    // rounding of an image 0.4 % off: 0.014).
    let rms = |image: &image::RgbaImage| rms_error(&converged, image);
    let (raw_rms, denoised_rms) = (rms(&reference), rms(&denoised_reference));
    let (raw_off, denoised_off) = (flip(&converged, &reference), flip(&converged, &denoised_reference));
    println!(
        "128 spp against 1024: raw RMS {raw_rms:.4} FLIP {raw_off:.4}, denoised RMS {denoised_rms:.4} FLIP {denoised_off:.4}; denoised against raw FLIP {:.4}",
        flip(&reference, &denoised_reference)
    );
    assert!(denoised_rms < raw_rms, "128 spp: RMS error {raw_rms} raw, {denoised_rms} denoised");
    assert!(denoised_off <= raw_off + 0.001, "128 spp: FLIP {raw_off} raw, {denoised_off} denoised");
    let (raw_error, denoised_error) = (flip(&converged, &raw), flip(&converged, &denoised));
    println!(
        "2 spp: raw FLIP {raw_error:.4} RMS {:.4}, denoised FLIP {denoised_error:.4} RMS {:.4}",
        rms(&raw),
        rms(&denoised)
    );
    assert!(denoised_error < 0.6 * raw_error, "denoising 2 spp: FLIP {raw_error} -> {denoised_error}");
}

#[test]
fn the_filter_moves_a_converging_image_by_little_more_than_its_noise() {
    // Every effect in view at 256 samples: the filter may take away the
    // noise the pixels still have (which moves them by about one standard
    // error) and move their light by little more (the no-bias check of
    // `bench quality`, which needs no cleaner reference). Its edge-stopping
    // weight lets neighbours within σ_l = 2 standard errors pull a pixel, so
    // a smooth gradient in the light is bent a little: 1.75 RMS here, 4 %
    // of channels beyond 4; SVGF's σ_l = 4 gives 2.55 and 9 %, σ_l = 1 1.15
    // and 0.8 %.
    let (mut scene, camera, settings, size) = every_effect();
    let mut renderer = renderer_for(&mut scene);
    let view = PathView { scene: &scene, camera: &camera, size, settings: &settings };
    sample(&mut renderer, &view, 256);
    let (sums, guides) = renderer.read_samples().unwrap();
    let change = change_in_standard_errors(&sums, &guides, &cpu_filter(&scene, &camera, size, &sums, &guides)).unwrap();
    println!("256 spp: the filter's change in standard errors {change:?}");
    assert!(change.rms < 2.0 && change.beyond_four < 0.06, "{change:?}");
}

#[test]
fn a_render_to_a_target_error_stops_near_it() {
    // Two scenes; a tighter target takes more samples, and the error then
    // measured against a 256-sample reference is within a factor of 2 of
    // the target (the reference's own noise included).
    let scenes = [
        ("materials", material_scene(), look(DVec3::new(18.0, 14.0, 26.0), DVec3::new(0.0, 3.0, 0.0))),
        ("checker", checker().0, look(DVec3::new(30.0, 20.0, 36.0), DVec3::new(12.0, 0.0, 12.0))),
    ];
    let settings = PathSettings { bounces: 2, ..PathSettings::default() };
    let size = (48, 32);
    for (name, mut scene, camera) in scenes {
        let mut renderer = renderer_for(&mut scene);
        let view = PathView { scene: &scene, camera: &camera, size, settings: &settings };
        let reference = reference_image(&mut renderer, &view, 256);
        let mut taken = Vec::new();
        for target in [0.04, 0.02] {
            let done = accumulate(&mut renderer, &view, 4096, Some(target), |_| ()).unwrap();
            let noise = renderer.noise_estimate().unwrap().unwrap();
            assert!(noise < target, "{name}: stopped at {noise} above {target}");
            let image = renderer.read_image().unwrap();
            let measured = rms_error(&reference, &image);
            let factor = measured / f64::from(target);
            println!(
                "{name}: target {target}: {} samples, estimate {noise:.4}, measured {measured:.4}",
                done.last.samples
            );
            assert!((0.25..2.0).contains(&factor), "{name}: measured {measured} at target {target}");
            taken.push(done.last.samples);
        }
        assert!(taken[1] > taken[0], "{name}: a tighter target took {taken:?} samples");
    }
}

/// Open Image Denoise (a build with `--features oidn`) on the GPU's
/// samples of the lamp-lit interior: nearer the converged image than the
/// raw samples are, and not blank.
#[cfg(feature = "oidn")]
#[test]
fn open_image_denoise_brings_few_samples_nearer_the_converged_image() {
    let mut scene = octovox::scene::demo::BuiltIn::Interior.scene();
    let camera = octovox::scene::showroom::interior_camera();
    let settings = PathSettings { bounces: 3, ..PathSettings::default() };
    let size = (80, 45);
    let mut renderer = renderer_for(&mut scene);
    let view = PathView { scene: &scene, camera: &camera, size, settings: &settings };
    let converged = reference_image(&mut renderer, &view, 256);
    sample(&mut renderer, &view, 4);
    let raw = renderer.read_image().unwrap();
    let (sums, guides) = renderer.read_samples().unwrap();
    let filtered = octovox::trace::oidn::denoised_image(&sums, &guides, size.0, size.1).unwrap();
    let rms = |image: &image::RgbaImage| rms_error(&converged, image);
    let (raw_rms, oidn_rms) = (rms(&raw), rms(&filtered));
    let (raw_flip, oidn_flip) = (flip(&converged, &raw), flip(&converged, &filtered));
    println!("4 spp against 256: raw RMS {raw_rms:.4} FLIP {raw_flip:.4}, OIDN RMS {oidn_rms:.4} FLIP {oidn_flip:.4}");
    assert!(grey_variance(&filtered) > 100.0, "a flat or blank image");
    assert!(oidn_rms < 0.7 * raw_rms, "4 spp: RMS error {raw_rms} raw, {oidn_rms} through OIDN");
    assert!(oidn_flip < 0.7 * raw_flip, "4 spp: FLIP {raw_flip} raw, {oidn_flip} through OIDN");
}

/// Open Image Denoise (a build with `--features oidn`) keeps the one-voxel
/// checker: it filters the light, and the colour is multiplied back after.
/// (Given the colour and the albedo, it lowered the contrast to 0.471
/// against the converged 0.570, and its RMS error was 0.042 against the
/// raw samples' 0.030.)
#[cfg(feature = "oidn")]
#[test]
fn open_image_denoise_keeps_a_one_voxel_checker() {
    let (mut scene, camera, settings, size) = checker_view();
    let mut renderer = renderer_for(&mut scene);
    let view = PathView { scene: &scene, camera: &camera, size, settings: &settings };
    let converged = reference_image(&mut renderer, &view, 1024);
    sample(&mut renderer, &view, 2);
    let raw = renderer.read_image().unwrap();
    let (sums, guides) = renderer.read_samples().unwrap();
    let filtered = octovox::trace::oidn::denoised_image(&sums, &guides, size.0, size.1).unwrap();
    let (want, got) = (contrast(&converged, scene.drawn(), &camera), contrast(&filtered, scene.drawn(), &camera));
    let (raw_rms, oidn_rms) = (rms_error(&converged, &raw), rms_error(&converged, &filtered));
    println!("checker contrast: converged {want:.4}, OIDN at 2 spp {got:.4}; RMS raw {raw_rms:.4}, OIDN {oidn_rms:.4}");
    assert!((got - want).abs() < 0.02 * want, "contrast {got} against the converged image's {want}");
    assert!(oidn_rms < 0.5 * raw_rms, "2 spp: RMS error {raw_rms} raw, {oidn_rms} through OIDN");
}

/// A block of 24³ voxels turned 45° about z, then 45° about y: a ridge
/// whose two faces both lie nearest the up axis.
fn ridge() -> Scene {
    use octovox::scene::objects::Model;
    let voxels: Vec<(IVec3, u8)> =
        (0..24).flat_map(|x| (0..24).flat_map(move |y| (0..24).map(move |z| (IVec3::new(x, y, z), 1)))).collect();
    let model = Model { size: [24, 24, 24], tree: Octree::from_voxels(&voxels).unwrap() };
    let scene = crate::path_trace::objects_scene(vec![model], &[(0, vec![("_t", "0 0 0")])], palette());
    let mut editor = octovox::editor::Editor::default();
    editor.set_scene(scene);
    let script = "object 0\nobject turn z 45\nobject turn y 45\n";
    for line in octovox::script::parse_script(std::path::Path::new("ridge.ovr"), script).unwrap().lines {
        editor.run(&line.command).unwrap();
    }
    editor.scene
}

/// How much of the noise of 4 samples the CPU filter leaves on the face
/// pixels of `scene` seen by `camera` (the RMS difference from 256 samples
/// of the reference seed, denoised over raw): guided by each face's own
/// normal, and by the nearest axis to it instead.
fn noise_left(scene: &Scene, camera: &Camera) -> (f64, f64) {
    let size = (48, 36);
    let settings = PathSettings { bounces: 1, ..PathSettings::default() };
    let noisy = render_cpu(scene, camera, size, &settings, 4);
    let reference = PathSettings { seed: REFERENCE_SEED, ..settings };
    let reference = render_cpu(scene, camera, size, &reference, 256).pixels;
    let faces: Vec<usize> = (0..noisy.guides.len()).filter(|&i| noisy.guides[i].is_filtered()).collect();
    assert!(faces.len() * 3 > noisy.guides.len(), "{} face pixels", faces.len());
    let rms = |image: &[glam::Vec3]| {
        let sum: f64 = faces.iter().map(|&i| f64::from((image[i] - reference[i]).length_squared())).sum();
        (sum / faces.len() as f64).sqrt()
    };
    let axis_guides: Vec<Guide> = noisy
        .guides
        .iter()
        .map(|g| match g.is_filtered() {
            true => Guide::filtered(glam::Vec3::from(g.point), g.normal(), false),
            false => *g,
        })
        .collect();
    let own = cpu_filter(scene, camera, size, &noisy.sums, &noisy.guides);
    let axis = cpu_filter(scene, camera, size, &noisy.sums, &axis_guides);
    (rms(&own) / rms(&noisy.pixels), rms(&axis) / rms(&noisy.pixels))
}

/// A freely turned face is denoised by its own normal (issue 49): the
/// guide carries it (packed in the guide's code) and the filter's plane
/// test reads it. Guided by the nearest axis instead (as before), the
/// plane test found a turned face's neighbours off the plane it looked
/// for, and the filter took less noise off a turned ridge (two faces, both
/// nearest the up axis). The GPU's guides carry the CPU's normals.
#[test]
fn a_turned_face_is_denoised_by_its_own_normal() {
    let mut scene = ridge();
    assert!(scene.instanced().is_some_and(|o| o.has_free_turns()));
    let (lo, hi) = scene.solid_bounds().unwrap();
    let centre = (lo + hi + IVec3::ONE).as_dvec3() / 2.0;
    for eye in [DVec3::new(1.0, 60.0, 2.0), DVec3::new(20.0, 40.0, 30.0), DVec3::new(-30.0, 40.0, 10.0)] {
        let (own, axis) = noise_left(&scene, &look(centre + eye, centre));
        println!("eye {eye}: noise left {own:.3} by the faces' own normals, {axis:.3} by the nearest axes");
        assert!(own < 0.9 * axis, "eye {eye}: noise left {own:.3} by the faces' own normals, {axis:.3} by the axes");
    }
    // The GPU's guides carry the same normals.
    let (camera, size) = (look(centre + DVec3::new(20.0, 40.0, 30.0), centre), (48, 36));
    let settings = PathSettings { bounces: 1, ..PathSettings::default() };
    let cpu = render_cpu(&scene, &camera, size, &settings, 1).guides;
    let mut renderer = renderer_for(&mut scene);
    sample(&mut renderer, &PathView { scene: &scene, camera: &camera, size, settings: &settings }, 1);
    let (_, gpu) = renderer.read_samples().unwrap();
    let both: Vec<usize> = (0..cpu.len()).filter(|&i| cpu[i].is_filtered() && gpu[i].is_filtered()).collect();
    assert!(both.len() > 500, "{} pixels filtered on both", both.len());
    let turned = both.iter().filter(|&&i| cpu[i].normal().abs().max_element() < 0.99).count();
    assert!(turned * 2 > both.len(), "{turned} of {} on a turned face", both.len());
    assert!(both.iter().all(|&i| cpu[i].normal().dot(gpu[i].normal()) > 0.9999), "the GPU's normals differ");
}
