//! The probe's side of a [`Session`]: which pixel it looks at, with what options, and the requests sent to the
//! probe's worker when what it depends on changes.

use super::Session;
use crate::probe::{Layers, ProbeSettings};
use crate::session::probe::{ProbeRequest, ProbeView};
use crate::session::worker::{A, B, Frame};
use std::sync::Arc;

/// What the probe looks at and how hard (the session sends a new request whenever any of it changes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeOptions {
    /// Re-probe the same pixel when the camera moves (else the point stays where it was picked).
    pub follow: bool,
    pub settings: ProbeSettings,
    pub layers: Layers,
    /// Also measure every strategy at the point.
    pub table: bool,
}

impl Default for ProbeOptions {
    fn default() -> Self {
        Self {
            follow: false,
            settings: ProbeSettings { keep: 2_000, ..Default::default() },
            layers: Layers::default(),
            table: false,
        }
    }
}

impl Session {
    /// The probed pixel, if any.
    pub fn probe_pixel(&self) -> Option<(u32, u32)> {
        self.probe_pixel.map(|(p, _)| p)
    }
    /// Where the probe's marker goes: the probed pixel, while the camera is the one it was picked with.
    pub fn probe_marker(&self) -> Option<(u32, u32)> {
        self.probe_pixel.filter(|(_, c)| *c == self.scene.camera).map(|(p, _)| p)
    }
    pub fn probe_options(&self) -> ProbeOptions {
        self.probe
    }
    /// The newest probe answer.
    pub fn probe_view(&self) -> Option<&ProbeView> {
        self.probe_view.as_ref()
    }
    /// The probe answered the request it is working on now (not an older one).
    pub fn probe_is_current(&self) -> bool {
        self.probe_view.as_ref().is_some_and(|v| self.last_request.as_ref() == Some(&v.request))
    }

    /// Probes pixel (x, y) of the current camera (`None`: no probe).
    pub fn set_probe_pixel(&mut self, pixel: Option<(u32, u32)>) {
        self.probe_pixel = pixel.map(|p| (p, self.scene.camera));
        self.probe.settings.chi2_samples = 0;
        if pixel.is_none() {
            self.probe_view = None;
            self.last_request = None;
        }
    }

    /// What the probe shows and how hard it works; the next [`Session::poll`] sends it.
    pub fn set_probe_options(&mut self, options: ProbeOptions) {
        self.probe = options;
    }

    /// Sends a new probe request when what the probe depends on changed.
    pub(super) fn request_probe(&mut self) {
        let Some((pixel, picked_with)) = self.probe_pixel else { return };
        if self.probe.follow && picked_with != self.scene.camera {
            self.probe_pixel = Some((pixel, self.scene.camera));
        }
        let camera = self.probe_pixel.map_or(self.scene.camera, |p| p.1);
        let guide_of = |f: Option<&Arc<Frame>>| f.and_then(|f| f.guide.as_ref()).map(|(_, g)| g.clone());
        let mut lanes = vec![self.settings];
        let mut guides = vec![guide_of(self.frames[A].as_ref())];
        if self.comparing {
            lanes.push(self.settings_b);
            guides.push(guide_of(self.frames[B].as_ref()));
        }
        let request = ProbeRequest {
            scene: self.scene.clone(),
            camera,
            pixel,
            lanes,
            guides,
            settings: self.probe.settings,
            layers: self.probe.layers,
            table: self.probe.table,
        };
        if self.last_request.as_ref() != Some(&request) {
            self.probe_worker.request(request.clone());
            self.last_request = Some(request);
        }
    }
}
