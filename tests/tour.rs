//! Tours, headless: every step of the bundled lecture renders (`illumlab tour`'s library function, and the CLI);
//! a malformed tour gives one error naming its step and field; a step saved from a session gives that session's
//! view back; stepping backwards shows what stepping forwards showed.

use illumlab::render::{Footprint, Strategy};
use illumlab::scene::{LightSelection, load_scene};
use illumlab::session::Session;
use illumlab::session::views::View;
use illumlab::session::worker::Budget;
use illumlab::tour::{Caption, Presenter, Step, Tour, TourRender, parse_tour, render_tour, step_toml};
use std::sync::Arc;
use std::time::Duration;

#[test]
fn the_bundled_lecture_covers_the_lecture_in_order() {
    let tour = Tour::lecture();
    assert_eq!(tour.title, "Illumination Integrals");
    let strategies: Vec<Strategy> = tour.steps.iter().filter_map(|s| s.strategy).collect();
    // Uniform first, then cosine, BRDF, emitter …, path guiding last; every strategy of the registry appears.
    assert_eq!(strategies.first(), Some(&Strategy::Uniform));
    assert_eq!(strategies.last(), Some(&Strategy::Guided));
    for s in Strategy::ALL {
        assert!(strategies.contains(&s), "the tour never shows {}", s.name());
    }
    let position = |s: Strategy| strategies.iter().position(|x| *x == s).unwrap();
    assert!(position(Strategy::Cosine) < position(Strategy::Brdf));
    assert!(position(Strategy::Brdf) < position(Strategy::Emitter));
    assert!(position(Strategy::Emitter) < position(Strategy::SolidAngle));
    assert!(position(Strategy::SolidAngle) < position(Strategy::ProjectedSolidAngle));
    // p_Δ: a step by area, then one by power.
    let selections: Vec<LightSelection> = tour.steps.iter().filter_map(|s| s.light_selection).collect();
    assert!(selections.windows(2).any(|w| w == [LightSelection::Area, LightSelection::Power]));
    for (i, step) in tour.steps.iter().enumerate() {
        let c = &step.caption;
        assert!(!c.title.is_empty() && !c.formula.is_empty() && !c.text.is_empty(), "step {} lacks a caption", i + 1);
    }
}

#[test]
fn every_step_of_the_bundled_tour_renders_headless() {
    let tour = Tour::lecture();
    let dir = tempfile::tempdir().unwrap();
    let options = TourRender {
        threads: 2,
        max_spp: Some(2),
        resolution: Some(40),
        reference_cache: None,
        reference_spp: 4,
        timeout: Duration::from_secs(120),
        ..TourRender::default()
    };
    let mut heard = 0;
    let written = render_tour(&tour, dir.path(), &options, |_, _| heard += 1).expect("every step renders");
    assert_eq!((written.len(), heard), (tour.steps.len(), tour.steps.len()));
    for (step, out) in tour.steps.iter().zip(&written) {
        let image = image::open(&out.image).expect("a PNG").to_rgb8();
        assert_eq!(image.width().max(image.height()), 40);
        assert!(image.pixels().any(|p| p.0 != [0, 0, 0]), "{} is black", out.image.display());
        assert_eq!(out.spp, 2);
        let sidecar: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&out.sidecar).unwrap()).unwrap();
        assert_eq!(sidecar["title"], step.caption.title.as_str());
        assert_eq!(sidecar["formula"], step.caption.formula.as_str());
        assert_eq!(sidecar["caption"], step.caption.text.as_str());
        assert!(
            sidecar["view_note"].is_null(),
            "{}: the view fell back to the image: {}",
            out.image.display(),
            sidecar["view_note"]
        );
        for probe in &out.probe {
            assert!(image::open(probe).is_ok(), "{} is no picture", probe.display());
        }
    }
    // Compare steps have a probe picture per lane; the first step (no compare) has one.
    assert_eq!(written[0].probe.len(), 1);
    assert_eq!(written[1].probe.len(), 2);
}

#[test]
fn the_tour_command_renders_and_a_bad_tour_is_one_line_and_a_failure() {
    let dir = tempfile::tempdir().unwrap();
    let tour = dir.path().join("mine.toml");
    std::fs::write(
        &tour,
        "title = \"mine\"\n[[step]]\ntitle = \"One\"\nscene = \"cornell-box\"\nstrategy = \"cosine\"\ntarget_spp = 2\n\
         [[step]]\ntitle = \"Two\"\ncompare = \"uniform\"\nview = \"std-error\"\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_illumlab"))
        .args(["tour", tour.to_str().unwrap(), "--out", out.to_str().unwrap(), "--resolution", "32", "--threads", "2"])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(out.join("01-one.png").is_file() && out.join("02-two.png").is_file() && out.join("02-two.json").is_file());

    std::fs::write(&tour, "[[step]]\ntitle = \"One\"\nstrategy = \"cosinus\"\n").unwrap();
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_illumlab"))
        .args(["tour", tour.to_str().unwrap(), "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("step 1") && stderr.contains("`strategy`") && stderr.contains("cosinus"), "{stderr}");
    // `view --tour` with a bad tour fails the same way, before a window opens.
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_illumlab"))
        .args(["view", "--tour", tour.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("`strategy`"));
    // A bundled scene's name after --tour is a mistake of order, said so.
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_illumlab"))
        .args(["view", "--tour", "cornell-box"])
        .output()
        .unwrap();
    assert!(!run.status.success());
    assert!(
        String::from_utf8_lossy(&run.stderr).contains("put it before --tour"),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

/// Each malformed tour, and the step and field its one error must name.
#[test]
fn a_malformed_tour_names_the_step_and_the_field() {
    let cases = [
        (
            "[[step]]\ntitle = \"A\"\n[[step]]\ntitle = \"B\"\nstrat = \"cosine\"\n",
            "step 2 (\"B\"), field `strat`",
            "unknown field",
        ),
        ("[[step]]\nstrategy = \"cosinus\"\n", "step 1, field `strategy`", "unknown strategy `cosinus`"),
        ("[[step]]\ncompare = \"nope\"\n", "step 1, field `compare`", "unknown strategy `nope`"),
        ("[[step]]\nexposure = \"bright\"\n", "step 1, field `exposure`", "expected a number, found string"),
        ("[[step]]\nexposure = 99.0\n", "step 1, field `exposure`", "outside"),
        ("[[step]]\ntarget_spp = 0\n", "step 1, field `target_spp`", "outside"),
        ("[[step]]\nview = \"noise\"\n", "step 1, field `view`", "unknown view `noise`"),
        ("[[step]]\nbudget = \"equal\"\n", "step 1, field `budget`", "unknown budget"),
        ("[[step]]\nprobe = [1]\n", "step 1, field `probe`", "expected [x, y]"),
        ("[[step]]\nlayers = [\"dots\"]\n", "step 1, field `layers`", "unknown layer `dots`"),
        ("[[step]]\ncamera = { eye = [0, 1] }\n", "step 1, field `camera`", "`eye`"),
        ("[[step]]\nmis = { techniques = [\"mis\", \"brdf\"] }\n", "step 1, field `mis`", "own technique"),
        ("[[step]]\n[[step.material]]\nkd = [0.5, 0.5, 0.5]\n", "step 1, field `material`", "needs the `name`"),
        ("titel = \"x\"\n[[step]]\n", "field `titel`", "unknown field"),
        ("[[step]\n", "tour.toml: ", "line 1"),
        ("title = \"empty\"\n", "tour.toml: ", "no steps"),
    ];
    for (text, place, problem) in cases {
        let e = parse_tour(text, "tour.toml").expect_err(text).to_string();
        assert!(e.starts_with("tour.toml: "), "{e}");
        assert!(e.contains(place) && e.contains(problem), "for {text:?}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}

fn session(scene: &str) -> Session {
    let mut s = Session::headless(Arc::new(load_scene(scene).unwrap()), scene, 2);
    s.set_reference_cache(None);
    s
}

/// A step saved from a session (TOML, appended to a file) and applied to a fresh session gives the same view.
#[test]
fn a_saved_step_gives_the_view_back() {
    let mut s = session("cornell-box");
    s.set_resolution(64);
    s.set_settings(illumlab::render::RenderSettings {
        strategy: Strategy::Mis,
        light_selection: LightSelection::Area,
        seed: 7,
        footprint: Footprint::Centre,
        ..s.settings()
    });
    s.set_strategy_b(Strategy::SolidAngle);
    s.set_comparing(true);
    s.set_budget(Budget::EqualTime);
    s.set_view(View::RelativeVariance);
    s.set_exposure(1.5);
    s.set_camera(illumlab::scene::Camera { fov_y: 30.0, ..s.camera() });
    let mut glossy = s.scene().materials[3];
    glossy.alpha = 500.0;
    s.set_material(3, glossy);
    s.set_probe_pixel(Some((20, 50)));
    s.set_sampling(s.pass_size(), Some(32));
    let caption = Caption { title: "Saved".into(), formula: "p = q".into(), text: "Look here.".into() };
    let step = Step::from_session(&s, caption.clone());

    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("my.toml");
    illumlab::tour::append_step(&file, &step).unwrap();
    illumlab::tour::append_step(&file, &step).unwrap();
    let tour = Tour::load(file.to_str().unwrap()).unwrap();
    assert_eq!(tour.steps.len(), 2, "appended twice");
    assert_eq!(tour.steps[0].caption, caption);
    assert_eq!(tour.steps[0], step, "the TOML round trip:\n{}", step_toml(&step));

    let mut t = session("default");
    tour.steps[0].apply(&mut t).unwrap();
    assert_eq!(t.source(), "cornell-box");
    assert_eq!(t.settings(), s.settings());
    assert_eq!(t.settings_b(), s.settings_b());
    assert!(t.is_comparing());
    assert_eq!((t.budget(), t.view(), t.exposure(), t.target_spp()), (s.budget(), s.view(), s.exposure(), Some(32)));
    assert_eq!(t.camera(), s.camera());
    assert_eq!(t.scene().materials, s.scene().materials);
    assert_eq!(t.probe_pixel(), Some((20, 50)));
}

/// What a step shows: scene, A's settings, B's strategy in compare mode, view, exposure, camera, probe.
type Shown = (
    String,
    illumlab::render::RenderSettings,
    Option<Strategy>,
    View,
    f32,
    illumlab::scene::Camera,
    Option<(u32, u32)>,
);

fn shown(s: &Session) -> Shown {
    let b = s.is_comparing().then(|| s.settings_b().strategy);
    (s.source().to_string(), s.settings(), b, s.view(), s.exposure(), s.camera(), s.probe_pixel())
}

/// Page Up returns to what Page Down showed: a step is the fold of the steps up to it.
#[test]
fn stepping_back_shows_what_stepping_forward_showed() {
    let tour = Tour::lecture();
    let mut s = session("default");
    let mut p = Presenter::start(tour.clone(), &mut s).unwrap();
    let mut seen = Vec::new();
    for i in 0..tour.steps.len() {
        if i > 0 {
            p.next(&mut s).unwrap();
        }
        assert_eq!(p.index(), i);
        seen.push(shown(&s));
    }
    p.next(&mut s).unwrap();
    assert_eq!(p.index(), tour.steps.len() - 1, "the last step stays");
    for i in (0..tour.steps.len()).rev() {
        let now = shown(&s);
        assert_eq!(now, seen[i], "step {}", i + 1);
        p.previous(&mut s).unwrap();
    }
    // A step that names another scene drops the earlier scene's probe pixel.
    let step = p.effective(5);
    assert_eq!(step.scene.as_deref(), Some("veach-mis"));
    assert_eq!(step.probe, Some(None));
}

/// A scene a tour step cannot load is an error naming the step and `scene`; the session keeps its scene.
#[test]
fn a_step_whose_scene_does_not_load_is_an_error_and_the_session_stays() {
    let tour = parse_tour("[[step]]\ntitle = \"Gone\"\nscene = \"/no/such/scene.toml\"\n", "t.toml").unwrap();
    let mut s = session("cornell-box");
    let e = Presenter::start(tour, &mut s).err().expect("an error").to_string();
    assert!(e.contains("step 1 (\"Gone\"), field `scene`"), "{e}");
    assert_eq!(s.source(), "cornell-box");
}

fn quick() -> TourRender {
    TourRender {
        threads: 2,
        resolution: Some(32),
        reference_cache: None,
        reference_spp: 4,
        timeout: Duration::from_secs(60),
        ..TourRender::default()
    }
}

/// Under equal time each lane stops at the CPU time the first needed for the target: the step is done then.
#[test]
fn an_equal_time_step_renders() {
    let tour = parse_tour(
        "[[step]]\ntitle = \"T\"\nscene = \"cornell-box\"\nstrategy = \"emitter\"\ncompare = \"projected-solid-angle\"\n\
         budget = \"equal-time\"\ntarget_spp = 8\n",
        "t.toml",
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let written = render_tour(&tour, dir.path(), &quick(), |_, _| {}).expect("the equal-time step renders");
    let sidecar: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&written[0].sidecar).unwrap()).unwrap();
    let (a, b) = (sidecar["a"]["spp"].as_u64().unwrap(), sidecar["b"]["spp"].as_u64().unwrap());
    assert!(a >= 8 || b >= 8, "a lane reached the target ({a}, {b})");
    let (ta, tb) = (sidecar["a"]["cpu_seconds"].as_f64().unwrap(), sidecar["b"]["cpu_seconds"].as_f64().unwrap());
    assert!(ta > 0.0 && tb > 0.0, "both lanes rendered ({ta} s, {tb} s)");
}

/// What a later step sets does not leak into an earlier one; cameras fold field by field; a step that names its
/// scene shows the scene file's camera and materials unless it names its own.
#[test]
fn a_step_shows_the_same_whichever_way_it_is_reached() {
    let tour = parse_tour(
        "[[step]]\ntitle = \"Home\"\nscene = \"cornell-box\"\n\
         [[step]]\ntitle = \"Eye\"\nexposure = 2.0\ncamera = { eye = [0.5, 1.0, 3.5] }\n\
         [[step.material]]\nname = \"glossy\"\nalpha = 500.0\n\
         [[step]]\ntitle = \"Fov\"\ncamera = { fov_y = 30.0 }\n",
        "t.toml",
    )
    .unwrap();
    let mut s = session("default");
    s.set_exposure(-1.0);
    let mut p = Presenter::start(tour, &mut s).unwrap();
    let home = s.camera();
    let glossy = s.scene().materials[3];
    assert_eq!(s.exposure(), -1.0, "the exposure the tour found");
    p.go(2, &mut s).unwrap();
    assert_eq!(s.camera().eye, glam::Vec3::new(0.5, 1.0, 3.5), "step 2's eye stays in step 3");
    assert_eq!(s.camera().fov_y, 30.0);
    assert_eq!((s.exposure(), s.scene().materials[3].alpha), (2.0, 500.0));
    p.go(0, &mut s).unwrap();
    assert_eq!(s.camera(), home, "back to the scene file's camera");
    assert_eq!(s.exposure(), -1.0, "step 2's exposure does not leak back");
    assert_eq!(s.scene().materials[3], glossy, "nor its material");
    // Jumping to step 3 gives what stepping forwards gave.
    p.go(2, &mut s).unwrap();
    assert_eq!((s.camera().eye.x, s.camera().fov_y, s.exposure()), (0.5, 30.0, 2.0));
}

/// A value that cannot be applied (a material the scene lacks, a probe outside the image) names the step that
/// set it, also when reached from a later step.
#[test]
fn an_error_when_applying_names_the_step_that_set_the_field() {
    let tour = parse_tour(
        "[[step]]\ntitle = \"One\"\nscene = \"cornell-box\"\nprobe = [9000, 10]\n\
         [[step]]\ntitle = \"Two\"\nstrategy = \"cosine\"\n\
         [[step]]\ntitle = \"Three\"\nprobe = \"off\"\n[[step.material]]\nname = \"marble\"\nalpha = 5.0\n",
        "t.toml",
    )
    .unwrap();
    let mut s = session("cornell-box");
    let mut p = Presenter::new(tour, &s);
    let e = p.go(1, &mut s).unwrap_err().to_string();
    assert!(e.contains("step 1 (\"One\"), field `probe`") && e.contains("outside"), "{e}");
    let e = p.go(2, &mut s).unwrap_err().to_string();
    assert!(e.contains("step 3 (\"Three\"), field `material`") && e.contains("marble"), "{e}");
}

/// The tour examples (the TOML blocks with steps) in the README and in docs/tours.md parse, and apply to a
/// session; docs/tours.md has at least one.
#[test]
fn the_documented_examples_are_valid_tours() {
    let mut examples = 0;
    for doc in ["README.md", "docs/tours.md"] {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/").to_string() + doc).unwrap();
        for block in text.split("```toml").skip(1) {
            let block = &block[..block.find("```").unwrap_or_else(|| panic!("{doc}: a TOML block is not closed"))];
            if !block.contains("[[step]]") {
                continue;
            }
            let example: String = block.lines().map(|l| l.trim_start().to_string() + "\n").collect();
            let tour = parse_tour(&example, doc).unwrap_or_else(|e| panic!("{e}"));
            let mut s = session("cornell-box");
            Presenter::start(tour, &mut s).unwrap_or_else(|e| panic!("{e}"));
            examples += 1;
        }
    }
    assert!(examples > 0, "docs/tours.md has no tour example");
}
