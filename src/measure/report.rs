//! Bench results as files: CSV (one row per strategy and budget) and a markdown table with the machine named.

use super::{BenchReport, BenchRow, Metric, most_efficient};
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
}

/// Writes the rows as CSV.
pub fn write_csv(path: &Path, report: &BenchReport) -> Result<(), String> {
    let mut w = csv::Writer::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    for row in &report.rows {
        w.serialize(row).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    w.flush().map_err(|e| format!("{}: {e}", path.display()))
}

/// The markdown report: a heading with scene, size, reference and machine; one table row per strategy and budget
/// with both efficiencies, the best at each budget in bold; then the winners at the largest budget.
pub fn markdown(report: &BenchReport, ctx: &BenchContext) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "### {} at {}×{}\n", ctx.scene, ctx.width, ctx.height);
    let _ = writeln!(md, "Machine: {}. Reference: {}.", ctx.machine, ctx.reference);
    if report.reference_rmse > 0.0 {
        let _ = writeln!(md, "The reference's own RMSE (noise floor) is {:.2e}.", report.reference_rmse);
    }
    let _ = writeln!(
        md,
        "\n| strategy | spp | seconds | M samples/s | RMSE | relMSE | 1/(MSE·s) | 1/(relMSE·s) |\n|---|---:|---:|---:|---:|---:|---:|---:|"
    );
    let best = |spp: u32, of: fn(&BenchRow) -> Option<f64>| {
        report.rows.iter().filter(|r| r.spp == spp).filter_map(of).fold(0.0f64, f64::max)
    };
    let cell = |row: &BenchRow, of: fn(&BenchRow) -> Option<f64>| match of(row) {
        Some(e) if e == best(row.spp, of) => format!("**{e:.3e}**"),
        Some(e) => format!("{e:.3e}"),
        None => "—".into(),
    };
    for row in &report.rows {
        let _ = writeln!(
            md,
            "| {} | {} | {:.3} | {:.2} | {:.3e} | {:.3e} | {} | {} |",
            row.strategy,
            row.spp,
            row.seconds,
            row.samples_per_second / 1e6,
            row.rmse,
            row.rel_mse,
            cell(row, |r| r.efficiency),
            cell(row, |r| r.rel_efficiency),
        );
    }
    let winner = |metric: Metric| {
        let i = most_efficient(&report.series, metric)?;
        let s = &report.series[i];
        let e = s.last().and_then(|p| metric.efficiency(p))?;
        let runner_up = report
            .series
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .filter_map(|(_, t)| t.last().and_then(|p| metric.efficiency(p)))
            .fold(0.0f64, f64::max);
        let margin = if runner_up > 0.0 { format!(" ({:.2}× the runner-up)", e / runner_up) } else { String::new() };
        Some((s.last().map_or(0, |p| p.spp), format!("**{}**{margin}", s.label)))
    };
    if let (Some((spp, by_mse)), Some((_, by_rel))) = (winner(Metric::Mse), winner(Metric::RelMse)) {
        let _ = writeln!(md, "\nMost efficient at {spp} spp: {by_mse} by MSE, {by_rel} by relMSE.");
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

    fn report() -> BenchReport {
        let row = |strategy: &str, spp, seconds, rmse: f64, rel_mse: f64| BenchRow {
            strategy: strategy.into(),
            spp,
            seconds,
            samples_per_second: 1e6,
            rmse,
            rel_mse,
            efficiency: Some(1.0 / (rmse * rmse * seconds)),
            rel_efficiency: Some(1.0 / (rel_mse * seconds)),
            non_finite_dropped: 0,
        };
        let mut a = Series::new("cosine");
        a.push(ConvergencePoint { spp: 4, seconds: 1.0, mse: 0.04, rel_mse: 0.2 });
        let mut b = Series::new("emitter");
        b.push(ConvergencePoint { spp: 4, seconds: 2.0, mse: 0.01, rel_mse: 0.3 });
        let rows = vec![row("cosine", 4, 1.0, 0.2, 0.2), row("emitter", 4, 2.0, 0.1, 0.3)];
        BenchReport { rows, series: vec![a, b], reference_rmse: 1e-3 }
    }

    #[test]
    fn markdown_marks_the_winner_and_names_the_machine() {
        let ctx = BenchContext { scene: "s", width: 2, height: 2, reference: "r", machine: "m" };
        let md = markdown(&report(), &ctx);
        assert!(md.contains("Machine: m"), "{md}");
        assert!(md.contains("| emitter | 4 | 2.000 | 1.00 | 1.000e-1 | 3.000e-1 | **5.000e1** | 1.667e0 |"), "{md}");
        assert!(md.contains("| cosine | 4 | 1.000 | 1.00 | 2.000e-1 | 2.000e-1 | 2.500e1 | **5.000e0** |"), "{md}");
        let winners = "Most efficient at 4 spp: **emitter** (2.00× the runner-up) by MSE, **cosine** (3.00× the runner-up) by relMSE";
        assert!(md.contains(winners), "{md}");
    }

    #[test]
    fn csv_has_a_header_and_a_row_per_budget() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("b.csv");
        write_csv(&path, &report()).expect("written");
        let text = std::fs::read_to_string(&path).expect("read");
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3);
        assert!(lines[0].starts_with("strategy,spp,seconds,samples_per_second,rmse,rel_mse,efficiency"), "{text}");
        assert!(lines[2].starts_with("emitter,4,2.0,"), "{text}");
    }
}
