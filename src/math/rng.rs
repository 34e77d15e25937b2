//! Seeded randomness per (seed, pixel, sample index): a render is a function of the scene, the settings and the
//! seed, whatever the thread count and the order in which passes run.

use glam::{Vec2, Vec3};
use wide::f32x8;

/// The largest f32 below one: uniforms live in [0, 1).
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// A PCG32 stream (O'Neill 2014: PCG-XSH-RR, 64-bit LCG state, 32-bit output, as `rand_pcg::Pcg32`) whose state
/// is a hash of (seed, pixel, sample index), so every pixel sample has its own independent stream. Dimensions are
/// drawn in a fixed order by each strategy.
#[derive(Clone, Copy, Debug)]
pub struct SampleRng {
    state: u64,
    increment: u64,
}

/// The LCG's multiplier (Knuth's MMIX, as in the PCG reference).
const MULTIPLIER: u64 = 6_364_136_223_846_793_005;

impl SampleRng {
    #[inline]
    pub fn new(seed: u64, pixel: u64, sample: u64) -> Self {
        PixelStreams::new(seed, pixel).sample(sample)
    }

    /// `rand_pcg::Pcg32::new(state, stream)`: the increment is `2·stream + 1`, the state moves off the seed by
    /// one increment and one step.
    #[inline(always)]
    fn pcg32(state: u64, stream: u64) -> Self {
        let increment = (stream << 1) | 1;
        Self { state: lcg_step(state.wrapping_add(increment), increment), increment }
    }

    /// The next 32 random bits: the output permutation of the current state, then one LCG step.
    #[inline(always)]
    fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = lcg_step(old, self.increment);
        xsh_rr(old)
    }

    /// A uniform in [0, 1) with 24 random bits.
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        to_uniform(self.next_u32())
    }

    #[inline]
    pub fn uniform_2d(&mut self) -> Vec2 {
        Vec2::new(self.uniform(), self.uniform())
    }

    /// The stream after `n` more uniforms.
    #[inline]
    pub fn after_uniforms(mut self, n: usize) -> Self {
        for _ in 0..n {
            self.next_u32();
        }
        self
    }
}

/// Eight [`SampleRng`] streams, one per SIMD lane, drawn together: the same numbers as each stream alone, in
/// AVX2 where the build has it ([`avx2`]), else from a loop over the lanes.
#[derive(Clone, Copy, Debug)]
pub struct SampleRngLanes {
    state: [u64; 8],
    increment: u64,
}

impl SampleRngLanes {
    /// The next uniform of every stream, lane i from stream i.
    #[inline(always)]
    pub fn uniform(&mut self) -> f32x8 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return avx2::uniforms(&mut self.state, self.increment);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        {
            let mut u = [0.0; 8];
            for (u, state) in u.iter_mut().zip(&mut self.state) {
                let old = *state;
                *state = lcg_step(old, self.increment);
                *u = to_uniform(xsh_rr(old));
            }
            f32x8::new(u)
        }
    }

    /// These streams, but those of `lanes` (bit i for stream i) as `before`'s after `n` more uniforms: where a
    /// sample drew fewer uniforms than the others since `before`.
    #[inline(always)]
    pub fn with_lanes_after(mut self, before: &Self, lanes: u32, n: usize) -> Self {
        for (i, state) in self.state.iter_mut().enumerate() {
            if lanes & (1 << i) != 0 {
                *state = before.lane(i).after_uniforms(n).state;
            }
        }
        self
    }

    /// Stream i, to go on alone.
    #[inline(always)]
    pub fn lane(&self, i: usize) -> SampleRng {
        SampleRng { state: self.state[i], increment: self.increment }
    }
}

#[inline(always)]
fn lcg_step(state: u64, increment: u64) -> u64 {
    state.wrapping_mul(MULTIPLIER).wrapping_add(increment)
}

/// PCG's output function XSH RR: an xorshift of the high bits, then a rotation by the top five.
#[inline(always)]
fn xsh_rr(state: u64) -> u32 {
    let rot = (state >> 59) as u32;
    let xsh = (((state >> 18) ^ state) >> 27) as u32;
    xsh.rotate_right(rot)
}

/// The top 24 bits as a uniform in [0, 1).
#[inline(always)]
fn to_uniform(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// PCG32 for eight streams in AVX2 registers (`safe_arch`'s wrappers of the intrinsics the build enables), the same
/// numbers as [`SampleRng`] bit for bit. Left to the compiler, the LCG's 64-bit products were vectorised but XSH RR
/// went lane by lane through the general registers (each state moved out, shifted, rotated and moved back).
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
mod avx2 {
    use super::MULTIPLIER;
    use safe_arch::*;
    use wide::f32x8;

    /// The next uniform of each of the eight streams `state` (advanced), as `to_uniform(xsh_rr(state))`.
    #[inline(always)]
    pub(super) fn uniforms(state: &mut [u64; 8], increment: u64) -> f32x8 {
        let [lo, hi]: [m256i; 2] = bytemuck::cast(*state);
        let increment = set_splat_i64_m256i(increment as i64);
        *state = bytemuck::cast([lcg_step(lo, increment), lcg_step(hi, increment)]);
        // XSH RR: xsh = ((s >> 18) ^ s) >> 27 and rot = s >> 59 in the low halves, then xsh rotated right by rot
        // (a left shift by 32 gives 0, so rot = 0 leaves xsh as it is).
        let xsh = |s| shr_imm_u64_m256i::<27>(bitxor_m256i(shr_imm_u64_m256i::<18>(s), s));
        let x = low_halves(xsh(lo), xsh(hi));
        let rot = low_halves(shr_imm_u64_m256i::<59>(lo), shr_imm_u64_m256i::<59>(hi));
        let left = sub_i32_m256i(set_splat_i32_m256i(32), rot);
        let bits = bitor_m256i(shr_each_u32_m256i(x, rot), shl_each_u32_m256i(x, left));
        // The top 24 bits as a uniform in [0, 1): exact in f32.
        let top = convert_to_m256_from_i32_m256i(shr_imm_u32_m256i::<8>(bits));
        bytemuck::cast(mul_m256(top, set_splat_m256(1.0 / (1u32 << 24) as f32)))
    }

    /// `s·M + c mod 2⁶⁴` in four lanes from 32-bit products: `s_lo·M_lo + ((s_hi·M_lo + s_lo·M_hi) << 32)`.
    #[inline(always)]
    fn lcg_step(s: m256i, increment: m256i) -> m256i {
        let m_lo = set_splat_i64_m256i((MULTIPLIER & 0xffff_ffff) as i64);
        let m_hi = set_splat_i64_m256i((MULTIPLIER >> 32) as i64);
        let cross =
            add_i64_m256i(mul_u64_low_bits_m256i(shr_imm_u64_m256i::<32>(s), m_lo), mul_u64_low_bits_m256i(s, m_hi));
        add_i64_m256i(add_i64_m256i(mul_u64_low_bits_m256i(s, m_lo), shl_imm_u64_m256i::<32>(cross)), increment)
    }

    /// The low 32 bits of a's four lanes, then of b's, as eight 32-bit lanes in order.
    #[inline(always)]
    fn low_halves(a: m256i, b: m256i) -> m256i {
        // Per 128-bit half: a₀ a₁ b₀ b₁ | a₂ a₃ b₂ b₃; then the 64-bit pairs reordered.
        let mixed = shuffle_m256::<0b10_00_10_00>(cast_to_m256_from_m256i(a), cast_to_m256_from_m256i(b));
        shuffle_ai_i64_all_m256i::<0b11_01_10_00>(cast_to_m256i_from_m256(mixed))
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
        SampleRng::pcg32(self.sample_state(sample), self.stream)
    }

    /// The streams of samples `first..first + 8`, lane i holding [`PixelStreams::sample`]`(first + i)`.
    /// A plain loop over the eight states, as in [`SampleRngLanes::uniform`]: built through `array::from_fn` and
    /// `map`, it compiled to calls per lane once the caller grew (5% more instructions for emitter sampling).
    #[inline(always)]
    pub fn samples(&self, first: u64) -> SampleRngLanes {
        let mut state = [0; 8];
        for (i, s) in state.iter_mut().enumerate() {
            *s = SampleRng::pcg32(self.sample_state(first.wrapping_add(i as u64)), self.stream).state;
        }
        SampleRngLanes { state, increment: SampleRng::pcg32(0, self.stream).increment }
    }

    #[inline(always)]
    fn sample_state(&self, sample: u64) -> u64 {
        mix64(self.key ^ sample.wrapping_mul(0xd1b5_4a32_d192_ed03))
    }
}

/// SplitMix64's finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mix.
#[inline(always)]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A hash of a point and a direction (of their coordinates' bits, through [`mix64`]): a random number that
/// depends on nothing but the ray, for choices that must not depend on the order of the rays.
#[inline]
pub fn hash_ray(p: Vec3, wi: Vec3) -> u64 {
    [p.to_array(), wi.to_array()].as_flattened().iter().fold(0, |h, v| mix64(h ^ v.to_bits() as u64))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stream_after_n_uniforms_goes_on_as_the_stream_that_drew_them() {
        for n in 0..5 {
            let mut drawn = SampleRng::new(3, 17, 5);
            for _ in 0..n {
                drawn.uniform();
            }
            let mut skipped = SampleRng::new(3, 17, 5).after_uniforms(n);
            assert!((0..4).all(|_| drawn.uniform().to_bits() == skipped.uniform().to_bits()), "n = {n}");
        }
    }

    /// Lanes taken from the streams before, n uniforms on, go on as those streams after n uniforms; the others
    /// are left as they were.
    #[test]
    fn lanes_after_fewer_uniforms_go_on_from_there() {
        let before = PixelStreams::new(9, 4).samples(16);
        let mut now = before;
        for _ in 0..3 {
            now.uniform();
        }
        let mixed = now.with_lanes_after(&before, 0b1010_0110, 1);
        for i in 0..8 {
            let expected = if 0b1010_0110 & (1 << i) != 0 { before.lane(i).after_uniforms(1) } else { now.lane(i) };
            let (mut a, mut b) = (mixed.lane(i), expected);
            assert!((0..4).all(|_| a.uniform().to_bits() == b.uniform().to_bits()), "lane {i}");
        }
    }

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

    /// Eight streams drawn together give each stream's numbers alone, bit for bit, over many states: every
    /// rotation XSH RR can apply (0 to 31) is met in every lane.
    #[test]
    fn eight_streams_together_are_each_stream_alone() {
        let mut rotations = [[0u32; 32]; 8];
        for pixel in 0..2000 {
            let mut lanes = PixelStreams::new(3, pixel).samples(pixel * 8);
            let mut alone: [SampleRng; 8] = std::array::from_fn(|i| lanes.lane(i));
            for _ in 0..8 {
                for (i, stream) in alone.iter().enumerate() {
                    rotations[i][(stream.state >> 59) as usize] += 1;
                }
                let together = lanes.uniform().to_array();
                for (i, stream) in alone.iter_mut().enumerate() {
                    assert_eq!(together[i].to_bits(), stream.uniform().to_bits(), "pixel {pixel}, lane {i}");
                }
            }
        }
        assert!(rotations.iter().flatten().all(|&n| n > 100), "{rotations:?}");
    }

    /// The streams are `rand_pcg::Pcg32`'s, number for number: alone, eight at a time, and alone again after
    /// drawing eight at a time.
    #[test]
    fn streams_are_rand_pcgs_pcg32() {
        use rand_core::Rng;
        for (seed, pixel) in [(0, 0), (1, 12_345), (u64::MAX, 7)] {
            let streams = PixelStreams::new(seed, pixel);
            for first in [0, 5, u64::MAX - 3] {
                let mut lanes = streams.samples(first);
                let together: Vec<[f32; 8]> = (0..10).map(|_| lanes.uniform().to_array()).collect();
                for i in 0..8 {
                    let sample = first.wrapping_add(i as u64);
                    let mut reference = rand_pcg::Pcg32::new(streams.sample_state(sample), streams.stream);
                    let (mut alone, mut after) = (streams.sample(sample), lanes.lane(i));
                    let mut drawn = together.iter().map(|u| u[i]).chain(std::iter::repeat_with(|| after.uniform()));
                    for draw in 0..20 {
                        let want = (reference.next_u32() >> 8) as f32 / (1u32 << 24) as f32;
                        assert_eq!(alone.uniform(), want);
                        let got = drawn.next().expect("endless");
                        assert_eq!(got, want, "seed {seed}, pixel {pixel}, sample {first} + {i}, draw {draw}");
                    }
                }
            }
        }
    }
}
