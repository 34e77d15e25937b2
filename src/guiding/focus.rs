//! Where a leaf's light rays converge: the focus of parallax-aware guiding (after Rath et al. 2023, "Focal Path
//! Guiding for Light Transport Simulation", whose focal points are where paths through an opening meet; here one
//! focus per spatial leaf, chosen in closed form).
//!
//! A record that found light is a ray from its shading point x to the light point y. Its leaf's quadtree learns
//! the point z = x + f (y − x) at the fraction f of the way (as the anchor c sees it, see [`super::Anchor`]), and a
//! point p of the leaf aims at the learned z's. What p wastes is what the z's of the leaf's other points spread
//! over beyond what p itself sees: the spread Var(z) against the spread f² Var(y | x) each point's own rays
//! make. With g = (1 − f)/f,
//!
//! `Var(z) / f² = Var(g x + y) = g² tr Var(x) + 2 g tr Cov(x, y) + tr Var(y)`,
//!
//! and `E[Var(y | x)]` does not depend on g, so the best focus minimises this quadratic:
//!
//! `g* = −tr Cov(x, y) / tr Var(x)`,   `f = 1 / (1 + max(g*, 0))`,
//!
//! all moments weighted by the records' values. Light seen in the open (y independent of x) gives g* = 0: the
//! focus is the light itself, f = 1. Light through an opening at the fraction h of the way gives
//! y = a/h − x (1 − h)/h for the opening point a, so Cov(x, y) = −(1 − h)/h Var(x) and f = h: the opening itself,
//! which every point of the leaf sees the light through.

use glam::{DVec3, Vec3};

/// The focus at least this far along a ray (a nearer one would put the learned points beside the leaf).
const MIN_FOCUS: f32 = 0.125;

/// Lit records a leaf needs before its focus moves from the light.
const MIN_RECORDS: u32 = 64;

/// Fraction bits of the moments' fixed point.
const FRACTION_BITS: i32 = 32;

/// The largest term a record adds (2³⁰): a larger one saturates, which can only move the focus.
const MAX_TERM: f64 = (1u64 << 30) as f64;

/// A term in fixed point (one conversion to i64; order-independent sums).
#[inline]
fn fixed_point(t: f64) -> i64 {
    (t.clamp(-MAX_TERM, MAX_TERM) * (FRACTION_BITS as f64).exp2()) as i64
}

/// Value-weighted moments of one leaf's lit records, x and y relative to its anchor, in fixed point: Σ w, Σ w x,
/// Σ w y, Σ w |x|², Σ w x·y.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FocusMoments {
    sums: [i128; 9],
    records: u32,
}

impl FocusMoments {
    /// Adds the ray from `x` to `y` (relative to the leaf's anchor) with weight `w` > 0 (others are ignored).
    pub fn record(&mut self, x: Vec3, y: Vec3, w: f32) {
        if !(w > 0.0 && w.is_finite() && x.is_finite() && y.is_finite()) {
            return;
        }
        let (x, y, w) = (x.as_dvec3(), y.as_dvec3(), w as f64);
        let terms = [w, w * x.x, w * x.y, w * x.z, w * y.x, w * y.y, w * y.z, w * x.dot(x), w * x.dot(y)];
        for (sum, t) in self.sums.iter_mut().zip(terms) {
            *sum = sum.wrapping_add(fixed_point(t) as i128);
        }
        self.records += 1;
    }

    /// The focus fraction f ∈ [[`MIN_FOCUS`], 1]: 1 (the light) with too few records or no spread of x.
    pub fn fraction(&self) -> f32 {
        if self.records < MIN_RECORDS || self.sums[0] <= 0 {
            return 1.0;
        }
        let s = self.sums.map(|v| v as f64);
        let w = s[0];
        let (mx, my) = (DVec3::new(s[1], s[2], s[3]) / w, DVec3::new(s[4], s[5], s[6]) / w);
        let var_x = s[7] / w - mx.dot(mx);
        let cov = s[8] / w - mx.dot(my);
        if !(var_x > 0.0) {
            return 1.0;
        }
        let g = (-cov / var_x).max(0.0);
        ((1.0 / (1.0 + g)) as f32).clamp(MIN_FOCUS, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rays from points spread over a floor through a small opening at height h of the way to a light plane: the
    /// focus is the opening; rays from the same points to a light seen in the open: the light.
    #[test]
    fn the_focus_is_the_opening_rays_pass_through() {
        let mut through = FocusMoments::default();
        let mut open = FocusMoments::default();
        let hole = Vec3::new(0.1, 1.0, -0.2);
        let mut state = 7u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..1000 {
            let x = Vec3::new(next() - 0.5, 0.0, next() - 0.5) * 0.6;
            let a = hole + Vec3::new(next() - 0.5, 0.0, next() - 0.5) * 0.2;
            // The light plane at y = 2.5: the ray through a reaches it at 2.5 times its way to the opening.
            through.record(x, x + (a - x) * 2.5, 1.0 + next());
            let on_light = Vec3::new(next() * 2.0 - 1.0, 2.5, next() * 2.0 - 1.0);
            open.record(x, on_light, 1.0 + next());
        }
        let f = through.fraction();
        assert!((f - 0.4).abs() < 0.02, "the opening is at 0.4 of the way: {f}");
        assert!(open.fraction() > 0.9, "{}", open.fraction());
        assert_eq!(FocusMoments::default().fraction(), 1.0);
    }

    /// The sums do not depend on the records' order.
    #[test]
    fn moments_are_order_independent() {
        let rays: Vec<(Vec3, Vec3, f32)> = (0..100)
            .map(|i| {
                let t = i as f32 * 0.37;
                (Vec3::new(t.sin(), 0.0, t.cos()) * 0.3, Vec3::new(t.cos(), 2.0, -t.sin()), 0.1 + (t * 3.0).sin().abs())
            })
            .collect();
        let (mut a, mut b) = (FocusMoments::default(), FocusMoments::default());
        rays.iter().for_each(|&(x, y, w)| a.record(x, y, w));
        rays.iter().rev().for_each(|&(x, y, w)| b.record(x, y, w));
        assert_eq!(a, b);
    }
}
