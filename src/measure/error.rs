//! Image error against a reference, over all pixels and the three channels:
//!
//! ```text
//! MSE    = 1/(3P) Σ_p Σ_c (I_pc − R_pc)²
//! relMSE = 1/(3P) Σ_p Σ_c (I_pc − R_pc)² / (R_pc² + ε),   ε = 10⁻²
//! ```
//!
//! For an unbiased estimator `E[MSE] = Var(estimate) + Var(reference)`: the first term falls as 1/N, the second is
//! the reference's own noise floor, known for a rendered reference (`σ̂²/N_ref` per pixel). It is reported beside
//! the MSE and drawn in the plots, not subtracted: a reference with many more samples than the estimate keeps it
//! small (the bench uses 16× the largest budget); the convergence test subtracts it.

use super::Reference;
use glam::Vec3;

/// ε in relMSE: keeps black pixels from dominating.
pub const REL_MSE_EPSILON: f64 = 1e-2;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorMetrics {
    pub mse: f64,
    pub rel_mse: f64,
    /// The reference's own noise: mean `σ̂²/N_ref` (0 when unknown).
    pub reference_mse: f64,
}

impl ErrorMetrics {
    pub fn rmse(&self) -> f64 {
        self.mse.sqrt()
    }

    /// Monte Carlo efficiency `1 / (MSE · seconds)`: higher is better, independent of the budget for an unbiased
    /// estimator (MSE ∝ 1/N ∝ 1/seconds). `None` when it is not finite (zero error or zero time).
    pub fn efficiency(&self, seconds: f64) -> Option<f64> {
        let e = 1.0 / (self.mse * seconds);
        e.is_finite().then_some(e)
    }
}

/// The errors of `estimate` (per-pixel means, row 0 first) against `reference`, which must have the same size.
pub fn error_vs_reference(estimate: &[Vec3], reference: &Reference) -> ErrorMetrics {
    assert_eq!(estimate.len(), reference.mean.len(), "estimate and reference sizes differ");
    let (mut se, mut rel) = (0.0f64, 0.0f64);
    for (e, r) in estimate.iter().zip(&reference.mean) {
        let (e, r) = (e.as_dvec3(), r.as_dvec3());
        let d2 = (e - r) * (e - r);
        se += d2.element_sum();
        rel += (d2 / (r * r + glam::DVec3::splat(REL_MSE_EPSILON))).element_sum();
    }
    let n = (3 * estimate.len().max(1)) as f64;
    ErrorMetrics { mse: se / n, rel_mse: rel / n, reference_mse: reference.noise_mse() }
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
    fn a_perfect_estimate_has_zero_error_and_no_infinite_efficiency() {
        let r = reference(vec![Vec3::ONE; 4], None);
        let m = error_vs_reference(&[Vec3::ONE; 4], &r);
        assert_eq!(m.mse, 0.0);
        assert_eq!(m.efficiency(1.0), None, "never inf");
    }
}
