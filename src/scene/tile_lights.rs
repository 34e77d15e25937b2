//! For a bundle of camera rays (a tile of pixels), the emitter triangles that every shadow ray from where they
//! hit reaches with nothing in the way (`Accel::shaft_blockers` finds none): a light strategy need not trace
//! those rays; and for others, the few triangles that can stop their rays (`ShadowBlockers`): those rays are
//! tested against them alone. Found once per tile and kept (`render::PixelCones`), so the cost is shared by every
//! sample of its pixels in every pass.
//!
//! The triangles the camera rays can hit (their cone's candidates) lie in one plane or a few (a tile across the
//! edge of a box). A footprint is where the camera rays meet one of those planes: the quad where the cone's four
//! corner rays meet it holds every such point. Its shaft to an emitter triangle Δ leaves out the triangles the
//! shadow rays cannot hit by construction: the one the footprint lies on when it is the only candidate (the ray
//! starts off it, `math::offset`), Δ itself and its convex group (the ray ends in front of Δ, and skips the
//! group); the shaft's fronts leave out everything on or behind either plane. Δ is clear when every
//! footprint's shaft holds no other triangle, listed when all of them hold few.

use super::{Scene, ShadowBlockers};
use crate::math::gamma;
use arrayvec::ArrayVec;
use glam::Vec3;

/// Scenes with more emitter triangles than this get no shafts (a shaft per emitter triangle per tile
/// would cost more than the rays it saves; veach-mis's sphere lights have 560).
const MAX_SHAFT_LIGHTS: usize = 8;

/// A shaft's walk gives up (the light is not clear) after this many nodes and leaves.
const SHAFT_BUDGET: u32 = 256;

/// Tiles whose candidates lie in more planes than this get nothing (a shaft per plane per light).
const MAX_PLANES: usize = 2;

/// What a tile's shadow rays to each emitter slot s (`Scene::emitters[s]`) can meet.
#[derive(Clone, Debug, Default)]
pub struct TileLights {
    /// Bit s set where every such ray is unblocked, as `Accel::occluded` would find it.
    pub clear: u32,
    /// For some other slots ([`ShadowBlockers::lights`]), every triangle that can stop their rays.
    pub blockers: Option<Box<ShadowBlockers>>,
}

impl TileLights {
    /// Nothing known: every shadow ray walks the tree.
    pub const NONE: Self = Self { clear: 0, blockers: None };
}

impl Scene {
    /// What the shadow rays can meet from a point where the camera rays from `eye` through the quad of
    /// directions `corners` meet the triangles `candidates` (all they can hit: their cone's) to a point of an
    /// emitter triangle.
    pub fn tile_lights(&self, eye: Vec3, corners: [Vec3; 4], candidates: &[u32]) -> TileLights {
        if self.emitters.is_empty() || self.emitters.len() > MAX_SHAFT_LIGHTS || candidates.is_empty() {
            return TileLights::NONE;
        }
        let Some(footprints) = self.footprints(eye, corners, candidates) else { return TileLights::NONE };
        let own_error = candidates.iter().map(|&t| self.triangles[t as usize].error.at_point).fold(0.0, f32::max);
        let mut clear = 0;
        // The blockers of the slots listed so far, with the slots whose rays each may stop.
        let (mut blockers, mut listed) = (ArrayVec::<(u32, u32), 8>::new(), 0);
        for (slot, &light) in self.emitters.iter().enumerate() {
            let mut found = ArrayVec::<u32, 8>::new();
            let shafts = footprints.iter().map(|f| self.light_blockers(eye, f, own_error, light, candidates));
            let all = shafts.into_iter().try_for_each(|in_shaft| {
                for t in in_shaft? {
                    if !found.contains(&t) {
                        found.try_push(t).ok()?;
                    }
                }
                Some(())
            });
            if all.is_none() {
                continue; // these rays walk the tree
            }
            if found.is_empty() {
                clear |= 1 << slot;
                continue;
            }
            let new = found.iter().filter(|&&t| !blockers.iter().any(|b| b.0 == t)).count();
            if blockers.len() + new > 8 {
                continue; // these too
            }
            for t in found {
                match blockers.iter_mut().find(|b| b.0 == t) {
                    Some(b) => b.1 |= 1 << slot,
                    None => blockers.push((t, 1 << slot)),
                }
            }
            listed |= 1 << slot;
        }
        let blockers = (listed != 0).then(|| {
            let triangle = |i: usize| (self.triangles[blockers[i].0 as usize].v, blockers[i].0, blockers[i].1);
            Box::new(ShadowBlockers::new(blockers.len(), triangle, listed))
        });
        TileLights { clear, blockers }
    }

    /// The candidates' planes (`(n, d)`, n towards the eye; a triangle whose vertices all lie in a plane found
    /// before, exactly, joins it), each with its footprint. `None` where there are more than [`MAX_PLANES`], or
    /// a corner ray does not meet one in front of the eye.
    fn footprints(&self, eye: Vec3, corners: [Vec3; 4], candidates: &[u32]) -> Option<Footprints> {
        let mut planes = Footprints::new();
        for &t in candidates {
            let tri = &self.triangles[t as usize];
            if planes.iter().any(|&((n, d), _)| tri.v.iter().all(|v| n.dot(*v) == d)) {
                continue;
            }
            let n = if tri.n.dot(eye - tri.v[0]) > 0.0 { tri.n } else { -tri.n };
            let d = n.dot(tri.v[0]);
            if !(n.dot(eye) - d > 0.0) {
                return None;
            }
            let mut footprint = [Vec3::ZERO; 4];
            for (f, c) in footprint.iter_mut().zip(corners) {
                let t = (d - n.dot(eye)) / n.dot(c);
                if !(t > 0.0 && t.is_finite()) {
                    return None;
                }
                *f = eye + c * t;
            }
            planes.try_push(((n, d), footprint)).ok()?;
        }
        Some(planes)
    }

    /// The triangles that may stop a shadow ray from `footprint` (off it by at most `own_error`) to the emitter
    /// triangle `light`: `None` where the footprint is not wholly in front of it, or there are more than eight.
    fn light_blockers(
        &self,
        eye: Vec3,
        &((n, d), footprint): &((Vec3, f32), [Vec3; 4]),
        own_error: f32,
        light: u32,
        candidates: &[u32],
    ) -> Option<ArrayVec<u32, 8>> {
        let tri = &self.triangles[light as usize];
        let points = footprint.iter().chain(&tri.v);
        let scale = points.clone().chain([&eye]).map(|p| p.abs().max_element()).fold(0.0, f32::max);
        let (lo, hi) = points.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        // The rays' ends lie off the patches by at most their offsets (`SurfaceError::far_end` at the light,
        // for any segment within the shaft's box) plus an ULP; the tests round by a few ULPs of the scale.
        let far =
            tri.error.at_point + (hi - lo).dot(tri.error.per_distance) + gamma(8) * scale * tri.n.abs().element_sum();
        let margin = 2.0 * (own_error + far) + 32.0 * f32::EPSILON * scale;
        let plane = (tri.n, tri.n.dot(tri.v[0]));
        // Rays from behind Δ's plane are never traced; the group is skipped only from in front of it.
        if !footprint.iter().all(|c| plane.0.dot(*c) - plane.1 > margin) {
            return None;
        }
        let shaft = super::Shaft::between(&footprint, (n, d), &tri.v, plane, margin);
        let group = self.convex_group(light);
        let left_out = |t: u32| {
            t == light
                || (candidates.len() == 1 && t == candidates[0])
                || (group.is_some() && self.convex_group(t) == group)
        };
        self.accel().shaft_blockers(&shaft, left_out, SHAFT_BUDGET)
    }
}

/// The candidates' planes, each with its footprint.
type Footprints = ArrayVec<((Vec3, f32), [Vec3; 4]), MAX_PLANES>;
