//! The charts of `glossmeter plot` and `compare --plot`, and of the page (docs/instrument.md §Pictures): the
//! in-plane BRDF section with the apertures ([`draw_sections`]), readings against one recipe number
//! ([`draw_vs_parameter`]) and `compare`'s residuals ([`draw_comparison`]). Only drawing lives here; the
//! numbers come from the library (`Brdf::eval`, the plan, the request's sweep, `compare`'s comparison).
use plotters::coord::Shift;
use plotters::prelude::*;
use serde_json::Value;

use super::{plot_err, Mark};
use crate::brdf::{mirror, Brdf};
use crate::colorimetry::weighting::Weighting;
use crate::instrument::standards::StandardGeometry;
use crate::{recipe, Error, Result, Vec3};

/// One panel of the section plot.
pub(crate) struct Section {
    id: String,
    angle: f64,
    /// (θo, f_r luminous) in degrees and sr⁻¹.
    curve: Vec<(f64, f64)>,
    /// The mirror image of the source stop, in plane (degrees).
    source_image: (f64, f64),
    /// Receptors in plane: name, from, to (degrees).
    receptors: Vec<(String, f64, f64)>,
    /// The mirror component's reflectance, if the model has one.
    delta: Option<f64>,
}

fn value(spec: &Value, pointer: &str) -> Option<f64> {
    spec.pointer(pointer).and_then(|v| v.get("value")).and_then(Value::as_f64)
}

/// The in-plane section of `brdf` through geometry `g`: the source at its nominal angle, the receptor swept
/// through the plane of incidence from 40° before to 40° past the specular direction (within ±89.5°).
pub(crate) fn section(brdf: &dyn Brdf, g: &StandardGeometry) -> Option<Section> {
    let spec = &g.spec;
    let angle = value(spec, "/angle_deg")?;
    let s_in = value(spec, "/source/in_plane_deg")?;
    let receptors: Vec<(String, f64, f64)> = spec
        .get("receptors")?
        .as_array()?
        .iter()
        .zip(&g.geometry.receptors)
        .filter_map(|(r, (_, stop))| {
            if r.get("shape").and_then(Value::as_str) == Some("pixels") {
                // A window of the profile array: its edges from the compiled stop (p = tan of the angle).
                let name = r.get("name").and_then(Value::as_str).unwrap_or("receptor").to_string();
                return Some((name, angle + stop.p[0].atan().to_degrees(), angle + stop.p[1].atan().to_degrees()));
            }
            let w = r.get("in_plane_deg")?.get("value")?.as_f64()?;
            let off = r.get("offset_deg").and_then(|o| o.get("value")).and_then(Value::as_f64).unwrap_or(0.0);
            let name = r.get("name").and_then(Value::as_str).unwrap_or("receptor").to_string();
            Some((name, angle + off - 0.5 * w, angle + off + 0.5 * w))
        })
        .collect();
    let t = angle.to_radians();
    let wi = Vec3::new(-t.sin(), 0.0, t.cos());
    let sampling = brdf.sampling();
    let lum = Weighting::luminous(sampling).ok()?;
    let mut out = vec![0.0; sampling.len()];
    let (lo, hi) = ((angle - 40.0).max(-89.5), (angle + 40.0).min(89.5));
    let n = 1601;
    let curve = (0..n)
        .map(|k| {
            let to = lo + (hi - lo) * k as f64 / (n - 1) as f64;
            let r = to.to_radians();
            brdf.eval(wi, Vec3::new(r.sin(), 0.0, r.cos()), &mut out);
            (to, lum.component(0, &out))
        })
        .collect();
    let mut d = vec![0.0; sampling.len()];
    let delta = brdf.delta_reflectance(wi, &mut d).then(|| lum.component(0, &d));
    let _ = mirror(wi);
    Some(Section {
        id: g.geometry.id.clone(),
        angle,
        curve,
        source_image: (angle - 0.5 * s_in, angle + 0.5 * s_in),
        receptors,
        delta,
    })
}

/// The log axis of a section panel (docs/instrument.md §Pictures): from half the smallest positive f_r of the
/// curve (but not below 10⁻⁸ of its largest, so a lobe's far tail does not spread the axis over 20 decades) to
/// twice the largest (10⁻³ to 1 when the regular part is 0 everywhere, a mirror). Values below the floor are
/// drawn at it. Within the normal finite numbers: a floor of 0 or an infinite top made
/// plotters' log scale loop for ever.
fn section_axis(p: &Section) -> (f64, f64) {
    let positive = p.curve.iter().map(|c| c.1).filter(|v| v.is_finite() && *v > 0.0);
    let (min, max) = positive.fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
    let (lo, hi) = if max > 0.0 { ((min * 0.5).max(max * 1e-8), max * 2.0) } else { (f64::INFINITY, 0.0) };
    if !(lo.is_finite() && hi > 0.0) {
        return (1e-3, 1.0);
    }
    let lo = lo.clamp(f64::MIN_POSITIVE, 1e300);
    let hi = hi.min(f64::MAX / 4.0).max(lo * 10.0);
    (lo, hi)
}

pub(crate) fn draw_sections<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    name: &str,
    panels: &[Section],
) -> Result<()> {
    root.fill(&WHITE).map_err(plot_err)?;
    let areas = root.split_evenly((panels.len(), 1));
    for (area, p) in areas.iter().zip(panels) {
        let (floor, top) = section_axis(p);
        let (chart_area, legend_area) = area.split_horizontally(680);
        let (x0, x1) = (p.curve[0].0, p.curve[p.curve.len() - 1].0);
        let mut chart = ChartBuilder::on(&chart_area)
            .caption(format!("in-plane section, {} (θi = {}°)", p.id, p.angle), ("sans-serif", 17))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, (floor..top).log_scale())
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("θo in the plane of incidence (°, + on the specular side)")
            .y_desc("f_r (1/sr, luminous)")
            .y_label_formatter(&|y| super::tick(*y))
            .draw()
            .map_err(plot_err)?;
        let blue = RGBColor(40, 90, 200);
        let orange = RGBColor(230, 140, 20);
        let mut legend: Vec<(Mark, String)> = vec![];
        for (i, (rname, a, b)) in p.receptors.iter().enumerate() {
            let c = Palette99::pick(i + 2).mix(0.22);
            chart
                .draw_series(std::iter::once(Rectangle::new([(*a, floor), (*b, top)], c.filled())))
                .map_err(plot_err)?;
            legend.push((Mark::Box(c), format!("receptor {rname}: {a:.2}° … {b:.2}°")));
        }
        let (a, b) = p.source_image;
        chart
            .draw_series(std::iter::once(Rectangle::new([(a, floor), (b, top)], orange.mix(0.55).filled())))
            .map_err(plot_err)?;
        legend.push((Mark::Box(orange.mix(0.55)), format!("mirror image of the source: {a:.2}° … {b:.2}°")));
        let clamped = p.curve.iter().filter(|c| c.1 < floor).count();
        let pts: Vec<(f64, f64)> = p.curve.iter().map(|&(x, y)| (x, y.max(floor).min(top))).collect();
        if p.curve.iter().any(|c| c.1 > 0.0) {
            chart.draw_series(LineSeries::new(pts, blue.stroke_width(2))).map_err(plot_err)?;
            legend.push((
                Mark::Line(blue.to_rgba()),
                if clamped > 0 {
                    format!("regular part of f_r ({clamped} of {} values below the axis drawn at it)", p.curve.len())
                } else {
                    "regular part of f_r".into()
                },
            ));
        } else {
            legend.push((Mark::Line(blue.to_rgba()), "regular part of f_r: 0 everywhere (not drawn)".into()));
        }
        if let Some(r) = p.delta {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(p.angle, floor), (p.angle, top)],
                    BLACK.stroke_width(2),
                )))
                .map_err(plot_err)?;
            legend.push((
                Mark::Line(BLACK.to_rgba()),
                format!("mirror (delta) component at the specular angle, reflectance R = {r:.4} (not on the f_r axis)"),
            ));
        }
        super::draw_side_legend(&legend_area, name, &legend, 13)?;
    }
    root.present().map_err(plot_err)?;
    Ok(())
}

/// The axis a reading is drawn on (docs/instrument.md §Pictures): one per unit (GU, HU, HU(log), DOI, the hue
/// angle's °), and colour's unitless coordinates on two of their own, CIELAB (L*, a*, b*, C*) and the
/// tristimulus values (X, Y, Z), never beside a unit's. `unit` and `name` are the reading's.
pub(crate) fn axis_of(unit: &str, name: &str) -> String {
    match (unit, name) {
        ("", "X" | "Y" | "Z") => "X, Y, Z".into(),
        ("", _) => "L*, a*, b*, C*".into(),
        (u, _) => u.into(),
    }
}

/// The axis of a series labelled `GEOMETRY READING (UNIT)` ([`axis_of`]).
fn series_axis(label: &str) -> String {
    let (head, unit) = match (label.rfind(" ("), label.strip_suffix(')')) {
        (Some(i), Some(_)) => (&label[..i], &label[i + 2..label.len() - 1]),
        _ => (label, ""),
    };
    axis_of(unit, head.split_once(' ').map_or(head, |(_, n)| n))
}

/// The axes of `keys` in order of first appearance, each with the indices that are drawn on it.
fn by_axis(keys: impl Iterator<Item = String>) -> Vec<(String, Vec<usize>)> {
    let mut out: Vec<(String, Vec<usize>)> = Vec::new();
    for (i, k) in keys.enumerate() {
        match out.iter_mut().find(|(a, _)| *a == k) {
            Some((_, v)) => v.push(i),
            None => out.push((k, vec![i])),
        }
    }
    out
}

/// The picture size of [`draw_vs_parameter`]: 1000 × 640, and 360 pixels a panel when the readings need more
/// than one axis.
pub(crate) fn vs_parameter_size(series: &[(String, Vec<(f64, f64)>)]) -> (u32, u32) {
    match by_axis(series.iter().map(|s| series_axis(&s.0))).len() {
        0 | 1 => (1000, 640),
        n => (1000, 360 * n as u32),
    }
}

/// Readings against the parameter, one chart per axis ([`axis_of`]: a unit, or colour's CIELAB or X, Y, Z)
/// stacked with the same x axis, so that GU, HU, DOI and colour never share a scale.
pub(crate) fn draw_vs_parameter<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    name: &str,
    label: &str,
    log: bool,
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<()> {
    let axes = by_axis(series.iter().map(|s| series_axis(&s.0)));
    if axes.len() <= 1 {
        return draw_vs_parameter_panel(root, name, label, log, series, None);
    }
    root.fill(&WHITE).map_err(plot_err)?;
    for (area, (axis, members)) in root.split_evenly((axes.len(), 1)).into_iter().zip(&axes) {
        let part: Vec<(String, Vec<(f64, f64)>)> = members.iter().map(|&i| series[i].clone()).collect();
        draw_vs_parameter_panel(area, name, label, log, &part, Some(axis))?;
    }
    root.present().map_err(plot_err)?;
    Ok(())
}

/// One chart of readings against the parameter: x on a log axis when the values are log-spaced (drawn as log10
/// x with the ticks labelled in x), the legend beside the chart; `axis` names the y axis of one panel of
/// several (None: the whole picture, named by the series' unit).
fn draw_vs_parameter_panel<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    name: &str,
    label: &str,
    log: bool,
    series: &[(String, Vec<(f64, f64)>)],
    axis: Option<&str>,
) -> Result<()> {
    root.fill(&WHITE).map_err(plot_err)?;
    let fx = |x: f64| if log { x.log10() } else { x };
    let xs = series.iter().flat_map(|s| s.1.iter().map(|p| fx(p.0)));
    let (x0, x1) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    let ys = series.iter().flat_map(|s| s.1.iter().map(|p| p.1));
    let (y0, y1) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| (a.min(y), b.max(y)));
    let pad = 0.05 * (y1 - y0).abs().max(1e-9);
    let xpad = 0.02 * (x1 - x0).abs().max(1e-12);
    let (chart_area, legend_area) = root.split_horizontally(720);
    let mut units: Vec<&str> =
        series.iter().filter_map(|s| s.0.rsplit_once('(').map(|(_, u)| u.trim_end_matches(')'))).collect();
    units.dedup();
    let y_desc = match axis {
        Some(a) if a.contains('*') || a.starts_with('X') => format!("colour: {a} (no unit)"),
        Some(a) => format!("reading ({a})"),
        None if units.len() == 1 => format!("reading ({})", units[0]),
        None => "reading (unit in the legend)".into(),
    };
    let what = label.split(',').next().unwrap_or(label);
    let caption = match axis {
        Some(a) => format!("{name}: readings against {what}: {a}"),
        None => format!("{name}: readings against {what}"),
    };
    let mut chart = ChartBuilder::on(&chart_area)
        .caption(caption, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d((x0 - xpad)..(x1 + xpad), (y0 - pad)..(y1 + pad))
        .map_err(plot_err)?;
    let x_desc = if log { format!("{label} (log scale)") } else { label.to_string() };
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&|x| super::tick(if log { 10f64.powf(*x) } else { *x }))
        .draw()
        .map_err(plot_err)?;
    let mut legend = vec![];
    for (i, (label, pts)) in series.iter().enumerate() {
        let c = Palette99::pick(i).to_rgba();
        let pts: Vec<(f64, f64)> = pts.iter().map(|&(x, y)| (fx(x), y)).collect();
        chart.draw_series(LineSeries::new(pts.clone(), c.stroke_width(2))).map_err(plot_err)?;
        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled()))).map_err(plot_err)?;
        legend.push((Mark::Line(c), label.clone()));
    }
    let spacing = if log { "values spaced logarithmically" } else { "values spaced evenly" };
    legend.push((Mark::Dot(BLACK.to_rgba()), format!("a computed reading ({spacing})")));
    super::draw_side_legend(&legend_area, "readings", &legend, 13)?;
    if axis.is_none() {
        root.present().map_err(plot_err)?;
    }
    Ok(())
}

/// One row of the residual chart.
#[derive(Clone)]
pub(crate) struct Residual {
    /// `SAMPLE GEOMETRY READING`.
    pub label: String,
    pub unit: String,
    /// Predicted − measured.
    pub residual: f64,
    /// The verdict's threshold A (None: the row has no allowance and is unchecked).
    pub allowance: Option<f64>,
    pub verdict: &'static str,
}

fn verdict_colour(v: &str) -> RGBAColor {
    match v {
        "ok" => RGBColor(30, 150, 60).to_rgba(),
        "OUTSIDE" => RGBColor(210, 40, 40).to_rgba(),
        _ => RGBColor(130, 130, 130).to_rgba(),
    }
}

/// The axis of a residual row ([`axis_of`], by its unit and its reading, the last word of its label).
fn residual_axis(r: &Residual) -> String {
    axis_of(&r.unit, r.label.rsplit_once(' ').map_or(r.label.as_str(), |(_, n)| n))
}

/// The picture height of [`draw_comparison`] for `rows`: one panel per axis, each tall enough for its legend.
pub(crate) fn comparison_height(rows: &[Residual]) -> u32 {
    let axes = by_axis(rows.iter().map(residual_axis));
    if axes.len() <= 1 {
        return 640.max(120 + 42 * rows.len().min(40) as u32);
    }
    axes.iter().map(|(_, m)| panel_height(m.len())).sum()
}

/// The height of one panel of several in the residual chart: room for its legend's rows, at least 360.
fn panel_height(rows: usize) -> u32 {
    (120 + 42 * rows.min(40) as u32).max(360)
}

/// `compare --plot`: the residuals, one chart per axis ([`axis_of`]: a unit, or colour's CIELAB or X, Y, Z),
/// stacked, so that GU, HU, DOI and colour never share a scale.
pub(crate) fn draw_comparison<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    name: &str,
    rows: &[Residual],
) -> Result<()> {
    let axes = by_axis(rows.iter().map(residual_axis));
    if axes.len() <= 1 {
        return draw_comparison_panel(root, name, rows, None);
    }
    root.fill(&WHITE).map_err(plot_err)?;
    let mut rest = root.clone();
    for (k, (axis, members)) in axes.iter().enumerate() {
        let part: Vec<Residual> = members.iter().map(|&i| rows[i].clone()).collect();
        let (area, below) =
            if k + 1 < axes.len() { rest.split_vertically(panel_height(members.len())) } else { (rest.clone(), rest) };
        draw_comparison_panel(area, name, &part, Some(axis))?;
        rest = below;
    }
    root.present().map_err(plot_err)?;
    Ok(())
}

fn draw_comparison_panel<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    name: &str,
    rows: &[Residual],
    axis: Option<&str>,
) -> Result<()> {
    root.fill(&WHITE).map_err(plot_err)?;
    // Symmetric about 0, wide enough for every residual and every band; within ±1e307 (a residual of 1e308
    // made the axis infinite and plotters' key points loop); what lies beyond is clipped.
    let span = rows
        .iter()
        .map(|r| r.residual.abs().max(r.allowance.unwrap_or(0.0)))
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max)
        .clamp(1e-12, 1e307)
        * 1.25;
    let n = rows.len();
    let (chart_area, legend_area) = root.split_horizontally(760);
    let mut units: Vec<&str> = rows.iter().map(|r| r.unit.as_str()).collect();
    units.sort();
    units.dedup();
    let mut chart = ChartBuilder::on(&chart_area)
        .caption(
            match axis {
                Some(a) => format!("{name}: predicted − measured, with the allowance: {a}"),
                None => format!("{name}: predicted − measured, with the allowance"),
            },
            ("sans-serif", 18),
        )
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(0.4..(n as f64 + 0.6), -span..span)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc("row of the comparison (named in the legend)")
        .y_desc(match axis {
            Some(a) if a.contains('*') || a.starts_with('X') => format!("predicted − measured, colour: {a} (no unit)"),
            Some(a) => format!("predicted − measured ({a})"),
            None => format!("predicted − measured ({})", units.join(", ")),
        })
        .x_labels(n.min(20) + 1)
        .x_label_formatter(&|x| {
            let k = x.round();
            if (x - k).abs() < 1e-6 && k >= 1.0 && k <= n as f64 {
                format!("{k}")
            } else {
                String::new()
            }
        })
        // The tick at 0 computed as 1.7e-18 is 0.
        .y_label_formatter(&|y| super::tick(if y.abs() < span * 1e-9 { 0.0 } else { *y }))
        .draw()
        .map_err(plot_err)?;
    chart
        .draw_series(std::iter::once(PathElement::new(vec![(0.4, 0.0), (n as f64 + 0.6, 0.0)], BLACK.stroke_width(1))))
        .map_err(plot_err)?;
    let band = RGBColor(60, 120, 220).mix(0.22);
    let mut legend = vec![(Mark::Box(band), "allowance ±A: inside ⇔ |predicted − measured| ≤ A".to_string())];
    for (i, r) in rows.iter().enumerate() {
        let x = i as f64 + 1.0;
        if let Some(a) = r.allowance.filter(|a| a.is_finite()) {
            let a = a.min(span);
            chart
                .draw_series(std::iter::once(Rectangle::new([(x - 0.3, -a), (x + 0.3, a)], band.filled())))
                .map_err(plot_err)?;
        }
        let c = verdict_colour(r.verdict);
        let y = r.residual.clamp(-span, span);
        chart.draw_series(std::iter::once(Circle::new((x, y), 5, c.filled()))).map_err(plot_err)?;
        chart
            .draw_series(std::iter::once(Text::new(
                r.verdict.to_string(),
                (x + 0.08, y),
                ("sans-serif", 13).into_font().color(&c),
            )))
            .map_err(plot_err)?;
        if i < 40 {
            let a = r.allowance.map(super::tick).unwrap_or_else(|| "none".into());
            legend.push((
                Mark::Dot(c),
                format!("{}: {}: {} (A = {a}) {}", i + 1, r.label, super::tick(r.residual), r.verdict),
            ));
        }
    }
    if n > 40 {
        legend.push((Mark::Dot(BLACK.to_rgba()), format!("… and {} more rows (in the table)", n - 40)));
    }
    super::draw_side_legend(&legend_area, "rows and verdicts", &legend, 12)?;
    if axis.is_none() {
        root.present().map_err(plot_err)?;
    }
    Ok(())
}

/// The in-plane section picture of `material` through `geometries` as an SVG document in memory (what
/// `plot --kind section` writes to a file; the server's `/api/plot`).
pub(crate) fn section_svg(material: &recipe::Material, geometries: &[StandardGeometry]) -> Result<String> {
    let panels: Vec<Section> = geometries.iter().filter_map(|g| section(material.brdf.as_ref(), g)).collect();
    if panels.is_empty() {
        return Err(Error::Usage("none of the geometries has a receptor in the plane of incidence to draw".into()));
    }
    let h = 420 * panels.len() as u32;
    super::to_svg((1000, h), |root| draw_sections(root, &material.name, &panels))
}

/// Readings against one recipe number (named `label`, on a log axis when `log`) as an SVG document in memory:
/// `series` holds a label
/// (geometry, reading, unit) and its (value of the number, reading) points, as `plot --kind
/// gloss-vs-parameter` draws them.
pub(crate) fn vs_parameter_svg(
    name: &str,
    label: &str,
    log: bool,
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<String> {
    if series.iter().all(|s| s.1.is_empty()) {
        return Err(Error::Numeric("no reading has a value over the range".into()));
    }
    super::to_svg(vs_parameter_size(series), |root| draw_vs_parameter(root, name, label, log, series))
}
