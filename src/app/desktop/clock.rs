//! The frame clock: when the window is ready, when the last frame was
//! drawn and the next is due, the render scale while the camera moves,
//! `--bench-frames` and `--frame-stats`. (What a frame must redo because
//! the scene changed, the renderer knows from the scene's revision.)

use std::cell::Cell;
use std::time::Instant;

use super::super::frame_bench::Bench;
use super::super::motion;
use super::frame_stats;
use crate::cli::WindowArgs;

pub(super) struct FrameClock {
    /// The first frame has been presented (`octovox: ready` printed).
    pub ready: bool,
    pub last_frame: Option<Instant>,
    pub next_repaint: Option<Instant>,
    /// A frame was asked for since the last one (see `App::request_redraw`).
    pub redraw_wanted: Cell<bool>,
    pub screenshot_requested: bool,
    pub bench: Option<Bench>,
    /// The render scale while the camera moves.
    pub motion: motion::MotionScale,
    /// Frame intervals while the camera moved (`--frame-stats`).
    pub moving_frames: Option<frame_stats::MovingFrames>,
    /// The last frame traced the preview in place of a path-traced frame
    /// that would have started the accumulation over; the next one starts it.
    pub preview_before_path: bool,
    /// Whether the stdout line `path: N samples` was written for the view
    /// shown: its samples done and, with Denoise on, filtered.
    pub path_reported: bool,
}

impl FrameClock {
    pub fn new(args: &WindowArgs) -> FrameClock {
        FrameClock {
            ready: false,
            last_frame: None,
            next_repaint: None,
            redraw_wanted: Cell::new(true),
            screenshot_requested: false,
            bench: args.bench_frames.map(Bench::new),
            motion: motion::MotionScale::default(),
            moving_frames: args.frame_stats.then(frame_stats::MovingFrames::default),
            preview_before_path: false,
            path_reported: false,
        }
    }
}
