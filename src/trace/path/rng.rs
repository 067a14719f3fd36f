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

    #[test]
    fn streams_differ_by_pixel_and_sample() {
        let first = |p, s| Rng::new(p, s).uniform();
        assert_ne!(first(0, 0), first(1, 0));
        assert_ne!(first(0, 0), first(0, 1));
        assert_eq!(first(5, 9), first(5, 9));
    }
}
