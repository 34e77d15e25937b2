//! Emitter sampling for up to eight samples of one pixel in f32x8, alone ([`estimate_emitter_lanes`]) or as the
//! light technique of MIS with BRDF sampling ([`estimate_mis_emitter_brdf_lanes`]). The chain of dependent square
//! roots and divisions each sample needs (hit point, point on the light, distance, ω, density) runs in f32x8;
//! what differs per lane in kind (light selection, the material's BRDF) runs in loops over independent lanes,
//! which the processor overlaps. Each lane computes what the scalar estimator computes, in the same order, bit for
//! bit.

use super::{LANES, mis_brdf_technique, mis_sums};
use crate::math::{SampleRngLanes, SurfaceErrorLanes, Vec3x8, for_each_lane, lane_mask, lanes_equal};
use crate::render::ShadingPoint;
use crate::render::estimator::visible_lanes;
use crate::render::strategy::mis::technique_context;
use crate::render::strategy::{Brdf, Emitter, SampleContext, Technique};
use crate::scene::{EmitterSampler, EmitterTriangle, HitLanes, PickedFields, Scene, TileLights};
use bytemuck::cast;
use glam::Vec3;
use std::f32::consts::FRAC_1_PI;
use wide::{CmpGt, CmpLt, f32x8, i32x8};

/// Emitter sampling's directions for up to eight lanes, before any ray is traced: each lane's shading point, the
/// light triangle it picked and the point x on it, ω towards x and the density p(ω) = p_Δ ‖x − p‖² / (A_Δ |n_Δ·ω|),
/// as `emitter::sample` computes them.
struct EmitterLanes {
    /// The shading points, their normals (turned towards ω_o), ω_o and the bounds of their rounding errors.
    p: Vec3x8,
    n: Vec3x8,
    wo: Vec3x8,
    p_error: f32x8,
    /// Per lane, the material of the triangle hit.
    materials: [u32; LANES],
    /// The lanes that hit something, and those that see the front of what they hit.
    hit: u32,
    front: u32,
    /// The lanes that picked a light, and those whose shading point is on its emitting side (so that the point on
    /// it is drawn).
    picked: u32,
    faces: u32,
    /// The point x on the light, the light's normal, material (u32::MAX for none), convex group and error bounds.
    x: Vec3x8,
    ln: Vec3x8,
    light_material: [u32; LANES],
    light_group: [u32; LANES],
    light_error: SurfaceErrorLanes,
    /// The picked triangles' L_e, where the picks were read from vectors (`EmitterSampler::pick_fields`).
    light_emission: Option<Vec3x8>,
    /// ω, p(ω) and ω·n.
    wi: Vec3x8,
    pdf: [f32; LANES],
    cos: [f32; LANES],
    /// Each lane's emitter slot (meaningful in the lanes of `picked`).
    slots: i32x8,
    /// The lanes whose direction is a sample that can contribute: on the emitting side, at a positive finite
    /// density, above the surface.
    ok: u32,
}

impl EmitterLanes {
    /// Draws each lane's direction: the light's uniform, then the point's two, from lane l of `rngs` (every lane
    /// draws all three, used or not).
    #[inline(always)]
    fn draw(
        scene: &Scene,
        emitters: &EmitterSampler,
        dirs: &Vec3x8,
        hits: &HitLanes,
        rngs: &mut SampleRngLanes,
    ) -> Self {
        // The lanes are visited through the bits of masks such as `hit`: whether a lane goes on varies from
        // sample to sample (half of veach-mis's samples pick the back of a sphere), and a branch per lane would be
        // mispredicted.
        let hit = hits.mask;
        // The shading points: x = v₀ + u (v₁ − v₀) + v (v₂ − v₀), with the normal turned towards ω_o = −dir. Each
        // lane's triangle as two rows of eight, transposed into one vector per component; (u, v) come as vectors.
        // Where every lane that hit met one triangle (most groups: a pixel inside a face), its values are
        // broadcast instead; a lane that missed holds zeros either way.
        let mut materials = [0; LANES];
        let first = hits.triangle[(hit.trailing_zeros() & 7) as usize];
        let same = lanes_equal(&hits.triangle, first);
        let ([a, b, c], [nx, ny, nz], p_error) = if hit != 0 && same & hit == hit {
            let tri = &scene.triangles[first as usize];
            for_each_lane(hit, |l| materials[l] = tri.material);
            let on: f32x8 = cast(lane_mask(hit));
            let vertex = |v: Vec3| Vec3x8::select(on, Vec3x8::splat(v), Vec3x8::splat(Vec3::ZERO));
            let n = vertex(tri.n);
            (tri.v.map(vertex), [n.x, n.y, n.z], on.blend(f32x8::splat(tri.error.at_point), f32x8::ZERO))
        } else {
            let mut rows = [[f32x8::ZERO; LANES]; 2];
            for_each_lane(hit, |l| {
                let tri = &scene.triangles[hits.triangle[l] as usize];
                let (c, n) = (tri.v[2], tri.n);
                rows[0][l] = Vec3x8::triangle_row(tri.v);
                rows[1][l] = f32x8::new([c.z, n.x, n.y, n.z, tri.error.at_point, 0.0, 0.0, 0.0]);
                materials[l] = tri.material;
            });
            let [cz, nx, ny, nz, p_error, _, _, _] = f32x8::transpose(rows[1]);
            (Vec3x8::triangles(rows[0], cz), [nx, ny, nz], p_error)
        };
        let (u, v) = (hits.u, hits.v);
        let p = a + (b - a) * u + (c - a) * v;
        let wo = -*dirs;
        let geometric = Vec3x8::new(nx, ny, nz);
        let facing = geometric.dot(wo);
        let n = Vec3x8::select(facing.cmp_lt(f32x8::ZERO), -geometric, geometric);
        let front = facing.cmp_gt(f32x8::ZERO).move_mask() as u32;

        // Light selection per lane (p_Δ may depend on the shading point), then a uniform point x on Δ. A few
        // records held in vectors are picked in f32x8 (`EmitterSampler::pick_fields`); otherwise the picked
        // records' rows transpose into one vector per field, read once every lane has picked, so that their
        // loads wait on the alias table together. A lane with no light keeps `EmitterTriangle::NONE`.
        let (u_light, u_point) = (rngs.uniform(), [rngs.uniform(), rngs.uniform()]);
        let (mut picked, mut light_emission) = (0, None);
        let (slots, [la, lb, lc], [nx, ny, nz, area, p_delta, material, group], light_error) =
            if let Some(PickedFields { slots, fields: f, errors, emission }) = emitters.pick_fields(u_light, hit) {
                (picked, light_emission) = (hit, Some(emission));
                let vertex = |k: usize| Vec3x8::new(f[k], f[k + 1], f[k + 2]);
                (slots, [vertex(0), vertex(3), vertex(6)], [f[9], f[10], f[11], f[12], f[13], f[14], f[15]], errors)
            } else {
                let mut light_error = [EmitterTriangle::NONE.error; LANES];
                let none = EmitterTriangle::NONE.rows();
                let (mut lo, mut hi) = ([none[0]; LANES], [none[1]; LANES]);
                let mut slots = [-1; LANES];
                let u_light = u_light.to_array();
                if let Some((picks, records)) = emitters.pick_fixed_lanes(u_light) {
                    for_each_lane(hit, |l| {
                        ([lo[l], hi[l]], light_error[l]) = (records[l].rows(), records[l].error);
                        slots[l] = picks[l] as i32;
                    });
                    picked = hit;
                } else {
                    for_each_lane(hit, |l| {
                        if let Some((t, p_delta)) = emitters.pick(scene, p.lane(l), u_light[l]) {
                            let record = EmitterTriangle::of(scene, t, p_delta);
                            ([lo[l], hi[l]], light_error[l]) = (record.rows(), record.error);
                            picked |= 1 << l;
                            slots[l] = emitters.slot(t) as i32;
                        }
                    });
                }
                let [cz, nx, ny, nz, area, p_delta, material, group] = f32x8::transpose(hi);
                let errors = SurfaceErrorLanes::from_lanes(&light_error);
                (i32x8::new(slots), Vec3x8::triangles(lo, cz), [nx, ny, nz, area, p_delta, material, group], errors)
            };
        let ln = Vec3x8::new(nx, ny, nz);
        // The picked triangle's material (u32::MAX for none) and convex emitter group.
        let light_material = material.to_array().map(f32::to_bits);
        let light_group = group.to_array().map(f32::to_bits);
        // sample_uniform_triangle, then the density p_Δ ‖x − p‖² / (A_Δ |n_Δ·ω|), as `emitter::sample` computes them.
        let su0 = u_point[0].sqrt();
        let b0 = f32x8::ONE - su0;
        let b1 = u_point[1] * su0;
        let x = la * b0 + lb * b1 + lc * (f32x8::ONE - b0 - b1);
        let d = x - p;
        let dist = d.length();
        let wi = d * (f32x8::ONE / dist);
        let cos_light = ln.dot(-wi);
        let pdf = p_delta * (dist * dist / (area * cos_light));
        let cos = n.dot(wi);
        // `faces`: p on the emitting side of Δ's plane (else L_i = 0, the back of a one-sided emitter).
        let faces = ln.dot(p - la).cmp_gt(f32x8::ZERO);
        let ok = faces
            & dist.cmp_gt(f32x8::ZERO)
            & cos_light.cmp_gt(f32x8::ZERO)
            & pdf.cmp_gt(f32x8::ZERO)
            & pdf.is_finite()
            & cos.cmp_gt(f32x8::ZERO);
        Self {
            p,
            n,
            wo,
            p_error,
            materials,
            hit,
            front,
            picked,
            faces: faces.move_mask() as u32,
            x,
            ln,
            light_material,
            light_group,
            light_error,
            light_emission,
            slots,
            wi,
            pdf: pdf.to_array(),
            cos: cos.to_array(),
            ok: ok.move_mask() as u32,
        }
    }

    /// Lane `l`'s shading point (a lane that hit something), as `lanes::shading_point` sets it up, bit for bit:
    /// p, n and ω_o went through the same operations in f32x8.
    #[inline(always)]
    fn shading_point<'a>(&self, scene: &'a Scene, l: usize) -> ShadingPoint<'a> {
        let material = &scene.materials[self.materials[l] as usize];
        let (p, n, wo, error) = (self.p.lane(l), self.n.lane(l), self.wo.lane(l), self.p_error.as_array_ref()[l]);
        ShadingPoint { p, n, wo, material, error }
    }

    /// The lanes of `active` whose shadow ray gets through; adds the shadow rays to `rays` (those to a clear
    /// light are answered without being traced, those to a light with the tile's blockers listed meet only
    /// them).
    #[inline(always)]
    fn visible(&self, scene: &Scene, tile: &TileLights, active: u32, rays: &mut u64) -> u32 {
        let (near, far, lights) =
            ((self.p, self.n, self.p_error), (self.x, self.ln), (|| self.light_error, self.light_group));
        visible_lanes(scene, near, far, lights, active, Some((tile, self.slots)), rays)
    }
}

/// `L_e(x, ω_o) + f_r L_i (ω·n) / p(ω)` for up to eight camera rays `dirs` of one pixel and their hits (none
/// in a lane that missed or is unused), with ω from emitter sampling. Lane l of `rngs` continues sample l's
/// stream after the camera's two uniforms. Adds the shadow rays traced to `rays`.
#[inline]
pub fn estimate_emitter_lanes(
    scene: &Scene,
    lights: (&EmitterSampler, &TileLights),
    dirs: &Vec3x8,
    hits: &HitLanes,
    rngs: &mut SampleRngLanes,
    rays: &mut u64,
) -> Vec3x8 {
    let e = EmitterLanes::draw(scene, lights.0, dirs, hits, rngs);
    // Per lane: L_e towards the camera, and f_r L_i (ω·n) / p(ω) if the shadow ray gets through.
    let zero = Vec3x8::splat(Vec3::ZERO);
    // Where the lanes that see a front face all see one material (most groups), its L_e is read once (and, for a
    // material that does not emit, not used at all).
    let seen = e.front & e.hit;
    let first = e.materials[(seen.trailing_zeros() & 7) as usize];
    let emitted = if seen & lanes_equal(&e.materials, first) == seen {
        let le = scene.materials[first as usize].emission;
        if le == Vec3::ZERO { zero } else { Vec3x8::select(cast(lane_mask(seen)), Vec3x8::splat(le), zero) }
    } else {
        let mut emitted = [Vec3::ZERO; LANES];
        for_each_lane(seen, |l| emitted[l] = scene.materials[e.materials[l] as usize].emission);
        Vec3x8::from_lanes(&emitted)
    };
    let mut reflected = zero;
    let mut shadow_rays = 0;
    let light = e.ok & e.picked;
    // Where every such lane shades one diffuse material (most groups), f_r = k_d/π wherever n·ω_o > 0 (n·ω > 0
    // is in `ok`), as `eval_brdf` gives it, and the value is computed in f32x8; lane by lane elsewhere.
    let m = e.materials[(light.trailing_zeros() & 7) as usize];
    let alike = lanes_equal(&e.materials, m);
    // Lane 0's material where no lane picked a light: a scene with emitters has materials.
    let material = &scene.materials[m as usize];
    if light != 0 && alike & light == light && material.ks == Vec3::ZERO {
        let f = material.kd * FRAC_1_PI;
        // `Scene::emitted(Δ, −ω)`: ω leaves Δ on its emitting side, since cos θ_Δ = n_Δ·(−ω) > 0 in `ok`. Read
        // with the picks where they came from vectors; else one light material (a scene with one light) is
        // broadcast, several gathered.
        let lm = e.light_material[(light.trailing_zeros() & 7) as usize];
        let (li, lit) = if let Some(li) = e.light_emission {
            (li, light & li.nonzero().move_mask() as u32)
        } else if light & !lanes_equal(&e.light_material, lm) == 0 {
            let li = scene.materials[lm as usize].emission;
            (Vec3x8::splat(li), if li != Vec3::ZERO { light } else { 0 })
        } else {
            let (mut li, mut lit) = ([Vec3::ZERO; LANES], 0);
            for_each_lane(light, |l| {
                li[l] = scene.materials[e.light_material[l] as usize].emission;
                lit |= ((li[l] != Vec3::ZERO) as u32) << l;
            });
            (Vec3x8::from_lanes(&li), lit)
        };
        if f != Vec3::ZERO {
            shadow_rays = lit & e.n.dot(e.wo).cmp_gt(f32x8::ZERO).move_mask() as u32;
            reflected = Vec3x8::splat(f) * li * f32x8::new(e.cos) / f32x8::new(e.pdf);
        }
    } else {
        let mut each = [Vec3::ZERO; LANES];
        for_each_lane(light, |l| {
            let material = &scene.materials[e.materials[l] as usize];
            let wi = e.wi.lane(l);
            let f = material.eval_brdf(e.n.lane(l), e.wo.lane(l), wi);
            let li = scene.materials[e.light_material[l] as usize].emission;
            if f != Vec3::ZERO && li != Vec3::ZERO {
                each[l] = f * li * e.cos[l] / e.pdf[l];
                shadow_rays |= 1 << l;
            }
        });
        reflected = Vec3x8::from_lanes(&each);
    }
    let visible = e.visible(scene, lights.1, shadow_rays, rays);
    emitted + Vec3x8::select(cast(lane_mask(visible)), reflected, zero)
}

/// MIS of emitter sampling and BRDF sampling, one direction each (the default `MisSettings`), for up to eight
/// samples of one pixel: what [`super::estimate_mis_lanes`] gives each sample with these two techniques, bit for
/// bit, with the light technique's directions drawn and weighed in f32x8 as [`estimate_emitter_lanes`] draws
/// them. Each lane's BRDF direction is then drawn from its own stream where the light technique left it, all
/// eight in f32x8 ([`super::brdf`]), and the BRDF directions walk the tree together, interleaved. Adds the rays
/// traced to `rays`. Not inlined: in the caller, beside emitter sampling's own path, it cost that path 9% more
/// instructions (its random streams were no longer drawn in vectorised loops).
#[inline(never)]
pub fn estimate_mis_emitter_brdf_lanes(
    ctx: &SampleContext,
    emitters: &EmitterSampler,
    dirs: &Vec3x8,
    hits: &HitLanes,
    rngs: &mut SampleRngLanes,
    rays: &mut u64,
) -> [Vec3; LANES] {
    let scene = ctx.scene;
    let contexts = [technique_context(ctx, 0), technique_context(ctx, 1)];
    let heuristic = ctx.mis.heuristic;
    let before = *rngs;
    let e = EmitterLanes::draw(scene, emitters, dirs, hits, rngs);
    // Each lane's L_e towards the camera, and its light direction's contribution, weighted (if its shadow ray
    // gets through), as `unshadowed` gives it: `f_r L_e (ω·n)`, with a shadow ray wherever f_r ≠ 0 and L_e ≠ 0.
    // Where the material is diffuse (k_s = 0) in f32x8: f_r = k_d/π where n·ω > 0 (in `ok`) and n·ω_o > 0, and
    // the BRDF technique's density p_d (ω·n)⁺/π with p_d = k_d/(k_d + 0) = 1, as `eval_brdf` and `pdf_brdf` give
    // them; lane by lane where k_s ≠ 0.
    let (mut emitted, mut first) = ([Vec3::ZERO; LANES], [Vec3::ZERO; LANES]);
    let (mut shadow_rays, mut specular) = (0, 0);
    let (mut kd, mut li) = ([Vec3::ZERO; LANES], [Vec3::ZERO; LANES]);
    let mut materials = [None; LANES];
    let light = e.ok & e.picked;
    for_each_lane(e.hit, |l| {
        let material = &scene.materials[e.materials[l] as usize];
        materials[l] = Some(material);
        if e.front & (1 << l) != 0 {
            emitted[l] = material.emission;
        }
        if light & (1 << l) == 0 {
            return;
        }
        li[l] = scene.materials[e.light_material[l] as usize].emission;
        if material.ks == Vec3::ZERO {
            kd[l] = material.kd;
            return;
        }
        specular |= 1 << l;
        let (sp, wi) = (e.shading_point(scene, l), e.wi.lane(l));
        let f = material.eval_brdf(sp.n, sp.wo, wi);
        if f != Vec3::ZERO && li[l] != Vec3::ZERO {
            let value = f * li[l] * e.cos[l];
            let w = heuristic.weight(1, e.pdf[l], 1, Brdf.pdf(&contexts[1], &sp, wi, None));
            first[l] = value * (w / (1.0 * e.pdf[l]));
            shadow_rays |= 1 << l;
        }
    });
    let (f, li) = (Vec3x8::from_lanes(&kd) * f32x8::splat(FRAC_1_PI), Vec3x8::from_lanes(&li));
    let (cos, pdf) = (f32x8::new(e.cos), f32x8::new(e.pdf));
    let towards = e.n.dot(e.wo).cmp_gt(f32x8::ZERO);
    let diffuse = (towards & f.nonzero() & li.nonzero()).move_mask() as u32 & light & !specular;
    let w = heuristic.weight_lanes(pdf, cos.max(f32x8::ZERO) * f32x8::splat(FRAC_1_PI));
    let weighted = (f * li * cos * (w / (f32x8::ONE * pdf))).to_lanes();
    for_each_lane(diffuse, |l| first[l] = weighted[l]);
    shadow_rays |= diffuse;
    // The BRDF directions, each drawn after its lane's light direction.
    // A sample that drew no point on a light (none picked, or p behind it) used one uniform, else three.
    let mut streams = rngs.with_lanes_after(&before, !(e.picked & e.faces), 1);
    let near = (e.p, e.n, e.wo, e.p_error);
    let from_brdf = mis_brdf_technique(&contexts, &Emitter, &materials, near, &mut streams, rays);
    let visible = e.visible(scene, ctx.tile, shadow_rays, rays);
    mis_sums(&emitted, &first, shadow_rays & !visible, &from_brdf)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::PixelStreams;
    use crate::render::MisSettings;
    use crate::render::lanes::estimate_mis_lanes;
    use crate::scene::{LightSelection, every_bundled_scene};

    /// The default MIS with its light technique in f32x8 gives every lane what MIS's lane-by-lane estimator gives
    /// it with emitter and BRDF sampling, bit for bit, on every bundled scene, with every light selection, in
    /// groups of one to eight samples.
    #[test]
    fn mis_with_emitter_lanes_is_the_lane_by_lane_mis() {
        let mis = MisSettings::default();
        for (name, scene, camera) in every_bundled_scene(24, 18) {
            for selection in LightSelection::ALL {
                let Some(emitters) = EmitterSampler::new(&scene, selection) else { continue };
                let ctx = SampleContext {
                    scene: &scene,
                    emitters: Some(&emitters),
                    mis: &mis,
                    state: None,
                    guide: None,
                    tile: &TileLights::NONE,
                };
                let basis = camera.basis();
                for (pixel, (x, y)) in
                    (0..camera.height).flat_map(|y| (0..camera.width).map(move |x| (x, y))).enumerate()
                {
                    let streams = PixelStreams::new(7, pixel as u64);
                    let n = pixel % 8 + 1;
                    let mut rngs = streams.samples(0);
                    let jitter = [rngs.uniform(), rngs.uniform()];
                    let dirs = basis.directions(x, y, jitter[0], jitter[1]);
                    let hits = HitLanes::from_hits(&std::array::from_fn(|l| {
                        (l < n).then(|| scene.accel().closest_hit(basis.eye(), dirs.lane(l), f32::INFINITY)).flatten()
                    }));
                    let (mut simd_rays, mut lane_rays) = (0, 0);
                    let mut lane_rngs = std::array::from_fn(|l| rngs.lane(l));
                    let simd =
                        estimate_mis_emitter_brdf_lanes(&ctx, &emitters, &dirs, &hits, &mut rngs, &mut simd_rays);
                    let by_lane =
                        estimate_mis_lanes(&ctx, (&Emitter, &Brdf), &dirs, &hits, &mut lane_rngs, &mut lane_rays);
                    for l in 0..n {
                        assert!(
                            simd[l].to_array().map(f32::to_bits) == by_lane[l].to_array().map(f32::to_bits),
                            "{name}, {}, pixel ({x}, {y}), lane {l}: {} against {}",
                            selection.name(),
                            simd[l],
                            by_lane[l]
                        );
                    }
                    assert_eq!(simd_rays, lane_rays, "{name}, pixel ({x}, {y}): rays traced");
                }
            }
        }
    }
}
