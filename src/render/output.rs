//! Writing the film: EXR (linear RGB, f32) or PNG (sRGB, with an exposure in stops). Files are written to a
//! temporary name beside the target and renamed, so a failure never leaves a partial file behind.

use super::Film;
use glam::Vec3;
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    Exr,
    Png,
}

#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("output {}: unsupported extension (use .exr or .png)", .0.display())]
    Extension(PathBuf),
    #[error("output {}: {} is not an existing folder", .0.display(), .1.display())]
    NoFolder(PathBuf, PathBuf),
    #[error("output {}: cannot write: {}", .0.display(), .1)]
    Write(PathBuf, String),
}

impl OutputFormat {
    pub fn of(path: &Path) -> Result<Self, OutputError> {
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("exr") => Ok(OutputFormat::Exr),
            Some("png") => Ok(OutputFormat::Png),
            _ => Err(OutputError::Extension(path.to_path_buf())),
        }
    }
}

/// Checks, before any rendering, that `path` has a supported extension and can be created (by creating and
/// removing its temporary file).
pub fn check_output_path(path: &Path) -> Result<OutputFormat, OutputError> {
    let format = OutputFormat::of(path)?;
    let folder = folder_of(path);
    if !folder.is_dir() {
        return Err(OutputError::NoFolder(path.to_path_buf(), folder));
    }
    let tmp = temp_path(path);
    std::fs::File::create(&tmp).map_err(|e| OutputError::Write(path.to_path_buf(), e.to_string()))?;
    let _ = std::fs::remove_file(&tmp);
    Ok(format)
}

/// Writes the film's per-pixel means. `exposure` (stops) applies to PNG only.
pub fn write_image(film: &Film, path: &Path, exposure: f32) -> Result<(), OutputError> {
    let format = OutputFormat::of(path)?;
    let means = film.means();
    let (w, h) = (film.width as usize, film.height as usize);
    let tmp = temp_path(path);
    let result = match format {
        OutputFormat::Exr => exr::prelude::write_rgb_file(&tmp, w, h, |x, y| {
            let c = means[y * w + x];
            (c.x, c.y, c.z)
        })
        .map_err(|e| e.to_string()),
        OutputFormat::Png => {
            let scale = exposure.exp2();
            let bytes: Vec<u8> = means.iter().flat_map(|c| srgb_bytes(*c * scale)).collect();
            image::RgbImage::from_raw(film.width, film.height, bytes)
                .ok_or_else(|| "image size mismatch".to_string())
                .and_then(|img| img.save_with_format(&tmp, image::ImageFormat::Png).map_err(|e| e.to_string()))
        }
    };
    let result = result.and_then(|()| std::fs::rename(&tmp, path).map_err(|e| e.to_string()));
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(OutputError::Write(path.to_path_buf(), e));
    }
    Ok(())
}

/// Linear radiance → 8-bit sRGB (IEC 61966-2-1), clamped to [0, 1].
pub fn srgb_bytes(c: Vec3) -> [u8; 3] {
    let encode = |v: f32| {
        let v = if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 };
        let s = if v <= 0.003_130_8 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 };
        (s * 255.0 + 0.5) as u8
    };
    [encode(c.x), encode(c.y), encode(c.z)]
}

fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    folder_of(path).join(format!(".{name}.{}.tmp", std::process::id()))
}
