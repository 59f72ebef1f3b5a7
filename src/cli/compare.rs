//! `glossmeter compare`: predictions set beside an instrument sheet, one table, one summary and one exit
//! status for all its samples. The reading of the sheet, the statistics, the verdicts and the baseline checks
//! are library functions (`comparison::sheet`, `comparison`); this module parses the arguments and formats.
//! Colour sheets (L*, a*, b* on colour geometries) are predicted by the same plan, and each (sample, geometry)
//! gets its CIEDE2000 ΔE00 (`comparison::colour_differences`; `--max-de00` makes it the check).
use std::path::PathBuf;

use crate::cli::common::{pad_table, readings_status, ColourArgs};
use crate::cli::output::{Existing, OutputTarget};
use crate::comparison::sheet::{self, Sheet};
use crate::comparison::{self, ColourDifference, Comparison, Drift, Recipes, Verdict, VerdictRule};
use crate::instrument::plan::DEFAULT_RTOL;
use crate::report;
use crate::report::junit;
use crate::request::{CompareRequest, SheetRequest};
use crate::{Error, Result};

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CompareFormat {
    Table,
    Json,
    Csv,
    /// JUnit XML, one test case per (sample, reading), for CI servers.
    Junit,
}

#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    /// `[RECIPE] SHEET`: the recipe (JSON) for every sample, then the sheet (CSV, or an .xlsx/.xls/.ods
    /// workbook; see docs/instrument.md §Sheets). Without RECIPE, samples take theirs from --recipe-dir /
    /// --recipe. Either may be `-`, standard input.
    #[arg(num_args = 1..=2, required = true, value_name = "[RECIPE] SHEET")]
    pub paths: Vec<PathBuf>,
    /// Take each sample's recipe from DIR/<sample>.json.
    #[arg(long, value_name = "DIR")]
    pub recipe_dir: Option<PathBuf>,
    /// The recipe of one sample (repeatable); takes precedence over --recipe-dir.
    #[arg(long = "recipe", value_name = "SAMPLE=FILE")]
    pub recipes: Vec<String>,
    /// The separator of a text sheet: `,`, `;` or `tab` (default: detected from the header line).
    #[arg(long)]
    pub delimiter: Option<String>,
    /// The sheet of a workbook (.xlsx, .xls, .ods) to read; default: its first sheet.
    #[arg(long, value_name = "NAME")]
    pub sheet_name: Option<String>,
    /// The line (or workbook row, 1-based) of the sheet's header; the rows above it are title and metadata
    /// rows (default: the first row naming known columns, else the first row).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub header_row: Option<u64>,
    /// Skip a column the reader does not know (repeatable; case and spaces do not matter).
    #[arg(long = "ignore-column", value_name = "HEADER")]
    pub ignore_columns: Vec<String>,
    /// Standard errors of the mean allowed for repeated readings (k·s/√n).
    #[arg(short = 'k', long = "k", default_value_t = crate::request::DEFAULT_K)]
    pub k: f64,
    /// Allowed |predicted − measured| in the reading's unit, for rows without an `uncertainty`: a number for
    /// every reading, or per reading (repeatable): `gloss=2`, `haze=5`, `astm-e430-30/doi=3` (the most specific
    /// key applies).
    #[arg(long, value_name = "[KEY=]NUMBER")]
    pub tolerance: Vec<String>,
    /// A previous `measure` or `compare` JSON: fail any prediction that moved by more than both error estimates.
    #[arg(long, value_name = "PREVIOUS.json")]
    pub baseline: Option<PathBuf>,
    // The help is written from the one default tolerance, not a copy of its value.
    #[arg(long, help = format!(
        "Relative tolerance of the predictions (default {DEFAULT_RTOL:e}; for a measured table, by default a \
         quarter of each integral's data uncertainty, never tighter than {DEFAULT_RTOL:e}: given here, it is used \
         as given, tables too)"
    ))]
    pub rtol: Option<f64>,
    /// Output: an aligned table, JSON (`schema --output-format compare`), CSV or JUnit XML.
    #[arg(long, value_enum, default_value_t = CompareFormat::Table)]
    pub format: CompareFormat,
    /// Write to this new file instead of stdout (`-`: stdout; an existing file is refused before any work).
    #[arg(long, short = 'o')]
    pub output: Option<PathBuf>,
    /// Exit 0 even if a prediction did not converge within its budget (the comparison is still made).
    #[arg(long)]
    pub allow_unconverged: bool,
    /// Largest allowed CIEDE2000 ΔE00 between a sample's L*, a*, b* and the prediction (exit 1 above it); it is
    /// then the verdict of those rows when they have no allowance of their own.
    #[arg(long)]
    pub max_de00: Option<f64>,
    #[command(flatten)]
    pub colour: ColourArgs,
    /// Evaluation budget of each aperture integral, as in `measure` (deterministic: the same bits on every
    /// machine); a reading whose integral runs out is marked not converged.
    #[arg(long, value_name = "N", default_value_t = crate::instrument::plan::PlanOptions::default().max_evals)]
    pub max_evals: usize,
    /// Also draw the residuals (predicted − measured) with the allowance and the verdict per reading (FILE.png
    /// or FILE.svg, never overwritten).
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

/// The request of a command line (the one place where `compare`'s arguments become the library's).
pub fn request(a: &CompareArgs) -> CompareRequest {
    CompareRequest {
        k: a.k,
        tolerance: None,
        tolerances: a.tolerance.clone(),
        max_de00: a.max_de00,
        plan: a.colour.plan(a.rtol, a.max_evals),
        sheet: SheetRequest {
            delimiter: a.delimiter.clone(),
            ignore_columns: a.ignore_columns.clone(),
            sheet_name: a.sheet_name.clone(),
            header_row: a.header_row.map(|n| n as usize),
        },
    }
}

pub fn run(a: CompareArgs, existing: Existing) -> Result<()> {
    let request = request(&a);
    let rule = request.rule()?;
    let plan_options = request.plan.options()?;
    if let Some(p) = &a.plot {
        crate::cli::plot::check_plot_path(p, "--plot", existing)?;
    }
    let max_de00 = request.max_de00()?;
    let target = OutputTarget::new(a.output.as_deref(), "--output", existing)?;
    let (default, sheet_path) = match a.paths.as_slice() {
        [s] => (None, s.clone()),
        [r, s] => (Some(r.clone()), s.clone()),
        _ => return Err(Error::Usage("give [RECIPE] SHEET".into())),
    };
    if default.is_none() && a.recipe_dir.is_none() && a.recipes.is_empty() {
        return Err(Error::Usage(
            "no recipe: give RECIPE SHEET, or SHEET with --recipe-dir DIR or --recipe SAMPLE=FILE".into(),
        ));
    }
    let mut per_sample = vec![];
    for r in &a.recipes {
        // Split at the last `=`: a sample name may hold `=` (instrument sheets' names are free text), a
        // recipe's file name seldom does.
        let Some((s, f)) = r.rsplit_once('=') else {
            return Err(Error::Usage(format!("--recipe takes SAMPLE=FILE, got `{r}`")));
        };
        per_sample.push((s.to_string(), PathBuf::from(f)));
    }
    if let Some(d) = &a.recipe_dir {
        if !d.is_dir() {
            return Err(Error::Usage(format!("--recipe-dir {}: not a directory", d.display())));
        }
    }
    crate::input::at_most_one_stdin(
        a.paths.iter().chain(&a.baseline).map(PathBuf::as_path).chain(per_sample.iter().map(|(_, f)| f.as_path())),
    )?;
    let options = request.sheet.options()?;
    // Standard input, if one of them is `-`, is read here, before any of them is parsed.
    let mut stdin = crate::input::Stdin::default();
    let default = default.map(|p| stdin.open_text(&p, "recipe")).transpose()?;
    let per_sample =
        per_sample.into_iter().map(|(s, p)| Ok((s, stdin.open_text(&p, "recipe")?))).collect::<Result<Vec<_>>>()?;
    let baseline = a.baseline.as_deref().map(|p| stdin.open_text(p, "baseline")).transpose()?;
    let sheet_source = stdin.open_text(&sheet_path, "sheet")?;
    let recipes = Recipes { default, dir: a.recipe_dir.clone(), per_sample };
    let baseline = baseline.as_ref().map(comparison::load_baseline_source).transpose()?;
    let sheet = sheet::load_source(&sheet_source, &options)?;
    let mut cmp = comparison::compare_sheet(&sheet, &recipes, &rule, &plan_options)?;
    let des = comparison::colour_differences(&mut cmp, max_de00);
    let drift = match &baseline {
        Some(b) => comparison::check_baseline(
            cmp.iter().filter_map(|c| c.predicted.as_ref().map(|p| (c.material.as_str(), p))),
            b,
        ),
        None => vec![],
    };
    let text = match a.format {
        CompareFormat::Table => table(&sheet, &cmp, &rule, &drift, baseline.is_some()) + &de_table(&des),
        CompareFormat::Json => {
            report::compare::json_doc(&sheet, &cmp, &rule, &drift, a.baseline.as_deref(), &des).text()
        }
        CompareFormat::Csv => report::compare::csv(&cmp)?,
        CompareFormat::Junit => junit::compare(&sheet, &cmp, &drift)?,
    };
    target.write(&text)?;
    if let Some(p) = &a.plot {
        crate::cli::pictures::write_comparison(p, &cmp, existing)?;
    }
    let outside = cmp.iter().filter(|c| c.verdict == Verdict::Outside).count();
    let unchecked = cmp.iter().filter(|c| c.verdict.why_unchecked().is_some()).count();
    let moved = drift.iter().filter(|d| d.moved).count();
    if baseline.is_some() && drift.is_empty() {
        return Err(Error::Check(
            "the baseline matched none of the predictions (no material, geometry and reading in common): nothing \
             was checked"
                .into(),
        ));
    }
    let de_outside = des.iter().filter(|d| d.inside == Some(false)).count();
    if de_outside > 0 {
        return Err(Error::Check(format!("{de_outside} of {} colour(s) with ΔE00 above --max-de00", des.len())));
    }
    if outside + unchecked + moved > 0 {
        return Err(Error::Check(format!(
            "of {} reading(s), {outside} outside the allowance, {unchecked} could not be checked (see the notes in \
             the output); {moved} moved from the baseline",
            cmp.len()
        )));
    }
    let predicted: Vec<_> = cmp.iter().filter_map(|c| c.predicted.clone()).collect();
    readings_status(&predicted, a.allow_unconverged)
}

/// A reading's number as its instrument displays it: rounded to the display step of its unit
/// (`report::display_step`: 0.1 GU, HU, DOI; 0.01 for colour coordinates), "—" without one.
fn fmt(v: Option<f64>, step: f64) -> String {
    v.filter(|x| x.is_finite()).map(|x| crate::report::displayed(x, step)).unwrap_or_else(|| "—".into())
}

/// The display step of a comparison's row: that of the predicted reading's unit; a row without a prediction
/// takes the step its reading's name implies (a colour coordinate 0.01, else 0.1).
fn step_of(c: &Comparison) -> f64 {
    let unit = match &c.predicted {
        Some(p) => p.unit.as_str(),
        None if ["X", "Y", "Z", "L*", "a*", "b*", "C*"].contains(&c.group.reading.as_str()) => "",
        None => "GU",
    };
    crate::report::display_step(unit)
}

/// Counts of the verdicts, for the summary line.
pub fn summary(cmp: &[Comparison]) -> String {
    let count = |f: &dyn Fn(&Verdict) -> bool| cmp.iter().filter(|c| f(&c.verdict)).count();
    format!(
        "{} reading(s) of {} sample(s): {} ok, {} outside, {} unchecked (no value), {} unchecked (no allowance), {} not predicted",
        cmp.len(),
        {
            let mut s: Vec<&str> = cmp.iter().map(|c| c.group.sample.as_str()).collect();
            s.sort();
            s.dedup();
            s.len()
        },
        count(&|v| *v == Verdict::Inside),
        count(&|v| *v == Verdict::Outside),
        count(&|v| matches!(v, Verdict::NoValue(_))),
        count(&|v| *v == Verdict::NoAllowance),
        count(&|v| matches!(v, Verdict::NotPredicted(_))),
    )
}

fn table(sheet: &Sheet, cmp: &[Comparison], rule: &VerdictRule, drift: &[Drift], with_baseline: bool) -> String {
    // Ten columns, so that a sheet's table fits 120 columns: the material is named once per sample below the
    // table, min and max are in the CSV and JSON, the standard deviation stands beside the mean.
    let head = [
        "sample",
        "geometry",
        "reading",
        "n",
        "mean ± std",
        "predicted",
        "num. error",
        "difference",
        "allowance",
        "verdict",
    ];
    let mut rows = vec![head.map(String::from).to_vec()];
    let mut notes = vec![];
    let mut materials: Vec<String> = vec![];
    for c in cmp {
        let p = c.predicted.as_ref();
        let v = p.and_then(|p| p.value);
        let s = c.group.stats;
        let material = format!("{}: {} ({})", c.group.sample, c.material, c.recipe);
        if !materials.contains(&material) {
            materials.push(material);
        }
        // Readings, differences and allowances as the instrument displays them; the standard deviation of the
        // sheet's readings one digit finer (docs/instrument.md §Sheets). CSV and JSON keep every digit.
        let step = step_of(c);
        let mean = fmt(Some(s.mean), step);
        rows.push(vec![
            c.group.sample.clone(),
            c.group.geometry.clone(),
            c.group.reading.clone(),
            s.n.to_string(),
            if s.n > 1 { format!("{mean} ± {}", fmt(Some(s.std), step / 10.0)) } else { mean },
            fmt(v, step),
            p.filter(|p| p.value.is_some()).map(|p| format!("{:.1e}", p.error_estimate)).unwrap_or("—".into()),
            fmt(c.difference(), step),
            fmt(c.allowance.map(|a| a.total()), step),
            c.verdict.label().into(),
        ]);
        let why = match &c.verdict {
            Verdict::NotPredicted(why) => Some(format!("not predicted: {why}")),
            v => v.why_unchecked().map(|w| format!("not checked: {w}")),
        };
        if let Some(why) = why {
            notes.push(format!(
                "line {} ({} {} {}): {why}",
                c.group.lines[0], c.group.sample, c.group.geometry, c.group.reading
            ));
        }
    }
    let mut s = match &sheet.workbook_sheet {
        Some(w) => format!("{} (sheet \"{w}\"): predictions against the sheet\n", sheet.file),
        None => format!("{}: predictions against the sheet\n", sheet.file),
    };
    for (k, v) in &sheet.metadata {
        s.push_str(&format!("# {k}: {v}\n"));
    }
    s.push('\n');
    s.push_str(&pad_table(&rows, &[3, 4, 5, 6, 7, 8]));
    s.push('\n');
    for m in &materials {
        s.push_str(&format!("sample {m}\n"));
    }
    // With a recipe's stated uncertainties, the prediction's own uncertainty u_pred joins the mean's spread
    // (docs/instrument.md §The prediction's uncertainty).
    let spread = if cmp.iter().any(|c| c.prediction_uncertainty.is_some()) {
        format!("{}·√(s²/n + u_pred²)", rule.k)
    } else {
        format!("{}·s/√n", rule.k)
    };
    s.push_str(&format!(
        "difference = predicted − measured; num. error = the prediction's numerical error estimate\nallowance = \
         {spread} + stated uncertainty + num. error\n{}\n",
        summary(cmp)
    ));
    s.push_str(&super::format::colour_line(cmp.iter().filter_map(|c| c.predicted.as_ref()).map(|p| p.colour)));
    for c in cmp {
        if let (Some(u), Some(a)) = (&c.prediction_uncertainty, &c.allowance) {
            notes.push(format!(
                "line {} ({} {} {}): u_pred = {:.3} from {}; allowance {:.3} = {:.3} + {:.3} + {:.1e}",
                c.group.lines[0],
                c.group.sample,
                c.group.geometry,
                c.group.reading,
                u.u,
                u.contributions
                    .iter()
                    .map(|p| format!("{} ({:.3})", p.pointer, p.contribution))
                    .collect::<Vec<_>>()
                    .join(", "),
                a.total(),
                a.random,
                a.stated,
                a.prediction
            ));
        }
    }
    if sheet.statistics_checked > 0 {
        s.push_str(&format!(
            "statistics: {} stated value(s) (mean, std, min, max, range columns) agree with the readings\n",
            sheet.statistics_checked
        ));
    }
    for n in notes {
        s.push_str(&format!("note: {n}\n"));
    }
    if with_baseline {
        let moved: Vec<&Drift> = drift.iter().filter(|d| d.moved).collect();
        s.push_str(&format!("baseline: {} prediction(s) checked, {} moved\n", drift.len(), moved.len()));
        for d in moved {
            s.push_str(&format!(
                "moved: {} {} {}: {} then, {} now (allowed {:.1e})\n",
                d.material, d.geometry, d.reading, d.then, d.now, d.allowed
            ));
        }
    }
    s
}

fn de_table(des: &[ColourDifference]) -> String {
    if des.is_empty() {
        return String::new();
    }
    let mut s = String::from("\nColour differences (CIEDE2000, kL = kC = kH = 1):\n");
    for d in des {
        s.push_str(&format!(
            "  {} {} (line {}): measured L*a*b* ({:.2}, {:.2}, {:.2}), predicted ({:.2}, {:.2}, {:.2}): ΔE00 = {:.3}{}\n",
            if d.sample.is_empty() { "-" } else { &d.sample },
            d.geometry,
            d.line,
            d.measured.l,
            d.measured.a,
            d.measured.b,
            d.predicted.l,
            d.predicted.a,
            d.predicted.b,
            d.de00,
            match d.inside {
                Some(true) => "  ok",
                Some(false) => "  OUTSIDE",
                None => "",
            }
        ));
    }
    s
}
