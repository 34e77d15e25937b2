//! The per-sample record sink: every direction an estimator evaluates can be reported, with its density, MIS
//! weight, contribution and, where it contributes nothing, why. The probe draws and counts them; a learning
//! strategy would train on them. The sink is a type parameter, so the production path, which passes `()`,
//! builds no record and pays nothing.

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
}

impl SampleRecord {
    /// A strategy that could draw no direction.
    #[inline(always)]
    pub fn none(technique: u8) -> Self {
        let (wi, contribution, radiance) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
        let (pdf, outcome, parts) = (0.0, Outcome::NoSample, [0.0; 3]);
        Self { technique, wi, pdf, mis_weight: 0.0, contribution, radiance, outcome, parts }
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
