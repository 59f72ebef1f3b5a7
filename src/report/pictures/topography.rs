//! The picture of a topography (`topography --plot`): the levelled height map in false colour beside its
//! radial PSD on logarithmic axes (docs/topography.md).
use plotters::coord::Shift;
use plotters::prelude::*;

use super::plot_err;
use crate::report::topography::TopographyDoc;
use crate::topography::analysis::Analysis;
use crate::topography::map::HeightMap;
use crate::Result;

/// The most cells drawn along each side of the height map (the map is averaged in blocks down to them).
pub(crate) const MAX_CELLS: usize = 128;

/// A colour for t in [0, 1]: dark blue through cyan and yellow to dark red.
fn ramp(t: f64) -> RGBColor {
    let stops = [
        (0.0, (48, 18, 140)),
        (0.3, (30, 150, 220)),
        (0.5, (90, 200, 120)),
        (0.7, (240, 210, 60)),
        (1.0, (150, 20, 20)),
    ];
    let t = t.clamp(0.0, 1.0);
    let k = stops.iter().position(|s| s.0 >= t).unwrap_or(stops.len() - 1).max(1);
    let ((a, ca), (b, cb)) = (stops[k - 1], stops[k]);
    let f = if b > a { (t - a) / (b - a) } else { 0.0 };
    let mix = |x: u8, y: u8| (x as f64 + (y as f64 - x as f64) * f).round() as u8;
    RGBColor(mix(ca.0, cb.0), mix(ca.1, cb.1), mix(ca.2, cb.2))
}

/// Draw the height map (µm, block means over the valid points; invalid blocks grey) and the radial PSD.
pub(crate) fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    map: &HeightMap,
    a: &Analysis,
    doc: &TopographyDoc,
    title: &str,
) -> Result<()> {
    root.fill(&WHITE).map_err(plot_err)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(plot_err)?;
    let (left, right) = root.split_horizontally(root.dim_in_pixel().0 / 2);
    // The height map, averaged in blocks.
    let block = map.nx.max(map.ny).div_ceil(MAX_CELLS).max(1);
    let (bx, by) = (map.nx.div_ceil(block), map.ny.div_ceil(block));
    let mut cells = vec![f64::NAN; bx * by];
    for (cj, row) in cells.chunks_mut(bx).enumerate() {
        for (ci, cell) in row.iter_mut().enumerate() {
            let (mut s, mut n) = (0.0, 0usize);
            for j in cj * block..((cj + 1) * block).min(map.ny) {
                for i in ci * block..((ci + 1) * block).min(map.nx) {
                    let z = a.levelled[j * map.nx + i];
                    if !z.is_nan() {
                        s += z;
                        n += 1;
                    }
                }
            }
            if n > 0 {
                *cell = s / n as f64 * 1e6;
            }
        }
    }
    let (lo, hi) = cells
        .iter()
        .filter(|v| !v.is_nan())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let span = if hi > lo { hi - lo } else { 1.0 };
    let (w, h) = (map.nx as f64 * map.dx * 1e6, map.ny as f64 * map.dy * 1e6);
    let mut chart = ChartBuilder::on(&left)
        .caption(format!("levelled heights, {lo:.3} … {hi:.3} µm (Sq {:.4} µm)", doc.heights.sq_um), ("sans-serif", 16))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(0.0..w, 0.0..h)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("x (µm)")
        .y_desc("y (µm)")
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(plot_err)?;
    let (cw, ch) = (block as f64 * map.dx * 1e6, block as f64 * map.dy * 1e6);
    chart
        .draw_series(cells.iter().enumerate().map(|(k, &v)| {
            let (ci, cj) = ((k % bx) as f64, (k / bx) as f64);
            let colour = if v.is_nan() { RGBColor(200, 200, 200) } else { ramp((v - lo) / span) };
            Rectangle::new([(ci * cw, cj * ch), (((ci + 1.0) * cw).min(w), ((cj + 1.0) * ch).min(h))], colour.filled())
        }))
        .map_err(plot_err)?;
    // The radial PSD (positive frequencies and values only).
    let pts: Vec<(f64, f64)> = doc
        .psd
        .radial
        .iter()
        .filter(|b| b.frequency_per_um > 0.0 && b.psd_nm2_um2 > 0.0)
        .map(|b| (b.frequency_per_um, b.psd_nm2_um2))
        .collect();
    let range =
        |v: &mut dyn Iterator<Item = f64>| v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    let (f0, f1) = range(&mut pts.iter().map(|p| p.0));
    let (s0, s1) = range(&mut pts.iter().map(|p| p.1));
    let (f0, f1) = if f0 < f1 { (f0, f1) } else { (1e-3, 1.0) };
    let (s0, s1) = if s0 < s1 { (s0 / 2.0, s1 * 2.0) } else { (1e-3, 1.0) };
    let mut chart = ChartBuilder::on(&right)
        .caption("radial PSD (two-sided, Σ S Δf² = Sq²)", ("sans-serif", 16))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(64)
        .build_cartesian_2d((f0..f1).log_scale(), (s0..s1).log_scale())
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc("spatial frequency (1/µm)")
        .y_desc("PSD (nm²·µm²)")
        .x_label_formatter(&|v| format!("{v:.1e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(plot_err)?;
    chart.draw_series(LineSeries::new(pts, BLUE.stroke_width(2))).map_err(plot_err)?;
    root.present().map_err(plot_err)?;
    Ok(())
}
