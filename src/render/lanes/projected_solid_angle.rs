//! Projected-solid-angle light sampling ([`ProjectedSolidAngle`]) for up to eight samples of one pixel. Each lane
//! picks its triangle and plans as alone; the lanes that sample by rejection wait, the others sample the area at
//! once. The waiting lanes then run their trials together, each trial's spherical-triangle candidates drawn in
//! f64x4 ([`sample_projected_triangle_lanes`]), and the shadow rays of all go together. Each lane gets what the
//! one-sample estimator with `ProjectedSolidAngle` gives it, bit for bit: each draws from its own stream in the
//! same order as alone.

use super::{LANES, OneSampleLanes, shading_point};
use crate::math::{SampleRng, Vec3x8, for_each_lane};
use crate::render::strategy::light::{TriangleSampler, light_sample, pick_facing};
use crate::render::strategy::{Emitter, ProjectedSolidAngle, SampleContext};
use crate::sampling::{ProjectedPlan, sample_projected_triangle_lanes};
use crate::scene::HitLanes;
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
    // The waiting lanes: shading point, triangle (index, p_Δ, Ω⊥), and p, n, Δ's vertices and the bound of ω·n.
    let mut waiting = [None; LANES];
    let (mut p, mut n, mut vertices, mut cos_max) =
        ([Vec3::ZERO; LANES], [Vec3::Z; LANES], [[Vec3::ZERO; 3]; LANES], [0.0; LANES]);
    let mut waiting_lanes = 0;
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
            ProjectedPlan::Rejection { projected, cos_max: bound, .. } => {
                (p[l], n[l], vertices[l], cos_max[l]) = (sp.p, sp.n, tri.v, bound);
                waiting[l] = Some((sp, triangle, p_delta, projected));
                waiting_lanes |= 1 << l;
            }
        }
    }
    if waiting_lanes != 0 {
        let drawn = sample_projected_triangle_lanes(rngs, waiting_lanes, (&p, &n), &vertices, &cos_max);
        for_each_lane(waiting_lanes, |l| {
            let Some((sp, triangle, p_delta, projected)) = waiting[l] else { return };
            let tri = &scene.triangles[triangle as usize];
            let drawn = ProjectedSolidAngle::rejection_sample(&sp, tri, projected, drawn[l]);
            if let Some(s) = light_sample(triangle, p_delta, drawn) {
                lanes.add(l, scene, &sp, s, rays);
            }
        });
    }
    lanes.finish(scene, rays)
}
