//! The native octree file, `.ovx`: the node pool as the GPU reads it, the
//! palette and the materials, zstd-compressed, with a version and a checksum.
//! Loading reads the pool back (no rebuild), checks that it is a tree, and
//! hands it to the renderer as it is. `docs/ovx.md` describes the layout.
//!
//! A file is a 32-byte header, a zstd frame, and a CRC-32 of everything
//! before it. The header holds the file's own length, so a cut file is told
//! from a corrupted one; the counts in the payload are checked against the
//! header's payload length and the memory budget before anything is
//! allocated.

use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};

use glam::IVec3;

use super::atomic::{Target, WriteOptions, write_atomically};
use super::progress::Progress;
use super::zstd_frame::{FrameReader, write_frame};
use crate::gpu_pool::{BRICK_BYTES, Brick, NODE_BYTES, NodeSlot, is_pointer, pointer_to, slot_of};
use crate::scene::objects::Objects;
use crate::scene::octree::{MAX_DEPTH, MIN_DEPTH, Octree};
use crate::scene::{Material, MaterialKind, Palette, Scene};

/// The first eight bytes of every .ovx file.
pub const MAGIC: [u8; 8] = *b"OCTOVOX\x1a";
/// The version this build writes and reads.
pub const VERSION: u32 = 1;
/// Magic, version, flags, file length, payload length.
const HEADER_BYTES: u64 = 32;
/// The CRC-32 at the end.
const FOOTER_BYTES: u64 = 4;
/// Largest .ovx file read (the memory budget usually says no first).
pub const MAX_FILE_BYTES: u64 = 1 << 36;
/// Payload bytes before the node and brick arrays: origin, depth, root,
/// node and brick counts, the palette.
const FIXED_PAYLOAD_BYTES: u64 = 12 + 4 + 4 + 8 + 8 + 256 * 4;
/// Header flag: the payload ends with the scene's objects (see `docs/ovx.md`).
const FLAG_OBJECTS: u32 = 1;
/// Flags this version defines.
const KNOWN_FLAGS: u32 = FLAG_OBJECTS;

/// Why an .ovx file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum OvxError {
    #[error("cannot read {}: {source}", path.display())]
    Read { path: PathBuf, source: io::Error },
    #[error("cannot write {}: {source}", path.display())]
    Write { path: PathBuf, source: io::Error },
    #[error("not an .ovx file (it does not start with octovox's magic bytes)")]
    NotOvx,
    #[error("unsupported .ovx version {0} (this octovox reads version {VERSION})")]
    UnsupportedVersion(u32),
    #[error("the file is truncated: {found} of its {expected} bytes are there")]
    Truncated { found: u64, expected: u64 },
    #[error("checksum mismatch (stored {stored:#010x}, computed {computed:#010x}): the file is corrupted")]
    BadChecksum { stored: u32, computed: u32 },
    #[error("the file is corrupted: {0}")]
    Corrupt(String),
    #[error(transparent)]
    OverBudget(#[from] crate::budget::OverBudget),
}

fn corrupt(what: impl Into<String>) -> OvxError {
    OvxError::Corrupt(what.into())
}

/// Writes `scene` to `path` atomically (the old file survives a failure).
///
/// # Errors
/// [`OvxError::Write`] with the cause; `path` is then unchanged.
pub fn save_ovx(path: &Path, scene: &Scene, options: WriteOptions) -> Result<(), OvxError> {
    let write_error = |source| OvxError::Write { path: path.to_path_buf(), source };
    let compact = Compact::of(scene.drawn());
    let materials = encode_materials(&scene.palette);
    let objects =
        objects_section(scene).map_err(|e| write_error(io::Error::new(io::ErrorKind::InvalidInput, e.to_string())))?;
    if materials.len() as u64 > MAX_MATERIALS_BYTES {
        let text =
            format!("the materials take {} bytes, past the {MAX_MATERIALS_BYTES} an .ovx holds", materials.len());
        return Err(write_error(io::Error::new(io::ErrorKind::InvalidInput, text)));
    }
    let payload_len = FIXED_PAYLOAD_BYTES
        + compact.nodes.len() as u64 * NODE_BYTES
        + compact.bricks.len() as u64 * BRICK_BYTES
        + materials.len() as u64
        + objects.as_ref().map_or(0, |o| OBJECTS_HEADER_BYTES + o.bytes.len() as u64);
    let flags = if objects.is_some() { FLAG_OBJECTS } else { 0 };
    write_atomically(path, options, |file| {
        let mut out = Counting::new(io::BufWriter::new(file));
        // The file length goes in once the frame is written (a seek back).
        out.write_all(&header(0, payload_len, flags))?;
        write_frame(&mut out, |encoder| {
            write_payload(encoder, scene.drawn(), &scene.palette, &compact, objects.as_ref(), &materials)
        })?;
        let file_len = out.written + FOOTER_BYTES;
        let file = out.into_inner()?;
        use std::io::Seek;
        file.seek(io::SeekFrom::Start(0))?;
        // The checksum covers the final header: recompute it over the file.
        file.write_all(&header(file_len, payload_len, flags))?;
        file.seek(io::SeekFrom::Start(0))?;
        let crc = crc_of(&mut *file, file_len - FOOTER_BYTES)?;
        file.seek(io::SeekFrom::End(0))?;
        file.write_all(&crc.to_le_bytes())?;
        Ok(())
    })
    .map_err(write_error)
}

/// The objects of a scene of several, as the `.vox` bytes that hold them
/// (models, graph, layers, kept chunks), and the frame shown.
struct ObjectsSection {
    bytes: Vec<u8>,
    frame: u64,
}

/// Bytes before the `.vox` bytes of the objects section: their length and the frame.
const OBJECTS_HEADER_BYTES: u64 = 16;

fn objects_section(scene: &Scene) -> Result<Option<ObjectsSection>, super::vox::VoxError> {
    let Some(objects) = scene.objects() else { return Ok(None) };
    let bytes = super::vox::encode_objects(&scene.palette, objects)?;
    Ok(Some(ObjectsSection { bytes, frame: objects.frame as u64 }))
}

fn header(file_len: u64, payload_len: u64, flags: u32) -> [u8; HEADER_BYTES as usize] {
    let mut h = [0u8; HEADER_BYTES as usize];
    h[..8].copy_from_slice(&MAGIC);
    h[8..12].copy_from_slice(&VERSION.to_le_bytes());
    h[12..16].copy_from_slice(&flags.to_le_bytes());
    h[16..24].copy_from_slice(&file_len.to_le_bytes());
    h[24..32].copy_from_slice(&payload_len.to_le_bytes());
    h
}

fn write_payload(
    out: &mut dyn Write,
    tree: &Octree,
    palette: &Palette,
    compact: &Compact,
    objects: Option<&ObjectsSection>,
    materials: &[u8],
) -> io::Result<()> {
    for v in tree.origin().to_array() {
        out.write_all(&v.to_le_bytes())?;
    }
    out.write_all(&tree.depth().to_le_bytes())?;
    out.write_all(&compact.root.to_le_bytes())?;
    out.write_all(&(compact.nodes.len() as u64).to_le_bytes())?;
    out.write_all(&(compact.bricks.len() as u64).to_le_bytes())?;
    out.write_all(bytemuck::cast_slice(&palette.colors))?;
    out.write_all(bytemuck::cast_slice(&compact.nodes))?;
    out.write_all(bytemuck::cast_slice(&compact.bricks))?;
    if let Some(objects) = objects {
        out.write_all(&(objects.bytes.len() as u64).to_le_bytes())?;
        out.write_all(&objects.frame.to_le_bytes())?;
        out.write_all(&objects.bytes)?;
    }
    out.write_all(materials)
}

/// The live part of a pool renumbered in depth-first order: no free slots.
struct Compact {
    root: u32,
    nodes: Vec<NodeSlot>,
    bricks: Vec<Brick>,
}

impl Compact {
    fn of(tree: &Octree) -> Compact {
        let mut compact = Compact { root: 0, nodes: Vec::new(), bricks: Vec::new() };
        compact.root = compact.copy(tree, tree.root_word(), tree.depth());
        compact
    }

    fn copy(&mut self, tree: &Octree, word: u32, level: u32) -> u32 {
        if !is_pointer(word) {
            return word;
        }
        if level == 1 {
            self.bricks.push(*tree.pool().bricks.get(slot_of(word)));
            return pointer_to(self.bricks.len() as u32 - 1);
        }
        let slot = *tree.pool().nodes.get(slot_of(word));
        let index = self.nodes.len();
        self.nodes.push(slot);
        let children = slot.children.map(|child| self.copy(tree, child, level - 1));
        self.nodes[index].children = children;
        pointer_to(index as u32)
    }
}

/// Kind byte, then the parameter count and each key and value, all
/// length-prefixed, for each of the 256 entries.
fn encode_materials(palette: &Palette) -> Vec<u8> {
    let mut out = Vec::new();
    for material in &palette.materials {
        let kind = MaterialKind::ALL.iter().position(|k| *k == material.kind).unwrap_or(0);
        out.push(kind as u8);
        out.extend((material.params.len() as u32).to_le_bytes());
        for (key, value) in &material.params {
            for text in [key, value] {
                out.extend((text.len() as u32).to_le_bytes());
                out.extend(text.as_bytes());
            }
        }
    }
    out
}

/// Reads an .ovx file.
///
/// # Errors
/// A distinct [`OvxError`] for a missing file, a wrong magic or version, a
/// cut file, a bad checksum, a pool that is not a tree, or one past the
/// memory budget; nothing is built then.
pub fn load_ovx(path: &Path, progress: &Progress) -> Result<Scene, OvxError> {
    let read_error = |source| OvxError::Read { path: path.to_path_buf(), source };
    let bytes = super::input::read_limited(path, MAX_FILE_BYTES).map_err(|e| match e {
        super::input::InputError::Io(source) => read_error(source),
        other => read_error(io::Error::new(io::ErrorKind::InvalidInput, other.to_string())),
    })?;
    decode_ovx(&bytes, progress)
}

/// Decodes the bytes of an .ovx file (see [`load_ovx`]).
///
/// # Errors
/// As [`load_ovx`].
pub fn decode_ovx(bytes: &[u8], progress: &Progress) -> Result<Scene, OvxError> {
    let found = bytes.len() as u64;
    if found < 12 || bytes[..8] != MAGIC {
        return Err(if found < 8 && MAGIC.starts_with(bytes) {
            OvxError::Truncated { found, expected: HEADER_BYTES + FOOTER_BYTES }
        } else {
            OvxError::NotOvx
        });
    }
    if le_u32(bytes, 8) != VERSION {
        return Err(OvxError::UnsupportedVersion(le_u32(bytes, 8)));
    }
    if found < HEADER_BYTES + FOOTER_BYTES {
        return Err(OvxError::Truncated { found, expected: HEADER_BYTES + FOOTER_BYTES });
    }
    let (expected, payload_len) = (le_u64(bytes, 16), le_u64(bytes, 24));
    if found < expected {
        return Err(OvxError::Truncated { found, expected });
    }
    if found > expected {
        return Err(corrupt(format!("{found} bytes where the header says {expected}")));
    }
    let body = &bytes[..bytes.len() - FOOTER_BYTES as usize];
    let stored = le_u32(bytes, body.len());
    let computed = crc32fast::hash(body);
    if stored != computed {
        return Err(OvxError::BadChecksum { stored, computed });
    }
    let flags = le_u32(bytes, 12);
    if flags & !KNOWN_FLAGS != 0 {
        return Err(corrupt(format!(
            "header flags {:#x} are set, but version {VERSION} defines only {KNOWN_FLAGS:#x}",
            flags & !KNOWN_FLAGS
        )));
    }
    crate::budget::check(|| format!("an .ovx pool of {payload_len} bytes"), payload_len)?;
    progress.start(payload_len);
    let decoder = FrameReader::new(&body[HEADER_BYTES as usize..]).map_err(|e| corrupt(format!("zstd: {e}")))?;
    let mut payload = Payload { decoder, progress, produced: 0, expected: payload_len };
    let scene = read_payload(&mut payload, flags & FLAG_OBJECTS != 0)?;
    payload.finish()?;
    Ok(scene)
}

/// Largest materials section read: 256 entries of up to 64 KiB of MATL
/// keys and values each (MagicaVoxel writes a few dozen bytes).
pub const MAX_MATERIALS_BYTES: u64 = 256 << 16;
/// Smallest materials section: 256 entries without parameters.
const MIN_MATERIALS_BYTES: u64 = 256 * 5;
/// Items read and checked at a time: memory follows what the zstd frame
/// really holds, not the counts it claims.
const CHUNK_BYTES: usize = 1 << 20;

/// The decompressed payload, read in bounded steps: never more than the
/// header's payload length plus the one byte that shows the frame holds
/// more, and from one zstd frame only.
struct Payload<'a> {
    decoder: FrameReader<'a>,
    progress: &'a Progress,
    /// Bytes the decoder has handed out.
    produced: u64,
    /// The header's payload length.
    expected: u64,
}

impl Payload<'_> {
    /// Fills `out`, or says why the payload ends before it.
    fn fill(&mut self, out: &mut [u8]) -> Result<(), OvxError> {
        let mut at = 0;
        while at < out.len() {
            let room = self.expected.saturating_sub(self.produced).min((out.len() - at) as u64) as usize;
            if room == 0 {
                return Err(corrupt(format!("the payload passes the header's {} bytes", self.expected)));
            }
            let n = match self.decoder.read(&mut out[at..at + room]) {
                Ok(n) => n,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(corrupt(format!("zstd: {e}"))),
            };
            if n == 0 {
                return Err(self.ended_early());
            }
            at += n;
            self.produced += n as u64;
            self.progress.advance(n as u64);
        }
        Ok(())
    }

    /// The frame ended before the payload did: a second frame after it is
    /// its own error (the format has one).
    fn ended_early(&self) -> OvxError {
        if self.decoder.remaining() == 0 {
            corrupt(format!("the payload ends early ({} of its {} bytes)", self.produced, self.expected))
        } else {
            corrupt(format!(
                "the payload is split over more than one zstd frame (the first ends after {} of its {} bytes)",
                self.produced, self.expected
            ))
        }
    }

    /// `n` items, read and checked `check(index, item)` a chunk at a time.
    fn items<T: bytemuck::Pod>(
        &mut self,
        n: u64,
        mut check: impl FnMut(usize, &T) -> Result<(), OvxError>,
    ) -> Result<Vec<T>, OvxError> {
        let n = usize::try_from(n).map_err(|_| corrupt(format!("{n} items do not fit in memory")))?;
        let per_chunk = (CHUNK_BYTES / size_of::<T>().max(1)).max(1);
        let mut items: Vec<T> = Vec::new();
        while items.len() < n {
            let start = items.len();
            let take = per_chunk.min(n - start);
            items.resize(start + take, T::zeroed());
            self.fill(bytemuck::cast_slice_mut(&mut items[start..]))?;
            for (k, item) in items[start..].iter().enumerate() {
                check(start + k, item)?;
            }
        }
        Ok(items)
    }

    /// After the payload: the frame must end there (one more byte would be
    /// past the header's length), and no bytes, another frame included,
    /// may follow it.
    fn finish(mut self) -> Result<(), OvxError> {
        let mut one = [0u8; 1];
        let extra = loop {
            match self.decoder.read(&mut one) {
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(corrupt(format!("zstd: {e}"))),
                Ok(n) => break n,
            }
        };
        self.produced += extra as u64;
        if extra > 0 {
            return Err(corrupt(format!(
                "the zstd frame holds more than the header's {} payload bytes",
                self.expected
            )));
        }
        let after = self.decoder.remaining();
        if after > 0 {
            return Err(corrupt(format!(
                "{after} bytes follow the payload's zstd frame (a second frame?); the format has one frame"
            )));
        }
        Ok(())
    }
}

fn read_payload(input: &mut Payload, with_objects: bool) -> Result<Scene, OvxError> {
    // The objects section's bytes come off what the materials may take.
    let payload_len = input.expected;
    let mut fixed = vec![0u8; FIXED_PAYLOAD_BYTES as usize];
    input.fill(&mut fixed)?;
    let word = |at: usize| le_u32(&fixed, at);
    let origin = IVec3::new(word(0) as i32, word(4) as i32, word(8) as i32);
    let (depth, root, node_count, brick_count) = (word(12), word(16), le_u64(&fixed, 20), le_u64(&fixed, 28));
    if !(MIN_DEPTH..=MAX_DEPTH).contains(&depth) {
        return Err(corrupt(format!("root depth {depth} is outside {MIN_DEPTH}..={MAX_DEPTH}")));
    }
    // What the counts can need: the arrays, and materials between the
    // smallest and the largest section read.
    let arrays = node_count
        .checked_mul(NODE_BYTES)
        .zip(brick_count.checked_mul(BRICK_BYTES))
        .and_then(|(n, b)| n.checked_add(b)?.checked_add(FIXED_PAYLOAD_BYTES));
    // With objects, their section lies between the bricks and the materials.
    let least = MIN_MATERIALS_BYTES + if with_objects { OBJECTS_HEADER_BYTES } else { 0 };
    let Some(mut materials_len) = arrays.and_then(|a| payload_len.checked_sub(a)).filter(|m| *m >= least) else {
        return Err(corrupt(format!("{node_count} nodes and {brick_count} bricks do not fit its {payload_len} bytes")));
    };
    if !with_objects && materials_len > MAX_MATERIALS_BYTES {
        return Err(corrupt(format!(
            "a payload of {payload_len} bytes is more than {node_count} nodes and {brick_count} bricks can need \
             (their arrays and at most {MAX_MATERIALS_BYTES} bytes of materials)"
        )));
    }
    let mut palette = Palette { colors: bytemuck::pod_read_unaligned(&fixed[36..36 + 256 * 4]), ..Palette::default() };
    let slots = node_count.max(brick_count);
    let nodes: Vec<NodeSlot> = input.items(node_count, |index, slot: &NodeSlot| check_node(index, slot, slots))?;
    let bricks: Vec<Brick> = input.items(brick_count, |index, brick: &Brick| {
        if brick.iter().all(|v| *v == brick[0]) {
            Err(corrupt(format!("brick {index} is uncollapsed: {brick:?}")))
        } else {
            Ok(())
        }
    })?;
    let objects = if with_objects {
        let (objects, composed, taken) = read_objects(input, materials_len)?;
        materials_len -= taken;
        Some((objects, composed))
    } else {
        None
    };
    palette.materials = decode_materials(&input.items::<u8>(materials_len, |_, _| Ok(()))?)?;
    let tree = Octree::from_parts(origin, depth, root, nodes, bricks).map_err(|e| corrupt(e.to_string()))?;
    // The pool is what is drawn and saved, the objects what edits change:
    // a file whose two disagree would save other voxels than it shows
    // (issue 48, item 13: `convert` said "wrote 11 voxels" and wrote 19).
    let objects = match objects {
        Some((_, composed)) if !composed.same_voxels(&tree) => {
            return Err(corrupt(format!(
                "its objects place {} voxels and its pool holds {}, or other ones: they describe other scenes",
                composed.solid_voxels(),
                tree.solid_voxels()
            )));
        }
        other => other.map(|(objects, _)| objects),
    };
    Ok(match objects {
        Some(objects) => Scene::with_objects(palette, tree, objects),
        None => Scene::new(palette, tree),
    })
}

/// Reads the objects section (at most `room` bytes, the materials' least
/// after it): its `.vox` bytes load as a scene whose objects are kept.
/// Returns them, the octree they compose (which the pool must equal) and
/// the bytes taken.
fn read_objects(input: &mut Payload, room: u64) -> Result<(Objects, Octree, u64), OvxError> {
    let head = input.items::<u8>(OBJECTS_HEADER_BYTES, |_, _| Ok(()))?;
    let (len, frame) = (le_u64(&head, 0), le_u64(&head, 8));
    let most = (room - OBJECTS_HEADER_BYTES - MIN_MATERIALS_BYTES).min(super::vox::MAX_FILE_BYTES);
    if len > most {
        return Err(corrupt(format!("an objects section of {len} bytes, past the {most} it can hold")));
    }
    let bytes = input.items::<u8>(len, |_, _| Ok(()))?;
    let frame = usize::try_from(frame).map_err(|_| corrupt(format!("frame {frame}")))?;
    let scene = super::vox::load_vox_objects(&bytes, frame).map_err(|e| corrupt(format!("its objects: {e}")))?.0;
    let composed = scene.drawn().clone();
    let objects = scene.into_objects().ok_or_else(|| corrupt("its objects section holds a single model"))?;
    let left = room - OBJECTS_HEADER_BYTES - len;
    if left > MAX_MATERIALS_BYTES {
        return Err(corrupt(format!("{left} bytes of materials, past the {MAX_MATERIALS_BYTES} an .ovx holds")));
    }
    Ok((objects, composed, OBJECTS_HEADER_BYTES + len))
}

/// What one stored node can be told wrong by on its own, as it is read (a
/// forged payload of repeated bytes fails on its first node): a uniform
/// word that is no palette index, a pointer past every array, the same
/// slot twice, or eight equal uniform children. [`Octree::from_parts`]
/// checks the rest once the pool is read.
fn check_node(index: usize, slot: &NodeSlot, slots: u64) -> Result<(), OvxError> {
    let children = &slot.children;
    for (k, &child) in children.iter().enumerate() {
        if !is_pointer(child) && child > 255 {
            return Err(corrupt(format!("node {index}: bad cell word {child:#x}")));
        }
        if is_pointer(child) && u64::from(slot_of(child)) >= slots {
            return Err(corrupt(format!("node {index}: child {k} points past the {slots} slots stored")));
        }
        if is_pointer(child) && children[..k].contains(&child) {
            return Err(corrupt(format!("node {index}: slot {} is used twice", slot_of(child))));
        }
    }
    if !is_pointer(children[0]) && children.iter().all(|c| *c == children[0]) {
        return Err(corrupt(format!("node {index} is uncollapsed: eight children of value {}", children[0])));
    }
    Ok(())
}

fn le_u32(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

fn le_u64(bytes: &[u8], at: usize) -> u64 {
    u64::from(le_u32(bytes, at)) | u64::from(le_u32(bytes, at + 4)) << 32
}

fn decode_materials(bytes: &[u8]) -> Result<Vec<Material>, OvxError> {
    let mut at = 0usize;
    let mut take = |n: usize| -> Result<&[u8], OvxError> {
        let part = bytes.get(at..at.saturating_add(n)).ok_or_else(|| corrupt("the materials end early"))?;
        at += n;
        Ok(part)
    };
    let mut materials = Vec::with_capacity(256);
    for index in 0..256 {
        let kind = take(1)?[0];
        let kind = *MaterialKind::ALL
            .get(usize::from(kind))
            .ok_or_else(|| corrupt(format!("material {index} has kind {kind}")))?;
        let mut material = Material::new(kind);
        let count = le_u32(take(4)?, 0);
        for _ in 0..count {
            let mut text = || -> Result<String, OvxError> {
                let len = le_u32(take(4)?, 0) as usize;
                String::from_utf8(take(len)?.to_vec())
                    .map_err(|_| corrupt(format!("material {index}: text is not UTF-8")))
            };
            let key = text()?;
            material.params.insert(key, text()?);
        }
        materials.push(material);
    }
    if at < bytes.len() {
        return Err(corrupt(format!("{} bytes of junk follow the 256 materials", bytes.len() - at)));
    }
    Ok(materials)
}

/// CRC-32 of the first `len` bytes read from `input`.
fn crc_of(input: &mut impl Read, len: u64) -> io::Result<u32> {
    let mut hasher = crc32fast::Hasher::new();
    let mut limited = input.take(len);
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = limited.read(&mut buf)?;
        if n == 0 {
            return Ok(hasher.finalize());
        }
        hasher.update(&buf[..n]);
    }
}

/// A writer that counts the bytes that pass through it.
struct Counting<W: Write> {
    inner: W,
    written: u64,
}

impl<W: Write> Counting<W> {
    fn new(inner: W) -> Self {
        Counting { inner, written: 0 }
    }
}

impl<'a> Counting<io::BufWriter<&'a mut Target>> {
    fn into_inner(self) -> io::Result<&'a mut Target> {
        self.inner.into_inner().map_err(|e| e.into_error())
    }
}

impl<W: Write> Write for Counting<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.written += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::scene::{Op, Shape};

    /// The showroom (materials of every kind) with an edit and its undo
    /// behind it, so the pool has free slots to compact away.
    fn scene() -> Scene {
        let mut scene = crate::scene::demo::BuiltIn::Showroom.scene();
        let patch = scene.apply_brush(&Shape::Sphere { center: IVec3::new(3, 9, 4), radius: 6 }, Op::Remove).unwrap();
        scene.apply_patch(&patch).unwrap();
        scene
    }

    fn saved(scene: &Scene) -> Vec<u8> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("scene.ovx");
        save_ovx(&path, scene, WriteOptions::default()).unwrap();
        std::fs::read(path).unwrap()
    }

    #[test]
    fn a_scene_comes_back_as_it_was() {
        let scene = scene();
        let loaded = decode_ovx(&saved(&scene), &Progress::default()).unwrap();
        assert_eq!(loaded.voxels(), scene.voxels());
        assert_eq!(loaded.palette, scene.palette);
        assert_eq!((loaded.origin(), loaded.drawn().depth()), (scene.origin(), scene.drawn().depth()));
        assert_eq!(loaded.counts(), scene.counts());
        assert_eq!(loaded.drawn().node_count(), scene.drawn().node_count());
        assert_eq!(loaded.drawn().pool().nodes.len(), scene.drawn().node_count(), "no free slots stored");
        loaded.drawn().check_invariants().unwrap();
        let empty = decode_ovx(&saved(&Scene::default()), &Progress::default()).unwrap();
        assert_eq!(empty.solid_voxels(), 0);
    }

    #[test]
    fn each_kind_of_damage_has_its_own_message() {
        let bytes = saved(&scene());
        let message = |b: &[u8]| decode_ovx(b, &Progress::default()).err().unwrap().to_string();
        assert!(message(&bytes[..bytes.len() - 10]).contains("truncated"), "{}", message(&bytes[..bytes.len() - 10]));
        assert!(message(&bytes[..20]).contains("truncated"));
        assert!(message(&bytes[..5]).contains("truncated"));
        let mut version = bytes.clone();
        version[8] = 9;
        assert!(message(&version).contains("unsupported .ovx version 9"));
        let mut flipped = bytes.clone();
        let middle = bytes.len() / 2;
        flipped[middle] ^= 0x40;
        assert!(message(&flipped).contains("checksum mismatch"));
        assert!(message(b"VOX \x96\0\0\0 and so on").contains("not an .ovx file"));
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(message(&longer).contains("corrupted"));
    }

    /// The decompressed payload of a saved file.
    fn payload_of(bytes: &[u8]) -> Vec<u8> {
        zstd::decode_all(&bytes[HEADER_BYTES as usize..bytes.len() - FOOTER_BYTES as usize]).unwrap()
    }

    /// A file of `frames` (already compressed) under a header claiming
    /// `payload_len`, with the right length and CRC-32, so that only the
    /// check under test can refuse it.
    fn forge(frames: &[Vec<u8>], payload_len: u64, flags: u32) -> Vec<u8> {
        let body: Vec<u8> = frames.concat();
        let file_len = HEADER_BYTES + body.len() as u64 + FOOTER_BYTES;
        let mut bytes = header(file_len, payload_len, flags).to_vec();
        bytes.extend(body);
        let crc = crc32fast::hash(&bytes);
        bytes.extend(crc.to_le_bytes());
        bytes
    }

    fn frame(parts: &[&[u8]], zeros: usize) -> Vec<u8> {
        let mut out = Vec::new();
        write_frame(&mut out, |encoder| {
            for part in parts {
                encoder.write_all(part)?;
            }
            let block = vec![0u8; 1 << 20];
            for start in (0..zeros).step_by(block.len()) {
                encoder.write_all(&block[..block.len().min(zeros - start)])?;
            }
            Ok(())
        })
        .unwrap();
        out
    }

    fn refusal(bytes: &[u8]) -> (String, u64) {
        let progress = Progress::default();
        let Err(error) = decode_ovx(bytes, &progress) else { panic!("the forged file loads") };
        (error.to_string(), progress.get().0)
    }

    /// Issue 24, item 15: docs/ovx.md says flags are 0 in version 1.
    #[test]
    fn header_flags_are_refused() {
        let payload = payload_of(&saved(&scene()));
        let good = forge(&[frame(&[&payload], 0)], payload.len() as u64, 0);
        assert!(decode_ovx(&good, &Progress::default()).is_ok(), "the forger makes loadable files");
        let (message, _) = refusal(&forge(&[frame(&[&payload], 0)], payload.len() as u64, 1));
        assert!(message.contains("an objects section of"), "flag 1 (objects) wants an objects section: {message}");
        let (message, _) = refusal(&forge(&[frame(&[&payload], 0)], payload.len() as u64, 2));
        assert!(message.contains("header flags 0x2 are set"), "{message}");
    }

    /// Issue 24, item 15: bytes after the 256 materials, inside the payload.
    #[test]
    fn junk_after_the_materials_is_refused() {
        let payload = payload_of(&saved(&scene()));
        let forged = forge(&[frame(&[&payload, b"junk"], 0)], payload.len() as u64 + 4, 0);
        let (message, _) = refusal(&forged);
        assert!(message.contains("4 bytes of junk follow the 256 materials"), "{message}");
    }

    /// Issue 24, item 15: the payload is one zstd frame.
    #[test]
    fn a_payload_in_two_frames_is_refused() {
        let payload = payload_of(&saved(&scene()));
        let half = payload.len() / 2;
        let split = forge(&[frame(&[&payload[..half]], 0), frame(&[&payload[half..]], 0)], payload.len() as u64, 0);
        let (message, _) = refusal(&split);
        assert!(message.contains("split over more than one zstd frame"), "{message}");
        let second = forge(&[frame(&[&payload], 0), frame(&[b"more"], 0)], payload.len() as u64, 0);
        let (message, _) = refusal(&second);
        assert!(message.contains("follow the payload's zstd frame"), "{message}");
    }

    /// Issue 24, item 13: a frame that decompresses to far more than the
    /// header's payload length is refused one byte past it.
    #[test]
    fn a_frame_longer_than_its_header_stops_one_byte_past_it() {
        let payload = payload_of(&saved(&scene()));
        let bomb = forge(&[frame(&[&payload], 256 << 20)], payload.len() as u64, 0);
        assert!(bomb.len() < 64 << 10, "{} bytes", bomb.len());
        let (message, produced) = refusal(&bomb);
        assert!(message.contains("holds more than the header's"), "{message}");
        assert!(produced <= payload.len() as u64 + 1, "the decoder produced {produced} bytes");
    }

    /// The fixed part of a payload: an empty palette, `nodes` and `bricks`.
    fn fixed_part(nodes: u64, bricks: u64) -> Vec<u8> {
        let mut fixed = Vec::new();
        for word in [0u32, 0, 0, MAX_DEPTH, pointer_to(0)] {
            fixed.extend(word.to_le_bytes());
        }
        fixed.extend(nodes.to_le_bytes());
        fixed.extend(bricks.to_le_bytes());
        fixed.resize(FIXED_PAYLOAD_BYTES as usize, 0);
        fixed
    }

    /// Issue 24, item 13: a small file whose counts claim gigabytes, and
    /// whose frame expands to tens of megabytes of zeros, is refused at its
    /// first node, having decompressed one step; before, `info` allocated
    /// what the counts claimed and decompressed all of it first.
    #[test]
    fn a_forged_pool_claiming_gigabytes_is_refused_at_its_first_node() {
        let nodes = 100_000_000u64;
        let payload_len = FIXED_PAYLOAD_BYTES + nodes * NODE_BYTES + MIN_MATERIALS_BYTES;
        assert!(payload_len > 3 << 30 && payload_len < crate::budget::DEFAULT_BUDGET_BYTES);
        let forged = forge(&[frame(&[&fixed_part(nodes, 0)], 64 << 20)], payload_len, 0);
        assert!(forged.len() < 128 << 10, "{} bytes", forged.len());
        let (message, produced) = refusal(&forged);
        assert!(message.contains("node 0 is uncollapsed"), "{message}");
        assert!(produced <= FIXED_PAYLOAD_BYTES + CHUNK_BYTES as u64, "the decoder produced {produced} bytes");
    }

    /// Issue 24, item 13: a header's payload length is capped by what the
    /// counts can need: their arrays and at most MAX_MATERIALS_BYTES.
    #[test]
    fn a_payload_longer_than_its_counts_need_is_refused_before_decompressing_it() {
        let forged = forge(&[frame(&[&fixed_part(0, 0)], 64 << 20)], 3 << 30, 0);
        let (message, produced) = refusal(&forged);
        assert!(message.contains("is more than 0 nodes and 0 bricks can need"), "{message}");
        assert_eq!(produced, FIXED_PAYLOAD_BYTES, "only the counts were decompressed");
    }

    #[test]
    fn a_pool_that_is_not_a_tree_is_refused() {
        let slot = |children: [u32; 8]| NodeSlot { children, lod: 0 };
        let shared = vec![slot([pointer_to(1), pointer_to(1), 0, 0, 0, 0, 0, 0]), slot([1, 2, 0, 0, 0, 0, 0, 0])];
        assert!(
            Octree::from_parts(IVec3::ZERO, 3, pointer_to(0), shared, Vec::new())
                .unwrap_err()
                .to_string()
                .contains("twice")
        );
        let cycle = vec![slot([pointer_to(0), 1, 0, 0, 0, 0, 0, 0])];
        assert!(
            Octree::from_parts(IVec3::ZERO, 4, pointer_to(0), cycle, Vec::new())
                .unwrap_err()
                .to_string()
                .contains("twice")
        );
        let past = vec![slot([pointer_to(7), 1, 0, 0, 0, 0, 0, 0])];
        assert!(
            Octree::from_parts(IVec3::ZERO, 3, pointer_to(0), past, Vec::new())
                .unwrap_err()
                .to_string()
                .contains("past")
        );
        let stale = vec![slot([1, 2, 0, 0, 0, 0, 0, 0])];
        assert!(
            Octree::from_parts(IVec3::ZERO, 3, pointer_to(0), stale, Vec::new())
                .unwrap_err()
                .to_string()
                .contains("summary")
        );
    }
}
