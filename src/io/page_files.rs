//! The browser page's files (docs/web.md): the page has no file system, so
//! the files a user gives it (the file picker, a drop, `?open=URL`) are
//! kept here by name, and what octovox writes (Save, Export) is kept here
//! too and queued for the page to hand over as a download. The readers and
//! writers are the desktop's: [`super::input::read_limited`] and
//! [`super::atomic::write_atomically`] come here instead of to the disk,
//! and so do the crash journal's lines and snapshots, which the page keeps
//! in the browser's storage instead of handing them over.

use std::cell::RefCell;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

thread_local! {
    /// Every file the page holds, by the name it was given or written as.
    static FILES: RefCell<HashMap<PathBuf, Vec<u8>>> = RefCell::new(HashMap::new());
    /// Files written since the page last took them.
    static WRITTEN: RefCell<Vec<PathBuf>> = const { RefCell::new(Vec::new()) };
    /// Files kept by choice (the recent files and their list).
    static KEPT: RefCell<HashSet<PathBuf>> = RefCell::new(HashSet::new());
    /// Kept files changed, removed or let go since the page last stored them.
    static CHANGED: RefCell<Vec<PathBuf>> = const { RefCell::new(Vec::new()) };
}

/// The page's own files (the recent-files list) live in this folder.
pub const OWN_FOLDER: &str = "octovox";

/// Whether octovox writes `path` for itself, never to hand over: a crash
/// journal or its snapshot, or one of the page's own files.
fn is_own(path: &Path) -> bool {
    path.file_name().is_some_and(|n| n.to_string_lossy().contains(".octovox-journal.")) || path.starts_with(OWN_FOLDER)
}

/// Whether the page keeps `path` in the browser's storage: its own files
/// and those kept by [`keep`].
pub fn is_kept(path: &Path) -> bool {
    is_own(path) || KEPT.with(|kept| kept.borrow().contains(path))
}

/// Keeps `path` in the browser's storage from now on, or lets it go
/// (`kept` false: it stays among the page's files until the page closes).
pub fn keep(path: &Path, kept: bool) {
    let changed = KEPT.with(|set| {
        let mut set = set.borrow_mut();
        if kept { set.insert(path.to_path_buf()) } else { set.remove(path) }
    });
    if changed {
        CHANGED.with(|q| q.borrow_mut().push(path.to_path_buf()));
    }
}

/// Keeps `bytes` as the file `path` (a file the user gave the page).
pub fn provide(path: &Path, bytes: Vec<u8>) {
    FILES.with(|files| files.borrow_mut().insert(path.to_path_buf(), bytes));
}

/// The bytes of the file `path`, if the page holds one.
pub fn read(path: &Path) -> Option<Vec<u8>> {
    FILES.with(|files| files.borrow().get(path).cloned())
}

/// The bytes of the file `path`.
///
/// # Errors
/// The page holds no such file.
pub fn read_existing(path: &Path) -> std::io::Result<Vec<u8>> {
    read(path).ok_or_else(not_found)
}

/// The error of a name the page holds no file by.
pub fn not_found() -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::NotFound,
        "the page holds no such file (open it with File ▸ Open or a drop)",
    )
}

/// Whether the page holds a file `path`.
pub fn exists(path: &Path) -> bool {
    FILES.with(|files| files.borrow().contains_key(path))
}

/// Keeps what octovox wrote to `path` and queues it for the page: to
/// download unless it is octovox's own, and to store if it is kept.
pub fn write(path: &Path, bytes: Vec<u8>) {
    provide(path, bytes);
    if is_kept(path) {
        CHANGED.with(|q| q.borrow_mut().push(path.to_path_buf()));
    }
    if !is_own(path) {
        WRITTEN.with(|q| q.borrow_mut().push(path.to_path_buf()));
    }
}

/// Adds `bytes` at the end of the file `path` (made if missing).
pub fn append(path: &Path, bytes: &[u8]) {
    FILES.with(|files| files.borrow_mut().entry(path.to_path_buf()).or_default().extend_from_slice(bytes));
    if is_kept(path) {
        CHANGED.with(|q| q.borrow_mut().push(path.to_path_buf()));
    }
}

/// Removes the file `path`.
///
/// # Errors
/// The page holds no such file.
pub fn remove(path: &Path) -> std::io::Result<()> {
    let removed = FILES.with(|files| files.borrow_mut().remove(path));
    if removed.is_none() {
        return Err(not_found());
    }
    if is_kept(path) {
        CHANGED.with(|q| q.borrow_mut().push(path.to_path_buf()));
    }
    Ok(())
}

/// The files in the folder `dir` (not below it).
pub fn list(dir: &Path) -> Vec<PathBuf> {
    FILES.with(|files| files.borrow().keys().filter(|p| p.parent() == Some(dir)).cloned().collect())
}

/// The kept files changed since the last call, with their bytes now
/// (`None`: removed or let go), for the page to store.
pub fn take_changed() -> Vec<(PathBuf, Option<Vec<u8>>)> {
    let mut paths = CHANGED.with(|q| std::mem::take(&mut *q.borrow_mut()));
    paths.sort();
    paths.dedup();
    paths.into_iter().map(|path| (path.clone(), is_kept(&path).then(|| read(&path)).flatten())).collect()
}

/// The files written since the last call, oldest first, with their bytes.
pub fn take_written() -> Vec<(PathBuf, Vec<u8>)> {
    let paths = WRITTEN.with(|written| std::mem::take(&mut *written.borrow_mut()));
    paths.into_iter().filter_map(|path| read(&path).map(|bytes| (path, bytes))).collect()
}
