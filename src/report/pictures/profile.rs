//! The goniophotometric profile's chart (`profile --plot`, the page): the normalised reading against the
//! angle, with its error estimates.
use plotters::coord::Shift;
use plotters::prelude::*;

use super::plot_err;
use crate::instrument::profile::Profile;
use crate::Result;

/// Draw the profile: reading (GU) against the angle from the specular direction, one point per pixel joined
/// by a line; pixels without a value are left out (the caption says how many).
pub(crate) fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, p: &Profile, title: &str) -> Result<()> {
    root.fill(&WHITE).map_err(plot_err)?;
    let pts: Vec<(f64, f64)> = p.rows.iter().filter_map(|r| r.reading.value.map(|v| (r.angle_deg, v))).collect();
    let missing = p.rows.len() - pts.len();
    let (x0, x1) =
        p.rows.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| (a.min(r.angle_deg), b.max(r.angle_deg)));
    let (x0, x1) = if x0 < x1 { (x0, x1) } else { (x0 - 1.0, x0 + 1.0) };
    let ymax = pts.iter().map(|(_, v)| *v).fold(0.0, f64::max);
    let ymin = pts.iter().map(|(_, v)| *v).fold(0.0, f64::min);
    let ymax = if ymax > ymin { ymax * 1.05 } else { ymin + 1.0 };
    let caption = if missing > 0 { format!(" ({missing} pixels without a value left out)") } else { String::new() };
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{title}{caption}"), ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(x0..x1, ymin..ymax)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc("angle from the specular direction (°)")
        .y_desc("reading (GU, standard = 100)")
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(plot_err)?;
    chart.draw_series(LineSeries::new(pts.iter().copied(), BLUE.stroke_width(2))).map_err(plot_err)?;
    root.present().map_err(plot_err)?;
    Ok(())
}

/// The profile's picture as an SVG document in memory (the server's `/api/plot`).
pub fn svg(p: &Profile, title: &str) -> Result<String> {
    super::to_svg((1000, 640), |root| draw(root, p, title))
}
