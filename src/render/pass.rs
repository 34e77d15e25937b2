//! Passes over the image: every pixel takes the samples `first..first + count`, in order, each from its own
//! seeded stream, rows in parallel (rayon). Per-pixel order is fixed, so the film is the same bit for bit with any
//! number of threads and any split into passes.

use super::strategy::MisSettings;
use super::{Film, ShadingPoint, Strategy, estimate_direct};
use crate::math::{PixelStreams, SampleRng};
use crate::scene::{Camera, CameraBasis, ConeCandidates, EmitterSampler, Hit, LightSelection, Scene};
use cpu_time::ThreadTime;
use glam::Vec3;
use rayon::prelude::*;
use std::time::Duration;

/// Passes of at least this many samples per pixel gather, once per pixel, the few triangles its camera rays
/// can hit (an exact cull: see `scene::accel::frustum`); each camera ray then tests only those.
const CONE_MIN_SAMPLES: u32 = 4;

/// What a render is a function of, besides the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RenderSettings {
    pub strategy: Strategy,
    pub light_selection: LightSelection,
    pub seed: u64,
    /// Used by [`Strategy::Mis`].
    pub mis: MisSettings,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            strategy: Strategy::Emitter,
            light_selection: LightSelection::Power,
            seed: 0,
            mis: MisSettings::default(),
        }
    }
}

/// Counts from one or more passes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PassStats {
    /// Pixel samples taken (accepted + dropped).
    pub samples: u64,
    /// Rays traced: camera, BRDF and shadow rays.
    pub rays: u64,
    /// Non-finite samples dropped.
    pub non_finite: u64,
    /// CPU time spent on the samples, summed over threads (each row's thread CPU clock).
    pub cpu: Duration,
}

impl std::ops::AddAssign for PassStats {
    fn add_assign(&mut self, o: Self) {
        self.samples += o.samples;
        self.rays += o.rays;
        self.non_finite += o.non_finite;
        self.cpu += o.cpu;
    }
}

/// Renders a scene with fixed settings.
pub struct Renderer<'a> {
    scene: &'a Scene,
    settings: RenderSettings,
    emitters: Option<EmitterSampler>,
    camera: CameraBasis,
    size: (u32, u32),
}

impl<'a> Renderer<'a> {
    pub fn new(scene: &'a Scene, settings: RenderSettings) -> Self {
        Self::with_camera(scene, settings, &scene.camera)
    }

    /// Renders through another camera than the scene's (e.g. a low-resolution preview).
    pub fn with_camera(scene: &'a Scene, settings: RenderSettings, camera: &Camera) -> Self {
        Self {
            scene,
            settings,
            emitters: EmitterSampler::new(scene, settings.light_selection),
            camera: camera.basis(),
            size: (camera.width, camera.height),
        }
    }

    /// Adds samples `first..first + count` to every pixel of `film` (which must match the camera's size).
    /// `cancelled` is polled once per row; when it returns true the pass stops early and leaves the film
    /// partially updated (the caller discards it).
    pub fn render_pass(
        &self,
        film: &mut Film,
        first: u32,
        count: u32,
        cancelled: &(dyn Fn() -> bool + Sync),
    ) -> PassStats {
        let width = film.width;
        assert_eq!((film.width, film.height), self.size, "film and camera sizes differ");
        film.pixels
            .par_chunks_mut(width as usize)
            .enumerate()
            .map(|(y, row)| {
                let mut stats = PassStats::default();
                if cancelled() {
                    return stats;
                }
                let cpu = ThreadTime::now();
                for (x, acc) in row.iter_mut().enumerate() {
                    let streams = PixelStreams::new(self.settings.seed, y as u64 * width as u64 + x as u64);
                    let (x, y) = (x as u32, y as u32);
                    let cone = (count >= CONE_MIN_SAMPLES)
                        .then(|| self.scene.accel().cone_candidates(self.camera.eye(), self.camera.pixel_corners(x, y)))
                        .flatten();
                    for s in first..first + count {
                        let mut rng = streams.sample(s as u64);
                        let (dir, hit) = self.camera_ray(x, y, cone.as_ref(), &mut rng);
                        stats.rays += 1;
                        let v = hit.map_or(Vec3::ZERO, |hit| self.shade(dir, &hit, &mut rng, &mut stats.rays));
                        if v.is_finite() {
                            acc.add(v);
                        } else {
                            stats.non_finite += 1;
                        }
                    }
                    stats.samples += count as u64;
                }
                stats.cpu = cpu.elapsed();
                stats
            })
            .reduce(PassStats::default, |mut a, b| {
                a += b;
                a
            })
    }

    /// A camera ray through a uniformly jittered position in pixel (x, y) (box filter) and its closest hit.
    /// `cone`, when given, holds every triangle the pixel's camera rays can hit.
    #[inline]
    fn camera_ray(&self, x: u32, y: u32, cone: Option<&ConeCandidates>, rng: &mut SampleRng) -> (Vec3, Option<Hit>) {
        let dir = self.camera.direction(x, y, rng.uniform_2d());
        let hit = match cone {
            Some(cone) => cone.closest_hit(dir, f32::INFINITY),
            None => self.scene.accel().closest_hit(self.camera.eye(), dir, f32::INFINITY),
        };
        (dir, hit)
    }

    /// One sample of `L = L_e(x, ω_o) + ∫ f_r L_i (ω·n) dω` at the first surface x seen along the camera ray `dir`.
    #[inline]
    fn shade(&self, dir: Vec3, hit: &Hit, rng: &mut SampleRng, rays: &mut u64) -> Vec3 {
        let tri = &self.scene.triangles[hit.triangle as usize];
        let p = self.scene.hit_point(hit);
        let wo = -dir;
        let material = &self.scene.materials[tri.material as usize];
        let sp = ShadingPoint::new(p, tri.n, wo, material);
        let emitted = self.scene.emitted(hit.triangle, wo);
        emitted + estimate_direct(self.scene, &sp, &self.settings, self.emitters.as_ref(), rng, rays)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::every_bundled_scene;

    /// One pass of 16 samples per pixel (camera rays through each pixel's cone) and 16 passes of one sample
    /// (a full traversal for every camera ray) give the same film bit for bit, on every bundled scene and for
    /// strategies that trace shadow rays and BRDF rays.
    #[test]
    fn any_split_into_passes_gives_the_same_film() {
        for (name, scene, camera) in every_bundled_scene(48, 36) {
            for strategy in [Strategy::Emitter, Strategy::Brdf, Strategy::Mis] {
                let settings = RenderSettings { strategy, seed: 3, ..Default::default() };
                let renderer = Renderer::with_camera(&scene, settings, &camera);
                let (mut whole, mut split) =
                    (Film::new(camera.width, camera.height), Film::new(camera.width, camera.height));
                renderer.render_pass(&mut whole, 0, 16, &|| false);
                for s in 0..16 {
                    renderer.render_pass(&mut split, s, 1, &|| false);
                }
                assert!(whole.pixels == split.pixels, "{name}, {}: the films differ", strategy.name());
            }
        }
    }
}
