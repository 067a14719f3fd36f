//! `--replay SCRIPT` plays a script visibly, one line per frame: the lines
//! that edit or read the scene go to the editor, as in `octovox replay`, and
//! through `App::run_line`, as mouse actions do (so they are recorded and
//! journaled); files, the camera and pixels are the window's. `--record
//! PATH` writes the session as a script.

use std::path::{Path, PathBuf};

use octovox::camera::Camera;
use octovox::editor::Outcome;
use octovox::replay::{Command as Line, Script};

use super::{App, Command};

/// A script being played in the window.
pub struct Player {
    script: Script,
    base: PathBuf,
    next: usize,
    passed: usize,
    failed: usize,
}

impl Player {
    pub fn new(script: Script) -> Player {
        let base = script.path.parent().unwrap_or(Path::new(".")).to_path_buf();
        Player { script, base, next: 0, passed: 0, failed: 0 }
    }
}

/// What one played line did.
enum Played {
    Done,
    Passed,
    /// A failed expectation or a line that could not run, with the message.
    Failed(String),
}

impl Played {
    fn check(ok: bool, message: String) -> Played {
        if ok { Played::Passed } else { Played::Failed(message) }
    }
}

impl App {
    /// Plays the next script line, if a script is playing and the app is
    /// idle (not loading). Prints the summary after the last line.
    pub(super) fn play_step(&mut self, event_loop: &winit::event_loop::ActiveEventLoop) {
        if self.loading.is_some() {
            return;
        }
        let Some(player) = &mut self.player else { return };
        let Some(line) = player.script.lines.get(player.next).cloned() else {
            report!("replay: {} passed, {} failed", player.passed, player.failed);
            self.ui.info(format!("replay done: {} passed, {} failed", player.passed, player.failed));
            self.player = None;
            return;
        };
        player.next += 1;
        let base = player.base.clone();
        let where_ = format!("{}:{}", player.script.path.display(), line.number);
        match self.play_line(&base, &line.command, event_loop) {
            Played::Done => {}
            Played::Passed => self.with_player(|p| p.passed += 1),
            Played::Failed(message) => {
                self.with_player(|p| p.failed += 1);
                report!("{where_}: {message}");
                self.ui.error(format!("{where_}: {message}"));
            }
        }
        self.request_redraw();
    }

    fn with_player(&mut self, f: impl FnOnce(&mut Player)) {
        if let Some(player) = &mut self.player {
            f(player);
        }
    }

    /// Carries out one line.
    fn play_line(&mut self, base: &Path, line: &Line, event_loop: &winit::event_loop::ActiveEventLoop) -> Played {
        match line {
            Line::Load(path) => self.start_loading(base.join(path)),
            Line::Camera { eye, target, fov } => {
                let fov_y_deg = fov.unwrap_or(self.state.camera.fov_y_deg);
                self.execute(Command::SetCamera(Camera { eye: *eye, target: *target, fov_y_deg }), event_loop);
            }
            // The window's size is the viewport.
            Line::Viewport(..) => {}
            Line::Click { x, y, tool } => match self.pick_at(f64::from(*x) + 0.5, f64::from(*y) + 0.5) {
                // A click is the place, remove or paint of the cell it picks.
                Ok(Some(pick)) => {
                    let center = octovox::tool::click_target(*tool, pick.voxel, pick.normal);
                    return self.play_editor_line(&octovox::replay::edit_command(*tool, center));
                }
                Ok(None) => return Played::Failed(format!("expected pixel ({x}, {y}) to hit a voxel, got nothing")),
                Err(gave_up) => return Played::Failed(format!("expected pixel ({x}, {y}) to hit a voxel: {gave_up}")),
            },
            Line::Save(path) => {
                if !self.save(&base.join(path), octovox::io::atomic::WriteOptions::default()) {
                    return Played::Failed(format!("could not save {}", path.display()));
                }
            }
            Line::Render(path) => {
                self.screenshot_path = Some(base.join(path));
                self.execute(Command::Screenshot, event_loop);
            }
            Line::ExpectWritten(limit) => {
                let got = self.stats.last_edit_bytes;
                return Played::check(got <= *limit, format!("expected at most {limit} bytes written, got {got}"));
            }
            Line::ExpectEffects(want) => {
                let (ok, got) = octovox::replay::effects_match(&self.editor.scene, &self.state.path_settings, want);
                let message = format!("expected effects [{}], got [{}]", want.join(" "), got.join(" "));
                return Played::check(ok, message);
            }
            // The window's size and panels differ from a headless render.
            Line::ExpectImage(..) => {
                report!("replay: 'expect image' is checked by `octovox replay`, not in the window")
            }
            _ => return self.play_editor_line(line),
        }
        Played::Done
    }

    /// A line the editor carries out, as `octovox replay` would.
    fn play_editor_line(&mut self, line: &Line) -> Played {
        match self.run_line(line) {
            Ok(Outcome::Checked { ok, expected, got }) => Played::check(ok, format!("expected {expected}, got {got}")),
            Ok(_) => Played::Done,
            Err(message) => Played::Failed(message),
        }
    }
}

impl App {
    /// Opens `--replay` and `--record` files given on the command line.
    pub(super) fn open_script_files(&mut self) {
        if let Some(path) = self.args.replay.clone() {
            match octovox::replay::load_script(&path) {
                Ok(script) => self.player = Some(Player::new(script)),
                Err(errors) => {
                    for error in &errors {
                        report!("{error}");
                    }
                    self.ui.error(format!("cannot play {}: {} error(s)", path.display(), errors.len()));
                }
            }
        }
        if let Some(path) = self.args.record.clone() {
            match octovox::replay::Recorder::create(&path) {
                Ok(recorder) => self.recorder = Some(recorder),
                Err(err) => self.ui.error(format!("cannot record to {}: {err}", path.display())),
            }
        }
    }
}
