//! Seeded randomness per (seed, pixel, sample index): a render is a function of the scene, the settings and the
//! seed, whatever the thread count and the order in which passes run.

use glam::Vec2;
use rand_core::Rng;
use rand_pcg::Pcg32;

/// The largest f32 below one: uniforms live in [0, 1).
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// A PCG32 stream (O'Neill 2014) whose state is a hash of (seed, pixel, sample index), so every pixel sample
/// has its own independent stream. Dimensions are drawn in a fixed order by each strategy.
pub struct SampleRng(Pcg32);

impl SampleRng {
    #[inline]
    pub fn new(seed: u64, pixel: u64, sample: u64) -> Self {
        PixelStreams::new(seed, pixel).sample(sample)
    }

    /// A uniform in [0, 1) with 24 random bits.
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        (self.0.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    #[inline]
    pub fn uniform_2d(&mut self) -> Vec2 {
        Vec2::new(self.uniform(), self.uniform())
    }
}

/// The part of every sample stream's key that depends only on (seed, pixel): hashed once per pixel, so each
/// sample's stream costs one more hash.
#[derive(Clone, Copy, Debug)]
pub struct PixelStreams {
    key: u64,
    stream: u64,
}

impl PixelStreams {
    #[inline]
    pub fn new(seed: u64, pixel: u64) -> Self {
        Self {
            key: mix64(seed ^ mix64(pixel ^ 0x9e37_79b9_7f4a_7c15)),
            stream: mix64(seed.wrapping_add(0x6a09_e667_f3bc_c909)),
        }
    }

    /// The stream of sample `sample`: PCG32 with state `mix64(key ⊕ sample·K)`, a bijection of the sample index
    /// for each pixel (K odd).
    #[inline]
    pub fn sample(&self, sample: u64) -> SampleRng {
        SampleRng(Pcg32::new(mix64(self.key ^ sample.wrapping_mul(0xd1b5_4a32_d192_ed03)), self.stream))
    }
}

/// SplitMix64's finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mix.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let draw = |sample| {
            let mut r = SampleRng::new(7, 3, sample);
            (0..8).map(|_| r.uniform()).collect::<Vec<f32>>()
        };
        let (a, b, c) = (draw(5), draw(5), draw(6));
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert!(a.iter().all(|u| (0.0..1.0).contains(u)));
    }

    #[test]
    fn uniforms_have_the_right_mean_across_pixels_and_across_samples() {
        let n = 100_000;
        let pixel = PixelStreams::new(1, 12_345);
        for draw in [|i| SampleRng::new(1, i, 0).uniform(), |i| PixelStreams::new(1, 12_345).sample(i).uniform()] {
            let mean = (0..n).map(|i| draw(i) as f64).sum::<f64>() / n as f64;
            // Standard error of the mean is sqrt(1/12/n) ≈ 9.1e-4; 5 standard errors (false failure ~6e-7).
            assert!((mean - 0.5).abs() < 4.6e-3, "{mean}");
        }
        assert_eq!(pixel.sample(7).uniform(), SampleRng::new(1, 12_345, 7).uniform());
    }
}
