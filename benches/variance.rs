//! Variance at equal samples (the Veach figure in numbers): for each strategy, the relative variance of one pixel
//! sample, σ²/μ² per pixel from the film's sums of squares, averaged over the pixels that see each material
//! (on the plates of `veach-mis`, separately in the image's leftmost quarter, under the 9 mm light, and its
//! rightmost, under the 0.9 m light), and the samples per second on one thread. Prints markdown tables;
//! asserts nothing. `cargo bench --bench variance`. Rare-event estimators (a light hit once in 10⁵ samples)
//! show a sample variance below their true one: read very small numbers in those cells with that in mind.

use illumlab::render::{Film, Heuristic, MisSettings, RenderSettings, Renderer, Strategy};
use illumlab::scene::{LightSelection, load_scene};
use std::collections::BTreeMap;
use std::time::Instant;

fn settings() -> Vec<(String, RenderSettings)> {
    let mut out: Vec<(String, RenderSettings)> = Strategy::ALL
        .into_iter()
        .filter(|s| *s != Strategy::Mis)
        .map(|strategy| (strategy.name().to_string(), RenderSettings { strategy, ..Default::default() }))
        .collect();
    for light in Strategy::ALL.into_iter().filter(|s| s.samples_lights()) {
        let mis = MisSettings { techniques: [light, Strategy::Brdf], heuristic: Heuristic::Power, samples: [1, 1] };
        out.push((
            format!("mis ({} + brdf)", light.name()),
            RenderSettings { strategy: Strategy::Mis, mis, ..Default::default() },
        ));
    }
    out
}

/// `columns`: split each material's pixels into the image's left and right quarters.
fn table(scene_name: &str, size: (u32, u32), spp: u32, materials: &[&str], columns: bool) {
    let mut scene = load_scene(scene_name).expect("bundled scene");
    (scene.camera.width, scene.camera.height) = size;
    let (w, h) = size;
    // The material each pixel sees through its centre.
    let seen: Vec<Option<String>> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            scene.pick(x, y).map(|t| scene.material_names[scene.triangles[t as usize].material as usize].clone())
        })
        .collect();
    println!("\n### {scene_name}, {w}×{h}, {spp} spp, light selection: power\n");
    println!("relative variance σ²/μ² of one pixel sample, mean over the pixels of each material (lower is better)\n");
    let header: Vec<String> =
        materials.iter().map(|m| if columns { format!("{m} (small / big light)") } else { m.to_string() }).collect();
    println!("| strategy | {} | M samples/s |", header.join(" | "));
    println!("|---|{}---|", "---|".repeat(materials.len()));
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    for (name, mut s) in settings() {
        s.light_selection = LightSelection::Power;
        let mut renderer = Renderer::new(std::sync::Arc::new(scene.clone()), s);
        let mut film = Film::new(w, h);
        let start = Instant::now();
        let stats = pool.install(|| renderer.render_pass(&mut film, 0, spp, &|| false));
        let rate = stats.samples as f64 / start.elapsed().as_secs_f64() / 1e6;
        let mut sums: BTreeMap<(&str, u32), (f64, u32)> = BTreeMap::new();
        for (i, m) in seen.iter().enumerate() {
            let Some(m) = m.as_deref().and_then(|m| materials.iter().find(|k| **k == m)) else { continue };
            let quarter = if columns { 4 * (i as u32 % w) / w } else { 0 };
            if columns && quarter != 0 && quarter != 3 {
                continue;
            }
            let p = &film.pixels[i];
            let (mean, var) = (p.mean().element_sum() / 3.0, p.variance().element_sum() / 3.0);
            if mean > 0.0 {
                let e = sums.entry((*m, quarter)).or_default();
                e.0 += var / (mean * mean);
                e.1 += 1;
            }
        }
        let cell = |m: &str, q: u32| sums.get(&(m, q)).map_or("–".into(), |(v, n)| format!("{:.3}", v / *n as f64));
        let cells: Vec<String> = materials
            .iter()
            .map(|m| if columns { format!("{} / {}", cell(m, 0), cell(m, 3)) } else { cell(m, 0) })
            .collect();
        println!("| {name} | {} | {rate:.2} |", cells.join(" | "));
    }
}

fn main() {
    // `cargo test --all-targets` runs benches without `--bench`: check that it runs, at a tiny size.
    if !std::env::args().any(|a| a == "--bench") {
        table("veach-mis", (12, 8), 1, &["backdrop"], false);
        return;
    }
    table("veach-mis", (192, 128), 64, &["plate1_a10", "plate2_a100", "plate3_a1000", "plate4_a10000"], true);
    table("veach-mis", (192, 128), 64, &["backdrop"], false);
    table("near-light", (128, 128), 64, &["floor"], false);
}
