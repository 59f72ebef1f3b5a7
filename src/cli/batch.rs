//! `glossmeter measure A.json B.json DIR ...`: many recipes in one process (`crate::batch`), one table, CSV
//! or JSON with a material column; and `--baseline PREVIOUS.json` for one or many recipes.
use serde_json::{json, Value};

use crate::cli::{format, pad_table, Format};
use crate::comparison::Drift;
use crate::instrument::plan::Reading;
use crate::recipe::Material;
use crate::{Error, Result};

pub fn table(materials: &[Material], readings: &[Vec<Reading>], timing: bool) -> String {
    let mut head = vec!["material", "geometry", "reading", "value", "unit", "± error", "evaluations"];
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
                    row.push(format!("{:.*}", format::decimals(r.error_estimate), v));
                    row.push(r.unit.clone());
                    row.push(format!("{:.1e}", r.error_estimate));
                }
                None => {
                    row.extend(["—".to_string(), r.unit.clone(), "—".to_string()]);
                }
            }
            row.push(r.evaluations.to_string());
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
        let one: Value = serde_json::from_str(&format::json(m, rs, timing)).expect("our own JSON");
        for mut r in one["readings"].as_array().cloned().unwrap_or_default() {
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

/// The CSV of `measure` with `material` and `file` columns in front.
pub fn csv(materials: &[Material], readings: &[Vec<Reading>], timing: bool) -> Result<String> {
    let err = |e: csv::Error| Error::Io { file: "<csv>".into(), source: std::io::Error::other(e) };
    let mut w = csv::Writer::from_writer(vec![]);
    for (i, (m, rs)) in materials.iter().zip(readings).enumerate() {
        let one = format::csv(rs, timing)?;
        let mut rdr = csv::ReaderBuilder::new().has_headers(false).from_reader(one.as_bytes());
        for (j, rec) in rdr.records().enumerate() {
            let rec = rec.map_err(err)?;
            if j == 0 {
                if i == 0 {
                    let mut h = vec!["material", "file"];
                    h.extend(rec.iter());
                    w.write_record(&h).map_err(err)?;
                }
                continue;
            }
            let mut row = vec![m.name.as_str(), m.file.as_str()];
            row.extend(rec.iter());
            w.write_record(&row).map_err(err)?;
        }
    }
    let bytes =
        w.into_inner().map_err(|e| Error::Io { file: "<csv>".into(), source: std::io::Error::other(e.to_string()) })?;
    Ok(String::from_utf8(bytes).expect("utf-8"))
}

/// The text of a batch in a format.
pub fn render(format: Format, materials: &[Material], readings: &[Vec<Reading>], timing: bool) -> Result<String> {
    Ok(match format {
        Format::Table => table(materials, readings, timing),
        Format::Json => serde_json::to_string_pretty(&json_doc(materials, readings, timing)).expect("finite") + "\n",
        Format::Csv => csv(materials, readings, timing)?,
    })
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
