//! Estimators of the scattering integral and the machinery that runs them over an image.

mod estimator;
mod film;
mod output;
mod pass;
mod shading;
pub mod strategy;

pub use estimator::estimate_direct;
pub use film::{Film, PixelAccum};
pub use output::{OutputFormat, check_output_path, write_image};
pub use pass::{PassStats, RenderSettings, Renderer};
pub use shading::ShadingPoint;
pub use strategy::{DirectionSample, Strategy, Target};
