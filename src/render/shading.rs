//! The shading point: where the scattering integral is evaluated.

use crate::math::gamma;
use crate::scene::{Material, Triangle};
use glam::Vec3;

/// A surface point with its normal flipped to the side ω_o is on (surfaces are two-sided).
#[derive(Clone, Copy, Debug)]
pub struct ShadingPoint<'a> {
    pub p: Vec3,
    /// Unit normal on ω_o's side: n·ω_o ≥ 0.
    pub n: Vec3,
    /// Unit direction towards the viewer.
    pub wo: Vec3,
    pub material: &'a Material,
    /// How far `p` may be off its surface (δ, see [`crate::math::SurfaceError`]): rays leave from p moved by it.
    pub error: f32,
}

impl<'a> ShadingPoint<'a> {
    /// `geometric_normal` may face either way; it is flipped towards `wo`.
    #[inline]
    pub fn new(p: Vec3, geometric_normal: Vec3, wo: Vec3, material: &'a Material) -> Self {
        let n = if geometric_normal.dot(wo) < 0.0 { -geometric_normal } else { geometric_normal };
        Self { p, n, wo, material, error: gamma(8) * p.abs().dot(n.abs()) }
    }

    /// The shading point at `p`, computed on the triangle `tri` (from barycentrics), with the triangle's bound.
    #[inline]
    pub fn on_triangle(p: Vec3, tri: &Triangle, wo: Vec3, material: &'a Material) -> Self {
        Self { error: tri.error.at_point, ..Self::new(p, tri.n, wo, material) }
    }
}
