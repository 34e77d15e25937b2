//! Real-world coordinates: a scene kilometres from the origin (CAD, GIS and scan exports) renders as it would at
//! the origin. An analytic scene — a diffuse floor (k_d = 0.5) and a 0.5 m square light 0.5 m above it — is
//! written to OBJ and TOML files translated (camera and all) by 0, 10³, 10⁴, 10⁵ and 10⁶ m, loaded (positions
//! read in f64 and rebased before they are rounded to f32), and every strategy is held to Lambert's closed form
//! at points under the light, near its edge and beside it, within 4 standard errors. Without the rebase the f32
//! positions 10⁵ m out are 8 mm apart; the ray offsets, bounded by the rounding actually made, still hold the
//! closed form of that quantised geometry (the second test).
//! Fixed seeds: deterministic; ≈ 115 comparisons of ≤ 3 × 6.3·10⁻⁵ each: a correct renderer fails this file
//! with probability ≲ 2%.

mod common;

use common::{estimate_with, on_surface};
use glam::{DVec3, Vec3};
use illumlab::math::lambert_polygon_irradiance;
use illumlab::render::{RenderSettings, Strategy};
use illumlab::scene::load_scene_file;
use std::f64::consts::PI;
use std::fmt::Write;

const LIGHT: [[f64; 3]; 4] = [[-0.25, 0.5, -0.25], [0.25, 0.5, -0.25], [0.25, 0.5, 0.25], [-0.25, 0.5, 0.25]];

/// The scene's files with every position moved by `t`.
fn write_scene(dir: &std::path::Path, t: DVec3) -> std::path::PathBuf {
    let v = |p: [f64; 3]| DVec3::from(p) + t;
    let mut obj = String::from("mtllib scene.mtl\n");
    let floor = [[-20.0, 0.0, 20.0], [20.0, 0.0, 20.0], [20.0, 0.0, -20.0], [-20.0, 0.0, -20.0]];
    for p in floor.iter().chain(&LIGHT) {
        let p = v(*p);
        writeln!(obj, "v {:.6} {:.6} {:.6}", p.x, p.y, p.z).unwrap();
    }
    // The light's corners run counter-clockwise seen from below, so that it faces the floor.
    obj.push_str("usemtl floor\nf 1 2 3 4\nusemtl light\nf 5 6 7 8\n");
    let mtl = "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl light\nKd 0 0 0\nKe 4 4 4\n";
    let (eye, target) = (v([0.0, 1.5, 3.0]), v([0.0, 0.0, 0.0]));
    let toml = format!(
        "[camera]\neye = [{:.6}, {:.6}, {:.6}]\ntarget = [{:.6}, {:.6}, {:.6}]\nup = [0.0, 1.0, 0.0]\nfov_y = 40.0\n\
         width = 8\nheight = 8\n\n[[mesh]]\nobj = \"scene.obj\"\n",
        eye.x, eye.y, eye.z, target.x, target.y, target.z
    );
    for (name, text) in [("scene.obj", obj.as_str()), ("scene.mtl", mtl), ("scene.toml", toml.as_str())] {
        std::fs::write(dir.join(name), text).unwrap();
    }
    dir.join("scene.toml")
}

#[test]
fn every_strategy_renders_as_at_the_origin_up_to_a_thousand_kilometres_away() {
    let light: Vec<DVec3> = LIGHT.iter().map(|p| DVec3::from(*p)).collect();
    let direction = DVec3::new(0.6, 0.3, -0.74).normalize();
    for distance in [0.0, 1e3, 1e4, 1e5, 1e6] {
        let dir = tempfile::tempdir().unwrap();
        let t = direction * distance;
        let scene = load_scene_file(&write_scene(dir.path(), t)).expect("loads");
        assert!(scene.warnings.iter().all(|w| !w.contains("degenerate")), "{:?}", scene.warnings);
        if distance > 0.0 {
            assert!((scene.origin - t).length() < 20.0, "rebased near the scene: origin {}", scene.origin);
        }
        let points = [
            ("under the light", [0.05, 0.0, -0.03]),
            ("near its edge", [0.3, 0.0, 0.1]),
            ("beside it", [1.2, 0.0, -0.8]),
        ];
        for (i, (label, local)) in points.into_iter().enumerate() {
            // The point in the files' coordinates, then in the scene's (rebased) ones.
            let world = DVec3::from(local) + t;
            let p = (world - scene.origin).as_vec3();
            let sp = on_surface(&scene, p, Vec3::Y, Vec3::new(0.2, 1.0, 0.3).normalize(), &scene.materials[0]);
            let expected = 4.0 * 0.5 / PI * lambert_polygon_irradiance(DVec3::from(local), DVec3::Y, &light, 1.0);
            for strategy in Strategy::ALL {
                let n = if strategy.samples_lights() || strategy == Strategy::Mis { 20_000 } else { 200_000 };
                let settings = RenderSettings { strategy, seed: 11 + i as u64, ..Default::default() };
                let est = estimate_with(&scene, &sp, &settings, n);
                let z = (est.mean - DVec3::splat(expected)).abs() / est.std_error;
                eprintln!(
                    "{distance:>9.0e} m, {label:>15}, {:>22}: mean {:.5} expected {expected:.5} z {:.2}",
                    strategy.name(),
                    est.mean.x,
                    z.x
                );
                assert_eq!(est.non_finite, 0);
                assert!(est.std_error.x < 0.1 * expected, "{label}: too few samples to test anything");
                assert!(z.max_element() < 4.0, "{} at {distance} m, {label}: z = {z:?}", strategy.name());
            }
        }
    }
}

/// Without the rebase, the ray offsets alone: the same floor and light built in f32 coordinates 10³, 10⁴ and 10⁵ m
/// from the origin (`Scene::new` takes them as they are). Every strategy is held to the closed form of the
/// geometry as rounded to f32 (the quantisation is the scene's, not the estimator's), within 4 standard errors:
/// offsets bounded by the rounding actually made (`math::offset`) move a ray by about one float there, where the
/// former fixed 256 ULPs moved it by 0.25 m at 10⁴ m (+10% with `cosine`) and over the light at 10⁵ m (black).
/// Fixed seeds; 3 × 3 × 8 comparisons.
#[test]
fn error_bounded_offsets_alone_hold_the_closed_form_far_from_the_origin() {
    use illumlab::scene::{Material, Scene};
    let direction = DVec3::new(0.6, 0.3, -0.74).normalize();
    for distance in [1e3, 1e4, 1e5] {
        let t = direction * distance;
        let v = |p: [f64; 3]| (DVec3::from(p) + t).as_vec3();
        let floor = [[-20.0, 0.0, 20.0], [20.0, 0.0, 20.0], [20.0, 0.0, -20.0], [-20.0, 0.0, -20.0]].map(v);
        let light = LIGHT.map(v);
        let quads = [
            common::quad(floor[0], floor[1], floor[2], floor[3]),
            common::quad(light[0], light[1], light[2], light[3]),
        ];
        let positions: Vec<[Vec3; 3]> = quads.concat();
        let materials = vec![
            Material { kd: Vec3::splat(0.5), ..Default::default() },
            Material { kd: Vec3::ZERO, emission: Vec3::splat(4.0), ..Default::default() },
        ];
        let camera = common::any_camera();
        let scene =
            Scene::new("far", camera, &positions, &[0, 0, 1, 1], materials, vec!["floor".into(), "light".into()])
                .expect("valid scene");
        let light_f64: Vec<DVec3> = light.iter().map(|p| p.as_dvec3()).collect();
        for (i, local) in [[0.05, 0.0, -0.03], [0.3, 0.0, 0.1], [1.2, 0.0, -0.8]].into_iter().enumerate() {
            let p = v(local);
            let sp = on_surface(&scene, p, Vec3::Y, Vec3::new(0.2, 1.0, 0.3).normalize(), &scene.materials[0]);
            let expected = 4.0 * 0.5 / PI * lambert_polygon_irradiance(sp.p.as_dvec3(), DVec3::Y, &light_f64, 1.0);
            for strategy in Strategy::ALL {
                let n = if strategy.samples_lights() || strategy == Strategy::Mis { 20_000 } else { 200_000 };
                let settings = RenderSettings { strategy, seed: 21 + i as u64, ..Default::default() };
                let est = estimate_with(&scene, &sp, &settings, n);
                let z = (est.mean - DVec3::splat(expected)).abs() / est.std_error;
                eprintln!(
                    "no rebase {distance:>6.0e} m, point {i}, {:>22}: mean {:.5} expected {expected:.5} ({:+.3}%) z {:.2}",
                    strategy.name(),
                    est.mean.x,
                    100.0 * (est.mean.x / expected - 1.0),
                    z.x
                );
                assert_eq!(est.non_finite, 0);
                assert!(z.max_element() < 4.0, "{} at {distance} m, point {i}: z = {z:?}", strategy.name());
            }
        }
    }
}
