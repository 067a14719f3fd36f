//! The window's side of crash recovery (`octovox::journal`): the journal
//! of the open scene starts at its first unsaved change, gets every change
//! before the change is reported done, and is removed on save or discard.
//! A change the journal cannot express as a line (an undo of a step made
//! before it started, a paste of a block copied before it started) starts
//! it again from a snapshot of the scene.

use std::path::{Path, PathBuf};

use octovox::journal::{FileStamp, RecoverError};
use octovox::replay::Recorder;
use octovox::script::Line;

use super::session::Session;

/// What starts the open scene's journal: the lines that make the scene as
/// it is on disk (or as it started, for an untitled one), and the stamp of
/// the file its `load` line loads, taken when the window read it (so a
/// file changed on disk after that is caught at recovery, not hidden).
#[derive(Debug, Default)]
pub(super) struct JournalStart {
    pub lines: Vec<Line>,
    pub stamp: Option<FileStamp>,
}

impl JournalStart {
    /// The journal starts from `lines`; no file stamp (a built-in or new scene).
    pub fn of(lines: Vec<Line>) -> JournalStart {
        JournalStart { lines, stamp: None }
    }

    /// The journal starts by loading `path` (absolute), as it is on disk
    /// now; `sha256` is its hash where the caller just computed it.
    pub fn load(path: PathBuf, sha256: Option<String>) -> JournalStart {
        let stamp = FileStamp::with_hash(&path, sha256).ok();
        JournalStart { lines: vec![Line::Load(path)], stamp }
    }

    fn clear(&mut self) {
        self.lines.clear();
        self.stamp = None;
    }
}

/// What the window does with a journal found beside a document it opened
/// (or an untitled one of a session that is gone).
pub(super) enum Found {
    /// Offer to apply it; with the reason to think twice, if there is one.
    Offer(Option<String>),
    /// Another window edits with it: leave it alone and say so.
    Live(String),
    /// A finished save holds its edits: it was removed.
    Stale(String),
}

/// Looks at a journal before the window offers it.
pub(super) fn classify(journal: &Path, document: Option<&Path>) -> Found {
    match octovox::journal::read(journal, document, octovox::journal::Checks::default()) {
        Err(err @ RecoverError::Live { .. }) => Found::Live(err.to_string()),
        Err(err @ RecoverError::Saved { .. }) => {
            octovox::journal::discard(journal);
            Found::Stale(format!("{err}: removed it"))
        }
        Err(err @ RecoverError::Changed { .. }) => Found::Offer(Some(err.to_string())),
        // Other faults are reported when the user asks to recover.
        Ok(_) | Err(_) => Found::Offer(None),
    }
}

impl Session {
    /// Runs `f` on the recorder and on the scene's journal (started at the
    /// first unsaved change); an I/O error stops that one, and the status
    /// bar says the edits are not protected until a journal starts again
    /// (the next save, or another document).
    pub(super) fn record(&mut self, f: impl Fn(&mut Recorder) -> std::io::Result<()>) {
        self.record_to_recording(&f);
        self.open_journal(self.doc.editor.selection);
        if let Some(journal) = &mut self.doc.journal
            && let Err(err) = f(journal)
        {
            let text = format!("the crash-recovery journal {} stopped: {err}", journal.path().display());
            self.journal_failed(text);
        }
    }

    /// The journal cannot go on: it is dropped (its lock with it), and the
    /// status bar says so until a journal starts again.
    pub(super) fn journal_failed(&mut self, text: String) {
        log::warn!("{text}");
        report!("journal failed: {text}");
        self.ui.journal_warning = Some(format!("unsaved edits are not protected: {text}"));
        self.doc.journal = None;
        self.doc.journal_start.clear();
    }

    /// Records an undo (or redo) the history just made. The journal gets
    /// `undo 1` when the step is in it; otherwise it starts again from a
    /// snapshot of the scene as it is now.
    pub(super) fn record_undo(&mut self, undo: bool) {
        let step = |r: &mut Recorder| if undo { r.undo() } else { r.redo() };
        let journal_has_it = self.doc.journal.as_ref().is_some_and(|j| if undo { j.can_undo() } else { j.can_redo() });
        if journal_has_it {
            return self.record(step);
        }
        self.record_to_recording(step);
        self.restart_journal_from_snapshot();
    }

    /// Runs `f` on the `--record` recorder only.
    pub(super) fn record_to_recording(&mut self, f: impl Fn(&mut Recorder) -> std::io::Result<()>) {
        if let Some(recorder) = &mut self.doc.recorder
            && let Err(err) = f(recorder)
        {
            self.ui.error(format!("recording to {} stopped: {err}", recorder.path().display()));
            self.doc.recorder = None;
        }
    }

    /// Where the open scene's journal goes: beside its file, or in saves/
    /// under this session's process id for a scene without one.
    fn journal_file(&self) -> PathBuf {
        match &self.state.path {
            Some(document) => octovox::journal::journal_path(document),
            None => self.untitled_journal_path(),
        }
    }

    /// Starts the journal of the open scene once it has unsaved changes:
    /// its first lines make the scene as it is on disk (or as it started,
    /// for an untitled one), with the stamp of the file it loads, then
    /// `selection`: the selection in force before the change (a `move` as
    /// the first edit moves it).
    pub(super) fn open_journal(&mut self, selection: Option<octovox::edit::selection::Region>) {
        if self.doc.journal.is_some() || !self.unsaved() || self.doc.journal_start.lines.is_empty() {
            return;
        }
        let path = self.journal_file();
        let header = match &self.state.path {
            Some(document) => format!("crash-recovery journal of {}: `octovox recover` replays it", document.display()),
            None => "crash-recovery journal of an untitled scene: `octovox recover THIS_FILE -o OUT.vox` replays it"
                .to_string(),
        };
        if let Some(dir) = path.parent() {
            let _ = std::fs::create_dir_all(dir);
        }
        let selection = selection.map(|r| Line::Select(Some((r.min, r.max))));
        // The object picked before the journal began (a click's `object N` runs before its edit).
        let picked = self
            .doc
            .editor
            .scene
            .objects()
            .and_then(|o| o.selected)
            .map(|i| Line::Object(octovox::script::ObjectLine::Pick(octovox::script::ObjectRef::Index(i))));
        let selection = selection.into_iter().chain(picked);
        let (lines, stamp) = (&self.doc.journal_start.lines, &self.doc.journal_start.stamp);
        // A journal that starts within a stroke (its first change is one of
        // the stroke's: a save ends strokes, so its earlier edits are in no
        // file) begins the stroke too, so that recovery makes the same steps.
        let stroke = self.doc.editor.history.stroke_open();
        let (tools, camera) = (self.doc.editor.tools, self.state.camera);
        let started = Recorder::journal(&path, &header).and_then(|mut journal| {
            let write = |journal: &mut Recorder| -> std::io::Result<()> {
                if let Some(stamp) = stamp {
                    journal.note(&stamp.note())?;
                }
                lines.iter().cloned().chain(selection.clone()).try_for_each(|line| journal.scene(line))?;
                if stroke {
                    journal.ran(&Line::Stroke(true), &tools, &camera, false)?;
                }
                Ok(())
            };
            if let Err(err) = write(&mut journal) {
                // No journal that holds only part of its start is left behind.
                octovox::journal::discard(journal.path());
                return Err(err);
            }
            Ok(journal)
        });
        match started {
            Ok(journal) => {
                self.doc.journal = Some(journal);
                self.ui.journal_warning = None;
                // What the clipboard holds was copied before this journal.
                self.doc.clipboard_journaled = false;
            }
            Err(err) => {
                self.journal_failed(format!("cannot write the crash-recovery journal {}: {err}", path.display()))
            }
        }
    }

    /// Starts the journal again from a snapshot of the scene as it is now,
    /// saved beside it (`octovox::journal::snapshot_path`).
    pub(super) fn restart_journal_from_snapshot(&mut self) {
        if self.doc.journal_start.lines.is_empty() {
            return;
        }
        let journal = self.journal_file();
        let snapshot = octovox::journal::snapshot_path(&journal);
        self.close_journal();
        if let Some(dir) = snapshot.parent() {
            let _ = std::fs::create_dir_all(dir);
        }
        // The save hashes what it writes: the snapshot is not read again for its stamp.
        let hash = std::cell::RefCell::new(None);
        let keep = |sha256: &str| *hash.borrow_mut() = Some(sha256.to_owned());
        let options = octovox::io::atomic::WriteOptions { before_replace: Some(&keep), ..Default::default() };
        match octovox::io::save_scene(&snapshot, &self.doc.editor.scene, options) {
            Ok(()) => {
                let absolute = std::fs::canonicalize(&snapshot).unwrap_or(snapshot);
                self.doc.journal_start = JournalStart::load(absolute, hash.into_inner());
                self.open_journal(self.doc.editor.selection);
            }
            Err(err) => self.journal_failed(format!("cannot snapshot the scene for the crash-recovery journal: {err}")),
        }
    }

    /// Removes the journal and its snapshot (the lock goes with the
    /// recorder, after the file): the scene was saved, or its edits
    /// discarded.
    pub(super) fn close_journal(&mut self) {
        if let Some(journal) = self.doc.journal.take() {
            octovox::journal::discard(journal.path());
        }
        self.ui.journal_warning = None;
    }
}
