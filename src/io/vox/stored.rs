//! Where each model of a scene goes in a `.vox` file: its grid, or — for a
//! model an edit grew past 256 voxels in some axis, which no `.vox` model
//! holds — the pieces of at most 256³ it is cut into, each its own model,
//! placed under a group that takes the model's place in the scene graph.

use glam::IVec3;

use super::VoxError;
use super::validate::MAX_MODEL_EDGE;
use crate::scene::graph::{self, Attributes, Node, NodeKind, SceneGraph};
use crate::scene::objects::Model;
use crate::scene::transform::{Rotation, Transform};

/// One model as written: the model cells `lo..lo + size` of a stored model,
/// shifted to `0..size`.
pub(super) struct Stored {
    /// The model it cuts from.
    pub model: usize,
    pub size: [u32; 3],
    pub lo: IVec3,
}

impl Stored {
    fn pivot(&self) -> IVec3 {
        pivot(self.size)
    }
}

/// MagicaVoxel turns a model about `floor(size / 2)`.
fn pivot(size: [u32; 3]) -> IVec3 {
    IVec3::new((size[0] / 2) as i32, (size[1] / 2) as i32, (size[2] / 2) as i32)
}

/// The grid a model is written in: its loaded grid `0..size`, grown to hold
/// what edits added outside it.
fn grid_box(model: &Model) -> (IVec3, IVec3) {
    let s = model.size;
    let top = IVec3::new(s[0] as i32, s[1] as i32, s[2] as i32) - IVec3::ONE;
    model.tree.solid_bounds().map_or((IVec3::ZERO, top), |(lo, hi)| (lo.min(IVec3::ZERO), hi.max(top)))
}

/// The grid of [`grid_box`] made to keep the model's pivot where it was
/// loaded: the same reach each side of it. A model turned by a free angle
/// is written so, as its placement could not follow a moved pivot in whole
/// cells (`shift_frames`).
fn pivot_keeping_box(model: &Model) -> (IVec3, IVec3) {
    let (lo, hi) = grid_box(model);
    if lo == IVec3::ZERO && hi == IVec3::from_array(model.size.map(|s| s as i32)) - IVec3::ONE {
        // Not grown: written as loaded.
        return (lo, hi);
    }
    let p = pivot(model.size);
    let half = (p - lo).max(hi + IVec3::ONE - p);
    (p - half, p + half - IVec3::ONE)
}

/// Every model as written: model `m` is entry `m` (a cut model's first
/// piece), and the other pieces of cut models follow all of them. Returns
/// the entries and, per model, the indices of its pieces when it was cut.
/// Models `turned` names keep their pivot ([`pivot_keeping_box`]).
pub(super) fn layout(models: &[Model], turned: &[bool]) -> (Vec<Stored>, Vec<Option<Vec<usize>>>) {
    let mut stored = Vec::with_capacity(models.len());
    let mut rest = Vec::new();
    let mut cuts = Vec::with_capacity(models.len());
    for (m, model) in models.iter().enumerate() {
        let (lo, hi) = if turned.get(m).copied().unwrap_or(false) { pivot_keeping_box(model) } else { grid_box(model) };
        let edge = hi - lo + IVec3::ONE;
        if edge.max_element() <= MAX_MODEL_EDGE as i32 {
            stored.push(Stored { model: m, size: edge.as_uvec3().to_array(), lo });
            cuts.push(None);
            continue;
        }
        let mut pieces = pieces_of(model, m, lo, hi).into_iter();
        let first = pieces.next().unwrap_or(Stored { model: m, size: [1, 1, 1], lo });
        stored.push(first);
        let mut indices = vec![m];
        for piece in pieces {
            indices.push(models.len() + rest.len());
            rest.push(piece);
        }
        cuts.push(Some(indices));
    }
    stored.extend(rest);
    (stored, cuts)
}

/// The non-empty blocks of 256³ that tile `lo..=hi`, each cropped to its voxels.
fn pieces_of(model: &Model, m: usize, lo: IVec3, hi: IVec3) -> Vec<Stored> {
    let step = MAX_MODEL_EDGE as usize;
    let mut out = Vec::new();
    for z in (lo.z..=hi.z).step_by(step) {
        for y in (lo.y..=hi.y).step_by(step) {
            for x in (lo.x..=hi.x).step_by(step) {
                let block_lo = IVec3::new(x, y, z);
                let block_hi = (block_lo + IVec3::splat(MAX_MODEL_EDGE as i32 - 1)).min(hi);
                let mut bounds: Option<(IVec3, IVec3)> = None;
                model.tree.for_each_solid_cell_in(block_lo, block_hi, |min, edge, _| {
                    let (a, b) = (min.max(block_lo), (min + IVec3::splat(edge - 1)).min(block_hi));
                    bounds = Some(bounds.map_or((a, b), |(l, h)| (l.min(a), h.max(b))));
                });
                if let Some((a, b)) = bounds {
                    out.push(Stored { model: m, size: (b - a + IVec3::ONE).as_uvec3().to_array(), lo: a });
                }
            }
        }
    }
    out
}

/// The graph as written: a transform showing a cut model shows a group of
/// its pieces instead, each under a transform that puts its voxels where
/// they were (the cut model's own transform and keyframes stay as they
/// are), and the cut model's shape goes. A transform of a model whose grid
/// moved gets the translation that keeps its voxels in place.
pub(super) fn written_graph(
    graph: &SceneGraph,
    models: &[Model],
    stored: &[Stored],
    cuts: &[Option<Vec<usize>>],
) -> Result<SceneGraph, VoxError> {
    let changed: Vec<bool> = (0..models.len())
        .map(|m| cuts[m].is_some() || stored[m].lo != IVec3::ZERO || stored[m].size != models[m].size)
        .collect();
    let mut out = graph.clone();
    let mut next = graph.nodes.iter().map(|n| n.id).max().unwrap_or(0);
    let (mut added, mut cut_shapes) = (Vec::new(), Vec::new());
    for node in &mut out.nodes {
        let NodeKind::Transform { child, frames, layer, .. } = &mut node.kind else { continue };
        let Some(m) = changed_model(graph, *child, &changed)? else { continue };
        let loaded = pivot(models[m].size);
        match &cuts[m] {
            None => shift_frames(frames, node.id, stored[m].lo + stored[m].pivot() - loaded)?,
            Some(pieces) => {
                let name = node.attributes.get("_name").cloned().unwrap_or_else(|| format!("model {m}"));
                let (group, nodes) = pieces_group(&mut next, &name, *layer, pieces, stored, loaded)?;
                cut_shapes.push(std::mem::replace(child, group));
                added.extend(nodes);
            }
        }
    }
    out.nodes.retain(|n| !cut_shapes.contains(&n.id));
    out.nodes.extend(added);
    Ok(out)
}

/// The model shape node `id` shows when that model was moved or cut; an
/// error when it shows such a model in some frames and another in others.
fn changed_model(graph: &SceneGraph, id: u32, changed: &[bool]) -> Result<Option<usize>, VoxError> {
    let Some(NodeKind::Shape { models }) = graph.node(id).map(|n| &n.kind) else { return Ok(None) };
    let is_changed = |m: u32| changed.get(m as usize).copied().unwrap_or(false);
    let Some(&(m, _)) = models.iter().find(|(m, _)| is_changed(*m)) else { return Ok(None) };
    if models.iter().any(|other| other.0 != m) {
        return Err(VoxError::Unsavable(format!(
            "model {m} grew, and shape node {id} shows other models in other frames: their placement cannot follow"
        )));
    }
    Ok(Some(m as usize))
}

/// Which models a transform with a free turn (`_ov_turn`) on some key shows.
pub(super) fn turned_models(graph: &SceneGraph, models: usize) -> Vec<bool> {
    let mut turned = vec![false; models];
    for node in &graph.nodes {
        let NodeKind::Transform { child, frames, .. } = &node.kind else { continue };
        if !frames.iter().any(|key| key.contains_key(graph::TURN_KEY)) {
            continue;
        }
        if let Some(NodeKind::Shape { models: shown }) = graph.node(*child).map(|n| &n.kind) {
            for (m, _) in shown {
                if let Some(t) = turned.get_mut(*m as usize) {
                    *t = true;
                }
            }
        }
    }
    turned
}

/// Moves every keyframe of a transform by `offset` model cells (turned by
/// its rotation), adding a keyframe to one without any.
fn shift_frames(frames: &mut Vec<Attributes>, id: u32, offset: IVec3) -> Result<(), VoxError> {
    if offset == IVec3::ZERO {
        return Ok(());
    }
    if frames.is_empty() {
        frames.push(Attributes::new());
    }
    for frame in frames.iter_mut() {
        if graph::parse_pose(frame, id)?.turn.is_some() {
            // The offset turned freely is no whole number of cells; `layout`
            // keeps such a model's pivot, so only a model another node shows
            // unturned and cut differently comes here.
            return Err(VoxError::Unsavable(format!(
                "transform node {id} turns a model by a free angle whose pivot moved: \
                 its place cannot be written in whole cells"
            )));
        }
        let mut transform = graph::parse_transform(frame, id)?;
        let moved = transform.rotation.apply([offset.x, offset.y, offset.z].map(i64::from));
        for (t, m) in transform.translation.iter_mut().zip(moved) {
            *t += m;
        }
        graph::write_transform(frame, transform);
    }
    Ok(())
}

/// A group of the pieces `pieces` (entries of `stored`), each under a
/// transform named `name 1`, `name 2`, … on `layer`: piece cell `u` lands
/// where model cell `u + lo` did under the cut model's pivot `loaded`.
/// Returns the group's id and the new nodes.
fn pieces_group(
    next: &mut u32,
    name: &str,
    layer: u32,
    pieces: &[usize],
    stored: &[Stored],
    loaded: IVec3,
) -> Result<(u32, Vec<Node>), VoxError> {
    let mut id = || {
        *next = next.checked_add(1).ok_or_else(|| VoxError::Unsavable("no node ids are left".to_owned()))?;
        Ok::<u32, VoxError>(*next)
    };
    let group = id()?;
    let mut nodes = Vec::new();
    let mut children = Vec::new();
    for (k, &entry) in pieces.iter().enumerate() {
        let piece = &stored[entry];
        let (transform, shape) = (id()?, id()?);
        let t = piece.lo + piece.pivot() - loaded;
        let mut frame = Attributes::new();
        graph::write_transform(
            &mut frame,
            Transform { rotation: Rotation::IDENTITY, translation: [t.x, t.y, t.z].map(i64::from) },
        );
        nodes.push(Node {
            id: transform,
            attributes: [("_name".to_owned(), format!("{name} {}", k + 1))].into(),
            kind: NodeKind::Transform { child: shape, reserved: u32::MAX, layer, frames: vec![frame] },
        });
        let model = u32::try_from(entry).map_err(|_| VoxError::Unsavable("too many models".to_owned()))?;
        nodes.push(Node {
            id: shape,
            attributes: Attributes::new(),
            kind: NodeKind::Shape { models: vec![(model, Attributes::new())] },
        });
        children.push(transform);
    }
    nodes.push(Node { id: group, attributes: Attributes::new(), kind: NodeKind::Group { children } });
    Ok((group, nodes))
}
