//! `illumlab bench`: every strategy at several budgets against a reference, written as CSV, markdown and a plot.

use super::{
    GuidingArgs, MisArgs, load_sized, parse_footprint, parse_light_selection, parse_size, parse_strategy, thread_pool,
};
use anyhow::{Context, Result, bail};
use illumlab::measure::{
    BenchContext, BenchPlan, Metric, Reference, machine_description, markdown, reference_settings, run_bench,
    sees_emitter, write_convergence_png, write_csv,
};
use illumlab::render::{Film, Footprint, RenderSettings, Renderer, Strategy, check_output_path};
use illumlab::scene::{LightSelection, Scene};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    /// A scene file or the name of a bundled scene.
    pub scene: String,
    /// Strategies to compare, comma-separated (default: all).
    #[arg(long, value_delimiter = ',', value_parser = parse_strategy)]
    pub strategies: Vec<Strategy>,
    /// Budgets in samples per pixel, comma-separated; each strategy renders progressively through them.
    #[arg(long, value_delimiter = ',', default_value = "1,4,16,64,256", value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub spp: Vec<u32>,
    /// A reference image (linear EXR of the same size); without it one is rendered and saved in the output folder.
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Samples per pixel of a rendered reference (default: 16 × the largest budget).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..), allow_negative_numbers = true)]
    pub reference_spp: Option<u32>,
    /// Output folder (created if needed; default: bench-<scene>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Image size WxH, overriding the scene's camera.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// The first seed; each strategy renders with seeds SEED, SEED+1, … (see --seeds).
    #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
    pub seed: u64,
    /// Independent runs per strategy, for the means and 95% intervals (a winner is declared only when the
    /// intervals separate).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub seeds: u32,
    /// Where camera rays go in their pixels: centre (fixed primary hits: the error is the estimator's alone) or
    /// jittered (the box filter of pictures: the error includes the footprint's noise, common to every strategy).
    #[arg(long, value_parser = parse_footprint, default_value = "centre")]
    pub footprint: Footprint,
    /// Measure the pixels that see an emitter directly too (left out by default).
    #[arg(long)]
    pub include_emitter_pixels: bool,
    #[arg(long, value_parser = parse_light_selection, default_value = "power")]
    pub light_selection: LightSelection,
    #[command(flatten)]
    pub mis: MisArgs,
    #[command(flatten)]
    pub guiding: GuidingArgs,
    /// The strategy of a rendered reference: mis (projected-solid-angle + BRDF, power heuristic) or guided
    /// (for scenes where light arrives through small openings, which MIS resolves slowly).
    #[arg(long, value_parser = parse_strategy, default_value = "mis")]
    pub reference_strategy: Strategy,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..), allow_negative_numbers = true)]
    pub threads: Option<u32>,
}

pub fn bench(args: BenchArgs) -> Result<()> {
    let mut budgets = args.spp.clone();
    budgets.sort_unstable();
    budgets.dedup();
    let strategies = if args.strategies.is_empty() { Strategy::ALL.to_vec() } else { args.strategies.clone() };
    let scene = std::sync::Arc::new(load_sized(&args.scene, args.size)?);
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from(format!("bench-{}", scene.name)));
    std::fs::create_dir_all(&out).with_context(|| format!("output folder {}", out.display()))?;
    check_output_path(&out.join("convergence.png"))?;
    let pool = thread_pool(args.threads)?;
    let (w, h) = (scene.camera.width, scene.camera.height);

    let (reference, reference_line) = match &args.reference {
        Some(path) => {
            let r = Reference::load_exr(path)?;
            r.check_size(w, h)?;
            (r, format!("{} (given: it must be rendered with the {} footprint)", path.display(), args.footprint.name()))
        }
        None => {
            let spp = args.reference_spp.unwrap_or(16 * budgets.last().copied().unwrap_or(1));
            let settings = match args.reference_strategy {
                Strategy::Mis => reference_settings(args.footprint),
                Strategy::Guided => RenderSettings {
                    strategy: Strategy::Guided,
                    guiding: args.guiding.settings(),
                    ..reference_settings(args.footprint)
                },
                other => bail!("--reference-strategy must be mis or guided, not {}", other.name()),
            };
            let r = pool.install(|| render_reference(&scene, spp, settings));
            let path = out.join("reference.exr");
            r.save_exr(&path)?;
            let what = match settings.strategy {
                Strategy::Guided => "guided (trained within its samples)",
                _ => "MIS (projected-solid-angle + BRDF, power heuristic)",
            };
            let line = format!(
                "{what}, {spp} spp, {} footprint, rendered in {:.1} s, saved as {}",
                args.footprint.name(),
                r.seconds,
                path.display()
            );
            println!("reference: {line}");
            (r, line)
        }
    };

    let base = RenderSettings {
        strategy: Strategy::Emitter,
        light_selection: args.light_selection,
        seed: args.seed,
        mis: args.mis.settings(),
        footprint: args.footprint,
        guiding: args.guiding.settings(),
    };
    let included: Option<Vec<bool>> =
        (!args.include_emitter_pixels).then(|| sees_emitter(&scene, args.footprint).into_iter().map(|s| !s).collect());
    let plan = BenchPlan { base, strategies, spp: budgets.clone(), seeds: args.seeds };
    let report = pool.install(|| {
        run_bench(&scene, &reference, &plan, included.as_deref(), |s, k, spp| {
            if Some(&spp) == budgets.last() && k + 1 == args.seeds {
                eprintln!("  {} done", s.name());
            }
        })
    });
    if budgets.is_empty() || report.rows.is_empty() {
        bail!("nothing to measure");
    }
    let machine = machine_description();
    let threads = pool.current_num_threads();
    let ctx = BenchContext {
        scene: &scene.name,
        width: w,
        height: h,
        reference: &reference_line,
        machine: &format!("{machine} ({threads} used; shadow rays in {})", scene.accel().shadow_walk()),
        footprint: args.footprint,
    };
    let md = markdown(&report, &ctx);
    write(&out.join("bench.md"), md.as_bytes())?;
    write_csv(&out.join("bench.csv"), &report).map_err(anyhow::Error::msg)?;
    let mode = match args.footprint {
        Footprint::Centre => "fixed hits",
        Footprint::Jittered => "jittered footprint",
    };
    let title = format!("{} {w}x{h}, {mode}: estimator RMSE, mean of {} seeds", scene.name, args.seeds);
    write_convergence_png(
        &out.join("convergence.png"),
        &title,
        &report.series,
        report.reference_rmse,
        Metric::Mse,
        WALL,
    )?;
    let title = format!("{} {w}x{h}, {mode}: estimator relative RMSE, mean of {} seeds", scene.name, args.seeds);
    let floor = reference.noise_rel_mse().sqrt();
    write_convergence_png(&out.join("convergence-relative.png"), &title, &report.series, floor, Metric::RelMse, WALL)?;
    println!("{md}");
    println!("wrote {}/bench.csv, bench.md, convergence.png, convergence-relative.png", out.display());
    Ok(())
}

const WALL: &str = "wall-clock seconds";

/// Renders the reference with `settings`.
fn render_reference(scene: &std::sync::Arc<Scene>, spp: u32, settings: RenderSettings) -> Reference {
    let mut renderer = Renderer::new(scene.clone(), settings);
    let mut film = Film::new(scene.camera.width, scene.camera.height);
    let start = Instant::now();
    super::progress::render_all(&mut renderer, &mut film, spp, "reference ");
    Reference::from_film(&film, start.elapsed().as_secs_f64())
}

fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    std::fs::write(path, bytes).with_context(|| format!("cannot write {}", path.display()))
}
