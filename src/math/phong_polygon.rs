//! The glossy counterpart of Lambert's formula: the exact integral of a Phong lobe times the cosine over a
//! polygon, by Arvo's irradiance tensors (Arvo 1995, "Applications of irradiance tensors to the simulation of
//! non-Lambertian phenomena", SIGGRAPH): the closed form the glossy estimators are tested against. Written from
//! the paper, in f64.
//!
//! For a spherical polygon P with edges e (unit end points a → b, arc length Θ_e, outward unit normal
//! n_e = (a×b)/|a×b|) and unit axes w (the lobe's ω_r) and n (the surface normal):
//!
//! - edge integrals `J_i(e) = ∫_e (w·u)^i ds`, by the recurrence
//!   `J_i = [(w·a)^{i−1}(w·t_a) − (w·b)^{i−1}(w·t_b)]/i + (i−1)/i · c² J_{i−2}`, J₀ = Θ_e, t_a and t_b the arc's
//!   unit tangents at a and b, c² = (w·a)² + (w·t_a)² (w projected onto the arc's plane; w·u = c cos(s − φ));
//! - the axial moment `τ_k = ∫_P (w·u)^k du = [Ω·𝟙(k even) − Σ_e (n_e·w) Σ_{i = k−1, k−3, …} J_i(e)] / (k+1)`;
//! - the double-axis moment `∫_P (w·u)^k (n·u) du = [k (w·n) τ_{k−1} − Σ_e (n_e·n) J_k(e)] / (k+2)`,
//!
//! which for k = 0 is Lambert's `½ Σ Θ_e (n·γ_e)` (γ_e = −n_e). The polygon is clipped to both hemispheres
//! first, so that (w·u)^k and (n·u) are the clamped ones the Phong BRDF has. An edge that the clipping lays on
//! the great circle w·u = 0 has J_i = 0 for i > 0 but still J₀ = Θ_e: it contributes to the sums above.

use super::polygon::clip_to_half_space;
use glam::DVec3;

/// `∫_{P ∩ H_n ∩ H_w} (ω·w)^k (ω·n) dω` over the directions from p through the planar polygon `vertices`, H_n
/// and H_w the hemispheres about n and w (unit vectors). Exact up to rounding; O(k) per edge.
pub fn phong_polygon_moment(p: DVec3, n: DVec3, w: DVec3, k: u32, vertices: &[DVec3]) -> f64 {
    let rel: Vec<DVec3> = vertices.iter().map(|v| *v - p).collect();
    let clipped = clip_to_half_space(&clip_to_half_space(&rel, n), w);
    let Some(poly) = spherical_polygon(&clipped) else { return 0.0 };
    // Each edge's normal and its integrals J_0 ..= J_k, which both sums below read.
    let edges: Vec<(DVec3, Vec<f64>)> =
        edges(&poly).filter_map(|(a, b)| Edge::new(a, b)).map(|e| (e.normal, e.integrals(w, k))).collect();
    let k_f = k as f64;
    let boundary: f64 = edges.iter().map(|(normal, j)| normal.dot(n) * j[k as usize]).sum();
    let axial = if k == 0 { 0.0 } else { axial_moment(solid_angle(&poly), &edges, w, k - 1) };
    let value = (k_f * w.dot(n) * axial - boundary) / (k_f + 2.0);
    value.max(0.0)
}

/// `τ_k = ∫_P (w·u)^k du` over a convex spherical polygon of solid angle Ω, from its edges' outward normals and
/// integrals J_i (i ≤ k at least).
fn axial_moment(omega: f64, edges: &[(DVec3, Vec<f64>)], w: DVec3, k: u32) -> f64 {
    let boundary: f64 = edges
        .iter()
        .map(|(normal, j)| {
            // i = k−1, k−3, … ≥ 0.
            let sum: f64 = (0..k).rev().step_by(2).map(|i| j[i as usize]).sum();
            normal.dot(w) * sum
        })
        .sum();
    let even = if k.is_multiple_of(2) { omega } else { 0.0 };
    (even - boundary) / (k as f64 + 1.0)
}

/// A great-circle arc a → b on the unit sphere.
struct Edge {
    a: DVec3,
    b: DVec3,
    /// Arc length Θ.
    theta: f64,
    /// Unit tangents of the arc at a and at b, pointing along a → b.
    tangent_a: DVec3,
    tangent_b: DVec3,
    /// n_e = (a×b)/|a×b|.
    normal: DVec3,
}

impl Edge {
    fn new(a: DVec3, b: DVec3) -> Option<Self> {
        let cross = a.cross(b);
        let sin = cross.length();
        if !(sin > 0.0) {
            return None; // a zero-length edge contributes nothing
        }
        let normal = cross / sin;
        let theta = sin.atan2(a.dot(b));
        Some(Self { a, b, theta, tangent_a: normal.cross(a), tangent_b: normal.cross(b), normal })
    }

    /// `J_i = ∫ (w·u)^i ds` along the arc for i = 0 ..= k (the module's recurrence).
    fn integrals(&self, w: DVec3, k: u32) -> Vec<f64> {
        let (wa, wb) = (w.dot(self.a), w.dot(self.b));
        let (ta, tb) = (w.dot(self.tangent_a), w.dot(self.tangent_b));
        let c2 = wa * wa + ta * ta;
        let mut j = Vec::with_capacity(k as usize + 1);
        j.push(self.theta);
        // (w·a)^{i−1} and (w·b)^{i−1}, starting at i = 1.
        let (mut pa, mut pb) = (1.0, 1.0);
        for i in 1..=k as usize {
            let fi = i as f64;
            let previous = if i >= 2 { j[i - 2] } else { 0.0 };
            j.push((pa * ta - pb * tb) / fi + (fi - 1.0) / fi * c2 * previous);
            pa *= wa;
            pb *= wb;
        }
        j
    }
}

/// Consecutive vertex pairs of a closed polygon.
fn edges(poly: &[DVec3]) -> impl Iterator<Item = (DVec3, DVec3)> + '_ {
    (0..poly.len()).map(move |i| (poly[i], poly[(i + 1) % poly.len()]))
}

/// The clipped polygon's directions as a spherical polygon, ordered so that every edge's normal a×b points
/// out of it; `None` when nothing is left.
fn spherical_polygon(rel: &[DVec3]) -> Option<Vec<DVec3>> {
    let mut poly: Vec<DVec3> = rel.iter().map(|v| v.normalize_or_zero()).filter(|v| *v != DVec3::ZERO).collect();
    if poly.len() < 3 {
        return None;
    }
    let centre: DVec3 = poly.iter().sum();
    let winding: f64 = edges(&poly).map(|(a, b)| a.cross(b).dot(centre)).sum();
    if winding > 0.0 {
        poly.reverse();
    }
    Some(poly)
}

/// Solid angle of a convex spherical polygon: a fan of Van Oosterom–Strackee triangles.
fn solid_angle(poly: &[DVec3]) -> f64 {
    let a = poly[0];
    (1..poly.len() - 1)
        .map(|i| {
            let (b, c) = (poly[i], poly[i + 1]);
            let num = a.dot(b.cross(c)).abs();
            let den = 1.0 + a.dot(b) + a.dot(c) + b.dot(c);
            2.0 * num.atan2(den)
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::lambert_polygon_irradiance;
    use std::f64::consts::PI;

    /// `∫_T (ω·w)⁺^k (ω·n)⁺ dω` by the midpoint rule on a regular subdivision of the triangle (in area measure:
    /// dω = cos θ_T / r² dA).
    fn brute_force(p: DVec3, n: DVec3, w: DVec3, k: u32, [a, b, c]: [DVec3; 3], res: usize) -> f64 {
        let (e1, e2) = (b - a, c - a);
        let normal = e1.cross(e2);
        let cell = normal.length() / 2.0 / (res * res) as f64;
        let normal = normal.normalize();
        let mut sum = 0.0;
        for i in 0..res {
            for j in 0..res - i {
                // Two kinds of cell: upright (i, j) and, but for the last in a row, inverted.
                let mut add = |s: f64, t: f64| {
                    let x = a + e1 * (s / res as f64) + e2 * (t / res as f64);
                    let d = x - p;
                    let r2 = d.length_squared();
                    let u = d / r2.sqrt();
                    let lobe = if u.dot(w) > 0.0 { u.dot(w).powi(k as i32) * u.dot(n).max(0.0) } else { 0.0 };
                    sum += lobe * u.dot(normal).abs() / r2 * cell;
                };
                let (fi, fj) = (i as f64, j as f64);
                add(fi + 1.0 / 3.0, fj + 1.0 / 3.0);
                if j + 1 < res - i {
                    add(fi + 2.0 / 3.0, fj + 2.0 / 3.0);
                }
            }
        }
        sum
    }

    #[test]
    fn order_zero_is_lambert() {
        let tri = [DVec3::new(-1.0, 1.0, -0.5), DVec3::new(1.5, 0.8, -0.4), DVec3::new(0.2, 1.1, 1.2)];
        let (p, n) = (DVec3::new(0.1, 0.0, 0.2), DVec3::Y);
        // With w = n the clip to H_w changes nothing: Lambert exactly.
        let m = phong_polygon_moment(p, n, n, 0, &tri);
        let e = lambert_polygon_irradiance(p, n, &tri, 1.0);
        assert!((m - e).abs() < 1e-12 * e, "{m} vs {e}");
        // k = 1 with w = n: ∫ cos² = the axial moment τ₂ about n.
        let m1 = phong_polygon_moment(p, n, n, 1, &tri);
        let bf = brute_force(p, n, n, 1, tri, 600);
        assert!((m1 / bf - 1.0).abs() < 1e-4, "{m1} vs {bf}");
    }

    #[test]
    fn matches_brute_force_for_triangles_the_lobe_meets_in_every_way() {
        let (p, n) = (DVec3::ZERO, DVec3::Y);
        let cases = [
            // (ω_r, triangle): ω_r inside, ω_r near an edge, straddling n's horizon, straddling ω_r's.
            (
                DVec3::new(0.2, 1.0, 0.1),
                [DVec3::new(-1.0, 1.0, -0.5), DVec3::new(1.5, 0.8, -0.4), DVec3::new(0.2, 1.1, 1.2)],
            ),
            (
                DVec3::new(0.6, 1.0, 0.0),
                [DVec3::new(-1.0, 1.0, -0.5), DVec3::new(0.5, 1.0, -0.5), DVec3::new(0.0, 1.0, 0.8)],
            ),
            (
                DVec3::new(1.0, 0.3, 0.0),
                [DVec3::new(2.0, -0.5, -1.0), DVec3::new(2.0, 0.8, -1.0), DVec3::new(2.0, 0.5, 1.2)],
            ),
            (
                DVec3::new(1.0, 0.1, 0.0),
                [DVec3::new(-2.0, 0.5, -1.0), DVec3::new(1.0, 0.5, -1.0), DVec3::new(0.5, 0.6, 1.5)],
            ),
        ];
        for (i, (w, tri)) in cases.into_iter().enumerate() {
            let w = w.normalize();
            for k in [1, 2, 5, 10, 40, 200] {
                let m = phong_polygon_moment(p, n, w, k, &tri);
                let bf = brute_force(p, n, w, k, tri, 1500);
                let tolerance = 2e-4 * bf.max(1e-9) + 1e-10;
                assert!((m - bf).abs() < tolerance, "case {i}, k = {k}: {m:e} vs brute force {bf:e}");
            }
        }
    }

    #[test]
    fn a_lobe_inside_a_huge_light_integrates_to_its_closed_form() {
        // ∫_{H} cos^k θ cos θ dω = 2π/(k+2) when w = n and the polygon covers the hemisphere.
        let h = 1e6;
        let square = [DVec3::new(-h, 1.0, -h), DVec3::new(h, 1.0, -h), DVec3::new(h, 1.0, h), DVec3::new(-h, 1.0, h)];
        for k in [0, 1, 10, 1000, 100_000] {
            let m = phong_polygon_moment(DVec3::ZERO, DVec3::Y, DVec3::Y, k, &square);
            let exact = 2.0 * PI / (k as f64 + 2.0);
            assert!((m / exact - 1.0).abs() < 1e-5, "k = {k}: {m} vs {exact}");
        }
    }

    #[test]
    fn an_edge_on_the_lobe_horizon_keeps_its_arc_length() {
        // A triangle cut by w·u = 0: the cut edge lies on the great circle, with J₀ = Θ and J_i = 0 for i > 0.
        let (p, n, w) = (DVec3::ZERO, DVec3::Y, DVec3::new(1.0, 0.4, 0.0).normalize());
        let tri = [DVec3::new(-1.0, 1.0, -1.0), DVec3::new(1.0, 1.0, -0.5), DVec3::new(0.0, 1.0, 1.0)];
        for k in [0, 1, 2, 7, 30] {
            let m = phong_polygon_moment(p, n, w, k, &tri);
            let bf = brute_force(p, n, w, k, tri, 1500);
            assert!((m / bf - 1.0).abs() < 2e-4, "k = {k}: {m} vs {bf}");
        }
    }
}
