//! Estimators of the scattering integral and the machinery that runs them over an image.

mod cones;
mod estimator;
mod film;
mod footprint;
mod lanes;
mod output;
mod pass;
mod shading;
pub mod sink;
pub mod strategy;

pub use cones::PixelCones;
pub use estimator::{SEGMENT_END, estimate_direct, reached, shadow_ray_ends, visible};
pub use film::{Film, PixelAccum};
pub use footprint::Footprint;
pub use lanes::LANES;
pub use output::{OutputError, OutputFormat, check_output_path, srgb_bytes, write_image, write_png_rgba};
pub use pass::{PassStats, RenderSettings, Renderer};
pub use shading::ShadingPoint;
pub use sink::{Census, Outcome, SampleRecord, SampleSink};
pub use strategy::{DirectionSample, Domain, Heuristic, MisSettings, Reached, SampleContext, Strategy, Target};
