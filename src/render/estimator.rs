//! One sample of the scattering integral: `f_r(ω_k, ω_o) L_i(ω_k) (ω_k·n) / p(ω_k)`, and what finding L_i takes
//! (tracing the sampled direction, or a shadow ray towards the sampled point on a light).

use super::sink::{Outcome, SampleRecord, SampleSink};
use super::strategy::{DirectionSample, Reached, SampleContext, Target};
use super::{RenderSettings, ShadingPoint};
use crate::math::{SampleRng, SurfaceErrorLanes, Vec3x8, lanes_in, offset_ray_origin, offset_ray_origins};
use crate::scene::{EmitterSampler, SKIP_NONE, Scene, TileLights};
use glam::Vec3;
use wide::{CmpGt, f32x8, i32x8};

/// Estimates the reflected radiance at `sp` with one sample of the settings' strategy. Returns the contribution
/// (possibly non-finite for pathological input: callers drop and count such samples) and adds the rays traced.
/// A strategy with state of its own prepares it here on every call: to take many samples, use a
/// [`super::Renderer`]'s [`super::Renderer::context`].
#[inline]
pub fn estimate_direct(
    scene: &Scene,
    sp: &ShadingPoint,
    settings: &RenderSettings,
    emitters: Option<&EmitterSampler>,
    rng: &mut SampleRng,
    rays: &mut u64,
) -> Vec3 {
    let state = settings.strategy.prepare(scene, settings);
    let (state, tile) = (state.as_deref(), &TileLights::NONE);
    let ctx = SampleContext { scene, emitters, mis: &settings.mis, state, guide: None, tile };
    settings.strategy.estimate(&ctx, sp, rng, rays, &mut ())
}

/// The one-sample estimator for a drawn direction (or none): `f_r L_i (ω·n) / p(ω)`, reported to `sink`.
#[inline(always)]
pub fn one_sample<S: SampleSink>(
    scene: &Scene,
    sp: &ShadingPoint,
    s: Option<DirectionSample>,
    rays: &mut u64,
    sink: &mut S,
) -> Vec3 {
    let Some(s) = s else {
        sink.record(SampleRecord::none(0));
        return Vec3::ZERO;
    };
    let (contribution, radiance, outcome, hit) = match integrand(scene, sp, &s, rays) {
        Ok((value, via)) => (value / s.pdf, scene.emitted(via.triangle, -s.wi), Outcome::Contributed, via.point),
        Err(outcome) => (Vec3::ZERO, Vec3::ZERO, outcome, Vec3::ZERO),
    };
    let (wi, pdf) = (s.wi, s.pdf);
    let parts = [0.0; 3];
    sink.record(SampleRecord { technique: 0, wi, pdf, mis_weight: 1.0, contribution, radiance, outcome, parts, hit });
    contribution
}

/// `f_r L_i (ω·n)` for a sampled direction (not yet divided by the density), and the emitter triangle and point
/// it reached; where it is zero, why.
#[inline]
pub(crate) fn integrand(
    scene: &Scene,
    sp: &ShadingPoint,
    s: &DirectionSample,
    rays: &mut u64,
) -> Result<(Vec3, Reached), Outcome> {
    match s.target {
        Target::Trace => {
            let (f, cos) = brdf_and_cos(sp, s)?;
            let (li, via) = lit(scene, sp, s.wi, rays)?;
            Ok((f * li * cos, via))
        }
        Target::Emitter { triangle, point } => {
            let (value, n_x) = unshadowed(scene, sp, s, triangle)?;
            if !visible(scene, sp, (triangle, point, n_x), rays) {
                return Err(Outcome::Occluded);
            }
            Ok((value, Reached { triangle, point }))
        }
    }
}

/// The emitter triangle the ray from `sp` along `wi` reaches first, and where; `None` where it meets a surface
/// that does not emit towards it, or nothing. Counts no ray: for densities that depend on what a direction
/// reaches, outside the estimate's own rays.
pub fn reached(scene: &Scene, sp: &ShadingPoint, wi: Vec3) -> Option<Reached> {
    lit(scene, sp, wi, &mut 0).ok().map(|(_, via)| via)
}

/// L_i(ω) along a traced direction ω = `wi` from `sp`, which is L_e(x, −ω) at the first surface x the ray from sp
/// meets, with the emitter triangle and x; why it is zero. The ray starts off the surface
/// (`math::offset_ray_origin`); x is looked for among the emitter triangles alone, nearest first
/// ([`crate::scene::EmitterTree`]), and then a shadow ray from sp to x ([`visible`]) asks whether anything lies
/// before it: two rays where x emits towards sp, one (in the lights' small tree) where none is met. The nearest of
/// all triangles gives the same answer but for ties within the shadow ray's offsets. Adds the rays traced.
#[inline]
fn lit(scene: &Scene, sp: &ShadingPoint, wi: Vec3, rays: &mut u64) -> Result<(Vec3, Reached), Outcome> {
    *rays += 1;
    let origin = offset_ray_origin(sp.p, sp.n, sp.error);
    let hit = scene.emitter_tree().closest_hit(origin, wi).ok_or(Outcome::MissedLights)?;
    let li = scene.emitted(hit.triangle, -wi);
    if li == Vec3::ZERO {
        return Err(Outcome::MissedLights);
    }
    let (triangle, point) = (hit.triangle, scene.hit_point(&hit));
    if !visible(scene, sp, (triangle, point, scene.triangles[triangle as usize].n), rays) {
        return Err(Outcome::Occluded);
    }
    Ok((li, Reached { triangle, point }))
}

/// f_r and ω·n for a sampled direction; why not, where the sample contributes nothing whatever arrives along ω
/// (below the surface, zero density, f_r = 0).
#[inline]
pub(super) fn brdf_and_cos(sp: &ShadingPoint, s: &DirectionSample) -> Result<(Vec3, f32), Outcome> {
    let cos = sp.n.dot(s.wi);
    if !(cos > 0.0 && s.pdf > 0.0) {
        return Err(if cos > 0.0 { Outcome::NoSample } else { Outcome::BelowSurface });
    }
    let f = sp.material.eval_brdf(sp.n, sp.wo, s.wi);
    if f == Vec3::ZERO { Err(Outcome::ZeroBrdf) } else { Ok((f, cos)) }
}

/// For a direction aimed at a point on the emitter triangle `triangle`: `f_r L_e (ω·n)`, which arrives if the
/// shadow ray gets through, and the triangle's normal (for the ray's far end). Why not, where it is zero anyway.
#[inline]
pub(super) fn unshadowed(
    scene: &Scene,
    sp: &ShadingPoint,
    s: &DirectionSample,
    triangle: u32,
) -> Result<(Vec3, Vec3), Outcome> {
    let (f, cos) = brdf_and_cos(sp, s)?;
    let le = scene.emitted(triangle, -s.wi);
    if le == Vec3::ZERO {
        return Err(Outcome::MissedLights);
    }
    Ok((f * le * cos, scene.triangles[triangle as usize].n))
}

/// Shadow ray between the shading point p (normal n, on the side of x) and the point x on the emitter triangle Δ
/// (normal n_x, facing p), given as (Δ, x, n_x): both ends are moved off their surfaces by the bounds of their
/// rounding errors (`math::offset`), so neither triangle occludes itself. From in front of Δ's plane, the ray
/// skips the rest of Δ's convex emitter group, which it cannot meet (`scene::convex`).
#[inline]
pub fn visible(scene: &Scene, sp: &ShadingPoint, (triangle, x, n_x): (u32, Vec3, Vec3), rays: &mut u64) -> bool {
    *rays += 1;
    let (from, to) = shadow_ray_ends(scene, sp.p, sp.n, sp.error, (triangle, x, n_x));
    let skip = if n_x.dot(from - x) > 0.0 { scene.convex_group(triangle) } else { None };
    !scene.accel().occluded(from, to - from, SEGMENT_END, skip)
}

/// The ends of the shadow ray from p (normal n, off its surface by at most `error`) to x on Δ (normal n_x), each
/// moved off its surface by its bound.
#[inline]
pub fn shadow_ray_ends(
    scene: &Scene,
    p: Vec3,
    n: Vec3,
    error: f32,
    (triangle, x, n_x): (u32, Vec3, Vec3),
) -> (Vec3, Vec3) {
    let far = scene.triangles[triangle as usize].error.far_end(p, x, n_x);
    (offset_ray_origin(p, n, error), offset_ray_origin(x, n_x, far))
}

/// The ends of eight shadow rays: [`shadow_ray_ends`] per lane, bit for bit, with lane l's far end on a triangle
/// with bounds lane l of `far`.
#[inline]
pub(super) fn shadow_ray_ends_lanes(
    (p, n, error): (Vec3x8, Vec3x8, f32x8),
    (x, n_x): (Vec3x8, Vec3x8),
    far: &SurfaceErrorLanes,
) -> (Vec3x8, Vec3x8) {
    let far = far.far_end(p, x, n_x);
    (offset_ray_origins(p, n, error), offset_ray_origins(x, n_x, far))
}

/// [`visible`] for eight pairs of points at once, one per lane, those in `active` (bit i for lane i): the
/// shading points (p, n, their bounds), the points x on the lights with their normals, lane i's x on a triangle
/// with the bounds in lane i of `far()` (asked for only where a ray is traced) and of convex emitter group
/// `groups[i]` ([`SKIP_NONE`] for none); returns the visible ones.
/// With `tile` (the pixel's tile, and each lane's emitter slot), the rays to its clear lights get through untraced
/// and those to a light its blockers list meet them alone; the others walk the tree. Lane i's answer is
/// `visible`'s, bit for bit.
#[inline]
pub(super) fn visible_lanes(
    scene: &Scene,
    near: (Vec3x8, Vec3x8, f32x8),
    (x, n_x): (Vec3x8, Vec3x8),
    (far, groups): (impl FnOnce() -> SurfaceErrorLanes, [u32; 8]),
    active: u32,
    tile: Option<(&TileLights, i32x8)>,
    rays: &mut u64,
) -> u32 {
    *rays += active.count_ones() as u64;
    let clear = tile.map_or(0, |(tile, slots)| lanes_in(tile.clear, slots)) & active;
    let traced = active & !clear;
    if traced == 0 {
        return active; // no ray (all missed, saw only a light, or were rejected), or only rays to clear lights
    }
    let (from, to) = shadow_ray_ends_lanes(near, (x, n_x), &far());
    let (mut occluded, mut walking) = (0, traced);
    if let Some((blockers, slots)) = tile.and_then(|(tile, slots)| Some((tile.blockers.as_deref()?, slots))) {
        let listed = traced & blockers.listed(slots);
        occluded = blockers.occluded_lanes(&from, &(to - from), SEGMENT_END, listed, slots);
        walking &= !listed;
    }
    if walking != 0 {
        let mut skips = [SKIP_NONE; 8];
        if groups != skips {
            let in_front = n_x.dot(from - x).cmp_gt(f32x8::ZERO).move_mask();
            skips = std::array::from_fn(|l| if in_front & (1 << l) != 0 { groups[l] } else { SKIP_NONE });
        }
        occluded |= scene.accel().occluded_lanes(&from, &(to - from), SEGMENT_END, walking, skips);
    }
    active & !occluded
}

/// Shadow rays run along `from + t·(to − from)` for 0 < t < 1 − 10⁻⁶ (the direction is not a unit vector).
pub const SEGMENT_END: f32 = 1.0 - 1e-6;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::gamma;
    use crate::sampling::sample_uniform_triangle;
    use crate::scene::load_scene;

    /// A shadow ray that skips its light's convex emitter group answers as one that tests every triangle: from
    /// points anywhere around veach-mis's sphere lights and from points just above their surfaces, to uniform
    /// points on triangles of those lights facing them.
    #[test]
    fn skipping_the_lights_own_group_changes_no_shadow_ray() {
        let scene = load_scene("veach-mis").expect("bundled scene");
        let lights: Vec<u32> = scene.emitters.iter().copied().filter(|&t| scene.convex_group(t).is_some()).collect();
        assert_eq!(lights.len(), 560, "the four sphere lights are convex groups");
        let (lo, hi) = lights
            .iter()
            .flat_map(|&t| scene.triangles[t as usize].v)
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let (centre, extent) = ((lo + hi) * 0.5, (hi - lo) * 2.0);
        let (mut tested, mut blocked) = (0, 0);
        for k in 0..40_000u64 {
            let mut rng = SampleRng::new(5, k, 0);
            let light = lights[(rng.uniform() * lights.len() as f32) as usize];
            let tri = &scene.triangles[light as usize];
            let x = sample_uniform_triangle(rng.uniform_2d(), tri.v[0], tri.v[1], tri.v[2]);
            let p = if k % 2 == 0 {
                let u = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5;
                centre + u * extent
            } else {
                // Just above the light, 10⁻⁴ to 10⁻¹ m from x, in a direction on its emitting side.
                let d = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5;
                x + (d + tri.n).normalize() * 10f32.powf(-4.0 + 3.0 * rng.uniform())
            };
            let n = (x - p).normalize();
            let error = gamma(8) * p.abs().dot(n.abs());
            let (from, to) = shadow_ray_ends(&scene, p, n, error, (light, x, tri.n));
            if !(tri.n.dot(from - x) > 0.0) {
                continue;
            }
            let skip = scene.convex_group(light);
            let full = scene.accel().occluded(from, to - from, SEGMENT_END, None);
            assert_eq!(scene.accel().occluded(from, to - from, SEGMENT_END, skip), full, "ray {k}: {p} to {x}");
            tested += 1;
            blocked += full as u32;
        }
        assert!(tested > 20_000 && blocked > 500, "{tested} rays, {blocked} blocked: the test checks too little");
    }
}
