//! Which estimator wins on each glossy ramp of the bundled `default` scene, at equal rays, measuring the
//! estimator alone: shading points are fixed (the first hits of pixel centres on each slab, no pixel jitter,
//! so no pixel-footprint noise), each point's truth is the probe's quadrature (visibility traced), and the error
//! of one sample is `(Y − Y_ref)²/Y_ref²` on luminance. relMSE at one ray is that times the rays one sample
//! casts (MIS casts two), averaged over the slab's points; the table gives it for several seeds (the spread is
//! the interval) and the ratio of the best MIS to each strategy. Prints markdown; asserts nothing.
//! `cargo bench --bench ramps` (all cores).

use illumlab::math::{SampleRng, luminance};
use illumlab::probe::{ProbePoint, quadrature};
use illumlab::render::{Heuristic, MisSettings, RenderSettings, Strategy, estimate_direct};
use illumlab::scene::{EmitterSampler, LightSelection, load_scene};
use rayon::prelude::*;
use std::time::Instant;

const SLABS: [&str; 4] = ["slab_a1", "slab_a30", "slab_a300", "slab_a3000"];
/// How much to measure: `cargo bench` measures, `cargo test --all-targets` (no `--bench`) only checks that it runs.
#[derive(Clone, Copy)]
struct Budget {
    points_per_slab: usize,
    samples: u64,
    seeds: u64,
}

fn configurations() -> Vec<(String, RenderSettings)> {
    let single = |s: Strategy, light_selection: LightSelection| {
        let name = format!("{} ({})", s.name(), light_selection.name());
        (name, RenderSettings { strategy: s, light_selection, ..Default::default() })
    };
    let mis = |light: Strategy, light_selection: LightSelection| {
        let mis = MisSettings { techniques: [light, Strategy::Brdf], heuristic: Heuristic::Power, samples: [1, 1] };
        let name = format!("mis ({} + brdf, {})", light.name(), light_selection.name());
        (name, RenderSettings { strategy: Strategy::Mis, mis, light_selection, ..Default::default() })
    };
    let (power, contribution) = (LightSelection::Power, LightSelection::Contribution);
    vec![
        single(Strategy::Brdf, power),
        single(Strategy::ProjectedSolidAngle, power),
        mis(Strategy::Emitter, power),
        mis(Strategy::SolidAngle, power),
        mis(Strategy::ProjectedSolidAngle, power),
        mis(Strategy::SolidAngle, contribution),
        mis(Strategy::ProjectedSolidAngle, contribution),
        single(Strategy::BrdfPolygon, power),
        single(Strategy::BrdfPolygon, contribution),
        mis(Strategy::BrdfPolygon, power),
        mis(Strategy::BrdfPolygon, contribution),
    ]
}

fn main() {
    let budget = if std::env::args().any(|a| a == "--bench") {
        Budget { points_per_slab: 48, samples: 20_000, seeds: 4 }
    } else {
        Budget { points_per_slab: 2, samples: 100, seeds: 1 }
    };
    let Budget { points_per_slab, samples, seeds } = budget;
    let scene = load_scene("default").expect("bundled scene");
    let camera = scene.camera;
    let start = Instant::now();
    // Points on each slab: pixel centres on a coarse grid, every k-th of those that see the slab.
    let mut points: Vec<Vec<(ProbePoint, f64)>> = Vec::new();
    for slab in SLABS {
        let material = scene.material_names.iter().position(|m| m == slab).expect("slab material") as u32;
        let candidates: Vec<ProbePoint> = (0..camera.height)
            .step_by(3)
            .flat_map(|y| (0..camera.width).step_by(3).map(move |x| (x, y)))
            .filter_map(|pixel| ProbePoint::at_pixel(&scene, &camera, pixel))
            .filter(|p| p.material == material)
            .collect();
        let stride = (candidates.len() / points_per_slab).max(1);
        let chosen: Vec<ProbePoint> = candidates.into_iter().step_by(stride).take(points_per_slab).collect();
        let with_truth: Vec<(ProbePoint, f64)> = chosen
            .into_par_iter()
            .map(|p| {
                let q = quadrature(&scene, &p.shading_point(&scene), 2_000_000);
                (p, luminance(q.value) as f64)
            })
            .filter(|(_, y)| *y > 1e-6)
            .collect();
        points.push(with_truth);
    }
    eprintln!("points and quadratures in {:.1} s", start.elapsed().as_secs_f64());

    println!("\n### default, fixed shading points, {samples} samples × {seeds} seeds per point\n");
    println!(
        "relMSE of a one-ray estimate, `E[(Y − Y_ref)²]/Y_ref² × rays per sample`, mean over each slab's points \
         (lower is better); min–max over the seeds in brackets\n"
    );
    let header: Vec<String> = SLABS.iter().zip(&points).map(|(s, p)| format!("{s} ({} points)", p.len())).collect();
    println!("| strategy | rays/sample | {} |", header.join(" | "));
    println!("|---|---:|{}", "---:|".repeat(SLABS.len()));
    let mut table: Vec<(String, Vec<[f64; 3]>)> = Vec::new();
    for (name, settings) in configurations() {
        let emitters = EmitterSampler::new(&scene, settings.light_selection);
        let mut cells = Vec::new();
        let mut rays_per_sample = 0.0;
        for slab_points in &points {
            let per_seed: Vec<(f64, f64)> = (0..seeds)
                .map(|seed| {
                    let (sum, rays): (f64, u64) = slab_points
                        .par_iter()
                        .map(|(p, truth)| {
                            let sp = p.shading_point(&scene);
                            let settings = RenderSettings { seed: 1000 * seed + p.pixel.0 as u64, ..settings };
                            let (mut sq, mut rays) = (0.0, 0u64);
                            for i in 0..samples {
                                let mut rng = SampleRng::new(settings.seed, p.pixel.1 as u64, i);
                                let v = estimate_direct(&scene, &sp, &settings, emitters.as_ref(), &mut rng, &mut rays);
                                let y = if v.is_finite() { luminance(v) as f64 } else { 0.0 };
                                sq += (y - truth).powi(2);
                            }
                            (sq / samples as f64 / (truth * truth), rays)
                        })
                        .reduce(|| (0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
                    let rays = rays as f64 / (samples as f64 * slab_points.len() as f64);
                    (sum / slab_points.len() as f64, rays)
                })
                .collect();
            rays_per_sample = per_seed[0].1;
            let values: Vec<f64> = per_seed.iter().map(|(v, r)| v * r).collect();
            let mean = values.iter().sum::<f64>() / values.len() as f64;
            let (lo, hi) = values.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &v| (lo.min(v), hi.max(v)));
            cells.push([mean, lo, hi]);
        }
        let text: Vec<String> =
            cells.iter().map(|[m, lo, hi]| format!("{} [{}–{}]", sig(*m), sig(*lo), sig(*hi))).collect();
        println!("| {name} | {rays_per_sample:.2} | {} |", text.join(" | "));
        table.push((name, cells));
    }
    // The best MIS per slab, against each strategy: > 1 means the strategy has the lower error.
    println!("\nbest MIS per slab ÷ strategy (relMSE at equal rays; > 1: the strategy wins); range over seeds\n");
    println!("| strategy | {} |", SLABS.join(" | "));
    println!("|---|{}", "---:|".repeat(SLABS.len()));
    let best: Vec<(usize, [f64; 3])> = (0..SLABS.len())
        .map(|s| {
            table
                .iter()
                .enumerate()
                .filter(|(_, (n, _))| n.starts_with("mis (") && !n.contains("brdf-polygon"))
                .map(|(i, (_, c))| (i, c[s]))
                .min_by(|a, b| a.1[0].total_cmp(&b.1[0]))
                .expect("an MIS row")
        })
        .collect();
    for (name, cells) in &table {
        let text: Vec<String> = cells
            .iter()
            .zip(&best)
            .map(|(c, (i, b))| {
                // The ratio's range: the best MIS's worst seed against this strategy's best, and back.
                format!("{:.2} [{:.2}–{:.2}] (vs {})", b[0] / c[0], b[1] / c[2], b[2] / c[1], table[*i].0)
            })
            .collect();
        println!("| {name} | {} |", text.join(" | "));
    }
    grazing_table(budget);
    eprintln!("done in {:.1} s", start.elapsed().as_secs_f64());
}

/// Three significant digits.
fn sig(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    if v.abs() >= 1e-3 { format!("{v:.digits$}") } else { format!("{v:.2e}") }
}

/// Grazing views, where the isotropic LTC (fitted to the lobe alone) ignores that `(ω·n)` cuts the lobe: a glossy
/// floor (k_d = 0.2, k_s = 0.6) and a 0.6 m triangle light 1 m away centred on ω_r, for views from 0° to 89°.
/// The truth is the closed form (Lambert plus Arvo's moment); relMSE at one ray as above, one point per view.
fn grazing_table(Budget { samples, seeds, .. }: Budget) {
    use glam::{DVec3, Vec3};
    use illumlab::math::{lambert_polygon_irradiance, phong_polygon_moment, reflect};
    use illumlab::render::ShadingPoint;
    use illumlab::scene::{Camera, Material, Scene};
    let camera =
        Camera { eye: Vec3::new(0.0, 1.0, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_y: 40.0, width: 8, height: 8 };
    println!(
        "\n### A glossy floor under a triangle light centred on ω_r, by view angle ({samples} samples × {seeds} seeds)\n"
    );
    println!("relMSE of a one-ray estimate (lower is better); min–max over the seeds\n");
    println!("| α | view | brdf-polygon | mis (projected-solid-angle + brdf) | mis ÷ brdf-polygon |");
    println!("|---:|---:|---:|---:|---:|");
    for alpha in [30.0f32, 300.0, 3000.0] {
        for view in [0.0f32, 30.0, 60.0, 80.0, 89.0] {
            let v = view.to_radians();
            let wo = Vec3::new(v.sin(), v.cos(), 0.0);
            let wr = reflect(wo, Vec3::Y);
            let (u, w) = (Vec3::Z, wr.cross(Vec3::Z).normalize());
            let light = [wr + u * 0.3 + w * 0.05, wr - u * 0.25 + w * 0.2, wr - u * 0.05 - w * 0.3];
            // The light faces the shading point at the origin.
            let n = (light[1] - light[0]).cross(light[2] - light[0]);
            let light = if n.dot(-light[0]) < 0.0 { [light[0], light[2], light[1]] } else { light };
            let f = 1e3;
            let positions = vec![
                [Vec3::new(-f, 0.0, -f), Vec3::new(-f, 0.0, f), Vec3::new(f, 0.0, f)],
                [Vec3::new(-f, 0.0, -f), Vec3::new(f, 0.0, f), Vec3::new(f, 0.0, -f)],
                light,
            ];
            let floor = Material { kd: Vec3::splat(0.2), ks: Vec3::splat(0.6), alpha, emission: Vec3::ZERO };
            let emitter = Material { kd: Vec3::ZERO, ks: Vec3::ZERO, alpha: 1.0, emission: Vec3::ONE };
            let names = vec!["floor".into(), "light".into()];
            let Ok(scene) = Scene::new("grazing", camera, &positions, &[0, 0, 1], vec![floor, emitter], names) else {
                continue;
            };
            // Just above the floor, so that the floor does not shadow a light that dips below the horizon.
            let p = Vec3::new(0.0, 1e-4, 0.0);
            let sp = ShadingPoint::new(p, Vec3::Y, wo, &scene.materials[0]);
            let poly: Vec<DVec3> = light.iter().map(|x| x.as_dvec3()).collect();
            let (pd, wrd) = (p.as_dvec3(), wr.as_dvec3().normalize());
            let truth = 0.2 / std::f64::consts::PI * lambert_polygon_irradiance(pd, DVec3::Y, &poly, 1.0)
                + 0.6 * (alpha as f64 + 1.0) / std::f64::consts::TAU
                    * phong_polygon_moment(pd, DVec3::Y, wrd, alpha as u32, &poly);
            let rel = |settings: RenderSettings| -> [f64; 3] {
                let emitters = EmitterSampler::new(&scene, settings.light_selection);
                let values: Vec<f64> = (0..seeds)
                    .into_par_iter()
                    .map(|seed| {
                        let (mut sq, mut rays) = (0.0, 0u64);
                        for i in 0..samples {
                            let mut rng = SampleRng::new(seed, 7, i);
                            let v = estimate_direct(&scene, &sp, &settings, emitters.as_ref(), &mut rng, &mut rays);
                            let y = if v.is_finite() { v.x as f64 } else { 0.0 };
                            sq += (y - truth).powi(2);
                        }
                        sq / samples as f64 / (truth * truth) * rays as f64 / samples as f64
                    })
                    .collect();
                let mean = values.iter().sum::<f64>() / values.len() as f64;
                let (lo, hi) = values.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &v| (lo.min(v), hi.max(v)));
                [mean, lo, hi]
            };
            let polygon = rel(RenderSettings { strategy: Strategy::BrdfPolygon, ..Default::default() });
            let mis = MisSettings { techniques: [Strategy::ProjectedSolidAngle, Strategy::Brdf], ..Default::default() };
            let mis = rel(RenderSettings { strategy: Strategy::Mis, mis, ..Default::default() });
            let cell = |c: [f64; 3]| format!("{} [{}–{}]", sig(c[0]), sig(c[1]), sig(c[2]));
            println!("| {alpha} | {view}° | {} | {} | {:.2} |", cell(polygon), cell(mis), mis[0] / polygon[0]);
        }
    }
}
