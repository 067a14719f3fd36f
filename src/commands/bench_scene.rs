//! `octovox bench scene`: a forest of 2,000 rotated references of one tree
//! against the same voxels as one merged model, in one run: load time, frame
//! time, pool bytes, and the bytes an object move writes to the GPU pool;
//! and path tracing a small scene of objects against it merged.

use std::time::Instant;

use anyhow::Context;
use glam::IVec3;
use serde::Serialize;

use octovox::camera::Camera;
use octovox::editor::Editor;
use octovox::gpu::{PathView, Renderer};
use octovox::io::vox::{encode_objects, encode_vox, load_vox_scene};
use octovox::scene::graph::{Attributes, Node, NodeKind, SceneGraph};
use octovox::scene::objects::{Model, Objects};
use octovox::scene::transform::Rotation;
use octovox::scene::{Instancing, Octree, Palette, Scene};
use octovox::script::{Line, ObjectLine, ObjectRef};
use octovox::settings::{PathSettings, RenderSettings};

use super::bench::{header, median};

#[derive(Serialize)]
struct SceneRow {
    objects: usize,
    voxels: u64,
    adapter: String,
    width: u32,
    height: u32,
    file_bytes_forest: usize,
    file_bytes_merged: usize,
    load_ms_forest: f64,
    load_ms_merged: f64,
    frame_ms_forest: f64,
    frame_ms_merged: f64,
    /// The models' node pools (the tree once), on the CPU.
    model_pool_bytes: u64,
    /// What the GPU traces: the models' pools and the instance words.
    drawn_pool_bytes: u64,
    merged_pool_bytes: u64,
    move_bytes_written: u64,
    rotate_bytes_written: u64,
    hide_bytes_written: u64,
    path: PathRow,
}

/// Path tracing a small scene of objects (issue 47, item 9): the file as
/// the scene draws it against its voxels merged into one model.
#[derive(Serialize)]
struct PathRow {
    file: &'static str,
    objects: usize,
    voxels: u64,
    /// How the scene is drawn: "instances" or "composed" (`Scene::instanced`).
    drawn_as: &'static str,
    width: u32,
    height: u32,
    samples: usize,
    ms_per_sample_drawn: f64,
    /// The same scene drawn as instances (`Instancing::References`: how
    /// it was drawn before `Instancing::Auto`).
    ms_per_sample_instances: f64,
    ms_per_sample_merged: f64,
}

/// The small scene of objects the path row traces.
const PATH_SCENE: &str = "vox/format/test_groups.vox";

/// Median milliseconds per path-traced sample of the scene in `PATH_SCENE`
/// as it is drawn, as instances, and as its voxels in one model, the three
/// alternating after one warm-up sample each (which compiles the kernel).
fn path_row(quick: bool) -> anyhow::Result<PathRow> {
    let (width, height, samples) = if quick { (320, 180, 2) } else { (1280, 720, 6) };
    let mut scene = octovox::io::load_scene(&super::bench::assets().join(PATH_SCENE), 0)?;
    let mut instances = scene.clone();
    instances.set_instancing(Instancing::References);
    let mut merged = Scene::new(scene.palette.clone(), scene.drawn().clone());
    let (lo, hi) = merged.solid_bounds().context("an empty scene")?;
    let camera = Camera::framing(lo, hi, 50.0);
    let settings = PathSettings::default();
    let renderer = || Renderer::headless().context("bench scene needs a GPU (lavapipe works)");
    let mut renderers = [renderer()?, renderer()?, renderer()?];
    let mut times = [Vec::new(), Vec::new(), Vec::new()];
    for round in 0..=samples {
        let scenes = [&mut scene, &mut instances, &mut merged];
        for ((scene, renderer), times) in scenes.into_iter().zip(&mut renderers).zip(&mut times) {
            renderer.sync(scene);
            let view = PathView { scene, camera: &camera, size: (width, height), settings: &settings };
            let frame = renderer.render_path(&view, round == 0)?;
            if round > 0 {
                times.push(frame.ms);
            }
        }
    }
    let [drawn_ms, instances_ms, merged_ms] = times;
    Ok(PathRow {
        file: PATH_SCENE,
        objects: scene.objects().map_or(1, |o| o.list().len()),
        voxels: merged.solid_voxels(),
        drawn_as: if scene.instanced().is_some() { "instances" } else { "composed" },
        width,
        height,
        samples,
        ms_per_sample_drawn: median(drawn_ms),
        ms_per_sample_instances: median(instances_ms),
        ms_per_sample_merged: median(merged_ms),
    })
}

/// A tree in MagicaVoxel's axes (z up): a trunk and a round crown.
fn tree_model() -> Model {
    let mut voxels = Vec::new();
    for z in 0..14 {
        for (x, y) in [(6, 6), (7, 6), (6, 7), (7, 7)] {
            voxels.push((IVec3::new(x, y, z), 3));
        }
    }
    let centre = IVec3::new(7, 7, 19);
    for z in 12..27 {
        for y in 0..15 {
            for x in 0..15 {
                let p = IVec3::new(x, y, z);
                if (p - centre).length_squared() <= 49 {
                    voxels.push((p, 5 + ((x + y + z) % 3) as u8));
                }
            }
        }
    }
    let tree = Octree::from_voxels(&voxels).expect("a small tree builds");
    Model { size: [15, 15, 27], tree }
}

/// How the trees of [`forest`] stand: by quarter turns only, or turned by
/// free angles too (about the up axis, and leaning 12° where `lean`); still,
/// or keyed to move over [`MOVING_FRAMES`].
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) struct Stand {
    pub turned: bool,
    pub lean: bool,
    pub moving: bool,
}

impl Stand {
    pub const ALIGNED: Stand = Stand { turned: false, lean: false, moving: false };
}

/// A tree's free turn at a key (`_ov_turn`): about MagicaVoxel's up axis
/// by its own angle (`spin` more at the loop's middle), and leaning 12°
/// where `lean`.
fn free_turn(k: u32, spin: f64, lean: bool) -> String {
    let about_up = (f64::from(k * 37 % 90) + 5.0 + spin).to_radians();
    let tilt = if lean { 12f64.to_radians() } else { 0.0 };
    let q = glam::DQuat::from_rotation_z(about_up) * glam::DQuat::from_rotation_x(tilt);
    format!("{} {} {} {}", q.x, q.y, q.z, q.w)
}

/// 2,000 placements of one model on a 50 × 40 grid, each turned by one of
/// the eight rotations that keep z up, and where `stand.turned` by a free
/// turn too; where `stand.moving`, each also keyed to rise and come back
/// over [`MOVING_FRAMES`] frames (turning 40° and back, where turned),
/// looping (`bench anim`).
pub(super) fn forest(count: u32, stand: Stand) -> anyhow::Result<Scene> {
    let moving = stand.moving;
    let upright: Vec<u8> =
        (0..=127u8).filter(|b| Rotation::from_byte(*b).is_some_and(|r| r.apply([0, 0, 1]) == [0, 0, 1])).collect();
    let attributes = Attributes::new;
    let mut nodes = vec![
        Node {
            id: 0,
            attributes: attributes(),
            kind: NodeKind::Transform { child: 1, reserved: u32::MAX, layer: u32::MAX, frames: vec![] },
        },
        Node {
            id: 1,
            attributes: attributes(),
            kind: NodeKind::Group { children: (0..count).map(|k| 2 + 2 * k).collect() },
        },
    ];
    for k in 0..count {
        let (x, y) = ((k % 50) as i32 * 24, (k / 50) as i32 * 24);
        let key = |f: u32, z: u32, spin: f64| -> Attributes {
            let mut key: Attributes = [
                ("_f".to_owned(), f.to_string()),
                ("_t".to_owned(), format!("{x} {y} {z}")),
                ("_r".to_owned(), upright[k as usize % upright.len()].to_string()),
            ]
            .into();
            if stand.turned {
                key.insert(octovox::scene::graph::TURN_KEY.to_owned(), free_turn(k, spin, stand.lean));
            }
            key
        };
        // Each tree rises its own height (1 to 8 voxels) and comes back.
        let frames = if moving {
            vec![key(0, 13, 0.0), key(MOVING_FRAMES / 2, 14 + k % 8, 40.0), key(MOVING_FRAMES, 13, 0.0)]
        } else {
            vec![key(0, 13, 0.0)]
        };
        let mut named: Attributes = [("_name".to_owned(), format!("tree {k}"))].into();
        if moving {
            named.insert("_loop".to_owned(), "1".to_owned());
        }
        nodes.push(Node {
            id: 2 + 2 * k,
            attributes: named,
            kind: NodeKind::Transform { child: 3 + 2 * k, reserved: u32::MAX, layer: 0, frames },
        });
        nodes.push(Node {
            id: 3 + 2 * k,
            attributes: attributes(),
            kind: NodeKind::Shape { models: vec![(0, attributes())] },
        });
    }
    let layer = octovox::scene::graph::Layer { id: 0, attributes: attributes(), reserved: u32::MAX };
    let graph = SceneGraph { nodes, layers: vec![layer], ..SceneGraph::default() };
    let objects = Objects::new(Some(graph), vec![tree_model()], Vec::new(), 0, usize::MAX)?;
    Ok(Scene::compose(Palette::default(), objects)?)
}

/// The frames a moving forest's loop takes.
pub(super) const MOVING_FRAMES: u32 = 48;

/// Median milliseconds of `runs` calls of `f`.
fn timed(runs: usize, mut f: impl FnMut() -> anyhow::Result<()>) -> anyhow::Result<f64> {
    let mut times = Vec::with_capacity(runs);
    for _ in 0..runs {
        let start = Instant::now();
        f()?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    Ok(median(times))
}

pub fn bench_scene(quick: bool) -> anyhow::Result<(String, String)> {
    let count = if quick { 200 } else { 2000 };
    let (width, height, frames, loads) = if quick { (320, 180, 3, 1) } else { (1280, 720, 9, 3) };
    let scene = forest(count, Stand::ALIGNED)?;
    let objects = scene.objects().context("a scene of objects")?;
    let forest_bytes = encode_objects(&scene.palette, objects)?;
    let merged_bytes = encode_vox(&scene.palette, &scene.voxels())?;
    // Loads alternate, so machine noise hits both alike.
    let (mut forest_loads, mut merged_loads) = (Vec::new(), Vec::new());
    for _ in 0..loads {
        forest_loads.push(timed(1, || Ok(load_vox_scene(&forest_bytes, 0).map(|_| ())?))?);
        merged_loads.push(timed(1, || Ok(load_vox_scene(&merged_bytes, 0).map(|_| ())?))?);
    }
    let mut forest_scene = load_vox_scene(&forest_bytes, 0)?.0;
    let mut merged = load_vox_scene(&merged_bytes, 0)?.0;
    anyhow::ensure!(forest_scene.voxels() == merged.voxels(), "the forest and the merged model differ");

    // A renderer each: a renderer's buffers hold one scene, and each scene
    // sends only its changes since its last upload.
    let renderer = || Renderer::headless().context("bench scene needs a GPU (lavapipe works)");
    let (mut forest_renderer, mut merged_renderer) = (renderer()?, renderer()?);
    let (lo, hi) = merged.solid_bounds().context("an empty forest")?;
    let camera = Camera::framing(lo, hi, 50.0);
    let settings = RenderSettings { shadows: false, ..RenderSettings::default() };
    let (mut forest_frames, mut merged_frames) = (Vec::new(), Vec::new());
    for round in 0..=frames {
        let pairs = [
            (&mut forest_scene, &mut forest_renderer, &mut forest_frames),
            (&mut merged, &mut merged_renderer, &mut merged_frames),
        ];
        for (scene, renderer, times) in pairs {
            renderer.sync(scene);
            let ms = renderer.render(scene, &camera, (width, height), &settings, None)?;
            if round > 0 {
                times.push(ms);
            }
        }
    }

    let model_pool_bytes = forest_scene.objects().map_or(0, |o| o.pool_bytes());
    let drawn_pool_bytes = forest_scene.drawn_pool_bytes();
    let mut editor = Editor::default();
    editor.set_scene(forest_scene);
    let _ = editor.scene.take_uploads();
    editor.run(&Line::Object(ObjectLine::Pick(ObjectRef::Index(5))))?;
    let mut written = |line: ObjectLine| -> anyhow::Result<u64> {
        editor.run(&Line::Object(line))?;
        Ok(editor.scene.take_uploads().byte_count())
    };
    let move_bytes_written = written(ObjectLine::Move(IVec3::new(3, 0, 0)))?;
    let rotate_bytes_written = written(ObjectLine::Rotate(2))?;
    let hide_bytes_written = written(ObjectLine::Hide(true))?;

    let row = SceneRow {
        objects: count as usize,
        voxels: merged.solid_voxels(),
        adapter: forest_renderer.gpu.adapter_name.clone(),
        width,
        height,
        file_bytes_forest: forest_bytes.len(),
        file_bytes_merged: merged_bytes.len(),
        load_ms_forest: median(forest_loads),
        load_ms_merged: median(merged_loads),
        frame_ms_forest: median(forest_frames),
        frame_ms_merged: median(merged_frames),
        model_pool_bytes,
        drawn_pool_bytes,
        merged_pool_bytes: merged.drawn_pool_bytes(),
        move_bytes_written,
        rotate_bytes_written,
        hide_bytes_written,
        path: path_row(quick)?,
    };
    Ok((report(&row), serde_json::to_string_pretty(&[row])?))
}

fn report(r: &SceneRow) -> String {
    let mut md = header(&format!("A forest of {} references against one merged model", r.objects));
    md += &format!(
        "Adapter: **{}**, {}×{}, SVO preview without shadows, median of the frames after one warm-up, the two scenes \
         alternating. One tree model ({} voxels as placed: {} in all) placed {} times with the eight upright rotations, \
         against the same voxels saved as one scene of 256³ blocks. The forest (whose model is placed 2000 times) is \
         traced in two levels: a tree of boxes over the instances, then each instance's model; the merged blocks (each \
         model placed once) are drawn composed into one octree (`Scene::instanced`). *Drawn*: what the GPU holds (the \
         forest's model pool once and its instance words: tree nodes and records); *bytes written*: what the upload \
         after the line sends. The targets are the issue's.\n\n",
        r.adapter,
        r.width,
        r.height,
        r.voxels / r.objects as u64,
        r.voxels,
        r.objects
    );
    md += "| measure | forest | merged | forest / merged | target |\n|---|---|---|---|---|\n";
    let ratio = |a: f64, b: f64| if b > 0.0 { format!("{:.3}", a / b) } else { "-".to_owned() };
    md += &format!(
        "| frame ms | {:.2} | {:.2} | {} | ≤ 1.2 |\n",
        r.frame_ms_forest,
        r.frame_ms_merged,
        ratio(r.frame_ms_forest, r.frame_ms_merged)
    );
    md += &format!(
        "| pool bytes (models, CPU) | {} | {} | {} | ≤ 0.02 |\n",
        r.model_pool_bytes,
        r.merged_pool_bytes,
        ratio(r.model_pool_bytes as f64, r.merged_pool_bytes as f64)
    );
    md += &format!(
        "| pool bytes (drawn, GPU) | {} | {} | {} | ≤ 0.02 |\n",
        r.drawn_pool_bytes,
        r.merged_pool_bytes,
        ratio(r.drawn_pool_bytes as f64, r.merged_pool_bytes as f64)
    );
    md += &format!(
        "| file bytes | {} | {} | {} | |\n",
        r.file_bytes_forest,
        r.file_bytes_merged,
        ratio(r.file_bytes_forest as f64, r.file_bytes_merged as f64)
    );
    md += &format!(
        "| load ms | {:.1} | {:.1} | {} | |\n",
        r.load_ms_forest,
        r.load_ms_merged,
        ratio(r.load_ms_forest, r.load_ms_merged)
    );
    md += &format!("| bytes written by one `object move` | {} | | | ≤ 256 |\n", r.move_bytes_written);
    md += &format!("| bytes written by one `object rotate z` | {} | | | ≤ 256 |\n", r.rotate_bytes_written);
    md += &format!("| bytes written by one `object hide` | {} | | | ≤ 256 |\n", r.hide_bytes_written);
    md + &path_report(&r.path)
}

fn path_report(p: &PathRow) -> String {
    let mut md = format!(
        "\n## Path tracing a small scene of objects\n\n`{}`: {} objects, {} voxels. *As drawn*: as `Scene::instanced` \
         chooses (**{}**); *instances*: drawn as instances, as every scene with a reference was before that choice; \
         *merged*: its voxels as one model. {}×{}, the path tracer's defaults, median of {} samples after one warm-up \
         each, the three alternating.\n\n",
        p.file, p.objects, p.voxels, p.drawn_as, p.width, p.height, p.samples
    );
    md += "| ms per sample | as drawn | instances | merged | as drawn / merged | instances / merged | target |\n";
    md += "|---|---|---|---|---|---|---|\n";
    let merged = p.ms_per_sample_merged.max(1e-9);
    md += &format!(
        "| {}×{} | {:.1} | {:.1} | {:.1} | {:.3} | {:.3} | ≤ 1.5 |\n",
        p.width,
        p.height,
        p.ms_per_sample_drawn,
        p.ms_per_sample_instances,
        p.ms_per_sample_merged,
        p.ms_per_sample_drawn / merged,
        p.ms_per_sample_instances / merged
    );
    md
}
