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
        OutputFormat::Exr => {
            use exr::prelude::*;
            let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
                let c: glam::Vec3 = means[y * w + x];
                (c.x, c.y, c.z)
            });
            // Blocks compressed in parallel land in the file in whatever order they finish; written in order, the
            // same image is the same file, byte for byte.
            Image::from_channels((w, h), channels).write().non_parallel().to_file(&tmp).map_err(|e| e.to_string())
        }
        OutputFormat::Png => {
            let scale = exposure.exp2();
            let bytes: Vec<u8> = means.iter().flat_map(|c| srgb_bytes(*c * scale)).collect();
            save_png(&tmp, film.width, film.height, bytes, image::ColorType::Rgb8)
        }
    };
    finish(path, &tmp, result)
}

/// Writes 8-bit RGBA pixels (row 0 at the top) as a PNG, atomically.
pub fn write_png_rgba(path: &Path, width: u32, height: u32, rgba: Vec<u8>) -> Result<(), OutputError> {
    let tmp = temp_path(path);
    finish(path, &tmp, save_png(&tmp, width, height, rgba, image::ColorType::Rgba8))
}

fn save_png(to: &Path, width: u32, height: u32, bytes: Vec<u8>, color: image::ColorType) -> Result<(), String> {
    if bytes.len() != width as usize * height as usize * color.bytes_per_pixel() as usize {
        return Err("image size mismatch".into());
    }
    image::save_buffer_with_format(to, &bytes, width, height, color, image::ImageFormat::Png).map_err(|e| e.to_string())
}

/// Renames the written temporary file to `path`, or removes it and reports the failure.
fn finish(path: &Path, tmp: &Path, written: Result<(), String>) -> Result<(), OutputError> {
    let result = written.and_then(|()| std::fs::rename(tmp, path).map_err(|e| e.to_string()));
    if let Err(e) = result {
        let _ = std::fs::remove_file(tmp);
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
