//! A discrete distribution over indices, proportional to non-negative weights: the p_Δ of emitter selection.

/// Walker's alias method in Vose's construction ("A Linear Algorithm for Generating Random Numbers with a Given
/// Distribution", 1991): every index owns a bucket of width 1/n; bucket i returns i with probability q_i and its
/// alias a_i otherwise, so that `Pr(i) = (q_i + Σ_{j: a_j = i} (1 − q_j)) / n = pmf(i)`. Sampling costs O(1)
/// whatever the number of emitter triangles. Entries of weight zero are never sampled.
#[derive(Clone, Debug, Default)]
pub struct DiscreteDistribution {
    /// Per bucket: q_i, and the alias a_i.
    buckets: Vec<(f64, u32)>,
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
        let n = weights.len();
        // Each bucket's share of its own index, in units of 1/n: below 1 it needs an alias to fill up.
        let mut share: Vec<f64> = weights.iter().map(|&w| clean(w) / total * n as f64).collect();
        let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| share[i] < 1.0);
        let mut buckets = vec![(1.0, 0u32); n];
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            buckets[s] = (share[s], l as u32);
            share[l] -= 1.0 - share[s];
            if share[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // What rounding leaves over is (to rounding) full; a bucket of weight zero still points elsewhere.
        let heaviest = (0..n).max_by(|&a, &b| clean(weights[a]).total_cmp(&clean(weights[b])))? as u32;
        for i in small.into_iter().chain(large) {
            buckets[i] = if clean(weights[i]) > 0.0 { (1.0, 0) } else { (0.0, heaviest) };
        }
        let pmf = weights.iter().map(|&w| (clean(w) / total) as f32).collect();
        Some(Self { buckets, pmf })
    }

    /// Picks index i with probability `pmf(i)`; returns it and its probability. The bucket and the choice in it
    /// come from `u·n` in f64, which is exact for u with 24 bits.
    #[inline]
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let i = self.sample_index(u);
        (i, self.pmf[i])
    }

    /// [`DiscreteDistribution::sample`] without the probability.
    #[inline]
    pub fn sample_index(&self, u: f32) -> usize {
        let x = u as f64 * self.buckets.len() as f64;
        let bucket = (x as usize).min(self.buckets.len() - 1);
        let (q, alias) = self.buckets[bucket];
        // Which of the two a bucket gives is a coin flip for the branch predictor: select without a branch.
        std::hint::select_unpredictable(x - (bucket as f64) < q, bucket, alias as usize)
    }

    /// [`DiscreteDistribution::sample_index`] for eight uniforms in [0, 1), the same index for each: the
    /// products, buckets and offsets in them run lane by lane in loops the compiler vectorises; only the table
    /// reads are one per lane. The buckets fit in i32 (a scene has fewer than 2³¹ emitter triangles).
    #[inline(always)]
    pub fn sample_indices(&self, u: [f32; 8]) -> [usize; 8] {
        let n = self.buckets.len();
        let x = u.map(|u| u as f64 * n as f64);
        let bucket = x.map(|x| (x as i32).min(n as i32 - 1));
        std::array::from_fn(|l| {
            let b = bucket[l] as usize;
            let (q, alias) = self.buckets[b];
            std::hint::select_unpredictable(x[l] - (bucket[l] as f64) < q, b, alias as usize)
        })
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
        assert!(matches!(d.sample(0.999_999_94).0, 1 | 3));
        assert!((d.pmf(3) - 0.75).abs() < 1e-7);
    }

    /// Over every u = k/2²⁴ (all the values `SampleRng::uniform` gives), each index is picked with its pmf up to
    /// 2⁻²³ per bucket (where a bucket starts, and where its own index gives way to the alias, fall on that grid):
    /// the table reproduces the weights, not just in expectation.
    #[test]
    fn every_uniform_picks_indices_in_proportion_to_their_weights() {
        let weights: Vec<f64> = (0..37).map(|i| if i % 5 == 0 { 0.0 } else { (i as f64 * 0.37).exp() % 7.0 }).collect();
        let d = DiscreteDistribution::new(&weights).unwrap();
        let mut counts = vec![0u64; weights.len()];
        let steps = 1u32 << 24;
        for k in 0..steps {
            let (i, p) = d.sample(k as f32 / steps as f32);
            assert_eq!(p, d.pmf(i));
            counts[i] += 1;
        }
        for (i, &c) in counts.iter().enumerate() {
            let share = c as f64 / steps as f64;
            let tolerance = 2f64.powi(-23) * weights.len() as f64;
            assert!((share - d.pmf(i) as f64).abs() <= tolerance, "index {i}: {share} vs {}", d.pmf(i));
            assert_eq!(c == 0, weights[i] == 0.0, "index {i}");
        }
    }

    /// Eight at a time picks what one at a time picks, for every u = k/2²⁴ (and for tables of 1 to 3 entries).
    #[test]
    fn eight_at_a_time_pick_the_same() {
        for weights in [vec![2.0], vec![1.0, 0.0, 3.0], (0..37).map(|i| ((i * 7) % 11) as f64).collect()] {
            let d = DiscreteDistribution::new(&weights).unwrap();
            for k in (0..1u32 << 24).step_by(8 * 3) {
                let u: [f32; 8] = std::array::from_fn(|l| (k + 3 * l as u32) as f32 / (1u32 << 24) as f32);
                assert_eq!(d.sample_indices(u), u.map(|u| d.sample_index(u)), "{weights:?} at {u:?}");
            }
        }
    }

    #[test]
    fn no_positive_weight_is_none() {
        assert!(DiscreteDistribution::new(&[0.0, f64::NAN, -1.0]).is_none());
        assert!(DiscreteDistribution::new(&[]).is_none());
    }
}
