//! What can be shown of a lane: the image, or one of its per-pixel error maps. Maps are scalars drawn in false
//! colour ([`ColorScale`]) on one scale for both lanes, so equal colours mean equal values across the split.

use super::worker::Frame;
use crate::measure::{ColorScale, Reference, absolute_error_map};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum View {
    #[default]
    Image,
    /// `sqrt(σ̂²/N)`: how far the pixel may still be from its expectation.
    StdError,
    /// `σ̂²/μ̂²`: the estimator's relative variance per sample, independent of N.
    RelativeVariance,
    /// `|I − R|` against the reference.
    AbsError,
    /// The largest single sample's share of the pixel's sum.
    Fireflies,
    /// `|A − B|`: with common random numbers, only where the estimators differ.
    Difference,
}

impl View {
    pub const ALL: [View; 6] =
        [View::Image, View::StdError, View::RelativeVariance, View::AbsError, View::Fireflies, View::Difference];

    pub fn name(self) -> &'static str {
        match self {
            View::Image => "image",
            View::StdError => "standard error",
            View::RelativeVariance => "relative variance",
            View::AbsError => "|estimate - reference|",
            View::Fireflies => "fireflies",
            View::Difference => "|A - B|",
        }
    }

    /// A file-name-safe name.
    pub fn slug(self) -> &'static str {
        match self {
            View::Image => "image",
            View::StdError => "std-error",
            View::RelativeVariance => "relative-variance",
            View::AbsError => "abs-error",
            View::Fireflies => "fireflies",
            View::Difference => "difference",
        }
    }

    pub fn from_slug(s: &str) -> Option<Self> {
        View::ALL.into_iter().find(|v| v.slug() == s)
    }

    /// One line on what the map shows, for the legend.
    pub fn description(self) -> &'static str {
        match self {
            View::Image => "the accumulated estimate",
            View::StdError => "standard error of the mean, sqrt(s^2/N), from the sum of squares (radiance)",
            View::RelativeVariance => "variance of one sample over the squared mean: samples needed for 100% error",
            View::AbsError => "absolute error against the reference (radiance)",
            View::Fireflies => "share of the pixel's sum carried by its largest single sample (1/N .. 1)",
            View::Difference => "absolute difference of A and B (radiance): zero where the estimators agree",
        }
    }

    pub fn needs_reference(self) -> bool {
        self == View::AbsError
    }

    pub fn needs_comparison(self) -> bool {
        self == View::Difference
    }
}

/// The per-pixel values of `view` for `frame`; `None` for the image, for a preview, or when the reference (or the
/// other lane) needed is missing or has another size.
pub fn view_values(
    view: View,
    frame: &Frame,
    reference: Option<&Reference>,
    other: Option<&Frame>,
) -> Option<Vec<f32>> {
    if frame.preview {
        return None;
    }
    match view {
        View::Image => None,
        View::StdError => Some(frame.std_error.clone()),
        View::RelativeVariance => Some(frame.relative_variance.clone()),
        View::Fireflies => Some(frame.largest_share.clone()),
        View::AbsError => {
            let r = reference.filter(|r| r.mean.len() == frame.radiance.len())?;
            Some(absolute_error_map(&frame.radiance, r))
        }
        View::Difference => {
            let o = other.filter(|o| o.radiance.len() == frame.radiance.len() && !o.preview)?;
            Some(frame.radiance.iter().zip(&o.radiance).map(|(a, b)| (*a - *b).abs().element_sum() / 3.0).collect())
        }
    }
}

/// Why `view` cannot be shown yet for `frame`, if it cannot; `other` is the other lane's frame in compare mode.
pub fn unavailable(
    view: View,
    frame: &Frame,
    reference: Option<&Reference>,
    other: Option<&Frame>,
) -> Option<&'static str> {
    match view {
        _ if frame.preview && view != View::Image => Some("after the first full pass"),
        View::AbsError if reference.is_none() => Some("no reference yet: compute or load one"),
        View::AbsError if reference.is_some_and(|r| r.mean.len() != frame.radiance.len()) => {
            Some("the reference has another size")
        }
        View::Difference if other.is_none() => Some("only in compare mode, once B has a frame"),
        View::Difference if other.is_some_and(|o| o.preview || o.radiance.len() != frame.radiance.len()) => {
            Some("after B's first full pass")
        }
        _ => None,
    }
}

/// One scale for all the maps shown together. A map of zeros (identical lanes) has none.
pub fn shared_scale(maps: &[&[f32]]) -> Option<ColorScale> {
    ColorScale::fit(maps.iter().copied())
}

/// What is shown of lanes A and B (`None` for a lane without a frame) in `view`: their pixels (RGBA), the one
/// scale of their error maps, and why the map is not shown (then the image is, at `exposure`).
pub struct Shown {
    pub rgba: [Option<Vec<u8>>; 2],
    pub scale: Option<ColorScale>,
    pub note: Option<&'static str>,
}

/// The pixels the viewer (and `illumlab tour`) show for `view`: the error map on a scale shared by both lanes,
/// or the image at `exposure` where the map is not available.
pub fn shown(view: View, frames: [Option<&Frame>; 2], reference: Option<&Reference>, exposure: f32) -> Shown {
    let values: [Option<Vec<f32>>; 2] =
        [0, 1].map(|i| frames[i].and_then(|f| view_values(view, f, reference, frames[1 - i])));
    let maps: Vec<&[f32]> = values.iter().flatten().map(|v| v.as_slice()).collect();
    let scale = shared_scale(&maps);
    let mut note = frames[0].and_then(|f| unavailable(view, f, reference, frames[1]));
    if note.is_none() && view != View::Image && scale.is_none() {
        note = Some("zero everywhere");
    }
    let rgba = [0, 1].map(|i| {
        let frame = frames[i]?;
        Some(match (&values[i], scale) {
            (Some(v), Some(scale)) if note.is_none() => scale.colorize(v),
            _ => super::snapshot::display_rgba(&frame.radiance, exposure),
        })
    });
    Shown { rgba, scale, note }
}
