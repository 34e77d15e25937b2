//! What the worker publishes: each lane's newest [`Frame`], and the state of the reference.

use crate::guiding::{Guide, TrainingStatus};
use crate::measure::Reference;
use crate::render::{PassStats, RenderSettings};
use crate::scene::Camera;
use glam::Vec3;
use std::sync::Arc;
use std::time::Duration;

/// A snapshot of one lane's film after a pass.
#[derive(Clone, Debug)]
pub struct Frame {
    /// [`super::A`] or [`super::B`].
    pub lane: usize,
    /// Increases with every restart of this lane; frames of one generation refine the same image.
    pub generation: u64,
    pub width: u32,
    pub height: u32,
    /// Mean radiance per pixel (linear RGB), row 0 at the top.
    pub radiance: Vec<Vec3>,
    /// Per pixel: standard error of the mean, relative variance, largest single sample's share of the sum (see
    /// [`crate::render::PixelAccum`]). Empty in a preview.
    pub std_error: Vec<f32>,
    pub relative_variance: Vec<f32>,
    pub largest_share: Vec<f32>,
    pub spp: u32,
    pub passes: u32,
    /// Wall-clock rendering time since the restart (pauses excluded).
    pub elapsed: Duration,
    /// Totals since the restart, CPU time included.
    pub stats: PassStats,
    pub settings: RenderSettings,
    pub scene_name: String,
    pub camera: Camera,
    /// A half-resolution, one-sample preview published right after a restart, before the first full pass.
    pub preview: bool,
    /// For a strategy that learns: where its training stands and the guide its passes sample from now.
    pub guide: Option<(TrainingStatus, Arc<Guide>)>,
}

/// The reference, as the worker last reported it.
#[derive(Clone, Debug)]
pub enum ReferenceStatus {
    /// None asked for.
    Off,
    Rendering {
        spp: u32,
        target: u32,
        elapsed: Duration,
    },
    /// Ready; `note` says where it came from or why it was not cached.
    Ready {
        reference: Arc<Reference>,
        note: String,
    },
    Failed(String),
}
