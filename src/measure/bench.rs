//! The speed/accuracy measurement behind `illumlab bench`: every strategy renders progressively through the
//! budgets (1, 4, 16, … spp); at each budget its wall-clock time so far and its error against the reference are
//! recorded. Passes run on rayon's pool; images (and so errors) are a pure function of the seed, only the timings
//! vary between runs.

use super::{ConvergencePoint, Reference, Series, error_vs_reference};
use crate::render::{Film, RenderSettings, Renderer, Strategy};
use crate::scene::Scene;
use serde::Serialize;
use std::sync::Arc;
use std::time::Instant;

/// One strategy at one budget.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BenchRow {
    pub strategy: String,
    pub spp: u32,
    /// Wall-clock seconds to render this many samples per pixel (all passes so far).
    pub seconds: f64,
    pub samples_per_second: f64,
    pub rmse: f64,
    pub rel_mse: f64,
    /// `1/(MSE · seconds)`; empty when not finite.
    pub efficiency: Option<f64>,
    /// `1/(relMSE · seconds)`; empty when not finite.
    pub rel_efficiency: Option<f64>,
    pub non_finite_dropped: u64,
}

/// Everything a bench run measured.
#[derive(Clone, Debug)]
pub struct BenchReport {
    pub rows: Vec<BenchRow>,
    /// One series per strategy, for plots.
    pub series: Vec<Series>,
    /// The reference's own RMSE (its noise floor), 0 when unknown.
    pub reference_rmse: f64,
}

/// Renders `scene` with each strategy in `strategies` (other settings from `base`) up to each budget in `spp`
/// (ascending), measuring against `reference`. `progress` is called after every budget with (strategy, spp).
pub fn run_bench(
    scene: &Arc<Scene>,
    reference: &Reference,
    base: RenderSettings,
    strategies: &[Strategy],
    spp: &[u32],
    mut progress: impl FnMut(Strategy, u32),
) -> BenchReport {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let mut rows = Vec::new();
    let mut series = Vec::new();
    for &strategy in strategies {
        let settings = RenderSettings { strategy, ..base };
        let renderer = Renderer::new(scene.clone(), settings);
        let mut film = Film::new(w, h);
        let mut run = Series::new(strategy.name());
        let (mut done, mut seconds, mut dropped) = (0u32, 0.0f64, 0u64);
        for &budget in spp {
            let start = Instant::now();
            let stats = renderer.render_pass(&mut film, done, budget.saturating_sub(done), &|| false);
            seconds += start.elapsed().as_secs_f64();
            done = done.max(budget);
            dropped += stats.non_finite;
            let metrics = error_vs_reference(&film.means(), reference);
            let point = ConvergencePoint::new(done, seconds, &metrics);
            run.push(point);
            rows.push(BenchRow {
                strategy: strategy.name().into(),
                spp: done,
                seconds,
                samples_per_second: (w as f64 * h as f64 * done as f64) / seconds.max(1e-9),
                rmse: point.rmse(),
                rel_mse: point.rel_mse,
                efficiency: point.efficiency(),
                rel_efficiency: point.rel_efficiency(),
                non_finite_dropped: dropped,
            });
            progress(strategy, done);
        }
        series.push(run);
    }
    BenchReport { rows, series, reference_rmse: reference.noise_mse().sqrt() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::reference_settings;
    use crate::scene::load_scene;

    #[test]
    fn rows_for_every_strategy_and_budget_deterministic_but_for_time() {
        let mut scene = load_scene("cornell-box").expect("bundled");
        scene.camera.width = 12;
        scene.camera.height = 12;
        let mut film = Film::new(12, 12);
        let scene = Arc::new(scene);
        Renderer::new(scene.clone(), reference_settings()).render_pass(&mut film, 0, 64, &|| false);
        let reference = Reference::from_film(&film, 0.0);
        let strategies = [Strategy::Cosine, Strategy::Emitter];
        let mut calls = 0;
        let a = run_bench(&scene, &reference, RenderSettings::default(), &strategies, &[1, 4], |_, _| calls += 1);
        assert_eq!(calls, 4);
        assert_eq!(a.rows.len(), 4);
        assert_eq!(a.series.len(), 2);
        assert!(a.rows.iter().all(|r| r.rmse > 0.0 && r.seconds > 0.0 && r.efficiency.is_some()));
        assert!(a.rows[1].seconds >= a.rows[0].seconds, "time is cumulative");
        let b = run_bench(&scene, &reference, RenderSettings::default(), &strategies, &[1, 4], |_, _| {});
        let errors = |r: &BenchReport| r.rows.iter().map(|r| (r.rmse, r.rel_mse)).collect::<Vec<_>>();
        assert_eq!(errors(&a), errors(&b));
    }
}
