//! Tours: a lecture as a sequence of demonstrations. A step sets a [`crate::session::Session`] (scene, strategies,
//! compare mode, view, exposure, camera, probe, target) and carries a caption: a title, the slide's formula in the
//! lecture's notation, and what to look at. Tours are TOML files, one `[[step]]` table per step, every field
//! optional (a missing one keeps the current setting); [`LECTURE`] follows "Illumination Integrals" in order.
//!
//! ```toml
//! title = "My lecture"
//! [[step]]
//! title = "Cosine sampling"
//! formula = "p(ω) = cos θ / π"
//! caption = "The cos θ of the integrand cancels: on a diffuse floor only L_i is left to vary."
//! scene = "cornell-box"
//! strategy = "cosine"
//! compare = "uniform"      # B, in compare mode ("off" leaves compare mode)
//! view = "relative-variance"
//! probe = [128, 200]       # or "off"
//! target_spp = 64
//! ```

mod file;
mod presenter;
mod render;
mod step;

pub use file::{TourError, append_step, parse_tour, step_toml};
pub use presenter::Presenter;
pub use render::{StepOutput, TourRender, render_tour};
pub use step::{CameraStep, MaterialStep, MisStep};

use crate::probe::Layers;
use crate::render::{Footprint, Strategy};
use crate::scene::LightSelection;
use crate::session::views::View;
use crate::session::worker::Budget;
use glam::Vec3;

/// The bundled tour: the lecture, in order.
pub const LECTURE: &str = include_str!("../../assets/tours/lecture.toml");

/// A sequence of steps, with a title.
#[derive(Clone, Debug, PartialEq)]
pub struct Tour {
    /// Where it was read from (a path, or `lecture`): errors name it.
    pub file: String,
    pub title: String,
    pub steps: Vec<Step>,
}

impl Tour {
    /// The bundled lecture tour.
    pub fn lecture() -> Tour {
        parse_tour(LECTURE, "lecture").expect("the bundled tour parses (tested)")
    }

    /// A tour file, or `lecture` for the bundled one.
    pub fn load(what: &str) -> Result<Tour, TourError> {
        if what == "lecture" {
            return Ok(Tour::lecture());
        }
        let text = std::fs::read_to_string(what)
            .map_err(|e| TourError::new(what, None, None, format!("cannot read it: {e}")))?;
        let mut tour = parse_tour(&text, what)?;
        // Scene files are named relative to the tour file.
        let folder = std::path::Path::new(what).parent().unwrap_or(std::path::Path::new(""));
        for step in &mut tour.steps {
            if let Some(scene) = &mut step.scene
                && !crate::scene::BUNDLED_SCENES.iter().any(|b| b.name == scene.as_str())
                && std::path::Path::new(scene.as_str()).is_relative()
            {
                *scene = folder.join(&*scene).to_string_lossy().into_owned();
            }
        }
        Ok(tour)
    }
}

/// What a step shows about itself.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Caption {
    pub title: String,
    /// The slide's formula, in the lecture's notation.
    pub formula: String,
    /// One or two sentences on what to look at.
    pub text: String,
}

/// One demonstration. Every setting is optional: `None` keeps what the session has.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Step {
    pub caption: Caption,
    /// A bundled scene's name or a scene file (relative to the tour file).
    pub scene: Option<String>,
    pub strategy: Option<Strategy>,
    /// `Some(Some(b))`: compare mode with B = `b`; `Some(None)`: leave compare mode.
    pub compare: Option<Option<Strategy>>,
    pub budget: Option<Budget>,
    pub view: Option<View>,
    /// Stops.
    pub exposure: Option<f32>,
    pub camera: Option<CameraStep>,
    /// Pixels on the image's longer side.
    pub resolution: Option<u32>,
    /// `Some(Some(pixel))` probes that pixel; `Some(None)` closes the probe.
    pub probe: Option<Option<(u32, u32)>>,
    pub layers: Option<Layers>,
    /// Refining stops here (and `illumlab tour` renders this many samples per pixel); `Some(None)`: never.
    pub target_spp: Option<Option<u32>>,
    pub light_selection: Option<LightSelection>,
    pub footprint: Option<Footprint>,
    pub seed: Option<u64>,
    pub mis: Option<MisStep>,
    /// Materials changed by name.
    pub materials: Vec<MaterialStep>,
}

/// The names the probe's layers have in tour files, in [`Layers`]' order.
pub const LAYER_NAMES: [&str; 6] = ["integrand", "density", "ratio", "lights", "samples", "guide"];

pub(crate) fn layers_from_names(names: &[&str]) -> Layers {
    let on = |n: &str| names.contains(&n);
    Layers {
        integrand: on("integrand"),
        density: on("density"),
        ratio: on("ratio"),
        outlines: on("lights"),
        samples: on("samples"),
        guide: on("guide"),
    }
}

pub(crate) fn layer_names(l: &Layers) -> Vec<&'static str> {
    let flags = [l.integrand, l.density, l.ratio, l.outlines, l.samples, l.guide];
    LAYER_NAMES.iter().zip(flags).filter(|(_, on)| *on).map(|(n, _)| *n).collect()
}

fn vec3(v: [f32; 3]) -> Vec3 {
    Vec3::from_array(v)
}
