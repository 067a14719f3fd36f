//! Reading chunk headers and chunk content, with errors that name the chunk
//! and its byte offset.

use super::VoxError;
use crate::scene::graph::Attributes;

/// Chunk id, content size, children size.
const CHUNK_HEADER_BYTES: usize = 12;

/// A chunk header and where its parts lie in the file.
pub(super) struct Chunk {
    pub id: [u8; 4],
    pub offset: usize,
    pub content_start: usize,
    pub content_end: usize,
    pub children_bytes: usize,
    /// One past its last byte (content and children).
    pub end: usize,
}

impl Chunk {
    fn name(&self) -> String {
        self.id.escape_ascii().to_string()
    }

    pub(super) fn fail(&self, problem: impl Into<String>) -> VoxError {
        VoxError::BadChunk { id: self.name(), offset: self.offset, problem: problem.into() }
    }

    pub(super) fn content_len(&self) -> usize {
        self.content_end - self.content_start
    }
}

/// Reads the chunk header at `offset`; the chunk must end by `limit`.
pub(super) fn read_chunk_header(bytes: &[u8], offset: usize, limit: usize) -> Result<Chunk, VoxError> {
    if limit - offset < CHUNK_HEADER_BYTES {
        return Err(if limit == bytes.len() {
            VoxError::Truncated(format!("file ends at byte {limit} inside the header of the chunk at byte {offset}"))
        } else {
            // Only MAIN's children are read with a limit short of the file's end.
            VoxError::BadChunk {
                id: "MAIN".to_owned(),
                offset: 8,
                problem: format!("ends with {} stray bytes at byte {offset} after its last child", limit - offset),
            }
        });
    }
    let mut id = [0u8; 4];
    id.copy_from_slice(&bytes[offset..offset + 4]);
    let content_bytes = le_u32(bytes, offset + 4).map_or(0, widen);
    let children_bytes = le_u32(bytes, offset + 8).map_or(0, widen);
    let content_start = offset + CHUNK_HEADER_BYTES;
    let chunk = Chunk {
        id,
        offset,
        content_start,
        content_end: content_start.saturating_add(content_bytes),
        children_bytes,
        end: content_start.saturating_add(content_bytes).saturating_add(children_bytes),
    };
    if !id.iter().all(|b| b.is_ascii_graphic() || *b == b' ') {
        return Err(chunk.fail("has an id that is not ASCII text"));
    }
    let room = limit - content_start;
    if content_bytes > room || children_bytes > room - content_bytes {
        return Err(chunk.fail(format!(
            "claims {content_bytes} content bytes and {children_bytes} child bytes but only {room} bytes follow its header{}",
            if limit == bytes.len() { " (truncated file?)" } else { " inside MAIN" }
        )));
    }
    Ok(chunk)
}

/// Reads little-endian values from one chunk's content, failing with the
/// chunk's name and offset when the content ends too early.
pub(super) struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// The chunk being read, for error messages.
    pub chunk: &'a Chunk,
}

impl<'a> Cursor<'a> {
    /// A cursor at the start of `chunk`'s content in `bytes`.
    pub(super) fn new(bytes: &'a [u8], chunk: &'a Chunk) -> Cursor<'a> {
        Cursor { bytes, pos: chunk.content_start, chunk }
    }

    pub(super) fn remaining(&self) -> usize {
        self.chunk.content_end - self.pos
    }

    pub(super) fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], VoxError> {
        if n > self.remaining() {
            return Err(self.chunk.fail(format!(
                "ends inside its {what}: byte {} needs {n} more bytes but the content ends at byte {}",
                self.pos, self.chunk.content_end
            )));
        }
        let start = self.pos;
        self.pos += n;
        Ok(&self.bytes[start..self.pos])
    }

    pub(super) fn u32(&mut self, what: &str) -> Result<u32, VoxError> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    pub(super) fn f32(&mut self, what: &str) -> Result<f32, VoxError> {
        self.u32(what).map(f32::from_bits)
    }

    pub(super) fn string(&mut self, what: &str) -> Result<&'a str, VoxError> {
        let len = widen(self.u32(what)?);
        let at = self.pos;
        let text = self.take(len, what)?;
        std::str::from_utf8(text)
            .map_err(|_| self.chunk.fail(format!("has a {what} at byte {at} that is not UTF-8 text")))
    }

    /// A DICT: the entry count, then key and value strings. A key given
    /// twice keeps its last value, as `dot_vox` reads it.
    pub(super) fn dict(&mut self, what: &str) -> Result<Attributes, VoxError> {
        let entries = widen(self.u32(what)?);
        let held = self.remaining();
        if entries > held / 8 {
            return Err(self.chunk.fail(format!("claims {entries} entries in its {what} but holds {held} bytes")));
        }
        let mut dict = Attributes::new();
        for _ in 0..entries {
            let key = self.string(what)?;
            let value = self.string(what)?;
            dict.insert(key.to_owned(), value.to_owned());
        }
        Ok(dict)
    }
}

pub(super) fn le_u32(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// `u32` to `usize`; lossless on the 32- and 64-bit targets octovox builds for.
pub(super) fn widen(n: u32) -> usize {
    usize::try_from(n).unwrap_or(usize::MAX)
}

/// The dictionary a kept chunk's content starts with (META's whole
/// content), or `None` where it holds none.
pub(super) fn content_dict(id: [u8; 4], content: &[u8]) -> Option<Attributes> {
    let chunk =
        Chunk { id, offset: 0, content_start: 0, content_end: content.len(), children_bytes: 0, end: content.len() };
    Cursor::new(content, &chunk).dict("settings").ok()
}
