//! Pure math: orthonormal frames, robust ray origins, seeded per-sample randomness, spherical geometry,
//! eight-lane vectors, the samplers' sin and cos, and denormals flushed while rendering.

mod denormals;
mod equal_area;
mod frame;
mod offset;
mod phong_polygon;
mod polygon;
mod rng;
mod trig;
mod vec3x8;

pub use denormals::without_denormals;
pub use equal_area::{SOLID_ANGLE_PER_DISK_AREA, disk_to_hemisphere, hemisphere_to_disk};
pub use frame::Frame;
pub use offset::{SurfaceError, SurfaceErrorLanes, gamma, offset_ray_origin, offset_ray_origins};
pub use phong_polygon::phong_polygon_moment;
pub use polygon::lambert_polygon_irradiance;
pub use rng::{ONE_MINUS_EPSILON, PixelStreams, SampleRng, SampleRngLanes, hash_ray, mix64};
pub use trig::{acos_f64_lanes, asin_f64, asin_f64_lanes, sin_cos, sin_cos_f64, sin_cos_f64_lanes, sin_cos_lanes};
pub use vec3x8::Vec3x8;

/// Reflects `w` about the unit normal `n`: ω_r = 2 (n·ω) n − ω (the lecture's mirror direction).
#[inline]
pub fn reflect(w: glam::Vec3, n: glam::Vec3) -> glam::Vec3 {
    2.0 * n.dot(w) * n - w
}

/// Calls `f` with the index of each set bit of a lane mask (bit i for lane i), lowest first: a loop over the
/// lanes that go on, where a branch per lane would be mispredicted when which lanes go on varies at random.
#[inline(always)]
pub fn for_each_lane(mut bits: u32, mut f: impl FnMut(usize)) {
    while bits != 0 {
        f(bits.trailing_zeros() as usize);
        bits &= bits - 1;
    }
}

/// The lane mask of a bit mask: all bits set in lane l where bit l of `bits` is (a comparison's true), none
/// elsewhere.
#[inline(always)]
pub fn lane_mask(bits: u32) -> wide::i32x8 {
    use wide::CmpEq;
    let lanes = wide::i32x8::new([1, 2, 4, 8, 16, 32, 64, 128]);
    (wide::i32x8::splat(bits as i32) & lanes).cmp_eq(lanes)
}

/// The lanes l whose index `indices[l]` is in the set `set` (bit i for index i, i < 31; other indices, negative
/// ones too, are in none), as a bit mask.
#[inline(always)]
pub fn lanes_in(set: u32, indices: wide::i32x8) -> u32 {
    use wide::{CmpEq, CmpLt, i32x8};
    // Negative indices and those past 30 shift to bit 31, which is clear.
    let last = i32x8::splat(31);
    let shift = indices.cmp_lt(i32x8::ZERO).blend(last, indices.min(last));
    let bit = (i32x8::splat((set & !(1 << 31)) as i32) >> shift) & i32x8::ONE;
    let on: wide::f32x8 = bytemuck::cast(bit.cmp_eq(i32x8::ONE));
    on.move_mask() as u32
}

/// The lanes l with `values[l] == value`, as a bit mask (bit l for lane l): one vector comparison.
#[inline(always)]
pub fn lanes_equal(values: &[u32; 8], value: u32) -> u32 {
    use wide::{CmpEq, i32x8};
    let equal = i32x8::new(values.map(|v| v as i32)).cmp_eq(i32x8::splat(value as i32));
    let on: wide::f32x8 = bytemuck::cast(equal);
    on.move_mask() as u32
}

/// The weights of [`luminance`].
const LUMINANCE: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// Luminance of a linear Rec. 709 / sRGB colour (ITU-R BT.709 weights).
#[inline]
pub fn luminance(c: glam::Vec3) -> f32 {
    LUMINANCE[0] * c.x + LUMINANCE[1] * c.y + LUMINANCE[2] * c.z
}

/// [`luminance`] of eight colours, one per lane: the same products summed in the same order, bit for bit.
#[inline(always)]
pub fn luminance_lanes(c: &Vec3x8) -> wide::f32x8 {
    use wide::f32x8;
    f32x8::splat(LUMINANCE[0]) * c.x + f32x8::splat(LUMINANCE[1]) * c.y + f32x8::splat(LUMINANCE[2]) * c.z
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn for_each_lane_visits_the_set_bits_in_order() {
        for bits in [0u32, 1, 0b1010_0110, 0xff, 1 << 31] {
            let mut seen = Vec::new();
            for_each_lane(bits, |l| seen.push(l));
            let expected: Vec<usize> = (0..32).filter(|&l| bits & (1 << l) != 0).collect();
            assert_eq!(seen, expected, "bits {bits:#b}");
        }
    }

    #[test]
    fn lanes_in_reads_each_lanes_bit_of_the_set() {
        let indices = wide::i32x8::new([0, 1, 2, 7, 30, 31, 40, -1]);
        assert_eq!(lanes_in(0b1000_0101, indices), 0b1101);
        assert_eq!(lanes_in(u32::MAX, indices), 0b1_1111, "indices past 30 and negative ones are in none");
        assert_eq!(lanes_in(0, indices), 0);
    }

    #[test]
    fn lane_mask_sets_the_lanes_of_the_bits() {
        for bits in [0u32, 1, 0b1010_0110, 0xff, 0x1ff] {
            let expected: [i32; 8] = std::array::from_fn(|l| if bits & (1 << l) != 0 { -1 } else { 0 });
            assert_eq!(lane_mask(bits).to_array(), expected, "bits {bits:#b}");
        }
    }
}
