//! `glossmeter plot` and `compare --plot`: pictures of what the engine computes, so that a user can see where
//! the apertures sit on the lobe, how a reading moves with one recipe parameter, and how predictions sit
//! beside measurements. Only drawing lives here; the numbers come from the library (`Brdf::eval`, the plan,
//! `compare`'s comparison).
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;
use serde_json::Value;

use super::common::check_rtol;
use super::plot::plot_err;
use crate::brdf::{mirror, Brdf};
use crate::colorimetry::weighting::Weighting;
use crate::comparison::Comparison;
use crate::instrument::plan::{Plan, PlanOptions};
use crate::instrument::standards::StandardGeometry;
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
    /// `/roughness=0.02..0.3`.
    #[arg(long)]
    pub vary: Option<String>,
    /// For gloss-vs-parameter: how many values, evenly spaced.
    #[arg(long, default_value_t = 9)]
    pub points: usize,
    /// Relative tolerance of the readings (gloss-vs-parameter).
    #[arg(long, default_value_t = 1e-5)]
    pub rtol: f64,
    /// The picture: FILE.png or FILE.svg (never overwritten).
    #[arg(long, short = 'o')]
    pub output: PathBuf,
}

const DEFAULT: &[&str] = &["astm-d523-20", "astm-d523-60", "astm-d523-85"];

pub fn run(a: PlotArgs) -> Result<()> {
    super::plot::check_plot_path(&a.output, "--output")?;
    check_rtol(a.rtol)?;
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
            let spec = a
                .vary
                .as_deref()
                .ok_or_else(|| Error::Usage("--kind gloss-vs-parameter needs --vary PATH=LO..HI".into()))?;
            let (pointer, lo, hi) = parse_vary(spec)?;
            if !(2..=200).contains(&a.points) {
                return Err(Error::Usage(format!("--points must be 2 to 200, got {}", a.points)));
            }
            let file = a.recipe.display().to_string();
            let text = std::fs::read_to_string(&a.recipe).map_err(|source| Error::Io { file: file.clone(), source })?;
            let json: Value = crate::input::json::parse_json(&text, &file)?;
            match json.pointer(&pointer) {
                Some(Value::Number(_)) => {}
                Some(v) => {
                    return Err(Error::input(
                        &file,
                        &pointer,
                        format!("--vary needs a number here, got {}", crate::input::json::kind(v)),
                    ))
                }
                None => return Err(Error::input(&file, &pointer, "--vary: no such field in the recipe")),
            }
            let name = recipe::parse_str(&text, &file)?.name;
            let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
            for k in 0..a.points {
                let x = lo + (hi - lo) * k as f64 / (a.points - 1) as f64;
                let mut j = json.clone();
                *j.pointer_mut(&pointer).expect("checked above") = serde_json::json!(x);
                let m = recipe::parse_str(&j.to_string(), &file)
                    .map_err(|e| Error::Usage(format!("--vary {pointer} = {x}: {e}")))?;
                let plan = Plan::compile(
                    m.brdf.clone(),
                    geos.clone(),
                    PlanOptions { rtol: a.rtol, ..PlanOptions::default() },
                )?;
                for r in plan.execute() {
                    let label = format!("{} {} ({})", r.geometry, r.name, r.unit);
                    let Some(v) = r.value else { continue };
                    match series.iter_mut().find(|s| s.0 == label) {
                        Some(s) => s.1.push((x, v)),
                        None => series.push((label, vec![(x, v)])),
                    }
                }
            }
            if series.is_empty() {
                return Err(Error::Numeric("no reading has a value over the range".into()));
            }
            crate::render_plot!(&a.output, "--output", (1000, 640), |root| draw_vs_parameter(
                root, &name, &pointer, &series
            ))?;
        }
    }
    eprintln!("plot: {}", a.output.display());
    Ok(())
}

/// `PATH=LO..HI` with PATH a JSON Pointer.
fn parse_vary(s: &str) -> Result<(String, f64, f64)> {
    let bad = || {
        Error::Usage(format!("--vary {s}: expected PATH=LO..HI with PATH a JSON Pointer, e.g. /roughness=0.02..0.3"))
    };
    let (path, range) = s.split_once('=').ok_or_else(bad)?;
    let (lo, hi) = range.split_once("..").ok_or_else(bad)?;
    let (lo, hi): (f64, f64) = (lo.trim().parse().map_err(|_| bad())?, hi.trim().parse().map_err(|_| bad())?);
    if !(path.starts_with('/') && lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(bad());
    }
    Ok((path.to_string(), lo, hi))
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
        .filter_map(|r| {
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

fn draw_sections<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, name: &str, panels: &[Section]) -> Result<()> {
    root.fill(&WHITE).map_err(plot_err)?;
    let areas = root.split_evenly((panels.len(), 1));
    for (area, p) in areas.iter().zip(panels) {
        // The log axis within the normal finite numbers: a floor of 0 (10⁻⁶ of a subnormal maximum) or an
        // infinite top (3× a maximum near f64::MAX, or an infinite f_r) made plotters' log scale loop for ever.
        let max = p.curve.iter().map(|c| c.1).fold(0.0f64, f64::max).min(f64::MAX);
        let floor = if max > 0.0 { (max * 1e-6).max(f64::MIN_POSITIVE) } else { 1e-6 };
        let top = if max > 0.0 { (max * 3.0).min(f64::MAX).max(floor * 10.0) } else { 1.0 };
        let (x0, x1) = (p.curve[0].0, p.curve[p.curve.len() - 1].0);
        let mut chart = ChartBuilder::on(area)
            .caption(format!("{name}: in-plane section, {} (θi = {}°)", p.id, p.angle), ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, (floor..top).log_scale())
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("θo in the plane of incidence (°, + on the specular side)")
            .y_desc("f_r (1/sr, luminous)")
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .draw()
            .map_err(plot_err)?;
        let blue = RGBColor(40, 90, 200);
        let orange = RGBColor(230, 140, 20);
        for (i, (rname, a, b)) in p.receptors.iter().enumerate() {
            let c = Palette99::pick(i + 2).mix(0.22);
            chart
                .draw_series(std::iter::once(Rectangle::new([(*a, floor), (*b, top)], c.filled())))
                .map_err(plot_err)?
                .label(format!("receptor {rname}: {a:.2}° … {b:.2}°"))
                .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], c.filled()));
        }
        let (a, b) = p.source_image;
        chart
            .draw_series(std::iter::once(Rectangle::new([(a, floor), (b, top)], orange.mix(0.55).filled())))
            .map_err(plot_err)?
            .label(format!("mirror image of the source: {a:.2}° … {b:.2}°"))
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], orange.mix(0.55).filled()));
        let pts: Vec<(f64, f64)> = p.curve.iter().map(|&(x, y)| (x, y.max(floor).min(top))).collect();
        chart
            .draw_series(LineSeries::new(pts, blue.stroke_width(2)))
            .map_err(plot_err)?
            .label("regular part of f_r (values below the floor drawn at it)")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], blue.stroke_width(2)));
        if let Some(r) = p.delta {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(p.angle, floor), (p.angle, top)],
                    BLACK.stroke_width(2),
                )))
                .map_err(plot_err)?
                .label(format!("mirror (delta) component, R = {r:.4}"))
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK.stroke_width(2)));
        }
        super::plot::draw_legend(&mut chart, SeriesLabelPosition::UpperRight, 12)?;
    }
    root.present().map_err(plot_err)?;
    Ok(())
}

fn draw_vs_parameter<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    name: &str,
    pointer: &str,
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<()> {
    root.fill(&WHITE).map_err(plot_err)?;
    let xs = series.iter().flat_map(|s| s.1.iter().map(|p| p.0));
    let (x0, x1) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    let ys = series.iter().flat_map(|s| s.1.iter().map(|p| p.1));
    let (y0, y1) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| (a.min(y), b.max(y)));
    let pad = 0.05 * (y1 - y0).abs().max(1e-9);
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{name}: readings against {pointer}"), ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, (y0 - pad)..(y1 + pad))
        .map_err(plot_err)?;
    chart.configure_mesh().x_desc(format!("recipe {pointer}")).y_desc("reading").draw().map_err(plot_err)?;
    for (i, (label, pts)) in series.iter().enumerate() {
        let c = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(plot_err)?
            .label(label.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(2)));
        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled()))).map_err(plot_err)?;
    }
    super::plot::draw_legend(&mut chart, SeriesLabelPosition::UpperRight, 13)?;
    root.present().map_err(plot_err)?;
    Ok(())
}

/// `compare --plot`: measured (x: the mean of the sheet's repeats, with the measurement's allowance — k·s/√n
/// plus the stated uncertainty — as a horizontal bar) against predicted (y, with the prediction's error
/// estimate as a vertical bar), one colour per geometry and reading, and y = x.
pub fn write_comparison(path: &Path, cmp: &[Comparison]) -> Result<()> {
    let mut groups: Vec<Group> = Vec::new();
    let mut names: Vec<&str> = Vec::new();
    for c in cmp {
        let Some(p) = c.predicted.as_ref() else { continue };
        let Some(v) = p.value else { continue };
        if !names.contains(&c.material.as_str()) {
            names.push(&c.material);
        }
        let label = format!("{} {}", c.group.geometry, c.group.reading);
        let bar = c.allowance.map(|a| a.statistical + a.stated).or(c.group.uncertainty).unwrap_or(0.0);
        let pt = (c.group.stats.mean, v, bar, p.error_estimate);
        match groups.iter_mut().find(|g| g.0 == label) {
            Some(g) => g.1.push(pt),
            None => groups.push((label, vec![pt])),
        }
    }
    if groups.is_empty() {
        return Err(Error::Numeric("nothing to plot: no row has a prediction with a value".into()));
    }
    let name = if names.len() <= 3 { names.join(", ") } else { format!("{} samples", names.len()) };
    crate::render_plot!(path, "--plot", (900, 800), |root| draw_comparison(root, &name, &groups))
}

/// A series label and its points (measured, predicted, measured's bar, predicted's bar).
type Group = (String, Vec<(f64, f64, f64, f64)>);

fn draw_comparison<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, name: &str, groups: &[Group]) -> Result<()> {
    root.fill(&WHITE).map_err(plot_err)?;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (_, pts) in groups {
        for &(m, p, um, up) in pts {
            lo = lo.min(m - um).min(p - up);
            hi = hi.max(m + um).max(p + up);
        }
    }
    // Within ±1e307 (a value of 1e308 ± 1e308 made the axis infinite, and plotters' key points looped); what
    // lies beyond is clipped.
    let (lo, hi) = (lo.clamp(-1e307, 1e307), hi.clamp(-1e307, 1e307));
    let pad = 0.05 * (hi - lo).abs().max(1e-9);
    let (lo, hi) = (lo - pad, hi + pad);
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{name}: predicted against measured"), ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(lo..hi, lo..hi)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc("measured (sheet), bar: the row's uncertainty")
        .y_desc("predicted, bar: error estimate")
        .draw()
        .map_err(plot_err)?;
    chart
        .draw_series(std::iter::once(PathElement::new(
            vec![(lo, lo), (hi, hi)],
            RGBColor(120, 120, 120).stroke_width(1),
        )))
        .map_err(plot_err)?
        .label("predicted = measured")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], RGBColor(120, 120, 120).stroke_width(1)));
    for (i, (label, pts)) in groups.iter().enumerate() {
        let c = Palette99::pick(i).to_rgba();
        chart
            .draw_series(
                pts.iter().map(|&(m, p, _, up)| ErrorBar::new_vertical(m, p - up, p, p + up, c.stroke_width(2), 8)),
            )
            .map_err(plot_err)?;
        chart
            .draw_series(
                pts.iter().map(|&(m, p, um, _)| ErrorBar::new_horizontal(p, m - um, m, m + um, c.stroke_width(2), 8)),
            )
            .map_err(plot_err)?;
        chart
            .draw_series(pts.iter().map(|&(m, p, _, _)| Circle::new((m, p), 4, c.filled())))
            .map_err(plot_err)?
            .label(label.clone())
            .legend(move |(x, y)| Circle::new((x + 8, y), 4, c.filled()));
    }
    super::plot::draw_legend(&mut chart, SeriesLabelPosition::UpperLeft, 13)?;
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

/// Readings against one recipe number (`pointer`) as an SVG document in memory: `series` holds a label
/// (geometry, reading, unit) and its (value of the number, reading) points, as `plot --kind
/// gloss-vs-parameter` draws them.
pub fn vs_parameter_svg(name: &str, pointer: &str, series: &[(String, Vec<(f64, f64)>)]) -> Result<String> {
    if series.iter().all(|s| s.1.is_empty()) {
        return Err(Error::Numeric("no reading has a value over the range".into()));
    }
    super::plot::to_svg((1000, 640), |root| draw_vs_parameter(root, name, pointer, series))
}
