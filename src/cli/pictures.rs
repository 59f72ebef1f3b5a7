//! `glossmeter plot` and `compare --plot`: pictures of what the engine computes, so that a user can see where
//! the apertures sit on the lobe, how a reading moves with one recipe parameter, and how predictions sit
//! beside measurements. Only drawing lives here; the numbers come from the library (`Brdf::eval`, the plan,
//! `compare`'s comparison).
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;
use serde_json::Value;

use super::plot::{plot_err, Mark};
use crate::brdf::{mirror, Brdf};
use crate::colorimetry::weighting::Weighting;
use crate::comparison::Comparison;
use crate::instrument::standards::StandardGeometry;
use crate::request::{self, PlanRequest, VsParameterRequest};
use crate::{recipe, Error, Result, Vec3};

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum PlotKind {
    /// The in-plane BRDF section (log scale) with the source image and the receptors drawn over it.
    Section,
    /// Readings against one recipe parameter (`--vary PATH=LO..HI`).
    GlossVsParameter,
}

#[derive(clap::Args, Debug)]
pub struct PlotArgs {
    /// The recipe (JSON).
    pub recipe: PathBuf,
    #[arg(long, value_enum)]
    pub kind: PlotKind,
    /// A shipped geometry id (repeatable). Default: ASTM D523 20°, 60°, 85°.
    #[arg(long = "geometry", short = 'g')]
    pub geometries: Vec<String>,
    /// For gloss-vs-parameter: the recipe number to vary, as a JSON Pointer, and its range, e.g.
    /// `/roughness=0.02..0.3` (the grammar of `sweep --vary`; `:N` there sets --points).
    #[arg(long)]
    pub vary: Option<String>,
    /// For gloss-vs-parameter: how many values.
    #[arg(long, default_value_t = 9)]
    pub points: usize,
    /// For gloss-vs-parameter: how the values are spaced. `auto`: logarithmically when the range spans a
    /// decade or more (LO > 0 and HI ≥ 10·LO, as a roughness range does), else evenly.
    #[arg(long, value_enum, default_value_t = Spacing::Auto)]
    pub spacing: Spacing,
    /// Relative tolerance of the readings (gloss-vs-parameter; default 1e-5, for a measured table a quarter of
    /// each integral's data uncertainty: given here, it is used as given).
    #[arg(long)]
    pub rtol: Option<f64>,
    /// The picture: FILE.png or FILE.svg (never overwritten).
    #[arg(long, short = 'o')]
    pub output: PathBuf,
}

/// The spacing of the values of gloss-vs-parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Spacing {
    Auto,
    Linear,
    Log,
}

const DEFAULT: &[&str] = crate::request::PLOT_GEOMETRIES;

pub use crate::request::parameter_label;

/// The request of a command line (the one place where `plot --kind gloss-vs-parameter`'s arguments become the
/// library's).
pub fn request(a: &PlotArgs) -> VsParameterRequest {
    VsParameterRequest {
        vary: a.vary.clone(),
        points: Some(a.points),
        spacing: match a.spacing {
            Spacing::Auto => request::Spacing::Auto,
            Spacing::Linear => request::Spacing::Linear,
            Spacing::Log => request::Spacing::Log,
        },
        plan: PlanRequest { rtol: a.rtol, ..PlanRequest::default() },
    }
}

pub fn run(a: PlotArgs) -> Result<()> {
    super::plot::check_plot_path(&a.output, "--output")?;
    if let Some(rtol) = a.rtol {
        request::check_rtol(rtol)?;
    }
    let geos = crate::resolve_geometries_or(&a.geometries, &[] as &[&str], DEFAULT)?;
    match a.kind {
        PlotKind::Section => {
            if a.vary.is_some() {
                return Err(Error::Usage("--vary belongs to --kind gloss-vs-parameter".into()));
            }
            let material = recipe::load_file(&a.recipe)?;
            let panels: Vec<Section> = geos.iter().filter_map(|g| section(material.brdf.as_ref(), g)).collect();
            if panels.is_empty() {
                return Err(Error::Usage(
                    "none of the geometries has a receptor in the plane of incidence to draw".into(),
                ));
            }
            let h = 420 * panels.len() as u32;
            crate::render_plot!(&a.output, "--output", (1000, h), |root| draw_sections(root, &material.name, &panels))?;
        }
        PlotKind::GlossVsParameter => {
            let file = crate::input::name(&a.recipe);
            let text = crate::input::read_text(&a.recipe, "recipe")?;
            let v = request(&a).read(&text, &file, geos)?;
            crate::render_plot!(&a.output, "--output", (1000, 640), |root| draw_vs_parameter(
                root, &v.name, &v.label, v.log, &v.series
            ))?;
        }
    }
    eprintln!("plot: {}", a.output.display());
    Ok(())
}

/// One panel of the section plot.
struct Section {
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
fn section(brdf: &dyn Brdf, g: &StandardGeometry) -> Option<Section> {
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

fn draw_sections<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, name: &str, panels: &[Section]) -> Result<()> {
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
            .y_label_formatter(&|y| super::plot::tick(*y))
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
        super::plot::draw_side_legend(&legend_area, name, &legend, 13)?;
    }
    root.present().map_err(plot_err)?;
    Ok(())
}

/// Readings against the parameter: x on a log axis when the values are log-spaced (drawn as log10 x with the
/// ticks labelled in x), the legend beside the chart.
fn draw_vs_parameter<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    name: &str,
    label: &str,
    log: bool,
    series: &[(String, Vec<(f64, f64)>)],
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
    let y_desc =
        if units.len() == 1 { format!("reading ({})", units[0]) } else { "reading (unit in the legend)".into() };
    let mut chart = ChartBuilder::on(&chart_area)
        .caption(format!("{name}: readings against {}", label.split(',').next().unwrap_or(label)), ("sans-serif", 18))
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
        .x_label_formatter(&|x| super::plot::tick(if log { 10f64.powf(*x) } else { *x }))
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
    super::plot::draw_side_legend(&legend_area, "readings", &legend, 13)?;
    root.present().map_err(plot_err)?;
    Ok(())
}

/// `compare --plot` (docs/instrument.md §Pictures): the residual predicted − measured of every reading with a
/// prediction, in the reading's unit, against its row in the comparison; the allowance (k·s/√n + stated
/// uncertainty + the prediction's error estimate, the verdict's threshold) as a band ±A about 0; each point
/// coloured by its verdict (ok green, outside red, unchecked grey) and the verdict written beside it. The legend,
/// beside the chart, names every row.
pub fn write_comparison(path: &Path, cmp: &[Comparison]) -> Result<()> {
    let mut rows: Vec<Residual> = Vec::new();
    let mut names: Vec<&str> = Vec::new();
    for c in cmp {
        let Some(d) = c.difference() else { continue };
        if !names.contains(&c.material.as_str()) {
            names.push(&c.material);
        }
        let unit = c.predicted.as_ref().map(|p| p.unit.clone()).unwrap_or_default();
        rows.push(Residual {
            label: format!("{} {} {}", c.group.sample, c.group.geometry, c.group.reading),
            unit,
            residual: d,
            allowance: c.allowance.map(|a| a.total()),
            verdict: c.verdict.label(),
        });
    }
    if rows.is_empty() {
        return Err(Error::Numeric("nothing to plot: no row has a prediction with a value".into()));
    }
    let name = if names.len() == 1 { names[0].to_string() } else { format!("{} materials", names.len()) };
    let h = 640.max(120 + 42 * rows.len().min(40) as u32);
    crate::render_plot!(path, "--plot", (1100, h), |root| draw_comparison(root, &name, &rows))
}

/// One row of the residual chart.
struct Residual {
    label: String,
    unit: String,
    residual: f64,
    /// The verdict's threshold A (None: the row has no allowance and is unchecked).
    allowance: Option<f64>,
    verdict: &'static str,
}

fn verdict_colour(v: &str) -> RGBAColor {
    match v {
        "ok" => RGBColor(30, 150, 60).to_rgba(),
        "OUTSIDE" => RGBColor(210, 40, 40).to_rgba(),
        _ => RGBColor(130, 130, 130).to_rgba(),
    }
}

fn draw_comparison<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, name: &str, rows: &[Residual]) -> Result<()> {
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
        .caption(format!("{name}: predicted − measured, with the allowance"), ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(0.4..(n as f64 + 0.6), -span..span)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc("row of the comparison (named in the legend)")
        .y_desc(format!("predicted − measured ({})", units.join(", ")))
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
        .y_label_formatter(&|y| super::plot::tick(if y.abs() < span * 1e-9 { 0.0 } else { *y }))
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
            let a = r.allowance.map(super::plot::tick).unwrap_or_else(|| "none".into());
            legend.push((
                Mark::Dot(c),
                format!("{}: {}: {} (A = {a}) {}", i + 1, r.label, super::plot::tick(r.residual), r.verdict),
            ));
        }
    }
    if n > 40 {
        legend.push((Mark::Dot(BLACK.to_rgba()), format!("… and {} more rows (in the table)", n - 40)));
    }
    super::plot::draw_side_legend(&legend_area, "rows and verdicts", &legend, 12)?;
    root.present().map_err(plot_err)?;
    Ok(())
}

/// The in-plane section picture of `material` through `geometries` as an SVG document in memory (what
/// `plot --kind section` writes to a file; the server's `/api/plot`).
pub fn section_svg(material: &recipe::Material, geometries: &[StandardGeometry]) -> Result<String> {
    let panels: Vec<Section> = geometries.iter().filter_map(|g| section(material.brdf.as_ref(), g)).collect();
    if panels.is_empty() {
        return Err(Error::Usage("none of the geometries has a receptor in the plane of incidence to draw".into()));
    }
    let h = 420 * panels.len() as u32;
    super::plot::to_svg((1000, h), |root| draw_sections(root, &material.name, &panels))
}

/// Readings against one recipe number (named `label`, on a log axis when `log`) as an SVG document in memory:
/// `series` holds a label
/// (geometry, reading, unit) and its (value of the number, reading) points, as `plot --kind
/// gloss-vs-parameter` draws them.
pub fn vs_parameter_svg(name: &str, label: &str, log: bool, series: &[(String, Vec<(f64, f64)>)]) -> Result<String> {
    if series.iter().all(|s| s.1.is_empty()) {
        return Err(Error::Numeric("no reading has a value over the range".into()));
    }
    super::plot::to_svg((1000, 640), |root| draw_vs_parameter(root, name, label, log, series))
}
