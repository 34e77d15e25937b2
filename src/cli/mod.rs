//! The headless command line: `render`, `bench`, `probe`, `tour` and `strategies`.

mod bench;
mod probe;
mod progress;
mod tour;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use illumlab::guiding::{GuideSettings, Training};
use illumlab::render::{
    Film, Footprint, Heuristic, MisSettings, RenderSettings, Renderer, Strategy, check_output_path, write_image,
};
use illumlab::scene::{LightSelection, Scene, load_scene};
use illumlab::session::views::View;
use illumlab::session::worker::Budget;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Parser, Debug)]
#[command(name = "illumlab", version, about = "Monte Carlo estimators of the scattering equation: render and measure")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Open the viewer (the default without a subcommand).
    View(ViewArgs),
    /// Render a scene with one strategy to an EXR (linear) or PNG (sRGB) file.
    Render(RenderArgs),
    /// Measure the speed/accuracy trade: every strategy at several budgets against a reference; writes CSV,
    /// markdown and a log–log plot of RMSE against spp and seconds.
    Bench(bench::BenchArgs),
    /// Probe one pixel's shading point: the estimate against a quadrature, the chi-square of the sampler there,
    /// and the hemisphere picture.
    Probe(probe::ProbeArgs),
    /// Render every step of a tour (a lecture's demonstrations) to PNG, with probe pictures and captions.
    Tour(tour::TourArgs),
    /// List the sampling strategies: name, then a one-line description.
    Strategies,
}

#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// A scene file (.toml, or a bare .obj) or the name of a bundled scene (default, cornell-box, veach-mis,
    /// near-light, occluded-light).
    pub scene: String,
    /// Sampling strategy (see `illumlab strategies`).
    #[arg(long, value_parser = parse_strategy)]
    pub strategy: Strategy,
    /// Samples per pixel.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..), allow_negative_numbers = true)]
    pub spp: u32,
    /// Seed of the random streams.
    #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
    pub seed: u64,
    /// How light strategies pick a triangle: uniform, area, power or contribution.
    #[arg(long, value_parser = parse_light_selection, default_value = "power")]
    pub light_selection: LightSelection,
    /// Where camera rays go in their pixels: jittered (a box filter, for pictures) or centre (fixed primary hits,
    /// to measure the estimator against a reference rendered the same way).
    #[arg(long, value_parser = parse_footprint, default_value = "jittered")]
    pub footprint: Footprint,
    /// Image size WxH, overriding the scene's camera.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Exposure in stops, for PNG output.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    #[command(flatten)]
    pub mis: MisArgs,
    #[command(flatten)]
    pub guiding: GuidingArgs,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..), allow_negative_numbers = true)]
    pub threads: Option<u32>,
    /// Output file: .exr or .png.
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(clap::Args, Debug)]
pub struct ViewArgs {
    /// A scene file or bundled scene; the embedded default scene if absent.
    pub scene: Option<String>,
    #[arg(long, value_parser = parse_strategy, default_value = "emitter")]
    pub strategy: Strategy,
    #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
    pub seed: u64,
    /// Threads that render passes (default: every core).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..), allow_negative_numbers = true)]
    pub threads: Option<u32>,
    /// Where camera rays go in their pixels: jittered (pictures) or centre (fixed primary hits: the error maps and
    /// the convergence plot show the estimators' own error; the reference is rendered the same way).
    #[arg(long, value_parser = parse_footprint, default_value = "jittered")]
    pub footprint: Footprint,
    #[arg(long, value_parser = parse_light_selection, default_value = "power")]
    pub light_selection: LightSelection,
    /// Stop refining at this many samples per pixel.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..), allow_negative_numbers = true)]
    pub target_spp: Option<u32>,
    /// Exposure in stops.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Image size WxH, overriding the scene's camera.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    #[command(flatten)]
    pub mis: MisArgs,
    #[command(flatten)]
    pub guiding: GuidingArgs,
    /// Open in compare mode with this strategy as B (A is --strategy).
    #[arg(long, value_parser = parse_strategy)]
    pub compare: Option<Strategy>,
    /// Compare mode's budget: equal-samples or equal-time.
    #[arg(long, value_parser = parse_budget, default_value = "equal-samples")]
    pub budget: Budget,
    /// What to show: image, std-error, relative-variance, abs-error, fireflies or difference.
    #[arg(long, value_parser = parse_view, default_value = "image")]
    pub view: View,
    /// Samples per pixel of the reference the error views and the plot measure against.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..), allow_negative_numbers = true)]
    pub reference_spp: u32,
    /// Open the convergence plot.
    #[arg(long)]
    pub plot: bool,
    /// Open the probe at pixel X,Y (column from the left, row from the top).
    #[arg(long, value_parser = probe::parse_pixel)]
    pub probe: Option<(u32, u32)>,
    /// Present a tour from its first step: a tour file, or the bundled lecture without one (a scene to start on
    /// goes before `--tour`).
    #[arg(long, num_args = 0..=1, default_missing_value = "lecture", value_name = "FILE")]
    pub tour: Option<String>,
}

/// The options of `--strategy mis`.
#[derive(clap::Args, Debug, Clone)]
pub struct MisArgs {
    /// MIS: its first technique, by default a light strategy (any strategy but mis).
    #[arg(long, value_parser = parse_technique, default_value = "emitter")]
    pub mis_light: Strategy,
    /// MIS: its second technique, by default BRDF sampling (any strategy but mis).
    #[arg(long, value_parser = parse_technique, default_value = "brdf")]
    pub mis_brdf: Strategy,
    /// MIS: balance or power heuristic.
    #[arg(long, value_parser = parse_heuristic, default_value = "power")]
    pub mis_heuristic: Heuristic,
    /// MIS: directions per pixel sample from the first and the second technique, as L,B.
    #[arg(long, value_parser = parse_mis_samples, default_value = "1,1")]
    pub mis_samples: (u32, u32),
}

/// The options of `--strategy guided` (and of MIS with a guided technique).
#[derive(clap::Args, Debug, Clone)]
pub struct GuidingArgs {
    /// guided: samples per pixel of training; the iterations (1, 2, 4, … spp) that end within it learn the
    /// guide, later samples use it frozen.
    #[arg(long, default_value_t = GuideSettings::default().training_spp)]
    pub train_spp: u32,
    /// guided: Müller's c; a spatial leaf with more than c·√(2^k) records in iteration k is split.
    #[arg(long, default_value_t = GuideSettings::default().spatial_threshold, value_parser = clap::value_parser!(u32).range(1..))]
    pub spatial_threshold: u32,
    /// guided: leave the training samples out of the image (by default every pass is kept: each is unbiased).
    #[arg(long)]
    pub discard_training: bool,
}

impl GuidingArgs {
    pub(crate) fn settings(&self) -> GuideSettings {
        GuideSettings {
            training_spp: self.train_spp,
            spatial_threshold: self.spatial_threshold,
            discard_training: self.discard_training,
        }
    }
}

impl MisArgs {
    pub(crate) fn settings(&self) -> MisSettings {
        MisSettings {
            techniques: [self.mis_light, self.mis_brdf],
            heuristic: self.mis_heuristic,
            samples: [self.mis_samples.0, self.mis_samples.1],
        }
    }
}

fn parse_technique(s: &str) -> Result<Strategy, String> {
    Strategy::techniques().find(|t| t.name() == s).ok_or_else(|| {
        let names: Vec<&str> = Strategy::techniques().map(|s| s.name()).collect();
        format!("unknown MIS technique (one of: {})", names.join(", "))
    })
}

fn parse_heuristic(s: &str) -> Result<Heuristic, String> {
    Heuristic::from_name(s).ok_or_else(|| "unknown heuristic (balance or power)".into())
}

fn parse_mis_samples(s: &str) -> Result<(u32, u32), String> {
    let (l, b) = s.split_once(',').ok_or("expected L,B, e.g. 1,1")?;
    match (l.trim().parse::<u32>(), b.trim().parse::<u32>()) {
        (Ok(l), Ok(b)) if l + b > 0 && l <= 1024 && b <= 1024 => Ok((l, b)),
        _ => Err("L and B must be whole numbers up to 1024, not both 0".into()),
    }
}

pub(crate) fn parse_strategy(s: &str) -> Result<Strategy, String> {
    Strategy::from_name(s).ok_or_else(|| {
        let names: Vec<&str> = Strategy::ALL.iter().map(|s| s.name()).collect();
        format!("unknown strategy (one of: {})", names.join(", "))
    })
}

fn parse_budget(s: &str) -> Result<Budget, String> {
    Budget::from_slug(s).ok_or_else(|| "unknown budget (equal-samples or equal-time)".into())
}

fn parse_view(s: &str) -> Result<View, String> {
    View::from_slug(s).ok_or_else(|| {
        let names: Vec<&str> = View::ALL.iter().map(|v| v.slug()).collect();
        format!("unknown view (one of: {})", names.join(", "))
    })
}

pub(crate) fn parse_footprint(s: &str) -> Result<Footprint, String> {
    Footprint::from_name(s).ok_or_else(|| "unknown footprint (one of: jittered, centre)".to_string())
}

pub(crate) fn parse_light_selection(s: &str) -> Result<LightSelection, String> {
    LightSelection::from_name(s)
        .ok_or_else(|| "unknown light selection (one of: uniform, area, power, contribution)".to_string())
}

pub(crate) fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or("expected WxH, e.g. 256x256")?;
    let parse = |v: &str| v.trim().parse::<u32>().ok().filter(|&v| (1..=16384).contains(&v));
    match (parse(w), parse(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err("width and height must be whole numbers from 1 to 16384".into()),
    }
}

/// `illumlab view` with clap's defaults: what runs without a subcommand.
pub fn default_command() -> Command {
    match Cli::try_parse_from(["illumlab", "view"]).map(|c| c.command) {
        Ok(Some(command)) => command,
        _ => unreachable!("`illumlab view` parses"),
    }
}

pub fn run(command: Command) -> Result<()> {
    match command {
        Command::Strategies => {
            for s in Strategy::ALL {
                println!("{:<22} {}", s.name(), s.description());
            }
            Ok(())
        }
        Command::Render(args) => render(args),
        Command::Bench(args) => bench::bench(args),
        Command::Probe(args) => probe::probe(args),
        Command::Tour(args) => tour::tour(args),
        Command::View(args) if !args.exposure.is_finite() => bail!("--exposure must be a finite number of stops"),
        Command::View(args) => {
            // A bad tour is one line and a non-zero exit, before any window opens.
            if let Some(t) = args.tour.as_deref()
                && illumlab::scene::BUNDLED_SCENES.iter().any(|b| b.name == t)
                && !std::path::Path::new(t).exists()
            {
                bail!("`{t}` is a scene, not a tour: put it before --tour (illumlab view {t} --tour)");
            }
            let tour = args.tour.as_deref().map(illumlab::tour::Tour::load).transpose()?;
            illumlab::app::run(illumlab::app::ViewOptions {
                scene: args.scene.unwrap_or_else(|| illumlab::scene::DEFAULT_SCENE.into()),
                settings: RenderSettings {
                    strategy: args.strategy,
                    light_selection: args.light_selection,
                    seed: args.seed,
                    mis: args.mis.settings(),
                    footprint: args.footprint,
                    guiding: args.guiding.settings(),
                },
                target_spp: args.target_spp,
                exposure: args.exposure,
                size: args.size,
                compare: args.compare,
                budget: args.budget,
                view: args.view,
                reference_spp: args.reference_spp,
                plot: args.plot,
                probe: args.probe,
                threads: args.threads.map(|t| t as usize),
                tour,
            })
        }
    }
}

fn render(args: RenderArgs) -> Result<()> {
    if !args.exposure.is_finite() {
        bail!("--exposure must be a finite number of stops");
    }
    check_output_path(&args.output)?;
    let scene = load_sized(&args.scene, args.size)?;
    let pool = thread_pool(args.threads)?;
    let settings = RenderSettings {
        strategy: args.strategy,
        light_selection: args.light_selection,
        seed: args.seed,
        mis: args.mis.settings(),
        footprint: args.footprint,
        guiding: args.guiding.settings(),
    };
    let mut film = Film::new(scene.camera.width, scene.camera.height);
    let shadow_walk = scene.accel().shadow_walk();
    // A large mesh's tree read back from the cache rather than built (`scene::TreeCache`): a faster load.
    let tree = if scene.accel().from_cache() { ", tree read from the cache" } else { "" };
    let mut renderer = Renderer::new(std::sync::Arc::new(scene), settings);

    let start = Instant::now();
    let stats = pool.install(|| progress::render_all(&mut renderer, &mut film, args.spp, ""));
    let seconds = start.elapsed().as_secs_f64();
    write_image(&film, &args.output, args.exposure)?;
    if let Some(training) = renderer.training() {
        print_training(training);
    }
    println!(
        "{} spp, {:.3} s, {:.2} M samples/s, {:.2} M rays/s, {} non-finite samples dropped, shadow rays in {}{} -> {}",
        args.spp,
        seconds,
        stats.samples as f64 / seconds / 1e6,
        stats.rays as f64 / seconds / 1e6,
        stats.non_finite,
        shadow_walk,
        tree,
        args.output.display()
    );
    Ok(())
}

/// What each iteration of a guide's training built (to standard error: the last line on standard output stays
/// the render's summary).
pub(crate) fn print_training(training: &Training) {
    for r in training.log() {
        eprintln!("guide {r}");
    }
    let frozen = if training.is_frozen() { "frozen" } else { "still learning" };
    eprintln!("guide: {frozen} after {} iterations", training.log().len());
}

/// Loads a scene (file or bundled), overrides the camera's size if asked, and prints its warnings.
pub(crate) fn load_sized(scene: &str, size: Option<(u32, u32)>) -> Result<Scene> {
    let mut scene = load_scene(scene)?;
    if let Some((w, h)) = size {
        scene.camera.width = w;
        scene.camera.height = h;
    }
    for w in &scene.warnings {
        eprintln!("warning: {}: {w}", scene.name);
    }
    Ok(scene)
}

/// The pool that renders: `threads` threads, or one per core.
pub(crate) fn thread_pool(threads: Option<u32>) -> Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0) as usize)
        .build()
        .context("cannot start the worker threads")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_subcommand_means_view_with_the_documented_defaults() {
        let Command::View(args) = default_command() else { panic!("not `view`") };
        assert_eq!(args.scene, None);
        assert_eq!(args.strategy, Strategy::Emitter);
        assert_eq!(args.light_selection, LightSelection::Power);
        assert_eq!(args.mis.settings(), MisSettings::default());
    }
}
