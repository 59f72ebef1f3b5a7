//! The documents of `measure`: one recipe's readings as JSON (with the tolerance envelope and the baseline
//! checks when asked for) and as CSV, and the same for many recipes in one process (`crate::batch`), each
//! reading with its material and file (the schema of both JSON forms is [`super::schema::measure`]).
use serde_json::{json, Value};

use super::{csv_text, drift_json, plain, pretty, reading_json};
use crate::comparison::Drift;
use crate::instrument::envelope::Envelope;
use crate::instrument::plan::Reading;
use crate::recipe::Material;
use crate::{Error, Result};

/// The JSON document of one material's readings (built as a value, never re-parsed: serde_json's default
/// float parser is not exact to the last bit).
pub fn json_doc(material: &Material, readings: &[Reading], timing: bool) -> serde_json::Value {
    json!({
        "material": {"name": material.name, "file": material.file, "model": material.brdf.describe()},
        "readings": readings.iter().map(|r| reading_json(r, timing)).collect::<Vec<_>>(),
    })
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

/// The CSV of `measure`: a header, then one record per reading (the fields of [`reading_json`]).
pub fn csv(readings: &[Reading], timing: bool) -> Result<String> {
    let mut head = vec!["geometry", "name", "quantity", "value", "unit", "error_estimate", "evaluations", "converged"];
    if timing {
        head.push("seconds");
    }
    head.push("problem");
    head.push("note");
    let rows = readings.iter().map(|r| {
        // The value and its error estimate to their precision (docs/instrument.md §Numbers in text).
        let (value, error) = r.value.map(|v| super::with_error(v, r.error_estimate)).unwrap_or_default();
        let mut rec = vec![
            r.geometry.clone(),
            r.name.clone(),
            r.quantity.clone(),
            value.clone(),
            r.unit.clone(),
            error.clone(),
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

/// Add the baseline checks to a JSON document (when a baseline was given).
pub fn with_baseline(mut doc: serde_json::Value, drift: Option<&[Drift]>, file: Option<String>) -> serde_json::Value {
    if let (Some(d), Some(file)) = (drift, file) {
        doc["baseline"] = serde_json::json!({
            "file": file,
            "checks": d.iter().map(drift_json).collect::<Vec<_>>(),
            "moved": d.iter().filter(|x| x.moved).count(),
        });
    }
    doc
}

/// The JSON of `measure` for many recipes: `materials` and `readings`, each reading with its `material` and
/// `file` (the per-reading fields are those of the one-recipe JSON).
pub fn batch_json_doc(materials: &[Material], readings: &[Vec<Reading>], timing: bool) -> Value {
    let mut all = vec![];
    for (m, rs) in materials.iter().zip(readings) {
        for r in rs {
            let mut r = reading_json(r, timing);
            r["material"] = json!(m.name);
            r["file"] = json!(m.file);
            all.push(r);
        }
    }
    json!({
        "materials": materials.iter().map(|m| json!({"name": m.name, "file": m.file, "model": m.brdf.describe()})).collect::<Vec<_>>(),
        "readings": all,
    })
}

/// Add each material's plan cost (`"evaluations"` in its `materials` entry: the BRDF evaluations of its
/// plan, each distinct integral counted once) and their sum at the top of a [`batch_json_doc`] document.
pub fn with_evaluations(mut doc: Value, evaluations: &[usize]) -> Value {
    if let Some(ms) = doc["materials"].as_array_mut() {
        for (m, e) in ms.iter_mut().zip(evaluations) {
            m["evaluations"] = json!(e);
        }
    }
    doc["evaluations"] = json!(evaluations.iter().sum::<usize>());
    doc
}

/// The CSV of `measure` with `material` and `file` columns in front.
pub fn batch_csv(materials: &[Material], readings: &[Vec<Reading>], timing: bool) -> Result<String> {
    let err = |e: csv::Error| Error::Io { file: "<csv>".into(), source: std::io::Error::other(e) };
    let mut head: Option<Vec<String>> = None;
    let mut rows = vec![];
    for (m, rs) in materials.iter().zip(readings) {
        let one = csv(rs, timing)?;
        let mut rdr = csv::ReaderBuilder::new().has_headers(false).from_reader(one.as_bytes());
        for (j, rec) in rdr.records().enumerate() {
            let rec = rec.map_err(err)?;
            if j == 0 {
                head.get_or_insert_with(|| {
                    ["material", "file"].into_iter().chain(rec.iter()).map(String::from).collect()
                });
                continue;
            }
            rows.push(
                [m.name.as_str(), m.file.as_str()].into_iter().chain(rec.iter()).map(String::from).collect::<Vec<_>>(),
            );
        }
    }
    match head {
        Some(h) => csv_text(&h.iter().map(String::as_str).collect::<Vec<_>>(), rows),
        None => Ok(String::new()),
    }
}
