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

/// A scene that finished loading replaces the session's; a failure is shown and the current scene stays.
pub(super) fn poll_loading(s: &mut crate::session::Session, u: &mut super::viewer::UiState) {
    let Some(result) = u.loading.as_ref().and_then(Loading::poll) else { return };
    let what = u.loading.take().map(|l| l.what).unwrap_or_default();
    match result {
        Ok(scene) => {
            if std::path::Path::new(&what).is_file()
                && let Err(e) = u.recent.push(&what)
            {
                u.error = Some(e);
            }
            u.selected_material = 0;
            // The scene's warnings are shown under the scene, for as long as it is loaded.
            u.message = None;
            // The probe point was the old scene's.
            u.probe.open = false;
            s.set_scene(scene, what);
        }
        Err(e) => u.error = Some(e.to_string()),
    }
}
