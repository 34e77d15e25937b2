//! Shared by the statistical tests: a generic chi-square goodness-of-fit tester for any (sample, pdf) pair on the
//! sphere or the triangle, and small analytic scenes.
#![allow(dead_code)]

pub mod chi2;

use glam::{DVec3, Vec3};
use illumlab::math::SampleRng;
use illumlab::render::{RenderSettings, ShadingPoint, Strategy, estimate_direct};
use illumlab::scene::{Camera, EmitterSampler, LightSelection, Material, Scene};

/// The scene file of the small test scenes the command-line and loader tests write (`scene.obj` beside it):
/// an 8×8 camera looking down at the floor.
pub const SMALL_SCENE_TOML: &str = r#"
[camera]
eye = [0.0, 1.0, 3.0]
target = [0.0, 0.5, 0.0]
up = [0.0, 1.0, 0.0]
fov_y = 45.0
width = 8
height = 8

[[mesh]]
obj = "scene.obj"
"#;

/// A camera that is never used to render: the estimators are evaluated at chosen shading points.
pub fn any_camera() -> Camera {
    Camera { eye: Vec3::new(0.0, 1.0, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_y: 40.0, width: 8, height: 8 }
}

/// Quad (a, b, c, d) as two counter-clockwise triangles: its normal is (b−a)×(c−a).
pub fn quad(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> [[Vec3; 3]; 2] {
    [[a, b, c], [a, c, d]]
}

/// The analytic scene of the unbiasedness tests: a diffuse floor (y = 0, k_d = 0.5) under a square light of
/// side `side` at height `height`, facing down, radiance `radiance`. No occluders.
pub struct FloorUnderLight {
    pub scene: Scene,
    pub light: Vec<DVec3>,
    pub radiance: Vec3,
    pub kd: f32,
}

pub fn floor_under_light(side: f32, height: f32, radiance: Vec3, floor_half: f32) -> FloorUnderLight {
    let h = 0.5 * side;
    // Seen from below, the light's corners run counter-clockwise so that its normal points down (−y).
    let l = [Vec3::new(-h, height, -h), Vec3::new(h, height, -h), Vec3::new(h, height, h), Vec3::new(-h, height, h)];
    let f = floor_half;
    let floor = quad(Vec3::new(-f, 0.0, -f), Vec3::new(-f, 0.0, f), Vec3::new(f, 0.0, f), Vec3::new(f, 0.0, -f));
    let light = quad(l[0], l[1], l[2], l[3]);
    let kd = 0.5;
    let materials = vec![
        Material { kd: Vec3::splat(kd), ks: Vec3::ZERO, alpha: 1.0, emission: Vec3::ZERO },
        Material { kd: Vec3::ZERO, ks: Vec3::ZERO, alpha: 1.0, emission: radiance },
    ];
    let positions: Vec<[Vec3; 3]> = floor.into_iter().chain(light).collect();
    let scene = Scene::new(
        "floor-under-light",
        any_camera(),
        &positions,
        &[0, 0, 1, 1],
        materials,
        vec!["floor".into(), "light".into()],
    )
    .expect("valid scene");
    assert!(scene.triangles.iter().filter(|t| t.material == 1).all(|t| t.n.y < -0.99), "light faces down");
    FloorUnderLight { scene, light: l.iter().map(|v| v.as_dvec3()).collect(), radiance, kd }
}

/// Mean and standard error of the mean (per channel) of `n` one-sample estimates at `sp`; also the number of
/// non-finite samples (which are not averaged in).
pub struct Estimate {
    pub mean: DVec3,
    pub std_error: DVec3,
    pub non_finite: u64,
}

/// The shading point where a ray towards p along −n meets the scene within 10⁻⁶ (1 + |p|) of p, as a camera
/// ray's hit: the point from the triangle's barycentrics, with the triangle's error bound. Where there is no such
/// triangle, [`ShadingPoint::new`] at p.
pub fn on_surface<'a>(scene: &Scene, p: Vec3, n: Vec3, wo: Vec3, material: &'a Material) -> ShadingPoint<'a> {
    let h = 1e-6 * (1.0 + p.abs().max_element());
    match scene.accel().closest_hit(p + n * h, -n, 2.0 * h) {
        Some(hit) => {
            let tri = &scene.triangles[hit.triangle as usize];
            ShadingPoint {
                n: ShadingPoint::new(p, n, wo, material).n,
                ..ShadingPoint::on_triangle(scene.hit_point(&hit), tri, wo, material)
            }
        }
        None => ShadingPoint::new(p, n, wo, material),
    }
}

pub fn estimate_at(
    scene: &Scene,
    sp: &ShadingPoint,
    strategy: Strategy,
    selection: LightSelection,
    n: u64,
    seed: u64,
) -> Estimate {
    estimate_with(scene, sp, &RenderSettings { strategy, light_selection: selection, seed, ..Default::default() }, n)
}

/// As [`estimate_at`], with every setting given (MIS among them).
pub fn estimate_with(scene: &Scene, sp: &ShadingPoint, settings: &RenderSettings, n: u64) -> Estimate {
    let (seed, selection) = (settings.seed, settings.light_selection);
    let emitters = EmitterSampler::new(scene, selection);
    let (mut sum, mut sum_sq, mut non_finite, mut rays) = (DVec3::ZERO, DVec3::ZERO, 0, 0);
    for i in 0..n {
        let mut rng = SampleRng::new(seed, 0, i);
        let v = estimate_direct(scene, sp, settings, emitters.as_ref(), &mut rng, &mut rays);
        if v.is_finite() {
            let v = v.as_dvec3();
            sum += v;
            sum_sq += v * v;
        } else {
            non_finite += 1;
        }
    }
    let k = (n - non_finite) as f64;
    let mean = sum / k;
    let var = ((sum_sq - sum * sum / k) / (k - 1.0)).max(DVec3::ZERO);
    Estimate { mean, std_error: (var / k).map(f64::sqrt), non_finite }
}
