//! Validating pre-pass over the raw chunk structure of a `.vox` file.
//!
//! `dot_vox` 5.2 checks element counts against the bytes left before it
//! allocates, but it recurses into the children of *any* chunk (a file of
//! nested chunk headers overflows the stack, which `catch_unwind` cannot
//! catch), silently drops chunks it fails to parse (which shifts model and
//! scene-node indices), stops reading at the first chunk id that is not UTF-8,
//! turns a stored colour index 0 into index 1, and accepts any SIZE. This pass
//! rejects all of that with a message naming the chunk and its byte offset, so
//! that what reaches `dot_vox` parses the way we expect. It also collects what
//! `dot_vox` does not keep: scene-node ids, old MATT materials, and voxels
//! stored with colour index 0.

use std::collections::BTreeMap;

use super::VoxError;
use super::chunk::{Chunk, Cursor, le_u32, read_chunk_header, widen};
use crate::scene::anim::Animation;
use crate::scene::graph::{Layer, Node, NodeKind, SceneGraph};
use crate::scene::objects::KeptChunk;
use crate::scene::{Material, MaterialKind};

/// "VOX " plus the version number.
const FILE_HEADER_BYTES: usize = 8;
/// MagicaVoxel's largest model edge, in voxels.
pub(super) const MAX_MODEL_EDGE: u32 = 256;
/// Bytes of an RGBA chunk: 256 colours of 4 bytes.
const PALETTE_BYTES: usize = 1024;

/// What the pre-pass learned about a file it accepted.
#[derive(Debug, Default)]
pub(super) struct Layout {
    /// The file's version (150 or 200).
    pub version: u32,
    /// Number of voxels of each model (XYZI chunk), in file order.
    pub model_voxels: Vec<usize>,
    /// The nTRN/nGRP/nSHP and LAYR chunks, in file order (`dot_vox` drops
    /// node and layer ids, and attribute order is its hash map's).
    pub graph: SceneGraph,
    /// Chunks octovox does not read, in file order, to be written back.
    pub kept: Vec<KeptChunk>,
    /// (model, voxel ordinal) of each voxel stored with colour index 0, which
    /// means "empty"; `dot_vox` would report it as index 1.
    pub zero_index_voxels: Vec<(usize, usize)>,
    /// Materials of old MATT chunks, by palette index.
    pub matt: BTreeMap<u8, Material>,
    /// Oddities that do not stop the load (bytes that are ignored).
    pub warnings: Vec<String>,
}

/// Checks the whole chunk structure of `bytes`.
pub(super) fn check(bytes: &[u8]) -> Result<Layout, VoxError> {
    let version = check_file_header(bytes)?;
    let main = read_chunk_header(bytes, FILE_HEADER_BYTES, bytes.len())?;
    if &main.id != b"MAIN" {
        return Err(main.fail("stands where the MAIN chunk should be"));
    }
    check_graph_budget(bytes, &main)?;
    let mut layout = Layout { version, ..Layout::default() };
    let mut size = None;
    let mut pos = main.content_end;
    while pos < main.end {
        let chunk = read_chunk_header(bytes, pos, main.end)?;
        check_chunk(bytes, &chunk, &mut size, &mut layout)?;
        pos = chunk.end;
    }
    if main.end < bytes.len() {
        layout.warnings.push(format!(
            "{} bytes after the MAIN chunk (from byte {}) are not part of the model and were ignored",
            bytes.len() - main.end,
            main.end
        ));
    }
    Ok(layout)
}

/// Bytes one scene-graph chunk (nTRN, nGRP, nSHP, LAYR) takes once read,
/// by `dot_vox` and by octovox (their nodes and attribute maps), and walked:
/// measured at about 1.1 KB on a file of 2^20 placements.
const BYTES_PER_GRAPH_CHUNK: u64 = 1024;

/// Counts the scene-graph chunks (headers only, nothing allocated) and asks
/// the budget for what reading them will take, before any is read: a 100 MB
/// file of 2^20 placements took 2.2 GB under a 64 MB budget.
fn check_graph_budget(bytes: &[u8], main: &Chunk) -> Result<(), VoxError> {
    let mut nodes = 0u64;
    let mut pos = main.content_end;
    while pos < main.end {
        let chunk = read_chunk_header(bytes, pos, main.end)?;
        nodes += u64::from(matches!(&chunk.id, b"nTRN" | b"nGRP" | b"nSHP" | b"LAYR"));
        pos = chunk.end;
    }
    crate::budget::check(|| format!("reading {nodes} scene-graph nodes"), nodes * BYTES_PER_GRAPH_CHUNK)?;
    Ok(())
}

fn check_file_header(bytes: &[u8]) -> Result<u32, VoxError> {
    if bytes.len() < 4 || &bytes[..4] != b"VOX " {
        return Err(VoxError::NotVox);
    }
    let version = le_u32(bytes, 4)
        .ok_or_else(|| VoxError::Truncated(format!("file ends at byte {} inside its 8-byte header", bytes.len())))?;
    if version != 150 && version != 200 {
        return Err(VoxError::UnsupportedVersion(version));
    }
    Ok(version)
}

/// Checks one child of MAIN and records what [`Layout`] keeps of it.
fn check_chunk(bytes: &[u8], chunk: &Chunk, size: &mut Option<[u32; 3]>, layout: &mut Layout) -> Result<(), VoxError> {
    if chunk.children_bytes != 0 {
        return Err(
            chunk.fail(format!("has {} bytes of child chunks; only MAIN may have children", chunk.children_bytes))
        );
    }
    let mut cursor = Cursor::new(bytes, chunk);
    match &chunk.id {
        b"SIZE" => *size = Some(check_size(&mut cursor)?),
        b"XYZI" => check_voxels(&mut cursor, *size, layout)?,
        b"RGBA" if chunk.content_len() != PALETTE_BYTES => {
            return Err(chunk
                .fail(format!("has {} bytes; a palette has {PALETTE_BYTES} (256 RGBA colours)", chunk.content_len())));
        }
        b"MATL" => {
            cursor.u32("material id")?;
            cursor.dict("material properties")?;
        }
        b"MATT" => {
            let (index, material) = read_matt(&mut cursor)?;
            layout.matt.insert(index, material);
        }
        b"nTRN" => layout.graph.nodes.push(read_transform_node(&mut cursor)?),
        b"nGRP" => layout.graph.nodes.push(read_group_node(&mut cursor)?),
        b"nSHP" => layout.graph.nodes.push(read_shape_node(&mut cursor)?),
        b"LAYR" => layout.graph.layers.push(read_layer(&mut cursor)?),
        // PACK only counts the models that follow; the saver writes none.
        b"PACK" | b"RGBA" => {}
        // Kept as read too; octovox reads its playback settings.
        b"META" => {
            match cursor.dict("settings") {
                Ok(meta) => {
                    let (animation, warnings) = Animation::from_meta(&meta);
                    layout.graph.animation = animation;
                    layout.warnings.extend(warnings);
                }
                Err(e) => layout.warnings.push(format!("{e}: its playback settings are ignored")),
            }
            layout
                .kept
                .push(KeptChunk { id: *b"META", content: bytes[chunk.content_start..chunk.content_end].to_vec() });
        }
        // IMAP, rOBJ, rCAM, NOTE and unknown chunks are kept as read.
        id => layout.kept.push(KeptChunk { id: *id, content: bytes[chunk.content_start..chunk.content_end].to_vec() }),
    }
    Ok(())
}

fn check_size(cursor: &mut Cursor<'_>) -> Result<[u32; 3], VoxError> {
    let len = cursor.chunk.content_len();
    if len != 12 {
        return Err(cursor.chunk.fail(format!("has {len} bytes; SIZE holds 12")));
    }
    let size = [cursor.u32("x size")?, cursor.u32("y size")?, cursor.u32("z size")?];
    if size.iter().any(|&s| s == 0 || s > MAX_MODEL_EDGE) {
        return Err(cursor.chunk.fail(format!(
            "gives model size {}x{}x{}; each edge must be 1..={MAX_MODEL_EDGE}",
            size[0], size[1], size[2]
        )));
    }
    Ok(size)
}

fn check_voxels(cursor: &mut Cursor<'_>, size: Option<[u32; 3]>, layout: &mut Layout) -> Result<(), VoxError> {
    let chunk = cursor.chunk;
    let size = size.ok_or_else(|| chunk.fail("comes before any SIZE chunk"))?;
    let count = widen(cursor.u32("voxel count")?);
    let held = cursor.remaining();
    if count > held / 4 {
        return Err(chunk.fail(format!("claims {count} voxels but holds {held} bytes")));
    }
    let model = layout.model_voxels.len();
    let data = cursor.take(count * 4, "voxels")?;
    if cursor.remaining() > 0 {
        layout.warnings.push(format!(
            "chunk XYZI at byte {} holds {} bytes past its {count} voxels; they were ignored",
            chunk.offset,
            cursor.remaining()
        ));
    }
    for (ordinal, voxel) in data.chunks_exact(4).enumerate() {
        let inside = voxel[..3].iter().zip(size).all(|(&c, edge)| u32::from(c) < edge);
        if !inside {
            return Err(chunk.fail(format!(
                "has voxel {ordinal} at ({}, {}, {}) outside the model size {}x{}x{}",
                voxel[0], voxel[1], voxel[2], size[0], size[1], size[2]
            )));
        }
        if voxel[3] == 0 {
            layout.zero_index_voxels.push((model, ordinal));
        }
    }
    layout.model_voxels.push(count);
    Ok(())
}

fn read_transform_node(cursor: &mut Cursor<'_>) -> Result<Node, VoxError> {
    let id = cursor.u32("node id")?;
    let attributes = cursor.dict("node attributes")?;
    let child = cursor.u32("child node id")?;
    let reserved = cursor.u32("reserved id")?;
    let layer = cursor.u32("layer id")?;
    let count = widen(cursor.u32("frame count")?);
    let held = cursor.remaining();
    if count > held / 4 {
        return Err(cursor.chunk.fail(format!("claims {count} frames but holds {held} bytes")));
    }
    let frames = (0..count).map(|_| cursor.dict("frame attributes")).collect::<Result<_, _>>()?;
    Ok(Node { id, attributes, kind: NodeKind::Transform { child, reserved, layer, frames } })
}

fn read_group_node(cursor: &mut Cursor<'_>) -> Result<Node, VoxError> {
    let id = cursor.u32("node id")?;
    let attributes = cursor.dict("node attributes")?;
    let count = widen(cursor.u32("child count")?);
    let held = cursor.remaining();
    if count > held / 4 {
        return Err(cursor.chunk.fail(format!("claims {count} children but holds {held} bytes")));
    }
    let children = (0..count).map(|_| cursor.u32("child id")).collect::<Result<_, _>>()?;
    Ok(Node { id, attributes, kind: NodeKind::Group { children } })
}

fn read_shape_node(cursor: &mut Cursor<'_>) -> Result<Node, VoxError> {
    let id = cursor.u32("node id")?;
    let attributes = cursor.dict("node attributes")?;
    let count = widen(cursor.u32("model count")?);
    let held = cursor.remaining();
    if count > held / 8 {
        return Err(cursor.chunk.fail(format!("claims {count} models but holds {held} bytes")));
    }
    let models = (0..count)
        .map(|_| Ok((cursor.u32("model id")?, cursor.dict("model attributes")?)))
        .collect::<Result<_, VoxError>>()?;
    Ok(Node { id, attributes, kind: NodeKind::Shape { models } })
}

fn read_layer(cursor: &mut Cursor<'_>) -> Result<Layer, VoxError> {
    let id = cursor.u32("layer id")?;
    let attributes = cursor.dict("layer attributes")?;
    let reserved = cursor.u32("reserved id")?;
    Ok(Layer { id, attributes, reserved })
}

/// Property names of a MATT chunk's property bits 0..=6, in bit order.
/// Bit 7 ("total power") carries no value and is not kept.
const MATT_PROPERTIES: [&str; 7] = ["_plastic", "_rough", "_spec", "_ior", "_att", "_flux", "_glow"];

/// Reads an old (MagicaVoxel 0.98) MATT chunk into a [`Material`], the way
/// opengametools' ogt_vox does: the type gives the kind, the weight becomes
/// `_weight` and also `_metal`/`_trans`/`_emit` for metal/glass/emissive.
fn read_matt(cursor: &mut Cursor<'_>) -> Result<(u8, Material), VoxError> {
    // MagicaVoxel numbers materials 1..=256, where 256 is palette index 0.
    let index = cursor.u32("material id")?.to_le_bytes()[0];
    let kind = match cursor.u32("material type")? {
        0 => MaterialKind::Diffuse,
        1 => MaterialKind::Metal,
        2 => MaterialKind::Glass,
        3 => MaterialKind::Emit,
        other => {
            return Err(cursor.chunk.fail(format!("has unknown material type {other}")));
        }
    };
    let weight = cursor.f32("material weight")?;
    let bits = cursor.u32("property bits")?;
    let mut material = Material::new(kind);
    material.params.insert("_weight".to_owned(), weight.to_string());
    let weight_key = match kind {
        MaterialKind::Metal => Some("_metal"),
        MaterialKind::Glass => Some("_trans"),
        MaterialKind::Emit => Some("_emit"),
        MaterialKind::Diffuse | MaterialKind::Media => None,
    };
    if let Some(key) = weight_key {
        material.params.insert(key.to_owned(), weight.to_string());
    }
    for (bit, key) in MATT_PROPERTIES.iter().enumerate() {
        if bits & (1 << bit) != 0 {
            let value = cursor.f32(key)?;
            material.params.insert((*key).to_owned(), value.to_string());
        }
    }
    Ok((index, material))
}
