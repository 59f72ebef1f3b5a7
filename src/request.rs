//! The front door (docs/architecture.md §The front door): one typed request per action (measure and explain,
//! sweep, plot, profile, convergence, compare, fit, topography). A request owns its defaults and its validation, with the
//! messages every front end gives: an argument is named in the library's own words ([`Words`]), and each front
//! end writes it its own way (the command line as its flag, `--rtol`; the server as the field of its body,
//! `/rtol`; Python as the keyword). The command line's clap structs, the server's JSON bodies and Python's
//! keyword arguments only convert into these types, in one place each, as ripgrep turns its low-level
//! arguments into high-level ones in one place.
//!
//! What a request does not own is where its inputs come from: a front end opens the files (or the standard
//! input, or an upload) and hands the text over with the name it gives it in messages; it resolves the
//! geometries (the server holds them to its limits); it writes the documents.
use serde_json::Value;

use crate::colorimetry::{Conditions, Illuminant, Observer};
use crate::comparison::conditions;
use crate::comparison::sheet::{Sheet, SheetOptions};
use crate::comparison::VerdictRule;
use crate::error::{given, Words};
use crate::fit::{self, FitOptions, FreeParameter, TargetReading};
use crate::instrument::convergence::{self, SweepOptions, DEFAULT_TOLERANCES};
use crate::instrument::plan::{rtol_refusal, Cancel, PlanOptions, DEFAULT_RTOL};
use crate::instrument::profile;
use crate::instrument::standards::StandardGeometry;
use crate::sweep::{self, Sweep, SweepAxis, SweepDesign};
use crate::topography::analysis::{analyse, Analysis};
use crate::topography::level::Levelling;
use crate::topography::map::HeightMap;
use crate::topography::text::Calibration;
use crate::topography::{self, units};
use crate::{recipe, Error, Result};

/// The illuminant of colour readings when none is given.
pub(crate) const DEFAULT_ILLUMINANT: &str = "D65";
/// The observer of colour readings when none is given (CIE 1964 10°).
pub(crate) const DEFAULT_OBSERVER: &str = "10";
/// The geometries `plot` draws (and reads against a parameter) when none is given.
pub(crate) const PLOT_GEOMETRIES: &[&str] = &["astm-d523-20", "astm-d523-60", "astm-d523-85"];
/// The geometries `convergence` sweeps when none is given.
pub const CONVERGENCE_GEOMETRIES: &[&str] = &["astm-d523-20", "astm-d523-60", "astm-d523-85"];
/// The geometry `profile` profiles when none is given (the 512-pixel array of a Rhopoint IQ-class meter).
pub const PROFILE_GEOMETRY: &str = "rspec-20";
/// The relative tolerance of the readings of a gloss-vs-parameter picture when none is given: a picture
/// needs no more (1e-5 of 100 GU is far below a pixel).
pub(crate) const PLOT_RTOL: f64 = 1e-5;
/// The values of the varied number of a gloss-vs-parameter picture when none is given.
pub(crate) const PLOT_POINTS: usize = 9;
/// The most values a gloss-vs-parameter picture draws.
pub(crate) const PLOT_POINTS_MAX: usize = 200;
/// Standard errors of the mean allowed for repeated readings (`k`) when none is given.
pub const DEFAULT_K: f64 = 2.0;

/// `rtol` in (0, 1), checked before any work (the planner's check, [`rtol_refusal`], naming the argument).
pub(crate) fn check_rtol(rtol: f64) -> Result<f64> {
    match rtol_refusal(rtol) {
        Some(why) => Err(Error::argument("rtol", format!(" {why}"))),
        None => Ok(rtol),
    }
}

fn at_least_one(name: &'static str, n: usize) -> Result<usize> {
    match n {
        0 => Err(Error::argument(name, " must be at least 1")),
        n => Ok(n),
    }
}

/// A template recipe's JSON, read as every recipe is (`input::json::parse_json`: a byte-order mark skipped, a key
/// given twice refused), for the front ends that vary it (`sweep`, `plot`).
pub(crate) fn read_template(text: &str, file: &str) -> Result<Value> {
    crate::input::json::parse_json(text, file)
}

/// `,`, `;`, `tab` (or a literal tab): the separator of a text sheet.
pub(crate) fn parse_delimiter(s: &str) -> Result<u8> {
    match s {
        "," => Ok(b','),
        ";" => Ok(b';'),
        "tab" | "\t" | "\\t" => Ok(b'\t'),
        _ => Err(Error::argument("delimiter", format!(" must be `,`, `;` or `tab`, got `{s}`"))),
    }
}

/// The options of a plan as a front end was given them (`None`: the default).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlanRequest {
    /// Relative tolerance of every reading. Without one it is [`DEFAULT_RTOL`] (or the request's own default),
    /// and a measured table's tolerance comes from its data (docs/accuracy.md §Data uncertainty of measured
    /// tables); a tolerance given is used as given.
    pub rtol: Option<f64>,
    /// Evaluation budget of each aperture integral.
    pub max_evals: Option<usize>,
    /// Illuminant of colour readings (D65, D50, A or C).
    pub illuminant: Option<String>,
    /// Observer of colour readings (10 or 2).
    pub observer: Option<String>,
}

impl PlanRequest {
    /// The plan's options, [`DEFAULT_RTOL`] without a tolerance.
    pub fn options(&self) -> Result<PlanOptions> {
        self.options_or(DEFAULT_RTOL)
    }

    /// The plan's options, `default_rtol` without a tolerance.
    pub(crate) fn options_or(&self, default_rtol: f64) -> Result<PlanOptions> {
        let rtol = check_rtol(self.rtol.unwrap_or(default_rtol))?;
        let colour = self.colour()?;
        let max_evals = at_least_one("max_evals", self.max_evals.unwrap_or(PlanOptions::default().max_evals))?;
        Ok(PlanOptions { rtol, max_evals, colour, rtol_from_data: self.rtol.is_none(), ..PlanOptions::default() })
    }

    /// The conditions of colour readings.
    pub(crate) fn colour(&self) -> Result<Conditions> {
        Ok(Conditions {
            illuminant: Illuminant::parse(self.illuminant.as_deref().unwrap_or(DEFAULT_ILLUMINANT))?,
            observer: Observer::parse(self.observer.as_deref().unwrap_or(DEFAULT_OBSERVER))?,
        })
    }
}

/// `measure` (and `explain`): a material read through geometries.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeasureRequest {
    pub plan: PlanRequest,
    /// Wall-clock limit of the whole measurement, seconds (0: none).
    pub max_seconds: f64,
}

impl MeasureRequest {
    /// The plan's options, with the wall-clock limit.
    pub fn options(&self) -> Result<PlanOptions> {
        let options = self.plan.options()?;
        let s = self.max_seconds;
        if !(s.is_finite() && s >= 0.0) {
            return Err(Error::argument(
                "max_seconds",
                format!(
                    " must be a finite number of seconds ≥ 0 (0: no wall-clock budget), got {}",
                    crate::error::given(s)
                ),
            ));
        }
        Ok(PlanOptions { max_seconds: (s > 0.0).then_some(s), ..options })
    }
}

/// `sweep`: a template recipe measured over a grid or a Latin hypercube of JSON Pointer paths.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SweepRequest {
    /// The varied numbers, `PATH=LO..HI:N` (grid) or `PATH=LO..HI` (hypercube) ([`sweep::parse_vary`]).
    pub vary: Vec<String>,
    /// The paths whose values are spaced logarithmically.
    pub log: Vec<String>,
    /// A Latin hypercube of this many points instead of the grid.
    pub lhs: Option<u64>,
    /// The hypercube's seed.
    pub seed: u64,
    pub plan: PlanRequest,
}

impl SweepRequest {
    /// The axes and the design, checked before any file is read.
    pub fn axes(&self) -> Result<(Vec<SweepAxis>, SweepDesign)> {
        let mut axes = self.vary.iter().map(|v| sweep::parse_vary(v)).collect::<Result<Vec<_>>>()?;
        for l in &self.log {
            match axes.iter_mut().find(|x| &x.path == l) {
                Some(x) => x.log = true,
                None => {
                    return Err(Error::Argument(
                        Words::argument("log").and(format!(" {l}: not a ")).and_argument("vary").and(" path"),
                    ))
                }
            }
        }
        let design = match self.lhs {
            Some(n) => SweepDesign::Lhs { n, seed: self.seed },
            None => SweepDesign::Grid,
        };
        Ok((axes, design))
    }

    /// The sweep of the template `text` (named `file` in messages) through `geometries`.
    pub fn sweep(&self, text: &str, file: &str, geometries: Vec<StandardGeometry>) -> Result<Sweep> {
        self.sweep_until(text, file, geometries, Cancel::default())
    }

    /// [`SweepRequest::sweep`], every point's plan stopped by `cancel` (the server's, raised when its client
    /// leaves or its time is up).
    pub(crate) fn sweep_until(
        &self,
        text: &str,
        file: &str,
        geometries: Vec<StandardGeometry>,
        cancel: Cancel,
    ) -> Result<Sweep> {
        let options = PlanOptions { cancel, ..self.plan.options()? };
        let (axes, design) = self.axes()?;
        let template = read_template(text, file)?;
        Sweep::new(template, file, axes, design, geometries, options)
    }
}

/// How the values of a gloss-vs-parameter picture are spaced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Spacing {
    /// Logarithmically when the range spans a decade or more (LO > 0 and HI ≥ 10·LO, as a roughness range
    /// does), else evenly.
    #[default]
    Auto,
    Linear,
    Log,
}

/// `plot --kind gloss-vs-parameter`: readings against one recipe number, on the sweep's grid (one vary
/// grammar and one grid for `sweep`, `plot` and the page).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VsParameterRequest {
    /// The varied number, `PATH=LO..HI` (or `PATH=LO..HI:N`, N values) ([`sweep::parse_vary`]).
    pub vary: Option<String>,
    /// How many values ([`PLOT_POINTS`] if none; `:N` in `vary` says it too, and wins).
    pub points: Option<usize>,
    pub spacing: Spacing,
    /// The plan's options ([`PLOT_RTOL`] without a tolerance).
    pub plan: PlanRequest,
}

/// A gloss-vs-parameter picture's numbers, ready to draw.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct VsParameter {
    /// The recipe's name (the picture's title).
    pub name: String,
    /// The axis' words ([`parameter_label`]).
    pub label: String,
    /// Logarithmic axis.
    pub log: bool,
    /// One series per reading, `GEOMETRY READING (UNIT)`: (value of the number, reading).
    pub series: Vec<(String, Vec<(f64, f64)>)>,
}

impl VsParameterRequest {
    /// The sweep of the template `text` (named `file`), checked before any work: one axis on a grid.
    pub fn sweep(&self, text: &str, file: &str, geometries: Vec<StandardGeometry>) -> Result<Sweep> {
        self.sweep_until(text, file, geometries, Cancel::default())
    }

    /// [`VsParameterRequest::sweep`], every point's plan stopped by `cancel` (the server's, raised when its
    /// client leaves or its time is up).
    pub(crate) fn sweep_until(
        &self,
        text: &str,
        file: &str,
        geometries: Vec<StandardGeometry>,
        cancel: Cancel,
    ) -> Result<Sweep> {
        let spec = self.vary.as_deref().ok_or_else(|| {
            Error::Argument(Words::from("a gloss-vs-parameter picture needs ").and_argument("vary").and(" PATH=LO..HI"))
        })?;
        let options = PlanOptions { cancel, ..self.plan.options_or(PLOT_RTOL)? };
        let mut axis = sweep::parse_vary(spec)?;
        let n = axis.n.map(|n| n as usize).or(self.points).unwrap_or(PLOT_POINTS);
        if !(2..=PLOT_POINTS_MAX).contains(&n) {
            return Err(Error::argument("points", format!(" must be 2 to {PLOT_POINTS_MAX}, got {n}")));
        }
        axis.n = Some(n as u64);
        axis.log = match self.spacing {
            Spacing::Log if !(axis.lo > 0.0) => {
                return Err(Error::argument("spacing", format!(" log needs LO > 0, got {}", given(axis.lo))))
            }
            Spacing::Log => true,
            Spacing::Linear => false,
            Spacing::Auto => axis.lo > 0.0 && axis.hi >= 10.0 * axis.lo,
        };
        let template = read_template(text, file)?;
        Sweep::new(template, file, vec![axis], SweepDesign::Grid, geometries, options)
    }

    /// The picture's numbers: every point of the sweep read (in order); a point whose recipe is invalid is an
    /// error naming its value.
    pub(crate) fn read(&self, text: &str, file: &str, geometries: Vec<StandardGeometry>) -> Result<VsParameter> {
        self.read_until(text, file, geometries, Cancel::default())
    }

    /// [`VsParameterRequest::read`], stopped by `cancel` as [`VsParameterRequest::sweep_until`] is.
    pub(crate) fn read_until(
        &self,
        text: &str,
        file: &str,
        geometries: Vec<StandardGeometry>,
        cancel: Cancel,
    ) -> Result<VsParameter> {
        let s = self.sweep_until(text, file, geometries, cancel)?;
        let name = recipe::parse_str(text, file)?.name;
        let (pointer, log) = (s.axes[0].path.clone(), s.axes[0].log);
        let label = parameter_label(&s.template, &pointer);
        let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
        s.run(0..s.len(), |r| {
            let readings =
                r.outcome.map_err(|why| Error::argument("vary", format!(" {pointer} = {}: {why}", r.values[0])))?;
            for reading in readings {
                let label = format!("{} {} ({})", reading.geometry, reading.name, reading.unit);
                let Some(v) = reading.value else { continue };
                match series.iter_mut().find(|s| s.0 == label) {
                    Some(s) => s.1.push((r.values[0], v)),
                    None => series.push((label, vec![(r.values[0], v)])),
                }
            }
            Ok(())
        })?;
        if series.is_empty() {
            return Err(Error::Numeric("no reading has a value over the range".into()));
        }
        Ok(VsParameter { name, label, log, series })
    }
}

/// The axis name of a recipe number (docs/instrument.md §Pictures): the registry's words for it, the
/// alternative that names the recipe's own choice where the words offer several (`GGX α` out of `Beckmann rms
/// slope m or GGX α` for a GGX recipe), its unit, and the pointer: `GGX α (slope), /roughness`.
pub(crate) fn parameter_label(recipe: &Value, pointer: &str) -> String {
    let model = recipe.get("model").and_then(Value::as_str).unwrap_or("");
    let Some(p) = crate::registry::lookup(model, pointer) else { return format!("recipe {pointer}") };
    let first = p.description.split(';').next().unwrap_or("").trim();
    let parent = pointer.rsplit_once('/').map_or("", |(a, _)| a);
    let choices: Vec<String> = recipe
        .pointer(parent)
        .and_then(Value::as_object)
        .map(|o| o.values().filter_map(Value::as_str).map(str::to_lowercase).collect())
        .unwrap_or_default();
    let words = first
        .split(" or ")
        .find(|alt| choices.iter().any(|c| !c.is_empty() && alt.to_lowercase().contains(c.as_str())))
        .unwrap_or(first);
    let unit = if p.unit.is_empty() { String::new() } else { format!(" ({})", p.unit) };
    format!("{words}{unit}, {pointer}")
}

/// `profile`: the goniophotometric profile of a material on a geometry with a profile array.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileRequest {
    pub plan: PlanRequest,
    /// Evaluation budget of each part of one pixel's integral.
    pub max_evals: usize,
    /// Evaluation budget of the whole profile.
    pub max_total_evals: usize,
}

impl Default for ProfileRequest {
    fn default() -> Self {
        ProfileRequest {
            plan: PlanRequest::default(),
            max_evals: profile::DEFAULT_PIXEL_EVALS,
            max_total_evals: profile::DEFAULT_TOTAL_EVALS,
        }
    }
}

impl ProfileRequest {
    /// The plan's options and the profile's budget.
    pub fn options(&self) -> Result<(PlanOptions, profile::Budget)> {
        let options = self.plan.options()?;
        if self.max_evals == 0 || self.max_total_evals == 0 {
            return Err(Error::Argument(
                Words::argument("max_evals").and(" and ").and_argument("max_total_evals").and(" must be at least 1"),
            ));
        }
        Ok((options, profile::Budget { per_part: self.max_evals, total: self.max_total_evals }))
    }
}

/// `topography`: a measured topography read, levelled and described (docs/topography.md).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TopographyRequest {
    /// The reference surface removed: `mean`, `plane` (the default), `poly2` … `poly5`.
    pub levelling: Option<String>,
    /// A plain matrix's point spacing, a length with its unit (`0.5um`); along x, and along y too unless
    /// `pixel_size_y` is given.
    pub pixel_size: Option<String>,
    pub pixel_size_y: Option<String>,
    /// A plain matrix's height unit (`um`, `nm`, ...).
    pub height_unit: Option<String>,
}

impl TopographyRequest {
    /// The levelling asked for.
    pub fn levelling(&self) -> Result<Levelling> {
        match self.levelling.as_deref() {
            None => Ok(Levelling::Plane),
            Some(s) => Levelling::parse(s).ok_or_else(|| {
                Error::argument("levelling", format!(" must be one of {}, got `{s}`", Levelling::allowed()))
            }),
        }
    }

    /// A plain matrix's calibration: `None` unless the pixel size is given, which then needs the height unit.
    pub(crate) fn calibration(&self) -> Result<Option<Calibration>> {
        let length = |name: &'static str, v: &str| {
            units::parse_length(v).ok_or_else(|| {
                Error::argument(
                    name,
                    format!(" must be a length with its unit ({}), e.g. `0.5um`, got `{v}`", units::allowed()),
                )
            })
        };
        let Some(dx) = self.pixel_size.as_deref() else {
            if self.pixel_size_y.is_some() || self.height_unit.is_some() {
                return Err(Error::Argument(
                    Words::argument("pixel_size_y")
                        .and(" and ")
                        .and_argument("height_unit")
                        .and(" need ")
                        .and_argument("pixel_size"),
                ));
            }
            return Ok(None);
        };
        let dx = length("pixel_size", dx)?;
        let dy = match self.pixel_size_y.as_deref() {
            Some(v) => length("pixel_size_y", v)?,
            None => dx,
        };
        let unit = self.height_unit.as_deref().ok_or_else(|| {
            Error::Argument(
                Words::argument("pixel_size")
                    .and(" needs ")
                    .and_argument("height_unit")
                    .and(format!(" ({})", units::allowed())),
            )
        })?;
        let z_unit = units::metres_per(unit).ok_or_else(|| {
            Error::argument("height_unit", format!(" must be one of {}, got `{unit}`", units::allowed()))
        })?;
        Ok(Some(Calibration { dx, dy, z_unit }))
    }

    /// Read a topography file's bytes (`ext`: its extension, lower case) and describe it.
    pub fn read(&self, bytes: &[u8], file: &str, ext: &str) -> Result<(HeightMap, Analysis)> {
        let levelling = self.levelling()?;
        let calibration = self.calibration()?;
        let map = topography::from_bytes(bytes, file, ext, calibration)?;
        let analysis = analyse(&map, levelling)?;
        Ok((map, analysis))
    }
}

/// `convergence`: error against run time over a sweep of tolerances.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvergenceRequest {
    /// The tolerances (empty: [`DEFAULT_TOLERANCES`]).
    pub tolerances: Vec<f64>,
    /// Repeat each execution until this many milliseconds have elapsed (or `max_repetitions`).
    pub min_time_ms: f64,
    pub max_repetitions: usize,
    /// Compare with a run at 1/100 of the tightest tolerance even when a closed form exists.
    pub reference_run: bool,
    /// Illuminant of colour readings (D65, D50, A or C; `None`: D65).
    pub illuminant: Option<String>,
    /// Observer of colour readings (10 or 2; `None`: 10).
    pub observer: Option<String>,
}

impl Default for ConvergenceRequest {
    fn default() -> Self {
        let d = SweepOptions::default();
        ConvergenceRequest {
            tolerances: vec![],
            min_time_ms: d.min_seconds * 1e3,
            max_repetitions: d.max_repetitions,
            reference_run: false,
            illuminant: None,
            observer: None,
        }
    }
}

impl ConvergenceRequest {
    /// The tolerances and the sweep's options, checked before the (possibly long) sweep.
    pub fn options(&self) -> Result<(Vec<f64>, SweepOptions)> {
        let tolerances = if self.tolerances.is_empty() { DEFAULT_TOLERANCES.to_vec() } else { self.tolerances.clone() };
        convergence::validate_tolerances(&tolerances).map_err(|e| Error::argument("tolerances", format!(": {e}")))?;
        if !(self.min_time_ms.is_finite() && self.min_time_ms >= 0.0) {
            return Err(Error::argument(
                "min_time_ms",
                format!(" must be a number ≥ 0, got {}", given(self.min_time_ms)),
            ));
        }
        let max_repetitions = at_least_one("max_repetitions", self.max_repetitions)?;
        let colour = PlanRequest {
            illuminant: self.illuminant.clone(),
            observer: self.observer.clone(),
            ..PlanRequest::default()
        }
        .colour()?;
        let options = SweepOptions {
            min_seconds: self.min_time_ms * 1e-3,
            max_repetitions,
            force_run_reference: self.reference_run,
            colour,
            ..SweepOptions::default()
        };
        Ok((tolerances, options))
    }
}

/// How a sheet is read (`compare`, `fit`): the options of [`crate::comparison::sheet::from_bytes`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SheetRequest {
    /// The separator of a text sheet ([`parse_delimiter`]); detected from the header line if none.
    pub delimiter: Option<String>,
    /// Columns to skip.
    pub ignore_columns: Vec<String>,
    /// The sheet of a workbook (default: its first).
    pub sheet_name: Option<String>,
    /// The header's 1-based row, for exports with title or metadata rows above it (default: found).
    pub header_row: Option<usize>,
}

impl SheetRequest {
    pub fn options(&self) -> Result<SheetOptions> {
        Ok(SheetOptions {
            delimiter: self.delimiter.as_deref().map(parse_delimiter).transpose()?,
            ignore_columns: self.ignore_columns.clone(),
            sheet_name: self.sheet_name.clone(),
            header_row: self.header_row,
        })
    }
}

/// `compare`: predictions beside an instrument sheet.
#[derive(Clone, Debug, PartialEq)]
pub struct CompareRequest {
    /// Standard errors of the mean allowed for repeated readings.
    pub k: f64,
    /// Allowed |predicted − measured| for rows without an uncertainty (and that no `tolerances` key names).
    pub tolerance: Option<f64>,
    /// Tolerances as `--tolerance` writes them, `[KEY=]NUMBER` (`gloss=2`, `astm-e430-30/doi=3`, `1`;
    /// [`crate::comparison::parse_tolerance`]).
    pub tolerances: Vec<String>,
    /// Largest allowed CIEDE2000 ΔE00.
    pub max_de00: Option<f64>,
    pub plan: PlanRequest,
    pub sheet: SheetRequest,
}

impl Default for CompareRequest {
    fn default() -> Self {
        CompareRequest {
            k: DEFAULT_K,
            tolerance: None,
            tolerances: vec![],
            max_de00: None,
            plan: PlanRequest::default(),
            sheet: SheetRequest::default(),
        }
    }
}

impl CompareRequest {
    /// The verdict rule, checked.
    pub fn rule(&self) -> Result<VerdictRule> {
        let mut rule = VerdictRule::with_tolerances(self.k, &self.tolerances)?;
        if let Some(t) = self.tolerance {
            if rule.tolerance.replace(t).is_some() {
                return Err(Error::argument("tolerance", " was given two plain numbers; give one"));
            }
        }
        rule.check()?;
        Ok(rule)
    }

    /// The largest ΔE00, checked.
    pub fn max_de00(&self) -> Result<Option<f64>> {
        match self.max_de00 {
            Some(m) if !(m.is_finite() && m >= 0.0) => {
                Err(Error::argument("max_de00", format!(" must be a finite number ≥ 0, got {}", given(m))))
            }
            m => Ok(m),
        }
    }
}

/// `fit`: recipe parameters from readings.
#[derive(Clone, Debug, PartialEq)]
pub struct FitRequest {
    /// The free parameters, `PATH=LO..HI` or `PATH=log:LO..HI` ([`FreeParameter::parse`]).
    pub free: Vec<String>,
    /// The target readings, `GEOMETRY/READING=VALUE[±U]` ([`TargetReading::parse`]); or a sheet's.
    pub targets: Vec<String>,
    /// Uncertainty of a target given without one.
    pub uncertainty: f64,
    /// Solver restarts of an exactly determined fit.
    pub restarts: usize,
    /// The forward readings' tolerance (default [`DEFAULT_RTOL`], never from a table's data: the fit compares
    /// readings at one tolerance), evaluation budget and colour conditions.
    pub plan: PlanRequest,
    pub sheet: SheetRequest,
    /// The sample of the sheet to fit.
    pub sample: Option<String>,
}

impl Default for FitRequest {
    fn default() -> Self {
        FitRequest {
            free: vec![],
            targets: vec![],
            uncertainty: fit::DEFAULT_UNCERTAINTY,
            restarts: fit::DEFAULT_RESTARTS,
            plan: PlanRequest::default(),
            sheet: SheetRequest::default(),
            sample: None,
        }
    }
}

impl FitRequest {
    /// The fit's options (without geometries), checked before any work.
    pub fn options(&self) -> Result<FitOptions> {
        let plan = self.plan.options_or(DEFAULT_RTOL)?;
        if !(self.uncertainty.is_finite() && self.uncertainty > 0.0) {
            return Err(Error::argument(
                "uncertainty",
                format!(" must be a finite number > 0, got {}", given(self.uncertainty)),
            ));
        }
        Ok(FitOptions {
            rtol: plan.rtol,
            max_evals: plan.max_evals,
            colour: plan.colour,
            default_uncertainty: self.uncertainty,
            restarts: self.restarts,
            ..FitOptions::default()
        })
    }

    /// The free parameters.
    pub fn free(&self) -> Result<Vec<FreeParameter>> {
        self.free.iter().map(|f| FreeParameter::parse(f)).collect()
    }

    /// The targets: the sheet's sample's if a sheet is given (with notes on what was left out; colour targets
    /// only under the colour conditions the sheet states, `comparison::conditions`), else the target readings.
    pub fn targets(&self, sheet: Option<&Sheet>) -> Result<(Vec<TargetReading>, Vec<String>)> {
        match sheet {
            Some(s) => {
                let (targets, notes) = fit::targets_from_sheet(s, self.sample.as_deref())?;
                if targets.iter().any(|t| conditions::is_colour_reading(&t.name)) {
                    conditions::check(s, self.plan.colour()?)?;
                }
                Ok((targets, notes))
            }
            None => Ok((self.targets.iter().map(|t| TargetReading::parse(t)).collect::<Result<_>>()?, vec![])),
        }
    }
}

/// `serve`: where the server listens and what it may read (the command line's `glossmeter serve`).
#[derive(Clone, Debug, PartialEq)]
pub struct ServeRequest {
    /// The port (0: any free port).
    pub port: u16,
    /// The address to listen on.
    pub host: String,
    /// The directory recipes may name table files in (None: no table file is read).
    pub data_dir: Option<std::path::PathBuf>,
    /// Other names the server answers to in the Host header.
    pub allow_hosts: Vec<String>,
    /// Computations running at once.
    pub jobs: usize,
    /// A request's time limit in seconds (None: the server's default, docs/serve.md §Limits).
    pub request_seconds: Option<f64>,
    /// Connections kept open at most (None: the server's default, below the open-file limit).
    pub max_connections: Option<usize>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flag(a: &'static str) -> String {
        format!("--{}", a.replace('_', "-"))
    }

    #[test]
    fn one_default_tolerance_serves_every_request() {
        assert_eq!(PlanRequest::default().options().unwrap().rtol, DEFAULT_RTOL);
        assert!(PlanRequest::default().options().unwrap().rtol_from_data);
        assert_eq!(FitRequest::default().options().unwrap().rtol, DEFAULT_RTOL);
        assert_eq!(FitOptions::default().rtol, DEFAULT_RTOL);
        assert_eq!(PlanOptions::default().rtol, DEFAULT_RTOL);
        let given = PlanRequest { rtol: Some(1e-3), ..PlanRequest::default() }.options().unwrap();
        assert_eq!((given.rtol, given.rtol_from_data), (1e-3, false));
    }

    #[test]
    fn refusals_name_the_argument_in_the_librarys_words() {
        let e = PlanRequest { rtol: Some(2.0), ..PlanRequest::default() }.options().unwrap_err();
        assert_eq!(e.naming(&flag), "--rtol must be a number in (0, 1), got `2`");
        let e = PlanRequest { max_evals: Some(0), ..PlanRequest::default() }.options().unwrap_err();
        assert_eq!(e.naming(&flag), "--max-evals must be at least 1");
        let e = MeasureRequest { max_seconds: f64::NAN, ..MeasureRequest::default() }.options().unwrap_err();
        assert!(e.naming(&flag).starts_with("--max-seconds must be a finite number of seconds ≥ 0"), "{e}");
        let e = SweepRequest { vary: vec!["/ior=1..2:3".into()], log: vec!["/x".into()], ..SweepRequest::default() }
            .axes()
            .unwrap_err();
        assert_eq!(e.naming(&flag), "--log /x: not a --vary path");
        let e = ProfileRequest { max_total_evals: 0, ..ProfileRequest::default() }.options().unwrap_err();
        assert_eq!(e.naming(&flag), "--max-evals and --max-total-evals must be at least 1");
        let e = ConvergenceRequest { max_repetitions: 0, ..ConvergenceRequest::default() }.options().unwrap_err();
        assert_eq!(e.naming(&flag), "--max-repetitions must be at least 1");
        let e = CompareRequest { max_de00: Some(-1.0), ..CompareRequest::default() }.max_de00().unwrap_err();
        assert_eq!(e.naming(&flag), "--max-de00 must be a finite number ≥ 0, got `-1`");
        let e = FitRequest { uncertainty: 0.0, ..FitRequest::default() }.options().unwrap_err();
        assert_eq!(e.naming(&flag), "--uncertainty must be a finite number > 0, got `0`");
        assert_eq!(parse_delimiter("|").unwrap_err().naming(&flag), "--delimiter must be `,`, `;` or `tab`, got `|`");
    }

    #[test]
    fn a_template_key_given_twice_is_refused_as_in_a_recipe() {
        let text = r#"{"model": "smooth-dielectric", "ior": 1.5, "ior": 1.6}"#;
        let e = SweepRequest { vary: vec!["/ior=1.4..1.6:3".into()], ..SweepRequest::default() }
            .sweep(text, "t.json", vec![])
            .err()
            .expect("refused");
        assert!(e.to_string().contains("a key appears twice"), "{e}");
        assert!(recipe::parse_str(text, "t.json").is_err());
    }

    #[test]
    fn the_picture_uses_the_sweeps_grid() {
        let text = r#"{"model": "smooth-dielectric", "ior": 1.5}"#;
        let r = VsParameterRequest { vary: Some("/ior=1.3..1.8".into()), points: Some(6), ..Default::default() };
        let s = r.sweep(text, "t.json", vec![]).unwrap();
        // The sweep's rounded decimals: 1.3, 1.4, …, 1.8 (not 1.4000000000000001).
        let xs: Vec<f64> = (0..s.len()).map(|i| s.point(i)[0]).collect();
        assert_eq!(xs, [1.3, 1.4, 1.5, 1.6, 1.7, 1.8]);
        assert!(!s.axes[0].log);
        // A range over a decade is logarithmic by default, with its ends exact.
        let r = VsParameterRequest { vary: Some("/ior=0.1..10".into()), points: Some(3), ..Default::default() };
        let s = r.sweep(r#"{"model": "lambert", "albedo": 0.5}"#, "t.json", vec![]);
        assert!(s.is_err(), "/ior is no parameter of lambert");
        let e = VsParameterRequest { vary: Some("/ior=1..2".into()), points: Some(1), ..Default::default() }
            .sweep(text, "t.json", vec![])
            .err()
            .expect("refused");
        assert_eq!(e.naming(&flag), "--points must be 2 to 200, got 1");
    }
}
