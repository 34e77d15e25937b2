//! Pure (sample, pdf) pairs. Every warp `sample_x(u)` has its density `x_pdf(..)` beside it; the doc comment
//! gives the density, the measure it is taken in, and the source. Random inputs are named `u`, in [0, 1)².

mod discrete;
mod hemisphere;
mod ltc;
mod phong_lobe;
mod phong_ltc_table;
mod projected_triangle;
mod spherical_triangle;
mod triangle;

pub use discrete::DiscreteDistribution;
pub use hemisphere::{
    cosine_hemisphere_pdf, sample_cosine_hemisphere, sample_uniform_hemisphere, uniform_hemisphere_pdf,
};
pub use ltc::{LobeSamples, Ltc, PhongLtc, PhongLtcParameters, phong_ltc_scale_squared};
pub use phong_lobe::{phong_lobe_pdf, phong_lobe_pdf_from_gap, sample_phong_lobe};
pub use projected_triangle::{
    MIN_ACCEPTANCE, ProjectedPlan, max_cosine, projected_solid_angle, projected_triangle_pdf, sample_projected_triangle,
};
pub use spherical_triangle::{
    MAX_SPHERICAL_SAMPLE_AREA, MIN_SPHERICAL_SAMPLE_AREA, sample_spherical_triangle, spherical_triangle_area,
    spherical_triangle_pdf,
};
pub use triangle::{sample_uniform_triangle, uniform_triangle_pdf_area};
