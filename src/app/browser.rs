//! The file browser inside the window (egui_file), for desktops where no
//! native dialog shows: folders and the files of the kind asked for, a name
//! field, and a row of recent folders (those of the recent documents, the
//! working folder and `saves/`) above it.

use std::path::{Path, PathBuf};

use egui_file::{FileDialog, State};

use super::dialog_kind::DialogKind;

/// Recent folders shown.
const FOLDERS: usize = 6;

/// The browser's size, and how far below the window's centre its centre is.
const SIZE: [f32; 2] = [440.0, 300.0];
const BELOW_CENTRE: f32 = 20.0;

/// An open browser.
pub struct Browser {
    kind: DialogKind,
    dialog: FileDialog,
    folders: Vec<PathBuf>,
}

impl std::fmt::Debug for Browser {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Browser").field("kind", &self.kind).field("folder", &self.dialog.directory()).finish()
    }
}

/// What the browser answered this frame.
pub enum Answer {
    Waiting,
    Chosen(PathBuf),
    Cancelled,
}

impl Browser {
    /// A browser for `kind` in the folder of `start` (a path, maybe
    /// relative); a save starts with `start`'s file name. `recent`: the
    /// recent documents, newest first.
    pub fn new(kind: DialogKind, start: &str, recent: &[PathBuf]) -> Browser {
        let start = Path::new(start);
        let folder = match start.parent() {
            Some(parent) if !parent.as_os_str().is_empty() => parent,
            _ => Path::new("."),
        };
        let folder = std::path::absolute(folder).unwrap_or_else(|_| folder.to_path_buf());
        // A folder not made yet (`saves/` before the first save): the working one.
        let folder = if folder.is_dir() { folder } else { std::env::current_dir().unwrap_or(folder) };
        let extensions = kind.extensions();
        let listed = move |path: &Path| {
            let extension = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
            extensions.contains(&extension.as_str())
        };
        let dialog = if kind.opens() {
            FileDialog::open_file()
        } else {
            let name = start.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
            FileDialog::save_file().default_filename(name)
        };
        // Centred and of one size: it stays where the recent folders and the
        // window tests expect it.
        let mut dialog = dialog
            .initial_path(folder)
            .title(kind.title())
            .id(egui::Id::unique("file browser"))
            .anchor(egui::Align2::CENTER_CENTER, [0.0, BELOW_CENTRE])
            .default_size(SIZE)
            .resizable(false)
            .show_rename(false)
            .show_files_filter(Box::new(listed));
        dialog.open();
        Browser { kind, dialog, folders: recent_folders(recent) }
    }

    pub fn kind(&self) -> DialogKind {
        self.kind
    }

    /// Draws the browser and its recent folders.
    pub fn show(&mut self, ctx: &egui::Context) -> Answer {
        let mut go_to = None;
        // Above the browser, from its left edge.
        let screen = ctx.content_rect();
        let left_top = egui::pos2(screen.center().x - SIZE[0] / 2.0, screen.top() + 28.0);
        egui::Window::new("Recent folders")
            .id(egui::Id::unique("recent folders"))
            .fixed_pos(left_top)
            .title_bar(false)
            .resizable(false)
            .show(ctx, |ui| {
                ui.horizontal_wrapped(|ui| {
                    ui.label("Recent folders:");
                    for folder in &self.folders {
                        let name = folder
                            .file_name()
                            .map_or_else(|| folder.display().to_string(), |n| n.to_string_lossy().into_owned());
                        if ui.button(name).on_hover_text(folder.display().to_string()).clicked() {
                            go_to = Some(folder.clone());
                        }
                    }
                });
            });
        if let Some(folder) = go_to {
            self.dialog.set_path(folder);
        }
        match self.dialog.show(ctx).state() {
            State::Selected => self.dialog.path().map_or(Answer::Cancelled, |p| Answer::Chosen(p.to_path_buf())),
            State::Open => Answer::Waiting,
            State::Cancelled | State::Closed => Answer::Cancelled,
        }
    }
}

/// The folders of the recent documents (newest first), then the working
/// folder and its `saves/`: each once, those that exist.
fn recent_folders(recent: &[PathBuf]) -> Vec<PathBuf> {
    let here = std::env::current_dir().ok();
    let saves = here.as_ref().map(|h| h.join(super::SAVES_DIR));
    let mut folders: Vec<PathBuf> = Vec::new();
    let candidates = recent.iter().filter_map(|f| f.parent().map(Path::to_path_buf)).chain(here).chain(saves);
    for folder in candidates {
        if folder.is_dir() && !folders.contains(&folder) {
            folders.push(folder);
        }
    }
    folders.truncate(FOLDERS);
    folders
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recent_folders_come_once_newest_first_and_exist() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a"), dir.path().join("b"));
        std::fs::create_dir_all(&a).unwrap();
        std::fs::create_dir_all(&b).unwrap();
        let recent = [b.join("x.vox"), a.join("y.vox"), b.join("z.vox"), dir.path().join("gone/w.vox")];
        let folders = recent_folders(&recent);
        assert_eq!(folders[..2], [b, a]);
        assert!(folders.iter().all(|f| f.is_dir()));
        assert_eq!(folders.len(), folders.iter().collect::<std::collections::HashSet<_>>().len());
    }
}
