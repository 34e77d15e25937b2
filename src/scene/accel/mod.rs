//! Ray queries for the integrator: the closest hit for camera rays (and, in the emitters' own tree, for traced
//! directions: `scene::EmitterTree`), any hit with early exit for shadow rays. obvhs builds a binary BVH, which is
//! collapsed into an 8-wide one whose nodes test eight child boxes and whose leaves test eight triangles against
//! one ray at once (f32x8): one ray, wide nodes, as in Embree's BVH8 (Wald et al. 2014). A single ray needs no
//! coherence with others, so every strategy's rays run as fast;
//! camera rays also have their pixel's cone of candidate triangles (`frustum`), an exact cull, and where a pixel
//! sees too many triangles for one, its camera rays walk the tree as one packet.

mod apex_packet;
#[cfg(all(target_arch = "x86_64", target_feature = "fma"))]
mod avx512;
mod blockers;
mod build;
mod cache;
mod frustum;
mod node;
mod packet;
mod ray;
mod shadow_bundle;
mod shaft;
mod traverse;
mod vectors;

pub use blockers::ShadowBlockers;
pub use cache::TreeCache;
pub use frustum::{ConeCandidates, ConeTriangles, MAX_CONE};
use glam::Vec3;
use node::{Child, ChildGroups, Node8};
use packet::TrianglePacket;
pub use shaft::Shaft;
pub use vectors::{VectorPath, has_avx512, vector_path};
use wide::f32x8;

/// The renderer's intersection test of one ray with one triangle: the distance of a hit at `0 < t`, if any.
#[cfg(test)]
pub(crate) fn test_ray_triangle(triangle: [Vec3; 3], origin: Vec3, dir: Vec3) -> Option<f32> {
    TrianglePacket::new(&[(triangle, 0)]).closest(&ray::WideRay::new(origin, dir), f32::INFINITY).map(|h| h.t)
}

/// Acceleration structure over the scene's triangles, stored in the BVH's leaf order so that a hit's triangle
/// index is the position in that order.
#[derive(Clone)]
pub struct Accel {
    nodes: Vec<Node8>,
    /// The groups of each node's children (see [`Accel::build`]).
    groups: Vec<ChildGroups>,
    packets: Vec<TrianglePacket>,
    /// `None` for a scene without triangles.
    root: Option<Child>,
    /// The wide levels on the tree's longest path (0 for a leaf or no tree).
    depth: usize,
    /// Read from a [`TreeCache`] rather than built.
    from_cache: bool,
}

/// The group a shadow ray skips when it skips none (see [`Accel::build`]).
pub const SKIP_NONE: u32 = u32::MAX;

/// A closest hit: the triangle (in stored order), the distance (in lengths of the ray's direction), and the barycentric
/// coordinates of the hit point, `x = v₀ + u (v₁ − v₀) + v (v₂ − v₀)`.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub triangle: u32,
    pub t: f32,
    pub u: f32,
    pub v: f32,
}

/// The closest hits of eight rays, one per lane, as vectors: what eight-lane code reads of them without
/// scattering and gathering per-lane [`Hit`]s.
#[derive(Clone, Copy, Debug)]
pub struct HitLanes {
    /// Bit i set where ray i hit something.
    pub mask: u32,
    /// The triangle each ray hit ([`u32::MAX`] where none).
    pub triangle: [u32; 8],
    /// The [`Hit`] fields, lane by lane; meaningless in lanes outside `mask`.
    pub t: f32x8,
    pub u: f32x8,
    pub v: f32x8,
}

impl HitLanes {
    /// Lane i holds `hits[i]`.
    pub fn from_hits(hits: &[Option<Hit>; 8]) -> Self {
        let field = |f: fn(&Hit) -> f32| f32x8::new(hits.map(|h| h.as_ref().map_or(0.0, f)));
        Self {
            mask: hits.iter().enumerate().fold(0, |m, (l, h)| m | (h.is_some() as u32) << l),
            triangle: hits.map(|h| h.map_or(u32::MAX, |h| h.triangle)),
            t: field(|h| h.t),
            u: field(|h| h.u),
            v: field(|h| h.v),
        }
    }

    /// Lane i's hit.
    #[inline(always)]
    pub fn lane(&self, i: usize) -> Option<Hit> {
        (self.mask & (1 << i) != 0).then(|| Hit {
            triangle: self.triangle[i],
            t: self.t.as_array_ref()[i],
            u: self.u.as_array_ref()[i],
            v: self.v.as_array_ref()[i],
        })
    }
}

impl Accel {
    /// Builds the BVH; returns it with the permutation `order[i]` = input index of the i-th stored triangle.
    /// `groups[i]` is the group of input triangle i (below 2³¹), if any: an any-hit query may skip one group,
    /// and does not enter the subtrees that hold only its triangles (the build does not mix groups on purpose:
    /// it keeps them apart where they lie apart, e.g. one light's triangles from the rest).
    pub fn build(positions: &[[Vec3; 3]], groups: &[Option<u32>]) -> (Self, Vec<u32>) {
        assert_eq!(positions.len(), groups.len(), "one group (or none) per triangle");
        if positions.is_empty() {
            let (nodes, groups, packets) = (Vec::new(), Vec::new(), Vec::new());
            let empty = Self { nodes, groups, packets, root: None, depth: 0, from_cache: false };
            return (empty, Vec::new());
        }
        let built = build::build(positions, groups);
        let (nodes, groups, packets, root, depth) =
            (built.nodes, built.groups, built.packets, Some(built.root), built.depth);
        (Self { nodes, groups, packets, root, depth, from_cache: false }, built.order)
    }

    /// The groups (see [`Accel::build`]) that some subtree holds apart: the only ones worth skipping.
    pub fn groups_held_apart(&self) -> Vec<u32> {
        let mut groups: Vec<u32> = self.groups.iter().flat_map(ChildGroups::groups).collect();
        groups.sort_unstable();
        groups.dedup();
        groups
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{SampleRng, Vec3x8};

    /// Whether a ray hits a triangle, decided in f64 with a margin: away from edges (and from t = 0 and t_max),
    /// and for rays that are not grazing, float rounding cannot change the answer, so the BVH must agree; within
    /// the margin either answer is right.
    #[derive(Clone, Copy, Debug, PartialEq)]
    enum Verdict {
        Hit(f64),
        Miss,
        Borderline,
    }

    fn verdict([a, b, c]: [Vec3; 3], o: Vec3, d: Vec3, t_max: f32) -> Verdict {
        const MARGIN: f64 = 1e-4;
        let (a, o, d) = (a.as_dvec3(), o.as_dvec3(), d.as_dvec3());
        let (e1, e2) = (b.as_dvec3() - a, c.as_dvec3() - a);
        let p = d.cross(e2);
        let det = e1.dot(p);
        let scale = e1.length() * e2.length() * d.length();
        if det.abs() <= 1e-3 * scale {
            return Verdict::Borderline; // grazing, or a needle: t is ill-conditioned
        }
        let tv = o - a;
        let q = tv.cross(e1);
        let (u, v, t) = (tv.dot(p) / det, d.dot(q) / det, e2.dot(q) / det);
        let t_max = t_max as f64;
        let inside = u.min(v).min(1.0 - u - v);
        let t_margin = MARGIN * t.abs().max(1.0);
        if inside < -MARGIN || t < -t_margin || t > t_max + t_margin * t_max.min(1e30) {
            Verdict::Miss
        } else if inside > MARGIN && t > t_margin && t < t_max - t_margin {
            Verdict::Hit(t)
        } else {
            Verdict::Borderline
        }
    }

    pub(super) fn random_soup(n: usize, size: f32, seed: u64) -> Vec<[Vec3; 3]> {
        let mut rng = SampleRng::new(seed, 0, 0);
        let mut point = |scale: f32| Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * scale;
        (0..n)
            .map(|_| {
                let centre = point(10.0);
                [centre + point(size), centre + point(size), centre + point(size)]
            })
            .collect()
    }

    /// Groups that the BVH can hold apart: triangles with centroid x > 2 in group 0, x < −2 in group 1.
    fn groups_by_side(tris: &[[Vec3; 3]]) -> Vec<Option<u32>> {
        let group = |[a, b, c]: &[Vec3; 3]| match (a.x + b.x + c.x) / 3.0 {
            x if x > 2.0 => Some(0),
            x if x < -2.0 => Some(1),
            _ => None,
        };
        tris.iter().map(group).collect()
    }

    /// Random soups of 1 to 3 000 triangles (seeds from `seed`), then 300 coincident triangles.
    fn soups_and_coincident_triangles(seed: u64) -> Vec<Vec<[Vec3; 3]>> {
        let mut soups: Vec<Vec<[Vec3; 3]>> =
            [(1, 4.0), (9, 3.0), (100, 2.0), (3000, 0.8)].map(|(n, size)| random_soup(n, size, seed + n as u64)).into();
        soups.push(vec![[Vec3::new(-5.0, -5.0, 0.0), Vec3::new(5.0, -5.0, 0.0), Vec3::new(0.0, 5.0, 0.0)]; 300]);
        soups
    }

    /// Closest hits and any hits against every triangle tested alone; any hits skipping group 0 against every
    /// triangle outside it (a clear hit on one of them is found; with no triangle hit at all, none is).
    fn check_against_brute_force(tris: &[[Vec3; 3]], rays: u64) {
        let groups = groups_by_side(tris);
        let (accel, order) = Accel::build(tris, &groups);
        let stored_groups: Vec<_> = order.iter().map(|&i| groups[i as usize]).collect();
        let mut skipped = 0;
        let stored: Vec<[Vec3; 3]> = order.iter().map(|&i| tris[i as usize]).collect();
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..tris.len() as u32).collect::<Vec<_>>(), "every triangle stored once");
        let mut hits = 0;
        for r in 0..rays {
            let mut rng = SampleRng::new(99, r, 0);
            let o = Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * 16.0;
            // Half the rays aim at a triangle's centroid (most of them hit something), half go anywhere.
            let [a, b, c] = tris[(rng.uniform() * tris.len() as f32) as usize % tris.len()];
            let aim = if r % 2 == 0 {
                (a + b + c) / 3.0 - o
            } else {
                Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5)
            };
            let d = aim.normalize_or(Vec3::X);
            let t_max = if r % 3 == 0 { f32::INFINITY } else { rng.uniform() * 24.0 };
            let verdicts: Vec<Verdict> = stored.iter().map(|&tri| verdict(tri, o, d, t_max)).collect();
            let nearest_clear =
                verdicts.iter().filter_map(|v| if let Verdict::Hit(t) = v { Some(*t) } else { None }).reduce(f64::min);
            match accel.closest_hit(o, d, t_max) {
                Some(h) => {
                    hits += 1;
                    assert!(
                        verdicts[h.triangle as usize] != Verdict::Miss,
                        "ray {r}: the BVH hit a triangle the ray misses"
                    );
                    // No clear hit on another triangle is nearer (a skipped node would show here).
                    for (k, v) in verdicts.iter().enumerate() {
                        if let (Verdict::Hit(t), true) = (v, k != h.triangle as usize) {
                            assert!(
                                h.t as f64 <= t + 1e-4 * (1.0 + t),
                                "ray {r}: triangle {k} at {t}, nearer than the BVH's {}",
                                h.t
                            );
                        }
                    }
                    let [a, b, c] = stored[h.triangle as usize];
                    let x = a + (b - a) * h.u + (c - a) * h.v;
                    assert!((x - (o + d * h.t)).length() < 1e-3 * (1.0 + h.t), "ray {r}: barycentrics");
                }
                None => assert!(nearest_clear.is_none(), "ray {r}: the BVH missed a hit at {nearest_clear:?}"),
            }
            let occluded = accel.occluded(o, d, t_max, None);
            let skipping = accel.occluded(o, d, t_max, Some(0));
            if nearest_clear.is_some() {
                assert!(occluded, "ray {r}: any-hit missed a hit");
            } else if verdicts.iter().all(|v| *v == Verdict::Miss) {
                assert!(!occluded && !skipping, "ray {r}: any-hit found a hit where there is none");
            }
            let outside = |(k, v): (usize, &Verdict)| stored_groups[k] != Some(0) && matches!(v, Verdict::Hit(_));
            if verdicts.iter().enumerate().any(outside) {
                assert!(skipping, "ray {r}: any-hit skipping group 0 missed a hit outside it");
            }
            skipped += (occluded && !skipping) as u32;
        }
        if tris.len() >= 100 {
            assert!(skipped > 0, "no ray was spared group 0's triangles: the skip is not tested");
        }
        assert!(hits > rays / 8, "the test rays mostly miss ({hits} hits): it checks too little");
    }

    #[test]
    fn agrees_with_brute_force_on_soups_of_every_size() {
        for (n, size) in [(1, 4.0), (7, 3.0), (8, 3.0), (9, 3.0), (100, 2.0), (3000, 0.8)] {
            check_against_brute_force(&random_soup(n, size, n as u64), 4000);
        }
        // A tree deeper than the shared walk pays in, whose any-hit walks push a node's children in one step.
        let deep = random_soup(40_000, 0.25, 40_000);
        assert!(Accel::build(&deep, &groups_by_side(&deep)).0.walks_alone());
        check_against_brute_force(&deep, 300);
    }

    /// Eight rays walking the BVH together, one per lane, answer as each does alone, bit for bit: bundles from
    /// nearby origins towards one region (as a pixel's shadow rays) and bundles of unrelated rays, with some
    /// lanes inactive and each lane skipping a group or none, on soups of every size (where fewer than five rays
    /// enter a subtree, they walk it alone, interleaved; in the largest soup's tree, deeper than the shared walk
    /// pays in, each walks alone from the root). Where the CPU has AVX-512, the 16-lane walk answers as the
    /// eight-lane one.
    #[test]
    fn eight_rays_together_answer_as_each_alone() {
        let mut occluded = 0;
        for (n, size) in [(1, 4.0), (9, 3.0), (100, 2.0), (3000, 0.8), (40_000, 0.25)] {
            let tris = random_soup(n, size, 40 + n as u64);
            let (accel, _) = Accel::build(&tris, &groups_by_side(&tris));
            let alone_from_the_root = accel.walks_alone();
            assert_eq!(alone_from_the_root, n == 40_000, "soup {n}: a tree of {} levels", accel.depth);
            for group in 0..1500u64 {
                let mut rng = SampleRng::new(17, group, n as u64);
                let mut point =
                    |scale: f32| Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * scale;
                let (centre, target) = (point(16.0), point(16.0));
                let coherent = group % 2 == 0;
                let origins: [Vec3; 8] =
                    std::array::from_fn(|_| if coherent { centre + point(0.5) } else { point(16.0) });
                let ends: [Vec3; 8] = std::array::from_fn(|_| if coherent { target + point(2.0) } else { point(16.0) });
                let dirs: [Vec3; 8] = std::array::from_fn(|l| ends[l] - origins[l]);
                let active = (group as u32).wrapping_mul(0x9e37_79b9) >> 24 | 1;
                let t_max = [1.0 - 1e-6, 0.5, f32::INFINITY][group as usize % 3];
                let skips = std::array::from_fn(|l| [SKIP_NONE, 0, 1][(group as usize + l) % 3]);
                let (origins_x8, dirs_x8) = (Vec3x8::from_lanes(&origins), Vec3x8::from_lanes(&dirs));
                let bits = accel.occluded_lanes_on(VectorPath::Avx2, &origins_x8, &dirs_x8, t_max, active, skips);
                if has_avx512() {
                    let wide = accel.occluded_lanes_on(VectorPath::Avx512, &origins_x8, &dirs_x8, t_max, active, skips);
                    assert_eq!(wide, bits, "soup {n}, group {group}: 16 lanes answer otherwise than 8");
                }
                for l in 0..8 {
                    let alone = active & (1 << l) != 0
                        && accel.occluded(origins[l], dirs[l], t_max, Some(skips[l]).filter(|&s| s != SKIP_NONE));
                    assert_eq!(bits & (1 << l) != 0, alone, "soup {n}, group {group}, lane {l}");
                    occluded += alone as u32;
                }
            }
        }
        assert!(occluded > 2000, "only {occluded} rays occluded: the test checks too little");
    }

    /// Eight closest-hit walks interleaved (`Accel::closest_hits`) find what each finds alone, bit for bit, with
    /// some lanes inactive: coherent and unrelated bundles, on soups of every size and on coincident triangles
    /// (ties broken as alone).
    #[test]
    fn eight_closest_hit_walks_interleaved_answer_as_each_alone() {
        let mut hit = 0;
        for (k, tris) in soups_and_coincident_triangles(70).iter().enumerate() {
            let (accel, _) = Accel::build(tris, &vec![None; tris.len()]);
            for group in 0..1000u64 {
                let mut rng = SampleRng::new(23, group, k as u64);
                let mut point =
                    |scale: f32| Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * scale;
                let (centre, target) = (point(16.0), point(4.0));
                let coherent = group % 2 == 0;
                let rays: [(Vec3, Vec3); 8] = std::array::from_fn(|_| {
                    let o = if coherent { centre + point(0.5) } else { point(16.0) };
                    (o, if coherent { target + point(2.0) - o } else { point(16.0) - o })
                });
                let active = (group as u32).wrapping_mul(0x9e37_79b9) >> 24 | 1;
                let t_max = [f32::INFINITY, 0.5][group as usize % 2];
                let together = accel.closest_hits(&rays, active, t_max);
                for l in 0..8 {
                    let alone =
                        (active & (1 << l) != 0).then(|| accel.closest_hit(rays[l].0, rays[l].1, t_max)).flatten();
                    let key = |h: Option<Hit>| h.map(|h| (h.triangle, h.t.to_bits(), h.u.to_bits(), h.v.to_bits()));
                    assert_eq!(key(together[l]), key(alone), "soup {k}, group {group}, lane {l}");
                    hit += alone.is_some() as u32;
                }
            }
        }
        assert!(hit > 4000, "only {hit} rays hit: the test checks too little");
    }

    /// Eight rays from one origin walking as a packet (`Accel::closest_hits_from`) find each the nearest distance
    /// its lone walk finds, bit for bit, and the same triangle and barycentrics unless two triangles tie there
    /// (coincident triangles): bundles as narrow as a pixel's camera rays and bundles in all directions, with some
    /// lanes inactive, on soups of every size.
    #[test]
    fn eight_rays_from_one_origin_as_a_packet_find_what_each_finds_alone() {
        let (mut hit, mut ties) = (0, 0);
        for (k, tris) in soups_and_coincident_triangles(90).iter().enumerate() {
            let (accel, _) = Accel::build(tris, &vec![None; tris.len()]);
            for group in 0..1000u64 {
                let mut rng = SampleRng::new(29, group, k as u64);
                let mut point =
                    |scale: f32| Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * scale;
                let (origin, target) = (point(16.0), point(4.0));
                let spread = [0.01, 1.0, 16.0][group as usize % 3];
                let dirs: [Vec3; 8] = std::array::from_fn(|_| target + point(spread) - origin);
                let active = (group as u32).wrapping_mul(0x9e37_79b9) >> 24 | 1;
                let t_max = [f32::INFINITY, 0.5][group as usize % 2];
                let packet = accel.closest_hits_from(origin, &Vec3x8::from_lanes(&dirs), active, t_max);
                for (l, &dir) in dirs.iter().enumerate() {
                    let alone = (active & (1 << l) != 0).then(|| accel.closest_hit(origin, dir, t_max)).flatten();
                    match (packet.lane(l), alone) {
                        (None, None) => {}
                        (Some(a), Some(b)) if a.triangle == b.triangle => {
                            let key = |h: Hit| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits());
                            assert_eq!(key(a), key(b), "soup {k}, group {group}, lane {l}");
                        }
                        (Some(a), Some(b)) => {
                            assert_eq!(a.t.to_bits(), b.t.to_bits(), "soup {k}, group {group}, lane {l}: a tie");
                            ties += 1;
                        }
                        (a, b) => panic!("soup {k}, group {group}, lane {l}: packet {a:?}, alone {b:?}"),
                    }
                    hit += alone.is_some() as u32;
                }
            }
        }
        assert!(hit > 4000, "only {hit} rays hit: the test checks too little");
        eprintln!("{ties} ties kept otherwise than alone");
    }

    #[test]
    fn agrees_on_coincident_and_needle_triangles() {
        // Thousands of identical triangles (a deep, degenerate tree: the depth limit makes one large leaf) and
        // needles with one near-zero edge.
        let mut tris = vec![[Vec3::new(-5.0, -5.0, 0.0), Vec3::new(5.0, -5.0, 0.0), Vec3::new(0.0, 5.0, 0.0)]; 2000];
        tris.extend(random_soup(200, 2.0, 5).into_iter().map(|[a, b, c]| [a, b, (a + b) * 0.5 + (c - a) * 1e-3]));
        check_against_brute_force(&tris, 2000);
    }

    #[test]
    fn an_empty_scene_is_never_hit() {
        let (accel, order) = Accel::build(&[], &[]);
        assert!(order.is_empty());
        assert!(accel.closest_hit(Vec3::ZERO, Vec3::X, f32::INFINITY).is_none());
        assert!(!accel.occluded(Vec3::ZERO, Vec3::X, f32::INFINITY, None));
    }
}
