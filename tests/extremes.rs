//! Numerical stability at the extremes: Phong exponents from 0 to 10⁶, grazing ω_o, shading points touching a
//! light and 10⁴ away, a light of area 10⁻¹⁰, degenerate triangles, k_d = k_s = 0. Every strategy must give
//! finite, non-negative samples (none dropped) and not panic.

mod common;

use common::{any_camera, estimate_with, on_surface, quad};
use glam::Vec3;
use illumlab::render::{Film, Heuristic, MisSettings, RenderSettings, Renderer, Strategy};
use illumlab::scene::{Camera, LightSelection, Material, Scene, TileLights};

const ALPHAS: [f32; 5] = [0.0, 1e-3, 1.0, 1e3, 1e6];

fn materials() -> Vec<Material> {
    let mut m = Vec::new();
    for alpha in ALPHAS {
        for (kd, ks) in [(0.5, 0.5), (0.0, 1.0), (1.0, 0.0), (0.0, 0.0), (0.9, 0.9)] {
            m.push(Material { kd: Vec3::splat(kd), ks: Vec3::splat(ks), alpha, emission: Vec3::ZERO });
        }
    }
    m
}

/// A floor reaching 2·10⁴ out, a unit light at height 1, a light of area 10⁻¹⁰, and degenerate triangles
/// (repeated and collinear vertices).
fn scene(camera: Camera) -> Scene {
    let f = 2.0e4;
    let mut positions: Vec<[Vec3; 3]> =
        quad(Vec3::new(-f, 0.0, -f), Vec3::new(-f, 0.0, f), Vec3::new(f, 0.0, f), Vec3::new(f, 0.0, -f)).to_vec();
    let mut ids = vec![0, 0];
    let light = quad(
        Vec3::new(-0.5, 1.0, -0.5),
        Vec3::new(0.5, 1.0, -0.5),
        Vec3::new(0.5, 1.0, 0.5),
        Vec3::new(-0.5, 1.0, 0.5),
    );
    positions.extend(light);
    ids.extend([1, 1]);
    // Area 10⁻¹⁰: legs of √2·10⁻⁵, facing down.
    let s = 2.0f32.sqrt() * 1e-5;
    positions.push([Vec3::new(2.0, 0.5, 0.0), Vec3::new(2.0 + s, 0.5, 0.0), Vec3::new(2.0, 0.5, s)]);
    ids.push(2);
    // A light standing on the floor: its lower edge touches the shading points' plane (it faces +x).
    positions.push([Vec3::new(-3.0, 0.0, -0.5), Vec3::new(-3.0, 0.6, 0.0), Vec3::new(-3.0, 0.0, 0.5)]);
    ids.push(1);
    positions.push([Vec3::new(1.0, 0.2, 1.0); 3]);
    positions.push([Vec3::new(0.0, 0.3, 0.0), Vec3::new(1.0, 0.3, 0.0), Vec3::new(2.0, 0.3, 0.0)]);
    ids.extend([1, 2]);
    let emitter = |l: f32| Material { kd: Vec3::ZERO, ks: Vec3::ZERO, alpha: 1.0, emission: Vec3::splat(l) };
    let mats = vec![Material { kd: Vec3::splat(0.5), ..Default::default() }, emitter(10.0), emitter(1e9)];
    let names = vec!["floor".into(), "light".into(), "tiny light".into()];
    let scene = Scene::new("extremes", camera, &positions, &ids, mats, names).expect("valid scene");
    assert!(scene.warnings.iter().any(|w| w.contains("2 degenerate")), "{:?}", scene.warnings);
    let tiny = scene.triangles.iter().find(|t| t.material == 2).expect("the tiny light is kept");
    // f32 vertices at magnitude 2 have ULPs of 2.4·10⁻⁷ against legs of 1.4·10⁻⁵: a few percent of area.
    assert!((tiny.area / 1e-10 - 1.0).abs() < 0.05 && tiny.n.y < 0.0, "area {}", tiny.area);
    scene
}

/// Every strategy with every light selection, and MIS with every light technique and heuristic.
fn all_settings() -> Vec<RenderSettings> {
    let mut out = Vec::new();
    for selection in LightSelection::ALL {
        for strategy in Strategy::ALL.into_iter().filter(|s| *s != Strategy::Mis) {
            out.push(RenderSettings { strategy, light_selection: selection, seed: 5, ..Default::default() });
        }
        for light in Strategy::ALL.into_iter().filter(|s| s.samples_lights()) {
            for heuristic in Heuristic::ALL {
                let mis = MisSettings { techniques: [light, Strategy::Brdf], heuristic, samples: [2, 1] };
                out.push(RenderSettings {
                    strategy: Strategy::Mis,
                    light_selection: selection,
                    seed: 5,
                    mis,
                    ..Default::default()
                });
            }
        }
    }
    out
}

#[test]
fn every_strategy_is_finite_at_the_extremes() {
    let scene = scene(any_camera());
    let grazing = Vec3::new(1.0, 1e-6, 0.3).normalize();
    let normal_view = Vec3::new(0.2, 0.9, 0.1).normalize();
    let points = [
        ("under the light", Vec3::new(0.1, 0.0, 0.0), normal_view),
        ("grazing ω_o", Vec3::new(0.1, 0.0, 0.0), grazing),
        ("10⁻⁴ below the light", Vec3::new(0.2, 1.0 - 1e-4, 0.1), normal_view),
        ("on the light's plane beside it", Vec3::new(0.5 + 1e-4, 1.0, 0.0), normal_view),
        ("on the light's own surface", Vec3::new(0.0, 1.0, 0.0), -normal_view),
        ("10⁴ away", Vec3::new(1e4, 0.0, 0.0), normal_view),
        ("10⁴ away, grazing", Vec3::new(1e4, 0.0, 0.0), Vec3::new(-1.0, 1e-5, 0.0).normalize()),
        ("under the tiny light", Vec3::new(2.0, 0.0, 0.0), normal_view),
        ("at the foot of the standing light", Vec3::new(-3.0 + 1e-4, 0.0, 0.0), normal_view),
    ];
    let materials = materials();
    let mut checked = 0;
    for (label, p, wo) in points {
        // The floor's normal is +y; at the light the geometric normal is −y.
        let n = if p.y >= 1.0 - 1e-3 { -Vec3::Y } else { Vec3::Y };
        for m in &materials {
            let sp = on_surface(&scene, p, n, wo, m);
            for settings in all_settings() {
                let e = estimate_with(&scene, &sp, &settings, 64);
                assert_eq!(e.non_finite, 0, "{label}, α = {}, {settings:?}: non-finite samples", m.alpha);
                assert!(e.mean.is_finite() && e.mean.min_element() >= 0.0, "{label}: mean {:?}", e.mean);
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 9 * 25 * all_settings().len());
}

#[test]
fn renders_of_extreme_scenes_drop_nothing() {
    // Cameras far away and close to the light, looking at grazing angles.
    let cameras = [
        Camera {
            eye: Vec3::new(0.0, 0.5, 3.0),
            target: Vec3::new(0.0, 0.5, 0.0),
            up: Vec3::Y,
            fov_y: 60.0,
            width: 16,
            height: 12,
        },
        Camera { eye: Vec3::new(1e4, 1.0, 0.0), target: Vec3::ZERO, up: Vec3::Y, fov_y: 1.0, width: 16, height: 12 },
        Camera {
            eye: Vec3::new(0.0, 1.0 - 1e-4, 0.0),
            target: Vec3::new(1.0, 0.0, 0.0),
            up: Vec3::Y,
            fov_y: 120.0,
            width: 16,
            height: 12,
        },
    ];
    for camera in cameras {
        let scene = std::sync::Arc::new(scene(camera));
        for settings in all_settings() {
            let mut renderer = Renderer::new(scene.clone(), settings);
            let mut film = Film::new(camera.width, camera.height);
            let stats = renderer.render_pass(&mut film, 0, 2, &|| false);
            assert_eq!(stats.non_finite, 0, "{settings:?}: non-finite samples");
            assert!(film.means().iter().all(|c| c.is_finite() && c.min_element() >= 0.0));
        }
    }
}

#[test]
fn scene_without_triangles_renders_black() {
    let scene = Scene::new("empty", any_camera(), &[], &[], vec![], vec![]).expect("an empty scene is valid");
    assert!(scene.warnings.iter().any(|w| w.contains("no emitter")));
    let mut renderer = Renderer::new(std::sync::Arc::new(scene), RenderSettings::default());
    let mut film = Film::new(8, 8);
    renderer.render_pass(&mut film, 0, 2, &|| false);
    assert!(film.means().iter().all(|c| *c == Vec3::ZERO));
}

/// The probe at the same extreme points, for every strategy and every α, black materials included: its
/// quadrature, running estimate, maps and chi-square test give finite numbers and do not panic.
#[test]
fn the_probe_is_finite_at_the_extremes() {
    use illumlab::probe::{Maps, ProbeRun, chi_square, quadrature};
    use illumlab::render::SampleContext;
    use illumlab::scene::EmitterSampler;
    let scene = scene(any_camera());
    let emitters = EmitterSampler::new(&scene, LightSelection::Power);
    let mis = MisSettings::default();
    let tile = &TileLights::NONE;
    let ctx = SampleContext { scene: &scene, emitters: emitters.as_ref(), mis: &mis, state: None, guide: None, tile };
    let view = Vec3::new(0.2, 0.9, 0.1).normalize();
    let points = [
        (Vec3::new(0.1, 0.0, 0.0), Vec3::Y, Vec3::new(1.0, 1e-6, 0.3).normalize()),
        (Vec3::new(0.2, 1.0 - 1e-4, 0.1), Vec3::Y, view),
        (Vec3::new(0.0, 1.0, 0.0), -Vec3::Y, -view),
        (Vec3::new(1e4, 0.0, 0.0), Vec3::Y, Vec3::new(-1.0, 1e-5, 0.0).normalize()),
        (Vec3::new(2.0, 0.0, 0.0), Vec3::Y, view),
        (Vec3::new(-3.0 + 1e-4, 0.0, 0.0), Vec3::Y, view),
    ];
    let materials: Vec<Material> = materials().into_iter().filter(|m| m.kd == m.ks || m.kd.x == 0.0).collect();
    for (p, n, wo) in points {
        for m in &materials {
            let sp = on_surface(&scene, p, n, wo, m);
            let q = quadrature(&scene, &sp, 20_000);
            assert!(
                q.value.is_finite() && q.value.min_element() >= 0.0,
                "{p}, α = {}: quadrature {}",
                m.alpha,
                q.value
            );
            let truth = illumlab::math::luminance(q.value);
            for strategy in Strategy::ALL {
                let what = format!("{p}, α = {}, k_d {}, {}", m.alpha, m.kd.x, strategy.name());
                let run = ProbeRun::run(&ctx, &sp, strategy, 64, 1, 64, truth);
                assert_eq!(run.non_finite, 0, "{what}");
                assert!(run.mean().is_finite() && run.std_error().is_finite(), "{what}");
                assert!(!run.relative_variance(truth as f64).is_nan() && !run.z_score(truth as f64).is_nan(), "{what}");
                let maps = Maps::new(&ctx, &sp, strategy, truth, 12);
                assert!(
                    maps.density.iter().chain(&maps.integrand).all(|v| v.is_nan() || (v.is_finite() && *v >= 0.0)),
                    "{what}"
                );
                let c = chi_square(&ctx, &sp, strategy, 300, 2);
                assert!((0.0..=1.0).contains(&c.p_value) && c.integral.is_finite(), "{what}: {c:?}");
            }
        }
    }
}
