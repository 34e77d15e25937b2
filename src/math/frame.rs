//! Orthonormal basis around a unit vector (local frame with z = n).

use glam::Vec3;

/// An orthonormal frame `(s, t, n)`; `to_local` maps world → local (z = n), `to_world` the inverse.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// Builds a frame around the unit vector `n` without branches on a threshold
    /// (Duff et al. 2017, "Building an Orthonormal Basis, Revisited", JCGT 6(1)).
    #[inline]
    pub fn from_z(n: Vec3) -> Self {
        debug_assert!(n.is_finite());
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Self { s, t, n }
    }

    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }

    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_invertible() {
        let dirs = [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.0, -1.0, 1e-8).normalize(),
            Vec3::new(1.0, 2.0, -3.0).normalize(),
            Vec3::new(-1e-7, 0.0, -1.0).normalize(),
        ];
        for n in dirs {
            let f = Frame::from_z(n);
            for (a, b) in [(f.s, f.t), (f.t, f.n), (f.s, f.n)] {
                assert!(a.dot(b).abs() < 1e-6, "{n:?}");
            }
            for v in [f.s, f.t, f.n] {
                assert!((v.length() - 1.0).abs() < 1e-6);
            }
            assert!((f.s.cross(f.t) - f.n).length() < 1e-5, "right-handed");
            let w = Vec3::new(0.3, -0.5, 0.7);
            assert!((f.to_world(f.to_local(w)) - w).length() < 1e-6);
        }
    }
}
