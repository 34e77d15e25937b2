//! Light selection: the probability p_Δ with which a light strategy picks the emissive triangle Δ.

use super::{SKIP_NONE, Scene};
use crate::math::{SurfaceError, SurfaceErrorLanes, Vec3x8, lane_mask, luminance};
use crate::sampling::{DiscreteDistribution, IndexSteps};
use glam::Vec3;
use wide::{f32x8, i32x8};

/// How p_Δ is chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum LightSelection {
    /// p_Δ = 1 / (number of emissive triangles).
    Uniform,
    /// p_Δ ∝ A_Δ.
    Area,
    /// p_Δ ∝ A_Δ × luminance(L_e): proportional to emitted power.
    #[default]
    Power,
    /// p_Δ ∝ luminance(L_e) × min(A_Δ cos θ_Δ / d², 2π) at the shading point: an estimate of each triangle's
    /// contribution there (solid angle × radiance, in the small-triangle limit); 0 for triangles facing away.
    /// Costs O(number of emitter triangles) per sample.
    Contribution,
}

impl LightSelection {
    pub const ALL: [LightSelection; 4] =
        [LightSelection::Uniform, LightSelection::Area, LightSelection::Power, LightSelection::Contribution];

    pub fn name(self) -> &'static str {
        match self {
            LightSelection::Uniform => "uniform",
            LightSelection::Area => "area",
            LightSelection::Power => "power",
            LightSelection::Contribution => "contribution",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }
}

/// p_Δ over the scene's emissive triangles, for one [`LightSelection`].
pub struct EmitterSampler {
    selection: LightSelection,
    /// For the selections that do not depend on the shading point.
    distribution: DiscreteDistribution,
    /// Emitter triangle of each distribution slot.
    triangles: Vec<u32>,
    /// Slot of each scene triangle (u32::MAX where it does not emit).
    slot_of: Vec<u32>,
    /// What light sampling reads of each slot's triangle, with its p_Δ, for the selections that do not depend on
    /// the shading point (empty for the others).
    records: Vec<EmitterTriangle>,
    /// The records in vectors, for at most [`FIELD_TABLE_SLOTS`] of them.
    table: Option<FieldTable>,
}

/// The most records [`EmitterSampler::pick_fields`] holds in vectors (lane 7 stands for no light).
const FIELD_TABLE_SLOTS: usize = 7;

/// A few records as vectors: field k of every record's rows ([`EmitterTriangle::rows`]) in one vector, record s
/// in lane s, [`EmitterTriangle::NONE`]'s in the lanes after them, and the alias table as a step function of u
/// ([`IndexSteps`]): eight picks take a compare, an and and an add per step, then read each field with one
/// permute, instead of eight table walks, sixteen loads and two transposes.
struct FieldTable {
    steps: IndexSteps,
    fields: [f32x8; 16],
    /// The records' offset bounds (`at_point`, then `per_distance`), as the fields are held.
    errors: [f32x8; 4],
    /// The emitted radiance L_e of each record's material (x, y, z), zero for [`EmitterTriangle::NONE`].
    emission: [f32x8; 3],
}

/// Eight lanes' picks with the picked records read from a [`FieldTable`] ([`EmitterSampler::pick_fields`]).
pub struct PickedFields {
    /// The slot picked in each lane (7 in the lanes that pick nothing).
    pub slots: i32x8,
    /// Field k of each picked record's rows ([`EmitterTriangle::rows`]) in vector k.
    pub fields: [f32x8; 16],
    /// The picked records' offset bounds.
    pub errors: SurfaceErrorLanes,
    /// The emitted radiance L_e of each picked triangle's material (zero where nothing is picked).
    pub emission: Vec3x8,
}

/// Values per slot as vectors: value k of slot s in lane s of vector k, for the [`FieldTable`]'s slots (the lanes
/// after the records' hold what `value` gives for them: [`EmitterTriangle::NONE`]'s).
fn by_slot<const K: usize>(value: impl Fn(usize) -> [f32; K]) -> [f32x8; K] {
    let slots: [[f32; K]; 8] = std::array::from_fn(value);
    std::array::from_fn(|k| f32x8::new(slots.map(|v| v[k])))
}

/// An emitter triangle as light sampling reads it, with its p_Δ, in one aligned record (its first cache line
/// holds what sampling reads, the second the offset bounds the shadow ray reads later): picking one costs one
/// load after the alias table's, where going through the slot's triangle index and the scene's triangle list
/// costs two more, each waiting on the one before.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct EmitterTriangle {
    pub v: [Vec3; 3],
    /// The unit normal n_Δ.
    pub n: Vec3,
    /// A_Δ.
    pub area: f32,
    pub p_delta: f32,
    pub material: u32,
    /// [`Scene::convex_group`] of the triangle, or [`SKIP_NONE`] (an `Option` would not fit the cache line).
    pub convex_group: u32,
    /// The triangle's [`Triangle::error`](super::Triangle::error), for the shadow ray's far end.
    pub error: SurfaceError,
}

impl EmitterTriangle {
    /// What an eight-lane estimator reads for a lane with no light: no material, no group, p_Δ = 0.
    pub const NONE: Self = Self {
        v: [Vec3::ZERO; 3],
        n: Vec3::ZERO,
        area: 1.0,
        p_delta: 0.0,
        material: u32::MAX,
        convex_group: SKIP_NONE,
        error: SurfaceError { at_point: 0.0, per_distance: Vec3::ZERO },
    };

    /// The record of the scene's triangle `t`, picked with probability `p_delta`.
    #[inline(always)]
    pub fn of(scene: &Scene, t: u32, p_delta: f32) -> Self {
        let tri = &scene.triangles[t as usize];
        let convex_group = scene.convex_group(t).unwrap_or(SKIP_NONE);
        Self { v: tri.v, n: tri.n, area: tri.area, p_delta, material: tri.material, convex_group, error: tri.error }
    }

    /// The record as two rows of eight, in field order (`v₀ v₁ v₂.xy`, then `v₂.z n_Δ A_Δ p_Δ material group`,
    /// the last two as bits): eight records' rows transpose (`f32x8::transpose`) into one vector per field.
    #[inline(always)]
    pub fn rows(&self) -> [f32x8; 2] {
        let ([a, b, c], n) = (self.v, self.n);
        let (material, group) = (f32::from_bits(self.material), f32::from_bits(self.convex_group));
        [Vec3x8::triangle_row([a, b, c]), f32x8::new([c.z, n.x, n.y, n.z, self.area, self.p_delta, material, group])]
    }
}

impl EmitterSampler {
    /// `None` when the scene has nothing to sample (no emissive triangle of non-zero area and power).
    pub fn new(scene: &Scene, selection: LightSelection) -> Option<Self> {
        let weights: Vec<f64> = scene
            .emitters
            .iter()
            .map(|&t| {
                let tri = &scene.triangles[t as usize];
                let area = tri.area as f64;
                match selection {
                    LightSelection::Uniform => {
                        if area > 0.0 {
                            1.0
                        } else {
                            0.0
                        }
                    }
                    LightSelection::Area => area,
                    LightSelection::Power | LightSelection::Contribution => {
                        area * luminance(scene.materials[tri.material as usize].emission).max(0.0) as f64
                    }
                }
            })
            .collect();
        let distribution = DiscreteDistribution::new(&weights)?;
        let mut slot_of = vec![u32::MAX; scene.triangles.len()];
        for (slot, &t) in scene.emitters.iter().enumerate() {
            slot_of[t as usize] = slot as u32;
        }
        let records = if selection == LightSelection::Contribution {
            Vec::new()
        } else {
            let record = |(slot, &t): (usize, &u32)| EmitterTriangle::of(scene, t, distribution.pmf(slot));
            scene.emitters.iter().enumerate().map(record).collect()
        };
        let small = !records.is_empty() && records.len() <= FIELD_TABLE_SLOTS;
        let table = distribution.steps().filter(|_| small).map(|steps| {
            let record = |s: usize| records.get(s).unwrap_or(&EmitterTriangle::NONE);
            let fields = by_slot(|s| {
                let [low, high] = record(s).rows();
                std::array::from_fn(|k| if k < 8 { low.as_array_ref()[k] } else { high.as_array_ref()[k - 8] })
            });
            let errors = by_slot(|s| {
                let SurfaceError { at_point, per_distance: w } = record(s).error;
                [at_point, w.x, w.y, w.z]
            });
            let emission = by_slot(|s| {
                records.get(s).map_or(Vec3::ZERO, |r| scene.materials[r.material as usize].emission).to_array()
            });
            FieldTable { steps, fields, errors, emission }
        });
        Some(Self { selection, distribution, triangles: scene.emitters.clone(), slot_of, records, table })
    }

    pub fn selection(&self) -> LightSelection {
        self.selection
    }

    /// The scene's emitter triangles, in the selection's order.
    pub fn triangles(&self) -> &[u32] {
        &self.triangles
    }

    /// What [`EmitterSampler::pick`] picks for eight uniforms (slot and record i for `u[i]`), as light sampling
    /// reads it, for the selections that do not depend on the shading point (`None` for
    /// [`LightSelection::Contribution`]).
    #[inline(always)]
    pub fn pick_fixed_lanes(&self, u: [f32; 8]) -> Option<([usize; 8], [&EmitterTriangle; 8])> {
        if self.records.is_empty() {
            return None;
        }
        let slots = self.distribution.sample_indices(u);
        Some((slots, slots.map(|i| &self.records[i])))
    }

    /// What [`EmitterSampler::pick`] picks for eight uniforms, in the lanes of `lanes` (bit l for lane l): the
    /// slot picked with `u`'s lane l in lane l (7 in the other lanes), field k ([`EmitterTriangle::rows`]' k-th
    /// value) of its record, its offset bounds and its material's L_e ([`EmitterTriangle::NONE`]'s, and no
    /// light, in the other lanes). `None` where the records are not held in vectors (more than seven, or a
    /// selection that depends on the shading point).
    #[inline(always)]
    pub fn pick_fields(&self, u: f32x8, lanes: u32) -> Option<PickedFields> {
        let table = self.table.as_ref()?;
        let slots = lane_mask(lanes).blend(table.steps.indices(u), i32x8::splat(7));
        let [at_point, x, y, z] = table.errors.map(|field| lane_lookup(field, slots));
        let errors = SurfaceErrorLanes { at_point, per_distance: Vec3x8::new(x, y, z) };
        let [r, g, b] = table.emission.map(|field| lane_lookup(field, slots));
        let fields = table.fields.map(|field| lane_lookup(field, slots));
        Some(PickedFields { slots, fields, errors, emission: Vec3x8::new(r, g, b) })
    }

    /// The slot of the scene's triangle `triangle` (its place in `Scene::emitters`), u32::MAX where it does not
    /// emit.
    #[inline]
    pub fn slot(&self, triangle: u32) -> u32 {
        self.slot_of.get(triangle as usize).copied().unwrap_or(u32::MAX)
    }

    /// Picks an emitter triangle Δ for the shading point p with one uniform; returns it and p_Δ. `None` where
    /// the selection gives every triangle weight 0 at p.
    #[inline(always)]
    pub fn pick(&self, scene: &Scene, p: Vec3, u: f32) -> Option<(u32, f32)> {
        if self.selection != LightSelection::Contribution {
            let (slot, p_delta) = self.distribution.sample(u);
            return Some((self.triangles[slot], p_delta));
        }
        self.pick_by_contribution(scene, p, u)
    }

    /// [`EmitterSampler::pick`] for [`LightSelection::Contribution`]: the weights are computed at p.
    #[inline(never)]
    fn pick_by_contribution(&self, scene: &Scene, p: Vec3, u: f32) -> Option<(u32, f32)> {
        let total: f64 = self.triangles.iter().map(|&t| contribution(scene, t, p)).sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let target = u as f64 * total;
        let mut acc = 0.0;
        let mut last = None;
        for &t in &self.triangles {
            let w = contribution(scene, t, p);
            if w > 0.0 {
                acc += w;
                last = Some((t, w));
                if target < acc {
                    break;
                }
            }
        }
        last.map(|(t, w)| (t, (w / total) as f32))
    }

    /// p_Δ of a scene triangle at the shading point p (0 for one that does not emit).
    #[inline]
    pub fn p_delta(&self, scene: &Scene, triangle: u32, p: Vec3) -> f32 {
        let Some(&slot) = self.slot_of.get(triangle as usize).filter(|&&s| s != u32::MAX) else { return 0.0 };
        if self.selection != LightSelection::Contribution {
            return self.distribution.pmf(slot as usize);
        }
        let total: f64 = self.triangles.iter().map(|&t| contribution(scene, t, p)).sum();
        let w = contribution(scene, triangle, p);
        if total > 0.0 { (w / total) as f32 } else { 0.0 }
    }
}

/// luminance(L_e) × min(A cos θ_Δ / d², 2π) from p to the triangle's centroid; 0 when p is behind it.
#[inline]
fn contribution(scene: &Scene, t: u32, p: Vec3) -> f64 {
    let tri = &scene.triangles[t as usize];
    let centroid = (tri.v[0] + tri.v[1] + tri.v[2]) / 3.0;
    let d = (p - centroid).as_dvec3();
    let d2 = d.length_squared();
    let cos = tri.n.as_dvec3().dot(d);
    if !(cos > 0.0) || tri.n.dot(p - tri.v[0]) <= 0.0 {
        return 0.0;
    }
    let solid_angle = (tri.area as f64 * cos / (d2 * d2.sqrt())).min(std::f64::consts::TAU);
    let l = luminance(scene.materials[tri.material as usize].emission).max(0.0) as f64;
    if solid_angle.is_finite() { solid_angle * l } else { std::f64::consts::TAU * l }
}

/// Lane `index[l]` of `table` in lane l (each index below 8): one `vpermps` where the build has AVX2.
#[inline(always)]
fn lane_lookup(table: f32x8, index: i32x8) -> f32x8 {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    {
        let index: safe_arch::m256i = bytemuck::cast(index);
        bytemuck::cast(safe_arch::shuffle_av_i32_all_m256(bytemuck::cast(table), index))
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    {
        f32x8::new(index.to_array().map(|i| table.as_array_ref()[i as usize]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load_scene;

    /// The records (and, for a scene of few emitter triangles, their fields in vectors) hold what `pick` picks.
    #[test]
    fn records_hold_what_pick_picks() {
        for (name, selection) in
            ["veach-mis", "cornell-box"].into_iter().flat_map(|n| LightSelection::ALL.map(|s| (n, s)))
        {
            let scene = load_scene(name).unwrap();
            let sampler = EmitterSampler::new(&scene, selection).unwrap();
            let fixed = selection != LightSelection::Contribution;
            assert_eq!(sampler.table.is_some(), fixed && scene.emitters.len() <= FIELD_TABLE_SLOTS, "{name}");
            for i in (0..10_000).step_by(8) {
                let u = std::array::from_fn(|l| (i + l) as f32 / 10_000.0);
                let Some((slots, records)) = sampler.pick_fixed_lanes(u) else {
                    assert_eq!(selection, LightSelection::Contribution);
                    continue;
                };
                let lanes = (i as u32 * 37) & 0xff;
                if let Some(PickedFields { slots: picked, fields, errors, emission }) =
                    sampler.pick_fields(f32x8::new(u), lanes)
                {
                    for (l, record) in records.iter().enumerate() {
                        let on = lanes & (1 << l) != 0;
                        assert_eq!(picked.as_array_ref()[l], if on { slots[l] as i32 } else { 7 });
                        assert!(std::ptr::eq(&sampler.records[slots[l]], *record));
                        let rows = if on { record.rows() } else { EmitterTriangle::NONE.rows() };
                        let row = |k: usize| fields[k].as_array_ref()[l].to_bits();
                        assert!((0..16).all(|k| row(k) == rows[k / 8].as_array_ref()[k % 8].to_bits()));
                        let error = if on { record.error } else { EmitterTriangle::NONE.error };
                        let (at_point, per_distance) = (errors.at_point.as_array_ref()[l], errors.per_distance.lane(l));
                        assert_eq!(SurfaceError { at_point, per_distance }, error);
                        let le = if on { scene.materials[record.material as usize].emission } else { Vec3::ZERO };
                        assert_eq!(emission.lane(l).to_array().map(f32::to_bits), le.to_array().map(f32::to_bits));
                    }
                }
                for ((e, u), slot) in records.iter().zip(u).zip(slots) {
                    let (t, p_delta) = sampler.pick(&scene, Vec3::ZERO, u).unwrap();
                    assert_eq!((scene.emitters[slot], sampler.slot(t)), (t, slot as u32));
                    let tri = &scene.triangles[t as usize];
                    let record = (e.v, e.n, e.area, e.p_delta, e.material);
                    assert_eq!(record, (tri.v, tri.n, tri.area, p_delta, tri.material));
                    assert_eq!(e.convex_group, scene.convex_group(t).unwrap_or(SKIP_NONE));
                }
            }
        }
    }
}
