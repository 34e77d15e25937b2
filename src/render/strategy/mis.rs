//! Multiple importance sampling (Veach & Guibas 1995; Veach 1997 ch. 9), multi-sample form: per pixel sample,
//! n_l directions from a light strategy and n_b from BRDF sampling, each weighted by
//! `w_i(ω) = (n_i p_i(ω))^β / Σ_j (n_j p_j(ω))^β` (β = 1: balance heuristic, β = 2: power heuristic):
//!
//! `F = Σ_{k<n_l} w_l f L cos / (n_l p_l) + Σ_{k<n_b} w_b f L cos / (n_b p_b)`.
//!
//! The weights of the two techniques sum to one for every direction, so F is unbiased; a weight that is not
//! finite is 0 (Mitsuba's rule).

use super::light::LightTechnique;

pub const DESCRIPTION: &str = "multiple importance sampling: a light strategy and BRDF sampling, weighted (Veach 1995)";
pub const PDF: &str = "w_i = (n_i p_i)^β / Σ_j (n_j p_j)^β,  β = 1 balance, 2 power";

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Heuristic {
    Balance,
    #[default]
    Power,
}

impl Heuristic {
    pub const ALL: [Heuristic; 2] = [Heuristic::Balance, Heuristic::Power];

    pub fn name(self) -> &'static str {
        match self {
            Heuristic::Balance => "balance",
            Heuristic::Power => "power",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|h| h.name() == name)
    }

    /// The weight of technique a (n_a samples, density p_a) against b; 0 where not finite.
    #[inline]
    pub fn weight(self, n_a: u32, p_a: f32, n_b: u32, p_b: f32) -> f32 {
        let (a, b) = (n_a as f32 * p_a, n_b as f32 * p_b);
        let w = match self {
            Heuristic::Balance => a / (a + b),
            Heuristic::Power => (a * a) / (a * a + b * b),
        };
        if w.is_finite() { w } else { 0.0 }
    }
}

/// How MIS combines its techniques.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MisSettings {
    pub light: LightTechnique,
    pub heuristic: Heuristic,
    /// Light samples per pixel sample (n_l).
    pub light_samples: u32,
    /// BRDF samples per pixel sample (n_b).
    pub brdf_samples: u32,
}

impl Default for MisSettings {
    fn default() -> Self {
        Self { light: LightTechnique::Area, heuristic: Heuristic::Power, light_samples: 1, brdf_samples: 1 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one_and_are_finite() {
        for h in Heuristic::ALL {
            for (pa, pb) in [(1.0, 1.0), (1e-30, 3.0), (5e3, 1e-3), (0.0, 2.0), (f32::MAX, 1.0)] {
                for (na, nb) in [(1, 1), (3, 1), (1, 4)] {
                    let (wa, wb) = (h.weight(na, pa, nb, pb), h.weight(nb, pb, na, pa));
                    assert!(wa.is_finite() && wb.is_finite());
                    if pa > 0.0 && pa < 1e30 {
                        assert!((wa + wb - 1.0).abs() < 1e-6, "{h:?} {pa} {pb}: {wa} + {wb}");
                    }
                }
            }
            assert_eq!(h.weight(1, f32::INFINITY, 1, f32::INFINITY), 0.0);
        }
    }
}
