//! Emitter sampling (the lecture's area-light sampling): pick an emissive triangle Δ with probability p_Δ, then
//! a uniform point x on it. Seen from the shading point p, the direction ω = (x − p)/‖x − p‖ has the solid-angle
//! density `p(ω) = p_Δ ‖x − p‖² / (A_Δ |n_Δ · ω|)`.

use super::Scene;
use crate::math::luminance;
use crate::sampling::{DiscreteDistribution, sample_uniform_triangle};
use glam::{Vec2, Vec3};

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
}

impl LightSelection {
    pub const ALL: [LightSelection; 3] = [LightSelection::Uniform, LightSelection::Area, LightSelection::Power];

    pub fn name(self) -> &'static str {
        match self {
            LightSelection::Uniform => "uniform",
            LightSelection::Area => "area",
            LightSelection::Power => "power",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }
}

/// A point on an emitter with the probability of its triangle.
#[derive(Clone, Copy, Debug)]
pub struct EmitterSample {
    pub triangle: u32,
    pub point: Vec3,
    pub p_delta: f32,
}

/// p_Δ over the scene's emissive triangles, for one [`LightSelection`].
pub struct EmitterSampler {
    distribution: DiscreteDistribution,
    /// Emitter triangle of each distribution slot.
    triangles: Vec<u32>,
    /// Slot of each scene triangle (u32::MAX where it does not emit).
    slot_of: Vec<u32>,
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
                    LightSelection::Power => {
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
        Some(Self { distribution, triangles: scene.emitters.clone(), slot_of })
    }

    /// Picks Δ with `u_select` and a uniform point on it with `u_point`.
    #[inline]
    pub fn sample(&self, scene: &Scene, u_select: f32, u_point: Vec2) -> EmitterSample {
        let (slot, p_delta) = self.distribution.sample(u_select);
        let triangle = self.triangles[slot];
        let [a, b, c] = scene.triangles[triangle as usize].v;
        EmitterSample { triangle, point: sample_uniform_triangle(u_point, a, b, c), p_delta }
    }

    /// p_Δ of a scene triangle (0 for one that does not emit).
    #[inline]
    pub fn p_delta(&self, triangle: u32) -> f32 {
        match self.slot_of.get(triangle as usize) {
            Some(&slot) if slot != u32::MAX => self.distribution.pmf(slot as usize),
            _ => 0.0,
        }
    }

    /// Solid-angle density at p of the direction towards x on triangle Δ:
    /// `p_Δ ‖x − p‖² / (A_Δ |n_Δ · ω|)`; 0 when ω grazes the triangle's plane.
    #[inline]
    pub fn pdf_solid_angle(&self, scene: &Scene, triangle: u32, p: Vec3, x: Vec3) -> f32 {
        let tri = &scene.triangles[triangle as usize];
        let d = x - p;
        let dist2 = d.length_squared();
        let cos = tri.n.dot(d).abs() / dist2.sqrt();
        let denom = tri.area * cos;
        if denom > 0.0 && dist2 > 0.0 { self.p_delta(triangle) * dist2 / denom } else { 0.0 }
    }
}
