//! Guided sampling (path guiding for direct light; Müller, Gross & Novák 2017): a one-sample mixture of the
//! learned guide, emitter sampling and BRDF sampling,
//!
//! `p(ω) = c_g p_guide(ω) + c_l p_light(ω) + c_b p_brdf(ω)`,
//!
//! where p_guide is the quadtree density of the spatial leaf holding the shading point ([`crate::guiding`]),
//! which the renderer learns from the directions evaluated at the points the camera sees, and (c_g, c_l, c_b)
//! are that leaf's weights: (½, ¼, ¼) until learned, then the candidate of least estimated variance
//! ([`crate::guiding::Moments`]). Where the leaf's quadtree is empty (and before any guide exists) c_g = 0 and
//! the others share its weight; where the scene has no emitters c_l = 0. Every weight vector has c_l + c_b > 0,
//! and light or BRDF sampling reaches every direction where f_r L_i (ω·n) > 0, so the estimator
//! `f_r L_i (ω·n) / p(ω)` stays unbiased whatever the guide learned. The guide learns light only (`L_e V`), not
//! the BRDF: a change of camera or material keeps it.

use super::brdf::Brdf;
use super::emitter::Emitter;
use super::{DirectionSample, DirectionStrategy, Domain, Reached, SampleContext, Target, Technique};
use crate::guiding::{DEFAULT_WEIGHTS, DTree, LeafHint};
use crate::math::SampleRng;
use crate::render::ShadingPoint;
use crate::render::estimator::{integrand, reached};
use crate::render::sink::{Outcome, SampleRecord, SampleSink};
use glam::Vec3;

pub struct Guided;

/// The weights (c_g, c_l, c_b) at a shading point: its spatial leaf's, with the parts that cannot sample there
/// left out (no quadtree density, no emitters) and the rest scaled to sum to one; BRDF sampling alone where
/// nothing is left.
#[inline]
pub fn weights(ctx: &SampleContext, sp: &ShadingPoint) -> [f32; 3] {
    Mixture::at(ctx, sp).w
}

/// The mixture at one shading point: its spatial leaf's quadtree (where a guide exists) and its weights, looked up
/// once per sample.
#[derive(Clone, Copy)]
struct Mixture<'a> {
    dtree: Option<&'a DTree>,
    w: [f32; 3],
}

impl<'a> Mixture<'a> {
    #[inline]
    fn at(ctx: &SampleContext<'a>, sp: &ShadingPoint) -> Self {
        Self::at_near(ctx, sp, &mut None)
    }

    /// [`Mixture::at`], its spatial leaf found through `hint` (the same leaf: see `STree::leaf_near`).
    #[inline]
    fn at_near(ctx: &SampleContext<'a>, sp: &ShadingPoint, hint: &mut Option<LeafHint>) -> Self {
        let (dtree, [g, l, b]) = match ctx.guide {
            Some(guide) => {
                let (dtree, w) = guide.leaf_near(sp.p, hint);
                (Some(dtree), w)
            }
            None => (None, DEFAULT_WEIGHTS),
        };
        let usable = dtree.is_some_and(DTree::is_usable);
        let w = [if usable { g } else { 0.0 }, if ctx.emitters.is_some() { l } else { 0.0 }, b];
        let sum = w[0] + w[1] + w[2];
        let w = if sum > 0.0 { w.map(|c| c / sum) } else { [0.0, 0.0, 1.0] };
        Self { dtree, w }
    }

    /// The densities of the guide, light and BRDF parts at `wi`, whatever their weights (a sample reports them:
    /// the weights are scored on the light and BRDF parts').
    #[inline]
    fn parts(&self, ctx: &SampleContext, sp: &ShadingPoint, wi: Vec3, via: Option<Reached>) -> [f32; 3] {
        let guide = self.dtree.map_or(0.0, |d| d.pdf_at(sp.p, wi));
        let light = if ctx.emitters.is_some() { Technique::pdf(&Emitter, ctx, sp, wi, via) } else { 0.0 };
        [guide, light, Technique::pdf(&Brdf, ctx, sp, wi, via)]
    }

    /// The mixture's density at `wi`, its parts of weight 0 left out (the same value: they add 0).
    #[inline]
    fn weighted_pdf(&self, ctx: &SampleContext, sp: &ShadingPoint, wi: Vec3, via: Option<Reached>) -> f32 {
        let [g, l, b] = self.w;
        let guide = match self.dtree {
            Some(d) if g > 0.0 => g * d.pdf_at(sp.p, wi),
            _ => 0.0,
        };
        let light =
            if l > 0.0 && ctx.emitters.is_some() { l * Technique::pdf(&Emitter, ctx, sp, wi, via) } else { 0.0 };
        let brdf = if b > 0.0 { b * Technique::pdf(&Brdf, ctx, sp, wi, via) } else { 0.0 };
        guide + light + brdf
    }

    /// The mixture's density, from its parts'.
    #[inline]
    fn pdf(&self, parts: &[f32; 3]) -> f32 {
        self.w[0] * parts[0] + self.w[1] * parts[1] + self.w[2] * parts[2]
    }
}

/// Which part draws, from one uniform.
#[inline]
fn choose(w: &[f32; 3], u: f32) -> usize {
    if u < w[0] {
        0
    } else if u < w[0] + w[1] || w[2] == 0.0 {
        1
    } else {
        2
    }
}

impl Guided {
    /// A direction from the part chosen, with that part's own density (the estimator divides by the mixture's).
    #[inline]
    fn sample_part<'a>(
        ctx: &SampleContext<'a>,
        sp: &ShadingPoint,
        rng: &mut SampleRng,
        hint: &mut Option<LeafHint>,
    ) -> Option<(DirectionSample, Mixture<'a>)> {
        let m = Mixture::at_near(ctx, sp, hint);
        let s = match choose(&m.w, rng.uniform()) {
            0 => {
                let (wi, pdf) = m.dtree?.sample_at(sp.p, rng)?;
                DirectionSample { wi, pdf, target: Target::Trace }
            }
            1 => Technique::sample(&Emitter, ctx, sp, rng)?,
            _ => Technique::sample(&Brdf, ctx, sp, rng)?,
        };
        Some((s, m))
    }
}

/// A direction drawn as [`Guided`]'s estimator draws it, for the eight-lane estimator
/// (`render::lanes::estimate_guided_lanes`), which traces the lanes' rays together and then weighs each value.
#[derive(Clone, Copy)]
pub(crate) struct Drawn<'a> {
    pub s: DirectionSample,
    m: Mixture<'a>,
}

impl<'a> Drawn<'a> {
    /// A direction of the mixture at `sp`, drawn from `rng` as the estimator draws it; its spatial leaf is found
    /// through `hint` (the samples of a pixel mostly share one).
    #[inline(always)]
    pub(crate) fn draw(
        ctx: &SampleContext<'a>,
        sp: &ShadingPoint,
        rng: &mut SampleRng,
        hint: &mut Option<LeafHint>,
    ) -> Option<Self> {
        Guided::sample_part(ctx, sp, rng, hint).map(|(s, m)| Self { s, m })
    }

    /// `f_r L_i (ω·n)` over the mixture's density at ω, given the emitter triangle and point ω reached: the
    /// estimator's contribution.
    #[inline(always)]
    pub(crate) fn weighted(&self, ctx: &SampleContext, sp: &ShadingPoint, value: Vec3, via: Reached) -> Vec3 {
        value / self.m.weighted_pdf(ctx, sp, self.s.wi, Some(via))
    }

    /// The estimator's contribution and what it reports, given what ω found: `f_r L_e (ω·n)` and the emitter
    /// triangle and point it reached, or why nothing arrived.
    #[inline]
    pub(crate) fn record(
        &self,
        ctx: &SampleContext,
        sp: &ShadingPoint,
        found: Result<(Vec3, Reached), Outcome>,
    ) -> (Vec3, SampleRecord) {
        let (s, m) = (&self.s, &self.m);
        let (contribution, parts, radiance, outcome, hit) = match found {
            Ok((value, via)) => {
                let parts = m.parts(ctx, sp, s.wi, Some(via));
                let radiance = ctx.scene.emitted(via.triangle, -s.wi);
                (value / m.pdf(&parts), parts, radiance, Outcome::Contributed, via.point)
            }
            Err(outcome) => {
                // An occluded or missed direction still tells the guide something: L_i = 0 there.
                let via = match s.target {
                    Target::Emitter { triangle, point } => Some(Reached { triangle, point }),
                    Target::Trace => None,
                };
                (Vec3::ZERO, m.parts(ctx, sp, s.wi, via), Vec3::ZERO, outcome, Vec3::ZERO)
            }
        };
        let (wi, pdf, mis_weight) = (s.wi, m.pdf(&parts), 1.0);
        let record = SampleRecord { technique: 0, wi, pdf, mis_weight, contribution, radiance, outcome, parts, hit };
        (contribution, record)
    }
}

impl DirectionStrategy for Guided {
    const NAME: &'static str = "guided";
    const DESCRIPTION: &'static str =
        "path guiding: a learned SD-tree of incident light, mixed with emitter and BRDF sampling (Müller 2017)";
    const PDF: &'static str =
        "p(ω) = c_g p_guide(ω) + c_l p_light(ω) + c_b p_brdf(ω),  c learned per region, from (½, ¼, ¼)";
    const DOMAIN: Domain = Domain::Learned;

    /// A direction of the mixture with the mixture's density (which, for a direction the guide or the BRDF
    /// drew, needs the emitter triangle it reaches: one more ray).
    fn sample(&self, ctx: &SampleContext, sp: &ShadingPoint, rng: &mut SampleRng) -> Option<DirectionSample> {
        let (s, m) = Self::sample_part(ctx, sp, rng, &mut None)?;
        let via = match s.target {
            Target::Emitter { triangle, point } => Some(Reached { triangle, point }),
            Target::Trace => reached(ctx.scene, sp, s.wi),
        };
        let pdf = m.weighted_pdf(ctx, sp, s.wi, via);
        (pdf > 0.0 && pdf.is_finite()).then_some(DirectionSample { pdf, ..s })
    }

    fn pdf(&self, ctx: &SampleContext, sp: &ShadingPoint, wi: Vec3, via: Option<Reached>) -> f32 {
        let m = Mixture::at(ctx, sp);
        m.weighted_pdf(ctx, sp, wi, via)
    }

    /// `f_r L_i (ω·n) / p(ω)` with the mixture's density, found after L_i (the ray the estimator traces anyway
    /// tells which emitter triangle ω reaches).
    #[inline]
    fn estimate<S: SampleSink>(
        &self,
        ctx: &SampleContext,
        sp: &ShadingPoint,
        rng: &mut SampleRng,
        rays: &mut u64,
        sink: &mut S,
    ) -> Vec3 {
        let Some((s, m)) = Self::sample_part(ctx, sp, rng, &mut None) else {
            sink.record(SampleRecord::none(0));
            return Vec3::ZERO;
        };
        let (contribution, record) = Drawn { s, m }.record(ctx, sp, integrand(ctx.scene, sp, &s, rays));
        sink.record(record);
        contribution
    }
}
