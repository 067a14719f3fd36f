//! The render scale while the camera moves: each frame traces as many
//! pixels as hold the frame-time target, and once the camera has kept still
//! for a moment the view is traced at the user's full scale again.

use std::time::Duration;

use web_time::Instant;

use octovox::camera::Camera;

/// The smallest share of the user's scale a moving frame traces, per axis.
pub const MIN_FACTOR: f32 = 0.25;

/// Default frame-time target while the camera moves, milliseconds.
pub const DEFAULT_TARGET_MS: f32 = 33.0;

/// What the last frame took, milliseconds.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameTimes {
    pub frame_ms: f64,
    pub trace_ms: f64,
}

/// How long the camera must keep still before the view rests (full scale,
/// then the path tracer). A hand orbiting leaves gaps between mouse moves
/// longer than a frame; resting in such a gap drew a full-scale frame (and
/// started a path-traced sample) in the middle of a drag, a stall of
/// 250–450 ms on lavapipe.
pub const SETTLE: Duration = Duration::from_millis(200);

/// Moving frames aim this far under the target, so that frames a few
/// milliseconds slower than the last (lavapipe's vary by ±15 %) still meet it.
const AIM: f64 = 0.85;

/// Picks the per-axis factor on the user's render scale, frame by frame.
#[derive(Clone, Debug)]
pub struct MotionScale {
    /// The factor moving frames trace at, kept from one motion to the next
    /// (a new drag starts where the last one ended, not at full scale).
    moving_factor: f32,
    /// This frame (the last, once the next one updates) is traced at
    /// `moving_factor`: its time says how to correct it.
    last_at_moving_factor: bool,
    last_camera: Option<Camera>,
    last_change: Option<Instant>,
    moving: bool,
}

impl Default for MotionScale {
    fn default() -> MotionScale {
        MotionScale {
            moving_factor: 1.0,
            last_at_moving_factor: false,
            last_camera: None,
            last_change: None,
            moving: false,
        }
    }
}

impl MotionScale {
    /// The factor for the frame drawn at `now`: 1 at rest (the camera kept
    /// still for `SETTLE`) or when the frame must be at full scale (e.g. a
    /// screenshot). While the camera moves, the trace (whose time grows
    /// with the pixels traced, the square of the factor) gets what the
    /// target (aimed 15 % under) leaves after the rest of the last frame,
    /// but at least a quarter of it: when the panels and the present alone
    /// take longer than the target, a smaller picture would not help.
    pub fn update(&mut self, camera: &Camera, now: Instant, last: FrameTimes, target_ms: f32, full_scale: bool) -> f32 {
        if self.last_camera.is_some_and(|previous| previous != *camera) {
            self.last_change = Some(now);
        }
        self.last_camera = Some(*camera);
        let was_moving = self.moving;
        self.moving = self.last_change.is_some_and(|at| now.duration_since(at) < SETTLE);
        if self.moving && last.trace_ms > 0.0 {
            let target = f64::from(target_ms) * AIM;
            // The rest of the frame is never below zero: a trace longer than
            // the frame's wall time ran beside it (a GPU that is not the
            // CPU), or is a path-traced sample's several bands.
            let rest = (last.frame_ms - last.trace_ms).max(0.0);
            let budget = (target - rest).max(target / 4.0);
            let correction = (budget / last.trace_ms).sqrt() as f32;
            if self.last_at_moving_factor {
                // At most halve or grow by a quarter per frame, so one odd
                // frame does not make the picture jump.
                self.moving_factor = (self.moving_factor * correction.clamp(0.5, 1.25)).clamp(MIN_FACTOR, 1.0);
            } else if !was_moving {
                // A motion starts after a full-scale frame: no larger than
                // that frame says fits.
                self.moving_factor = self.moving_factor.min(correction.clamp(MIN_FACTOR, 1.0));
            }
        }
        self.last_at_moving_factor = self.moving && !full_scale;
        self.factor()
    }

    /// This frame's factor.
    pub fn factor(&self) -> f32 {
        if self.last_at_moving_factor { self.moving_factor } else { 1.0 }
    }

    /// The camera moved less than `SETTLE` ago.
    pub fn moving(&self) -> bool {
        self.moving
    }

    /// While moving: when the view will rest, the time to draw it at full
    /// scale unless the camera moves again first.
    pub fn settles_at(&self) -> Option<Instant> {
        self.moving.then(|| self.last_change.map(|at| at + SETTLE)).flatten()
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
        let start = Instant::now();
        let ms = |t: u64| start + Duration::from_millis(t);
        let mut motion = MotionScale::default();
        assert_eq!(motion.update(&at(0.0), ms(0), times(60.0, 40.0), 33.0, false), 1.0, "the first frame is at rest");
        // The first moving frame: 40 ms of full-scale trace in a 60 ms
        // frame, so the trace gets 8.05 ms of the 28.05 aimed at.
        let first = motion.update(&at(1.0), ms(60), times(60.0, 40.0), 33.0, false);
        assert!((first - (8.05f32 / 40.0).sqrt()).abs() < 0.01, "{first}");
        // On the aim, the factor holds.
        let steady = motion.update(&at(3.0), ms(150), times(28.05, 8.05), 33.0, false);
        assert!((steady - first).abs() < 1e-4, "{steady} {first}");
        // A frame with no mouse move in between is no rest.
        assert_eq!(motion.update(&at(3.0), ms(180), times(28.05, 8.05), 33.0, false), steady);
        assert!(motion.moving());
        assert_eq!(motion.settles_at(), Some(ms(150) + SETTLE));
        // The rest of the frame alone is over the target: the trace keeps a
        // quarter of what is aimed at rather than shrinking to nothing.
        let mut factor = steady;
        for x in 4u32..30 {
            let trace = 40.0 * f64::from(factor * factor);
            factor =
                motion.update(&at(f64::from(x)), ms(200 + 30 * u64::from(x)), times(90.0 + trace, trace), 33.0, false);
        }
        assert!((40.0 * f64::from(factor * factor) - 33.0 * AIM / 4.0).abs() < 0.5, "{factor}");
        // A screenshot is taken at full scale even while moving, and leaves the moving factor as it was.
        let trace = 40.0 * f64::from(factor * factor);
        assert_eq!(motion.update(&at(40.0), ms(1200), times(90.0 + trace, trace), 33.0, true), 1.0);
        let after = motion.update(&at(41.0), ms(1230), times(500.0, 400.0), 33.0, false);
        assert!((after - factor).abs() < 1e-3, "{after} {factor}");
        // Far too slow: never below the floor.
        for x in 42u32..60 {
            motion.update(&at(f64::from(x)), ms(1230 + 30 * u64::from(x)), times(5000.0, 4900.0), 33.0, false);
        }
        assert_eq!(motion.factor(), MIN_FACTOR);
        // Still for SETTLE: full scale, and no further frame needed.
        let last_move = ms(1230 + 30 * 59);
        assert_eq!(motion.update(&at(59.0), last_move + SETTLE, times(500.0, 400.0), 33.0, false), 1.0);
        assert!(!motion.moving());
        assert_eq!(motion.settles_at(), None);
        // The next drag starts where this one ended, unless the resting frame says less fits.
        assert_eq!(motion.update(&at(60.0), last_move + SETTLE * 2, times(20.0, 10.0), 33.0, false), MIN_FACTOR);
        motion.update(&at(60.0), last_move + SETTLE * 4, times(20.0, 10.0), 33.0, false);
        assert!(!motion.moving());
        let mut quick = MotionScale { moving_factor: 0.8, ..MotionScale::default() };
        quick.update(&at(0.0), ms(0), times(20.0, 10.0), 33.0, false);
        assert_eq!(quick.update(&at(1.0), ms(30), times(20.0, 10.0), 33.0, false), 0.8);
        let mut slow = MotionScale { moving_factor: 0.8, ..MotionScale::default() };
        slow.update(&at(0.0), ms(0), times(110.0, 100.0), 33.0, false);
        let started = slow.update(&at(1.0), ms(30), times(110.0, 100.0), 33.0, false);
        assert!((started - (18.05f32 / 100.0).sqrt()).abs() < 0.01, "{started}");
        // A trace longer than its frame (a sample's bands at rest, or a GPU
        // beside the CPU) leaves the whole aim to the trace, no more.
        let mut banded = MotionScale::default();
        banded.update(&at(0.0), ms(0), times(30.0, 250.0), 33.0, false);
        let started = banded.update(&at(1.0), ms(30), times(30.0, 250.0), 33.0, false);
        assert!((started - (28.05f32 / 250.0).sqrt()).abs() < 0.01, "{started}");
    }
}
