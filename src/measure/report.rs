//! Bench results as files: CSV (one row per strategy and budget) and a markdown table with the machine named.

use super::{BenchReport, BenchRow, MeanInterval, Metric, Ratio};
use crate::render::Footprint;
use std::fmt::Write as _;
use std::path::Path;

/// What the run was, for the markdown heading.
pub struct BenchContext<'a> {
    pub scene: &'a str,
    pub width: u32,
    pub height: u32,
    /// How the reference came about, one line.
    pub reference: &'a str,
    pub machine: &'a str,
    pub footprint: Footprint,
}

/// Writes the rows as CSV.
pub fn write_csv(path: &Path, report: &BenchReport) -> Result<(), String> {
    let mut w = csv::Writer::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    for row in &report.rows {
        w.serialize(row).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    w.flush().map_err(|e| format!("{}: {e}", path.display()))
}

/// A value with its interval: `1.23e-3 [1.10e-3, 1.40e-3]`; an open end where unbounded.
fn with_interval(value: Option<f64>, lo: Option<f64>, hi: Option<f64>, bold: bool) -> String {
    let Some(v) = value else { return "—".into() };
    let end = |e: Option<f64>| e.filter(|e| e.is_finite()).map_or("∞".to_string(), |e| format!("{e:.2e}"));
    let lo = lo.filter(|l| l.is_finite()).map_or("–∞".to_string(), |l| format!("{l:.2e}"));
    let v = if bold { format!("**{v:.3e}**") } else { format!("{v:.3e}") };
    format!("{v} [{lo}, {}]", end(hi))
}

/// The verdict at the largest budget by one metric: the strategy with the highest efficiency against the
/// runner-up, declared the winner only when the 95% interval of their efficiency ratio excludes 1.
fn verdict(report: &BenchReport, metric: Metric) -> Option<String> {
    let last = report.intervals.first()?.len().checked_sub(1)?;
    let spp = report.series.first()?.points.last()?.spp;
    let k = if metric == Metric::Mse { 0 } else { 1 };
    // Per strategy: (label, MSE interval at the largest budget, seconds).
    let mut ranked: Vec<(&str, MeanInterval, f64)> = report
        .series
        .iter()
        .zip(&report.intervals)
        .filter_map(|(s, i)| Some((s.label.as_str(), i[last][k], s.points.last()?.seconds)))
        .filter(|(_, m, t)| m.mean > 0.0 && *t > 0.0)
        .collect();
    ranked.sort_by(|a, b| (a.1.mean * a.2).total_cmp(&(b.1.mean * b.2)));
    let by = metric.name();
    let (best, runner) = match ranked.as_slice() {
        [] => return None,
        [only] => return Some(format!("By {by} at {spp} spp: **{}** (the only one measured).", only.0)),
        [a, b, ..] => (a, b),
    };
    // E_A/E_B = (MSE_B t_B)/(MSE_A t_A); the times are means, nearly exact beside the MSEs' spread.
    let Some(r) = Ratio::of(&runner.1, &best.1) else {
        return Some(format!(
            "By {by} at {spp} spp: **{}** has the highest mean efficiency; one seed gives no interval, so no winner is declared.",
            best.0
        ));
    };
    let scale = runner.2 / best.2;
    let (ratio, lo, hi) = (r.ratio * scale, r.lo * scale, r.hi * scale);
    Some(if lo > 1.0 {
        format!(
            "By {by} at {spp} spp: **{}** is the most efficient, {ratio:.2}× {} (95%: {lo:.2}–{hi:.2}×).",
            best.0, runner.0
        )
    } else {
        format!(
            "By {by} at {spp} spp: no significant difference between **{}** and **{}** ({ratio:.2}×, 95%: {lo:.2}–{hi:.2}×).",
            best.0, runner.0
        )
    })
}

/// The markdown report: a heading with scene, size, reference, machine and what the error contains; one table
/// row per strategy and budget with means and 95% intervals over the seeds, the best mean at each budget in bold;
/// then the verdicts at the largest budget.
pub fn markdown(report: &BenchReport, ctx: &BenchContext) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "### {} at {}×{}\n", ctx.scene, ctx.width, ctx.height);
    let _ = writeln!(md, "Machine: {}. Reference: {}.", ctx.machine, ctx.reference);
    let seeds = report.rows.first().map_or(0, |r| r.seeds);
    let _ = writeln!(
        md,
        "Measured with {}; {} of {} pixels (those that see an emitter) left out; the reference's own noise \
         (RMSE {:.2e}) subtracted; means over {seeds} seed(s) with 95% intervals.",
        ctx.footprint.description(),
        report.excluded,
        report.pixels + report.excluded,
        report.reference_rmse,
    );
    let _ = writeln!(
        md,
        "\n| strategy | spp | seconds | M samples/s | RMSE | relMSE [95%] | 1/(MSE·s) [95%] | 1/(relMSE·s) [95%] |\n|---|---:|---:|---:|---:|---:|---:|---:|"
    );
    let best = |spp: u32, of: fn(&BenchRow) -> Option<f64>| {
        report.rows.iter().filter(|r| r.spp == spp).filter_map(of).fold(0.0f64, f64::max)
    };
    for row in &report.rows {
        let rel = with_interval(Some(row.rel_mse), Some(row.rel_mse_lo), Some(row.rel_mse_hi), false);
        let eff = with_interval(
            row.efficiency,
            row.efficiency_lo,
            row.efficiency_hi,
            row.efficiency.is_some_and(|e| e == best(row.spp, |r| r.efficiency)),
        );
        let rel_eff = with_interval(
            row.rel_efficiency,
            row.rel_efficiency_lo,
            row.rel_efficiency_hi,
            row.rel_efficiency.is_some_and(|e| e == best(row.spp, |r| r.rel_efficiency)),
        );
        let _ = writeln!(
            md,
            "| {} | {} | {:.3} | {:.2} | {:.3e} | {rel} | {eff} | {rel_eff} |",
            row.strategy,
            row.spp,
            row.seconds,
            row.samples_per_second / 1e6,
            row.rmse,
        );
    }
    md.push('\n');
    for metric in [Metric::Mse, Metric::RelMse] {
        if let Some(v) = verdict(report, metric) {
            let _ = writeln!(md, "{v}");
        }
    }
    if !report.census.is_empty() {
        let rates: Vec<String> =
            report.census.iter().map(|(s, c)| format!("{s} {:.1}%", 100.0 * c.success_rate())).collect();
        let _ = writeln!(md, "\nTraced directions (shadow and BRDF rays) that found light: {}.", rates.join(", "));
    }
    for (strategy, log) in &report.guides {
        let _ = writeln!(md, "\n{strategy}'s guide (first seed), per training iteration:");
        for r in log {
            let _ = writeln!(md, "- {r}");
        }
    }
    md
}

/// The machine, one line: CPU model and logical cores (from /proc/cpuinfo where available).
pub fn machine_description() -> String {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .filter(|m| !m.is_empty())
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    format!("{model}, {cores} threads")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::{BenchRow, ConvergencePoint, Series};

    /// Two strategies at 4 spp, from per-seed MSEs; `seconds` each.
    fn report(a: &[f64], b: &[f64], seconds: [f64; 2]) -> BenchReport {
        let names = ["cosine", "emitter"];
        let (mut rows, mut series, mut intervals) = (vec![], vec![], vec![]);
        for (k, values) in [a, b].into_iter().enumerate() {
            let m = MeanInterval::of(values);
            let t = seconds[k];
            rows.push(BenchRow {
                strategy: names[k].into(),
                spp: 4,
                seeds: values.len() as u32,
                seconds: t,
                samples_per_second: 1e6,
                rmse: m.mean.sqrt(),
                mse: m.mean,
                mse_lo: m.lo(),
                mse_hi: m.hi(),
                rel_mse: m.mean,
                rel_mse_lo: m.lo(),
                rel_mse_hi: m.hi(),
                efficiency: Some(1.0 / (m.mean * t)),
                efficiency_lo: Some(1.0 / (m.hi() * t)),
                efficiency_hi: (m.lo() > 0.0).then(|| 1.0 / (m.lo() * t)),
                rel_efficiency: Some(1.0 / (m.mean * t)),
                rel_efficiency_lo: Some(1.0 / (m.hi() * t)),
                rel_efficiency_hi: (m.lo() > 0.0).then(|| 1.0 / (m.lo() * t)),
                non_finite_dropped: 0,
            });
            let mut s = Series::new(names[k]);
            s.push(ConvergencePoint { spp: 4, seconds: t, mse: m.mean, rel_mse: m.mean });
            series.push(s);
            intervals.push(vec![[m, m]]);
        }
        let (census, guides) = (Vec::new(), Vec::new());
        BenchReport { rows, intervals, series, reference_rmse: 1e-3, pixels: 90, excluded: 10, census, guides }
    }

    fn ctx() -> BenchContext<'static> {
        BenchContext { scene: "s", width: 10, height: 10, reference: "r", machine: "m", footprint: Footprint::Centre }
    }

    #[test]
    fn markdown_names_the_machine_and_what_the_error_contains() {
        let md = markdown(&report(&[0.04, 0.05, 0.03], &[0.01, 0.011, 0.009], [1.0, 1.0]), &ctx());
        assert!(md.contains("Machine: m"), "{md}");
        assert!(md.contains("fixed primary hits"), "{md}");
        assert!(md.contains("10 of 100 pixels"), "{md}");
        assert!(md.contains("means over 3 seed(s) with 95% intervals"), "{md}");
        assert!(
            md.contains("| emitter | 4 | 1.000 | 1.00 | 1.000e-1 | 1.000e-2 [7.52e-3, 1.25e-2] | **1.000e2**"),
            "{md}"
        );
    }

    #[test]
    fn a_winner_only_where_the_intervals_separate() {
        let md = markdown(&report(&[0.04, 0.05, 0.03], &[0.01, 0.011, 0.009], [1.0, 1.0]), &ctx());
        assert!(md.contains("By MSE at 4 spp: **emitter** is the most efficient, 4.00× cosine"), "{md}");
        let md = markdown(&report(&[0.010, 0.013, 0.008], &[0.01, 0.011, 0.009], [1.0, 1.0]), &ctx());
        assert!(md.contains("By MSE at 4 spp: no significant difference between **emitter** and **cosine**"), "{md}");
        // Time counts: a strategy with 4× the MSE in a fifth of the time is the more efficient.
        let md = markdown(&report(&[0.04, 0.05, 0.03], &[0.01, 0.011, 0.009], [0.2, 1.0]), &ctx());
        assert!(md.contains("**cosine** and **emitter** (1.25×"), "{md}");
        let md = markdown(&report(&[0.04], &[0.01], [1.0, 1.0]), &ctx());
        assert!(md.contains("one seed gives no interval, so no winner is declared"), "{md}");
    }

    #[test]
    fn csv_has_a_header_and_a_row_per_budget() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("b.csv");
        write_csv(&path, &report(&[0.04, 0.05], &[0.01, 0.02], [1.0, 2.0])).expect("written");
        let text = std::fs::read_to_string(&path).expect("read");
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3);
        assert!(lines[0].starts_with("strategy,spp,seeds,seconds,samples_per_second,rmse,mse,mse_lo,mse_hi"), "{text}");
        assert!(lines[2].starts_with("emitter,4,2,2.0,"), "{text}");
    }
}
