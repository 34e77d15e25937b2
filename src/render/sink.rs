//! The per-sample record sink: every direction an estimator evaluates can be reported, with its density, MIS
//! weight, contribution and, where it contributes nothing, why. The probe draws and counts them, the bench counts
//! those that found light ([`Census`]), and a pass that learns turns them into guide records ([`Learner`]). The
//! sink is a type parameter, so the production path, which passes `()`,
//! builds no record and pays nothing.

use crate::guiding::{Found, GuideRecord, LeafHint, MixtureSample, STree};
use crate::math::{hash_ray, luminance};
use glam::Vec3;

/// Why a direction contributed what it did.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Outcome {
    /// f_r L_i (ω·n) > 0.
    Contributed,
    /// The strategy could draw no direction (e.g. it picked the back of a one-sided light).
    NoSample,
    /// ω·n ≤ 0: below the surface.
    BelowSurface,
    /// f_r(ω, ω_o) = 0 (a black material, or outside every lobe).
    ZeroBrdf,
    /// The ray reached no emitting surface.
    MissedLights,
    /// The shadow ray towards the sampled point on a light was blocked.
    Occluded,
}

impl Outcome {
    pub const ZERO: [Outcome; 5] =
        [Outcome::NoSample, Outcome::BelowSurface, Outcome::ZeroBrdf, Outcome::MissedLights, Outcome::Occluded];

    pub fn name(self) -> &'static str {
        match self {
            Outcome::Contributed => "contributed",
            Outcome::NoSample => "no sample",
            Outcome::BelowSurface => "below the surface",
            Outcome::ZeroBrdf => "zero BRDF",
            Outcome::MissedLights => "missed every light",
            Outcome::Occluded => "occluded",
        }
    }

    /// A name for keys and JSON.
    pub fn slug(self) -> &'static str {
        match self {
            Outcome::Contributed => "contributed",
            Outcome::NoSample => "no_sample",
            Outcome::BelowSurface => "below_surface",
            Outcome::ZeroBrdf => "zero_brdf",
            Outcome::MissedLights => "missed_lights",
            Outcome::Occluded => "occluded",
        }
    }
}

/// One evaluated direction.
#[derive(Clone, Copy, Debug)]
pub struct SampleRecord {
    /// Which technique drew it: 0, or for MIS the index of the technique in [`super::MisSettings::techniques`].
    pub technique: u8,
    /// ω_k (zero for [`Outcome::NoSample`]).
    pub wi: Vec3,
    /// The density it was drawn with, p(ω_k).
    pub pdf: f32,
    /// Its MIS weight (1 outside MIS).
    pub mis_weight: f32,
    /// What it adds to the estimate: `w f_r L_i (ω·n) / (n p)`.
    pub contribution: Vec3,
    /// L_i(ω_k): the radiance that arrived along it (zero where it was occluded or missed every light; zero
    /// too where no ray was traced, see `outcome`).
    pub radiance: Vec3,
    pub outcome: Outcome,
    /// For a one-sample mixture over a learned guide (`guided`): the densities of its guide, light and BRDF
    /// parts at ω_k, of which `pdf` is the weighted sum. Zero for every other strategy.
    pub parts: [f32; 3],
    /// The point on an emitter where L_i was found (zero where none was).
    pub hit: Vec3,
}

impl SampleRecord {
    /// A strategy that could draw no direction.
    #[inline(always)]
    pub fn none(technique: u8) -> Self {
        let (wi, contribution, radiance) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
        let (pdf, outcome, parts) = (0.0, Outcome::NoSample, [0.0; 3]);
        Self { technique, wi, pdf, mis_weight: 0.0, contribution, radiance, outcome, parts, hit: Vec3::ZERO }
    }

    /// Whether L_i was found along ω_k (a ray was traced): what a learning strategy can learn from.
    #[inline(always)]
    pub fn traced(&self) -> bool {
        matches!(self.outcome, Outcome::Contributed | Outcome::MissedLights | Outcome::Occluded)
    }
}

/// Receives the records of the directions an estimator evaluates.
pub trait SampleSink {
    fn record(&mut self, record: SampleRecord);
}

/// No sink: the production path.
impl SampleSink for () {
    #[inline(always)]
    fn record(&mut self, _: SampleRecord) {}
}

impl SampleSink for Vec<SampleRecord> {
    fn record(&mut self, record: SampleRecord) {
        self.push(record);
    }
}

/// Directions along which L_i was looked for (a ray traced), and those that found light.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Census {
    pub traced: u64,
    pub lit: u64,
}

impl Census {
    /// The share of traced directions that found light.
    pub fn success_rate(&self) -> f64 {
        if self.traced == 0 { 0.0 } else { self.lit as f64 / self.traced as f64 }
    }
}

impl SampleSink for Census {
    fn record(&mut self, r: SampleRecord) {
        if r.traced() {
            self.traced += 1;
            self.lit += (r.radiance != Vec3::ZERO) as u64;
        }
    }
}

/// The sink of a pass that learns: every direction along which L_i was found becomes a guide record of the
/// shading point's spatial leaf, valued `w L_i / (n_i p_i)` (luminance; w the MIS weight and n_i the directions
/// of its technique, both 1 outside MIS): summed over a pixel sample's directions, an unbiased estimate of
/// ∫ L_i over each direction cell, whichever technique drew it.
///
/// Each record goes to the leaf of a point jittered uniformly within the box of the shading point's leaf
/// (Müller et al. 2017's stochastic spatial box filter, so that neighbouring leaves share what they learn); the
/// jitter is a hash of the point and the direction, so it depends on nothing but the sample. A record that found
/// light carries its ray, from the shading point to the light's point (the leaf learns it where the leaf's rays
/// converge: [`crate::guiding::Training::learn`]); the others add no energy and only count.
pub(super) struct Learner<'a> {
    pub(super) stree: &'a STree,
    /// The leaf holding p (a jittered point in it is found by a box test).
    pub(super) home: Option<LeafHint>,
    pub(super) p: Vec3,
    /// The size of the box of the leaf holding p.
    pub(super) extent: Vec3,
    /// Directions per pixel sample of each technique (n_0, n_1).
    pub(super) samples: [u32; 2],
    pub(super) out: &'a mut Vec<GuideRecord>,
}

impl SampleSink for Learner<'_> {
    #[inline]
    fn record(&mut self, r: SampleRecord) {
        if r.traced() && r.pdf > 0.0 {
            let n = self.samples[(r.technique as usize).min(1)].max(1) as f32;
            let value = r.mis_weight * luminance(r.radiance) / (n * r.pdf);
            let bits = hash_ray(self.p, r.wi);
            let u = Vec3::new(
                (bits & 0x1f_ffff) as f32,
                ((bits >> 21) & 0x1f_ffff) as f32,
                ((bits >> 42) & 0x1f_ffff) as f32,
            ) / (1u32 << 21) as f32;
            let leaf = self.stree.leaf_near(self.p + (u - 0.5) * self.extent, &mut { self.home });
            let mixture = (r.parts != [0.0; 3]).then(|| MixtureSample {
                contribution: luminance(r.contribution),
                pdf: r.pdf,
                parts: r.parts,
            });
            let found = (value > 0.0).then_some(Found { value, from: self.p, at: r.hit });
            self.out.push(GuideRecord { leaf, found, mixture });
        }
    }
}
