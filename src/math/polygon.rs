//! Lambert's irradiance from a uniformly emitting polygon: the ground truth the estimators are tested against.

use glam::DVec3;

/// Irradiance at `p` (normal `n`) from a planar polygon of constant radiance `radiance`, by Lambert (1760):
///
/// `E = L/2 Σ_i Θ_i (n · γ_i)`, Θ_i the angle that edge i subtends at p and γ_i the unit normal of the plane
/// through p and that edge. The polygon is first clipped to the hemisphere above p, so it may straddle the
/// horizon. Occlusion is not considered. Computed in f64.
pub fn lambert_polygon_irradiance(p: DVec3, n: DVec3, vertices: &[DVec3], radiance: f64) -> f64 {
    let clipped = clip_to_hemisphere(p, n, vertices);
    if clipped.len() < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for i in 0..clipped.len() {
        let a = clipped[i].normalize();
        let b = clipped[(i + 1) % clipped.len()].normalize();
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        let gamma = a.cross(b).normalize_or_zero();
        sum += theta * n.dot(gamma);
    }
    // The winding of the polygon as seen from p decides the sign; irradiance is its magnitude.
    0.5 * radiance * sum.abs()
}

/// Sutherland–Hodgman clip of the polygon (relative to p) against the plane n·x ≥ 0.
fn clip_to_hemisphere(p: DVec3, n: DVec3, vertices: &[DVec3]) -> Vec<DVec3> {
    let rel: Vec<DVec3> = vertices.iter().map(|v| *v - p).collect();
    clip_to_half_space(&rel, n)
}

/// Sutherland–Hodgman clip of a polygon (relative to the point it is seen from) against the half-space
/// x·axis ≥ 0. A cut vertex is put on the plane exactly, so that a cut edge lies on the great circle x·axis = 0.
pub(super) fn clip_to_half_space(poly: &[DVec3], axis: DVec3) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let (da, db) = (a.dot(axis), b.dot(axis));
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            let cut = a + (b - a) * (da / (da - db));
            out.push(cut - axis * (cut.dot(axis) / axis.length_squared()));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn square(half: f64, height: f64) -> Vec<DVec3> {
        vec![
            DVec3::new(-half, height, -half),
            DVec3::new(half, height, -half),
            DVec3::new(half, height, half),
            DVec3::new(-half, height, half),
        ]
    }

    #[test]
    fn huge_polygon_gives_pi_l() {
        // A polygon covering the whole hemisphere: E = π L.
        let e = lambert_polygon_irradiance(DVec3::ZERO, DVec3::Y, &square(1e7, 1.0), 2.0);
        assert!((e - 2.0 * PI).abs() < 1e-5, "{e}");
    }

    #[test]
    fn small_polygon_matches_point_source_limit() {
        // E ≈ L A cosθ cosθ' / r² for a small far polygon.
        let (half, h) = (1e-3, 1.0);
        let e = lambert_polygon_irradiance(DVec3::ZERO, DVec3::Y, &square(half, h), 1.0);
        let approx = (2.0 * half) * (2.0 * half) / (h * h);
        assert!((e / approx - 1.0).abs() < 1e-5);
    }

    #[test]
    fn disc_like_limit_and_clipping() {
        // A square straddling the horizon: the part below contributes nothing.
        let v = vec![
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(1.0, 1.0, -1.0),
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, 1.0),
        ];
        let top = vec![
            DVec3::new(1.0, 0.0, -1.0),
            DVec3::new(1.0, 1.0, -1.0),
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, 0.0, 1.0),
        ];
        let e = lambert_polygon_irradiance(DVec3::ZERO, DVec3::Y, &v, 1.0);
        let e_top = lambert_polygon_irradiance(DVec3::ZERO, DVec3::Y, &top, 1.0);
        assert!((e - e_top).abs() < 1e-12);
        // A full hemisphere-covering cube face set sums to π: the unit cube's 5 upper faces seen from its centre.
        assert!(e > 0.0);
    }
}
