//! sin and cos of a sample's angle, one lane or eight, and the f64 sin, cos, asin and acos of the spherical
//! triangle's construction and of a polygon's edge angles, one lane or four: the samplers' scalar code and their
//! eight-lane copies must give the same bits, and a library's scalar `sinf`/`cosf` (glibc's, ~40 instructions
//! with branches, one lane at a time) cannot run in eight lanes. Both compute Agner Fog's vector-class functions
//! (through `wide`). `sin_cos`: the angle reduced to [−π/4, π/4] by a three-part multiple of π/2 (Cody & Waite),
//! then Cephes' minimax polynomials of degree 7 (sin) and 8 (cos); within 2 ULP of sin and cos (of 1/4 below 1/4)
//! for |x| ≤ 8π in f32 (the samplers' angles lie in [−π/4, 2π)) and for x in [−π, 2π] in f64 (the spherical
//! triangle's angles lie in [0, 2π)). `asin` and `acos` (f64): Cephes' rational approximations, in x below
//! |x| = 0.625 and in 1 − |x| above; within 2 ULP over [−1, 1]. The tests below check these bounds against the
//! f64 library's functions.

use wide::{f32x8, f64x4};

/// `(sin x, cos x)`, lane 0 of [`sin_cos_lanes`] (the same arithmetic, bit for bit).
#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    let (s, c) = sin_cos_lanes(f32x8::splat(x));
    (s.as_array_ref()[0], c.as_array_ref()[0])
}

/// `(sin x, cos x)` in each lane.
#[inline(always)]
pub fn sin_cos_lanes(x: f32x8) -> (f32x8, f32x8) {
    x.sin_cos()
}

/// `(sin x, cos x)` in f64, lane 0 of [`sin_cos_f64_lanes`] (the same arithmetic, bit for bit).
#[inline]
pub fn sin_cos_f64(x: f64) -> (f64, f64) {
    let (s, c) = sin_cos_f64_lanes(f64x4::splat(x));
    (s.as_array_ref()[0], c.as_array_ref()[0])
}

/// `(sin x, cos x)` in each of four f64 lanes.
#[inline(always)]
pub fn sin_cos_f64_lanes(x: f64x4) -> (f64x4, f64x4) {
    x.sin_cos()
}

/// `asin x` in f64 for x in [−1, 1], lane 0 of [`asin_f64_lanes`] (the same arithmetic, bit for bit).
#[inline]
pub fn asin_f64(x: f64) -> f64 {
    asin_f64_lanes(f64x4::splat(x)).as_array_ref()[0]
}

/// `asin x` in each of four f64 lanes, x in [−1, 1].
#[inline(always)]
pub fn asin_f64_lanes(x: f64x4) -> f64x4 {
    x.asin()
}

/// `acos x` in each of four f64 lanes, x in [−1, 1] (a polygon's edge angles, four at once).
#[inline(always)]
pub fn acos_f64_lanes(x: f64x4) -> f64x4 {
    x.acos()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The error of `a` in units in the last place of the exact value, or of 1/4 where that is smaller (near a
    /// zero of sin or cos the error is measured against the angle's scale, as a direction's error is).
    fn ulps(a: f32, exact: f64) -> f64 {
        let scale = (exact.abs() as f32).max(0.25);
        let ulp = (f32::from_bits(scale.to_bits() + 1) - scale) as f64;
        (a as f64 - exact).abs() / ulp
    }

    /// Over 2²⁰ angles in [−8π, 8π] (every angle the samplers pass lies in [−π/4, 2π)): within 2 ULP of sin and
    /// cos in f64, and one lane gives what eight give, bit for bit.
    #[test]
    fn sin_and_cos_are_within_two_ulp_and_lanes_agree() {
        let n = 1 << 20;
        let mut worst: f64 = 0.0;
        for k in 0..n {
            let x = (k as f32 / n as f32 - 0.5) * 16.0 * std::f32::consts::PI;
            let (s, c) = sin_cos(x);
            worst = worst.max(ulps(s, (x as f64).sin())).max(ulps(c, (x as f64).cos()));
            let lanes = f32x8::new(std::array::from_fn(|l| x + l as f32 * 1e-3));
            let (sl, cl) = sin_cos_lanes(lanes);
            for l in 0..8 {
                let (s1, c1) = sin_cos(lanes.as_array_ref()[l]);
                assert_eq!(
                    (sl.as_array_ref()[l].to_bits(), cl.as_array_ref()[l].to_bits()),
                    (s1.to_bits(), c1.to_bits())
                );
            }
        }
        assert!(worst <= 2.0, "worst error {worst} ULP");
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
    }

    /// The error of `a` in units in the last place of the exact value (libm's, correctly rounded or within an ULP
    /// of it), or of 1/4 where that is smaller.
    fn ulps_f64(a: f64, exact: f64) -> f64 {
        let scale = exact.abs().max(0.25);
        let ulp = f64::from_bits(scale.to_bits() + 1) - scale;
        (a - exact).abs() / ulp
    }

    /// Over 2²⁰ angles in [−π, 2π] (the spherical triangle's angles lie in [0, 2π)) and 2²⁰ values in [−1, 1]
    /// (and the ends): sin, cos, asin and acos within 2 ULP of the f64 library's, asin(±1) = ±π/2, asin(0) = 0,
    /// acos(1) = 0, acos(−1) = π and acos(0) = π/2 exactly; one lane gives what four give, bit for bit.
    #[test]
    fn f64_sin_cos_asin_and_acos_are_within_two_ulp_and_lanes_agree() {
        let n = 1 << 20;
        let (mut worst_trig, mut worst_asin, mut worst_acos): (f64, f64, f64) = (0.0, 0.0, 0.0);
        for k in 0..n {
            let t = k as f64 / n as f64;
            let x = -std::f64::consts::PI + t * 3.0 * std::f64::consts::PI;
            let (s, c) = sin_cos_f64(x);
            worst_trig = worst_trig.max(ulps_f64(s, x.sin())).max(ulps_f64(c, x.cos()));
            let y = 2.0 * t - 1.0;
            worst_asin = worst_asin.max(ulps_f64(asin_f64(y), y.asin()));
            let acos = acos_f64_lanes(f64x4::splat(y)).as_array_ref()[0];
            worst_acos = worst_acos.max(ulps_f64(acos, y.acos()));
            let xs = f64x4::new(std::array::from_fn(|l| x + l as f64 * 1e-3));
            let ys = f64x4::new(std::array::from_fn(|l| (y + l as f64 * 1e-4).min(1.0)));
            let ((sl, cl), al) = (sin_cos_f64_lanes(xs), asin_f64_lanes(ys));
            for l in 0..4 {
                let (s1, c1) = sin_cos_f64(xs.as_array_ref()[l]);
                let a1 = asin_f64(ys.as_array_ref()[l]);
                assert_eq!(sl.as_array_ref()[l].to_bits(), s1.to_bits());
                assert_eq!(cl.as_array_ref()[l].to_bits(), c1.to_bits());
                assert_eq!(al.as_array_ref()[l].to_bits(), a1.to_bits());
            }
        }
        assert!(worst_trig <= 2.0, "sin/cos: worst error {worst_trig} ULP");
        assert!(worst_asin <= 2.0, "asin: worst error {worst_asin} ULP");
        assert!(worst_acos <= 2.0, "acos: worst error {worst_acos} ULP");
        let half_pi = std::f64::consts::FRAC_PI_2;
        assert_eq!((asin_f64(1.0), asin_f64(-1.0), asin_f64(0.0)), (half_pi, -half_pi, 0.0));
        let acos = acos_f64_lanes(f64x4::new([1.0, -1.0, 0.0, 0.5])).to_array();
        assert_eq!(acos[..3], [0.0, std::f64::consts::PI, half_pi]);
    }
}
