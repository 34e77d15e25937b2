//! Uniform sampling of the spherical triangle that a planar triangle subtends (Arvo 1995, "Stratified sampling
//! of spherical triangles"; after pbrt-v4's `SampleSphericalTriangle`). Computed in f64: the construction
//! subtracts nearly equal angles for small triangles. Its sines, cosines and arcsines are `math::trig`'s, which
//! the four-lane copy (`super::spherical_triangle_lanes`) computes four at a time, bit for bit.

use crate::math::{asin_f64, sin_cos_f64};
use glam::{DVec3, Vec2, Vec3};
use std::f64::consts::PI;

/// Below this solid angle (sr) the construction loses precision, above it the triangle nearly covers the
/// hemisphere; pbrt-v4 falls back to area sampling outside [3·10⁻⁴, 6.22] sr, and so do we.
pub const MIN_SPHERICAL_SAMPLE_AREA: f32 = 3e-4;
pub const MAX_SPHERICAL_SAMPLE_AREA: f32 = 6.22;

/// Solid angle Ω subtended at `p` by the triangle (a, b, c) (Van Oosterom & Strackee 1983):
/// `tan(Ω/2) = |a·(b×c)| / (|a||b||c| + (a·b)|c| + (a·c)|b| + (b·c)|a|)`, vertices relative to p.
pub fn spherical_triangle_area(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let (a, b, c) = ((a - p).as_dvec3(), (b - p).as_dvec3(), (c - p).as_dvec3());
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let num = a.dot(b.cross(c)).abs();
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    let omega = 2.0 * num.atan2(den);
    if omega.is_finite() { omega.max(0.0) as f32 } else { 0.0 }
}

/// A direction from `p` uniformly distributed over the spherical triangle of (a, b, c): density `1/Ω` w.r.t.
/// solid angle ([`spherical_triangle_pdf`]). `None` when the triangle is degenerate as seen from p.
pub fn sample_spherical_triangle(u: Vec2, p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Option<Vec3> {
    let a = (a - p).as_dvec3().normalize_or_zero();
    let b = (b - p).as_dvec3().normalize_or_zero();
    let c = (c - p).as_dvec3().normalize_or_zero();
    let (n_ab, n_bc, n_ca) = (a.cross(b), b.cross(c), c.cross(a));
    if n_ab.length_squared() == 0.0 || n_bc.length_squared() == 0.0 || n_ca.length_squared() == 0.0 {
        return None;
    }
    let (n_ab, n_bc, n_ca) = (n_ab.normalize(), n_bc.normalize(), n_ca.normalize());
    // The spherical triangle's angles at its vertices; its area is α + β + γ − π.
    let alpha = angle_between(n_ab, -n_ca);
    let beta = angle_between(n_bc, -n_ab);
    let gamma = angle_between(n_ca, -n_bc);
    let area_pi = alpha + beta + gamma;
    if !(area_pi - PI > 0.0) {
        return None;
    }
    // The sub-triangle of area A' = u₀ A fixes the point c' on the arc a→c ...
    let ap_pi = PI + f64::from(u.x) * (area_pi - PI);
    let (sin_alpha, cos_alpha) = sin_cos_f64(alpha);
    let (sin_ap, cos_ap) = sin_cos_f64(ap_pi);
    let sin_phi = sin_ap * cos_alpha - cos_ap * sin_alpha;
    let cos_phi = cos_ap * cos_alpha + sin_ap * sin_alpha;
    let k1 = cos_phi + cos_alpha;
    let k2 = sin_phi - sin_alpha * a.dot(b);
    let cos_bp = ((k2 + (k2 * cos_phi - k1 * sin_phi) * cos_alpha) / ((k2 * sin_phi + k1 * cos_phi) * sin_alpha))
        .clamp(-1.0, 1.0);
    let sin_bp = (1.0 - cos_bp * cos_bp).max(0.0).sqrt();
    let cp = cos_bp * a + sin_bp * gram_schmidt(c, a).normalize_or_zero();
    // ... and u₁ the point along the arc b→c' (uniform in 1 − cos θ from b).
    let cos_theta = 1.0 - f64::from(u.y) * (1.0 - cp.dot(b));
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let w = cos_theta * b + sin_theta * gram_schmidt(cp, b).normalize_or_zero();
    let w = w.normalize_or_zero();
    (w != DVec3::ZERO && w.is_finite()).then(|| w.as_vec3())
}

/// Density of [`sample_spherical_triangle`]: `1/Ω` (solid angle); 0 for a degenerate triangle.
#[inline]
pub fn spherical_triangle_pdf(solid_angle: f32) -> f32 {
    if solid_angle > 0.0 { 1.0 / solid_angle } else { 0.0 }
}

/// The angle between unit vectors, accurate also when they are nearly parallel or opposite.
fn angle_between(v1: DVec3, v2: DVec3) -> f64 {
    if v1.dot(v2) < 0.0 {
        PI - 2.0 * asin_f64(((v1 + v2).length() / 2.0).clamp(-1.0, 1.0))
    } else {
        2.0 * asin_f64(((v2 - v1).length() / 2.0).clamp(-1.0, 1.0))
    }
}

/// The part of `v` orthogonal to the unit vector `w`.
fn gram_schmidt(v: DVec3, w: DVec3) -> DVec3 {
    v - v.dot(w) * w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octant_has_solid_angle_pi_over_two() {
        let o = spherical_triangle_area(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z);
        assert!((o - std::f32::consts::FRAC_PI_2).abs() < 1e-6);
    }

    #[test]
    fn samples_lie_inside_the_triangle() {
        let (a, b, c) = (Vec3::new(-1.0, 1.0, -1.0), Vec3::new(1.5, 1.0, -0.5), Vec3::new(0.0, 1.0, 2.0));
        let n = (b - a).cross(c - a);
        for i in 0..32 {
            for j in 0..32 {
                let u = Vec2::new(i as f32 / 32.0, j as f32 / 32.0);
                let w = sample_spherical_triangle(u, Vec3::ZERO, a, b, c).expect("a sample");
                // The ray from p along w meets the triangle's plane inside the triangle.
                let t = n.dot(a) / n.dot(w);
                let x = w * t;
                let inside = [(a, b), (b, c), (c, a)].iter().all(|(p, q)| (*q - *p).cross(x - *p).dot(n) >= -1e-4);
                assert!(t > 0.0 && inside, "{u:?} -> {w:?}");
            }
        }
    }
}
