//! The open document: the engine's editor (scene, history, tools,
//! selection, clipboard), where its file comes from (a background load, the
//! recent files), its crash journal, and the scripts
//! played on it or recorded from it.

use std::path::PathBuf;
use std::sync::mpsc::Receiver;
use web_time::Instant;

use octovox::editor::Editor;
use octovox::io::LoadError;
use octovox::journal::FileStamp;
use octovox::replay::Recorder;
use octovox::scene::Scene;

use super::{journal, recent, script};

/// A file being read on a background thread.
pub(super) struct Loading {
    pub path: PathBuf,
    pub started: Instant,
    pub progress: octovox::io::progress::Progress,
    pub result: Receiver<Result<(Scene, Option<FileStamp>), LoadError>>,
}

pub(super) struct Document {
    /// Scene, history, brush, colour, mirror, selection: the engine's
    /// editor, which played scripts drive too.
    pub editor: Editor,
    pub loading: Option<Loading>,
    /// File ▸ Open recent.
    pub recent: recent::Recent,
    /// The crash-recovery journal of the open document (`octovox::journal`),
    /// and what starts it (the document as saved).
    pub journal: Option<Recorder>,
    pub journal_start: journal::JournalStart,
    /// The clipboard was filled by a `copy` or `cut` the open journal holds
    /// (else a paste starts the journal again from a snapshot).
    pub clipboard_journaled: bool,
    /// `--record`: where the session is written as a script.
    pub recorder: Option<Recorder>,
    /// `--replay`: the script being played.
    pub player: Option<script::Player>,
}

impl Default for Document {
    fn default() -> Document {
        Document {
            editor: Editor::default(),
            loading: None,
            recent: recent::Recent::load(),
            journal: None,
            journal_start: journal::JournalStart::default(),
            clipboard_journaled: false,
            recorder: None,
            player: None,
        }
    }
}
