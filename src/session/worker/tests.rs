//! The worker end to end: restarts, targets, common random numbers, budgets and the reference cache.

use super::*;
use crate::measure::{Reference, ReferenceOrigin};
use crate::render::{Film, Renderer, Strategy};
use crate::scene::load_scene;
use std::path::PathBuf;
use std::time::{Duration, Instant};

fn wait_for(worker: &Worker, pred: impl Fn(&Frame) -> bool) -> Arc<Frame> {
    wait_for_lane(worker, A, pred)
}

fn wait_for_lane(worker: &Worker, lane: usize, pred: impl Fn(&Frame) -> bool) -> Arc<Frame> {
    let start = Instant::now();
    loop {
        if let Some(f) = worker.take_lane(lane)
            && pred(&f)
        {
            return f;
        }
        assert!(start.elapsed() < Duration::from_secs(60), "no matching frame");
        std::thread::sleep(Duration::from_millis(2));
    }
}

fn wait_for_reference(worker: &Worker) -> (Arc<Reference>, String) {
    let start = Instant::now();
    loop {
        match worker.take_reference() {
            Some(ReferenceStatus::Ready { reference, note }) => return (reference, note),
            Some(ReferenceStatus::Failed(e)) => panic!("reference failed: {e}"),
            _ => {}
        }
        assert!(start.elapsed() < Duration::from_secs(60), "no reference");
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// Sends `commands`, then restarts the images, so that they render with all of them from their first sample: the
/// worker starts rendering as it is spawned and, on a busy machine, may pass a target before the command setting it
/// arrives (it then never shows a frame at the target).
fn configure(worker: &Worker, commands: impl IntoIterator<Item = Command>) {
    commands.into_iter().for_each(|c| worker.send(c));
    worker.send(Command::Restart);
}

fn settings(strategy: Strategy) -> RenderSettings {
    RenderSettings { strategy, ..RenderSettings::default() }
}

fn small_scene() -> Arc<Scene> {
    let mut scene = load_scene("cornell-box").expect("bundled");
    scene.camera.width = 32;
    scene.camera.height = 32;
    Arc::new(scene)
}

#[test]
fn refines_then_restarts_on_a_new_strategy() {
    let worker = Worker::spawn(small_scene(), RenderSettings::default(), 1, || {});
    let f = wait_for(&worker, |f| f.spp >= 3);
    assert_eq!(f.settings.strategy, Strategy::Emitter);
    worker.send(Command::SetSettings(RenderSettings { strategy: Strategy::Cosine, ..RenderSettings::default() }));
    let g = wait_for(&worker, |g| g.settings.strategy == Strategy::Cosine);
    assert!(g.generation > f.generation);
    // Restarted: the film holds exactly samples 0..spp of the new strategy, however many passes ran.
    let mut film = Film::new(32, 32);
    Renderer::new(small_scene(), g.settings).render_pass(&mut film, 0, g.spp, &|| false);
    assert_eq!(g.radiance, film.means(), "accumulation restarted");
}

#[test]
fn stops_at_the_target_and_is_the_same_image_as_a_batch_render() {
    let scene = small_scene();
    let worker = Worker::spawn(scene.clone(), RenderSettings::default(), 1, || {});
    configure(&worker, [Command::SetTargetSpp(Some(5)), Command::SetPassSize(PassSize::Fixed(2))]);
    let f = wait_for(&worker, |f| f.spp == 5);
    std::thread::sleep(Duration::from_millis(50));
    assert!(worker.take_frame().is_none(), "idle at the target");
    // The progressive film equals a one-shot render of the same samples.
    let mut film = Film::new(32, 32);
    Renderer::new(scene, RenderSettings::default()).render_pass(&mut film, 0, 5, &|| false);
    assert_eq!(f.radiance, film.means());
}

/// By default passes are sized by time (the first takes one sample per pixel: `pass_size`'s unit test): later
/// ones take many more (a 32² box renders hundreds of spp in 30 ms), and the film is still a one-shot render's,
/// bit for bit.
#[test]
fn auto_passes_grow_from_one_sample_and_give_the_one_shot_image() {
    let scene = small_scene();
    let worker = Worker::spawn(scene.clone(), RenderSettings::default(), 1, || {});
    configure(&worker, [Command::SetTargetSpp(Some(2000))]);
    let done = wait_for(&worker, |f| f.spp == 2000);
    assert!(done.passes < 200, "{} passes for 2000 spp: they grew", done.passes);
    let mut film = Film::new(32, 32);
    Renderer::new(scene, RenderSettings::default()).render_pass(&mut film, 0, 2000, &|| false);
    assert_eq!(done.radiance, film.means());
}

/// Passes of 4 spp go through the pixel cones, which the worker keeps from pass to pass and finds again when the
/// camera moves: the film is a one-shot render's, bit for bit, before and after the move.
#[test]
fn kept_pixel_cones_give_the_one_shot_image_and_follow_the_camera() {
    let scene = small_scene();
    let one_shot = |scene: &Scene| {
        let mut film = Film::new(32, 32);
        Renderer::new(Arc::new(scene.clone()), RenderSettings::default()).render_pass(&mut film, 0, 12, &|| false);
        film.means()
    };
    let worker = Worker::spawn(scene.clone(), RenderSettings::default(), 1, || {});
    configure(&worker, [Command::SetPassSize(PassSize::Fixed(4)), Command::SetTargetSpp(Some(12))]);
    let f = wait_for(&worker, |f| f.spp == 12);
    assert_eq!(f.passes, 3);
    assert_eq!(f.radiance, one_shot(&scene));
    let mut moved = (*scene).clone();
    moved.camera.eye += glam::Vec3::new(0.3, 0.1, 0.0);
    worker.send(Command::SetCamera(moved.camera));
    let g = wait_for(&worker, |g| g.spp == 12 && g.camera == moved.camera);
    assert_eq!(g.radiance, one_shot(&moved));
}

#[test]
fn equal_samples_with_common_random_numbers_makes_identical_strategies_identical() {
    let worker = Worker::spawn(small_scene(), settings(Strategy::Brdf), 1, || {});
    configure(&worker, [Command::SetCompare(Some(settings(Strategy::Brdf))), Command::SetTargetSpp(Some(6))]);
    let a = wait_for_lane(&worker, A, |f| f.spp == 6);
    let b = wait_for_lane(&worker, B, |f| f.spp == 6);
    assert_eq!(a.radiance, b.radiance, "A − B is zero everywhere");
    assert_eq!(a.std_error, b.std_error);
    // A different estimator on the same streams differs, but sees the same camera rays.
    // (Emitter sampling: on this diffuse-walled box, BRDF and cosine sampling coincide except on the glossy block.)
    worker.send(Command::SetCompare(Some(settings(Strategy::Emitter))));
    let c = wait_for_lane(&worker, B, |f| f.spp == 6 && f.settings.strategy == Strategy::Emitter);
    assert!(a.radiance != c.radiance, "emitter and BRDF sampling gave the same image");
}

#[test]
fn equal_time_gives_both_lanes_the_same_cpu_time() {
    // Projected-solid-angle sampling costs about twice as much per sample as cosine sampling.
    let worker = Worker::spawn(small_scene(), settings(Strategy::Cosine), 1, || {});
    worker.send(Command::SetCompare(Some(settings(Strategy::ProjectedSolidAngle))));
    worker.send(Command::SetBudget(Budget::EqualTime));
    worker.send(Command::SetPassSize(PassSize::Fixed(4)));
    worker.send(Command::SetTargetSpp(Some(400)));
    let a = wait_for_lane(&worker, A, |f| f.spp >= 400);
    let b = wait_for_lane(&worker, B, |f| f.stats.cpu >= a.stats.cpu);
    std::thread::sleep(Duration::from_millis(100));
    let b = worker.take_lane(B).unwrap_or(b);
    let (ta, tb) = (a.stats.cpu.as_secs_f64(), b.stats.cpu.as_secs_f64());
    println!("equal time: A {} spp in {ta:.3} s CPU, B {} spp in {tb:.3} s CPU", a.spp, b.spp);
    assert!((ta - tb).abs() <= 0.1 * ta.max(tb), "CPU time A {ta:.3} s, B {tb:.3} s");
    assert!(b.spp < a.spp, "the costlier estimator took fewer samples: {} vs {}", b.spp, a.spp);
    assert!(worker.take_lane(A).is_none(), "A stopped at the time budget");
}

#[test]
fn reference_is_rendered_cached_and_reused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let cache = Some(dir.path().to_path_buf());
    let worker = Worker::spawn(small_scene(), RenderSettings::default(), 1, || {});
    worker.send(Command::SetReference { spp: Some(16), cache: cache.clone() });
    let (rendered, note) = wait_for_reference(&worker);
    assert_eq!(rendered.spp, 16);
    assert!(note.contains("cached in"), "{note}");
    // A strategy change keeps it; a new worker finds it in the cache.
    worker.send(Command::SetSettings(settings(Strategy::Cosine)));
    std::thread::sleep(Duration::from_millis(50));
    assert!(worker.take_reference().is_none(), "still the same reference");
    drop(worker);
    let worker = Worker::spawn(small_scene(), RenderSettings::default(), 1, || {});
    worker.send(Command::SetReference { spp: Some(16), cache });
    let (cached, note) = wait_for_reference(&worker);
    assert!(matches!(cached.origin, ReferenceOrigin::Cache(_)), "{note}");
    assert_eq!(cached.mean, rendered.mean);
    // The reference is independent of the estimates: it uses its own seed.
    let f = wait_for(&worker, |f| f.spp >= 16);
    assert_ne!(f.radiance, cached.mean);
}

#[test]
fn a_bad_reference_file_is_reported() {
    let worker = Worker::spawn(small_scene(), RenderSettings::default(), 1, || {});
    worker.send(Command::LoadReference(PathBuf::from("/nonexistent/ref.exr")));
    let start = Instant::now();
    let message = loop {
        if let Some(ReferenceStatus::Failed(e)) = worker.take_reference() {
            break e;
        }
        assert!(start.elapsed() < Duration::from_secs(30));
        std::thread::sleep(Duration::from_millis(2));
    };
    assert!(message.contains("/nonexistent/ref.exr"), "{message}");
    wait_for(&worker, |f| f.spp >= 2);
}

#[test]
fn a_pass_that_panics_reaches_the_ui_and_a_new_setting_renders_again() {
    let worker = Worker::spawn(small_scene(), RenderSettings::default(), 1, || {});
    wait_for(&worker, |f| f.spp >= 1);
    worker.send(Command::PanicInNextPass);
    let start = Instant::now();
    let failure = loop {
        if let Some(f) = worker.take_failure() {
            break f;
        }
        assert!(start.elapsed() < Duration::from_secs(60), "the failure never reached the handle");
        std::thread::sleep(Duration::from_millis(2));
    };
    assert!(failure.contains("panicked") && failure.contains("injected"), "{failure}");
    // Stalled, not dead: the next command that restarts an image renders again.
    worker.send(Command::SetSettings(settings(Strategy::Cosine)));
    let f = wait_for(&worker, |f| f.settings.strategy == Strategy::Cosine && f.spp >= 2);
    assert!(f.radiance.iter().all(|v| v.is_finite()));
}
