//! Adaptive quadrature over a planar triangle: a degree-5 rule (Dunavant 1985, 7 points) on the triangle and on
//! its four midpoint children; where the two disagree by more than the tolerance, each child is refined with a
//! quarter of it. Visibility makes integrands discontinuous, so the refinement also stops at a node budget.

use glam::DVec3;

/// Barycentric points and weights of Dunavant's 7-point rule (exact for polynomials of degree 5).
const RULE: [([f64; 3], f64); 7] = [
    ([1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0], 0.225),
    ([0.059_715_871_789_770, 0.470_142_064_105_115, 0.470_142_064_105_115], 0.132_394_152_788_506),
    ([0.470_142_064_105_115, 0.059_715_871_789_770, 0.470_142_064_105_115], 0.132_394_152_788_506),
    ([0.470_142_064_105_115, 0.470_142_064_105_115, 0.059_715_871_789_770], 0.132_394_152_788_506),
    ([0.797_426_985_353_087, 0.101_286_507_323_456, 0.101_286_507_323_456], 0.125_939_180_544_827),
    ([0.101_286_507_323_456, 0.797_426_985_353_087, 0.101_286_507_323_456], 0.125_939_180_544_827),
    ([0.101_286_507_323_456, 0.101_286_507_323_456, 0.797_426_985_353_087], 0.125_939_180_544_827),
];

/// How far refinement may go.
#[derive(Clone, Copy, Debug)]
pub struct Refinement {
    /// Absolute tolerance of the whole triangle's integral.
    pub tolerance: f64,
    /// Deepest subdivision (4^depth leaves at most).
    pub max_depth: u32,
    /// Integrand evaluations at most.
    pub max_nodes: u64,
}

/// `∫_T f dA` over the triangle (a, b, c), and the evaluations spent (added to `nodes`). `f` returns a value per
/// channel; the tolerance applies to the sum of channels.
pub fn integrate_triangle(
    [a, b, c]: [DVec3; 3],
    f: &mut impl FnMut(DVec3) -> DVec3,
    refinement: Refinement,
    nodes: &mut u64,
) -> DVec3 {
    let whole = rule(a, b, c, f, nodes);
    refine([a, b, c], whole, refinement.tolerance, 0, f, &refinement, nodes)
}

fn refine(
    [a, b, c]: [DVec3; 3],
    whole: DVec3,
    tolerance: f64,
    depth: u32,
    f: &mut impl FnMut(DVec3) -> DVec3,
    r: &Refinement,
    nodes: &mut u64,
) -> DVec3 {
    let (ab, bc, ca) = ((a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5);
    let children = [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]];
    let parts = children.map(|[p, q, s]| rule(p, q, s, f, nodes));
    let sum: DVec3 = parts.iter().sum();
    if (sum - whole).abs().element_sum() <= tolerance || depth + 1 >= r.max_depth || *nodes >= r.max_nodes {
        return sum;
    }
    children.iter().zip(parts).map(|(&child, part)| refine(child, part, tolerance * 0.25, depth + 1, f, r, nodes)).sum()
}

fn rule(a: DVec3, b: DVec3, c: DVec3, f: &mut impl FnMut(DVec3) -> DVec3, nodes: &mut u64) -> DVec3 {
    let area = 0.5 * (b - a).cross(c - a).length();
    *nodes += RULE.len() as u64;
    RULE.iter().map(|&([u, v, w], weight)| f(a * u + b * v + c * w) * weight).sum::<DVec3>() * area
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_polynomials_and_a_peak() {
        let tri = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let r = Refinement { tolerance: 1e-12, max_depth: 12, max_nodes: 1_000_000 };
        let mut nodes = 0;
        // ∫ x² y over the unit right triangle = 1/60.
        let v = integrate_triangle(tri, &mut |p| DVec3::splat(p.x * p.x * p.y), r, &mut nodes);
        assert!((v.x - 1.0 / 60.0).abs() < 1e-14, "{v}");
        // A peak d/(r² + d²)^(3/2) at a corner, d = 10⁻³: ∫ over the quarter disk of radius 1 is
        // (π/2)(1 − d/√(1 + d²)); over the triangle, less. Check against the polar integral numerically.
        let d = 1e-3;
        let peak = |p: DVec3| DVec3::splat(d / (p.length_squared() + d * d).powf(1.5));
        let mut nodes = 0;
        let r = Refinement { tolerance: 1e-7, max_depth: 30, max_nodes: 10_000_000 };
        let v = integrate_triangle(tri, &mut |p| peak(p), r, &mut nodes);
        // Polar: ∫_0^{π/2} ∫_0^{R(φ)} d r/(r²+d²)^{3/2} dr dφ, R(φ) = 1/(cos φ + sin φ): inner = 1 − d/√(R²+d²).
        let n = 200_000;
        let polar: f64 = (0..n)
            .map(|i| {
                let phi = (i as f64 + 0.5) / n as f64 * std::f64::consts::FRAC_PI_2;
                let big_r = 1.0 / (phi.cos() + phi.sin());
                (1.0 - d / (big_r * big_r + d * d).sqrt()) * std::f64::consts::FRAC_PI_2 / n as f64
            })
            .sum();
        assert!((v.x - polar).abs() / polar < 1e-5, "{} against {polar} ({nodes} nodes)", v.x);
    }
}
