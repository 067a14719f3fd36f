//! How far an image is from a reference: NVIDIA's FLIP (perceptual, mean
//! over the pixels, 0 = identical, 1 = as different as can be) and PSNR;
//! one frame drawn at a quality setting, timed; and which of a set of
//! (time, error) points no other beats on both. `bench quality` and the
//! window's quality presets use them.

use image::RgbaImage;

use crate::camera::Camera;
use crate::gpu::{PathFrame, PathView, Renderer};
use crate::io::png::upscale;
use crate::scene::Scene;
use crate::settings::{PathSettings, RenderSettings, TraceMode, View, scaled_size};

/// Mean FLIP error of `test` against `reference` (same size; RGB, the
/// alpha ignored), at FLIP's default viewing distance (67 pixels per degree).
///
/// # Panics
/// If the sizes differ.
pub fn flip(reference: &RgbaImage, test: &RgbaImage) -> f32 {
    let rgb = |image: &RgbaImage| {
        let bytes: Vec<u8> = image.pixels().flat_map(|p| [p[0], p[1], p[2]]).collect();
        nv_flip::FlipImageRgb8::with_data(image.width(), image.height(), &bytes)
    };
    let error = nv_flip::flip(rgb(reference), rgb(test), nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    nv_flip::FlipPool::from_image(&error).mean()
}

/// The RMS difference of the RGB bytes, as a fraction of full scale
/// (0 for identical images).
pub fn rms_error(reference: &RgbaImage, test: &RgbaImage) -> f64 {
    let (mut sum, mut count) = (0.0f64, 0u64);
    for (a, b) in reference.pixels().zip(test.pixels()) {
        for c in 0..3 {
            let d = (f64::from(a[c]) - f64::from(b[c])) / 255.0;
            sum += d * d;
            count += 1;
        }
    }
    (sum / count.max(1) as f64).sqrt()
}

/// Peak signal-to-noise ratio over the RGB bytes in dB; `None` for
/// identical images (infinite).
pub fn psnr(reference: &RgbaImage, test: &RgbaImage) -> Option<f64> {
    let rms = rms_error(reference, test);
    (rms > 0.0).then(|| -20.0 * rms.log10())
}

/// One way to draw a frame: the path tracer with its knobs, or the preview.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setting {
    Path {
        spp: u32,
        bounces: u32,
        shadow_samples: u32,
        render_scale: f32,
        /// Denoised after the last sample (its time counted in the frame's).
        denoise: bool,
        /// `PathSettings::seed`: [`REFERENCE_SEED`] for a reference.
        seed: u32,
    },
    /// The preview; `lod` is the level-of-detail footprint in pixels (0 exact).
    Preview { mode: TraceMode, render_scale: f32, lod: f32 },
}

/// The seed of the reference images the path tracer's settings are
/// measured against: their samples are independent of the measured ones
/// (seed 0), which would otherwise be the reference's first samples.
pub const REFERENCE_SEED: u32 = 1;

impl Setting {
    /// The same setting drawn from the samples of `seed` (the preview has
    /// none).
    pub fn with_seed(self, seed: u32) -> Setting {
        match self {
            Setting::Path { spp, bounces, shadow_samples, render_scale, denoise, .. } => {
                Setting::Path { spp, bounces, shadow_samples, render_scale, denoise, seed }
            }
            preview => preview,
        }
    }
}

/// Draws one frame with `setting`; returns its wall-clock milliseconds
/// (submit to finish of all its samples, which needs a renderer that waits
/// for its frames; readback and upscaling excluded) and the image at `size`.
/// Wall time rather than GPU timestamps: on lavapipe those of small frames
/// cannot be trusted once the path kernel has run.
pub fn render_setting(
    renderer: &mut Renderer,
    scene: &Scene,
    camera: &Camera,
    size: (u32, u32),
    setting: Setting,
) -> Result<(f64, RgbaImage), crate::gpu::GpuError> {
    match setting {
        Setting::Path { spp, bounces, shadow_samples, render_scale, denoise, seed } => {
            let settings = PathSettings { bounces, shadow_samples, seed, ..PathSettings::default() };
            let traced = scaled_size(size, render_scale);
            renderer.compile_path_kernel(scene, &settings)?;
            let start = web_time::Instant::now();
            let view = PathView { scene, camera, size: traced, settings: &settings };
            accumulate(renderer, &view, spp, None, |_| ())?;
            if denoise {
                renderer.denoise_now()?;
            }
            let ms = start.elapsed().as_secs_f64() * 1e3;
            Ok((ms, upscale(renderer.read_image()?, size)))
        }
        Setting::Preview { mode, render_scale, lod } => {
            let settings =
                RenderSettings { mode, view: View::Shaded, shadows: true, render_scale: 1.0, lod, ground: None };
            let traced = scaled_size(size, render_scale);
            if mode == TraceMode::Grid {
                let grid = crate::trace::grid::DenseGrid::from_octree(scene.drawn())
                    .map_err(|e| crate::gpu::GpuError::TooLarge(e.to_string()))?;
                renderer.set_grid(&grid, scene.revision())?;
            }
            // The first frame compiles nothing but warms caches; time the second.
            renderer.render(scene, camera, traced, &settings, None)?;
            let start = web_time::Instant::now();
            renderer.render(scene, camera, traced, &settings, None)?;
            let ms = start.elapsed().as_secs_f64() * 1e3;
            Ok((ms, upscale(renderer.read_image()?, size)))
        }
    }
}

/// What [`accumulate`] did.
pub struct Accumulated {
    /// The last sample's frame.
    pub last: PathFrame,
    /// The milliseconds of all the samples.
    pub ms: f64,
}

/// Path traces `view` from a fresh accumulation: `cap` samples, or fewer
/// once the noise estimate is below `target` (measured after every sample
/// only then). `each` sees every sample's frame.
///
/// # Errors
/// A failed frame.
pub fn accumulate(
    renderer: &mut Renderer,
    view: &PathView,
    cap: u32,
    target: Option<f32>,
    mut each: impl FnMut(&PathFrame),
) -> Result<Accumulated, crate::gpu::GpuError> {
    let (mut ms, mut last) = (0.0, None);
    // Toward a target, every sample's frame measures the noise it is checked by.
    let mut options = crate::gpu::PathOptions::default();
    options.wants.estimate_noise = target.is_some();
    for sample in 0..cap {
        let frame = renderer.render_path_with(view, sample == 0, options)?;
        ms += frame.ms;
        each(&frame);
        last = Some(frame);
        if let Some(target) = target
            && renderer.noise_estimate()?.is_some_and(|noise| noise < target)
        {
            break;
        }
    }
    let last = last.ok_or_else(|| crate::gpu::GpuError::Readback("no samples were asked for".into()))?;
    Ok(Accumulated { last, ms })
}

/// For each (time, error) point, whether no other point is at least as good
/// on both and better on one: the Pareto front.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    points.iter().map(|&(t, e)| !points.iter().any(|&(t2, e2)| t2 <= t && e2 <= e && (t2 < t || e2 < e))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(f: impl Fn(u32, u32) -> [u8; 4]) -> RgbaImage {
        RgbaImage::from_fn(64, 48, |x, y| image::Rgba(f(x, y)))
    }

    #[test]
    fn identical_images_have_no_error_and_noise_has_some() {
        let a = image(|x, y| [(x * 3) as u8, (y * 5) as u8, 128, 255]);
        assert_eq!(flip(&a, &a), 0.0);
        assert_eq!(psnr(&a, &a), None);
        let noisy = image(|x, y| {
            let n = if (x * 7 + y * 13) % 5 == 0 { 40 } else { 0 };
            [((x * 3) as u8).saturating_add(n), (y * 5) as u8, 128, 255]
        });
        let (f, p) = (flip(&a, &noisy), psnr(&a, &noisy).unwrap());
        assert!(f > 0.01 && f < 0.5, "{f}");
        assert!(p > 20.0 && p < 40.0, "{p}");
        let black = image(|_, _| [0, 0, 0, 255]);
        assert!(flip(&a, &black) > f);
    }

    #[test]
    fn the_pareto_front_keeps_what_nothing_beats() {
        let points = [(1.0, 0.5), (2.0, 0.2), (3.0, 0.3), (4.0, 0.1), (2.0, 0.5)];
        assert_eq!(pareto_front(&points), [true, true, false, true, false]);
    }
}
