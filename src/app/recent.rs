//! File ▸ Open recent: the last documents opened or saved, newest first,
//! kept in `$XDG_CONFIG_HOME/octovox/recent.txt` (else `~/.config/…`), one
//! absolute path per line. A list that cannot be read or written costs the
//! list, never the session.

use std::path::{Path, PathBuf};

/// Entries the list keeps.
const KEEP: usize = 10;

#[derive(Debug, Default)]
pub struct Recent {
    /// The list's file; `None` where there is no config folder.
    file: Option<PathBuf>,
    files: Vec<PathBuf>,
}

impl Recent {
    /// The list as saved (empty if there is none).
    pub fn load() -> Recent {
        let config = std::env::var_os("XDG_CONFIG_HOME")
            .map(PathBuf::from)
            .filter(|p| p.is_absolute())
            .or_else(|| std::env::var_os("HOME").map(|home| Path::new(&home).join(".config")));
        let file = config.map(|dir| dir.join("octovox").join("recent.txt"));
        let files = file
            .as_ref()
            .and_then(|f| std::fs::read_to_string(f).ok())
            .map(|text| text.lines().filter(|l| !l.is_empty()).map(PathBuf::from).take(KEEP).collect())
            .unwrap_or_default();
        Recent { file, files }
    }

    /// The listed files that still exist, newest first.
    pub fn files(&self) -> impl Iterator<Item = &PathBuf> {
        self.files.iter().filter(|p| p.is_file())
    }

    /// Puts `path` first and saves the list.
    pub fn add(&mut self, path: &Path) {
        let path = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        self.files.retain(|p| *p != path);
        self.files.insert(0, path);
        self.files.truncate(KEEP);
        if let Err(err) = self.save() {
            log::warn!("cannot keep the recent-files list: {err}");
        }
    }

    fn save(&self) -> std::io::Result<()> {
        let Some(file) = &self.file else { return Ok(()) };
        if let Some(dir) = file.parent() {
            std::fs::create_dir_all(dir)?;
        }
        let text: String = self.files.iter().map(|p| format!("{}\n", p.display())).collect();
        let options = octovox::io::atomic::WriteOptions::default();
        octovox::io::atomic::write_atomically(file, options, |f| std::io::Write::write_all(f, text.as_bytes()))
    }
}
