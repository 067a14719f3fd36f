//! Reading input files with a size limit: a device such as `/dev/zero` or a
//! folder is refused, and no file is read past its limit, whatever its
//! metadata claims (a FIFO, which a slow producer may feed, is read up to the
//! limit like a regular file).

use std::io;
use std::path::Path;

/// Why an input could not be read: an I/O error, or a limit.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    #[error(transparent)]
    Io(#[from] io::Error),
    #[error("is not a regular file (a device, socket or folder)")]
    NotRegular,
    #[error("is larger than the {limit}-byte limit")]
    TooLarge { limit: u64 },
}

/// Reads all of `path`, refusing anything longer than `limit` bytes: in
/// the browser, from the files the page holds ([`super::page_files`]).
#[cfg(target_arch = "wasm32")]
pub fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, InputError> {
    let bytes = super::page_files::read_existing(path)?;
    if bytes.len() as u64 > limit {
        return Err(InputError::TooLarge { limit });
    }
    Ok(bytes)
}

/// Whether `path` is a regular file (in the browser, one of the page's files).
pub fn is_file(path: &Path) -> bool {
    #[cfg(not(target_arch = "wasm32"))]
    return path.is_file();
    #[cfg(target_arch = "wasm32")]
    super::page_files::exists(path)
}

/// Reads all of `path`, refusing devices, sockets and folders and anything
/// longer than `limit` bytes.
#[cfg(not(target_arch = "wasm32"))]
pub fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, InputError> {
    use std::io::Read as _;
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    if !(meta.is_file() || is_fifo(&meta)) {
        return Err(InputError::NotRegular);
    }
    if meta.is_file() && meta.len() > limit {
        return Err(InputError::TooLarge { limit });
    }
    let mut bytes = Vec::new();
    // One byte past the limit, so a file that grows while it is read (or a
    // FIFO) is refused rather than cut.
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(InputError::TooLarge { limit });
    }
    Ok(bytes)
}

#[cfg(all(unix, not(target_arch = "wasm32")))]
fn is_fifo(meta: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::FileTypeExt;
    meta.file_type().is_fifo()
}

#[cfg(not(any(unix, target_arch = "wasm32")))]
fn is_fifo(_meta: &std::fs::Metadata) -> bool {
    false
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn devices_and_oversized_files_are_refused() {
        #[cfg(unix)]
        assert!(matches!(read_limited(Path::new("/dev/zero"), 1 << 20), Err(InputError::NotRegular)));
        let dir = tempfile::tempdir().unwrap();
        assert!(matches!(read_limited(dir.path(), 10), Err(InputError::NotRegular)));
        let file = dir.path().join("f");
        std::fs::write(&file, [7u8; 11]).unwrap();
        assert!(matches!(read_limited(&file, 10), Err(InputError::TooLarge { limit: 10 })));
        assert_eq!(read_limited(&file, 11).unwrap().len(), 11);
    }
}
