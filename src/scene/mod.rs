//! Scenes: triangles with Phong materials, emissive triangles as area lights, a pinhole camera and a BVH.
//! Loaded from a TOML scene file that lists OBJ/MTL meshes, or built directly (tests, analytic scenes).

mod accel;
mod bundled;
mod camera;
mod convex;
mod disk_cache;
mod emitter_tree;
mod emitters;
mod error;
mod file;
mod load;
mod material;
mod mtl;
mod obj;
mod obj_cache;
mod obj_words;
mod tile_lights;

#[cfg(test)]
pub(crate) use accel::test_ray_triangle;
pub use accel::{
    Accel, ConeCandidates, ConeTriangles, Hit, HitLanes, MAX_CONE, SKIP_NONE, ShadowBlockers, Shaft, TreeCache,
    VectorPath, has_avx512, vector_path,
};
#[cfg(test)]
pub(crate) use bundled::every_bundled_scene;
pub use bundled::{BUNDLED_SCENES, DEFAULT_SCENE};
pub use camera::{Camera, CameraBasis};
pub use disk_cache::{DiskCache, user_cache_folder};
pub use emitter_tree::EmitterTree;
pub use emitters::{EmitterSampler, EmitterTriangle, LightSelection, PickedFields};
pub use error::SceneError;
pub use file::{MaterialOverride, SceneFile};
pub use load::{load_scene, load_scene_file, load_scene_from_bytes};
pub use material::Material;
pub use tile_lights::TileLights;

use crate::math::SurfaceError;
use glam::Vec3;
use rayon::prelude::*;
use std::borrow::Cow;

/// A triangle with its unit geometric normal `n = normalize((v₁−v₀)×(v₂−v₀))` (counter-clockwise winding) and
/// area. Emitters emit on the side `n` faces; other surfaces are two-sided.
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    pub v: [Vec3; 3],
    pub n: Vec3,
    pub area: f32,
    pub material: u32,
    /// How far computed points on it may be off its plane, for offsetting rays that leave it or end on it.
    pub error: SurfaceError,
}

impl Triangle {
    /// The triangle with vertices `v` (of non-zero area) and material `material`.
    pub fn new(v: [Vec3; 3], material: u32) -> Self {
        let cross = (v[1] - v[0]).cross(v[2] - v[0]);
        let len = cross.length();
        let n = cross / len;
        Self { v, n, area: 0.5 * len, material, error: SurfaceError::of_triangle(v, n) }
    }
}

/// A loaded scene, ready to render.
#[derive(Clone)]
pub struct Scene {
    pub name: String,
    pub camera: Camera,
    /// In BVH order: a hit's triangle id indexes this directly.
    pub triangles: Vec<Triangle>,
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    /// Indices into `triangles` of the emissive triangles of non-zero area.
    pub emitters: Vec<u32>,
    /// Things the user should know that do not stop rendering (no emitter, non-energy-conserving material, …).
    pub warnings: Vec<String>,
    /// Where the scene's own origin is in the coordinates of its files: a scene far from the origin is rebased
    /// to its bounds' centre before its positions are rounded to f32 (0 for a scene near the origin).
    pub origin: glam::DVec3,
    accel: Accel,
    /// The emitter triangles' own tree: what a traced direction reaches is looked for there first.
    emitter_tree: EmitterTree,
    /// Per triangle, its convex emitter group (see `convex`), which the shadow rays towards it may skip.
    convex_groups: Vec<Option<u32>>,
}

impl Scene {
    /// Builds a scene from triangle positions and per-triangle material indices. Zero-area (degenerate)
    /// triangles can neither be hit nor emit: they are dropped and counted in a warning.
    pub fn new(
        name: impl Into<String>,
        camera: Camera,
        positions: &[[Vec3; 3]],
        material_ids: &[u32],
        materials: Vec<Material>,
        material_names: Vec<String>,
    ) -> Result<Self, SceneError> {
        camera.validate()?;
        assert_eq!(positions.len(), material_ids.len(), "one material id per triangle");
        let mut warnings = Vec::new();
        for (i, m) in materials.iter().enumerate() {
            let name = material_names.get(i).map(String::as_str).unwrap_or("?");
            material::validate(m, name)?;
            if m.exceeds_energy_conservation() {
                warnings.push(format!(
                    "material '{name}': k_d + k_s > 1 is not energy-conserving (it reflects more than it receives)"
                ));
            }
        }
        let mut degenerate = Vec::new();
        for (i, (tri, &m)) in positions.iter().zip(material_ids).enumerate() {
            if tri.iter().any(|v| !v.is_finite()) {
                return Err(SceneError::NonFinite("vertex position".into()));
            }
            if (m as usize) >= materials.len() {
                return Err(SceneError::Invalid(format!("triangle uses material {m}, which does not exist")));
            }
            let cross = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
            if !(cross.length_squared() > 0.0 && cross.length_squared().is_finite()) {
                degenerate.push(i);
            }
        }
        // The triangles kept: all of them (not copied) unless some are degenerate.
        let (kept, kept_ids): (Cow<[[Vec3; 3]]>, Cow<[u32]>) = if degenerate.is_empty() {
            (Cow::Borrowed(positions), Cow::Borrowed(material_ids))
        } else {
            let keep = |i: &usize| degenerate.binary_search(i).is_err();
            (
                (0..positions.len()).filter(keep).map(|i| positions[i]).collect(),
                (0..positions.len()).filter(keep).map(|i| material_ids[i]).collect(),
            )
        };
        if !degenerate.is_empty() {
            warnings.push(format!("{} degenerate (zero-area) triangle(s) ignored", degenerate.len()));
        }
        let groups = convex::convex_emitter_groups(&kept, |i| materials[kept_ids[i] as usize].is_emissive());
        // A large mesh's tree is read back from the cache the environment names, if it holds one for this input.
        let (accel, order) = Accel::build_cached(&kept, &groups, TreeCache::from_env());
        // Each triangle's normal, area and error bounds, worked out in the tree's order on all cores (worked out
        // in input order beside the build, then reordered, they took a second copy: 72 MB for 1M triangles).
        let triangles: Vec<Triangle> =
            order.par_iter().map(|&i| Triangle::new(kept[i as usize], kept_ids[i as usize])).collect();
        // Only groups that some subtree holds apart spare a shadow ray any work.
        let apart = accel.groups_held_apart();
        let convex_groups = order.iter().map(|&i| groups[i as usize].filter(|g| apart.contains(g))).collect();
        let emitters: Vec<u32> = (0..triangles.len() as u32)
            .filter(|&i| materials[triangles[i as usize].material as usize].is_emissive())
            .collect();
        if emitters.is_empty() {
            warnings.push("the scene has no emitter: the image will be black".into());
        }
        let emitter_tree = EmitterTree::new(&triangles, &emitters);
        Ok(Self {
            name: name.into(),
            camera,
            triangles,
            materials,
            material_names,
            emitters,
            warnings,
            origin: glam::DVec3::ZERO,
            accel,
            emitter_tree,
            convex_groups,
        })
    }

    #[inline]
    pub fn accel(&self) -> &Accel {
        &self.accel
    }

    #[inline]
    pub fn emitter_tree(&self) -> &EmitterTree {
        &self.emitter_tree
    }

    /// The convex emitter group of triangle `t`, if any: a shadow ray from in front of t's plane to a point on
    /// t meets no other triangle of the group, so it may skip them ([`Accel::occluded`]).
    #[inline]
    pub fn convex_group(&self, t: u32) -> Option<u32> {
        self.convex_groups[t as usize]
    }

    /// The hit point from its barycentrics rather than `o + t·d`, whose error grows with the distance travelled
    /// (Ray Tracing Gems ch. 6): its error is a few ULPs of the vertices.
    #[inline]
    pub fn hit_point(&self, hit: &Hit) -> Vec3 {
        let [v0, v1, v2] = self.triangles[hit.triangle as usize].v;
        v0 + (v1 - v0) * hit.u + (v2 - v0) * hit.v
    }

    /// The triangles that camera rays from `apex` through the quad of directions `corners` can hit, in packets;
    /// `None` when there are more than [`MAX_CONE`] (see [`Accel::cone_triangles`]).
    pub fn cone_candidates(&self, apex: Vec3, corners: [Vec3; 4]) -> Option<ConeCandidates> {
        Some(self.cone(apex, &self.accel.cone_triangles(apex, corners, MAX_CONE)?))
    }

    /// The cone from `apex` of the triangles `ids` (at most [`MAX_CONE`], as `Accel::cone_triangles` orders them).
    #[inline]
    pub fn cone(&self, apex: Vec3, ids: &[u32]) -> ConeCandidates {
        ConeCandidates::new(apex, ids.len(), |i| (self.triangles[ids[i] as usize].v, ids[i]))
    }

    #[inline]
    pub fn material_of(&self, triangle: u32) -> &Material {
        &self.materials[self.triangles[triangle as usize].material as usize]
    }

    /// The triangle seen through pixel (x, y)'s centre, if any.
    pub fn pick(&self, x: u32, y: u32) -> Option<u32> {
        let basis = self.camera.basis();
        let dir = basis.direction(x, y, glam::Vec2::splat(0.5));
        self.accel.closest_hit(basis.eye(), dir, f32::INFINITY).map(|h| h.triangle)
    }

    /// Radiance emitted by triangle `t` towards direction `w` (pointing away from the triangle): L_e on the side
    /// its normal faces, 0 behind it.
    #[inline]
    pub fn emitted(&self, t: u32, w: Vec3) -> Vec3 {
        let tri = &self.triangles[t as usize];
        let m = &self.materials[tri.material as usize];
        if tri.n.dot(w) > 0.0 { m.emission } else { Vec3::ZERO }
    }
}
