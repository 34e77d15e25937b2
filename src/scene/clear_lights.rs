//! For a bundle of camera rays (a tile of pixels), the emitter triangles that every shadow ray from where they
//! hit reaches with nothing in the way (`Accel::shaft_is_clear`): a light strategy need not trace those rays.
//! Found once per tile and kept (`render::PixelCones`), so the cost is shared by every sample of its pixels in
//! every pass.
//!
//! The footprint is where the camera rays meet the plane of the triangles they can hit (their cone's
//! candidates, which must share one plane): the quad where the cone's four corner rays meet it. Its shaft to an
//! emitter triangle Δ leaves out the triangles the shadow rays cannot hit by construction: the one the footprint
//! lies on (the ray starts off it, `math::offset`), Δ itself and its convex group (the ray ends in front of Δ,
//! and skips the group); the shaft's fronts leave out everything on or behind either plane.

use super::Scene;
use crate::math::gamma;
use glam::Vec3;

/// Scenes with more emitter triangles than this get no clear lights (a shaft per emitter triangle per tile
/// would cost more than the rays it saves; veach-mis's sphere lights have 560).
const MAX_SHAFT_LIGHTS: usize = 8;

/// A shaft's walk gives up (the light is not clear) after this many nodes and leaves.
const SHAFT_BUDGET: u32 = 256;

impl Scene {
    /// Bit s set for emitter slot s (`Scene::emitters[s]`) when every shadow ray from a point where the camera
    /// rays from `eye` through the quad of directions `corners` meet the triangles `candidates` (all they can
    /// hit: their cone's) to a point of that triangle is unblocked, as `Accel::occluded` would find it.
    pub fn clear_lights(&self, eye: Vec3, corners: [Vec3; 4], candidates: &[u32]) -> u32 {
        if self.emitters.is_empty() || self.emitters.len() > MAX_SHAFT_LIGHTS || candidates.is_empty() {
            return 0;
        }
        // The candidates' plane, its normal towards the eye; several candidates must lie in it exactly.
        let own = &self.triangles[candidates[0] as usize];
        let n = if own.n.dot(eye - own.v[0]) > 0.0 { own.n } else { -own.n };
        let d = n.dot(own.v[0]);
        let coplanar = |&t: &u32| self.triangles[t as usize].v.iter().all(|v| n.dot(*v) == d);
        if !(n.dot(eye) - d > 0.0) || !candidates[1..].iter().all(coplanar) {
            return 0;
        }
        let mut footprint = [Vec3::ZERO; 4];
        for (f, c) in footprint.iter_mut().zip(corners) {
            let t = (d - n.dot(eye)) / n.dot(c);
            if !(t > 0.0 && t.is_finite()) {
                return 0;
            }
            *f = eye + c * t;
        }
        let own_error = candidates.iter().map(|&t| self.triangles[t as usize].error.at_point).fold(0.0, f32::max);
        let mut clear = 0;
        for (slot, &light) in self.emitters.iter().enumerate() {
            let tri = &self.triangles[light as usize];
            let points = footprint.iter().chain(&tri.v);
            let scale = points.clone().chain([&eye]).map(|p| p.abs().max_element()).fold(0.0, f32::max);
            let (lo, hi) = points.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
            // The rays' ends lie off the patches by at most their offsets (`SurfaceError::far_end` at the light,
            // for any segment within the shaft's box) plus an ULP; the tests round by a few ULPs of the scale.
            let far = tri.error.at_point
                + (hi - lo).dot(tri.error.per_distance)
                + gamma(8) * scale * tri.n.abs().element_sum();
            let margin = 2.0 * (own_error + far) + 32.0 * f32::EPSILON * scale;
            let plane = (tri.n, tri.n.dot(tri.v[0]));
            // Rays from behind Δ's plane are never traced; the group is skipped only from in front of it.
            if !footprint.iter().all(|c| plane.0.dot(*c) - plane.1 > margin) {
                continue;
            }
            let shaft = super::Shaft::between(&footprint, (n, d), &tri.v, plane, margin);
            let group = self.convex_group(light);
            let left_out = |t: u32| {
                t == light
                    || (candidates.len() == 1 && t == candidates[0])
                    || (group.is_some() && self.convex_group(t) == group)
            };
            if self.accel().shaft_is_clear(&shaft, left_out, SHAFT_BUDGET) {
                clear |= 1 << slot;
            }
        }
        clear
    }
}
