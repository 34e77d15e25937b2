//! Learning the guide, iteration by iteration (Müller et al. 2017, §3.4): iteration k takes the samples
//! `2^k − 1 .. 2^(k+1) − 1` of every pixel (1, 2, 4, … samples per pixel), sampled with the guide built from
//! iteration k − 1 (none for k = 0), and keeps each evaluated direction that found light with its spatial leaf.
//! At the end of the iteration they become the next guide: each leaf fits its focal plane to them and sums them
//! into a quadtree refined where a quadrant holds more than 1% of its energy (or lies on an edge of the light);
//! leaves that received more than `c √(2^k)` records are split. Iterations that end within the training budget
//! learn; after them the guide is frozen.
//!
//! A pass is unbiased given the frozen guide it samples from, so every pass may be kept. The guide is a function
//! of the records only, every sum in fixed point: the same for any order, so for any thread count and any split
//! into passes, provided every sample of an iteration is recorded exactly once. A pass that does not continue
//! the iteration where the last one stopped (a restart) starts the iteration's records again.

use super::{Anchor, DTree, Guide, MixtureSample, Moments, STree, Sums, dir_to_square, focal_plane, light_fingerprint};
use crate::math::hash_ray;
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A quadrant holding more than this share of a quadtree's energy is split for the next iteration.
const ENERGY_THRESHOLD: f64 = 0.01;
/// Quadtree levels at most (Müller's 20 less 8; cells of 2⁻¹² square, 0.015°, are far finer than direct light from
/// area lights needs). A direction is stored in f32: one drawn within rounding (~10⁻⁷) of its leaf's edge may
/// map back into the neighbouring leaf and be given that leaf's density. The deeper the leaf, the larger that
/// share: ~2·10⁻⁴ of draws at depth 10 (measured by `tests/guided.rs`), ~10⁻² it would be at depth 16.
const MAX_DTREE_DEPTH: usize = 12;
/// Samples a leaf scores its mixture weights on, about, at most.
const SCORED: u64 = 2048;
/// Records that found light a leaf fits its focal plane to, about, at most.
const FITTED: u64 = 4096;
/// Spatial tree levels at most.
const MAX_STREE_DEPTH: usize = 30;

/// How a guide learns.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct GuideSettings {
    /// Samples per pixel of training: the iterations that end within it learn, then the guide is frozen.
    pub training_spp: u32,
    /// Müller's c: a spatial leaf with more than `c √(2^k)` records in iteration k is split.
    pub spatial_threshold: u32,
    /// Leave the training samples out of the image (they are unbiased, but noisier).
    pub discard_training: bool,
}

impl Default for GuideSettings {
    fn default() -> Self {
        Self { training_spp: 64, spatial_threshold: 1000, discard_training: false }
    }
}

impl GuideSettings {
    /// Samples `0..training_end()` are taken while learning.
    pub fn training_end(&self) -> u32 {
        (0..32).map(iteration_samples).take_while(|r| r.end <= self.training_spp).last().map_or(0, |r| r.end)
    }
}

/// The samples of every pixel that iteration k records: `2^k − 1 .. 2^(k+1) − 1`.
pub fn iteration_samples(k: u32) -> Range<u32> {
    let start = (1u64 << k) - 1;
    start.min(u32::MAX as u64) as u32..((1u64 << (k + 1)) - 1).min(u32::MAX as u64) as u32
}

/// One recorded direction: the spatial leaf of its point, and what it found; for a sample of `guided` itself,
/// what its leaf's mixture weights learn from. A record that found nothing counts toward its leaf's split.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuideRecord {
    pub leaf: u32,
    pub found: Option<Found>,
    pub mixture: Option<MixtureSample>,
}

/// Light found along a recorded direction: `L_i / p` (luminance, > 0), the shading point and the light's point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Found {
    pub value: f32,
    pub from: Vec3,
    pub at: Vec3,
}

/// A record that found light, kept until its iteration's guide is built: its ray from the shading point to the
/// light, its value, and for a sample of `guided`, what scores the mixture weights (a [`MixtureSample`] whose
/// guide part was the old guide's).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Lit {
    from: Vec3,
    at: Vec3,
    value: f32,
    mixture: Option<MixtureSample>,
}

/// Every how many of `count` records one is chosen to keep about `at_most` of them.
fn stride_for(count: usize, at_most: u64) -> u64 {
    (count as u64).div_ceil(at_most).max(1)
}

/// Whether the ray from `from` along `wi` is among the one in `stride` chosen by its hash (the same set in any
/// order).
fn chosen(from: Vec3, wi: Vec3, stride: u64) -> bool {
    stride == 1 || hash_ray(from, wi).is_multiple_of(stride)
}

impl Lit {
    /// The ray's direction.
    fn wi(&self) -> Vec3 {
        (self.at - self.from).normalize_or(Vec3::Z)
    }
}

/// What one iteration built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IterationReport {
    pub iteration: u32,
    /// Samples per pixel learned from by the end of this iteration.
    pub spp: u32,
    pub records: u64,
    pub leaves: usize,
    pub dtree_nodes: usize,
    pub bytes: usize,
    /// Time spent adding the iteration's records to the sums (splats and weight scores).
    pub learn: Duration,
    /// Time spent building the next guide from the sums.
    pub build: Duration,
    /// The next guide's mixture weights (c_g, c_l, c_b), the mean over its leaves that received records.
    pub weights: [f32; 3],
}

/// `iteration 5: learned from 63 spp (1562225 records, 198.8 ms), 2010 spatial leaves, 140313 quadtree nodes,
/// 6608.6 KiB, built in 16.8 ms` (one line; `scripts/guide-sizes.sh` reads it).
impl std::fmt::Display for IterationReport {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(
            f,
            "iteration {}: learned from {} spp ({} records, {:.1} ms), {} spatial leaves, {} quadtree nodes, {:.1} KiB, \
             built in {:.1} ms, mean weights (guide, light, BRDF) ({:.2}, {:.2}, {:.2})",
            self.iteration,
            self.spp,
            self.records,
            self.learn.as_secs_f64() * 1e3,
            self.leaves,
            self.dtree_nodes,
            self.bytes as f64 / 1024.0,
            self.build.as_secs_f64() * 1e3,
            self.weights[0],
            self.weights[1],
            self.weights[2]
        )
    }
}

/// Where the training stands, for the viewer's status line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrainingStatus {
    /// The guide was learned before (kept across a camera or material change), not by this render.
    pub kept: bool,
    /// The iteration being recorded (or, when frozen, the number of iterations).
    pub iteration: u32,
    /// Samples per pixel the current guide learned from.
    pub learned_spp: u32,
    pub frozen: bool,
    pub leaves: usize,
    pub dtree_nodes: usize,
    pub bytes: usize,
    /// The last iteration's build time.
    pub build: Duration,
}

/// A guide being learned.
#[derive(Clone, Debug)]
pub struct Training {
    settings: GuideSettings,
    guide: Arc<Guide>,
    /// Per leaf of the guide's spatial tree: how many records the current iteration gave it.
    records: Vec<u64>,
    /// Per leaf: the current iteration's records that found light (its quadtree at the build).
    lit: Vec<Vec<Lit>>,
    iteration: u32,
    /// The sample the current iteration's records continue from.
    next: u32,
    log: Vec<IterationReport>,
    /// Time spent in [`Training::learn`] this iteration.
    learning: Duration,
    /// Learned before this training began ([`Training::kept`]): frozen from the start.
    kept: bool,
}

impl Training {
    /// Starts with no guide, over the scene's box.
    pub fn new(scene: &Scene, settings: GuideSettings) -> Self {
        let (lo, hi) = scene
            .triangles
            .iter()
            .flat_map(|t| t.v)
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let (lo, hi) = if lo.cmple(hi).all() { (lo, hi) } else { (Vec3::ZERO, Vec3::ONE) };
        Self::from_guide(Arc::new(Guide::empty(lo, hi, light_fingerprint(scene))), settings)
    }

    fn from_guide(guide: Arc<Guide>, settings: GuideSettings) -> Self {
        let (records, lit) = (vec![0; guide.dtrees.len()], vec![Vec::new(); guide.dtrees.len()]);
        let (iteration, next, log, learning) = (0, 0, Vec::new(), Duration::ZERO);
        Self { settings, guide, records, lit, iteration, next, log, learning, kept: false }
    }

    /// A guide learned earlier (e.g. kept across a camera change), used as it is: it learns no more.
    pub fn kept(guide: Arc<Guide>, settings: GuideSettings) -> Self {
        Self { kept: true, ..Self::from_guide(guide, settings) }
    }

    /// The guide passes sample from now.
    pub fn guide(&self) -> &Arc<Guide> {
        &self.guide
    }

    pub fn settings(&self) -> &GuideSettings {
        &self.settings
    }

    /// Whether the guide no longer learns.
    pub fn is_frozen(&self) -> bool {
        self.kept || iteration_samples(self.iteration).end > self.settings.training_spp
    }

    /// Whether its guide was learned before it began.
    pub fn is_kept(&self) -> bool {
        self.kept
    }

    /// What each iteration built.
    pub fn log(&self) -> &[IterationReport] {
        &self.log
    }

    pub fn status(&self) -> TrainingStatus {
        let last = self.log.last();
        TrainingStatus {
            kept: self.kept,
            iteration: self.iteration,
            learned_spp: last.map_or(0, |r| r.spp),
            frozen: self.is_frozen(),
            leaves: self.guide.stree.leaves(),
            dtree_nodes: self.guide.dtree_nodes(),
            bytes: self.guide.bytes(),
            build: last.map_or(Duration::ZERO, |r| r.build),
        }
    }

    /// How to take samples `first..end`: the first `stop − first` of them, recording them or not. A range that
    /// learns never crosses an iteration's end, so the guide changes only between ranges.
    pub fn plan(&mut self, first: u32, end: u32) -> (u32, bool) {
        if self.is_frozen() {
            return (end, false);
        }
        let samples = iteration_samples(self.iteration);
        if first != self.next {
            // A restart or a gap: this iteration's records start again from its first sample.
            self.records.iter_mut().for_each(|n| *n = 0);
            self.lit.iter_mut().for_each(Vec::clear);
            self.next = samples.start;
        }
        if first < samples.start {
            (end.min(samples.start), false)
        } else if first == self.next {
            (end.min(samples.end), true)
        } else {
            (end, false)
        }
    }

    /// Takes the records of samples `self.next..until` (a range [`Training::plan`] said to record); builds the
    /// next guide when they complete the iteration. Each leaf counts its records and keeps those that found light.
    pub fn learn(&mut self, records: impl IntoIterator<Item = GuideRecord>, until: u32) {
        let start = Instant::now();
        for r in records {
            let leaf = r.leaf as usize;
            let Some(count) = self.records.get_mut(leaf) else { continue };
            *count += 1;
            if let Some(Found { value, from, at }) = r.found {
                self.lit[leaf].push(Lit { from, at, value, mixture: r.mixture });
            }
        }
        self.learning += start.elapsed();
        self.next = until;
        if until == iteration_samples(self.iteration).end {
            self.build();
        }
    }

    /// The next guide from this iteration's sums.
    fn build(&mut self) {
        let start = Instant::now();
        let records: u64 = self.records.iter().sum();
        // Each leaf's lit records are learned as its anchor sees them through its focal plane (fitted to them).
        // They are first recorded unfiltered into the last guide's quadtree refined once, which only shapes the
        // quadtree they then go into, filtered: refined where the light fell, it resolves the light as finely
        // wherever it is. The weights are then scored against this new guide (its density at each sample's
        // direction), on the samples it was built from: E_c[X²] = E_old[g² / (p_c p_old)] holds for any new
        // density in p_c.
        let leaves = self.lit.par_iter().zip(&self.guide.dtrees).zip(&self.guide.centres);
        let (densities, moments): (Vec<DTree>, Vec<Moments>) = leaves
            .map(|((lit, old), &c)| {
                // The plane from at most about FITTED of them (chosen by hash, as the scored samples below).
                let stride = stride_for(lit.len(), FITTED);
                let fitted = lit.iter().filter(|r| chosen(r.from, r.wi(), stride));
                let plane = focal_plane(fitted.map(|r| (r.from - c, r.at - c, r.value)));
                let anchor = plane.map(|(normal, height)| Anchor { centre: c, normal, height });
                let square = |r: &Lit| {
                    let wi = r.wi();
                    dir_to_square(anchor.map_or(wi, |a| a.direction_of(r.from, wi)))
                };
                let squares: Vec<Vec2> = lit.iter().map(square).collect();
                let mut shaping = Sums::new(old.refined_shape(ENERGY_THRESHOLD, MAX_DTREE_DEPTH));
                squares.iter().zip(lit).for_each(|(&s, r)| shaping.record(s, r.value));
                let mut again = Sums::new(shaping.density().refined_shape(ENERGY_THRESHOLD, MAX_DTREE_DEPTH));
                squares.iter().zip(lit).for_each(|(&s, r)| again.record_filtered(s, r.value));
                let density = again.density().with_anchor(anchor);
                // At most about SCORED of them (those whose hash falls on a multiple of the stride: the same set in
                // any order): a few thousand samples choose among the candidates as well as millions would.
                let scored = lit.iter().filter_map(|r| r.mixture.map(|m| (r.from, r.wi(), m)));
                let stride = stride_for(scored.clone().count(), SCORED);
                let mut moments = Moments::default();
                for (from, wi, sample) in scored.filter(|&(from, wi, _)| chosen(from, wi, stride)) {
                    let [_, light, brdf] = sample.parts;
                    moments.record(&MixtureSample { parts: [density.pdf_at(from, wi), light, brdf], ..sample });
                }
                (density, moments)
            })
            .unzip();
        let (mut weight_sum, mut lit_leaves) = ([0.0f32; 3], 0);
        let mut stree: STree = self.guide.stree.clone();
        let threshold = self.settings.spatial_threshold as f64 * (self.iteration as f64).exp2().sqrt();
        let parents = stree.split(&self.records, threshold, MAX_STREE_DEPTH);
        let dtrees: Vec<DTree> = parents.iter().map(|&p| densities[p as usize].clone()).collect();
        let weights = parents.iter().map(|&p| moments[p as usize].best()).collect::<Vec<_>>();
        for (w, &p) in weights.iter().zip(&parents) {
            if self.records[p as usize] > 0 {
                (0..3).for_each(|k| weight_sum[k] += w[k]);
                lit_leaves += 1;
            }
        }
        self.records = vec![0; dtrees.len()];
        self.lit = vec![Vec::new(); dtrees.len()];
        let centres = stree.leaf_centres();
        let fingerprint = self.guide.fingerprint;
        self.guide = Arc::new(Guide { stree, dtrees, weights, centres, fingerprint });
        self.log.push(IterationReport {
            iteration: self.iteration,
            spp: iteration_samples(self.iteration).end,
            records,
            leaves: self.guide.stree.leaves(),
            dtree_nodes: self.guide.dtree_nodes(),
            bytes: self.guide.bytes(),
            learn: std::mem::take(&mut self.learning),
            build: start.elapsed(),
            weights: weight_sum.map(|w| w / lit_leaves.max(1) as f32),
        });
        self.iteration += 1;
        self.next = iteration_samples(self.iteration).start;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iterations_double() {
        let ranges: Vec<_> = (0..4).map(iteration_samples).collect();
        assert_eq!(ranges, vec![0..1, 1..3, 3..7, 7..15]);
        assert_eq!(GuideSettings { training_spp: 64, ..Default::default() }.training_end(), 63);
        assert_eq!(GuideSettings { training_spp: 16, ..Default::default() }.training_end(), 15);
        assert_eq!(GuideSettings { training_spp: 0, ..Default::default() }.training_end(), 0);
    }

    /// Passes split anywhere learn at the same samples; a restart records the iteration again.
    #[test]
    fn plans_follow_the_iterations() {
        let scene = crate::scene::load_scene("cornell-box").expect("bundled");
        let mut t = Training::new(&scene, GuideSettings { training_spp: 8, ..Default::default() });
        assert_eq!(t.plan(0, 13), (1, true));
        t.learn([], 1);
        assert_eq!(t.plan(1, 2), (2, true));
        t.learn([], 2);
        assert_eq!(t.plan(2, 13), (3, true));
        t.learn([], 3);
        // A restart at 0 while iteration 2 (samples 3..7) is due: 0..3 with the guide, then learn from 3.
        assert_eq!(t.plan(0, 5), (3, false));
        assert_eq!(t.plan(3, 5), (5, true));
        t.learn([], 5);
        assert_eq!(t.plan(5, 13), (7, true));
        t.learn([], 7);
        assert!(t.is_frozen(), "iteration 3 would end at 15 > 8");
        assert_eq!(t.plan(7, 13), (13, false));
        assert_eq!(t.log().len(), 3);
    }
}
