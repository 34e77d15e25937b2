//! Passes over the image: every pixel takes the samples `first..first + count`, in order, each from its own
//! seeded stream, rows in parallel (rayon). Per-pixel order is fixed, so the film is the same bit for bit with any
//! number of threads and any split into passes.

use super::lanes::{
    LANES, estimate_emitter_lanes, estimate_guided_lanes, estimate_mis_emitter_brdf_lanes, estimate_mis_lanes,
    estimate_one_sample_lanes, estimate_projected_solid_angle_lanes, estimate_solid_angle_lanes,
};
use super::sink::{Census, Learner, SampleRecord, SampleSink};
use super::strategy::{Brdf, Emitter, ProjectedSolidAngle, SampleContext, SolidAngle, StrategyState};
use super::{Film, Footprint, PixelAccum, PixelCones, ShadingPoint, Strategy};
use crate::guiding::{Guide, GuideRecord, LeafHint, Training};
use crate::math::{PixelStreams, SampleRng, Vec3x8, without_denormals};
use crate::scene::{Camera, CameraBasis, ConeCandidates, EmitterSampler, Hit, HitLanes, Scene, TileLights};
use cpu_time::ThreadTime;
use glam::Vec3;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::Arc;
use wide::{CmpLt, f32x8};

/// Passes of at least this many samples per pixel gather, once per pixel, the few triangles its camera rays
/// can hit (an exact cull: see `scene::accel::frustum`; found on the first such pass and kept, see
/// `super::cones`), and take the samples eight at a time, one per SIMD lane (see `super::lanes`). Both give
/// the one-sample path's values bit for bit.
const GROUP_MIN_SAMPLES: u32 = 4;

/// What a pass's rows ask of its caller: whether to stop ([`Renderer::render_pass`]), and where to report each
/// row done.
struct PassHooks<'a> {
    cancelled: &'a (dyn Fn() -> bool + Sync),
    row_done: &'a (dyn Fn(u32) + Sync),
}

/// Renders a scene with fixed settings, pass after pass. It owns what is built once per scene and settings and
/// kept across passes: the light selection's p_Δ tables, the pixel cones and, for `guided`, the guide it learns
/// (see [`crate::guiding::Training`]; a render is still a function of scene, settings and seed, whatever the
/// split into passes and the number of threads).
pub struct Renderer {
    scene: Arc<Scene>,
    settings: RenderSettings,
    emitters: Option<EmitterSampler>,
    camera: CameraBasis,
    size: (u32, u32),
    cones: Arc<PixelCones>,
    /// The strategy's own state ([`super::strategy::DirectionStrategy::prepare`]).
    state: Option<StrategyState>,
    /// The guide being learned, when the strategy learns one.
    training: Option<Training>,
}

impl Renderer {
    pub fn new(scene: Arc<Scene>, settings: RenderSettings) -> Self {
        let camera = scene.camera;
        Self::with_camera(scene, settings, &camera)
    }

    /// Renders through another camera than the scene's (e.g. a low-resolution preview).
    pub fn with_camera(scene: Arc<Scene>, settings: RenderSettings, camera: &Camera) -> Self {
        Self {
            emitters: EmitterSampler::new(&scene, settings.light_selection),
            state: settings.strategy.prepare(&scene, &settings),
            training: Strategy::learns(&settings).then(|| Training::new(&scene, settings.guiding)),
            scene,
            settings,
            camera: camera.basis(),
            size: (camera.width, camera.height),
            cones: Arc::new(PixelCones::new(camera)),
        }
    }

    pub fn scene(&self) -> &Arc<Scene> {
        &self.scene
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// What its strategies read besides the shading point.
    pub fn context(&self) -> SampleContext<'_> {
        SampleContext {
            scene: &self.scene,
            emitters: self.emitters.as_ref(),
            mis: &self.settings.mis,
            state: self.state.as_deref(),
            guide: self.guide().map(|g| &**g),
            tile: &TileLights::NONE,
        }
    }

    /// The guide passes sample from now, when the strategy learns one.
    pub fn guide(&self) -> Option<&Arc<Guide>> {
        self.training.as_ref().map(Training::guide)
    }

    /// The guide's training (its log and status), when the strategy learns one.
    pub fn training(&self) -> Option<&Training> {
        self.training.as_ref()
    }

    /// Samples from a guide learned earlier for the same light, frozen (a viewer keeps it across camera and
    /// material changes); ignored if the strategy learns none or the guide is of another scene's light.
    pub fn with_guide(mut self, guide: Arc<Guide>) -> Self {
        if let Some(t) = &mut self.training
            && guide.fingerprint == t.guide().fingerprint
        {
            *t = Training::kept(guide, self.settings.guiding);
        }
        self
    }

    /// The pixel cones this renderer found and keeps, to give to a later renderer of the same scene geometry
    /// ([`Renderer::with_cones`]).
    pub fn cones(&self) -> Arc<PixelCones> {
        self.cones.clone()
    }

    /// Takes the pixel cones an earlier renderer found (e.g. a viewer's, which makes a renderer per pass), if they
    /// are for this renderer's camera, so that they are not found again. They must be for this scene's geometry:
    /// cones of other triangles would cull the wrong ones.
    pub fn with_cones(mut self, cones: Arc<PixelCones>) -> Self {
        if cones.camera() == self.cones.camera() {
            self.cones = cones;
        }
        self
    }

    /// Adds samples `first..first + count` to every pixel of `film` (which must match the camera's size).
    /// `cancelled` is polled once per row; when it returns true the pass stops early and leaves the film
    /// partially updated (the caller discards it). A strategy that learns takes the pass in parts that never
    /// cross a training iteration's end, records the directions evaluated in the parts that learn, and builds
    /// its next guide between them.
    pub fn render_pass(
        &mut self,
        film: &mut Film,
        first: u32,
        count: u32,
        cancelled: &(dyn Fn() -> bool + Sync),
    ) -> PassStats {
        self.render_pass_with_progress(film, first, count, cancelled, &|_| {})
    }

    /// [`Renderer::render_pass`], calling `row_done(n)` from the thread that rendered it each time a row has
    /// taken `n` more samples per pixel (a pass that learns calls it once per row for each of its parts).
    pub fn render_pass_with_progress(
        &mut self,
        film: &mut Film,
        first: u32,
        count: u32,
        cancelled: &(dyn Fn() -> bool + Sync),
        row_done: &(dyn Fn(u32) + Sync),
    ) -> PassStats {
        let end = first + count;
        let mut stats = PassStats::default();
        let mut s = first;
        while s < end {
            let (mut stop, learn) = match &mut self.training {
                Some(t) => t.plan(s, end),
                None => (end, false),
            };
            let training_end = self.settings.guiding.training_end();
            let trains = self.training.as_ref().is_some_and(|t| !t.is_kept());
            let keep = !(trains && self.settings.guiding.discard_training && s < training_end);
            if !keep {
                stop = stop.min(training_end);
            }
            let hooks = PassHooks { cancelled, row_done };
            let (part, records) = self.render_range(film, s, stop - s, learn, keep, &hooks);
            stats += part;
            if cancelled() {
                break;
            }
            if let (Some(t), true) = (&mut self.training, learn) {
                t.learn(records.into_iter().flatten(), stop);
            }
            s = stop;
        }
        stats
    }

    /// Samples `first..first + count` of every pixel, added to `film` if `keep`; with `learn`, the guide records
    /// of each row, in row order.
    fn render_range(
        &self,
        film: &mut Film,
        first: u32,
        count: u32,
        learn: bool,
        keep: bool,
        hooks: &PassHooks,
    ) -> (PassStats, Vec<Vec<GuideRecord>>) {
        let width = film.width;
        assert_eq!((film.width, film.height), self.size, "film and camera sizes differ");
        film.pixels
            .par_chunks_mut(width as usize)
            .enumerate()
            // Denormals flushed (see `without_denormals`): every sample of a film is taken under the same flags.
            .map(|(y, row)| without_denormals(|| self.render_row(row, y, (first, count), (learn, keep), hooks)))
            .collect::<Vec<_>>()
            .into_iter()
            .fold((PassStats::default(), Vec::new()), |(mut stats, mut rows), (s, records)| {
                stats += s;
                if learn {
                    rows.push(records);
                }
                (stats, rows)
            })
    }

    /// Row `y`'s samples `first..first + count` (`samples`), added to its pixels if `keep`; with `learn`, the
    /// guide records of the row.
    #[inline]
    fn render_row(
        &self,
        row: &mut [PixelAccum],
        y: usize,
        (first, count): (u32, u32),
        (learn, keep): (bool, bool),
        hooks: &PassHooks,
    ) -> (PassStats, Vec<GuideRecord>) {
        let width = row.len() as u32;
        let mut stats = PassStats::default();
        let mut records = Vec::new();
        if (hooks.cancelled)() {
            return (stats, records);
        }
        let cpu = ThreadTime::now();
        let mut learned = learn.then_some(&mut records);
        let mut add = |acc: &mut PixelAccum, v: Vec3| {
            if !v.is_finite() {
                stats.non_finite += 1;
            } else if keep {
                acc.add(v);
            }
        };
        let mut rays = 0;
        let streams = |x: usize| PixelStreams::new(self.settings.seed, y as u64 * width as u64 + x as u64);
        if count < GROUP_MIN_SAMPLES {
            let mut leaf = None;
            for (x, acc) in row.iter_mut().enumerate() {
                let streams = streams(x);
                for s in first..first + count {
                    let mut rng = streams.sample(s as u64);
                    let (dir, hit) = self.camera_ray(x as u32, y as u32, &mut rng);
                    rays += 1;
                    let learned = learned.as_deref_mut();
                    let shade = |hit| self.shade(dir, &hit, &mut rng, &mut rays, learned, &mut leaf);
                    add(acc, hit.map_or(Vec3::ZERO, shade));
                }
            }
        } else {
            // Through the pixel centres every sample shares one ray: no cone is needed (see below).
            let mut cones = (self.settings.footprint == Footprint::Jittered)
                .then(|| self.cones.row(&self.scene, &self.camera, y as u32, width));
            for (x, acc) in row.iter_mut().enumerate() {
                let (ids, tile) = cones.as_mut().and_then(|c| c.next()).unwrap_or((None, &TileLights::NONE));
                // Made here, where it is used: moved through the rows' iterators it was copied each time.
                let cone = ids.map(|ids| self.scene.cone(self.camera.eye(), ids));
                let streams = streams(x);
                // The pixel's sums stay in vectors over its groups (`PixelSums`).
                let mut sums = acc.sums();
                for group in (first..first + count).step_by(LANES) {
                    let samples = group..(group + LANES as u32).min(first + count);
                    let n = samples.len();
                    let pixel = (x as u32, y as u32);
                    let learned = learned.as_deref_mut();
                    let cone = (cone.as_ref(), tile);
                    let values = self.sample_lanes(pixel, &streams, samples, cone, &mut rays, learned);
                    if keep {
                        stats.non_finite += sums.add_lanes(&values, n);
                    } else {
                        let finite = values.x.is_finite() & values.y.is_finite() & values.z.is_finite();
                        stats.non_finite += (!finite.move_mask() as u32 & ((1 << n) - 1)).count_ones() as u64;
                    }
                }
                if keep {
                    sums.store(acc);
                }
            }
        }
        stats.rays = rays;
        stats.samples = count as u64 * width as u64;
        stats.cpu = cpu.elapsed();
        (hooks.row_done)(count);
        (stats, records)
    }

    /// Counts, over every `stride`-th pixel's samples `first..first + count` (taken as a pass would take them,
    /// but not added to any film), the directions along which L_i was looked for and those that found light:
    /// how often a strategy's shadow and BRDF rays pay off. Outside the timed passes: it costs what it counts.
    pub fn census(&self, first: u32, count: u32, stride: usize) -> Census {
        let (width, height) = self.size;
        (0..(width as usize * height as usize))
            .into_par_iter()
            .step_by(stride.max(1))
            // Under the passes' flags, so that a direction counts as lit where a pass finds it lit.
            .map(|i| {
                without_denormals(|| {
                    let (x, y) = ((i % width as usize) as u32, (i / width as usize) as u32);
                    let streams = PixelStreams::new(self.settings.seed, i as u64);
                    let mut census = Census::default();
                    for s in first..first + count {
                        let mut rng = streams.sample(s as u64);
                        let (dir, hit) = self.camera_ray(x, y, &mut rng);
                        if let Some(hit) = hit {
                            let sp = self.shading_point(dir, &hit);
                            self.settings.strategy.estimate(&self.context(), &sp, &mut rng, &mut 0, &mut census);
                        }
                    }
                    census
                })
            })
            .reduce(Census::default, |a, b| Census { traced: a.traced + b.traced, lit: a.lit + b.lit })
    }

    /// The shading point at a camera ray's hit.
    #[inline]
    fn shading_point(&self, dir: Vec3, hit: &Hit) -> ShadingPoint<'_> {
        let tri = &self.scene.triangles[hit.triangle as usize];
        let material = &self.scene.materials[tri.material as usize];
        ShadingPoint::on_triangle(self.scene.hit_point(hit), tri, -dir, material)
    }

    /// A camera ray through pixel (x, y), at a uniformly jittered position (box filter) or its centre (see
    /// [`Footprint`]), and its closest hit.
    #[inline]
    fn camera_ray(&self, x: u32, y: u32, rng: &mut SampleRng) -> (Vec3, Option<Hit>) {
        let dir = self.camera.direction(x, y, self.settings.footprint.position(rng.uniform_2d()));
        (dir, self.scene.accel().closest_hit(self.camera.eye(), dir, f32::INFINITY))
    }

    /// Samples `samples` (at most eight) of pixel (x, y), one per lane; lane l gets what [`Self::camera_ray`] and
    /// [`Self::shade`] give sample `samples.start + l`, bit for bit. `cone`, when given, holds every triangle the
    /// pixel's camera rays can hit; `tile` what its shadow rays can meet (`Scene::tile_lights`).
    #[inline]
    fn sample_lanes(
        &self,
        (x, y): (u32, u32),
        streams: &PixelStreams,
        samples: Range<u32>,
        (cone, tile): (Option<&ConeCandidates>, &TileLights),
        rays: &mut u64,
        mut learned: Option<&mut Vec<GuideRecord>>,
    ) -> Vec3x8 {
        let n = samples.len();
        let mut rngs = streams.samples(samples.start as u64);
        let footprint = self.settings.footprint;
        let (jitter_x, jitter_y) = (footprint.positions(rngs.uniform()), footprint.positions(rngs.uniform()));
        let dirs = self.camera.directions(x, y, jitter_x, jitter_y);
        let hits = match cone {
            // Every sample's ray is the centre's: traced once, as `camera_ray` traces it (a packet could break a
            // tie between two triangles, on an edge through the centre, the other way).
            _ if footprint == Footprint::Centre => {
                let hit = self.scene.accel().closest_hit(self.camera.eye(), dirs.lane(0), f32::INFINITY);
                HitLanes::from_hits(&std::array::from_fn(|l| if l < n { hit } else { None }))
            }
            Some(cone) => {
                // All bits set in lanes 0..n (a comparison's true).
                let active = f32x8::new([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]).cmp_lt(f32x8::splat(n as f32));
                cone.closest_hits(&dirs, active, f32::INFINITY)
            }
            // A pixel that sees too many triangles for a cone: its rays walk the tree as one packet.
            None => self.scene.accel().closest_hits_from(self.camera.eye(), &dirs, (1 << n) - 1, f32::INFINITY),
        };
        *rays += n as u64;
        let strategy = self.settings.strategy;
        let values = match (strategy, &self.emitters) {
            (Strategy::Emitter, Some(emitters)) => {
                return estimate_emitter_lanes(&self.scene, (emitters, tile), &dirs, &hits, &mut rngs, rays);
            }
            (_, Some(_)) if strategy.samples_lights() => {
                let mut rngs = std::array::from_fn(|l| rngs.lane(l));
                let ctx = SampleContext { tile, ..self.context() };
                // The bundled light strategies' own code, inlined; any other through the registry.
                match strategy {
                    Strategy::SolidAngle => estimate_solid_angle_lanes(&ctx, &dirs, &hits, &mut rngs, rays),
                    Strategy::ProjectedSolidAngle => {
                        estimate_projected_solid_angle_lanes(&ctx, &dirs, &hits, &mut rngs, rays)
                    }
                    _ => estimate_one_sample_lanes(&ctx, &strategy, &dirs, &hits, &mut rngs, rays),
                }
            }
            // The hemisphere strategies: their rays walk the tree together.
            (Strategy::Uniform | Strategy::Cosine | Strategy::Brdf, _) if learned.is_none() => {
                let mut rngs = std::array::from_fn(|l| rngs.lane(l));
                let ctx = SampleContext { tile, ..self.context() };
                estimate_one_sample_lanes(&ctx, &strategy, &dirs, &hits, &mut rngs, rays)
            }
            // `guided`, frozen or learning (a learning pass records every direction at its point's leaf).
            (Strategy::Guided, _) => {
                let mut rngs = std::array::from_fn(|l| rngs.lane(l));
                let ctx = SampleContext { tile, ..self.context() };
                match (learned, ctx.guide) {
                    (Some(out), Some(guide)) => {
                        let mut home = None;
                        let mut record = |sp: &ShadingPoint, r: SampleRecord| {
                            let (_, extent) = guide.stree.leaf_extent_near(sp.p, &mut home);
                            let (stree, p, samples) = (&guide.stree, sp.p, [1, 1]);
                            Learner { stree, home, p, extent, samples, out: &mut *out }.record(r);
                        };
                        estimate_guided_lanes(&ctx, &dirs, &hits, &mut rngs, rays, Some(&mut record))
                    }
                    _ => estimate_guided_lanes(&ctx, &dirs, &hits, &mut rngs, rays, None),
                }
            }
            // The default MIS (emitter and BRDF sampling, a direction each): the light directions in f32x8.
            (Strategy::Mis, Some(emitters))
                if learned.is_none()
                    && self.settings.mis.samples == [1, 1]
                    && self.settings.mis.techniques == [Strategy::Emitter, Strategy::Brdf] =>
            {
                let ctx = SampleContext { tile, ..self.context() };
                estimate_mis_emitter_brdf_lanes(&ctx, emitters, &dirs, &hits, &mut rngs, rays)
            }
            // MIS with one direction per technique, learning nothing: the light directions' shadow rays together.
            (Strategy::Mis, _)
                if learned.is_none() && self.settings.mis.is_valid() && self.settings.mis.samples == [1, 1] =>
            {
                let mut rngs = std::array::from_fn(|l| rngs.lane(l));
                let ctx = SampleContext { tile, ..self.context() };
                let lanes = (&dirs, &hits, &mut rngs, rays);
                // The usual pairs with their techniques' code inlined, as MIS's own estimator has them.
                match self.settings.mis.techniques {
                    [Strategy::Emitter, Strategy::Brdf] => mis_lanes(&ctx, (&Emitter, &Brdf), lanes),
                    [Strategy::SolidAngle, Strategy::Brdf] => mis_lanes(&ctx, (&SolidAngle, &Brdf), lanes),
                    [Strategy::ProjectedSolidAngle, Strategy::Brdf] => {
                        mis_lanes(&ctx, (&ProjectedSolidAngle, &Brdf), lanes)
                    }
                    [a, b] => mis_lanes(&ctx, (&a, &b), lanes),
                }
            }
            _ => {
                // The lanes' points mostly share a spatial leaf of the guide: found once, then by a box test.
                let mut leaf = None;
                std::array::from_fn(|l| {
                    hits.lane(l).map_or(Vec3::ZERO, |hit| {
                        self.shade(dirs.lane(l), &hit, &mut rngs.lane(l), rays, learned.as_deref_mut(), &mut leaf)
                    })
                })
            }
        };
        Vec3x8::from_lanes(&values)
    }

    /// One sample of `L = L_e(x, ω_o) + ∫ f_r L_i (ω·n) dω` at the first surface x seen along the camera ray `dir`;
    /// with `learned`, the directions evaluated are recorded there for the guide (x's spatial leaf found through
    /// `leaf`, see [`STree::leaf_near`]).
    #[inline]
    fn shade(
        &self,
        dir: Vec3,
        hit: &Hit,
        rng: &mut SampleRng,
        rays: &mut u64,
        learned: Option<&mut Vec<GuideRecord>>,
        leaf: &mut Option<LeafHint>,
    ) -> Vec3 {
        let sp = self.shading_point(dir, hit);
        let emitted = self.scene.emitted(hit.triangle, -dir);
        let (strategy, ctx) = (self.settings.strategy, self.context());
        let estimate = match (learned, ctx.guide) {
            (Some(out), Some(guide)) => {
                // MIS divides technique i's directions by n_i; one-sample strategies take one (technique 0).
                let samples = if strategy == Strategy::Mis { ctx.mis.samples } else { [1, 1] };
                let (_, extent) = guide.stree.leaf_extent_near(sp.p, leaf);
                let mut learner = Learner { stree: &guide.stree, home: *leaf, p: sp.p, extent, samples, out };
                strategy.estimate(&ctx, &sp, rng, rays, &mut learner)
            }
            _ => strategy.estimate(&ctx, &sp, rng, rays, &mut ()),
        };
        emitted + estimate
    }
}

/// [`estimate_mis_lanes`] with the lanes' arguments in one tuple.
#[inline(always)]
fn mis_lanes(
    ctx: &SampleContext,
    techniques: (&impl super::strategy::Technique, &impl super::strategy::Technique),
    (dirs, hits, rngs, rays): (&crate::math::Vec3x8, &HitLanes, &mut [SampleRng; LANES], &mut u64),
) -> [Vec3; LANES] {
    estimate_mis_lanes(ctx, techniques, dirs, hits, rngs, rays)
}

mod settings;
#[cfg(test)]
mod tests;

pub use settings::{PassStats, RenderSettings};
