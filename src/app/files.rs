//! Scenes in and out of the window: replacing the scene, the unsaved-changes
//! guard, saving, and loading on a background thread (in the browser, at
//! once: its files are in memory).

use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, TryRecvError};
use web_time::Instant;

use octovox::io::atomic::WriteOptions;
use octovox::io::output::same_file;
use octovox::scene::Scene;

use octovox::journal::{Checks, FileStamp};
use octovox::script::Line::Load;

use super::dialog_kind::DialogKind;
use super::document::Loading;
use super::gesture::Gesture;
use super::journal::{Found, JournalStart, classify};
use super::session::{Session, first_used_color};
use super::{Choice, Pending, camera_control, ui};

impl Session {
    /// Puts a new scene in place (load, New, a built-in scene) and uploads
    /// it whole; `source` is the script line that makes it (`load`, `new`,
    /// `demo`), which the recorder writes.
    /// `stamp` is the loaded file's as it was read (`JournalStart`).
    pub(super) fn replace_scene(&mut self, scene: Scene, source: octovox::script::Line, stamp: Option<FileStamp>) {
        self.doc.editor.set_scene(scene);
        self.scene_replaced(source, stamp);
    }

    /// Follows up a scene the editor just put in place (opened, or made by a
    /// `new` or `demo` line): the recording, a fresh journal, the title, and
    /// all of it to the GPU.
    pub(super) fn scene_replaced(&mut self, source: octovox::script::Line, stamp: Option<FileStamp>) {
        let (path, line) = match source {
            octovox::script::Line::Load(path) => {
                let absolute = std::fs::canonicalize(&path).unwrap_or_else(|_| path.clone());
                (Some(path), octovox::script::Line::Load(absolute))
            }
            line => (None, line),
        };
        self.record(|r| r.scene(line.clone()));
        // A new scene starts still, at the frame it was opened at.
        self.ui.playback.stop();
        // The old document's edits were saved or discarded before this.
        self.close_journal();
        // The line that makes the scene starts its journal (untitled ones too).
        self.doc.journal_start = match line {
            octovox::script::Line::Load(path) => JournalStart { lines: vec![Load(path)], stamp },
            line => JournalStart::of(vec![line]),
        };
        self.gesture = Gesture::Idle;
        self.readouts.stats.last_edit_bytes = None;
        // What the presets cost was measured on the scene before.
        self.readouts.presets_measured = None;
        // An imported mesh has no .vox to save back to: Save asks for one
        // rather than writing .vox bytes over the .obj.
        self.state.path = path.filter(|p| !octovox::io::is_mesh_path(p));
        self.state.saved_state = Some(self.doc.editor.history.state_id());
        self.doc.editor.tools.color = first_used_color(&self.doc.editor.scene).unwrap_or(self.doc.editor.tools.color);
        let upload = self.upload();
        log::info!("scene uploaded: {} bytes", upload.bytes);
        self.update_title();
        self.request_redraw();
    }

    /// Runs `action` now, or first asks about unsaved changes.
    pub(super) fn guard_unsaved(&mut self, action: Pending) {
        if self.unsaved() {
            self.ui.pending = Some(action);
            self.ui.prompt_open = true;
        } else {
            self.perform(action);
        }
    }

    pub(super) fn resolve(&mut self, choice: Choice) {
        self.ui.prompt_open = false;
        let Some(pending) = self.ui.pending.take() else { return };
        match choice {
            Choice::Cancel => {}
            Choice::Discard => self.perform(pending),
            Choice::Save => match self.state.path.clone() {
                Some(path) => {
                    if self.save_document(&path, WriteOptions::default()) {
                        self.perform(pending);
                    } else if self.ui.replace.is_some() {
                        // Replacing from the prompt carries on with it.
                        self.ui.pending = Some(pending);
                    }
                }
                None => {
                    // Ask for a path; SaveAs carries on with the pending action.
                    self.ui.pending = Some(pending);
                    self.ask_path(DialogKind::SaveAs, "saves/untitled.vox".into());
                }
            },
        }
    }

    pub(super) fn perform(&mut self, action: Pending) {
        match action {
            Pending::New => {
                self.replace_scene(Scene::default(), octovox::script::Line::New, None);
                let volume = self.state.working_volume();
                self.state.camera = camera_control::fresh_camera(self.state.camera.fov_y_deg, None);
                self.frame_box(Some(volume));
                report!("new: an empty scene on the ground");
            }
            Pending::Open(path) => self.start_loading(path),
            Pending::Quit => {
                // Saved or discarded: nothing is left to recover.
                self.close_journal();
                self.effects.exit = true;
            }
        }
    }

    /// Applies a crash-recovery journal (what `octovox recover` does): the
    /// open document's, and journaling goes on at its end; or an untitled
    /// scene's, which this session's own journal then replaces. `checks`
    /// says whether the user chose to apply it to a changed document.
    pub(super) fn recover_journal(&mut self, journal: &Path, checks: Checks) {
        let document = self.state.path.clone().filter(|d| octovox::journal::journal_path(d) == journal);
        let recovered = match &document {
            Some(document) => octovox::journal::recover(document, checks),
            None => octovox::journal::recover_from(journal, None, checks),
        };
        let scene = match recovered {
            Ok(scene) => scene,
            Err(err) => return self.ui.error(format!("cannot recover: {err}")),
        };
        let source = document.clone().map_or(octovox::script::Line::New, octovox::script::Line::Load);
        self.replace_scene(scene, source, None);
        // What is shown is the scene plus its journal, not yet saved.
        self.state.saved_state = None;
        if document.is_some() {
            match octovox::replay::Recorder::append(journal) {
                Ok(recorder) => self.doc.journal = Some(recorder),
                Err(err) => self.ui.error(format!("cannot go on with the journal {}: {err}", journal.display())),
            }
        } else {
            // This session's own journal starts from the recovered scene;
            // the dead session's journal and snapshot go.
            self.restart_journal_from_snapshot();
            if self.doc.journal.is_some() {
                octovox::journal::discard(journal);
            }
        }
        let what = document.as_ref().map_or_else(|| "the untitled scene".to_string(), |d| d.display().to_string());
        report!("recovered: {what}");
        self.ui.info(format!("recovered the unsaved edits of {what}"));
        self.update_title();
    }

    /// A journal found beside the document just opened (or an untitled
    /// one a dead session left): offered, or said to be another window's,
    /// or removed when a finished save holds its edits.
    pub(super) fn found_journal(&mut self, journal: PathBuf, document: Option<&Path>) {
        match classify(&journal, document) {
            Found::Offer(doubt) => {
                report!("asking: recover {}", journal.display());
                self.ui.recover = Some((journal, doubt));
            }
            Found::Live(text) => {
                report!("journal live: {}", journal.display());
                self.journal_failed(format!("{text}; this window's edits are not journaled"));
            }
            Found::Stale(text) => {
                report!("journal stale: {}", journal.display());
                self.ui.info(text);
            }
        }
    }

    /// Where this session journals a scene that has no file.
    pub(super) fn untitled_journal_path(&self) -> PathBuf {
        octovox::journal::untitled_journal_path(Path::new(super::SAVES_DIR), octovox::journal::session_id())
    }

    /// Saves, then makes `path` the document and carries on with an action
    /// that waited for a path to save to.
    pub(super) fn save_as(&mut self, path: PathBuf, options: WriteOptions) {
        if self.save_document(&path, options) {
            self.state.path = Some(path);
            self.update_title();
            if let Some(pending) = self.ui.pending.take() {
                self.perform(pending);
            }
        }
    }

    /// Saves atomically; reports the outcome in the UI and on stdout. A
    /// read-only file is not replaced: the user is asked first.
    pub(super) fn save_document(&mut self, path: &Path, options: WriteOptions) -> bool {
        // A save ends the drag under way: the file holds whole undo steps,
        // and a journal started after it never begins inside one.
        self.close_strokes();
        if !options.overwrite_read_only && octovox::io::atomic::is_read_only(path) {
            report!("asking: {} is read-only", path.display());
            self.ui.replace = Some(ui::Replace { path: path.to_path_buf(), read_only: true });
            return false;
        }
        // Nothing replaces a file but the document's own unless the user
        // says so (issue 48, item 5: Save As onto an existing file replaced it).
        let own = self.state.path.as_deref().is_some_and(|own| own == path || same_file(own, path));
        if !options.overwrite_read_only && path.exists() && !own {
            report!("asking: {} exists", path.display());
            self.ui.replace = Some(ui::Replace { path: path.to_path_buf(), read_only: false });
            return false;
        }
        // Just before the rename, the journal notes which file will hold its
        // edits: a kill before the journal's removal leaves it stale, not
        // replayed a second time.
        let target = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
        let journal = std::cell::RefCell::new(self.doc.journal.take());
        let saved_hash = std::cell::RefCell::new(None);
        let note = |sha256: &str| {
            *saved_hash.borrow_mut() = Some(sha256.to_owned());
            if let Some(journal) = journal.borrow_mut().as_mut()
                && let Err(err) = journal.note(&octovox::journal::saved_note(sha256, &target))
            {
                log::warn!("cannot note the save in the crash-recovery journal: {err}");
            }
        };
        let result = octovox::io::save_scene(
            path,
            &self.doc.editor.scene,
            WriteOptions { before_replace: Some(&note), ..options },
        );
        self.doc.journal = journal.into_inner();
        match result {
            Ok(()) => {
                hold_for_tests_after_rename();
                self.doc.recent.add(path);
                report!("saved: {}", path.display());
                // Saved in the middle of a stroke: the state the stroke
                // ends in gets a new id, so it will count as unsaved.
                self.state.saved_state = Some(self.doc.editor.history.state_id()).filter(|&id| id != u64::MAX);
                // The file now holds every edit: the journal starts again from it.
                self.close_journal();
                let absolute = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
                // The hash the save computed: the file is not read again.
                self.doc.journal_start = JournalStart::load(absolute, saved_hash.into_inner());
                match octovox::io::magicavoxel_note(path, &self.doc.editor.scene) {
                    Some(note) => {
                        report!("note: {note}");
                        self.ui.info(format!("saved {}; {note}", path.display()));
                    }
                    None => self.ui.info(format!("saved {}", path.display())),
                }
                self.update_title();
                true
            }
            Err(err) => {
                self.ui.error(format!("save failed: {err}"));
                false
            }
        }
    }

    /// Exports the scene as a mesh, by the rules of `octovox export`: an
    /// existing mesh or the open document is never replaced.
    pub(super) fn export(&mut self, path: &Path) {
        let inputs: Vec<&Path> = self.state.path.iter().map(PathBuf::as_path).collect();
        let result =
            octovox::io::export::check_outputs(path, &inputs, false).map_err(|e| e.to_string()).and_then(|()| {
                octovox::io::export::export_mesh(path, &self.doc.editor.scene, 1.0, WriteOptions::default())
                    .map_err(|e| e.to_string())
            });
        match result {
            Ok(stats) => {
                report!("exported: {} ({} triangles)", path.display(), stats.triangles);
                self.ui.info(format!("exported {} triangles to {}", stats.triangles, path.display()));
            }
            Err(err) => self.ui.error(format!("export failed: {err}")),
        }
    }

    /// Reads a .vox or .ovx (or voxelizes an .obj) on a background thread; the
    /// window keeps drawing.
    pub(super) fn start_loading(&mut self, path: PathBuf) {
        let (tx, rx) = mpsc::channel();
        let thread_path = path.clone();
        let progress = octovox::io::progress::Progress::default();
        let reporter = progress.clone();
        let load = move || {
            // The stamp before the read: a change on disk after it is one the
            // journal's recovery then notices.
            let stamp = FileStamp::of(&thread_path).ok();
            let result = octovox::io::load_scene_with(&thread_path, 0, &reporter).map(|scene| (scene, stamp));
            // The window may have closed meanwhile; then nobody wants the scene.
            let _ = tx.send(result);
        };
        #[cfg(not(target_arch = "wasm32"))]
        let spawned = std::thread::Builder::new().name("vox loader".into()).spawn(load);
        // The page has one thread, and its files are in memory: read now;
        // the next frame takes the scene as from a loader thread.
        #[cfg(target_arch = "wasm32")]
        let spawned = {
            load();
            std::io::Result::Ok(())
        };
        match spawned {
            Ok(_) => self.doc.loading = Some(Loading { path, started: Instant::now(), progress, result: rx }),
            Err(err) => self.ui.error(format!("cannot start loading: {err}")),
        }
        self.request_redraw();
    }

    pub(super) fn poll_loading(&mut self) {
        let Some(loading) = &self.doc.loading else { return };
        let result = match loading.result.try_recv() {
            Ok(result) => result.map_err(|err| err.to_string()),
            Err(TryRecvError::Empty) => return,
            Err(TryRecvError::Disconnected) => Err("the loader thread stopped".to_owned()),
        };
        let Some(loading) = self.doc.loading.take() else { return };
        match result {
            Ok((scene, stamp)) => {
                self.doc.recent.add(&loading.path);
                let seconds = loading.started.elapsed().as_secs_f64();
                report!("loaded: {} ({} voxels, {seconds:.2} s)", loading.path.display(), scene.solid_voxels());
                self.replace_scene(scene, Load(loading.path.clone()), stamp);
                // A camera from the command line wins for the file it came with.
                let keep_camera = self.camera_for.as_ref() == Some(&loading.path);
                if !keep_camera {
                    // A new document starts in the default view, not the last one's.
                    self.state.camera = camera_control::fresh_camera(self.state.camera.fov_y_deg, None);
                    self.frame_box(self.doc.editor.scene.solid_bounds());
                }
                self.ui.info(format!("opened {}", loading.path.display()));
                if let Some(document) = self.state.path.clone()
                    && let Some(journal) = octovox::journal::find(&document)
                {
                    self.found_journal(journal, Some(&document));
                }
            }
            Err(err) => self.ui.error(format!("cannot open {}: {err}", loading.path.display())),
        }
    }
}

/// With `OCTOVOX_TEST_HOLD_AFTER_SAVE` set, a save stops between its rename
/// and the journal's removal, says so, and waits to be killed: the moment a
/// crash would leave a journal whose edits the file already holds, which a
/// test cannot otherwise reach (tests/window/recovery.rs).
fn hold_for_tests_after_rename() {
    if std::env::var_os("OCTOVOX_TEST_HOLD_AFTER_SAVE").is_some() {
        report!("test hold: saved, the journal not yet removed");
        loop {
            std::thread::sleep(std::time::Duration::from_secs(3600));
        }
    }
}
