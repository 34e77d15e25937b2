//! The convergence plot as a PNG (plotters, bitmap backend): RMSE against samples per pixel and against seconds,
//! log–log, one line per estimator, with a 1/√N slope for orientation and the reference's noise floor.
//! Text uses egui's embedded Ubuntu font, so no system font is needed.

use super::{Metric, Series};
use crate::render::{OutputError, write_png_rgba};
use plotters::prelude::*;
use std::path::Path;

const WIDTH: u32 = 1200;
const HEIGHT: u32 = 480;

/// Draws the plot into RGBA pixels (`WIDTH`×`HEIGHT`): the square root of `metric` (RMSE, or relative RMSE
/// `sqrt(relMSE)`); `floor` is the reference's own value of it (0: not drawn); `time_axis` names the seconds
/// (wall-clock, CPU).
pub fn convergence_rgba(
    title: &str,
    series: &[Series],
    floor: f64,
    metric: Metric,
    time_axis: &str,
) -> Result<(u32, u32, Vec<u8>), String> {
    register_font();
    let mut rgb = vec![255u8; (WIDTH * HEIGHT * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let root = root.titled(title, ("sans-serif", 22)).map_err(|e| e.to_string())?;
        let (left, right) = root.split_horizontally(WIDTH / 2);
        panel(&left, series, floor, metric, "samples per pixel", |p| p.spp as f64)?;
        panel(&right, series, floor, metric, time_axis, |p| p.seconds)?;
        root.present().map_err(|e| e.to_string())?;
    }
    let rgba = rgb.chunks_exact(3).flat_map(|c| [c[0], c[1], c[2], 255]).collect();
    Ok((WIDTH, HEIGHT, rgba))
}

/// Writes the plot as a PNG, atomically.
pub fn write_convergence_png(
    path: &Path,
    title: &str,
    series: &[Series],
    floor: f64,
    metric: Metric,
    time_axis: &str,
) -> Result<(), OutputError> {
    let (w, h, rgba) = convergence_rgba(title, series, floor, metric, time_axis)
        .map_err(|e| OutputError::Write(path.to_path_buf(), e))?;
    write_png_rgba(path, w, h, rgba)
}

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    series: &[Series],
    floor: f64,
    metric: Metric,
    x_desc: &str,
    x_of: impl Fn(&super::ConvergencePoint) -> f64,
) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let points: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.points.iter())
        .map(|p| (x_of(p), y_of(metric, p)))
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .collect();
    let bounds = |v: &mut dyn Iterator<Item = f64>| v.fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
    let (x0, x1) = if points.is_empty() { (1.0, 10.0) } else { bounds(&mut points.iter().map(|p| p.0)) };
    let (mut y0, y1) = if points.is_empty() { (0.1, 1.0) } else { bounds(&mut points.iter().map(|p| p.1)) };
    if floor > 0.0 {
        y0 = y0.min(floor);
    }
    let (x0, x1, y0, y1) = (x0 / 1.5, x1 * 1.5, y0 / 1.5, y1 * 1.5);
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(64)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(match metric {
            Metric::Mse => "RMSE vs reference",
            Metric::RelMse => "relative RMSE vs reference",
        })
        .x_label_formatter(&|v| short(*v))
        .y_label_formatter(&|v| short(*v))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    for (i, s) in series.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let line: Vec<(f64, f64)> =
            s.points.iter().map(|p| (x_of(p), y_of(metric, p))).filter(|(x, y)| *x > 0.0 && *y > 0.0).collect();
        chart
            .draw_series(LineSeries::new(line.clone(), color.stroke_width(2)))
            .map_err(err)?
            .label(s.label.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
        chart.draw_series(line.into_iter().map(|p| Circle::new(p, 3, color.filled()))).map_err(err)?;
    }
    // A slope of −½ through the geometric middle of the data: parallel lines converge at the same rate.
    if !points.is_empty() {
        let (gx, gy) = geometric_mean(&points);
        let guide = [x0, x1].map(|x| (x, gy * (x / gx).powf(-0.5)));
        chart
            .draw_series(DashedLineSeries::new(guide, 6, 4, RGBColor(120, 120, 120).stroke_width(1)))
            .map_err(err)?
            .label("slope -1/2 (1/sqrt N)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RGBColor(120, 120, 120)));
    }
    if floor > 0.0 {
        chart
            .draw_series(DottedLineSeries::new([(x0, floor), (x1, floor)], 3, 3, |c| Circle::new(c, 1, BLACK.filled())))
            .map_err(err)?
            .label("reference noise")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.85))
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    Ok(())
}

fn y_of(metric: Metric, p: &super::ConvergencePoint) -> f64 {
    match metric {
        Metric::Mse => p.mse.sqrt(),
        Metric::RelMse => p.rel_mse.sqrt(),
    }
}

fn geometric_mean(points: &[(f64, f64)]) -> (f64, f64) {
    let n = points.len() as f64;
    let (sx, sy) = points.iter().fold((0.0, 0.0), |(a, b), p| (a + p.0.ln(), b + p.1.ln()));
    ((sx / n).exp(), (sy / n).exp())
}

/// Axis numbers: short, scientific when far from 1.
fn short(v: f64) -> String {
    if (1e-2..1e4).contains(&v.abs()) { format!("{}", (v * 1000.0).round() / 1000.0) } else { format!("{v:.0e}") }
}

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::ConvergencePoint;

    #[test]
    fn draws_lines_in_colour_and_writes_a_png() {
        let mut a = Series::new("emitter");
        let mut b = Series::new("cosine");
        for spp in [1u32, 4, 16, 64] {
            let n = spp as f64;
            a.push(ConvergencePoint { spp, seconds: n * 0.01, mse: 0.01 / n, rel_mse: 0.1 / n });
            b.push(ConvergencePoint { spp, seconds: n * 0.008, mse: 0.09 / n, rel_mse: 0.9 / n });
        }
        let (w, h, rgba) =
            convergence_rgba("test", &[a.clone(), b.clone()], 0.005, Metric::Mse, "seconds").expect("drawn");
        assert_eq!(rgba.len(), (w * h * 4) as usize);
        let coloured = rgba.chunks_exact(4).filter(|p| p[0].abs_diff(p[1]) > 60 || p[1].abs_diff(p[2]) > 60).count();
        assert!(coloured > 500, "series lines drawn: {coloured} coloured pixels");
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("plot.png");
        write_convergence_png(&path, "test", &[a, b], 0.0, Metric::RelMse, "seconds").expect("written");
        assert_eq!(image::image_dimensions(&path).expect("png"), (w, h));
    }
}
