//! The mixture weights (c_g, c_l, c_b) of `guided`, learned per spatial leaf: where light sampling is already
//! near-perfect (an unoccluded light) the guide and the BRDF parts only waste samples, and where shadow rays are
//! almost all blocked the light part does. Müller et al. 2019 ("Practical Path Guiding in Production", §10)
//! learn the BSDF-sampling fraction by gradient descent on the KL divergence; here, simpler and exactly
//! reproducible, each of a fixed set of candidates is scored by the second moment of the one-sample estimator it
//! would give, estimated from the iteration's own samples (drawn with the old weights and guide, density p_old):
//!
//! `E_c[X²] = ∫ g² / p_c dω = E_old[ g² / (p_c p_old) ]`,  `p_c = c_g p_guide + c_l p_light + c_b p_brdf`,
//!
//! with g = luminance(f_r L_i (ω·n)) and X = g / p_c; p_guide is the density of the guide built from these same
//! samples (the identity holds for any p_c), so the weights fit the guide they are sampled with. The next
//! iteration takes the candidate of least second moment (so of least variance, the mean being the same for
//! all). Every candidate has c_l + c_b > 0, so the estimator stays unbiased whichever is chosen. Samples that
//! found light are scored (about 2048 a leaf, in fixed point, so in any order); with fewer than 64 of them a leaf
//! keeps [`DEFAULT_WEIGHTS`].

/// The weights of the example, before anything is learned: guide, light, BRDF.
pub const DEFAULT_WEIGHTS: [f32; 3] = [0.5, 0.25, 0.25];

/// The guide's shares tried, and the light part's share of the rest.
const GUIDE_SHARES: [f32; 5] = [0.0, 0.25, 0.5, 0.75, 0.9];
const LIGHT_SHARES: [f32; 5] = [1.0, 0.75, 0.5, 0.25, 0.0];

/// How many candidates are scored.
pub const CANDIDATES: usize = GUIDE_SHARES.len() * LIGHT_SHARES.len();

/// Candidate i: (c_g, c_l, c_b).
pub const fn candidate(i: usize) -> [f32; 3] {
    let (g, l) = (GUIDE_SHARES[i / LIGHT_SHARES.len()], LIGHT_SHARES[i % LIGHT_SHARES.len()]);
    [g, (1.0 - g) * l, (1.0 - g) * (1.0 - l)]
}

/// Every candidate's weights, in f64 (what a sample's score is computed in).
const WEIGHTS: [[f64; 3]; CANDIDATES] = {
    let mut table = [[0.0; 3]; CANDIDATES];
    let mut i = 0;
    while i < CANDIDATES {
        let c = candidate(i);
        table[i] = [c[0] as f64, c[1] as f64, c[2] as f64];
        i += 1;
    }
    table
};

/// Records that found light a leaf needs before its weights are learned.
const MIN_LIT_RECORDS: u32 = 64;

/// Fixed-point fraction bits of the second-moment sums (as the quadtree's sums: order-independent).
const FRACTION_BITS: i32 = 32;

/// The largest term a sample adds (2⁶⁰): with 32 fraction bits a sum of 2³⁶ such terms still fits in a u128.
const MAX_TERM: f64 = (1u64 << 60) as f64;

/// A finite `term` ≥ 0 in fixed point with [`FRACTION_BITS`] fraction bits (truncated, at most [`MAX_TERM`]).
/// Whole and fraction are converted apart, each through u64 (one instruction; f64 → u128 is a library call):
/// every sample scores 25 candidates.
#[inline]
fn fixed_point(term: f64) -> u128 {
    let t = term.clamp(0.0, MAX_TERM);
    let whole = t.trunc();
    ((whole as u64 as u128) << FRACTION_BITS) + ((t - whole) * (FRACTION_BITS as f64).exp2()) as u64 as u128
}

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
    /// Candidates that could not have drawn a direction that carried light (an infinite score).
    unbounded: [bool; CANDIDATES],
    lit: u32,
}

impl Default for Moments {
    fn default() -> Self {
        Self { sums: [0; CANDIDATES], unbounded: [false; CANDIDATES], lit: 0 }
    }
}

impl Moments {
    /// Adds one sample: `g² / (p_c p_old) = contribution² p_old / p_c` to each candidate's sum (an infinite
    /// score where the candidate could not have drawn a direction that carries light, p_c = 0). Fewer than 2³⁶
    /// samples a leaf never overflow the sums.
    pub fn record(&mut self, s: &MixtureSample) {
        if !(s.contribution > 0.0 && s.pdf > 0.0) {
            return;
        }
        self.lit += 1;
        let numerator = s.contribution as f64 * s.contribution as f64 * s.pdf as f64;
        let parts = s.parts.map(f64::from);
        let mut terms = [0.0f64; CANDIDATES];
        for (term, c) in terms.iter_mut().zip(&WEIGHTS) {
            *term = numerator / (c[0] * parts[0] + c[1] * parts[1] + c[2] * parts[2]);
        }
        for ((sum, unbounded), term) in self.sums.iter_mut().zip(&mut self.unbounded).zip(terms) {
            if term.is_finite() {
                *sum = sum.wrapping_add(fixed_point(term));
            } else {
                *unbounded = true;
            }
        }
    }

    /// The candidate of least second moment, or the default with too few samples that found light.
    pub fn best(&self) -> [f32; 3] {
        if self.lit < MIN_LIT_RECORDS {
            return DEFAULT_WEIGHTS;
        }
        let scores = self.sums.iter().zip(&self.unbounded).map(|(&s, &u)| if u { u128::MAX } else { s });
        let (i, _) = scores.enumerate().min_by_key(|&(_, s)| s).unwrap_or((0, 0));
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

    #[test]
    fn terms_are_fixed_point_with_32_fraction_bits() {
        assert_eq!(fixed_point(1.5), 3 << 31);
        assert_eq!(fixed_point(0.0), 0);
        assert_eq!(fixed_point(1e30), (MAX_TERM as u128) << 32);
    }

    /// Samples drawn where no guide existed (its density 0 in each) leave the guide's share at 0; a candidate
    /// that could not have drawn one of them (light sampling alone, for a direction only the BRDF reaches) never
    /// wins, however small its sum.
    #[test]
    fn without_a_guide_only_light_and_brdf_shares_win() {
        let mut m = Moments::default();
        for k in 0..100 {
            let parts = if k == 0 { [0.0, 0.0, 0.5] } else { [0.0, 2.0 + (k % 3) as f32, 0.5] };
            let pdf = 0.5 * parts[1] + 0.5 * parts[2];
            m.record(&MixtureSample { contribution: 1.0 / pdf, pdf, parts });
        }
        let best = m.best();
        assert!(best[0] == 0.0 && best[2] > 0.0 && best[1] >= 0.5, "{best:?}");
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
