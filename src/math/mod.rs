//! Pure math: orthonormal frames, robust ray origins, seeded per-sample randomness, spherical geometry and
//! eight-lane vectors.

mod frame;
mod offset;
mod polygon;
mod rng;
mod vec3x8;

pub use frame::Frame;
pub use offset::{offset_ray_origin, offset_ray_origins};
pub use polygon::lambert_polygon_irradiance;
pub use rng::{ONE_MINUS_EPSILON, PixelStreams, SampleRng};
pub use vec3x8::Vec3x8;

/// Reflects `w` about the unit normal `n`: ω_r = 2 (n·ω) n − ω (the lecture's mirror direction).
#[inline]
pub fn reflect(w: glam::Vec3, n: glam::Vec3) -> glam::Vec3 {
    2.0 * n.dot(w) * n - w
}

/// Luminance of a linear Rec. 709 / sRGB colour (ITU-R BT.709 weights).
#[inline]
pub fn luminance(c: glam::Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}
