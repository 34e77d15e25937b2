//! Compare mode's state on the [`Viewer`]: lane B, budget, wipe, view, the reference, the convergence runs and
//! the comparison export. The widgets are in `compare.rs`, `viewport.rs` and `convergence.rs`.

use super::viewer::Viewer;
use crate::measure::{ConvergencePoint, Reference, Series, error_vs_reference};
use crate::render::{RenderSettings, Strategy};
use crate::session::comparison::{Comparison, write_comparison};
use crate::session::views::View;
use crate::session::worker::{B, Budget, Command, Frame, ReferenceStatus};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

impl Viewer {
    /// Lane B's newest frame shown (compare mode).
    pub fn frame_b(&self) -> Option<&Frame> {
        self.frame_b.as_deref().filter(|_| self.comparing)
    }

    pub fn is_comparing(&self) -> bool {
        self.comparing
    }

    pub fn budget(&self) -> Budget {
        self.budget
    }

    pub fn wipe(&self) -> f32 {
        self.wipe
    }

    /// The reference, once ready.
    pub fn reference(&self) -> Option<&Arc<Reference>> {
        match &self.reference {
            ReferenceStatus::Ready { reference, .. } => Some(reference),
            _ => None,
        }
    }

    /// The convergence runs recorded against the current reference.
    pub fn history(&self) -> &[Series] {
        &self.history
    }

    pub fn view(&self) -> View {
        self.view
    }

    /// Why the chosen error map is not shown, if it is not (e.g. "zero everywhere").
    pub fn view_note(&self) -> Option<&'static str> {
        self.view_note
    }

    /// Where the image (A's, in compare mode) was last drawn, in points.
    pub fn image_rect(&self) -> Option<egui::Rect> {
        self.image_rect
    }

    /// Samples per pixel of the next reference rendered.
    pub fn set_reference_spp(&mut self, spp: u32) {
        self.reference_spp = spp.max(1);
    }

    /// Where reference renders are cached (`None`: not cached).
    pub fn set_reference_cache(&mut self, folder: Option<PathBuf>) {
        self.reference_cache = folder;
    }

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
        let series = match self.history.iter().position(|s| s.label == label) {
            Some(i) => &mut self.history[i],
            None => {
                self.history.push(Series::new(label));
                self.history.last_mut().expect("just pushed")
            }
        };
        if series.last().is_some_and(|p| p.spp >= frame.spp) {
            series.points.clear();
        }
        series.push(point);
    }

    /// Enters or leaves compare mode; entering asks for a reference if there is none.
    pub fn set_comparing(&mut self, on: bool) {
        if self.comparing == on {
            return;
        }
        self.comparing = on;
        self.frame_b = None;
        self.send_compare();
        if on {
            self.ensure_reference();
        }
        self.texture_stale = true;
    }

    /// Opens the convergence window (asking for a reference if there is none).
    pub fn show_convergence_plot(&mut self) {
        self.show_plot = true;
        self.ensure_reference();
    }

    pub fn set_strategy_b(&mut self, strategy: Strategy) {
        if self.settings_b.strategy != strategy {
            self.settings_b.strategy = strategy;
            self.send_compare();
        }
    }

    /// Swaps the estimators of A and B (both restart; with common random numbers they reconverge identically).
    pub fn swap_lanes(&mut self) {
        std::mem::swap(&mut self.settings.strategy, &mut self.settings_b.strategy);
        self.send_restarting(Command::SetSettings(self.settings));
        self.send_compare();
    }

    pub fn set_budget(&mut self, budget: Budget) {
        if self.budget != budget {
            self.budget = budget;
            self.send_restarting(Command::SetBudget(budget));
        }
    }

    pub fn set_wipe(&mut self, wipe: f32) {
        self.wipe = wipe.clamp(0.0, 1.0);
    }

    pub fn set_view(&mut self, view: View) {
        if self.view != view {
            self.view = view;
            self.texture_stale = true;
            if view.needs_reference() {
                self.ensure_reference();
            }
        }
    }

    pub(super) fn send_compare(&mut self) {
        let b = self.comparing.then_some(self.settings_b);
        self.send_restarting(Command::SetCompare(b));
    }

    /// Asks for a reference (rendered, or from the cache) unless one is ready or on its way.
    pub(super) fn ensure_reference(&mut self) {
        if matches!(self.reference, ReferenceStatus::Off | ReferenceStatus::Failed(_)) {
            self.compute_reference();
        }
    }

    pub(super) fn compute_reference(&mut self) {
        self.worker.send(Command::SetReference { spp: Some(self.reference_spp), cache: self.reference_cache.clone() });
        self.reference = ReferenceStatus::Rendering { spp: 0, target: self.reference_spp, elapsed: Duration::ZERO };
    }

    pub(super) fn load_reference(&mut self, path: PathBuf) {
        self.worker.send(Command::LoadReference(path));
    }

    /// Writes the comparison (split, both images, error maps, plot, sidecar); the outcome is shown, never fatal.
    pub fn export_comparison(&mut self) {
        let (Some(a), Some(b)) = (self.frame.clone(), self.frame_b.clone().filter(|_| self.comparing)) else {
            self.message = Some("nothing to compare yet".into());
            return;
        };
        let reference = self.reference().cloned();
        let comparison = Comparison {
            a: &a,
            b: &b,
            reference: reference.as_deref(),
            series: &self.history,
            budget: self.budget,
            wipe: self.wipe,
            exposure: self.exposure,
        };
        match write_comparison(&comparison, &PathBuf::from(&self.export_folder)) {
            Ok(folder) => {
                self.message = Some(format!("saved the comparison in {}", folder.display()));
                self.error = None;
                // The probe's pictures and numbers go in the same folder.
                if let Some(view) = self.probe.view.as_ref()
                    && let Err(e) = view.export(&folder)
                {
                    self.error = Some(format!("probe not saved: {e}"));
                }
            }
            Err(e) => self.error = Some(format!("comparison not saved: {e}")),
        }
    }
}

/// How a run is named in the convergence plot: the strategy, and what else distinguishes its estimator.
pub(super) fn series_label(s: &RenderSettings) -> String {
    let mut label = s.strategy.name().to_string();
    if s.strategy == Strategy::Mis {
        label += &format!(" ({})", s.mis.label());
    }
    if s.strategy.samples_lights() || s.strategy == Strategy::Mis {
        label += &format!(" [{}]", s.light_selection.name());
    }
    label
}
