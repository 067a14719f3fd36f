//! Scene-graph traversal: which model goes where, with which transform.
//!
//! The walk starts at node 0, composes nTRN transforms down the tree (child
//! first, as `ogt_vox` flattens them), and yields one [`Placement`] per nSHP
//! it reaches. Nodes may be shared (an instance placed by several
//! transforms); a node on its own path is a cycle. The walk is iterative, so
//! deep graphs cannot overflow the stack, and bounded by [`MAX_NODE_VISITS`],
//! [`MAX_INSTANCES`] and [`MAX_VOXELS`].

use std::collections::HashMap;

use dot_vox::{Dict, SceneNode, ShapeModel};

use super::transform::{Placement, Rotation, Transform};
use super::{MAX_INSTANCES, MAX_NODE_VISITS, MAX_VOXELS, VoxError};

/// Walks the scene graph from node 0 and returns every shape placement.
///
/// `node_ids[k]` is the id of `nodes[k]`; `model_voxels[m]` the voxel count of
/// model `m`, used to refuse scenes over [`MAX_VOXELS`] before building them.
/// `frame` picks the keyframe of animated transforms and shapes (`_f`).
pub(super) fn placements(
    nodes: &[SceneNode],
    node_ids: &[u32],
    model_voxels: &[usize],
    frame: usize,
) -> Result<Vec<Placement>, VoxError> {
    let walk = Walk {
        nodes,
        index_of: index_nodes(node_ids)?,
        model_voxels,
        frame,
        on_path: vec![false; nodes.len()],
        stack: vec![Step::Enter { id: 0, parent: None, transform: Transform::IDENTITY }],
        visits: 0,
        voxels: 0,
        out: Vec::new(),
    };
    walk.run()
}

/// One entry of the explicit depth-first stack.
enum Step {
    /// Visit node `id`, reached from `parent`, under the accumulated `transform`.
    Enter { id: u32, parent: Option<u32>, transform: Transform },
    /// All of node `index`'s descendants are done: it leaves the current path.
    Leave { index: usize },
}

/// State of one scene-graph walk.
struct Walk<'a> {
    nodes: &'a [SceneNode],
    index_of: HashMap<u32, usize>,
    model_voxels: &'a [usize],
    frame: usize,
    /// Nodes on the path from the root to the node being visited.
    on_path: Vec<bool>,
    stack: Vec<Step>,
    visits: usize,
    /// Voxels of all placements so far.
    voxels: usize,
    out: Vec<Placement>,
}

impl Walk<'_> {
    fn run(mut self) -> Result<Vec<Placement>, VoxError> {
        while let Some(step) = self.stack.pop() {
            match step {
                Step::Leave { index } => self.on_path[index] = false,
                Step::Enter { id, parent, transform } => self.enter(id, parent, transform)?,
            }
        }
        Ok(self.out)
    }

    fn enter(&mut self, id: u32, parent: Option<u32>, transform: Transform) -> Result<(), VoxError> {
        let index = self.index_of.get(&id).copied().ok_or_else(|| {
            VoxError::BadSceneGraph(match parent {
                Some(parent) => format!("node {parent} refers to missing node {id}"),
                None => "there is no root node 0".to_owned(),
            })
        })?;
        if self.on_path[index] {
            return Err(VoxError::SceneCycle(id));
        }
        self.visits += 1;
        if self.visits > MAX_NODE_VISITS {
            return Err(VoxError::BadSceneGraph(format!(
                "more than {MAX_NODE_VISITS} node visits (nodes shared along too many paths)"
            )));
        }
        self.on_path[index] = true;
        self.stack.push(Step::Leave { index });
        let nodes = self.nodes;
        match &nodes[index] {
            SceneNode::Transform { frames, child, .. } => {
                let picked = pick_keyframe(frames.iter().map(|f| &f.attributes), self.frame, id)?;
                let local = match picked {
                    Some(k) => parse_transform(&frames[k].attributes, id)?,
                    None => Transform::IDENTITY,
                };
                let transform = transform.compose(local);
                self.stack.push(Step::Enter { id: *child, parent: Some(id), transform });
            }
            SceneNode::Group { children, .. } => {
                // Reversed so that children are visited in file order.
                for &child in children.iter().rev() {
                    self.stack.push(Step::Enter { id: child, parent: Some(id), transform });
                }
            }
            SceneNode::Shape { models, .. } => self.place_shape(id, models, transform)?,
        }
        Ok(())
    }

    fn place_shape(&mut self, id: u32, models: &[ShapeModel], transform: Transform) -> Result<(), VoxError> {
        let picked = pick_keyframe(models.iter().map(|m| &m.attributes), self.frame, id)?;
        let Some(k) = picked else { return Ok(()) };
        let model = usize::try_from(models[k].model_id).unwrap_or(usize::MAX);
        let count = self.model_voxels.get(model).copied().ok_or_else(|| {
            VoxError::BadSceneGraph(format!(
                "shape node {id} uses model {model} but the file has {} models",
                self.model_voxels.len()
            ))
        })?;
        self.voxels = self.voxels.saturating_add(count);
        if self.voxels > MAX_VOXELS {
            return Err(VoxError::TooManyVoxels { limit: MAX_VOXELS, found: self.voxels });
        }
        if self.out.len() >= MAX_INSTANCES {
            return Err(VoxError::BadSceneGraph(format!("more than {MAX_INSTANCES} model placements")));
        }
        self.out.push(Placement { model, transform, centred: true });
        Ok(())
    }
}

fn index_nodes(node_ids: &[u32]) -> Result<HashMap<u32, usize>, VoxError> {
    let mut index_of = HashMap::with_capacity(node_ids.len());
    for (index, &id) in node_ids.iter().enumerate() {
        if index_of.insert(id, index).is_some() {
            return Err(VoxError::BadSceneGraph(format!("node id {id} is used twice")));
        }
    }
    Ok(index_of)
}

/// Index of the keyframe shown at `frame`: the last one whose `_f` is at
/// most `frame` (a missing `_f` counts as 0), else the first; `None` when
/// there are none. MagicaVoxel interpolates translations between keyframes;
/// octovox snaps to the earlier one.
fn pick_keyframe<'a>(
    keyframes: impl Iterator<Item = &'a Dict>,
    frame: usize,
    node: u32,
) -> Result<Option<usize>, VoxError> {
    let mut best: Option<(usize, usize)> = None;
    let mut any = false;
    for (k, attributes) in keyframes.enumerate() {
        any = true;
        let at = match attributes.get("_f") {
            None => 0,
            Some(text) => text
                .trim()
                .parse::<usize>()
                .map_err(|_| VoxError::BadSceneGraph(format!("node {node} has a malformed frame index _f={text:?}")))?,
        };
        if at <= frame && best.is_none_or(|(best_at, _)| at > best_at) {
            best = Some((at, k));
        }
    }
    Ok(best.map(|(_, k)| k).or(any.then_some(0)))
}

/// Parses a keyframe's `_r` rotation byte and `_t` translation.
fn parse_transform(attributes: &Dict, node: u32) -> Result<Transform, VoxError> {
    let rotation = match attributes.get("_r") {
        None => Rotation::IDENTITY,
        Some(text) => text
            .trim()
            .parse::<u8>()
            .ok()
            .and_then(Rotation::from_byte)
            .ok_or_else(|| VoxError::BadSceneGraph(format!("node {node} has an invalid rotation _r={text:?}")))?,
    };
    let translation = match attributes.get("_t") {
        None => [0, 0, 0],
        Some(text) => parse_translation(text)
            .ok_or_else(|| VoxError::BadSceneGraph(format!("node {node} has a malformed translation _t={text:?}")))?,
    };
    Ok(Transform { rotation, translation })
}

fn parse_translation(text: &str) -> Option<[i64; 3]> {
    let mut parts = text.split_ascii_whitespace().map(|p| p.parse::<i32>().ok().map(i64::from));
    let t = [parts.next()??, parts.next()??, parts.next()??];
    parts.next().is_none().then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn translation_parsing_is_strict() {
        assert_eq!(parse_translation("1 -2  3"), Some([1, -2, 3]));
        assert_eq!(parse_translation("1 2"), None);
        assert_eq!(parse_translation("1 2 3 4"), None);
        assert_eq!(parse_translation("1 2 x"), None);
    }
}
