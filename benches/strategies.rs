//! Samples per second of a full pass, per strategy, on two bundled scenes and the real mesh (`assets/knot-box`, 67 200
//! triangles; one thread: the per-core rate). Passes take 16 samples per pixel, as the command line's do (it takes
//! up to 128): enough for the camera-ray cones.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use illumlab::render::{Film, RenderSettings, Renderer, Strategy};
use illumlab::scene::{LightSelection, load_scene};

const SPP: u32 = 16;

fn strategies(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("thread pool");
    let knot = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/knot-box/knot-box.toml");
    for (name, source) in [("cornell-box", "cornell-box"), ("veach-mis", "veach-mis"), ("knot-box", knot)] {
        let mut scene = load_scene(source).expect("the scene loads");
        scene.camera.width = 128;
        scene.camera.height = 128;
        let mut group = c.benchmark_group(format!("pass/{name}"));
        group.throughput(Throughput::Elements(128 * 128 * SPP as u64));
        for strategy in Strategy::ALL {
            let settings =
                RenderSettings { strategy, light_selection: LightSelection::Power, seed: 0, ..Default::default() };
            let mut renderer = Renderer::new(std::sync::Arc::new(scene.clone()), settings);
            let mut film = Film::new(128, 128);
            let mut first = 0;
            group.bench_function(strategy.name(), |b| {
                b.iter(|| {
                    pool.install(|| renderer.render_pass(&mut film, first, SPP, &|| false));
                    first += SPP;
                })
            });
        }
        group.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = strategies
}
criterion_main!(benches);
