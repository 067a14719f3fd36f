//! Palette files artists trade: MagicaVoxel's 256×1 PNG, Lospec's `.hex`
//! (one `RRGGBB` per line) and GIMP's `.gpl`. Entry k of a file (pixel k
//! of the PNG, colour line k of the text) is palette index k + 1, as
//! MagicaVoxel reads its PNGs; a 256th entry would be index 0, which no
//! voxel uses, and is skipped. The few built-in presets live here too.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use crate::io::atomic::WriteOptions;
use crate::scene::Palette;

/// Largest palette file read: far more than 256 colours in any format.
const MAX_PALETTE_BYTES: u64 = 1 << 20;

/// Most entries a file may hold: palette indices 1..=255, and the 256th
/// pixel of MagicaVoxel's PNG.
pub const MAX_ENTRIES: usize = 256;

/// A palette file format, named by the file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PaletteFormat {
    Png,
    Hex,
    Gpl,
}

impl PaletteFormat {
    /// The format `path`'s extension names, in any case.
    ///
    /// # Errors
    /// Any other extension.
    pub fn of(path: &Path) -> Result<PaletteFormat, PaletteFileError> {
        let extension = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
        match extension.as_str() {
            "png" => Ok(PaletteFormat::Png),
            "hex" => Ok(PaletteFormat::Hex),
            "gpl" => Ok(PaletteFormat::Gpl),
            _ => Err(PaletteFileError::Format(path.to_path_buf())),
        }
    }
}

/// Why a palette file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum PaletteFileError {
    #[error("{}: a palette file is .png (MagicaVoxel, 256×1), .hex (Lospec) or .gpl (GIMP)", .0.display())]
    Format(PathBuf),
    #[error("cannot read {}: {source}", path.display())]
    Read { path: PathBuf, source: crate::io::input::InputError },
    #[error("{}:{line}: {message}", path.display())]
    Bad { path: PathBuf, line: usize, message: String },
    #[error("{}: {message}", path.display())]
    Image { path: PathBuf, message: String },
    #[error("cannot write {}: {source}", path.display())]
    Write { path: PathBuf, source: std::io::Error },
}

/// The colours of a palette file, entry k first for index k + 1 (at most
/// [`MAX_ENTRIES`]).
///
/// # Errors
/// An unknown extension, a file that cannot be read, or one that is not
/// a palette of that format (every fault named with its line).
pub fn read_colors(path: &Path) -> Result<Vec<[u8; 3]>, PaletteFileError> {
    let format = PaletteFormat::of(path)?;
    let bytes = crate::io::input::read_limited(path, MAX_PALETTE_BYTES)
        .map_err(|source| PaletteFileError::Read { path: path.to_path_buf(), source })?;
    match format {
        PaletteFormat::Png => png_colors(path, &bytes),
        PaletteFormat::Hex | PaletteFormat::Gpl => {
            let text = std::str::from_utf8(&bytes).map_err(|_| bad(path, 0, "it is not UTF-8 text".to_owned()))?;
            let text = clean_text(text);
            let colors = if format == PaletteFormat::Hex { hex_colors(&text) } else { gpl_colors(&text) };
            let colors = colors.map_err(|(line, message)| bad(path, line, message))?;
            if colors.is_empty() {
                return Err(bad(path, 0, "it holds no colour".to_owned()));
            }
            if colors.len() > MAX_ENTRIES {
                let message = format!("{} colours; a palette holds at most {MAX_ENTRIES}", colors.len());
                return Err(bad(path, 0, message));
            }
            Ok(colors)
        }
    }
}

/// The text as its twin without a byte-order mark and with `\n` line
/// ends reads it: a UTF-8 byte-order mark (Windows editors write one) is
/// dropped, and `\r\n` and lone `\r` (old Mac files) end lines as `\n` does.
fn clean_text(text: &str) -> String {
    text.strip_prefix('\u{feff}').unwrap_or(text).replace("\r\n", "\n").replace('\r', "\n")
}

fn bad(path: &Path, line: usize, message: String) -> PaletteFileError {
    PaletteFileError::Bad { path: path.to_path_buf(), line, message }
}

/// The pixels of a PNG of at most 256 pixels, row by row (MagicaVoxel's
/// are 256×1); the size is read before any pixel is decoded.
fn png_colors(path: &Path, bytes: &[u8]) -> Result<Vec<[u8; 3]>, PaletteFileError> {
    let image_error = |message: String| PaletteFileError::Image { path: path.to_path_buf(), message };
    let reader = || image::ImageReader::with_format(std::io::Cursor::new(bytes), image::ImageFormat::Png);
    // The size from the header itself: the decoder refuses a huge one with
    // "Memory limit exceeded", which names neither it nor the limit.
    let (width, height) = match png_header_size(bytes) {
        Some(size) => size,
        None => reader().into_dimensions().map_err(|e| image_error(e.to_string()))?,
    };
    if u64::from(width) * u64::from(height) > MAX_ENTRIES as u64 {
        return Err(image_error(format!(
            "a {width}×{height} image; a palette PNG has at most {MAX_ENTRIES} pixels (MagicaVoxel's are 256×1)"
        )));
    }
    let image = reader().decode().map_err(|e| image_error(e.to_string()))?.to_rgb8();
    Ok(image.pixels().map(|p| p.0).collect())
}

/// Width and height from a PNG's IHDR chunk (the first, by the format),
/// when the bytes start like a PNG.
fn png_header_size(bytes: &[u8]) -> Option<(u32, u32)> {
    const SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];
    if bytes.get(..8)? != SIGNATURE || bytes.get(12..16)? != b"IHDR" {
        return None;
    }
    let word = |at: usize| Some(u32::from_be_bytes(bytes.get(at..at + 4)?.try_into().ok()?));
    Some((word(16)?, word(20)?))
}

/// Lospec's `.hex`: one `RRGGBB` (or `#RRGGBB`) per line; blank lines skipped.
fn hex_colors(text: &str) -> Result<Vec<[u8; 3]>, (usize, String)> {
    let mut colors = Vec::new();
    for (line, number) in text.lines().zip(1..) {
        let word = line.trim();
        if word.is_empty() {
            continue;
        }
        colors.push(parse_hex(word).ok_or((number, format!("expected a colour RRGGBB, found '{word}'")))?);
    }
    Ok(colors)
}

/// `RRGGBB` or `#RRGGBB` as red, green and blue.
pub fn parse_hex(word: &str) -> Option<[u8; 3]> {
    let digits = word.strip_prefix('#').unwrap_or(word);
    if digits.len() != 6 || !digits.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    let channel = |i: usize| u8::from_str_radix(&digits[i..i + 2], 16).ok();
    Some([channel(0)?, channel(2)?, channel(4)?])
}

/// GIMP's `.gpl`: a `GIMP Palette` first line, then `Name:` and `Columns:`
/// lines, `#` comments and one `R G B [name]` per colour.
fn gpl_colors(text: &str) -> Result<Vec<[u8; 3]>, (usize, String)> {
    let mut lines = text.lines().zip(1..);
    match lines.next() {
        Some((first, _)) if first.trim() == "GIMP Palette" => {}
        _ => return Err((1, "a GIMP palette starts with the line 'GIMP Palette'".to_owned())),
    }
    let mut colors = Vec::new();
    for (line, number) in lines {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with("Name:") || line.starts_with("Columns:") {
            continue;
        }
        let mut words = line.split_whitespace();
        let mut channel = || words.next().and_then(|w| w.parse::<u8>().ok());
        let color = [channel(), channel(), channel()];
        match color {
            [Some(r), Some(g), Some(b)] => colors.push([r, g, b]),
            _ => return Err((number, format!("expected 'R G B [name]' (each 0..=255), found '{line}'"))),
        }
    }
    Ok(colors)
}

/// The palette's 255 colours, index 1 first, in `format`; the PNG is
/// MagicaVoxel's 256×1, its last pixel the colour index 0 keeps.
pub fn encode(palette: &Palette, format: PaletteFormat) -> Vec<u8> {
    let rgb = |index: u8| {
        let [r, g, b, _] = palette.color(index);
        [r, g, b]
    };
    let mut out = Vec::new();
    match format {
        PaletteFormat::Png => {
            let image = image::RgbaImage::from_fn(256, 1, |x, _| {
                let [r, g, b] = rgb(((x + 1) % 256) as u8);
                image::Rgba([r, g, b, 255])
            });
            // Encoding a 256×1 image into memory cannot fail.
            let _ = image.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png);
        }
        PaletteFormat::Hex => {
            for index in 1..=255 {
                let [r, g, b] = rgb(index);
                let _ = writeln!(out, "{r:02x}{g:02x}{b:02x}");
            }
        }
        PaletteFormat::Gpl => {
            let _ = write!(out, "GIMP Palette\nName: octovox\nColumns: 16\n#\n");
            for index in 1..=255 {
                let [r, g, b] = rgb(index);
                let _ = writeln!(out, "{r:3} {g:3} {b:3}\tIndex {index}");
            }
        }
    }
    out
}

/// Writes the palette to `path` in the format its extension names,
/// atomically, as every file octovox writes.
///
/// # Errors
/// An unknown extension, or the file cannot be written.
pub fn save(palette: &Palette, path: &Path) -> Result<(), PaletteFileError> {
    let bytes = encode(palette, PaletteFormat::of(path)?);
    crate::io::atomic::write_atomically(path, WriteOptions::default(), |file| file.write_all(&bytes))
        .map_err(|source| PaletteFileError::Write { path: path.to_path_buf(), source })
}

/// The colours of a built-in palette, for index 1 on.
type PresetColors = fn() -> Vec<[u8; 3]>;

/// The built-in palettes by name.
pub const PRESETS: [(&str, PresetColors); 4] =
    [("magicavoxel", magicavoxel), ("pico8", pico8), ("sweetie16", sweetie16), ("gray", gray)];

/// The colours of the preset `name`, or `None`.
pub fn preset(name: &str) -> Option<Vec<[u8; 3]>> {
    PRESETS.iter().find(|(n, _)| *n == name).map(|(_, colors)| colors())
}

/// MagicaVoxel's default palette (what a file without RGBA shows).
fn magicavoxel() -> Vec<[u8; 3]> {
    let palette = Palette::default_magicavoxel();
    (1..=255).map(|i| palette.color(i)).map(|[r, g, b, _]| [r, g, b]).collect()
}

/// Lexaloffle's PICO-8 sixteen.
fn pico8() -> Vec<[u8; 3]> {
    from_hex(&[
        "000000", "1d2b53", "7e2553", "008751", "ab5236", "5f574f", "c2c3c7", "fff1e8", "ff004d", "ffa300", "ffec27",
        "00e436", "29adff", "83769c", "ff77a8", "ffccaa",
    ])
}

/// GrafxKid's Sweetie 16.
fn sweetie16() -> Vec<[u8; 3]> {
    from_hex(&[
        "1a1c2c", "5d275d", "b13e53", "ef7d57", "ffcd75", "a7f070", "38b764", "257179", "29366f", "3b5dc9", "41a6f6",
        "73eff7", "f4f4f4", "94b0c2", "566c86", "333c57",
    ])
}

/// 255 greys from white (index 1) to black (index 255).
fn gray() -> Vec<[u8; 3]> {
    (0..255u32).map(|i| [(255 - i * 255 / 254) as u8; 3]).collect()
}

fn from_hex(words: &[&str]) -> Vec<[u8; 3]> {
    words.iter().filter_map(|w| parse_hex(w)).collect()
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn every_format_reads_back_what_it_wrote() {
        let dir = tempfile::tempdir().unwrap();
        let mut palette = Palette::default();
        palette.colors[1] = [1, 2, 3, 255];
        palette.colors[255] = [250, 128, 7, 255];
        for name in ["p.png", "p.hex", "p.gpl"] {
            let path = dir.path().join(name);
            save(&palette, &path).unwrap();
            let colors = read_colors(&path).unwrap();
            assert_eq!(colors.len(), if name.ends_with("png") { 256 } else { 255 }, "{name}");
            assert_eq!((colors[0], colors[254]), ([1, 2, 3], [250, 128, 7]), "{name}");
            let all: Vec<[u8; 3]> = (1..=255).map(|i| palette.color(i)).map(|[r, g, b, _]| [r, g, b]).collect();
            assert_eq!(colors[..255], all[..], "{name}");
        }
    }

    #[test]
    fn bad_files_are_named_with_their_line() {
        let dir = tempfile::tempdir().unwrap();
        let cases: [(&str, &str, &str); 5] = [
            ("a.hex", "ff0000\nnot-a-colour\n", "a.hex:2: expected a colour RRGGBB, found 'not-a-colour'"),
            ("b.gpl", "JASC-PAL\n", "b.gpl:1: a GIMP palette starts with the line 'GIMP Palette'"),
            ("c.gpl", "GIMP Palette\n1 2 300 x\n", "c.gpl:2: expected 'R G B [name]' (each 0..=255)"),
            ("d.png", "not a png", "d.png:"),
            ("e.txt", "", "a palette file is .png"),
        ];
        for (name, text, message) in cases {
            let path = dir.path().join(name);
            std::fs::write(&path, text).unwrap();
            let err = read_colors(&path).unwrap_err().to_string();
            assert!(err.contains(message), "{name}: {err}");
        }
        let many: String = (0..300).map(|i| format!("{:06x}\n", i)).collect();
        std::fs::write(dir.path().join("f.hex"), many).unwrap();
        let err = read_colors(&dir.path().join("f.hex")).unwrap_err().to_string();
        assert!(err.contains("300 colours; a palette holds at most 256"), "{err}");
        let big = image::RgbImage::new(32, 32);
        big.save(dir.path().join("g.png")).unwrap();
        let err = read_colors(&dir.path().join("g.png")).unwrap_err().to_string();
        assert!(err.contains("a 32×32 image; a palette PNG has at most 256 pixels"), "{err}");
    }

    #[test]
    fn the_presets_are_whole() {
        assert_eq!(preset("magicavoxel").unwrap().len(), 255);
        assert_eq!(preset("pico8").unwrap().len(), 16);
        assert_eq!(preset("sweetie16").unwrap().len(), 16);
        assert_eq!((preset("gray").unwrap()[0], preset("gray").unwrap()[254]), ([255; 3], [0; 3]));
        assert!(preset("nope").is_none());
    }
}
