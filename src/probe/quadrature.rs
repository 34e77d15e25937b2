//! The point's "truth": the scattering integral by deterministic quadrature over every emitter triangle, with
//! visibility traced,
//!
//! `L_o = Σ_Δ ∫_Δ f_r(ω, ω_o) L_e(x, −ω) (ω·n)⁺ V(p, x) (n_Δ·−ω)⁺ / ‖x − p‖² dA(x)`,  ω = (x − p)/‖x − p‖,
//!
//! the area form of `∫ f_r L_i (ω·n) dω` restricted to the directions that reach a light. Integrating over each
//! light triangle (not a grid over the hemisphere) finds small lights, and the adaptive rule follows the
//! `1/‖x − p‖²` peak of a light millimetres away and the edges of shadows, within a node budget.

use super::adaptive::{Refinement, integrate_triangle};
use crate::render::ShadingPoint;
use crate::render::strategy::light::faces;
use crate::render::visible;
use crate::scene::Scene;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// The quadrature's value and what it cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Quadrature {
    /// Reflected radiance L_o (RGB).
    pub value: Vec3,
    /// Integrand evaluations (each one shadow ray where the integrand is not zero anyway).
    pub nodes: u64,
    /// Whether the node budget stopped refinement somewhere (the value is then less certain).
    pub budget_reached: bool,
}

/// The relative tolerance the quadrature aims at.
pub const RELATIVE_TOLERANCE: f64 = 2e-5;

/// Integrates the scattering integral at `sp` with visibility, spending at most about `max_nodes` evaluations.
pub fn quadrature(scene: &Scene, sp: &ShadingPoint, max_nodes: u64) -> Quadrature {
    let lights: Vec<u32> =
        scene.emitters.iter().copied().filter(|&t| faces(&scene.triangles[t as usize], sp.p)).collect();
    if lights.is_empty() {
        return Quadrature::default();
    }
    let per_light = (max_nodes / lights.len() as u64).max(2_000);
    // A coarse pass without visibility sets the scale of the tolerance.
    let coarse = Refinement { tolerance: f64::INFINITY, max_depth: 5, max_nodes: per_light / 4 };
    let scale: f64 = lights.par_iter().map(|&t| integrate_light(scene, sp, t, false, coarse).0.element_sum()).sum();
    if !(scale > 0.0) {
        return Quadrature { nodes: lights.len() as u64 * 28, ..Default::default() };
    }
    let fine =
        Refinement { tolerance: RELATIVE_TOLERANCE * scale / lights.len() as f64, max_depth: 18, max_nodes: per_light };
    let parts: Vec<(DVec3, u64)> = lights.par_iter().map(|&t| integrate_light(scene, sp, t, true, fine)).collect();
    let value: DVec3 = parts.iter().map(|p| p.0).sum();
    let nodes = parts.iter().map(|p| p.1).sum();
    Quadrature { value: value.as_vec3(), nodes, budget_reached: parts.iter().any(|p| p.1 >= per_light) }
}

/// One light triangle's part, with or without visibility, and its evaluations.
fn integrate_light(scene: &Scene, sp: &ShadingPoint, t: u32, occlusion: bool, r: Refinement) -> (DVec3, u64) {
    let tri = &scene.triangles[t as usize];
    let p = sp.p.as_dvec3();
    let (n, n_light) = (sp.n.as_dvec3(), tri.n.as_dvec3());
    let mut rays = 0;
    let mut f = |x: DVec3| {
        let d = x - p;
        let r2 = d.length_squared();
        let w = d / r2.sqrt();
        let (cos, cos_light) = (n.dot(w), -n_light.dot(w));
        if !(cos > 0.0 && cos_light > 0.0 && r2 > 0.0) {
            return DVec3::ZERO;
        }
        let wi = w.as_vec3();
        let fr = sp.material.eval_brdf(sp.n, sp.wo, wi);
        let le = scene.emitted(t, -wi);
        if fr == Vec3::ZERO || le == Vec3::ZERO {
            return DVec3::ZERO;
        }
        if occlusion && !visible(scene, sp, (t, x.as_vec3(), tri.n), &mut rays) {
            return DVec3::ZERO;
        }
        (fr * le).as_dvec3() * (cos * cos_light / r2)
    };
    let mut nodes = 0;
    let v = integrate_triangle(tri.v.map(|v| v.as_dvec3()), &mut f, r, &mut nodes);
    (v, nodes)
}
