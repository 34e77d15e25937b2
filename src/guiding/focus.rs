//! Where a leaf's light rays converge: the focus of parallax-aware guiding (after Rath et al. 2023, "Focal Path
//! Guiding for Light Transport Simulation", whose focal points are where paths through an opening meet; here one
//! focal plane per spatial leaf, chosen in closed form).
//!
//! A record that found light is a ray from its shading point x to the light point y. Its leaf's quadtree learns
//! the point where the ray crosses the leaf's focal plane (as the anchor c sees it, see [`super::Anchor`]), and a
//! point p of the leaf aims at the learned points. First the focus along the rays: what p wastes is what the
//! points z = x + f (y − x) of the leaf's other points spread over beyond what p itself sees: the spread Var(z)
//! against the spread f² Var(y | x) each point's own rays make. With g = (1 − f)/f,
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
//! which every point of the leaf sees the light through. A single fraction puts the focal points of rays that
//! leave from different heights at different heights, though, so the points are then fitted with a plane
//! ([`focal_plane`]), where the rays' crossing points stop depending on where they left from.

use glam::{DMat3, DVec3, Vec3};

/// The focus at least this far along a ray (a nearer one would put the learned points beside the leaf).
const MIN_FOCUS: f32 = 0.125;

/// Lit records a leaf needs before its focus moves from the light (and before it has a focal plane).
const MIN_RECORDS: u32 = 64;

/// Fraction bits of the moments' fixed point.
const FRACTION_BITS: i32 = 32;

/// The largest term a record adds (2³⁰): a larger one saturates, which can only move the focus.
const MAX_TERM: f64 = (1u64 << 30) as f64;

/// Rays that cross the focal plane at a cosine below this are left out of its height's fit (they would weigh
/// as 1/cos).
const MIN_CROSSING_COSINE: f64 = 0.1;

/// A term in fixed point (one conversion to i64; order-independent sums).
#[inline]
fn fixed_point(t: f64) -> i64 {
    (t.clamp(-MAX_TERM, MAX_TERM) * (FRACTION_BITS as f64).exp2()) as i64
}

/// N sums of terms in fixed point: the same whatever the order the terms come in.
#[derive(Clone, Debug, PartialEq)]
struct FixedSums<const N: usize>([i128; N]);

impl<const N: usize> Default for FixedSums<N> {
    fn default() -> Self {
        Self([0; N])
    }
}

impl<const N: usize> FixedSums<N> {
    #[inline]
    fn add(&mut self, terms: [f64; N]) {
        for (sum, t) in self.0.iter_mut().zip(terms) {
            *sum = sum.wrapping_add(fixed_point(t) as i128);
        }
    }

    /// The sums divided by the first (the weights'): means.
    fn means(&self) -> Option<[f64; N]> {
        let s = self.0.map(|v| v as f64);
        (s[0] > 0.0).then(|| s.map(|v| v / s[0]))
    }
}

/// Value-weighted moments of one leaf's lit records, x and y relative to its anchor, in fixed point: Σ w, Σ w x,
/// Σ w y, Σ w |x|², Σ w x·y.
#[derive(Clone, Debug, Default, PartialEq)]
struct FocusMoments {
    sums: FixedSums<9>,
    records: u32,
}

impl FocusMoments {
    /// Adds the ray from `x` to `y` (relative to the leaf's anchor, finite) with weight `w` > 0 (finite).
    fn record(&mut self, x: Vec3, y: Vec3, w: f32) {
        let (x, y, w) = (x.as_dvec3(), y.as_dvec3(), w as f64);
        self.sums.add([w, w * x.x, w * x.y, w * x.z, w * y.x, w * y.y, w * y.z, w * x.dot(x), w * x.dot(y)]);
        self.records += 1;
    }

    /// The focus fraction f ∈ [[`MIN_FOCUS`], 1]: 1 (the light) with too few records or no spread of x.
    fn fraction(&self) -> f32 {
        let Some(m) = self.sums.means().filter(|_| self.records >= MIN_RECORDS) else { return 1.0 };
        let (mx, my) = (DVec3::new(m[1], m[2], m[3]), DVec3::new(m[4], m[5], m[6]));
        let var_x = m[7] - mx.dot(mx);
        let cov = m[8] - mx.dot(my);
        if !(var_x > 0.0) {
            return 1.0;
        }
        let g = (-cov / var_x).max(0.0);
        ((1.0 / (1.0 + g)) as f32).clamp(MIN_FOCUS, 1.0)
    }
}

/// The plane a leaf's lit rays converge in, relative to its anchor (the origin): the points q with n·q = h.
///
/// Its normal n is the axis along which the rays' focal points z = x + f (y − x) (see [`FocusMoments`]) spread
/// least (the eigenvector of the least eigenvalue of their covariance), turned along the rays. Its height h is
/// where the point z(h) at which a ray crosses the plane stops depending on the point x the ray left from:
///
/// `z(h) = a + h u`,  `u = ω / (n·ω)`,  `a = x − (n·x) u`,   `h* = −⟨Cov(a, x), Cov(u, x)⟩ / ‖Cov(u, x)‖²`
///
/// (least squares over the cross-covariances' entries, ⟨·,·⟩ their Frobenius product). Light through an
/// opening: z(h) is the opening's point for any x at the opening's plane, so Cov(z(h), x) = 0 there; light seen
/// in the open: the same at the light. Where the rays are parallel (Cov(u, x) = 0), the plane passes through
/// the focal points' mean. h is kept between an eighth of the way and the light. `None` with fewer than
/// [`MIN_RECORDS`] rays, or where the plane would not lie ahead of the anchor.
pub fn focal_plane<I>(rays: I) -> Option<(Vec3, f32)>
where
    I: Iterator<Item = (Vec3, Vec3, f32)> + Clone,
{
    let rays = rays.filter(|&(x, y, w)| w > 0.0 && w.is_finite() && x.is_finite() && y.is_finite() && x != y);
    let mut focus = FocusMoments::default();
    rays.clone().for_each(|(x, y, w)| focus.record(x, y, w));
    if focus.records < MIN_RECORDS {
        return None;
    }
    let f = focus.fraction() as f64;
    let as_f64 = |(x, y, w): (Vec3, Vec3, f32)| (x.as_dvec3(), y.as_dvec3(), w as f64);
    // The focal points' moments (Σ w, Σ w z, Σ w z zᵀ's six entries), with the rays' mean direction and the
    // mean x and y.
    let mut points = FixedSums::<19>::default();
    for (x, y, w) in rays.clone().map(as_f64) {
        let (z, d) = (x + (y - x) * f, (y - x).normalize());
        points.add([
            w,
            w * z.x,
            w * z.y,
            w * z.z,
            w * z.x * z.x,
            w * z.y * z.y,
            w * z.z * z.z,
            w * z.x * z.y,
            w * z.x * z.z,
            w * z.y * z.z,
            w * d.x,
            w * d.y,
            w * d.z,
            w * x.x,
            w * x.y,
            w * x.z,
            w * y.x,
            w * y.y,
            w * y.z,
        ]);
    }
    let m = points.means()?;
    let mean_z = DVec3::new(m[1], m[2], m[3]);
    let direction = DVec3::new(m[10], m[11], m[12]).try_normalize()?;
    let (mean_x, mean_y) = (DVec3::new(m[13], m[14], m[15]), DVec3::new(m[16], m[17], m[18]));
    let mut n = least_spread_axis(covariance(&m[..10]), direction);
    if n.dot(direction) < 0.0 {
        n = -n;
    }
    let (lo, hi) = (n.dot(mean_x + (mean_y - mean_x) * MIN_FOCUS as f64), n.dot(mean_y));
    let h = crossing_height(rays.map(as_f64), n).unwrap_or(n.dot(mean_z)).clamp(lo.min(hi), hi.max(lo));
    (h > 0.0 && h.is_finite()).then(|| (n.as_vec3(), h as f32))
}

/// The covariance of points from their means `[1, E z, E z zᵀ (xx, yy, zz, xy, xz, yz)]`.
fn covariance(m: &[f64]) -> DMat3 {
    let mean = DVec3::new(m[1], m[2], m[3]);
    DMat3::from_cols_array(&[m[4], m[7], m[8], m[7], m[5], m[9], m[8], m[9], m[6]])
        - DMat3::from_cols(mean * mean.x, mean * mean.y, mean * mean.z)
}

/// The ray from x along ω crossing the plane n·q = h: `z(h) = a + h u`, `u = ω / (n·ω)`, `a = x − (n·x) u`;
/// `None` for a ray that crosses at a cosine below [`MIN_CROSSING_COSINE`].
#[inline]
fn crossing(x: DVec3, y: DVec3, n: DVec3) -> Option<(DVec3, DVec3)> {
    let d = (y - x).normalize();
    let cos = n.dot(d);
    (cos >= MIN_CROSSING_COSINE).then(|| {
        let u = d / cos;
        (x - u * n.dot(x), u)
    })
}

/// The height h of the plane with normal `n` where the crossing points stop depending on x: least squares of
/// Cov(a, x) + h Cov(u, x) over their entries, from the moments Σ w, Σ w x, Σ w a, Σ w u, Σ w a xᵀ, Σ w u xᵀ.
/// `None` where the rays are parallel.
fn crossing_height(rays: impl Iterator<Item = (DVec3, DVec3, f64)>, n: DVec3) -> Option<f64> {
    let mut sums = FixedSums::<28>::default();
    for (x, y, w) in rays {
        let Some((a, u)) = crossing(x, y, n) else { continue };
        let mut t = [0.0; 28];
        t[0] = w;
        for k in 0..3 {
            t[1 + k] = w * x[k];
            t[4 + k] = w * a[k];
            t[7 + k] = w * u[k];
            for j in 0..3 {
                t[10 + 3 * j + k] = w * a[j] * x[k];
                t[19 + 3 * j + k] = w * u[j] * x[k];
            }
        }
        sums.add(t);
    }
    let m = sums.means()?;
    let (mut dot, mut norm) = (0.0, 0.0);
    for j in 0..3 {
        for k in 0..3 {
            let cov_a = m[10 + 3 * j + k] - m[4 + j] * m[1 + k];
            let cov_u = m[19 + 3 * j + k] - m[7 + j] * m[1 + k];
            dot += cov_a * cov_u;
            norm += cov_u * cov_u;
        }
    }
    let h = -dot / norm;
    (norm > 1e-12 && h.is_finite()).then_some(h)
}

/// The unit eigenvector of the least eigenvalue of the symmetric positive semi-definite `c`: power iteration on
/// `tr(c) I − c` (whose largest eigenvalue it is), from `start`; `start` where `c` has no spread.
fn least_spread_axis(c: DMat3, start: DVec3) -> DVec3 {
    let b = DMat3::from_diagonal(DVec3::splat(c.x_axis.x + c.y_axis.y + c.z_axis.z)) - c;
    let mut v = start;
    for _ in 0..100 {
        match (b * v).try_normalize() {
            Some(next) => v = next,
            None => return start,
        }
    }
    v
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

    /// Rays from a floor and from a box's side (off the opening's column) through a square opening at height 1 to
    /// a light at 2: the plane is the opening's (within 8°: the normal comes from the points at a single fraction
    /// of the way, which tilt where rays leave from different heights; a plane tilted about the opening's centre
    /// blurs its edges by the tilt times the opening's half width times the rays' spread of directions); to the
    /// light in the open: the light's plane. Too few rays: no plane.
    #[test]
    fn the_focal_plane_is_the_openings() {
        let mut state = 11u64;
        let mut next = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let anchor = Vec3::new(0.4, 0.1, -0.3);
        let (mut through, mut open) = (Vec::new(), Vec::new());
        for _ in 0..2000 {
            // One in ten from a box's side, 0–0.3 m up; the others from the floor.
            let up = if next() < 0.1 { 0.3 * next() } else { 0.0 };
            let x = Vec3::new(0.2 + 0.4 * next(), up, -0.5 + 0.4 * next());
            let a = Vec3::new(0.2 * next() - 0.1, 1.0, 0.2 * next() - 0.1);
            let y = x + (a - x) * ((2.0 - x.y) / (1.0 - x.y));
            through.push((x - anchor, y - anchor, 0.5 + next()));
            let on_light = Vec3::new(2.0 * next() - 1.0, 2.0, 2.0 * next() - 1.0);
            open.push((x - anchor, on_light - anchor, 0.5 + next()));
        }
        let (n, h) = focal_plane(through.iter().copied()).expect("a plane");
        assert!(n.dot(Vec3::Y) > 0.99, "normal {n}");
        let centre = Vec3::new(0.0, 1.0, 0.0) - anchor;
        assert!((h - n.dot(centre)).abs() < 0.01, "the plane n·q = {h} should pass through the opening's centre");
        let (n, h) = focal_plane(open.iter().copied()).expect("a plane");
        assert!(n.dot(Vec3::Y) > 0.999 && (h - (2.0 - anchor.y)).abs() < 0.01, "the light's plane: {n} {h}");
        assert_eq!(focal_plane(through[..40].iter().copied()), None);
        // The same in any order.
        assert_eq!(focal_plane(through.iter().rev().copied()), focal_plane(through.iter().copied()));
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
