//! Solid-angle light sampling ([`SolidAngle`]) for up to eight samples of one pixel. Each lane picks its triangle
//! as alone; a lane whose triangle's solid angle is in the spherical range waits, one whose is not samples the
//! area at once. The waiting lanes' spherical triangles are then sampled together in f64x4
//! ([`sample_spherical_triangle_lanes`]), and the shadow rays of all go together. Each lane gets what the
//! one-sample estimator with `SolidAngle` gives it, bit for bit: only the order in which lanes draw changes, and
//! each draws from its own stream.

use super::{LANES, OneSampleLanes, shading_point};
use crate::math::{SampleRng, Vec3x8, for_each_lane};
use crate::render::strategy::light::{TriangleSampler, light_sample, pick_facing};
use crate::render::strategy::{Emitter, SampleContext, SolidAngle};
use crate::sampling::sample_spherical_triangle_lanes;
use crate::scene::HitLanes;
use glam::{Vec2, Vec3};

/// The one-sample estimate of `solid-angle` for each lane; adds the rays traced to `rays`.
#[inline]
pub fn estimate_solid_angle_lanes(
    ctx: &SampleContext,
    dirs: &Vec3x8,
    hits: &HitLanes,
    rngs: &mut [SampleRng; LANES],
    rays: &mut u64,
) -> [Vec3; LANES] {
    let scene = ctx.scene;
    let mut lanes = OneSampleLanes::default();
    // The waiting lanes: shading point, triangle (index, p_Δ, Ω_Δ), the two uniforms, and p and Δ's vertices.
    let mut waiting = [None; LANES];
    let (mut u, mut p, mut vertices) = ([Vec2::ZERO; LANES], [Vec3::ZERO; LANES], [[Vec3::ZERO; 3]; LANES]);
    let mut waiting_lanes = 0;
    for l in 0..LANES {
        let Some((sp, le)) = shading_point(scene, dirs, hits, l) else { continue };
        lanes.emitted[l] = le;
        let Some((triangle, p_delta, tri)) = pick_facing(ctx, &sp, &mut rngs[l]) else { continue };
        let (omega, spherical) = SolidAngle::solid_angle_at(sp.p, tri);
        if spherical {
            (u[l], p[l], vertices[l]) = (rngs[l].uniform_2d(), sp.p, tri.v);
            waiting[l] = Some((sp, triangle, p_delta, omega));
            waiting_lanes |= 1 << l;
        } else if let Some(s) = light_sample(triangle, p_delta, Emitter::sample_triangle(&sp, tri, &mut rngs[l])) {
            lanes.add(l, scene, &sp, s, rays);
        }
    }
    if waiting_lanes != 0 {
        let drawn = sample_spherical_triangle_lanes(&u, &p, &vertices, waiting_lanes);
        for_each_lane(waiting_lanes, |l| {
            let Some((sp, triangle, p_delta, omega)) = waiting[l] else { return };
            let tri = &scene.triangles[triangle as usize];
            let drawn = SolidAngle::spherical_sample(sp.p, tri, omega, drawn[l]);
            if let Some(s) = light_sample(triangle, p_delta, drawn) {
                lanes.add(l, scene, &sp, s, rays);
            }
        });
    }
    lanes.finish(ctx, rays)
}
