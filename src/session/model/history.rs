//! The convergence history of a [`Session`]: each run's error against the reference, by samples and seconds, as
//! the plot shows it.

use super::Session;
use crate::measure::{ConvergencePoint, Series, error_vs_reference};
use crate::render::{RenderSettings, Strategy};
use crate::session::worker::{B, Frame};

impl Session {
    /// Adds a point to the frame's convergence run (a restarted run starts its series again). B's frames are
    /// skipped when B runs A's estimator: with common random numbers they are the same run.
    pub(super) fn record(&mut self, frame: &Frame) {
        let Some(reference) = self.reference().cloned() else { return };
        if frame.preview || frame.spp == 0 || reference.mean.len() != frame.radiance.len() {
            return;
        }
        if frame.lane == B && series_label(&frame.settings) == series_label(&self.settings) {
            return;
        }
        // The estimator's own error: the reference's noise is subtracted, as the bench subtracts it.
        let metrics = error_vs_reference(&frame.radiance, &reference);
        let point = ConvergencePoint {
            spp: frame.spp,
            seconds: frame.stats.cpu.as_secs_f64(),
            mse: metrics.estimator_mse(),
            rel_mse: metrics.estimator_rel_mse(),
        };
        let label = series_label(&frame.settings);
        let i = match self.history.iter().position(|s| s.label == label) {
            Some(i) => i,
            None => {
                self.history.push(Series::new(label));
                self.history.len() - 1
            }
        };
        let series = &mut self.history[i];
        if series.last().is_some_and(|p| p.spp >= frame.spp) {
            series.points.clear();
        }
        series.push(point);
    }
}

/// How a run is named in the convergence plot: the strategy, and what else distinguishes its estimator.
pub fn series_label(s: &RenderSettings) -> String {
    let mut label = s.strategy.name().to_string();
    if s.strategy == Strategy::Mis {
        label += &format!(" ({})", s.mis.label());
    }
    if s.strategy.samples_lights() || s.strategy == Strategy::Mis {
        label += &format!(" [{}]", s.light_selection.name());
    }
    label
}
