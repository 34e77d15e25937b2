//! Exporting a comparison: the split image as shown, both images (PNG at the exposure, EXR linear), every error
//! map available on its shared scale, the convergence plot, and a JSON sidecar with settings, budgets, errors
//! and scales. Everything goes into a new folder named after scene, strategies and spp; nothing is overwritten.

use super::snapshot::{SnapshotError, display_rgba};
use super::views::{View, shared_scale, view_values};
use super::worker::{Budget, Frame};
use crate::measure::{Metric, Reference, ReferenceOrigin, Series, error_vs_reference, write_convergence_png};
use crate::render::{Film, write_image, write_png_rgba};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// What is being compared and how it is shown.
pub struct Comparison<'a> {
    pub a: &'a Frame,
    pub b: &'a Frame,
    pub reference: Option<&'a Reference>,
    /// Convergence runs of this session (against the current reference).
    pub series: &'a [Series],
    pub budget: Budget,
    /// Where the split is, as a fraction of the width: A left of it, B right.
    pub wipe: f32,
    pub exposure: f32,
}

/// Writes the comparison into a new folder inside `folder`; returns that folder.
pub fn write_comparison(c: &Comparison, folder: &Path) -> Result<PathBuf, SnapshotError> {
    let (a, b) = (c.a, c.b);
    if (a.width, a.height) != (b.width, b.height) {
        return Err(SnapshotError::Folder(folder.to_path_buf(), "A and B have different sizes".into()));
    }
    let stem = format!(
        "{}-{}-vs-{}-{}spp",
        a.scene_name,
        a.settings.strategy.name(),
        b.settings.strategy.name(),
        a.spp.min(b.spp)
    );
    std::fs::create_dir_all(folder).map_err(|e| SnapshotError::Folder(folder.to_path_buf(), e.to_string()))?;
    // `create_dir` fails on an existing folder, so two exports never share one.
    let mut out = None;
    for i in 0..1000 {
        let candidate = folder.join(if i == 0 { stem.clone() } else { format!("{stem}-{i}") });
        match std::fs::create_dir(&candidate) {
            Ok(()) => {
                out = Some(candidate);
                break;
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(SnapshotError::Folder(candidate, e.to_string())),
        }
    }
    let out = out.ok_or_else(|| SnapshotError::Folder(folder.to_path_buf(), "no free name".into()))?;
    let (w, h) = (a.width, a.height);

    let png = |name: &str, rgba: Vec<u8>| write_png_rgba(&out.join(name), w, h, rgba);
    let (rgba_a, rgba_b) = (display_rgba(&a.radiance, c.exposure), display_rgba(&b.radiance, c.exposure));
    png("split.png", split(&rgba_a, &rgba_b, w, c.wipe))?;
    png("a.png", rgba_a)?;
    png("b.png", rgba_b)?;
    write_image(&Film::from_means(w, h, &a.radiance), &out.join("a.exr"), 0.0)?;
    write_image(&Film::from_means(w, h, &b.radiance), &out.join("b.exr"), 0.0)?;

    let mut scales = serde_json::Map::new();
    for view in View::ALL.into_iter().filter(|v| *v != View::Image) {
        let (Some(va), Some(vb)) =
            (view_values(view, a, c.reference, Some(b)), view_values(view, b, c.reference, Some(a)))
        else {
            continue;
        };
        let Some(scale) = shared_scale(&[&va, &vb]) else { continue };
        if view.needs_comparison() {
            png(&format!("{}.png", view.slug()), scale.colorize(&va))?; // the same map for both lanes
        } else {
            png(&format!("{}-a.png", view.slug()), scale.colorize(&va))?;
            png(&format!("{}-b.png", view.slug()), scale.colorize(&vb))?;
        }
        scales.insert(view.slug().into(), json!({ "lo": scale.lo, "hi": scale.hi, "log": true }));
    }
    if c.series.iter().any(|s| !s.points.is_empty()) {
        let floor = c.reference.map_or(0.0, |r| r.noise_mse().sqrt());
        let title = format!("{}, {} footprint: RMSE against the reference", a.scene_name, a.settings.footprint.name());
        write_convergence_png(&out.join("convergence.png"), &title, c.series, floor, Metric::Mse, "CPU seconds")?;
        let floor = c.reference.map_or(0.0, |r| r.noise_rel_mse().sqrt());
        let title =
            format!("{}, {} footprint: relative RMSE against the reference", a.scene_name, a.settings.footprint.name());
        write_convergence_png(
            &out.join("convergence-relative.png"),
            &title,
            c.series,
            floor,
            Metric::RelMse,
            "CPU seconds",
        )?;
    }

    let sidecar = json!({
        "scene": a.scene_name,
        "width": w,
        "height": h,
        "budget": c.budget.name(),
        "wipe": c.wipe,
        "exposure_stops": c.exposure,
        "common_random_numbers": a.settings.seed == b.settings.seed,
        "a": lane_json(a, c.reference),
        "b": lane_json(b, c.reference),
        "reference": c.reference.map(reference_json),
        "scales": scales,
        "version": env!("CARGO_PKG_VERSION"),
    });
    let path = out.join("comparison.json");
    let text =
        serde_json::to_string_pretty(&sidecar).map_err(|e| SnapshotError::Sidecar(path.clone(), e.to_string()))?;
    std::fs::write(&path, text).map_err(|e| SnapshotError::Sidecar(path.clone(), e.to_string()))?;
    Ok(out)
}

/// A's pixels left of the wipe, B's right of it, and a white line on it.
pub fn split(a: &[u8], b: &[u8], width: u32, wipe: f32) -> Vec<u8> {
    let cut = (wipe.clamp(0.0, 1.0) * width as f32).round() as usize;
    let row = width as usize * 4;
    let mut out = Vec::with_capacity(a.len());
    for (ra, rb) in a.chunks_exact(row).zip(b.chunks_exact(row)) {
        out.extend_from_slice(&ra[..cut * 4]);
        out.extend_from_slice(&rb[cut * 4..]);
        if cut > 0 && cut < width as usize {
            let at = out.len() - row + cut * 4;
            out[at..at + 4].copy_from_slice(&[255, 255, 255, 255]);
        }
    }
    out
}

fn lane_json(f: &Frame, reference: Option<&Reference>) -> Value {
    let errors = reference.filter(|r| r.mean.len() == f.radiance.len()).map(|r| {
        let m = error_vs_reference(&f.radiance, r);
        let seconds = f.stats.cpu.as_secs_f64();
        json!({ "rmse": m.rmse(), "rel_mse": m.rel_mse, "efficiency": m.efficiency(seconds) })
    });
    json!({
        "strategy": f.settings.strategy.name(),
        "light_selection": f.settings.light_selection.name(),
        "mis": format!("{:?}", f.settings.mis),
        "seed": f.settings.seed,
        "footprint": f.settings.footprint.name(),
        "spp": f.spp,
        "cpu_seconds": f.stats.cpu.as_secs_f64(),
        "wall_seconds": f.elapsed.as_secs_f64(),
        "samples": f.stats.samples,
        "non_finite_dropped": f.stats.non_finite,
        "errors": errors,
    })
}

fn reference_json(r: &Reference) -> Value {
    let origin = match &r.origin {
        ReferenceOrigin::Rendered => "rendered".to_string(),
        ReferenceOrigin::Cache(p) => format!("cache: {}", p.display()),
        ReferenceOrigin::File(p) => format!("file: {}", p.display()),
    };
    json!({ "origin": origin, "spp": r.spp, "seconds": r.seconds, "rmse_noise_floor": r.noise_mse().sqrt() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_takes_a_left_and_b_right_with_a_line() {
        let a = vec![10u8; 4 * 4 * 2];
        let b = vec![20u8; 4 * 4 * 2];
        let s = split(&a, &b, 4, 0.5);
        let px = |x: usize, y: usize| s[(y * 4 + x) * 4];
        assert_eq!((px(0, 0), px(1, 1), px(2, 0), px(3, 1)), (10, 10, 255, 20));
        assert_eq!(split(&a, &b, 4, 0.0), b);
        assert_eq!(split(&a, &b, 4, 1.0), a);
    }
}
