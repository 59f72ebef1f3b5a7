//! The command-line layer: argument parsing and output formatting only. Every computation lives in the
//! library modules; this module turns their results into tables, JSON or CSV (the readings' documents are
//! written by `crate::report`), and their errors into a message on stderr and a non-zero exit status: 2 for bad
//! input, unreadable files or usage; 1 when a reading has no finite value or a comparison fails.
//!
//! The folder, by stage:
//! * [`args`]: the command line's definitions (clap: [`args::Cli`], [`args::Command`], [`args::OutputSchema`]);
//! * [`common`]: what the subcommands share ([`common::Format`], [`common::ColourArgs`], [`common::check_rtol`],
//!   [`common::readings_status`], and [`common::pad_table`], through which every text table goes);
//! * `mod.rs` (this): [`run`] runs a command line and dispatches it, [`exit_status`] maps an error to its status;
//! * a file per subcommand, which parses its own arguments and formats its results: [`batch`] (`measure` of
//!   many recipes), [`compare`], [`convergence`], [`fit`], [`pictures`] (`plot`), [`profile`], [`sweep`], [`topography`];
//! * the writers: [`format`](mod@format) the text tables of `measure` ([`format::table`],
//!   [`format::envelope_table`]), [`output`] the files ([`output::OutputTarget`]: a new file whole or not at
//!   all, never overwriting, or standard output), [`plot`] the pictures (PNG or SVG with an embedded font),
//!   [`junit`] the JUnit XML of `compare`, [`progress`] the progress bar of `sweep` (rate and time left from the
//!   work done).
use std::io::Write;
use std::path::PathBuf;

use clap::Parser;

use crate::instrument::plan::{Plan, PlanOptions};
use crate::instrument::standards;
use crate::{recipe, report, Error, Result};

pub mod args;
pub mod batch;
pub mod common;
pub mod compare;
pub mod convergence;
pub mod fit;
pub mod format;
pub mod output;
pub mod pictures;
pub mod plot;
pub mod profile;
pub mod progress;
pub mod sweep;
pub mod topography;

use args::{Cli, Command, OutputSchema};
use common::{readings_status, Format};
use output::{print, OutputTarget, STDOUT};

/// Run the CLI; returns the process exit status. `glossmeter serve` needs the server, which stands above
/// the command line: the binary passes it in through [`run_with`]; here it is refused.
pub fn run<I, T>(args: I) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    run_with(args, &|_| Err(Error::Usage("this program has no server: run the glossmeter binary".into())))
}

/// The server of `glossmeter serve`, given by the caller ([`run_with`]).
pub type Serve<'a> = &'a dyn Fn(&crate::request::ServeRequest) -> Result<()>;

/// Run the CLI with `serve` as the server of `glossmeter serve`; returns the process exit status.
pub fn run_with<I, T>(args: I, serve: Serve) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            // Help and version go to standard output: a write that fails there (a full disk) is an error like
            // any other output's, not a silent exit 0 (docs/instrument.md §Exit statuses).
            let printed = e.print().and_then(|()| std::io::stdout().flush());
            return match printed {
                Err(source) if !e.use_stderr() && source.kind() != std::io::ErrorKind::BrokenPipe => {
                    let _ = writeln!(std::io::stderr(), "error: {STDOUT}: {source}");
                    2
                }
                _ if e.use_stderr() => 2,
                _ => 0,
            };
        }
    };
    let result = dispatch(cli, serve);
    match result {
        Ok(()) => 0,
        // A reader that went away (`glossmeter standards | head -1`) is not an error: end quietly, as
        // ripgrep does. Only standard output is treated so; a file that cannot be written is an error.
        Err(Error::Io { file, source }) if file == STDOUT && source.kind() == std::io::ErrorKind::BrokenPipe => 0,
        Err(e) => {
            // The library names arguments in its own words; the command line writes them as its flags.
            let _ = writeln!(std::io::stderr(), "error: {}", e.naming(&common::flag));
            exit_status(&e)
        }
    }
}

/// The exit status of an error (docs/instrument.md §Exit statuses): 2 for bad input, unreadable or unwritable
/// files and usage; 1 for a result that is not one (no finite value, not converged, a failed check).
pub fn exit_status(e: &Error) -> i32 {
    match e {
        Error::Input { .. } | Error::Usage(_) | Error::Argument(_) | Error::Io { .. } => 2,
        Error::Numeric(_) | Error::Check(_) => 1,
    }
}

fn dispatch(cli: Cli, #[allow(unused_variables)] serve: Serve) -> Result<()> {
    let existing = output::Existing::from_force(cli.force);
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
            let request = crate::request::MeasureRequest { plan: colour.plan(rtol, max_evals), max_seconds };
            let options = request.options()?;
            let max_seconds = options.max_seconds;
            // The limit is the whole command's, counted from here: the nominal readings and every envelope
            // variant share it (docs/instrument.md §Bounded work).
            let deadline =
                max_seconds.and_then(|s| crate::instrument::method::deadline_after(std::time::Instant::now(), s));
            if envelope && format == Format::Csv {
                return Err(Error::Usage(
                    "--envelope is reported in the table and JSON formats; use --format table or json".into(),
                ));
            }
            crate::input::at_most_one_stdin(
                recipes.iter().chain(&baseline).chain(&geometry_files).map(PathBuf::as_path),
            )?;
            let target = OutputTarget::new(output.as_deref(), "--output", existing)?;
            // Standard input, if an input is `-`, is read once, when that input's turn comes.
            let mut stdin = crate::input::Stdin::default();
            let baseline = baseline.as_deref().map(|p| stdin.open_text(p, "baseline")).transpose()?;
            let baseline_file = baseline.as_ref().map(crate::input::Source::name);
            let baseline = baseline.as_ref().map(crate::comparison::load_baseline_source).transpose()?;
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
                return measure_batch(&recipes, &geometries, &geometry_files, &options, &batch, &target, stdin);
            }
            let material = recipe::load_source(&stdin.open_text(&recipes[0], "recipe")?)?;
            let files = stdin.open_text_all(&geometry_files, "geometry file")?;
            let geos = crate::api::resolve_geometries_from(&geometries, &files, crate::DEFAULT_PANEL)?;
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
            let run = plan.run_until(deadline);
            let evaluations = run.evaluations();
            let readings = run.readings;
            // The recipe's stated uncertainties propagated to each reading (nothing is run without them).
            let uncertainties = match format {
                Format::Csv => vec![],
                _ => crate::comparison::propagation::propagate(&material, &geos, &options, &readings)?,
            };
            let envelopes = if envelope {
                Some(crate::instrument::envelope::read(material.brdf.clone(), &geos, &readings, options, deadline)?)
            } else {
                None
            };
            let drift = baseline
                .as_deref()
                .map(|b| crate::comparison::check_baseline(readings.iter().map(|r| (material.name.as_str(), r)), b));
            text.push_str(&match (format, &envelopes) {
                (Format::Table, None) => {
                    format::table(&material, &readings, !no_timing)
                        + &format::uncertainty_text(&readings, &uncertainties)
                }
                (Format::Table, Some(e)) => {
                    format::table(&material, &readings, !no_timing)
                        + &format::uncertainty_text(&readings, &uncertainties)
                        + &format::envelope_table(&readings, e)
                }
                (Format::Json, e) => {
                    let doc = report::measure::json_doc(&material, &readings, !no_timing, evaluations)
                        .with_uncertainties(&uncertainties)
                        .with_baseline(drift.as_deref(), baseline_file.clone());
                    match e {
                        None => doc,
                        Some(e) => doc.with_envelope(e),
                    }
                    .text()
                }
                (Format::Csv, _) => report::measure::csv(&readings, !no_timing)?,
            });
            if let (Format::Table, Some(d)) = (format, &drift) {
                text.push_str(&batch::drift_text(d));
            }
            target.write(&text)?;
            check_drift(drift.as_deref())?;
            if let Some(cut) = envelopes.as_ref().map(|e| &e.cut).filter(|c| !c.is_empty()) {
                return Err(Error::Numeric(format!(
                    "the wall-clock limit (--max-seconds, for the whole command) was reached before the tolerance \
                     envelope of {} was read: it is left out (null), since a partial one would depend on the \
                     machine's speed and load",
                    cut.join(", ")
                )));
            }
            readings_status(&readings, allow_unconverged)
        }
        Command::Standards { id } => {
            let text = match id {
                None => standards::builtin_all()?.iter().map(|g| standards::list_line_any(g) + "\n").collect(),
                Some(id) => standards::describe_any(&standards::find(&id)?) + "\n",
            };
            print(&text)
        }
        Command::Convergence(args) => convergence::run(args, existing),
        Command::Compare(args) => compare::run(args, existing),
        Command::Fit(args) => fit::run(args, existing),
        Command::Plot(args) => pictures::run(args, existing),
        Command::Profile(args) => profile::run(args, existing),
        Command::Sweep(args) => sweep::run(args, existing),
        Command::Topography(args) => topography::run(args, existing),
        #[cfg(feature = "serve")]
        Command::Serve(args) => serve(&args.request()),
        Command::Schema { output_format } => print(&schema_text(output_format)?),
        Command::Completions { shell } => {
            let mut bytes = Vec::new();
            clap_complete::generate(shell, &mut <Cli as clap::CommandFactory>::command(), "glossmeter", &mut bytes);
            print(&String::from_utf8_lossy(&bytes))
        }
        Command::Man => print(&man_page()?),
    }
}

/// `glossmeter schema`: the recipe format's JSON Schema, or an output document's.
fn schema_text(output_format: Option<OutputSchema>) -> Result<String> {
    let schema = match output_format {
        None => recipe::schema::schema(),
        Some(OutputSchema::Measure) => crate::report::schema::measure(),
        Some(OutputSchema::Compare) => crate::report::schema::compare(),
        Some(OutputSchema::Sweep) => crate::report::schema::sweep(),
        Some(OutputSchema::Fit) => crate::report::schema::fit(),
        Some(OutputSchema::Profile) => crate::report::schema::profile(),
        Some(OutputSchema::Convergence) => crate::report::schema::convergence(),
        Some(OutputSchema::Sheet) => crate::report::schema::sheet(),
        Some(OutputSchema::Topography) => crate::report::schema::topography(),
    };
    let text = serde_json::to_string_pretty(&schema)
        .map_err(|e| Error::Numeric(format!("the schema does not serialise: {e}")))?;
    Ok(text + "\n")
}

/// `glossmeter man`: the manual page, from the same argument definitions as `--help`.
fn man_page() -> Result<String> {
    let mut bytes = Vec::new();
    clap_mangen::Man::new(<Cli as clap::CommandFactory>::command())
        .render(&mut bytes)
        .map_err(|e| Error::Io { file: STDOUT.into(), source: e })?;
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// Exit status 1 when a baseline reading moved.
fn check_drift(drift: Option<&[crate::comparison::Drift]>) -> Result<()> {
    if drift.is_some_and(|d| d.is_empty()) {
        return Err(Error::Check(
            "the baseline matched none of the readings (no material, geometry and reading in common): nothing \
             was checked"
                .into(),
        ));
    }
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
    target: &OutputTarget,
    mut stdin: crate::input::Stdin,
) -> Result<()> {
    let files = crate::batch::recipe_files(paths)?;
    // Every recipe is loaded before any work; the first bad one is the error.
    let mut materials = Vec::with_capacity(files.len());
    for f in &files {
        materials.push(recipe::load_source(&stdin.open_text(f, "recipe")?)?);
    }
    let files = stdin.open_text_all(geometry_files, "geometry file")?;
    let geos = crate::api::resolve_geometries_from(geometries, &files, crate::DEFAULT_PANEL)?;
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
        Format::Json => report::measure::batch_json_doc(&materials, &readings, how.timing, &evaluations)
            // The recipes' stated uncertainties propagated to their readings (nothing is run without them).
            .with_uncertainties(
                &materials
                    .iter()
                    .zip(&readings)
                    .map(|(m, rs)| crate::comparison::propagation::propagate(m, &geos, options, rs))
                    .collect::<Result<Vec<_>>>()?,
            )
            .with_baseline(drift.as_deref(), how.baseline.as_ref().map(|(_, f)| f.clone()))
            .text(),
        Format::Csv => report::measure::batch_csv(&materials, &readings, how.timing)?,
    };
    target.write(&text)?;
    check_drift(drift.as_deref())?;
    let all: Vec<crate::Reading> = readings.into_iter().flatten().collect();
    readings_status(&all, how.allow_unconverged)
}
