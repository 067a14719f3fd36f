//! `--frame-stats`: where the time of each frame went while the camera
//! moved, summed up when the window closes (benches/window_orbit.sh).

/// Where one frame's time went, milliseconds (wall time of each part; on
/// a CPU-emulated GPU the queue's work runs inside submit, present and the
/// next acquire).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameParts {
    /// The time since the frame before.
    pub interval_ms: f64,
    /// The trace pass (GPU timestamps where trusted).
    pub trace_ms: f64,
    /// Laying out the panels and tessellating them.
    pub panels_ms: f64,
    /// Waiting for a swapchain image.
    pub acquire_ms: f64,
    /// Recording the blit and egui's buffers and pass.
    pub draw_ms: f64,
    /// Submitting and presenting.
    pub submit_ms: f64,
    pub scale: f32,
}

/// The frames while the camera moved, for `--frame-stats`.
#[derive(Clone, Debug, Default)]
pub struct MovingFrames {
    frames: Vec<FrameParts>,
}

impl MovingFrames {
    pub fn push(&mut self, frame: FrameParts) {
        self.frames.push(frame);
    }

    /// "N frames while moving: F fps, median M ms, worst W ms; median trace
    /// T ms, present P ms (acquire A, blit+egui B, submit+present C),
    /// panels U ms, scale S".
    pub fn summary(&self) -> String {
        let n = self.frames.len();
        let total: f64 = self.frames.iter().map(|f| f.interval_ms).sum();
        let fps = if total > 0.0 { n as f64 * 1e3 / total } else { 0.0 };
        let worst = self.frames.iter().map(|f| f.interval_ms).fold(0.0, f64::max);
        let m = |part: fn(&FrameParts) -> f64| median(self.frames.iter().map(part).collect());
        format!(
            "{n} frames while moving: {fps:.1} fps, median {:.1} ms, worst {worst:.1} ms; median trace {:.1} ms, \
             present {:.1} ms (acquire {:.1}, blit+egui {:.1}, submit+present {:.1}), panels {:.1} ms, scale {:.2}",
            m(|f| f.interval_ms),
            m(|f| f.trace_ms),
            m(|f| f.acquire_ms + f.draw_ms + f.submit_ms),
            m(|f| f.acquire_ms),
            m(|f| f.draw_ms),
            m(|f| f.submit_ms),
            m(|f| f.panels_ms),
            m(|f| f64::from(f.scale)),
        )
    }
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(0.0)
}
