//! `glossmeter sweep`: a template recipe measured over a grid or a Latin hypercube of JSON Pointer paths,
//! streamed as CSV or JSON lines. The points, shards and rows are the library's (`crate::sweep`); this module
//! parses the arguments, draws the progress bar (only when stderr is a terminal; `cli::progress`) and writes.
use std::io::IsTerminal;
use std::path::PathBuf;

use crate::cli::common::ColourArgs;
use crate::cli::output::{Existing, OutputTarget};
use crate::instrument::plan::{PlanOptions, DEFAULT_RTOL};
use crate::request::SweepRequest;
use crate::sweep;
use crate::{resolve_geometries, Error, Result};

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SweepFormat {
    Csv,
    Jsonl,
}

#[derive(clap::Args, Debug)]
pub struct SweepArgs {
    /// The template recipe (JSON).
    pub template: PathBuf,
    /// A varied number: PATH=LO..HI:N (grid) or PATH=LO..HI (with --lhs); PATH is a JSON Pointer (repeatable).
    #[arg(long = "vary", value_name = "PATH=LO..HI[:N]", required = true)]
    pub vary: Vec<String>,
    /// Space this path's values logarithmically (repeatable).
    #[arg(long = "log", value_name = "PATH")]
    pub log: Vec<String>,
    /// A Latin hypercube of N points instead of the grid.
    #[arg(long, value_name = "N")]
    pub lhs: Option<u64>,
    /// The hypercube's seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// A shipped geometry id (repeatable; default: the default panel).
    #[arg(long = "geometry", short = 'g')]
    pub geometries: Vec<String>,
    /// Compute only the K-th of M contiguous slices (concatenated in order they equal the whole run).
    #[arg(long, value_name = "K/M")]
    pub shard: Option<String>,
    /// Output: CSV or JSON lines (`schema --output-format sweep`), one record per point.
    #[arg(long, value_enum, default_value_t = SweepFormat::Csv)]
    pub format: SweepFormat,
    // The help is written from the one default tolerance, not a copy of its value.
    #[arg(long, help = format!(
        "Relative tolerance of every reading (default {DEFAULT_RTOL:e}; for a measured table, by default a \
         quarter of each integral's data uncertainty, as in `measure`: given here, it is used as given)"
    ))]
    pub rtol: Option<f64>,
    /// Leave the per-point wall time out (then the output is reproducible byte for byte).
    #[arg(long)]
    pub no_timing: bool,
    /// Evaluation budget of each aperture integral (a reading that runs out is marked not converged).
    #[arg(long, default_value_t = PlanOptions::default().max_evals)]
    pub max_evals: usize,
    #[command(flatten)]
    pub colour: ColourArgs,
    /// Write to this new file instead of stdout (refused before any work if it exists; the file appears
    /// whole when the sweep ends, or not at all).
    #[arg(long, short = 'o')]
    pub output: Option<PathBuf>,
}

/// The request of a command line (the one place where `sweep`'s arguments become the library's).
pub fn request(a: &SweepArgs) -> SweepRequest {
    SweepRequest {
        vary: a.vary.clone(),
        log: a.log.clone(),
        lhs: a.lhs,
        seed: a.seed,
        plan: a.colour.plan(a.rtol, a.max_evals),
    }
}

pub fn run(a: SweepArgs, existing: Existing) -> Result<()> {
    let request = request(&a);
    // Every check that needs no file comes before any work.
    request.plan.options()?;
    request.axes()?;
    let (k, m) = a.shard.as_deref().map(sweep::parse_shard).transpose()?.unwrap_or((1, 1));
    let target = OutputTarget::new(a.output.as_deref(), "--output", existing)?;
    let template = crate::input::Stdin::default().open_text(&a.template, "recipe")?;
    let (file, text) = (template.name(), template.text("recipe")?);
    let geos = resolve_geometries(&a.geometries, &[] as &[&str])?;
    let s = request.sweep(&text, &file, geos)?;
    let range = s.shard(k, m);
    let timing = !a.no_timing;
    let bar = crate::cli::progress::Bar::new(range.end - range.start, std::io::stderr().is_terminal());
    let name = target.name();
    let io = |source: std::io::Error| Error::Io { file: name.clone(), source };
    target.stream(|out| {
        if a.format == SweepFormat::Csv && k == 1 {
            out.write_all(s.csv_header(timing).as_bytes()).map_err(io)?;
        }
        s.run_reporting(
            range,
            |r| {
                let line = match a.format {
                    SweepFormat::Csv => s.csv_row(&r, timing),
                    SweepFormat::Jsonl => s.jsonl_row(&r, timing),
                };
                out.write_all(line.as_bytes()).map_err(io)
            },
            &|done| bar.report(done),
        )
    })?;
    bar.finish();
    Ok(())
}
