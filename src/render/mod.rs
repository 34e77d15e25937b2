//! Estimators of the scattering integral and the machinery that runs them over an image.

mod cones;
mod estimator;
mod film;
mod lanes;
mod output;
mod pass;
mod shading;
pub mod strategy;

pub use cones::PixelCones;
pub use estimator::{SEGMENT_END, estimate_direct};
pub use film::{Film, PixelAccum};
pub use output::{OutputError, OutputFormat, check_output_path, srgb_bytes, write_image, write_png_rgba};
pub use pass::{PassStats, RenderSettings, Renderer};
pub use shading::ShadingPoint;
pub use strategy::{DirectionSample, Heuristic, LightTechnique, MisSettings, Strategy, Target};
