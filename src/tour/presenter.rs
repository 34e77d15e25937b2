//! Presenting a tour: which step is shown. Step k is the session as it was when the tour started (the baseline),
//! then steps 1 … k folded into one ([`Step::then`]): a step looks the same whether it is reached forwards,
//! backwards or by a jump, and what a later step set never leaks into an earlier one.

use super::{Caption, Step, Tour, TourError};
use crate::session::Session;
use crate::session::worker::PassSize;

/// Where a presentation stands: the tour, the step shown, and the session's settings before the tour.
pub struct Presenter {
    pub tour: Tour,
    index: usize,
    baseline: Step,
}

impl Presenter {
    /// A presentation of `tour` over the session as it is now, not yet at a step. The baseline keeps the
    /// session's settings but not its view of the scene: the steps start from the scene file's camera, size and
    /// materials.
    pub fn new(tour: Tour, s: &Session) -> Self {
        let now = Step::from_session(s, Caption::default());
        let baseline = Step { camera: None, resolution: None, materials: Vec::new(), ..now };
        Presenter { tour, index: 0, baseline }
    }

    /// Starts presenting `tour` at its first step.
    pub fn start(tour: Tour, s: &mut Session) -> Result<Self, TourError> {
        let mut p = Presenter::new(tour, s);
        p.go(0, s)?;
        Ok(p)
    }

    pub fn index(&self) -> usize {
        self.index
    }

    pub fn step(&self) -> &Step {
        &self.tour.steps[self.index]
    }

    /// Goes to step `index` (clamped to the tour) and applies it; rendering restarts at once with its settings.
    /// The error names the step that set the offending field.
    pub fn go(&mut self, index: usize, s: &mut Session) -> Result<(), TourError> {
        let Some(last) = self.tour.steps.len().checked_sub(1) else {
            return Err(TourError::new(&self.tour.file, None, None, "no steps"));
        };
        self.index = index.min(last);
        // A step refines in passes sized by time, from its first sample.
        if s.pass_size() != PassSize::Auto {
            s.set_sampling(PassSize::Auto, s.target_spp());
        }
        self.effective(self.index).apply(s).map_err(|(field, problem)| {
            let from = self.origin(self.index, field);
            let title = self.tour.steps[from].caption.title.clone();
            TourError::new(&self.tour.file, Some((from + 1, title)), Some(field), problem)
        })
    }

    pub fn next(&mut self, s: &mut Session) -> Result<(), TourError> {
        if self.index + 1 < self.tour.steps.len() { self.go(self.index + 1, s) } else { Ok(()) }
    }

    pub fn previous(&mut self, s: &mut Session) -> Result<(), TourError> {
        if self.index > 0 { self.go(self.index - 1, s) } else { Ok(()) }
    }

    /// The baseline, then steps 1 … `index`, folded into one.
    pub fn effective(&self, index: usize) -> Step {
        let end = index.min(self.tour.steps.len().saturating_sub(1));
        self.tour.steps[..=end].iter().fold(self.baseline.clone(), |acc, step| acc.then(step))
    }

    /// The last step up to `index` that names `field` (step `index` itself if none does).
    fn origin(&self, index: usize, field: &str) -> usize {
        (0..=index).rev().find(|&i| self.tour.steps[i].names(field)).unwrap_or(index)
    }
}
