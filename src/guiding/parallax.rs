//! Parallax-aware guiding (after Ruppert, Herholz & Lensch 2020, "Robust Fitting of Parallax-Aware Mixtures for
//! Path Guiding", which keep a distance per component; here a plane per quadtree): a spatial leaf's quadtree
//! learns the light as seen from one point, its anchor c (the centre of the leaf's box), each record's direction
//! d = (z − c)/|z − c| aimed at the point z where its ray crosses the leaf's focal plane (the plane its light
//! rays converge in: the light itself, or the opening it comes through; see [`super::FocalPlane`]). A shading
//! point p elsewhere in the leaf draws d from the quadtree, aims at the same point z = c + t_c d of the plane and
//! takes ω = (z − p)/|z − p|: its density, through the change of variables,
//!
//! `p(ω) = p_c(d) dΩ_c/dΩ_p = p_c(d) (cos θ_c t_p²) / (cos θ_p t_c²) = p_c(d) (h_c / h_p) (t_p / t_c)³`,
//!
//! with h_c, h_p the distances of c and p from the plane, t_c, t_p theirs from z, θ the angles to its normal n.
//! The directions that meet the plane from c are those with d·n > 0, and the same from p (on c's side of it):
//! the map is a bijection of those half-spheres, and the directions that never meet the plane (ω·n ≤ 0) map to
//! themselves, so the density is exact on the whole sphere. A record's value is left as it is (an estimate of
//! ∫ L_i dΩ_p over its cell): then p_c ∝ L_i / (dΩ_c/dΩ_p) and p(ω) ∝ L_i at the point that recorded it. Light
//! that passes through the plane is seen by every point of the leaf at the same z: without the map, the points
//! of a leaf see a light through an opening in directions as far apart as the leaf is wide; with it, none.
//! The map is used where p is at least a quarter as far from the plane as c; nearer the plane than that, the
//! quadtree is read as directions at p.

use glam::Vec3;

/// Directions within this cosine of grazing the plane map to themselves (the map's limit there).
const GRAZING: f32 = 1e-6;

/// Where a quadtree learned its light from: its anchor c, and the plane its directions aim at: the points q with
/// n·(q − c) = h (n a unit vector, h > 0: c is on the plane's back side).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Anchor {
    pub centre: Vec3,
    pub normal: Vec3,
    pub height: f32,
}

impl Anchor {
    /// p's distance from the plane (positive on c's side).
    #[inline]
    fn height_of(&self, p: Vec3) -> f32 {
        self.height - self.normal.dot(p - self.centre)
    }

    /// Whether the map from the anchor's directions to directions at `p` is used there: p is at least a quarter as
    /// far from the plane as c, on its side.
    #[inline]
    pub fn reaches(&self, p: Vec3) -> bool {
        self.height.is_finite() && self.height > 0.0 && self.height_of(p) >= 0.25 * self.height
    }

    /// The anchor's direction d of the direction `wi` at `p` (which the anchor [`reaches`](Anchor::reaches)), and
    /// `dΩ_c/dΩ_p`.
    #[inline]
    pub fn from_point(&self, p: Vec3, wi: Vec3) -> (Vec3, f32) {
        let (cos_p, h_p) = (wi.dot(self.normal), self.height_of(p));
        if !(cos_p > GRAZING) {
            return (wi, if cos_p > 0.0 { self.height / h_p } else { 1.0 });
        }
        let t_p = h_p / cos_p;
        let v = p + wi * t_p - self.centre;
        let t_c = v.length();
        let d = if t_c > 0.0 { v / t_c } else { wi };
        let r = t_p / t_c;
        (d, self.height / h_p * r * r * r)
    }

    /// The direction ω at `p` toward the point of the plane the anchor's direction `d` names, and `dΩ_c/dΩ_p` there
    /// (as [`Anchor::from_point`] gives it, but for rounding).
    #[inline]
    pub fn to_point(&self, p: Vec3, d: Vec3) -> (Vec3, f32) {
        let (cos_c, h_p) = (d.dot(self.normal), self.height_of(p));
        if !(cos_c > GRAZING) {
            return (d, if cos_c > 0.0 { self.height / h_p } else { 1.0 });
        }
        let t_c = self.height / cos_c;
        let v = self.centre + d * t_c - p;
        let t_p = v.length();
        let wi = if t_p > 0.0 { v / t_p } else { d };
        let r = t_p / t_c;
        (wi, self.height / h_p * r * r * r)
    }

    /// The direction a ray from `x` along `wi` is learned at: toward the point where it crosses the plane, as c
    /// sees it; the ray's own direction where it does not cross it ahead of x (it leaves away from the plane, or x
    /// is beyond it).
    #[inline]
    pub fn direction_of(&self, x: Vec3, wi: Vec3) -> Vec3 {
        let (cos, h) = (wi.dot(self.normal), self.height_of(x));
        if !(cos > GRAZING && h > 0.0) {
            return wi;
        }
        (x + wi * (h / cos) - self.centre).try_normalize().unwrap_or(wi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn anchor() -> Anchor {
        Anchor { centre: Vec3::new(0.3, -0.2, 1.0), normal: Vec3::new(0.0, 0.8, 0.6), height: 2.0 }
    }

    /// At the centre the map is the identity; elsewhere `to_point` and `from_point` are inverses, the Jacobian is
    /// the ratio of solid angles of a small cone about d, measured numerically, and directions that do not meet
    /// the plane map to themselves.
    #[test]
    fn the_map_and_its_jacobian() {
        let a = anchor();
        let (d, j) = a.from_point(a.centre, Vec3::new(0.0, 0.6, 0.8));
        assert!((d - Vec3::new(0.0, 0.6, 0.8)).length() < 1e-6 && (j - 1.0).abs() < 1e-5, "{d} {j}");
        let p = a.centre + Vec3::new(0.5, 0.3, -0.4);
        assert!(a.reaches(p) && !a.reaches(a.centre + a.normal * 1.6) && !a.reaches(a.centre + a.normal * 3.0));
        for d in [Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.48, 0.6, 0.64)] {
            let (w, j_to) = a.to_point(p, d);
            let (back, j) = a.from_point(p, w);
            assert!((back - d).length() < 1e-5, "{d} -> {w} -> {back}");
            assert!((j_to / j - 1.0).abs() < 1e-5, "{j_to} against {j}");
            // A small square of directions about d, and its image at p: the solid angles' ratio.
            let (t, b) = d.any_orthonormal_pair();
            let h = 1e-3f32;
            let corners = [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(x, y)| (d + t * x + b * y).normalize());
            let at_p = corners.map(|c| a.to_point(p, c).0);
            let area = |c: [Vec3; 4]| (c[1] - c[0]).cross(c[3] - c[0]).length() as f64;
            let ratio = area(corners) / area(at_p);
            assert!((ratio / j as f64 - 1.0).abs() < 1e-2, "d {d}: numerical {ratio}, formula {j}");
        }
        let away = Vec3::new(0.0, -0.6, -0.8);
        assert_eq!(a.to_point(p, away), (away, 1.0));
        assert_eq!(a.from_point(p, away), (away, 1.0));
    }

    /// Rays through one point of the plane from anywhere on c's side are learned at the direction c sees it in.
    #[test]
    fn rays_through_a_point_of_the_plane_are_learned_alike() {
        let a = anchor();
        let z = a.centre + Vec3::new(0.7, 1.1, 0.9);
        let z = z + a.normal * (a.height - a.normal.dot(z - a.centre));
        let seen = (z - a.centre).normalize();
        for x in [a.centre + Vec3::new(0.4, -0.3, 0.2), a.centre + Vec3::new(-0.5, 0.1, -0.6)] {
            let d = a.direction_of(x, (z - x).normalize());
            assert!((d - seen).length() < 1e-5, "from {x}: {d} against {seen}");
        }
        let back = Vec3::new(0.0, -0.8, -0.6);
        assert_eq!(a.direction_of(a.centre, back), back);
    }
}
