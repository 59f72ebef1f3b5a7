//! The command-line layer: argument parsing and output formatting only. Every computation lives in the
//! library modules; this module turns their results into tables, JSON or CSV, and their errors into a
//! message on stderr and a non-zero exit status: 2 for bad input, unreadable files or usage; 1 when a reading has
//! no finite value or a comparison fails.
use std::io::Write;
use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};

use crate::colorimetry::{Conditions, Illuminant, Observer};
use crate::instrument::plan::{Plan, PlanOptions};
use crate::instrument::standards;
use crate::{recipe, report, resolve_geometries, Error, Result};

pub mod batch;
pub mod compare;
pub mod convergence;
pub mod fit;
pub mod format;
pub mod junit;
pub mod output;
pub mod pictures;
pub mod plot;
pub mod profile;
pub mod sweep;

pub use output::{print, Target, STDOUT};

#[derive(Parser, Debug)]
#[command(
    name = "glossmeter",
    version,
    about = "A virtual gloss, haze and DOI meter: reads a BRDF through the apertures of ASTM D523 / ISO 2813 / ASTM E430 / ISO 13803 instruments."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    Table,
    Json,
    Csv,
}

/// The conditions of colour readings (colour geometries only; gloss is luminous whatever they say).
#[derive(clap::Args, Debug, Clone)]
pub struct ColourArgs {
    /// Illuminant of colour readings: D65, D50, A or C.
    #[arg(long, default_value = "D65")]
    pub illuminant: String,
    /// Observer of colour readings: 10 (CIE 1964 10°) or 2 (CIE 1931 2°).
    #[arg(long, default_value = "10")]
    pub observer: String,
}

impl ColourArgs {
    pub fn conditions(&self) -> Result<Conditions> {
        Ok(Conditions { illuminant: Illuminant::parse(&self.illuminant)?, observer: Observer::parse(&self.observer)? })
    }
}

/// The outputs whose JSON Schema `glossmeter schema --output-format` prints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OutputSchema {
    Measure,
    Compare,
    Sweep,
    Fit,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Read materials (recipe JSON files, or directories of them) through instrument geometries.
    Measure {
        /// The recipe (JSON; see `glossmeter schema` and docs/recipe-format.md); several recipes or a directory
        /// are measured together in parallel, in one table / CSV / JSON with a material column.
        #[arg(required = true, num_args = 1..)]
        recipes: Vec<PathBuf>,
        /// A previous `measure` or `compare` JSON: exit 1 if a reading moved by more than both error estimates.
        #[arg(long, value_name = "PREVIOUS.json")]
        baseline: Option<PathBuf>,
        /// A shipped geometry id (repeatable); see `glossmeter standards`. Default: ASTM D523 20°/60°/85°,
        /// ASTM E430 30° (gloss, haze, DOI), ISO 13803 20° haze and the ASTM D4039 haze index.
        #[arg(long = "geometry", short = 'g')]
        geometries: Vec<String>,
        /// A user geometry file in the standards format (repeatable).
        #[arg(long = "geometry-file")]
        geometry_files: Vec<PathBuf>,
        /// Relative tolerance of every reading.
        #[arg(long, default_value_t = 1e-6)]
        rtol: f64,
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
        /// Print the measurement plan before measuring.
        #[arg(long)]
        explain: bool,
        /// Leave the wall-time column out (everything else is reproducible bit for bit).
        #[arg(long)]
        no_timing: bool,
        /// Write the result to this new file instead of stdout (an existing file is refused before any work).
        #[arg(long, short = 'o')]
        output: Option<PathBuf>,
        /// Exit 0 even if a reading did not converge within its budget (it is still marked in the output).
        #[arg(long)]
        allow_unconverged: bool,
        /// Evaluation budget of each aperture integral; a reading whose integral runs out is "not converged".
        #[arg(long, default_value_t = PlanOptions::default().max_evals)]
        max_evals: usize,
        #[command(flatten)]
        colour: ColourArgs,
        /// Wall-clock budget of the whole measurement, seconds (all its integrals share it); a reading whose
        /// integral runs out is "not converged" and its value depends on the machine's speed. 0: none.
        #[arg(long, default_value_t = crate::instrument::plan::DEFAULT_MAX_SECONDS)]
        max_seconds: f64,
        /// Also read every reading at the corners of the tolerances the standard data allow (and across the
        /// plausible range of assumed numbers); reports the minimum and maximum (table and JSON).
        #[arg(long)]
        envelope: bool,
    },
    /// List the shipped geometries, or show one with the provenance of every number.
    Standards {
        /// A geometry id.
        id: Option<String>,
    },
    /// Print the JSON Schema of the recipe format, or of an output (`--output-format measure|compare|sweep|fit`).
    Schema {
        #[arg(long, value_enum)]
        output_format: Option<OutputSchema>,
    },
    /// Measure a template recipe over a grid or a Latin hypercube of JSON Pointer paths (CSV or JSON lines).
    Sweep(sweep::SweepArgs),
    /// Set predictions beside a glossmeter sheet (CSV); exits 1 if a reading falls outside its uncertainty.
    Compare(compare::CompareArgs),
    /// Error against run time over a sweep of tolerances (table, CSV, JSON, and a log–log plot).
    Convergence(convergence::ConvergenceArgs),
    /// Fit recipe parameters (JSON Pointers) to readings, with standard errors and an identifiability
    /// verdict; exits 1 if the fit did not converge, hit a bound or is not identifiable (docs/inverse.md).
    Fit(fit::FitArgs),
    /// Draw a picture (PNG or SVG): the in-plane BRDF section with the apertures, or readings against a parameter.
    Plot(pictures::PlotArgs),
    /// The goniophotometric profile about the 20° specular direction (Rhopoint IQ-class 512-pixel array):
    /// one row per pixel, angle and normalised reading with their error estimates (CSV or JSON).
    Profile(profile::ProfileArgs),
}

/// Run the CLI; returns the process exit status.
pub fn run<I, T>(args: I) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() { 2 } else { 0 };
        }
    };
    match dispatch(cli) {
        Ok(()) => 0,
        // A reader that went away (`glossmeter standards | head -1`) is not an error: end quietly, as
        // ripgrep does. Only standard output is treated so; a file that cannot be written is an error.
        Err(Error::Io { file, source }) if file == STDOUT && source.kind() == std::io::ErrorKind::BrokenPipe => 0,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: {e}");
            exit_status(&e)
        }
    }
}

/// The exit status of an error (docs/instrument.md §Exit statuses): 2 for bad input, unreadable or unwritable
/// files and usage; 1 for a result that is not one (no finite value, not converged, a failed check).
pub fn exit_status(e: &Error) -> i32 {
    match e {
        Error::Input { .. } | Error::Usage(_) | Error::Io { .. } => 2,
        Error::Numeric(_) | Error::Check(_) => 1,
    }
}

fn dispatch(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Measure {
            recipes,
            baseline,
            geometries,
            geometry_files,
            rtol,
            format,
            explain,
            no_timing,
            output,
            allow_unconverged,
            max_evals,
            colour,
            max_seconds,
            envelope,
        } => {
            check_rtol(rtol)?;
            let colour = colour.conditions()?;
            if max_evals == 0 {
                return Err(Error::Usage("--max-evals must be at least 1".into()));
            }
            if !(max_seconds.is_finite() && max_seconds >= 0.0) {
                return Err(Error::Usage(format!(
                    "--max-seconds must be a finite number of seconds ≥ 0 (0: no wall-clock budget), got {}",
                    crate::error::given(max_seconds)
                )));
            }
            let max_seconds = (max_seconds > 0.0).then_some(max_seconds);
            if envelope && format == Format::Csv {
                return Err(Error::Usage(
                    "--envelope is reported in the table and JSON formats; use --format table or json".into(),
                ));
            }
            let target = Target::new(output.as_deref(), "--output")?;
            let baseline_file = baseline.as_ref().map(|p| p.display().to_string());
            let baseline = baseline.as_deref().map(crate::comparison::load_baseline).transpose()?;
            let options = PlanOptions { rtol, max_evals, max_seconds, colour, ..PlanOptions::default() };
            if recipes.len() > 1 || recipes[0].is_dir() {
                if explain {
                    return Err(Error::Usage("--explain takes one recipe".into()));
                }
                let batch = Batch {
                    baseline: baseline.as_deref().map(|b| (b, baseline_file.clone().unwrap_or_default())),
                    format,
                    timing: !no_timing,
                    allow_unconverged,
                };
                return measure_batch(&recipes, &geometries, &geometry_files, &options, &batch, &target);
            }
            let material = recipe::load_file(&recipes[0])?;
            let geos = resolve_geometries(&geometries, &geometry_files)?;
            let plan = Plan::compile(material.brdf.clone(), geos.clone(), options.clone())?;
            let mut text = String::new();
            if explain {
                let e = plan.explain();
                match format {
                    Format::Table => text.push_str(&format!("{e}\n")),
                    // Keep machine formats parseable: the plan goes to stderr.
                    _ => eprint!("{e}"),
                }
            }
            let run = plan.run();
            let evaluations = run.evaluations();
            let readings = run.readings;
            let envelopes = if envelope {
                Some(crate::instrument::envelope::read(material.brdf.clone(), &geos, &readings, options)?)
            } else {
                None
            };
            let drift = baseline
                .as_deref()
                .map(|b| crate::comparison::check_baseline(readings.iter().map(|r| (material.name.as_str(), r)), b));
            text.push_str(&match (format, &envelopes) {
                (Format::Table, None) => format::table(&material, &readings, !no_timing),
                (Format::Table, Some(e)) => {
                    format::table(&material, &readings, !no_timing) + &format::envelope_table(&readings, e)
                }
                (Format::Json, e) => {
                    let mut doc = report::json_doc(&material, &readings, !no_timing);
                    doc["evaluations"] = serde_json::json!(evaluations);
                    let doc = with_baseline(doc, drift.as_deref(), baseline_file.clone());
                    report::pretty(&match e {
                        None => doc,
                        Some(e) => report::json_with_envelope(doc, e),
                    })
                }
                (Format::Csv, _) => report::csv(&readings, !no_timing)?,
            });
            if let (Format::Table, Some(d)) = (format, &drift) {
                text.push_str(&batch::drift_text(d));
            }
            target.write(&text)?;
            check_drift(drift.as_deref())?;
            readings_status(&readings, allow_unconverged)
        }
        Command::Standards { id } => {
            let text = match id {
                None => standards::builtin_all()?.iter().map(|g| standards::list_line_any(g) + "\n").collect(),
                Some(id) => standards::describe_any(&standards::find(&id)?) + "\n",
            };
            print(&text)
        }
        Command::Convergence(args) => convergence::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Fit(args) => fit::run(args),
        Command::Plot(args) => pictures::run(args),
        Command::Profile(args) => profile::run(args),
        Command::Sweep(args) => sweep::run(args),
        Command::Schema { output_format } => {
            let schema = match output_format {
                None => recipe::schema::schema(),
                Some(OutputSchema::Measure) => crate::report::schema::measure(),
                Some(OutputSchema::Compare) => crate::report::schema::compare(),
                Some(OutputSchema::Sweep) => crate::report::schema::sweep(),
                Some(OutputSchema::Fit) => crate::report::schema::fit(),
            };
            let text = serde_json::to_string_pretty(&schema)
                .map_err(|e| Error::Numeric(format!("the schema does not serialise: {e}")))?;
            print(&(text + "\n"))
        }
    }
}

/// The verdict on a set of readings (docs/instrument.md §Exit statuses): an error (exit 1) if one has no
/// finite value, or did not converge (unless allowed).
pub fn readings_status(readings: &[crate::Reading], allow_unconverged: bool) -> Result<()> {
    // The hue of a neutral colour has no value by definition, not by failure.
    let neutral_hue = |r: &crate::Reading| r.problem.as_deref().is_some_and(|p| p.starts_with(NEUTRAL_HUE));
    let missing = readings.iter().filter(|r| r.value.is_none() && !neutral_hue(r)).count();
    if missing > 0 {
        return Err(Error::Numeric(format!(
            "{missing} of {} reading(s) have no finite value (see the notes in the output)",
            readings.len()
        )));
    }
    let unconverged = readings.iter().filter(|r| !r.converged).count();
    if unconverged > 0 && !allow_unconverged {
        return Err(Error::Check(format!(
            "{unconverged} of {} reading(s) did not converge to the tolerance within the budgets (evaluations \
             or wall-clock time; their values are best estimates; --allow-unconverged exits 0 anyway)",
            readings.len()
        )));
    }
    Ok(())
}

/// How the hue reading of a neutral colour (C*ab = 0) explains its missing value (`plan::colour_value`).
pub const NEUTRAL_HUE: &str = "neutral colour";

/// `--rtol` in (0, 1), checked before any work.
pub fn check_rtol(rtol: f64) -> Result<()> {
    if !(rtol.is_finite() && rtol > 0.0 && rtol < 1.0) {
        return Err(Error::Usage(format!("--rtol must be a number in (0, 1), got {}", crate::error::given(rtol))));
    }
    Ok(())
}
/// A text table: a header row, a rule, then the rows; columns listed in `right` are right-aligned. Padding
/// is done by hand (a `format!` width is limited to 65 535).
pub fn pad_table(rows: &[Vec<String>], right: &[usize]) -> String {
    let ncol = rows.first().map(|r| r.len()).unwrap_or(0);
    let w: Vec<usize> = (0..ncol).map(|i| rows.iter().map(|r| r[i].chars().count()).max().unwrap_or(0)).collect();
    let mut s = String::new();
    for (k, r) in rows.iter().enumerate() {
        let cells: Vec<String> = r
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let pad = " ".repeat(w[i] - v.chars().count());
                if right.contains(&i) {
                    format!("{pad}{v}")
                } else {
                    format!("{v}{pad}")
                }
            })
            .collect();
        s.push_str(cells.join("  ").trim_end());
        s.push('\n');
        if k == 0 {
            s.push_str(&w.iter().map(|n| "-".repeat(*n)).collect::<Vec<_>>().join("  "));
            s.push('\n');
        }
    }
    s
}

/// Add the baseline checks to a JSON document (when a baseline was given).
fn with_baseline(
    mut doc: serde_json::Value,
    drift: Option<&[crate::comparison::Drift]>,
    file: Option<String>,
) -> serde_json::Value {
    if let (Some(d), Some(file)) = (drift, file) {
        doc["baseline"] = serde_json::json!({
            "file": file,
            "checks": d.iter().map(compare::drift_json).collect::<Vec<_>>(),
            "moved": d.iter().filter(|x| x.moved).count(),
        });
    }
    doc
}

/// Exit status 1 when a baseline reading moved.
fn check_drift(drift: Option<&[crate::comparison::Drift]>) -> Result<()> {
    let moved = drift.map(|d| d.iter().filter(|x| x.moved).count()).unwrap_or(0);
    if moved > 0 {
        return Err(Error::Check(format!(
            "{moved} reading(s) moved from the baseline by more than both error estimates"
        )));
    }
    Ok(())
}

/// How a batch `measure` reports.
struct Batch<'a> {
    baseline: Option<(&'a [crate::comparison::BaselineEntry], String)>,
    format: Format,
    timing: bool,
    allow_unconverged: bool,
}

/// `measure` of several recipes or a directory.
fn measure_batch(
    paths: &[PathBuf],
    geometries: &[String],
    geometry_files: &[PathBuf],
    options: &PlanOptions,
    how: &Batch,
    target: &Target,
) -> Result<()> {
    let files = crate::batch::recipe_files(paths)?;
    let materials = crate::batch::load_all(&files)?;
    let geos = resolve_geometries(geometries, geometry_files)?;
    let runs = crate::batch::run_many(&materials, &geos, options)?;
    let evaluations: Vec<usize> = runs.iter().map(|e| e.evaluations()).collect();
    let readings: Vec<Vec<crate::Reading>> = runs.into_iter().map(|e| e.readings).collect();
    let drift = how.baseline.as_ref().map(|(b, _)| {
        crate::comparison::check_baseline(
            materials.iter().zip(&readings).flat_map(|(m, rs)| rs.iter().map(move |r| (m.name.as_str(), r))),
            b,
        )
    });
    let text = match how.format {
        Format::Table => {
            let mut t = batch::table(&materials, &readings, how.timing);
            if let Some(d) = &drift {
                t.push_str(&batch::drift_text(d));
            }
            t
        }
        Format::Json => report::pretty(&with_baseline(
            batch::with_evaluations(batch::json_doc(&materials, &readings, how.timing), &evaluations),
            drift.as_deref(),
            how.baseline.as_ref().map(|(_, f)| f.clone()),
        )),
        Format::Csv => batch::csv(&materials, &readings, how.timing)?,
    };
    target.write(&text)?;
    check_drift(drift.as_deref())?;
    let all: Vec<crate::Reading> = readings.into_iter().flatten().collect();
    readings_status(&all, how.allow_unconverged)
}
