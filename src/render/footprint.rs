//! Where in its pixel a camera ray goes: the pixel filter, or a fixed primary hit.
//!
//! With a box filter, a pixel's value is `1/A ∫_pixel L(x_film) dx`: each sample jitters its camera ray
//! uniformly over the pixel, and the estimate's error includes how L varies over the footprint (edges, a visible
//! light's outline). That noise is common to every strategy under common random numbers and can dwarf the
//! estimators' own variance. Through the pixel's centre the primary hit is fixed, the value estimated is the
//! scattering integral at that one point, and the error is the estimator's alone: the mode to *measure* in. The
//! jittered footprint stays for pictures (it antialiases).

use glam::Vec2;
use wide::f32x8;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Footprint {
    /// Uniform over the pixel (a box filter): pictures.
    #[default]
    Jittered,
    /// The pixel's centre, every sample: measurements of the estimator.
    Centre,
}

impl Footprint {
    pub const ALL: [Footprint; 2] = [Footprint::Jittered, Footprint::Centre];

    pub fn name(self) -> &'static str {
        match self {
            Footprint::Jittered => "jittered",
            Footprint::Centre => "centre",
        }
    }

    /// One line for reports and the viewer: what the error then contains.
    pub fn description(self) -> &'static str {
        match self {
            Footprint::Jittered => "jittered pixel footprint (box filter): the error includes the footprint's noise",
            Footprint::Centre => "fixed primary hits (pixel centres): the error is the estimator's alone",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The position in the pixel for a sample that drew `jitter` (uniform in [0,1)²): drawn either way, so that
    /// the rest of the sample's stream is the same in both modes.
    #[inline(always)]
    pub fn position(self, jitter: Vec2) -> Vec2 {
        match self {
            Footprint::Jittered => jitter,
            Footprint::Centre => Vec2::splat(0.5),
        }
    }

    /// [`Footprint::position`] for eight samples, one coordinate.
    #[inline(always)]
    pub fn positions(self, jitter: f32x8) -> f32x8 {
        match self {
            Footprint::Jittered => jitter,
            Footprint::Centre => f32x8::splat(0.5),
        }
    }
}
