//! BRDF-weighted polygon sampling (after Peters 2021, "BRDF Importance Sampling for Polygonal Lights", ACM TOG
//! 40(4), with an LTC fitted to the Phong lobe): pick a triangle Δ with p_Δ, then a direction over it with a
//! density close to `f_r (ω·n)` there, from a one-sample mixture of two exact densities:
//!
//! - diffuse part: `(ω·n)⁺/Ω⊥` — projected-solid-angle sampling of Δ about n;
//! - specular part: `π D(ω)/Ω⊥(M⁻¹Δ)` over Δ — D the linearly transformed cosine fitted to the Phong lobe times
//!   the cosine ([`PhongLtc`], a table over (α, θ_o) by `examples/fit_phong_ltc.rs`): Δ is carried into cosine
//!   space by M⁻¹, sampled there by projected solid angle, and the direction carried back by M;
//!
//! chosen with `P_d = W_d/(W_d + W_s)`, where `W_d = max(k̄_d, 0.01) Ω⊥/π` and
//! `W_s = k̄_s min(Z Ω⊥(M⁻¹Δ)/π, (α+1)/(2π) c_max^α Ω⊥)` estimate the two lobes' integrals over Δ (Z the lobe's
//! mass above the horizon, which the LTC's unit mass stands for). The min bounds the LTC's estimate by the lobe's
//! largest value on Δ (c_max = max over Δ of ω·ω_r) times Δ's projected solid angle: the LTC has a heavier tail
//! than cos^α, and without the bound a light far outside a narrow lobe would get a large specular share. The
//! floor on k_d keeps the diffuse part, which covers all of Δ above the horizon, in every mixture: any positive
//! weights keep the estimator unbiased.
//!
//! `p(ω) = p_Δ [P_d (ω·n)⁺/Ω⊥ + (1 − P_d) π D(ω)/Ω⊥(M⁻¹Δ)]`, exact for any ω that reaches Δ.
//!
//! Deterministic fallbacks (functions of the shading point and Δ only, so the density can be evaluated): where
//! M⁻¹Δ covers nearly a hemisphere of cosine space the whole cosine lobe is sampled and drawn again until it
//! meets M⁻¹Δ (the same density); where it is too small, or too close to the lobe's horizon, for either to
//! accept 5% of its trials, the specular part samples Δ's area uniformly; the diffuse part has
//! projected-solid-angle sampling's own fallback. With k_s = 0, or Δ behind the lobe, it is projected-solid-
//! angle sampling.
//!
//! With the `contribution` light selection, p_Δ ∝ luminance(L_e) (W_d + W_s) at the shading point: the same
//! lobe-aware estimate, so that a glossy point picks the triangles its lobe sees.

use super::emitter::Emitter;
use super::light::{TriangleSampler, area_pdf_solid_angle, faces, hit_plane, light_pdf, sample_light};
use super::{DirectionSample, DirectionStrategy, Domain, Reached, SampleContext, Target};
use crate::math::{SampleRng, luminance, reflect};
use crate::render::ShadingPoint;
use crate::sampling::{
    Ltc, MAX_SPHERICAL_SAMPLE_AREA, MIN_ACCEPTANCE, MIN_SPHERICAL_SAMPLE_AREA, PhongLtc, ProjectedPlan, max_cosine,
    projected_solid_angle, projected_solid_angle_f64, projected_triangle_pdf, sample_cosine_hemisphere,
    sample_projected_triangle, spherical_triangle_area,
};
use crate::scene::{LightSelection, Triangle};
use glam::{DVec3, Vec3};
use std::f64::consts::{FRAC_1_PI, PI};

pub struct BrdfPolygon;

/// The least diffuse albedo the mixture weighs the diffuse part with (Peters' floor).
const DIFFUSE_FLOOR: f64 = 0.01;
/// Draws of the whole cosine lobe before giving up (acceptance ≥ 5%: reached with probability 0.95¹⁰⁰⁰⁰).
const MAX_TRIALS: u32 = 10_000;

/// How directions towards one triangle are drawn from one shading point: a deterministic function of (p, n,
/// ω_o, material, Δ), so that the density can be evaluated for any direction.
struct Plan {
    diffuse: ProjectedPlan,
    /// Ω⊥ of Δ about n.
    projected: f64,
    specular: Specular,
    /// P_d.
    p_diffuse: f64,
}

enum Specular {
    /// No specular part (k_s = 0, Δ entirely behind the lobe's axis, or a lobe too narrow to reach Δ: W_s = 0).
    None,
    /// Projected-solid-angle sampling of M⁻¹Δ in cosine space (rejection from its spherical triangle).
    Rejection { ltc: Ltc, tri: [Vec3; 3], cos_max: f32, projected: f64 },
    /// The whole cosine lobe, drawn until it meets M⁻¹Δ.
    WholeLobe { ltc: Ltc, tri: [DVec3; 3], projected: f64 },
    /// Uniform points on Δ.
    Area,
}

/// The mixture's weights, W_d and W_s, and the geometry they are computed from: all that the `contribution`
/// light selection needs of a triangle; [`Weights::plan`] completes the plan for the one that is sampled.
struct Weights {
    /// Ω⊥ of Δ about n.
    projected: f32,
    /// The lobe's LTC and Δ in its cosine space, with Ω⊥(M⁻¹Δ); `None` without a specular part.
    lobe: Option<(Ltc, [DVec3; 3], f64)>,
    w_d: f64,
    w_s: f64,
}

impl Weights {
    /// `None` where nothing of Δ is above the horizon.
    fn new(sp: &ShadingPoint, tri: &Triangle) -> Option<Self> {
        let (p, n, [a, b, c]) = (sp.p, sp.n, tri.v);
        let projected = projected_solid_angle(p, n, a, b, c);
        if !(projected > 0.0) {
            return None;
        }
        let m = sp.material;
        let w_d = (m.kd.element_sum() as f64 / 3.0).max(DIFFUSE_FLOOR) * projected as f64 * FRAC_1_PI;
        let ks = m.ks.element_sum() as f64 / 3.0;
        let (mut lobe, mut w_s) = (None, 0.0);
        if ks > 0.0
            && let Some(PhongLtc { ltc, mass }) = PhongLtc::new(n, sp.wo, m.alpha)
        {
            let cosine_space = tri.v.map(|v| ltc.to_cosine_space((v - p).as_dvec3()));
            let projected_lobe = projected_solid_angle_f64(DVec3::Z, cosine_space);
            if projected_lobe > 0.0 {
                let alpha = m.alpha as f64;
                let wr = reflect(sp.wo, n);
                // ∫_Δ lobe (ω·n) dω ≤ the lobe's largest value on Δ times ∫_Δ (ω·n) dω.
                let bound =
                    (alpha + 1.0) / (2.0 * PI) * (max_cosine(p, wr, a, b, c) as f64).powf(alpha) * projected as f64;
                w_s = ks * (mass * projected_lobe * FRAC_1_PI).min(bound);
                lobe = Some((ltc, cosine_space, projected_lobe));
            }
        }
        Some(Self { projected, lobe, w_d, w_s })
    }

    /// W_d + W_s: the estimated `∫_Δ f_r (ω·n) dω`.
    fn total(&self) -> f64 {
        self.w_d + self.w_s
    }

    /// The sampling plan: each part's method, by the deterministic fallbacks of the module's docs.
    fn plan(&self, sp: &ShadingPoint, tri: &Triangle) -> Plan {
        let [a, b, c] = tri.v;
        let diffuse = ProjectedPlan::with_projected(sp.p, sp.n, a, b, c, self.projected);
        let specular = match self.lobe {
            Some((ltc, tri, projected)) if self.w_s > 0.0 => specular_plan(ltc, tri, projected),
            _ => Specular::None,
        };
        Plan { diffuse, projected: self.projected as f64, specular, p_diffuse: self.w_d / self.total() }
    }
}

impl Plan {
    /// `None` where nothing of Δ is above the horizon.
    fn new(sp: &ShadingPoint, tri: &Triangle) -> Option<Self> {
        Some(Weights::new(sp, tri)?.plan(sp, tri))
    }

    /// A direction towards Δ, its density given Δ, and the point on Δ it aims at.
    fn sample(&self, sp: &ShadingPoint, tri: &Triangle, rng: &mut SampleRng) -> Option<(Vec3, f32, Vec3)> {
        let wi = if (rng.uniform() as f64) < self.p_diffuse {
            match self.diffuse {
                ProjectedPlan::Rejection { cos_max, .. } => sample_projected_triangle(rng, sp.p, sp.n, tri.v, cos_max)?,
                _ => Emitter::sample_triangle(sp, tri, rng)?.0,
            }
        } else {
            match &self.specular {
                Specular::Rejection { ltc, tri, cos_max, .. } => {
                    let w0 = sample_projected_triangle(rng, Vec3::ZERO, Vec3::Z, *tri, *cos_max)?;
                    ltc.from_cosine_space(w0.as_dvec3()).normalize().as_vec3()
                }
                Specular::WholeLobe { ltc, tri, .. } => sample_whole_lobe(ltc, tri, rng)?,
                Specular::Area | Specular::None => Emitter::sample_triangle(sp, tri, rng)?.0,
            }
        };
        let x = hit_plane(sp.p, wi, tri)?;
        let pdf = self.pdf(sp, tri, x, wi);
        (pdf > 0.0 && pdf.is_finite()).then_some((wi, pdf, x))
    }

    /// `P_d p_d(ω) + (1 − P_d) p_s(ω)` for `wi`, which meets Δ at `x`.
    fn pdf(&self, sp: &ShadingPoint, tri: &Triangle, x: Vec3, wi: Vec3) -> f32 {
        let p_d = match self.diffuse {
            ProjectedPlan::Rejection { .. } => projected_triangle_pdf(wi.dot(sp.n), self.projected as f32) as f64,
            _ => area_pdf_solid_angle(sp.p, tri, x, wi) as f64,
        };
        let p_s = match &self.specular {
            Specular::None => 0.0,
            Specular::Rejection { ltc, projected, .. } | Specular::WholeLobe { ltc, projected, .. } => {
                ltc.density(wi.as_dvec3()) * PI / projected
            }
            Specular::Area => area_pdf_solid_angle(sp.p, tri, x, wi) as f64,
        };
        let pdf = self.p_diffuse * p_d + (1.0 - self.p_diffuse) * p_s;
        if pdf.is_finite() { pdf as f32 } else { 0.0 }
    }
}

/// How the specular part samples M⁻¹Δ (`tri`, of projected solid angle `projected` in cosine space).
fn specular_plan(ltc: Ltc, tri: [DVec3; 3], projected: f64) -> Specular {
    let tri_f32 = tri.map(DVec3::as_vec3);
    let [a, b, c] = tri_f32;
    let solid_angle = spherical_triangle_area(Vec3::ZERO, a, b, c);
    if (MIN_SPHERICAL_SAMPLE_AREA..=MAX_SPHERICAL_SAMPLE_AREA).contains(&solid_angle) {
        let cos_max = max_cosine(Vec3::ZERO, Vec3::Z, a, b, c);
        if projected >= (MIN_ACCEPTANCE * solid_angle * cos_max) as f64 {
            return Specular::Rejection { ltc, tri: tri_f32, cos_max, projected };
        }
    }
    if projected * FRAC_1_PI >= MIN_ACCEPTANCE as f64 {
        Specular::WholeLobe { ltc, tri, projected }
    } else {
        Specular::Area
    }
}

/// A direction of the whole LTC, drawn until its cosine-space direction meets `tri` (density D(ω)/∫_Δ D).
fn sample_whole_lobe(ltc: &Ltc, tri: &[DVec3; 3], rng: &mut SampleRng) -> Option<Vec3> {
    let [a, b, c] = *tri;
    let (ab, bc, ca) = (a.cross(b), b.cross(c), c.cross(a));
    let orientation = a.dot(bc);
    for _ in 0..MAX_TRIALS {
        let w0 = sample_cosine_hemisphere(rng.uniform_2d()).as_dvec3();
        let inside = [ab, bc, ca].iter().all(|e| e.dot(w0) * orientation > 0.0);
        if inside {
            return Some(ltc.from_cosine_space(w0).normalize().as_vec3());
        }
    }
    None
}

impl TriangleSampler for BrdfPolygon {
    fn sample_triangle(sp: &ShadingPoint, tri: &Triangle, rng: &mut SampleRng) -> Option<(Vec3, f32, Vec3)> {
        Plan::new(sp, tri)?.sample(sp, tri, rng)
    }

    fn triangle_pdf(sp: &ShadingPoint, tri: &Triangle, x: Vec3, wi: Vec3) -> f32 {
        Plan::new(sp, tri).map_or(0.0, |plan| plan.pdf(sp, tri, x, wi))
    }
}

/// Each of the scene's emitter triangles' weights at the shading point (in the light selection's order; `None`
/// where it faces away or is below the horizon) and its weight for p_Δ, luminance(L_e) (W_d + W_s).
fn lobe_weights(ctx: &SampleContext, sp: &ShadingPoint, triangles: &[u32]) -> Vec<(Option<Weights>, f64)> {
    triangles
        .iter()
        .map(|&t| {
            let tri = &ctx.scene.triangles[t as usize];
            let weights = faces(tri, sp.p).then(|| Weights::new(sp, tri)).flatten();
            let l = luminance(ctx.scene.materials[tri.material as usize].emission).max(0.0) as f64;
            let w = weights.as_ref().map_or(0.0, Weights::total) * l;
            (weights, if w.is_finite() { w } else { 0.0 })
        })
        .collect()
}

fn lobe_aware(ctx: &SampleContext) -> bool {
    ctx.emitters.is_some_and(|e| e.selection() == LightSelection::Contribution)
}

impl DirectionStrategy for BrdfPolygon {
    const NAME: &'static str = "brdf-polygon";
    const DESCRIPTION: &'static str = "directions over a light triangle with density close to f_r cos θ: projected solid angle for k_d, an LTC-warped triangle for the Phong lobe (exact)";
    const PDF: &'static str = "p(ω) = p_Δ [P_d (ω·n)/Ω_proj + (1−P_d) π D_M(ω)/Ω_proj(Δ')],  D_M: the cosine warped by M to fit the lobe, Δ' = M^-1 Δ";
    const DOMAIN: Domain = Domain::Lights;

    fn sample(&self, ctx: &SampleContext, sp: &ShadingPoint, rng: &mut SampleRng) -> Option<DirectionSample> {
        if !lobe_aware(ctx) {
            return sample_light::<Self>(ctx, sp, rng);
        }
        let triangles = ctx.emitters?.triangles();
        let weights = lobe_weights(ctx, sp, triangles);
        let total: f64 = weights.iter().map(|w| w.1).sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let target = rng.uniform() as f64 * total;
        let (mut acc, mut chosen) = (0.0, None);
        for (i, &(_, w)) in weights.iter().enumerate() {
            if w > 0.0 {
                acc += w;
                chosen = Some(i);
                if target < acc {
                    break;
                }
            }
        }
        let i = chosen?;
        let triangle = triangles[i];
        let tri = &ctx.scene.triangles[triangle as usize];
        let (parts, weight) = &weights[i];
        let (wi, pdf, point) = parts.as_ref()?.plan(sp, tri).sample(sp, tri, rng)?;
        let pdf = (weight / total) as f32 * pdf;
        (pdf > 0.0 && pdf.is_finite()).then_some(DirectionSample {
            wi,
            pdf,
            target: Target::Emitter { triangle, point },
        })
    }

    fn pdf(&self, ctx: &SampleContext, sp: &ShadingPoint, wi: Vec3, via: Option<Reached>) -> f32 {
        if !lobe_aware(ctx) {
            return light_pdf::<Self>(ctx, sp, wi, via);
        }
        let (Some(emitters), Some(Reached { triangle, point })) = (ctx.emitters, via) else { return 0.0 };
        let triangles = emitters.triangles();
        let Some(i) = triangles.iter().position(|&t| t == triangle) else { return 0.0 };
        let weights = lobe_weights(ctx, sp, triangles);
        let total: f64 = weights.iter().map(|w| w.1).sum();
        let (Some(parts), weight) = &weights[i] else { return 0.0 };
        if !(total > 0.0 && *weight > 0.0) {
            return 0.0;
        }
        let tri = &ctx.scene.triangles[triangle as usize];
        (weight / total) as f32 * parts.plan(sp, tri).pdf(sp, tri, point, wi)
    }
}
