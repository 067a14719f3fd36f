//! File ▸ Open recent: the last documents opened or saved, newest first,
//! kept in `$XDG_CONFIG_HOME/octovox/recent.txt` (else `~/.config/…`), one
//! absolute path per line. A list that cannot be read or written costs the
//! list, never the session. In the browser the list and the files on it
//! are among the page's files, kept in the browser's storage.

use std::path::{Path, PathBuf};

/// Entries the list keeps.
const KEEP: usize = 10;

/// Largest list read.
const MAX_LIST_BYTES: u64 = 1 << 16;

#[derive(Debug, Default)]
pub struct Recent {
    /// The list's file; `None` where there is no config folder.
    file: Option<PathBuf>,
    files: Vec<PathBuf>,
}

impl Recent {
    /// The list as saved (empty if there is none).
    pub fn load() -> Recent {
        let file = list_file();
        let files = file
            .as_ref()
            .and_then(|f| octovox::io::input::read_limited(f, MAX_LIST_BYTES).ok())
            .and_then(|bytes| String::from_utf8(bytes).ok())
            .map(|text| text.lines().filter(|l| !l.is_empty()).map(PathBuf::from).take(KEEP).collect())
            .unwrap_or_default();
        Recent { file, files }
    }

    /// The listed files that still exist, newest first.
    pub fn files(&self) -> impl Iterator<Item = &PathBuf> {
        self.files.iter().filter(|p| octovox::io::input::is_file(p))
    }

    /// Puts `path` first and saves the list.
    pub fn add(&mut self, path: &Path) {
        let path = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        self.files.retain(|p| *p != path);
        self.files.insert(0, path);
        #[cfg(target_arch = "wasm32")]
        {
            octovox::io::page_files::keep(&self.files[0], true);
            for dropped in self.files.iter().skip(KEEP) {
                octovox::io::page_files::keep(dropped, false);
            }
        }
        self.files.truncate(KEEP);
        if let Err(err) = self.save() {
            log::warn!("cannot keep the recent-files list: {err}");
        }
    }

    fn save(&self) -> std::io::Result<()> {
        let Some(file) = &self.file else { return Ok(()) };
        #[cfg(not(target_arch = "wasm32"))]
        if let Some(dir) = file.parent() {
            std::fs::create_dir_all(dir)?;
        }
        let text: String = self.files.iter().map(|p| format!("{}\n", p.display())).collect();
        let options = octovox::io::atomic::WriteOptions::default();
        octovox::io::atomic::write_atomically(file, options, |f| std::io::Write::write_all(f, text.as_bytes()))
    }
}

/// Where the list is kept: the desktop's config folder, if there is one.
#[cfg(not(target_arch = "wasm32"))]
fn list_file() -> Option<PathBuf> {
    let config = std::env::var_os("XDG_CONFIG_HOME")
        .map(PathBuf::from)
        .filter(|p| p.is_absolute())
        .or_else(|| std::env::var_os("HOME").map(|home| Path::new(&home).join(".config")));
    config.map(|dir| dir.join("octovox").join("recent.txt"))
}

/// Where the list is kept: among the page's own files.
#[cfg(target_arch = "wasm32")]
fn list_file() -> Option<PathBuf> {
    Some(Path::new(octovox::io::page_files::OWN_FOLDER).join("recent.txt"))
}
