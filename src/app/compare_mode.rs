//! The viewer's public handles on compare mode and the reference (for the command line and the tests; each is the
//! session's setter), and the comparison export. The widgets are in `compare.rs`, `viewport.rs` and
//! `convergence.rs`.

use super::viewer::{UiState, Viewer};
use crate::measure::{Reference, Series};
use crate::render::Strategy;
use crate::session::Session;
use crate::session::comparison::{Comparison, write_comparison};
use crate::session::views::View;
use crate::session::worker::Budget;
use std::path::PathBuf;
use std::sync::Arc;

impl Viewer {
    pub fn is_comparing(&self) -> bool {
        self.session.is_comparing()
    }

    pub fn budget(&self) -> Budget {
        self.session.budget()
    }

    /// The reference, once ready.
    pub fn reference(&self) -> Option<&Arc<Reference>> {
        self.session.reference()
    }

    /// The convergence runs recorded against the current reference.
    pub fn history(&self) -> &[Series] {
        self.session.history()
    }

    pub fn view(&self) -> View {
        self.session.view()
    }

    /// Samples per pixel of the next reference rendered.
    pub fn set_reference_spp(&mut self, spp: u32) {
        self.session.set_reference_spp(spp);
    }

    /// Where reference renders are cached (`None`: not cached).
    pub fn set_reference_cache(&mut self, folder: Option<PathBuf>) {
        self.session.set_reference_cache(folder);
    }

    /// Enters or leaves compare mode; entering asks for a reference if there is none.
    pub fn set_comparing(&mut self, on: bool) {
        self.session.set_comparing(on);
    }

    pub fn set_strategy_b(&mut self, strategy: Strategy) {
        self.session.set_strategy_b(strategy);
    }

    pub fn set_budget(&mut self, budget: Budget) {
        self.session.set_budget(budget);
    }

    pub fn set_view(&mut self, view: View) {
        self.session.set_view(view);
    }

    pub fn set_wipe(&mut self, wipe: f32) {
        self.ui.wipe = wipe.clamp(0.0, 1.0);
    }

    /// Writes the comparison (split, both images, error maps, plot, sidecar); the outcome is shown, never fatal.
    pub fn export_comparison(&mut self) {
        export_comparison(&self.session, &mut self.ui);
    }
}

pub(super) fn export_comparison(s: &Session, u: &mut UiState) {
    let (Some(a), Some(b)) = (s.frame().cloned(), s.frame_b().cloned()) else {
        u.message = Some("nothing to compare yet".into());
        return;
    };
    let comparison = Comparison {
        a: &a,
        b: &b,
        reference: s.reference().map(|r| &**r),
        series: s.history(),
        budget: s.budget(),
        wipe: u.wipe,
        exposure: s.exposure(),
    };
    match write_comparison(&comparison, &PathBuf::from(&u.export_folder)) {
        Ok(folder) => {
            u.message = Some(format!("saved the comparison in {}", folder.display()));
            u.error = None;
            // The probe's pictures and numbers go in the same folder.
            if let Some(view) = s.probe_view()
                && let Err(e) = view.export(&folder)
            {
                u.error = Some(format!("probe not saved: {e}"));
            }
        }
        Err(e) => u.error = Some(format!("comparison not saved: {e}")),
    }
}
