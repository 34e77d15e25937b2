//! Pinhole camera. It looks from `eye` to `target`; `up` is up in the image and the image's right is
//! forward × up (as in Mitsuba and pbrt). Row 0 is the image's top row.

use crate::math::Vec3x8;
use crate::scene::SceneError;
use glam::{Vec2, Vec3};
use wide::f32x8;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y: f32,
    pub width: u32,
    pub height: u32,
}

/// What [`Camera::basis`] precomputes for generating rays.
#[derive(Clone, Copy, Debug)]
pub struct CameraBasis {
    eye: Vec3,
    forward: Vec3,
    /// Right, scaled to the half-width of the image plane at distance 1.
    right: Vec3,
    /// Up, scaled to the half-height of the image plane at distance 1.
    up: Vec3,
    inv_size: Vec2,
}

impl Camera {
    /// This camera at another resolution: `long_side` pixels on its longer side, with the aspect of `home`.
    pub fn with_long_side(&self, home: &Camera, long_side: u32) -> Camera {
        let (w, h) = (home.width as f32, home.height as f32);
        let long_side = long_side.clamp(1, 16384);
        let (width, height) = if w >= h {
            (long_side, ((long_side as f32 * h / w).round() as u32).max(1))
        } else {
            (((long_side as f32 * w / h).round() as u32).max(1), long_side)
        };
        Camera { width, height, ..*self }
    }

    /// Checks every value; the error names the offending field.
    pub fn validate(&self) -> Result<(), SceneError> {
        let bad = |what: &str| Err(SceneError::Camera(what.to_string()));
        if !(self.eye.is_finite() && self.target.is_finite() && self.up.is_finite()) {
            return bad("eye, target and up must be finite");
        }
        let forward = self.target - self.eye;
        if forward.length_squared() <= f32::MIN_POSITIVE {
            return bad("eye and target coincide");
        }
        if forward.normalize().cross(self.up).length_squared() <= 1e-12 {
            return bad("up is zero or parallel to the viewing direction");
        }
        if !(self.fov_y > 0.0 && self.fov_y < 180.0) {
            return bad("fov_y must be between 0 and 180 degrees");
        }
        if self.width == 0 || self.height == 0 || self.width > 16384 || self.height > 16384 {
            return bad("width and height must be between 1 and 16384");
        }
        Ok(())
    }

    pub fn basis(&self) -> CameraBasis {
        let forward = (self.target - self.eye).normalize();
        let right = forward.cross(self.up).normalize();
        let up = right.cross(forward);
        let half_h = (0.5 * self.fov_y.to_radians()).tan();
        let half_w = half_h * self.width as f32 / self.height as f32;
        CameraBasis {
            eye: self.eye,
            forward,
            right: right * half_w,
            up: up * half_h,
            inv_size: Vec2::new(1.0 / self.width as f32, 1.0 / self.height as f32),
        }
    }
}

impl CameraBasis {
    /// Unit direction through the film position `(x, y) + jitter` in pixels (box filter: jitter uniform in
    /// [0, 1)²); y grows downwards.
    #[inline]
    pub fn direction(&self, x: u32, y: u32, jitter: Vec2) -> Vec3 {
        let ndc = (Vec2::new(x as f32, y as f32) + jitter) * self.inv_size * 2.0 - Vec2::ONE;
        (self.forward + self.right * ndc.x - self.up * ndc.y).normalize()
    }

    /// [`CameraBasis::direction`] for eight jitters `(jitter_x, jitter_y)` at once, one per lane, each equal to the
    /// scalar one bit for bit.
    #[inline]
    pub fn directions(&self, x: u32, y: u32, jitter_x: f32x8, jitter_y: f32x8) -> Vec3x8 {
        let ndc = |pixel: u32, jitter: f32x8, inv_size: f32| {
            (f32x8::splat(pixel as f32) + jitter) * f32x8::splat(inv_size) * f32x8::splat(2.0) - f32x8::ONE
        };
        let ndc_x = ndc(x, jitter_x, self.inv_size.x);
        let ndc_y = ndc(y, jitter_y, self.inv_size.y);
        (Vec3x8::splat(self.forward) + Vec3x8::splat(self.right) * ndc_x - Vec3x8::splat(self.up) * ndc_y).normalize()
    }

    /// Directions (not unit) through the corners of pixel (x, y), enlarged by 1/64 of a pixel on every side,
    /// in order around it: every [`CameraBasis::direction`] of the pixel lies strictly inside the cone they span,
    /// whatever the rounding.
    pub fn pixel_corners(&self, x: u32, y: u32) -> [Vec3; 4] {
        const MARGIN: f32 = 1.0 / 64.0;
        let (lo, hi) = (-MARGIN, 1.0 + MARGIN);
        [(lo, lo), (hi, lo), (hi, hi), (lo, hi)].map(|(jx, jy)| {
            let ndc = (Vec2::new(x as f32 + jx, y as f32 + jy)) * self.inv_size * 2.0 - Vec2::ONE;
            self.forward + self.right * ndc.x - self.up * ndc.y
        })
    }

    #[inline]
    pub fn eye(&self) -> Vec3 {
        self.eye
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera { eye: Vec3::ZERO, target: -Vec3::Z, up: Vec3::Y, fov_y: 90.0, width: 200, height: 100 }
    }

    #[test]
    fn another_resolution_keeps_the_aspect() {
        let c = cam().with_long_side(&cam(), 512);
        assert_eq!((c.width, c.height), (512, 256));
        let tall = Camera { width: 100, height: 200, ..cam() };
        assert_eq!((c.with_long_side(&tall, 64).width, c.with_long_side(&tall, 64).height), (32, 64));
    }

    #[test]
    fn orientation_matches_mitsuba() {
        let b = cam().basis();
        let centre = b.direction(100, 50, Vec2::ZERO);
        assert!((centre + Vec3::Z).length() < 1e-6);
        // Top-left pixel looks up and to the left (right = forward × up = +x).
        let tl = b.direction(0, 0, Vec2::ZERO);
        assert!(tl.x < 0.0 && tl.y > 0.0);
        // 90° vertical: the top edge is at 45°, the left edge at atan(2).
        assert!((tl.y / -tl.z - 1.0).abs() < 1e-6);
        assert!((tl.x / tl.z - 2.0).abs() < 1e-6);
    }

    #[test]
    fn invalid_cameras_are_rejected() {
        let mut c = cam();
        c.up = -Vec3::Z;
        assert!(c.validate().is_err());
        let mut c = cam();
        c.fov_y = 180.0;
        assert!(c.validate().is_err());
        let mut c = cam();
        c.width = 0;
        assert!(c.validate().is_err());
        let mut c = cam();
        c.eye = Vec3::NAN;
        assert!(c.validate().is_err());
        assert!(cam().validate().is_ok());
    }
}
