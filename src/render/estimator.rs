//! One sample of the scattering integral: `f_r(ω_k, ω_o) L_i(ω_k) (ω_k·n) / p(ω_k)`, or, for MIS, the weighted
//! combination of a light and a BRDF technique.

use super::strategy::{DirectionSample, MisSettings, Target};
use super::{RenderSettings, ShadingPoint, Strategy};
use crate::math::{SampleRng, Vec3x8, offset_ray_origin, offset_ray_origins};
use crate::scene::{EmitterSampler, Scene};
use glam::Vec3;

/// Estimates the reflected radiance at `sp` with one sample of the settings' strategy. Returns the contribution
/// (possibly non-finite for pathological input: callers drop and count such samples) and adds the rays traced.
#[inline]
pub fn estimate_direct(
    scene: &Scene,
    sp: &ShadingPoint,
    settings: &RenderSettings,
    emitters: Option<&EmitterSampler>,
    rng: &mut SampleRng,
    rays: &mut u64,
) -> Vec3 {
    if settings.strategy == Strategy::Mis {
        return estimate_mis(scene, sp, &settings.mis, emitters, rng, rays);
    }
    let Some(s) = settings.strategy.sample(sp, scene, emitters, rng) else { return Vec3::ZERO };
    match integrand(scene, sp, &s, rays) {
        Some((value, _)) => value / s.pdf,
        None => Vec3::ZERO,
    }
}

/// `f_r L_i (ω·n)` for a sampled direction (not yet divided by the density), and the emitter triangle and point
/// it reached. `None` where it is zero.
#[inline]
fn integrand(scene: &Scene, sp: &ShadingPoint, s: &DirectionSample, rays: &mut u64) -> Option<(Vec3, (u32, Vec3))> {
    match s.target {
        Target::Trace => {
            let (f, cos) = brdf_and_cos(sp, s)?;
            *rays += 1;
            let origin = offset_ray_origin(sp.p, sp.n);
            let hit = scene.accel().closest_hit(origin, s.wi, f32::INFINITY)?;
            let li = scene.emitted(hit.triangle, -s.wi);
            (li != Vec3::ZERO).then_some((f * li * cos, (hit.triangle, scene.hit_point(&hit))))
        }
        Target::Emitter { triangle, point } => {
            let (value, n_x) = unshadowed(scene, sp, s, triangle)?;
            visible(scene, sp.p, sp.n, point, n_x, rays).then_some((value, (triangle, point)))
        }
    }
}

/// f_r and ω·n for a sampled direction; `None` where the sample contributes nothing whatever arrives along ω
/// (below the surface, zero density, f_r = 0).
#[inline]
fn brdf_and_cos(sp: &ShadingPoint, s: &DirectionSample) -> Option<(Vec3, f32)> {
    let cos = sp.n.dot(s.wi);
    if !(cos > 0.0 && s.pdf > 0.0) {
        return None;
    }
    let f = sp.material.eval_brdf(sp.n, sp.wo, s.wi);
    (f != Vec3::ZERO).then_some((f, cos))
}

/// For a direction aimed at a point on the emitter triangle `triangle`: `f_r L_e (ω·n)`, which arrives if the
/// shadow ray gets through, and the triangle's normal (for the ray's far end). `None` where it is zero anyway.
#[inline]
pub(super) fn unshadowed(scene: &Scene, sp: &ShadingPoint, s: &DirectionSample, triangle: u32) -> Option<(Vec3, Vec3)> {
    let (f, cos) = brdf_and_cos(sp, s)?;
    let le = scene.emitted(triangle, -s.wi);
    (le != Vec3::ZERO).then(|| (f * le * cos, scene.triangles[triangle as usize].n))
}

/// Veach's multi-sample MIS estimator (see [`super::strategy::mis`]).
fn estimate_mis(
    scene: &Scene,
    sp: &ShadingPoint,
    mis: &MisSettings,
    emitters: Option<&EmitterSampler>,
    rng: &mut SampleRng,
    rays: &mut u64,
) -> Vec3 {
    let (n_l, n_b) = (mis.light_samples, mis.brdf_samples);
    let mut total = Vec3::ZERO;
    if let Some(emitters) = emitters {
        for _ in 0..n_l {
            let Some(s) = mis.light.sample(sp, scene, emitters, rng) else { continue };
            if let Some((value, _)) = integrand(scene, sp, &s, rays) {
                let p_b = sp.material.pdf_brdf(sp.n, sp.wo, s.wi);
                let w = mis.heuristic.weight(n_l, s.pdf, n_b, p_b);
                total += value * (w / (n_l as f32 * s.pdf));
            }
        }
    }
    for _ in 0..n_b {
        let Some(s) = Strategy::Brdf.sample(sp, scene, emitters, rng) else { continue };
        if let Some((value, (triangle, x))) = integrand(scene, sp, &s, rays) {
            let p_l = emitters.map_or(0.0, |e| mis.light.pdf(sp, scene, e, triangle, x, s.wi));
            let w = if n_l == 0 { 1.0 } else { mis.heuristic.weight(n_b, s.pdf, n_l, p_l) };
            total += value * (w / (n_b as f32 * s.pdf));
        }
    }
    total
}

/// Shadow ray between p (normal n, on the side of x) and the point x on an emitter (normal n_x, facing p): both
/// ends are moved off their surfaces (Ray Tracing Gems ch. 6), so neither triangle occludes itself.
#[inline]
pub fn visible(scene: &Scene, p: Vec3, n: Vec3, x: Vec3, n_x: Vec3, rays: &mut u64) -> bool {
    *rays += 1;
    let from = offset_ray_origin(p, n);
    let to = offset_ray_origin(x, n_x);
    !scene.accel().occluded(from, to - from, SEGMENT_END)
}

/// [`visible`] for eight pairs of points at once, one per lane, those in `active` (bit i for lane i); returns
/// the visible ones. Lane i's answer is `visible`'s, bit for bit.
#[inline]
pub(super) fn visible_lanes(
    scene: &Scene,
    p: Vec3x8,
    n: Vec3x8,
    x: Vec3x8,
    n_x: Vec3x8,
    active: u32,
    rays: &mut u64,
) -> u32 {
    if active == 0 {
        return 0; // a group whose samples all missed, saw only a light, or were rejected
    }
    *rays += active.count_ones() as u64;
    let from = offset_ray_origins(p, n);
    let to = offset_ray_origins(x, n_x);
    active & !scene.accel().occluded_lanes(&from, &(to - from), SEGMENT_END, active)
}

/// Shadow rays run along `from + t·(to − from)` for 0 < t < 1 − 10⁻⁶ (the direction is not a unit vector).
pub const SEGMENT_END: f32 = 1.0 - 1e-6;
