//! Uniform points on a triangle.

use glam::{Vec2, Vec3};

/// Uniform point on the triangle (a, b, c): density `1/A_Δ` w.r.t. area. Barycentrics
/// `b₀ = 1 − √u₀, b₁ = u₁ √u₀` (Shirley & Chiu; pbrt's UniformSampleTriangle). Returns the point.
#[inline]
pub fn sample_uniform_triangle(u: Vec2, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let su0 = u.x.sqrt();
    let b0 = 1.0 - su0;
    let b1 = u.y * su0;
    a * b0 + b * b1 + c * (1.0 - b0 - b1)
}

/// Density of [`sample_uniform_triangle`]: `1/A_Δ` (area measure); 0 for a degenerate triangle.
#[inline]
pub fn uniform_triangle_pdf_area(area: f32) -> f32 {
    if area > 0.0 { 1.0 / area } else { 0.0 }
}
