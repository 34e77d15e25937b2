//! Emitter (area-light) sampling: pick a triangle with p_Δ, a uniform point x on it, and aim at it:
//! `p(ω) = p_Δ ‖x − p‖² / (A_Δ |n_Δ·ω|)`. A shadow ray decides visibility.

use super::{DirectionSample, Target};
use crate::math::SampleRng;
use crate::render::ShadingPoint;
use crate::scene::{EmitterSampler, Scene};

pub const DESCRIPTION: &str = "area-light sampling: triangle with p_Δ, uniform point on it, shadow ray";
pub const PDF: &str = "p(ω) = p_Δ ‖x−p‖² / (A_Δ |n_Δ·ω|)";

#[inline]
pub fn sample(
    sp: &ShadingPoint,
    scene: &Scene,
    emitters: &EmitterSampler,
    rng: &mut SampleRng,
) -> Option<DirectionSample> {
    let u_select = rng.uniform();
    let s = emitters.sample(scene, u_select, rng.uniform_2d());
    let d = s.point - sp.p;
    let dist = d.length();
    if !(dist > 0.0) {
        return None;
    }
    let wi = d / dist;
    let tri = &scene.triangles[s.triangle as usize];
    let cos_light = tri.n.dot(-wi);
    if !(cos_light > 0.0) {
        return None; // the back of a one-sided emitter: L_i = 0
    }
    let pdf = s.p_delta * dist * dist / (tri.area * cos_light);
    Some(DirectionSample { wi, pdf, target: Target::Emitter { triangle: s.triangle, point: s.point } })
}
