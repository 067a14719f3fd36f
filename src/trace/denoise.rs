//! The denoiser: an edge-avoiding à-trous wavelet filter (Dammertz et al.
//! 2010; the spatial filter of SVGF, Schied et al. 2017) over the path
//! tracer's accumulation, guided by what the first hit knows exactly, and
//! the noise estimate that `render --target-error` and the window read.
//!
//! This is the CPU twin of `shaders/denoise.wgsl`, the reference for its
//! tests: change both together.
//!
//! Per pixel the path tracer keeps the sums of its samples, of their
//! squares and of the colour (albedo) of each sample's first hit, and a
//! [`Guide`] from the ray through the pixel's centre: the point where it
//! enters a voxel face and the face's normal. The filter divides the mean
//! by the mean albedo (so a voxel-sharp colour edge is not blurred, only
//! the light on it, and a pixel across such an edge keeps its mix),
//! averages it with neighbours facing the same way near the same face
//! plane whose light is within a few standard deviations, five times with
//! 3×3 taps 1, 2, 4, 8 and 16 pixels apart, and multiplies the colour back. Pixels whose first hit is the sky, a lamp,
//! glass or metal are left to their samples: their light does not lie on
//! the face the guide describes.

use glam::Vec3;

/// À-trous iterations; iteration i takes taps `2^i` pixels apart.
pub const ITERATIONS: u32 = 5;
/// How many standard deviations of a pixel's light a neighbour's may differ
/// by and still weigh `1/e` (SVGF's σ_l). SVGF's 4 smoothed away the shading
/// of voxels a pixel wide: 2 took FLIP at 16 spp on teapot256 from 0.0102
/// to 0.0088, and on the interior from 0.083 to 0.085 (docs/bench/denoise.md).
pub const SIGMA_LIGHT: f32 = 2.0;
/// How far off a pixel's face plane a neighbour's point may lie, in pixel
/// footprints per pixel of distance, and still weigh `1/e`.
pub const SIGMA_PLANE: f32 = 1.0;
/// Below this many samples a pixel's variance is taken from its neighbours:
/// its own sum of squares says too little.
pub const SPATIAL_VARIANCE_BELOW: u32 = 4;
/// The 3-tap B-spline (1/4, 1/2, 1/4) of the à-trous kernel and of the
/// variance's blur: its centre and side weights. Dammertz et al. use 5
/// taps; 3×3 taps instead of 5×5 cost less than half as much for the same reach
/// (taps up to 16 pixels apart; `docs/bench/denoise.md`).
pub const KERNEL_CENTRE: f32 = 0.5;
pub const KERNEL_SIDE: f32 = 0.25;

/// The kernel's weight `d` taps from the centre (−1, 0 or 1).
fn kernel(d: i32) -> f32 {
    if d == 0 { KERNEL_CENTRE } else { KERNEL_SIDE }
}
/// Albedo channels below this are divided by it (a black voxel has no
/// light to demodulate).
pub const MIN_ALBEDO: f32 = 1.0 / 255.0;

/// Bit of [`Guide::code`] set where the filter may change the pixel.
pub const GUIDE_FILTERED: u32 = 1 << 3;
/// Bit of [`Guide::code`] set where the face is a freely turned one, whose
/// own normal follows from [`GUIDE_NORMAL_SHIFT`].
pub const GUIDE_TURNED: u32 = 1 << 4;
/// Where a freely turned face's normal starts in [`Guide::code`]: its
/// octahedral coordinates, 12 bits each.
pub const GUIDE_NORMAL_SHIFT: u32 = 8;
/// Steps of each octahedral coordinate across −1..=1: an even count, so
/// that 0 and ±1 are exact.
pub const GUIDE_NORMAL_STEPS: u32 = 4094;

/// The first hit of a pixel's centre ray. Twin of the guide `vec4<f32>` the
/// path kernel writes: `point` in tree-local voxels, then `code` as bits.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Guide {
    pub point: [f32; 3],
    /// The face's nearest axis' code (1..=6: +x, −x, +y, −y, +z, −z) in
    /// bits 0..3, [`GUIDE_FILTERED`], and on a freely turned face
    /// [`GUIDE_TURNED`] and its own normal from [`GUIDE_NORMAL_SHIFT`].
    pub code: u32,
}

impl Guide {
    /// A pixel the filter leaves alone (sky, lamp, glass, metal).
    pub const LEFT: Guide = Guide { point: [0.0; 3], code: 0 };

    /// A filtered pixel whose centre ray enters a face of normal `normal`
    /// at `point`: a face of the grid (an axis), or a freely turned one.
    pub fn filtered(point: Vec3, normal: Vec3, turned: bool) -> Guide {
        let mut code = GUIDE_FILTERED | crate::trace::normal_code(crate::trace::nearest_axis(normal));
        if turned {
            code |= GUIDE_TURNED | pack_normal(normal) << GUIDE_NORMAL_SHIFT;
        }
        Guide { point: point.to_array(), code }
    }

    pub fn is_filtered(&self) -> bool {
        self.code & GUIDE_FILTERED != 0
    }

    /// The nearest axis' code.
    pub fn axis_code(&self) -> u32 {
        self.code & 7
    }

    /// The face's unit normal.
    pub fn normal(&self) -> Vec3 {
        match self.code & GUIDE_TURNED {
            0 => crate::trace::normal_from_code(self.axis_code()).as_vec3(),
            _ => unpack_normal(self.code >> GUIDE_NORMAL_SHIFT),
        }
    }
}

/// −1 for a negative number, else 1.
fn sign_not_zero(v: f32) -> f32 {
    if v < 0.0 { -1.0 } else { 1.0 }
}

/// A unit normal's octahedral coordinates, [`GUIDE_NORMAL_STEPS`] steps
/// each, in 24 bits (twin of `pack_normal` in shaders/path.wgsl).
fn pack_normal(n: Vec3) -> u32 {
    let n = n / (n.x.abs() + n.y.abs() + n.z.abs());
    let (mut u, mut v) = (n.x, n.y);
    if n.z < 0.0 {
        (u, v) = ((1.0 - n.y.abs()) * sign_not_zero(n.x), (1.0 - n.x.abs()) * sign_not_zero(n.y));
    }
    let step = |c: f32| ((c + 1.0) * 0.5 * GUIDE_NORMAL_STEPS as f32 + 0.5).floor() as u32;
    step(u) | step(v) << 12
}

/// The unit normal of [`pack_normal`]'s bits (twin of `unpack_normal` in
/// shaders/denoise.wgsl).
fn unpack_normal(bits: u32) -> Vec3 {
    let coordinate = |b: u32| (b & 0xfff) as f32 / GUIDE_NORMAL_STEPS as f32 * 2.0 - 1.0;
    let (u, v) = (coordinate(bits), coordinate(bits >> 12));
    let z = 1.0 - u.abs() - v.abs();
    let (x, y) =
        if z < 0.0 { ((1.0 - v.abs()) * sign_not_zero(u), (1.0 - u.abs()) * sign_not_zero(v)) } else { (u, v) };
    Vec3::new(x, y, z).normalize()
}

/// One pixel of the accumulation: the sums of the samples, of their
/// squares and of their first hits' albedo, per channel, and the count.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sums {
    pub sum: Vec3,
    pub squares: Vec3,
    pub albedo: Vec3,
    pub count: u32,
}

impl Sums {
    pub fn mean(&self) -> Vec3 {
        self.sum / self.count.max(1) as f32
    }

    /// The colour the light is divided by: the mean albedo, each channel at
    /// least [`MIN_ALBEDO`].
    pub fn albedo(&self) -> Vec3 {
        (self.albedo / self.count.max(1) as f32).max(Vec3::splat(MIN_ALBEDO))
    }

    /// The mean divided by [`Sums::albedo`]: the light the filters smooth
    /// (this one and Open Image Denoise), the colour multiplied back after.
    pub fn light(&self) -> Vec3 {
        self.mean() / self.albedo()
    }

    /// The variance of the mean, per channel; zero below two samples.
    pub fn variance_of_mean(&self) -> Vec3 {
        if self.count < 2 {
            return Vec3::ZERO;
        }
        let n = self.count as f32;
        let mean = self.sum / n;
        ((self.squares / n - mean * mean) / (n - 1.0)).max(Vec3::ZERO)
    }
}

/// Luminance weights (Rec. 709).
pub const LUMINANCE: Vec3 = Vec3::new(0.2126, 0.7152, 0.0722);

/// Where the image's pixels are: what a neighbour's plane distance is
/// measured in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    /// The camera in tree-local voxels, its view axis of unit length.
    pub eye: Vec3,
    pub forward: Vec3,
    /// One pixel's width in voxels: `at_start + per_t · depth`
    /// (`crate::trace::Footprint::of_pixels` for one pixel).
    pub footprint: crate::trace::Footprint,
}

impl Frame {
    /// The frame of the camera rays of `basis`.
    pub fn of(basis: &crate::camera::RayBasis) -> Frame {
        Frame {
            width: basis.width,
            height: basis.height,
            eye: basis.eye,
            forward: basis.forward.normalize_or_zero(),
            footprint: crate::trace::Footprint::of_pixels(basis, 1.0),
        }
    }

    /// One pixel's width in voxels at `point`.
    fn pixel_width(&self, point: Vec3) -> f32 {
        self.footprint.at_start + self.footprint.per_t * (point - self.eye).dot(self.forward).max(0.0)
    }
}

/// A pixel between passes: the demodulated light and its luminance's variance.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Light {
    rgb: Vec3,
    variance: f32,
}

/// The denoised mean radiance of every pixel, row-major.
pub fn denoise(frame: &Frame, sums: &[Sums], guides: &[Guide]) -> Vec<Vec3> {
    let mut light = prepare(frame, sums, guides);
    for iteration in 0..ITERATIONS {
        light = atrous(frame, guides, &light, 1 << iteration);
    }
    (0..light.len())
        .map(|i| if guides[i].is_filtered() { light[i].rgb * sums[i].albedo() } else { sums[i].mean() })
        .collect()
}

/// The pixels of a `width × height` image around `(x, y)` at offsets
/// `-radius..=radius` times `step`, with the offsets in taps.
fn taps(frame: &Frame, x: u32, y: u32, radius: i32, step: i32) -> impl Iterator<Item = (usize, i32, i32)> + '_ {
    (-radius..=radius).flat_map(move |dy| {
        (-radius..=radius).filter_map(move |dx| {
            let (qx, qy) = (x as i32 + dx * step, y as i32 + dy * step);
            let inside = qx >= 0 && qy >= 0 && qx < frame.width as i32 && qy < frame.height as i32;
            inside.then(|| ((qy as u32 * frame.width + qx as u32) as usize, dx, dy))
        })
    })
}

/// Whether `q` may be averaged into `p`: both filtered, facing the same way
/// (the same nearest axis: a test at every tap, kept to one comparison;
/// the plane test reads a turned face's own normal).
fn same_surface(p: &Guide, q: &Guide) -> bool {
    q.is_filtered() && q.axis_code() == p.axis_code()
}

/// Demodulated light and its variance per pixel; below
/// [`SPATIAL_VARIANCE_BELOW`] samples the variance of the 3×3 neighbours'
/// light on the same surface.
fn prepare(frame: &Frame, sums: &[Sums], guides: &[Guide]) -> Vec<Light> {
    let mut out = Vec::with_capacity(sums.len());
    for y in 0..frame.height {
        for x in 0..frame.width {
            let i = (y * frame.width + x) as usize;
            let (g, s) = (&guides[i], &sums[i]);
            if !g.is_filtered() {
                out.push(Light { rgb: s.mean(), variance: 0.0 });
                continue;
            }
            let variance = if s.count < SPATIAL_VARIANCE_BELOW {
                let (mut m1, mut m2, mut n) = (0.0f32, 0.0f32, 0.0f32);
                for (q, _, _) in taps(frame, x, y, 1, 1).filter(|&(q, _, _)| same_surface(g, &guides[q])) {
                    let l = sums[q].light().dot(LUMINANCE);
                    (m1, m2, n) = (m1 + l, m2 + l * l, n + 1.0);
                }
                (m2 / n - (m1 / n) * (m1 / n)).max(0.0)
            } else {
                let albedo = s.albedo();
                (s.variance_of_mean() * (LUMINANCE / albedo) * (LUMINANCE / albedo)).element_sum()
            };
            out.push(Light { rgb: s.light(), variance });
        }
    }
    out
}

/// The variance at `p` blurred over its 3×3 neighbours on the same surface
/// (SVGF's prefilter: one pixel's estimate is itself noisy). SVGF blurs
/// before every pass; here only the first, which halved the filter's time
/// on lavapipe.
fn blurred_variance(frame: &Frame, guides: &[Guide], light: &[Light], x: u32, y: u32) -> f32 {
    let p = &guides[(y * frame.width + x) as usize];
    let (mut sum, mut weight) = (0.0f32, 0.0f32);
    for (q, dx, dy) in taps(frame, x, y, 1, 1).filter(|&(q, _, _)| same_surface(p, &guides[q])) {
        let w = kernel(dx) * kernel(dy);
        sum += w * light[q].variance;
        weight += w;
    }
    sum / weight
}

/// One à-trous iteration with taps `step` pixels apart.
fn atrous(frame: &Frame, guides: &[Guide], light: &[Light], step: u32) -> Vec<Light> {
    let mut out = light.to_vec();
    for y in 0..frame.height {
        for x in 0..frame.width {
            let i = (y * frame.width + x) as usize;
            let p = &guides[i];
            if !p.is_filtered() {
                continue;
            }
            // The first pass blurs the pixels' own estimates; later ones
            // read what the passes before filtered.
            let variance_p = if step == 1 { blurred_variance(frame, guides, light, x, y) } else { light[i].variance };
            let luminance = light[i].rgb.dot(LUMINANCE);
            let point = Vec3::from(p.point);
            let normal = p.normal();
            let plane_scale = SIGMA_PLANE * frame.pixel_width(point) * step as f32;
            let (mut rgb, mut variance, mut weight) = (Vec3::ZERO, 0.0f32, 0.0f32);
            for (q, dx, dy) in taps(frame, x, y, 1, step as i32).filter(|&(q, _, _)| same_surface(p, &guides[q])) {
                let off_plane = normal.dot(Vec3::from(guides[q].point) - point).abs();
                let distance = ((dx * dx + dy * dy) as f32).sqrt();
                let w_plane = (-off_plane / (plane_scale * distance + 1e-6)).exp();
                // Symmetric in p and q: a bright outlier whose own variance is
                // large is taken in by its dark neighbours as it takes them
                // in, so its light is spread, not lost.
                let sigma = SIGMA_LIGHT * (variance_p + light[q].variance).sqrt() + 1e-6;
                let w_light = (-(light[q].rgb.dot(LUMINANCE) - luminance).abs() / sigma).exp();
                let w = kernel(dx) * kernel(dy) * w_plane * w_light;
                rgb += w * light[q].rgb;
                variance += w * w * light[q].variance;
                weight += w;
            }
            out[i] = Light { rgb: rgb / weight, variance: variance / (weight * weight) };
        }
    }
    out
}

/// The image's remaining noise, estimated from its samples: the root mean
/// square over pixels and channels of the standard error of each displayed
/// value (0..1; channels whose mean is displayed as full white count as
/// exact). `None` below two samples.
pub fn noise_estimate(sums: &[Sums]) -> Option<f32> {
    if sums.first().is_none_or(|s| s.count < 2) {
        return None;
    }
    let total: f64 = sums.iter().map(|s| f64::from(displayed_variance(s))).sum();
    Some((total / (3 * sums.len()) as f64).sqrt() as f32)
}

/// How far a filter moved the pixels it filtered, measured in the standard
/// errors of their raw means.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Change {
    /// Root mean square over filtered channels of the change divided by the
    /// channel's standard error.
    pub rms: f32,
    /// The share of those channels moved by more than 4 standard errors
    /// (a normal distribution puts 0.006 % there).
    pub beyond_four: f32,
}

/// The filter's change to each filtered pixel, in standard errors of its
/// raw mean: the no-bias check that needs no cleaner reference. A filter
/// that takes away only noise moves a pixel by about the noise it had (RMS
/// near 1, no pattern); one that also moves the light moves it further, by
/// more the more samples there are. Channels displayed white before and
/// after, and channels without variance, are left out; `None` when none
/// is left.
pub fn change_in_standard_errors(sums: &[Sums], guides: &[Guide], denoised: &[Vec3]) -> Option<Change> {
    let (mut squares, mut beyond, mut n) = (0.0f64, 0usize, 0usize);
    for ((s, _), after) in sums.iter().zip(guides).zip(denoised).filter(|((_, g), _)| g.is_filtered()) {
        let (before, variance) = (s.mean(), s.variance_of_mean());
        for c in (0..3).filter(|&c| variance[c] > 0.0 && (before[c] < 1.0 || after[c] < 1.0)) {
            let z = (after[c] - before[c]) / variance[c].sqrt();
            squares += f64::from(z * z);
            beyond += usize::from(z.abs() > 4.0);
            n += 1;
        }
    }
    (n > 0).then(|| Change { rms: (squares / n as f64).sqrt() as f32, beyond_four: beyond as f32 / n as f32 })
}

/// The variance of a pixel's displayed channels, summed. Twin of the
/// estimate in `shaders/denoise.wgsl`.
pub fn displayed_variance(s: &Sums) -> f32 {
    let shown = Vec3::select(s.mean().cmplt(Vec3::ONE), Vec3::ONE, Vec3::ZERO);
    (s.variance_of_mean() * shown).element_sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::Footprint;

    const W: u32 = 32;
    const H: u32 = 24;

    fn frame() -> Frame {
        let footprint = Footprint { at_start: 0.1, per_t: 0.0 };
        Frame { width: W, height: H, eye: Vec3::new(0.0, 10.0, 0.0), forward: Vec3::NEG_Y, footprint }
    }

    /// A floor seen from above: every pixel on the plane y = 0, facing +y;
    /// the guides and each pixel's albedo, `colour(x, y)`.
    fn floor(colour: impl Fn(u32, u32) -> [u8; 3]) -> (Vec<Guide>, Vec<Vec3>) {
        (0..W * H)
            .map(|i| {
                let (x, y) = (i % W, i / W);
                let albedo = Vec3::from(colour(x, y).map(|c| f32::from(c) / 255.0));
                (Guide::filtered(Vec3::new(x as f32 * 0.1, 0.0, y as f32 * 0.1), Vec3::Y, false), albedo)
            })
            .unzip()
    }

    /// `n` noisy samples of light `light(x, y)` times each pixel's albedo.
    fn noisy(albedo: &[Vec3], n: u32, light: impl Fn(u32, u32) -> f32) -> Vec<Sums> {
        let mut rng = 12345u32;
        let mut uniform = move || {
            rng = rng.wrapping_mul(1664525).wrapping_add(1013904223);
            (rng >> 8) as f32 / 16777216.0
        };
        (0..W * H)
            .map(|i| {
                let truth = albedo[i as usize] * light(i % W, i / W);
                let mut s = Sums { count: n, albedo: albedo[i as usize] * n as f32, ..Sums::default() };
                for _ in 0..n {
                    let v = truth * 2.0 * uniform();
                    s.sum += v;
                    s.squares += v * v;
                }
                s
            })
            .collect()
    }

    fn rms(a: &[Vec3], b: impl Fn(usize) -> Vec3) -> f32 {
        (a.iter().enumerate().map(|(i, v)| (*v - b(i)).length_squared()).sum::<f32>() / a.len() as f32).sqrt()
    }

    #[test]
    fn it_removes_most_of_the_noise_of_a_flat_floor() {
        let (guides, albedo) = floor(|_, _| [200, 150, 100]);
        let sums = noisy(&albedo, 4, |_, _| 0.5);
        let truth = |i: usize| albedo[i] * 0.5;
        let raw: Vec<Vec3> = sums.iter().map(Sums::mean).collect();
        let denoised = denoise(&frame(), &sums, &guides);
        let (before, after) = (rms(&raw, truth), rms(&denoised, truth));
        assert!(after < before * 0.3, "rms {before} -> {after}");
    }

    #[test]
    fn a_one_pixel_checker_of_colours_keeps_its_contrast() {
        let (guides, albedo) = floor(|x, y| if (x + y) % 2 == 0 { [240, 240, 240] } else { [30, 30, 30] });
        let sums = noisy(&albedo, 2, |_, _| 0.8);
        let denoised = denoise(&frame(), &sums, &guides);
        let contrast = |pixels: &dyn Fn(usize) -> Vec3| {
            let (mut light, mut dark) = (0.0, 0.0);
            for i in 0..(W * H) as usize {
                let l = pixels(i).dot(LUMINANCE);
                if (i as u32 % W + i as u32 / W).is_multiple_of(2) { light += l } else { dark += l }
            }
            (light - dark) / (light + dark)
        };
        let reference = contrast(&|i| albedo[i] * 0.8);
        let kept = contrast(&|i| denoised[i]);
        assert!((kept - reference).abs() < 0.01 * reference, "contrast {kept} against {reference}");
    }

    #[test]
    fn a_step_between_planes_and_pixels_left_to_their_samples_stay_sharp() {
        // The left half is a floor one voxel lower than the right half, lit
        // half as much; a column of lamp pixels down the middle.
        let (mut guides, albedo) = floor(|_, _| [128, 128, 128]);
        for (i, g) in guides.iter_mut().enumerate() {
            if i as u32 % W < W / 2 {
                g.point[1] = -1.0;
            }
        }
        let lamp = |i: usize| i as u32 % W == W / 2;
        let sums = noisy(&albedo, 8, |x, _| if x < W / 2 { 0.25 } else { 0.5 });
        let mut guides_with_lamps = guides.clone();
        for (i, g) in guides_with_lamps.iter_mut().enumerate() {
            if lamp(i) {
                *g = Guide::LEFT;
            }
        }
        let denoised = denoise(&frame(), &sums, &guides_with_lamps);
        for (i, pixel) in denoised.iter().enumerate() {
            if lamp(i) {
                assert_eq!(*pixel, sums[i].mean(), "a lamp pixel changed");
                continue;
            }
            let truth = albedo[i].x * if (i as u32 % W) < W / 2 { 0.25 } else { 0.5 };
            assert!((pixel.x - truth).abs() < 0.25 * truth, "pixel {i}: {} against {truth}", pixel.x);
        }
    }

    #[test]
    fn the_noise_estimate_follows_the_standard_error() {
        let (_, albedo) = floor(|_, _| [255, 255, 255]);
        let light = |_, _| 0.3;
        let (few, many) = (noise_estimate(&noisy(&albedo, 4, light)), noise_estimate(&noisy(&albedo, 64, light)));
        // Samples uniform on 0..0.6: standard deviation 0.6/√12.
        let expected = |n: f32| 0.6 / 12f32.sqrt() / n.sqrt();
        let (few, many) = (few.unwrap(), many.unwrap());
        assert!((few / expected(4.0) - 1.0).abs() < 0.2, "{few} against {}", expected(4.0));
        assert!((many / expected(64.0) - 1.0).abs() < 0.1, "{many} against {}", expected(64.0));
        assert_eq!(noise_estimate(&noisy(&albedo, 1, light)), None);
    }

    #[test]
    fn the_change_in_standard_errors_tells_noise_from_bias() {
        let (guides, albedo) = floor(|_, _| [200; 3]);
        let light = |x: u32, _| if x < W / 2 { 0.25 } else { 0.5 };
        let sums = noisy(&albedo, 256, light);
        let change = |image: &[Vec3]| change_in_standard_errors(&sums, &guides, image).unwrap();
        // Moved to the truth: by exactly the noise.
        let truth: Vec<Vec3> = (0..W * H).map(|i| albedo[i as usize] * light(i % W, i / W)).collect();
        let exact = change(&truth);
        assert!((0.9..1.1).contains(&exact.rms) && exact.beyond_four < 0.001, "{exact:?}");
        let filtered = change(&denoise(&frame(), &sums, &guides));
        assert!(filtered.rms < 1.1 && filtered.beyond_four < 0.001, "{filtered:?}");
        // Blurred across the step in the light: biased everywhere.
        let blurred: Vec<Vec3> = albedo.iter().map(|a| *a * 0.375).collect();
        let biased = change(&blurred);
        assert!(biased.rms > 4.0 && biased.beyond_four > 0.5, "{biased:?}");
        let none_filtered = vec![Guide::LEFT; guides.len()];
        assert_eq!(change_in_standard_errors(&sums, &none_filtered, &truth), None);
    }

    #[test]
    fn a_pixel_across_a_colour_edge_keeps_its_mix() {
        // Light and dark columns, 4 pixels wide; the pixels of every 4th
        // column straddle the edge: half their samples hit each colour,
        // their centre ray the dark one.
        let (light, dark) = (Vec3::splat(0.9), Vec3::splat(0.1));
        let (guides, mut albedo) = floor(|x, _| if (x / 4) % 2 == 0 { [230; 3] } else { [26; 3] });
        let edge = |i: usize| i as u32 % W % 8 == 4;
        for (i, a) in albedo.iter_mut().enumerate() {
            if edge(i) {
                *a = (light + dark) * 0.5;
            }
        }
        let sums = noisy(&albedo, 16, |_, _| 0.5);
        let denoised = denoise(&frame(), &sums, &guides);
        for (i, pixel) in denoised.iter().enumerate().filter(|(i, _)| edge(*i)) {
            let truth = albedo[i].x * 0.5;
            assert!((pixel.x - truth).abs() < 0.15 * truth, "edge pixel {i}: {} against {truth}", pixel.x);
        }
    }
}
