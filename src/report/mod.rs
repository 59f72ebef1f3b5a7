//! The readings as documents: the JSON, JSON lines and CSV that `measure`, `sweep`, `compare` and `fit` print,
//! written by the library so that every program (the command line, the Python bindings) gets the same fields.
//! The JSON form is a contract for scripts and CI (docs/instrument.md §Output), and its schemas are beside the
//! writers. A reading without a finite value is null in JSON and empty in CSV, with the reason: never NaN or
//! inf. The text tables for people are the command line's (`cli::format`).
//!
//! The folder:
//! * `mod.rs`: the numbers ([`decimals`], [`plain`]), one reading and one material's readings as JSON
//!   ([`reading_json`], [`json_doc`], [`json()`], [`pretty`], [`json_with_envelope`]), a sweep's reading
//!   ([`sweep_reading_json`]), and CSV ([`csv()`], [`csv_text`]);
//! * [`schema`]: the JSON Schemas of the outputs.
pub mod schema;

use crate::instrument::envelope::Envelope;
use crate::instrument::plan::Reading;
use crate::recipe::Material;
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

/// A number for CSV: plain decimal digits, the shortest that read back to the same double (never `1e2`).
pub fn plain(v: f64) -> String {
    format!("{v}")
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

/// The JSON document of one material's readings (built as a value, never re-parsed: serde_json's default
/// float parser is not exact to the last bit).
pub fn json_doc(material: &Material, readings: &[Reading], timing: bool) -> serde_json::Value {
    json!({
        "material": {"name": material.name, "file": material.file, "model": material.brdf.describe()},
        "readings": readings.iter().map(|r| reading_json(r, timing)).collect::<Vec<_>>(),
    })
}

/// A JSON value as the CLI prints it: pretty, with a final newline.
pub fn pretty(doc: &serde_json::Value) -> String {
    let mut s = serde_json::to_string_pretty(doc).expect("finite values serialise");
    s.push('\n');
    s
}

pub fn json(material: &Material, readings: &[Reading], timing: bool) -> String {
    pretty(&json_doc(material, readings, timing))
}

/// Add `"envelope_min"`, `"envelope_max"` and the variations to each reading of a `json` document (null where
/// the standard data give no tolerance), and the envelope's method at the top.
pub fn json_with_envelope(mut doc: serde_json::Value, envelopes: &[Option<Envelope>]) -> serde_json::Value {
    if let Some(rs) = doc["readings"].as_array_mut() {
        for (r, e) in rs.iter_mut().zip(envelopes) {
            r["envelope_min"] = json!(e.as_ref().map(|e| e.min));
            r["envelope_max"] = json!(e.as_ref().map(|e| e.max));
            if let Some(e) = e {
                r["envelope"] = json!({
                    "variants": e.variants,
                    "method": if e.corners { "all corners" } else { "one number at a time" },
                    "varied": e.variations.iter().map(|v| json!({
                        "pointer": v.pointer, "kind": v.kind, "nominal": v.nominal, "low": v.low, "high": v.high, "status": v.status
                    })).collect::<Vec<_>>(),
                });
            }
        }
    }
    doc
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

/// The CSV of `measure`: a header, then one record per reading (the fields of [`reading_json`]).
pub fn csv(readings: &[Reading], timing: bool) -> Result<String> {
    let mut head = vec!["geometry", "name", "quantity", "value", "unit", "error_estimate", "evaluations", "converged"];
    if timing {
        head.push("seconds");
    }
    head.push("problem");
    head.push("note");
    let rows = readings.iter().map(|r| {
        let mut rec = vec![
            r.geometry.clone(),
            r.name.clone(),
            r.quantity.clone(),
            r.value.map(plain).unwrap_or_default(),
            r.unit.clone(),
            r.value.map(|_| plain(r.error_estimate)).unwrap_or_default(),
            r.evaluations.to_string(),
            r.converged.to_string(),
        ];
        if timing {
            rec.push(plain(r.seconds));
        }
        rec.push(r.problem.clone().unwrap_or_default());
        rec.push(r.note.clone().unwrap_or_default());
        rec
    });
    csv_text(&head, rows)
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
