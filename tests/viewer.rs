//! The viewer, driven through egui_kittest (no window, no GPU): the controls reach the integrator, restarts are
//! visible in the next frames, screenshots are written, and a broken scene file leaves the viewer usable.

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use illumlab::app::Viewer;
use illumlab::render::{Film, Footprint, Heuristic, Renderer, Strategy};
use illumlab::scene::load_scene;
use illumlab::session::views::View;
use std::sync::Arc;
use std::time::{Duration, Instant};

fn viewer() -> Viewer {
    let mut scene = load_scene("cornell-box").expect("bundled scene");
    scene.camera.width = 48;
    scene.camera.height = 48;
    let mut v = Viewer::with_scene(Arc::new(scene));
    v.set_reference_cache(None); // tests never write to the user's cache
    v
}

fn harness(v: Viewer) -> Harness<'static, Viewer> {
    let mut h =
        Harness::builder().with_size(egui::vec2(1200.0, 1600.0)).build_ui_state(|ui, v: &mut Viewer| v.ui(ui), v);
    h.step();
    h
}

/// Steps the UI until `pred` holds (the worker renders concurrently); fails after 30 s.
fn step_until(h: &mut Harness<'_, Viewer>, what: &str, pred: impl Fn(&Viewer) -> bool) {
    let start = Instant::now();
    while !pred(h.state()) {
        assert!(start.elapsed() < Duration::from_secs(30), "timed out waiting for: {what}");
        std::thread::sleep(Duration::from_millis(5));
        h.step();
    }
}

/// Opens the combo box that shows `current` and clicks `choice` in its popup.
fn choose_in_combo_box(h: &mut Harness<'_, Viewer>, current: &str, choice: &str) {
    h.get_all_by_role(Role::ComboBox)
        .find(|n| n.value().as_deref() == Some(current))
        .unwrap_or_else(|| panic!("no combo box shows {current}"))
        .click();
    // The popup opens on the frame after the click.
    h.step();
    h.step();
    h.get_by_label(choice).click();
}

/// Types `path` into the scene panel's file field, presses Open and waits for the load to end.
fn open_by_path(h: &mut Harness<'_, Viewer>, path: &std::path::Path) {
    h.get_by_label("file").focus();
    h.step();
    h.get_by_label("file").type_text(&path.to_string_lossy());
    h.step();
    h.get_by_label("Open").click();
    h.step();
    step_until(h, "loading to end", |v| !v.is_loading());
    h.step();
}

#[test]
fn choosing_a_strategy_by_its_label_changes_the_render_and_restarts() {
    let mut h = harness(viewer());
    step_until(&mut h, "a few passes", |v| v.frame().is_some_and(|f| f.spp >= 4));
    let before = h.state().frame().map(|f| f.generation).expect("a frame");
    assert_eq!(h.state().frame().map(|f| f.settings.strategy), Some(Strategy::Emitter));
    h.get_by_label("2 cosine").click();
    h.step();
    step_until(&mut h, "a cosine frame", |v| {
        v.frame().is_some_and(|f| f.settings.strategy == Strategy::Cosine && !f.preview)
    });
    let f = h.state().frame().expect("a frame");
    assert!(f.generation > before, "a new generation");
    // Accumulation restarted: the film holds exactly samples 0..spp of the new strategy, none of the old one's
    // (however many passes the worker managed between two UI steps).
    let scene = h.state().scene();
    let mut film = Film::new(f.width, f.height);
    Renderer::new(std::sync::Arc::new(scene.clone()), f.settings).render_pass(&mut film, 0, f.spp, &|| false);
    assert_eq!(f.radiance, film.means(), "the cosine frame at {} spp is a fresh cosine render", f.spp);
}

#[test]
fn keyboard_chooses_strategies() {
    let mut h = harness(viewer());
    h.key_press(egui::Key::Num3);
    h.step();
    step_until(&mut h, "a brdf frame", |v| v.frame().is_some_and(|f| f.settings.strategy == Strategy::Brdf));
}

#[test]
fn a_material_slider_change_restarts() {
    let mut h = harness(viewer());
    step_until(&mut h, "a few passes", |v| v.frame().is_some_and(|f| f.spp >= 4));
    let before = h.state().frame().map(|f| f.generation).expect("a frame");
    let alpha = h.state().scene().materials[0].alpha;
    h.get_by_role_and_label(Role::Slider, "α").set_value_accesskit(500.0);
    h.step();
    assert_ne!(h.state().scene().materials[0].alpha, alpha, "the slider changed α");
    step_until(&mut h, "a frame of the new generation", |v| v.frame().is_some_and(|f| f.generation > before));
}

#[test]
fn the_screenshot_button_writes_png_exr_and_json() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut v = viewer();
    v.set_export_folder(dir.path().join("shots").to_string_lossy().into_owned());
    let mut h = harness(v);
    step_until(&mut h, "a frame", |v| v.frame().is_some());
    h.get_by_label("Save screenshot (S)").click();
    h.step();
    let names: Vec<String> = std::fs::read_dir(dir.path().join("shots"))
        .expect("the folder was created")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    for ext in ["png", "exr", "json"] {
        assert!(
            names.iter().any(|n| n.starts_with("cornell-box-emitter-") && n.ends_with(&format!("spp.{ext}"))),
            "{ext} missing: {names:?}"
        );
    }
    let json = names.iter().find(|n| n.ends_with(".json")).expect("sidecar");
    let text = std::fs::read_to_string(dir.path().join("shots").join(json)).expect("readable");
    for key in ["\"scene\"", "\"strategy\"", "\"spp\"", "\"seconds\"", "\"seed\"", "\"version\"", "\"camera\""] {
        assert!(text.contains(key), "{key} missing from the sidecar");
    }
}

#[test]
fn an_unwritable_screenshot_folder_is_shown_not_fatal() {
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("a-file");
    std::fs::write(&file, "not a folder").expect("write");
    let mut v = viewer();
    v.set_export_folder(file.join("shots").to_string_lossy().into_owned());
    let mut h = harness(v);
    step_until(&mut h, "a frame", |v| v.frame().is_some());
    h.get_by_label("Save screenshot (S)").click();
    h.step();
    assert!(h.state().error().is_some_and(|e| e.contains("screenshot not saved")), "{:?}", h.state().error());
    h.step();
    assert!(h.query_by_label_contains("screenshot not saved").is_some(), "the error is on screen");
}

#[test]
fn a_broken_scene_file_shows_an_error_and_the_previous_scene_stays_usable() {
    let dir = tempfile::tempdir().expect("temp dir");
    let broken = dir.path().join("broken.toml");
    std::fs::write(&broken, "[camera]\neye = [0, 1, 2\n").expect("write");
    let mut h = harness(viewer());
    step_until(&mut h, "a frame", |v| v.frame().is_some());
    open_by_path(&mut h, &broken);
    let error = h.state().error().expect("an error").to_string();
    assert!(error.contains("broken.toml"), "{error}");
    assert!(h.query_by_label_contains("broken.toml").is_some(), "the error is on screen");
    assert_eq!(h.state().scene().name, "cornell-box");
    // Still rendering, and still controllable.
    h.get_by_label("4 emitter").click();
    h.get_by_label("1 uniform").click();
    h.step();
    step_until(&mut h, "a uniform frame", |v| v.frame().is_some_and(|f| f.settings.strategy == Strategy::Uniform));
}

#[test]
fn a_scene_whose_mtl_is_missing_loads_and_says_so() {
    let dir = tempfile::tempdir().expect("temp dir");
    let obj = dir.path().join("lonely.obj");
    std::fs::write(&obj, "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl marble\nf 1 2 3\n").expect("write");
    let mut h = harness(viewer());
    step_until(&mut h, "a frame", |v| v.frame().is_some());
    open_by_path(&mut h, &obj);
    assert!(h.state().error().is_none(), "{:?}", h.state().error());
    assert_eq!(h.state().scene().name, "lonely");
    assert!(h.query_by_label_contains("no such MTL file").is_some(), "the missing MTL is on screen");
    assert!(h.query_by_label_contains("marble").is_some(), "the unknown material is on screen");
}

/// A file dropped on the window, as eframe hands it over.
#[derive(Debug)]
struct Dropped(std::path::PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &std::path::Path {
        &self.0
    }

    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

#[test]
fn a_dropped_scene_opens_joins_the_recent_files_and_a_dropped_text_file_is_an_error() {
    let dir = tempfile::tempdir().expect("temp dir");
    let obj = dir.path().join("dropped.obj");
    let mtl = "newmtl l\nKe 1 1 1\n";
    std::fs::write(dir.path().join("dropped.mtl"), mtl).expect("write");
    std::fs::write(&obj, "mtllib dropped.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl l\nf 1 2 3\n").expect("write");
    let mut v = viewer();
    v.set_recent_file(dir.path().join("config/recent"));
    let mut h = harness(v);
    step_until(&mut h, "a frame", |v| v.frame().is_some());
    h.input_mut().dropped_files.push(Arc::new(Dropped(obj.clone())));
    h.step();
    step_until(&mut h, "loading to end", |v| !v.is_loading());
    h.step();
    assert_eq!(h.state().scene().name, "dropped");
    assert_eq!(h.state().recent_files(), [obj.to_string_lossy()]);
    let saved = std::fs::read_to_string(dir.path().join("config/recent")).expect("the list is saved");
    assert_eq!(saved.trim(), obj.to_string_lossy());
    // The recent list is on screen, and opens again from there.
    choose_in_combo_box(&mut h, "open a recent file", &obj.to_string_lossy());
    h.step();
    step_until(&mut h, "loading to end", |v| !v.is_loading());
    assert_eq!(h.state().scene().name, "dropped");
    // Something that is neither a scene nor a reference: an error, and the scene stays.
    h.input_mut().dropped_files.push(Arc::new(Dropped(dir.path().join("notes.txt"))));
    h.step();
    h.step();
    assert!(h.state().error().is_some_and(|e| e.contains("notes.txt")), "{:?}", h.state().error());
    assert_eq!(h.state().scene().name, "dropped");
}

#[test]
fn choosing_a_bundled_scene_loads_it_in_the_background() {
    let mut h = harness(viewer());
    step_until(&mut h, "a frame", |v| v.frame().is_some());
    choose_in_combo_box(&mut h, "cornell-box", "near-light");
    h.step();
    step_until(&mut h, "the near-light frame", |v| v.frame().is_some_and(|f| f.scene_name == "near-light"));
    assert_eq!(h.state().scene().name, "near-light");
}

#[test]
fn mis_controls_reach_the_integrator() {
    let mut h = harness(viewer());
    h.get_by_label("8 mis").click();
    h.step();
    h.step();
    h.get_by_role_and_label(Role::RadioButton, "balance").click();
    h.step();
    step_until(&mut h, "a balance-heuristic MIS frame", |v| {
        v.frame()
            .is_some_and(|f| f.settings.strategy == Strategy::Mis && f.settings.mis.heuristic == Heuristic::Balance)
    });
    h.get_by_role_and_label(Role::Slider, "technique 1 / 2 split").set_value_accesskit(3.0);
    h.step();
    step_until(&mut h, "a 3 + 1 split", |v| v.frame().is_some_and(|f| f.settings.mis.samples == [3, 1]));
}

/// Compare mode end to end: enter it, swap A and B, move the wipe (slider and drag), switch budgets, look at the
/// difference of identical estimators, export.
#[test]
fn compare_mode_swap_wipe_budgets_and_export() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut v = viewer();
    v.set_export_folder(dir.path().join("shots").to_string_lossy().into_owned());
    v.set_reference_cache(Some(dir.path().join("cache")));
    v.set_reference_spp(64);
    let mut h = harness(v);
    step_until(&mut h, "a frame", |v| v.frame().is_some());

    h.get_by_label("Compare A | B (C)").click();
    h.step();
    assert!(h.state().is_comparing());
    step_until(&mut h, "A and B frames", |v| {
        v.frame().is_some_and(|f| f.spp >= 2) && v.frame_b().is_some_and(|f| f.spp >= 2)
    });
    assert_eq!(h.state().frame_b().map(|f| f.settings.strategy), Some(Strategy::Cosine));

    h.get_by_label("Swap A/B (X)").click();
    h.step();
    step_until(&mut h, "swapped frames", |v| {
        v.frame().is_some_and(|f| f.settings.strategy == Strategy::Cosine)
            && v.frame_b().is_some_and(|f| f.settings.strategy == Strategy::Emitter)
    });

    h.get_by_role_and_label(Role::Slider, "wipe").set_value_accesskit(0.25);
    h.step();
    assert!((h.state().wipe() - 0.25).abs() < 1e-6);
    // Drag the line itself from a quarter to three quarters of the image.
    let rect = h.state().image_rect().expect("drawn");
    let y = rect.center().y;
    let (from, to) = (rect.min.x + 0.25 * rect.width(), rect.min.x + 0.75 * rect.width());
    h.hover_at(egui::pos2(from, y));
    h.step();
    h.drag_at(egui::pos2(from, y));
    h.step();
    for k in 1..=4 {
        h.hover_at(egui::pos2(from + (to - from) * k as f32 / 4.0, y));
        h.step();
    }
    h.drop_at(egui::pos2(to, y));
    h.step();
    assert!((h.state().wipe() - 0.75).abs() < 0.02, "wipe {}", h.state().wipe());

    h.get_by_label("equal time").click();
    h.step();
    assert_eq!(h.state().budget(), illumlab::session::worker::Budget::EqualTime);
    step_until(&mut h, "equal-time frames", |v| {
        v.frame().is_some_and(|f| f.spp >= 4) && v.frame_b().is_some_and(|f| f.spp >= 2)
    });
    h.get_by_label("equal samples").click();
    h.step();
    assert_eq!(h.state().budget(), illumlab::session::worker::Budget::EqualSamples);

    // Both lanes past the restart of the budget change (frames of the current settings: `reached`), each with a
    // recorded run.
    step_until(&mut h, "the reference and a recorded run", |v| {
        v.session().reached(2) && v.reference().is_some() && v.history().iter().any(|s| s.points.len() >= 2)
    });
    // The convergence window: its plots, the efficiency table and the winner (kittest also fails on any glyph the
    // fonts cannot draw).
    h.key_press(egui::Key::P);
    h.step();
    h.step();
    assert!(h.query_by_label_contains("1/(relMSE·s)").is_some(), "the efficiency table is shown");
    assert!(h.query_all_by_label_contains("best").count() >= 1, "a winner is highlighted");
    h.get_by_role_and_label(Role::RadioButton, "RMSE").click();
    h.step();
    h.get_by_label("Export comparison").click();
    h.step();
    let folder = std::fs::read_dir(dir.path().join("shots"))
        .expect("the export folder was created")
        .map(|e| e.expect("entry").path())
        .find(|p| p.is_dir())
        .expect("a comparison folder");
    let name = folder.file_name().expect("name").to_string_lossy().into_owned();
    assert!(name.starts_with("cornell-box-cosine-vs-emitter-"), "{name}");
    for file in [
        "split.png",
        "a.png",
        "b.png",
        "a.exr",
        "b.exr",
        "std-error-a.png",
        "relative-variance-b.png",
        "abs-error-a.png",
        "fireflies-b.png",
        "difference.png",
        "convergence.png",
        "comparison.json",
    ] {
        assert!(folder.join(file).exists(), "{file} missing in {name}");
    }
    let json = std::fs::read_to_string(folder.join("comparison.json")).expect("sidecar");
    for key in ["\"budget\"", "\"wipe\"", "\"rmse\"", "\"reference\"", "\"scales\"", "\"cpu_seconds\""] {
        assert!(json.contains(key), "{key} missing from the sidecar");
    }
}

#[test]
fn identical_estimators_differ_nowhere_and_error_views_switch() {
    let mut v = viewer();
    v.configure(illumlab::render::RenderSettings::default(), Some(4), 0.0);
    let mut h = harness(v);
    h.key_press(egui::Key::C);
    h.step();
    choose_in_combo_box(&mut h, "cosine", "emitter");
    h.step();
    step_until(&mut h, "both lanes at the target", |v| {
        v.frame_b().is_some_and(|b| b.settings.strategy == Strategy::Emitter && b.spp == 4)
            && v.frame().is_some_and(|a| a.spp == 4)
    });
    let (a, b) = (h.state().frame().expect("A"), h.state().frame_b().expect("B"));
    assert_eq!(a.radiance, b.radiance, "common random numbers: A − B = 0 everywhere");
    // The view key cycles image → standard error → relative variance → |I − R| → fireflies → |A − B|.
    let expected = [View::StdError, View::RelativeVariance, View::AbsError, View::Fireflies, View::Difference];
    for view in expected {
        h.key_press(egui::Key::V);
        h.step();
        assert_eq!(h.state().view(), view);
    }
    h.step();
    assert_eq!(h.state().view_note(), Some("zero everywhere"));
}

/// A click on the image at `pos` (press and release in separate frames, as a person's).
fn click_at(h: &mut Harness<'_, Viewer>, pos: egui::Pos2, modifiers: egui::Modifiers) {
    h.event(egui::Event::ModifiersChanged(modifiers));
    h.hover_at(pos);
    h.step();
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton { pos, button: egui::PointerButton::Primary, pressed, modifiers });
        h.step();
    }
    h.event(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
    h.step();
}

/// The probe end to end: `I` and a click on the image probe that pixel (Ctrl-click too); switching the strategy
/// updates the probe's samples and density; the chi-square button shows a p-value.
#[test]
fn clicking_the_image_probes_that_pixel_and_follows_the_strategy() {
    let mut h = harness(viewer());
    step_until(&mut h, "a frame", |v| v.frame().is_some());
    h.step();
    let rect = h.state().image_rect().expect("the image is drawn");
    let at = |x: f32, y: f32| rect.min + egui::vec2(x + 0.5, y + 0.5) * (rect.width() / 48.0);
    h.key_press(egui::Key::I);
    h.step();
    click_at(&mut h, at(12.0, 44.0), egui::Modifiers::NONE);
    step_until(&mut h, "a probe of pixel 12,44", |v| {
        v.probe_view().is_some_and(|p| p.request.pixel == (12, 44) && p.point.is_some() && !p.lanes.is_empty())
    });
    let view = h.state().probe_view().expect("a probe");
    let (emitter, _) = &view.lanes[0];
    assert_eq!(emitter.strategy, Strategy::Emitter);
    assert!(emitter.run.records.iter().any(|r| r.outcome == illumlab::render::Outcome::Contributed));
    let emitter_density = emitter.maps.density.clone();
    // The strategy radio updates the probe: other samples, another density.
    h.get_by_label("2 cosine").click();
    h.step();
    step_until(&mut h, "a cosine probe", |v| v.probe_view().is_some_and(|p| p.lanes[0].0.strategy == Strategy::Cosine));
    let cosine = &h.state().probe_view().expect("a probe").lanes[0].0;
    assert_ne!(cosine.maps.density, emitter_density, "the density layer follows the strategy");
    assert!(h.query_by_label_contains("cosine — p(ω) = (ω·n)/π").is_some(), "the panel names the strategy and its pdf");
    // The chi-square button.
    h.get_by_label("Chi-square here").click();
    h.step();
    step_until(&mut h, "a chi-square result", |v| v.probe_view().is_some_and(|p| p.lanes[0].0.chi2.is_some()));
    h.step();
    assert!(h.query_by_label_contains("at 1%), ").is_some(), "the p-value is shown");
    // Ctrl-click elsewhere, probe mode off.
    h.key_press(egui::Key::I);
    h.step();
    click_at(&mut h, at(30.0, 40.0), egui::Modifiers::COMMAND);
    step_until(&mut h, "a probe of pixel 30,40", |v| v.probe_view().is_some_and(|p| p.request.pixel == (30, 40)));
}

/// The measurement mode: "Fixed primary hits" sends the centre footprint to the integrator, the panel says what
/// the errors then contain, and the reference it computes is the centre footprint's (the same image as a
/// headless render with the reference settings), not the box-filtered picture's.
#[test]
fn fixed_primary_hits_reach_the_integrator_and_the_reference() {
    let mut h = harness(viewer());
    h.get_by_label("Fixed primary hits (measure the estimator)").click();
    h.step();
    step_until(&mut h, "a centre-footprint frame", |v| {
        v.frame().is_some_and(|f| f.settings.footprint == Footprint::Centre)
    });
    assert!(h.query_by_label_contains("Errors: fixed primary hits").is_some(), "the mode is said");
    h.get_by_label("Compute reference").click();
    h.step();
    step_until(&mut h, "the reference", |v| v.reference().is_some());
    let reference = h.state().reference().expect("ready").clone();
    let scene = Arc::new(h.state().scene().clone());
    let mut film = Film::new(48, 48);
    let settings = illumlab::measure::reference_settings(Footprint::Centre);
    Renderer::new(scene, settings).render_pass(&mut film, 0, reference.spp, &|| false);
    assert!(film.means() == reference.mean, "the reference is the centre footprint's");
}

fn guide_status(v: &Viewer) -> Option<illumlab::guiding::TrainingStatus> {
    v.frame()?.guide.as_ref().map(|(t, _)| *t)
}

/// `guided` in the viewer: it learns as the viewer refines and says so in the status bar, freezes after its
/// training spp (six iterations at the default 64), and *Reset guide* starts learning again from the first sample.
#[test]
fn guided_learns_as_it_refines_and_reset_guide_starts_again() {
    let mut h = harness(viewer());
    h.get_by_label("9 guided").click();
    h.step();
    step_until(&mut h, "the guide to learn", |v| guide_status(v).is_some_and(|t| t.learned_spp > 0));
    step_until(&mut h, "the guide to freeze", |v| guide_status(v).is_some_and(|t| t.frozen));
    h.step();
    assert!(h.query_by_label_contains("guide frozen after 6 iterations").is_some(), "the status bar says so");
    let t = guide_status(h.state()).expect("a guide");
    assert!(t.leaves > 1 && t.dtree_nodes > 0 && t.bytes > 0 && !t.kept, "{t:?}");
    let before = h.state().frame().map(|f| f.generation).expect("a frame");
    h.get_by_label("Reset guide").click();
    h.step();
    step_until(&mut h, "learning again", |v| {
        v.frame().is_some_and(|f| f.generation > before && !f.preview)
            && guide_status(v).is_some_and(|t| !t.frozen && !t.kept && t.iteration < 6)
    });
}

/// Presenting the lecture: Page Down goes to the next step (its strategy, view and caption on screen), Page Up
/// returns; the presenter view hides the side panel; Ctrl + scales the UI and is remembered, not an exposure change.
#[test]
fn a_tour_steps_with_page_down_and_page_up() {
    let mut v = viewer();
    let dir = tempfile::tempdir().unwrap();
    let scale_file = dir.path().join("ui-scale");
    v.set_ui_scale_file(scale_file.clone());
    v.present(illumlab::tour::Tour::lecture());
    let mut h = harness(v);
    let lecture = illumlab::tour::Tour::lecture();
    let check = |h: &mut Harness<'_, Viewer>, i: usize| {
        let step = &lecture.steps[i];
        h.step();
        assert_eq!(h.state().presenter().map(|p| p.index()), Some(i));
        assert!(h.query_by_label(&step.caption.title).is_some(), "the title of step {} is on screen", i + 1);
        assert!(h.query_by_label(&step.caption.text).is_some(), "the caption of step {} is on screen", i + 1);
        let s = h.state().session();
        if let Some(strategy) = step.strategy {
            assert_eq!(s.settings().strategy, strategy);
        }
        if let Some(view) = step.view {
            assert_eq!(s.view(), view);
        }
        if let Some(compare) = step.compare {
            assert_eq!(s.is_comparing(), compare.is_some());
        }
    };
    check(&mut h, 0);
    assert!(h.state().is_presenting() && h.query_by_label("Strategy").is_none(), "the presenter view hides the panels");
    step_until(&mut h, "the first step's image", |v| v.frame().is_some_and(|f| !f.preview));
    h.key_press(egui::Key::PageDown);
    check(&mut h, 1);
    h.key_press(egui::Key::PageDown);
    check(&mut h, 2);
    assert_eq!(h.state().session().view(), View::RelativeVariance);
    h.key_press(egui::Key::PageUp);
    check(&mut h, 1);
    assert_eq!(h.state().session().view(), View::Image, "Page Up returns to the step's view");
    h.key_press(egui::Key::ArrowRight);
    check(&mut h, 2);
    h.key_press(egui::Key::ArrowLeft);
    check(&mut h, 1);
    step_until(&mut h, "the step's images", |v| v.frame().is_some_and(|f| f.settings.strategy == Strategy::Cosine));
    // Every step, forwards (its caption drawn: every glyph of the formulas exists in egui's fonts), then back.
    h.key_press(egui::Key::Home);
    check(&mut h, 0);
    for i in 1..lecture.steps.len() {
        h.key_press(egui::Key::PageDown);
        check(&mut h, i);
    }
    for i in (0..lecture.steps.len() - 1).rev() {
        h.key_press(egui::Key::PageUp);
        check(&mut h, i);
    }

    // T leaves the presenter view: the panels are back, with the tour's step list.
    h.key_press(egui::Key::T);
    h.step();
    assert!(h.query_by_label("Strategy").is_some() && h.query_by_label("presenter view (T)").is_some());

    // Ctrl + zooms the UI (egui's own shortcut), is remembered in the file, and leaves the exposure alone.
    let exposure = h.state().session().exposure();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Plus);
    h.step();
    h.step();
    assert!(h.ctx.zoom_factor() > 1.0, "zoomed: {}", h.ctx.zoom_factor());
    assert_eq!(h.state().session().exposure(), exposure);
    let saved: f32 = std::fs::read_to_string(&scale_file).expect("remembered").trim().parse().unwrap();
    assert_eq!(saved, h.ctx.zoom_factor());
}

/// An invalid tour file opened from the side panel is one error on screen naming the step and the field; the
/// viewer keeps rendering. "Save this view as a step" writes a tour that "Present" then presents.
#[test]
fn an_invalid_tour_is_an_error_on_screen_and_a_saved_view_presents() {
    let dir = tempfile::tempdir().unwrap();
    let present = |h: &mut Harness<'_, Viewer>, path: &std::path::Path, button: &str| {
        h.get_by_label("tour file").focus();
        h.step();
        h.get_by_label("tour file").type_text(&path.to_string_lossy());
        h.step();
        h.get_by_label(button).click();
        h.step();
    };
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "[[step]]\ntitle = \"First\"\nview = \"noise\"\n").unwrap();
    let mut h = harness(viewer());
    step_until(&mut h, "a frame", |v| v.frame().is_some());
    present(&mut h, &bad, "Present");
    let error = h.state().error().expect("an error on screen").to_string();
    assert!(error.contains("step 1 (\"First\"), field `view`") && error.contains("noise"), "{error}");
    assert!(h.state().presenter().is_none());
    let g = h.state().frame().unwrap().generation;
    h.key_press(egui::Key::R);
    step_until(&mut h, "rendering to go on", |v| v.frame().is_some_and(|f| f.generation > g));

    let mut h = harness(viewer());
    step_until(&mut h, "a frame", |v| v.frame().is_some());
    h.get_by_label("3 brdf").click();
    h.step();
    let saved = dir.path().join("saved.toml");
    present(&mut h, &saved, "Save this view as a step");
    let tour = illumlab::tour::Tour::load(saved.to_str().unwrap()).expect("the saved tour loads");
    assert_eq!(tour.steps.len(), 1);
    assert_eq!(tour.steps[0].strategy, Some(Strategy::Brdf));
    h.get_by_label("1 uniform").click();
    h.step();
    h.get_by_label("Present").click();
    h.step();
    assert_eq!(h.state().presenter().map(|p| p.tour.steps.len()), Some(1));
    assert_eq!(h.state().session().settings().strategy, Strategy::Brdf, "the saved step's strategy is back");
}
