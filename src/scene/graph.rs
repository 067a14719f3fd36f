//! A MagicaVoxel scene graph as the file holds it: transform, group and
//! shape nodes with their attributes, and layers; and the walk that turns it
//! into the objects of a scene.
//!
//! The walk starts at node 0, composes nTRN transforms down the tree (child
//! first, as `ogt_vox` flattens them), and yields one [`Object`] per nSHP it
//! reaches. Nodes may be shared (a model placed by several transforms); a
//! node on its own path is a cycle. The walk is iterative, so deep graphs
//! cannot overflow the stack, and bounded by [`MAX_NODE_VISITS`],
//! [`MAX_INSTANCES`] and a voxel limit the caller gives.

use std::collections::{BTreeMap, HashMap};

use super::transform::{Placement, Pose, Rigid, Rotation, Transform, Turn};

/// Most model placements (shape instances) one scene graph may produce.
pub const MAX_INSTANCES: usize = 1 << 20;

/// Most scene-graph node visits one walk may make (a node shared by several
/// parents is visited once per path to it).
pub const MAX_NODE_VISITS: usize = 1 << 22;

/// Attributes as MagicaVoxel stores them (a DICT): `_name`, `_hidden`,
/// `_t`, `_r`, `_f`, `_color`, and whatever else a file holds.
pub type Attributes = BTreeMap<String, String>;

/// The nodes and layers of a scene, in file order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SceneGraph {
    pub nodes: Vec<Node>,
    pub layers: Vec<Layer>,
    /// The playback settings of the file's META chunk.
    pub animation: super::anim::Animation,
}

/// One nTRN, nGRP or nSHP chunk.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Node {
    pub id: u32,
    pub attributes: Attributes,
    pub kind: NodeKind,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NodeKind {
    /// One child placed by keyframes (`_t`, `_r`, `_f`), on a layer
    /// (`u32::MAX` for none); `reserved` is written back as read.
    Transform {
        child: u32,
        reserved: u32,
        layer: u32,
        frames: Vec<Attributes>,
    },
    Group {
        children: Vec<u32>,
    },
    /// Which model it shows, per keyframe (`_f`).
    Shape {
        models: Vec<(u32, Attributes)>,
    },
}

/// One LAYR chunk.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layer {
    pub id: u32,
    pub attributes: Attributes,
    /// Written back as read (MagicaVoxel writes −1).
    pub reserved: u32,
}

impl Node {
    /// Its `_name`, when it has one that is not empty.
    pub fn name(&self) -> Option<&str> {
        self.attributes.get("_name").map(String::as_str).filter(|n| !n.is_empty())
    }
}

impl Layer {
    pub fn name(&self) -> &str {
        self.attributes.get("_name").map_or("", String::as_str)
    }

    pub fn hidden(&self) -> bool {
        is_set(&self.attributes, "_hidden")
    }

    /// Its colour (`_color`, "R G B"), white where it has none or a bad one.
    pub fn color(&self) -> [u8; 3] {
        let parts: Vec<u8> = self
            .attributes
            .get("_color")
            .map_or(Vec::new(), |c| c.split_whitespace().filter_map(|p| p.parse().ok()).collect());
        match parts[..] {
            [r, g, b] => [r, g, b],
            _ => [255; 3],
        }
    }
}

/// Whether a flag attribute (`_hidden`) is set: MagicaVoxel writes "1".
pub fn is_set(attributes: &Attributes, key: &str) -> bool {
    attributes.get(key).is_some_and(|v| v.trim() == "1")
}

/// Why a scene graph cannot be walked.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum GraphError {
    /// A node reachable from itself.
    #[error("scene graph cycle at node {0}")]
    Cycle(u32),
    /// A missing node, a model id out of range, a malformed transform.
    #[error("scene graph: {0}")]
    Bad(String),
    /// A frame past the last a key can name (`_f` is 32 bits).
    #[error("frame {0} is past the last frame a key can name (4294967295)")]
    FrameTooLate(usize),
    /// The placed models hold more voxels than the caller allows.
    #[error("the scene holds more than {limit} voxels (at least {found})")]
    TooManyVoxels { limit: usize, found: usize },
    /// Its placements would take more memory than the budget allows.
    #[error(transparent)]
    OverBudget(#[from] crate::budget::OverBudget),
}

/// Bytes a placement takes once walked, at most: its `Object`, outline row,
/// name entry, cell map, GPU instance record and tree-of-boxes share.
pub const BYTES_PER_PLACEMENT: u64 = 256;

/// One placed model: what the walk found at an nSHP.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Object {
    pub placement: Placement,
    /// The nSHP node, and the nTRN right above it (whose `_t`/`_r` move it).
    pub shape_node: u32,
    pub transform_node: Option<u32>,
    /// The last named transform on the way down, as an entry of the walk's
    /// name table ([`path_of`] joins the names by `/`). Paths share
    /// their beginnings there, so 131,072 objects under 17 levels of long
    /// names take one entry a visit, not 100 KB each.
    pub name: Option<u32>,
    /// Layer of its transform (`None` for none).
    pub layer: Option<u32>,
    /// Hidden itself, below a hidden transform, or on a hidden layer.
    pub hidden: bool,
    /// Its own transform's `_hidden` flag (what `object hide` sets).
    pub own_hidden: bool,
}

impl Object {
    /// Model `model` of a file without a scene graph (an animation frame), as stored.
    pub fn frame(model: usize) -> Object {
        Object {
            placement: Placement { model, transform: Transform::IDENTITY, centred: false, turned: None },
            shape_node: 0,
            transform_node: None,
            name: None,
            layer: None,
            hidden: false,
            own_hidden: false,
        }
    }
}

impl SceneGraph {
    /// The objects of the scene at `frame`, in walk order (node 0 first,
    /// children in file order). `model_voxels[m]` is the voxel count of model
    /// `m`; the placed models may hold at most `voxel_limit` voxels together.
    pub fn objects(&self, model_voxels: &[usize], frame: usize, voxel_limit: usize) -> Result<Vec<Object>, GraphError> {
        Ok(self.walk(model_voxels, frame, voxel_limit)?.objects)
    }

    /// The objects as [`SceneGraph::objects`] finds them, and the outline
    /// of groups and objects that shows them.
    pub fn walk(&self, model_voxels: &[usize], frame: usize, voxel_limit: usize) -> Result<Walked, GraphError> {
        let walk = Walk {
            graph: self,
            index_of: index_nodes(&self.nodes)?,
            hidden_layers: self.layers.iter().filter(|l| l.hidden()).map(|l| l.id).collect(),
            model_voxels,
            frame: u32::try_from(frame).map_err(|_| GraphError::FrameTooLate(frame))?,
            voxel_limit,
            on_path: vec![false; self.nodes.len()],
            stack: vec![Step::Enter { id: 0, parent: None, context: Context::ROOT }],
            visits: 0,
            voxels: 0,
            rigids: Vec::new(),
            out: Walked::default(),
        };
        walk.run()
    }

    /// The node with id `id`: found at once where ids are file positions
    /// (as MagicaVoxel writes them), else searched for.
    pub fn node(&self, id: u32) -> Option<&Node> {
        self.nodes.get(id as usize).filter(|n| n.id == id).or_else(|| self.nodes.iter().find(|n| n.id == id))
    }

    /// Reads every key of every node (frame, translation, turn, easing),
    /// so that a key no frame shows yet is refused when the file is read,
    /// not when a frame first shows it.
    pub fn check_keys(&self) -> Result<(), GraphError> {
        for node in &self.nodes {
            match &node.kind {
                NodeKind::Transform { frames, .. } => {
                    for key in frames {
                        super::anim::key_frame(key, node.id)?;
                        parse_pose(key, node.id)?;
                        super::anim::Ease::of(key, node.id)?;
                    }
                }
                NodeKind::Shape { models } => {
                    for (_, key) in models {
                        super::anim::key_frame(key, node.id)?;
                    }
                }
                NodeKind::Group { .. } => {}
            }
        }
        Ok(())
    }

    /// Number of group nodes.
    pub fn group_count(&self) -> usize {
        self.nodes.iter().filter(|n| matches!(n.kind, NodeKind::Group { .. })).count()
    }
}

/// What a path down the graph has gathered so far.
#[derive(Clone, Copy)]
struct Context {
    transform: Transform,
    /// The whole placement where a free turn was met on the way down, as
    /// an entry of `Walk::rigids` (kept apart: the context is copied for
    /// every node on the stack).
    rigid: Option<u32>,
    hidden: bool,
    own_hidden: bool,
    /// The nearest nTRN above, and its layer.
    transform_node: Option<u32>,
    layer: Option<u32>,
    /// Last named transform on the path, as an entry of `Walked::names`.
    name: Option<u32>,
    /// Groups above, not counting the root's.
    depth: u32,
}

impl Context {
    const ROOT: Context = Context {
        transform: Transform::IDENTITY,
        rigid: None,
        hidden: false,
        own_hidden: false,
        transform_node: None,
        layer: None,
        name: None,
        depth: 0,
    };
}

/// One entry of the explicit depth-first stack.
enum Step {
    /// Visit node `id`, reached from `parent`.
    Enter { id: u32, parent: Option<u32>, context: Context },
    /// All of node `index`'s descendants are done: it leaves the current path.
    Leave { index: usize },
}

/// State of one scene-graph walk.
struct Walk<'a> {
    graph: &'a SceneGraph,
    index_of: HashMap<u32, usize>,
    hidden_layers: Vec<u32>,
    model_voxels: &'a [usize],
    frame: u32,
    voxel_limit: usize,
    /// Nodes on the path from the root to the node being visited.
    on_path: Vec<bool>,
    stack: Vec<Step>,
    visits: usize,
    /// Voxels of all placements so far.
    voxels: usize,
    /// The whole placements below free turns (`Context::rigid`).
    rigids: Vec<Rigid>,
    out: Walked,
}

/// What a walk finds: the objects, and the rows of the outline.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Walked {
    pub objects: Vec<Object>,
    pub outline: Vec<OutlineRow>,
    /// The named transforms met, each with the entry above it on its path.
    pub names: Vec<NameEntry>,
}

/// A named transform met on the way down: its node, and the named entry
/// above it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NameEntry {
    pub parent: Option<u32>,
    pub node: u32,
}

/// The names of the named transforms down to entry `at` of `names` (a
/// walk's [`Walked::names`]), joined by `/` (empty for none), read from
/// `graph`, the graph walked.
pub fn path_of(graph: &SceneGraph, names: &[NameEntry], mut at: Option<u32>) -> String {
    let mut parts = Vec::new();
    while let Some(entry) = at.and_then(|i| names.get(i as usize)) {
        parts.push(graph.node(entry.node).and_then(Node::name).unwrap_or_default());
        at = entry.parent;
    }
    parts.reverse();
    parts.join("/")
}

/// One row of the outline, in walk order: a group (the transform above an
/// nGRP other than the root's) or an object; `depth` counts the groups
/// above it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum OutlineRow {
    /// `transform`'s name is the group's (`SceneGraph::node`).
    Group {
        transform: u32,
        depth: u32,
        hidden: bool,
    },
    Object {
        index: usize,
        depth: u32,
    },
}

impl<'a> Walk<'a> {
    fn run(mut self) -> Result<Walked, GraphError> {
        while let Some(step) = self.stack.pop() {
            match step {
                Step::Leave { index } => self.on_path[index] = false,
                Step::Enter { id, parent, context } => self.enter(id, parent, context)?,
            }
        }
        Ok(self.out)
    }

    fn enter(&mut self, id: u32, parent: Option<u32>, context: Context) -> Result<(), GraphError> {
        let index = self.index_of.get(&id).copied().ok_or_else(|| {
            GraphError::Bad(match parent {
                Some(parent) => format!("node {parent} refers to missing node {id}"),
                None => "there is no root node 0".to_owned(),
            })
        })?;
        if self.on_path[index] {
            return Err(GraphError::Cycle(id));
        }
        self.visits += 1;
        if self.visits > MAX_NODE_VISITS {
            return Err(GraphError::Bad(format!(
                "more than {MAX_NODE_VISITS} node visits (nodes shared along too many paths)"
            )));
        }
        self.on_path[index] = true;
        self.stack.push(Step::Leave { index });
        let node: &'a Node = &self.graph.nodes[index];
        match &node.kind {
            NodeKind::Transform { frames, child, layer, .. } => {
                let mut context = self.transformed(node, frames, *layer, context)?;
                if parent.is_some() && self.leads_to_group(*child) {
                    let (depth, hidden) = (context.depth, context.hidden);
                    self.out.outline.push(OutlineRow::Group { transform: id, depth, hidden });
                    context.depth += 1;
                }
                self.stack.push(Step::Enter { id: *child, parent: Some(id), context });
            }
            NodeKind::Group { children } => {
                // Reversed so that children are visited in file order.
                for &child in children.iter().rev() {
                    self.stack.push(Step::Enter { id: child, parent: Some(id), context });
                }
            }
            NodeKind::Shape { models } => self.place_shape(node, models, context)?,
        }
        Ok(())
    }

    /// Whether node `id` is a group (a missing one is reported when entered).
    fn leads_to_group(&self, id: u32) -> bool {
        self.index_of.get(&id).is_some_and(|&i| matches!(self.graph.nodes[i].kind, NodeKind::Group { .. }))
    }

    /// The context below transform `node`.
    fn transformed(
        &mut self,
        node: &'a Node,
        frames: &[Attributes],
        layer: u32,
        context: Context,
    ) -> Result<Context, GraphError> {
        let local = super::anim::sample_transform(frames, &node.attributes, self.frame, node.id)?;
        let layer = (layer != u32::MAX).then_some(layer);
        let name = match node.name() {
            Some(_) => {
                let entry =
                    u32::try_from(self.out.names.len()).map_err(|_| GraphError::Bad("too many names".into()))?;
                self.out.names.push(NameEntry { parent: context.name, node: node.id });
                Some(entry)
            }
            None => context.name,
        };
        let own_hidden = is_set(&node.attributes, "_hidden");
        let rigid = match (context.rigid, local.turn) {
            (None, None) => None,
            (above, _) => {
                let above = above.map_or(Rigid::of_transform(context.transform), |k| self.rigids[k as usize]);
                let at = u32::try_from(self.rigids.len()).map_err(|_| GraphError::Bad("too many turns".into()))?;
                self.rigids.push(above.compose(Rigid::of_pose(&local)));
                Some(at)
            }
        };
        Ok(Context {
            transform: context.transform.compose(local.transform),
            rigid,
            own_hidden,
            hidden: context.hidden || own_hidden || layer.is_some_and(|l| self.hidden_layers.contains(&l)),
            transform_node: Some(node.id),
            layer,
            name,
            depth: context.depth,
        })
    }

    fn place_shape(&mut self, node: &Node, models: &[(u32, Attributes)], context: Context) -> Result<(), GraphError> {
        let id = node.id;
        let Some(k) = super::anim::sample_model(models, &node.attributes, self.frame, id)? else { return Ok(()) };
        let model = usize::try_from(models[k].0).unwrap_or(usize::MAX);
        let count = self.model_voxels.get(model).copied().ok_or_else(|| {
            GraphError::Bad(format!(
                "shape node {id} uses model {model} but the file has {} models",
                self.model_voxels.len()
            ))
        })?;
        self.voxels = self.voxels.saturating_add(count);
        if self.voxels > self.voxel_limit {
            return Err(GraphError::TooManyVoxels { limit: self.voxel_limit, found: self.voxels });
        }
        if self.out.objects.len() >= MAX_INSTANCES {
            return Err(GraphError::Bad(format!("more than {MAX_INSTANCES} model placements")));
        }
        let index = self.out.objects.len();
        // Checked as the lists double: a shared graph of 52 nodes can place
        // 131,072 objects (the file says nothing of it up front).
        if (index + 1).is_power_of_two() && index >= 1024 {
            let bytes = 2 * (index as u64 + 1) * BYTES_PER_PLACEMENT;
            crate::budget::check(|| format!("placing {} models and more", index + 1), bytes)?;
        }
        self.out.outline.push(OutlineRow::Object { index, depth: context.depth });
        self.out.objects.push(Object {
            placement: Placement {
                model,
                transform: context.transform,
                centred: true,
                turned: context.rigid.map(|k| self.rigids[k as usize]),
            },
            shape_node: id,
            transform_node: context.transform_node,
            name: context.name,
            layer: context.layer,
            hidden: context.hidden,
            own_hidden: context.own_hidden,
        });
        Ok(())
    }
}

fn index_nodes(nodes: &[Node]) -> Result<HashMap<u32, usize>, GraphError> {
    let mut index_of = HashMap::with_capacity(nodes.len());
    for (index, node) in nodes.iter().enumerate() {
        if index_of.insert(node.id, index).is_some() {
            return Err(GraphError::Bad(format!("node id {} is used twice", node.id)));
        }
    }
    Ok(index_of)
}

/// Parses a keyframe's `_r` rotation byte and `_t` translation.
pub fn parse_transform(attributes: &Attributes, node: u32) -> Result<Transform, GraphError> {
    let rotation = match attributes.get("_r") {
        None => Rotation::IDENTITY,
        Some(text) => text
            .trim()
            .parse::<u8>()
            .ok()
            .and_then(Rotation::from_byte)
            .ok_or_else(|| GraphError::Bad(format!("node {node} has an invalid rotation _r={text:?}")))?,
    };
    let translation = match attributes.get("_t") {
        None => [0, 0, 0],
        Some(text) => parse_translation(text)
            .ok_or_else(|| GraphError::Bad(format!("node {node} has a malformed translation _t={text:?}")))?,
    };
    Ok(Transform { rotation, translation })
}

fn parse_translation(text: &str) -> Option<[i64; 3]> {
    let mut parts = text.split_ascii_whitespace().map(|p| p.parse::<i32>().ok().map(i64::from));
    let t = [parts.next()??, parts.next()??, parts.next()??];
    parts.next().is_none().then_some(t)
}

/// The key of octovox's free turn in a keyframe (see `transform`): a unit
/// quaternion `x y z w` in MagicaVoxel axes, which other readers ignore.
pub const TURN_KEY: &str = "_ov_turn";

/// Most a stored free turn's length may differ from 1 (it is normalized).
const TURN_LENGTH_SLACK: f64 = 1e-6;

/// Parses a keyframe's `_r`, `_t` and free turn `_ov_turn`.
pub fn parse_pose(attributes: &Attributes, node: u32) -> Result<Pose, GraphError> {
    let transform = parse_transform(attributes, node)?;
    let Some(text) = attributes.get(TURN_KEY) else { return Ok(Pose { transform, turn: None }) };
    let bad = || GraphError::Bad(format!("node {node} has a malformed turn {TURN_KEY}={text:?}"));
    let parts: Vec<f64> =
        text.split_ascii_whitespace().map(|p| p.parse::<f64>().map_err(|_| bad())).collect::<Result<_, _>>()?;
    let [x, y, z, w] = parts[..] else { return Err(bad()) };
    let q = glam::DQuat::from_xyzw(x, y, z, w);
    if !q.is_finite() || (q.length() - 1.0).abs() > TURN_LENGTH_SLACK {
        return Err(bad());
    }
    Ok(Pose { transform, turn: Some(Turn(q.normalize())) })
}

/// Writes a pose back: `_r` and `_t` ([`write_transform`]) and the free
/// turn, exactly (Rust prints the shortest text that reads back the same
/// number), or no `_ov_turn` without one.
pub fn write_pose(attributes: &mut Attributes, pose: &Pose) {
    write_transform(attributes, pose.transform);
    match pose.turn {
        Some(Turn(q)) => attributes.insert(TURN_KEY.to_owned(), format!("{} {} {} {}", q.x, q.y, q.z, q.w)),
        None => attributes.remove(TURN_KEY),
    };
}

/// Writes a transform back as `_r` and `_t` into a keyframe's attributes
/// (leaving `_r` out for the identity, as MagicaVoxel does).
pub fn write_transform(attributes: &mut Attributes, transform: Transform) {
    let [x, y, z] = transform.translation;
    attributes.insert("_t".to_owned(), format!("{x} {y} {z}"));
    if transform.rotation == Rotation::IDENTITY {
        attributes.remove("_r");
    } else {
        attributes.insert("_r".to_owned(), transform.rotation.to_byte().to_string());
    }
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

    fn transform(id: u32, child: u32, layer: u32, name: &str) -> Node {
        let mut attributes = Attributes::new();
        if !name.is_empty() {
            attributes.insert("_name".into(), name.into());
        }
        Node { id, attributes, kind: NodeKind::Transform { child, reserved: u32::MAX, layer, frames: vec![] } }
    }

    fn shape(id: u32, model: u32) -> Node {
        Node { id, attributes: Attributes::new(), kind: NodeKind::Shape { models: vec![(model, Attributes::new())] } }
    }

    /// Paths name the named transforms on the way; a hidden layer hides what
    /// is on it; the outline puts a group's objects below it.
    #[test]
    fn objects_carry_paths_layers_and_hidden_flags() {
        let hidden_layer = Layer { id: 1, attributes: [("_hidden".into(), "1".into())].into(), reserved: u32::MAX };
        let graph = SceneGraph {
            nodes: vec![
                transform(0, 1, u32::MAX, ""),
                Node { id: 1, attributes: Attributes::new(), kind: NodeKind::Group { children: vec![2, 6] } },
                transform(2, 3, 0, "house"),
                Node { id: 3, attributes: Attributes::new(), kind: NodeKind::Group { children: vec![4] } },
                transform(4, 5, 1, "door"),
                shape(5, 0),
                transform(6, 5, 0, ""),
            ],
            layers: vec![hidden_layer],
            ..SceneGraph::default()
        };
        let walked = graph.walk(&[10], 0, 100).unwrap();
        let seen: Vec<(String, bool, Option<u32>)> =
            walked.objects.iter().map(|o| (path_of(&graph, &walked.names, o.name), o.hidden, o.layer)).collect();
        assert_eq!(seen, [("house/door".to_owned(), true, Some(1)), (String::new(), false, Some(0))]);
        let house = OutlineRow::Group { transform: 2, depth: 0, hidden: false };
        let rows = [house, OutlineRow::Object { index: 0, depth: 1 }, OutlineRow::Object { index: 1, depth: 0 }];
        assert_eq!(graph.walk(&[10], 0, 100).unwrap().outline, rows, "the outline nests the door in the house");
        assert_eq!(graph.objects(&[10], 0, 15).unwrap_err(), GraphError::TooManyVoxels { limit: 15, found: 20 });
    }

    /// A chain 100,000 transforms deep walks without overflowing the stack or
    /// copying its path at every level.
    #[test]
    fn a_very_deep_chain_is_walked() {
        let depth = 100_000u32;
        let mut nodes: Vec<Node> = (0..depth).map(|i| transform(i, i + 1, u32::MAX, "n")).collect();
        nodes.push(shape(depth, 0));
        let graph = SceneGraph { nodes, layers: vec![], ..SceneGraph::default() };
        let walked = graph.walk(&[1], 0, 10).unwrap();
        assert_eq!(walked.objects.len(), 1);
        assert_eq!(path_of(&graph, &walked.names, walked.objects[0].name).len(), 2 * depth as usize - 1);
    }
}
