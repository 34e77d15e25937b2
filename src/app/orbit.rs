//! Orbit, pan and zoom of the pinhole camera about its target (pure math: the viewport maps mouse motion to
//! these).

use crate::scene::Camera;
use glam::Quat;

/// Turns the eye about the target: `yaw` radians about the camera's up axis, `pitch` about its right axis.
/// The pitch stops a little short of the poles, where `up` and the view direction would coincide.
pub fn orbit(c: &Camera, yaw: f32, pitch: f32) -> Camera {
    let offset = c.eye - c.target;
    let up = c.up.normalize();
    let right = (-offset).normalize().cross(up).normalize();
    let elevation = offset.normalize().dot(up).clamp(-1.0, 1.0).asin();
    let max = 89f32.to_radians();
    let pitch = (elevation + pitch).clamp(-max, max) - elevation;
    let rotation = Quat::from_axis_angle(up, -yaw) * Quat::from_axis_angle(right, -pitch);
    Camera { eye: c.target + rotation * offset, ..*c }
}

/// Moves eye and target together within the image plane, by fractions of the view's height at the target.
pub fn pan(c: &Camera, dx: f32, dy: f32) -> Camera {
    let forward = c.target - c.eye;
    let distance = forward.length();
    let right = forward.normalize().cross(c.up).normalize();
    let up = right.cross(forward.normalize());
    let height = 2.0 * distance * (0.5 * c.fov_y.to_radians()).tan();
    let shift = (-right * dx + up * dy) * height;
    Camera { eye: c.eye + shift, target: c.target + shift, ..*c }
}

/// Moves the eye towards the target by the factor `scale` of their distance (< 1 zooms in); never onto it.
pub fn zoom(c: &Camera, scale: f32) -> Camera {
    let offset = c.eye - c.target;
    let d = (offset.length() * scale).max(1e-4);
    Camera { eye: c.target + offset.normalize() * d, ..*c }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn cam() -> Camera {
        Camera {
            eye: Vec3::new(0.0, 1.0, 4.0),
            target: Vec3::new(0.0, 1.0, 0.0),
            up: Vec3::Y,
            fov_y: 40.0,
            width: 320,
            height: 240,
        }
    }

    #[test]
    fn orbit_keeps_distance_and_stays_valid() {
        let c = cam();
        let o = orbit(&c, 0.7, 0.3);
        assert!(((o.eye - o.target).length() - 4.0).abs() < 1e-4);
        assert!(o.validate().is_ok());
        // Pitching far past the pole stops short of it.
        let p = orbit(&c, 0.0, 10.0);
        assert!(p.validate().is_ok());
        assert!((p.eye - p.target).normalize().dot(Vec3::Y) < 0.9999);
    }

    #[test]
    fn pan_and_zoom() {
        let c = cam();
        let p = pan(&c, 0.1, 0.0);
        assert!((p.eye - p.target - (c.eye - c.target)).length() < 1e-5);
        assert!(p.target.x < 0.0, "dragging right moves the view left");
        let z = zoom(&c, 0.5);
        assert!(((z.eye - z.target).length() - 2.0).abs() < 1e-5);
        assert!(zoom(&c, 0.0).validate().is_ok());
    }
}
