//! Multiple importance sampling (Veach & Guibas 1995; Veach 1997 ch. 9), as a combinator of any two techniques
//! of the registry, multi-sample form: per pixel sample, n_0 directions from technique 0 (by default a light
//! strategy) and n_1 from technique 1 (by default BRDF sampling), each weighted by
//! `w_i(ω) = (n_i p_i(ω))^β / Σ_j (n_j p_j(ω))^β` (β = 1: balance heuristic, β = 2: power heuristic):
//!
//! `F = Σ_{k<n_0} w_0 f L cos / (n_0 p_0) + Σ_{k<n_1} w_1 f L cos / (n_1 p_1)`.
//!
//! The weights of the two techniques sum to one for every direction, so F is unbiased; a weight that is not
//! finite is 0 (Mitsuba's rule). As a (sample, pdf) pair — what the probe draws and the chi-square tests check —
//! MIS is the mixture its directions come from: technique i with probability n_i / (n_0 + n_1), so
//! `p(ω) = (n_0 p_0(ω) + n_1 p_1(ω)) / (n_0 + n_1)`.

use super::{DirectionSample, DirectionStrategy, Domain, Reached, SampleContext, Strategy, StrategyState, Technique};
use crate::math::SampleRng;
use crate::render::RenderSettings;
use crate::render::ShadingPoint;
use crate::render::estimator::integrand;
use crate::render::sink::{Outcome, SampleRecord, SampleSink};
use crate::scene::Scene;
use glam::Vec3;
use std::sync::Arc;
use wide::f32x8;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Heuristic {
    Balance,
    #[default]
    Power,
}

impl Heuristic {
    pub const ALL: [Heuristic; 2] = [Heuristic::Balance, Heuristic::Power];

    pub fn name(self) -> &'static str {
        match self {
            Heuristic::Balance => "balance",
            Heuristic::Power => "power",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|h| h.name() == name)
    }

    /// The weight of technique a (n_a samples, density p_a) against b; 0 where not finite.
    #[inline]
    pub fn weight(self, n_a: u32, p_a: f32, n_b: u32, p_b: f32) -> f32 {
        let (a, b) = (n_a as f32 * p_a, n_b as f32 * p_b);
        let w = match self {
            Heuristic::Balance => a / (a + b),
            Heuristic::Power => (a * a) / (a * a + b * b),
        };
        if w.is_finite() { w } else { 0.0 }
    }

    /// [`Heuristic::weight`] with one direction per technique (n_a = n_b = 1) for eight pairs of densities, lane
    /// by lane, the same value bit for bit.
    #[inline(always)]
    pub fn weight_lanes(self, p_a: f32x8, p_b: f32x8) -> f32x8 {
        let (a, b) = (f32x8::ONE * p_a, f32x8::ONE * p_b);
        let w = match self {
            Heuristic::Balance => a / (a + b),
            Heuristic::Power => (a * a) / (a * a + b * b),
        };
        w.is_finite().blend(w, f32x8::ZERO)
    }
}

/// How MIS combines its techniques.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MisSettings {
    /// The two techniques (any strategies but MIS itself), sampled in this order.
    pub techniques: [Strategy; 2],
    pub heuristic: Heuristic,
    /// Directions per pixel sample from each technique (n_0, n_1).
    pub samples: [u32; 2],
}

impl Default for MisSettings {
    fn default() -> Self {
        Self { techniques: [Strategy::Emitter, Strategy::Brdf], heuristic: Heuristic::Power, samples: [1, 1] }
    }
}

impl MisSettings {
    /// Whether these settings describe an estimator: two techniques other than MIS, at least one direction.
    pub fn is_valid(&self) -> bool {
        self.techniques.iter().all(|&t| t != Strategy::Mis) && self.samples.iter().sum::<u32>() > 0
    }

    /// A short label: `emitter×1 + brdf×1, power`.
    pub fn label(&self) -> String {
        let [a, b] = self.techniques;
        let [na, nb] = self.samples;
        format!("{}×{na} + {}×{nb}, {}", a.name(), b.name(), self.heuristic.name())
    }
}

pub struct Mis;

impl DirectionStrategy for Mis {
    const NAME: &'static str = "mis";
    const DESCRIPTION: &'static str =
        "multiple importance sampling: two techniques (a light strategy and BRDF sampling), weighted (Veach 1995)";
    const PDF: &'static str = "w_i = (n_i p_i)^β / Σ_j (n_j p_j)^β,  β = 1 balance, 2 power";
    const DOMAIN: Domain = Domain::Mixture;

    /// The states of its two techniques, if either has one.
    fn prepare(&self, scene: &Scene, settings: &RenderSettings) -> Option<StrategyState> {
        let states = settings.mis.techniques.map(|t| t.prepare(scene, settings));
        states.iter().any(Option::is_some).then(|| Arc::new(TechniqueStates(states)) as StrategyState)
    }

    /// A direction of the mixture: technique 0 with probability n_0 / (n_0 + n_1) (one uniform chooses), and the
    /// mixture density.
    fn sample(&self, ctx: &SampleContext, sp: &ShadingPoint, rng: &mut SampleRng) -> Option<DirectionSample> {
        let [t0, t1] = valid_techniques(ctx)?;
        let [n0, n1] = ctx.mis.samples;
        let i = if rng.uniform() * ((n0 + n1) as f32) < n0 as f32 { 0 } else { 1 };
        let s = [t0, t1][i].sample(&technique_context(ctx, i), sp, rng)?;
        let via = match s.target {
            super::Target::Emitter { triangle, point } => Some(Reached { triangle, point }),
            super::Target::Trace => crate::render::estimator::reached(ctx.scene, sp, s.wi),
        };
        let pdf = DirectionStrategy::pdf(self, ctx, sp, s.wi, via);
        (pdf > 0.0 && pdf.is_finite()).then_some(DirectionSample { pdf, ..s })
    }

    fn pdf(&self, ctx: &SampleContext, sp: &ShadingPoint, wi: Vec3, via: Option<Reached>) -> f32 {
        let Some([t0, t1]) = valid_techniques(ctx) else { return 0.0 };
        let [n0, n1] = ctx.mis.samples.map(|n| n as f32);
        let (c0, c1) = (technique_context(ctx, 0), technique_context(ctx, 1));
        (n0 * t0.pdf(&c0, sp, wi, via) + n1 * t1.pdf(&c1, sp, wi, via)) / (n0 + n1)
    }

    /// Veach's multi-sample estimator.
    #[inline]
    fn estimate<S: SampleSink>(
        &self,
        ctx: &SampleContext,
        sp: &ShadingPoint,
        rng: &mut SampleRng,
        rays: &mut u64,
        sink: &mut S,
    ) -> Vec3 {
        let Some(techniques) = valid_techniques(ctx) else { return Vec3::ZERO };
        // The usual pairs get an estimator of their own (the two techniques' code inlined), the rest the same
        // code through the registry's dispatch: the same values either way.
        use super::{
            brdf::Brdf, emitter::Emitter, projected_solid_angle::ProjectedSolidAngle, solid_angle::SolidAngle,
        };
        match techniques {
            [Strategy::Emitter, Strategy::Brdf] => combine(&Emitter, &Brdf, ctx, sp, rng, rays, sink),
            [Strategy::SolidAngle, Strategy::Brdf] => combine(&SolidAngle, &Brdf, ctx, sp, rng, rays, sink),
            [Strategy::ProjectedSolidAngle, Strategy::Brdf] => {
                combine(&ProjectedSolidAngle, &Brdf, ctx, sp, rng, rays, sink)
            }
            [a, b] => combine(&a, &b, ctx, sp, rng, rays, sink),
        }
    }
}

/// Veach's multi-sample estimator of techniques a (n_0 directions) and b (n_1), in that order.
#[inline(always)]
fn combine<S: SampleSink>(
    a: &impl Technique,
    b: &impl Technique,
    ctx: &SampleContext,
    sp: &ShadingPoint,
    rng: &mut SampleRng,
    rays: &mut u64,
    sink: &mut S,
) -> Vec3 {
    let contexts = [technique_context(ctx, 0), technique_context(ctx, 1)];
    let total = directions(0, a, b, &contexts, sp, rng, rays, sink, Vec3::ZERO);
    directions(1, b, a, &contexts, sp, rng, rays, sink, total)
}

/// Adds to `total` the n_i directions of technique i (`own`; the other is `other`), each weighted against the
/// other's density, one after the other.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn directions<S: SampleSink>(
    i: usize,
    own: &impl Technique,
    other: &impl Technique,
    contexts: &[SampleContext; 2],
    sp: &ShadingPoint,
    rng: &mut SampleRng,
    rays: &mut u64,
    sink: &mut S,
    mut total: Vec3,
) -> Vec3 {
    let ctx = &contexts[i];
    let (heuristic, n) = (ctx.mis.heuristic, ctx.mis.samples);
    for _ in 0..n[i] {
        let Some(s) = own.sample(ctx, sp, rng) else {
            sink.record(SampleRecord::none(i as u8));
            continue;
        };
        let (contribution, w, radiance, outcome, hit) = match integrand(ctx.scene, sp, &s, rays) {
            Ok((value, via)) => {
                let p_other = other.pdf(&contexts[1 - i], sp, s.wi, Some(via));
                let w = heuristic.weight(n[i], s.pdf, n[1 - i], p_other);
                let radiance = ctx.scene.emitted(via.triangle, -s.wi);
                (value * (w / (n[i] as f32 * s.pdf)), w, radiance, Outcome::Contributed, via.point)
            }
            Err(outcome) => {
                // L_i = 0 along ω: weighted as if it had arrived (the weight of a zero is the record's only use).
                let via = match s.target {
                    super::Target::Emitter { triangle, point } => Some(Reached { triangle, point }),
                    super::Target::Trace => None,
                };
                let p_other = other.pdf(&contexts[1 - i], sp, s.wi, via);
                (Vec3::ZERO, heuristic.weight(n[i], s.pdf, n[1 - i], p_other), Vec3::ZERO, outcome, Vec3::ZERO)
            }
        };
        total += contribution;
        let (wi, pdf, technique) = (s.wi, s.pdf, i as u8);
        let parts = [0.0; 3];
        sink.record(SampleRecord { technique, wi, pdf, mis_weight: w, contribution, radiance, outcome, parts, hit });
    }
    total
}

/// MIS's state: each technique's own.
struct TechniqueStates([Option<StrategyState>; 2]);

/// The context technique i sees: MIS's, with the technique's own state.
#[inline(always)]
pub(crate) fn technique_context<'a>(ctx: &SampleContext<'a>, i: usize) -> SampleContext<'a> {
    let state = ctx.state::<TechniqueStates>().and_then(|s| s.0[i].as_deref());
    SampleContext { state, ..*ctx }
}

fn valid_techniques(ctx: &SampleContext) -> Option<[Strategy; 2]> {
    ctx.mis.is_valid().then_some(ctx.mis.techniques)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each technique of MIS sees its own state, and a technique without one sees none.
    #[test]
    fn techniques_see_their_own_state() {
        let scene = crate::scene::load_scene("cornell-box").expect("bundled");
        let states = TechniqueStates([Some(Arc::new(7u32) as StrategyState), None]);
        let mis = MisSettings::default();
        let tile = &crate::scene::TileLights::NONE;
        let ctx = SampleContext { scene: &scene, emitters: None, mis: &mis, state: Some(&states), guide: None, tile };
        assert_eq!(technique_context(&ctx, 0).state::<u32>(), Some(&7));
        assert!(technique_context(&ctx, 1).state.is_none());
        // No registered technique has state yet, so MIS prepares none.
        assert!(Mis.prepare(&scene, &RenderSettings::default()).is_none());
    }

    /// Eight weights at once are the weights one at a time, bit for bit: densities from 0 to the largest floats,
    /// subnormal, infinite and NaN.
    #[test]
    fn lanes_weigh_as_one_at_a_time() {
        let mut rng = SampleRng::new(2, 9, 4);
        let special = [0.0, -0.0, 1e-45, 1e-30, 1.0, 3e38, f32::MAX, f32::INFINITY, f32::NAN];
        for round in 0..2000 {
            let mut density = |k: usize| {
                if (round + k).is_multiple_of(3) {
                    special[(round * 7 + k) % special.len()]
                } else {
                    rng.uniform() * 1e3
                }
            };
            let p_a: [f32; 8] = std::array::from_fn(&mut density);
            let p_b: [f32; 8] = std::array::from_fn(|k| density(k + 3));
            for heuristic in Heuristic::ALL {
                let lanes = heuristic.weight_lanes(f32x8::new(p_a), f32x8::new(p_b)).to_array();
                for l in 0..8 {
                    let alone = heuristic.weight(1, p_a[l], 1, p_b[l]);
                    assert_eq!(lanes[l].to_bits(), alone.to_bits(), "{p_a:?} {p_b:?} lane {l}");
                }
            }
        }
    }

    #[test]
    fn weights_sum_to_one_and_are_finite() {
        for h in Heuristic::ALL {
            for (pa, pb) in [(1.0, 1.0), (1e-30, 3.0), (5e3, 1e-3), (0.0, 2.0), (f32::MAX, 1.0)] {
                for (na, nb) in [(1, 1), (3, 1), (1, 4)] {
                    let (wa, wb) = (h.weight(na, pa, nb, pb), h.weight(nb, pb, na, pa));
                    assert!(wa.is_finite() && wb.is_finite());
                    if pa > 0.0 && pa < 1e30 {
                        assert!((wa + wb - 1.0).abs() < 1e-6, "{h:?} {pa} {pb}: {wa} + {wb}");
                    }
                }
            }
            assert_eq!(h.weight(1, f32::INFINITY, 1, f32::INFINITY), 0.0);
        }
    }
}
