//! Lambert's azimuthal equal-area projection of the hemisphere z ≥ 0 onto the unit disk: the direction at polar
//! angle θ lands at radius `r = √(1 − cos θ)`, azimuth kept. Areas on the disk are solid angles: `dω = 2 dA`
//! (the disk's area π is the hemisphere's 2π sr), so a density drawn on it shows where the samples go, undistorted.

use glam::{Vec2, Vec3};

/// The disk point of the local direction `w` (unit, z ≥ 0): `(x, y) / √(1 + z)`.
#[inline]
pub fn hemisphere_to_disk(w: Vec3) -> Vec2 {
    let s = (1.0 + w.z.max(0.0)).sqrt();
    Vec2::new(w.x, w.y) / s
}

/// The local direction of the disk point `d` (|d| ≤ 1): `z = 1 − |d|²`, `(x, y) = d √(2 − |d|²)`.
#[inline]
pub fn disk_to_hemisphere(d: Vec2) -> Vec3 {
    let r2 = d.length_squared().min(1.0);
    let s = (2.0 - r2).sqrt();
    Vec3::new(d.x * s, d.y * s, 1.0 - r2).normalize()
}

/// Solid angle per unit disk area.
pub const SOLID_ANGLE_PER_DISK_AREA: f32 = 2.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_equal_area() {
        for i in 0..50 {
            for j in 0..50 {
                let d = Vec2::new(i as f32 / 49.0 * 2.0 - 1.0, j as f32 / 49.0 * 2.0 - 1.0);
                if d.length() > 0.999 {
                    continue;
                }
                let w = disk_to_hemisphere(d);
                assert!((w.length() - 1.0).abs() < 1e-5 && w.z >= 0.0);
                assert!((hemisphere_to_disk(w) - d).length() < 1e-5, "{d} -> {w}");
            }
        }
        // The cap θ < θ₀ (solid angle 2π(1 − cos θ₀)) is the disk of radius √(1 − cos θ₀): area π(1 − cos θ₀).
        for cos0 in [0.9f32, 0.5, 0.1] {
            let r = hemisphere_to_disk(Vec3::new((1.0 - cos0 * cos0).sqrt(), 0.0, cos0)).length();
            let (cap, disk) = (std::f32::consts::TAU * (1.0 - cos0), std::f32::consts::PI * r * r);
            assert!((cap - SOLID_ANGLE_PER_DISK_AREA * disk).abs() < 1e-5);
        }
    }
}
