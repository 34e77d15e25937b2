//! The light strategies: each picks an emitter triangle Δ with p_Δ and then a direction towards it, and can
//! evaluate its density for any direction that reaches an emitter (multiple importance sampling needs that).

use super::{DirectionSample, Target, emitter, projected_solid_angle, solid_angle};
use crate::math::SampleRng;
use crate::render::ShadingPoint;
use crate::scene::{EmitterSampler, Scene, Triangle};
use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightTechnique {
    /// Uniform point on Δ (`emitter`).
    Area,
    /// Uniform direction in the spherical triangle (`solid-angle`).
    SolidAngle,
    /// Direction ∝ (ω·n) over Δ (`projected-solid-angle`).
    ProjectedSolidAngle,
}

impl LightTechnique {
    pub const ALL: [LightTechnique; 3] =
        [LightTechnique::Area, LightTechnique::SolidAngle, LightTechnique::ProjectedSolidAngle];

    /// The name of the stand-alone strategy.
    pub fn name(self) -> &'static str {
        match self {
            LightTechnique::Area => "emitter",
            LightTechnique::SolidAngle => "solid-angle",
            LightTechnique::ProjectedSolidAngle => "projected-solid-angle",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name() == name)
    }

    #[inline(always)]
    pub fn sample(
        self,
        sp: &ShadingPoint,
        scene: &Scene,
        emitters: &EmitterSampler,
        rng: &mut SampleRng,
    ) -> Option<DirectionSample> {
        let (triangle, p_delta) = emitters.pick(scene, sp.p, rng.uniform())?;
        let tri = &scene.triangles[triangle as usize];
        if !faces(tri, sp.p) {
            return None; // the back of a one-sided emitter: L_i = 0
        }
        let (wi, pdf, point) = match self {
            LightTechnique::Area => emitter::sample(sp, tri, rng)?,
            LightTechnique::SolidAngle => solid_angle::sample(sp, tri, rng)?,
            LightTechnique::ProjectedSolidAngle => projected_solid_angle::sample(sp, tri, rng)?,
        };
        let pdf = p_delta * pdf;
        (pdf > 0.0 && pdf.is_finite()).then_some(DirectionSample {
            wi,
            pdf,
            target: Target::Emitter { triangle, point },
        })
    }

    /// Density w.r.t. solid angle of drawing `wi`, which reaches emitter triangle `triangle` at `x`.
    #[inline]
    pub fn pdf(
        self,
        sp: &ShadingPoint,
        scene: &Scene,
        emitters: &EmitterSampler,
        triangle: u32,
        x: Vec3,
        wi: Vec3,
    ) -> f32 {
        let tri = &scene.triangles[triangle as usize];
        if !faces(tri, sp.p) {
            return 0.0;
        }
        let p_delta = emitters.p_delta(scene, triangle, sp.p);
        if p_delta == 0.0 {
            return 0.0;
        }
        p_delta
            * match self {
                LightTechnique::Area => emitter::pdf(sp, tri, x, wi),
                LightTechnique::SolidAngle => solid_angle::pdf(sp, tri, x, wi),
                LightTechnique::ProjectedSolidAngle => projected_solid_angle::pdf(sp, tri, x, wi),
            }
    }
}

/// Whether p is on the emitting side of the triangle's plane.
#[inline]
fn faces(tri: &Triangle, p: Vec3) -> bool {
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
