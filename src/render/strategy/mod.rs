//! The sampling strategies. Each is one file implementing one contract, [`DirectionStrategy`]: it draws a
//! direction ω_k and knows its density p(ω) for any ω, so that `f_r L_i (ω_k·n) / p(ω_k)` estimates the
//! scattering integral; all of them estimate the same integral. The `registry!` below lists them, and
//! everything that lists strategies (the CLI, the viewer, `illumlab strategies`, the tests) iterates
//! [`Strategy::ALL`].
//!
//! Adding a strategy: a new file here with a unit struct implementing [`DirectionStrategy`], one line in the
//! registry, and its tests (the chi-square, unbiasedness and pass tests iterate the registry by themselves).

mod brdf;
mod brdf_polygon;
mod cosine;
mod emitter;
pub mod guided;
pub mod light;
pub mod mis;
mod projected_solid_angle;
mod solid_angle;
mod uniform;

pub(crate) use brdf::Brdf;
pub use brdf_polygon::BrdfPolygon;
pub(crate) use emitter::Emitter;
pub use mis::{Heuristic, MisSettings};
pub use projected_solid_angle::ProjectedSolidAngle;
pub use solid_angle::SolidAngle;

use super::sink::SampleSink;
use super::{RenderSettings, ShadingPoint};
use crate::guiding::Guide;
use crate::math::SampleRng;
use crate::scene::{EmitterSampler, Scene, TileLights};
use glam::Vec3;
use std::any::Any;
use std::sync::Arc;

/// What a strategy builds once per scene and settings (a table, a fitted lobe, a learned guide): made by
/// [`DirectionStrategy::prepare`], owned by the renderer (which persists across passes), read by every sample
/// through [`SampleContext::state`].
pub type StrategyState = Arc<dyn Any + Send + Sync>;

/// What a strategy may read besides the shading point: the scene and what is built once per scene and settings
/// by the renderer that owns it (the light selection's p_Δ tables, the strategy's own state).
#[derive(Clone, Copy)]
pub struct SampleContext<'a> {
    pub scene: &'a Scene,
    /// p_Δ; `None` in a scene without emitters.
    pub emitters: Option<&'a EmitterSampler>,
    pub mis: &'a MisSettings,
    /// The strategy's own state, if its `prepare` made one.
    pub state: Option<&'a (dyn Any + Send + Sync)>,
    /// The guide the renderer is learning or has learned (`guided`, alone or as a technique of MIS); it changes
    /// only between passes.
    pub guide: Option<&'a Guide>,
    /// What the renderer knows of the shadow rays from the pixel being shaded (its tile's clear lights and
    /// blockers), which the eight-lane estimators use to answer them; [`TileLights::NONE`] elsewhere. Every
    /// answer is the one tracing gives.
    pub tile: &'a TileLights,
}

impl<'a> SampleContext<'a> {
    /// The strategy's state as its own type.
    pub fn state<T: 'static>(&self) -> Option<&'a T> {
        self.state?.downcast_ref()
    }
}

/// A sampled incident direction and how to find the radiance arriving along it.
#[derive(Clone, Copy, Debug)]
pub struct DirectionSample {
    /// Unit direction towards the light (ω_k).
    pub wi: Vec3,
    /// Its density w.r.t. solid angle.
    pub pdf: f32,
    pub target: Target,
}

/// How L_i(ω_k) is found.
#[derive(Clone, Copy, Debug)]
pub enum Target {
    /// Trace a ray along ω_k; L_i is the radiance emitted by whatever it hits first.
    Trace,
    /// The direction was aimed at a point on an emitter triangle: L_i is its emission if a shadow ray gets
    /// through.
    Emitter { triangle: u32, point: Vec3 },
}

/// An emitter triangle a direction reaches, and where: what a light strategy's density depends on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reached {
    pub triangle: u32,
    pub point: Vec3,
}

/// Which directions a strategy draws, which decides how its density is evaluated over the sphere and how its
/// samples are binned in a chi-square test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Domain {
    /// Directions anywhere on the sphere (those below the surface contribute nothing); `pdf` ignores `via`.
    Hemisphere,
    /// Directions towards emitter triangles: the density of ω is that of reaching `via`, the emitter triangle ω
    /// meets; over the sphere it is the sum over every facing emitter triangle ω passes through.
    Lights,
    /// A mixture of two techniques of either domain (MIS).
    Mixture,
    /// A one-sample mixture of a learned guide (over the sphere), emitter sampling and BRDF sampling (`guided`).
    Learned,
}

/// The contract every strategy implements: a (sample, pdf) pair with its name, description and formula.
pub trait DirectionStrategy {
    /// The command-line name.
    const NAME: &'static str;
    /// One line: what the strategy samples.
    const DESCRIPTION: &'static str;
    /// The density in the lecture's notation.
    const PDF: &'static str;
    const DOMAIN: Domain;

    /// Builds the state the strategy keeps per scene and settings; none by default.
    fn prepare(&self, _scene: &Scene, _settings: &RenderSettings) -> Option<StrategyState> {
        None
    }

    /// Draws ω_k. `None`: no sample could be taken (it counts as zero).
    fn sample(&self, ctx: &SampleContext, sp: &ShadingPoint, rng: &mut SampleRng) -> Option<DirectionSample>;

    /// The density w.r.t. solid angle of drawing `wi`; `via` is the emitter triangle and point `wi` reaches
    /// (light strategies are 0 without one). Finite and ≥ 0.
    fn pdf(&self, ctx: &SampleContext, sp: &ShadingPoint, wi: Vec3, via: Option<Reached>) -> f32;

    /// One sample of the scattering integral at `sp`, reporting every direction it evaluates to `sink`. The
    /// one-sample estimator `f_r L_i (ω·n) / p(ω)` unless a strategy combines several directions (MIS).
    #[inline(always)]
    fn estimate<S: SampleSink>(
        &self,
        ctx: &SampleContext,
        sp: &ShadingPoint,
        rng: &mut SampleRng,
        rays: &mut u64,
        sink: &mut S,
    ) -> Vec3 {
        let s = self.sample(ctx, sp, rng);
        super::estimator::one_sample(ctx.scene, sp, s, rays, sink)
    }
}

/// What MIS and the eight-lane path need of a strategy: its samples and its density. Implemented by every
/// strategy's own type (known at compile time, so its code is inlined) and by [`Strategy`] (dispatched at run
/// time): the same values either way.
pub trait Technique {
    fn sample(&self, ctx: &SampleContext, sp: &ShadingPoint, rng: &mut SampleRng) -> Option<DirectionSample>;
    fn pdf(&self, ctx: &SampleContext, sp: &ShadingPoint, wi: Vec3, via: Option<Reached>) -> f32;
}

impl<T: DirectionStrategy> Technique for T {
    #[inline(always)]
    fn sample(&self, ctx: &SampleContext, sp: &ShadingPoint, rng: &mut SampleRng) -> Option<DirectionSample> {
        DirectionStrategy::sample(self, ctx, sp, rng)
    }

    #[inline(always)]
    fn pdf(&self, ctx: &SampleContext, sp: &ShadingPoint, wi: Vec3, via: Option<Reached>) -> f32 {
        DirectionStrategy::pdf(self, ctx, sp, wi, via)
    }
}

impl Technique for Strategy {
    #[inline(always)]
    fn sample(&self, ctx: &SampleContext, sp: &ShadingPoint, rng: &mut SampleRng) -> Option<DirectionSample> {
        Strategy::sample(*self, ctx, sp, rng)
    }

    #[inline(always)]
    fn pdf(&self, ctx: &SampleContext, sp: &ShadingPoint, wi: Vec3, via: Option<Reached>) -> f32 {
        Strategy::pdf(*self, ctx, sp, wi, via)
    }
}

/// Generates [`Strategy`], the registry: one line per strategy, `Variant => path::Type`.
macro_rules! registry {
    ($($variant:ident => $ty:path),* $(,)?) => {
        /// A strategy of the registry, by its command-line name.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Strategy {
            $($variant),*
        }

        impl Strategy {
            /// Every registered strategy, in the order the CLI and the viewer list them.
            pub const ALL: [Strategy; [$(stringify!($variant)),*].len()] = [$(Strategy::$variant),*];

            pub fn name(self) -> &'static str {
                match self { $(Strategy::$variant => <$ty as DirectionStrategy>::NAME),* }
            }

            pub fn description(self) -> &'static str {
                match self { $(Strategy::$variant => <$ty as DirectionStrategy>::DESCRIPTION),* }
            }

            pub fn pdf_formula(self) -> &'static str {
                match self { $(Strategy::$variant => <$ty as DirectionStrategy>::PDF),* }
            }

            pub fn domain(self) -> Domain {
                match self { $(Strategy::$variant => <$ty as DirectionStrategy>::DOMAIN),* }
            }

            /// [`DirectionStrategy::prepare`].
            pub fn prepare(self, scene: &Scene, settings: &RenderSettings) -> Option<StrategyState> {
                match self { $(Strategy::$variant => $ty.prepare(scene, settings)),* }
            }

            /// [`DirectionStrategy::sample`].
            #[inline(always)]
            pub fn sample(self, ctx: &SampleContext, sp: &ShadingPoint, rng: &mut SampleRng) -> Option<DirectionSample> {
                match self { $(Strategy::$variant => DirectionStrategy::sample(&$ty, ctx, sp, rng)),* }
            }

            /// [`DirectionStrategy::pdf`].
            #[inline]
            pub fn pdf(self, ctx: &SampleContext, sp: &ShadingPoint, wi: Vec3, via: Option<Reached>) -> f32 {
                match self { $(Strategy::$variant => DirectionStrategy::pdf(&$ty, ctx, sp, wi, via)),* }
            }

            /// [`DirectionStrategy::estimate`].
            #[inline(always)]
            pub fn estimate<S: SampleSink>(
                self,
                ctx: &SampleContext,
                sp: &ShadingPoint,
                rng: &mut SampleRng,
                rays: &mut u64,
                sink: &mut S,
            ) -> Vec3 {
                match self { $(Strategy::$variant => $ty.estimate(ctx, sp, rng, rays, sink)),* }
            }
        }
    };
}

registry! {
    Uniform => uniform::Uniform,
    Cosine => cosine::Cosine,
    Brdf => brdf::Brdf,
    Emitter => emitter::Emitter,
    SolidAngle => solid_angle::SolidAngle,
    ProjectedSolidAngle => projected_solid_angle::ProjectedSolidAngle,
    BrdfPolygon => brdf_polygon::BrdfPolygon,
    Mis => mis::Mis,
    Guided => guided::Guided,
}

impl Strategy {
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }

    /// The strategies that can be a technique of MIS: all but MIS itself.
    pub fn techniques() -> impl Iterator<Item = Strategy> {
        Self::ALL.into_iter().filter(|&s| s != Strategy::Mis)
    }

    /// Whether rendering with `settings` learns a guide: `guided`, alone or as a technique of MIS.
    pub fn learns(settings: &RenderSettings) -> bool {
        settings.strategy == Strategy::Guided
            || (settings.strategy == Strategy::Mis && settings.mis.techniques.contains(&Strategy::Guided))
    }

    /// Whether the strategy draws directions towards emitter triangles.
    pub fn samples_lights(self) -> bool {
        self.domain() == Domain::Lights
    }
}
