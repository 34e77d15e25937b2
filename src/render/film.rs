//! The film: per pixel, the sum and the sum of squares of the accepted samples, in f64 so that 10⁵ samples still
//! average correctly, and their count; and the largest single sample, for the firefly map. Non-finite samples are
//! never added: the pass counts them instead.

use crate::math::{Vec3x8, lane_mask, luminance, luminance_lanes};
use glam::{DVec3, Vec3};
use wide::{f32x8, f64x4};

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelAccum {
    pub sum: DVec3,
    pub sum_sq: DVec3,
    pub n: u32,
    /// Luminance of the largest single sample.
    pub max_luminance: f32,
}

impl PixelAccum {
    #[inline]
    pub fn add(&mut self, v: Vec3) {
        let d = v.as_dvec3();
        self.sum += d;
        self.sum_sq += d * d;
        self.n += 1;
        self.max_luminance = brighter(self.max_luminance, luminance(v));
    }

    /// The pixel's sums held in vectors, to add a pixel's groups of samples to ([`PixelSums::add_finite`]) and
    /// then store back ([`PixelSums::store`]).
    #[inline]
    pub fn sums(&self) -> PixelSums {
        let four = |v: DVec3| f64x4::new([v.x, v.y, v.z, 0.0]);
        PixelSums { sum: four(self.sum), sum_sq: four(self.sum_sq), n: self.n, max_luminance: self.max_luminance }
    }

    /// The pixel estimate: the sample mean.
    #[inline]
    pub fn mean(&self) -> DVec3 {
        if self.n == 0 { DVec3::ZERO } else { self.sum / self.n as f64 }
    }

    /// Unbiased sample variance of one sample, per channel.
    #[inline]
    pub fn variance(&self) -> DVec3 {
        if self.n < 2 {
            return DVec3::ZERO;
        }
        let n = self.n as f64;
        ((self.sum_sq - self.sum * self.sum / n) / (n - 1.0)).max(DVec3::ZERO)
    }

    /// The standard error of the mean, `sqrt(σ̂²/N)`, as the root mean square over R, G, B.
    #[inline]
    pub fn std_error(&self) -> f64 {
        if self.n < 2 { 0.0 } else { (self.variance().element_sum() / 3.0 / self.n as f64).sqrt() }
    }

    /// The relative variance of one sample, `σ̂² / (μ̂² + ε)` averaged over R, G, B with ε = 10⁻⁴: the number of
    /// samples needed for 100% relative error. Dimensionless, so dark and bright regions compare.
    #[inline]
    pub fn relative_variance(&self) -> f64 {
        let m = self.mean();
        (self.variance() / (m * m + DVec3::splat(1e-4))).element_sum() / 3.0
    }

    /// The firefly measure: the share of the pixel's luminance sum that its largest single sample carries, in
    /// [1/N, 1]. Near 1/N the samples are alike; near 1 one rare sample makes the pixel.
    #[inline]
    pub fn largest_share(&self) -> f64 {
        let total = luminance(self.sum.as_vec3()) as f64;
        if self.n == 0 || !(total > 0.0) { 0.0 } else { (self.max_luminance as f64 / total).min(1.0) }
    }
}

/// A pixel's sums while a pass adds its samples group by group: x, y, z in lanes 0–2 of f64x4 (lane 3 sums
/// zeros), so that each lane's sums are [`PixelAccum::add`]'s, bit for bit; taken from the pixel once
/// ([`PixelAccum::sums`]) and stored back once ([`PixelSums::store`]). The additions had taken 12–14% of the
/// Cornell box's `emitter` render (measured by leaving them out); adding a group from its vectors
/// ([`PixelSums::add_lanes`]) rather than sample by sample from an array took the render from 361.3 M to 333.8 M
/// instructions (callgrind, 128², 64 spp, one thread) and about 9% of its CPU time.
#[derive(Clone, Copy, Debug)]
pub struct PixelSums {
    sum: f64x4,
    sum_sq: f64x4,
    n: u32,
    max_luminance: f32,
}

impl PixelSums {
    /// Adds the finite samples of `values` in order, as [`PixelAccum::add`] would one by one (the same sums, bit
    /// for bit), and returns how many were not finite (counted, never added).
    #[inline]
    pub fn add_finite(&mut self, values: &[Vec3]) -> u64 {
        let mut added = 0;
        for &v in values.iter().filter(|v| v.is_finite()) {
            let d = f64x4::new([v.x as f64, v.y as f64, v.z as f64, 0.0]);
            self.sum += d;
            self.sum_sq += d * d;
            self.max_luminance = brighter(self.max_luminance, luminance(v));
            added += 1;
        }
        self.n += added;
        (values.len() - added as usize) as u64
    }

    /// Adds the samples in lanes `0..n` of `v` in lane order, as [`PixelSums::add_finite`] adds them from an
    /// array (the same sums, bit for bit), and returns how many were not finite. Where all n are finite (nearly
    /// always) their luminances are found in f32x8 and each sample's row `[x, y, z, 0]` is widened and transposed
    /// in vectors; the largest luminance does not depend on the order it is taken in ([`brighter`] from +0).
    #[inline]
    pub fn add_lanes(&mut self, v: &Vec3x8, n: usize) -> u64 {
        let used = (1u32 << n) - 1;
        let finite = (v.x.is_finite() & v.y.is_finite() & v.z.is_finite()).move_mask() as u32;
        if finite & used != used {
            return self.add_finite(&v.to_lanes()[..n]);
        }
        let l = bytemuck::cast::<_, f32x8>(lane_mask(used)).blend(luminance_lanes(v), f32x8::ZERO);
        let l = l.to_array();
        let half: [f32; 4] = std::array::from_fn(|i| brighter(l[i], l[i + 4]));
        self.max_luminance =
            brighter(self.max_luminance, brighter(brighter(half[0], half[2]), brighter(half[1], half[3])));
        for row in &wide_rows(v)[..n] {
            self.sum += *row;
            self.sum_sq += *row * *row;
        }
        self.n += n as u32;
        0
    }

    /// Stores the sums into the pixel they were taken from.
    #[inline]
    pub fn store(&self, pixel: &mut PixelAccum) {
        let three = |v: f64x4| DVec3::from_slice(&v.as_array_ref()[..3]);
        (pixel.sum, pixel.sum_sq, pixel.n, pixel.max_luminance) =
            (three(self.sum), three(self.sum_sq), self.n, self.max_luminance);
    }
}

/// Lane i of `v` as the row `[x, y, z, 0]` in f64, for each i: three vectors widened in halves and transposed in
/// 4 × 4 blocks (`vcvtps2pd`, `vunpcklpd`/`vunpckhpd`, `vperm2f128`).
#[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
#[inline(always)]
fn wide_rows(v: &Vec3x8) -> [f64x4; 8] {
    use safe_arch::*;
    let halves = |c: f32x8| {
        let c: m256 = bytemuck::cast(c);
        [cast_to_m128_from_m256(c), extract_m128_from_m256::<1>(c)].map(convert_to_m256d_from_m128)
    };
    let ([x0, x1], [y0, y1], [z0, z1]) = (halves(v.x), halves(v.y), halves(v.z));
    let block = |x: m256d, y: m256d, z: m256d| {
        let zero = zeroed_m256d();
        let (xy_even, xy_odd) = (unpack_lo_m256d(x, y), unpack_hi_m256d(x, y));
        let (z_even, z_odd) = (unpack_lo_m256d(z, zero), unpack_hi_m256d(z, zero));
        [
            permute2z_m256d::<0x20>(xy_even, z_even),
            permute2z_m256d::<0x20>(xy_odd, z_odd),
            permute2z_m256d::<0x31>(xy_even, z_even),
            permute2z_m256d::<0x31>(xy_odd, z_odd),
        ]
    };
    bytemuck::cast([block(x0, y0, z0), block(x1, y1, z1)])
}

/// Lane i of `v` as the row `[x, y, z, 0]` in f64, for each i.
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
#[inline(always)]
fn wide_rows(v: &Vec3x8) -> [f64x4; 8] {
    v.to_lanes().map(|v| f64x4::new([v.x as f64, v.y as f64, v.z as f64, 0.0]))
}

/// The largest luminance so far, `max`, after one more sample's `l`: `l` where it is greater, else `max`. One
/// `maxss`: `f32::max` also handles NaN, which no added sample has, at twice the latency, on a chain that runs
/// through every sample of a pixel.
#[inline(always)]
fn brighter(max: f32, l: f32) -> f32 {
    if l > max { l } else { max }
}

#[derive(Clone, Debug)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<PixelAccum>,
}

impl Film {
    pub fn new(width: u32, height: u32) -> Self {
        Self { width, height, pixels: vec![PixelAccum::default(); width as usize * height as usize] }
    }

    /// A film holding one sample per pixel with the given values (to write means that were computed elsewhere).
    pub fn from_means(width: u32, height: u32, means: &[Vec3]) -> Self {
        let mut film = Self::new(width, height);
        for (p, m) in film.pixels.iter_mut().zip(means) {
            p.add(*m);
        }
        film
    }

    #[inline]
    pub fn pixel(&self, x: u32, y: u32) -> &PixelAccum {
        &self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// The mean radiance of every pixel, row 0 first (the top row).
    pub fn means(&self) -> Vec<Vec3> {
        self.pixels.iter().map(|p| p.mean().as_vec3()).collect()
    }

    pub fn clear(&mut self) {
        self.pixels.fill(PixelAccum::default());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_variance() {
        let mut p = PixelAccum::default();
        for v in [1.0, 2.0, 3.0, 4.0] {
            p.add(Vec3::splat(v));
        }
        assert_eq!(p.mean(), DVec3::splat(2.5));
        assert!((p.variance().x - 5.0 / 3.0).abs() < 1e-12);
    }

    /// `PixelSums::add_finite` adds what `add` adds, bit for bit, and counts the non-finite samples it leaves
    /// out; stored back, the sums are the pixel's, and taken again they go on from there.
    #[test]
    fn sums_add_what_add_adds_for_each_finite_sample() {
        let values: Vec<Vec3> = (0..37)
            .map(|i| match i % 9 {
                4 => Vec3::new(f32::NAN, 1.0, 0.0),
                7 => Vec3::splat(f32::INFINITY),
                _ => Vec3::new(0.1 * i as f32, 1.0 / (i + 1) as f32, (i as f32).sqrt() * 3.7),
            })
            .collect();
        let (mut one, mut each) = (PixelAccum::default(), PixelAccum::default());
        let mut skipped = 0;
        for half in values.chunks(20) {
            let mut sums = one.sums();
            for chunk in half.chunks(8) {
                skipped += sums.add_finite(chunk);
            }
            sums.store(&mut one);
        }
        values.iter().filter(|v| v.is_finite()).for_each(|&v| each.add(v));
        assert_eq!(skipped, 8);
        assert_eq!(one, each);
        assert_eq!((one.sum.to_array().map(f64::to_bits), one.n), (each.sum.to_array().map(f64::to_bits), 29));
    }

    /// `PixelSums::add_lanes` adds lanes 0..n as `add` adds them one by one, bit for bit (sums, squares, count
    /// and the largest luminance, whatever the order of the largest and of zeros of either sign), for n = 1 to 8,
    /// with groups holding non-finite samples (counted, left out) and negative ones.
    #[test]
    fn lanes_add_what_add_adds() {
        let value = |i: usize| match i % 23 {
            5 => Vec3::new(1.0, f32::NAN, 0.0),
            11 => Vec3::new(0.0, 0.0, f32::NEG_INFINITY),
            13 => Vec3::splat(-0.0),
            17 => Vec3::new(-0.3, 0.1, -2.0),
            _ => Vec3::new((i as f32 * 0.37).sin() * 4.0, 1.0 / (i + 1) as f32, (i as f32).sqrt() * 1.7),
        };
        for n in 1..=8 {
            let (mut lanes, mut each) = (PixelAccum::default(), PixelAccum::default());
            let (mut sums, mut skipped) = (lanes.sums(), 0);
            for group in 0..40 {
                let v: [Vec3; 8] = std::array::from_fn(|l| value(group * 8 + l));
                skipped += sums.add_lanes(&Vec3x8::from_lanes(&v), n);
                v[..n].iter().filter(|v| v.is_finite()).for_each(|&v| each.add(v));
            }
            sums.store(&mut lanes);
            let bits = |p: &PixelAccum| {
                let (s, q) = (p.sum.to_array().map(f64::to_bits), p.sum_sq.to_array().map(f64::to_bits));
                (s, q, p.n, p.max_luminance.to_bits())
            };
            assert_eq!(bits(&lanes), bits(&each), "{n} lanes");
            assert_eq!(skipped + each.n as u64, 40 * n as u64, "{n} lanes: every sample added or counted");
            assert!(skipped > 0, "{n} lanes: the groups hold non-finite samples");
        }
    }

    #[test]
    fn error_measures() {
        let mut p = PixelAccum::default();
        for v in [1.0, 1.0, 1.0, 5.0] {
            p.add(Vec3::splat(v));
        }
        assert!((p.std_error() - (4.0f64 / 4.0).sqrt()).abs() < 1e-9, "σ̂² = 4, N = 4");
        assert!((p.relative_variance() - 4.0 / (4.0 + 1e-4)).abs() < 1e-9);
        assert!((p.largest_share() - 5.0 / 8.0).abs() < 1e-6);
        assert_eq!(PixelAccum::default().largest_share(), 0.0);
    }

    #[test]
    fn many_small_samples_average_exactly_enough() {
        let mut p = PixelAccum::default();
        for _ in 0..100_000 {
            p.add(Vec3::splat(1e-3));
        }
        assert!((p.mean().x / 1e-3f32 as f64 - 1.0).abs() < 1e-9);
    }
}
