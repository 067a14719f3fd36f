//! One zstd frame, written and read: the C library on the desktop,
//! ruzstd (pure Rust, no C compiler for wasm32 needed) in the browser.
//! Both write a frame with its content checksum, and each reads the
//! other's frames (the tests below).

use std::io::{self, Read, Write};

/// zstd level on the desktop: fast (about the speed of writing the file)
/// and within a few percent of level 9 on pools.
#[cfg(not(target_arch = "wasm32"))]
const LEVEL: i32 = 3;

/// Writes one frame holding what `fill` writes.
///
/// # Errors
/// What `fill` or `out` fail with.
#[cfg(not(target_arch = "wasm32"))]
pub fn write_frame(out: &mut impl Write, fill: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> io::Result<()> {
    let mut encoder = zstd::Encoder::new(out, LEVEL)?;
    encoder.include_checksum(true)?;
    fill(&mut encoder)?;
    encoder.finish()?;
    Ok(())
}

/// Writes one frame holding what `fill` writes. ruzstd compresses from a
/// reader, so the content is gathered first (the browser's files are small).
///
/// # Errors
/// What `fill` or `out` fail with.
#[cfg(target_arch = "wasm32")]
pub fn write_frame(out: &mut impl Write, fill: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> io::Result<()> {
    let mut content = Vec::new();
    fill(&mut content)?;
    let frame = ruzstd::encoding::compress_to_vec(content.as_slice(), ruzstd::encoding::CompressionLevel::Fastest);
    out.write_all(&frame)
}

/// The content of the one frame at the start of `bytes`, read in steps.
pub struct FrameReader<'a> {
    #[cfg(not(target_arch = "wasm32"))]
    inner: zstd::stream::read::Decoder<'a, &'a [u8]>,
    #[cfg(target_arch = "wasm32")]
    inner: ruzstd::decoding::StreamingDecoder<&'a [u8], ruzstd::decoding::FrameDecoder>,
}

impl<'a> FrameReader<'a> {
    /// Reads the frame header.
    ///
    /// # Errors
    /// The bytes do not start a zstd frame.
    pub fn new(bytes: &'a [u8]) -> io::Result<Self> {
        #[cfg(not(target_arch = "wasm32"))]
        let inner = zstd::Decoder::with_buffer(bytes)?.single_frame();
        #[cfg(target_arch = "wasm32")]
        let inner = ruzstd::decoding::StreamingDecoder::new(bytes).map_err(io::Error::other)?;
        Ok(FrameReader { inner })
    }

    /// The bytes not yet taken by the decoder: after the frame's end, what
    /// follows it.
    pub fn remaining(&self) -> usize {
        self.inner.get_ref().len()
    }
}

impl Read for FrameReader<'_> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        self.inner.read(buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Some pool-like bytes: runs and noise.
    fn content() -> Vec<u8> {
        (0..300_000u32).map(|i| if i % 7 < 3 { 0 } else { (i.wrapping_mul(2_654_435_761) >> 24) as u8 }).collect()
    }

    #[test]
    fn the_desktop_reads_the_browsers_frames() {
        let content = content();
        let frame = ruzstd::encoding::compress_to_vec(content.as_slice(), ruzstd::encoding::CompressionLevel::Fastest);
        let mut reader = FrameReader::new(&frame).unwrap();
        let mut read = Vec::new();
        reader.read_to_end(&mut read).unwrap();
        assert_eq!(read, content);
        assert_eq!(reader.remaining(), 0);
    }

    #[test]
    fn the_browser_reads_the_desktops_frames() {
        let content = content();
        let mut frame = Vec::new();
        write_frame(&mut frame, |out| out.write_all(&content)).unwrap();
        let mut decoder = ruzstd::decoding::StreamingDecoder::new(frame.as_slice()).unwrap();
        let mut read = Vec::new();
        decoder.read_to_end(&mut read).unwrap();
        assert_eq!(read, content);
    }
}
