//! Loads a scene and builds its BVH on a background thread, so the UI stays responsive.

use crate::scene::{Scene, SceneError, load_scene};
use std::sync::mpsc::{Receiver, TryRecvError, channel};
use std::time::Instant;

pub struct Loading {
    /// What is being loaded (a bundled scene's name or a path).
    pub what: String,
    pub started: Instant,
    rx: Receiver<Result<Scene, SceneError>>,
}

impl Loading {
    pub fn start(what: String, notify: impl Fn() + Send + 'static) -> Self {
        let (tx, rx) = channel();
        let name = what.clone();
        std::thread::spawn(move || {
            let _ = tx.send(load_scene(&name));
            notify();
        });
        Self { what, started: Instant::now(), rx }
    }

    /// The result once it is there.
    pub fn poll(&self) -> Option<Result<Scene, SceneError>> {
        match self.rx.try_recv() {
            Ok(r) => Some(r),
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => {
                Some(Err(SceneError::Invalid(format!("loading {} stopped unexpectedly", self.what))))
            }
        }
    }
}
