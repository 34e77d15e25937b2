//! The probe in the background: a thread that answers the newest probe request (a pixel, the lanes' settings,
//! how much work) with the reports and pictures of [`crate::probe`], so that the UI never waits on a quadrature
//! or a chi-square test. Requests supersede each other (only the newest pending one is computed), the quadrature
//! of a point is kept while only the strategies change, and the answer comes through a latest-value slot.

use crate::guiding::Guide;
use crate::probe::{
    Layers, Picture, Probe, ProbeJson, ProbePoint, ProbeReport, ProbeSettings, Quadrature, StrategyRow, quadrature,
};
use crate::render::{RenderSettings, write_png_rgba};
use crate::scene::{Camera, Scene};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// What to probe.
#[derive(Clone)]
pub struct ProbeRequest {
    pub scene: Arc<Scene>,
    pub camera: Camera,
    pub pixel: (u32, u32),
    /// Lane A's settings, and B's in compare mode (the same samples' streams: common random numbers).
    pub lanes: Vec<RenderSettings>,
    /// Per lane: the guide its renderer samples from now (a strategy that learns one), as of the lane's newest
    /// frame.
    pub guides: Vec<Option<Arc<Guide>>>,
    pub settings: ProbeSettings,
    pub layers: Layers,
    /// Also measure every strategy at the point.
    pub table: bool,
}

impl PartialEq for ProbeRequest {
    fn eq(&self, o: &Self) -> bool {
        Arc::ptr_eq(&self.scene, &o.scene)
            && self.camera == o.camera
            && self.pixel == o.pixel
            && self.lanes == o.lanes
            && self.guides.len() == o.guides.len()
            && self.guides.iter().zip(&o.guides).all(|(a, b)| match (a, b) {
                (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                (a, b) => a.is_none() && b.is_none(),
            })
            && self.settings == o.settings
            && self.layers == o.layers
            && self.table == o.table
    }
}

/// The answer to a request.
pub struct ProbeView {
    pub request: ProbeRequest,
    /// `None` where the pixel's camera ray meets nothing.
    pub point: Option<ProbePoint>,
    /// Per lane: the report and its picture.
    pub lanes: Vec<(ProbeReport, Picture)>,
    pub table: Option<Vec<StrategyRow>>,
    /// From the request's arrival to the answer.
    pub elapsed: Duration,
}

impl ProbeView {
    /// Writes each lane's picture (PNG) and numbers (JSON) into `folder` as `probe-<scene>-<x>-<y>-<strategy>`;
    /// returns the PNG paths.
    pub fn export(&self, folder: &Path) -> Result<Vec<PathBuf>, String> {
        std::fs::create_dir_all(folder).map_err(|e| format!("cannot create {}: {e}", folder.display()))?;
        let scene = &self.request.scene;
        let (x, y) = self.request.pixel;
        let mut written = Vec::new();
        for (report, picture) in &self.lanes {
            let stem = format!("probe-{}-{x}-{y}-{}", scene.name, report.strategy.name());
            let png = folder.join(format!("{stem}.png"));
            write_png_rgba(&png, picture.width as u32, picture.height as u32, picture.rgba.clone())
                .map_err(|e| e.to_string())?;
            let json = ProbeJson::new(scene, report, self.table.clone());
            let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())?;
            std::fs::write(folder.join(format!("{stem}.json")), text).map_err(|e| e.to_string())?;
            written.push(png);
        }
        Ok(written)
    }
}

/// The probe's thread.
pub struct ProbeWorker {
    requests: Option<Sender<ProbeRequest>>,
    latest: Arc<Mutex<Option<ProbeView>>>,
    thread: Option<JoinHandle<()>>,
}

impl ProbeWorker {
    /// Starts the thread; it calls `notify` after each answer.
    pub fn spawn(notify: impl Fn() + Send + 'static) -> Self {
        let (tx, rx) = channel();
        let latest = Arc::new(Mutex::new(None));
        let slot = latest.clone();
        let thread =
            std::thread::Builder::new().name("illumlab-probe".into()).spawn(move || serve(rx, slot, notify)).ok();
        Self { requests: Some(tx), latest, thread }
    }

    pub fn request(&self, request: ProbeRequest) {
        if let Some(tx) = &self.requests {
            let _ = tx.send(request);
        }
    }

    /// The newest answer, if one came since the last call.
    pub fn take(&self) -> Option<ProbeView> {
        self.latest.lock().ok()?.take()
    }
}

impl Drop for ProbeWorker {
    fn drop(&mut self) {
        self.requests = None; // the thread's receive fails and it ends
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn serve(rx: Receiver<ProbeRequest>, slot: Arc<Mutex<Option<ProbeView>>>, notify: impl Fn()) {
    // The quadrature of the last point, kept while only strategies and work change.
    let mut kept: Option<(Arc<Scene>, ProbePoint, u64, Quadrature)> = None;
    while let Ok(mut request) = rx.recv() {
        while let Ok(newer) = rx.try_recv() {
            request = newer;
        }
        let start = Instant::now();
        let point = ProbePoint::at_pixel(&request.scene, &request.camera, request.pixel);
        let mut lanes = Vec::new();
        let mut table = None;
        if let Some(point) = point {
            let quadrature = match &kept {
                Some((s, p, nodes, q))
                    if Arc::ptr_eq(s, &request.scene) && *p == point && *nodes == request.settings.quadrature_nodes =>
                {
                    *q
                }
                _ => {
                    let scene = &request.scene;
                    let q = quadrature(scene, &point.shading_point(scene), request.settings.quadrature_nodes);
                    kept = Some((request.scene.clone(), point, request.settings.quadrature_nodes, q));
                    q
                }
            };
            for (i, settings) in request.lanes.iter().enumerate() {
                let guide = request.guides.get(i).cloned().flatten();
                let probe = Probe::new(request.scene.clone(), *settings).with_guide(guide);
                let report = probe.run(&point, settings.strategy, quadrature, &request.settings);
                let picture = probe.picture(&report, request.layers);
                lanes.push((report, picture));
            }
            if request.table
                && let Some(settings) = request.lanes.first()
            {
                let probe = Probe::new(request.scene.clone(), *settings);
                table = Some(probe.table(
                    &point,
                    &quadrature,
                    request.settings.samples.min(100_000),
                    request.settings.seed,
                ));
            }
        }
        let view = ProbeView { request, point, lanes, table, elapsed: start.elapsed() };
        if let Ok(mut s) = slot.lock() {
            *s = Some(view);
        }
        notify();
    }
}
