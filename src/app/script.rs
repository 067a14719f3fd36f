//! `--replay SCRIPT` plays a script visibly, one line per frame, through
//! the same interpreter as `octovox replay` (`octovox::replay::step`, with
//! the window as its host, see `host.rs`): so played lines are recorded and
//! journaled as mouse actions are. `--record PATH` writes the session as a
//! script.

use std::path::{Path, PathBuf};

use octovox::replay::{DEFAULT_VIEWPORT, StepResult};
use octovox::script::Script;

use super::session::Session;

/// A script being played in the window, and what its lines set that the
/// window itself has not: the size and the image of its renders.
pub struct Player {
    script: Script,
    base: PathBuf,
    next: usize,
    passed: usize,
    failed: usize,
    /// `viewport W H`: the size `render` makes its image at.
    pub viewport: (u32, u32),
    /// The image of the last `render`, for `expect image`.
    pub last_render: Option<image::RgbaImage>,
}

impl Player {
    pub fn new(script: Script) -> Player {
        let base = script.path.parent().unwrap_or(Path::new(".")).to_path_buf();
        Player { script, base, next: 0, passed: 0, failed: 0, viewport: DEFAULT_VIEWPORT, last_render: None }
    }

    /// The script's file.
    pub fn path(&self) -> &Path {
        &self.script.path
    }
}

impl Session {
    /// Plays the next script line, if a script is playing and the app is
    /// idle (not loading). Prints the summary after the last line.
    pub(super) fn play_step(&mut self) {
        if self.doc.loading.is_some() {
            return;
        }
        let Some(player) = &mut self.doc.player else { return };
        let Some(line) = player.script.lines.get(player.next).cloned() else {
            report!("replay: {} passed, {} failed", player.passed, player.failed);
            self.ui.info(format!("replay done: {} passed, {} failed", player.passed, player.failed));
            self.doc.player = None;
            return;
        };
        player.next += 1;
        let base = player.base.clone();
        let where_ = format!("{}:{}", player.script.path.display(), line.number);
        let failure = match self.run_script_line(&base, &line.command) {
            Ok(StepResult::Done | StepResult::Ran(_)) => None,
            Ok(StepResult::Passed) => {
                self.with_player(|p| p.passed += 1);
                None
            }
            Ok(StepResult::Failed { expected, got }) => Some(format!("expected {expected}, got {got}")),
            Err(err) => {
                // A line that cannot run stops the script, as in `octovox replay`.
                self.with_player(|p| p.next = p.script.lines.len());
                Some(err.to_string())
            }
        };
        if let Some(message) = failure {
            self.with_player(|p| p.failed += 1);
            report!("{where_}: {message}");
            self.ui.error(format!("{where_}: {message}"));
        }
        self.request_redraw();
    }

    fn with_player(&mut self, f: impl FnOnce(&mut Player)) {
        if let Some(player) = &mut self.doc.player {
            f(player);
        }
    }
}

impl Session {
    /// Opens `--replay` and `--record` files given on the command line.
    pub(super) fn open_script_files(&mut self, replay: Option<&Path>, record: Option<&Path>) {
        if let Some(path) = replay {
            match octovox::script::load_script(path) {
                Ok(script) => self.doc.player = Some(Player::new(script)),
                Err(errors) => {
                    for error in &errors {
                        report!("{error}");
                    }
                    self.ui.error(format!("cannot play {}: {} error(s)", path.display(), errors.len()));
                }
            }
        }
        if let Some(path) = record {
            match octovox::replay::Recorder::create(path) {
                Ok(recorder) => self.doc.recorder = Some(recorder),
                Err(err) => self.ui.error(format!("cannot record to {}: {err}", path.display())),
            }
        }
    }
}
