//! Raw BVH throughput: closest-hit and occlusion rays per second on the bundled scenes, with the rays an
//! integrator would trace (eight samples in each of 8 192 pixels spread over the image: camera rays, then
//! shadow segments from the hit points to points on the lights), traced one at a time; the same shadow rays
//! skipping their light's convex emitter group, as the integrator traces them; the same shadow rays eight at
//! a time (a pixel's, one per lane), and camera rays through each pixel's cone of candidate
//! triangles, as the integrator traces them; and, in the same run, the rays per second of the `emitter`
//! integrator itself (passes of 32 samples per pixel over the scene's image), so the rates compare under the
//! same machine load.
//!
//! After the criterion rows, unless a filter is given, the integrator's share of the raw rate is measured in
//! rounds that alternate the raw rays (camera and shadow rays one at a time, as a mix) with an integrator pass,
//! each timed by its thread's CPU clock: the machine's load drifts over seconds, so a ratio of two rows taken
//! a minute apart moves by up to ±20%, where the ratio within a round holds still.

use cpu_time::ThreadTime;
use criterion::{Criterion, SamplingMode, Throughput, criterion_group};
use glam::Vec3;
use illumlab::math::{SampleRng, Vec3x8};
use illumlab::render::{Film, RenderSettings, Renderer, SEGMENT_END, Strategy, shadow_ray_ends};
use illumlab::sampling::sample_uniform_triangle;
use illumlab::scene::{EmitterSampler, LightSelection, SKIP_NONE, Scene, load_scene};
use std::hint::black_box;

const RAYS: usize = 1 << 16;
const PER_PIXEL: usize = 8;

struct Workload {
    primary: Vec<(Vec3, Vec3)>,
    /// Segments `o + t·d`, 0 < t < [`SEGMENT_END`], from a hit point to a point on a light, as the integrator
    /// traces them (both ends moved off their surfaces).
    shadow: Vec<(Vec3, Vec3)>,
    /// Per shadow segment, the group the integrator lets it skip (the light's convex emitter group), if any.
    skip: Vec<Option<u32>>,
    /// The same segments grouped by pixel: origins, directions and the lanes in use.
    shadow_lanes: Vec<(Vec3x8, Vec3x8, u32)>,
}

fn workload(scene: &Scene) -> Workload {
    let basis = scene.camera.basis();
    let emitters = EmitterSampler::new(scene, LightSelection::Power).expect("scene has emitters");
    let (w, h) = (scene.camera.width, scene.camera.height);
    let pixels = RAYS / PER_PIXEL;
    let mut work = Workload { primary: Vec::new(), shadow: Vec::new(), skip: Vec::new(), shadow_lanes: Vec::new() };
    for k in 0..pixels as u64 {
        let pixel = k * (w * h) as u64 / pixels as u64;
        let (x, y) = ((pixel % w as u64) as u32, (pixel / w as u64) as u32);
        let mut lanes = ([Vec3::ZERO; PER_PIXEL], [Vec3::ZERO; PER_PIXEL], 0u32);
        for s in 0..PER_PIXEL as u64 {
            let mut rng = SampleRng::new(1, pixel, s);
            let dir = basis.direction(x, y, rng.uniform_2d());
            work.primary.push((basis.eye(), dir));
            let Some(hit) = scene.accel().closest_hit(basis.eye(), dir, f32::INFINITY) else { continue };
            // The shadow ray `emitter` traces for this sample, if any: it skips a sample whose point on the
            // light is behind the light or below the surface, or whose f_r is 0, since it contributes nothing.
            let tri = &scene.triangles[hit.triangle as usize];
            let n = if tri.n.dot(dir) < 0.0 { tri.n } else { -tri.n };
            let p = scene.hit_point(&hit);
            let Some((t, _)) = emitters.pick(scene, p, rng.uniform()) else { continue };
            let light = &scene.triangles[t as usize];
            let [a, b, c] = light.v;
            let x = sample_uniform_triangle(rng.uniform_2d(), a, b, c);
            let wi = (x - p).normalize();
            let f = scene.materials[tri.material as usize].eval_brdf(n, -dir, wi);
            if !(light.n.dot(p - a) > 0.0 && light.n.dot(-wi) > 0.0 && n.dot(wi) > 0.0 && f != Vec3::ZERO) {
                continue;
            }
            let (from, to) = shadow_ray_ends(scene, p, n, tri.error.at_point, (t, x, light.n));
            let d = to - from;
            let l = lanes.2.count_ones() as usize;
            (lanes.0[l], lanes.1[l], lanes.2) = (from, d, lanes.2 | 1 << l);
            work.shadow.push((from, d));
            work.skip.push(if light.n.dot(from - x) > 0.0 { scene.convex_group(t) } else { None });
        }
        if lanes.2 != 0 {
            work.shadow_lanes.push((Vec3x8::from_lanes(&lanes.0), Vec3x8::from_lanes(&lanes.1), lanes.2));
        }
    }
    work
}

fn rays(c: &mut Criterion) {
    for name in ["cornell-box", "veach-mis"] {
        let scene = load_scene(name).expect("bundled scene loads");
        let work = workload(&scene);
        let mut group = c.benchmark_group(format!("rays/{name}"));
        group.throughput(Throughput::Elements(work.primary.len() as u64));
        group.bench_function("closest_hit", |b| {
            b.iter(|| {
                let mut hits = 0u32;
                for &(o, d) in &work.primary {
                    hits += scene.accel().closest_hit(o, d, f32::INFINITY).is_some() as u32;
                }
                black_box(hits)
            })
        });
        group.throughput(Throughput::Elements(work.shadow.len() as u64));
        group.bench_function("occluded", |b| {
            b.iter(|| {
                let mut blocked = 0u32;
                for &(o, d) in &work.shadow {
                    blocked += scene.accel().occluded(o, d, SEGMENT_END, None) as u32;
                }
                black_box(blocked)
            })
        });
        group.bench_function("occluded_skipping", |b| {
            b.iter(|| {
                let mut blocked = 0u32;
                for (&(o, d), &skip) in work.shadow.iter().zip(&work.skip) {
                    blocked += scene.accel().occluded(o, d, SEGMENT_END, skip) as u32;
                }
                black_box(blocked)
            })
        });
        group.bench_function("occluded_eight_lanes", |b| {
            b.iter(|| {
                let mut blocked = 0u32;
                for (o, d, active) in &work.shadow_lanes {
                    blocked += scene.accel().occluded_lanes(o, d, SEGMENT_END, *active, [SKIP_NONE; 8]).count_ones();
                }
                black_box(blocked)
            })
        });
        // Cones of the first 4 096 pixels that have one (gathered outside the timing, as the integrator gathers
        // each once per pass), 16 jittered camera rays each.
        let basis = scene.camera.basis();
        let (w, h) = (scene.camera.width, scene.camera.height);
        let cones: Vec<_> = (0..w * h)
            .filter_map(|i| {
                let (x, y) = (i % w, i / w);
                scene.cone_candidates(basis.eye(), basis.pixel_corners(x, y)).map(|c| (x, y, c))
            })
            .take(4096)
            .collect();
        let rays: Vec<_> = cones
            .iter()
            .enumerate()
            .flat_map(|(k, (x, y, _))| {
                let mut rng = SampleRng::new(2, k as u64, 0);
                (0..16).map(move |_| (k, basis.direction(*x, *y, rng.uniform_2d())))
            })
            .collect();
        group.throughput(Throughput::Elements(rays.len() as u64));
        group.bench_function("camera_cone", |b| {
            b.iter(|| {
                let mut hits = 0u32;
                for &(k, d) in &rays {
                    hits += cones[k].2.closest_hit(d, f32::INFINITY).is_some() as u32;
                }
                black_box(hits)
            })
        });
        // The integrator, on one thread like the rays above: every ray it traces (camera and shadow rays), with its
        // sampling and shading around them, in passes of 32 samples per pixel over the scene's own image.
        const SPP: u32 = 32;
        let mut renderer = Renderer::new(
            std::sync::Arc::new(scene.clone()),
            RenderSettings { strategy: Strategy::Emitter, ..Default::default() },
        );
        let mut film = Film::new(w, h);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("thread pool");
        let rays_per_pass = pool.install(|| renderer.render_pass(&mut film, 0, SPP, &|| false)).rays;
        let mut first = SPP;
        group.throughput(Throughput::Elements(rays_per_pass));
        group.sample_size(10).sampling_mode(SamplingMode::Flat).measurement_time(std::time::Duration::from_secs(6));
        group.bench_function("integrator_emitter", |b| {
            b.iter(|| {
                let stats = pool.install(|| renderer.render_pass(&mut film, first, SPP, &|| false));
                first += SPP;
                black_box(stats.rays)
            })
        });
        group.finish();
    }
}

/// The integrator's rays/s over the raw BVH's for the same mix of rays (camera rays, then the shadow rays plain
/// and skipping their light's convex group), in alternating rounds; prints the median ratio and its range.
fn ratio_rounds() {
    const ROUNDS: usize = 31;
    const SPP: u32 = 32;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("thread pool");
    for name in ["cornell-box", "veach-mis"] {
        let scene = load_scene(name).expect("bundled scene loads");
        let work = workload(&scene);
        let raw_rate = |skip: bool| {
            let cpu = ThreadTime::now();
            let mut n = 0u32;
            for &(o, d) in &work.primary {
                n += scene.accel().closest_hit(o, d, f32::INFINITY).is_some() as u32;
            }
            for (&(o, d), &group) in work.shadow.iter().zip(&work.skip) {
                n += scene.accel().occluded(o, d, SEGMENT_END, group.filter(|_| skip)) as u32;
            }
            black_box(n);
            (work.primary.len() + work.shadow.len()) as f64 / cpu.elapsed().as_secs_f64()
        };
        let mut renderer = Renderer::new(
            std::sync::Arc::new(scene.clone()),
            RenderSettings { strategy: Strategy::Emitter, ..Default::default() },
        );
        let mut film = Film::new(scene.camera.width, scene.camera.height);
        let mut first = 0;
        let mut integrator_rate = || {
            let stats = pool.install(|| renderer.render_pass(&mut film, first, SPP, &|| false));
            first += SPP;
            stats.rays as f64 / stats.cpu.as_secs_f64()
        };
        integrator_rate(); // warm-up
        let rounds: Vec<[f64; 3]> = (0..ROUNDS).map(|_| [raw_rate(false), raw_rate(true), integrator_rate()]).collect();
        let column = |f: &dyn Fn(&[f64; 3]) -> f64| median_and_range(rounds.iter().map(f).collect());
        let (plain, skipping, integrator) = (column(&|r| r[0]), column(&|r| r[1]), column(&|r| r[2]));
        let (ratio, ratio_skipping) = (column(&|r| r[2] / r[0]), column(&|r| r[2] / r[1]));
        println!(
            "ratio/{name}: {:.3} shadow rays per camera ray; medians of {ROUNDS} rounds: integrator {:.1} M rays/s, \
             raw single rays {:.1} M/s, skipping {:.1} M/s",
            work.shadow.len() as f64 / work.primary.len() as f64,
            integrator.0 / 1e6,
            plain.0 / 1e6,
            skipping.0 / 1e6
        );
        let percent =
            |(m, lo, hi): (f64, f64, f64)| format!("{:.1}% ({:.1} … {:.1}%)", 100.0 * m, 100.0 * lo, 100.0 * hi);
        println!(
            "ratio/{name}: integrator / raw, median of the rounds' ratios: {}; against the rays skipping: {}",
            percent(ratio),
            percent(ratio_skipping)
        );
        // Load only ever slows a run down: the fastest of many is the least disturbed.
        println!(
            "ratio/{name}: fastest rounds: integrator {:.1} M rays/s, raw {:.1} M/s ({:.1}%), skipping {:.1} M/s ({:.1}%)",
            integrator.2 / 1e6,
            plain.2 / 1e6,
            100.0 * integrator.2 / plain.2,
            skipping.2 / 1e6,
            100.0 * integrator.2 / skipping.2
        );
    }
}

/// The median, least and greatest of `v`.
fn median_and_range(mut v: Vec<f64>) -> (f64, f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[v.len() / 2], v[0], v[v.len() - 1])
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = rays
}

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
    // A filter (an argument not starting with '-') picks criterion rows; "ratio" picks the rounds alone.
    let filters: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with('-')).collect();
    if filters.is_empty() || filters.iter().any(|f| f == "ratio") {
        ratio_rounds();
    }
}
