//! The probe: the lecture's hemisphere pictures at any point of a real scene. It fixes a pixel's primary hit and
//! shows, for a strategy, where its samples land, how large each `f_r L_i (ω·n) / p(ω)` is, and how its density
//! compares with the integrand; with the running estimate, a quadrature "truth" and a chi-square test of the
//! sampler at that point. Headless: the CLI's `probe` and the viewer's probe panel both call [`Probe::run`].

mod adaptive;
pub mod chi2;
mod density;
mod estimate;
pub mod picture;
mod point;
mod quadrature;

pub use chi2::{ChiSquare, chi_square, chi_square_against};
pub use density::{density, intersect};
pub use estimate::{HISTOGRAM_BINS, HISTOGRAM_DECADES, OUTCOMES, ProbeRun};
pub use picture::{Layers, Maps, PROJECTION, Picture};
pub use point::ProbePoint;
pub use quadrature::{Quadrature, RELATIVE_TOLERANCE, quadrature};

use crate::guiding::Guide;
use crate::math::luminance;
use crate::render::strategy::StrategyState;
use crate::render::{RenderSettings, SampleContext, Strategy};
use crate::scene::{EmitterSampler, Scene, TileLights};
use serde::Serialize;
use std::collections::BTreeMap;
use std::sync::Arc;

/// How much work a probe does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeSettings {
    /// Pixel samples of the strategy's estimator at the point.
    pub samples: u64,
    pub seed: u64,
    /// Records kept for the dots (the last ones).
    pub keep: usize,
    /// Disk size of the picture, in pixels.
    pub map_size: usize,
    /// The quadrature's budget of integrand evaluations.
    pub quadrature_nodes: u64,
    /// Draws of the chi-square test (0: no test).
    pub chi2_samples: u64,
}

impl Default for ProbeSettings {
    fn default() -> Self {
        Self { samples: 20_000, seed: 0, keep: 2_000, map_size: 192, quadrature_nodes: 400_000, chi2_samples: 0 }
    }
}

/// A scene with render settings, ready to be probed at any point.
pub struct Probe {
    scene: Arc<Scene>,
    settings: RenderSettings,
    emitters: Option<EmitterSampler>,
    state: Option<StrategyState>,
    /// The guide `guided` samples from (a lane's, as learned so far).
    guide: Option<Arc<Guide>>,
}

/// Everything a probe found at one point for one strategy.
#[derive(Clone, Debug)]
pub struct ProbeReport {
    pub point: ProbePoint,
    pub strategy: Strategy,
    pub run: ProbeRun,
    pub quadrature: Quadrature,
    pub chi2: Option<ChiSquare>,
    pub maps: Maps,
}

/// One row of the table that compares every strategy at the point.
#[derive(Clone, Debug, Serialize)]
pub struct StrategyRow {
    pub strategy: &'static str,
    pub relative_variance: f64,
    pub samples_per_second: f64,
    /// `1 / (σ²/μ² · t)` per second of one thread.
    pub efficiency: f64,
    pub z: f64,
}

impl Probe {
    pub fn new(scene: Arc<Scene>, settings: RenderSettings) -> Self {
        let emitters = EmitterSampler::new(&scene, settings.light_selection);
        let state = settings.strategy.prepare(&scene, &settings);
        Self { scene, settings, emitters, state, guide: None }
    }

    /// Probes with a learned guide (what `guided` samples from at the probed point).
    pub fn with_guide(mut self, guide: Option<Arc<Guide>>) -> Self {
        self.guide = guide;
        self
    }

    pub fn scene(&self) -> &Arc<Scene> {
        &self.scene
    }

    /// The guide it probes with, if any.
    pub fn guide(&self) -> Option<&Guide> {
        self.guide.as_deref()
    }

    pub fn context(&self) -> SampleContext<'_> {
        let state = self.state.as_deref();
        let guide = self.guide.as_deref();
        let (scene, emitters, mis, tile) = (&self.scene, self.emitters.as_ref(), &self.settings.mis, &TileLights::NONE);
        SampleContext { scene, emitters, mis, state, guide, tile }
    }

    /// The point under pixel (x, y) of the scene's camera.
    pub fn point(&self, pixel: (u32, u32)) -> Option<ProbePoint> {
        ProbePoint::at_pixel(&self.scene, &self.scene.camera, pixel)
    }

    /// The quadrature at a point (the slow part, to be done once per point).
    pub fn quadrature(&self, point: &ProbePoint, settings: &ProbeSettings) -> Quadrature {
        quadrature(&self.scene, &point.shading_point(&self.scene), settings.quadrature_nodes)
    }

    /// Runs `strategy` at the point: samples, picture data and (if asked) the chi-square test.
    pub fn run(
        &self,
        point: &ProbePoint,
        strategy: Strategy,
        quadrature: Quadrature,
        settings: &ProbeSettings,
    ) -> ProbeReport {
        let ctx = self.context();
        let sp = point.shading_point(&self.scene);
        let truth = luminance(quadrature.value);
        let run = ProbeRun::run(&ctx, &sp, strategy, settings.samples, settings.seed, settings.keep, truth);
        let maps = Maps::new(&ctx, &sp, strategy, truth, settings.map_size);
        let chi2 = (settings.chi2_samples > 0)
            .then(|| chi_square(&ctx, &sp, strategy, settings.chi2_samples, settings.seed ^ 0xC41));
        ProbeReport { point: *point, strategy, run, quadrature, chi2, maps }
    }

    /// The picture of a report; below it, if the report has one, the chi-square test's (observed, expected and
    /// residual per cell).
    pub fn picture(&self, report: &ProbeReport, layers: Layers) -> Picture {
        let ctx = self.context();
        let sp = report.point.shading_point(&self.scene);
        let truth = luminance(report.quadrature.value);
        let main = picture::draw(&ctx, &sp, &report.maps, &report.run.records, truth, layers);
        match &report.chi2 {
            Some(c) => Picture::stack(&[main, c.picture(&ctx, &sp, report.maps.size)], 12),
            None => main,
        }
    }

    /// Every registered strategy at the point, `samples` each: the lecture's "which is best here, and by how
    /// much?" (CPU time of one thread; the relative variance against the quadrature).
    pub fn table(&self, point: &ProbePoint, quadrature: &Quadrature, samples: u64, seed: u64) -> Vec<StrategyRow> {
        let ctx = self.context();
        let sp = point.shading_point(&self.scene);
        let truth = luminance(quadrature.value) as f64;
        Strategy::ALL
            .into_iter()
            .map(|strategy| {
                let run = ProbeRun::run(&ctx, &sp, strategy, samples, seed, 0, truth as f32);
                StrategyRow {
                    strategy: strategy.name(),
                    relative_variance: run.relative_variance(truth),
                    samples_per_second: 1.0 / run.seconds_per_sample(),
                    efficiency: run.efficiency(truth),
                    z: run.z_score(truth),
                }
            })
            .collect()
    }
}

/// What `illumlab probe --json` prints: the numbers of a report.
#[derive(Clone, Debug, Serialize)]
pub struct ProbeJson {
    pub scene: String,
    pub strategy: &'static str,
    pub pixel: (u32, u32),
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub wo: [f32; 3],
    pub material: u32,
    pub samples: u64,
    pub estimate: [f32; 3],
    pub std_error: [f32; 3],
    /// Of the luminance.
    pub interval_95: (f64, f64),
    pub quadrature: [f32; 3],
    pub quadrature_nodes: u64,
    /// (estimate − quadrature) / standard error, on luminance.
    pub z: f64,
    /// σ²/μ² of one sample's luminance.
    pub relative_variance: f64,
    pub chi2_p: Option<f64>,
    pub chi2: Option<ChiSquare>,
    /// Directions that contributed nothing, by cause.
    pub zero_samples: BTreeMap<&'static str, u64>,
    pub non_finite: u64,
    pub samples_per_second: f64,
    pub projection: &'static str,
    pub strategies: Option<Vec<StrategyRow>>,
}

impl ProbeJson {
    pub fn new(scene: &Scene, r: &ProbeReport, strategies: Option<Vec<StrategyRow>>) -> Self {
        let truth = luminance(r.quadrature.value) as f64;
        Self {
            scene: scene.name.clone(),
            strategy: r.strategy.name(),
            pixel: r.point.pixel,
            position: r.point.position.to_array(),
            normal: r.point.normal.to_array(),
            wo: r.point.wo.to_array(),
            material: r.point.material,
            samples: r.run.samples,
            estimate: r.run.mean().to_array(),
            std_error: r.run.std_error().to_array(),
            interval_95: r.run.interval_95(),
            quadrature: r.quadrature.value.to_array(),
            quadrature_nodes: r.quadrature.nodes,
            z: r.run.z_score(truth),
            relative_variance: r.run.relative_variance(truth),
            chi2_p: r.chi2.as_ref().map(|c| c.p_value),
            chi2: r.chi2.clone(),
            zero_samples: r.run.zero_counts().map(|(o, n)| (o.slug(), n)).collect(),
            non_finite: r.run.non_finite,
            samples_per_second: 1.0 / r.run.seconds_per_sample(),
            projection: PROJECTION,
            strategies,
        }
    }
}
