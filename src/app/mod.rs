//! The sandbox window, in two halves. The editing session (`session`)
//! knows no window: it holds the document, the editor's state, the
//! gesture under way and what the cursor is over, carries out every
//! command (`Session::execute`: mouse, keyboard, panels, played scripts)
//! and says what the window must do. Its edits are script lines run
//! through the one interpreter (`host`); opening and saving are in
//! `files`. Around it, one of two shells: the desktop's winit window
//! (`desktop`) or the browser's page (`web`). Each turns its events into
//! commands (`input`), lays out the panels (`ui`), draws the frame the
//! same way (`drawing`) and does what the session asks.

/// Prints one status line (`edit: …`, `saved: …`, `octovox: ready`; tests
/// and scripts read them): on stdout, or in the browser on the console. A
/// closed stdout is not an error worth dying for.
macro_rules! report {
    ($($arg:tt)*) => {{
        #[cfg(not(target_arch = "wasm32"))]
        {
            use std::io::Write as _;
            let _ = writeln!(std::io::stdout(), $($arg)*);
        }
        #[cfg(target_arch = "wasm32")]
        web_sys::console::log_1(&format!($($arg)*).into());
    }};
}

mod actions;
#[cfg_attr(
    target_arch = "wasm32",
    expect(dead_code, reason = "the desktop opens it where no native dialog shows; the page has the browser's picker")
)]
mod browser;
mod camera_control;
mod command;
mod dialog_kind;
mod document;
mod drag;
mod drawing;
mod files;
mod frame_bench;
mod gesture;
mod gizmo;
mod host;
mod input;
mod journal;
mod motion;
mod outliner;
mod presets;
mod preview;
mod recent;
mod script;
mod selection;
mod session;
mod slow_clicks;
mod state;
mod timeline;
mod ui;

#[cfg(not(target_arch = "wasm32"))]
mod desktop;
#[cfg(target_arch = "wasm32")]
mod web;

pub use command::{AppCommand, Choice, Nudge, Pending, StrokePhase};
#[cfg(not(target_arch = "wasm32"))]
pub use desktop::run;
#[cfg(target_arch = "wasm32")]
pub use web::start;

/// Where screenshots and the journal of an untitled scene go, relative to
/// the working directory.
const SAVES_DIR: &str = "saves";
