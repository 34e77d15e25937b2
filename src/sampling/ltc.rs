//! An isotropic linearly transformed cosine (LTC; Heitz, Dupuy, Hill & Neubelt 2016, "Real-Time Polygonal-Light
//! Shading with Linearly Transformed Cosines") fitted to the Phong lobe `(α+1)/(2π) cos^α θ_r` about ω_r, with no
//! table. Directions ω₀ of the clamped cosine `D₀(ω₀) = (ω₀·z)⁺/π` are mapped by `M = Rᵀ·diag(s, s, 1)` (R a
//! frame whose z is ω_r) to ω = Mω₀/‖Mω₀‖, whose density is
//!
//! `D(ω) = D₀(ω₀) |M⁻¹| / ‖M⁻¹ω‖³ = d_z⁺ / (π s² ‖d‖⁴)`,  d = M⁻¹ω = diag(1/s, 1/s, 1) R ω.
//!
//! A polygon P of directions maps to the polygon M⁻¹P of cosine space, so `∫_P D dω = Ω⊥(M⁻¹P)/π` by Lambert,
//! and a direction with density `D/∫_P D` over P is a projected-solid-angle sample of M⁻¹P mapped back by M.
//!
//! The width: `s² = √2/(α + √2 − 1)` minimises `∫ q²/D dω` (q the Phong lobe: the relative second moment of
//! q/D, 1 for a perfect fit) to three digits from α = 1 to 10⁶; there it is at most 1.21 (measured in the
//! tests below; 2/(α+2) gives up to 1.25). At α = 1 the fit is exact (s = 1: the lobe is a cosine).

use glam::{DVec3, Vec3};
use std::f64::consts::{FRAC_1_PI, SQRT_2};

/// The LTC `M = Rᵀ·diag(s, s, 1)` about an axis.
#[derive(Clone, Copy, Debug)]
pub struct PhongLtc {
    /// R's rows: a frame whose z is ω_r.
    x: DVec3,
    y: DVec3,
    z: DVec3,
    s: f64,
}

/// The fitted s² for the Phong exponent α.
pub fn phong_ltc_scale_squared(alpha: f64) -> f64 {
    SQRT_2 / (alpha.max(0.0) + SQRT_2 - 1.0)
}

impl PhongLtc {
    pub fn new(axis: Vec3, alpha: f32) -> Self {
        Self::with_scale(axis, phong_ltc_scale_squared(alpha as f64).sqrt())
    }

    pub fn with_scale(axis: Vec3, s: f64) -> Self {
        // Duff et al.'s frame (as `Frame::from_z`), in f64: at α = 10⁶ the lobe is 10⁻³ rad wide, and an f32
        // frame's 10⁻⁷ of non-orthogonality would be visible in the density's ratio to the sampled one.
        let n = axis.as_dvec3().normalize();
        let sign = 1.0f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let x = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let y = DVec3::new(b, sign + n.y * n.y * a, -n.y);
        Self { x, y, z: n, s }
    }

    /// d = M⁻¹v = diag(1/s, 1/s, 1) R v: a vector (or a point relative to the shading point) in cosine space.
    #[inline]
    pub fn to_cosine_space(&self, v: DVec3) -> DVec3 {
        DVec3::new(v.dot(self.x) / self.s, v.dot(self.y) / self.s, v.dot(self.z))
    }

    /// Mω₀ = Rᵀ diag(s, s, 1) ω₀ (not normalised).
    #[inline]
    pub fn from_cosine_space(&self, w0: DVec3) -> DVec3 {
        self.x * (w0.x * self.s) + self.y * (w0.y * self.s) + self.z * w0.z
    }

    /// `D(ω) = d_z⁺ / (π s² ‖d‖⁴)` for a unit ω (solid angle; over the whole sphere it integrates to 1).
    #[inline]
    pub fn density(&self, w: DVec3) -> f64 {
        let d = self.to_cosine_space(w);
        if !(d.z > 0.0) {
            return 0.0;
        }
        let d2 = d.length_squared();
        d.z * FRAC_1_PI / (self.s * self.s * d2 * d2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `∫ q²/D dω` about the axis (both are isotropic), by the midpoint rule in θ.
    fn second_moment(alpha: f64, s: f64) -> f64 {
        let ltc = PhongLtc::with_scale(Vec3::Z, s);
        let width = (12.0 / (alpha + 1.0).sqrt()).min(std::f64::consts::FRAC_PI_2);
        let steps = 20_000;
        let h = width / steps as f64;
        (0..steps)
            .map(|i| {
                let t = (i as f64 + 0.5) * h;
                let q = (alpha + 1.0) / std::f64::consts::TAU * t.cos().powf(alpha);
                let d = ltc.density(DVec3::new(t.sin(), 0.0, t.cos()));
                q * q / d * t.sin() * std::f64::consts::TAU * h
            })
            .sum()
    }

    #[test]
    fn the_fitted_width_is_the_best_one_to_three_digits() {
        for alpha in [1.0, 3.0, 10.0, 30.0, 300.0, 3000.0, 1e6] {
            let s2 = phong_ltc_scale_squared(alpha);
            let fit = second_moment(alpha, s2.sqrt());
            // The best s² by golden-section search on log s².
            let (mut lo, mut hi) = ((s2 / 4.0).ln(), (s2 * 4.0).ln());
            for _ in 0..60 {
                let (a, b) = (lo + (hi - lo) * 0.382, lo + (hi - lo) * 0.618);
                if second_moment(alpha, (a.exp()).sqrt()) < second_moment(alpha, (b.exp()).sqrt()) {
                    hi = b;
                } else {
                    lo = a;
                }
            }
            let best = second_moment(alpha, ((lo + hi) / 2.0).exp().sqrt());
            assert!(fit <= 1.21 && fit / best - 1.0 < 1e-3, "α = {alpha}: ∫q²/D = {fit} against the best {best}");
        }
        // α = 1: the lobe is a cosine, the fit exact.
        assert!((second_moment(1.0, phong_ltc_scale_squared(1.0).sqrt()) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn density_integrates_to_one_and_maps_back_and_forth() {
        for alpha in [0.0, 1.0, 40.0, 1e4] {
            let ltc = PhongLtc::new(Vec3::Z, alpha);
            // D is isotropic about its axis: ∫ D dω = ∫ D(θ) 2π sin θ dθ, by the midpoint rule in cos θ.
            let steps = 200_000;
            let integral: f64 = (0..steps)
                .map(|i| {
                    let c = (i as f64 + 0.5) / steps as f64;
                    ltc.density(DVec3::new((1.0 - c * c).sqrt(), 0.0, c)) * std::f64::consts::TAU / steps as f64
                })
                .sum();
            assert!((integral - 1.0).abs() < 1e-3, "α = {alpha}: ∫D = {integral}");
        }
        let ltc = PhongLtc::new(Vec3::new(0.3, 0.2, 0.9).normalize(), 40.0);
        let w = DVec3::new(0.1, -0.3, 0.95).normalize();
        let back = ltc.from_cosine_space(ltc.to_cosine_space(w));
        assert!((back - w).length() < 1e-12);
        assert_eq!(ltc.density(-w), 0.0);
    }
}
