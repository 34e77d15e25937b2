//! A strategy's density at any direction, over the whole sphere. For the hemisphere strategies it is their
//! `pdf(ω)`; a light strategy can reach ω through every facing emitter triangle ω passes through (occluded or
//! not: the shadow ray is traced after sampling), so its density is the sum of `p_Δ p(ω | Δ)` over them; MIS's
//! is the mixture of its two techniques' densities, and `guided`'s that of its guide, emitter and BRDF parts.

use crate::render::strategy::guided;
use crate::render::strategy::light::faces;
use crate::render::{Domain, Reached, SampleContext, ShadingPoint, Strategy};
use glam::Vec3;

/// The density w.r.t. solid angle with which `strategy` draws `wi` at `sp`.
pub fn density(ctx: &SampleContext, sp: &ShadingPoint, strategy: Strategy, wi: Vec3) -> f32 {
    match strategy.domain() {
        Domain::Hemisphere => strategy.pdf(ctx, sp, wi, None),
        Domain::Lights => {
            let scene = ctx.scene;
            scene
                .emitters
                .iter()
                .filter_map(|&t| {
                    let tri = &scene.triangles[t as usize];
                    if !faces(tri, sp.p) {
                        return None;
                    }
                    let point = intersect(sp.p, wi, tri.v)?;
                    Some(strategy.pdf(ctx, sp, wi, Some(Reached { triangle: t, point })))
                })
                .sum()
        }
        Domain::Mixture => {
            let [t0, t1] = ctx.mis.techniques;
            if !ctx.mis.is_valid() {
                return 0.0;
            }
            let [n0, n1] = ctx.mis.samples.map(|n| n as f32);
            (n0 * density(ctx, sp, t0, wi) + n1 * density(ctx, sp, t1, wi)) / (n0 + n1)
        }
        Domain::Learned => {
            let [c_g, c_l, c_b] = guided::weights(ctx, sp);
            let guide = ctx.guide.map_or(0.0, |g| g.dtree(sp.p).pdf_at(sp.p, wi));
            let light = if c_l > 0.0 { density(ctx, sp, Strategy::Emitter, wi) } else { 0.0 };
            c_g * guide + c_l * light + c_b * density(ctx, sp, Strategy::Brdf, wi)
        }
    }
}

/// Where the ray from p along w meets the triangle (Möller–Trumbore), if it does.
pub fn intersect(p: Vec3, w: Vec3, [a, b, c]: [Vec3; 3]) -> Option<Vec3> {
    let (e1, e2) = (b - a, c - a);
    let h = w.cross(e2);
    let det = e1.dot(h);
    if det.abs() < 1e-20 {
        return None;
    }
    let s = p - a;
    let u = s.dot(h) / det;
    let q = s.cross(e1);
    let v = w.dot(q) / det;
    let t = e2.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0).then(|| p + w * t)
}
