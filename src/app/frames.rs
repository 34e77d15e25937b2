//! Frames from the session to the screen: the textures of what is shown (refinements uploaded at most every
//! [`UPLOAD_INTERVAL`]), and the callbacks with which other threads wake the UI.

use super::viewer::UiState;
use crate::session::views::shown;
use crate::session::worker::{A, B};
use crate::session::{Notify, Session};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Takes the session's news: frames, reference, probe answers, failures.
pub(super) fn take_frames(s: &mut Session, u: &mut UiState) {
    let update = s.poll();
    if let Some(failure) = update.failure {
        u.error = Some(failure);
    }
    if let Some((latency, w, h)) = update.restart_latency
        && u.trace
    {
        eprintln!("trace: restart-to-frame {:.1} ms at {w}x{h}", latency.as_secs_f64() * 1e3);
    }
    u.texture_stale |= update.restarted;
    u.refined |= update.refined;
    if update.probed {
        u.probe.stale = true;
    }
}

/// The textures of A (and B when comparing) in the current view and exposure, updated in place.
pub(super) fn textures(s: &Session, u: &mut UiState, ctx: &egui::Context) -> [Option<egui::TextureId>; 2] {
    let frames = [s.frame().cloned(), s.frame_b().cloned()];
    // A new view, exposure or compare mode shows at once.
    if u.shown_with != (s.view(), s.exposure(), s.is_comparing()) {
        u.shown_with = (s.view(), s.exposure(), s.is_comparing());
        u.texture_stale = true;
    }
    if u.refined {
        match u.last_upload.map(|t| t.elapsed()) {
            Some(since) if since < UPLOAD_INTERVAL => ctx.request_repaint_after(UPLOAD_INTERVAL - since),
            _ => u.texture_stale = true,
        }
    }
    if u.texture_stale || u.textures[A].is_none() {
        u.texture_stale = false;
        u.refined = false;
        u.last_upload = Some(Instant::now());
        let reference = s.reference().cloned();
        let view = shown(s.view(), [frames[A].as_deref(), frames[B].as_deref()], reference.as_deref(), s.exposure());
        u.scale = view.scale;
        u.view_note = view.note;
        for (i, rgba) in view.rgba.into_iter().enumerate() {
            let (Some(frame), Some(rgba)) = (frames[i].as_deref(), rgba) else { continue };
            let image = egui::ColorImage::from_rgba_unmultiplied([frame.width as usize, frame.height as usize], &rgba);
            match &mut u.textures[i] {
                Some(t) => t.set(image, egui::TextureOptions::NEAREST),
                None => {
                    u.textures[i] =
                        Some(ctx.load_texture(["lane A", "lane B"][i], image, egui::TextureOptions::NEAREST))
                }
            }
        }
    }
    [A, B].map(|i| frames[i].as_ref().and(u.textures[i].as_ref()).map(|t| t.id()))
}

/// Refined frames of the image on screen are uploaded at most this often: on a software rasteriser (a VM, Xvfb) an
/// upload and repaint per pass would take the core that renders. A restart, a new view or exposure shows at once.
pub(super) const UPLOAD_INTERVAL: Duration = Duration::from_millis(250);

/// The session's callback: a repaint at once when urgent (a new setting's first frame, a probe answer), else
/// within [`UPLOAD_INTERVAL`], when the refined frame is uploaded anyway.
pub(super) fn repaint_notify(repaint: &Arc<Mutex<Option<egui::Context>>>) -> Notify {
    let target = repaint.clone();
    Arc::new(move |urgent| {
        if let Ok(ctx) = target.lock()
            && let Some(ctx) = ctx.as_ref()
        {
            if urgent {
                ctx.request_repaint();
            } else {
                ctx.request_repaint_after(UPLOAD_INTERVAL);
            }
        }
    })
}

/// A callback for other threads that asks the bound context, if any, to repaint.
pub(super) fn notifier(repaint: &Arc<Mutex<Option<egui::Context>>>) -> impl Fn() + Send + 'static {
    let target = repaint.clone();
    move || {
        if let Ok(ctx) = target.lock()
            && let Some(ctx) = ctx.as_ref()
        {
            ctx.request_repaint();
        }
    }
}
