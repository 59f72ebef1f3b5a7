//! `glossmeter fit`: recipe parameters from readings (the inverse problem). Argument parsing, the table for
//! people and the output only; the fit itself is `glossmeter::fit` (docs/inverse.md), its JSON document
//! `report::fit`.
use std::path::PathBuf;

use crate::cli::common::{ColourArgs, Format};
use crate::cli::output::{print, Existing, OutputTarget};
use crate::comparison::sheet;
use crate::fit::{self, FitOptions, FitReport};
use crate::request::{FitRequest, SheetRequest};
use crate::{recipe, Error, Result};

#[derive(clap::Args, Debug)]
pub struct FitArgs {
    /// The recipe (JSON); the fit starts from its values.
    pub recipe: PathBuf,
    /// A free parameter: a JSON Pointer with bounds, PATH=LO..HI, or PATH=log:LO..HI to fit its logarithm
    /// (e.g. /roughness=log:1e-3..0.5). Repeatable.
    #[arg(long = "free", required = true)]
    pub free: Vec<String>,
    /// A target reading, GEOMETRY/READING=VALUE[±U] (or +-U), e.g. astm-d523-60/gloss=85±0.2. Repeatable.
    #[arg(long = "target")]
    pub targets: Vec<String>,
    /// Targets from a glossmeter sheet (CSV or an .xlsx/.xls/.ods workbook, the layouts `compare` reads; `-`:
    /// standard input).
    #[arg(long, conflicts_with = "targets")]
    pub sheet: Option<PathBuf>,
    /// The sample of the sheet to fit (needed when the sheet has several).
    #[arg(long, requires = "sheet")]
    pub sample: Option<String>,
    /// The sheet's separator (`,`, `;` or `tab`); detected from the header line by default.
    #[arg(long, requires = "sheet")]
    pub delimiter: Option<String>,
    /// The sheet of a workbook to read (default: its first sheet), as in `compare`.
    #[arg(long, value_name = "NAME", requires = "sheet")]
    pub sheet_name: Option<String>,
    /// The line (or workbook row, 1-based) of the sheet's header; the rows above it are title and metadata
    /// rows (default: the first row naming known columns, else the first row).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..), requires = "sheet")]
    pub header_row: Option<u64>,
    /// A sheet column to skip (repeatable), as in `compare`.
    #[arg(long = "ignore-column", value_name = "HEADER", requires = "sheet")]
    pub ignore_columns: Vec<String>,
    /// A user geometry file (JSON, the format of `measure --geometry-file`) whose readings may be targets,
    /// named by its id (repeatable).
    #[arg(long = "geometry-file", value_name = "FILE")]
    pub geometry_files: Vec<PathBuf>,
    /// Uncertainty of a target given without one, in the reading's unit.
    #[arg(long, default_value_t = fit::DEFAULT_UNCERTAINTY)]
    pub uncertainty: f64,
    /// For an exactly determined fit (as many targets as free parameters): solver restarts from
    /// deterministic starts that check whether another solution fits the targets as well (0: not checked,
    /// said in the verdict).
    #[arg(long, default_value_t = fit::DEFAULT_RESTARTS)]
    pub restarts: usize,
    /// Relative tolerance of every forward reading.
    #[arg(long, default_value_t = crate::DEFAULT_RTOL)]
    pub rtol: f64,
    /// Evaluation budget of each aperture integral of every forward run, as in `measure` (deterministic).
    #[arg(long, default_value_t = crate::instrument::plan::PlanOptions::default().max_evals)]
    pub max_evals: usize,
    #[command(flatten)]
    pub colour: ColourArgs,
    /// Output: an aligned table, JSON (`schema --output-format fit`) or CSV.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
    /// Write the fitted recipe to this new file (never overwrites one).
    #[arg(long, short = 'o')]
    pub output: Option<PathBuf>,
    /// Leave the wall time out of the report.
    #[arg(long)]
    pub no_timing: bool,
}

/// The request of a command line (the one place where `fit`'s arguments become the library's).
pub fn request(a: &FitArgs) -> FitRequest {
    FitRequest {
        free: a.free.clone(),
        targets: a.targets.clone(),
        uncertainty: a.uncertainty,
        restarts: a.restarts,
        plan: a.colour.plan(Some(a.rtol), a.max_evals),
        sheet: SheetRequest {
            delimiter: a.delimiter.clone(),
            ignore_columns: a.ignore_columns.clone(),
            sheet_name: a.sheet_name.clone(),
            header_row: a.header_row.map(|n| n as usize),
        },
        sample: a.sample.clone(),
    }
}

pub fn run(a: FitArgs, existing: Existing) -> Result<()> {
    let request = request(&a);
    let options = request.options()?;
    // Refused before any work if it exists (or its directory does not); written whole or not at all.
    let output = OutputTarget::new(a.output.as_deref(), "-o", existing)?;
    crate::input::at_most_one_stdin(
        std::iter::once(&a.recipe).chain(&a.sheet).chain(&a.geometry_files).map(PathBuf::as_path),
    )?;
    let free = request.free()?;
    let mut stdin = crate::input::Stdin::default();
    let sheet = match &a.sheet {
        Some(s) => Some(sheet::load_source(&stdin.open_text(s, "sheet")?, &request.sheet.options()?)?),
        None => None,
    };
    let (targets, notes) = request.targets(sheet.as_ref())?;
    for n in notes {
        eprintln!("note: {n}");
    }
    let material = recipe::load_source(&stdin.open_text(&a.recipe, "recipe")?)?;
    let files = stdin.open_text_all(&a.geometry_files, "geometry file")?;
    let geometries = crate::api::resolve_geometries_from::<&str>(&[], &files, &[])?;
    let options = FitOptions { geometries, ..options };
    let report = match fit::fit(&material.json, &material.file, &free, &targets, &options) {
        Ok(report) => report,
        // A fit that cannot run still writes its document, with the failure in it (then exits 1).
        Err(Error::Numeric(why)) if a.format == Format::Json => {
            let doc = crate::report::fit::failure_json(&free, &targets, &why);
            print(&(serde_json::to_string_pretty(&doc).unwrap_or_default() + "\n"))?;
            return Err(Error::Numeric(why));
        }
        Err(e) => return Err(e),
    };
    let text = match a.format {
        Format::Json => {
            serde_json::to_string_pretty(&crate::report::fit::json(&report, !a.no_timing))
                .map_err(|e| Error::Numeric(format!("the report does not serialise: {e}")))?
                + "\n"
        }
        Format::Table | Format::Csv => table(&material.name, &report, !a.no_timing),
    };
    print(&text)?;
    if output.path().is_some() {
        let fitted = serde_json::to_string_pretty(&report.recipe)
            .map_err(|e| Error::Numeric(format!("the recipe does not serialise: {e}")))?;
        output.write(&(fitted + "\n"))?;
    }
    if !report.ok() {
        let mut why = Vec::new();
        if !report.reproduces {
            why.push("the model cannot reproduce these readings");
        }
        if !report.converged {
            why.push("it did not converge");
        }
        if report.parameters.iter().any(|p| p.at_bound) {
            why.push("a parameter is at a bound");
        }
        if !report.identifiable {
            why.push("the targets do not determine every parameter");
        }
        if report.stationary {
            why.push("the readings are stationary at the fit");
        }
        return Err(Error::Check(format!("the fit is not to be trusted: {}", why.join("; "))));
    }
    Ok(())
}

fn sig(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        format!("{x}")
    } else {
        format!("{x:.6e}").parse::<f64>().map(|v| format!("{v}")).unwrap_or_default()
    }
}

fn table(name: &str, r: &FitReport, timing: bool) -> String {
    let mut s = format!("fit of {name}: {}; {} forward runs", r.termination, r.evaluations);
    let mut parts = Vec::new();
    if r.linearity_evaluations > 0 {
        parts.push(format!("{} for the linearity check", r.linearity_evaluations));
    }
    if r.restart_evaluations > 0 {
        parts.push(if r.scan_evaluations > 0 {
            format!(
                "{} for the scan of the bounds and the restarts ({} for the scan)",
                r.restart_evaluations, r.scan_evaluations
            )
        } else {
            format!("{} for the restarts", r.restart_evaluations)
        });
    }
    if !parts.is_empty() {
        s.push_str(&format!(" (of which {})", parts.join(", ")));
    }
    if timing {
        s.push_str(&format!(", {:.2} s", r.seconds));
    }
    s.push_str("\n\nparameter                                  value      ± std error   bounds                 note\n");
    for p in &r.parameters {
        let se = p.std_error.map(|e| format!("{e:.3e}")).unwrap_or_else(|| "undetermined".into());
        let bounds = format!("{}{}..{}", if p.log { "log:" } else { "" }, p.lower, p.upper);
        let mut note = Vec::new();
        if p.at_bound {
            note.push("AT BOUND".to_string());
        }
        if let Some(i) = p.most_sensitive {
            let t = &r.targets[i].target;
            note.push(format!("set mostly by {}/{}", t.geometry, t.name));
        }
        s.push_str(&format!(
            "{:<40} {:>12} {:>14}   {:<22} {}\n",
            p.pointer,
            sig(p.value),
            se,
            bounds,
            note.join("; ")
        ));
    }
    s.push_str("\ntarget                       measured        ± u     predicted    residual   weighted\n");
    for t in &r.targets {
        s.push_str(&format!(
            "{:<26} {:>11.4} {:>10.3} {:>13.4} {:>11.3e} {:>10.3}\n",
            format!("{}/{}", t.target.geometry, t.target.name),
            t.target.value,
            t.uncertainty,
            t.predicted,
            t.residual,
            t.weighted_residual
        ));
    }
    s.push_str(&super::format::colour_line(r.targets.iter().map(|t| t.colour)));
    s.push_str(&format!("\nχ² = {:.4} for {} degree(s) of freedom", r.chi2, r.dof));
    match r.p_value {
        Some(p) => s.push_str(&format!(", p = {p:.3e}")),
        None => s.push_str(" (exactly determined: every target must be reached within its uncertainty)"),
    }
    s.push_str(&format!(
        "; reproduces the readings: {}\n",
        if r.reproduces { "yes" } else { "NO: the model cannot reproduce these readings" }
    ));
    if r.error_scale > 1.0 {
        s.push_str(&format!(
            "standard errors scaled by the error scale factor S = √(χ²/dof) = {:.4} (the residuals scatter more \
             than the uncertainties say)\n",
            r.error_scale
        ));
    }
    s.push_str(&format!(
        "singular values of the weighted Jacobian (columns × bound width): {}\n",
        r.singular_values.iter().map(|v| format!("{v:.4e}")).collect::<Vec<_>>().join(", ")
    ));
    if r.parameters.len() > 1 {
        s.push_str("correlation:\n");
        for row in &r.correlation {
            let cells: Vec<String> =
                row.iter().map(|c| c.map(|c| format!("{c:>7.3}")).unwrap_or_else(|| "      —".into())).collect();
            s.push_str(&format!("  {}\n", cells.join(" ")));
        }
    }
    s.push_str(&format!(
        "identifiable: {}\n",
        match (r.identifiable, r.stationary) {
            (true, false) => "yes: the targets determine every parameter",
            (true, true) => "NO: the targets see every parameter, but the readings are stationary at the fit",
            (false, _) => "NO",
        }
    ));
    for v in &r.verdict {
        s.push_str(&format!("  - {v}\n"));
    }
    s
}
