//! The mixture weights (c_g, c_l, c_b) of `guided`, learned per spatial leaf: where light sampling is already
//! near-perfect (an unoccluded light) the guide and the BRDF parts only waste samples, and where shadow rays are
//! almost all blocked the light part does. Müller et al. 2019 ("Practical Path Guiding in Production", §10)
//! learn the BSDF-sampling fraction by gradient descent on the KL divergence; here, simpler and exactly
//! reproducible, each of a fixed set of candidates is scored by the second moment of the one-sample estimator it
//! would give, estimated from the iteration's own samples (drawn with the old weights and guide, density p_old):
//!
//! `E_c[X²] = ∫ g² / p_c dω = E_old[ g² / (p_c p_old) ]`,  `p_c = c_g p_guide + c_l p_light + c_b p_brdf`,
//!
//! with g = luminance(f_r L_i (ω·n)) and X = g / p_c; the next iteration takes the candidate of least second
//! moment (so of least variance, the mean being the same for all). Every candidate has c_l + c_b > 0, so the
//! estimator stays unbiased whichever is chosen. Before a leaf has a guide, or with too few records that found
//! light, it keeps [`DEFAULT_WEIGHTS`].

/// The weights of the example, before anything is learned: guide, light, BRDF.
pub const DEFAULT_WEIGHTS: [f32; 3] = [0.5, 0.25, 0.25];

/// The guide's shares tried, and the light part's share of the rest.
const GUIDE_SHARES: [f32; 5] = [0.0, 0.25, 0.5, 0.75, 0.9];
const LIGHT_SHARES: [f32; 5] = [1.0, 0.75, 0.5, 0.25, 0.0];

/// How many candidates are scored.
pub const CANDIDATES: usize = GUIDE_SHARES.len() * LIGHT_SHARES.len();

/// Candidate i: (c_g, c_l, c_b).
pub fn candidate(i: usize) -> [f32; 3] {
    let (g, l) = (GUIDE_SHARES[i / LIGHT_SHARES.len()], LIGHT_SHARES[i % LIGHT_SHARES.len()]);
    [g, (1.0 - g) * l, (1.0 - g) * (1.0 - l)]
}

/// Records that found light a leaf needs before its weights are learned.
const MIN_LIT_RECORDS: u32 = 64;

/// Fixed-point fraction bits of the second-moment sums (as the quadtree's sums: order-independent).
const FRACTION_BITS: i32 = 32;

/// One sample's data for the weights: g / p_old (its luminance contribution), p_old, and the densities of the
/// guide, light and BRDF parts at its direction.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MixtureSample {
    pub contribution: f32,
    pub pdf: f32,
    pub parts: [f32; 3],
}

/// The second moments of every candidate over one leaf's samples.
#[derive(Clone, Debug)]
pub struct Moments {
    sums: [u128; CANDIDATES],
    lit: u32,
}

impl Default for Moments {
    fn default() -> Self {
        Self { sums: [0; CANDIDATES], lit: 0 }
    }
}

impl Moments {
    /// Adds one sample: `g² / (p_c p_old) = contribution² p_old / p_c` to each candidate's sum (an infinite
    /// score where the candidate could not have drawn a direction that carries light).
    pub fn record(&mut self, s: &MixtureSample) {
        if !(s.contribution > 0.0 && s.pdf > 0.0) {
            return;
        }
        self.lit += 1;
        let numerator = s.contribution as f64 * s.contribution as f64 * s.pdf as f64;
        for (i, sum) in self.sums.iter_mut().enumerate() {
            let c = candidate(i);
            let p = c[0] as f64 * s.parts[0] as f64 + c[1] as f64 * s.parts[1] as f64 + c[2] as f64 * s.parts[2] as f64;
            let term = if p > 0.0 { numerator / p } else { f64::INFINITY };
            let fixed = if term.is_finite() {
                (term.min((1u64 << 60) as f64) * (FRACTION_BITS as f64).exp2()).round() as u128
            } else {
                u128::MAX
            };
            *sum = sum.saturating_add(fixed);
        }
    }

    /// The candidate of least second moment, or the default with too few samples that found light.
    pub fn best(&self) -> [f32; 3] {
        if self.lit < MIN_LIT_RECORDS {
            return DEFAULT_WEIGHTS;
        }
        let (i, _) = self.sums.iter().enumerate().min_by_key(|&(_, s)| *s).unwrap_or((0, &0));
        candidate(i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_candidate_is_a_mixture_that_keeps_light_or_brdf_sampling() {
        for i in 0..CANDIDATES {
            let c = candidate(i);
            assert!((c.iter().sum::<f32>() - 1.0).abs() < 1e-6, "{c:?}");
            assert!(c[1] + c[2] > 0.0 && c.iter().all(|&w| w >= 0.0), "{c:?}");
        }
        assert!((0..CANDIDATES).any(|i| candidate(i) == [0.0, 1.0, 0.0]), "pure light sampling is a candidate");
    }

    /// Samples where only light sampling finds the light favour it; where only the guide does, the guide; where
    /// both fail, the BRDF; too few samples keep the default.
    #[test]
    fn the_best_candidate_follows_the_densities() {
        let score = |parts: [f32; 3]| {
            let mut m = Moments::default();
            for _ in 0..100 {
                // Drawn with the default weights: p_old is their mixture.
                let pdf: f32 = (0..3).map(|k| DEFAULT_WEIGHTS[k] * parts[k]).sum();
                m.record(&MixtureSample { contribution: 1.0 / pdf, pdf, parts });
            }
            m.best()
        };
        assert_eq!(score([0.0, 10.0, 0.1]), [0.0, 1.0, 0.0]);
        let guide = score([10.0, 0.0, 0.1]);
        assert!(guide[0] == 0.9 && guide[1] == 0.0, "{guide:?}");
        let mut few = Moments::default();
        few.record(&MixtureSample { contribution: 1.0, pdf: 1.0, parts: [0.0, 1.0, 0.0] });
        assert_eq!(few.best(), DEFAULT_WEIGHTS);
    }
}
