//! Means over independent runs with 95% confidence intervals, and when two of them differ.
//!
//! For n runs with values X₁…X_n (the MSE of n seeds, say) the mean `X̄` has the interval
//! `X̄ ± t₀.₉₇₅,ₙ₋₁ s/√n`, s the sample standard deviation and t Student's quantile (the values are nearly
//! normal for MSEs averaged over many pixels). A ratio of two means `A/B` has, by the delta method on
//! `ln A − ln B`, the interval `A/B · exp(± t √(s_A²/(n_A A²) + s_B²/(n_B B²)))`, with the smaller of the two
//! sample sizes' degrees of freedom. Two strategies differ significantly when the ratio's interval excludes 1.

/// Student's t quantile at 0.975 for `df` degrees of freedom (1.96 in the limit).
pub fn student_t_975(df: usize) -> f64 {
    const T: [f64; 30] = [
        12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160, 2.145, 2.131,
        2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042,
    ];
    match df {
        0 => f64::INFINITY,
        1..=30 => T[df - 1],
        31..=60 => 2.000,
        61..=120 => 1.980,
        _ => 1.960,
    }
}

/// The mean of independent values and its 95% interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeanInterval {
    pub mean: f64,
    /// `s/√n` (0 for one value).
    pub std_error: f64,
    pub n: usize,
}

impl MeanInterval {
    pub fn of(values: &[f64]) -> Self {
        let n = values.len();
        let mean = values.iter().sum::<f64>() / n.max(1) as f64;
        let var = if n > 1 { values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64 } else { 0.0 };
        Self { mean, std_error: (var / n.max(1) as f64).sqrt(), n }
    }

    /// The same values times `c` (e.g. an MSE times its spp).
    pub fn scaled(self, c: f64) -> Self {
        Self { mean: self.mean * c, std_error: self.std_error * c.abs(), n: self.n }
    }

    pub fn half_width(&self) -> f64 {
        if self.n < 2 { f64::INFINITY } else { student_t_975(self.n - 1) * self.std_error }
    }

    pub fn lo(&self) -> f64 {
        self.mean - self.half_width()
    }

    pub fn hi(&self) -> f64 {
        self.mean + self.half_width()
    }
}

/// A ratio `A/B` of two positive means and its 95% interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ratio {
    pub ratio: f64,
    pub lo: f64,
    pub hi: f64,
}

impl Ratio {
    /// The 95% interval; `None` unless both means are positive and both have at least two values.
    pub fn of(a: &MeanInterval, b: &MeanInterval) -> Option<Self> {
        Self::with_quantile(a, b, student_t_975(a.n.min(b.n).max(2) - 1))
    }

    /// The interval `ratio · exp(± t · spread)` for a quantile `t` of one's choosing (tests that want a smaller
    /// false-failure rate than 5% widen it).
    pub fn with_quantile(a: &MeanInterval, b: &MeanInterval, t: f64) -> Option<Self> {
        if !(a.mean > 0.0 && b.mean > 0.0 && a.n > 1 && b.n > 1) {
            return None;
        }
        let spread = ((a.std_error / a.mean).powi(2) + (b.std_error / b.mean).powi(2)).sqrt();
        let ratio = a.mean / b.mean;
        Some(Self { ratio, lo: ratio * (-t * spread).exp(), hi: ratio * (t * spread).exp() })
    }

    /// Whether the interval excludes 1.
    pub fn significant(&self) -> bool {
        self.lo > 1.0 || self.hi < 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::SampleRng;

    #[test]
    fn mean_and_interval_by_hand() {
        let m = MeanInterval::of(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(m.mean, 2.5);
        let s = (5.0f64 / 3.0).sqrt();
        assert!((m.std_error - s / 2.0).abs() < 1e-12);
        assert!((m.half_width() - 3.182 * s / 2.0).abs() < 1e-12);
        assert_eq!(MeanInterval::of(&[7.0]).half_width(), f64::INFINITY, "one value: no interval");
    }

    /// 2000 trials of 8 normal values (Box–Muller) with mean 1: the interval covers 1 in 95% ± 1.5% of them, and
    /// the ratio of two such means covers 1 at least as often (delta method). Fixed seed.
    #[test]
    fn intervals_cover_at_their_stated_rate() {
        let mut rng = SampleRng::new(9, 0, 0);
        let mut normal = || {
            let (u, v) = (rng.uniform().max(1e-7) as f64, rng.uniform() as f64);
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        };
        let (mut covered, mut ratio_covered) = (0, 0);
        let trials = 2000;
        for _ in 0..trials {
            let a: Vec<f64> = (0..8).map(|_| 1.0 + 0.1 * normal()).collect();
            let b: Vec<f64> = (0..8).map(|_| 1.0 + 0.1 * normal()).collect();
            let (ma, mb) = (MeanInterval::of(&a), MeanInterval::of(&b));
            covered += (ma.lo() <= 1.0 && 1.0 <= ma.hi()) as u32;
            ratio_covered += !Ratio::of(&ma, &mb).expect("positive").significant() as u32;
        }
        let rate = covered as f64 / trials as f64;
        let ratio_rate = ratio_covered as f64 / trials as f64;
        assert!((rate - 0.95).abs() < 0.015, "{rate}");
        // The ratio's interval takes the smaller sample's degrees of freedom (7, where Welch's would give about
        // 14): conservative, so it covers a little more often than 95%.
        assert!((0.94..0.985).contains(&ratio_rate), "{ratio_rate}");
    }
}
