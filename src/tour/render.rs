//! `illumlab tour FILE --out DIR`: every step rendered headless, as presented (steps folded as the
//! [`Presenter`] folds them), to `NN-title.png` (the view at the step's exposure; compare mode split at the
//! middle, A left), `NN-title-probe-A.png` (and `-B`) where the step probes a point, and `NN-title.json` with the
//! caption, the settings and what was measured. Slides for the instructor, and a check that every step renders.

use super::{Presenter, Tour, TourError};
use crate::render::write_png_rgba;
use crate::scene::load_scene;
use crate::session::comparison::split;
use crate::session::views::shown;
use crate::session::worker::ReferenceStatus;
use crate::session::{Session, series_label};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How `illumlab tour` renders.
#[derive(Clone, Debug)]
pub struct TourRender {
    pub threads: usize,
    /// Samples per pixel of a step that names no target.
    pub spp: u32,
    /// Overrides every step's target (quick checks).
    pub max_spp: Option<u32>,
    /// Pixels on the longer side, overriding the steps'.
    pub resolution: Option<u32>,
    /// Where references are cached (`None`: rendered each time).
    pub reference_cache: Option<PathBuf>,
    pub reference_spp: u32,
    /// A step that takes longer is an error.
    pub timeout: Duration,
}

impl Default for TourRender {
    fn default() -> Self {
        Self {
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
            spp: 64,
            max_spp: None,
            resolution: None,
            reference_cache: crate::measure::default_cache_folder(),
            reference_spp: 1024,
            timeout: Duration::from_secs(600),
        }
    }
}

/// What one step wrote.
#[derive(Clone, Debug)]
pub struct StepOutput {
    pub image: PathBuf,
    pub probe: Vec<PathBuf>,
    pub sidecar: PathBuf,
    pub spp: u32,
    pub seconds: f64,
}

/// Renders every step of `tour` into `out`; `progress` hears of each step as it is written.
pub fn render_tour(
    tour: &Tour,
    out: &Path,
    options: &TourRender,
    mut progress: impl FnMut(usize, &StepOutput),
) -> Result<Vec<StepOutput>, TourError> {
    let fail = |problem: String| TourError::new(&tour.file, None, None, problem);
    std::fs::create_dir_all(out).map_err(|e| fail(format!("cannot create {}: {e}", out.display())))?;
    let first = tour.steps.iter().find_map(|s| s.scene.clone()).unwrap_or_else(|| crate::scene::DEFAULT_SCENE.into());
    let scene = load_scene(&first).map_err(|e| {
        let at = tour.steps.iter().position(|s| s.scene.is_some()).unwrap_or(0);
        TourError::new(&tour.file, Some((at + 1, tour.steps[at].caption.title.clone())), Some("scene"), e.to_string())
    })?;
    let mut session = Session::headless(Arc::new(scene), first, options.threads);
    session.set_reference_cache(options.reference_cache.clone());
    session.set_reference_spp(options.reference_spp);
    // Only a step that shows the error against a reference renders one.
    session.set_reference_for_compare(false);
    let presenter = Presenter::new(tour.clone(), &session);
    let mut written = Vec::new();
    for index in 0..tour.steps.len() {
        let mut step = presenter.effective(index);
        // Another resolution moves the probed pixel with the image.
        let probe = step.probe.take();
        let native = step.resolution;
        step.resolution = options.resolution.or(native);
        let step_error = |(field, problem): (&str, String)| {
            let from = (0..=index).rev().find(|&i| tour.steps[i].names(field)).unwrap_or(index);
            TourError::new(&tour.file, Some((from + 1, tour.steps[from].caption.title.clone())), Some(field), problem)
        };
        step.apply(&mut session).map_err(step_error)?;
        if let Some(pixel) = probe {
            let home = session.home_camera();
            let from = native.unwrap_or(home.width.max(home.height)) as f32;
            let scale = session.camera().width.max(session.camera().height) as f32 / from;
            let pixel = pixel.map(|(x, y)| ((x as f32 * scale) as u32, (y as f32 * scale) as u32));
            let probe_step = super::Step { probe: Some(pixel), ..Default::default() };
            probe_step.apply(&mut session).map_err(step_error)?;
        }
        let target = session.target_spp().unwrap_or(options.spp);
        let target = options.max_spp.map_or(target, |m| m.min(target));
        session.set_sampling(session.pass_size(), Some(target));
        let step = &tour.steps[index];
        let at =
            |problem: String| TourError::new(&tour.file, Some((index + 1, step.caption.title.clone())), None, problem);
        let start = Instant::now();
        loop {
            let update = session.poll();
            if let Some(failure) = update.failure {
                return Err(at(failure));
            }
            let reference_done = !session.view().needs_reference()
                || matches!(session.reference_status(), ReferenceStatus::Ready { .. } | ReferenceStatus::Failed(_));
            let probe_done = session.probe_pixel().is_none() || session.probe_is_current();
            if session.reached(target) && reference_done && probe_done {
                break;
            }
            if start.elapsed() > options.timeout {
                return Err(at(format!("not rendered within {} s", options.timeout.as_secs())));
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        let output = write_step(&session, index, step, out).map_err(at)?;
        progress(index, &output);
        written.push(output);
    }
    Ok(written)
}

/// A file-name-safe form of a title.
fn slug(title: &str) -> String {
    let s: String = title.to_lowercase().chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '-' }).collect();
    let s = s.split('-').filter(|p| !p.is_empty()).collect::<Vec<_>>().join("-");
    s.chars().take(48).collect()
}

fn write_step(s: &Session, index: usize, step: &super::Step, out: &Path) -> Result<StepOutput, String> {
    let stem = match slug(&step.caption.title) {
        t if t.is_empty() => format!("{:02}", index + 1),
        t => format!("{:02}-{t}", index + 1),
    };
    let a = s.frame().ok_or("no frame")?.clone();
    let b = s.frame_b().cloned();
    let reference = s.reference().cloned();
    let view = shown(s.view(), [Some(&*a), b.as_deref()], reference.as_deref(), s.exposure());
    let [Some(rgba_a), rgba_b] = view.rgba else { return Err("no frame".into()) };
    let rgba = match &rgba_b {
        Some(rgba_b) => split(&rgba_a, rgba_b, a.width, 0.5),
        None => rgba_a,
    };
    let image = out.join(format!("{stem}.png"));
    write_png_rgba(&image, a.width, a.height, rgba).map_err(|e| e.to_string())?;
    let mut probe = Vec::new();
    let mut probe_json = Vec::new();
    if let Some(pv) = s.probe_view() {
        for ((report, picture), lane) in pv.lanes.iter().zip(["A", "B"]) {
            let path = out.join(format!("{stem}-probe-{lane}.png"));
            write_png_rgba(&path, picture.width as u32, picture.height as u32, picture.rgba.clone())
                .map_err(|e| e.to_string())?;
            probe.push(path);
            probe_json.push(json!({
                "lane": lane,
                "strategy": report.strategy.name(),
                "estimate": report.run.mean_luminance(),
                "std_error": report.run.luminance_std_error(),
                "quadrature": crate::math::luminance(report.quadrature.value),
                "samples": report.run.samples,
            }));
        }
    }
    let lane = |f: &crate::session::worker::Frame| {
        json!({
            "estimator": series_label(&f.settings),
            "spp": f.spp,
            "cpu_seconds": f.stats.cpu.as_secs_f64(),
            "samples": f.stats.samples,
            "non_finite_dropped": f.stats.non_finite,
        })
    };
    let sidecar = json!({
        "step": index + 1,
        "title": step.caption.title,
        "formula": step.caption.formula,
        "caption": step.caption.text,
        "scene": a.scene_name,
        "width": a.width,
        "height": a.height,
        "view": s.view().slug(),
        "view_note": view.note,
        "exposure_stops": s.exposure(),
        "a": lane(&a),
        "b": b.as_deref().map(lane),
        "layout": if b.is_some() { "split at the middle: A left, B right" } else { "A" },
        "probe_pixel": s.probe_pixel(),
        "probe_material": s.probe_view().and_then(|v| v.point).and_then(|p| {
            s.scene().material_names.get(p.material as usize).cloned()
        }),
        "probe": probe_json,
        "version": env!("CARGO_PKG_VERSION"),
    });
    let path = out.join(format!("{stem}.json"));
    let text = serde_json::to_string_pretty(&sidecar).map_err(|e| e.to_string())?;
    std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(StepOutput { image, probe, sidecar: path, spp: a.spp, seconds: a.elapsed.as_secs_f64() })
}
