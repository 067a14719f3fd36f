//! `octovox bench build|edit|render`, and what every bench shares: the
//! models, the report header, the median.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use glam::IVec3;
use serde::Serialize;

use octovox::camera::Camera;
use octovox::gpu::Renderer;
use octovox::io::mesh::{DenseVoxels, MESH_COLOR, UpAxis, load_obj_triangles, voxelize_dense};
use octovox::scene::{Octree, Op, Palette, Scene, Shape, sculpture};
use octovox::settings::{RenderSettings, TraceMode, View};
use octovox::trace::grid::DenseGrid;

/// A bench scene and the report's numbers for it.
struct Model {
    name: &'static str,
    /// The report's (SVO MB, grid ms, SVO ms, SVO build s).
    report: (f64, f64, f64, f64),
}

/// The report's 10 M-voxel scene is the Pietà (not public); its stand-in is
/// the solid voxelization of `meshes/nefertiti.obj`, 512 voxels tall.
/// `sculpture10M` is a smooth procedural shape with the Pietà's extent.
const MODELS: [Model; 4] = [
    Model { name: "torus64", report: (0.07, 1.795, 1.214, 0.067) },
    Model { name: "teapot256", report: (1.26, 10.774, 4.925, 4.121) },
    Model { name: "nefertiti512", report: (12.12, 150.497, 3.702, 34.636) },
    Model { name: "sculpture10M", report: (12.12, 150.497, 3.702, 34.636) },
];

pub(super) fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets")
}

/// Source data of a model: a voxel list (.vox) or a dense array.
enum Source {
    List(Box<octovox::scene::VoxelModel>),
    Dense(DenseVoxels),
}

fn source(model: &Model) -> anyhow::Result<Source> {
    Ok(match model.name {
        "sculpture10M" => Source::Dense(DenseVoxels { dims: sculpture::DIMS, data: sculpture::sculpture_dense() }),
        "nefertiti512" => {
            let path = assets().join("meshes/nefertiti.obj");
            // The dense block, so that the build row times `from_dense` as before.
            Source::Dense(voxelize_dense(&load_obj_triangles(&path, UpAxis::Z)?, 512, MESH_COLOR))
        }
        name => {
            let path = assets().join(format!("vox/seed/{name}.vox"));
            let model =
                octovox::io::vox::load_vox_file(&path, 0).with_context(|| format!("cannot load {}", path.display()))?;
            Source::List(Box::new(model))
        }
    })
}

/// The procedural 10 M-voxel sculpture as a scene (default palette).
pub(super) fn sculpture_scene() -> anyhow::Result<Scene> {
    let dense = sculpture::sculpture_dense();
    Ok(Scene::new(Palette::default(), Octree::from_dense(sculpture::DIMS, IVec3::ZERO, &dense)?))
}

fn build(source: &Source) -> anyhow::Result<Octree> {
    Ok(match source {
        Source::List(model) => Octree::from_voxels(&model.voxels)?,
        Source::Dense(dense) => Octree::from_dense(dense.dims, IVec3::ZERO, &dense.data)?,
    })
}

/// Mean traversal steps per pixel of a frame's hit records.
pub(super) fn mean_steps(hits: &[octovox::trace::Hit]) -> f64 {
    hits.iter().map(|h| f64::from(h.iterations)).sum::<f64>() / hits.len().max(1) as f64
}

pub(super) fn median(mut samples: Vec<f64>) -> f64 {
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

pub(super) fn header(title: &str) -> String {
    format!(
        "# {title}\n\nMeasured by `octovox bench` on {} ({} cores), {}.\n\n",
        std::env::consts::ARCH,
        std::thread::available_parallelism().map_or(1, |n| n.get()),
        if cfg!(debug_assertions) { "DEBUG build: numbers not meaningful" } else { "release build" }
    )
}

#[derive(Serialize)]
struct BuildRow {
    model: &'static str,
    solid_voxels: u64,
    nodes: usize,
    bricks: usize,
    pool_bytes: u64,
    bytes_per_voxel: f64,
    report_svo_bytes: f64,
    dense_grid_bytes: u64,
    build_ms: f64,
    report_build_ms: f64,
}

pub(super) fn bench_build(quick: bool) -> anyhow::Result<(String, String)> {
    let mut rows = Vec::new();
    for model in &MODELS {
        let source = source(model)?;
        let runs = if quick { 1 } else { 7 };
        let mut times = Vec::new();
        let mut tree = Octree::default();
        for _ in 0..runs {
            let start = Instant::now();
            tree = build(&source)?;
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
        let grid = DenseGrid::from_octree(&tree)?;
        let solid = tree.solid_voxels();
        rows.push(BuildRow {
            model: model.name,
            solid_voxels: solid,
            nodes: tree.node_count(),
            bricks: tree.brick_count(),
            pool_bytes: tree.pool().live_bytes(),
            bytes_per_voxel: tree.pool().live_bytes() as f64 / solid.max(1) as f64,
            report_svo_bytes: model.report.0 * 1e6,
            dense_grid_bytes: grid.bytes(),
            build_ms: median(times),
            report_build_ms: model.report.3 * 1e3,
        });
    }
    let mut md = header("Octree build and memory");
    md += "| model | solid voxels | nodes | bricks | pool bytes | bytes/voxel | report SVO bytes | pool / report | dense grid bytes (cube, u8) | build ms (median) | report build ms | speed-up |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for r in &rows {
        md += &format!(
            "| {} | {} | {} | {} | {} | {:.3} | {:.0} | {:.2} | {} | {:.1} | {:.0} | {:.0}× |\n",
            r.model,
            r.solid_voxels,
            r.nodes,
            r.bricks,
            r.pool_bytes,
            r.bytes_per_voxel,
            r.report_svo_bytes,
            r.pool_bytes as f64 / r.report_svo_bytes,
            r.dense_grid_bytes,
            r.build_ms,
            r.report_build_ms,
            r.report_build_ms / r.build_ms
        );
    }
    md += "\nBuild: .vox models from their voxel list (parallel Morton sort, then bottom-up); the voxelized Nefertiti and the procedural sculpture from their dense arrays (64³ cubes in parallel, then assembled bottom-up; `import` builds the same cubes from column runs, with no dense array). Times exclude file parsing, voxelization and the sculpture's generation. The report's times are from its own machine (see DESIGN.md), so the speed-up column compares machines too.\n";
    Ok((md, serde_json::to_string_pretty(&rows)?))
}

#[derive(Serialize)]
struct EditRow {
    edit: &'static str,
    median_us: f64,
    bytes_written: u64,
    ranges: usize,
    cells_recorded: usize,
}

pub(super) fn bench_edit(quick: bool) -> anyhow::Result<(String, String)> {
    let model = octovox::io::vox::load_vox_file(&assets().join("vox/seed/teapot256.vox"), 0)?;
    let mut tree = Octree::from_voxels(&model.voxels)?;
    tree.pool_mut().flush();
    // The first solid voxel along +x through the centre: on the teapot's
    // wall, so every edit changes real geometry.
    let at = (-200..200)
        .map(|x| IVec3::new(x, 0, 0))
        .find(|p| tree.get(*p) != 0)
        .context("teapot has no wall at y = z = 0")?;
    let cases: [(&str, Shape); 3] = [
        ("one voxel", Shape::Voxel(at)),
        ("sphere r = 8", Shape::Sphere { center: at, radius: 8 }),
        ("sphere r = 32", Shape::Sphere { center: at, radius: 32 }),
    ];
    let runs = if quick { 5 } else { 101 };
    let mut rows = Vec::new();
    for (name, shape) in cases {
        let mut times = Vec::new();
        let (mut bytes, mut ranges, mut cells) = (0, 0, 0);
        for i in 0..runs {
            // Alternate remove and place so each run changes the same cells.
            let op = if i % 2 == 0 { Op::Remove } else { Op::Place(2) };
            let start = Instant::now();
            let patch = tree.apply_brush(&shape, op)?;
            let upload = tree.pool_mut().flush();
            times.push(start.elapsed().as_secs_f64() * 1e6);
            if i == 0 {
                bytes = upload.byte_count();
                ranges = upload.nodes.range_count() + upload.bricks.range_count();
                cells = patch.cell_count();
            }
        }
        rows.push(EditRow {
            edit: name,
            median_us: median(times),
            bytes_written: bytes,
            ranges,
            cells_recorded: cells,
        });
    }
    let mut md = header(&format!("Edit latency on teapot256.vox, centred on its wall at {at}"));
    md += &format!(
        "Pool: {} nodes, {} bricks, {} bytes. Each edit is applied and the pool flushed (dirty slots → coalesced byte ranges); the GPU write itself is `queue.write_buffer` of those ranges.\n\n",
        tree.node_count(),
        tree.brick_count(),
        tree.pool().live_bytes()
    );
    md +=
        "| edit | median µs (apply + flush) | bytes written | ranges | cells in undo patch |\n|---|---|---|---|---|\n";
    for r in &rows {
        md += &format!(
            "| {} | {:.1} | {} | {} | {} |\n",
            r.edit, r.median_us, r.bytes_written, r.ranges, r.cells_recorded
        );
    }
    let objects = edits_in_objects(at, quick)?;
    md += &objects_table(&objects);
    // One list: the one-model rows, then the scene-of-objects rows (their
    // own keys: objects_us, one_model_us, …).
    let mut json: Vec<serde_json::Value> = rows.iter().map(serde_json::to_value).collect::<Result<_, _>>()?;
    json.extend(objects.iter().map(serde_json::to_value).collect::<Result<Vec<_>, _>>()?);
    Ok((md, serde_json::to_string_pretty(&json)?))
}

#[derive(Serialize)]
struct ObjectsEditRow {
    edit: &'static str,
    /// Median µs of apply + upload, in the teapot's scene of six objects
    /// (into the model of the object there) and in its voxels as one model.
    objects_us: f64,
    one_model_us: f64,
    objects_bytes: u64,
    one_model_bytes: u64,
}

/// The same brushes in teapot256.vox as the scene of six objects it is
/// (each edit into the model of the object at `at`, every placement of it
/// composed again) and as its voxels merged into one model, in one run.
fn edits_in_objects(at: IVec3, quick: bool) -> anyhow::Result<Vec<ObjectsEditRow>> {
    let path = assets().join("vox/seed/teapot256.vox");
    let (mut objects, _) = octovox::io::vox::load_vox_scene_file(&path, 0)?;
    let index = objects.objects().and_then(|o| o.target_at(at)).context("teapot256 is a scene of objects")?;
    let mut merged = Scene::new(objects.palette.clone(), objects.drawn().clone());
    objects.take_uploads();
    merged.take_uploads();
    let cases: [(&str, Shape, usize); 4] = [
        ("one voxel", Shape::Voxel(at), 101),
        ("sphere r = 8", Shape::Sphere { center: at, radius: 8 }, 101),
        ("sphere r = 32", Shape::Sphere { center: at, radius: 32 }, 21),
        ("box 255³", Shape::centered_box(at, IVec3::splat(255)), 11),
    ];
    let mut rows = Vec::new();
    for (name, shape, runs) in cases {
        let runs = if quick { runs.min(3) } else { runs };
        let time = |scene: &mut Scene, in_object: bool| -> anyhow::Result<(f64, u64)> {
            let (mut times, mut bytes) = (Vec::new(), 0);
            for i in 0..runs {
                let op = if i % 2 == 0 { Op::Remove } else { Op::Place(2) };
                let start = Instant::now();
                if in_object {
                    scene.apply_in_object(index, &shape, op)?;
                } else {
                    scene.apply_brush(&shape, op)?;
                }
                let upload = scene.take_uploads();
                times.push(start.elapsed().as_secs_f64() * 1e6);
                if i == 0 {
                    bytes = upload.byte_count();
                }
            }
            Ok((median(times), bytes))
        };
        let (objects_us, objects_bytes) = time(&mut objects, true)?;
        let (one_model_us, one_model_bytes) = time(&mut merged, false)?;
        rows.push(ObjectsEditRow { edit: name, objects_us, one_model_us, objects_bytes, one_model_bytes });
    }
    Ok(rows)
}

fn objects_table(rows: &[ObjectsEditRow]) -> String {
    let mut md = "\n## The same brushes in a scene of objects\n\n\
        teapot256.vox as the scene of six objects it is: each edit goes into the model of the object at the wall \
        (through the inverse of its cell map) and every placement of that model is composed again into the drawn \
        octree, uniform cells as cubes (`Objects::recompose`); against the same voxels as one model. Median of \
        apply + upload, in one run. The region an edit reaches is emptied and composed again from every object \
        in it, so cells that did not change are written and uploaded too (the big box's bytes). Peak heap is \
        measured by `tests/vox_alloc.rs` (a counting allocator): a 255³ box in a new object of test_groups.vox \
        13 MB against 7 MB as one model (677 MB when composing listed every voxel); 2048³ 513 MB against \
        208 MB (it asked for 8 GB and aborted).\n\n\
        | edit | scene of objects µs | one model µs | ratio | objects bytes uploaded | one model bytes |\n\
        |---|---|---|---|---|---|\n"
        .to_owned();
    for r in rows {
        md += &format!(
            "| {} | {:.1} | {:.1} | {:.2} | {} | {} |\n",
            r.edit,
            r.objects_us,
            r.one_model_us,
            r.objects_us / r.one_model_us.max(1e-9),
            r.objects_bytes,
            r.one_model_bytes
        );
    }
    md
}

#[derive(Serialize)]
struct RenderRow {
    model: &'static str,
    adapter: String,
    width: u32,
    height: u32,
    grid_ms: f64,
    svo_ms: f64,
    /// The floor kernel: everything a frame does but the traversal.
    floor_ms: f64,
    svo_over_floor: f64,
    grid_over_svo: f64,
    svo_mrays_per_s: f64,
    grid_mean_iterations: f64,
    svo_mean_iterations: f64,
    report_grid_over_svo: f64,
}

pub(super) fn bench_render(quick: bool, lod: f32) -> anyhow::Result<(String, String)> {
    let (width, height) = if quick { (425, 225) } else { (1700, 900) };
    let mut renderer = Renderer::headless().context("bench render needs a GPU (lavapipe works)")?;
    let mut rows = Vec::new();
    for model in &MODELS {
        let mut scene = Scene::new(Palette::default(), build(&source(model)?)?);
        let grid = DenseGrid::from_octree(scene.drawn())?;
        renderer.sync(&mut scene);
        renderer.set_grid(&grid, scene.revision())?;
        let (lo, hi) = scene.solid_bounds().context("empty model")?;
        let camera = Camera::framing(lo, hi, 50.0);
        // Shared machines are noisy: enough frames for a steady median.
        let frames = if quick { 2 } else { 9 };
        // The level of detail applies to the SVO only: the grid is exact.
        let settings = |mode| RenderSettings {
            mode,
            view: View::Shaded,
            shadows: false,
            render_scale: 1.0,
            lod: if mode == TraceMode::Svo { lod } else { 0.0 },
            ground: None,
        };
        let modes = [TraceMode::Grid, TraceMode::Svo];
        // Warm up all three, then alternate frames so machine noise hits them alike.
        for mode in modes {
            renderer.render(&scene, &camera, (width, height), &settings(mode), None)?;
        }
        renderer.render_floor(&scene, &camera, (width, height))?;
        let mut times = [Vec::new(), Vec::new()];
        let mut floor_times = Vec::new();
        for _ in 0..frames {
            for (i, mode) in modes.into_iter().enumerate() {
                times[i].push(renderer.render(&scene, &camera, (width, height), &settings(mode), None)?);
            }
            floor_times.push(renderer.render_floor(&scene, &camera, (width, height))?);
        }
        let floor_ms = median(floor_times);
        // Hit records (for the step counts) only outside the timed frames.
        renderer.hit_records = true;
        let mut mean_iterations = [0.0; 2];
        for (i, mode) in modes.into_iter().enumerate() {
            renderer.render(&scene, &camera, (width, height), &settings(mode), None)?;
            let hits = renderer.read_hits()?;
            mean_iterations[i] = mean_steps(&hits);
        }
        renderer.hit_records = false;
        let [grid_times, svo_times] = times;
        let (grid_ms, svo_ms) = (median(grid_times), median(svo_times));
        let [grid_iter, svo_iter] = mean_iterations;
        rows.push(RenderRow {
            model: model.name,
            adapter: renderer.gpu.adapter_name.clone(),
            width,
            height,
            grid_ms,
            svo_ms,
            floor_ms,
            svo_over_floor: svo_ms / floor_ms,
            grid_over_svo: grid_ms / svo_ms,
            svo_mrays_per_s: f64::from(width * height) / (svo_ms * 1e3),
            grid_mean_iterations: grid_iter,
            svo_mean_iterations: svo_iter,
            report_grid_over_svo: model.report.1 / model.report.2,
        });
    }
    let lod_note = if lod > 0.0 { format!(", SVO at level of detail {lod} px") } else { String::new() };
    let mut md = header(&format!("Grid DDA vs SVO, {width}×{height}{lod_note}"));
    md += &format!(
        "Adapter: **{}**; GPU time from timestamp queries where available, else wall time of submit + wait; median of the frames after one warm-up. Shadows off (the report's shading had none). Camera frames each whole model. The SVO time covers all of its dispatches: the floor kernel drawing every pixel as sky, the beam prepass (one thread per 16×16-pixel tile, listing the tiles with something in them), the one-thread kernel that sizes the trace, and the per-pixel traversal of the listed tiles; its mean steps count the traversal's loop iterations per pixel (0 outside the listed tiles). The report's 10 M-voxel scene is the Pietà, which is not public: `nefertiti512` is DESIGN.md's stand-in for it (the solid voxelization of meshes/nefertiti.obj, 512 voxels tall, 12.8 M voxels) and `sculpture10M` a smooth procedural shape with the Pietà's extent (11.6 M voxels); both rows compare with the report's Pietà. *Floor*: a kernel that does everything the per-pixel pass does except the traversal (the pixel's ray, shading a miss, one store per pixel, a thread per pixel): no traversal on this adapter can be faster, and *SVO / floor* says how far above it the SVO is.\n\n",
        renderer.gpu.adapter_name
    );
    md += "| model | grid ms | SVO ms | floor ms | SVO / floor | grid / SVO | report grid / SVO | SVO Mrays/s | mean steps grid | mean steps SVO |\n|---|---|---|---|---|---|---|---|---|---|\n";
    for r in &rows {
        md += &format!(
            "| {} | {:.2} | {:.2} | {:.2} | {:.2}× | {:.2}× | {:.2}× | {:.2} | {:.1} | {:.1} |\n",
            r.model,
            r.grid_ms,
            r.svo_ms,
            r.floor_ms,
            r.svo_over_floor,
            r.grid_over_svo,
            r.report_grid_over_svo,
            r.svo_mrays_per_s,
            r.grid_mean_iterations,
            r.svo_mean_iterations
        );
    }
    Ok((md, serde_json::to_string_pretty(&rows)?))
}
