//! The render scale while the camera moves: each frame traces as many
//! pixels as hold the frame-time target, and the first frame after the
//! camera comes to rest traces at the user's full scale again.

use octovox::camera::Camera;

/// The smallest share of the user's scale a moving frame traces, per axis.
pub const MIN_FACTOR: f32 = 0.25;

/// Default frame-time target while the camera moves, milliseconds.
pub const DEFAULT_TARGET_MS: f32 = 33.0;

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

/// What the last frame took, milliseconds.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameTimes {
    pub frame_ms: f64,
    pub trace_ms: f64,
}

/// Picks the per-axis factor on the user's render scale, frame by frame.
#[derive(Clone, Debug)]
pub struct MotionScale {
    factor: f32,
    last_camera: Option<Camera>,
    moving: bool,
}

impl Default for MotionScale {
    fn default() -> MotionScale {
        MotionScale { factor: 1.0, last_camera: None, moving: false }
    }
}

impl MotionScale {
    /// The factor for this frame: 1 at rest (or when the frame must be at
    /// full scale, e.g. for a screenshot). While the camera moves, the trace
    /// (whose time grows with the pixels traced, the square of the factor)
    /// gets what the target leaves after the rest of the last frame, but at
    /// least a quarter of it: when the panels and the present alone take
    /// longer than the target, a smaller picture would not help.
    pub fn update(&mut self, camera: &Camera, last: FrameTimes, target_ms: f32, full_scale: bool) -> f32 {
        self.moving = self.last_camera.is_some_and(|previous| previous != *camera);
        self.last_camera = Some(*camera);
        self.factor = if !self.moving || full_scale {
            1.0
        } else if last.trace_ms > 0.0 {
            let target = f64::from(target_ms);
            let budget = (target - (last.frame_ms - last.trace_ms)).max(target / 4.0);
            let correction = (budget / last.trace_ms).sqrt() as f32;
            // At most halve or grow by a quarter per frame, so one odd frame
            // does not make the picture jump.
            (self.factor * correction.clamp(0.5, 1.25)).clamp(MIN_FACTOR, 1.0)
        } else {
            self.factor
        };
        self.factor
    }

    pub fn factor(&self) -> f32 {
        self.factor
    }

    /// The camera moved since the last frame: one more frame must follow,
    /// to draw the resting view at full scale.
    pub fn moving(&self) -> bool {
        self.moving
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;

    fn at(x: f64) -> Camera {
        Camera { eye: DVec3::new(x, 5.0, 9.0), ..Camera::default() }
    }

    fn times(frame_ms: f64, trace_ms: f64) -> FrameTimes {
        FrameTimes { frame_ms, trace_ms }
    }

    #[test]
    fn moving_frames_shrink_toward_the_target_and_rest_restores_full_scale() {
        let mut motion = MotionScale::default();
        assert_eq!(motion.update(&at(0.0), times(60.0, 40.0), 33.0, false), 1.0, "the first frame is at rest");
        // 40 ms of trace in a 60 ms frame: the trace gets 13 ms of the 33.
        let first = motion.update(&at(1.0), times(60.0, 40.0), 33.0, false);
        assert!((first - (13.0f32 / 40.0).sqrt()).abs() < 0.01, "{first}");
        // On target, the factor holds.
        let steady = motion.update(&at(2.0), times(33.0, 13.0), 33.0, false);
        assert!((steady - first).abs() < 1e-6);
        // The rest of the frame alone is over the target: the trace keeps a
        // quarter of it rather than shrinking to nothing.
        let mut factor = steady;
        for x in 3..30 {
            let trace = 40.0 * f64::from(factor * factor);
            factor = motion.update(&at(f64::from(x)), times(90.0 + trace, trace), 33.0, false);
        }
        assert!((40.0 * f64::from(factor * factor) - 33.0 / 4.0).abs() < 0.5, "{factor}");
        assert!(motion.moving());
        // A screenshot is taken at full scale even while moving.
        assert_eq!(motion.update(&at(40.0), times(500.0, 400.0), 33.0, true), 1.0);
        // Far too slow: never below the floor.
        for x in 41..60 {
            motion.update(&at(f64::from(x)), times(5000.0, 4900.0), 33.0, false);
        }
        assert_eq!(motion.factor(), MIN_FACTOR);
        // Rest: full scale, and no further frame needed.
        assert_eq!(motion.update(&at(59.0), times(500.0, 400.0), 33.0, false), 1.0);
        assert!(!motion.moving());
    }
}
