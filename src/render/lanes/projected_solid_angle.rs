//! Projected-solid-angle light sampling ([`ProjectedSolidAngle`]) for up to eight samples of one pixel. Each lane
//! picks its triangle and plans as alone; the lanes that sample by rejection wait, the others sample the area at
//! once. The waiting lanes then run their trials together, each trial's spherical-triangle candidates drawn in
//! f64x4 ([`sample_projected_triangle_lanes`]), and the shadow rays of all go together. Each lane gets what the
//! one-sample estimator with `ProjectedSolidAngle` gives it, bit for bit: each draws from its own stream in the
//! same order as alone.

use super::{LANES, OneSampleLanes, shading_point};
use crate::math::{SampleRng, Vec3x8};
use crate::render::strategy::light::{TriangleSampler, light_sample, pick_facing};
use crate::render::strategy::{Emitter, ProjectedSolidAngle, SampleContext};
use crate::sampling::{ProjectedPlan, sample_projected_triangle_lanes};
use crate::scene::HitLanes;
use arrayvec::ArrayVec;
use glam::Vec3;

/// The one-sample estimate of `projected-solid-angle` for each lane; adds the rays traced to `rays`.
#[inline]
pub fn estimate_projected_solid_angle_lanes(
    ctx: &SampleContext,
    dirs: &Vec3x8,
    hits: &HitLanes,
    rngs: &mut [SampleRng; LANES],
    rays: &mut u64,
) -> [Vec3; LANES] {
    let scene = ctx.scene;
    let mut lanes = OneSampleLanes::default();
    // The waiting lanes, in lane order: lane, shading point, triangle (index, p_Δ, Ω⊥) and the bound of ω·n. Kept
    // compact, so that a group where no lane waits (most groups on small lights) fills no per-lane arrays.
    let mut waiting = ArrayVec::<_, LANES>::new();
    for (l, rng) in rngs.iter_mut().enumerate() {
        let Some((sp, le)) = shading_point(scene, dirs, hits, l) else { continue };
        lanes.emitted[l] = le;
        let Some((triangle, p_delta, tri)) = pick_facing(ctx, &sp, rng) else { continue };
        match ProjectedSolidAngle::plan(&sp, tri) {
            ProjectedPlan::Invisible => {}
            ProjectedPlan::Area => {
                if let Some(s) = light_sample(triangle, p_delta, Emitter::sample_triangle(&sp, tri, rng)) {
                    lanes.add(l, scene, &sp, s, rays);
                }
            }
            ProjectedPlan::Rejection { projected, cos_max, .. } => {
                waiting.push((l, sp, triangle, p_delta, projected, cos_max))
            }
        }
    }
    if !waiting.is_empty() {
        let (mut p, mut n, mut vertices, mut bound) =
            ([Vec3::ZERO; LANES], [Vec3::Z; LANES], [[Vec3::ZERO; 3]; LANES], [0.0; LANES]);
        let mut waiting_lanes = 0;
        for &(l, ref sp, triangle, _, _, cos_max) in &waiting {
            (p[l], n[l], vertices[l], bound[l]) = (sp.p, sp.n, scene.triangles[triangle as usize].v, cos_max);
            waiting_lanes |= 1 << l;
        }
        let drawn = sample_projected_triangle_lanes(rngs, waiting_lanes, (&p, &n), &vertices, &bound);
        for (l, sp, triangle, p_delta, projected, _) in &waiting {
            let tri = &scene.triangles[*triangle as usize];
            let drawn = ProjectedSolidAngle::rejection_sample(sp, tri, *projected, drawn[*l]);
            if let Some(s) = light_sample(*triangle, *p_delta, drawn) {
                lanes.add(*l, scene, sp, s, rays);
            }
        }
    }
    lanes.finish(ctx, rays)
}
