//! A discrete distribution over indices, proportional to non-negative weights: the p_Δ of emitter selection.

/// Piecewise-constant CDF with binary-search sampling. Entries of weight zero are never sampled.
#[derive(Clone, Debug, Default)]
pub struct DiscreteDistribution {
    cdf: Vec<f64>,
    pmf: Vec<f32>,
}

impl DiscreteDistribution {
    /// `None` when no weight is positive and finite (nothing can be sampled).
    pub fn new(weights: &[f64]) -> Option<Self> {
        let clean = |w: f64| if w.is_finite() && w > 0.0 { w } else { 0.0 };
        let total: f64 = weights.iter().map(|&w| clean(w)).sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let mut cdf = Vec::with_capacity(weights.len() + 1);
        let mut acc = 0.0;
        cdf.push(0.0);
        for &w in weights {
            acc += clean(w);
            cdf.push(acc / total);
        }
        *cdf.last_mut()? = 1.0;
        let pmf = weights.iter().map(|&w| (clean(w) / total) as f32).collect();
        Some(Self { cdf, pmf })
    }

    /// Picks index i with probability `pmf(i)`; returns it and its probability.
    #[inline]
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let u = u as f64;
        // The number of CDF entries after the leading 0 that are ≤ u; a branch-free count for a few entries.
        let below = if self.cdf.len() <= 17 {
            self.cdf[1..].iter().filter(|&&c| c <= u).count()
        } else {
            self.cdf.partition_point(|&c| c <= u) - 1
        };
        let i = below.min(self.pmf.len() - 1);
        (i, self.pmf[i])
    }

    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf[i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_weights_are_never_picked() {
        let d = DiscreteDistribution::new(&[0.0, 1.0, 0.0, 3.0, 0.0]).unwrap();
        for k in 0..1000 {
            let (i, p) = d.sample(k as f32 / 1000.0);
            assert!(i == 1 || i == 3);
            assert!(p > 0.0);
        }
        assert_eq!(d.sample(0.0).0, 1);
        assert_eq!(d.sample(0.999_999_94).0, 3);
        assert!((d.pmf(3) - 0.75).abs() < 1e-7);
    }

    #[test]
    fn no_positive_weight_is_none() {
        assert!(DiscreteDistribution::new(&[0.0, f64::NAN, -1.0]).is_none());
        assert!(DiscreteDistribution::new(&[]).is_none());
    }
}
