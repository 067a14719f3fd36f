//! When the denoiser runs over a progressive accumulation, as plain data:
//! which frames start a filter, which stage of it each frame records, and
//! what the output shows. `Renderer::encode_path` records what this
//! decides; the tests here run whole accumulations without a GPU.
//!
//! A filter is [`STAGES`] dispatches: stage 0 (`prepare`, which also
//! measures the noise) and then the à-trous passes. It runs a stage a
//! frame, so that a frame that must show a moved camera waits for one
//! stage, as for one band of a sample; on a slow adapter the whole filter
//! costs about a sample (docs/bench/denoise.md). It starts after samples
//! 1, 2, 4, 8, … where none is under way, and after the last one wanted
//! (at rest, once the one under way is done).

use super::denoise_pass::STAGES;

/// What the window (or a headless render) wants of an accumulation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Wants {
    /// Show the accumulation denoised.
    pub denoise: bool,
    /// Measure the noise after every sample (stage 0 alone where no
    /// filter starts).
    pub estimate_noise: bool,
    /// The accumulation stops growing at this many samples.
    pub sample_target: u32,
}

/// The filter's progress over one accumulation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FilterSchedule {
    /// A filter under way: the next stage and the samples it filters.
    pub filtering: Option<(usize, u32)>,
    /// The samples the last finished filter saw.
    pub denoised_of: Option<u32>,
}

/// The dispatches of the denoiser one frame records, in this order.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FilterFrame {
    /// Stage 0 over the accumulation as it is after this frame's band:
    /// `Some(true)` starts a filter, `Some(false)` only measures the noise.
    pub prepare: Option<bool>,
    /// The next stage of the filter under way.
    pub stage: Option<usize>,
}

impl FilterSchedule {
    /// A frame that traces a band of a sample; `completes`: it is the
    /// sample's last, after which `done` samples are accumulated.
    pub fn band(&mut self, completes: bool, done: u32, wants: Wants) -> FilterFrame {
        let mut frame = FilterFrame::default();
        if completes && (wants.denoise || wants.estimate_noise) {
            let starts =
                wants.denoise && self.filtering.is_none() && (done.is_power_of_two() || done >= wants.sample_target);
            frame.prepare = Some(starts);
            if starts {
                self.filtering = Some((1, done));
                return frame;
            }
        }
        frame.stage = self.advance();
        frame
    }

    /// A frame of an accumulation that has its `samples`: the last
    /// sample's filter if the one under way when it came was of an earlier
    /// one, else the next stage of the one under way.
    pub fn at_rest(&mut self, samples: u32, wants: Wants) -> FilterFrame {
        let behind = self.filtering.is_none() && self.denoised_of != Some(samples);
        if wants.denoise && behind {
            self.filtering = Some((1, samples));
            return FilterFrame { prepare: Some(true), stage: None };
        }
        FilterFrame { prepare: None, stage: self.advance() }
    }

    /// The filter was run whole at once (`Renderer::denoise_now`).
    pub fn filtered_now(&mut self, samples: u32) {
        (self.filtering, self.denoised_of) = (None, Some(samples));
    }

    /// Whether frames are still wanted for the filter: one is under way,
    /// or the last sample's has not run.
    pub fn pending(&self, samples: u32, wants: Wants) -> bool {
        wants.denoise && (self.filtering.is_some() || self.denoised_of != Some(samples))
    }

    /// Whether the output shows a finished filter.
    pub fn shows_denoised(&self, wants: Wants) -> bool {
        wants.denoise && self.denoised_of.is_some()
    }

    /// Takes the filter under way one stage further; the stage recorded.
    fn advance(&mut self) -> Option<usize> {
        let (stage, samples) = self.filtering?;
        self.filtering = Some((stage + 1, samples));
        if stage + 1 == STAGES {
            (self.filtering, self.denoised_of) = (None, Some(samples));
        }
        Some(stage)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One frame of an accumulation in `bands` bands toward `wants`: what
    /// the renderer does with the schedule (a band while samples are
    /// wanted, else a frame at rest). Returns the samples after it.
    fn frame(s: &mut FilterSchedule, samples: &mut u32, band: &mut u32, bands: u32, wants: Wants) -> FilterFrame {
        if *samples >= wants.sample_target {
            return s.at_rest(*samples, wants);
        }
        let completes = *band + 1 == bands;
        *band = (*band + 1) % bands;
        let frame = s.band(completes, *samples + u32::from(completes), wants);
        *samples += u32::from(completes);
        frame
    }

    /// Runs `frames` frames; returns each frame's dispatches.
    fn run(frames: usize, bands: u32, wants: Wants) -> (Vec<FilterFrame>, FilterSchedule) {
        let (mut s, mut samples, mut band) = (FilterSchedule::default(), 0, 0);
        let out = (0..frames).map(|_| frame(&mut s, &mut samples, &mut band, bands, wants)).collect();
        (out, s)
    }

    const DENOISED: Wants = Wants { denoise: true, estimate_noise: true, sample_target: 16 };

    #[test]
    fn filters_start_after_powers_of_two_and_the_last_sample_and_run_a_stage_a_frame() {
        let (frames, s) = run(60, 1, DENOISED);
        // The samples each filter started at: one sample a frame, so frame k
        // completes sample k + 1.
        let started: Vec<usize> =
            (0..frames.len()).filter(|&k| frames[k].prepare == Some(true)).map(|k| k + 1).collect();
        // Sample 2's and 4's came while sample 1's filter ran.
        assert_eq!(started, [1, 8, 16], "{frames:?}");
        // A started filter's stages follow it, one a frame, in order.
        for &k in &started[..started.len() - 1] {
            let stages: Vec<Option<usize>> = frames[k..k + STAGES - 1].iter().map(|f| f.stage).collect();
            assert_eq!(stages, (1..STAGES).map(Some).collect::<Vec<_>>(), "after sample {k}");
        }
        // The last one ends, and nothing is left to do at rest.
        assert_eq!(s, FilterSchedule { filtering: None, denoised_of: Some(16) });
        assert!(!s.pending(16, DENOISED) && s.shows_denoised(DENOISED));
        assert!(frames[40..].iter().all(|f| *f == FilterFrame::default()), "{:?}", &frames[40..]);
    }

    #[test]
    fn a_sample_that_completes_while_a_filter_runs_only_measures_the_noise() {
        let (frames, _) = run(6, 1, DENOISED);
        // Sample 3 (frame 2) comes while sample 2's filter runs.
        assert_eq!(frames[2], FilterFrame { prepare: Some(false), stage: Some(2) });
    }

    #[test]
    fn the_last_samples_filter_runs_at_rest_when_it_came_during_another() {
        let wants = Wants { sample_target: 3, ..DENOISED };
        let (frames, s) = run(3 + 3 * STAGES, 1, wants);
        // Sample 3, the last, came while sample 2's filter ran: it is
        // filtered at rest once that one is done.
        let starts: Vec<usize> = (0..frames.len()).filter(|&k| frames[k].prepare == Some(true)).collect();
        assert_eq!(starts, [0, STAGES], "sample 1's filter, then sample 3's at rest: {frames:?}");
        assert_eq!(s.denoised_of, Some(3));
    }

    #[test]
    fn without_denoise_no_filter_runs_and_the_noise_is_measured_per_sample() {
        let wants = Wants { denoise: false, estimate_noise: true, sample_target: 8 };
        let (frames, s) = run(20, 2, wants);
        let measured = frames.iter().filter(|f| f.prepare == Some(false)).count();
        assert_eq!(measured, 8, "one measurement per sample (two bands each): {frames:?}");
        assert!(frames.iter().all(|f| f.stage.is_none() && f.prepare != Some(true)));
        assert!(!s.pending(8, wants) && !s.shows_denoised(wants));
        let quiet = Wants { estimate_noise: false, ..wants };
        assert!(run(20, 2, quiet).0.iter().all(|f| *f == FilterFrame::default()));
    }

    #[test]
    fn bands_that_complete_no_sample_take_the_filter_a_stage_further() {
        let (frames, _) = run(8, 4, DENOISED);
        // Frame 3 completes sample 1 and starts its filter; the next bands
        // run its stages.
        assert_eq!(frames[3].prepare, Some(true));
        assert_eq!(frames[4..8].iter().map(|f| f.stage).collect::<Vec<_>>(), [Some(1), Some(2), Some(3), Some(4)]);
    }
}
