//! Chi-square goodness-of-fit of the spherical-triangle sampler against its density 1/Ω, and of the
//! projected-solid-angle sampler against (ω·n)/Ω⊥, for small, large, thin and nearly degenerate triangles and
//! triangles at grazing elevation. A sampled direction is mapped to the point it hits on the triangle's plane,
//! where the density in area measure, `(1/Ω) cos θ_Δ / d²`, is smooth, and binned there. Fixed seeds:
//! deterministic; a correct sampler fails this file with probability 1% for a fresh seed (Šidák).

mod common;

use common::chi2::{Outcome, per_test_level, triangle_test};
use glam::{Vec2, Vec3};
use illumlab::math::SampleRng;
use illumlab::sampling::{
    ProjectedPlan, projected_triangle_pdf, sample_projected_triangle, sample_spherical_triangle,
    spherical_triangle_area, spherical_triangle_pdf,
};

const TESTS_IN_FILE: usize = 9;

/// Tests a direction sampler against its solid-angle density on triangle `tri` seen from p: each direction is
/// mapped to the point it hits on the triangle's plane, where the density is `pdf(ω) cos θ_Δ / d²`.
fn check_directions(
    name: &str,
    p: Vec3,
    tri: [Vec3; 3],
    seed: u64,
    sample: &dyn Fn(Vec2) -> Vec3,
    pdf: &dyn Fn(Vec3) -> f64,
) {
    let [a, b, c] = tri;
    let plane = (b - a).cross(c - a).normalize();
    let o = triangle_test(
        tri,
        12,
        400_000,
        seed,
        &|u: Vec2| {
            let w = sample(u);
            p + w * (plane.dot(a - p) / plane.dot(w))
        },
        &|x: Vec3| {
            let d = x - p;
            let w = d / d.length();
            pdf(w) * plane.dot(w).abs() as f64 / d.length_squared() as f64
        },
    );
    assert_fits(name, &o);
}

fn check(name: &str, p: Vec3, tri: [Vec3; 3], seed: u64) {
    let [a, b, c] = tri;
    let omega = spherical_triangle_area(p, a, b, c);
    check_directions(
        &format!("{name} (Ω = {omega:.3e} sr)"),
        p,
        tri,
        seed,
        &|u| sample_spherical_triangle(u, p, a, b, c).expect("a sample"),
        &|_| spherical_triangle_pdf(omega) as f64,
    );
}

/// The density integrates to one and the histogram fits it.
fn assert_fits(name: &str, o: &Outcome) {
    let level = per_test_level(TESTS_IN_FILE);
    eprintln!("{name}: χ² = {:.1}, dof {}, p = {:.4}, ∫pdf = {:.5}", o.statistic, o.dof, o.p_value, o.integral);
    assert!((o.integral - 1.0).abs() < 2e-3, "{name}: the density integrates to {}", o.integral);
    assert!(o.p_value > level, "{name}: p = {} < {level}", o.p_value);
}

#[test]
fn small_triangle() {
    // Ω ≈ 1.5·10⁻³ sr, above the fallback threshold of 3·10⁻⁴.
    check("small", Vec3::ZERO, [Vec3::new(-0.02, 1.0, 0.0), Vec3::new(0.03, 1.0, 0.01), Vec3::new(0.0, 1.0, 0.04)], 1);
}

#[test]
fn large_triangle() {
    check("large", Vec3::ZERO, [Vec3::new(-3.0, 0.5, -3.0), Vec3::new(3.0, 0.5, -3.0), Vec3::new(0.0, 0.5, 4.0)], 2);
}

#[test]
fn thin_triangle() {
    check("thin", Vec3::ZERO, [Vec3::new(-1.0, 1.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.03)], 3);
}

#[test]
fn nearly_degenerate_triangle() {
    // A sliver: one angle of about 0.1°.
    check("sliver", Vec3::ZERO, [Vec3::new(-1.0, 1.0, 0.0), Vec3::new(1.0, 1.0, 0.002), Vec3::new(0.95, 1.0, 0.0)], 4);
}

#[test]
fn triangle_at_grazing_elevation() {
    // Seen from a point on the floor, just above its horizon.
    check("grazing", Vec3::ZERO, [Vec3::new(3.0, 0.05, -1.0), Vec3::new(3.0, 0.05, 1.0), Vec3::new(3.0, 0.6, 0.0)], 5);
}

/// The projected sampler consumes a varying number of uniforms (rejection): each test sample seeds its own
/// stream from the tester's two uniforms.
fn check_projected(name: &str, p: Vec3, n: Vec3, tri: [Vec3; 3], seed: u64) {
    let [a, b, c] = tri;
    let ProjectedPlan::Rejection { projected, cos_max, .. } = ProjectedPlan::new(p, n, a, b, c) else {
        panic!("{name}: expected the rejection plan");
    };
    check_directions(
        &format!("projected, {name}"),
        p,
        tri,
        seed,
        &|u| {
            let mut rng = SampleRng::new(u.x.to_bits() as u64, u.y.to_bits() as u64, seed);
            sample_projected_triangle(&mut rng, p, n, tri, cos_max).expect("a sample")
        },
        &|w| projected_triangle_pdf(w.dot(n), projected) as f64,
    );
}

#[test]
fn projected_large_triangle_overhead() {
    let tri = [Vec3::new(-3.0, 0.5, -3.0), Vec3::new(3.0, 0.5, -3.0), Vec3::new(0.0, 0.5, 4.0)];
    check_projected("large", Vec3::ZERO, Vec3::Y, tri, 11);
}

#[test]
fn projected_thin_tilted_triangle() {
    let tri = [Vec3::new(-1.0, 1.0, 0.0), Vec3::new(1.0, 1.4, 0.0), Vec3::new(0.0, 1.0, 0.05)];
    check_projected("thin", Vec3::ZERO, Vec3::new(0.3, 1.0, 0.1).normalize(), tri, 12);
}

#[test]
fn projected_triangle_at_grazing_elevation() {
    // Its lowest edge 1° above the horizon: the density varies strongly across it.
    let tri = [Vec3::new(3.0, 0.052, -1.0), Vec3::new(3.0, 0.052, 1.0), Vec3::new(3.0, 1.2, 0.0)];
    check_projected("grazing", Vec3::ZERO, Vec3::Y, tri, 13);
}

#[test]
fn projected_small_triangle() {
    let tri = [Vec3::new(-0.02, 1.0, 0.0), Vec3::new(0.03, 1.0, 0.01), Vec3::new(0.0, 1.0, 0.04)];
    check_projected("small", Vec3::ZERO, Vec3::new(0.5, 1.0, 0.0).normalize(), tri, 14);
}
