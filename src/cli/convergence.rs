//! `glossmeter convergence`: value, estimated error, actual error, evaluations and time of every reading
//! over a sweep of tolerances, as a table, CSV or JSON, and optionally a log–log plot of error against
//! time (SVG). The computation is `instrument::convergence::sweep`; this module parses, formats and writes.
use std::path::PathBuf;

use super::common::{pad_table, ColourArgs, Format};
use super::output::{Existing, OutputTarget};
use super::plot;
use crate::instrument::convergence::{self, ReferenceKind, Sweep};
use crate::recipe::{self, Material};
use crate::report::plain;
use crate::request::ConvergenceRequest;
use crate::{Error, Result};

/// The geometries swept when none is given.
pub const DEFAULT_GEOMETRIES: &[&str] = crate::request::CONVERGENCE_GEOMETRIES;

/// Arguments of `glossmeter convergence`.
#[derive(clap::Args, Debug)]
pub struct ConvergenceArgs {
    /// The recipe (JSON).
    pub recipe: PathBuf,
    /// Shipped geometry ids (repeatable); default: astm-d523-20, -60, -85.
    #[arg(long = "geometry", short = 'g')]
    pub geometries: Vec<String>,
    /// A user geometry file in the standards format (repeatable).
    #[arg(long = "geometry-file")]
    pub geometry_files: Vec<PathBuf>,
    /// Relative tolerances to sweep, comma-separated, each in (0, 1) [default: 1e-2,1e-3,…,1e-10].
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub tolerances: Vec<f64>,
    /// Output: an aligned table, JSON (`schema --output-format convergence`) or CSV.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
    /// Also draw actual and estimated error against time, log–log, to this new .svg file.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Write the table/CSV/JSON to this new file instead of stdout (refuses to overwrite).
    #[arg(long, short = 'o')]
    pub output: Option<PathBuf>,
    /// Repeat each execution until this many milliseconds have elapsed (or --max-repetitions), and report
    /// the minimum time per execution.
    #[arg(long, default_value_t = ConvergenceRequest::default().min_time_ms)]
    pub min_time_ms: f64,
    /// At most this many timed executions per tolerance.
    #[arg(long, default_value_t = ConvergenceRequest::default().max_repetitions)]
    pub max_repetitions: usize,
    /// Compare with a run at 1/100 of the tightest tolerance even when a closed form exists.
    #[arg(long)]
    pub reference_run: bool,
    #[command(flatten)]
    pub colour: ColourArgs,
}

/// The request of a command line (the one place where `convergence`'s arguments become the library's).
pub fn request(a: &ConvergenceArgs) -> ConvergenceRequest {
    ConvergenceRequest {
        tolerances: a.tolerances.clone(),
        min_time_ms: a.min_time_ms,
        max_repetitions: a.max_repetitions,
        reference_run: a.reference_run,
        illuminant: Some(a.colour.illuminant.clone()),
        observer: Some(a.colour.observer.clone()),
    }
}

pub fn run(args: ConvergenceArgs, existing: Existing) -> Result<()> {
    // Every check that can fail cheaply comes before the (possibly long) sweep.
    let (tolerances, options) = request(&args).options()?;
    let target = OutputTarget::new(args.output.as_deref(), "--output", existing)?;
    if let Some(p) = &args.plot {
        plot::check_plot_path(p, "--plot", existing)?;
        if args.output.as_deref() == Some(p.as_path()) {
            return Err(Error::Usage(format!("--plot and --output name the same file {}", p.display())));
        }
    }
    let mut stdin = crate::input::Stdin::default();
    let material = recipe::load_source(&stdin.open_text(&args.recipe, "recipe")?)?;
    let files = stdin.open_text_all(&args.geometry_files, "geometry file")?;
    let geometries = crate::api::resolve_geometries_from(&args.geometries, &files, DEFAULT_GEOMETRIES)?;
    let sweep = convergence::sweep(material.brdf.clone(), geometries, &tolerances, &options)?;
    let text = match args.format {
        Format::Table => table(&material, &sweep),
        Format::Json => json(&material, &sweep),
        Format::Csv => csv(&sweep)?,
    };
    if let Some(p) = &args.plot {
        let title = format!("{}: error vs time", material.name);
        let s = plot::write_plot(&sweep, &title, p, existing)?;
        eprintln!(
            "plot: {} ({} series; errors below {:.1e} drawn at that floor: {} actual, {} estimated)",
            p.display(),
            s.series,
            s.floor,
            s.clamped_actual,
            s.clamped_estimated
        );
    }
    target.write(&text)?;
    if sweep.rows.iter().any(|r| r.value.is_none()) {
        return Err(Error::Numeric("some readings have no value (see the rows' problem)".into()));
    }
    Ok(())
}

/// Decimals that show a value to one digit below its estimated error (2 to 14).
fn decimals(err: Option<f64>) -> usize {
    match err {
        Some(e) if e > 0.0 && e.is_finite() => ((-e.log10().floor()) as i64 + 1).clamp(2, 14) as usize,
        _ => 14,
    }
}

fn err_cell(e: Option<f64>) -> String {
    match e {
        Some(0.0) => "0".into(),
        Some(x) => format!("{x:.2e}"),
        None => "—".into(),
    }
}

fn reference_note(sweep: &Sweep) -> String {
    match &sweep.reference {
        ReferenceKind::ClosedForm => {
            "Reference: closed form (Lambertian material: (ρ/π)·P_s·P_r by Lambert's polygon formula; gloss standard by 64×64 Gauss–Legendre), independent of the engine.".into()
        }
        ReferenceKind::Run { rtol } => format!(
            "Reference: the same engine at rtol = {rtol:e} (100× tighter than the tightest of the sweep; {}); an actual error below the reference's own estimate is not resolved.",
            super::format::secs(sweep.reference_seconds)
        ),
    }
}

/// The aligned table.
pub fn table(material: &Material, sweep: &Sweep) -> String {
    let head =
        ["rtol", "geometry", "reading", "value", "est. error", "actual error", "evaluations", "time", "reference"];
    let mut rows: Vec<Vec<String>> = vec![head.iter().map(|s| s.to_string()).collect()];
    let mut notes = Vec::new();
    for r in &sweep.rows {
        let value = match r.value {
            Some(v) => crate::report::shown(v, decimals(r.error_estimate.map(|e| e.min(r.actual_error.unwrap_or(e))))),
            None => "—".into(),
        };
        let mark = if r.converged { "" } else { " *" };
        rows.push(vec![
            format!("{:.0e}", r.rtol),
            r.geometry.clone(),
            format!("{} ({})", r.reading, r.unit),
            value,
            err_cell(r.error_estimate),
            err_cell(r.actual_error),
            format!("{}{mark}", r.evaluations),
            super::format::secs(r.seconds),
            r.reference_kind.clone(),
        ]);
        if let Some(p) = &r.problem {
            notes.push(format!("rtol {:e} {} {}: {p}", r.rtol, r.geometry, r.reading));
        }
    }
    let mut s =
        format!("{} ({})\n{}\n{}\n", material.name, material.file, material.brdf.describe(), reference_note(sweep));
    s.push_str(&format!(
        "Time: per reading (sum of the wall times of the aperture integrals it uses), minimum over repeated executions (until {} ms or {} executions).\n\n",
        sweep.options.min_seconds * 1e3,
        sweep.options.max_repetitions
    ));
    s.push_str(&pad_table(&rows, &[0, 3, 4, 5, 6, 7]));
    if sweep.rows.iter().any(|r| !r.converged) {
        s.push_str("* evaluation budget exhausted before the tolerance was met\n");
    }
    s.push_str(&super::format::colour_line(sweep.rows.iter().map(|r| r.colour)));
    for n in notes {
        s.push_str(&format!("note: {n}\n"));
    }
    s
}

/// CSV: one line per row, every number in full precision; empty cells where there is no value.
pub fn csv(sweep: &Sweep) -> Result<String> {
    let head = [
        "rtol",
        "geometry",
        "reading",
        "quantity",
        "unit",
        "value",
        "error_estimate",
        "actual_error",
        "reference",
        "reference_error",
        "reference_kind",
        "evaluations",
        "seconds",
        "plan_seconds",
        "repetitions",
        "converged",
        "illuminant",
        "observer",
        "problem",
    ];
    let opt = |x: Option<f64>| x.map(plain).unwrap_or_default();
    let rows = sweep.rows.iter().map(|r| {
        let [illuminant, observer] = crate::report::ConditionsDoc::cells(r.colour);
        [
            plain(r.rtol),
            r.geometry.clone(),
            r.reading.clone(),
            r.quantity.clone(),
            r.unit.clone(),
            opt(r.value),
            opt(r.error_estimate),
            opt(r.actual_error),
            opt(r.reference),
            opt(r.reference_error),
            r.reference_kind.clone(),
            r.evaluations.to_string(),
            plain(r.seconds),
            plain(r.plan_seconds),
            r.repetitions.to_string(),
            r.converged.to_string(),
            illuminant,
            observer,
            r.problem.clone().unwrap_or_default(),
        ]
    });
    crate::report::csv_text(&head, rows)
}

/// JSON: the sweep's settings and one object per row (null where there is no value).
pub fn json(material: &Material, sweep: &Sweep) -> String {
    crate::report::convergence::ConvergenceDoc::new(material, sweep).text()
}
