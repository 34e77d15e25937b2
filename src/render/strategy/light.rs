//! What the light strategies share: each picks an emitter triangle Δ with p_Δ and then a direction towards it,
//! `p(ω) = p_Δ p(ω | Δ)`, and can evaluate that density for any direction that reaches an emitter (multiple
//! importance sampling and the probe need it). A light strategy implements [`TriangleSampler`] (the part given
//! Δ) and [`LightStrategy`] (its names); its [`DirectionStrategy`] follows, by [`sample_light`] and [`light_pdf`].

use super::{DirectionSample, DirectionStrategy, Domain, Reached, SampleContext, Target};
use crate::math::SampleRng;
use crate::render::ShadingPoint;
use crate::scene::Triangle;
use glam::Vec3;

/// Directions towards one emitter triangle Δ, seen from a shading point.
pub trait TriangleSampler {
    /// A direction towards Δ, its density w.r.t. solid angle given Δ, and the point on Δ it aims at.
    fn sample_triangle(sp: &ShadingPoint, tri: &Triangle, rng: &mut SampleRng) -> Option<(Vec3, f32, Vec3)>;

    /// The density given Δ of `wi`, which meets Δ at `x`.
    fn triangle_pdf(sp: &ShadingPoint, tri: &Triangle, x: Vec3, wi: Vec3) -> f32;
}

/// A light strategy's names, as [`DirectionStrategy`] has them.
pub trait LightStrategy: TriangleSampler {
    const NAME: &'static str;
    const DESCRIPTION: &'static str;
    const PDF: &'static str;
}

impl<T: LightStrategy> DirectionStrategy for T {
    const NAME: &'static str = <T as LightStrategy>::NAME;
    const DESCRIPTION: &'static str = <T as LightStrategy>::DESCRIPTION;
    const PDF: &'static str = <T as LightStrategy>::PDF;
    const DOMAIN: Domain = Domain::Lights;

    #[inline(always)]
    fn sample(&self, ctx: &SampleContext, sp: &ShadingPoint, rng: &mut SampleRng) -> Option<DirectionSample> {
        sample_light::<T>(ctx, sp, rng)
    }

    #[inline]
    fn pdf(&self, ctx: &SampleContext, sp: &ShadingPoint, wi: Vec3, via: Option<Reached>) -> f32 {
        light_pdf::<T>(ctx, sp, wi, via)
    }
}

/// Picks Δ with p_Δ, then a direction towards it: density `p_Δ p(ω | Δ)`.
#[inline(always)]
pub fn sample_light<T: TriangleSampler>(
    ctx: &SampleContext,
    sp: &ShadingPoint,
    rng: &mut SampleRng,
) -> Option<DirectionSample> {
    let (triangle, p_delta, tri) = pick_facing(ctx, sp, rng)?;
    light_sample(triangle, p_delta, T::sample_triangle(sp, tri, rng))
}

/// [`sample_light`]'s first step: Δ picked with p_Δ from the stream's next uniform, if `sp` sees its emitting side
/// (the back of a one-sided emitter: L_i = 0, no sample).
#[inline(always)]
pub fn pick_facing<'a>(
    ctx: &SampleContext<'a>,
    sp: &ShadingPoint,
    rng: &mut SampleRng,
) -> Option<(u32, f32, &'a Triangle)> {
    let emitters = ctx.emitters?;
    let (triangle, p_delta) = emitters.pick(ctx.scene, sp.p, rng.uniform())?;
    let tri = &ctx.scene.triangles[triangle as usize];
    faces(tri, sp.p).then_some((triangle, p_delta, tri))
}

/// [`sample_light`]'s last step: the direction drawn towards Δ (with its density given Δ and the point it aims
/// at) as a sample of density `p_Δ p(ω | Δ)`, if that is positive and finite.
#[inline(always)]
pub fn light_sample(triangle: u32, p_delta: f32, drawn: Option<(Vec3, f32, Vec3)>) -> Option<DirectionSample> {
    let (wi, pdf, point) = drawn?;
    let pdf = p_delta * pdf;
    (pdf > 0.0 && pdf.is_finite()).then_some(DirectionSample { wi, pdf, target: Target::Emitter { triangle, point } })
}

/// Density w.r.t. solid angle of drawing `wi`, which reaches the emitter triangle `via`: `p_Δ p(ω | Δ)`.
#[inline]
pub fn light_pdf<T: TriangleSampler>(ctx: &SampleContext, sp: &ShadingPoint, wi: Vec3, via: Option<Reached>) -> f32 {
    let (Some(emitters), Some(Reached { triangle, point })) = (ctx.emitters, via) else { return 0.0 };
    let tri = &ctx.scene.triangles[triangle as usize];
    if !faces(tri, sp.p) {
        return 0.0;
    }
    let p_delta = emitters.p_delta(ctx.scene, triangle, sp.p);
    if p_delta == 0.0 {
        return 0.0;
    }
    p_delta * T::triangle_pdf(sp, tri, point, wi)
}

/// Whether p is on the emitting side of the triangle's plane.
#[inline]
pub fn faces(tri: &Triangle, p: Vec3) -> bool {
    tri.n.dot(p - tri.v[0]) > 0.0
}

/// Density w.r.t. solid angle of a uniform point on the triangle, seen from p: `‖x − p‖² / (A |n_Δ·ω|)`.
#[inline]
pub(super) fn area_pdf_solid_angle(p: Vec3, tri: &Triangle, x: Vec3, wi: Vec3) -> f32 {
    let cos = tri.n.dot(wi).abs();
    let d2 = (x - p).length_squared();
    let denom = tri.area * cos;
    if denom > 0.0 { d2 / denom } else { 0.0 }
}

/// Where the ray from p along ω meets the triangle's plane (the shadow ray's end).
#[inline]
pub(super) fn hit_plane(p: Vec3, wi: Vec3, tri: &Triangle) -> Option<Vec3> {
    let t = tri.n.dot(tri.v[0] - p) / tri.n.dot(wi);
    (t > 0.0 && t.is_finite()).then(|| p + wi * t)
}
