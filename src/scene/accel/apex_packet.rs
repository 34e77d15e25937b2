//! Eight triangles as rays from one apex meet them: a pixel's cone, whose camera rays all start at the eye. Of
//! Möller–Trumbore's terms, `T = o − v₀`, `Q = T × e₁` and `e₂·Q` depend on the triangle and the origin alone
//! ([`OriginTerms`]); they are worked out once per cone, with the operations the test itself runs, so each ray's
//! test gives the numbers [`TrianglePacket`]'s gives, bit for bit, and costs the direction's terms only (`P`, det,
//! `T·P`, `d·Q`). With the broadcasts of `packet::lane_splat`, the Cornell box's `emitter` render took 315.5 M
//! instructions instead of 334.3 M, the knot's 811.2 M instead of 835.4 M (callgrind, 128², 64 spp, one thread).

use super::packet::{LaneHit, NearestLanes, OriginTerms, TrianglePacket, lane_splat, moller_trumbore_from};
use glam::Vec3;
use wide::f32x8;

#[derive(Clone, Debug)]
pub(super) struct ApexPacket {
    e1: [f32x8; 3],
    e2: [f32x8; 3],
    origin: OriginTerms,
    /// The triangle in each lane; `u32::MAX` in an unused lane, which no ray hits (e₁ = e₂ = 0).
    pub ids: [u32; 8],
}

impl ApexPacket {
    /// `packet`'s triangles, seen from `apex`.
    #[inline]
    pub fn new(packet: &TrianglePacket, apex: Vec3) -> Self {
        let (v0, e1, e2) = packet.edges();
        let origin = OriginTerms::new(v0, e1, e2, &apex.to_array().map(f32x8::splat));
        Self { e1: *e1, e2: *e2, origin, ids: packet.ids }
    }

    /// The nearest hit at `0 < t < t_max` along `apex + t·dir`: [`TrianglePacket::closest`]'s for that ray.
    #[inline(always)]
    pub fn closest(&self, dir: Vec3, t_max: f32) -> Option<LaneHit> {
        let d = dir.to_array().map(f32x8::splat);
        let (hit, tuvd) = moller_trumbore_from(&self.origin, &self.e1, &self.e2, &d, f32x8::splat(t_max));
        LaneHit::nearest(hit.move_mask() as u32, tuvd, t_max)
    }

    /// [`TrianglePacket::nearer_of_rays`] for eight rays from the apex along `d` (one per lane; those in
    /// `active`, all bits set), bit for bit.
    #[inline(always)]
    pub fn nearer_of_rays(&self, d: &[f32x8; 3], active: f32x8, nearest: &mut NearestLanes) {
        let limit = nearest.t;
        for k in (0..8).filter(|&k| self.ids[k] != u32::MAX) {
            let (e1, e2) = (lane_splat(&self.e1, k), lane_splat(&self.e2, k));
            let (hit, tuvd) = moller_trumbore_from(&self.origin.splat(k), &e1, &e2, d, limit);
            nearest.keep_nearer(hit & active, tuvd, self.ids[k]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{SampleRng, Vec3x8};
    use crate::scene::accel::ray::WideRay;
    use wide::CmpLt;

    /// From an apex, one ray and eight rays at once find through the apex packet what they find through the
    /// triangle packet, bit for bit: hits, misses, edges and grazing rays among random triangles around the apex.
    #[test]
    fn apex_packets_find_what_triangle_packets_find() {
        let mut rng = SampleRng::new(11, 0, 0);
        let mut point = |scale: f32| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 * scale - scale;
        let (mut hits, mut compared) = (0, 0);
        for round in 0..400 {
            let apex = point(1.0);
            let n = round % 8 + 1;
            let triangles: Vec<([Vec3; 3], u32)> = (0..n)
                .map(|i| {
                    let centre = apex + Vec3::new(0.0, 0.0, 2.0) + point(1.5);
                    ([centre + point(0.8), centre + point(0.8), centre + point(0.8)], 100 + i as u32)
                })
                .collect();
            let packet = TrianglePacket::new(&triangles);
            let apex_packet = ApexPacket::new(&packet, apex);
            let dirs: [Vec3; 8] = std::array::from_fn(|l| {
                // Towards a triangle's corner or edge (grazing), or anywhere ahead.
                let ([a, b, _], _) = triangles[(round + l) % n];
                match l % 3 {
                    0 => a - apex,
                    1 => (a + b) * 0.5 - apex,
                    _ => Vec3::new(0.0, 0.0, 2.0) + point(1.5),
                }
            });
            let limit = if round % 5 == 0 { 2.0 } else { f32::INFINITY };
            for &dir in &dirs {
                let alone = packet.closest(&WideRay::new(apex, dir), limit);
                assert_eq!(apex_packet.closest(dir, limit), alone, "round {round}, direction {dir}");
                hits += alone.is_some() as u32;
                compared += 1;
            }
            let d = Vec3x8::from_lanes(&dirs);
            let (o, d) = (apex.to_array().map(f32x8::splat), [d.x, d.y, d.z]);
            let active = f32x8::new([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]).cmp_lt(f32x8::splat(7.0));
            let (mut through_apex, mut through_packet) = (NearestLanes::new(limit), NearestLanes::new(limit));
            apex_packet.nearer_of_rays(&d, active, &mut through_apex);
            packet.nearer_of_rays(&o, &d, active, &mut through_packet);
            let (a, b) = (through_apex.hits(), through_packet.hits());
            assert_eq!((a.mask, a.triangle), (b.mask, b.triangle), "round {round}");
            let bits = |v: f32x8| v.to_array().map(f32::to_bits);
            assert_eq!([bits(a.t), bits(a.u), bits(a.v)], [bits(b.t), bits(b.u), bits(b.v)], "round {round}");
        }
        assert!(hits > compared / 4 && hits < compared, "{hits} hits of {compared}: the test checks too little");
    }
}
