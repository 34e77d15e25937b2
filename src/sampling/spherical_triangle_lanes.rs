//! [`sample_spherical_triangle`] for eight directions at once, as two f64x4 halves (Arvo 1995, as there). The
//! normalisations, cross and dot products, divisions and square roots run in f64x4 in the scalar code's order
//! (glam's `DVec3` formulas, no fused multiply-adds), and so do the transcendental functions (the three angles'
//! `asin`, the two `sin_cos`: `math::trig`'s, which the scalar code computes in lane 0). Each lane gets what
//! `sample_spherical_triangle` gives it, bit for bit.

use super::sample_spherical_triangle;
use crate::math::{asin_f64_lanes, for_each_lane, sin_cos_f64_lanes};
use glam::{DVec3, Vec2, Vec3};
use std::f64::consts::PI;
use wide::{CmpEq, CmpGt, CmpLt, f64x4};

/// Per lane with its bit set in `lanes`: a direction from `p[l]` uniformly distributed over the spherical triangle
/// of `triangles[l]`, or `None` where the triangle is degenerate as seen from p (the scalar function's answer).
pub fn sample_spherical_triangle_lanes(
    u: &[Vec2; 8],
    p: &[Vec3; 8],
    triangles: &[[Vec3; 3]; 8],
    lanes: u32,
) -> [Option<Vec3>; 8] {
    let mut out = [None; 8];
    for half in 0..2 {
        let in_half = (lanes >> (4 * half)) & 0xf;
        let at = |l: usize| 4 * half + l;
        if in_half.count_ones() < 2 {
            // None, or one lane: alone it is cheaper than four (the same arithmetic, so the same bits).
            for_each_lane(in_half, |l| {
                let [a, b, c] = triangles[at(l)];
                out[at(l)] = sample_spherical_triangle(u[at(l)], p[at(l)], a, b, c);
            });
            continue;
        }
        let relative = |k: usize| {
            DVec3x4::from_lanes(std::array::from_fn(|l| {
                if in_half & (1 << l) != 0 { (triangles[at(l)][k] - p[at(l)]).as_dvec3() } else { DVec3::ZERO }
            }))
        };
        let u: [Vec2; 4] = std::array::from_fn(|l| u[at(l)]);
        let found = sample_four(&u, [relative(0), relative(1), relative(2)], in_half);
        out[4 * half..4 * half + 4].copy_from_slice(&found);
    }
    out
}

/// The construction for the lanes of `lanes` (< 16) of one half, vertices relative to p.
#[inline(always)]
fn sample_four(u: &[Vec2; 4], [a, b, c]: [DVec3x4; 3], lanes: u32) -> [Option<Vec3>; 4] {
    let (a, b, c) = (a.normalize_or_zero(), b.normalize_or_zero(), c.normalize_or_zero());
    let (n_ab, n_bc, n_ca) = (a.cross(b), b.cross(c), c.cross(a));
    let zero = f64x4::ZERO;
    let degenerate = n_ab.dot(n_ab).cmp_eq(zero) | n_bc.dot(n_bc).cmp_eq(zero) | n_ca.dot(n_ca).cmp_eq(zero);
    let mut valid = lanes & !(degenerate.move_mask() as u32);
    let (n_ab, n_bc, n_ca) = (n_ab.normalize(), n_bc.normalize(), n_ca.normalize());
    // The spherical triangle's angles at its vertices; its area is α + β + γ − π.
    let alpha = angle_between(n_ab, -n_ca);
    let beta = angle_between(n_bc, -n_ab);
    let gamma = angle_between(n_ca, -n_bc);
    let area_pi = alpha + beta + gamma;
    valid &= (area_pi - f64x4::splat(PI)).cmp_gt(zero).move_mask() as u32;
    // The sub-triangle of area A' = u₀ A fixes the point c' on the arc a→c ...
    let u_x = f64x4::new(u.map(|u| f64::from(u.x)));
    let ap_pi = f64x4::splat(PI) + u_x * (area_pi - f64x4::splat(PI));
    let ((sin_alpha, cos_alpha), (sin_ap, cos_ap)) = (sin_cos_f64_lanes(alpha), sin_cos_f64_lanes(ap_pi));
    let sin_phi = sin_ap * cos_alpha - cos_ap * sin_alpha;
    let cos_phi = cos_ap * cos_alpha + sin_ap * sin_alpha;
    let k1 = cos_phi + cos_alpha;
    let k2 = sin_phi - sin_alpha * a.dot(b);
    let cos_bp =
        clamp_unit((k2 + (k2 * cos_phi - k1 * sin_phi) * cos_alpha) / ((k2 * sin_phi + k1 * cos_phi) * sin_alpha));
    let sin_bp = non_negative(f64x4::ONE - cos_bp * cos_bp).sqrt();
    let cp = a.scale(cos_bp) + gram_schmidt(c, a).normalize_or_zero().scale(sin_bp);
    // ... and u₁ the point along the arc b→c' (uniform in 1 − cos θ from b).
    let u_y = f64x4::new(u.map(|u| f64::from(u.y)));
    let cos_theta = f64x4::ONE - u_y * (f64x4::ONE - cp.dot(b));
    let sin_theta = non_negative(f64x4::ONE - cos_theta * cos_theta).sqrt();
    let w = (b.scale(cos_theta) + gram_schmidt(cp, b).normalize_or_zero().scale(sin_theta)).normalize_or_zero();
    let mut out = [None; 4];
    for_each_lane(valid, |l| {
        let w = w.lane(l);
        out[l] = (w != DVec3::ZERO && w.is_finite()).then(|| w.as_vec3());
    });
    out
}

/// `angle_between` of `spherical_triangle.rs` per lane: `π − 2 asin(|v₁ + v₂|/2)` where v₁·v₂ < 0, else
/// `2 asin(|v₂ − v₁|/2)`.
#[inline(always)]
fn angle_between(v1: DVec3x4, v2: DVec3x4) -> f64x4 {
    let opposed = v1.dot(v2).cmp_lt(f64x4::ZERO);
    let half_chord = opposed.blend((v1 + v2).length(), (v2 - v1).length()) / f64x4::splat(2.0);
    let twice = f64x4::splat(2.0) * asin_f64_lanes(clamp_unit(half_chord));
    opposed.blend(f64x4::splat(PI) - twice, twice)
}

/// `f64::clamp(x, −1, 1)` per lane: NaN stays NaN.
#[inline(always)]
fn clamp_unit(x: f64x4) -> f64x4 {
    let x = x.cmp_lt(f64x4::splat(-1.0)).blend(f64x4::splat(-1.0), x);
    x.cmp_gt(f64x4::ONE).blend(f64x4::ONE, x)
}

/// `f64::max(x, 0)` per lane for an x that is not −0 (here `1 − c²`): x where x > 0, else 0 (also for NaN).
#[inline(always)]
fn non_negative(x: f64x4) -> f64x4 {
    x.cmp_gt(f64x4::ZERO).blend(x, f64x4::ZERO)
}

/// The part of `v` orthogonal to the unit vector `w`: `v − (v·w) w`.
#[inline(always)]
fn gram_schmidt(v: DVec3x4, w: DVec3x4) -> DVec3x4 {
    v - w.scale(v.dot(w))
}

/// Four `DVec3`s, one per lane, with glam's formulas.
#[derive(Clone, Copy)]
struct DVec3x4 {
    x: f64x4,
    y: f64x4,
    z: f64x4,
}

impl DVec3x4 {
    #[inline(always)]
    fn from_lanes(v: [DVec3; 4]) -> Self {
        Self { x: f64x4::new(v.map(|v| v.x)), y: f64x4::new(v.map(|v| v.y)), z: f64x4::new(v.map(|v| v.z)) }
    }

    #[inline(always)]
    fn lane(self, l: usize) -> DVec3 {
        DVec3::new(self.x.as_array_ref()[l], self.y.as_array_ref()[l], self.z.as_array_ref()[l])
    }

    #[inline(always)]
    fn dot(self, rhs: Self) -> f64x4 {
        (self.x * rhs.x) + (self.y * rhs.y) + (self.z * rhs.z)
    }

    #[inline(always)]
    fn cross(self, rhs: Self) -> Self {
        Self {
            x: self.y * rhs.z - rhs.y * self.z,
            y: self.z * rhs.x - rhs.z * self.x,
            z: self.x * rhs.y - rhs.x * self.y,
        }
    }

    /// `s · v` (or `v · s`: the products are the same).
    #[inline(always)]
    fn scale(self, s: f64x4) -> Self {
        Self { x: self.x * s, y: self.y * s, z: self.z * s }
    }

    #[inline(always)]
    fn length(self) -> f64x4 {
        self.dot(self).sqrt()
    }

    /// `DVec3::normalize`: v · (1/|v|).
    #[inline(always)]
    fn normalize(self) -> Self {
        self.scale(f64x4::ONE / self.length())
    }

    /// `DVec3::normalize_or_zero`: v · (1/|v|) where 1/|v| is finite and > 0, else 0.
    #[inline(always)]
    fn normalize_or_zero(self) -> Self {
        let rcp = f64x4::ONE / self.length();
        let ok = rcp.is_finite() & rcp.cmp_gt(f64x4::ZERO);
        let n = self.scale(rcp);
        Self { x: ok.blend(n.x, f64x4::ZERO), y: ok.blend(n.y, f64x4::ZERO), z: ok.blend(n.z, f64x4::ZERO) }
    }
}

impl std::ops::Add for DVec3x4 {
    type Output = Self;
    #[inline(always)]
    fn add(self, rhs: Self) -> Self {
        Self { x: self.x + rhs.x, y: self.y + rhs.y, z: self.z + rhs.z }
    }
}

impl std::ops::Sub for DVec3x4 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, rhs: Self) -> Self {
        Self { x: self.x - rhs.x, y: self.y - rhs.y, z: self.z - rhs.z }
    }
}

impl std::ops::Neg for DVec3x4 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        // The sign bit flipped, as f64's negation does (wide's `-x` is `0 − x`, which gives +0 for +0).
        let sign = f64x4::splat(-0.0);
        Self { x: self.x ^ sign, y: self.y ^ sign, z: self.z ^ sign }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::SampleRng;

    /// Eight lanes draw what the scalar function draws, bit for bit (or `None` where it gives `None`): triangles
    /// of every size and distance seen from points around them, near-degenerate ones (a vertex almost on
    /// another, seen edge-on, touching p) and lanes left out.
    #[test]
    fn eight_lanes_draw_what_the_scalar_construction_draws() {
        let (mut compared, mut none) = (0, 0);
        for group in 0..6000u64 {
            let mut rng = SampleRng::new(11, group, 0);
            let point = |rng: &mut SampleRng, scale: f32| {
                let u = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5;
                u * scale
            };
            let (mut u, mut p, mut triangles) = ([Vec2::ZERO; 8], [Vec3::ZERO; 8], [[Vec3::ZERO; 3]; 8]);
            for l in 0..8 {
                let size = 10f32.powi((group % 7) as i32 - 3);
                let centre = point(&mut rng, 4.0);
                let mut tri = [0; 3].map(|_| centre + point(&mut rng, size));
                match (group + l as u64) % 11 {
                    0 => tri[1] = tri[0] + Vec3::splat(1e-7), // two vertices almost together
                    1 => tri[2] = (tri[0] + tri[1]) * 0.5,    // collinear
                    2 => p[l] = tri[0],                       // p on a vertex
                    3 => p[l] = (tri[0] + tri[1]) * 0.5,      // p on an edge: seen edge-on
                    _ => p[l] = point(&mut rng, 8.0),
                }
                triangles[l] = tri;
                u[l] = Vec2::new(rng.uniform(), rng.uniform());
            }
            let lanes = if group % 5 == 0 { 0b1011_0110 } else { 0xff };
            let found = sample_spherical_triangle_lanes(&u, &p, &triangles, lanes);
            for l in 0..8 {
                if lanes & (1 << l) == 0 {
                    assert!(found[l].is_none());
                    continue;
                }
                let [a, b, c] = triangles[l];
                let expected = sample_spherical_triangle(u[l], p[l], a, b, c);
                assert_eq!(
                    found[l].map(|w| w.to_array().map(f32::to_bits)),
                    expected.map(|w| w.to_array().map(f32::to_bits)),
                    "group {group}, lane {l}: {:?} from {}",
                    triangles[l],
                    p[l]
                );
                compared += 1;
                none += expected.is_none() as u32;
            }
        }
        assert!(compared > 40_000 && none > 1000, "{compared} lanes, {none} without a sample: too few of either");
    }
}
