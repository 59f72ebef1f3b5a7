//! The pictures (feature `pictures`): the drawing code of every chart glossmeter draws, for any plotters
//! backend, and [`to_svg`], which draws one into an SVG document in memory. The command line writes them to
//! PNG or SVG files (`cli::plot`), the server answers with the SVG (docs/serve.md). The charts:
//! * the convergence chart of `glossmeter convergence --plot` ([`draw_sweep`], here): a log–log chart of the
//!   actual error, solid line and filled points, and the estimated error, dashed, against the time per reading;
//! * the in-plane BRDF section, readings against a recipe number and `compare`'s residuals ([`charts`]);
//! * the goniophotometric profile ([`profile`]);
//! * a measured topography's height map and radial PSD ([`topography`]).
//!
//! Fonts: a clean CI machine may have no system fonts, so the text is drawn with DejaVu Sans embedded in the
//! binary (`assets/fonts/`, Bitstream Vera licence with public-domain DejaVu changes: `assets/fonts/LICENSE`)
//! through plotters' `ab_glyph` renderer, which reads no system font at all; the same metrics lay out the SVG.
//!
//! An error of exactly 0, or below the floor of the chart, cannot be drawn on a log axis: it is drawn at
//! the floor as a hollow point, and the caption under the chart says so and gives the floor.
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::instrument::convergence::Sweep;
use crate::{Error, Result};

pub(crate) mod charts;
pub(crate) mod profile;
pub(crate) mod topography;

/// What was drawn, for messages.
#[derive(Clone, Debug, PartialEq)]
pub struct PlotSummary {
    pub series: usize,
    /// The floor under which errors are drawn at the floor.
    pub floor: f64,
    /// How many actual (estimated) errors were drawn at the floor.
    pub clamped_actual: usize,
    pub clamped_estimated: usize,
    /// Rows left out because the reading had no value.
    pub skipped: usize,
}

/// Register the embedded font once (plotters' `ab_glyph` text renderer has no font until one is registered).
pub(crate) fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The font is embedded and known to be valid; an error here would only lose the text.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            include_bytes!("../../../assets/fonts/DejaVuSans.ttf"),
        );
    });
}

pub(crate) fn plot_err(e: impl std::fmt::Display) -> Error {
    Error::Numeric(format!("plotting failed: {e}"))
}

/// The legend of every chart the command line draws: the series labels in a framed, slightly transparent box
/// in a corner, in a sans-serif font of `size` px.
pub(crate) fn draw_legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    size: u32,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", size))
        .draw()
        .map_err(plot_err)
}

/// The mark of a legend entry drawn beside a chart ([`draw_side_legend`]).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Mark {
    Line(RGBAColor),
    Box(RGBAColor),
    Dot(RGBAColor),
}

/// A legend beside the chart, in its own drawing area, so that it never covers the data: one entry per line
/// (long texts wrapped at words), a mark then the text, in a sans-serif font of `size` px.
pub(crate) fn draw_side_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    entries: &[(Mark, String)],
    size: u32,
) -> Result<()> {
    let (w, _) = area.dim_in_pixel();
    let chars = ((w as f64 - 40.0) / (0.55 * size as f64)).max(10.0) as usize;
    let font = ("sans-serif", size).into_font();
    let line = size as i32 + 5;
    let mut y = 30;
    for l in wrap(title, chars + 3) {
        area.draw(&Text::new(l, (8, y), font.clone().style(FontStyle::Bold))).map_err(plot_err)?;
        y += line;
    }
    y += 4;
    for (mark, text) in entries {
        let c = y + size as i32 / 2;
        match *mark {
            Mark::Line(col) => area.draw(&PathElement::new(vec![(8, c), (26, c)], col.stroke_width(3))),
            Mark::Box(col) => area.draw(&Rectangle::new([(8, c - 6), (26, c + 6)], col.filled())),
            Mark::Dot(col) => area.draw(&Circle::new((17, c), 5, col.filled())),
        }
        .map_err(plot_err)?;
        for l in wrap(text, chars) {
            area.draw(&Text::new(l, (32, y), font.clone())).map_err(plot_err)?;
            y += line;
        }
        y += 3;
    }
    Ok(())
}

/// Words wrapped into lines of at most `width` characters (a longer word stands alone).
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = vec![];
    let mut cur = String::new();
    for word in text.split_whitespace() {
        if !cur.is_empty() && cur.chars().count() + 1 + word.chars().count() > width {
            lines.push(std::mem::take(&mut cur));
        }
        if !cur.is_empty() {
            cur.push(' ');
        }
        cur.push_str(word);
    }
    if !cur.is_empty() || lines.is_empty() {
        lines.push(cur);
    }
    lines
}

/// A tick label with two significant digits: plain from 10⁻³ to 10⁴, else `3.2e-5`.
pub(crate) fn tick(y: f64) -> String {
    if y == 0.0 || !y.is_finite() {
        return "0".into();
    }
    let r: f64 = format!("{y:.1e}").parse().unwrap_or(y);
    if (1e-3..1e4).contains(&r.abs()) {
        format!("{r}")
    } else {
        format!("{r:.1e}").replace(".0e", "e")
    }
}

/// One series: (time, actual error, estimated error) per tolerance, loose to tight.
struct Series {
    label: String,
    points: Vec<(f64, f64, f64)>,
}

/// Draw the sweep on `root` (1000 × 720). `title` goes on top of the chart.
pub(crate) fn draw_sweep<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    sweep: &Sweep,
    title: &str,
) -> Result<PlotSummary>
where
    DB::ErrorType: 'static,
{
    let mut series: Vec<Series> = Vec::new();
    let mut skipped = 0;
    let mut scale: f64 = 0.0;
    for r in &sweep.rows {
        let (Some(v), Some(a), Some(e)) = (r.value, r.actual_error, r.error_estimate) else {
            skipped += 1;
            continue;
        };
        scale = scale.max(v.abs()).max(r.reference.unwrap_or(0.0).abs());
        let label = format!("{} {}", r.geometry, r.reading);
        let t = r.seconds.max(1e-9);
        match series.iter_mut().find(|s| s.label == label) {
            Some(s) => s.points.push((t, a, e)),
            None => series.push(Series { label, points: vec![(t, a, e)] }),
        }
    }
    if series.is_empty() {
        return Err(Error::Numeric("nothing to plot: no reading of the sweep has a value and an actual error".into()));
    }
    // The floor: 1e-16 of the largest value (the relative rounding level of a double).
    let floor = if scale > 0.0 { 1e-16 * scale } else { 1e-300 };
    let clamp = |x: f64| x.max(floor);
    let mut clamped_actual = 0;
    let mut clamped_estimated = 0;
    let (mut tmin, mut tmax, mut emax) = (f64::INFINITY, 0.0f64, floor);
    for s in &series {
        for &(t, a, e) in &s.points {
            tmin = tmin.min(t);
            tmax = tmax.max(t);
            emax = emax.max(a).max(e);
            clamped_actual += usize::from(a < floor);
            clamped_estimated += usize::from(e < floor);
        }
    }
    // The reference's own error estimate (tight-run references only): actual errors below it are not
    // resolved; drawn as a grey dotted line.
    let ref_err = sweep.rows.iter().filter_map(|r| r.reference_error).fold(0.0f64, f64::max);
    let emin = series
        .iter()
        .flat_map(|s| s.points.iter().flat_map(|&(_, a, e)| [clamp(a), clamp(e)]))
        .chain((ref_err > 0.0).then_some(clamp(ref_err)))
        .fold(f64::INFINITY, f64::min);
    let emax = emax.max(ref_err);
    let x_range = (tmin / 2.0)..(tmax * 2.0);
    let y_range = (emin / 3.0)..(emax * 3.0);

    {
        root.fill(&WHITE).map_err(plot_err)?;
        let (chart_area, caption_area) = root.split_vertically(660);
        let mut chart = ChartBuilder::on(&chart_area)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(75)
            .build_cartesian_2d(x_range.log_scale(), y_range.log_scale())
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("time per reading (s), minimum over repeated runs")
            .y_desc("error (reading units)")
            .x_label_formatter(&|x| format!("{x:.0e}"))
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .draw()
            .map_err(plot_err)?;
        for (i, s) in series.iter().enumerate() {
            let colour = Palette99::pick(i).to_rgba();
            let actual: Vec<(f64, f64)> = s.points.iter().map(|&(t, a, _)| (t, clamp(a))).collect();
            let estimated: Vec<(f64, f64)> = s.points.iter().map(|&(t, _, e)| (t, clamp(e))).collect();
            chart
                .draw_series(LineSeries::new(actual.clone(), colour.stroke_width(2)))
                .map_err(plot_err)?
                .label(format!("{}: actual error", s.label))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
            chart
                .draw_series(s.points.iter().map(|&(t, a, _)| {
                    let filled = a >= floor;
                    Circle::new((t, clamp(a)), 4, if filled { colour.filled() } else { colour.stroke_width(1) })
                }))
                .map_err(plot_err)?;
            chart
                .draw_series(DashedLineSeries::new(estimated.clone(), 6, 4, colour.stroke_width(1)))
                .map_err(plot_err)?
                .label(format!("{}: estimated error (dashed)", s.label))
                .legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (6, 0)], colour.stroke_width(1))
                        + PathElement::new(vec![(10, 0), (16, 0)], colour.stroke_width(1))
                });
            chart.draw_series(estimated.iter().map(|&p| Cross::new(p, 3, colour.stroke_width(1)))).map_err(plot_err)?;
        }
        if ref_err > 0.0 {
            let grey = RGBColor(110, 110, 110);
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(tmin / 2.0, clamp(ref_err)), (tmax * 2.0, clamp(ref_err))],
                    2,
                    4,
                    grey.stroke_width(1),
                ))
                .map_err(plot_err)?
                .label(format!("largest error estimate of the reference run ({ref_err:.1e}): actual errors below it are not resolved"))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], grey.stroke_width(1)));
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight, 12)?;
        let mut lines = vec![format!(
            "Reference: {}. Points from loose to tight tolerance ({}); solid = actual error |value − reference|, dashed = the engine's estimate.",
            sweep.reference.label(),
            tolerance_span(&sweep.tolerances)
        )];
        lines.push(format!(
            "Errors of exactly 0 or below {floor:.1e} (1e-16 of the largest value) are drawn at {floor:.1e} as hollow points: {clamped_actual} actual, {clamped_estimated} estimated."
        ));
        if skipped > 0 {
            lines.push(format!("{skipped} row(s) without a value or an actual error are not drawn."));
        }
        for (k, l) in lines.iter().enumerate() {
            caption_area
                .draw(&Text::new(l.clone(), (15, 8 + 18 * k as i32), ("sans-serif", 13).into_font().color(&BLACK)))
                .map_err(plot_err)?;
        }
        root.present().map_err(plot_err)?;
    }
    Ok(PlotSummary { series: series.len(), floor, clamped_actual, clamped_estimated, skipped })
}

fn tolerance_span(t: &[f64]) -> String {
    match (t.first(), t.last()) {
        (Some(a), Some(b)) if t.len() > 1 => format!("rtol {a:e} … {b:e}"),
        (Some(a), _) => format!("rtol {a:e}"),
        _ => String::new(),
    }
}

/// Draw with `draw` into an SVG document of `size` pixels held in memory (the server's pictures,
/// docs/serve.md): the same drawing code and embedded font as the files `render_plot!` writes.
pub(crate) fn to_svg<T>(
    size: (u32, u32),
    draw: impl FnOnce(DrawingArea<SVGBackend<'_>, Shift>) -> Result<T>,
) -> Result<String> {
    register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw(root)?;
    }
    Ok(svg)
}
