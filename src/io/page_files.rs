//! The browser page's files (docs/web.md): the page has no file system, so
//! the files a user gives it (the file picker, a drop, `?open=URL`) are
//! kept here by name, and what octovox writes (Save, Export) is kept here
//! too and queued for the page to hand over as a download. The readers and
//! writers are the desktop's: [`super::input::read_limited`] and
//! [`super::atomic::write_atomically`] come here instead of to the disk.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

thread_local! {
    /// Every file the page holds, by the name it was given or written as.
    static FILES: RefCell<HashMap<PathBuf, Vec<u8>>> = RefCell::new(HashMap::new());
    /// Files written since the page last took them.
    static WRITTEN: RefCell<Vec<PathBuf>> = const { RefCell::new(Vec::new()) };
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

/// Keeps what octovox wrote to `path` and queues it for the page.
pub fn write(path: &Path, bytes: Vec<u8>) {
    provide(path, bytes);
    WRITTEN.with(|written| written.borrow_mut().push(path.to_path_buf()));
}

/// The files written since the last call, oldest first, with their bytes.
pub fn take_written() -> Vec<(PathBuf, Vec<u8>)> {
    let paths = WRITTEN.with(|written| std::mem::take(&mut *written.borrow_mut()));
    paths.into_iter().filter_map(|path| read(&path).map(|bytes| (path, bytes))).collect()
}
