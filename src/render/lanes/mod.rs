//! Up to eight samples of one pixel at once, one per SIMD lane. The shadow rays of all lanes are offset together
//! and walk the BVH together (`Accel::occluded_lanes`); traced directions walk the emitters' own tree interleaved,
//! and their shadow rays go together too. Emitter sampling,
//! alone or as MIS's light technique, runs in f32x8 ([`emitter`]), and so does the default MIS's BRDF technique
//! ([`brdf`]); `solid-angle` and `projected-solid-angle` draw their spherical triangles together in f64x4
//! ([`solid_angle`], [`projected_solid_angle`]); the other techniques sample lane by lane.
//! Every lane computes what the one-sample estimator ([`super::estimate_direct`]) computes, in the same order, bit
//! for bit, so a film does not depend on how its samples were grouped.

mod brdf;
mod emitter;
mod projected_solid_angle;
mod solid_angle;

pub use emitter::{estimate_emitter_lanes, estimate_mis_emitter_brdf_lanes};
pub use projected_solid_angle::estimate_projected_solid_angle_lanes;
pub use solid_angle::estimate_solid_angle_lanes;

use super::estimator::{integrand, unshadowed, visible_lanes};
use super::sink::{Outcome, SampleRecord};
use super::strategy::{DirectionSample, Reached, SampleContext, Technique};
use super::{ShadingPoint, Target};
use crate::math::{
    SampleRng, SampleRngLanes, SurfaceError, SurfaceErrorLanes, Vec3x8, for_each_lane, offset_ray_origins,
};
use crate::scene::{Hit, HitLanes, Material, SKIP_NONE, Scene, TileLights};
use glam::Vec3;
use wide::{f32x8, i32x8};

/// Samples per group.
pub const LANES: usize = 8;

/// The one-sample estimator `f_r L_i (ω·n) / p(ω)` of any strategy that draws one direction (the light
/// strategies but `emitter`'s own SIMD path, and uniform, cosine and BRDF sampling) for up to eight samples of one
/// pixel, bit for bit: per lane the direction is drawn as [`super::estimator::one_sample`] draws it; then the
/// shadow rays of the directions aimed at a light go together ([`ShadowRays`]) and the traced directions walk the
/// tree together, interleaved ([`TracedRays`]). Each lane's stream `rngs[l]` continues after the camera's two
/// uniforms. Adds the rays traced to `rays`.
#[inline]
pub fn estimate_one_sample_lanes(
    ctx: &SampleContext,
    strategy: &impl Technique,
    dirs: &Vec3x8,
    hits: &HitLanes,
    rngs: &mut [SampleRng; LANES],
    rays: &mut u64,
) -> [Vec3; LANES] {
    let mut lanes = OneSampleLanes::default();
    for (l, rng) in rngs.iter_mut().enumerate() {
        let Some((sp, le)) = shading_point(ctx.scene, dirs, hits, l) else { continue };
        lanes.emitted[l] = le;
        if let Some(s) = strategy.sample(ctx, &sp, rng) {
            lanes.add(l, ctx.scene, &sp, s, rays);
        }
    }
    lanes.finish(ctx, rays)
}

/// The one-sample estimator's lanes as their directions are added: the radiance each camera ray sees emitted,
/// each direction's unshadowed `f_r L_e (ω·n) / p` with its shadow ray, or its traced ray.
#[derive(Default)]
pub(super) struct OneSampleLanes {
    pub emitted: [Vec3; LANES],
    reflected: [Vec3; LANES],
    shadow_rays: ShadowRays,
    traced: TracedRays,
}

impl OneSampleLanes {
    /// Lane `l`'s direction `s` from `sp`.
    #[inline(always)]
    pub fn add(&mut self, l: usize, scene: &Scene, sp: &ShadingPoint, s: DirectionSample, rays: &mut u64) {
        match s.target {
            Target::Emitter { triangle, point } => {
                let Ok((value, n_x)) = unshadowed(scene, sp, &s, triangle) else { return };
                self.reflected[l] = value / s.pdf;
                self.shadow_rays.add(l, scene, sp, (triangle, point, n_x));
            }
            Target::Trace => {
                let _ = self.traced.add(l, sp, s, rays);
            }
        }
    }

    /// Traces the rays together; each lane's estimate.
    #[inline(always)]
    pub fn finish(mut self, ctx: &SampleContext, rays: &mut u64) -> [Vec3; LANES] {
        let visible = self.shadow_rays.trace(ctx.scene, ctx.tile, rays);
        for (l, found) in self.traced.trace(ctx.scene, ctx.tile, rays).into_iter().enumerate() {
            if let Ok((value, _, s)) = found {
                self.reflected[l] = value / s.pdf;
            }
        }
        std::array::from_fn(|l| {
            let shadowed = self.shadow_rays.lanes & !visible & (1 << l) != 0;
            self.emitted[l] + if shadowed { Vec3::ZERO } else { self.reflected[l] }
        })
    }
}

/// Lane `l`'s shading point (where its camera ray along `dirs` hit, if it did) and the radiance it emits
/// towards the camera, as the one-sample estimator sets them up.
#[inline(always)]
fn shading_point<'a>(scene: &'a Scene, dirs: &Vec3x8, hits: &HitLanes, l: usize) -> Option<(ShadingPoint<'a>, Vec3)> {
    let hit = hits.lane(l)?;
    let tri = &scene.triangles[hit.triangle as usize];
    let wo = -dirs.lane(l);
    let sp = ShadingPoint::on_triangle(scene.hit_point(&hit), tri, wo, scene.material_of(hit.triangle));
    Some((sp, scene.emitted(hit.triangle, wo)))
}

/// A shading point as a shadow ray leaves it: p, its normal and the bound of its rounding error.
type Near = (Vec3, Vec3, f32);

/// The shadow rays of a group's lanes, gathered lane by lane and traced together ([`visible_lanes`]).
struct ShadowRays {
    /// Per lane: the shading point and its normal, the point on the light and its normal.
    ends: [[Vec3; LANES]; 4],
    p_error: [f32; LANES],
    light_error: [SurfaceError; LANES],
    groups: [u32; LANES],
    /// Per lane: the emitter triangle the ray ends on.
    lights: [u32; LANES],
    /// The lanes with a ray.
    lanes: u32,
}

impl Default for ShadowRays {
    fn default() -> Self {
        let (p_error, light_error, groups) = ([0.0; LANES], [SurfaceError::default(); LANES], [SKIP_NONE; LANES]);
        Self { ends: [[Vec3::ZERO; LANES]; 4], p_error, light_error, groups, lights: [u32::MAX; LANES], lanes: 0 }
    }
}

impl ShadowRays {
    /// Lane `l`'s ray from `sp` to `point` (normal `n_x`) on emitter triangle `triangle`.
    #[inline(always)]
    fn add(&mut self, l: usize, scene: &Scene, sp: &ShadingPoint, to: (u32, Vec3, Vec3)) {
        self.add_from(l, scene, (sp.p, sp.n, sp.error), to);
    }

    /// Lane `l`'s ray from p (normal n, rounding error bound `error`) to `point` on emitter triangle `triangle`.
    #[inline(always)]
    fn add_from(&mut self, l: usize, scene: &Scene, (p, n, error): Near, (triangle, point, n_x): (u32, Vec3, Vec3)) {
        (self.ends[0][l], self.ends[1][l], self.ends[2][l], self.ends[3][l]) = (p, n, point, n_x);
        (self.p_error[l], self.light_error[l]) = (error, scene.triangles[triangle as usize].error);
        self.groups[l] = scene.convex_group(triangle).unwrap_or(SKIP_NONE);
        self.lights[l] = triangle;
        self.lanes |= 1 << l;
    }

    /// Lane `l`'s ray from `near` to the point a traced direction reached on an emitter triangle.
    #[inline(always)]
    fn add_to_reached(&mut self, l: usize, scene: &Scene, near: Near, via: Reached) {
        self.add_from(l, scene, near, (via.triangle, via.point, scene.triangles[via.triangle as usize].n));
    }

    /// The lanes whose ray gets through; adds the rays to `rays` (those to one of `tile`'s clear lights are
    /// answered without being traced, those to a light its blockers list meet only them).
    #[inline(always)]
    fn trace(&self, scene: &Scene, tile: &TileLights, rays: &mut u64) -> u32 {
        if self.lanes == 0 {
            return 0; // no lane has a ray (most groups' BRDF directions miss the lights)
        }
        let [p, n, x, n_x] = self.ends.map(|e| Vec3x8::from_lanes(&e));
        let near = (p, n, f32x8::new(self.p_error));
        // Each lane's emitter slot, where the tile knows something (only in a scene of a few emitter triangles).
        let slot = |t: u32| scene.emitters.iter().position(|&e| e == t).map_or(-1, |s| s as i32);
        let known = tile.clear != 0 || tile.blockers.is_some();
        let tile = known.then(|| (tile, i32x8::new(self.lights.map(slot))));
        let far = || SurfaceErrorLanes::from_lanes(&self.light_error);
        visible_lanes(scene, near, (x, n_x), (far, self.groups), self.lanes, tile, rays)
    }
}

/// Veach's multi-sample MIS with one direction from a light technique and one from a BRDF technique
/// (`MisSettings::samples` = [1, 1]) for up to eight samples of one pixel: what [`super::strategy::mis`]'s estimator
/// gives each sample, bit for bit. Per lane, the light technique draws first and the BRDF technique second from
/// the sample's own stream, as there; each weight needs only the two densities, so it is computed before the
/// rays are traced. The light directions' shadow rays then go together ([`visible_lanes`]) and the BRDF directions
/// walk the tree together, interleaved ([`TracedRays`]); a first technique's direction that is not aimed at a
/// light, or a second technique's that is, is looked up alone. Adds the rays traced to `rays`.
#[inline]
pub fn estimate_mis_lanes(
    ctx: &SampleContext,
    (light, brdf): (&impl Technique, &impl Technique),
    dirs: &Vec3x8,
    hits: &HitLanes,
    rngs: &mut [SampleRng; LANES],
    rays: &mut u64,
) -> [Vec3; LANES] {
    use super::strategy::mis::technique_context;
    let scene = ctx.scene;
    let contexts = [technique_context(ctx, 0), technique_context(ctx, 1)];
    let heuristic = ctx.mis.heuristic;
    let mut emitted = [Vec3::ZERO; LANES];
    // Each lane's first direction's contribution, weighted (if its shadow ray, if it has one, gets through).
    let mut first = [Vec3::ZERO; LANES];
    let mut shadow_rays = ShadowRays::default();
    let mut shading = [None; LANES];
    for l in 0..LANES {
        let Some((sp, le)) = shading_point(scene, dirs, hits, l) else { continue };
        emitted[l] = le;
        if let Some(s) = light.sample(&contexts[0], &sp, &mut rngs[l]) {
            let Target::Emitter { triangle, point } = s.target else {
                if let Ok((value, via)) = integrand(scene, &sp, &s, rays) {
                    let w = heuristic.weight(1, s.pdf, 1, brdf.pdf(&contexts[1], &sp, s.wi, Some(via)));
                    first[l] = value * (w / (1.0 * s.pdf));
                }
                shading[l] = Some(sp);
                continue;
            };
            if let Ok((value, n_x)) = unshadowed(scene, &sp, &s, triangle) {
                let p_other = brdf.pdf(&contexts[1], &sp, s.wi, Some(Reached { triangle, point }));
                let w = heuristic.weight(1, s.pdf, 1, p_other);
                first[l] = value * (w / (1.0 * s.pdf));
                shadow_rays.add(l, scene, &sp, (triangle, point, n_x));
            }
        }
        shading[l] = Some(sp);
    }
    // The BRDF directions, each drawn after its lane's light direction.
    let from_brdf = mis_second_technique(&contexts, (light, brdf), &shading, rngs, rays);
    let visible = shadow_rays.trace(scene, ctx.tile, rays);
    mis_sums(&emitted, &first, shadow_rays.lanes & !visible, &from_brdf)
}

/// MIS's second technique for up to eight lanes, each with its shading point (none where the camera ray missed):
/// a direction from `brdf` drawn from the lane's stream, weighed against `light`'s density there. The directions to
/// trace walk the tree together ([`TracedRays`]); any other is looked up alone. Returns each lane's weighted
/// contribution; adds the rays traced to `rays`.
#[inline(always)]
fn mis_second_technique(
    contexts: &[SampleContext; 2],
    (light, brdf): (&impl Technique, &impl Technique),
    shading: &[Option<ShadingPoint>; LANES],
    rngs: &mut [SampleRng; LANES],
    rays: &mut u64,
) -> [Vec3; LANES] {
    let scene = contexts[1].scene;
    let mut weighted = [Vec3::ZERO; LANES];
    let mut traced = TracedRays::default();
    for l in 0..LANES {
        let Some(sp) = &shading[l] else { continue };
        let Some(s) = brdf.sample(&contexts[1], sp, &mut rngs[l]) else { continue };
        if let Target::Trace = s.target {
            let _ = traced.add(l, sp, s, rays);
        } else if let Ok((value, via)) = integrand(scene, sp, &s, rays) {
            weighted[l] = weighted_second(contexts, light, sp, value, via, &s);
        }
    }
    for (l, found) in traced.trace(scene, contexts[1].tile, rays).into_iter().enumerate() {
        let (Some(sp), Ok((value, via, s))) = (&shading[l], found) else { continue };
        weighted[l] = weighted_second(contexts, light, sp, value, via, &s);
    }
    weighted
}

/// [`mis_second_technique`] with BRDF sampling as the second technique, its directions, densities and f_r drawn in
/// f32x8 ([`brdf::sample_brdf_lanes`]) from lane l of `rngs` for lane l: each lane gets what the generic one gives
/// it, bit for bit. `near` holds the shading points' p, n, ω_o and rounding-error bounds in lanes, and `materials`
/// their materials (none where a lane has no shading point): the rays leave them as `offset_ray_origin` moves
/// them, all eight at once, and are tested against the root of the lights' tree in lanes
/// ([`crate::scene::EmitterTree::closest_hits_lanes`]); most miss it, and nothing is gathered lane by lane for
/// those. A lane whose ray finds an emitter has its shading point made up from the lanes.
#[inline(always)]
fn mis_brdf_technique(
    contexts: &[SampleContext; 2],
    light: &impl Technique,
    materials: &[Option<&Material>; LANES],
    (p, n, wo, error): (Vec3x8, Vec3x8, Vec3x8, f32x8),
    rngs: &mut SampleRngLanes,
    rays: &mut u64,
) -> [Vec3; LANES] {
    let scene = contexts[1].scene;
    let drawn = brdf::sample_brdf_lanes(materials, (n, wo), rngs);
    let lanes = drawn.contributing;
    *rays += lanes.count_ones() as u64;
    let origins = offset_ray_origins(p, n, error);
    let found = scene.emitter_tree().closest_hits_lanes(&origins, &drawn.wi, lanes);
    let mut weighted = [Vec3::ZERO; LANES];
    let mut shadow_rays = ShadowRays::default();
    for_each_lane(lanes, |l| {
        let (Some(material), Some(hit)) = (materials[l], found[l]) else { return };
        let s = DirectionSample { wi: drawn.wi.lane(l), pdf: drawn.pdf[l], target: Target::Trace };
        let Some((value, via)) = lit_along(scene, hit, &s, (drawn.f.lane(l), drawn.cos[l])) else { return };
        let sp = ShadingPoint { p: p.lane(l), n: n.lane(l), wo: wo.lane(l), material, error: error.as_array_ref()[l] };
        shadow_rays.add_to_reached(l, scene, (sp.p, sp.n, sp.error), via);
        weighted[l] = weighted_second(contexts, light, &sp, value, via, &s);
    });
    let blocked = shadow_rays.lanes & !shadow_rays.trace(scene, contexts[1].tile, rays);
    for_each_lane(blocked, |l| weighted[l] = Vec3::ZERO);
    weighted
}

/// `f_r L_e (ω·n)` along a traced direction `s` whose nearest emitter triangle is `hit` (`f_r` and ω·n given),
/// and the point it reached, where that triangle emits towards the ray (`None` where L_e = 0): what arrives
/// unless something lies before it.
#[inline(always)]
fn lit_along(scene: &Scene, hit: Hit, s: &DirectionSample, (f, cos): (Vec3, f32)) -> Option<(Vec3, Reached)> {
    let li = scene.emitted(hit.triangle, -s.wi);
    if li == Vec3::ZERO {
        return None;
    }
    Some((f * li * cos, Reached { triangle: hit.triangle, point: scene.hit_point(&hit) }))
}

/// A second-technique sample's share, one direction per technique: `w₂ f_r L_e (ω·n) / p₂` with `value` =
/// `f_r L_e (ω·n)` and `w₂` the heuristic's weight against `light`'s density at ω (reached `via` its emitter).
#[inline(always)]
fn weighted_second(
    contexts: &[SampleContext; 2],
    light: &impl Technique,
    sp: &ShadingPoint,
    value: Vec3,
    via: Reached,
    s: &DirectionSample,
) -> Vec3 {
    let w = contexts[1].mis.heuristic.weight(1, s.pdf, 1, light.pdf(&contexts[0], sp, s.wi, Some(via)));
    value * (w / (1.0 * s.pdf))
}

/// Each lane's MIS estimate: the radiance its camera ray sees emitted, plus its first technique's weighted
/// contribution unless that direction's shadow ray was blocked (bit l of `blocked`), plus its second's.
#[inline(always)]
fn mis_sums(emitted: &[Vec3; LANES], first: &[Vec3; LANES], blocked: u32, second: &[Vec3; LANES]) -> [Vec3; LANES] {
    std::array::from_fn(|l| {
        let mut total = Vec3::ZERO;
        total += if blocked & (1 << l) != 0 { Vec3::ZERO } else { first[l] };
        total += second[l];
        emitted[l] + total
    })
}

/// Sampled directions to trace, gathered lane by lane (`integrand`'s first half: f_r and ω·n, the ray's origin off
/// the surface) and traced together, then looked up as `estimator::lit` looks them up: the nearest emitter
/// triangles on the rays (`EmitterTree::closest_hits`), then the shadow rays to those that emit towards their
/// shading points, together ([`ShadowRays`]).
#[derive(Default)]
struct TracedRays {
    rays: [(Vec3, Vec3); LANES],
    /// Per lane: the shading point the ray leaves, the direction, f_r and ω·n.
    pending: [Option<(Near, DirectionSample, Vec3, f32)>; LANES],
    lanes: u32,
}

impl TracedRays {
    /// Lane `l`'s direction `s` from `sp`, unless it contributes nothing whatever arrives along it (then no ray is
    /// traced, as in `integrand`, and the reason is returned).
    #[inline(always)]
    fn add(&mut self, l: usize, sp: &ShadingPoint, s: DirectionSample, rays: &mut u64) -> Result<(), Outcome> {
        let (f, cos) = super::estimator::brdf_and_cos(sp, &s)?;
        *rays += 1;
        self.rays[l] = (crate::math::offset_ray_origin(sp.p, sp.n, sp.error), s.wi);
        self.pending[l] = Some(((sp.p, sp.n, sp.error), s, f, cos));
        self.lanes |= 1 << l;
        Ok(())
    }

    /// Per lane: `f_r L_e (ω·n)` where the ray meets a surface that emits towards it, the emitter triangle and point
    /// it reached, and the direction; or why nothing arrives. Adds the shadow rays traced to `rays`.
    #[inline(always)]
    fn trace(
        &self,
        scene: &Scene,
        tile: &TileLights,
        rays: &mut u64,
    ) -> [Result<(Vec3, super::strategy::Reached, DirectionSample), Outcome>; LANES] {
        let found = scene.emitter_tree().closest_hits(&self.rays, self.lanes);
        let mut shadow_rays = ShadowRays::default();
        let mut lit = [Err(Outcome::MissedLights); LANES];
        for_each_lane(self.lanes, |l| {
            let (Some((near, s, f, cos)), Some(hit)) = (self.pending[l], found[l]) else { return };
            let Some((value, via)) = lit_along(scene, hit, &s, (f, cos)) else { return };
            shadow_rays.add_to_reached(l, scene, near, via);
            lit[l] = Ok((value, via, s));
        });
        let blocked = shadow_rays.lanes & !shadow_rays.trace(scene, tile, rays);
        for_each_lane(blocked, |l| lit[l] = Err(Outcome::Occluded));
        lit
    }
}

/// Where a pass that learns sends each lane's report: with the lane's shading point.
pub type LaneSink<'a> = dyn FnMut(&ShadingPoint, SampleRecord) + 'a;

/// [`super::strategy::guided`]'s estimator for up to eight samples of one pixel, bit for bit: per lane a
/// direction of the mixture; the directions aimed at a light have their shadow rays traced together, the others
/// walk the tree together, interleaved; then each value is divided by the mixture's density at its direction,
/// given the emitter it reached. With `sink` (a pass that learns), each lane's direction is reported to it as the
/// estimator reports it, with the lane's shading point. Adds the rays traced to `rays`.
#[inline]
pub fn estimate_guided_lanes(
    ctx: &SampleContext,
    dirs: &Vec3x8,
    hits: &HitLanes,
    rngs: &mut [SampleRng; LANES],
    rays: &mut u64,
    mut sink: Option<&mut LaneSink>,
) -> [Vec3; LANES] {
    use super::strategy::Reached;
    use super::strategy::guided::Drawn;
    /// What a lane knows before the rays are traced: the unshadowed value of a light's point and where it is, a
    /// ray being traced (`None`), or why nothing can arrive.
    type Known = Result<Option<(Vec3, Reached)>, Outcome>;
    let scene = ctx.scene;
    let (mut emitted, mut reflected) = ([Vec3::ZERO; LANES], [Vec3::ZERO; LANES]);
    let (mut shadow_rays, mut traced) = (ShadowRays::default(), TracedRays::default());
    let mut drawn: [Option<(ShadingPoint, Drawn, Known)>; LANES] = std::array::from_fn(|_| None);
    let mut leaf = None;
    for l in 0..LANES {
        let Some((sp, le)) = shading_point(scene, dirs, hits, l) else { continue };
        emitted[l] = le;
        let Some(d) = Drawn::draw(ctx, &sp, &mut rngs[l], &mut leaf) else { continue };
        let known = match d.s.target {
            Target::Emitter { triangle, point } => unshadowed(scene, &sp, &d.s, triangle).map(|(value, n_x)| {
                shadow_rays.add(l, scene, &sp, (triangle, point, n_x));
                Some((value, Reached { triangle, point }))
            }),
            Target::Trace => traced.add(l, &sp, d.s, rays).map(|()| None),
        };
        drawn[l] = Some((sp, d, known));
    }
    let visible = shadow_rays.trace(scene, ctx.tile, rays);
    let found = traced.trace(scene, ctx.tile, rays);
    for (l, lane) in drawn.iter().enumerate() {
        let Some((sp, d, known)) = lane else { continue };
        let result = match *known {
            Ok(Some(lit)) if visible & (1 << l) != 0 => Ok(lit),
            Ok(Some(_)) => Err(Outcome::Occluded),
            Ok(None) => found[l].map(|(value, via, _)| (value, via)),
            Err(outcome) => Err(outcome),
        };
        reflected[l] = match sink.as_deref_mut() {
            Some(sink) => {
                let (contribution, record) = d.record(ctx, sp, result);
                sink(sp, record);
                contribution
            }
            None => result.map_or(Vec3::ZERO, |(value, via)| d.weighted(ctx, sp, value, via)),
        };
    }
    std::array::from_fn(|l| emitted[l] + reflected[l])
}
