//! One sample of the scattering integral: `f_r(ω_k, ω_o) L_i(ω_k) (ω_k·n) / p(ω_k)`.

use super::{ShadingPoint, Strategy, Target};
use crate::math::{SampleRng, offset_ray_origin};
use crate::scene::{EmitterSampler, Scene};
use glam::Vec3;

/// Estimates the reflected radiance at `sp` with one sample of `strategy`. Returns the contribution (possibly
/// non-finite if the inputs are pathological: callers drop and count such samples) and adds the rays traced to
/// `rays`.
#[inline]
pub fn estimate_direct(
    scene: &Scene,
    sp: &ShadingPoint,
    strategy: Strategy,
    emitters: Option<&EmitterSampler>,
    rng: &mut SampleRng,
    rays: &mut u64,
) -> Vec3 {
    let Some(s) = strategy.sample(sp, scene, emitters, rng) else { return Vec3::ZERO };
    let cos = sp.n.dot(s.wi);
    if !(cos > 0.0 && s.pdf > 0.0) {
        return Vec3::ZERO;
    }
    let f = sp.material.eval_brdf(sp.n, sp.wo, s.wi);
    if f == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let li = match s.target {
        Target::Trace => incident_radiance(scene, sp.p, sp.n, s.wi, rays),
        Target::Emitter { triangle, point } => {
            let le = scene.emitted(triangle, -s.wi);
            if le == Vec3::ZERO || !visible(scene, sp.p, sp.n, point, scene.triangles[triangle as usize].n, rays) {
                return Vec3::ZERO;
            }
            le
        }
    };
    f * li * (cos / s.pdf)
}

/// L_i(ω): the radiance emitted towards p by the first surface along ω, or 0.
#[inline]
pub fn incident_radiance(scene: &Scene, p: Vec3, n: Vec3, wi: Vec3, rays: &mut u64) -> Vec3 {
    *rays += 1;
    match scene.accel().closest_hit(offset_ray_origin(p, n), wi, f32::INFINITY) {
        Some(hit) => scene.emitted(hit.triangle, -wi),
        None => Vec3::ZERO,
    }
}

/// Shadow ray between p (normal n, on the side of x) and the point x on an emitter (normal n_x, facing p): both
/// ends are moved off their surfaces (Ray Tracing Gems ch. 6), so neither triangle occludes itself.
#[inline]
pub fn visible(scene: &Scene, p: Vec3, n: Vec3, x: Vec3, n_x: Vec3, rays: &mut u64) -> bool {
    *rays += 1;
    let from = offset_ray_origin(p, n);
    let to = offset_ray_origin(x, n_x);
    let d = to - from;
    let dist = d.length();
    if !(dist > 0.0) {
        return true;
    }
    !scene.accel().occluded(from, d / dist, dist * (1.0 - 1e-6))
}
