//! The triangles a bundle of rays can hit: every ray from one apex through a convex quad of directions (a
//! pixel's footprint, slightly enlarged) lies in the cone the four planes through the apex and consecutive corner
//! directions bound. A triangle with all three vertices on the negative side of one plane lies outside it and
//! is hit by none of those rays, so the closest hit among the remaining triangles is the closest hit in the
//! scene. When at most eight remain they form one packet: each ray of the bundle then costs one packet test
//! instead of a traversal.

use super::node::Child;
use super::packet::TrianglePacket;
use super::ray::WideRay;
use super::traverse::STACK;
use super::{Accel, Hit, HitLanes};
use crate::math::Vec3x8;
use arrayvec::ArrayVec;
use glam::Vec3;
use wide::f32x8;

/// The triangles a cone of rays from one apex can hit, in one packet.
pub struct ConeCandidates {
    apex: Vec3,
    packet: TrianglePacket,
}

/// The ids of the triangles a cone can hit: 4 bytes a triangle, small enough to keep for every pixel of an
/// image.
pub type ConeTriangles = ArrayVec<u32, 8>;

impl Accel {
    /// The triangles that rays from `apex` through the quad of directions `corners` (in order around it) can
    /// hit; `None` when there are more than eight of them (trace such rays with [`Accel::closest_hit`]).
    pub fn cone_triangles(&self, apex: Vec3, corners: [Vec3; 4]) -> Option<ConeTriangles> {
        let centre = corners.iter().sum::<Vec3>();
        let normals = [0, 1, 2, 3].map(|i| {
            let n = corners[i].cross(corners[(i + 1) % 4]);
            if n.dot(centre) < 0.0 { -n } else { n }
        });
        let mut found = ConeTriangles::new();
        let mut stack = ArrayVec::<Child, STACK>::new();
        stack.push(self.root?);
        while let Some(child) = stack.pop() {
            if child.is_leaf() {
                for packet in &self.packets[child.first as usize..(child.first + child.packets) as usize] {
                    for lane in 0..8 {
                        let Some(v) = packet.vertices(lane) else { continue };
                        let outside = normals.iter().any(|n| v.iter().all(|&p| n.dot(p - apex) < 0.0));
                        if !outside && found.try_push(packet.ids[lane]).is_err() {
                            return None;
                        }
                    }
                }
            } else {
                let node = &self.nodes[child.first as usize];
                let mut mask = node.inside_planes(apex, &normals);
                while mask != 0 {
                    stack.push(node.children[mask.trailing_zeros() as usize]);
                    mask &= mask - 1;
                }
            }
        }
        Some(found)
    }
}

impl ConeCandidates {
    /// The cone from `apex` whose `n` triangles (at most eight: the ones [`Accel::cone_triangles`] found) are
    /// `triangle(i)` = (vertices, id), i < n. With the vertices the tree was built from, its packet holds the
    /// same numbers as the tree's (both are built by `TrianglePacket::from_fn`), so its hits are the tree's.
    #[inline]
    pub fn new(apex: Vec3, n: usize, triangle: impl Fn(usize) -> ([Vec3; 3], u32)) -> Self {
        Self { apex, packet: TrianglePacket::from_fn(n, triangle) }
    }

    /// The closest hit along `apex + t·dir`, 0 < t < t_max, for a direction inside the cone: the same hit
    /// [`Accel::closest_hit`] finds.
    #[inline]
    pub fn closest_hit(&self, dir: Vec3, t_max: f32) -> Option<Hit> {
        let h = self.packet.closest(&WideRay::new(self.apex, dir), t_max)?;
        Some(Hit { triangle: self.packet.ids[h.lane], t: h.t, u: h.u, v: h.v })
    }

    /// [`ConeCandidates::closest_hit`] for eight directions at once (one per lane; those in `active`, all bits
    /// set): lane i gets direction i's hit, bit for bit.
    #[inline]
    pub fn closest_hits(&self, dirs: &Vec3x8, active: f32x8, t_max: f32) -> HitLanes {
        self.packet.closest_of_rays(self.apex, dirs, active, t_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{ONE_MINUS_EPSILON, SampleRng};
    use crate::scene::every_bundled_scene;
    use glam::Vec2;

    /// Every camera ray of a pixel, its corners included, finds through the pixel's cone the hit the full
    /// traversal finds, at the same distance bit for bit; eight rays at once find what each finds alone.
    #[test]
    fn cones_find_the_closest_hit_of_every_camera_ray() {
        for (name, scene, camera) in every_bundled_scene(96, 72) {
            let basis = camera.basis();
            let mut cones = 0;
            for y in 0..camera.height {
                for x in 0..camera.width {
                    let Some(cone) = scene.cone_candidates(basis.eye(), basis.pixel_corners(x, y)) else {
                        continue;
                    };
                    cones += 1;
                    let mut rng = SampleRng::new(5, (y * camera.width + x) as u64, 0);
                    let corners = [
                        (0.0, 0.0),
                        (ONE_MINUS_EPSILON, 0.0),
                        (0.0, ONE_MINUS_EPSILON),
                        (ONE_MINUS_EPSILON, ONE_MINUS_EPSILON),
                    ];
                    let random: [Vec2; 8] = std::array::from_fn(|_| rng.uniform_2d());
                    // Eight directions at once, and their hits through the cone, lane by lane as alone.
                    let dirs = basis.directions(x, y, f32x8::new(random.map(|j| j.x)), f32x8::new(random.map(|j| j.y)));
                    let lanes = cone.closest_hits(&dirs, f32x8::splat(f32::from_bits(u32::MAX)), f32::INFINITY);
                    for (l, jitter) in random.iter().enumerate() {
                        let dir = basis.direction(x, y, *jitter);
                        assert_eq!(dirs.lane(l).to_array().map(f32::to_bits), dir.to_array().map(f32::to_bits));
                        let alone = cone.closest_hit(dir, f32::INFINITY);
                        let key = |h: Option<Hit>| h.map(|h| (h.triangle, h.t.to_bits(), h.u.to_bits(), h.v.to_bits()));
                        assert_eq!(key(lanes.lane(l)), key(alone), "{name} pixel ({x}, {y}), lane {l}");
                    }
                    let jitters = corners.into_iter().map(Vec2::from).chain(random);
                    for jitter in jitters.collect::<Vec<_>>() {
                        let dir = basis.direction(x, y, jitter);
                        let full = scene.accel().closest_hit(basis.eye(), dir, f32::INFINITY);
                        let culled = cone.closest_hit(dir, f32::INFINITY);
                        match (full, culled) {
                            (None, None) => {}
                            // Equal distances; the triangle may differ only where two share the edge hit.
                            (Some(a), Some(b)) => {
                                assert!(a.t == b.t, "{name} pixel ({x}, {y}): {a:?} vs {b:?}")
                            }
                            (a, b) => panic!("{name} pixel ({x}, {y}) jitter {jitter}: traversal {a:?}, cone {b:?}"),
                        }
                    }
                }
            }
            let pixels = camera.width * camera.height;
            assert!(cones * 10 > pixels * 8, "{name}: only {cones} of {pixels} pixels have a cone of ≤ 8 triangles");
        }
    }
}
