//! Measuring estimators: error against a reference image, per-pixel error maps in false colour, convergence
//! series and efficiency, and the `bench` run that writes them as CSV, markdown and a plot. Headless, like
//! [`crate::render`] below it.

mod bench;
mod convergence;
mod emitter_pixels;
mod error;
mod heatmap;
mod interval;
mod plot;
mod reference;
mod report;

pub use bench::{BenchPlan, BenchReport, BenchRow, run_bench};
pub use convergence::{ConvergencePoint, Metric, Series, most_efficient};
pub use emitter_pixels::sees_emitter;
pub use error::{ErrorMetrics, REL_MSE_EPSILON, absolute_error_map, error_over, error_vs_reference};
pub use heatmap::{ColorScale, gradient};
pub use interval::{MeanInterval, Ratio, student_t_975};
pub use plot::{convergence_rgba, write_convergence_png};
pub use reference::{
    REFERENCE_SEED, Reference, ReferenceError, ReferenceOrigin, cache_path, default_cache_folder, load_cached,
    reference_key, reference_settings, store_cached, variance_path,
};
pub use report::{BenchContext, machine_description, markdown, write_csv};
