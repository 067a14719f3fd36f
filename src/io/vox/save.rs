//! Saving: world voxels → version-200 `.vox` with a scene graph.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

use dot_vox::{Color, Dict, DotVoxData, Frame, Layer, Model, SceneNode, ShapeModel, Size};
use glam::IVec3;

use super::VoxError;
use super::load::sort_and_dedup;
use super::validate::MAX_MODEL_EDGE;
use crate::scene::{Material, Palette, Voxel};

/// Encodes `voxels` (world positions, y up; palette indices 1..=255) and
/// `palette` as a version-200 `.vox` file that MagicaVoxel opens.
///
/// The file holds an RGBA palette, a MATL chunk for every palette entry whose
/// material is not plain diffuse (parameters kept verbatim), and a scene
/// graph: root nTRN → nGRP → for each model an nTRN with a `_t` translation →
/// nSHP. Scenes wider than 256 voxels on an axis are cut into models of at most
/// 256³ so nothing is lost. Where two voxels share a position, the later wins.
/// An empty scene is written as one empty 1×1×1 model.
///
/// # Errors
/// [`VoxError::Unsavable`] for a voxel with palette index 0 (empty) or a model
/// whose translation does not fit MagicaVoxel's 32-bit range.
pub fn encode_vox(palette: &Palette, voxels: &[Voxel]) -> Result<Vec<u8>, VoxError> {
    let blocks = split_into_blocks(voxels)?;
    let mut models = Vec::with_capacity(blocks.len().max(1));
    let mut translations = Vec::with_capacity(blocks.len().max(1));
    for block in blocks {
        translations.push(block.translation()?);
        models.push(block.model);
    }
    if models.is_empty() {
        models.push(Model { size: Size { x: 1, y: 1, z: 1 }, voxels: Vec::new() });
        translations.push([0, 0, 0]);
    }
    let data = DotVoxData {
        version: 200,
        index_map: dot_vox::DEFAULT_INDEX_MAP.to_vec(),
        models,
        palette: rgba_chunk(palette),
        materials: matl_chunks(palette),
        scenes: scene_graph(&translations),
        layers: vec![Layer { attributes: dict([("_name", "0".to_owned())]) }],
    };
    let mut bytes = Vec::new();
    data.write_vox(&mut bytes).map_err(|e| VoxError::Unsavable(e.to_string()))?;
    Ok(bytes)
}

/// Encodes the scene like [`encode_vox`] and writes it to `path` atomically:
/// the bytes go to a temporary file in the same directory, which then replaces
/// `path`, so a failed save never destroys the previous file.
///
/// # Errors
/// As [`encode_vox`], plus [`VoxError::Write`] naming `path` when the
/// temporary file cannot be created, written or renamed.
pub fn save_vox(path: &Path, palette: &Palette, voxels: &[Voxel]) -> Result<(), VoxError> {
    let bytes = encode_vox(palette, voxels)?;
    write_atomically(path, &bytes)
}

fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), VoxError> {
    let write_error = |source| VoxError::Write { path: path.to_owned(), source };
    let dir = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".octovox-save-").suffix(".tmp");
    // tempfile creates files readable by the owner only; give the saved file
    // the permissions of the file it replaces, or the usual rw-r--r--.
    let permissions = match std::fs::metadata(path) {
        Ok(meta) => Some(meta.permissions()),
        Err(_) => default_permissions(),
    };
    if let Some(permissions) = permissions {
        builder.permissions(permissions);
    }
    let mut file = builder.tempfile_in(dir).map_err(write_error)?;
    file.write_all(bytes).map_err(write_error)?;
    file.as_file().sync_all().map_err(write_error)?;
    file.persist(path).map_err(|e| write_error(e.error))?;
    Ok(())
}

#[cfg(unix)]
fn default_permissions() -> Option<std::fs::Permissions> {
    use std::os::unix::fs::PermissionsExt;
    Some(std::fs::Permissions::from_mode(0o644))
}

#[cfg(not(unix))]
fn default_permissions() -> Option<std::fs::Permissions> {
    None
}

/// Up to 256³ voxels that become one model.
struct Block {
    /// Scene position (MagicaVoxel axes) of the model's voxel (0, 0, 0).
    origin: [i64; 3],
    model: Model,
}

impl Block {
    /// The nTRN translation that puts model voxel `v` at `origin + v`: the
    /// loader places it at `v − size / 2 + t`.
    fn translation(&self) -> Result<[i32; 3], VoxError> {
        let size = [self.model.size.x, self.model.size.y, self.model.size.z];
        let t = [0, 1, 2].map(|axis| self.origin[axis] + i64::from(size[axis] / 2));
        let fit = |c: i64| {
            i32::try_from(c)
                .map_err(|_| VoxError::Unsavable(format!("a model would sit at {c}, outside the 32-bit range")))
        };
        Ok([fit(t[0])?, fit(t[1])?, fit(t[2])?])
    }
}

/// World (x, y, z) → MagicaVoxel scene (x, −z, y): the inverse of the loader's
/// (x, y, z) → (x, z, −y).
fn to_scene(p: IVec3) -> [i64; 3] {
    [i64::from(p.x), -i64::from(p.z), i64::from(p.y)]
}

/// Groups the voxels into 256-aligned cells of the scene's bounding box and
/// makes each non-empty cell a model cropped to its own voxels.
fn split_into_blocks(voxels: &[Voxel]) -> Result<Vec<Block>, VoxError> {
    if let Some((p, _)) = voxels.iter().find(|(_, index)| *index == 0) {
        return Err(VoxError::Unsavable(format!(
            "the voxel at ({}, {}, {}) has palette index 0, which means empty",
            p.x, p.y, p.z
        )));
    }
    let mut unique = voxels.to_vec();
    sort_and_dedup(&mut unique);
    let scene: Vec<([i64; 3], u8)> = unique.iter().map(|&(p, index)| (to_scene(p), index)).collect();
    let Some(low) = scene.iter().map(|(p, _)| *p).reduce(|a, b| [0, 1, 2].map(|i| a[i].min(b[i]))) else {
        return Ok(Vec::new());
    };
    let edge = i64::from(MAX_MODEL_EDGE);
    let mut cells: BTreeMap<[i64; 3], Vec<([i64; 3], u8)>> = BTreeMap::new();
    for &(p, index) in &scene {
        let key = [0, 1, 2].map(|i| (p[i] - low[i]) / edge);
        cells.entry(key).or_default().push((p, index));
    }
    Ok(cells.into_values().map(|cell| crop_block(&cell)).collect())
}

fn crop_block(cell: &[([i64; 3], u8)]) -> Block {
    let mut lo = [i64::MAX; 3];
    let mut hi = [i64::MIN; 3];
    for (p, _) in cell {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    // A cell spans at most 256 positions per axis, so every offset and edge
    // fits in u8 and u32 (the conversions below cannot fail).
    let edge = |i: usize| u32::try_from(hi[i] - lo[i] + 1).unwrap_or(MAX_MODEL_EDGE);
    let offset = |p: &[i64; 3], i: usize| u8::try_from(p[i] - lo[i]).unwrap_or(u8::MAX);
    let voxels = cell
        .iter()
        .map(|(p, index)| dot_vox::Voxel {
            x: offset(p, 0),
            y: offset(p, 1),
            z: offset(p, 2),
            // dot_vox writes `i + 1`; indices here are 1..=255, so 255 → 254 → 255.
            i: index - 1,
        })
        .collect();
    let size = Size { x: edge(0), y: edge(1), z: edge(2) };
    Block { origin: lo, model: Model { size, voxels } }
}

/// dot_vox's palette entry k is palette index k + 1 (entry 255 is index 0).
fn rgba_chunk(palette: &Palette) -> Vec<Color> {
    (0..256)
        .map(|entry| {
            let [r, g, b, a] = palette.colors[(entry + 1) % 256];
            Color { r, g, b, a }
        })
        .collect()
}

fn matl_chunks(palette: &Palette) -> Vec<dot_vox::Material> {
    let plain = Material::default();
    palette
        .materials
        .iter()
        .take(256)
        .enumerate()
        .filter(|(_, material)| **material != plain)
        .map(|(index, material)| {
            let mut properties: Dict = material.params.iter().map(|(k, v)| (k.clone(), v.clone())).collect();
            properties.insert("_type".to_owned(), material.kind.vox_name().to_owned());
            // MagicaVoxel numbers materials 1..=256; 256 stands for index 0.
            let id = if index == 0 { 256 } else { u32::try_from(index).unwrap_or(0) };
            dot_vox::Material { id, properties }
        })
        .collect()
}

/// Root nTRN (0) → nGRP (1) → per model k: nTRN (2 + 2k) → nSHP (3 + 2k).
/// dot_vox writes each node with its index in this list as its id.
fn scene_graph(translations: &[[i32; 3]]) -> Vec<SceneNode> {
    let node_id = |k: usize, offset: usize| u32::try_from(2 + 2 * k + offset).unwrap_or(u32::MAX);
    let mut nodes = vec![
        SceneNode::Transform {
            attributes: Dict::default(),
            frames: vec![Frame::new(Dict::default())],
            child: 1,
            layer_id: u32::MAX,
        },
        SceneNode::Group {
            attributes: Dict::default(),
            children: (0..translations.len()).map(|k| node_id(k, 0)).collect(),
        },
    ];
    for (k, t) in translations.iter().enumerate() {
        let frame = dict([("_t", format!("{} {} {}", t[0], t[1], t[2]))]);
        nodes.push(SceneNode::Transform {
            attributes: Dict::default(),
            frames: vec![Frame::new(frame)],
            child: node_id(k, 1),
            layer_id: 0,
        });
        nodes.push(SceneNode::Shape {
            attributes: Dict::default(),
            models: vec![ShapeModel { model_id: u32::try_from(k).unwrap_or(u32::MAX), attributes: Dict::default() }],
        });
    }
    nodes
}

fn dict<const N: usize>(entries: [(&str, String); N]) -> Dict {
    entries.into_iter().map(|(k, v)| (k.to_owned(), v)).collect()
}
