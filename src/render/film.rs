//! The film: per pixel, the sum and the sum of squares of the accepted samples, in f64 so that 10⁵ samples still
//! average correctly, and their count. Non-finite samples are never added: the pass counts them instead.

use glam::{DVec3, Vec3};

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelAccum {
    pub sum: DVec3,
    pub sum_sq: DVec3,
    pub n: u32,
}

impl PixelAccum {
    #[inline]
    pub fn add(&mut self, v: Vec3) {
        let v = v.as_dvec3();
        self.sum += v;
        self.sum_sq += v * v;
        self.n += 1;
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

    #[test]
    fn many_small_samples_average_exactly_enough() {
        let mut p = PixelAccum::default();
        for _ in 0..100_000 {
            p.add(Vec3::splat(1e-3));
        }
        assert!((p.mean().x / 1e-3f32 as f64 - 1.0).abs() < 1e-9);
    }
}
