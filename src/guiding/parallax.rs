//! Parallax-aware guiding (after Ruppert, Herholz & Lensch 2020, "Robust Fitting of Parallax-Aware Mixtures for
//! Path Guiding", here for a quadtree): a spatial leaf's quadtree learns the light as seen from one point, its
//! anchor c (the centre of the leaf's box), each record's direction d = (y − c)/|y − c| aimed at the point y
//! where it found light. The light is taken to lie on the sphere of radius R about c, R the energy-weighted mean
//! of |y − c|. A shading point p elsewhere in the leaf draws d from the quadtree, aims at y = c + R d and takes
//! ω = (y − p)/|y − p|: its density, through the change of variables,
//!
//! `p(ω) = p_c(d) dΩ_c/dΩ_p = p_c(d) s² / (R² (ω·d))`,   s = |y − p|,
//!
//! where y is the point where the ray from p along ω leaves the sphere (one point: p is inside), so d → ω is a
//! bijection and the density is exact. A record's value is left as it is (an estimate of ∫ L_i dΩ_p over its
//! cell): then p_c ∝ L_i / (dΩ_c/dΩ_p) and p(ω) ∝ L_i at the point that recorded it. Without the anchor, the
//! points of a leaf see a light through an opening in directions as far apart as the leaf is wide; with it, the
//! spread left is the opening's parallax alone. The map is used where |p − c| ≤ R/2 (so ω·d ≥ √3/2); nearer a
//! light than that, the quadtree is read as directions at p.

use glam::Vec3;

/// Where a quadtree learned its light from: its anchor c and the light's mean distance R.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Anchor {
    pub centre: Vec3,
    pub radius: f32,
}

impl Anchor {
    /// Whether the map from the anchor's directions to directions at `p` is used there: |p − c| ≤ R/2.
    #[inline]
    pub fn reaches(&self, p: Vec3) -> bool {
        self.radius.is_finite() && (p - self.centre).length_squared() <= 0.25 * self.radius * self.radius
    }

    /// The anchor's direction d of the direction `wi` at `p` (which the anchor [`reaches`](Anchor::reaches)), and
    /// `dΩ_c/dΩ_p = s² / (R² (ω·d))`: s is the positive root of |p − c + s ω| = R.
    #[inline]
    pub fn from_point(&self, p: Vec3, wi: Vec3) -> (Vec3, f32) {
        let (q, r) = (p - self.centre, self.radius);
        let b = q.dot(wi);
        let s = -b + (b * b - q.length_squared() + r * r).max(0.0).sqrt();
        let d = (q + wi * s).normalize_or(wi);
        (d, s * s / (r * r * wi.dot(d).max(1e-3)))
    }

    /// The direction ω at `p` toward the point the anchor's direction `d` names, y = c + R d, and
    /// `dΩ_c/dΩ_p` there (as [`Anchor::from_point`] gives it, but for rounding).
    #[inline]
    pub fn to_point(&self, p: Vec3, d: Vec3) -> (Vec3, f32) {
        let v = self.centre + d * self.radius - p;
        let s = v.length();
        let wi = if s > 0.0 { v / s } else { d };
        (wi, s * s / (self.radius * self.radius * wi.dot(d).max(1e-3)))
    }
}

/// A record's direction as its leaf's quadtree learns it: from the leaf's anchor `centre` toward `hit`, the
/// point where it found light, and that point's distance (for R). `None` where `hit` is the centre itself.
#[inline]
pub fn anchor_direction(centre: Vec3, hit: Vec3) -> Option<(Vec3, f32)> {
    let v = (hit - centre).as_dvec3();
    let r = v.length();
    (r > 0.0 && r.is_finite()).then(|| ((v / r).as_vec3(), r as f32))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At the centre the map is the identity; elsewhere `to_point` and `from_point` are inverses, and the
    /// Jacobian is the ratio of solid angles of a small cone about d, measured numerically.
    #[test]
    fn the_map_and_its_jacobian() {
        let a = Anchor { centre: Vec3::new(0.3, -0.2, 1.0), radius: 2.0 };
        let (d, j) = a.from_point(a.centre, Vec3::new(0.0, 0.6, 0.8));
        assert!((d - Vec3::new(0.0, 0.6, 0.8)).length() < 1e-6 && (j - 1.0).abs() < 1e-6);
        let p = a.centre + Vec3::new(0.5, 0.3, -0.4);
        assert!(a.reaches(p) && !a.reaches(a.centre + Vec3::new(1.2, 0.0, 0.0)));
        for d in [Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.6, 0.0, -0.8), Vec3::new(-0.48, 0.6, 0.64)] {
            let (w, j_to) = a.to_point(p, d);
            let (back, j) = a.from_point(p, w);
            assert!((back - d).length() < 1e-5, "{d} -> {w} -> {back}");
            assert!((j_to / j - 1.0).abs() < 1e-5, "{j_to} against {j}");
            // A small square of directions about d, and its image at p: the solid angles' ratio.
            let (t, b) = (d.any_orthonormal_pair().0, d.any_orthonormal_pair().1);
            let h = 1e-3f32;
            let corners = [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(x, y)| (d + t * x + b * y).normalize());
            let at_p = corners.map(|c| a.to_point(p, c).0);
            let area = |c: [Vec3; 4]| (c[1] - c[0]).cross(c[3] - c[0]).length() as f64;
            let ratio = area(corners) / area(at_p);
            assert!((ratio / j as f64 - 1.0).abs() < 1e-2, "d {d}: numerical {ratio}, formula {j}");
        }
    }

    #[test]
    fn anchor_directions() {
        let (d, r) = anchor_direction(Vec3::ZERO, Vec3::new(0.0, 3.0, 4.0)).expect("a direction");
        assert!((d - Vec3::new(0.0, 0.6, 0.8)).length() < 1e-7 && (r - 5.0).abs() < 1e-6);
        assert!(anchor_direction(Vec3::ONE, Vec3::ONE).is_none());
    }
}
