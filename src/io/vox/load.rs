//! Loading: pre-pass, guarded `dot_vox` parse, scene placement, axis change.

use std::collections::{BTreeMap, HashSet};
use std::path::Path;

use dot_vox::DotVoxData;
use glam::IVec3;

use super::validate::{self, Layout};
use super::{MAX_FILE_BYTES, MAX_VOXELS, VoxError};
use crate::io::guard::catch_quietly;
use crate::io::input::{InputError, read_limited};
use crate::scene::graph::Object;
use crate::scene::objects::{Model, Objects};
use crate::scene::octree::WORLD_LIMIT;
use crate::scene::transform::Placement;
use crate::scene::{Material, MaterialKind, Octree, Palette, Scene, Voxel, VoxelModel};

/// Reads and loads the `.vox` file at `path`; see [`load_vox`].
///
/// # Errors
/// [`VoxError::Read`] (naming the path) when the file cannot be read,
/// [`VoxError::FileTooLarge`] beyond [`MAX_FILE_BYTES`], else as [`load_vox`].
pub fn load_vox_file(path: &Path, frame: usize) -> Result<VoxelModel, VoxError> {
    load_vox(&read_file(path)?, frame)
}

/// Reads the `.vox` file at `path` into an octree; see [`load_vox_scene`].
///
/// # Errors
/// As [`load_vox_file`].
pub fn load_vox_scene_file(path: &Path, frame: usize) -> Result<(Scene, VoxMeta), VoxError> {
    load_vox_scene(&read_file(path)?, frame)
}

fn read_file(path: &Path) -> Result<Vec<u8>, VoxError> {
    read_limited(path, MAX_FILE_BYTES).map_err(|e| match e {
        InputError::Io(source) => VoxError::Read { path: path.to_owned(), source },
        InputError::NotRegular => VoxError::NotRegular { path: path.to_owned() },
        InputError::TooLarge { .. } => VoxError::FileTooLarge { path: path.to_owned() },
    })
}

/// Loads a MagicaVoxel `.vox` file held in memory.
///
/// Files with a scene graph (nTRN/nGRP/nSHP) are placed by walking it from
/// node 0; hidden objects and objects on hidden layers are left out, as
/// MagicaVoxel draws them; `frame`
/// picks the keyframe where transforms or shapes are animated (`_f`). Files
/// without one hold either one model or animation frames (several models,
/// PACK), of which model `frame` is loaded as is, in its own grid.
/// Positions are in octovox world axes (y up): scene (x, y, z) → (x, z, −y).
/// Voxels are sorted by position; where two placements overlap, the later one
/// in the scene graph wins.
///
/// # Errors
/// Any malformed or hostile input gives a [`VoxError`] naming the problem;
/// nothing in the file can make this panic or allocate much more than the
/// scene it describes (at most [`super::MAX_VOXELS`] voxels).
pub fn load_vox(bytes: &[u8], frame: usize) -> Result<VoxelModel, VoxError> {
    let parsed = parse(bytes, frame)?;
    let voxels = place_voxels(&parsed)?;
    let (palette, meta) = parsed.palette_and_meta();
    Ok(VoxelModel { palette, voxels, models: meta.models, stored_models: meta.stored_models, warnings: meta.warnings })
}

/// What a load says beside the voxels.
#[derive(Clone, Debug, Default)]
pub struct VoxMeta {
    /// Models placed, and models stored in the file.
    pub models: usize,
    pub stored_models: usize,
    /// What the loader accepted but the user should know, one sentence each.
    pub warnings: Vec<String>,
}

/// Loads a `.vox` file held in memory straight into an octree, one placed
/// model at a time: the same voxels as [`load_vox`] then
/// `Scene::from_model`, without ever holding the list of every voxel.
///
/// A file of several models or objects, with a hidden one, a scene graph
/// that says more than where its model is, or chunks octovox does not read
/// becomes a scene of objects (`Scene::objects`): its models, scene graph,
/// layers and those chunks are kept, and saving writes them back. Only a
/// bare model (as octovox writes one) loads as one model.
///
/// # Errors
/// As [`load_vox`].
pub fn load_vox_scene(bytes: &[u8], frame: usize) -> Result<(Scene, VoxMeta), VoxError> {
    load_scene_as(bytes, frame, false)
}

/// [`load_vox_scene`], keeping the objects whatever the file is: what an
/// .ovx's objects section is read with (a scene of objects saved it, even
/// one whose graph has become plain).
///
/// # Errors
/// As [`load_vox`].
pub fn load_vox_objects(bytes: &[u8], frame: usize) -> Result<(Scene, VoxMeta), VoxError> {
    load_scene_as(bytes, frame, true)
}

fn load_scene_as(bytes: &[u8], frame: usize, keep_objects: bool) -> Result<(Scene, VoxMeta), VoxError> {
    let parsed = parse(bytes, frame)?;
    let visible = || parsed.objects.iter().filter(|o| !o.hidden).map(|o| &o.placement);
    let largest = visible().map(|p| parsed.layout.model_voxels[p.model]).max().unwrap_or(0);
    let total: usize = visible().map(|p| parsed.layout.model_voxels[p.model]).sum();
    let stored: usize = parsed.layout.model_voxels.iter().sum();
    crate::budget::check(
        || format!("loading {total} voxels"),
        largest as u64 * BYTES_PER_STREAMED_VOXEL + (total + stored) as u64 * POOL_BYTES_PER_VOXEL,
    )?;
    let (palette, meta) = parsed.palette_and_meta();
    if keep_objects || parsed.keeps_objects() {
        let objects = parsed.into_objects(frame)?;
        let scene = Scene::compose(palette, objects).map_err(|e| VoxError::BadSceneGraph(e.to_string()))?;
        return Ok((scene, meta));
    }
    // The bounds first, so the root is placed as a build from the whole list places it.
    let mut bounds: Option<(IVec3, IVec3)> = None;
    for placement in visible() {
        for voxel in parsed.placed(placement) {
            let p = voxel?.0;
            bounds = Some(crate::scene::grow_bounds(bounds, p));
        }
    }
    let mut tree = match bounds {
        Some((lo, hi)) => Octree::empty_for(lo, hi).map_err(|e| VoxError::BadSceneGraph(e.to_string()))?,
        None => Octree::default(),
    };
    for placement in visible() {
        let voxels: Vec<Voxel> = parsed.placed(placement).collect::<Result<_, _>>()?;
        tree.insert_voxels(&voxels);
    }
    Ok((Scene::new(palette, tree), meta))
}

/// A file parsed and checked, with its model placements.
struct Parsed {
    data: DotVoxData,
    layout: Layout,
    /// Every object, hidden ones included, in walk order.
    objects: Vec<Object>,
    /// (model, ordinal) of voxels with palette index 0, which are skipped.
    empty: HashSet<(usize, usize)>,
}

fn parse(bytes: &[u8], frame: usize) -> Result<Parsed, VoxError> {
    let layout = validate::check(bytes)?;
    let data = parse_guarded(bytes)?;
    cross_check(&layout, &data)?;
    let objects = if data.scenes.is_empty() {
        frame_objects(data.models.len(), frame)?
    } else {
        layout.graph.check_keys()?;
        layout.graph.objects(&layout.model_voxels, frame, MAX_VOXELS)?
    };
    let empty = layout.zero_index_voxels.iter().copied().collect();
    Ok(Parsed { data, layout, objects, empty })
}

impl Parsed {
    /// The voxels of one placement in world axes, in file order.
    fn placed<'a>(&'a self, placement: &'a Placement) -> impl Iterator<Item = Result<Voxel, VoxError>> + 'a {
        let model = &self.data.models[placement.model];
        let size = [model.size.x, model.size.y, model.size.z];
        model
            .voxels
            .iter()
            .enumerate()
            .filter(move |(ordinal, _)| !self.empty.contains(&(placement.model, *ordinal)))
            .map(move |(_, v)| {
                let [x, y, z] = placement.place([v.x, v.y, v.z], size);
                let world = to_world([x, z, -y]).ok_or_else(|| {
                    VoxError::BadSceneGraph(format!(
                        "a voxel of model {} lands at ({x}, {y}, {z}) (MagicaVoxel's axes), past the coordinate \
                         limit ±{WORLD_LIMIT} (±2^24) that edits and rendering keep exact",
                        placement.model
                    ))
                })?;
                // `dot_vox` stores the file's index minus one; 0 was skipped above.
                Ok((world, v.i.saturating_add(1)))
            })
    }

    fn palette_and_meta(&self) -> (Palette, VoxMeta) {
        let mut warnings = self.layout.warnings.clone();
        let palette = palette_of(&self.data, &self.layout, &mut warnings);
        let meta = VoxMeta { models: self.objects.len(), stored_models: self.data.models.len(), warnings };
        (palette, meta)
    }

    /// Whether the file is more than one bare model: several models or
    /// objects, a hidden one, a scene graph that says more than where the
    /// model is (keys, turns, layers, names, `_loop`: see [`is_plain`]) or
    /// chunks octovox does not read (cameras, render settings, notes).
    /// Then its objects are kept, and saving writes all of it back; a file
    /// of one visible object is still drawn as one octree.
    fn keeps_objects(&self) -> bool {
        self.data.models.len() > 1
            || self.objects.len() > 1
            || self.objects.iter().any(|o| o.hidden)
            || !self.layout.kept.is_empty()
            || !is_plain(&self.layout.graph)
            || !self.tight()
    }

    /// Whether the model's grid is its voxels' box: a bare model is saved
    /// cropped to its voxels, so a grid with empty margins (MagicaVoxel's
    /// box) is kept by keeping the objects.
    fn tight(&self) -> bool {
        self.data.models.iter().all(|model| {
            let (mut lo, mut hi) = ([u8::MAX; 3], [0u8; 3]);
            for v in &model.voxels {
                for (axis, c) in [v.x, v.y, v.z].into_iter().enumerate() {
                    (lo[axis], hi[axis]) = (lo[axis].min(c), hi[axis].max(c));
                }
            }
            let size = [model.size.x, model.size.y, model.size.z];
            model.voxels.is_empty() || (0..3).all(|axis| lo[axis] == 0 && u32::from(hi[axis]) + 1 == size[axis])
        })
    }

    /// The models as octrees in their own grids, the graph and the kept chunks.
    fn into_objects(self, frame: usize) -> Result<Objects, VoxError> {
        let mut models = Vec::with_capacity(self.data.models.len());
        for (m, model) in self.data.models.iter().enumerate() {
            let voxels: Vec<Voxel> = model
                .voxels
                .iter()
                .enumerate()
                .filter(|(ordinal, _)| !self.empty.contains(&(m, *ordinal)))
                .map(|(_, v)| (IVec3::new(v.x.into(), v.y.into(), v.z.into()), v.i.saturating_add(1)))
                .collect();
            let tree = Octree::from_voxels(&voxels).map_err(|e| VoxError::BadSceneGraph(e.to_string()))?;
            models.push(Model { size: [model.size.x, model.size.y, model.size.z], tree });
        }
        let graph = (!self.data.scenes.is_empty()).then_some(self.layout.graph);
        Objects::new(graph, models, self.layout.kept, frame, MAX_VOXELS).map_err(|e| match e {
            crate::scene::objects::ObjectsError::Graph(e) => e.into(),
            other => VoxError::BadSceneGraph(other.to_string()),
        })
    }
}

/// Whether a scene graph says nothing but where its models are: no node
/// attributes (names, `_loop`, hidden), no keys or turns (a single frame
/// holding at most `_t`), one model a shape, and at most one layer, unnamed
/// or named `0`. That is the graph octovox writes for a model (and none at
/// all is plain too): saving the model rewrites it without loss, so such a
/// file loads as one model. Any other graph is kept as the file's.
fn is_plain(graph: &crate::scene::graph::SceneGraph) -> bool {
    use crate::scene::graph::NodeKind;
    let plain_node = |node: &crate::scene::graph::Node| {
        node.attributes.is_empty()
            && match &node.kind {
                NodeKind::Transform { frames, layer, .. } => {
                    frames.len() <= 1
                        && frames.iter().all(|f| f.keys().all(|k| k == "_t"))
                        && (*layer == 0 || *layer == u32::MAX)
                }
                NodeKind::Group { .. } => true,
                NodeKind::Shape { models } => models.len() == 1 && models[0].1.is_empty(),
            }
    };
    let plain_layer =
        |layer: &crate::scene::graph::Layer| layer.attributes.iter().all(|(key, value)| key == "_name" && value == "0");
    graph.layers.len() <= 1 && graph.layers.iter().all(plain_layer) && graph.nodes.iter().all(plain_node)
}

/// Runs `dot_vox::load_bytes`, turning a panic into [`VoxError::ParserPanic`].
///
/// The pre-pass should leave `dot_vox` nothing to panic on; this is the
/// second line of defence.
fn parse_guarded(bytes: &[u8]) -> Result<DotVoxData, VoxError> {
    match catch_quietly(|| dot_vox::load_bytes(bytes)) {
        Ok(parsed) => parsed.map_err(VoxError::Parser),
        Err(panicked) => Err(VoxError::ParserPanic(panicked.0)),
    }
}

/// `dot_vox` must have seen the same models and nodes as the pre-pass, or
/// model and node indices would not line up.
fn cross_check(layout: &Layout, data: &DotVoxData) -> Result<(), VoxError> {
    let model_counts: Vec<usize> = data.models.iter().map(|m| m.voxels.len()).collect();
    if model_counts != layout.model_voxels {
        return Err(VoxError::Inconsistent(format!(
            "dot_vox read {} models, the pre-pass {}",
            model_counts.len(),
            layout.model_voxels.len()
        )));
    }
    if data.scenes.len() != layout.graph.nodes.len() || data.layers.len() != layout.graph.layers.len() {
        return Err(VoxError::Inconsistent(format!(
            "dot_vox read {} scene nodes and {} layers, the pre-pass {} and {}",
            data.scenes.len(),
            data.layers.len(),
            layout.graph.nodes.len(),
            layout.graph.layers.len()
        )));
    }
    if data.version != layout.version {
        return Err(VoxError::Inconsistent("dot_vox read another version".to_owned()));
    }
    Ok(())
}

/// Without a scene graph, `frame` selects one model, placed as stored.
fn frame_objects(models: usize, frame: usize) -> Result<Vec<Object>, VoxError> {
    if models == 0 && frame == 0 {
        return Ok(Vec::new());
    }
    if frame >= models {
        return Err(VoxError::FrameOutOfRange { requested: frame, models });
    }
    Ok(vec![Object::frame(frame)])
}

/// Peak bytes per voxel of a load and the octree build after it: the list
/// (16), its sort, and the build's Morton keys (16 each).
const BYTES_PER_LOADED_VOXEL: u64 = 48;
/// Of a streamed load, per voxel of the largest placed model: its list (16)
/// and its Morton keys (16).
const BYTES_PER_STREAMED_VOXEL: u64 = 32;
/// The pool a streamed load builds, per placed voxel at most (bricks of one
/// solid voxel and their nodes; solid regions cost far less).
const POOL_BYTES_PER_VOXEL: u64 = 8;

/// Every placed voxel in world axes, sorted by position, overlaps resolved.
fn place_voxels(parsed: &Parsed) -> Result<Vec<Voxel>, VoxError> {
    let visible: Vec<&Placement> = parsed.objects.iter().filter(|o| !o.hidden).map(|o| &o.placement).collect();
    let total: usize = visible.iter().map(|p| parsed.layout.model_voxels[p.model]).sum();
    crate::budget::check(|| format!("loading {total} voxels"), total as u64 * BYTES_PER_LOADED_VOXEL)?;
    let mut voxels = Vec::with_capacity(total);
    for placement in visible {
        for voxel in parsed.placed(placement) {
            voxels.push(voxel?);
        }
    }
    sort_and_dedup(&mut voxels);
    Ok(voxels)
}

/// A position in world axes, if it is inside the coordinate limit
/// (what an edit may reach: docs/limits.md).
fn to_world(p: [i64; 3]) -> Option<IVec3> {
    let limit = i64::from(WORLD_LIMIT);
    p.iter().all(|c| -limit < *c && *c < limit).then(|| IVec3::new(p[0] as i32, p[1] as i32, p[2] as i32))
}

/// Sorts by position (x, then y, then z) and keeps the last of equal positions.
pub(super) fn sort_and_dedup(voxels: &mut Vec<Voxel>) {
    voxels.sort_by_key(|(p, _)| (p.x, p.y, p.z));
    voxels.dedup_by(|later, kept| {
        let same = later.0 == kept.0;
        if same {
            kept.1 = later.1;
        }
        same
    });
}

/// Colours from RGBA (or MagicaVoxel's default), materials from MATT then
/// MATL; problems with the materials go to `warnings`.
fn palette_of(data: &DotVoxData, layout: &Layout, warnings: &mut Vec<String>) -> Palette {
    let mut palette = Palette::default_magicavoxel();
    for (entry, color) in data.palette.iter().take(256).enumerate() {
        // Entry k of the RGBA chunk is palette index k + 1; the last is index 0.
        palette.colors[(entry + 1) % 256] = (*color).into();
    }
    let mut materials = vec![Material::default(); 256];
    for (&index, material) in &layout.matt {
        materials[usize::from(index)] = material.clone();
    }
    for matl in &data.materials {
        // MagicaVoxel numbers materials 1..=256, where 256 is palette index 0.
        let index = usize::from(matl.id.to_le_bytes()[0]);
        materials[index] = material_from_properties(index, &matl.properties, warnings);
    }
    palette.materials = materials;
    palette
}

/// A MATL's material; what it holds that octovox cannot use as it is goes
/// to `warnings`, naming the palette index.
fn material_from_properties(index: usize, properties: &dot_vox::Dict, warnings: &mut Vec<String>) -> Material {
    let kind = match properties.get("_type") {
        None => MaterialKind::Diffuse,
        Some(name) => MaterialKind::from_vox_name(name).unwrap_or_else(|| {
            warnings.push(format!("material {index}: type '{name}' is not one octovox renders; treated as diffuse"));
            MaterialKind::Diffuse
        }),
    };
    let params: BTreeMap<String, String> = properties
        .iter()
        .filter(|(key, _)| key.as_str() != "_type")
        .map(|(key, value)| (key.clone(), value.clone()))
        .collect();
    let material = Material { kind, params };
    warnings.extend(material.problems().into_iter().map(|p| format!("material {index}: {p}")));
    material
}
