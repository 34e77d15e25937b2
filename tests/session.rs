//! The session without egui: every setter reaches the worker (the next frames are rendered with it), B follows A
//! where it should and keeps its own strategy, and a scene change resets what belongs to the old scene.

use illumlab::render::{Footprint, RenderSettings, Strategy};
use illumlab::scene::{LightSelection, load_scene};
use illumlab::session::Session;
use illumlab::session::views::View;
use illumlab::session::worker::{Budget, Frame, PassSize, ReferenceStatus};
use std::sync::Arc;
use std::time::{Duration, Instant};

fn session() -> Session {
    let mut scene = load_scene("cornell-box").unwrap();
    scene.camera.width = 32;
    scene.camera.height = 32;
    let mut s = Session::headless(Arc::new(scene), "cornell-box", 2);
    s.set_reference_cache(None);
    s
}

/// Polls until `pred` holds; fails after 30 s.
fn until(s: &mut Session, what: &str, pred: impl Fn(&Session) -> bool) {
    let start = Instant::now();
    loop {
        s.poll();
        if pred(s) {
            return;
        }
        assert!(start.elapsed() < Duration::from_secs(30), "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(2));
    }
}

fn a(s: &Session) -> &Frame {
    s.frame().expect("a frame")
}

#[test]
fn setters_reach_the_worker() {
    let mut s = session();
    s.set_sampling(PassSize::Fixed(2), Some(4));
    until(&mut s, "the first image", |s| s.reached(4));
    assert_eq!(a(&s).spp, 4, "the target stops refining");

    s.set_strategy(Strategy::Cosine);
    until(&mut s, "cosine", |s| s.reached(4));
    assert_eq!(a(&s).settings.strategy, Strategy::Cosine);

    let camera = illumlab::scene::Camera { fov_y: 25.0, ..s.camera() };
    s.set_camera(camera);
    until(&mut s, "the camera", |s| s.reached(4));
    assert_eq!(a(&s).camera, camera);

    s.set_resolution(20);
    until(&mut s, "the resolution", |s| s.reached(4));
    assert_eq!((a(&s).width, a(&s).height), (20, 20));

    let mut m = s.scene().materials[0];
    m.kd *= 0.5;
    let before = a(&s).radiance.iter().map(|r| r.x).sum::<f32>();
    s.set_material(0, m);
    until(&mut s, "the material", |s| s.reached(4));
    let after = a(&s).radiance.iter().map(|r| r.x).sum::<f32>();
    assert!(after < before, "a darker white wall darkens the image ({before} -> {after})");

    s.set_settings(RenderSettings { seed: 9, footprint: Footprint::Centre, ..s.settings() });
    until(&mut s, "the seed", |s| s.reached(4));
    assert_eq!((a(&s).settings.seed, a(&s).settings.footprint), (9, Footprint::Centre));

    let g = a(&s).generation;
    s.restart();
    until(&mut s, "a restart", |s| s.reached(4) && s.frame().is_some_and(|f| f.generation > g));

    s.set_paused(true);
    s.set_sampling(PassSize::Fixed(2), Some(8));
    std::thread::sleep(Duration::from_millis(100));
    s.poll();
    assert_eq!(a(&s).spp, 4, "paused: no pass");
    s.set_paused(false);
    until(&mut s, "resumed", |s| s.reached(8));

    // The probe: a pixel, then an answer for it.
    s.set_probe_pixel(Some((16, 28)));
    until(&mut s, "the probe's answer", |s| s.probe_is_current());
    assert_eq!(s.probe_view().unwrap().request.pixel, (16, 28));
}

#[test]
fn b_follows_a_except_its_strategy() {
    let mut s = session();
    s.set_sampling(PassSize::Fixed(2), Some(2));
    s.set_strategy_b(Strategy::Uniform);
    s.set_comparing(true);
    s.set_budget(Budget::EqualSamples);
    s.set_settings(RenderSettings {
        strategy: Strategy::Emitter,
        light_selection: LightSelection::Area,
        seed: 3,
        ..s.settings()
    });
    assert_eq!(s.settings_b().strategy, Strategy::Uniform, "B keeps its strategy");
    assert_eq!((s.settings_b().light_selection, s.settings_b().seed), (LightSelection::Area, 3), "B follows A");
    until(&mut s, "both lanes", |s| s.reached(2));
    let b = s.frame_b().expect("B's frame");
    assert_eq!(
        (b.settings.strategy, b.settings.light_selection, b.settings.seed),
        (Strategy::Uniform, LightSelection::Area, 3)
    );

    s.swap_lanes();
    assert_eq!((s.settings().strategy, s.settings_b().strategy), (Strategy::Uniform, Strategy::Emitter));
    until(&mut s, "swapped lanes", |s| s.reached(2));
    assert_eq!(s.frame_b().unwrap().settings.strategy, Strategy::Emitter);

    s.set_comparing(false);
    assert!(
        matches!(s.reference_status(), ReferenceStatus::Rendering { .. } | ReferenceStatus::Ready { .. }),
        "compare mode asked for a reference"
    );
}

#[test]
fn a_scene_change_resets_what_belongs_to_the_old_scene() {
    let mut s = session();
    s.set_strategy(Strategy::Cosine);
    s.set_reference_spp(2);
    s.set_sampling(PassSize::Fixed(1), Some(4));
    s.set_view(View::AbsError); // asks for a reference
    let mut m = s.scene().materials[0];
    m.kd *= 0.5;
    s.set_material(0, m);
    s.set_probe_pixel(Some((10, 10)));
    until(&mut s, "the reference and the runs", |s| s.reference().is_some() && !s.history().is_empty() && s.reached(4));

    let mut near = load_scene("near-light").unwrap();
    near.camera.width = 24;
    near.camera.height = 24;
    let home = near.camera;
    s.set_scene(near, "near-light");
    assert_eq!((s.source(), s.home_camera()), ("near-light", home));
    assert!(s.probe_pixel().is_none() && s.probe_view().is_none(), "the probe point was the old scene's");
    assert!(s.history().is_empty(), "the runs were against the old scene");
    assert_eq!(s.home_materials(), s.scene().materials.as_slice(), "no material edits carried over");
    assert_eq!(s.settings().strategy, Strategy::Cosine, "settings stay");
    until(&mut s, "the new scene's image and reference", |s| {
        s.reached(4) && s.reference().is_some_and(|r| r.mean.len() == 24 * 24)
    });
    assert_eq!(a(&s).scene_name, "near-light");
    assert!(s.probe_view().is_none(), "an answer for the old scene's point, arriving late, is dropped");
    s.reset_camera();
    assert_eq!(s.camera(), home);
}
