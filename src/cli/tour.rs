//! `illumlab tour FILE --out DIR`: every step of a tour rendered headless, for slides and for checking a tour.

use anyhow::{Result, bail};
use illumlab::tour::{Tour, TourRender, render_tour};
use std::path::PathBuf;
use std::time::Duration;

#[derive(clap::Args, Debug)]
pub struct TourArgs {
    /// A tour file (TOML, one [[step]] table per step), or `lecture` for the bundled tour.
    pub tour: String,
    /// Folder for each step's PNG (and probe pictures) and JSON sidecar with the caption.
    #[arg(long)]
    pub out: PathBuf,
    /// Samples per pixel of a step that names no target_spp.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: u32,
    /// At most this many samples per pixel in any step (a quick check of a tour).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub max_spp: Option<u32>,
    /// Pixels on the image's longer side, overriding the steps'.
    #[arg(long, value_parser = clap::value_parser!(u32).range(8..=4096))]
    pub resolution: Option<u32>,
    /// Samples per pixel of a reference, for steps that show the error against one.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..))]
    pub reference_spp: u32,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub threads: Option<u32>,
    /// Seconds a step may take before it is an error.
    #[arg(long, default_value_t = 600)]
    pub timeout: u64,
}

pub fn tour(args: TourArgs) -> Result<()> {
    let tour = Tour::load(&args.tour)?;
    let defaults = TourRender::default();
    let options = TourRender {
        threads: args.threads.map_or(defaults.threads, |t| t as usize),
        spp: args.spp,
        max_spp: args.max_spp,
        resolution: args.resolution,
        reference_spp: args.reference_spp,
        timeout: Duration::from_secs(args.timeout.max(1)),
        ..defaults
    };
    let count = tour.steps.len();
    let written = render_tour(&tour, &args.out, &options, |i, out| {
        println!(
            "step {}/{count}: {} spp in {:.2} s -> {}{}",
            i + 1,
            out.spp,
            out.seconds,
            out.image.display(),
            if out.probe.is_empty() { String::new() } else { format!(" (+ {} probe pictures)", out.probe.len()) }
        );
    })?;
    if written.len() != count {
        bail!("only {} of {count} steps were rendered", written.len());
    }
    Ok(())
}
