//! Frames from the worker to the screen: the newest of each lane taken, their textures uploaded (refinements at
//! most every [`UPLOAD_INTERVAL`]), and the callbacks with which other threads wake the UI.

use super::viewer::Viewer;
use crate::session::snapshot::display_rgba;
use crate::session::views::{View, shared_scale, unavailable, view_values};
use crate::session::worker::{A, B, ReferenceStatus};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

impl Viewer {
    /// The newest frames and reference from the worker, if any; records convergence; refreshes textures lazily.
    pub(super) fn take_frames(&mut self) {
        if let Some(failure) = self.worker.take_failure() {
            self.error = Some(failure);
        }
        if let Some(status) = self.worker.take_reference() {
            // Progress reports of the same render change neither the runs nor the maps.
            let progress = matches!(
                (&self.reference, &status),
                (ReferenceStatus::Rendering { .. }, ReferenceStatus::Rendering { .. })
            );
            if !progress {
                self.history.clear();
                self.texture_stale = true;
            }
            self.reference = status;
        }
        for lane in [A, B] {
            let Some(frame) = self.worker.take_lane(lane) else { continue };
            if lane == B && !self.comparing {
                continue; // a frame from before compare mode was left
            }
            if let Some((sent, generation)) = self.restart_sent
                && frame.generation >= generation
            {
                self.restart_latency = Some(sent.elapsed());
                self.restart_sent = None;
                if self.trace {
                    let ms = sent.elapsed().as_secs_f64() * 1e3;
                    eprintln!("trace: restart-to-frame {ms:.1} ms at {}x{}", frame.width, frame.height);
                }
            }
            if self.restart_sent.is_none() {
                self.awaiting_frame.store(false, Ordering::Relaxed);
            }
            self.record(&frame);
            let shown = if lane == A { &mut self.frame } else { &mut self.frame_b };
            // A refinement of the image on screen may wait for the next upload; anything else shows at once.
            let refinement = shown.as_ref().is_some_and(|f| f.generation == frame.generation && !f.preview);
            *shown = Some(frame);
            if refinement {
                self.refined = true;
            } else {
                self.texture_stale = true;
            }
        }
    }

    /// The textures of A (and B when comparing) in the current view and exposure, updated in place.
    pub(super) fn textures(&mut self, ctx: &egui::Context) -> [Option<egui::TextureId>; 2] {
        let frames = [self.frame.clone(), self.frame_b.clone().filter(|_| self.comparing)];
        if self.refined {
            match self.last_upload.map(|t| t.elapsed()) {
                Some(since) if since < UPLOAD_INTERVAL => ctx.request_repaint_after(UPLOAD_INTERVAL - since),
                _ => self.texture_stale = true,
            }
        }
        if self.texture_stale || self.textures[A].is_none() {
            self.texture_stale = false;
            self.refined = false;
            self.last_upload = Some(Instant::now());
            let reference = self.reference().cloned();
            let reference = reference.as_deref();
            let values: Vec<Option<Vec<f32>>> = [A, B]
                .map(|i| {
                    let f = frames[i].as_deref()?;
                    view_values(self.view, f, reference, frames[1 - i].as_deref())
                })
                .into();
            let shown: Vec<&[f32]> = values.iter().flatten().map(|v| v.as_slice()).collect();
            self.scale = shared_scale(&shown);
            self.view_note =
                frames[A].as_deref().and_then(|f| unavailable(self.view, f, reference, frames[B].as_deref()));
            if self.view_note.is_none() && self.view != View::Image && self.scale.is_none() {
                self.view_note = Some("zero everywhere");
            }
            for i in [A, B] {
                let Some(frame) = frames[i].as_deref() else { continue };
                let rgba = match (&values[i], self.scale) {
                    (Some(v), Some(scale)) if self.view_note.is_none() => scale.colorize(v),
                    _ => display_rgba(&frame.radiance, self.exposure),
                };
                let image =
                    egui::ColorImage::from_rgba_unmultiplied([frame.width as usize, frame.height as usize], &rgba);
                match &mut self.textures[i] {
                    Some(t) => t.set(image, egui::TextureOptions::NEAREST),
                    None => {
                        self.textures[i] =
                            Some(ctx.load_texture(["lane A", "lane B"][i], image, egui::TextureOptions::NEAREST))
                    }
                }
            }
        }
        [A, B].map(|i| frames[i].as_ref().and(self.textures[i].as_ref()).map(|t| t.id()))
    }
}

/// Refined frames of the image on screen are uploaded at most this often: on a software rasteriser (a VM, Xvfb) an
/// upload and repaint per pass would take the core that renders. A restart, a new view or exposure shows at once.
pub(super) const UPLOAD_INTERVAL: Duration = Duration::from_millis(250);

/// The worker's callback: a repaint at once while `awaiting` (a new setting's first frame), else within
/// [`UPLOAD_INTERVAL`], when the refined frame is uploaded anyway.
pub(super) fn frame_notifier(
    repaint: &Arc<Mutex<Option<egui::Context>>>,
    awaiting: Arc<AtomicBool>,
) -> impl Fn() + Send + 'static {
    let target = repaint.clone();
    move || {
        if let Ok(ctx) = target.lock()
            && let Some(ctx) = ctx.as_ref()
        {
            if awaiting.load(Ordering::Relaxed) {
                ctx.request_repaint();
            } else {
                ctx.request_repaint_after(UPLOAD_INTERVAL);
            }
        }
    }
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
