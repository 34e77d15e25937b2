//! Linearly transformed cosines (LTC; Heitz, Dupuy, Hill & Neubelt 2016, "Real-Time Polygonal-Light Shading with
//! Linearly Transformed Cosines"), fitted to the Phong lobe times the cosine. Directions ω₀ of the clamped cosine
//! `D₀(ω₀) = (ω₀·z)⁺/π` are mapped by a matrix M to ω = Mω₀/‖Mω₀‖, whose density is
//!
//! `D(ω) = D₀(ω₀) |M⁻¹| / ‖M⁻¹ω‖³ = d_z⁺ |M⁻¹| / (π ‖d‖⁴)`,  d = M⁻¹ω.
//!
//! A polygon P of directions maps to the polygon M⁻¹P of cosine space, so `∫_P D dω = Ω⊥(M⁻¹P)/π` by Lambert,
//! and a direction with density `D/∫_P D` over P is a projected-solid-angle sample of M⁻¹P mapped back by M.
//! Any invertible M gives an exact density; the fit only decides how close D is to the lobe.
//!
//! The Phong LTC ([`PhongLtc`]) is built in the shading frame (z = n, x towards ω_o's side of the plane of
//! incidence, θ_o the view's angle from n) as
//!
//! `M = F · R_y(τ) · [[a, 0, b], [0, c, 0], [0, 0, 1]]`,  (a, b, c) = s·(A, B, C), τ = θ_o + T,
//!
//! F the shading frame, R_y(τ) the tilt of the axis from n towards ω_r, and s² = √2/(α + √2 − 1) the width of
//! the isotropic fit to the lobe alone ([`phong_ltc_scale_squared`]; A = C = 1, B = T = 0 is that fit about ω_r).
//! (A, B, C, T) and the lobe's mass above the horizon `Z = ∫ (α+1)/(2π) (ω·ω_r)⁺^α (ω·n)⁺ dω` are tabulated over
//! (α, θ_o) by `examples/fit_phong_ltc.rs` (in [`super::phong_ltc_table`]), fitted to `q = lobe·(ω·n)⁺/Z` by
//! minimising `∫ q²/D dω`, the relative second moment of q/D (1 for a perfect fit: the variance of sampling q with
//! D). Between the nodes the parameters are interpolated bilinearly in (ln(α+1), θ_o); beyond them, clamped.

use super::phong_ltc_table::{ALPHA_NODES, PARAMETERS, THETA_NODES};
use glam::{DMat3, DVec3, Vec3};
use std::f64::consts::{FRAC_1_PI, SQRT_2};

/// An LTC: the matrix M, its inverse and |M⁻¹|.
#[derive(Clone, Copy, Debug)]
pub struct Ltc {
    m: DMat3,
    m_inv: DMat3,
    det_inv: f64,
}

impl Ltc {
    /// `None` for a singular M.
    pub fn from_matrix(m: DMat3) -> Option<Self> {
        let det = m.determinant();
        (det.abs() > 0.0 && det.is_finite()).then(|| Self { m, m_inv: m.inverse(), det_inv: 1.0 / det.abs() })
    }

    /// d = M⁻¹v: a vector (or a point relative to the shading point) in cosine space.
    #[inline]
    pub fn to_cosine_space(&self, v: DVec3) -> DVec3 {
        self.m_inv * v
    }

    /// Mω₀ (not normalised).
    #[inline]
    pub fn from_cosine_space(&self, w0: DVec3) -> DVec3 {
        self.m * w0
    }

    /// `D(ω) = d_z⁺ |M⁻¹| / (π ‖d‖⁴)` for a unit ω (solid angle; over the whole sphere it integrates to 1).
    #[inline]
    pub fn density(&self, w: DVec3) -> f64 {
        let d = self.m_inv * w;
        if !(d.z > 0.0) {
            return 0.0;
        }
        let d2 = d.length_squared();
        d.z * self.det_inv * FRAC_1_PI / (d2 * d2)
    }
}

/// The width s² of the isotropic LTC about ω_r fitted to the lobe alone (no cosine): it minimises `∫ q²/D` to
/// three digits from α = 1 to 10⁶, where that is at most 1.21 (tested below).
pub fn phong_ltc_scale_squared(alpha: f64) -> f64 {
    SQRT_2 / (alpha.max(0.0) + SQRT_2 - 1.0)
}

/// The fitted parameters at one (α, θ_o): the LTC's shape relative to the isotropic fit, and the lobe's mass Z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhongLtcParameters {
    pub a: f64,
    pub b: f64,
    pub c: f64,
    /// The axis's tilt from ω_r's angle θ_o, towards ω_r (radians).
    pub tilt: f64,
    /// `∫ (α+1)/(2π) (ω·ω_r)⁺^α (ω·n)⁺ dω` over the whole hemisphere.
    pub mass: f64,
}

impl PhongLtcParameters {
    /// The isotropic fit about ω_r (what the fit starts from).
    pub const ISOTROPIC: Self = Self { a: 1.0, b: 0.0, c: 1.0, tilt: 0.0, mass: 1.0 };

    /// M in the shading frame (z = n, ω_o in the xz-plane on the +x side) for the view angle θ_o.
    pub fn local_matrix(&self, alpha: f64, theta_o: f64) -> DMat3 {
        let s = phong_ltc_scale_squared(alpha).sqrt();
        let tau = theta_o + self.tilt;
        // R_y(τ) takes z to (−sin τ, 0, cos τ): towards ω_r, which is on the −x side.
        let (sin, cos) = tau.sin_cos();
        let rotation = DMat3::from_cols(DVec3::new(cos, 0.0, sin), DVec3::Y, DVec3::new(-sin, 0.0, cos));
        let shape = DMat3::from_cols(
            DVec3::new(s * self.a, 0.0, 0.0),
            DVec3::new(0.0, s * self.c, 0.0),
            DVec3::new(s * self.b, 0.0, 1.0),
        );
        rotation * shape
    }

    /// Bilinear interpolation of the table in (ln(α+1), θ_o), clamped at its ends.
    pub fn lookup(alpha: f64, theta_o: f64) -> Self {
        let (i, fi) = locate(&ALPHA_NODES, (alpha.max(0.0) + 1.0).ln());
        let (j, fj) = locate(&THETA_NODES, theta_o);
        let at = |i: usize, j: usize| PARAMETERS[i * THETA_NODES.len() + j];
        let lerp = |p: [f64; 5], q: [f64; 5], t: f64| std::array::from_fn::<f64, 5, _>(|k| p[k] + (q[k] - p[k]) * t);
        let row0 = lerp(at(i, j), at(i, j + 1), fj);
        let row1 = lerp(at(i + 1, j), at(i + 1, j + 1), fj);
        let [a, b, c, tilt, mass] = lerp(row0, row1, fi);
        Self { a, b, c, tilt, mass }
    }
}

/// The cell of `nodes` (increasing) that holds x and where in it, clamped to the ends.
fn locate(nodes: &[f64], x: f64) -> (usize, f64) {
    let last = nodes.len() - 2;
    let i = nodes.partition_point(|&n| n <= x).saturating_sub(1).min(last);
    let t = ((x - nodes[i]) / (nodes[i + 1] - nodes[i])).clamp(0.0, 1.0);
    (i, if t.is_finite() { t } else { 0.0 })
}

/// The Phong lobe's LTC at a shading point, and the lobe's mass above the horizon.
#[derive(Clone, Copy, Debug)]
pub struct PhongLtc {
    pub ltc: Ltc,
    /// `Z = ∫ (α+1)/(2π) (ω·ω_r)⁺^α (ω·n)⁺ dω`: the specular part's integral is `k_s Z ∫_Δ D` where D fits.
    pub mass: f64,
}

impl PhongLtc {
    /// For unit n and ω_o (ω_o·n ≥ 0) and the exponent α. `None` where M is singular (it is not for the table's
    /// values).
    pub fn new(n: Vec3, wo: Vec3, alpha: f32) -> Option<Self> {
        let (n, wo) = (n.as_dvec3().normalize(), wo.as_dvec3());
        let tangent = wo - n * wo.dot(n);
        // At normal incidence the lobe is symmetric about n: any tangent will do.
        let x = if tangent.length_squared() > 1e-24 { tangent.normalize() } else { n.any_orthonormal_vector() };
        let y = n.cross(x);
        let theta_o = wo.dot(n).clamp(-1.0, 1.0).acos();
        let alpha = alpha as f64;
        let parameters = PhongLtcParameters::lookup(alpha, theta_o);
        let frame = DMat3::from_cols(x, y, n);
        let ltc = Ltc::from_matrix(frame * parameters.local_matrix(alpha, theta_o))?;
        Some(Self { ltc, mass: parameters.mass.max(0.0) })
    }
}

/// Stratified samples of the Phong lobe about ω_r at (α, θ_o), in the shading frame, for the fit's objective
/// `∫ q²/D dω = E_g[g (ω·n)⁺² / (Z² D(ω))]` (q = lobe·(ω·n)⁺/Z, g the lobe's density, which covers q). Fixed
/// samples make the objective a smooth function of the LTC (`examples/fit_phong_ltc.rs` minimises it).
pub struct LobeSamples {
    directions: Vec<DVec3>,
    /// `g (ω·n)⁺² / Z²` per sample.
    weights: Vec<f64>,
    /// Z, the lobe's mass above the horizon.
    pub mass: f64,
}

impl LobeSamples {
    pub fn new(alpha: f64, theta_o: f64, strata: usize) -> Self {
        let wr = DVec3::new(-theta_o.sin(), 0.0, theta_o.cos());
        let e1 = DVec3::new(theta_o.cos(), 0.0, theta_o.sin());
        let (mut directions, mut lobe, mut cosines) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..strata {
            for j in 0..strata {
                let u = (i as f64 + 0.5) / strata as f64;
                let phi = std::f64::consts::TAU * (j as f64 + 0.5) / strata as f64;
                // cos θ_r = u^{1/(α+1)}; ln g = ln((α+1)/2π) + α ln cos θ_r.
                let ln_cos = u.ln() / (alpha + 1.0);
                let sin = (-(2.0 * ln_cos).exp_m1()).max(0.0).sqrt();
                let w = (e1 * phi.cos() + DVec3::Y * phi.sin()) * sin + wr * ln_cos.exp();
                directions.push(w.normalize());
                lobe.push((((alpha + 1.0) / std::f64::consts::TAU).ln() + alpha * ln_cos).exp());
                cosines.push(w.z.max(0.0));
            }
        }
        let mass = cosines.iter().sum::<f64>() / cosines.len() as f64;
        let weights = lobe.iter().zip(&cosines).map(|(g, c)| g * c * c / (mass * mass)).collect();
        Self { directions, weights, mass }
    }

    /// `∫ q²/D dω` for the LTC (in the shading frame): 1 for a perfect fit; infinite where D misses q.
    pub fn second_moment(&self, ltc: &Ltc) -> f64 {
        let mut sum = 0.0;
        for (w, weight) in self.directions.iter().zip(&self.weights) {
            if *weight > 0.0 {
                let d = ltc.density(*w);
                if !(d > 0.0) {
                    return f64::INFINITY;
                }
                sum += weight / d;
            }
        }
        sum / self.directions.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::SampleRng;
    use crate::sampling::sample_cosine_hemisphere;

    /// `∫ q²/D dω` about the axis for the isotropic LTC against the lobe alone (both isotropic), by the midpoint
    /// rule in θ.
    fn second_moment(alpha: f64, s: f64) -> f64 {
        let m = DMat3::from_diagonal(DVec3::new(s, s, 1.0));
        let ltc = Ltc::from_matrix(m).unwrap();
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
    fn the_isotropic_width_is_the_best_one_to_three_digits() {
        for alpha in [1.0, 3.0, 10.0, 30.0, 300.0, 3000.0, 1e6] {
            let s2 = phong_ltc_scale_squared(alpha);
            let fit = second_moment(alpha, s2.sqrt());
            // The best s² by golden-section search on ln s².
            let (mut lo, mut hi) = ((s2 / 4.0).ln(), (s2 * 4.0).ln());
            for _ in 0..60 {
                let (a, b) = (lo + (hi - lo) * 0.382, lo + (hi - lo) * 0.618);
                if second_moment(alpha, a.exp().sqrt()) < second_moment(alpha, b.exp().sqrt()) {
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

    /// Between the table's nodes (where interpolation could leave the fit's valley), the interpolated LTC is
    /// never worse than the isotropic one about ω_r by more than 1%, and better at grazing views where the
    /// horizon cuts the lobe (θ_o > 85°, 1 ≤ α ≤ 1000; a narrower lobe is not cut there).
    #[test]
    fn the_table_beats_the_isotropic_fit_between_its_nodes() {
        use super::super::phong_ltc_table::{ALPHA_NODES, THETA_NODES};
        let (mut worst, mut gain_at_grazing) = (0.0f64, f64::INFINITY);
        for i in 0..ALPHA_NODES.len() - 1 {
            for j in 0..THETA_NODES.len() - 1 {
                let alpha = (0.5 * (ALPHA_NODES[i] + ALPHA_NODES[i + 1])).exp_m1();
                let theta = 0.5 * (THETA_NODES[j] + THETA_NODES[j + 1]);
                let samples = LobeSamples::new(alpha, theta, 32);
                let moment = |p: PhongLtcParameters| {
                    samples.second_moment(&Ltc::from_matrix(p.local_matrix(alpha, theta)).unwrap())
                };
                let (fit, isotropic) =
                    (moment(PhongLtcParameters::lookup(alpha, theta)), moment(PhongLtcParameters::ISOTROPIC));
                worst = worst.max(fit / isotropic);
                if theta > 85f64.to_radians() && (1.0..=1000.0).contains(&alpha) {
                    gain_at_grazing = gain_at_grazing.min(isotropic / fit);
                }
            }
        }
        eprintln!("worst fitted/isotropic between nodes {worst:.4}; least gain at grazing {gain_at_grazing:.3}");
        assert!(worst < 1.01, "the interpolated fit is worse than the isotropic one: {worst}");
        assert!(gain_at_grazing > 1.1, "no gain at grazing: {gain_at_grazing}");
    }

    #[test]
    fn density_integrates_to_one_and_is_the_pushed_forward_cosine() {
        for (alpha, theta) in [(0.0f32, 0.0f32), (1.0, 0.3), (40.0, 1.2), (1e4, 1.5)] {
            let wo = Vec3::new(theta.sin(), theta.cos(), 0.0);
            let ltc = PhongLtc::new(Vec3::Y, wo, alpha).unwrap().ltc;
            if alpha <= 40.0 {
                // ∫ D over the sphere by the midpoint rule in (cos, φ) about n (too coarse for a narrow lobe).
                let (nc, np) = (400, 400);
                let mut integral = 0.0;
                for i in 0..nc {
                    for j in 0..np {
                        let c = -1.0 + 2.0 * (i as f64 + 0.5) / nc as f64;
                        let phi = std::f64::consts::TAU * (j as f64 + 0.5) / np as f64;
                        let s = (1.0 - c * c).sqrt();
                        let w = DVec3::new(s * phi.cos(), c, s * phi.sin());
                        integral += ltc.density(w) * 2.0 / nc as f64 * std::f64::consts::TAU / np as f64;
                    }
                }
                assert!((integral - 1.0).abs() < 5e-3, "α = {alpha}, θ_o = {theta}: ∫D = {integral}");
            }
            // Cosine samples pushed forward land where D > 0, and map back.
            let mut rng = SampleRng::new(1, 2, 3);
            for _ in 0..1000 {
                let w0 = sample_cosine_hemisphere(rng.uniform_2d()).as_dvec3();
                let w = ltc.from_cosine_space(w0).normalize();
                assert!(ltc.density(w) > 0.0);
                assert!((ltc.to_cosine_space(w).normalize() - w0).length() < 1e-6);
            }
        }
    }
}
