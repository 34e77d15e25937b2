//! Sampling a triangle proportionally to projected solid angle: density `p(ω) = (ω·n)⁺ / Ω⊥` (solid angle),
//! Ω⊥ = ∫_Δ (ω·n)⁺ dω the triangle's projected solid angle above p's horizon. For a diffuse surface under one
//! triangle of constant radiance this is the ideal density: `f_r L (ω·n) / p = (k_d/π) L Ω⊥`, a constant.
//!
//! Exact by rejection: directions are drawn uniformly over the spherical triangle (Arvo 1995) and accepted with
//! probability (ω·n)/cosmax, cosmax = max over the spherical triangle of ω·n, so the accepted ones have density
//! ∝ (ω·n)⁺. Ω⊥ comes from Lambert's closed form `½ Σ Θ_i (n·γ_i)` of the triangle clipped to the hemisphere.
//! The expected number of trials is `Ω cosmax / Ω⊥`.

use super::spherical_triangle::{MAX_SPHERICAL_SAMPLE_AREA, MIN_SPHERICAL_SAMPLE_AREA};
use super::{sample_spherical_triangle, spherical_triangle_area};
use crate::math::SampleRng;
use glam::{DVec3, Vec3};

/// Rejection is used only where it accepts at least this fraction of trials; elsewhere the caller samples area.
pub const MIN_ACCEPTANCE: f32 = 0.05;
/// Never reached where acceptance ≥ 5% (probability 0.95¹⁰⁰⁰⁰ ≈ 10⁻²²³); only guards against NaN input.
const MAX_TRIALS: u32 = 10_000;

/// How a triangle is sampled from p: a deterministic function of (p, n, triangle), so that a density can be
/// evaluated for any direction (multiple importance sampling needs that).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ProjectedPlan {
    /// Rejection from uniform spherical-triangle samples; density (ω·n)⁺/Ω⊥.
    Rejection { solid_angle: f32, projected: f32, cos_max: f32 },
    /// Too small, too large or too close to the horizon for rejection: the caller samples area uniformly.
    Area,
    /// Nothing of the triangle is above the horizon.
    Invisible,
}

impl ProjectedPlan {
    pub fn new(p: Vec3, n: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Self {
        Self::with_projected(p, n, a, b, c, projected_solid_angle(p, n, a, b, c))
    }

    /// [`ProjectedPlan::new`] given the triangle's [`projected_solid_angle`] (computed already).
    pub fn with_projected(p: Vec3, n: Vec3, a: Vec3, b: Vec3, c: Vec3, projected: f32) -> Self {
        if !(projected > 0.0) {
            return ProjectedPlan::Invisible;
        }
        let solid_angle = spherical_triangle_area(p, a, b, c);
        if !(MIN_SPHERICAL_SAMPLE_AREA..=MAX_SPHERICAL_SAMPLE_AREA).contains(&solid_angle) {
            return ProjectedPlan::Area;
        }
        let cos_max = max_cosine(p, n, a, b, c);
        if projected < MIN_ACCEPTANCE * solid_angle * cos_max {
            return ProjectedPlan::Area;
        }
        ProjectedPlan::Rejection { solid_angle, projected, cos_max }
    }
}

/// A direction with density (ω·n)⁺/Ω⊥, by rejection (see the module docs). `None` for a degenerate triangle.
pub fn sample_projected_triangle(rng: &mut SampleRng, p: Vec3, n: Vec3, tri: [Vec3; 3], cos_max: f32) -> Option<Vec3> {
    let [a, b, c] = tri;
    for _ in 0..MAX_TRIALS {
        let w = sample_spherical_triangle(rng.uniform_2d(), p, a, b, c)?;
        if rng.uniform() * cos_max < w.dot(n) {
            return Some(w);
        }
    }
    None
}

/// Density of [`sample_projected_triangle`]: `(ω·n)⁺ / Ω⊥` (solid angle).
#[inline]
pub fn projected_triangle_pdf(cos_theta: f32, projected_solid_angle: f32) -> f32 {
    if projected_solid_angle > 0.0 { cos_theta.max(0.0) / projected_solid_angle } else { 0.0 }
}

/// Projected solid angle Ω⊥ of the triangle (a, b, c) seen from p with unit normal n, only the part above the
/// horizon: Lambert's `½ |Σ Θ_i (n·γ_i)|` over the triangle clipped to n·(x − p) ≥ 0. In f64, no allocation.
pub fn projected_solid_angle(p: Vec3, n: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let rel = [a - p, b - p, c - p].map(Vec3::as_dvec3);
    projected_solid_angle_f64(n.as_dvec3(), rel) as f32
}

/// [`projected_solid_angle`] of a triangle given in f64 relative to the point (the LTC's cosine space, where
/// rounding the vertices to f32 would move a plane that passes close to the origin).
pub fn projected_solid_angle_f64(n: DVec3, rel: [DVec3; 3]) -> f64 {
    let mut poly = [DVec3::ZERO; 4];
    let mut len = 0;
    for i in 0..3 {
        let (u, v) = (rel[i], rel[(i + 1) % 3]);
        let (du, dv) = (u.dot(n), v.dot(n));
        if du >= 0.0 {
            poly[len] = u;
            len += 1;
        }
        if (du >= 0.0) != (dv >= 0.0) {
            poly[len] = u + (v - u) * (du / (du - dv));
            len += 1;
        }
    }
    if len < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for i in 0..len {
        let (u, v) = (poly[i].normalize_or_zero(), poly[(i + 1) % len].normalize_or_zero());
        let theta = u.dot(v).clamp(-1.0, 1.0).acos();
        sum += theta * n.dot(u.cross(v).normalize_or_zero());
    }
    let result = 0.5 * sum.abs();
    if result.is_finite() { result } else { 0.0 }
}

/// max of ω·n over the spherical triangle of (a, b, c) seen from p: 1 where n points into it, else the largest
/// of the vertices and of each edge's great-circle arc (whose maximum is where n projects onto its plane).
pub fn max_cosine(p: Vec3, n: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let n = n.as_dvec3();
    let v = [(a - p).as_dvec3().normalize(), (b - p).as_dvec3().normalize(), (c - p).as_dvec3().normalize()];
    let orientation = v[0].dot(v[1].cross(v[2])).signum();
    let edges = [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])];
    if edges.iter().all(|(x, y)| orientation * n.dot(x.cross(*y)) >= 0.0) {
        return 1.0;
    }
    let mut best = v.iter().map(|x| x.dot(n)).fold(f64::NEG_INFINITY, f64::max);
    for (x, y) in edges {
        let e = x.cross(y).normalize_or_zero();
        let m = n - n.dot(e) * e;
        let len = m.length();
        if len > 0.0 {
            let m = m / len;
            // m lies on the arc from x to y when it is on the inner side of both end points.
            if x.cross(m).dot(e) >= 0.0 && m.cross(y).dot(e) >= 0.0 {
                best = best.max(len);
            }
        }
    }
    best.clamp(0.0, 1.0) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::lambert_polygon_irradiance;

    #[test]
    fn projected_solid_angle_matches_lambert() {
        let p = Vec3::new(0.3, 0.0, -0.2);
        let tris = [
            [Vec3::new(-1.0, 1.0, -1.0), Vec3::new(1.0, 1.0, -1.0), Vec3::new(0.0, 1.0, 1.0)],
            [Vec3::new(2.0, -0.5, -1.0), Vec3::new(2.0, 0.5, -1.0), Vec3::new(2.0, 0.5, 1.0)], // straddles
        ];
        for [a, b, c] in tris {
            let e =
                lambert_polygon_irradiance(p.as_dvec3(), DVec3::Y, &[a.as_dvec3(), b.as_dvec3(), c.as_dvec3()], 1.0);
            let o = projected_solid_angle(p, Vec3::Y, a, b, c);
            assert!((o as f64 - e).abs() < 1e-6 * e.max(1e-3), "{o} vs {e}");
        }
    }

    #[test]
    fn max_cosine_is_an_upper_bound_and_tight() {
        let p = Vec3::ZERO;
        let (a, b, c) = (Vec3::new(2.0, 0.2, -1.0), Vec3::new(2.0, 0.2, 1.0), Vec3::new(1.0, 1.5, 0.0));
        let m = max_cosine(p, Vec3::Y, a, b, c);
        let mut seen = 0.0f32;
        let mut rng = SampleRng::new(1, 2, 3);
        for _ in 0..20_000 {
            let w = sample_spherical_triangle(rng.uniform_2d(), p, a, b, c).expect("sample");
            assert!(w.y <= m + 1e-5);
            seen = seen.max(w.y);
        }
        assert!(m - seen < 0.01, "bound {m}, seen {seen}");
        // n pointing into the triangle.
        assert_eq!(max_cosine(p, Vec3::new(1.0, 0.5, 0.0).normalize(), a, b, c), 1.0);
    }
}
