//! The few triangles that can stop the shadow rays from a tile of pixels to some of the scene's lights, in one
//! packet: found once per tile by the shafts that find its clear lights (`Scene::tile_lights`), they answer those
//! shadow rays with one packet test each, where the walk of the tree tests boxes, pushes and pops nodes and meets
//! the same triangles (and others the rays cannot hit) leaf by leaf.
//!
//! A shadow ray to slot s's light Δ from a point of the tile can be stopped only by a triangle that meets a segment
//! of s's shaft and is not one the ray cannot hit by construction (Δ, its convex group, the one the tile lies on:
//! see `scene::tile_lights`). Where those are all here, the ray is stopped by one of them (tested as the tree's
//! leaves test it, the same arithmetic on the same numbers) exactly when the walk finds it stopped.

use super::TrianglePacket;
use super::ray::RayLanes;
use crate::math::{Vec3x8, lanes_in};
use glam::Vec3;
use wide::i32x8;

/// Up to eight triangles and, for each, the emitter slots whose shadow rays it may stop.
#[derive(Clone, Debug)]
pub struct ShadowBlockers {
    packet: TrianglePacket,
    /// Bit s of lane k set where triangle k may stop slot s's shadow rays.
    stops: [u32; 8],
    /// The slots all of whose possible blockers are here (bit s for slot s, s < 31).
    lights: u32,
}

impl ShadowBlockers {
    /// The `n` triangles `triangle(i)` = (vertices, id, the slots whose rays it may stop), i < n ≤ 8, all the
    /// possible blockers of the slots of `lights`. Built from the vertices the tree was built from, the packet
    /// holds the tree's numbers (both through `TrianglePacket::from_fn`), so its hits are the tree's.
    pub fn new(n: usize, triangle: impl Fn(usize) -> ([Vec3; 3], u32, u32), lights: u32) -> Self {
        assert!(lights < 1 << 31, "slots below 31");
        let packet = TrianglePacket::from_fn(n, |i| {
            let (v, id, _) = triangle(i);
            (v, id)
        });
        Self { packet, stops: std::array::from_fn(|k| if k < n { triangle(k).2 } else { 0 }), lights }
    }

    /// The slots all of whose possible blockers are here.
    pub fn lights(&self) -> u32 {
        self.lights
    }

    /// The lanes whose slot (`slots`, lane l's for ray l) is one of [`ShadowBlockers::lights`].
    #[inline(always)]
    pub fn listed(&self, slots: i32x8) -> u32 {
        lanes_in(self.lights, slots)
    }

    /// Of the rays `origins + t·dirs` in `active` (bit l for lane l), all listed ([`ShadowBlockers::listed`]),
    /// those stopped at 0 < t < t_max by a triangle that may stop their slot's rays: for each, what
    /// [`super::Accel::occluded`] finds, bit for bit.
    #[inline]
    pub fn occluded_lanes(&self, origins: &Vec3x8, dirs: &Vec3x8, t_max: f32, active: u32, slots: i32x8) -> u32 {
        if active == 0 {
            return 0;
        }
        let rays = RayLanes::new(origins, dirs);
        let mut occluded = 0;
        for k in 0..8 {
            let lanes = active & lanes_in(self.stops[k], slots) & !occluded;
            if lanes != 0 {
                occluded |= self.packet.rays_hitting(k, &rays, t_max) & lanes;
            }
        }
        occluded
    }
}
