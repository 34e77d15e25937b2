//! The triangles a bundle of rays can hit: every ray from one apex through a convex quad of directions (a
//! pixel's footprint, slightly enlarged) lies in the cone the four planes through the apex and consecutive corner
//! directions bound. A triangle with all three vertices on the negative side of one plane lies outside it and
//! is hit by none of those rays, so the closest hit among the remaining triangles is the closest hit in the
//! scene. When few remain (at most [`MAX_CONE`]) they are kept in packets of eight, more than eight nearest
//! first: each ray of the bundle then costs a packet test or a few instead of a traversal, and a packet none of
//! whose triangles can be nearer than every ray's hit so far is not tested (nor any after it).

use super::apex_packet::ApexPacket;
use super::node::Child;
use super::packet::{NearestLanes, TrianglePacket};
use super::traverse::STACK;
use super::{Accel, Hit, HitLanes};
use crate::math::Vec3x8;
use arrayvec::ArrayVec;
use glam::Vec3;
use wide::{CmpLe, CmpLt, f32x8};

/// The most triangles a pixel's cone keeps: sixteen packets. On the knot's room at 256², 6 510 of the 65 536
/// pixels' cones hold more than eight triangles, all but 44 of them at most 128 (most 33 to 64: the tube's near
/// and far sides, and what lies behind); their camera rays walked the tree as packets of eight, 31% of the
/// sample loop's time. Through cones of up to 128 the loop took 22% fewer instructions (callgrind, 256², 64 spp)
/// and the whole `emitter` render 3–4% less CPU time (256 spp, two threads; 2026-12-07, AMD EPYC Zen 4).
pub const MAX_CONE: usize = 128;

/// The triangles a cone of rays from one apex can hit in packets of eight (more than eight: nearest first), each
/// with a lower bound of the distance from the apex to its triangles: the first packet in place, any others apart
/// (a cone is made for each pixel, and most hold one packet).
pub struct ConeCandidates {
    first: (ApexPacket, f32),
    rest: Vec<(ApexPacket, f32)>,
}

/// The ids of the triangles a cone can hit: 4 bytes a triangle, small enough to keep for every pixel of an
/// image.
pub type ConeTriangles = ArrayVec<u32, MAX_CONE>;

/// A lower bound of the distance from `p` to the triangle with corners `v`: the distance to its bounding box,
/// less a thousandth, far more than the rounding of this and of a hit's distance (but for a ray within a few
/// hundredths of a degree of a triangle's plane, whose distance Möller–Trumbore's test rounds more): 4 mm at the
/// knot, whose tube is 0.2 m across.
#[inline]
fn distance_below(p: Vec3, v: &[Vec3; 3]) -> f32 {
    let (lo, hi) = (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]));
    (lo - p).max(p - hi).max(Vec3::ZERO).length() * (1.0 - 1e-3)
}

impl Accel {
    /// The triangles that rays from `apex` through the quad of directions `corners` (in order around it) can
    /// hit, more than eight of them ordered by the distance from the apex to their boxes; `None` when there are
    /// more than `most` of them (at most [`MAX_CONE`]: trace such rays with [`Accel::closest_hit`]).
    pub fn cone_triangles(&self, apex: Vec3, corners: [Vec3; 4], most: usize) -> Option<ConeTriangles> {
        let centre = corners.iter().sum::<Vec3>();
        let normals = [0, 1, 2, 3].map(|i| {
            let n = corners[i].cross(corners[(i + 1) % 4]);
            if n.dot(centre) < 0.0 { -n } else { n }
        });
        let mut found = ArrayVec::<(f32, u32), MAX_CONE>::new();
        let mut stack = ArrayVec::<Child, STACK>::new();
        stack.push(self.root?);
        while let Some(child) = stack.pop() {
            if child.is_leaf() {
                for packet in &self.packets[child.first as usize..(child.first + child.packets) as usize] {
                    let mut inside = packet.in_cone(apex, &normals);
                    if found.len() + inside.count_ones() as usize > most.min(MAX_CONE) {
                        return None;
                    }
                    while inside != 0 {
                        let lane = inside.trailing_zeros() as usize;
                        inside &= inside - 1;
                        let v = packet.vertices(lane).expect("a used lane");
                        found.push((distance_below(apex, &v), packet.ids[lane]));
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
        // One packet's triangles are all tested: their order matters only from the second packet on.
        if found.len() > 8 {
            found.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        }
        Some(found.into_iter().map(|(_, id)| id).collect())
    }
}

impl ConeCandidates {
    /// The cone from `apex` whose `n` triangles (at most [`MAX_CONE`]: the ones [`Accel::cone_triangles`] found,
    /// in its order) are `triangle(i)` = (vertices, id), i < n. With the vertices the tree was built from, its
    /// packets hold the same numbers as the tree's (both are built by `TrianglePacket::from_fn`), so its hits
    /// are the tree's.
    #[inline]
    pub fn new(apex: Vec3, n: usize, triangle: impl Fn(usize) -> ([Vec3; 3], u32)) -> Self {
        let packet = |j: usize| {
            let len = (n - 8 * j).min(8);
            let near = (0..len).map(|i| distance_below(apex, &triangle(8 * j + i).0)).fold(f32::INFINITY, f32::min);
            (ApexPacket::new(&TrianglePacket::from_fn(len, |i| triangle(8 * j + i)), apex), near)
        };
        // The first packet is always tested (no ray has a hit before it): its bound, 0, is never reached, and is
        // not worked out (most cones, made for every pixel on every pass, hold only this packet).
        let first = (ApexPacket::new(&TrianglePacket::from_fn(n.min(8), &triangle), apex), 0.0);
        Self { first, rest: (1..n.div_ceil(8)).map(packet).collect() }
    }

    /// The packets, in order, with their distances.
    #[inline(always)]
    fn packets(&self) -> impl Iterator<Item = &(ApexPacket, f32)> {
        std::iter::once(&self.first).chain(&self.rest)
    }

    /// The closest hit along `apex + t·dir`, 0 < t < t_max, for a direction inside the cone: the same hit
    /// [`Accel::closest_hit`] finds.
    #[inline]
    pub fn closest_hit(&self, dir: Vec3, t_max: f32) -> Option<Hit> {
        let (length, mut best, mut limit) = (dir.length(), None, t_max);
        for (packet, near) in self.packets() {
            if limit * length <= *near {
                break; // nothing in this packet or after it is nearer than the hit or the limit
            }
            if let Some(h) = packet.closest(dir, limit) {
                (best, limit) = (Some(Hit { triangle: packet.ids[h.lane], t: h.t, u: h.u, v: h.v }), h.t);
            }
        }
        best
    }

    /// [`ConeCandidates::closest_hit`] for eight directions at once (one per lane; those in `active`, all bits
    /// set): lane i gets direction i's hit, bit for bit.
    #[inline]
    pub fn closest_hits(&self, dirs: &Vec3x8, active: f32x8, t_max: f32) -> HitLanes {
        let mut nearest = NearestLanes::new(t_max);
        let d = [dirs.x, dirs.y, dirs.z];
        let (length, inactive) = (dirs.length(), !active);
        for (packet, near) in self.packets() {
            // Every active ray has a hit no further than anything in this packet can be.
            if ((nearest.t * length).cmp_le(f32x8::splat(*near)) | inactive).all() {
                break;
            }
            packet.nearer_of_rays(&d, active, &mut nearest);
        }
        nearest.hits()
    }
}

impl TrianglePacket {
    /// The lanes whose triangle has no plane among those through `apex` with `normals` that its three corners
    /// all lie on the negative side of: those the cone may hold (unused lanes left out).
    #[inline]
    fn in_cone(&self, apex: Vec3, normals: &[Vec3; 4]) -> u32 {
        let (v0, e1, e2) = self.edges();
        // Each corner less the apex, as `vertices` makes the corners and a test of one corner would.
        let corner = |e: Option<&[f32x8; 3]>| {
            std::array::from_fn::<_, 3, _>(|a| e.map_or(v0[a], |e| v0[a] + e[a]) - f32x8::splat(apex[a]))
        };
        let corners = [corner(None), corner(Some(e1)), corner(Some(e2))];
        let mut outside = f32x8::ZERO; // no lane outside yet (an all-zero mask)
        for n in normals {
            let below = |p: &[f32x8; 3]| {
                (p[0] * f32x8::splat(n.x) + p[1] * f32x8::splat(n.y) + p[2] * f32x8::splat(n.z)).cmp_lt(f32x8::ZERO)
            };
            outside |= below(&corners[0]) & below(&corners[1]) & below(&corners[2]);
        }
        let unused = crate::math::lanes_equal(&self.ids, u32::MAX);
        !(outside.move_mask() as u32) & !unused & 0xff
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

    /// Through a stack of thin plates (9 to 128 triangles in a pixel's cone, in several packets): more than
    /// eight of the cone's triangles come nearest first, and more than `most` give none; every ray, alone or
    /// eight at once, finds through the cone the distance the full traversal finds, also where the far packets
    /// are skipped.
    #[test]
    fn cones_of_several_packets_find_the_closest_hit() {
        // Plates of two triangles each, 0.5 apart along −z, shifted so that pixels see several edges.
        let mut rng = SampleRng::new(9, 0, 0);
        let mut tris = Vec::new();
        for k in 0..24 {
            let (z, dx, dy) = (-2.0 - 0.5 * k as f32, rng.uniform() * 0.1, rng.uniform() * 0.1);
            for (i, j) in [(-1.0f32, -1.0f32), (0.0, -1.0), (-1.0, 0.0), (0.0, 0.0)] {
                let c = Vec3::new(i + dx, j + dy, z);
                tris.push([c, c + Vec3::X, c + Vec3::Y]);
                tris.push([c + Vec3::X, c + Vec3::X + Vec3::Y, c + Vec3::Y]);
            }
        }
        let (accel, order) = Accel::build(&tris, &vec![None; tris.len()]);
        let stored = |t: u32| tris[order[t as usize] as usize];
        let camera = crate::scene::Camera {
            eye: Vec3::new(0.03, 0.02, 0.0),
            target: Vec3::new(0.03, 0.02, -1.0),
            up: Vec3::Y,
            fov_y: 30.0,
            width: 24,
            height: 24,
        };
        let basis = camera.basis();
        let (mut sizes, mut skipped) = (Vec::new(), 0);
        for y in 0..camera.height {
            for x in 0..camera.width {
                let corners = basis.pixel_corners(x, y);
                let Some(ids) = accel.cone_triangles(basis.eye(), corners, MAX_CONE) else { continue };
                sizes.push(ids.len());
                if ids.len() > 8 {
                    assert!(accel.cone_triangles(basis.eye(), corners, ids.len() - 1).is_none());
                }
                let near: Vec<f32> = ids.iter().map(|&t| distance_below(basis.eye(), &stored(t))).collect();
                assert!(ids.len() <= 8 || near.windows(2).all(|w| w[0] <= w[1]), "nearest first");
                let triangle = |i: usize| (stored(ids[i]), ids[i]);
                let cone = ConeCandidates::new(basis.eye(), ids.len(), triangle);
                let random: [Vec2; 8] = std::array::from_fn(|_| rng.uniform_2d());
                let dirs = basis.directions(x, y, f32x8::new(random.map(|j| j.x)), f32x8::new(random.map(|j| j.y)));
                let lanes = cone.closest_hits(&dirs, f32x8::splat(f32::from_bits(u32::MAX)), f32::INFINITY);
                for (l, jitter) in random.iter().enumerate() {
                    let dir = basis.direction(x, y, *jitter);
                    let full = accel.closest_hit(basis.eye(), dir, f32::INFINITY).map(|h| h.t.to_bits());
                    let alone = cone.closest_hit(dir, f32::INFINITY);
                    assert_eq!(alone.map(|h| h.t.to_bits()), full, "pixel ({x}, {y}), lane {l}");
                    let key = |h: Option<Hit>| h.map(|h| (h.triangle, h.t.to_bits(), h.u.to_bits(), h.v.to_bits()));
                    assert_eq!(key(lanes.lane(l)), key(alone), "pixel ({x}, {y}), lane {l}");
                    skipped += alone.is_some_and(|h| h.t * dir.length() <= cone.packets().last().unwrap().1) as u32;
                }
            }
        }
        assert!(sizes.iter().filter(|&&n| n > 16).count() > 100, "cones of three packets or more: {sizes:?}");
        assert!(skipped > 500, "rays whose far packets were skipped: {skipped}");
    }
}
