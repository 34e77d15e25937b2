//! Screenshot export: the image as displayed (PNG, sRGB after exposure), the linear radiance (EXR) and a JSON
//! sidecar with everything needed to reproduce it. File names say scene, strategy and spp; an existing file is
//! never overwritten (a counter is appended).

use super::worker::Frame;
use crate::render::{OutputError, srgb_bytes};
use serde::Serialize;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum SnapshotError {
    #[error("cannot create the folder {}: {}", .0.display(), .1)]
    Folder(PathBuf, String),
    #[error(transparent)]
    Image(#[from] OutputError),
    #[error("cannot write {}: {}", .0.display(), .1)]
    Sidecar(PathBuf, String),
}

/// The three files written.
#[derive(Clone, Debug)]
pub struct SnapshotPaths {
    pub png: PathBuf,
    pub exr: PathBuf,
    pub json: PathBuf,
}

#[derive(Serialize)]
struct Sidecar<'a> {
    scene: &'a str,
    strategy: &'a str,
    light_selection: &'a str,
    seed: u64,
    spp: u32,
    passes: u32,
    seconds: f64,
    exposure_stops: f32,
    width: u32,
    height: u32,
    camera: CameraJson,
    samples: u64,
    rays: u64,
    non_finite_dropped: u64,
    version: &'a str,
}

#[derive(Serialize)]
struct CameraJson {
    eye: [f32; 3],
    target: [f32; 3],
    up: [f32; 3],
    fov_y: f32,
}

/// Writes `<scene>-<strategy>-<spp>spp.{png,exr,json}` into `folder` (created if needed).
pub fn write_snapshot(frame: &Frame, folder: &Path, exposure: f32) -> Result<SnapshotPaths, SnapshotError> {
    std::fs::create_dir_all(folder).map_err(|e| SnapshotError::Folder(folder.to_path_buf(), e.to_string()))?;
    let stem = format!("{}-{}-{}spp", frame.scene_name, frame.settings.strategy.name(), frame.spp);
    let paths = (0..)
        .map(|i| {
            let name = if i == 0 { stem.clone() } else { format!("{stem}-{i}") };
            let p = folder.join(name);
            SnapshotPaths { png: p.with_extension("png"), exr: p.with_extension("exr"), json: p.with_extension("json") }
        })
        .find(|p| !p.png.exists() && !p.exr.exists() && !p.json.exists())
        .ok_or_else(|| SnapshotError::Folder(folder.to_path_buf(), "no free file name".into()))?;

    let film_like = crate::render::Film::from_means(frame.width, frame.height, &frame.radiance);
    crate::render::write_image(&film_like, &paths.exr, 0.0)?;
    crate::render::write_image(&film_like, &paths.png, exposure)?;
    let c = frame.camera;
    let sidecar = Sidecar {
        scene: &frame.scene_name,
        strategy: frame.settings.strategy.name(),
        light_selection: frame.settings.light_selection.name(),
        seed: frame.settings.seed,
        spp: frame.spp,
        passes: frame.passes,
        seconds: frame.elapsed.as_secs_f64(),
        exposure_stops: exposure,
        width: frame.width,
        height: frame.height,
        camera: CameraJson { eye: c.eye.to_array(), target: c.target.to_array(), up: c.up.to_array(), fov_y: c.fov_y },
        samples: frame.stats.samples,
        rays: frame.stats.rays,
        non_finite_dropped: frame.stats.non_finite,
        version: env!("CARGO_PKG_VERSION"),
    };
    let text = serde_json::to_string_pretty(&sidecar)
        .map_err(|e| SnapshotError::Sidecar(paths.json.clone(), e.to_string()))?;
    std::fs::write(&paths.json, text).map_err(|e| SnapshotError::Sidecar(paths.json.clone(), e.to_string()))?;
    Ok(paths)
}

/// The displayed image: sRGB bytes of `radiance · 2^exposure`, RGBA, row 0 at the top.
pub fn display_rgba(radiance: &[glam::Vec3], exposure: f32) -> Vec<u8> {
    let scale = exposure.exp2();
    radiance
        .iter()
        .flat_map(|c| {
            let [r, g, b] = srgb_bytes(*c * scale);
            [r, g, b, 255]
        })
        .collect()
}
