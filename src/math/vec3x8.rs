//! Eight 3-vectors in structure-of-arrays form, one per SIMD lane (f32x8), for code that runs eight samples at
//! once. Each operation is the one glam's `Vec3` performs, lane by lane, in the same order and without fused
//! multiply-adds, so a lane rounds exactly as the scalar code does: `(a + b).dot(c)` on lane i equals
//! `(a_i + b_i).dot(c_i)` bit for bit.

use glam::Vec3;
use std::ops::{Add, Div, Mul, Neg, Sub};
use wide::f32x8;

#[derive(Clone, Copy, Debug, Default)]
pub struct Vec3x8 {
    pub x: f32x8,
    pub y: f32x8,
    pub z: f32x8,
}

impl Vec3x8 {
    #[inline(always)]
    pub fn splat(v: Vec3) -> Self {
        Self { x: f32x8::splat(v.x), y: f32x8::splat(v.y), z: f32x8::splat(v.z) }
    }

    #[inline(always)]
    pub fn new(x: f32x8, y: f32x8, z: f32x8) -> Self {
        Self { x, y, z }
    }

    /// Lane i holds `v[i]`.
    #[inline(always)]
    pub fn from_lanes(v: &[Vec3; 8]) -> Self {
        Self { x: f32x8::new(v.map(|v| v.x)), y: f32x8::new(v.map(|v| v.y)), z: f32x8::new(v.map(|v| v.z)) }
    }

    /// A triangle's first eight vertex coordinates (v₀, v₁, v₂.x, v₂.y) as one row: eight triangles' rows and
    /// their v₂.z become one vector per vertex through [`Vec3x8::triangles`].
    #[inline(always)]
    pub fn triangle_row([a, b, c]: [Vec3; 3]) -> f32x8 {
        f32x8::new([a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y])
    }

    /// The vertices of eight triangles, lane i from triangle i's row `rows[i]` ([`Vec3x8::triangle_row`]) and
    /// its v₂.z in lane i of `last`: one 8×8 transpose.
    #[inline(always)]
    pub fn triangles(rows: [f32x8; 8], last: f32x8) -> [Self; 3] {
        let [ax, ay, az, bx, by, bz, cx, cy] = f32x8::transpose(rows);
        [Self::new(ax, ay, az), Self::new(bx, by, bz), Self::new(cx, cy, last)]
    }

    /// Lane i as `v[i]`: [`Vec3x8::from_lanes`] undone.
    #[inline(always)]
    pub fn to_lanes(&self) -> [Vec3; 8] {
        let (x, y, z) = (self.x.to_array(), self.y.to_array(), self.z.to_array());
        std::array::from_fn(|i| Vec3::new(x[i], y[i], z[i]))
    }

    #[inline(always)]
    pub fn lane(&self, i: usize) -> Vec3 {
        Vec3::new(self.x.as_array_ref()[i], self.y.as_array_ref()[i], self.z.as_array_ref()[i])
    }

    /// `x₁x₂ + y₁y₂ + z₁z₂`, summed left to right as `Vec3::dot`.
    #[inline(always)]
    pub fn dot(self, o: Self) -> f32x8 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline(always)]
    pub fn length(self) -> f32x8 {
        self.dot(self).sqrt()
    }

    /// `self / |self|` as `Vec3::normalize`: multiplied by the reciprocal of the length.
    #[inline(always)]
    pub fn normalize(self) -> Self {
        self * (f32x8::ONE / self.length())
    }

    /// All bits set in the lanes that are not the zero vector (as `v != Vec3::ZERO`: −0 counts as 0).
    #[inline(always)]
    pub fn nonzero(&self) -> f32x8 {
        use wide::CmpEq;
        !(self.x.cmp_eq(f32x8::ZERO) & self.y.cmp_eq(f32x8::ZERO) & self.z.cmp_eq(f32x8::ZERO))
    }

    /// `t` in the lanes where `mask` is set (all bits), `f` elsewhere.
    #[inline(always)]
    pub fn select(mask: f32x8, t: Self, f: Self) -> Self {
        Self { x: mask.blend(t.x, f.x), y: mask.blend(t.y, f.y), z: mask.blend(t.z, f.z) }
    }
}

impl Add for Vec3x8 {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self { x: self.x + o.x, y: self.y + o.y, z: self.z + o.z }
    }
}

impl Sub for Vec3x8 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self { x: self.x - o.x, y: self.y - o.y, z: self.z - o.z }
    }
}

/// A sign flip, as `-v` on a `Vec3` (−0 for 0; `wide`'s own negation computes `0 − v`, which gives +0).
impl Neg for Vec3x8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        let sign = f32x8::splat(-0.0);
        Self { x: self.x ^ sign, y: self.y ^ sign, z: self.z ^ sign }
    }
}

/// Component by component, as `Vec3 * Vec3`.
impl Mul for Vec3x8 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self { x: self.x * o.x, y: self.y * o.y, z: self.z * o.z }
    }
}

impl Mul<f32x8> for Vec3x8 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: f32x8) -> Self {
        Self { x: self.x * s, y: self.y * s, z: self.z * s }
    }
}

impl Div<f32x8> for Vec3x8 {
    type Output = Self;
    #[inline(always)]
    fn div(self, s: f32x8) -> Self {
        Self { x: self.x / s, y: self.y / s, z: self.z / s }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::SampleRng;
    use wide::CmpLt;

    /// Every operation, on awkward values (zeros of both signs, tiny and huge magnitudes), equals glam's per
    /// lane bit for bit.
    #[test]
    fn lanes_round_exactly_as_glam() {
        let mut rng = SampleRng::new(1, 2, 3);
        let mut value = |k: usize| match k % 6 {
            0 => 0.0,
            1 => -0.0,
            2 => (rng.uniform() - 0.5) * 1e-20,
            3 => (rng.uniform() - 0.5) * 1e20,
            _ => rng.uniform() * 2.0 - 1.0,
        };
        let mut k = 0;
        let mut vectors = || {
            std::array::from_fn::<Vec3, 8, _>(|_| {
                k += 1;
                Vec3::new(value(k), value(k + 1), value(k + 3))
            })
        };
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        for _ in 0..50 {
            let (a, b) = (vectors(), vectors());
            let (wa, wb) = (Vec3x8::from_lanes(&a), Vec3x8::from_lanes(&b));
            let s = wa.dot(wb);
            let mask = wa.x.cmp_lt(wb.x);
            for i in 0..8 {
                let d = a[i].dot(b[i]);
                let lane = |w: Vec3x8| bits(w.lane(i));
                assert_eq!(lane(wa + wb), bits(a[i] + b[i]));
                assert_eq!(lane(wa - wb), bits(a[i] - b[i]));
                assert_eq!(lane(-wa), bits(-a[i]));
                assert_eq!(lane(wa * s), bits(a[i] * d));
                assert_eq!(lane(wa * wb), bits(a[i] * b[i]));
                assert_eq!(bits(wa.to_lanes()[i]), bits(a[i]));
                assert_eq!(lane(wa / s), bits(a[i] / d));
                assert_eq!(s.as_array_ref()[i].to_bits(), d.to_bits());
                assert_eq!(wa.length().as_array_ref()[i].to_bits(), a[i].length().to_bits());
                if a[i].length() > 0.0 {
                    assert_eq!(lane(wa.normalize()), bits(a[i].normalize()));
                }
                let chosen = if a[i].x < b[i].x { a[i] } else { b[i] };
                assert_eq!(lane(Vec3x8::select(mask, wa, wb)), bits(chosen));
            }
        }
    }
}
