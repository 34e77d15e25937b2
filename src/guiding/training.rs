//! Learning the guide, iteration by iteration (Müller et al. 2017, §3.4): iteration k takes the samples
//! `2^k − 1 .. 2^(k+1) − 1` of every pixel (1, 2, 4, … samples per pixel), sampled with the guide built from
//! iteration k − 1 (none for k = 0), and records each evaluated direction into the sums of a tree shaped by that
//! guide. At the end of the iteration the sums become the next guide: leaves that received more than
//! `c √(2^k)` records are split, and each quadtree is refined where a quadrant holds more than 1% of its energy.
//! Iterations that end within the training budget learn; after them the guide is frozen.
//!
//! A pass is unbiased given the frozen guide it samples from, so every pass may be kept. The guide is a function
//! of the records only, summed in fixed point: the same for any order, so for any thread count and any split
//! into passes, provided every sample of an iteration is recorded exactly once. A pass that does not continue
//! the iteration where the last one stopped (a restart) starts the iteration's records again.

use super::{
    DTree, FocusMoments, Guide, MixtureSample, Moments, STree, Sums, anchor_direction, dir_to_square, light_fingerprint,
};
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

/// A record that found light as its leaf's quadtree took it: square point, value, distance from the anchor; for a
/// sample of `guided`, what scores the mixture weights.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Lit {
    square: Vec2,
    value: f32,
    distance: Option<f32>,
    scored: Option<Scored>,
}

/// A sample of `guided` that found light, as the weights score it against the guide built from its iteration:
/// its point and direction (for the new guide's density there), and its [`MixtureSample`] (whose guide part was
/// the old guide's).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Scored {
    from: Vec3,
    wi: Vec3,
    sample: MixtureSample,
}

impl Scored {
    /// A hash of its point and direction (which of a leaf's samples are scored).
    fn hash(&self) -> u64 {
        hash_ray(self.from, self.wi)
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
    /// Per leaf of the guide's spatial tree: the records of the current iteration.
    sums: Vec<Sums>,
    /// Per leaf: where the current iteration's rays converge.
    foci: Vec<FocusMoments>,
    /// Per leaf: the current iteration's records that found light, as recorded (recorded again at the build,
    /// into a quadtree refined where they put their energy).
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
        let sums = guide.dtrees.iter().map(|d| Sums::new(d.refined_shape(ENERGY_THRESHOLD, MAX_DTREE_DEPTH))).collect();
        let foci = vec![FocusMoments::default(); guide.dtrees.len()];
        let lit = vec![Vec::new(); guide.dtrees.len()];
        let (iteration, next, log, learning) = (0, 0, Vec::new(), Duration::ZERO);
        Self { settings, guide, sums, foci, lit, iteration, next, log, learning, kept: false }
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
            self.sums.iter_mut().for_each(|s| *s = Sums::new(s.shape().clone()));
            self.foci.iter_mut().for_each(|m| *m = FocusMoments::default());
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
    /// next guide when they complete the iteration. Leaves take their records in parallel (the sums are exact,
    /// so the order does not matter). A record that found light goes into its leaf's quadtree as the direction
    /// from the leaf's anchor toward the point of its ray at the leaf's focus, with that point's distance.
    pub fn learn(&mut self, records: impl IntoIterator<Item = GuideRecord>, until: u32) {
        let start = Instant::now();
        let mut by_leaf: Vec<Vec<GuideRecord>> = vec![Vec::new(); self.sums.len()];
        for r in records {
            if let Some(bucket) = by_leaf.get_mut(r.leaf as usize) {
                bucket.push(r);
            }
        }
        let (centres, foci) = (&self.guide.centres, &self.guide.foci);
        let leaves = self.sums.par_iter_mut().zip(self.foci.par_iter_mut()).zip(self.lit.par_iter_mut());
        leaves.zip(by_leaf).enumerate().for_each(|(leaf, (((sums, focus), lit), records))| {
            let (c, f) = (centres[leaf], foci[leaf]);
            for r in records {
                match r.found {
                    Some(Found { value, from, at }) => {
                        let wi = (at - from).normalize_or(Vec3::Z);
                        let (d, distance) = match anchor_direction(c, from + (at - from) * f) {
                            Some((d, distance)) => (d, Some(distance)),
                            None => (wi, None),
                        };
                        let scored = r.mixture.map(|sample| Scored { from, wi, sample });
                        let record = Lit { square: dir_to_square(d), value, distance, scored };
                        sums.record(record.square, value);
                        lit.push(record);
                        focus.record(from - c, at - c, value);
                    }
                    None => sums.record_empty(),
                }
            }
        });
        self.learning += start.elapsed();
        self.next = until;
        if until == iteration_samples(self.iteration).end {
            self.build();
        }
    }

    /// The next guide from this iteration's sums.
    fn build(&mut self) {
        let start = Instant::now();
        let records: u64 = self.sums.iter().map(|s| s.records).sum();
        // The sums were recorded (unfiltered) into a quadtree shaped by the last iteration's light; where this
        // iteration's light fell elsewhere (a focus that moved, a leaf just split whose anchor moved) they hold it
        // in coarse cells. They only shape the quadtree the records then go into, filtered: refined where the light
        // fell, it resolves the light as finely wherever it is. The weights are then scored against this new guide
        // (its density at each sample's direction), on the samples it was built from: E_c[X²] =
        // E_old[g² / (p_c p_old)] holds for any new density in p_c.
        let sums = self.sums.par_iter().zip(&self.lit);
        let (densities, moments): (Vec<DTree>, Vec<Moments>) = sums
            .zip(&self.guide.centres)
            .map(|((sums, lit), &c)| {
                let mut again = Sums::new(sums.density().refined_shape(ENERGY_THRESHOLD, MAX_DTREE_DEPTH));
                lit.iter().for_each(|r| again.record_filtered(r.square, r.value, r.distance));
                let density = again.density_about(c);
                // At most about SCORED of them (those whose hash falls on a multiple of the stride: the same set in
                // any order): a few thousand samples choose among the candidates as well as millions would.
                let scored = lit.iter().filter_map(|r| r.scored.as_ref());
                let stride = (scored.clone().count() as u64).div_ceil(SCORED).max(1);
                let mut moments = Moments::default();
                for s in scored.filter(|s| s.hash() % stride == 0) {
                    let [_, light, brdf] = s.sample.parts;
                    moments.record(&MixtureSample { parts: [density.pdf_at(s.from, s.wi), light, brdf], ..s.sample });
                }
                (density, moments)
            })
            .unzip();
        let (mut weight_sum, mut lit_leaves) = ([0.0f32; 3], 0);
        let counts: Vec<u64> = self.sums.iter().map(|s| s.records).collect();
        let mut stree: STree = self.guide.stree.clone();
        let threshold = self.settings.spatial_threshold as f64 * (self.iteration as f64).exp2().sqrt();
        let parents = stree.split(&counts, threshold, MAX_STREE_DEPTH);
        let dtrees: Vec<DTree> = parents.iter().map(|&p| densities[p as usize].clone()).collect();
        let weights = parents.iter().map(|&p| moments[p as usize].best()).collect::<Vec<_>>();
        let foci = parents.iter().map(|&p| self.foci[p as usize].fraction()).collect::<Vec<_>>();
        for (w, &p) in weights.iter().zip(&parents) {
            if self.sums[p as usize].records > 0 {
                (0..3).for_each(|k| weight_sum[k] += w[k]);
                lit_leaves += 1;
            }
        }
        self.sums = dtrees.iter().map(|d| Sums::new(d.refined_shape(ENERGY_THRESHOLD, MAX_DTREE_DEPTH))).collect();
        self.foci = vec![FocusMoments::default(); dtrees.len()];
        self.lit = vec![Vec::new(); dtrees.len()];
        let centres = stree.leaf_centres();
        let fingerprint = self.guide.fingerprint;
        self.guide = Arc::new(Guide { stree, dtrees, weights, centres, foci, fingerprint });
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
