//! Phong BRDF sampling ([`crate::render::strategy::Brdf`]) for up to eight shading points at once: the lobe
//! probability Pr_d from the lanes' materials, the lobe choice, the cosine-weighted and the cos^α samples, the
//! frames around n and ω_r, the mixture's density `p(ω) = Pr_d (ω·n)/π + (1−Pr_d) (α+1)/(2π) (ω·ω_r)^α` and f_r
//! run in f32x8, the sample's angle's sin and cos too (`crate::math::sin_cos_lanes`, the scalar samplers' own
//! arithmetic). The other transcendental functions (the lobe's ln and expm1, the density's `cos^α`) are the
//! scalar code's own calls, lane by lane, and every other operation is the scalar code's, in its order and without
//! fused multiply-adds (as [`Vec3x8`]'s): each lane gets what `Brdf::sample` and `eval_brdf` give it, bit for bit.

use super::LANES;
use crate::math::{ONE_MINUS_EPSILON, SampleRngLanes, Vec3x8, for_each_lane, sin_cos_lanes};
use crate::sampling::phong_lobe_pdf_from_gap;
use crate::scene::Material;
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};
use wide::{CmpEq, CmpGt, CmpLt, f32x8};

/// Per lane, a direction drawn from its material's BRDF mixture with what the estimator needs of it.
#[derive(Default)]
pub(super) struct BrdfSamples {
    pub wi: Vec3x8,
    /// The mixture's density at ω_i (solid angle).
    pub pdf: [f32; LANES],
    /// `f_r(ω_i, ω_o)`.
    pub f: Vec3x8,
    /// `ω_i·n`.
    pub cos: [f32; LANES],
    /// The lanes whose direction can carry light: drawn (a material that is not black), above the surface
    /// (ω_i·n > 0), with p > 0 and f_r ≠ 0 (what `brdf_and_cos` lets through).
    pub contributing: u32,
}

/// Draws each lane's direction as `Brdf::sample` does at a shading point of material `materials[l]` (none where
/// the lane has no shading point) from lane l of `rngs` (two uniforms, drawn in every lane), with its density,
/// f_r and ω_i·n. `(n, wo)` hold the shading points' n and ω_o in lanes.
#[inline]
pub(super) fn sample_brdf_lanes(
    materials: &[Option<&Material>; LANES],
    (n, wo): (Vec3x8, Vec3x8),
    rngs: &mut SampleRngLanes,
) -> BrdfSamples {
    let (u_x, u_y) = (rngs.uniform(), rngs.uniform());
    // The materials' k_d, k_s and α as one row each, transposed into one vector per field; where every lane
    // with a material has the same one (most groups), broadcast. A lane without one holds zeros either way.
    let first = materials.iter().flatten().next();
    let same = first.is_some_and(|f| materials.iter().flatten().all(|m| std::ptr::eq(*m, *f)));
    let [kd_x, kd_y, kd_z, ks_x, ks_y, ks_z, alpha, _] = match first {
        Some(m) if same => {
            let on = f32x8::new(materials.map(|m| if m.is_some() { f32::from_bits(u32::MAX) } else { 0.0 }));
            [m.kd.x, m.kd.y, m.kd.z, m.ks.x, m.ks.y, m.ks.z, m.alpha, 0.0].map(|v| on & f32x8::splat(v))
        }
        _ => {
            let mut rows = [f32x8::ZERO; LANES];
            for (l, material) in materials.iter().enumerate() {
                let Some(m) = material else { continue };
                rows[l] = f32x8::new([m.kd.x, m.kd.y, m.kd.z, m.ks.x, m.ks.y, m.ks.z, m.alpha, 0.0]);
            }
            f32x8::transpose(rows)
        }
    };
    let (kd, ks) = (Vec3x8::new(kd_x, kd_y, kd_z), Vec3x8::new(ks_x, ks_y, ks_z));
    let (zero, one) = (f32x8::ZERO, f32x8::ONE);
    // `diffuse_probability`: Pr_d = k_d/(k_d + k_s) on the RGB sums, none (nothing drawn) where both are 0.
    let (d, s) = (kd_x + kd_y + kd_z, ks_x + ks_y + ks_z);
    // A lane without a material has rows of zeros: none is drawn there.
    let black = !(d + s).cmp_gt(zero);
    let drawn = !black.move_mask() as u32 & 0xff;
    if drawn == 0 {
        return BrdfSamples::default();
    }
    let p_d = black.blend(one, d / (d + s));
    // k_s ≠ 0 as `ks != Vec3::ZERO` has it (−0 is 0, NaN is not).
    let glossy = !(ks_x.cmp_eq(zero) & ks_y.cmp_eq(zero) & ks_z.cmp_eq(zero));
    let (alpha_lanes, glossy_lanes) = (alpha.to_array(), glossy.move_mask() as u32);

    // The lecture's Bernoulli lobe choice; u₀ rescaled and reused.
    let diffuse = u_x.cmp_lt(p_d);
    let diffuse_lanes = diffuse.move_mask() as u32 & drawn;
    let u0_diffuse = (u_x / p_d).min(f32x8::splat(ONE_MINUS_EPSILON));
    let u0_glossy = ((u_x - p_d) / (one - p_d)).max(zero).min(f32x8::splat(ONE_MINUS_EPSILON));
    let u0 = diffuse.blend(u0_diffuse, u0_glossy);

    // Diffuse: Shirley & Chiu's concentric disc, lifted to the hemisphere (`sample_cosine_hemisphere`).
    let (o_x, o_y) = (f32x8::splat(2.0) * u0 - one, f32x8::splat(2.0) * u_y - one);
    let x_wider = o_x.abs().cmp_gt(o_y.abs());
    let radius = x_wider.blend(o_x, o_y);
    let theta = x_wider
        .blend(f32x8::splat(FRAC_PI_4) * (o_y / o_x), f32x8::splat(FRAC_PI_2) - f32x8::splat(FRAC_PI_4) * (o_x / o_y));
    let centre = o_x.cmp_eq(zero) & o_y.cmp_eq(zero);
    let (sin_theta, cos_theta) = sin_cos_lanes(theta);
    let disc_x = centre.blend(zero, radius * cos_theta);
    let disc_y = centre.blend(zero, radius * sin_theta);
    let height = (one - (disc_x * disc_x + disc_y * disc_y)).max(zero).sqrt();
    let cosine_sample = Vec3x8::new(disc_x, disc_y, height);

    // Glossy: the cos^α lobe around ω_r (`sample_phong_lobe`): 1 − cos θ_r = −expm1(ln u₀ / (α+1)).
    let u0_lanes = u0.as_array_ref();
    let mut gap = [0.0; LANES];
    for_each_lane(drawn & !diffuse_lanes, |l| {
        gap[l] = (-(u0_lanes[l].ln() / (alpha_lanes[l] + 1.0)).exp_m1()).clamp(0.0, 1.0);
    });
    let (sin_phi, cos_phi) = sin_cos_lanes(f32x8::splat(2.0 * PI) * u_y);
    let gap = f32x8::new(gap);
    let sin_theta_r = (gap * (f32x8::splat(2.0) - gap)).max(zero).sqrt();
    let lobe_sample = Vec3x8::new(sin_theta_r * cos_phi, sin_theta_r * sin_phi, one - gap);

    // Into the world: about n (diffuse) or ω_r = 2(n·ω_o)n − ω_o (glossy).
    let wr = n * (f32x8::splat(2.0) * n.dot(wo)) - wo;
    let axis = Vec3x8::select(diffuse, n, wr);
    let wi = frame_to_world(axis, Vec3x8::select(diffuse, cosine_sample, lobe_sample));

    // The lobe's value at ω_i, from `|ω_i − ω_r|²/2`: for the density where Pr_d < 1, for f_r where k_s ≠ 0.
    let cos = n.dot(wi);
    let cos_o = n.dot(wo);
    let diff = wi - wr;
    let mirror_gap = (f32x8::splat(0.5) * diff.dot(diff)).to_array();
    let p_d_lanes = p_d.as_array_ref();
    let mut lobe = [0.0; LANES];
    let above = cos.cmp_gt(zero) & cos_o.cmp_gt(zero);
    let for_brdf = glossy_lanes & above.move_mask() as u32;
    for_each_lane(drawn, |l| {
        if p_d_lanes[l] < 1.0 || for_brdf & (1 << l) != 0 {
            lobe[l] = phong_lobe_pdf_from_gap(mirror_gap[l], alpha_lanes[l]);
        }
    });
    let lobe = f32x8::new(lobe);
    let pdf = p_d * (cos.max(zero) * f32x8::splat(FRAC_1_PI));
    let pdf = p_d.cmp_lt(one).blend(pdf + (one - p_d) * lobe, pdf);

    // f_r = k_d/π + k_s lobe (the lobe added only where k_s ≠ 0), 0 with either direction below the surface;
    // `brdf_and_cos`'s checks: a lane contributes if ω_i·n > 0, p > 0 and f_r ≠ 0.
    let diffuse_f = kd * f32x8::splat(FRAC_1_PI);
    let f = Vec3x8::select(glossy, diffuse_f + ks * lobe, diffuse_f);
    let kept = above & cos.cmp_gt(zero) & pdf.cmp_gt(zero);
    let f = Vec3x8::select(kept, f, Vec3x8::default());
    let nonzero = !(f.x.cmp_eq(zero) & f.y.cmp_eq(zero) & f.z.cmp_eq(zero));
    let contributing = (kept & nonzero).move_mask() as u32 & drawn;
    BrdfSamples { wi, pdf: pdf.to_array(), f, cos: cos.to_array(), contributing }
}

/// `Frame::from_z(z).to_world(v)` lane by lane (Duff et al. 2017), in the scalar code's order.
#[inline(always)]
fn frame_to_world(z: Vec3x8, v: Vec3x8) -> Vec3x8 {
    let flip = f32x8::splat(-0.0);
    let sign = f32x8::ONE.copysign(z.z);
    let a = (f32x8::ONE ^ flip) / (sign + z.z);
    let b = z.x * z.y * a;
    let s = Vec3x8::new(f32x8::ONE + sign * z.x * z.x * a, sign * b, (sign ^ flip) * z.x);
    let t = Vec3x8::new(b, sign + z.y * z.y * a, z.y ^ flip);
    s * v.x + t * v.y + z * v.z
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{PixelStreams, SampleRng};
    use crate::render::strategy::{Brdf, DirectionStrategy, SampleContext};
    use crate::render::{MisSettings, ShadingPoint};
    use crate::scene::load_scene;
    use glam::Vec3;

    /// Every lane's direction, density, f_r and ω_i·n are `Brdf::sample`'s and `eval_brdf`'s, bit for bit, and so
    /// is which lanes contribute: materials diffuse, glossy (α from 0 to 10⁶), with k_s too small to move the
    /// lobe choice off 1, and black; random normals and viewing directions, some lanes without a shading point.
    #[test]
    fn eight_lanes_draw_what_brdf_sampling_draws_lane_by_lane() {
        let materials = [
            Material::default(),
            Material { kd: Vec3::new(0.3, 0.2, 0.1), ks: Vec3::splat(0.6), alpha: 40.0, ..Default::default() },
            Material { kd: Vec3::ZERO, ks: Vec3::ONE, alpha: 1e6, ..Default::default() },
            Material { kd: Vec3::splat(0.2), ks: Vec3::splat(0.5), alpha: 0.0, ..Default::default() },
            // Pr_d = 3/(3 + 10⁻⁷) rounds to 1, yet k_s·lobe shows in f_r near ω_r.
            Material { kd: Vec3::ONE, ks: Vec3::new(1e-7, 0.0, 0.0), alpha: 100.0, ..Default::default() },
            Material { kd: Vec3::ZERO, ks: Vec3::ZERO, ..Default::default() },
            Material { kd: Vec3::splat(0.1), ks: Vec3::splat(0.8), alpha: 3000.0, ..Default::default() },
        ];
        let scene = load_scene("cornell-box").expect("bundled scene");
        let mis = MisSettings::default();
        let tile = &crate::scene::TileLights::NONE;
        let ctx = SampleContext { scene: &scene, emitters: None, mis: &mis, state: None, guide: None, tile };
        let mut setup = SampleRng::new(11, 0, 0);
        let mut unit = || {
            let w = crate::sampling::sample_uniform_hemisphere(setup.uniform_2d());
            if setup.uniform() < 0.5 { w } else { -w }
        };
        assert_eq!(materials[4].diffuse_probability(), Some(1.0));
        let (mut contributing, mut glossy, mut unseen_lobe) = (0, 0, 0);
        for group in 0..4000u64 {
            let shading: [Option<ShadingPoint>; LANES] = std::array::from_fn(|l| {
                let n = unit();
                let wo = unit();
                let wo = if n.dot(wo) < 0.0 { -wo } else { wo };
                let material = &materials[(group as usize * 3 + l) % materials.len()];
                (!(l as u64 + group).is_multiple_of(9)).then_some(ShadingPoint {
                    p: Vec3::ZERO,
                    n,
                    wo,
                    material,
                    error: 0.0,
                })
            });
            let mut lanes = PixelStreams::new(5, group).samples(0);
            let mut alone: [SampleRng; LANES] = std::array::from_fn(|l| lanes.lane(l));
            let lane_vectors = |v: fn(&ShadingPoint) -> Vec3| {
                Vec3x8::from_lanes(&std::array::from_fn(|l| shading[l].as_ref().map_or(Vec3::ZERO, v)))
            };
            let (n, wo) = (lane_vectors(|sp| sp.n), lane_vectors(|sp| sp.wo));
            let drawn = sample_brdf_lanes(&shading.map(|sp| sp.map(|sp| sp.material)), (n, wo), &mut lanes);
            let next = lanes.uniform();
            for l in 0..LANES {
                let Some(sp) = &shading[l] else { continue };
                let s = Brdf.sample(&ctx, sp, &mut alone[l]);
                assert_eq!(next.as_array_ref()[l].to_bits(), alone[l].uniform().to_bits(), "streams left alike");
                let Some(s) = s else {
                    assert_eq!(drawn.contributing & (1 << l), 0);
                    continue;
                };
                let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                assert_eq!(bits(drawn.wi.lane(l)), bits(s.wi), "group {group} lane {l}: {:?}", sp.material);
                assert_eq!(drawn.pdf[l].to_bits(), s.pdf.to_bits(), "group {group} lane {l}");
                let cos = sp.n.dot(s.wi);
                let f = sp.material.eval_brdf(sp.n, sp.wo, s.wi);
                let contributes = cos > 0.0 && s.pdf > 0.0 && f != Vec3::ZERO;
                assert_eq!(drawn.contributing & (1 << l) != 0, contributes, "group {group} lane {l}");
                if contributes {
                    assert_eq!(bits(drawn.f.lane(l)), bits(f));
                    assert_eq!(drawn.cos[l].to_bits(), cos.to_bits());
                    contributing += 1;
                    glossy += (sp.material.ks != Vec3::ZERO) as u32;
                    unseen_lobe += (sp.material == &materials[4] && f != sp.material.kd * FRAC_1_PI) as u32;
                }
            }
        }
        assert!(contributing > 10_000 && glossy > 5_000, "{contributing} contributing, {glossy} glossy");
        assert!(unseen_lobe > 20, "{unseen_lobe} directions where a lobe the lobe choice never draws shows in f_r");
    }
}
