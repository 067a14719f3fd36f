//! The turns row of `octovox bench anim`: what a free turn costs against
//! a quarter turn. A ball of one object is turned by 90° (a signed
//! permutation: its cells copied box by box) and by 45° (every world cell
//! resampled through the turn by its centre, the cells `expect`, `info`
//! and export read); each turn is timed as the editor runs it, and the
//! frame that draws it after (90°: the composed octree; 45°: the ball
//! traced exactly as a turned instance).

use std::time::Instant;

use anyhow::Context;
use dot_vox::{DotVoxData, Frame, Layer, Model, SceneNode, ShapeModel, Size, Voxel};
use serde::Serialize;

use octovox::camera::Camera;
use octovox::editor::Editor;
use octovox::gpu::Renderer;
use octovox::script::{Degrees, Line, ObjectLine, ObjectRef};
use octovox::settings::RenderSettings;

use super::bench::median;

#[derive(Serialize)]
pub struct TurnsRow {
    /// The ball's model edge, in voxels, and its voxels.
    pub edge: u32,
    pub voxels: u64,
    /// Milliseconds of `object turn y 90` and of `object turn y 45`.
    pub quarter_turn_ms: f64,
    pub free_turn_ms: f64,
    /// The preview frame after each, median of five.
    pub quarter_frame_ms: f64,
    pub free_frame_ms: f64,
    /// Cells drawn after each.
    pub quarter_cells: u64,
    pub free_cells: u64,
}

/// A ball of `edge` voxels across, coloured by octant, as the one object
/// `ball` of a scene graph.
fn ball(edge: u32) -> anyhow::Result<Vec<u8>> {
    let r = f64::from(edge) / 2.0;
    let mut voxels = Vec::new();
    for x in 0..edge {
        for y in 0..edge {
            for z in 0..edge {
                let d = [x, y, z].map(|c| f64::from(c) + 0.5 - r);
                if d.iter().map(|c| c * c).sum::<f64>() <= r * r {
                    let octant = u8::from(d[0] > 0.0) | u8::from(d[1] > 0.0) << 1 | u8::from(d[2] > 0.0) << 2;
                    voxels.push(Voxel { x: x as u8, y: y as u8, z: z as u8, i: 10 + 8 * octant });
                }
            }
        }
    }
    let dict = |pairs: &[(&str, &str)]| pairs.iter().map(|(k, v)| ((*k).to_owned(), (*v).to_owned())).collect();
    let data = DotVoxData {
        version: 200,
        index_map: Vec::new(),
        models: vec![Model { size: Size { x: edge, y: edge, z: edge }, voxels }],
        palette: dot_vox::DEFAULT_PALETTE.to_vec(),
        materials: Vec::new(),
        scenes: vec![
            SceneNode::Transform { attributes: dict(&[]), frames: vec![], child: 1, layer_id: u32::MAX },
            SceneNode::Group { attributes: dict(&[]), children: vec![2] },
            SceneNode::Transform {
                attributes: dict(&[("_name", "ball")]),
                frames: vec![Frame::new(dict(&[("_t", "0 0 0")]))],
                child: 3,
                layer_id: 0,
            },
            SceneNode::Shape { attributes: dict(&[]), models: vec![ShapeModel { model_id: 0, attributes: dict(&[]) }] },
        ],
        layers: vec![Layer { attributes: dict(&[("_name", "0")]) }],
    };
    let mut bytes = Vec::new();
    data.write_vox(&mut bytes).context("writing the ball")?;
    Ok(bytes)
}

pub fn bench_turns(quick: bool, size: (u32, u32)) -> anyhow::Result<TurnsRow> {
    let edge = if quick { 32 } else { 128 };
    let (scene, _) = octovox::io::vox::load_vox_scene(&ball(edge)?, 0)?;
    let voxels = scene.solid_voxels();
    let mut renderer = Renderer::headless().context("bench anim needs a GPU (lavapipe works)")?;
    let settings = RenderSettings { shadows: false, ..RenderSettings::default() };
    let (lo, hi) = scene.solid_bounds().context("an empty ball")?;
    let camera =
        Camera::framing(lo - glam::IVec3::splat(edge as i32 / 4), hi + glam::IVec3::splat(edge as i32 / 4), 50.0);
    let mut editor = Editor::default();
    editor.set_scene(scene);
    editor.run(&Line::Object(ObjectLine::Pick(ObjectRef::Index(0))))?;
    let mut turn = |degrees: f64| -> anyhow::Result<(f64, f64, u64)> {
        let start = Instant::now();
        editor.run(&Line::Object(ObjectLine::Turn { axis: 1, degrees: Degrees(degrees) }))?;
        let turn_ms = start.elapsed().as_secs_f64() * 1e3;
        renderer.sync(&mut editor.scene);
        renderer.render(&editor.scene, &camera, size, &settings, None)?;
        let mut frames = Vec::new();
        for _ in 0..5 {
            let start = Instant::now();
            renderer.render(&editor.scene, &camera, size, &settings, None)?;
            frames.push(start.elapsed().as_secs_f64() * 1e3);
        }
        let cells = editor.scene.solid_voxels();
        editor.run(&Line::Undo(1))?;
        Ok((turn_ms, median(frames), cells))
    };
    let (quarter_turn_ms, quarter_frame_ms, quarter_cells) = turn(90.0)?;
    let (free_turn_ms, free_frame_ms, free_cells) = turn(45.0)?;
    Ok(TurnsRow {
        edge,
        voxels,
        quarter_turn_ms,
        free_turn_ms,
        quarter_frame_ms,
        free_frame_ms,
        quarter_cells,
        free_cells,
    })
}

/// The row as Markdown.
pub fn report(t: &TurnsRow) -> String {
    format!(
        "## A quarter turn and a free turn\n\nA ball {} voxels across ({} voxels), the one object of its scene, \
         turned about y by `object turn y 90` (a signed permutation: the cells copied box by box) and by `object \
         turn y 45` (every world cell resampled by its centre), each undone before the next. The turn as the \
         editor runs it (the scene composed again: at 45° its cells resampled), then the preview of the turned \
         ball, median of five: at 90° the composed octree, at 45° the ball traced exactly as a turned instance.\n\n\
         | turn | turn ms | frame ms | cells |\n|---|---|---|---|\n\
         | 90° (exact) | {:.1} | {:.2} | {} |\n| 45° (free) | {:.1} | {:.2} | {} |\n| 45° / 90° | {:.1}× | {:.2}× | |\n",
        t.edge,
        t.voxels,
        t.quarter_turn_ms,
        t.quarter_frame_ms,
        t.quarter_cells,
        t.free_turn_ms,
        t.free_frame_ms,
        t.free_cells,
        t.free_turn_ms / t.quarter_turn_ms.max(1e-9),
        t.free_frame_ms / t.quarter_frame_ms.max(1e-9),
    )
}
