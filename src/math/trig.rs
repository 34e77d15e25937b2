//! sin and cos of a sample's angle, one lane or eight: the samplers' scalar code and their eight-lane copies
//! must give the same bits, and a library's scalar `sinf`/`cosf` (glibc's, ~40 instructions with branches, one
//! lane at a time) cannot run in eight lanes. Both compute Agner Fog's vector-class `sin_cos` (through `wide`): the
//! angle reduced to [−π/4, π/4] by a three-part multiple of π/2 (Cody & Waite), then Cephes' minimax polynomials
//! of degree 7 (sin) and 8 (cos). Within 2 ULP of sin and cos (of 1/4 below 1/4) for |x| ≤ 8π (the samplers' angles lie
//! in [−π/4, 2π)), as the test below checks against f64.

use wide::f32x8;

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
}
