//! Chi-square goodness-of-fit of every sampler against its own density (the (sample, pdf) pairs must agree), and
//! the density integrates to one. Fixed seeds: deterministic. With a fresh seed, a correct implementation would
//! fail this file with probability 1% (Šidák-corrected over its tests).

mod common;

use common::chi2::{SphereBins, discrete_test, per_test_level, triangle_test};
use glam::{Vec2, Vec3};
use illumlab::sampling::{
    DiscreteDistribution, cosine_hemisphere_pdf, phong_lobe_pdf, sample_cosine_hemisphere, sample_phong_lobe,
    sample_uniform_hemisphere, sample_uniform_triangle, uniform_hemisphere_pdf, uniform_triangle_pdf_area,
};
use illumlab::scene::Material;

const TESTS_IN_FILE: usize = 10;
const SAMPLES: u64 = 1_000_000;

fn check(name: &str, o: common::chi2::Outcome) {
    let level = per_test_level(TESTS_IN_FILE);
    eprintln!("{name}: χ² = {:.1}, dof = {}, p = {:.4}, ∫pdf = {:.6}", o.statistic, o.dof, o.p_value, o.integral);
    assert!((o.integral - 1.0).abs() < 1e-3, "{name}: the pdf integrates to {}", o.integral);
    assert!(o.p_value > level, "{name}: χ² = {} with {} dof, p = {} < {level}", o.statistic, o.dof, o.p_value);
}

fn hemisphere_bins() -> SphereBins {
    SphereBins { axis: Vec3::Z, cos_min: 0.0, res_cos: 20, res_phi: 40 }
}

#[test]
fn uniform_hemisphere() {
    let o = hemisphere_bins().test(
        SAMPLES,
        1,
        &|u| Some(sample_uniform_hemisphere(u)),
        &|w| if w.z >= 0.0 { uniform_hemisphere_pdf() as f64 } else { 0.0 },
        8,
    );
    check("uniform hemisphere", o);
}

#[test]
fn cosine_hemisphere() {
    let o = hemisphere_bins().test(
        SAMPLES,
        2,
        &|u| Some(sample_cosine_hemisphere(u)),
        &|w| cosine_hemisphere_pdf(w.z) as f64,
        8,
    );
    check("cosine hemisphere", o);
}

/// The Phong lobe about its axis; the cap is narrowed with α so that the bins resolve the lobe
/// (outside the cap the density holds less than e⁻³⁰ of the mass).
fn phong_lobe(alpha: f32, seed: u64) {
    let cos_min = (1.0 - 30.0 / (alpha as f64 + 1.0)).max(0.0);
    let bins = SphereBins { axis: Vec3::Z, cos_min, res_cos: 20, res_phi: 20 };
    let o = bins.test(SAMPLES, seed, &|u| Some(sample_phong_lobe(u, alpha)), &|w| phong_lobe_pdf(w.z, alpha) as f64, 8);
    check(&format!("Phong lobe α = {alpha}"), o);
}

#[test]
fn phong_lobe_alpha_0() {
    phong_lobe(0.0, 3);
}

#[test]
fn phong_lobe_alpha_1() {
    phong_lobe(1.0, 4);
}

#[test]
fn phong_lobe_alpha_50() {
    phong_lobe(50.0, 5);
}

#[test]
fn phong_lobe_alpha_10000() {
    phong_lobe(1e4, 6);
}

/// The full BRDF-sampling mixture (Bernoulli lobe choice with the uniform reused) over the whole sphere: the
/// lobe around ω_r reaches below the surface, and those directions are part of the density too.
#[test]
fn phong_brdf_mixture() {
    let m = Material { kd: Vec3::new(0.3, 0.4, 0.5), ks: Vec3::new(0.5, 0.4, 0.3), alpha: 20.0, emission: Vec3::ZERO };
    let wo = Vec3::new(60f32.to_radians().sin(), 0.0, 60f32.to_radians().cos());
    let bins = SphereBins { axis: Vec3::Z, cos_min: -1.0, res_cos: 40, res_phi: 40 };
    let o = bins.test(SAMPLES, 7, &|u| m.sample_brdf(Vec3::Z, wo, u), &|w| m.pdf_brdf(Vec3::Z, wo, w) as f64, 8);
    check("Phong BRDF mixture", o);
}

/// Grazing ω_o: most of the specular lobe lies below the surface.
#[test]
fn phong_brdf_mixture_grazing() {
    let m = Material { kd: Vec3::splat(0.2), ks: Vec3::splat(0.7), alpha: 5.0, emission: Vec3::ZERO };
    let wo = Vec3::new(0.999, 0.0, 0.0447).normalize();
    let bins = SphereBins { axis: Vec3::Z, cos_min: -1.0, res_cos: 40, res_phi: 40 };
    let o = bins.test(SAMPLES, 8, &|u| m.sample_brdf(Vec3::Z, wo, u), &|w| m.pdf_brdf(Vec3::Z, wo, w) as f64, 8);
    check("Phong BRDF mixture, grazing ω_o", o);
}

#[test]
fn uniform_triangle_point() {
    // A thin, tilted triangle.
    let tri = [Vec3::new(0.1, -0.2, 0.3), Vec3::new(2.0, 0.5, -0.7), Vec3::new(0.4, 0.3, 0.9)];
    let area = 0.5 * (tri[1] - tri[0]).cross(tri[2] - tri[0]).length();
    let o = triangle_test(tri, 16, SAMPLES, 9, &|u: Vec2| sample_uniform_triangle(u, tri[0], tri[1], tri[2]), &|_| {
        uniform_triangle_pdf_area(area) as f64
    });
    check("uniform point on a triangle", o);
}

#[test]
fn light_selection_alias_table() {
    // 600 emitter triangles (Veach's spheres have hundreds) whose weights span six orders of magnitude, with zeros.
    let weights: Vec<f64> =
        (0..600).map(|i| if i % 7 == 3 { 0.0 } else { 10f64.powf((i as f64 * 0.618).fract() * 6.0 - 3.0) }).collect();
    let total: f64 = weights.iter().sum();
    let probabilities: Vec<f64> = weights.iter().map(|w| w / total).collect();
    let d = DiscreteDistribution::new(&weights).unwrap();
    check("light selection p_Δ (alias table)", discrete_test(&probabilities, SAMPLES, 10, &|u| d.sample(u)));
}
