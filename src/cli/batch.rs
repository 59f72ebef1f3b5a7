//! `glossmeter measure A.json B.json DIR ...`: many recipes in one process (`crate::batch`), one table, CSV
//! or JSON with a material column; and `--baseline PREVIOUS.json` for one or many recipes.
use serde_json::{json, Value};

use crate::cli::common::pad_table;
use crate::cli::format;
use crate::comparison::Drift;
use crate::instrument::plan::Reading;
use crate::recipe::Material;
use crate::report;
use crate::{Error, Result};

pub fn table(materials: &[Material], readings: &[Vec<Reading>], timing: bool) -> String {
    let mut head = vec!["material", "geometry", "reading", "value", "unit", "numerical error", "evaluations"];
    if timing {
        head.push("time");
    }
    let mut rows = vec![head.iter().map(|s| s.to_string()).collect::<Vec<_>>()];
    let mut notes = vec![];
    for (m, rs) in materials.iter().zip(readings) {
        for r in rs {
            let mut row = vec![m.name.clone(), r.geometry.clone(), r.name.clone()];
            match r.value {
                Some(v) => {
                    row.push(format!("{:.*}", report::decimals(r.error_estimate), v));
                    row.push(r.unit.clone());
                    row.push(format!("{:.1e}", r.error_estimate));
                }
                None => {
                    row.extend(["—".to_string(), r.unit.clone(), "—".to_string()]);
                }
            }
            // The mark (and its footnote) only on a printed value: a reading without one says why in its note.
            row.push(if r.converged || r.value.is_none() {
                r.evaluations.to_string()
            } else {
                format!("{} *", r.evaluations)
            });
            if timing {
                row.push(format::secs(r.seconds));
            }
            for n in [&r.problem, &r.note].into_iter().flatten() {
                notes.push(format!("{} {} {}: {n}", m.name, r.geometry, r.name));
            }
            rows.push(row);
        }
    }
    let mut s = format!("{} recipe(s)\n", materials.len());
    for m in materials {
        s.push_str(&format!("{}: {} ({})\n", m.name, m.brdf.describe(), m.file));
    }
    s.push('\n');
    s.push_str(&pad_table(&rows, &[3, 5, 6, 7]));
    let all = || readings.iter().flatten();
    if all().any(|r| !r.converged && r.value.is_some()) {
        s.push_str("* not converged: the evaluation budget ran out before the tolerance was met\n");
    }
    if all().any(|r| r.value.is_some()) {
        s.push_str("numerical error: the integration's error estimate, not the uncertainty of the prediction\n");
    }
    for n in notes {
        s.push_str(&format!("note: {n}\n"));
    }
    s
}

/// The JSON of `measure` for many recipes: `materials` and `readings`, each reading with its `material` and
/// `file` (the per-reading fields are those of the one-recipe JSON).
pub fn json_doc(materials: &[Material], readings: &[Vec<Reading>], timing: bool) -> Value {
    let mut all = vec![];
    for (m, rs) in materials.iter().zip(readings) {
        for r in rs {
            let mut r = report::reading_json(r, timing);
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
/// plan, each distinct integral counted once) and their sum at the top of a [`json_doc`] document.
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
pub fn csv(materials: &[Material], readings: &[Vec<Reading>], timing: bool) -> Result<String> {
    let err = |e: csv::Error| Error::Io { file: "<csv>".into(), source: std::io::Error::other(e) };
    let mut head: Option<Vec<String>> = None;
    let mut rows = vec![];
    for (m, rs) in materials.iter().zip(readings) {
        let one = report::csv(rs, timing)?;
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
        Some(h) => report::csv_text(&h.iter().map(String::as_str).collect::<Vec<_>>(), rows),
        None => Ok(String::new()),
    }
}

/// The baseline lines of a table.
pub fn drift_text(drift: &[Drift]) -> String {
    let moved: Vec<&Drift> = drift.iter().filter(|d| d.moved).collect();
    let mut s = format!("baseline: {} reading(s) checked, {} moved\n", drift.len(), moved.len());
    for d in moved {
        s.push_str(&format!(
            "moved: {} {} {}: {} then, {} now (allowed {:.1e})\n",
            d.material, d.geometry, d.reading, d.then, d.now, d.allowed
        ));
    }
    s
}
