//! Native file dialogs (rfd: the desktop portal over D-Bus, else zenity),
//! run on a thread of their own so the window keeps drawing. Where neither
//! is there, or a dialog gives up without showing itself, the file browser
//! inside the window (`browser`) asks instead.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, TryRecvError};
use std::time::{Duration, Instant};

use winit::event_loop::ActiveEventLoop;

use super::super::browser::Browser;
use super::super::dialog_kind::DialogKind;
use super::App;

/// A dialog that answers faster than this never showed itself: nobody
/// picks or cancels a file that fast.
const NO_DIALOG_WITHIN: Duration = Duration::from_millis(300);

/// A native dialog that is open.
pub struct NativeDialog {
    kind: DialogKind,
    /// Where the browser starts if the dialog never shows.
    start: String,
    /// The path chosen (`None`: cancelled, or no dialog), and how long the
    /// dialog took, measured by its thread.
    answer: Receiver<(Option<PathBuf>, Duration)>,
}

/// Whether a native dialog can show: zenity is installed, or a desktop
/// portal is on the session bus (it starts on demand, so its service file
/// is what tells). `OCTOVOX_NO_NATIVE_DIALOGS` turns them off.
pub fn available() -> bool {
    if std::env::var_os("OCTOVOX_NO_NATIVE_DIALOGS").is_some() {
        return false;
    }
    let on_path = |name: &str| {
        std::env::var_os("PATH").is_some_and(|paths| std::env::split_paths(&paths).any(|d| d.join(name).is_file()))
    };
    let portal = || {
        let dirs = std::env::var("XDG_DATA_DIRS").unwrap_or_else(|_| "/usr/local/share:/usr/share".into());
        std::env::split_paths(&dirs).any(|d| d.join("dbus-1/services/org.freedesktop.portal.Desktop.service").is_file())
    };
    on_path("zenity") || (std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_some() && portal())
}

/// The rfd dialog of `kind`, starting at `start` (a path, maybe relative).
fn dialog(kind: DialogKind, start: &Path) -> rfd::FileDialog {
    let folder = match start.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let folder = std::fs::canonicalize(&folder).unwrap_or(folder);
    let name = start.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let dialog = rfd::FileDialog::new().set_directory(folder).set_title(kind.title());
    let dialog = dialog.add_filter(kind.extensions().join(", "), kind.extensions());
    if kind.opens() { dialog.add_filter("All files", &["*"]) } else { dialog.set_file_name(name) }
}

impl App {
    /// Asks for a path for `kind`: in a native dialog where there is one,
    /// else in the window's file browser, starting at `start`.
    pub(super) fn ask_path(&mut self, kind: DialogKind, start: String) {
        if self.file_dialog.is_some() {
            return self.session.ui.info("a file dialog is open");
        }
        if !available() {
            return self.open_browser(kind, &start);
        }
        let (tx, rx) = mpsc::channel();
        let from = PathBuf::from(&start);
        let spawned = std::thread::Builder::new().name("file dialog".into()).spawn(move || {
            let (d, opened) = (dialog(kind, &from), Instant::now());
            let chosen = if kind.opens() { d.pick_file() } else { d.save_file() };
            let _ = tx.send((chosen, opened.elapsed()));
        });
        match spawned {
            Ok(_) => {
                report!("file dialog: native");
                self.file_dialog = Some(NativeDialog { kind, start, answer: rx });
            }
            Err(_) => self.open_browser(kind, &start),
        }
    }

    fn open_browser(&mut self, kind: DialogKind, start: &str) {
        let recent: Vec<PathBuf> = self.session.doc.recent.files().cloned().collect();
        self.session.ui.dialog = Some(Browser::new(kind, start, &recent));
        // Drawn now, not at the next input: a click meant for it must not reach the scene.
        self.request_redraw();
        report!("file dialog: browser");
    }

    /// Carries out the answer of the open native dialog, once it came.
    pub(super) fn poll_file_dialog(&mut self, event_loop: &ActiveEventLoop) {
        let Some(open) = &self.file_dialog else { return };
        let (answer, took) = match open.answer.try_recv() {
            Ok(answer) => answer,
            Err(TryRecvError::Empty) => return,
            Err(TryRecvError::Disconnected) => (None, Duration::ZERO),
        };
        let Some(open) = self.file_dialog.take() else { return };
        match answer {
            Some(path) => self.execute(open.kind.command(path), event_loop),
            None if took < NO_DIALOG_WITHIN => {
                report!("file dialog: none showed; asking in the window");
                self.open_browser(open.kind, &open.start);
            }
            // Cancelled: an action that waited for a path waits no more.
            None => self.session.ui.pending = None,
        }
        self.request_redraw();
    }
}
