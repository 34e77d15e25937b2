//! Convergence series: the error of one estimator against the reference as its budget grows, in samples per
//! pixel and in seconds. For an unbiased estimator `MSE = σ²/N`, so on log–log axes RMSE falls with slope −½
//! against spp and against time; estimators differ by the height of that line, which is what efficiency
//! `1/(MSE · seconds)` measures.

use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ConvergencePoint {
    pub spp: u32,
    pub seconds: f64,
    pub mse: f64,
    pub rel_mse: f64,
}

impl ConvergencePoint {
    pub fn rmse(&self) -> f64 {
        self.mse.sqrt()
    }

    /// `1/(MSE · seconds)`, `None` when not finite or not positive (an MSE with the reference's noise
    /// subtracted can come out at or below 0).
    pub fn efficiency(&self) -> Option<f64> {
        let e = 1.0 / (self.mse * self.seconds);
        (e.is_finite() && e > 0.0).then_some(e)
    }

    /// `1/(relMSE · seconds)`: the same with every pixel's error relative to its brightness, so that dark regions
    /// count as much as visible lights.
    pub fn rel_efficiency(&self) -> Option<f64> {
        let e = 1.0 / (self.rel_mse * self.seconds);
        (e.is_finite() && e > 0.0).then_some(e)
    }
}

/// One estimator's run.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub label: String,
    pub points: Vec<ConvergencePoint>,
}

impl Series {
    pub fn new(label: impl Into<String>) -> Self {
        Self { label: label.into(), points: Vec::new() }
    }

    /// Adds a point with more samples than the last. The newest point is always kept; beyond 8 spp it replaces
    /// the previous one when that lies within a factor 1.2 in spp of the one before, so a long run keeps a few
    /// dozen points spread evenly on the log axis.
    pub fn push(&mut self, point: ConvergencePoint) {
        let n = self.points.len();
        if n > 0 && point.spp <= self.points[n - 1].spp {
            return;
        }
        let provisional = n >= 2
            && self.points[n - 1].spp > 8
            && (self.points[n - 1].spp as f64) < self.points[n - 2].spp as f64 * 1.2;
        if provisional {
            self.points[n - 1] = point;
        } else {
            self.points.push(point);
        }
    }

    pub fn last(&self) -> Option<&ConvergencePoint> {
        self.points.last()
    }

    /// Efficiency at the largest budget.
    pub fn efficiency(&self) -> Option<f64> {
        self.last().and_then(ConvergencePoint::efficiency)
    }

    /// The least-squares slope of ln RMSE against ln spp (−½ for an unbiased estimator once the reference's
    /// noise is negligible). `None` with fewer than two points.
    pub fn slope(&self) -> Option<f64> {
        let pts: Vec<(f64, f64)> = self
            .points
            .iter()
            .filter(|p| p.mse > 0.0 && p.spp > 0)
            .map(|p| ((p.spp as f64).ln(), p.rmse().ln()))
            .collect();
        if pts.len() < 2 {
            return None;
        }
        let n = pts.len() as f64;
        let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / n, pts.iter().map(|p| p.1).sum::<f64>() / n);
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        (sxx > 0.0).then(|| sxy / sxx)
    }
}

/// Which error an efficiency divides by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Metric {
    Mse,
    RelMse,
}

impl Metric {
    pub fn name(self) -> &'static str {
        match self {
            Metric::Mse => "MSE",
            Metric::RelMse => "relMSE",
        }
    }

    pub fn efficiency(self, p: &ConvergencePoint) -> Option<f64> {
        match self {
            Metric::Mse => p.efficiency(),
            Metric::RelMse => p.rel_efficiency(),
        }
    }
}

/// The index of the series with the highest efficiency at its largest budget.
pub fn most_efficient(series: &[Series], metric: Metric) -> Option<usize> {
    series
        .iter()
        .enumerate()
        .filter_map(|(i, s)| s.last().and_then(|p| metric.efficiency(p)).map(|e| (i, e)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(spp: u32, seconds: f64, mse: f64) -> ConvergencePoint {
        ConvergencePoint { spp, seconds, mse, rel_mse: mse }
    }

    #[test]
    fn slope_of_an_ideal_estimator_is_minus_one_half() {
        let mut s = Series::new("ideal");
        for spp in [1, 4, 16, 64, 256] {
            s.push(point(spp, spp as f64 * 0.01, 2.0 / spp as f64));
        }
        assert!((s.slope().expect("points") + 0.5).abs() < 1e-12);
        assert!((s.efficiency().expect("finite") - 1.0 / (2.0 / 256.0 * 2.56)).abs() < 1e-9);
    }

    #[test]
    fn push_keeps_points_log_spaced_and_increasing() {
        let mut s = Series::new("run");
        for spp in 1..=100 {
            s.push(point(spp, spp as f64, 1.0 / spp as f64));
        }
        s.push(point(50, 1.0, 1.0));
        let spp: Vec<u32> = s.points.iter().map(|p| p.spp).collect();
        assert!(spp.windows(2).all(|w| w[1] > w[0]));
        assert!(spp.starts_with(&[1, 2, 3, 4, 5, 6, 7, 8, 10]), "{spp:?}");
        assert_eq!(spp.last(), Some(&100), "the newest point is kept");
        assert!(spp.len() < 25, "{spp:?}");
    }

    #[test]
    fn the_most_efficient_series_wins() {
        let mut a = Series::new("a");
        a.push(point(16, 1.0, 0.1));
        let mut b = Series::new("b");
        b.push(point(16, 2.0, 0.02));
        let empty = Series::new("c");
        assert_eq!(most_efficient(&[a, b, empty], Metric::Mse), Some(1));
        assert_eq!(most_efficient(&[], Metric::RelMse), None);
    }
}
