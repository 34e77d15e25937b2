//! The background integrator: a thread that owns the films and refines them pass after pass.
//!
//! It renders one image (lane A) or, in compare mode, two (lanes A and B: two estimators of the same scene and
//! camera, with the same per-pixel random streams), and optionally a reference in between. The UI sends
//! [`Command`]s over a channel and takes the newest [`Frame`] of each lane from latest-value slots: it never
//! waits for a pass and never receives stale frames. A command that changes what a lane converges to bumps that
//! lane's generation at once; the lane's pass in flight polls it row by row, so the new setting shows in the next
//! frame. The worker calls `notify` after every pass (the app binds it to `request_repaint`).
//!
//! Budgets in compare mode: **equal samples** runs the lane with fewer spp next, so both reach the same spp;
//! **equal time** runs the lane with less CPU time next (each row's thread CPU clock, summed), so both get the
//! same time within one pass and each shows its own spp. With a target spp, equal time stops each lane at the CPU
//! time the first one needed to reach the target.

mod command;
mod frame;
mod lane;
mod pass_size;
mod reference_job;
mod state;

pub use command::{Budget, Command};
pub use frame::{Frame, ReferenceStatus};
pub use pass_size::PassSize;

use crate::render::RenderSettings;
use crate::scene::Scene;
use state::State;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Sender, channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

/// Lane indices.
pub const A: usize = 0;
pub const B: usize = 1;
/// The reference's index among the generation counters.
const R: usize = 2;

/// Handle to the integrator thread; dropping it stops the thread.
pub struct Worker {
    /// Commands with the generation they were sent at.
    commands: Sender<(u64, Command)>,
    latest: Arc<Slots>,
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
}

/// Latest-value slots, one per lane, and the reference's.
#[derive(Default)]
struct Slots {
    frames: [Mutex<Option<Arc<Frame>>>; 2],
    reference: Mutex<Option<ReferenceStatus>>,
    /// What stopped the integrator (no thread, no pool, a pass that panicked), for the UI to show.
    failure: Mutex<Option<String>>,
}

/// Counters the UI bumps and passes poll.
#[derive(Default)]
struct Shared {
    /// Bumped by every command that restarts something.
    generation: AtomicU64,
    /// Per lane and reference: the generation of the last command that restarted it.
    resets: [AtomicU64; 3],
}

impl Worker {
    /// Starts rendering `scene` at once. `threads`: size of the pass's thread pool.
    pub fn spawn(
        scene: Arc<Scene>,
        settings: RenderSettings,
        threads: usize,
        notify: impl Fn() + Send + 'static,
    ) -> Self {
        let (commands, rx) = channel();
        let latest = Arc::new(Slots::default());
        let shared = Arc::new(Shared::default());
        let state = State::new(scene, settings, latest.clone(), shared.clone(), Box::new(notify));
        let thread =
            match std::thread::Builder::new().name("integrator".into()).spawn(move || state.run(rx, threads.max(1))) {
                Ok(thread) => Some(thread),
                Err(e) => {
                    if let Ok(mut slot) = latest.failure.lock() {
                        *slot = Some(format!("cannot start the integrator thread: {e}"));
                    }
                    None
                }
            };
        Self { commands, latest, shared, thread }
    }

    /// Why the integrator stopped, if it did since the last call: the UI shows it (rendering resumes, if it
    /// can, with the next command that restarts an image).
    pub fn take_failure(&self) -> Option<String> {
        self.latest.failure.lock().ok()?.take()
    }

    /// Sends a command; one that changes an image cancels that image's pass in flight first. The generation
    /// travels with the command, so the worker restarts an image only once the command that changed it arrived.
    pub fn send(&self, command: Command) {
        let resets = command.resets();
        let g = if resets.is_empty() {
            self.shared.generation.load(Ordering::SeqCst)
        } else {
            let g = self.shared.generation.fetch_add(1, Ordering::SeqCst) + 1;
            for &i in resets {
                self.shared.resets[i].store(g, Ordering::SeqCst);
            }
            g
        };
        let _ = self.commands.send((g, command));
    }

    /// Lane A's newest frame, if one was published since the last call.
    pub fn take_frame(&self) -> Option<Arc<Frame>> {
        self.take_lane(A)
    }

    /// The newest frame of `lane` ([`A`] or [`B`]), if one was published since the last call.
    pub fn take_lane(&self, lane: usize) -> Option<Arc<Frame>> {
        self.latest.frames[lane].lock().ok()?.take()
    }

    /// The reference's status, if it changed since the last call.
    pub fn take_reference(&self) -> Option<ReferenceStatus> {
        self.latest.reference.lock().ok()?.take()
    }

    /// The generation of the last command sent: a frame whose lane was restarted by it carries this generation
    /// or a later one.
    pub fn generation(&self) -> u64 {
        self.shared.generation.load(Ordering::SeqCst)
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        let g = self.shared.generation.fetch_add(1, Ordering::SeqCst) + 1;
        self.shared.resets.iter().for_each(|r| r.store(g, Ordering::SeqCst));
        let _ = self.commands.send((g, Command::Quit));
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

#[cfg(test)]
mod tests;
