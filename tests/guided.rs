//! Path guiding (`guided`): the quadtree sampler against its density on the whole sphere, the mixture at a
//! frozen guide, unbiasedness against Lambert's closed form with a well-trained and with adversarial guides, and
//! determinism across thread counts.
//!
//! False-failure rate: the chi-square tests share a 1% family-wise level (Šidák over the file's tests); the
//! unbiasedness checks use 4 standard errors (two-sided 6·10⁻⁵ each, 24 checks: about 0.2%); the rest are exact.

mod common;

use common::chi2::{SIGNIFICANCE, SphereBins};
use common::{floor_under_light, on_surface};
use glam::{DVec3, Vec2, Vec3};
use illumlab::guiding::{Anchor, DTree, Guide, STree, Shape, dir_to_square, square_to_dir};
use illumlab::math::{SampleRng, lambert_polygon_irradiance};
use illumlab::probe::chi2::{p_value, pearson};
use illumlab::probe::{Probe, ProbeRun, density};
use illumlab::render::{Film, MisSettings, RenderSettings, Renderer, SampleContext, ShadingPoint, Strategy};
use illumlab::scene::{Camera, EmitterSampler, LightSelection, Scene, TileLights, load_scene};
use std::f32::consts::PI;
use std::sync::Arc;

/// The chi-square tests in this file, for the Šidák correction.
const CHI2_TESTS: usize = 11;

fn level() -> f64 {
    1.0 - (1.0 - SIGNIFICANCE).powf(1.0 / CHI2_TESTS as f64)
}

/// The synthetic energy maps of the issue: uniform; one hot leaf ten levels deep; a band in cos θ.
fn synthetic_trees() -> Vec<(&'static str, DTree)> {
    let hot = Vec2::new(0.713, 0.291);
    let inside = |c: Vec2, side: f32, s: Vec2| (c.x..c.x + side).contains(&s.x) && (c.y..c.y + side).contains(&s.y);
    vec![
        ("uniform", DTree::from_leaf_energies(Shape::uniform(3), |_, side| side * side)),
        (
            "hot leaf at depth 10",
            DTree::from_leaf_energies(Shape::towards(hot, 10), |c, side| {
                if inside(c, side, hot) { 1.0 } else { 0.3 * side * side }
            }),
        ),
        (
            "band",
            DTree::from_leaf_energies(Shape::uniform(5), |c, side| {
                if (0.40..0.55).contains(&(c.x + side * 0.5)) { side * side } else { 0.01 * side * side }
            }),
        ),
    ]
}

/// Binned on the tree's own leaves, each cut into 4 × 4: the expected share of a cell is the density at its centre
/// times its solid angle (the density is constant over a leaf), computed from `pdf` alone; the observed counts
/// come from `sample` alone.
fn leaf_binned_test(tree: &DTree, n: u64, seed: u64) -> (f64, f64) {
    let leaves = tree.shape().leaves();
    let cells: Vec<(Vec2, f32)> = leaves
        .iter()
        .flat_map(|&(c, side)| {
            let s = side / 4.0;
            (0..16).map(move |k| (c + Vec2::new((k % 4) as f32, (k / 4) as f32) * s, s))
        })
        .collect();
    let expected: Vec<f64> = cells
        .iter()
        .map(|&(c, s)| tree.pdf(square_to_dir(c + Vec2::splat(s * 0.5))) as f64 * 4.0 * PI as f64 * (s * s) as f64)
        .collect();
    let mut observed = vec![0.0; cells.len()];
    let mut rounded_across = 0;
    for k in 0..n {
        let mut rng = SampleRng::new(seed, k, 0);
        let (w, pdf) = tree.sample(&mut rng).expect("a tree with energy draws");
        assert!((w.length() - 1.0).abs() < 1e-4);
        // The density of the leaf drawn from, but for a direction that rounds (f32) across its leaf's edge.
        if (pdf - tree.pdf(w)).abs() > 1e-5 * pdf {
            rounded_across += 1;
        }
        let s = dir_to_square(w);
        let i = cells
            .iter()
            .position(|&(c, side)| (c.x..c.x + side).contains(&s.x) && (c.y..c.y + side).contains(&s.y))
            .expect("every square point is in a cell");
        observed[i] += 1.0;
    }
    assert!(rounded_across as f64 <= 1e-3 * n as f64, "{rounded_across} of {n} draws rounded into another leaf");
    let (statistic, dof) = pearson(&observed, &expected, n as f64);
    (p_value(statistic, dof), expected.iter().sum())
}

#[test]
fn the_quadtree_sampler_matches_its_density_on_the_whole_sphere() {
    for (seed, (name, tree)) in synthetic_trees().into_iter().enumerate() {
        let (p, integral) = leaf_binned_test(&tree, 200_000, 10 + seed as u64);
        assert!((integral - 1.0).abs() < 1e-4, "{name}: ∫ pdf = {integral}");
        assert!(p > level(), "{name}: leaf-binned chi-square p = {p:.2e}");
    }
    // Binned by the generic sphere tester: (cos θ, φ) about +z on the 32 × 32 grid of the trees' finest cells,
    // the density integrated numerically over each.
    for (name, tree) in synthetic_trees().into_iter().filter(|(name, _)| *name != "hot leaf at depth 10") {
        let bins = SphereBins { axis: Vec3::Z, cos_min: -1.0, res_cos: 32, res_phi: 32 };
        let draw = |u: Vec2| {
            let mut rng = SampleRng::new(7, (u.x * 1e9) as u64, (u.y * 1e9) as u64);
            tree.sample(&mut rng).map(|(w, _)| w)
        };
        let out = bins.test(100_000, 3, &draw, &|w| tree.pdf(w) as f64, 6);
        assert!((out.integral - 1.0).abs() < 1e-3, "{name}: ∫ pdf = {}", out.integral);
        assert!(out.p_value > level(), "{name}: sphere-binned chi-square p = {:.2e}", out.p_value);
    }
}

/// A quadtree seen from an anchor (parallax-aware: directions at p aimed where c's direction d meets a plane, the
/// others kept), sampled at a point off the anchor: its draws against its density (`pdf_at`, the quadtree's
/// times the Jacobian), binned on the sphere.
#[test]
fn the_anchored_quadtree_matches_its_density_off_the_anchor() {
    let anchor = Anchor { centre: Vec3::new(0.1, 0.2, -0.1), normal: Vec3::new(0.0, 0.6, 0.8), height: 2.0 };
    let p = Vec3::new(0.45, -0.15, 0.5);
    assert!(anchor.reaches(p));
    let trees = synthetic_trees().into_iter().filter(|(name, _)| *name != "hot leaf at depth 10");
    for (i, (name, tree)) in trees.enumerate() {
        let tree = tree.with_anchor(Some(anchor));
        let bins = SphereBins { axis: Vec3::Z, cos_min: -1.0, res_cos: 32, res_phi: 32 };
        let draw = |u: Vec2| {
            let mut rng = SampleRng::new(17, (u.x * 1e9) as u64, (u.y * 1e9) as u64);
            let (w, pdf) = tree.sample_at(p, &mut rng)?;
            let at = tree.pdf_at(p, w);
            assert!((pdf - at).abs() <= 1e-3 * at, "{name}: draw's pdf {pdf} against pdf_at {at}");
            Some(w)
        };
        let out = bins.test(100_000, 40 + i as u64, &draw, &|w| tree.pdf_at(p, w) as f64, 12);
        assert!((out.integral - 1.0).abs() < 2e-3, "{name}: ∫ pdf = {}", out.integral);
        assert!(out.p_value > level(), "{name}: anchored chi-square p = {:.2e}", out.p_value);
    }
}

/// A floor under a square light (1 m, 1.5 m up), seen by a camera from above, for training.
fn lit_floor() -> (Scene, common::FloorUnderLight) {
    let f = floor_under_light(1.0, 1.5, Vec3::splat(4.0), 2.0);
    let mut scene = f.scene.clone();
    scene.camera =
        Camera { eye: Vec3::new(0.0, 1.2, 2.6), target: Vec3::ZERO, up: Vec3::Y, fov_y: 60.0, width: 48, height: 48 };
    (scene, f)
}

/// Trains `guided` on `scene` for 64 spp and returns its frozen guide.
fn trained_guide(scene: &Scene) -> Arc<Guide> {
    let settings = RenderSettings { strategy: Strategy::Guided, ..Default::default() };
    let mut renderer = Renderer::new(Arc::new(scene.clone()), settings);
    let mut film = Film::new(scene.camera.width, scene.camera.height);
    renderer.render_pass(&mut film, 0, 64, &|| false);
    let training = renderer.training().expect("guided learns");
    assert!(training.is_frozen() && training.log().len() == 6, "{:?}", training.log());
    renderer.guide().expect("a guide").clone()
}

fn context<'a>(scene: &'a Scene, emitters: Option<&'a EmitterSampler>, guide: &'a Guide) -> SampleContext<'a> {
    static MIS: std::sync::OnceLock<MisSettings> = std::sync::OnceLock::new();
    let mis = MIS.get_or_init(MisSettings::default);
    SampleContext { scene, emitters, mis, state: None, guide: Some(guide), tile: &TileLights::NONE }
}

/// The whole mixture (guide + emitter + BRDF) at a frozen guide, binned on the sphere about +z: a synthetic guide
/// whose cells are the bins' (so its part is integrated exactly), the light's and the BRDF's parts numerically.
#[test]
fn the_mixture_matches_its_density_at_a_frozen_guide() {
    let (scene, _) = lit_floor();
    let emitters = EmitterSampler::new(&scene, LightSelection::Power);
    // One spatial leaf; the quadtree favours the upper hemisphere's band around the light (y up: cos θ about z
    // is 0 there) with a little energy everywhere.
    let tree = DTree::from_leaf_energies(Shape::uniform(5), |c, side| {
        let w = square_to_dir(c + Vec2::splat(side * 0.5));
        side * side * (0.05 + w.y.max(0.0).powi(3))
    });
    // Its directions seen from the shading point itself, and from an anchor above the floor (parallax-aware).
    let plane = Anchor { centre: Vec3::new(0.5, 0.2, 0.3), normal: Vec3::Y, height: 1.3 };
    let anchored = tree.clone().with_anchor(Some(plane));
    let guides = [tree, anchored].map(|t| Guide::new(STree::new(Vec3::splat(-2.0), Vec3::splat(2.0)), vec![t], 0));
    let material = scene.materials[0];
    let points = [Vec3::new(0.2, 0.0, -0.1), Vec3::new(1.4, 0.0, 0.9)];
    for (i, (guide, p)) in guides.iter().flat_map(|g| points.map(|p| (g, p))).enumerate() {
        let ctx = context(&scene, emitters.as_ref(), guide);
        let sp = on_surface(&scene, p, Vec3::Y, Vec3::new(0.3, 1.0, 0.2).normalize(), &material);
        assert_eq!(illumlab::render::strategy::guided::weights(&ctx, &sp), [0.5, 0.25, 0.25]);
        let bins = SphereBins { axis: Vec3::Z, cos_min: -1.0, res_cos: 32, res_phi: 32 };
        let draw = |u: Vec2| {
            let mut rng = SampleRng::new(11, (u.x * 1e9) as u64, (u.y * 1e9) as u64);
            let s = Strategy::Guided.sample(&ctx, &sp, &mut rng).expect("the mixture always draws here");
            let pdf = density(&ctx, &sp, Strategy::Guided, s.wi);
            assert!((s.pdf - pdf).abs() <= 1e-4 * pdf + 1e-7, "sample's pdf {} against pdf(ω) {pdf}", s.pdf);
            Some(s.wi)
        };
        let out = bins.test(60_000, 20 + i as u64, &draw, &|w| density(&ctx, &sp, Strategy::Guided, w) as f64, 12);
        assert!((out.integral - 1.0).abs() < 3e-3, "point {p}: ∫ pdf = {}", out.integral);
        assert!(out.p_value > level(), "point {p}: chi-square p = {:.2e}", out.p_value);
    }
}

/// Lambert's closed form for the diffuse floor under the unoccluded square light.
fn lambert(f: &common::FloorUnderLight, p: Vec3) -> f64 {
    let e = lambert_polygon_irradiance(p.as_dvec3(), DVec3::Y, &f.light, f.radiance.x as f64);
    f.kd as f64 / std::f64::consts::PI * e
}

/// `n` one-sample estimates of `guided` at p with the guide `guide`: (mean, standard error) of the red channel.
fn estimate(scene: &Scene, guide: &Guide, p: Vec3, n: u64, seed: u64) -> (f64, f64) {
    let emitters = EmitterSampler::new(scene, LightSelection::Power);
    let ctx = context(scene, emitters.as_ref(), guide);
    let material = scene.materials[0];
    let sp: ShadingPoint = on_surface(scene, p, Vec3::Y, Vec3::new(-0.2, 1.0, 0.5).normalize(), &material);
    let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
    for k in 0..n {
        let mut rng = SampleRng::new(seed, 0, k);
        let v = Strategy::Guided.estimate(&ctx, &sp, &mut rng, &mut 0u64, &mut ()).x as f64;
        assert!(v.is_finite() && v >= 0.0);
        sum += v;
        sum_sq += v * v;
    }
    let mean = sum / n as f64;
    (mean, ((sum_sq / n as f64 - mean * mean) / (n - 1) as f64).max(0.0).sqrt())
}

/// Within 4 standard errors of Lambert's closed form with a guide trained on the scene (with the weights it
/// learned, and with the default weights, which draw half the directions from the guide), a guide trained on
/// another scene, a guide of random energies leaning on it as far as any weights do, and no guide. Under an
/// unoccluded light the learned weights favour light sampling, and do better there than the default weights.
#[test]
fn guided_is_unbiased_with_good_and_adversarial_guides() {
    let (scene, f) = lit_floor();
    let trained = trained_guide(&scene);
    assert!(trained.is_usable() && trained.stree.leaves() > 1, "{} leaves", trained.stree.leaves());
    let mut trained_default = (*trained).clone();
    trained_default.weights.iter_mut().for_each(|w| *w = illumlab::guiding::DEFAULT_WEIGHTS);
    let mut other = load_scene("cornell-box").expect("bundled");
    other.camera.width = 32;
    other.camera.height = 32;
    let elsewhere = trained_guide(&other);
    let random_tree = DTree::from_leaf_energies(Shape::uniform(4), |c, _| {
        let mut rng = SampleRng::new(99, (c.x * 1e6) as u64, (c.y * 1e6) as u64);
        rng.uniform().powi(4)
    });
    // Random energies and, adversarially, weights that lean on the guide as far as any candidate does.
    let mut random = Guide::new(STree::new(Vec3::splat(-2.0), Vec3::splat(2.0)), vec![random_tree], 0);
    random.weights = vec![illumlab::guiding::candidate(illumlab::guiding::CANDIDATES - 1)];
    let empty = Guide::empty(Vec3::splat(-2.0), Vec3::splat(2.0), 0);
    let points = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.7, 0.0, -0.4), Vec3::new(-1.3, 0.0, 1.1)];
    for &p in &points {
        let [_, light, _] = trained.leaf(p).1;
        assert!(light >= 0.5, "at {p} the learned weights should favour light sampling: {:?}", trained.leaf(p).1);
    }
    let mut errors = [0.0f64; 2];
    let guides = [
        ("trained", &*trained),
        ("trained, default weights", &trained_default),
        ("other scene", &*elsewhere),
        ("random", &random),
        ("none", &empty),
    ];
    for (g, (name, guide)) in guides.into_iter().enumerate() {
        for (i, &p) in points.iter().enumerate() {
            let truth = lambert(&f, p);
            let (mean, se) = estimate(&scene, guide, p, 40_000, 100 + i as u64);
            let z = (mean - truth) / se;
            assert!(z.abs() < 4.0, "{name} guide at {p}: {mean} ± {se} against {truth} (z = {z:.2})");
            if g < 2 {
                errors[g] += se / truth;
            }
        }
    }
    assert!(errors[0] < errors[1], "the learned weights should beat the default ones here: {errors:?}");
}

/// After training, the film is the same bit for bit with 1, 2 and 8 threads, and another seed gives another.
#[test]
fn training_gives_the_same_image_with_any_thread_count() {
    let mut scene = load_scene("occluded-light").expect("bundled");
    scene.camera.width = 40;
    scene.camera.height = 40;
    let scene = Arc::new(scene);
    let render = |threads: usize, seed: u64, passes: &[u32]| {
        let settings = RenderSettings { strategy: Strategy::Guided, seed, ..Default::default() };
        let mut renderer = Renderer::new(scene.clone(), settings);
        let mut film = Film::new(40, 40);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        let mut first = 0;
        for &count in passes {
            pool.install(|| renderer.render_pass(&mut film, first, count, &|| false));
            first += count;
        }
        let guide = renderer.guide().expect("guided learns").clone();
        (film, guide)
    };
    // Passes that cut iterations anywhere (the renderer splits them at iterations' ends), and so record an
    // iteration's samples in another order than one pass does.
    let uneven = [5, 11, 27, 37];
    let (one, guide_one) = render(1, 5, &uneven);
    assert!(guide_one.is_usable() && guide_one.stree.leaves() > 1);
    for (threads, passes) in [(2, &uneven[..]), (8, &uneven[..]), (2, &[80][..]), (8, &[1; 80][..])] {
        let (film, guide) = render(threads, 5, passes);
        assert!(film.pixels == one.pixels, "{threads} threads, passes {passes:?}: another film");
        assert!(*guide == *guide_one, "{threads} threads, passes {passes:?}: another guide");
    }
    let (other, _) = render(2, 6, &uneven);
    assert!(other.pixels != one.pixels, "another seed should give another film");
}

/// On occluded-light, at points that see the light only through the hole, with the guide trained on the scene
/// at 128 × 128: within 4 combined standard errors of emitter sampling (unbiased, checked against closed forms
/// elsewhere; the quadrature resolves a light seen through a small hole too poorly to judge by). There the
/// learned weights use the guide (c_g > 0; at this coarse size they trust it less than under a guide trained at
/// 256 × 256), the leaf learned its light through the opening (a focal plane through the hole, near level), and
/// guided's estimate is the less noisy.
#[test]
fn guided_is_unbiased_through_the_opening() {
    let mut scene = load_scene("occluded-light").expect("bundled");
    scene.camera.width = 128;
    scene.camera.height = 128;
    let guide = trained_guide(&scene);
    let settings = RenderSettings { strategy: Strategy::Guided, ..Default::default() };
    let probe = Probe::new(Arc::new(scene), settings).with_guide(Some(guide.clone()));
    let (mut checked, mut variances) = (0, Vec::new());
    for pixel in [(64, 80), (43, 91), (80, 69), (64, 100)] {
        let Some(point) = probe.point(pixel) else { continue };
        let sp = point.shading_point(probe.scene());
        let ctx = probe.context();
        let emitter = ProbeRun::run(&ctx, &sp, Strategy::Emitter, 1_000_000, 4, 0, 0.0);
        if !(emitter.mean_luminance() > 0.0) {
            continue;
        }
        let guided = ProbeRun::run(&ctx, &sp, Strategy::Guided, 200_000, 3, 0, 0.0);
        assert_eq!(guided.non_finite, 0);
        let (a, b) = (guided.mean_luminance(), emitter.mean_luminance());
        let se = (guided.luminance_std_error().powi(2) + emitter.luminance_std_error().powi(2)).sqrt();
        assert!(((a - b) / se).abs() < 4.0, "pixel {pixel:?}: guided {a} against emitter {b} (± {se:.2e})");
        let weights = guide.leaf(sp.p).1;
        assert!(weights[0] > 0.0, "pixel {pixel:?}: the learned weights should use the guide: {weights:?}");
        let anchor = *guide.dtree(sp.p).anchor().expect("the leaf learned through a focal plane");
        // Through the hole's centre (0, 1, 0) within 15 cm (near the lit patch's rim, where the light's edge cuts
        // the rays too, the plane settles between the hole and the light), no more than 20° from level (a leaf
        // that holds the glossy box's sides with the floor tilts it: trained with seeds 0 to 5, the leaves of
        // (64, 80) and (80, 69) settled 9° to 17° from level, those of the other two level).
        let off = anchor.normal.dot(Vec3::Y - anchor.centre) - anchor.height;
        assert!(
            anchor.normal.y > 0.94 && off.abs() < 0.15,
            "pixel {pixel:?}: the leaf's focal plane {anchor:?} should be the ceiling's, y = 1"
        );
        variances.push((guided.relative_variance(b), emitter.relative_variance(b)));
        checked += 1;
    }
    assert!(checked >= 3, "only {checked} lit points checked");
    let (g, e) = variances.iter().fold((0.0, 0.0), |(g, e), v| (g + v.0, e + v.1));
    assert!(g < e, "guided's relative variances {variances:?} should be lower than emitter's over the points");
}
