//! The readings as documents: the JSON, JSON lines and CSV that `measure`, `sweep`, `compare` and `fit` print,
//! written by the library so that every program (the command line, the Python bindings) gets the same fields.
//! The JSON form is a contract for scripts and CI (docs/instrument.md §Output), and its schemas are beside the
//! writers. A reading without a finite value is null in JSON and empty in CSV, with the reason: never NaN or
//! inf. The text tables for people and the JUnit XML are the command line's (`cli::format`, `cli::junit`); the
//! command line chooses a document, prints it and writes it.
//!
//! The folder, a file per family of documents:
//! * `mod.rs`: what the documents share: the numbers ([`decimals`], [`plain`]), one reading as JSON
//!   ([`reading_json`]) and as a sweep writes it ([`sweep_reading_json`]; the sweep's lines are
//!   `crate::sweep`'s), one baseline check ([`drift_json`]), JSON printed ([`pretty`]) and CSV text
//!   ([`csv_text`]);
//! * [`measure`]: one recipe's readings as JSON and CSV, with the envelope, the baseline and, for many
//!   recipes, each reading's material;
//! * [`compare`]: the predictions beside a sheet, as JSON and CSV;
//! * [`fit`]: the fit's report as JSON;
//! * [`schema`]: the JSON Schemas of the outputs.
pub mod compare;
pub mod fit;
pub mod measure;
pub mod schema;

use crate::comparison::Drift;
use crate::instrument::plan::Reading;
use crate::{Error, Result};
use serde_json::json;

/// Decimal places of a reading in the table: one, i.e. 0.1 of the instrument's unit (GU, HU, DOI), as a
/// glossmeter displays it (ASTM D523 reports gloss to 0.1 GU); none if the numerical error is larger than
/// half of that. Full precision is in the JSON and CSV output; the numerical error has its own column.
pub fn decimals(error: f64) -> usize {
    if error.is_finite() && error > 0.05 {
        0
    } else {
        1
    }
}

/// A number for CSV: the shortest digits that read back to the same double, plain decimals in
/// [10⁻¹⁵, 10¹⁵) (never `1e2`) and scientific notation outside it (`1e300`, not 301 digits; every CSV reader
/// takes both; `docs/instrument.md` §Numbers in text).
pub fn plain(v: f64) -> String {
    if v.is_finite() && v != 0.0 && !(1e-15..1e15).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// A reading's value for a table: `decimals` places, or three significant digits in scientific notation
/// from 10¹⁵ on (a 1e300-class reading is not a 300-character column).
pub fn shown(v: f64, decimals: usize) -> String {
    if v.is_finite() && v.abs() >= 1e15 {
        format!("{v:.3e}")
    } else {
        format!("{v:.decimals$}")
    }
}

/// One reading as `measure --format json` writes it (the schema is [`schema::measure`]).
pub fn reading_json(r: &Reading, timing: bool) -> serde_json::Value {
    let mut o = json!({
        "geometry": r.geometry,
        "name": r.name,
        "quantity": r.quantity,
        "value": r.value,
        "unit": r.unit,
        "error_estimate": if r.value.is_some() { Some(r.error_estimate) } else { None },
        "evaluations": r.evaluations,
        "converged": r.converged,
    });
    if let (Some(_), Some(u)) = (r.value, r.data_uncertainty) {
        o["data_uncertainty"] = json!(u);
    }
    if timing {
        o["seconds"] = json!(r.seconds);
    }
    if let Some(p) = &r.problem {
        o["problem"] = json!(p);
    }
    if let Some(n) = &r.note {
        o["note"] = json!(n);
    }
    o
}

/// One baseline check (a reading then and now, and whether it moved), as `measure` and `compare` list them.
pub fn drift_json(d: &Drift) -> serde_json::Value {
    json!({"material": d.material, "geometry": d.geometry, "reading": d.reading,
           "now": d.now, "then": d.then, "allowed": d.allowed, "moved": d.moved})
}

/// A JSON value as the CLI prints it: pretty, with a final newline.
pub fn pretty(doc: &serde_json::Value) -> String {
    let mut s = serde_json::to_string_pretty(doc).expect("finite values serialise");
    s.push('\n');
    s
}

/// The fields [`sweep_reading_json`] keeps.
const SWEEP_READING_FIELDS: [&str; 7] = ["geometry", "name", "unit", "value", "error_estimate", "converged", "problem"];

/// One reading as a line of `sweep --format jsonl` writes it (the schema is [`schema::sweep`]): the object of
/// [`reading_json`] without the quantity, the evaluation count, the note and the time.
pub fn sweep_reading_json(r: &Reading) -> serde_json::Value {
    let mut o = reading_json(r, false);
    if let Some(fields) = o.as_object_mut() {
        fields.retain(|k, _| SWEEP_READING_FIELDS.contains(&k.as_str()));
    }
    o
}

/// CSV text in memory: the header, then one record per row (quoted where the csv crate must). Every CSV that
/// the command line writes (measure, many recipes, compare, convergence, profile) goes through here.
pub fn csv_text<R: IntoIterator<Item = String>>(header: &[&str], rows: impl IntoIterator<Item = R>) -> Result<String> {
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
