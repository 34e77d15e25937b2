//! # illumlab
//!
//! Monte Carlo estimation of the scattering equation, as taught in "Illumination Integrals" (CS5630):
//!
//! ```text
//! L_o(ω_o) = ∫_{H²} f_r(ω, ω_o) L_i(ω) (ω·n) dω  ≈  1/N Σ_k f_r(ω_k, ω_o) L_i(ω_k) (ω_k·n) / p(ω_k)
//! ```
//!
//! with several densities p: uniform, cosine, Phong-BRDF and emitter sampling (see [`render::Strategy`]).
//!
//! Layers, bottom up: [`math`] and [`sampling`] are pure and tested against closed forms; [`scene`] loads
//! triangles, Phong materials, emissive triangles and a camera and builds the BVH; [`render`] runs the estimators
//! over an image; [`measure`] judges estimates against a reference; [`session`] refines one image or two
//! (compare mode) and a reference in the background, headless; a [`tour`] step sets a session. Only [`app`], the
//! egui/eframe viewer on top, knows about the UI.
//!
//! Conventions: `wo` points towards the viewer, `wi` towards the light; local frames have z = n; uniforms are
//! named `u` and live in [0, 1); a density names its measure (`pdf_area`, `pdf_solid_angle`).

pub mod app;
pub mod fuzz;
pub mod guiding;
pub mod math;
pub mod measure;
pub mod probe;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod session;
pub mod tour;
