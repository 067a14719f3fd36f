//! Two-level tracing: a scene of objects traced as instances, on the GPU
//! (`shaders/instances.wgsl`) and by the CPU reference
//! (`octovox::trace::instanced`), against each other and against the
//! objects composed into one octree, with every one of the 48 transforms,
//! objects overlapping, and the hard-case cameras.

use crate::common::{self, Agreement};
use dot_vox::{DotVoxData, Frame, Model, SceneNode, ShapeModel, Size, Voxel};
use glam::DVec3;
use octovox::camera::Camera;
use octovox::editor::Editor;
use octovox::gpu::Renderer;
use octovox::scene::{Instancing, Scene};
use octovox::settings::RenderSettings;
use octovox::trace::instanced::Traced;
use octovox::trace::render::{Tracer, trace_image};
use octovox::trace::{Footprint, Hit, Ray};

fn dict(pairs: &[(&str, String)]) -> dot_vox::Dict {
    pairs.iter().map(|(k, v)| ((*k).to_owned(), v.clone())).collect()
}

/// A lopsided model (a 6×4×3 block, one corner cut, colours by cell), so
/// that every turn and mirror shows.
fn lopsided(base: u8) -> Model {
    let mut voxels = Vec::new();
    for x in 0..6u8 {
        for y in 0..4u8 {
            for z in 0..3u8 {
                if x + y + z < 9 {
                    voxels.push(Voxel { x, y, z, i: base + (x + 2 * y + 3 * z) % 7 });
                }
            }
        }
    }
    Model { size: Size { x: 6, y: 4, z: 3 }, voxels }
}

/// 96 objects of two models, each of the 48 rotations twice, on a grid
/// 4 voxels apart: neighbours overlap, and the later one wins there.
fn overlapping_scene(dir: &std::path::Path) -> Scene {
    let rotations: Vec<u8> = (0..128u8)
        .filter(|b| {
            let (first, second) = (b & 3, (b >> 2) & 3);
            first < 3 && second < 3 && first != second
        })
        .collect();
    let count = 96u32;
    let mut scenes = vec![
        SceneNode::Transform { attributes: dict(&[]), frames: vec![Frame::new(dict(&[]))], child: 1, layer_id: 0 },
        SceneNode::Group { attributes: dict(&[]), children: (0..count).map(|k| 2 + 2 * k).collect() },
    ];
    for k in 0..count {
        let (x, y, z) = ((k % 8) as i32 * 4 - 16, (k / 32) as i32 * 4, ((k / 8) % 4) as i32 * 4);
        let frame = dict(&[("_t", format!("{x} {y} {z}")), ("_r", rotations[k as usize % 48].to_string())]);
        scenes.push(SceneNode::Transform {
            attributes: dict(&[("_name", format!("piece {k}"))]),
            frames: vec![Frame::new(frame)],
            child: 3 + 2 * k,
            layer_id: 0,
        });
        scenes.push(SceneNode::Shape {
            attributes: dict(&[]),
            models: vec![ShapeModel { model_id: k % 2, attributes: dict(&[]) }],
        });
    }
    let mut scene = written(&dir.join("pieces.vox"), vec![lopsided(10), lopsided(40)], scenes);
    assert_eq!(scene.objects().map(|o| o.list().len()), Some(count as usize));
    // So many overlapping pieces compose into less than twice the models'
    // bytes, which `Instancing::Auto` would draw composed.
    scene.set_instancing(Instancing::References);
    assert!(scene.instanced().is_some());
    scene
}

fn camera(eye: [f64; 3], target: [f64; 3], fov: f32) -> Camera {
    Camera { eye: DVec3::from_array(eye), target: DVec3::from_array(target), fov_y_deg: fov, ortho: None }
}

/// The cameras of the shared models' test and the hard cases: rays along
/// the axes from integer and half-integer origins, along edges and faces,
/// from inside a solid voxel, and from a boundary.
fn cameras(scene: &Scene) -> Vec<Camera> {
    let (lo, hi) = scene.solid_bounds().unwrap();
    let mut out = common::cameras_for(lo, hi);
    out.extend([
        camera([0.0, 4.0, -60.0], [0.0, 4.0, 0.0], 30.0),
        camera([0.5, 2.5, -60.0], [0.5, 2.5, 0.0], 30.0),
        camera([-40.0, -30.0, -40.0], [0.0, 4.0, 4.0], 40.0),
        camera([-50.0, 4.0, 3.0], [0.0, 4.0, 3.0], 30.0),
        camera([-15.5, 0.5, 0.5], [0.0, 6.0, 8.0], 90.0),
        camera([-16.0, 0.0, 0.0], [20.0, 8.0, 12.0], 60.0),
    ]);
    out
}

fn rays(scene: &Scene, camera: &Camera, size: (u32, u32)) -> Vec<Ray> {
    let basis = camera.basis(size.0, size.1, scene.origin());
    (0..size.0 * size.1)
        .map(|i| {
            let (origin, dir) = basis.ray(i % size.0, i / size.0);
            Ray::new(origin, dir)
        })
        .collect()
}

fn gpu_hits(renderer: &mut Renderer, scene: &Scene, camera: &Camera, size: (u32, u32)) -> Vec<Hit> {
    let settings = RenderSettings::default();
    renderer.render(scene, camera, size, &settings, None).unwrap();
    renderer.read_hits().unwrap()
}

fn cpu_hits(scene: &Scene, camera: &Camera, size: (u32, u32), composed: bool) -> Vec<Hit> {
    let basis = camera.basis(size.0, size.1, scene.origin());
    let traced = if composed { Traced::Tree(scene.drawn()) } else { Traced::of(scene) };
    trace_image(&Tracer::Svo(traced), &basis, Footprint::EXACT)
}

/// GPU and CPU trace the instances alike, and both draw what the objects
/// composed draw, but for rays that graze an edge.
fn check(renderer: &mut Renderer, scene: &Scene, what: &str) {
    let size = (96, 64);
    let (mut twins, mut composed) = (Agreement::default(), Agreement::default());
    let mut hits = 0;
    for camera in cameras(scene) {
        let gpu = gpu_hits(renderer, scene, &camera, size);
        assert!(gpu.iter().all(|h| !h.gave_up()), "{what}: a GPU ray gave up");
        let cpu = cpu_hits(scene, &camera, size, false);
        twins.add(&gpu, &cpu);
        composed.add_grazing(&cpu, &cpu_hits(scene, &camera, size, true), &rays(scene, &camera, size));
        hits += cpu.iter().filter(|h| h.is_hit()).count();
    }
    twins.assert_good(&format!("{what}: GPU instances vs CPU instances"));
    // Where a ray crosses two planes at one t, each frame counts them in its
    // own x, y, z order, and a turned object's axes are not the scene's:
    // such rays (the hard cameras aim along edges) may end in the voxel
    // beside, never elsewhere.
    eprintln!("{what}: CPU instances vs the composed tree: {composed:?}");
    assert!(composed.other == 0 && composed.exact_fraction() >= 0.999, "{what}: {composed:?}");
    assert!(hits > 20_000, "{what}: the cameras see too little ({hits} hits)");
}

#[test]
fn instances_with_every_transform_and_overlaps_match_on_gpu_and_cpu() {
    let dir = tempfile::tempdir().unwrap();
    let scene = overlapping_scene(dir.path());
    let mut editor = Editor::default();
    editor.set_scene(scene);
    let mut renderer = Renderer::headless().expect("a GPU adapter (lavapipe on CI)");
    renderer.hit_records = true;
    renderer.sync(&mut editor.scene);
    check(&mut renderer, &editor.scene, "as loaded");
    // Moved, turned, hidden and edited through the objects: the uploads
    // keep the GPU copy in step.
    for line in ["object 5", "object move 3 -2 1", "object rotate y", "object 40", "object hide", "object 41"] {
        run(&mut editor, line);
    }
    run(&mut editor, "place -9 1 2");
    renderer.sync(&mut editor.scene);
    check(&mut renderer, &editor.scene, "after edits");
}

/// Moving, turning or hiding one of many references writes its instance
/// record and the boxes above it, not the models' pools.
#[test]
fn an_object_move_writes_only_instance_words() {
    let dir = tempfile::tempdir().unwrap();
    let mut editor = Editor::default();
    editor.set_scene(overlapping_scene(dir.path()));
    let first = editor.scene.take_uploads().byte_count();
    assert!(first > 0);
    let models: u64 = editor.scene.objects().unwrap().pool_bytes();
    for (line, limit) in [("object 50", 0), ("object move 1 0 0", 256), ("object rotate z", 256), ("object hide", 256)]
    {
        run(&mut editor, line);
        let written = editor.scene.take_uploads().byte_count();
        assert!(written <= limit, "`{line}` wrote {written} bytes (at most {limit})");
        if limit > 0 {
            assert!(written > 0, "`{line}` wrote nothing");
        }
    }
    // An edit writes the model's changed slots and the root word of each
    // of its 48 placements, not the whole copy.
    run(&mut editor, "object 51");
    let objects = editor.scene.objects().unwrap();
    let (lo, hi) = objects.world_box(51).unwrap();
    let cell = (lo.x..=hi.x)
        .flat_map(|x| (lo.y..=hi.y).flat_map(move |y| (lo.z..=hi.z).map(move |z| glam::IVec3::new(x, y, z))))
        .find(|&c| objects.owner_at(c) == Some(51))
        .unwrap();
    run(&mut editor, &format!("remove {} {} {}", cell.x, cell.y, cell.z));
    let written = editor.scene.take_uploads().byte_count();
    assert!(written > 0 && written <= models + 48 * 4, "an edit wrote {written} bytes ({models} in the pools)");
}

fn run(editor: &mut Editor, line: &str) {
    let script = octovox::script::parse_script(std::path::Path::new("t.ovr"), line).unwrap();
    for step in &script.lines {
        editor.run(&step.command).unwrap_or_else(|e| panic!("{line}: {e}"));
    }
}

/// Issue 47, item 9: test_groups.vox (19 objects, 1,754 voxels, some
/// models placed twice) was drawn as instances, and a path-traced sample
/// took 2.2–3.5× the time of its voxels merged into one model on lavapipe.
/// Its objects composed take about as many bytes as its models, so it is
/// drawn composed; a forest of references far apart, whose composed tree
/// would be many times its models, is still drawn as instances. Both draw
/// the same voxels either way.
#[test]
fn small_scenes_of_references_are_drawn_composed_and_forests_as_instances() {
    let mut groups = octovox::io::load_scene(&common::assets().join("vox/format/test_groups.vox"), 0).unwrap();
    assert!(groups.objects().unwrap().has_references());
    assert!(groups.instanced().is_none(), "test_groups.vox is drawn composed");
    groups.set_instancing(Instancing::References);
    assert!(groups.instanced().is_some(), "and as instances when asked");

    let dir = tempfile::tempdir().unwrap();
    let forest = spread_scene(dir.path());
    assert!(forest.instanced().is_some(), "48 references far apart are drawn as instances");
}

/// 48 placements of one model, 64 voxels apart: nothing shared when composed.
fn spread_scene(dir: &std::path::Path) -> Scene {
    let count = 48u32;
    let mut scenes = vec![
        SceneNode::Transform { attributes: dict(&[]), frames: vec![Frame::new(dict(&[]))], child: 1, layer_id: 0 },
        SceneNode::Group { attributes: dict(&[]), children: (0..count).map(|k| 2 + 2 * k).collect() },
    ];
    for k in 0..count {
        let frame = dict(&[("_t", format!("{} {} 0", (k % 8) * 64, (k / 8) * 64))]);
        scenes.push(SceneNode::Transform {
            attributes: dict(&[]),
            frames: vec![Frame::new(frame)],
            child: 3 + 2 * k,
            layer_id: 0,
        });
        scenes.push(SceneNode::Shape {
            attributes: dict(&[]),
            models: vec![ShapeModel { model_id: 0, attributes: dict(&[]) }],
        });
    }
    written(&dir.join("spread.vox"), vec![lopsided(10)], scenes)
}

/// `models` placed by `scenes` (one layer), written by dot_vox to `path`
/// and loaded.
fn written(path: &std::path::Path, models: Vec<Model>, scenes: Vec<SceneNode>) -> Scene {
    let data = DotVoxData {
        version: 200,
        index_map: Vec::new(),
        models,
        palette: dot_vox::DEFAULT_PALETTE.to_vec(),
        materials: Vec::new(),
        scenes,
        layers: vec![dot_vox::Layer { attributes: dict(&[("_name", "0".into())]) }],
    };
    let mut bytes = Vec::new();
    data.write_vox(&mut bytes).unwrap();
    std::fs::write(path, bytes).unwrap();
    octovox::io::load_scene(path, 0).unwrap()
}
