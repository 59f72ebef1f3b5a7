//! `glossmeter profile`: the goniophotometric profile of a recipe on a geometry with a profile array
//! (default `rspec-20`, the 512-pixel array of a Rhopoint IQ-class meter), one row per pixel with its angle,
//! its normalised reading and their error estimates, as CSV or JSON, and optionally a picture. The
//! computation is `instrument::profile::measure`; this module parses, formats and writes.
use std::path::PathBuf;

use super::common::readings_status;
use super::output::{Existing, OutputTarget};
use crate::instrument::plan::DEFAULT_RTOL;
use crate::instrument::profile::{self, Profile};
use crate::recipe::{self, Material};
use crate::report::pictures::profile::draw;
pub use crate::report::pictures::profile::svg;
use crate::report::plain;
use crate::request::{PlanRequest, ProfileRequest};
use crate::{Error, Result};

/// The geometry profiled when none is given.
pub const DEFAULT_GEOMETRY: &str = crate::request::PROFILE_GEOMETRY;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ProfileFormat {
    Csv,
    Json,
}

/// Arguments of `glossmeter profile`.
#[derive(clap::Args, Debug)]
pub struct ProfileArgs {
    /// The recipe (JSON).
    pub recipe: PathBuf,
    /// A shipped geometry id with a profile array (default rspec-20).
    #[arg(long = "geometry", short = 'g')]
    pub geometry: Option<String>,
    /// A user geometry file with a `profile` block (instead of --geometry).
    #[arg(long = "geometry-file", conflicts_with = "geometry")]
    pub geometry_file: Option<PathBuf>,
    /// Output: CSV (one row per pixel) or JSON (`schema --output-format profile`).
    #[arg(long, value_enum, default_value_t = ProfileFormat::Csv)]
    pub format: ProfileFormat,
    /// Also draw the profile (reading against angle) to this new .svg or .png file.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Write the CSV/JSON to this new file instead of stdout (refuses to overwrite).
    #[arg(long, short = 'o')]
    pub output: Option<PathBuf>,
    // The help is written from the one default tolerance, not a copy of its value.
    #[arg(long, help = format!(
        "Relative tolerance of every pixel's reading (default {DEFAULT_RTOL:e}; for a measured table, by default \
         a quarter of each integral's data uncertainty, as in `measure`: given here, it is used as given)"
    ))]
    pub rtol: Option<f64>,
    /// Exit 0 even if a pixel did not converge within its budget (it is still marked in the output).
    #[arg(long)]
    pub allow_unconverged: bool,
    /// Evaluation budget of each part of one pixel's integral (deterministic: a pixel that reaches it is
    /// marked not converged, the same bits on every machine).
    #[arg(long, default_value_t = profile::DEFAULT_PIXEL_EVALS)]
    pub max_evals: usize,
    /// Evaluation budget of the whole profile, shared equally by the pixels: each part of each pixel's
    /// integral gets at most MAX_TOTAL_EVALS / (2 × pixels), and at most --max-evals.
    #[arg(long, default_value_t = profile::DEFAULT_TOTAL_EVALS)]
    pub max_total_evals: usize,
}

/// The request of a command line (the one place where `profile`'s arguments become the library's).
pub fn request(a: &ProfileArgs) -> ProfileRequest {
    ProfileRequest {
        plan: PlanRequest { rtol: a.rtol, ..PlanRequest::default() },
        max_evals: a.max_evals,
        max_total_evals: a.max_total_evals,
    }
}

pub fn run(args: ProfileArgs, existing: Existing) -> Result<()> {
    let (options, budget) = request(&args).options()?;
    let target = OutputTarget::new(args.output.as_deref(), "--output", existing)?;
    if let Some(p) = &args.plot {
        super::plot::check_plot_path(p, "--plot", existing)?;
        if args.output.as_deref() == Some(p.as_path()) {
            return Err(Error::Usage(format!("--plot and --output name the same file {}", p.display())));
        }
    }
    let mut stdin = crate::input::Stdin::default();
    let material = recipe::load_source(&stdin.open_text(&args.recipe, "recipe")?)?;
    let g = match &args.geometry_file {
        Some(f) => crate::instrument::standards::load_source(&stdin.open_text(f, "geometry file")?)?,
        None => crate::instrument::standards::find(args.geometry.as_deref().unwrap_or(DEFAULT_GEOMETRY))?,
    };
    // Checked before any work: the geometry must have a profile array.
    crate::instrument::standards::profile::of(&g)?;
    let prof = profile::measure(material.brdf.clone(), &g, options, budget)?;
    let text = match args.format {
        ProfileFormat::Csv => csv(&prof)?,
        ProfileFormat::Json => json(&material, &prof),
    };
    if let Some(p) = &args.plot {
        let title = format!("{}: {} profile", material.name, prof.geometry);
        crate::render_plot!(p, "--plot", existing, (1000, 640), |root| draw(root, &prof, &title))?;
        eprintln!("plot: {} ({} pixels)", p.display(), prof.rows.len());
    }
    target.write(&text)?;
    let readings: Vec<crate::Reading> = prof.rows.iter().map(|r| r.reading.clone()).collect();
    readings_status(&readings, args.allow_unconverged)
}

/// The columns of the CSV, in order (also the keys of a JSON row).
pub const COLUMNS: &[&str] =
    &["pixel", "angle_deg", "angle_half_width_deg", "value", "error_estimate", "unit", "converged", "evaluations"];

/// CSV: one line per pixel, the angles in full precision, each value and its error estimate to their precision
/// (`report::with_error`); an empty value where there is none.
pub fn csv(p: &Profile) -> Result<String> {
    let rows = p.rows.iter().map(|r| {
        let (value, error) =
            r.reading.value.map(|v| crate::report::with_error(v, r.reading.error_estimate)).unwrap_or_default();
        [
            r.pixel.to_string(),
            plain(r.angle_deg),
            plain(r.half_width_deg),
            value,
            error,
            r.reading.unit.clone(),
            r.reading.converged.to_string(),
            r.reading.evaluations.to_string(),
        ]
    });
    crate::report::csv_text(COLUMNS, rows)
}

/// JSON: the material, the array and one object per pixel (null where there is no value): `report::profile`.
pub fn json(material: &Material, p: &Profile) -> String {
    crate::report::profile::ProfileDoc::new(material, p).text()
}
