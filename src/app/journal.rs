//! The window's side of crash recovery (`octovox::journal`): the journal
//! of the open scene starts at its first unsaved change, gets every change
//! before the change is reported done, and is removed on save or discard.
//! A change the journal cannot express as a line (an undo of a step made
//! before it started, a paste of a block copied before it started) starts
//! it again from a snapshot of the scene.

use std::path::PathBuf;

use octovox::replay::{Command as Line, Recorder};

use super::App;

impl App {
    /// Runs `f` on the recorder and on the scene's journal (started at the
    /// first unsaved change); an I/O error stops that one with a message.
    pub(super) fn record(&mut self, f: impl Fn(&mut Recorder) -> std::io::Result<()>) {
        self.record_to_recording(&f);
        self.open_journal();
        if let Some(journal) = &mut self.journal
            && let Err(err) = f(journal)
        {
            self.ui.error(format!("the crash-recovery journal {} stopped: {err}", journal.path().display()));
            self.journal = None;
            self.journal_source.clear();
        }
    }

    /// Records an undo (or redo) the history just made. The journal gets
    /// `undo 1` when the step is in it; otherwise it starts again from a
    /// snapshot of the scene as it is now.
    pub(super) fn record_undo(&mut self, undo: bool) {
        let step = |r: &mut Recorder| if undo { r.undo() } else { r.redo() };
        let journal_has_it = self.journal.as_ref().is_some_and(|j| if undo { j.can_undo() } else { j.can_redo() });
        if journal_has_it {
            return self.record(step);
        }
        self.record_to_recording(step);
        self.restart_journal_from_snapshot();
    }

    /// Runs `f` on the `--record` recorder only.
    pub(super) fn record_to_recording(&mut self, f: impl Fn(&mut Recorder) -> std::io::Result<()>) {
        if let Some(recorder) = &mut self.recorder
            && let Err(err) = f(recorder)
        {
            self.ui.error(format!("recording to {} stopped: {err}", recorder.path().display()));
            self.recorder = None;
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
    /// for an untitled one), then the selection in force.
    fn open_journal(&mut self) {
        if self.journal.is_some() || !self.state.dirty || self.journal_source.is_empty() {
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
        let selection = self.editor.selection.map(|r| Line::Select(Some((r.min, r.max))));
        let start: Vec<Line> = self.journal_source.iter().cloned().chain(selection).collect();
        match Recorder::with_header(&path, &header).and_then(|mut journal| {
            start.into_iter().try_for_each(|line| journal.scene(line))?;
            Ok(journal)
        }) {
            Ok(journal) => {
                self.journal = Some(journal);
                // What the clipboard holds was copied before this journal.
                self.clipboard_journaled = false;
            }
            Err(err) => {
                self.ui.error(format!("cannot write the crash-recovery journal {}: {err}", path.display()));
                self.journal_source.clear();
            }
        }
    }

    /// Starts the journal again from a snapshot of the scene as it is now,
    /// saved beside it (`octovox::journal::snapshot_path`).
    pub(super) fn restart_journal_from_snapshot(&mut self) {
        if self.journal_source.is_empty() {
            return;
        }
        let journal = self.journal_file();
        let snapshot = octovox::journal::snapshot_path(&journal);
        self.close_journal();
        if let Some(dir) = snapshot.parent() {
            let _ = std::fs::create_dir_all(dir);
        }
        match octovox::io::save_scene(&snapshot, &self.editor.scene, octovox::io::atomic::WriteOptions::default()) {
            Ok(()) => {
                let absolute = std::fs::canonicalize(&snapshot).unwrap_or(snapshot);
                self.journal_source = vec![Line::Load(absolute)];
                self.open_journal();
            }
            Err(err) => {
                self.ui.error(format!("cannot snapshot the scene for the crash-recovery journal: {err}"));
                self.journal_source.clear();
            }
        }
    }

    /// Removes the journal and its snapshot: the scene was saved, or its
    /// edits discarded.
    pub(super) fn close_journal(&mut self) {
        if let Some(journal) = self.journal.take() {
            let _ = std::fs::remove_file(octovox::journal::snapshot_path(journal.path()));
            let _ = std::fs::remove_file(journal.path());
        }
    }
}
