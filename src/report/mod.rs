//! The readings as documents: the JSON, JSON lines and CSV that `measure`, `sweep`, `compare` and `fit` print,
//! written by the library so that every program (the command line, the Python bindings) gets the same fields.
//! The JSON form is a contract for scripts and CI (docs/instrument.md §Output), and its schemas are beside the
//! writers. A reading without a finite value is null in JSON and empty in CSV, with the reason: never NaN or
//! inf. The text tables for people are the command line's (`cli::format`), the JUnit XML is `junit` (feature `junit`); the
//! command line chooses a document, prints it and writes it.
//!
//! The folder, a file per family of documents:
//! * `mod.rs`: what the documents share: the numbers ([`decimals`], [`plain`]), one reading as JSON
//!   ([`ReadingDoc`], [`reading_json`]) and as a sweep's line holds it ([`SweepReadingDoc`], in a
//!   [`SweepLineDoc`] that `crate::sweep` writes), the baseline checks ([`BaselineDoc`], [`drift_json`]), JSON
//!   printed ([`pretty`]) and CSV text ([`csv_text`]);
//! * [`measure`]: one recipe's readings as JSON and CSV, with the envelope, the baseline and, for many
//!   recipes, each reading's material;
//! * [`compare`]: the predictions beside a sheet, as JSON and CSV;
//! * [`fit`]: the fit's report as JSON;
//! * [`topography`]: a measured topography's statistics as JSON (`glossmeter topography`);
//! * [`schema`]: the JSON Schemas of the outputs, derived (`schemars`) from the document types: the structs
//!   that the writers serialise ([`ReadingDoc`], [`measure::MeasureDoc`], [`compare::CompareDoc`],
//!   [`fit::FitDoc`], ...), so a field cannot be written without being in its schema.
pub mod compare;
pub mod convergence;
pub mod fit;
#[cfg(feature = "junit")]
pub(crate) mod junit;
pub mod measure;
#[cfg(feature = "pictures")]
pub(crate) mod pictures;
pub mod profile;
pub mod schema;
pub mod topography;

use crate::colorimetry::Conditions;
use crate::comparison::propagation::PredictionUncertainty;
use crate::comparison::Drift;
use crate::instrument::envelope::Envelope;
use crate::instrument::plan::Reading;
use crate::{Error, Result};
use schemars::JsonSchema;
use serde::Serialize;

/// Decimal places of a reading in the table: one, i.e. 0.1 of the instrument's unit (GU, HU, DOI), as a
/// glossmeter displays it (ASTM D523 reports gloss to 0.1 GU); none if the numerical error is larger than
/// half of that. Full precision is in the JSON and CSV output; the numerical error has its own column.
pub(crate) fn decimals(error: f64) -> usize {
    if error.is_finite() && error > 0.05 {
        0
    } else {
        1
    }
}

/// The step a reading of `unit` is displayed in by the instrument that reads it (docs/instrument.md §Numbers
/// in text): 0.1 for gloss, haze (linear and log) and DOI (`GU`, `HU`, `HU(log)`, `DOI`: the one-decimal
/// display of gloss, haze and DOI meters) and for the hue angle (`°`); 0.01 for the colour coordinates X, Y, Z,
/// L*, a*, b*, C* (unit `""`: the two-decimal CIELAB display of spectrophotometers) and any other unit. A
/// display convention, not a number of any standard; the page of `glossmeter serve` rounds by the same table.
pub(crate) fn display_step(unit: &str) -> f64 {
    match unit {
        "GU" | "HU" | "HU(log)" | "DOI" | "°" => 0.1,
        _ => 0.01,
    }
}

/// `v` as the instrument displays it: rounded to the multiple of `step` nearest it (a half up, as the page's
/// `Math.round`), with the step's decimals; `-0.0` is `0.0`; a value of 10¹⁵ or more in scientific notation
/// ([`shown`]).
pub(crate) fn displayed(v: f64, step: f64) -> String {
    let d = (-step.log10()).round().max(0.0) as usize;
    if !v.is_finite() || v.abs() >= 1e15 {
        return shown(v, d);
    }
    let s = format!("{:.d$}", (v / step + 0.5).floor() * step);
    if s.starts_with('-') && s[1..].bytes().all(|b| b == b'0' || b == b'.') {
        s[1..].to_string()
    } else {
        s
    }
}

/// A number for CSV: the shortest digits that read back to the same double, plain decimals in
/// [10⁻¹⁵, 10¹⁵) (never `1e2`) and scientific notation outside it (`1e300`, not 301 digits; every CSV reader
/// takes both; `docs/instrument.md` §Numbers in text).
pub(crate) fn plain(v: f64) -> String {
    if v.is_finite() && v != 0.0 && !(1e-15..1e15).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// A measured number (a sheet's mean, std, min, max; a difference or an allowance built from them) for CSV and
/// JUnit text: rounded to ten significant digits, then its shortest decimals, plain or scientific as [`plain`].
/// A sheet's 99.99 averaged in binary is `99.99000000000001`; no instrument reads to 10⁻¹⁴ GU, so it prints
/// `99.99` (docs/instrument.md §Numbers in text). JSON keeps the full double.
pub(crate) fn measured(v: f64) -> String {
    if !v.is_finite() || v == 0.0 {
        return plain(v);
    }
    plain(format!("{v:.9e}").parse::<f64>().unwrap_or(v))
}

/// An error estimate alone for text (JUnit messages): two significant digits, rounded up (a printed estimate is
/// never below the computed one); plain in [10⁻³, 10⁶), else `3.6e-11`.
pub(crate) fn error_text(e: f64) -> String {
    if !(e.is_finite() && e > 0.0) {
        return plain(e);
    }
    two_digits_up(e)
}

/// A value and its error estimate for CSV, each to the precision the estimate gives it (docs/instrument.md
/// §Numbers in text): the value rounded at the estimate's third significant digit (at most 17 significant
/// digits), the estimate to two significant digits rounded up after adding the value's rounding (half a unit of
/// its last printed digit), so that the printed estimate still covers the printed value's error. Both are plain
/// decimals in [10⁻¹⁵, 10¹⁵) as [`plain`]: `89.14 ± 3.5763209946461607e-11` prints `89.1400000000000` and
/// `0.000000000036`. A zero or non-finite estimate leaves the value at [`measured`].
pub(crate) fn with_error(v: f64, e: f64) -> (String, String) {
    match rounded(v, e) {
        Some((value, up)) => (value, plain_two_digits(up)),
        None => (measured(v), if e.is_finite() { plain(e) } else { String::new() }),
    }
}

/// [`with_error`] for text (JUnit messages): the estimate as [`error_text`] writes it (`3.6e-11`).
pub(crate) fn with_error_text(v: f64, e: f64) -> (String, String) {
    match rounded(v, e) {
        Some((value, up)) => (value, two_digits_up(up)),
        None => (measured(v), if e.is_finite() { plain(e) } else { String::new() }),
    }
}

/// The value rounded to its estimate's precision, and the estimate plus that rounding (None without a positive
/// finite estimate).
fn rounded(v: f64, e: f64) -> Option<(String, f64)> {
    if !(v.is_finite() && e.is_finite() && e > 0.0) {
        return None;
    }
    // The place of the estimate's third significant digit, and the value's decimals (negative: tens, ...).
    let place = e.log10().floor() as i32 - 2;
    let magnitude = if v == 0.0 { place } else { v.abs().log10().floor() as i32 };
    let place = place.max(magnitude - 16);
    let half_unit = 0.5 * 10f64.powi(place);
    let value = if (1e-15..1e15).contains(&v.abs()) || v == 0.0 {
        if place < 0 {
            format!("{v:.*}", (-place) as usize)
        } else {
            let unit = 10f64.powi(place);
            format!("{:.0}", (v / unit).round() * unit)
        }
    } else {
        format!("{v:.*e}", (magnitude - place).clamp(0, 16) as usize)
    };
    Some((value, e + half_unit))
}

/// `x` > 0 rounded up to two significant digits, as [`plain`] writes numbers (plain in [10⁻¹⁵, 10¹⁵)).
/// An uncertainty in CSV: two significant digits, rounded up, as plain decimals from 10⁻¹⁵ to 10¹⁵.
pub(crate) fn plain_two_digits(x: f64) -> String {
    let (r, q) = up_two_digits(x);
    if (1e-15..1e15).contains(&r) {
        format!("{r:.*}", (1 - q).max(0) as usize)
    } else {
        format!("{r:.1e}")
    }
}

/// `x` > 0 rounded up to two significant digits, and the power of ten of its first digit.
fn up_two_digits(x: f64) -> (f64, i32) {
    let q = x.log10().floor() as i32;
    let unit = 10f64.powi(q - 1);
    // The quotient carries the division's rounding; a hair above a whole number is that number.
    let m = x / unit;
    let m = if m - m.floor() < 1e-12 { m.floor() } else { m.ceil() };
    (m * unit, q)
}

/// `x` > 0 rounded up to two significant digits: plain in [10⁻³, 10⁶), else `3.6e-11`.
fn two_digits_up(x: f64) -> String {
    let (r, q) = up_two_digits(x);
    if (1e-3..1e6).contains(&r) {
        format!("{r:.*}", (1 - q).max(0) as usize)
    } else {
        format!("{r:.1e}")
    }
}

/// A reading's value for a table: `decimals` places, or three significant digits in scientific notation
/// from 10¹⁵ on (a 1e300-class reading is not a 300-character column).
pub(crate) fn shown(v: f64, decimals: usize) -> String {
    if v.is_finite() && v.abs() >= 1e15 {
        format!("{v:.3e}")
    } else {
        format!("{v:.decimals$}")
    }
}

/// A document as a JSON value. Built from the document's struct, never re-parsed from text (serde_json's
/// default float parser is not exact to the last bit); a non-finite number would be null (the writers put none).
pub fn to_json<T: Serialize>(doc: &T) -> serde_json::Value {
    serde_json::to_value(doc).expect("a report document serialises (string keys, no custom serialisers)")
}

/// For a document type's schemars `transform`: these nullable fields (`Option` without `skip_serializing_if`)
/// are always written, as null when there is nothing, so they are required. (schemars leaves an `Option` field
/// out of `required`, and its `required` attribute forbids null.) A transform is named by a function path, not
/// an expression: the derive parses it with syn's default features (the library alone builds without syn's
/// `full`).
pub(crate) fn nullable_but_written(schema: &mut schemars::Schema, fields: &[&str]) {
    let required = schema.ensure_object().entry("required").or_insert_with(|| serde_json::Value::Array(vec![]));
    if let Some(required) = required.as_array_mut() {
        for f in fields {
            if !required.iter().any(|r| r == f) {
                required.push((*f).into());
            }
        }
    }
}

/// The quantities a reading can be of (`Reading::quantity`).
const QUANTITIES: [&str; 15] = [
    "gloss",
    "haze",
    "log-haze",
    "haze-compensated",
    "log-haze-compensated",
    "doi",
    "haze-index",
    "X",
    "Y",
    "Z",
    "L*",
    "a*",
    "b*",
    "C*",
    "h",
];

fn quantity_enum(schema: &mut schemars::Schema) {
    schema.insert("enum".into(), QUANTITIES.into());
}

/// The CIE illuminant and observer a colour reading is computed under, by the names `--illuminant` and
/// `--observer` take (docs/instrument.md §Output): flattened into every document's colour readings (`measure`,
/// `sweep`, `compare`, `fit`, `convergence`), absent on the others.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConditionsDoc {
    /// `D65`, `D50`, `A` or `C`.
    #[schemars(extend("enum" = ["D65", "D50", "A", "C"]))]
    pub illuminant: String,
    /// `2` (CIE 1931 2°) or `10` (CIE 1964 10°).
    #[schemars(extend("enum" = ["2", "10"]))]
    pub observer: String,
}

impl ConditionsDoc {
    pub(crate) fn new(c: Conditions) -> ConditionsDoc {
        ConditionsDoc { illuminant: c.illuminant.id().to_owned(), observer: c.observer.id().to_owned() }
    }

    /// The two CSV cells of a reading (`illuminant`, `observer`), empty on a reading that is no colour.
    pub(crate) fn cells(c: Option<Conditions>) -> [String; 2] {
        c.map(|c| [c.illuminant.id().to_owned(), c.observer.id().to_owned()]).unwrap_or_default()
    }
}

/// One reading of `measure --format json` (docs/instrument.md §Output; the Python bindings' dicts).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = reading_doc_nullable)]
#[serde(deny_unknown_fields)]
pub struct ReadingDoc {
    /// The geometry id.
    pub geometry: String,
    /// The reading's name (e.g. haze-narrow).
    pub name: String,
    /// What the reading is.
    #[schemars(transform = quantity_enum)]
    pub quantity: String,
    /// The reading; null when there is no finite value (see problem).
    pub value: Option<f64>,
    pub unit: String,
    /// The numerical error estimate (of the integration); null when there is no value.
    #[schemars(range(min = 0))]
    pub error_estimate: Option<f64>,
    /// A measured table's data (resolution) uncertainty, in the reading's unit: the reading through the table on
    /// every second sample against the reading through the table (docs/accuracy.md); absent for models and
    /// readings without a value.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 0))]
    pub data_uncertainty: Option<f64>,
    /// BRDF evaluations of the integrals this reading uses.
    pub evaluations: usize,
    /// Whether every integral met the tolerance within the budgets.
    pub converged: bool,
    /// Wall time in seconds; absent with --no-timing.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 0))]
    pub seconds: Option<f64>,
    /// Why there is no value, or what limits it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub problem: Option<String>,
    /// What the reader should know (e.g. a standard's scope).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// A colour reading (X, Y, Z, L*, a*, b*, C*, h)'s CIE illuminant and observer ([`ConditionsDoc`]); absent on every other reading.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub colour: Option<ConditionsDoc>,
    /// With --envelope: the least reading within the tolerances (null where the data give none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub envelope_min: Option<Option<f64>>,
    /// With --envelope: the greatest reading within the tolerances (null where the data give none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub envelope_max: Option<Option<f64>>,
    /// With --envelope: how the envelope was read.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub envelope: Option<EnvelopeDoc>,
    /// With --envelope and --max-seconds: the limit (the whole command's) was reached before this geometry's
    /// envelope was read, so it is null (exit 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(extend("const" = true))]
    pub envelope_cut: Option<bool>,
    /// When the recipe states uncertainties of its numbers (its `uncertainty` block): the prediction's standard
    /// uncertainty u_pred in the reading's unit, propagated to first order (docs/instrument.md §The
    /// prediction's uncertainty). Separate from `error_estimate`, the numerical error.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 0))]
    pub prediction_uncertainty: Option<f64>,
    /// With `prediction_uncertainty`: each stated number's share of it (u_pred² is the sum of the squared
    /// contributions).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uncertainty_budget: Option<Vec<BudgetLineDoc>>,
}

/// One line of a reading's uncertainty budget: a number of the recipe, its stated standard uncertainty, the
/// reading's sensitivity to it and the contribution (docs/instrument.md §The prediction's uncertainty).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BudgetLineDoc {
    /// The JSON Pointer of the number in the recipe.
    pub pointer: String,
    /// Its stated standard uncertainty u(x), in its unit.
    #[schemars(range(min = 0))]
    pub u: f64,
    /// ∂y/∂x by a difference with the step u(x): the reading's unit per the number's unit.
    pub sensitivity: f64,
    /// |∂y/∂x|·u(x), in the reading's unit.
    #[schemars(range(min = 0))]
    pub contribution: f64,
    /// How the sensitivity was differenced: central, or one-sided where x ± u(x) leaves the number's range.
    #[schemars(extend("enum" = ["central", "forward", "backward"]))]
    pub difference: String,
}

impl BudgetLineDoc {
    /// The budget of a prediction uncertainty.
    pub(crate) fn budget(u: &PredictionUncertainty) -> Vec<BudgetLineDoc> {
        u.contributions
            .iter()
            .map(|c| BudgetLineDoc {
                pointer: c.pointer.clone(),
                u: c.u,
                sensitivity: c.sensitivity,
                contribution: c.contribution,
                difference: c.difference.label().into(),
            })
            .collect()
    }
}

impl ReadingDoc {
    pub fn new(r: &Reading, timing: bool) -> ReadingDoc {
        ReadingDoc {
            geometry: r.geometry.clone(),
            name: r.name.clone(),
            quantity: r.quantity.clone(),
            value: r.value,
            unit: r.unit.clone(),
            error_estimate: r.value.map(|_| r.error_estimate),
            data_uncertainty: r.value.and(r.data_uncertainty),
            evaluations: r.evaluations,
            converged: r.converged,
            seconds: timing.then_some(r.seconds),
            problem: r.problem.clone(),
            note: r.note.clone(),
            colour: r.colour.map(ConditionsDoc::new),
            envelope_min: None,
            envelope_max: None,
            envelope: None,
            envelope_cut: None,
            prediction_uncertainty: None,
            uncertainty_budget: None,
        }
    }

    /// With the prediction's uncertainty (None: the recipe states none, or the reading has no value).
    pub fn with_uncertainty(mut self, u: Option<&PredictionUncertainty>) -> ReadingDoc {
        self.prediction_uncertainty = u.map(|u| u.u);
        self.uncertainty_budget = u.map(BudgetLineDoc::budget);
        self
    }

    /// With the tolerance envelope of `measure --envelope` (`None`: the standard data give no tolerance).
    pub(crate) fn with_envelope(mut self, e: Option<&Envelope>, cut: bool) -> ReadingDoc {
        self.envelope_cut = cut.then_some(true);
        self.envelope_min = Some(e.map(|e| e.min));
        self.envelope_max = Some(e.map(|e| e.max));
        self.envelope = e.map(EnvelopeDoc::new);
        self
    }
}

/// How a reading's envelope was read: the variant geometries, the method and the numbers varied.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EnvelopeDoc {
    /// How many variant geometries were read.
    pub variants: usize,
    /// "all corners" or "one number at a time".
    #[schemars(extend("enum" = ["all corners", "one number at a time"]))]
    pub method: String,
    pub varied: Vec<VariationDoc>,
}

/// One number of a geometry varied within its tolerance (`envelope::Variation`).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VariationDoc {
    /// JSON Pointer of the number in the geometry file.
    pub pointer: String,
    /// "tolerance" or "plausible".
    pub kind: String,
    pub nominal: f64,
    pub low: f64,
    pub high: f64,
    /// The variation's own status (verified, secondary, assumed).
    pub status: String,
}

impl EnvelopeDoc {
    fn new(e: &Envelope) -> EnvelopeDoc {
        EnvelopeDoc {
            variants: e.variants,
            method: if e.corners { "all corners" } else { "one number at a time" }.into(),
            varied: e
                .variations
                .iter()
                .map(|v| VariationDoc {
                    pointer: v.pointer.clone(),
                    kind: v.kind.into(),
                    nominal: v.nominal,
                    low: v.low,
                    high: v.high,
                    status: v.status.clone(),
                })
                .collect(),
        }
    }
}

/// One reading as `measure --format json` writes it (the schema is [`schema::measure`]).
pub fn reading_json(r: &Reading, timing: bool) -> serde_json::Value {
    to_json(&ReadingDoc::new(r, timing))
}

/// One baseline check: a reading then and now, and whether it moved.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DriftDoc {
    pub material: String,
    pub geometry: String,
    pub reading: String,
    pub now: f64,
    pub then: f64,
    /// The difference allowed.
    #[schemars(range(min = 0))]
    pub allowed: f64,
    pub moved: bool,
}

impl From<&Drift> for DriftDoc {
    fn from(d: &Drift) -> DriftDoc {
        DriftDoc {
            material: d.material.clone(),
            geometry: d.geometry.clone(),
            reading: d.reading.clone(),
            now: d.now,
            then: d.then,
            allowed: d.allowed,
            moved: d.moved,
        }
    }
}

/// The baseline checks of `measure --baseline` and `compare --baseline`.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BaselineDoc {
    /// The baseline file.
    pub file: String,
    pub checks: Vec<DriftDoc>,
    /// How many readings moved by more than allowed.
    pub moved: usize,
}

impl BaselineDoc {
    pub(crate) fn new(file: String, drift: &[Drift]) -> BaselineDoc {
        BaselineDoc {
            file,
            checks: drift.iter().map(DriftDoc::from).collect(),
            moved: drift.iter().filter(|d| d.moved).count(),
        }
    }
}

/// One baseline check (a reading then and now, and whether it moved), as `measure` and `compare` list them.
pub fn drift_json(d: &Drift) -> serde_json::Value {
    to_json(&DriftDoc::from(d))
}

/// A JSON value as the CLI prints it: pretty, with a final newline.
pub fn pretty(doc: &serde_json::Value) -> String {
    let mut s = serde_json::to_string_pretty(doc).expect("finite values serialise");
    s.push('\n');
    s
}

/// One reading of a `sweep --format jsonl` line: the fields of a `measure` reading without the quantity, the
/// evaluation count, the note and the time.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = sweep_reading_doc_nullable)]
#[serde(deny_unknown_fields)]
pub struct SweepReadingDoc {
    pub geometry: String,
    pub name: String,
    pub unit: String,
    /// null when there is no finite value (see problem).
    pub value: Option<f64>,
    /// The numerical error estimate; null when there is no value.
    #[schemars(range(min = 0))]
    pub error_estimate: Option<f64>,
    pub converged: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub problem: Option<String>,
    /// A colour reading's illuminant and observer, as [`ReadingDoc`]'s.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub colour: Option<ConditionsDoc>,
}

impl SweepReadingDoc {
    pub(crate) fn new(r: &Reading) -> SweepReadingDoc {
        let d = ReadingDoc::new(r, false);
        SweepReadingDoc {
            geometry: d.geometry,
            name: d.name,
            unit: d.unit,
            value: d.value,
            error_estimate: d.error_estimate,
            converged: d.converged,
            problem: d.problem,
            colour: d.colour,
        }
    }
}

/// One line of `sweep --format jsonl`: the point's index and parameter values, and its readings or why there
/// are none (the lines are written by `crate::sweep`).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(title = "glossmeter sweep --format jsonl (one object per line)")]
pub struct SweepLineDoc {
    /// The point's index in the grid or design.
    pub index: u64,
    /// The varied values, by JSON Pointer.
    pub parameters: std::collections::BTreeMap<String, f64>,
    /// The readings at this point (absent when the recipe at this point is invalid).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub readings: Option<Vec<SweepReadingDoc>>,
    /// Why the recipe at this point is invalid (then no readings).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub problem: Option<String>,
    /// Wall time in seconds; absent with --no-timing.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 0))]
    pub seconds: Option<f64>,
}

/// CSV text in memory: the header, then one record per row (quoted where the csv crate must). Every CSV that
/// the command line writes (measure, many recipes, compare, convergence, profile) goes through here.
pub(crate) fn csv_text<R: IntoIterator<Item = String>>(
    header: &[&str],
    rows: impl IntoIterator<Item = R>,
) -> Result<String> {
    let err = |e: csv::Error| Error::Io { file: "<csv>".into(), source: std::io::Error::other(e) };
    let mut w = csv::Writer::from_writer(vec![]);
    w.write_record(header).map_err(err)?;
    for row in rows {
        w.write_record(row).map_err(err)?;
    }
    let bytes =
        w.into_inner().map_err(|e| Error::Io { file: "<csv>".into(), source: std::io::Error::other(e.to_string()) })?;
    Ok(String::from_utf8(bytes).expect("csv is utf-8"))
}

fn reading_doc_nullable(schema: &mut schemars::Schema) {
    nullable_but_written(schema, &["value", "error_estimate"]);
}

fn sweep_reading_doc_nullable(schema: &mut schemars::Schema) {
    nullable_but_written(schema, &["value", "error_estimate"]);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_text_are_rounded_to_their_precision() {
        assert_eq!(measured(99.99000000000001), "99.99");
        assert_eq!(measured(0.1 + 0.2), "0.3");
        assert_eq!(measured(-2.5e-20), "-2.5e-20");
        assert_eq!(error_text(0.000000000035763209946461607), "3.6e-11");
        assert_eq!(error_text(0.0123), "0.013");
        assert_eq!(error_text(0.012), "0.012");
        assert_eq!(error_text(250.0), "250");
        assert_eq!(
            with_error_text(89.13999999999999, 3.5763209946461607e-11),
            ("89.1400000000000".into(), "3.6e-11".into())
        );
        // CSV keeps plain decimals.
        assert_eq!(with_error(89.14, 3.5763209946461607e-11).1, "0.000000000036");
        assert_eq!(with_error(12.345, 0.21), ("12.345".into(), "0.22".into()));
        assert_eq!(with_error(12345.4, 250.0), ("12345".into(), "260".into()));
        // The printed estimate covers the printed value's error, whatever the digits.
        for (v, e) in [(1.23456789, 3.3e-4), (0.7, 0.0101), (-4.4, 0.0999), (5e20, 1e12), (1.5e-9, 2e-13)] {
            let (vs, es) = with_error(v, e);
            let (pv, pe): (f64, f64) = (vs.parse().unwrap(), es.parse().unwrap());
            assert!(pe >= e && (pv - v).abs() <= pe - e + 1e-15 * v.abs(), "{v} {e}: {vs} {es}");
        }
    }

    #[test]
    fn readings_are_displayed_in_their_units_step() {
        assert_eq!(displayed(89.14, display_step("GU")), "89.1");
        assert_eq!(displayed(89.15000001, display_step("GU")), "89.2");
        assert_eq!(displayed(-0.04, display_step("HU")), "0.0");
        assert_eq!(displayed(-0.06, display_step("DOI")), "-0.1");
        assert_eq!(displayed(52.345678, display_step("")), "52.35");
        assert_eq!(displayed(231.26, display_step("°")), "231.3");
        assert_eq!(displayed(2e20, 0.1), "2.000e20");
    }
}
