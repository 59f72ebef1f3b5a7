//! `glossmeter plot` and `compare --plot`: pictures of what the engine computes, so that a user can see where
//! the apertures sit on the lobe, how a reading moves with one recipe parameter, and how predictions sit
//! beside measurements. Only drawing lives here; the numbers come from the library (`Brdf::eval`, the plan,
//! `compare`'s comparison).
use std::path::{Path, PathBuf};

use crate::cli::common::ColourArgs;
use crate::cli::output::Existing;
use crate::comparison::Comparison;
use crate::input::Stdin;
use crate::report::pictures::charts::{
    comparison_height, draw_comparison, draw_sections, draw_vs_parameter, section, vs_parameter_size, Residual, Section,
};
use crate::request::{self, VsParameterRequest};
use crate::{recipe, Error, Result};

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
    /// The picture to draw.
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
    #[arg(long, default_value_t = request::PLOT_POINTS)]
    pub points: usize,
    /// For gloss-vs-parameter: how the values are spaced. `auto`: logarithmically when the range spans a
    /// decade or more (LO > 0 and HI ≥ 10·LO, as a roughness range does), else evenly.
    #[arg(long, value_enum, default_value_t = Spacing::Auto)]
    pub spacing: Spacing,
    /// Relative tolerance of the readings (gloss-vs-parameter; default 1e-5, for a measured table a quarter of
    /// each integral's data uncertainty: given here, it is used as given).
    #[arg(long)]
    pub rtol: Option<f64>,
    #[command(flatten)]
    pub colour: ColourArgs,
    /// Evaluation budget of each aperture integral, as in `measure` (deterministic: the same bits on every
    /// machine); a reading whose integral runs out is marked not converged.
    #[arg(long, value_name = "N", default_value_t = crate::instrument::plan::PlanOptions::default().max_evals)]
    pub max_evals: usize,
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
        plan: a.colour.plan(a.rtol, a.max_evals),
    }
}

pub fn run(a: PlotArgs, existing: Existing) -> Result<()> {
    super::plot::check_plot_path(&a.output, "--output", existing)?;
    // The tolerance and the colour conditions, checked before any work.
    request(&a).plan.options()?;
    let geos = crate::resolve_geometries_or(&a.geometries, &[] as &[&str], DEFAULT)?;
    match a.kind {
        PlotKind::Section => {
            if a.vary.is_some() {
                return Err(Error::Usage("--vary belongs to --kind gloss-vs-parameter".into()));
            }
            let material = recipe::load_source(&Stdin::default().open_text(&a.recipe, "recipe")?)?;
            let panels: Vec<Section> = geos.iter().filter_map(|g| section(material.brdf.as_ref(), g)).collect();
            if panels.is_empty() {
                return Err(Error::Usage(
                    "none of the geometries has a receptor in the plane of incidence to draw".into(),
                ));
            }
            let h = 420 * panels.len() as u32;
            crate::render_plot!(&a.output, "--output", existing, (1000, h), |root| draw_sections(
                root,
                &material.name,
                &panels
            ))?;
        }
        PlotKind::GlossVsParameter => {
            let source = Stdin::default().open_text(&a.recipe, "recipe")?;
            let (file, text) = (source.name(), source.text("recipe")?);
            let v = request(&a).read(&text, &file, geos)?;
            crate::render_plot!(&a.output, "--output", existing, vs_parameter_size(&v.series), |root| {
                draw_vs_parameter(root, &v.name, &v.label, v.log, &v.series)
            })?;
        }
    }
    eprintln!("plot: {}", a.output.display());
    Ok(())
}

/// `compare --plot` (docs/instrument.md §Pictures): the residual predicted − measured of every reading with a
/// prediction, in the reading's unit, against its row in the comparison; the allowance (k·s/√n + stated
/// uncertainty + the prediction's error estimate, the verdict's threshold) as a band ±A about 0; each point
/// coloured by its verdict (ok green, outside red, unchecked grey) and the verdict written beside it. The legend,
/// beside the chart, names every row.
pub fn write_comparison(path: &Path, cmp: &[Comparison], existing: Existing) -> Result<()> {
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
    let h = comparison_height(&rows);
    crate::render_plot!(path, "--plot", existing, (1100, h), |root| draw_comparison(root, &name, &rows))
}
