//! Emitter (area-light) sampling: pick a triangle with p_Δ, a uniform point x on it, and aim at it:
//! `p(ω) = p_Δ ‖x − p‖² / (A_Δ |n_Δ·ω|)`. A shadow ray decides visibility.

use super::light::{LightStrategy, TriangleSampler, area_pdf_solid_angle};
use crate::math::SampleRng;
use crate::render::ShadingPoint;
use crate::sampling::sample_uniform_triangle;
use crate::scene::Triangle;
use glam::Vec3;

pub struct Emitter;

impl TriangleSampler for Emitter {
    #[inline(always)]
    fn sample_triangle(sp: &ShadingPoint, tri: &Triangle, rng: &mut SampleRng) -> Option<(Vec3, f32, Vec3)> {
        let [a, b, c] = tri.v;
        let x = sample_uniform_triangle(rng.uniform_2d(), a, b, c);
        let d = x - sp.p;
        let dist = d.length();
        if !(dist > 0.0) {
            return None;
        }
        let wi = d * dist.recip();
        let cos_light = tri.n.dot(-wi);
        if !(cos_light > 0.0) {
            return None;
        }
        Some((wi, dist * dist / (tri.area * cos_light), x))
    }

    #[inline]
    fn triangle_pdf(sp: &ShadingPoint, tri: &Triangle, x: Vec3, wi: Vec3) -> f32 {
        area_pdf_solid_angle(sp.p, tri, x, wi)
    }
}

impl LightStrategy for Emitter {
    const NAME: &'static str = "emitter";
    const DESCRIPTION: &'static str = "area-light sampling: triangle with p_Δ, uniform point on it, shadow ray";
    const PDF: &'static str = "p(ω) = p_Δ ‖x−p‖² / (A_Δ |n_Δ·ω|)";
}
