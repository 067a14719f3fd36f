//! PNG files for renders, screenshots and reference images.

use std::io::Write;
use std::path::Path;

use crate::io::atomic::WriteOptions;

/// Why a PNG could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum PngError {
    #[error("cannot write {}: {source}", path.display())]
    Write { path: std::path::PathBuf, source: std::io::Error },
    #[error("cannot encode {}: {source}", path.display())]
    Encode { path: std::path::PathBuf, source: image::ImageError },
    #[error("cannot read {}: {source}", path.display())]
    Read { path: std::path::PathBuf, source: image::ImageError },
}

/// Writes a PNG atomically, like every file octovox writes
/// ([`crate::io::atomic`]): the folder must exist, links are followed,
/// devices refused, new files get the usual permissions (umask applied).
pub fn save_png(image: &image::RgbaImage, path: &Path, options: WriteOptions) -> Result<(), PngError> {
    save_encoded(path, options, |out| image.write_to(out, image::ImageFormat::Png))
}

/// Writes what `encode` writes into a buffered file, atomically, with
/// errors that name the file (PNG and GIF alike).
pub(crate) fn save_encoded(
    path: &Path,
    options: WriteOptions,
    encode: impl FnOnce(&mut std::io::BufWriter<&mut crate::io::atomic::Target>) -> Result<(), image::ImageError>,
) -> Result<(), PngError> {
    let result = crate::io::atomic::write_atomically(path, options, |file| {
        let mut out = std::io::BufWriter::new(file);
        encode(&mut out).map_err(EncodeOrIo::Encode)?;
        out.flush().map_err(EncodeOrIo::Io)
    });
    result.map_err(|e| match e {
        EncodeOrIo::Io(source) => PngError::Write { path: path.to_path_buf(), source },
        EncodeOrIo::Encode(source) => PngError::Encode { path: path.to_path_buf(), source },
    })
}

enum EncodeOrIo {
    Io(std::io::Error),
    Encode(image::ImageError),
}

impl From<std::io::Error> for EncodeOrIo {
    fn from(e: std::io::Error) -> EncodeOrIo {
        EncodeOrIo::Io(e)
    }
}

pub fn load_png(path: &Path) -> Result<image::RgbaImage, PngError> {
    Ok(image::open(path).map_err(|source| PngError::Read { path: path.to_path_buf(), source })?.to_rgba8())
}

/// Fraction of pixels whose channels differ by more than 2 (float rounding
/// between GPU drivers), or 1.0 when the sizes differ.
pub fn differing_fraction(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    if a.dimensions() != b.dimensions() {
        return 1.0;
    }
    let differing =
        a.pixels().zip(b.pixels()).filter(|(p, q)| p.0.iter().zip(q.0).any(|(x, y)| x.abs_diff(y) > 2)).count();
    differing as f64 / (a.width() as f64 * a.height() as f64).max(1.0)
}

/// The image stretched to `size` (bilinear), or itself when it has that size:
/// what the window's blit does to a frame traced at a lower render scale.
pub fn upscale(image: image::RgbaImage, size: (u32, u32)) -> image::RgbaImage {
    if image.dimensions() == size {
        return image;
    }
    image::imageops::resize(&image, size.0, size.1, image::imageops::FilterType::Triangle)
}
