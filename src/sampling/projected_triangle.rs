//! Sampling a triangle proportionally to projected solid angle: density `p(ω) = (ω·n)⁺ / Ω⊥` (solid angle),
//! Ω⊥ = ∫_Δ (ω·n)⁺ dω the triangle's projected solid angle above p's horizon. For a diffuse surface under one
//! triangle of constant radiance this is the ideal density: `f_r L (ω·n) / p = (k_d/π) L Ω⊥`, a constant.
//!
//! Exact by rejection: directions are drawn uniformly over the spherical triangle (Arvo 1995) and accepted with
//! probability (ω·n)/cosmax, cosmax = max over the spherical triangle of ω·n, so the accepted ones have density
//! ∝ (ω·n)⁺. Ω⊥ comes from Lambert's closed form `½ Σ Θ_i (n·γ_i)` of the triangle clipped to the hemisphere.
//! The expected number of trials is `Ω cosmax / Ω⊥`.

use super::spherical_triangle::{MAX_SPHERICAL_SAMPLE_AREA, MIN_SPHERICAL_SAMPLE_AREA};
use super::{sample_spherical_triangle, sample_spherical_triangle_lanes, spherical_triangle_area};
use crate::math::{SampleRng, acos_f64_lanes, for_each_lane};
use glam::{DVec3, Vec2, Vec3};
use wide::f64x4;

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

/// [`sample_projected_triangle`] for the lanes of `lanes` (bit l for lane l), lane l drawing from `rngs[l]`: each
/// trial's candidates are drawn together ([`sample_spherical_triangle_lanes`]), then each lane accepts or rejects
/// its own. What `sample_projected_triangle` gives each lane, bit for bit: every lane draws from its stream in the
/// same order as alone.
pub fn sample_projected_triangle_lanes(
    rngs: &mut [SampleRng; 8],
    lanes: u32,
    (p, n): (&[Vec3; 8], &[Vec3; 8]),
    triangles: &[[Vec3; 3]; 8],
    cos_max: &[f32; 8],
) -> [Option<Vec3>; 8] {
    let (mut out, mut u, mut pending) = ([None; 8], [Vec2::ZERO; 8], lanes);
    if lanes.count_ones() == 1 {
        // One lane: its trials alone (the same draws, without the others' bookkeeping).
        let l = lanes.trailing_zeros() as usize;
        out[l] = sample_projected_triangle(&mut rngs[l], p[l], n[l], triangles[l], cos_max[l]);
        return out;
    }
    for _ in 0..MAX_TRIALS {
        if pending == 0 {
            break;
        }
        for_each_lane(pending, |l| u[l] = rngs[l].uniform_2d());
        let drawn = sample_spherical_triangle_lanes(&u, p, triangles, pending);
        for_each_lane(pending, |l| match drawn[l] {
            None => pending &= !(1 << l),
            Some(w) => {
                if rngs[l].uniform() * cos_max[l] < w.dot(n[l]) {
                    out[l] = Some(w);
                    pending &= !(1 << l);
                }
            }
        });
    }
    out
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
    // The edges' angles Θ_i = acos(γ̂_i·γ̂_{i+1}), all of them in one four-lane `acos`.
    let unit = poly.map(DVec3::normalize_or_zero);
    let mut cosines = [1.0; 4];
    for i in 0..len {
        cosines[i] = unit[i].dot(unit[(i + 1) % len]).clamp(-1.0, 1.0);
    }
    let theta = acos_f64_lanes(f64x4::new(cosines)).to_array();
    let mut sum = 0.0;
    for i in 0..len {
        sum += theta[i] * n.dot(unit[i].cross(unit[(i + 1) % len]).normalize_or_zero());
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

    /// Eight lanes draw what the scalar rejection draws, bit for bit, and leave each stream where it leaves it:
    /// triangles around points with normals at random, through `ProjectedPlan`'s bound of ω·n, lanes left out,
    /// and single lanes.
    #[test]
    fn eight_lanes_draw_what_the_scalar_rejection_draws() {
        let (mut compared, mut drawn) = (0, 0);
        for group in 0..6000u64 {
            let mut setup = SampleRng::new(12, group, 0);
            let mut point = |scale: f32| {
                let u = Vec3::new(setup.uniform(), setup.uniform(), setup.uniform()) - 0.5;
                u * scale
            };
            let (mut p, mut n, mut triangles, mut cos_max) =
                ([Vec3::ZERO; 8], [Vec3::Z; 8], [[Vec3::ZERO; 3]; 8], [0.0; 8]);
            let mut lanes = 0u32;
            for l in 0..8 {
                let size = 10f32.powi((group % 4) as i32 - 2);
                let centre = point(3.0);
                triangles[l] = [centre + point(size), centre + point(size), centre + point(size)];
                p[l] = point(3.0);
                n[l] = point(2.0).normalize_or(Vec3::Z);
                let [a, b, c] = triangles[l];
                if let ProjectedPlan::Rejection { cos_max: bound, .. } = ProjectedPlan::new(p[l], n[l], a, b, c) {
                    cos_max[l] = bound;
                    lanes |= 1 << l;
                }
            }
            let lanes = match group % 5 {
                0 => lanes & 0b0110_1001,
                1 => lanes & (1 << lanes.trailing_zeros().min(31)),
                _ => lanes,
            };
            let mut rngs: [SampleRng; 8] = std::array::from_fn(|l| SampleRng::new(13, group, l as u64));
            let mut alone = rngs;
            let found = sample_projected_triangle_lanes(&mut rngs, lanes, (&p, &n), &triangles, &cos_max);
            for l in 0..8 {
                let expected = if lanes & (1 << l) != 0 {
                    sample_projected_triangle(&mut alone[l], p[l], n[l], triangles[l], cos_max[l])
                } else {
                    None
                };
                let bits = |w: Option<Vec3>| w.map(|w| w.to_array().map(f32::to_bits));
                assert_eq!(bits(found[l]), bits(expected), "group {group}, lane {l}");
                assert_eq!(
                    rngs[l].uniform().to_bits(),
                    alone[l].uniform().to_bits(),
                    "group {group}, lane {l}'s stream"
                );
                compared += (lanes >> l) & 1;
                drawn += expected.is_some() as u32;
            }
        }
        assert!(compared > 10_000 && drawn > 10_000, "{compared} lanes, {drawn} drawn: the test checks too little");
    }

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
