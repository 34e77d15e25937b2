//! Image error against a reference, over all pixels and the three channels:
//!
//! ```text
//! MSE    = 1/(3P) Σ_p Σ_c (I_pc − R_pc)²
//! relMSE = 1/(3P) Σ_p Σ_c (I_pc − R_pc)² / (R_pc² + ε),   ε = 10⁻²
//! ```
//!
//! For an unbiased estimator `E[MSE] = Var(estimate) + Var(reference)`: the first term falls as 1/N, the second is
//! the reference's own noise floor, known for a rendered reference (`σ̂²/N_ref` per pixel). The viewer reports it
//! beside the MSE and draws it in the plots; the bench subtracts it ([`ErrorMetrics::estimator_mse`]), over the
//! same pixels: [`error_over`] leaves some out (those that see an emitter directly, see
//! [`super::sees_emitter`]).

use super::Reference;
use glam::{DVec3, Vec3};

/// ε in relMSE: keeps black pixels from dominating.
pub const REL_MSE_EPSILON: f64 = 1e-2;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorMetrics {
    pub mse: f64,
    pub rel_mse: f64,
    /// The reference's own noise over the same pixels: mean `σ̂²/N_ref` (0 when unknown).
    pub reference_mse: f64,
    /// The same relative to the reference's brightness: mean `(σ̂²/N_ref) / (R² + ε)` (0 when unknown).
    pub reference_rel_mse: f64,
}

impl ErrorMetrics {
    pub fn rmse(&self) -> f64 {
        self.mse.sqrt()
    }

    /// The estimator's own MSE: `MSE − Var(reference)`, an unbiased estimate of `Var(estimate)` (it can come out
    /// slightly negative when the estimate is as good as the reference).
    pub fn estimator_mse(&self) -> f64 {
        self.mse - self.reference_mse
    }

    /// The same for relMSE.
    pub fn estimator_rel_mse(&self) -> f64 {
        self.rel_mse - self.reference_rel_mse
    }

    /// Monte Carlo efficiency `1 / (MSE · seconds)`: higher is better, independent of the budget for an unbiased
    /// estimator (MSE ∝ 1/N ∝ 1/seconds). `None` when it is not finite (zero error or zero time).
    pub fn efficiency(&self, seconds: f64) -> Option<f64> {
        let e = 1.0 / (self.mse * seconds);
        e.is_finite().then_some(e)
    }
}

/// The errors of `estimate` (per-pixel means, row 0 first) against `reference`, which must have the same size,
/// over every pixel.
pub fn error_vs_reference(estimate: &[Vec3], reference: &Reference) -> ErrorMetrics {
    error_over(estimate, reference, None)
}

/// The errors over the pixels `included` marks (all when `None`; zero errors when it marks none).
pub fn error_over(estimate: &[Vec3], reference: &Reference, included: Option<&[bool]>) -> ErrorMetrics {
    assert_eq!(estimate.len(), reference.mean.len(), "estimate and reference sizes differ");
    let eps = DVec3::splat(REL_MSE_EPSILON);
    let (mut se, mut rel, mut var, mut rel_var, mut pixels) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0usize);
    for (i, (e, r)) in estimate.iter().zip(&reference.mean).enumerate() {
        if included.is_some_and(|inc| !inc[i]) {
            continue;
        }
        let (e, r) = (e.as_dvec3(), r.as_dvec3());
        let d2 = (e - r) * (e - r);
        se += d2.element_sum();
        rel += (d2 / (r * r + eps)).element_sum();
        if let Some(v) = &reference.var_of_mean {
            let v = v[i].as_dvec3();
            var += v.element_sum();
            rel_var += (v / (r * r + eps)).element_sum();
        }
        pixels += 1;
    }
    let n = (3 * pixels.max(1)) as f64;
    ErrorMetrics { mse: se / n, rel_mse: rel / n, reference_mse: var / n, reference_rel_mse: rel_var / n }
}

/// `|I − R|` per pixel, averaged over R, G, B: the absolute-error map.
pub fn absolute_error_map(estimate: &[Vec3], reference: &Reference) -> Vec<f32> {
    estimate.iter().zip(&reference.mean).map(|(e, r)| (*e - *r).abs().element_sum() / 3.0).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::ReferenceOrigin;

    fn reference(mean: Vec<Vec3>, var: Option<Vec<Vec3>>) -> Reference {
        Reference {
            width: mean.len() as u32,
            height: 1,
            mean,
            var_of_mean: var,
            spp: 16,
            seconds: 0.0,
            origin: ReferenceOrigin::Rendered,
        }
    }

    #[test]
    fn metrics_by_hand() {
        let r = reference(vec![Vec3::splat(1.0), Vec3::splat(0.0)], Some(vec![Vec3::splat(0.01), Vec3::ZERO]));
        let e = [Vec3::new(1.0, 1.0, 3.0), Vec3::splat(0.1)];
        let m = error_vs_reference(&e, &r);
        // Squared errors: (0, 0, 4) and (0.01, 0.01, 0.01).
        assert!((m.mse - 4.03 / 6.0).abs() < 1e-7);
        assert!((m.rmse() - (4.03f64 / 6.0).sqrt()).abs() < 1e-7);
        let rel = 4.0 / 1.01 + 3.0 * 0.01 / 0.01;
        assert!((m.rel_mse - rel / 6.0).abs() < 1e-6);
        assert!((m.reference_mse - 0.03 / 6.0).abs() < 1e-9);
        assert_eq!(m.efficiency(2.0), Some(1.0 / (m.mse * 2.0)));
        assert_eq!(absolute_error_map(&e, &r)[0], 2.0 / 3.0);
    }

    #[test]
    fn excluded_pixels_count_for_neither_the_error_nor_the_reference_noise() {
        let r = reference(vec![Vec3::splat(1.0), Vec3::splat(0.0)], Some(vec![Vec3::splat(0.01), Vec3::splat(0.5)]));
        let e = [Vec3::new(1.0, 1.0, 3.0), Vec3::splat(0.1)];
        let m = error_over(&e, &r, Some(&[true, false]));
        assert!((m.mse - 4.0 / 3.0).abs() < 1e-7);
        assert!((m.reference_mse - 0.01).abs() < 1e-9);
        assert!((m.reference_rel_mse - 0.01 / 1.01).abs() < 1e-9);
        assert!((m.estimator_mse() - (4.0 / 3.0 - 0.01)).abs() < 1e-7);
        assert_eq!(error_over(&e, &r, Some(&[false, false])).mse, 0.0);
        assert_eq!(error_over(&e, &r, None), error_vs_reference(&e, &r));
    }

    #[test]
    fn a_perfect_estimate_has_zero_error_and_no_infinite_efficiency() {
        let r = reference(vec![Vec3::ONE; 4], None);
        let m = error_vs_reference(&[Vec3::ONE; 4], &r);
        assert_eq!(m.mse, 0.0);
        assert_eq!(m.efficiency(1.0), None, "never inf");
    }
}
