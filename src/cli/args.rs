//! The command line's definition for clap: the program ([`Cli`]), its subcommands ([`Command`], with the
//! arguments of `measure`, `standards` and `schema`; the other subcommands' arguments are in their own files)
//! and the outputs `schema --output-format` names ([`OutputSchema`]). `glossmeter --help` is written from here.
use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};

use super::common::{ColourArgs, Format};
use super::{compare, convergence, fit, pictures, profile, sweep, topography};
use crate::instrument::plan::{PlanOptions, DATA_MAX_RTOL, DEFAULT_RTOL};

#[derive(Parser, Debug)]
#[command(
    name = "glossmeter",
    version,
    about = "A virtual gloss, haze and DOI meter: reads a BRDF through the apertures of ASTM D523 / ISO 2813 / ASTM E430 / ISO 13803 instruments."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// Replace output files that exist (`-o`, `--plot`, ...; for re-runs in a Makefile). Each is still
    /// written whole first and renamed over the old one, so a failed run leaves the old file as it was.
    #[arg(long, global = true)]
    pub force: bool,
}

/// The outputs whose JSON Schema `glossmeter schema --output-format` prints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OutputSchema {
    Measure,
    Compare,
    Sweep,
    Fit,
    Profile,
    Convergence,
    /// A sheet as the one sheet reader reads it (the Python bindings' `read_sheet`).
    Sheet,
    /// `topography --format json`.
    Topography,
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
        // The help is written from the one default tolerance and the data's loosest, not copies of their values.
        #[arg(long, help = format!(
            "Relative tolerance of every reading (default {DEFAULT_RTOL:e}; for a measured table, by default a \
             quarter of each integral's data uncertainty, never tighter than {DEFAULT_RTOL:e} nor looser than \
             {DATA_MAX_RTOL:e}: given here, it is used as given, for tables too)"
        ))]
        rtol: Option<f64>,
        /// Output: an aligned table, JSON (`schema --output-format measure`) or CSV.
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
        /// Evaluation budget of each aperture integral (deterministic: the same bits on every machine); a
        /// reading whose integral runs out is "not converged".
        #[arg(long, default_value_t = PlanOptions::default().max_evals)]
        max_evals: usize,
        #[command(flatten)]
        colour: ColourArgs,
        /// Wall-clock limit of the whole measurement, seconds (all its integrals share it; 0: none, the
        /// default). A reading whose integral meets it gets no value (it would depend on the machine's speed)
        /// and the command exits 1; the evaluation budget is the deterministic bound.
        #[arg(long, default_value_t = 0.0)]
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
    /// Print the JSON Schema of the recipe format, or of an output (`--output-format
    /// measure|compare|sweep|fit|profile|convergence|topography`).
    Schema {
        /// The output whose schema to print (default: the recipe format's).
        #[arg(long, value_enum)]
        output_format: Option<OutputSchema>,
    },
    /// Measure a template recipe over a grid or a Latin hypercube of JSON Pointer paths (CSV or JSON lines).
    Sweep(sweep::SweepArgs),
    /// Set predictions beside an instrument sheet (CSV, or an .xlsx/.xls/.ods workbook); exits 1 if a reading
    /// falls outside its allowance.
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
    /// A measured surface topography (X3P, SDF, GSF or a text matrix): its height and slope parameters
    /// (ISO 25178-2), slope distribution and PSD (docs/topography.md).
    Topography(topography::TopographyArgs),
    /// Serve the virtual meter as a local web page and an HTTP API (docs/serve.md); prints the address and
    /// serves until stopped.
    #[cfg(feature = "serve")]
    Serve(ServeArgs),
    /// Print the shell completions of glossmeter (e.g. `glossmeter completions bash >
    /// ~/.local/share/bash-completion/completions/glossmeter`).
    Completions {
        /// The shell to complete for.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Print the man page of glossmeter, roff (`glossmeter man > glossmeter.1; man ./glossmeter.1`).
    Man,
}

impl ServeArgs {
    /// The request of a command line (the server, `glossmeter::serve`, takes it from the binary).
    pub fn request(&self) -> crate::request::ServeRequest {
        crate::request::ServeRequest {
            port: self.port,
            host: self.host.clone(),
            data_dir: self.data_dir.clone(),
            allow_hosts: self.allow_hosts.clone(),
            jobs: self.jobs,
            request_seconds: self.request_seconds,
            max_connections: self.max_connections,
        }
    }
}

/// The arguments of `glossmeter serve` (the server is `glossmeter::serve`, wired in by the binary).
#[derive(clap::Args, Debug, Clone)]
pub struct ServeArgs {
    /// The port to listen on (0: any free port; the address printed says which).
    #[arg(long, default_value_t = 8080)]
    pub port: u16,
    /// The address to listen on. Anything but loopback lets other machines reach the server (it warns).
    #[arg(long, default_value = "127.0.0.1")]
    pub host: String,
    /// The directory recipes may name table files in (relative paths, no `..`, no symbolic links out);
    /// without it no table file is read.
    #[arg(long, value_name = "DIR")]
    pub data_dir: Option<PathBuf>,
    /// Another name the server answers to in the Host header (repeatable), e.g. the machine's name when
    /// --host is not loopback.
    #[arg(long = "allow-host", value_name = "NAME")]
    pub allow_hosts: Vec<String>,
    /// Computations running at once; further requests are answered 503 (busy) at once.
    #[arg(long, default_value_t = 2)]
    pub jobs: usize,
    /// Wall-clock seconds of one computation [default: 60]: then the answer has the readings finished and
    /// the others without a value (docs/serve.md §Limits).
    #[arg(long, value_name = "SECONDS")]
    pub request_seconds: Option<f64>,
    /// Connections kept open at most [default: 1024, and 64 below the open-file limit].
    #[arg(long, value_name = "N")]
    pub max_connections: Option<usize>,
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    /// Every argument of every subcommand has its own help line (`--help` and the man page are written from
    /// these; a doc comment written above the wrong field once left `--ignore-column` blank).
    #[test]
    fn every_argument_has_help() {
        fn walk(cmd: &clap::Command, path: &str, blank: &mut Vec<String>) {
            for a in cmd.get_arguments() {
                let id = a.get_id().as_str();
                if matches!(id, "help" | "version") || a.is_hide_set() {
                    continue;
                }
                if a.get_help().is_none_or(|h| h.to_string().trim().is_empty()) {
                    blank.push(format!("{path} {id}"));
                }
            }
            for sub in cmd.get_subcommands() {
                walk(sub, &format!("{path} {}", sub.get_name()), blank);
            }
        }
        let mut blank = Vec::new();
        walk(&super::Cli::command(), "glossmeter", &mut blank);
        assert!(blank.is_empty(), "arguments without help: {blank:?}");
    }

    /// Every command that runs plans hands `--max-evals`, `--illuminant` and `--observer` to its request, as
    /// `measure` does (the server's and Python's requests take the same fields): the one place each command's
    /// arguments become the library's.
    #[test]
    fn every_plan_command_hands_the_budget_and_the_colour_conditions_to_its_request() {
        use super::{Cli, Command};
        use crate::request::PlanRequest;
        use clap::Parser;
        let flags = ["--max-evals", "60", "--illuminant", "A", "--observer", "2"];
        let plan = |args: &[&str]| -> PlanRequest {
            let cli = Cli::try_parse_from(["glossmeter"].iter().chain(args).chain(&flags)).expect("parses");
            match cli.command {
                Command::Sweep(a) => crate::cli::sweep::request(&a).plan,
                Command::Compare(a) => crate::cli::compare::request(&a).plan,
                Command::Fit(a) => crate::cli::fit::request(&a).plan,
                Command::Plot(a) => crate::cli::pictures::request(&a).plan,
                other => panic!("not a plan command: {other:?}"),
            }
        };
        for args in [
            &["sweep", "r.json", "--vary", "/roughness=0.1..0.2:2"][..],
            &["compare", "r.json", "s.csv"],
            &["fit", "r.json", "--free", "/roughness=0.1..0.2", "--target", "astm-d523-60/gloss=50"],
            &["plot", "r.json", "--kind", "gloss-vs-parameter", "-o", "p.svg"],
        ] {
            let p = plan(args);
            assert_eq!(
                (p.max_evals, p.illuminant.as_deref(), p.observer.as_deref()),
                (Some(60), Some("A"), Some("2")),
                "{}",
                args[0]
            );
        }
    }
}
