//! The emitter triangles' own BVH. A direct-illumination estimator needs, along a traced direction ω, only
//! L_i(ω) = L_e(x, −ω) at the first surface x met: zero unless x is on an emitter. So rather than the nearest of all
//! triangles, it looks for the nearest *emitter* triangle on the ray, in this tree of the emitters alone, and then
//! asks a shadow ray whether anything lies before it (`render::estimator::lit`). The answer is the same but
//! for ties within the rays' offsets; most traced directions miss every light (in a Cornell box, most of the
//! hemisphere), and those are answered here without walking the scene's tree.

use super::{Accel, Hit, Triangle};
use crate::math::Vec3x8;
use glam::Vec3;

/// A BVH over the scene's emitter triangles whose hits name triangles in the scene's order.
#[derive(Clone)]
pub struct EmitterTree {
    accel: Accel,
    /// The scene index of each triangle in the tree's order.
    ids: Vec<u32>,
}

impl EmitterTree {
    /// The tree of the triangles `emitters` (indices into `triangles`).
    pub fn new(triangles: &[Triangle], emitters: &[u32]) -> Self {
        let positions: Vec<[Vec3; 3]> = emitters.iter().map(|&e| triangles[e as usize].v).collect();
        let (accel, order) = Accel::build(&positions, &vec![None; positions.len()]);
        Self { accel, ids: order.iter().map(|&i| emitters[i as usize]).collect() }
    }

    /// The nearest emitter triangle on `origin + t·dir`, 0 < t: its hit, with the triangle's scene index. The
    /// intersection is the scene tree's, bit for bit (the same test of the same vertices).
    #[inline]
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3) -> Option<Hit> {
        self.accel.closest_hit(origin, dir, f32::INFINITY).map(|h| self.in_scene(h))
    }

    /// [`EmitterTree::closest_hit`] for the rays of `active` (bit l for `rays[l]`), walked interleaved
    /// ([`Accel::closest_hits`]): each lane's answer is the ray's alone, bit for bit.
    #[inline]
    pub fn closest_hits(&self, rays: &[(Vec3, Vec3); 8], active: u32) -> [Option<Hit>; 8] {
        self.accel.closest_hits(rays, active, f32::INFINITY).map(|h| h.map(|h| self.in_scene(h)))
    }

    /// [`EmitterTree::closest_hits`] for rays given as lanes: ray l is `origins + t·dirs` in lane l.
    #[inline]
    pub fn closest_hits_lanes(&self, origins: &Vec3x8, dirs: &Vec3x8, active: u32) -> [Option<Hit>; 8] {
        self.accel.closest_hits_lanes(origins, dirs, active, f32::INFINITY).map(|h| h.map(|h| self.in_scene(h)))
    }

    #[inline(always)]
    fn in_scene(&self, hit: Hit) -> Hit {
        Hit { triangle: self.ids[hit.triangle as usize], ..hit }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::SampleRng;
    use crate::scene::every_bundled_scene;

    /// Where the scene's tree finds an emitter triangle nearest, the emitter tree finds that triangle at the same
    /// distance and barycentrics, bit for bit; where it finds none, the nearest emitter triangle is behind another
    /// surface or there is none. Random rays from inside every bundled scene's bounds, half of them aimed at an
    /// emitter triangle's centroid.
    #[test]
    fn finds_what_the_scene_tree_finds_on_emitters() {
        let mut agreed = 0;
        for (name, scene, _) in every_bundled_scene(8, 8) {
            let tree = EmitterTree::new(&scene.triangles, &scene.emitters);
            let (lo, hi) = scene
                .triangles
                .iter()
                .flat_map(|t| t.v)
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
            for r in 0..4000 {
                let mut rng = SampleRng::new(5, r, 0);
                let mut uniform3 = || Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
                let origin = lo + (hi - lo) * uniform3();
                let aim = uniform3() - 0.5;
                let e = scene.emitters.get(r as usize % scene.emitters.len().max(1)).filter(|_| r % 2 == 0);
                let dir = e.map_or(aim, |&e| scene.triangles[e as usize].v.iter().sum::<Vec3>() / 3.0 - origin);
                let dir = dir.normalize_or(Vec3::Y);
                let nearest = scene.accel().closest_hit(origin, dir, f32::INFINITY);
                let emitter = tree.closest_hit(origin, dir);
                let key = |h: Hit| (h.triangle, h.t.to_bits(), h.u.to_bits(), h.v.to_bits());
                match nearest {
                    Some(h) if scene.emitters.contains(&h.triangle) => {
                        assert_eq!(emitter.map(key), Some(key(h)), "{name}, ray {r}");
                        agreed += 1;
                    }
                    Some(h) => assert!(emitter.is_none_or(|e| e.t >= h.t), "{name}, ray {r}: an emitter before"),
                    None => assert!(emitter.is_none(), "{name}, ray {r}: an emitter the scene tree missed"),
                }
            }
        }
        assert!(agreed > 2000, "only {agreed} rays met an emitter first: the test checks too little");
    }
}
