//! The film: per pixel, the sum and the sum of squares of the accepted samples, in f64 so that 10⁵ samples still
//! average correctly, and their count; and the largest single sample, for the firefly map. Non-finite samples are
//! never added: the pass counts them instead.

use crate::math::luminance;
use glam::{DVec3, Vec3};
use wide::f64x4;

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
        self.max_luminance = self.max_luminance.max(luminance(v));
    }

    /// Adds the finite samples of `values` in order, as [`PixelAccum::add`] would one by one (the same sums, bit
    /// for bit), and returns how many were not finite (counted, never added). The sums stay in registers over the
    /// slice, where one `add` per sample stores them and loads them back, each add waiting on the store before.
    #[inline]
    pub fn add_finite(&mut self, values: &[Vec3]) -> u64 {
        // x, y, z in lanes 0–2 of f64x4: each lane's sums are the scalar ones (lane 3 sums zeros).
        let four = |v: DVec3| f64x4::new([v.x, v.y, v.z, 0.0]);
        let (mut sum, mut sum_sq, mut max) = (four(self.sum), four(self.sum_sq), self.max_luminance);
        let mut added = 0;
        for &v in values.iter().filter(|v| v.is_finite()) {
            let d = f64x4::new([v.x as f64, v.y as f64, v.z as f64, 0.0]);
            sum += d;
            sum_sq += d * d;
            max = max.max(luminance(v));
            added += 1;
        }
        let three = |v: f64x4| DVec3::from_slice(&v.as_array_ref()[..3]);
        (self.sum, self.sum_sq, self.max_luminance) = (three(sum), three(sum_sq), max);
        self.n += added;
        (values.len() - added as usize) as u64
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

    /// `add_finite` adds what `add` adds, bit for bit, and counts the non-finite samples it leaves out.
    #[test]
    fn add_finite_is_add_for_each_finite_sample() {
        let values: Vec<Vec3> = (0..37)
            .map(|i| match i % 9 {
                4 => Vec3::new(f32::NAN, 1.0, 0.0),
                7 => Vec3::splat(f32::INFINITY),
                _ => Vec3::new(0.1 * i as f32, 1.0 / (i + 1) as f32, (i as f32).sqrt() * 3.7),
            })
            .collect();
        let (mut one, mut each) = (PixelAccum::default(), PixelAccum::default());
        let mut skipped = 0;
        for chunk in values.chunks(8) {
            skipped += one.add_finite(chunk);
        }
        values.iter().filter(|v| v.is_finite()).for_each(|&v| each.add(v));
        assert_eq!(skipped, 8);
        assert_eq!(one, each);
        assert_eq!((one.sum.to_array().map(f64::to_bits), one.n), (each.sum.to_array().map(f64::to_bits), 29));
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
