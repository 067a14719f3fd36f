//! The browser page's files (docs/web.md): the page has no file system, so
//! the files a user gives it (the file picker, a drop, `?open=URL`) are
//! kept here by name, and what octovox writes (Save, Export) is kept here
//! too and queued for the page to hand over as a download. The readers and
//! writers are the desktop's: [`super::input::read_limited`] and
//! [`super::atomic::write_atomically`] come here instead of to the disk,
//! and so do the crash journal's lines and snapshots, which the page keeps
//! in the browser's storage instead of handing them over.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

thread_local! {
    /// Every file the page holds, by the name it was given or written as.
    static FILES: RefCell<HashMap<PathBuf, Vec<u8>>> = RefCell::new(HashMap::new());
    /// Files written since the page last took them.
    static WRITTEN: RefCell<Vec<PathBuf>> = const { RefCell::new(Vec::new()) };
    /// Kept files (journals, their snapshots) changed or removed since the
    /// page last stored them.
    static CHANGED: RefCell<Vec<PathBuf>> = const { RefCell::new(Vec::new()) };
}

/// Whether octovox keeps `path` for itself (a crash journal or its
/// snapshot): stored in the browser, never downloaded.
pub fn is_kept(path: &Path) -> bool {
    path.file_name().is_some_and(|n| n.to_string_lossy().contains(".octovox-journal."))
}

/// Keeps `bytes` as the file `path` (a file the user gave the page).
pub fn provide(path: &Path, bytes: Vec<u8>) {
    FILES.with(|files| files.borrow_mut().insert(path.to_path_buf(), bytes));
}

/// The bytes of the file `path`, if the page holds one.
pub fn read(path: &Path) -> Option<Vec<u8>> {
    FILES.with(|files| files.borrow().get(path).cloned())
}

/// Whether the page holds a file `path`.
pub fn exists(path: &Path) -> bool {
    FILES.with(|files| files.borrow().contains_key(path))
}

/// Keeps what octovox wrote to `path` and queues it for the page: to
/// download, or for a kept file to store.
pub fn write(path: &Path, bytes: Vec<u8>) {
    provide(path, bytes);
    let queue = if is_kept(path) { &CHANGED } else { &WRITTEN };
    queue.with(|q| q.borrow_mut().push(path.to_path_buf()));
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
        return Err(std::io::Error::new(std::io::ErrorKind::NotFound, "the page holds no such file"));
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
/// (`None`: removed), for the page to store.
pub fn take_changed() -> Vec<(PathBuf, Option<Vec<u8>>)> {
    let mut paths = CHANGED.with(|q| std::mem::take(&mut *q.borrow_mut()));
    paths.sort();
    paths.dedup();
    paths.into_iter().map(|path| (path.clone(), read(&path))).collect()
}

/// The files written since the last call, oldest first, with their bytes.
pub fn take_written() -> Vec<(PathBuf, Vec<u8>)> {
    let paths = WRITTEN.with(|written| std::mem::take(&mut *written.borrow_mut()));
    paths.into_iter().filter_map(|path| read(&path).map(|bytes| (path, bytes))).collect()
}
