//! The frontier plot: image error against frame time, every candidate a point, the
//! frontier a line, the effect as authored and the choice marked.

use plotters::prelude::*;

use super::report::TuneReport;

/// The plot as SVG text.
pub fn frontier_svg(report: &TuneReport) -> String {
    let mut svg = String::new();
    if let Err(e) = draw(report, &mut svg) {
        log::warn!("the frontier plot failed: {e}");
    }
    svg
}

/// Errors below this are drawn at it (the plot's error axis is logarithmic).
const FLOOR: f64 = 1e-3;

fn draw<'a>(r: &TuneReport, out: &'a mut String) -> Result<(), Box<dyn std::error::Error + 'a>> {
    let root = SVGBackend::with_string(out, (960, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let pts: Vec<(f64, f64)> = r
        .results
        .iter()
        .map(|m| (m.frame_ms.max(1e-6), m.error.mean.max(FLOOR)))
        .collect();
    let (x0, x1) = pts
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (y0, y1) = pts
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "{}: image error against frame time ({})",
                r.effect, r.adapter
            ),
            ("sans-serif", 18),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(
            (x0 * 0.9..x1 * 1.1).log_scale(),
            (y0 * 0.7..y1 * 1.5).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc("frame time, ms")
        .y_desc("mean error, 8-bit levels")
        .draw()?;
    let grey = RGBColor(150, 150, 150);
    chart
        .draw_series(pts.iter().map(|&p| Circle::new(p, 3, grey.filled())))?
        .label("candidates")
        .legend(move |(x, y)| Circle::new((x + 8, y), 3, grey.filled()));
    let front: Vec<(f64, f64)> = r.frontier.iter().map(|&i| pts[i]).collect();
    let blue = RGBColor(30, 90, 200);
    chart
        .draw_series(LineSeries::new(front.clone(), blue.stroke_width(2)))?
        .label("frontier")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], blue));
    chart.draw_series(front.iter().map(|&p| Circle::new(p, 4, blue.filled())))?;
    let marks = [
        (Some(r.authored), "as authored", BLACK),
        (r.chosen, "chosen", RED),
    ];
    for (i, name, color) in marks {
        let Some(p) = i.map(|i| pts[i]) else {
            continue;
        };
        chart
            .draw_series([Circle::new(p, 8, color.stroke_width(2))])?
            .label(name)
            .legend(move |(x, y)| Circle::new((x + 8, y), 6, color.stroke_width(2)));
    }
    legend_and_present(&mut chart, &root)?;
    Ok(())
}

/// The charts' log-log axes.
pub(crate) type LogLog = Cartesian2d<LogCoord<f64>, LogCoord<f64>>;

/// Draws the legend (white box, black border) of a log-log SVG chart and finishes the
/// image.
pub(crate) fn legend_and_present<'a, 'b: 'a>(
    chart: &mut ChartContext<'a, SVGBackend<'b>, LogLog>,
    root: &DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
) -> Result<(), DrawingAreaErrorKind<std::io::Error>> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()
}
