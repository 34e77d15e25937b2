//! The probe end to end. Its quadrature against Lambert's closed form; at probed points of every bundled scene
//! (under a light, in a penumbra, on a glossy surface, at grazing view), every strategy's running estimate
//! against the quadrature, and every strategy's sampling against its own pdf (chi-square) and its reported
//! densities against `pdf(ω)`. Fixed seeds: deterministic. For fresh seeds, a correct estimator fails one
//! comparison (|z| > 4, normal approximation) with probability 6.3·10⁻⁵; the chi-square tests share a
//! family-wise level of 1% (Šidák), so a correct build fails this file with probability ≲ 2%.

mod common;

use common::floor_under_light;
use glam::{DVec3, Vec3};
use illumlab::math::SampleRng;
use illumlab::math::{lambert_polygon_irradiance, luminance};
use illumlab::probe::{
    Probe, ProbePoint, ProbeRun, ProbeSettings, chi_square, chi_square_against, chi2, density, quadrature,
};
use illumlab::render::{Domain, Outcome, Reached, RenderSettings, ShadingPoint, Strategy, Target};
use illumlab::scene::{BUNDLED_SCENES, Material, load_scene};
use std::f64::consts::PI;
use std::sync::Arc;

/// Lambert: L_o = k_d/π · E at diffuse points under one square light, far, millimetres away, and at grazing
/// elevation, each within 0.1%.
#[test]
fn quadrature_matches_lambert_at_unoccluded_diffuse_points() {
    for (side, height, x) in
        [(0.5, 1.6, 0.0), (0.05, 0.002, 0.0), (0.05, 0.0005, 0.01), (0.5, 0.3, 3.0), (1.0, 1.0, 0.4)]
    {
        let f = floor_under_light(side, height, Vec3::splat(10.0), 50.0);
        let material = Material { kd: Vec3::splat(f.kd), ..Default::default() };
        let p = Vec3::new(x, 0.0, 0.1 * side);
        let sp = ShadingPoint::new(p, Vec3::Y, Vec3::new(0.3, 1.0, 0.0).normalize(), &material);
        let q = quadrature(&f.scene, &sp, 4_000_000);
        let e = lambert_polygon_irradiance(p.as_dvec3(), DVec3::Y, &f.light, 10.0);
        let exact = f.kd as f64 / PI * e;
        let rel = (q.value.x as f64 - exact).abs() / exact;
        assert!(
            rel < 1e-3,
            "side {side}, height {height}, x {x}: quadrature {} against Lambert {exact} ({rel:.2e}, {} nodes)",
            q.value.x,
            q.nodes
        );
    }
}

/// The points the checks probe: per bundled scene, the first pixel (scanning a 48×36 image) that is lit with
/// nothing in the way, one in a penumbra, a lit glossy one (the brightest under BRDF sampling, which puts its
/// light near ω_r), and a lit one seen at grazing angle; those a scene has.
fn probed_points(probe: &Probe) -> Vec<(&'static str, ProbePoint)> {
    let scene = probe.scene();
    let ctx = probe.context();
    let (mut lit, mut penumbra, mut grazing) = (None, None, None);
    let mut glossy: Option<(f64, ProbePoint)> = None;
    for y in (0..scene.camera.height).step_by(2) {
        for x in (0..scene.camera.width).step_by(2) {
            let Some(point) = probe.point((x, y)) else { continue };
            let sp = point.shading_point(scene);
            if sp.material.is_emissive() {
                continue;
            }
            let run = ProbeRun::run(&ctx, &sp, Strategy::Emitter, 64, 1, 0, 0.0);
            let count = |o: Outcome| run.outcomes[illumlab::probe::OUTCOMES.iter().position(|&x| x == o).unwrap()];
            let (hit, occluded) = (count(Outcome::Contributed), count(Outcome::Occluded));
            if hit == 0 {
                continue;
            }
            let fraction = occluded as f64 / (hit + occluded) as f64;
            if occluded == 0 && lit.is_none() {
                lit = Some(point);
            }
            if (0.2..0.8).contains(&fraction) && penumbra.is_none() {
                penumbra = Some(point);
            }
            if sp.n.dot(sp.wo) < 0.25 && occluded == 0 && grazing.is_none() {
                grazing = Some(point);
            }
            if sp.material.ks != Vec3::ZERO && sp.material.alpha > 5.0 {
                let brdf = ProbeRun::run(&ctx, &sp, Strategy::Brdf, 256, 1, 0, 0.0).mean_luminance();
                if glossy.is_none_or(|(b, _)| brdf > b) {
                    glossy = Some((brdf, point));
                }
            }
        }
    }
    [("lit", lit), ("penumbra", penumbra), ("glossy", glossy.map(|g| g.1)), ("grazing", grazing)]
        .into_iter()
        .filter_map(|(k, p)| p.map(|p| (k, p)))
        .collect()
}

fn small(name: &str) -> Arc<illumlab::scene::Scene> {
    let mut scene = load_scene(name).expect("bundled");
    scene.camera.width = 48;
    scene.camera.height = 36;
    Arc::new(scene)
}

/// Every strategy's estimate at every probed point is within 4 standard errors of the quadrature. A strategy whose
/// mean rests on fewer than 200 effective samples after 1.6·10⁶ (a hemisphere strategy under tiny bright lights:
/// its sample variance misses the tail) cannot be judged by a z-score and is skipped; the light strategies and MIS
/// never are.
#[test]
fn every_strategy_matches_the_quadrature_at_probed_points() {
    let (mut checked, mut skipped) = (0, Vec::new());
    for b in BUNDLED_SCENES {
        // occluded-light's light shows through a small hole, which the quadrature at this budget resolves too
        // coarsely to judge by (0.1639 where emitter, MIS and guided agree on 0.1548 ± 0.0005 with 2·10⁶ samples
        // each; brdf 9% above it at the glossy box): tests/guided.rs checks the strategies there against emitter.
        if b.name == "occluded-light" {
            continue;
        }
        let probe = Probe::new(small(b.name), RenderSettings::default());
        let points = probed_points(&probe);
        assert!(points.iter().any(|(k, _)| *k == "lit"), "{}: no lit point", b.name);
        for (kind, point) in points {
            let q = probe.quadrature(&point, &ProbeSettings { quadrature_nodes: 2_000_000, ..Default::default() });
            let truth = luminance(q.value) as f64;
            for strategy in Strategy::ALL {
                let sp = point.shading_point(probe.scene());
                let mut n = 20_000;
                let run = loop {
                    let run = ProbeRun::run(&probe.context(), &sp, strategy, n, 7, 0, 0.0);
                    if run.effective_samples() >= 1_000.0 || n >= 1_600_000 {
                        break run;
                    }
                    n *= 4;
                };
                assert_eq!(run.non_finite, 0);
                if run.effective_samples() < 200.0 {
                    assert!(!strategy.samples_lights() && strategy != Strategy::Mis, "{}", strategy.name());
                    skipped.push(format!("{} {kind} {}", b.name, strategy.name()));
                    continue;
                }
                let z = run.z_score(truth);
                println!(
                    "{:<10} {kind:<9} {:<22} {n:>8} est {:.6} quad {truth:.6} ({} nodes) z {z:+.2}",
                    b.name,
                    strategy.name(),
                    run.mean_luminance(),
                    q.nodes
                );
                assert!(
                    z.abs() < 4.0,
                    "{} {kind} {:?} {}: {} against the quadrature {truth} (z = {z:.2})",
                    b.name,
                    point.pixel,
                    strategy.name(),
                    run.mean_luminance()
                );
                checked += 1;
            }
        }
    }
    println!("checked {checked}, skipped {skipped:?}");
    assert!(checked >= 60, "only {checked} comparisons");
}

/// Chi-square at every probed point for every strategy (light strategies binned on their triangles), and a
/// density 4% too high on one side of the normal and 4% too low on the other fails.
#[test]
fn every_strategy_samples_its_pdf_at_probed_points() {
    let mut tests = Vec::new();
    for b in BUNDLED_SCENES {
        let probe = Probe::new(small(b.name), RenderSettings::default());
        for (kind, point) in probed_points(&probe) {
            for strategy in Strategy::ALL {
                tests.push((b.name, kind, point, strategy));
            }
        }
    }
    let level = chi2::level(tests.len());
    for (scene, kind, point, strategy) in &tests {
        let probe = Probe::new(small(scene), RenderSettings::default());
        let sp = point.shading_point(probe.scene());
        let c = chi_square(&probe.context(), &sp, *strategy, 100_000, 3);
        println!(
            "{scene:<10} {kind:<9} {:<22} {} p = {:.4} ∫p = {:.5}",
            strategy.name(),
            c.binning,
            c.p_value,
            c.integral
        );
        assert!(c.p_value >= level, "{scene} {kind} {}: p = {} < {level} ({c:?})", strategy.name(), c.p_value);
    }
    // A wrong pdf fails: cosine sampling at the Cornell box's lit point, against (1 ± 4%)·cos/π.
    let probe = Probe::new(small("cornell-box"), RenderSettings::default());
    let (_, point) = probed_points(&probe).into_iter().find(|(k, _)| *k == "lit").expect("a lit point");
    let sp = point.shading_point(probe.scene());
    let ctx = probe.context();
    let tangent = illumlab::math::Frame::from_z(sp.n).to_world(Vec3::X);
    let wrong = |w: Vec3, via: Option<Reached>| {
        Strategy::Cosine.pdf(&ctx, &sp, w, via) * if w.dot(tangent) > 0.0 { 1.04 } else { 0.96 }
    };
    let c = chi_square_against(&ctx, &sp, Strategy::Cosine, 400_000, 3, &wrong);
    assert!(c.p_value < 1e-6, "a wrong pdf passes: p = {}", c.p_value);
}

/// At every probed point, the density every strategy reports for its samples is its `pdf(ω)` there, and its
/// density over the sphere integrates to its coverage: 1, or for the light strategies the probability of picking a
/// triangle the point faces.
#[test]
fn reported_densities_are_the_pdf_and_integrate_to_the_coverage() {
    for b in BUNDLED_SCENES {
        let probe = Probe::new(small(b.name), RenderSettings::default());
        let ctx = probe.context();
        for (kind, point) in probed_points(&probe) {
            let sp = point.shading_point(probe.scene());
            for strategy in Strategy::ALL {
                let mut failed = 0;
                for k in 0..2_000 {
                    let mut rng = SampleRng::new(11, 5, k);
                    let Some(s) = strategy.sample(&ctx, &sp, &mut rng) else {
                        failed += 1;
                        continue;
                    };
                    let via = match s.target {
                        Target::Emitter { triangle, point } => Some(Reached { triangle, point }),
                        Target::Trace => illumlab::render::reached(probe.scene(), &sp, s.wi),
                    };
                    let pdf = strategy.pdf(&ctx, &sp, s.wi, via);
                    assert!(
                        (pdf - s.pdf).abs() <= 1e-4 * s.pdf,
                        "{} {kind} {}: sampled {} against pdf(ω) {pdf}",
                        b.name,
                        strategy.name(),
                        s.pdf
                    );
                    // The density sums over the light triangles the ray along ω meets. Where ω grazes the sampled
                    // triangle (cos θ_Δ < 0.01), ω's rounding in f32 moves the crossing by a hundred times more
                    // than it moves ω, and a point drawn near an edge can be missed: those draws are left out.
                    let grazing = match s.target {
                        Target::Emitter { triangle, .. } => {
                            probe.scene().triangles[triangle as usize].n.dot(-s.wi).abs() < 0.01
                        }
                        Target::Trace => false,
                    };
                    if strategy.domain() == Domain::Lights && !grazing {
                        let d = density(&ctx, &sp, strategy, s.wi);
                        assert!(
                            d >= s.pdf * (1.0 - 1e-4),
                            "{} {kind} {}: sampled {:?} at {} against the density {d} over the sphere",
                            b.name,
                            strategy.name(),
                            s.target,
                            s.pdf
                        );
                    }
                }
                let c = chi_square(&ctx, &sp, strategy, 20_000, 9);
                // The failure cell expects what the density does not cover.
                let expected_failures = 1.0 - c.integral;
                assert!(
                    (failed as f64 / 2_000.0 - expected_failures).abs() < 0.05,
                    "{} {kind} {}: {failed} of 2000 draws failed, the density covers {}",
                    b.name,
                    strategy.name(),
                    c.integral
                );
                if strategy.domain() == Domain::Hemisphere && sp.material.diffuse_probability().is_some() {
                    assert!(
                        (c.integral - 1.0).abs() < 2e-3,
                        "{} {kind} {}: ∫p dω = {}",
                        b.name,
                        strategy.name(),
                        c.integral
                    );
                }
            }
        }
    }
}
