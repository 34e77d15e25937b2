//! Presenting a tour: which step is shown. Stepping to step k applies steps 1 … k folded into one
//! ([`Step::then`]), so a step looks the same whether it is reached forwards, backwards or by jumping.

use super::{Step, Tour, TourError};
use crate::session::Session;
use crate::session::worker::PassSize;

/// Where a presentation stands: the tour, the step shown, and the last step's error.
pub struct Presenter {
    pub tour: Tour,
    index: usize,
}

impl Presenter {
    /// A presentation of `tour` that has not applied a step yet.
    pub fn new(tour: Tour) -> Self {
        Presenter { tour, index: 0 }
    }

    /// Starts presenting `tour` at its first step.
    pub fn start(tour: Tour, s: &mut Session) -> Result<Self, TourError> {
        let mut p = Presenter::new(tour);
        p.go(0, s)?;
        Ok(p)
    }

    pub fn index(&self) -> usize {
        self.index
    }

    pub fn step(&self) -> &Step {
        &self.tour.steps[self.index]
    }

    /// Goes to step `index` (clamped to the tour) and applies it. Passes restart at once with its settings.
    pub fn go(&mut self, index: usize, s: &mut Session) -> Result<(), TourError> {
        self.index = index.min(self.tour.steps.len().saturating_sub(1));
        // A step refines in passes sized by time, from its first sample.
        if s.pass_size() != PassSize::Auto {
            s.set_sampling(PassSize::Auto, s.target_spp());
        }
        self.effective(self.index).apply(s).map_err(|(field, problem)| {
            let title = self.tour.steps[self.index].caption.title.clone();
            TourError::new(&self.tour.file, Some((self.index + 1, title)), Some(field), problem)
        })
    }

    /// Steps 1 … `index` folded into one.
    pub fn effective(&self, index: usize) -> Step {
        self.tour.steps[..=index.min(self.tour.steps.len() - 1)]
            .iter()
            .fold(Step::default(), |acc, step| acc.then(step))
    }

    pub fn next(&mut self, s: &mut Session) -> Result<(), TourError> {
        self.go(self.index + 1, s)
    }

    pub fn previous(&mut self, s: &mut Session) -> Result<(), TourError> {
        self.go(self.index.saturating_sub(1), s)
    }
}
