//! Ray queries through obvhs's compressed wide BVH (CWBVH, Ylitie et al. 2017): closest hit for camera and
//! BRDF rays, any hit with early exit for shadow rays.

use glam::{Vec3, Vec3A};
use obvhs::{
    BvhBuildParams,
    cwbvh::{CwBvh, builder::build_cwbvh_from_tris},
    ray::{Ray, RayHit},
    rt_triangle::RtTriangle,
    triangle::Triangle as ObvhsTriangle,
};
use std::time::Duration;

/// Acceleration structure over the scene's triangles, stored in the BVH's leaf order so that a hit's
/// primitive id indexes them directly.
#[derive(Clone)]
pub struct Accel {
    bvh: Option<CwBvh>,
    tris: Vec<RtTriangle>,
}

/// A closest hit: the triangle (in BVH order) and the distance along the unit direction.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub triangle: u32,
    pub t: f32,
}

impl Accel {
    /// Builds the BVH; returns it with the permutation `order[i]` = input index of the i-th stored triangle.
    pub fn build(positions: &[[Vec3; 3]]) -> (Self, Vec<u32>) {
        if positions.is_empty() {
            return (Self { bvh: None, tris: Vec::new() }, Vec::new());
        }
        let input: Vec<ObvhsTriangle> = positions
            .iter()
            .map(|[a, b, c]| ObvhsTriangle { v0: (*a).into(), v1: (*b).into(), v2: (*c).into() })
            .collect();
        let bvh = build_cwbvh_from_tris(&input, BvhBuildParams::medium_build(), &mut Duration::default());
        let order = bvh.primitive_indices.clone();
        let tris = order.iter().map(|&i| RtTriangle::from(&input[i as usize])).collect();
        (Self { bvh: Some(bvh), tris }, order)
    }

    /// Nearest intersection along `origin + t·dir`, 0 ≤ t < t_max.
    #[inline]
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(dir), 0.0, t_max);
        let mut hit = RayHit::none();
        bvh.ray_traverse(ray, &mut hit, |r, id| self.tris[id].intersect(r))
            .then_some(Hit { triangle: hit.primitive_id, t: hit.t })
    }

    /// True when something lies on `origin + t·dir` for 0 ≤ t < t_max; stops at the first hit found.
    #[inline]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        let Some(bvh) = self.bvh.as_ref() else { return false };
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(dir), 0.0, t_max);
        !bvh.ray_traverse_miss(ray, |r, id| self.tris[id].intersect(r))
    }
}
