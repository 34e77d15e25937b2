//! What the UI asks of the worker, and how compare mode shares it between the lanes.

use super::{A, B, PassSize, R};
use crate::render::RenderSettings;
use crate::scene::{Camera, Material, Scene};
use std::path::PathBuf;
use std::sync::Arc;

/// How compare mode shares the integrator between A and B.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Budget {
    #[default]
    EqualSamples,
    EqualTime,
}

impl Budget {
    pub fn name(self) -> &'static str {
        match self {
            Budget::EqualSamples => "equal samples",
            Budget::EqualTime => "equal time",
        }
    }

    /// The command line's and the tour files' name.
    pub fn slug(self) -> &'static str {
        match self {
            Budget::EqualSamples => "equal-samples",
            Budget::EqualTime => "equal-time",
        }
    }

    pub fn from_slug(s: &str) -> Option<Self> {
        [Budget::EqualSamples, Budget::EqualTime].into_iter().find(|b| b.slug() == s)
    }
}

/// What the UI can ask of the worker.
pub enum Command {
    /// Render another scene (its camera included).
    SetScene(Arc<Scene>),
    /// Lane A's settings.
    SetSettings(RenderSettings),
    /// Compare mode: lane B's settings; `None` renders A alone.
    SetCompare(Option<RenderSettings>),
    SetBudget(Budget),
    SetCamera(Camera),
    SetMaterial {
        index: usize,
        material: Material,
    },
    /// Samples per pixel taken in one pass (how often a frame is published).
    SetPassSize(PassSize),
    /// Stop refining at this many samples per pixel (`None`: never).
    SetTargetSpp(Option<u32>),
    Pause(bool),
    /// Discard the films and start again (the reference stays).
    Restart,
    /// Forget the guides `guided` learned and start learning (and the films) again.
    ResetGuide,
    /// Render a reference at this many spp (or take it from the cache folder, and store it there when done);
    /// `None` forgets the reference.
    SetReference {
        spp: Option<u32>,
        cache: Option<PathBuf>,
    },
    /// Use the reference in this EXR file (with its `.var.exr` sibling if present).
    LoadReference(PathBuf),
    Quit,
    /// Tests: the next pass panics.
    #[cfg(test)]
    PanicInNextPass,
}

impl Command {
    /// The generation counters the command bumps: lanes and reference whose image it changes.
    pub(crate) fn resets(&self) -> &'static [usize] {
        match self {
            Command::SetScene(_) | Command::SetCamera(_) | Command::SetMaterial { .. } => &[A, B, R],
            // A change to either lane restarts both: under equal time they must start from zero CPU time together.
            Command::Restart
            | Command::ResetGuide
            | Command::SetBudget(_)
            | Command::SetSettings(_)
            | Command::SetCompare(_) => &[A, B],
            Command::SetReference { .. } | Command::LoadReference(_) => &[R],
            _ => &[],
        }
    }
}
