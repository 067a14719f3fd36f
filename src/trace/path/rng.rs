//! The counter-based random numbers of the path tracer, twin of `rng_*` in
//! `shaders/path.wgsl`: integer hashing only (wrapping u32 arithmetic), so
//! the CPU reference and the shader draw the same numbers for the same
//! pixel and sample.

/// PCG hash (Jarzynski and Olano, "Hash Functions for GPU Rendering", 2020).
pub fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// The R2 sequence's steps (Roberts 2018, the plastic number's
/// reciprocal and its square) in 0.32 fixed point.
pub const R2_STEP: [u32; 2] = [3_242_174_889, 2_447_445_414];
/// Mixed into the pixel index before hashing it into the pixel's shift.
pub const R2_SHIFT_SEED: u32 = 0x5bd1_e995;

/// Where sample `sample` falls in pixel `pixel` ([0, 1)²): the R2
/// sequence shifted by a hash of the pixel (a Cranley–Patterson rotation,
/// so that neighbours' patterns differ). Any run of consecutive samples
/// covers the pixel evenly, where independent jitter leaves holes and
/// clumps: edges and sub-pixel detail converge faster. Integer arithmetic
/// so that it stays exact at any sample count, and equal to the shader's.
pub fn pixel_offset(pixel: u32, sample: u32) -> (f32, f32) {
    let shift_x = pcg(pixel ^ R2_SHIFT_SEED);
    let shift_y = pcg(shift_x);
    let x = shift_x.wrapping_add(sample.wrapping_mul(R2_STEP[0]));
    let y = shift_y.wrapping_add(sample.wrapping_mul(R2_STEP[1]));
    let unit = |v: u32| (v >> 8) as f32 * (1.0 / 16_777_216.0);
    (unit(x), unit(y))
}

/// The random stream of one pixel's sample.
#[derive(Clone, Copy, Debug)]
pub struct Rng {
    state: u32,
}

impl Rng {
    /// Stream of sample `sample` of pixel `pixel` (row-major index).
    pub fn new(pixel: u32, sample: u32) -> Rng {
        Rng { state: pcg(pixel ^ pcg(sample.wrapping_add(0x9e37_79b9))) }
    }

    /// Uniform in [0, 1): the top 24 bits of the next hash.
    pub fn uniform(&mut self) -> f32 {
        self.state = pcg(self.state);
        (self.state >> 8) as f32 * (1.0 / 16_777_216.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_uniform_and_below_one() {
        let mut rng = Rng::new(12345, 7);
        let n = 100_000;
        let values: Vec<f32> = (0..n).map(|_| rng.uniform()).collect();
        assert!(values.iter().all(|v| (0.0..1.0).contains(v)));
        let mean = values.iter().sum::<f32>() / n as f32;
        assert!((mean - 0.5).abs() < 0.01, "mean {mean}");
        let low = values.iter().filter(|v| **v < 0.1).count() as f32 / n as f32;
        assert!((low - 0.1).abs() < 0.01, "{low}");
    }

    /// The cells of a 4×4 grid over the pixel that 16 consecutive offsets
    /// leave empty.
    fn empty_cells(offsets: impl Iterator<Item = (f32, f32)>) -> usize {
        let mut cells = [0u32; 16];
        for (x, y) in offsets {
            assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
            cells[(y * 4.0) as usize * 4 + (x * 4.0) as usize] += 1;
        }
        cells.iter().filter(|c| **c == 0).count()
    }

    #[test]
    fn pixel_offsets_cover_the_pixel_evenly() {
        // Independent jitter leaves about 6 of the 16 cells empty.
        let (mut r2, mut independent) = (0, 0);
        for pixel in [0, 1, 777, 123_456] {
            for start in [0, 5, 1000] {
                let samples = start..start + 16;
                let empty = empty_cells(samples.clone().map(|s| pixel_offset(pixel, s)));
                assert!(empty <= 3, "pixel {pixel}, samples {start}..: {empty} empty cells");
                r2 += empty;
                independent += empty_cells(samples.map(|s| {
                    let mut rng = Rng::new(pixel, s);
                    (rng.uniform(), rng.uniform())
                }));
            }
        }
        println!("empty cells of 12 runs of 16: R2 {r2}, independent {independent}");
        assert!(3 * r2 < independent, "R2 {r2}, independent {independent}");
        assert_ne!(pixel_offset(0, 0), pixel_offset(1, 0));
    }

    #[test]
    fn streams_differ_by_pixel_and_sample() {
        let first = |p, s| Rng::new(p, s).uniform();
        assert_ne!(first(0, 0), first(1, 0));
        assert_ne!(first(0, 0), first(0, 1));
        assert_eq!(first(5, 9), first(5, 9));
    }
}
