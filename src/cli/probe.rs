//! `illumlab probe`: the probe at one pixel, headless: the estimate, its interval, the quadrature value, the
//! z-score, the relative variance, the chi-square p-value and the zero samples by cause, and the picture.

use super::{GuidingArgs, MisArgs, load_sized, parse_light_selection, parse_strategy, print_training};
use anyhow::{Context, Result, bail};
use illumlab::math::luminance;
use illumlab::probe::{Layers, Probe, ProbeJson, ProbeSettings, chi2};
use illumlab::render::{Film, Footprint, RenderSettings, Renderer, Strategy, check_output_path, write_png_rgba};
use illumlab::scene::LightSelection;
use std::path::PathBuf;
use std::sync::Arc;

#[derive(clap::Args, Debug)]
pub struct ProbeArgs {
    /// A scene file or the name of a bundled scene.
    pub scene: String,
    /// The pixel X,Y: X the column from the left, Y the row from the top. The point is the first hit of the pixel
    /// centre's camera ray.
    #[arg(long, value_parser = parse_pixel)]
    pub pixel: (u32, u32),
    #[arg(long, value_parser = parse_strategy)]
    pub strategy: Strategy,
    /// Pixel samples of the strategy's estimator at the point.
    #[arg(long, default_value_t = 20_000, value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
    pub samples: u64,
    #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
    pub seed: u64,
    #[arg(long, value_parser = parse_light_selection, default_value = "power")]
    pub light_selection: LightSelection,
    #[command(flatten)]
    pub mis: MisArgs,
    /// guided: its guide is first learned by rendering the scene for --train-spp samples per pixel.
    #[command(flatten)]
    pub guiding: GuidingArgs,
    /// Image size WxH, overriding the scene's camera (the pixel is in this size).
    #[arg(long, value_parser = super::parse_size)]
    pub size: Option<(u32, u32)>,
    /// Draws of the chi-square test of the sampler at the point (0: none).
    #[arg(long, default_value_t = 200_000)]
    pub chi2_samples: u64,
    /// Also measure every strategy at the point (relative variance, samples/s, efficiency).
    #[arg(long)]
    pub table: bool,
    /// Write the hemisphere picture (PNG).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

pub(crate) fn parse_pixel(s: &str) -> Result<(u32, u32), String> {
    let (x, y) = s.split_once(',').ok_or("expected X,Y, e.g. 120,200")?;
    match (x.trim().parse(), y.trim().parse()) {
        (Ok(x), Ok(y)) => Ok((x, y)),
        _ => Err("X and Y must be whole numbers".into()),
    }
}

pub fn probe(args: ProbeArgs) -> Result<()> {
    if let Some(out) = &args.output {
        check_output_path(out)?;
    }
    let scene = Arc::new(load_sized(&args.scene, args.size)?);
    let (w, h) = (scene.camera.width, scene.camera.height);
    if args.pixel.0 >= w || args.pixel.1 >= h {
        bail!("pixel {},{} is outside the {w}x{h} image", args.pixel.0, args.pixel.1);
    }
    let settings = RenderSettings {
        strategy: args.strategy,
        light_selection: args.light_selection,
        seed: args.seed,
        mis: args.mis.settings(),
        footprint: Footprint::Jittered,
        guiding: args.guiding.settings(),
    };
    // A strategy that learns is probed with the guide it learns over the whole image.
    let guide = Strategy::learns(&settings).then(|| {
        let mut renderer = Renderer::new(scene.clone(), settings);
        let mut film = Film::new(w, h);
        renderer.render_pass(&mut film, 0, settings.guiding.training_end(), &|| false);
        if let Some(t) = renderer.training() {
            print_training(t);
        }
        renderer.guide().cloned()
    });
    let probe = Probe::new(scene.clone(), settings).with_guide(guide.flatten());
    let point = probe
        .point(args.pixel)
        .with_context(|| format!("the camera ray through pixel {},{} meets no surface", args.pixel.0, args.pixel.1))?;
    let ps = ProbeSettings {
        samples: args.samples,
        seed: args.seed,
        chi2_samples: args.chi2_samples,
        quadrature_nodes: 4_000_000,
        ..Default::default()
    };
    let quadrature = probe.quadrature(&point, &ps);
    let report = probe.run(&point, args.strategy, quadrature, &ps);
    if let Some(out) = &args.output {
        let pic = probe.picture(&report, Layers::default());
        write_png_rgba(out, pic.width as u32, pic.height as u32, pic.rgba)?;
    }
    let table = args.table.then(|| probe.table(&point, &quadrature, args.samples.min(200_000), args.seed));
    if args.json {
        println!("{}", serde_json::to_string_pretty(&ProbeJson::new(&scene, &report, table))?);
        return Ok(());
    }
    let r = &report.run;
    let truth = luminance(quadrature.value) as f64;
    let (lo, hi) = r.interval_95();
    let p = &point;
    println!(
        "{} pixel {},{}: p = {:.4} n = {:.4} ω_o = {:.4} material {}",
        scene.name,
        p.pixel.0,
        p.pixel.1,
        scene.origin + p.position.as_dvec3(), // in the scene files' coordinates
        p.normal,
        p.wo,
        p.material
    );
    println!(
        "strategy {}: {} samples, {:.3} M samples/s (one thread)",
        args.strategy.name(),
        r.samples,
        1e-6 / r.seconds_per_sample()
    );
    println!(
        "estimate   {:.6} (RGB {:.6}) ± {:.6} standard error; 95% interval [{lo:.6}, {hi:.6}]",
        r.mean_luminance(),
        r.mean(),
        r.luminance_std_error()
    );
    println!(
        "quadrature {truth:.6} (RGB {:.6}, {} evaluations{}); z = {:.2}",
        quadrature.value,
        quadrature.nodes,
        if quadrature.budget_reached { ", budget reached" } else { "" },
        r.z_score(truth)
    );
    println!("relative variance of one sample σ²/μ² = {:.4}", r.relative_variance(truth));
    if let Some(guide) = probe.guide() {
        let leaf = guide.stree.leaf(p.position) as usize;
        let [g, l, b] = guide.weights[leaf];
        let d = &guide.dtrees[leaf];
        let plane = match d.anchor() {
            Some(a) => format!(
                "learned through the plane n·q = {:.3} (n = {:.3}), seen from {:.3}",
                a.normal.as_dvec3().dot(scene.origin + a.centre.as_dvec3()) + a.height as f64,
                a.normal,
                scene.origin + a.centre.as_dvec3()
            ),
            None => "learned as directions at the shading points".to_string(),
        };
        let nodes = d.shape().nodes();
        println!(
            "guide here: spatial leaf {leaf}, {nodes} quadtree nodes, weights (guide, light, BRDF) ({g:.2}, {l:.2}, {b:.2})"
        );
        println!("            {plane}");
    }
    let zeros: Vec<String> = r.zero_counts().map(|(o, n)| format!("{} {n}", o.name())).collect();
    println!("zero directions: {}; non-finite samples: {}", zeros.join(", "), r.non_finite);
    if let Some(c) = &report.chi2 {
        let verdict = if c.p_value >= chi2::level(1) { "pass" } else { "FAIL" };
        println!(
            "chi-square ({}, {} draws): {:.1} on {} dof, p = {:.4} ({verdict} at 1%), ∫p dω = {:.5}",
            c.binning, c.samples, c.statistic, c.dof, c.p_value, c.integral
        );
    }
    if let Some(rows) = table {
        println!("{:<22} {:>14} {:>14} {:>14} {:>8}", "strategy", "σ²/μ²", "samples/s", "1/(σ²t)", "z");
        for row in rows {
            println!(
                "{:<22} {:>14.4} {:>14.0} {:>14.1} {:>8.2}",
                row.strategy, row.relative_variance, row.samples_per_second, row.efficiency, row.z
            );
        }
    }
    if let Some(out) = &args.output {
        println!("picture -> {}", out.display());
    }
    Ok(())
}
