//! A discrete distribution over indices, proportional to non-negative weights: the p_Δ of emitter selection.

use wide::{CmpGe, f32x8, i32x8};

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

    /// [`DiscreteDistribution::sample_index`] as a step function of u ∈ [0, 1), for tables of at most
    /// [`IndexSteps::MOST_BUCKETS`] buckets (`None` for larger ones).
    pub fn steps(&self) -> Option<IndexSteps> {
        (self.buckets.len() <= IndexSteps::MOST_BUCKETS).then(|| IndexSteps::of(self))
    }
}

/// The alias table's index as a step function of u: on [0, 1) it is `first` below the first bound and changes
/// by `delta` at each bound u_k (the index is `first + Σ_{k: u ≥ u_k} delta_k`). Bucket b covers the u with
/// `⌊u n⌋ = b` (the last one up to 1) and gives b below `(b + q_b)/n`, a_b above: as the table's own test does in
/// f64, where `u n` and `u n − b` are exact for every f32 u (24 bits times a small n; Sterbenz), so that each
/// bound is the smallest f32 at which the test changes, found by bisection over the floats' bits and checked
/// against the table for every u = k/2²⁴. Eight picks cost a compare, an and and an add per bound, with no
/// table read: what a scene of a few emitter triangles spends on light selection.
#[derive(Clone, Debug, PartialEq)]
pub struct IndexSteps {
    first: i32,
    /// (u_k, delta_k), u_k increasing.
    steps: Vec<(f32, i32)>,
}

impl IndexSteps {
    /// The largest table kept as steps: 2n − 1 bounds at most.
    pub const MOST_BUCKETS: usize = 8;

    fn of(d: &DiscreteDistribution) -> Self {
        let n = d.buckets.len();
        // The smallest f32 in [lo, 1) at which the monotone predicate `after` holds (1 where none does).
        let least = |lo: f32, after: &dyn Fn(f32) -> bool| {
            let (mut a, mut b) = (lo.to_bits(), 1f32.to_bits());
            while a < b {
                let mid = a + (b - a) / 2;
                if after(f32::from_bits(mid)) { b = mid } else { a = mid + 1 }
            }
            f32::from_bits(a)
        };
        let bucket = |u: f32| ((u as f64 * n as f64) as usize).min(n - 1);
        let mut pieces = Vec::new();
        let mut start = 0.0;
        for b in 0..n {
            let end = if b + 1 < n { least(start, &|u| bucket(u) > b) } else { 1.0 };
            let alias_from = least(start, &|u| u >= end || d.sample_index(u) != b);
            pieces.push((start, b as i32));
            pieces.push((alias_from, d.buckets[b].1 as i32));
            start = end;
        }
        // Each piece runs to the next one's start: the empty ones and those that repeat an index add no step.
        let ends = pieces.iter().skip(1).map(|p| p.0).chain([1.0]);
        let mut kept = pieces.iter().zip(ends).filter(|(p, end)| p.0 < *end).map(|(p, _)| *p);
        let (_, first) = kept.next().expect("the pieces cover [0, 1)");
        let (mut steps, mut index) = (Vec::new(), first);
        for (from, i) in kept {
            if i != index {
                steps.push((from, i - index));
                index = i;
            }
        }
        Self { first, steps }
    }

    /// The index for each of eight uniforms in [0, 1): what [`DiscreteDistribution::sample_index`] gives.
    #[inline(always)]
    pub fn indices(&self, u: f32x8) -> i32x8 {
        self.steps.iter().fold(i32x8::splat(self.first), |index, &(bound, delta)| {
            let past: i32x8 = bytemuck::cast(u.cmp_ge(f32x8::splat(bound)));
            index + (past & i32x8::splat(delta))
        })
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

    /// The steps give the table's index for every u = k/2²⁴ (all the values `SampleRng::uniform` gives) and for
    /// 10⁶ other floats in [0, 1), on tables of one to eight buckets: equal weights (no alias taken), zeros
    /// (a bucket that is all alias), weights of very different sizes and weights whose shares are not
    /// multiples of 1/n.
    #[test]
    fn steps_give_the_tables_index() {
        let tables: [Vec<f64>; 6] = [
            vec![2.0],
            vec![1.0, 1.0],
            vec![1.0, 0.0, 3.0],
            vec![0.1, 1e-9, 5.0, 0.3],
            (0..7).map(|i| ((i * 7) % 11) as f64 + 0.3).collect(),
            (0..8).map(|i| (i as f64 * 0.37).exp() % 7.0).collect(),
        ];
        for weights in tables {
            let d = DiscreteDistribution::new(&weights).unwrap();
            let steps = d.steps().expect("a small table");
            assert!(steps.steps.len() < 2 * weights.len(), "{weights:?}: {} steps", steps.steps.len());
            let check = |u: [f32; 8]| {
                let got: [i32; 8] = steps.indices(f32x8::new(u)).to_array();
                assert_eq!(got, u.map(|u| d.sample_index(u) as i32), "{weights:?} at {u:?}");
            };
            for k in (0..1u32 << 24).step_by(8) {
                check(std::array::from_fn(|l| (k + l as u32) as f32 / (1u32 << 24) as f32));
            }
            let mut bits = 0x9e37_79b9u32;
            for _ in 0..125_000 {
                check(std::array::from_fn(|_| {
                    bits = bits.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
                    f32::from_bits(bits % 1f32.to_bits())
                }));
            }
        }
        let big = DiscreteDistribution::new(&[1.0; IndexSteps::MOST_BUCKETS + 1]).unwrap();
        assert!(big.steps().is_none());
    }

    #[test]
    fn no_positive_weight_is_none() {
        assert!(DiscreteDistribution::new(&[0.0, f64::NAN, -1.0]).is_none());
        assert!(DiscreteDistribution::new(&[]).is_none());
    }
}
