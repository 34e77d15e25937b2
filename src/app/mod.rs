//! The interactive viewer: a thin egui/eframe shell over [`crate::session`]. Only this module knows egui.

mod compare;
mod compare_mode;
mod controls;
mod convergence;
mod files;
mod frames;
mod loader;
mod orbit;
mod probe;
mod shortcuts;
mod status;
mod tour;
mod viewer;
mod viewport;

pub use viewer::Viewer;

/// What the window opens on.
#[derive(Clone, Debug)]
pub struct ViewOptions {
    /// A bundled scene's name or a scene file.
    pub scene: String,
    pub settings: crate::render::RenderSettings,
    pub target_spp: Option<u32>,
    pub exposure: f32,
    /// Image size, overriding the scene's camera.
    pub size: Option<(u32, u32)>,
    /// Compare mode with this strategy as B.
    pub compare: Option<crate::render::Strategy>,
    pub budget: crate::session::worker::Budget,
    pub view: crate::session::views::View,
    pub reference_spp: u32,
    /// Open the convergence plot.
    pub plot: bool,
    /// Open the probe at this pixel.
    pub probe: Option<(u32, u32)>,
    /// Threads that render passes (`None`: the default, see [`Viewer::with_scene`]).
    pub threads: Option<usize>,
    /// Present this tour (a file, or `lecture`) from its first step.
    pub tour: Option<crate::tour::Tour>,
}

/// Opens the window, already rendering.
pub fn run(options: ViewOptions) -> anyhow::Result<()> {
    let mut scene = crate::scene::load_scene(&options.scene)?;
    let source = options.scene.clone();
    if let Some((w, h)) = options.size {
        scene.camera.width = w;
        scene.camera.height = h;
    }
    let native = eframe::NativeOptions {
        renderer: eframe::Renderer::Wgpu,
        viewport: egui::ViewportBuilder::default().with_inner_size([1280.0, 800.0]).with_title("illumlab"),
        ..Default::default()
    };
    eframe::run_native(
        "illumlab",
        native,
        Box::new(move |cc| {
            let mut viewer = Viewer::with_threads(std::sync::Arc::new(scene), options.threads);
            viewer.session_mut().set_source(source);
            viewer.configure(options.settings, options.target_spp, options.exposure);
            viewer.set_reference_spp(options.reference_spp);
            viewer.set_budget(options.budget);
            if let Some(b) = options.compare {
                viewer.set_strategy_b(b);
                viewer.set_comparing(true);
            }
            viewer.set_view(options.view);
            if options.plot {
                viewer.show_convergence_plot();
            }
            if let Some(pixel) = options.probe {
                viewer.set_probe_pixel(pixel);
            }
            if let Some(file) = files::RecentFiles::default_file() {
                viewer.set_recent_file(file);
            }
            if let Some(file) = files::UiScale::default_file() {
                viewer.set_ui_scale_file(file);
            }
            if let Some(tour) = options.tour {
                viewer.present(tour);
            }
            viewer.bind_repaint(cc.egui_ctx.clone());
            Ok(Box::new(viewer))
        }),
    )
    .map_err(|e| anyhow::anyhow!("cannot open the window: {e}"))
}

impl eframe::App for Viewer {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        Viewer::ui(self, ui);
    }
}
