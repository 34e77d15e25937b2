//! The pass's unit tests: kept cones, and films that do not depend on how samples are split into passes.

use super::*;
use crate::guiding::GuideSettings;
use crate::render::{Heuristic, MisSettings};
use crate::scene::{LightSelection, every_bundled_scene};

/// A renderer takes an earlier one's pixel cones for its own camera only, and renders with them what it
/// renders with the cones it finds itself.
#[test]
fn kept_cones_are_taken_for_the_same_camera_only() {
    let (_, scene, camera) = every_bundled_scene(24, 16).find(|(name, ..)| *name == "veach-mis").expect("bundled");
    let scene = Arc::new(scene);
    let mut first = Renderer::with_camera(scene.clone(), RenderSettings::default(), &camera);
    let mut kept = Film::new(camera.width, camera.height);
    first.render_pass(&mut kept, 0, 8, &|| false);
    let mut second = Renderer::with_camera(scene.clone(), RenderSettings::default(), &camera).with_cones(first.cones());
    assert!(Arc::ptr_eq(&second.cones(), &first.cones()), "same camera: the cones are taken");
    second.render_pass(&mut kept, 8, 8, &|| false);
    let mut fresh = Film::new(camera.width, camera.height);
    Renderer::with_camera(scene.clone(), RenderSettings::default(), &camera).render_pass(&mut fresh, 0, 16, &|| false);
    assert!(kept.pixels == fresh.pixels, "kept cones change the film");
    let moved = Camera { eye: camera.eye + Vec3::new(0.1, 0.0, 0.0), ..camera };
    let third = Renderer::with_camera(scene, RenderSettings::default(), &moved).with_cones(first.cones());
    assert!(!Arc::ptr_eq(&third.cones(), &first.cones()), "another camera: its own cones");
}

/// Thirteen samples per pixel in one pass (through each pixel's cone, eight lanes then five), in thirteen
/// passes of one (a full traversal and the one-sample estimator each) and in passes of three and ten give the
/// same film bit for bit: on every bundled scene, with every registered strategy (the light strategies and MIS
/// take the eight-lane estimators), with every light selection for the light strategies, with MIS's other
/// technique pairs and heuristic and with a direction split the eight-lane path does not take, and with both
/// footprints.
#[test]
fn any_split_into_passes_gives_the_same_film() {
    let settings: Vec<RenderSettings> = Strategy::ALL
        .into_iter()
        .flat_map(|strategy| {
            let selections =
                if strategy.samples_lights() { &LightSelection::ALL[..] } else { &[LightSelection::Power] };
            selections.iter().map(move |&light_selection| RenderSettings {
                strategy,
                light_selection,
                ..Default::default()
            })
        })
        .chain(Strategy::ALL.map(|strategy| RenderSettings {
            strategy,
            footprint: Footprint::Centre,
            ..Default::default()
        }))
        .chain(
            [
                ([Strategy::SolidAngle, Strategy::Brdf], Heuristic::Power, [1, 1]),
                ([Strategy::ProjectedSolidAngle, Strategy::Brdf], Heuristic::Balance, [1, 1]),
                ([Strategy::Cosine, Strategy::Brdf], Heuristic::Power, [1, 1]),
                ([Strategy::Brdf, Strategy::Emitter], Heuristic::Power, [1, 1]),
                ([Strategy::Emitter, Strategy::Brdf], Heuristic::Power, [2, 1]),
            ]
            .map(|(techniques, heuristic, samples)| RenderSettings {
                strategy: Strategy::Mis,
                mis: MisSettings { techniques, heuristic, samples },
                ..Default::default()
            }),
        )
        // A guide frozen after 3 spp: the rest of the passes take the eight-lane estimator.
        .chain(std::iter::once(RenderSettings {
            strategy: Strategy::Guided,
            guiding: GuideSettings { training_spp: 3, ..Default::default() },
            ..Default::default()
        }))
        .collect();
    for (name, scene, camera) in every_bundled_scene(48, 36) {
        let scene = Arc::new(scene);
        for settings in &settings {
            let settings = RenderSettings { seed: 3, ..*settings };
            // A renderer per film (a learning strategy's guide is the renderer's), sharing the first one's
            // cones once found.
            let first = Renderer::with_camera(scene.clone(), settings, &camera);
            let film = |passes: &[u32]| {
                let mut renderer = Renderer::with_camera(scene.clone(), settings, &camera).with_cones(first.cones());
                let mut film = Film::new(camera.width, camera.height);
                let mut first = 0;
                for &count in passes {
                    renderer.render_pass(&mut film, first, count, &|| false);
                    first += count;
                }
                film
            };
            let one_by_one = film(&[1; 13]);
            // (Passes of 5 and 8 take the second's cones from the first.)
            for passes in [&[13][..], &[3, 10], &[5, 8]] {
                assert!(
                    film(passes).pixels == one_by_one.pixels,
                    "{name}, {} ({}, {}, {}): passes {passes:?} differ from one sample at a time",
                    settings.strategy.name(),
                    settings.light_selection.name(),
                    settings.footprint.name(),
                    settings.mis.label()
                );
            }
        }
    }
}
