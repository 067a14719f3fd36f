//! `--bench-frames N` (and the page's `?bench-frames=N`): N frames drawn
//! back to back once the view is ready, timed by the wall clock from the
//! end of the first (which warms up) to the end of the last.

use web_time::Instant;

use super::session::Session;

/// Frames left and the measurements so far.
pub struct Bench {
    left: u32,
    total: u32,
    started: Option<Instant>,
    trace_ms: f64,
}

impl Bench {
    pub fn new(frames: u32) -> Bench {
        Bench { left: frames.max(1), total: frames.max(1), started: None, trace_ms: 0.0 }
    }

    /// Counts a frame `session` just drew; after the last, the line to
    /// report: "bench: N frames at WxH: F fps, M ms/frame, trace T ms
    /// (GPU timestamps|wall)".
    pub fn frame(&mut self, session: &Session) -> Option<String> {
        let Some(started) = self.started else {
            self.started = Some(Instant::now());
            return None;
        };
        self.trace_ms += session.readouts.stats.trace_ms;
        self.left -= 1;
        if self.left > 0 {
            return None;
        }
        let seconds = started.elapsed().as_secs_f64();
        let n = f64::from(self.total);
        let (w, h) = session.trace_size();
        let clock = session.renderer.as_ref().map_or("", |r| if r.timed_by_gpu() { "GPU timestamps" } else { "wall" });
        Some(format!(
            "bench: {} frames at {w}x{h}: {:.2} fps, {:.1} ms/frame, trace {:.1} ms ({clock})",
            self.total,
            n / seconds,
            seconds * 1e3 / n,
            self.trace_ms / n,
        ))
    }
}
