//! False colour for per-pixel error maps, with the scale a legend needs. Errors span decades, so the scale is
//! logarithmic; its range is taken over every map shown together (both sides of a comparison), so equal colours
//! mean equal values. The colour map is matplotlib's perceptually uniform *inferno* (via `colorous`).

/// A logarithmic colour scale from `lo` (darkest) to `hi` (brightest); values outside are clamped, zero and
/// non-finite values are drawn black.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColorScale {
    pub lo: f32,
    pub hi: f32,
}

impl ColorScale {
    /// The range of the positive finite values of all `maps`, from the 1st to the 99.9th percentile, so that a
    /// few extreme pixels do not flatten the rest. `None` when no value is positive.
    pub fn fit<'a>(maps: impl IntoIterator<Item = &'a [f32]>) -> Option<Self> {
        let mut v: Vec<f32> = maps.into_iter().flatten().copied().filter(|x| x.is_finite() && *x > 0.0).collect();
        if v.is_empty() {
            return None;
        }
        // Two order statistics by selection, O(n): this runs on the UI thread for every new frame.
        let mut at = |q: f64| {
            let k = ((v.len() - 1) as f64 * q).round() as usize;
            *v.select_nth_unstable_by(k, f32::total_cmp).1
        };
        let (lo, hi) = (at(0.01), at(0.999));
        // At least a factor 10 so a flat map still reads.
        let hi = hi.max(lo * 10.0);
        Some(Self { lo, hi })
    }

    /// Position of `value` on the scale, in [0, 1].
    pub fn position(&self, value: f32) -> f32 {
        let t = (value.ln() - self.lo.ln()) / (self.hi.ln() - self.lo.ln());
        t.clamp(0.0, 1.0)
    }

    /// The colour of `value`, RGBA.
    pub fn color(&self, value: f32) -> [u8; 4] {
        if !(value.is_finite() && value > 0.0) {
            return [0, 0, 0, 255];
        }
        gradient(self.position(value))
    }

    /// Every value coloured, RGBA, in order.
    pub fn colorize(&self, values: &[f32]) -> Vec<u8> {
        values.iter().flat_map(|v| self.color(*v)).collect()
    }

    /// Legend ticks: the powers of ten inside the range (at least the two ends), as (position in [0, 1], value).
    pub fn ticks(&self) -> Vec<(f32, f32)> {
        let (a, b) = (self.lo.log10().ceil() as i32, self.hi.log10().floor() as i32);
        let mut ticks: Vec<(f32, f32)> = (a..=b).map(|e| 10f32.powi(e)).map(|v| (self.position(v), v)).collect();
        if ticks.len() < 2 {
            ticks = vec![(0.0, self.lo), (1.0, self.hi)];
        }
        ticks
    }
}

/// The colour map at `t` ∈ [0, 1], RGBA.
pub fn gradient(t: f32) -> [u8; 4] {
    let c = colorous::INFERNO.eval_continuous(t.clamp(0.0, 1.0) as f64);
    [c.r, c.g, c.b, 255]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_is_logarithmic_and_clamped() {
        let s = ColorScale { lo: 1e-3, hi: 1e1 };
        assert_eq!(s.position(1e-3), 0.0);
        assert!((s.position(1e-1) - 0.5).abs() < 1e-6);
        assert_eq!(s.position(1e3), 1.0);
        assert_eq!(s.color(0.0), [0, 0, 0, 255]);
        assert_eq!(s.color(f32::NAN), [0, 0, 0, 255]);
        assert!(s.color(1e1)[0] > s.color(1e-3)[0], "brighter at the top");
        let ticks: Vec<f32> = s.ticks().iter().map(|t| t.1).collect();
        assert_eq!(ticks, [1e-3, 1e-2, 1e-1, 1e0, 1e1]);
    }

    #[test]
    fn fit_spans_every_map_and_ignores_zeros() {
        let a: Vec<f32> = (1..=1000).map(|i| i as f32).collect();
        let b = vec![0.0, f32::INFINITY, 5000.0];
        let s = ColorScale::fit([a.as_slice(), b.as_slice()]).expect("positive values");
        assert!(s.lo >= 1.0 && s.lo <= 12.0, "{s:?}");
        assert!(s.hi >= 990.0, "{s:?}");
        assert!(ColorScale::fit([[0.0f32, -1.0].as_slice()]).is_none());
        let flat = ColorScale::fit([[2.0f32; 8].as_slice()]).expect("flat");
        assert_eq!((flat.lo, flat.hi), (2.0, 20.0));
    }
}
