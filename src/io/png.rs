//! PNG files for renders, screenshots and reference images.

use std::path::Path;

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

/// Writes a PNG atomically: a temporary file in the same folder, then a rename.
pub fn save_png(image: &image::RgbaImage, path: &Path) -> Result<(), PngError> {
    let write_err = |source| PngError::Write { path: path.to_path_buf(), source };
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(write_err)?;
    let tmp = tempfile::Builder::new().suffix(".png").tempfile_in(dir).map_err(write_err)?;
    image
        .write_to(&mut std::io::BufWriter::new(tmp.as_file()), image::ImageFormat::Png)
        .map_err(|source| PngError::Encode { path: path.to_path_buf(), source })?;
    tmp.persist(path).map_err(|e| write_err(e.error))?;
    Ok(())
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
