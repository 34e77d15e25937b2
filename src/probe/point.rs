//! The probed point: the first hit of a pixel centre's camera ray, fixed while the probe looks at it.

use crate::render::ShadingPoint;
use crate::scene::{Camera, Scene};
use glam::{Vec2, Vec3};

/// A shading point fixed by a pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbePoint {
    /// Column from the left, row from the top.
    pub pixel: (u32, u32),
    pub position: Vec3,
    /// The unit normal on the viewer's side.
    pub normal: Vec3,
    /// Towards the camera.
    pub wo: Vec3,
    pub triangle: u32,
    pub material: u32,
}

impl ProbePoint {
    /// The first surface the camera ray through the centre of pixel (x, y) meets; `None` where it meets none or
    /// the pixel is outside the image.
    pub fn at_pixel(scene: &Scene, camera: &Camera, (x, y): (u32, u32)) -> Option<Self> {
        if x >= camera.width || y >= camera.height {
            return None;
        }
        let basis = camera.basis();
        let dir = basis.direction(x, y, Vec2::splat(0.5));
        let hit = scene.accel().closest_hit(basis.eye(), dir, f32::INFINITY)?;
        let tri = &scene.triangles[hit.triangle as usize];
        let material = &scene.materials[tri.material as usize];
        let sp = ShadingPoint::on_triangle(scene.hit_point(&hit), tri, -dir, material);
        Some(Self {
            pixel: (x, y),
            position: sp.p,
            normal: sp.n,
            wo: sp.wo,
            triangle: hit.triangle,
            material: tri.material,
        })
    }

    pub fn shading_point<'a>(&self, scene: &'a Scene) -> ShadingPoint<'a> {
        ShadingPoint {
            p: self.position,
            n: self.normal,
            wo: self.wo,
            material: &scene.materials[self.material as usize],
            error: scene.triangles[self.triangle as usize].error.at_point,
        }
    }
}
