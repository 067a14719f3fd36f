//! Saving: the octree → version-200 `.vox` with a scene graph, written one
//! model at a time so that memory stays at one 256³ block whatever the scene.

use std::io::{Seek, SeekFrom, Write};
use std::path::Path;

use glam::IVec3;

use super::validate::MAX_MODEL_EDGE;
use super::{MAX_FILE_BYTES, MAX_VOXELS, VoxError};
use super::{chunk, stored};
use crate::io::atomic::{WriteOptions, write_atomically};
use crate::scene::anim::Animation;
use crate::scene::graph::{Attributes, Node, NodeKind, SceneGraph};
use crate::scene::objects::Objects;
use crate::scene::{Material, Octree, Palette, Voxel};

/// Level of the octree cells that become one model: 2^8 = 256 voxels, the
/// largest model edge MagicaVoxel reads.
const BLOCK_LEVEL: u32 = 8;
const _: () = assert!(1 << BLOCK_LEVEL == MAX_MODEL_EDGE);

/// Bytes of a chunk header: id, content size, children size.
const CHUNK_HEADER_BYTES: u64 = 12;

/// Encodes `voxels` (world positions, y up; palette indices 1..=255) and
/// `palette` in memory, as [`write_vox`] does; where two voxels share a
/// position, the later wins.
///
/// # Errors
/// [`VoxError::Unsavable`] for a voxel with palette index 0 (empty), a scene
/// wider than the octree holds, or one octovox could not read back.
pub fn encode_vox(palette: &Palette, voxels: &[Voxel]) -> Result<Vec<u8>, VoxError> {
    let tree = tree_of(voxels)?;
    check_savable(&tree)?;
    let mut bytes = std::io::Cursor::new(Vec::new());
    write_vox(&mut bytes, palette, &tree).map_err(|e| match e {
        WriteError::Vox(e) => e,
        WriteError::Io(e) => VoxError::Unsavable(e.to_string()),
    })?;
    Ok(bytes.into_inner())
}

/// Saves `voxels` like [`encode_vox`] to `path`, atomically (see [`save_tree`]).
///
/// # Errors
/// As [`encode_vox`] and [`save_tree`].
pub fn save_vox(path: &Path, palette: &Palette, voxels: &[Voxel]) -> Result<(), VoxError> {
    save_tree(path, palette, &tree_of(voxels)?, WriteOptions::default())
}

fn tree_of(voxels: &[Voxel]) -> Result<Octree, VoxError> {
    if let Some((p, _)) = voxels.iter().find(|(_, index)| *index == 0) {
        return Err(VoxError::Unsavable(format!(
            "the voxel at ({}, {}, {}) has palette index 0, which means empty",
            p.x, p.y, p.z
        )));
    }
    Octree::from_voxels(voxels).map_err(|e| VoxError::Unsavable(e.to_string()))
}

/// Writes the scene to `path` through a temporary file that replaces it only
/// when complete (`crate::io::atomic`): a failed save never destroys the
/// previous file, symlinks are followed, devices and FIFOs are refused.
///
/// # Errors
/// [`VoxError::Unsavable`] before anything is written when the scene cannot
/// be read back by octovox; [`VoxError::Write`] naming `path` otherwise.
pub fn save_tree(path: &Path, palette: &Palette, tree: &Octree, options: WriteOptions) -> Result<(), VoxError> {
    check_savable(tree)?;
    write_atomically(path, options, |file| {
        let mut out = std::io::BufWriter::new(file);
        write_vox(&mut out, palette, tree)?;
        out.flush()?;
        Ok(())
    })
    .map_err(|e| match e {
        WriteError::Vox(e) => e,
        WriteError::Io(source) => VoxError::Write { path: path.to_owned(), source },
    })
}

/// What can go wrong while writing: the scene, or the output.
#[derive(Debug)]
enum WriteError {
    Vox(VoxError),
    Io(std::io::Error),
}

impl From<std::io::Error> for WriteError {
    fn from(e: std::io::Error) -> WriteError {
        WriteError::Io(e)
    }
}

/// A file octovox would refuse to load is never written.
fn check_savable(tree: &Octree) -> Result<(), VoxError> {
    let voxels = tree.solid_voxels();
    if voxels > MAX_VOXELS as u64 {
        return Err(VoxError::Unsavable(format!(
            "the scene holds {voxels} voxels; a .vox file octovox can read back holds at most {MAX_VOXELS}"
        )));
    }
    Ok(())
}

/// Writes a version-200 `.vox` file that MagicaVoxel opens: one model per
/// non-empty 256³ cell of the octree (cropped to its voxels), a scene graph
/// (root nTRN → nGRP → for each model an nTRN with a `_t` translation →
/// nSHP), a layer, the RGBA palette and a MATL chunk for every palette entry
/// whose material is not plain diffuse (parameters kept verbatim, in key
/// order, so the same scene always gives the same bytes). An empty scene is
/// written as one empty 1×1×1 model. Callers have run [`check_savable`].
fn write_vox<W: Write + Seek>(out: &mut W, palette: &Palette, tree: &Octree) -> Result<(), WriteError> {
    out.write_all(b"VOX ")?;
    out.write_all(&200u32.to_le_bytes())?;
    let main_at = out.stream_position()?;
    write_chunk(out, b"MAIN", &[], 0)?;
    let mut translations = Vec::new();
    for (min, word, level) in tree.blocks(BLOCK_LEVEL) {
        let block = Block::collect(tree, min, word, level);
        translations.push(block.translation().map_err(WriteError::Vox)?);
        block.write(out)?;
    }
    if translations.is_empty() {
        write_chunk(out, b"SIZE", &[1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0], 0)?;
        write_chunk(out, b"XYZI", &0u32.to_le_bytes(), 0)?;
        translations.push([0, 0, 0]);
    }
    write_scene_graph(out, &translations)?;
    write_chunk(out, b"LAYR", &layer_chunk(), 0)?;
    write_chunk(out, b"RGBA", &rgba_chunk(palette), 0)?;
    for (id, material) in materials(palette) {
        let mut chunk = id.to_le_bytes().to_vec();
        write_dict(&mut chunk, material.iter().map(|(k, v)| (k.as_str(), v.as_str())));
        write_chunk(out, b"MATL", &chunk, 0)?;
    }
    let end = out.stream_position()?;
    let children = end - main_at - CHUNK_HEADER_BYTES;
    if end > MAX_FILE_BYTES {
        return Err(WriteError::Vox(VoxError::Unsavable(format!(
            "the file would be {end} bytes; octovox reads .vox files of at most {MAX_FILE_BYTES}"
        ))));
    }
    out.seek(SeekFrom::Start(main_at + 8))?;
    out.write_all(&u32::try_from(children).unwrap_or(u32::MAX).to_le_bytes())?;
    out.seek(SeekFrom::Start(end))?;
    Ok(())
}

fn write_chunk<W: Write>(out: &mut W, id: &[u8; 4], content: &[u8], children: u32) -> std::io::Result<()> {
    out.write_all(id)?;
    out.write_all(&u32::try_from(content.len()).unwrap_or(u32::MAX).to_le_bytes())?;
    out.write_all(&children.to_le_bytes())?;
    out.write_all(content)
}

/// A chunk appended to bytes in memory.
fn push_chunk(out: &mut Vec<u8>, id: &[u8; 4], content: &[u8], children: u32) {
    out.extend_from_slice(id);
    out.extend_from_slice(&u32::try_from(content.len()).unwrap_or(u32::MAX).to_le_bytes());
    out.extend_from_slice(&children.to_le_bytes());
    out.extend_from_slice(content);
}

fn write_string(buffer: &mut Vec<u8>, text: &str) {
    buffer.extend_from_slice(&u32::try_from(text.len()).unwrap_or(u32::MAX).to_le_bytes());
    buffer.extend_from_slice(text.as_bytes());
}

fn write_dict<'a>(buffer: &mut Vec<u8>, entries: impl ExactSizeIterator<Item = (&'a str, &'a str)>) {
    buffer.extend_from_slice(&u32::try_from(entries.len()).unwrap_or(u32::MAX).to_le_bytes());
    for (key, value) in entries {
        write_string(buffer, key);
        write_string(buffer, value);
    }
}

/// One model: the voxels of one octree cell of at most 256³, in
/// MagicaVoxel's axes, cropped to their bounds.
struct Block {
    /// Scene position (MagicaVoxel axes) of the model's voxel (0, 0, 0).
    origin: [i64; 3],
    size: [u32; 3],
    /// x, y, z, palette index, as XYZI stores them.
    voxels: Vec<[u8; 4]>,
}

impl Block {
    fn collect(tree: &Octree, min: IVec3, word: u32, level: u32) -> Block {
        let mut lo = [i64::MAX; 3];
        let mut hi = [i64::MIN; 3];
        tree.visit_cells(word, min, level, &mut |cell, size, _| {
            // The cell's corners in scene axes; world z flips into scene −y.
            for corner in [to_scene(cell), to_scene(cell + IVec3::splat(size - 1))] {
                for i in 0..3 {
                    lo[i] = lo[i].min(corner[i]);
                    hi[i] = hi[i].max(corner[i]);
                }
            }
        });
        let mut voxels = Vec::new();
        tree.visit_cells(word, min, level, &mut |cell, size, index| {
            for z in 0..size {
                for y in 0..size {
                    for x in 0..size {
                        let p = to_scene(cell + IVec3::new(x, y, z));
                        // A block spans at most 256 positions per axis, so
                        // every offset fits in a byte.
                        let offset = |i: usize| u8::try_from(p[i] - lo[i]).unwrap_or(u8::MAX);
                        voxels.push([offset(0), offset(1), offset(2), index]);
                    }
                }
            }
        });
        let edge = |i: usize| u32::try_from(hi[i] - lo[i] + 1).unwrap_or(MAX_MODEL_EDGE);
        Block { origin: lo, size: [edge(0), edge(1), edge(2)], voxels }
    }

    /// The nTRN translation that puts model voxel `v` at `origin + v`: the
    /// loader places it at `v − size / 2 + t`.
    fn translation(&self) -> Result<[i32; 3], VoxError> {
        let t = [0, 1, 2].map(|axis| self.origin[axis] + i64::from(self.size[axis] / 2));
        let fit = |c: i64| {
            i32::try_from(c)
                .map_err(|_| VoxError::Unsavable(format!("a model would sit at {c}, outside the 32-bit range")))
        };
        Ok([fit(t[0])?, fit(t[1])?, fit(t[2])?])
    }

    fn write<W: Write>(&self, out: &mut W) -> std::io::Result<()> {
        let size: Vec<u8> = self.size.iter().flat_map(|s| s.to_le_bytes()).collect();
        write_chunk(out, b"SIZE", &size, 0)?;
        let count = u32::try_from(self.voxels.len()).unwrap_or(u32::MAX);
        out.write_all(b"XYZI")?;
        out.write_all(&(4 + count * 4).to_le_bytes())?;
        out.write_all(&0u32.to_le_bytes())?;
        out.write_all(&count.to_le_bytes())?;
        out.write_all(self.voxels.as_flattened())
    }
}

/// World (x, y, z) → MagicaVoxel scene (x, −z, y): the inverse of the loader's
/// (x, y, z) → (x, z, −y).
fn to_scene(p: IVec3) -> [i64; 3] {
    [i64::from(p.x), -i64::from(p.z), i64::from(p.y)]
}

/// Root nTRN (0) → nGRP (1) → per model k: nTRN (2 + 2k) → nSHP (3 + 2k).
fn write_scene_graph<W: Write>(out: &mut W, translations: &[[i32; 3]]) -> std::io::Result<()> {
    let node_id = |k: usize, offset: usize| u32::try_from(2 + 2 * k + offset).unwrap_or(u32::MAX);
    write_chunk(out, b"nTRN", &transform_node(0, 1, u32::MAX, None), 0)?;
    let mut group = 1u32.to_le_bytes().to_vec();
    write_dict(&mut group, std::iter::empty());
    group.extend_from_slice(&u32::try_from(translations.len()).unwrap_or(u32::MAX).to_le_bytes());
    for k in 0..translations.len() {
        group.extend_from_slice(&node_id(k, 0).to_le_bytes());
    }
    write_chunk(out, b"nGRP", &group, 0)?;
    for (k, t) in translations.iter().enumerate() {
        write_chunk(out, b"nTRN", &transform_node(node_id(k, 0), node_id(k, 1), 0, Some(*t)), 0)?;
        let mut shape = node_id(k, 1).to_le_bytes().to_vec();
        write_dict(&mut shape, std::iter::empty());
        shape.extend_from_slice(&1u32.to_le_bytes());
        shape.extend_from_slice(&u32::try_from(k).unwrap_or(u32::MAX).to_le_bytes());
        write_dict(&mut shape, std::iter::empty());
        write_chunk(out, b"nSHP", &shape, 0)?;
    }
    Ok(())
}

/// An nTRN chunk: id, no attributes, child, reserved −1, layer, one frame.
fn transform_node(id: u32, child: u32, layer: u32, translation: Option<[i32; 3]>) -> Vec<u8> {
    let mut chunk = id.to_le_bytes().to_vec();
    write_dict(&mut chunk, std::iter::empty());
    for word in [child, u32::MAX, layer, 1] {
        chunk.extend_from_slice(&word.to_le_bytes());
    }
    match translation {
        Some([x, y, z]) => write_dict(&mut chunk, [("_t", format!("{x} {y} {z}").as_str())].into_iter()),
        None => write_dict(&mut chunk, std::iter::empty()),
    }
    chunk
}

/// Layer 0, named "0".
fn layer_chunk() -> Vec<u8> {
    let mut chunk = 0u32.to_le_bytes().to_vec();
    write_dict(&mut chunk, [("_name", "0")].into_iter());
    chunk.extend_from_slice(&u32::MAX.to_le_bytes());
    chunk
}

/// RGBA entry k is palette index k + 1 (entry 255 is index 0).
fn rgba_chunk(palette: &Palette) -> Vec<u8> {
    (0..256).flat_map(|entry| palette.colors[(entry + 1) % 256]).collect()
}

/// (MagicaVoxel material id, properties in key order) of every palette entry
/// that is not plain diffuse; ids run 1..=256, where 256 is palette index 0.
fn materials(palette: &Palette) -> Vec<(u32, Vec<(String, String)>)> {
    let plain = Material::default();
    let mut out: Vec<(u32, Vec<(String, String)>)> = palette
        .materials
        .iter()
        .take(256)
        .enumerate()
        .filter(|(_, material)| **material != plain)
        .map(|(index, material)| {
            let mut properties: Vec<(String, String)> =
                material.params.iter().map(|(k, v)| (k.clone(), v.clone())).collect();
            properties.push(("_type".to_owned(), material.kind.vox_name().to_owned()));
            properties.sort();
            let id = if index == 0 { 256 } else { u32::try_from(index).unwrap_or(0) };
            (id, properties)
        })
        .collect();
    out.sort_by_key(|(id, _)| *id);
    out
}

/// Saves a scene of objects to `path`, atomically (as [`save_tree`]): every
/// model once, the scene graph, the layers and the kept chunks as loaded,
/// with the palette and materials of the document.
///
/// # Errors
/// [`VoxError::Unsavable`] before anything is written when the scene cannot
/// be written as a `.vox` (a model past 256 voxels a side is cut into
/// pieces, except in a file of animation frames without a scene graph);
/// [`VoxError::Write`] naming `path` otherwise.
pub fn save_objects(path: &Path, palette: &Palette, objects: &Objects, options: WriteOptions) -> Result<(), VoxError> {
    let bytes = encode_objects(palette, objects)?;
    write_atomically(path, options, |file| {
        file.write_all(&bytes)?;
        Ok(())
    })
    .map_err(|source| VoxError::Write { path: path.to_owned(), source })
}

/// The bytes [`save_objects`] writes.
///
/// # Errors
/// As [`save_objects`].
pub fn encode_objects(palette: &Palette, objects: &Objects) -> Result<Vec<u8>, VoxError> {
    let turned = objects.graph.as_ref().map_or_else(Vec::new, |g| stored::turned_models(g, objects.models.len()));
    let (stored, cuts) = stored::layout(&objects.models, &turned);
    let mut children = Vec::new();
    let mut stored_voxels = Vec::with_capacity(stored.len());
    for entry in &stored {
        stored_voxels.push(write_stored(&mut children, entry, &objects.models[entry.model].tree));
    }
    if let Some(graph) = &objects.graph {
        let written = stored::written_graph(graph, &objects.models, &stored, &cuts)?;
        check_loadable(&written, &stored_voxels, objects.frame)?;
        for node in &written.nodes {
            let (id, content) = node_chunk(node);
            push_chunk(&mut children, id, &content, 0);
        }
        for layer in &graph.layers {
            let mut content = layer.id.to_le_bytes().to_vec();
            write_attributes(&mut content, &layer.attributes);
            content.extend_from_slice(&layer.reserved.to_le_bytes());
            push_chunk(&mut children, b"LAYR", &content, 0);
        }
    } else if cuts.iter().any(Option::is_some) {
        return Err(VoxError::Unsavable(
            "a frame of an animation grew past 256 voxels a side: a file without a scene graph cannot hold its pieces"
                .to_owned(),
        ));
    }
    push_chunk(&mut children, b"RGBA", &rgba_chunk(palette), 0);
    for (id, material) in materials(palette) {
        let mut chunk = id.to_le_bytes().to_vec();
        write_dict(&mut chunk, material.iter().map(|(k, v)| (k.as_str(), v.as_str())));
        push_chunk(&mut children, b"MATL", &chunk, 0);
    }
    // A file without a scene graph has no settings of its own: its META goes back as read.
    let animation = objects.graph.as_ref().map(|g| g.animation);
    for kept in &objects.kept {
        match (kept.id, animation) {
            (META, Some(animation)) => {
                push_chunk(&mut children, &META, &meta_content(Some(&kept.content), animation), 0)
            }
            (id, _) => push_chunk(&mut children, &id, &kept.content, 0),
        }
    }
    if let Some(animation) = animation.filter(|a| *a != Animation::default())
        && !objects.kept.iter().any(|k| k.id == META)
    {
        push_chunk(&mut children, &META, &meta_content(None, animation), 0);
    }
    let total = 8 + CHUNK_HEADER_BYTES + children.len() as u64;
    if total > MAX_FILE_BYTES {
        return Err(VoxError::Unsavable(format!(
            "the file would be {total} bytes; octovox reads .vox files of at most {MAX_FILE_BYTES}"
        )));
    }
    let mut out = b"VOX ".to_vec();
    out.extend_from_slice(&200u32.to_le_bytes());
    push_chunk(&mut out, b"MAIN", &[], u32::try_from(children.len()).unwrap_or(u32::MAX));
    out.extend_from_slice(&children);
    Ok(out)
}

const META: [u8; 4] = *b"META";

/// A META chunk's content holding `animation`: the one read, as read, where
/// it says the same; else its dictionary with the settings written in.
fn meta_content(read: Option<&[u8]>, animation: Animation) -> Vec<u8> {
    let mut meta = read.and_then(|content| chunk::content_dict(META, content)).unwrap_or_default();
    if let Some(content) = read
        && Animation::from_meta(&meta).0 == animation
    {
        return content.to_vec();
    }
    animation.write_meta(&mut meta);
    let mut content = Vec::new();
    write_attributes(&mut content, &meta);
    content
}

/// A scene whose placements octovox would refuse to load is not written:
/// the loader's own walk, at frame 0 (what a plain load shows) and at the
/// frame shown now, over the models as written.
fn check_loadable(graph: &SceneGraph, stored_voxels: &[usize], frame: usize) -> Result<(), VoxError> {
    for frame in [0, frame] {
        graph.objects(stored_voxels, frame, MAX_VOXELS).map_err(|e| match VoxError::from(e) {
            VoxError::TooManyVoxels { found, .. } => VoxError::Unsavable(format!(
                "the scene places at least {found} voxels (every reference counted); a .vox file octovox can \
                 read back places at most {MAX_VOXELS} (docs/limits.md): place fewer references"
            )),
            other => VoxError::Unsavable(format!("octovox could not read the file back: {other}")),
        })?;
    }
    Ok(())
}

/// The SIZE and XYZI chunks of one model as written: the cells of `tree` in
/// `entry`'s box, shifted to its grid. Returns how many voxels it holds.
fn write_stored(out: &mut Vec<u8>, entry: &stored::Stored, tree: &Octree) -> usize {
    let size: Vec<u8> = entry.size.iter().flat_map(|s| s.to_le_bytes()).collect();
    push_chunk(out, b"SIZE", &size, 0);
    let hi = entry.lo + IVec3::from_array(entry.size.map(|s| s as i32)) - IVec3::ONE;
    let mut voxels: Vec<[u8; 4]> = Vec::new();
    tree.for_each_solid_cell_in(entry.lo, hi, |min, edge, index| {
        let (a, b) = (min.max(entry.lo), (min + IVec3::splat(edge - 1)).min(hi));
        for z in a.z..=b.z {
            for y in a.y..=b.y {
                for x in a.x..=b.x {
                    // Inside 0..size ≤ 256 by `stored::layout`.
                    let p = IVec3::new(x, y, z) - entry.lo;
                    voxels.push([p.x as u8, p.y as u8, p.z as u8, index]);
                }
            }
        }
    });
    let mut content = u32::try_from(voxels.len()).unwrap_or(u32::MAX).to_le_bytes().to_vec();
    content.extend_from_slice(voxels.as_flattened());
    push_chunk(out, b"XYZI", &content, 0);
    voxels.len()
}

/// An nTRN, nGRP or nSHP chunk's id and content.
fn node_chunk(node: &Node) -> (&'static [u8; 4], Vec<u8>) {
    let mut content = node.id.to_le_bytes().to_vec();
    write_attributes(&mut content, &node.attributes);
    let push = |content: &mut Vec<u8>, n: usize| {
        content.extend_from_slice(&u32::try_from(n).unwrap_or(u32::MAX).to_le_bytes())
    };
    match &node.kind {
        NodeKind::Transform { child, reserved, layer, frames } => {
            for word in [*child, *reserved, *layer] {
                content.extend_from_slice(&word.to_le_bytes());
            }
            push(&mut content, frames.len());
            for frame in frames {
                write_attributes(&mut content, frame);
            }
            (b"nTRN", content)
        }
        NodeKind::Group { children } => {
            push(&mut content, children.len());
            for child in children {
                content.extend_from_slice(&child.to_le_bytes());
            }
            (b"nGRP", content)
        }
        NodeKind::Shape { models } => {
            push(&mut content, models.len());
            for (model, attributes) in models {
                content.extend_from_slice(&model.to_le_bytes());
                write_attributes(&mut content, attributes);
            }
            (b"nSHP", content)
        }
    }
}

fn write_attributes(buffer: &mut Vec<u8>, attributes: &Attributes) {
    write_dict(buffer, attributes.iter().map(|(k, v)| (k.as_str(), v.as_str())));
}
