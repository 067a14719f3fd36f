//! Replacing a file without ever destroying it: the bytes go to a temporary
//! file beside the target, which is renamed over it only once it is complete.
//!
//! What a plain rename would get wrong, and what happens instead:
//! - a symlink is followed, so the file it points to is replaced and the link
//!   stays a link;
//! - a device, FIFO, socket or folder is refused: renaming over it would turn
//!   `/dev/full` into a regular file or a FIFO's reader would never see data;
//! - a read-only file is refused unless the caller says to overwrite it;
//! - a temporary file that a killed save left behind is removed by the next
//!   save of the same document (its name starts with the document's name).
//!
//! In the browser there is no disk: the bytes go into a buffer, which the
//! page keeps and hands over as a download ([`super::page_files`]).

use std::io;
use std::path::{Path, PathBuf};

/// How far a save may go.
#[derive(Clone, Copy, Default)]
pub struct WriteOptions<'a> {
    /// Replace a file whose permissions say it is read-only.
    pub overwrite_read_only: bool,
    /// Told the SHA-256 (lowercase hex) of the complete new file just before
    /// it replaces the target: the crash journal notes which save holds its
    /// edits, so a kill between the rename and the journal's removal leaves
    /// a journal recovery knows to be stale.
    pub before_replace: Option<&'a dyn Fn(&str)>,
}

impl WriteOptions<'_> {
    /// The default options, replacing a read-only file when `force` says so.
    pub fn forced(force: bool) -> WriteOptions<'static> {
        WriteOptions { overwrite_read_only: force, before_replace: None }
    }
}

impl std::fmt::Debug for WriteOptions<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WriteOptions")
            .field("overwrite_read_only", &self.overwrite_read_only)
            .field("before_replace", &self.before_replace.is_some())
            .finish()
    }
}

/// What a save writes into: the temporary file beside the target, or in
/// the browser a buffer. Writers use its `Write`, `Read` and `Seek` only.
#[cfg(not(target_arch = "wasm32"))]
pub type Target = std::fs::File;
#[cfg(target_arch = "wasm32")]
pub type Target = io::Cursor<Vec<u8>>;

/// The SHA-256 of a file's bytes (in the browser, one of the page's
/// files), in lowercase hex.
///
/// # Errors
/// The file cannot be read.
pub fn sha256_of(path: &Path) -> io::Result<String> {
    use sha2::Digest as _;
    #[cfg(not(target_arch = "wasm32"))]
    let hasher = {
        let mut hasher = sha2::Sha256::new();
        io::copy(&mut std::fs::File::open(path)?, &mut hasher)?;
        hasher
    };
    #[cfg(target_arch = "wasm32")]
    let hasher = sha2::Sha256::new_with_prefix(super::page_files::read_existing(path)?);
    Ok(hex(&hasher.finalize()))
}

/// The SHA-256 of `bytes`, in lowercase hex.
pub fn sha256_of_bytes(bytes: &[u8]) -> String {
    use sha2::Digest as _;
    hex(&sha2::Sha256::digest(bytes))
}

fn hex(digest: &[u8]) -> String {
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// Why the target cannot be written; `io::Error`s keep their own text.
fn refuse(kind: io::ErrorKind, text: String) -> io::Error {
    io::Error::new(kind, text)
}

/// The file a save to `path` must replace: `path` itself, or the final
/// target of a chain of symlinks (a dangling link's target is created).
pub fn resolve_target(path: &Path) -> io::Result<PathBuf> {
    let mut current = path.to_path_buf();
    // More links than this is a loop; the OS's own limit is 40.
    for _ in 0..40 {
        match std::fs::symlink_metadata(&current) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let link = std::fs::read_link(&current)?;
                current = match current.parent() {
                    Some(dir) if link.is_relative() => dir.join(link),
                    _ => link,
                };
            }
            _ => return Ok(current),
        }
    }
    Err(refuse(io::ErrorKind::InvalidInput, format!("{} is a loop of symbolic links", path.display())))
}

/// True when `path` exists and its permissions deny writing (for anyone,
/// root included: a read-only document is a statement of the user's).
pub fn is_read_only(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|meta| meta.permissions().readonly())
}

/// Refuses targets that are not regular files (or absent).
#[cfg(not(target_arch = "wasm32"))]
fn check_target(target: &Path, options: WriteOptions) -> io::Result<Option<std::fs::Permissions>> {
    let meta = match std::fs::metadata(target) {
        Ok(meta) => meta,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e),
    };
    if !meta.is_file() {
        let what = if meta.is_dir() { "a folder" } else { "not a regular file (a device, FIFO or socket)" };
        return Err(refuse(
            io::ErrorKind::InvalidInput,
            format!("{} is {what}; refusing to replace it", target.display()),
        ));
    }
    if meta.permissions().readonly() && !options.overwrite_read_only {
        return Err(refuse(
            io::ErrorKind::PermissionDenied,
            format!("{} is read-only; refusing to overwrite it (--force overwrites)", target.display()),
        ));
    }
    Ok(Some(meta.permissions()))
}

/// Prefix of the temporary files of a save of `name`.
#[cfg(not(target_arch = "wasm32"))]
fn temp_prefix(name: &std::ffi::OsStr) -> String {
    format!(".{}.octovox-save-", name.to_string_lossy())
}

/// Removes temporary files a killed save of the same document left.
#[cfg(not(target_arch = "wasm32"))]
fn remove_stale_temporaries(dir: &Path, prefix: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if name.starts_with(prefix) && name.ends_with(".tmp") {
            // Best effort: a file we cannot remove is left as it was.
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Writes a file through `write` and puts it in place of `path` atomically.
/// The folder must exist (it is never created: a typo in a path is an error).
///
/// # Errors
/// The target is refused as described in the module comment; any I/O error
/// of the temporary file or the rename is returned, and `path` is unchanged.
#[cfg(not(target_arch = "wasm32"))]
pub fn write_atomically<E: From<io::Error>>(
    path: &Path,
    options: WriteOptions,
    write: impl FnOnce(&mut Target) -> Result<(), E>,
) -> Result<(), E> {
    let target = resolve_target(path)?;
    let existing = check_target(&target, options)?;
    let dir = match target.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(refuse(io::ErrorKind::NotFound, format!("folder {} does not exist", dir.display())).into());
    }
    let name = target.file_name().ok_or_else(|| refuse(io::ErrorKind::InvalidInput, "no file name".into()))?;
    let prefix = temp_prefix(name);
    remove_stale_temporaries(dir, &prefix);
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    // New files get rw for all, less the umask, like any program's files.
    set_new_file_permissions(&mut builder);
    let mut temp = builder.tempfile_in(dir)?;
    write(temp.as_file_mut())?;
    temp.as_file().sync_all()?;
    if let Some(permissions) = existing {
        temp.as_file().set_permissions(permissions)?;
    }
    if let Some(before_replace) = options.before_replace {
        before_replace(&sha256_of(temp.path())?);
    }
    temp.persist(&target).map_err(|e| e.error)?;
    Ok(())
}

/// In the browser: `write` fills a buffer, which the page keeps as the
/// file `path` and hands over as a download ([`super::page_files`]).
///
/// # Errors
/// What `write` fails with; nothing is kept then.
#[cfg(target_arch = "wasm32")]
pub fn write_atomically<E: From<io::Error>>(
    path: &Path,
    options: WriteOptions,
    write: impl FnOnce(&mut Target) -> Result<(), E>,
) -> Result<(), E> {
    let mut target = io::Cursor::new(Vec::new());
    write(&mut target)?;
    let bytes = target.into_inner();
    if let Some(before_replace) = options.before_replace {
        before_replace(&sha256_of_bytes(&bytes));
    }
    super::page_files::write(path, bytes);
    Ok(())
}

#[cfg(all(unix, not(target_arch = "wasm32")))]
fn set_new_file_permissions(builder: &mut tempfile::Builder<'_, '_>) {
    use std::os::unix::fs::PermissionsExt;
    builder.permissions(std::fs::Permissions::from_mode(0o666));
}

/// Elsewhere a new file's default permissions are already the usual ones.
#[cfg(not(any(unix, target_arch = "wasm32")))]
fn set_new_file_permissions(_builder: &mut tempfile::Builder<'_, '_>) {}
