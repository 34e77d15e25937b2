//! The speed/accuracy measurement behind `illumlab bench`: every strategy renders progressively through the
//! budgets (1, 4, 16, … spp), several times with independent seeds; at each budget its wall-clock time so far and
//! its error against the reference are recorded, and reported as the mean over the seeds with a 95% interval
//! ([`MeanInterval`]).
//!
//! What the error contains is chosen, and said: with the [`Footprint::Centre`] footprint every pixel's primary
//! hit is fixed, so the error is the estimator's alone (the default of `bench`); pixels that see an emitter are
//! left out (`included`); the reference's own noise is subtracted ([`ErrorMetrics::estimator_mse`]). Passes run
//! on rayon's pool; images (and so errors) are a pure function of the seeds, only the timings vary between runs.

use super::{ConvergencePoint, ErrorMetrics, MeanInterval, Reference, Series, error_over};
use crate::guiding::IterationReport;
use crate::render::{Census, Film, RenderSettings, Renderer, Strategy};
use crate::scene::Scene;
use serde::Serialize;
use std::sync::Arc;
use std::time::Instant;

/// What to measure: each strategy (other settings from `base`) up to each budget in `spp` (ascending), with
/// `seeds` independent seeds `base.seed, base.seed + 1, …`.
#[derive(Clone, Debug)]
pub struct BenchPlan {
    pub base: RenderSettings,
    pub strategies: Vec<Strategy>,
    pub spp: Vec<u32>,
    pub seeds: u32,
}

/// One strategy at one budget, over the seeds: means and 95% intervals (`_lo`, `_hi`). MSE and relMSE are the
/// estimator's (the reference's noise subtracted) over the included pixels; the efficiencies' intervals follow
/// from the MSE's at the mean time (empty where unbounded or not finite).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BenchRow {
    pub strategy: String,
    pub spp: u32,
    pub seeds: u32,
    /// Mean wall-clock seconds to render this many samples per pixel (all passes so far).
    pub seconds: f64,
    pub samples_per_second: f64,
    /// `√max(MSE, 0)`.
    pub rmse: f64,
    pub mse: f64,
    pub mse_lo: f64,
    pub mse_hi: f64,
    pub rel_mse: f64,
    pub rel_mse_lo: f64,
    pub rel_mse_hi: f64,
    /// `1/(MSE · seconds)`.
    pub efficiency: Option<f64>,
    pub efficiency_lo: Option<f64>,
    pub efficiency_hi: Option<f64>,
    /// `1/(relMSE · seconds)`.
    pub rel_efficiency: Option<f64>,
    pub rel_efficiency_lo: Option<f64>,
    pub rel_efficiency_hi: Option<f64>,
    /// Over all seeds.
    pub non_finite_dropped: u64,
}

/// Everything a bench run measured.
#[derive(Clone, Debug)]
pub struct BenchReport {
    pub rows: Vec<BenchRow>,
    /// Per strategy and budget, the MSE and relMSE over the seeds (for verdicts between strategies).
    pub intervals: Vec<Vec<[MeanInterval; 2]>>,
    /// One series per strategy (the means), for plots.
    pub series: Vec<Series>,
    /// The reference's own RMSE over the included pixels (its noise floor, subtracted), 0 when unknown.
    pub reference_rmse: f64,
    /// Pixels measured, and pixels left out.
    pub pixels: usize,
    pub excluded: usize,
    /// Per strategy (first seed, after its largest budget): how many of its traced directions found light.
    pub census: Vec<(String, Census)>,
    /// Per strategy that learns a guide (first seed): what each training iteration built.
    pub guides: Vec<(String, Vec<IterationReport>)>,
}

/// `1/(x · seconds)` where finite and positive.
fn inverse(x: f64, seconds: f64) -> Option<f64> {
    let e = 1.0 / (x * seconds);
    (e.is_finite() && e > 0.0).then_some(e)
}

/// Renders `scene` as `plan` says, measuring against `reference` over the pixels `included` marks (all when
/// `None`). `progress` is called after every budget of every seed with (strategy, seed index, spp).
pub fn run_bench(
    scene: &Arc<Scene>,
    reference: &Reference,
    plan: &BenchPlan,
    included: Option<&[bool]>,
    mut progress: impl FnMut(Strategy, u32, u32),
) -> BenchReport {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let pixels = included.map_or((w * h) as usize, |inc| inc.iter().filter(|&&b| b).count());
    let (mut rows, mut series, mut intervals) = (Vec::new(), Vec::new(), Vec::new());
    let (mut census, mut guides) = (Vec::new(), Vec::new());
    let noise = error_over(&reference.mean, reference, included);
    for &strategy in &plan.strategies {
        // Per seed and budget: seconds so far, the metrics, non-finite samples so far.
        let mut runs: Vec<Vec<(f64, ErrorMetrics, u64)>> = Vec::new();
        for k in 0..plan.seeds.max(1) {
            let settings = RenderSettings { strategy, seed: plan.base.seed.wrapping_add(k as u64), ..plan.base };
            let mut renderer = Renderer::new(scene.clone(), settings);
            let mut film = Film::new(w, h);
            let (mut done, mut seconds, mut dropped) = (0u32, 0.0f64, 0u64);
            let mut run = Vec::new();
            for &budget in &plan.spp {
                let start = Instant::now();
                let stats = renderer.render_pass(&mut film, done, budget.saturating_sub(done), &|| false);
                seconds += start.elapsed().as_secs_f64();
                done = done.max(budget);
                dropped += stats.non_finite;
                let metrics = error_over(&film.means(), reference, included);
                run.push((seconds, metrics, dropped));
                progress(strategy, k, done);
            }
            runs.push(run);
            if k == 0 {
                // About 16 000 pixels, 4 samples each, after the last budget (a guide as trained by then).
                let stride = ((w * h) as usize / 16_000).max(1);
                census.push((strategy.name().to_string(), renderer.census(done, 4, stride)));
                if let Some(t) = renderer.training() {
                    guides.push((strategy.name().to_string(), t.log().to_vec()));
                }
            }
        }
        let mut line = Series::new(strategy.name());
        let mut per_budget = Vec::new();
        for (j, &spp) in plan.spp.iter().enumerate() {
            let of = |f: &dyn Fn(&ErrorMetrics) -> f64| {
                MeanInterval::of(&runs.iter().map(|r| f(&r[j].1)).collect::<Vec<_>>())
            };
            let mse = of(&|m| m.estimator_mse());
            let rel = of(&|m| m.estimator_rel_mse());
            let seconds = runs.iter().map(|r| r[j].0).sum::<f64>() / runs.len() as f64;
            let dropped = runs.iter().map(|r| r[j].2).sum();
            line.push(ConvergencePoint { spp, seconds, mse: mse.mean, rel_mse: rel.mean });
            rows.push(BenchRow {
                strategy: strategy.name().into(),
                spp,
                seeds: runs.len() as u32,
                seconds,
                samples_per_second: (w as f64 * h as f64 * spp as f64) / seconds.max(1e-9),
                rmse: mse.mean.max(0.0).sqrt(),
                mse: mse.mean,
                mse_lo: mse.lo(),
                mse_hi: mse.hi(),
                rel_mse: rel.mean,
                rel_mse_lo: rel.lo(),
                rel_mse_hi: rel.hi(),
                efficiency: inverse(mse.mean, seconds),
                efficiency_lo: inverse(mse.hi(), seconds),
                efficiency_hi: inverse(mse.lo(), seconds),
                rel_efficiency: inverse(rel.mean, seconds),
                rel_efficiency_lo: inverse(rel.hi(), seconds),
                rel_efficiency_hi: inverse(rel.lo(), seconds),
                non_finite_dropped: dropped,
            });
            per_budget.push([mse, rel]);
        }
        series.push(line);
        intervals.push(per_budget);
    }
    let excluded = (w * h) as usize - pixels;
    let reference_rmse = noise.reference_mse.sqrt();
    BenchReport { rows, intervals, series, reference_rmse, pixels, excluded, census, guides }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::reference_settings;
    use crate::render::Footprint;
    use crate::scene::load_scene;

    #[test]
    fn rows_for_every_strategy_and_budget_deterministic_but_for_time() {
        let mut scene = load_scene("cornell-box").expect("bundled");
        scene.camera.width = 12;
        scene.camera.height = 12;
        let mut film = Film::new(12, 12);
        let scene = Arc::new(scene);
        Renderer::new(scene.clone(), reference_settings(Footprint::Centre)).render_pass(&mut film, 0, 64, &|| false);
        let reference = Reference::from_film(&film, 0.0);
        let base = RenderSettings { footprint: Footprint::Centre, ..Default::default() };
        let plan = BenchPlan { base, strategies: vec![Strategy::Cosine, Strategy::Emitter], spp: vec![1, 4], seeds: 3 };
        let mut calls = 0;
        let included: Vec<bool> = (0..144).map(|i| i % 7 != 0).collect();
        let a = run_bench(&scene, &reference, &plan, Some(&included), |_, _, _| calls += 1);
        assert_eq!(calls, 2 * 3 * 2);
        assert_eq!((a.rows.len(), a.series.len(), a.intervals.len()), (4, 2, 2));
        assert_eq!((a.pixels, a.excluded), (123, 21));
        assert!(a.rows.iter().all(|r| r.rmse > 0.0 && r.seconds > 0.0 && r.efficiency.is_some() && r.seeds == 3));
        assert!(a.rows.iter().all(|r| r.mse_lo < r.mse && r.mse < r.mse_hi), "an interval around each mean");
        assert!(a.rows[1].seconds >= a.rows[0].seconds, "time is cumulative");
        let b = run_bench(&scene, &reference, &plan, Some(&included), |_, _, _| {});
        let errors = |r: &BenchReport| r.rows.iter().map(|r| (r.rmse, r.rel_mse, r.mse_hi)).collect::<Vec<_>>();
        assert_eq!(errors(&a), errors(&b));
        let one = run_bench(&scene, &reference, &BenchPlan { seeds: 1, ..plan.clone() }, Some(&included), |_, _, _| {});
        assert_eq!(one.rows[0].mse_hi, f64::INFINITY, "one seed: no interval");
    }
}
