//! Unbiasedness: on a diffuse floor under polygonal lights with no occluders, every strategy's mean equals the
//! closed form `L_o = k_d/π · E`, with Lambert's polygon irradiance `E = L/2 Σ Θ_i (n·γ_i)`, within 4 standard
//! errors. Fixed seeds: deterministic. For a fresh seed, each comparison (one strategy at one point) fails with
//! probability ≤ 3 × 6.3·10⁻⁵ (normal approximation, three channels); this file makes 75 of them, so a correct
//! estimator fails it with probability ≲ 1.4%. Projected-solid-angle sampling is also checked for the zero
//! variance it must have under a single unoccluded triangle.

mod common;

use common::{any_camera, estimate_with, on_surface};
use glam::{DVec3, Vec3};
use illumlab::math::lambert_polygon_irradiance;
use illumlab::render::{Heuristic, MisSettings, RenderSettings, Strategy};
use illumlab::scene::{LightSelection, Material, Scene};
use std::f64::consts::PI;

/// A floor (k_d = 0.5) under two lights: a unit square at height 1 split into a fan of four unequal triangles
/// about an off-centre point (so uniform, area and power selection differ), and a smaller, brighter triangle.
struct Setup {
    scene: Scene,
    lights: Vec<(Vec<DVec3>, Vec3)>,
    kd: f64,
}

fn setup() -> Setup {
    let square =
        [Vec3::new(-0.5, 1.0, -0.5), Vec3::new(0.5, 1.0, -0.5), Vec3::new(0.5, 1.0, 0.5), Vec3::new(-0.5, 1.0, 0.5)];
    let centre = Vec3::new(0.3, 1.0, -0.2);
    // The second light must subtend enough solid angle at the grazing point that cosine sampling hits it some
    // 30 times in the samples taken there: with a handful of hits the sample variance misses the estimator's
    // tail and a 4σ bound means nothing (a smaller light fails here with ~3 hits in 2.6·10⁷ samples).
    let small = [Vec3::new(-1.5, 0.9, 0.0), Vec3::new(-0.9, 0.9, 0.0), Vec3::new(-1.2, 0.9, 0.6)];
    let (l_square, l_small) = (Vec3::new(4.0, 3.0, 2.0), Vec3::new(20.0, 25.0, 30.0));
    let f = 1.0e3;
    let mut positions = vec![
        [Vec3::new(-f, 0.0, -f), Vec3::new(-f, 0.0, f), Vec3::new(f, 0.0, f)],
        [Vec3::new(-f, 0.0, -f), Vec3::new(f, 0.0, f), Vec3::new(f, 0.0, -f)],
    ];
    let mut ids = vec![0, 0];
    for i in 0..4 {
        positions.push([square[i], square[(i + 1) % 4], centre]);
        ids.push(1);
    }
    positions.push(small);
    ids.push(2);
    let light = |l: Vec3| Material { kd: Vec3::ZERO, ks: Vec3::ZERO, alpha: 1.0, emission: l };
    let floor = Material { kd: Vec3::splat(0.5), ks: Vec3::ZERO, alpha: 1.0, emission: Vec3::ZERO };
    let scene = Scene::new(
        "lambert",
        any_camera(),
        &positions,
        &ids,
        vec![floor, light(l_square), light(l_small)],
        vec!["floor".into(), "square".into(), "small".into()],
    )
    .expect("valid scene");
    for t in scene.triangles.iter().filter(|t| t.material > 0) {
        assert!(t.n.y < -0.99, "every light faces the floor");
    }
    let poly = |v: &[Vec3]| v.iter().map(|p| p.as_dvec3()).collect::<Vec<_>>();
    Setup { scene, lights: vec![(poly(&square), l_square), (poly(&small), l_small)], kd: 0.5 }
}

/// `k_d/π · Σ_lights E_light`, per channel.
fn closed_form(s: &Setup, p: DVec3) -> DVec3 {
    let mut e = DVec3::ZERO;
    for (poly, l) in &s.lights {
        let unit = lambert_polygon_irradiance(p, DVec3::Y, poly, 1.0);
        e += l.as_dvec3() * unit;
    }
    e * (s.kd / PI)
}

fn check(strategy: Strategy, selection: LightSelection, samples: u64) {
    let far = if strategy.samples_lights() { samples } else { samples * 64 };
    check_with(RenderSettings { strategy, light_selection: selection, ..Default::default() }, samples, far);
}

fn check_with(settings: RenderSettings, samples: u64, far_samples: u64) {
    let (strategy, selection) = (settings.strategy, settings.light_selection);
    let s = setup();
    let wo = Vec3::new(0.3, 0.8, -0.2).normalize();
    let points = [
        ("under the light", Vec3::new(0.1, 0.0, -0.05)),
        ("near the light's edge", Vec3::new(0.55, 0.0, 0.1)),
        ("far away, grazing", Vec3::new(12.0, 0.0, 3.0)),
    ];
    for (i, (label, p)) in points.into_iter().enumerate() {
        let material = &s.scene.materials[0];
        let sp = on_surface(&s.scene, p, Vec3::Y, wo, material);
        let n = if i == 2 { far_samples } else { samples };
        let est = estimate_with(&s.scene, &sp, &RenderSettings { seed: 100 + i as u64, ..settings }, n);
        let expected = closed_form(&s, p.as_dvec3());
        let z = (est.mean - expected).abs() / est.std_error;
        eprintln!(
            "{:>8} {:>7} {label:>22}: mean {:.6?} expected {:.6?} z {:.2?} rel.se {:.4}",
            strategy.name(),
            selection.name(),
            est.mean,
            expected,
            z,
            est.std_error.x / expected.x
        );
        assert_eq!(est.non_finite, 0);
        // The test has power: the standard error is small against the value.
        assert!(est.std_error.x < 0.1 * expected.x, "{label}: too few samples to test anything");
        assert!(z.max_element() < 4.0, "{} ({}) at {label}: z = {z:?}", strategy.name(), selection.name());
    }
}

#[test]
fn uniform_is_unbiased() {
    check(Strategy::Uniform, LightSelection::Power, 400_000);
}

#[test]
fn cosine_is_unbiased() {
    check(Strategy::Cosine, LightSelection::Power, 400_000);
}

#[test]
fn brdf_is_unbiased() {
    check(Strategy::Brdf, LightSelection::Power, 400_000);
}

#[test]
fn emitter_uniform_selection_is_unbiased() {
    check(Strategy::Emitter, LightSelection::Uniform, 100_000);
}

#[test]
fn emitter_area_selection_is_unbiased() {
    check(Strategy::Emitter, LightSelection::Area, 100_000);
}

#[test]
fn emitter_power_selection_is_unbiased() {
    check(Strategy::Emitter, LightSelection::Power, 100_000);
}

#[test]
fn emitter_contribution_selection_is_unbiased() {
    check(Strategy::Emitter, LightSelection::Contribution, 100_000);
}

#[test]
fn solid_angle_is_unbiased_for_every_light_selection() {
    for selection in LightSelection::ALL {
        check(Strategy::SolidAngle, selection, 100_000);
    }
}

#[test]
fn projected_solid_angle_is_unbiased_for_every_light_selection() {
    for selection in LightSelection::ALL {
        check(Strategy::ProjectedSolidAngle, selection, 100_000);
    }
}

#[test]
fn mis_is_unbiased_for_every_light_technique_and_heuristic() {
    for light in Strategy::ALL.into_iter().filter(|s| s.samples_lights()) {
        for heuristic in Heuristic::ALL {
            for samples in [[1, 1], [3, 1]] {
                let mis = MisSettings { techniques: [light, Strategy::Brdf], heuristic, samples };
                let settings = RenderSettings { strategy: Strategy::Mis, mis, ..Default::default() };
                check_with(settings, 50_000, 50_000);
            }
        }
    }
    let mis = MisSettings { techniques: [Strategy::SolidAngle, Strategy::Brdf], ..Default::default() };
    check_with(
        RenderSettings {
            strategy: Strategy::Mis,
            light_selection: LightSelection::Contribution,
            mis,
            ..Default::default()
        },
        50_000,
        50_000,
    );
}

/// Under one unoccluded triangle on a diffuse surface, projected-solid-angle sampling estimates the constant
/// (k_d/π) L Ω⊥: every sample equals the closed form, up to float error.
#[test]
fn projected_solid_angle_has_zero_variance_under_one_triangle() {
    let l = Vec3::new(3.0, 2.0, 1.0);
    let tri = [Vec3::new(-0.5, 1.0, -0.4), Vec3::new(0.6, 1.2, -0.3), Vec3::new(0.1, 0.9, 0.7)];
    let f = 50.0;
    let positions = vec![
        [Vec3::new(-f, 0.0, -f), Vec3::new(-f, 0.0, f), Vec3::new(f, 0.0, f)],
        [Vec3::new(-f, 0.0, -f), Vec3::new(f, 0.0, f), Vec3::new(f, 0.0, -f)],
        tri, // (b − a) × (c − a) points down, towards the floor
    ];
    let floor = Material { kd: Vec3::splat(0.5), ks: Vec3::ZERO, alpha: 1.0, emission: Vec3::ZERO };
    let light = Material { kd: Vec3::ZERO, ks: Vec3::ZERO, alpha: 1.0, emission: l };
    let scene =
        Scene::new("one", any_camera(), &positions, &[0, 0, 1], vec![floor, light], vec!["f".into(), "l".into()])
            .expect("valid scene");
    let poly: Vec<DVec3> = tri.iter().map(|v| v.as_dvec3()).collect();
    for p in [Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.8, 0.0, 0.5), Vec3::new(3.0, 0.0, -2.0)] {
        let sp = on_surface(&scene, p, Vec3::Y, Vec3::new(0.1, 1.0, 0.2).normalize(), &scene.materials[0]);
        let settings = RenderSettings { strategy: Strategy::ProjectedSolidAngle, ..Default::default() };
        let est = estimate_with(&scene, &sp, &settings, 20_000);
        let expected = l.as_dvec3() * (0.5 / PI) * lambert_polygon_irradiance(p.as_dvec3(), DVec3::Y, &poly, 1.0);
        let relative_sd = est.std_error * (20_000f64).sqrt() / expected;
        eprintln!("p = {p}: mean {:.6?}, expected {:.6?}, relative sd {:.2e}", est.mean, expected, relative_sd.x);
        assert!(relative_sd.max_element() < 1e-4, "variance is not zero: relative sd {relative_sd:?}");
        assert!(((est.mean - expected) / expected).abs().max_element() < 1e-4);
    }
}
