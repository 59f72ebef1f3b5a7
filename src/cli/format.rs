//! Output formats of `measure`. The JSON form is a contract for scripts and CI (docs/instrument.md
//! §Output); the table is for people. A reading without a finite value is printed as "—" in the table,
//! null in JSON, empty in CSV, with the reason: never as NaN or inf.
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

/// A duration for people: µs, ms or s.
pub fn secs(s: f64) -> String {
    if s < 1e-3 {
        format!("{:.1} µs", s * 1e6)
    } else if s < 1.0 {
        format!("{:.2} ms", s * 1e3)
    } else {
        format!("{s:.2} s")
    }
}

pub fn table(material: &Material, readings: &[Reading], timing: bool) -> String {
    let mut rows: Vec<Vec<String>> = vec![];
    let mut head = vec!["geometry", "reading", "value", "unit", "numerical error", "evaluations"];
    if timing {
        head.push("time");
    }
    rows.push(head.iter().map(|s| s.to_string()).collect());
    let mut notes = vec![];
    for r in readings {
        let mut row = vec![r.geometry.clone(), r.name.clone()];
        match r.value {
            Some(v) => {
                // A value that rounds to zero is shown as 0.0, never "-0.0" (a compensated haze of −1e-15).
                let shown = format!("{:.*}", decimals(r.error_estimate), v);
                let shown = if shown.trim_start_matches('-').chars().all(|c| c == '0' || c == '.') {
                    shown.trim_start_matches('-').to_string()
                } else {
                    shown
                };
                row.push(shown);
                row.push(r.unit.clone());
                row.push(format!("{:.1e}", r.error_estimate));
            }
            None => {
                row.push("—".into());
                row.push(r.unit.clone());
                row.push("—".into());
            }
        }
        // The mark (and its footnote) only on a printed value: a reading without one says why in its note.
        row.push(if r.converged || r.value.is_none() {
            r.evaluations.to_string()
        } else {
            format!("{} *", r.evaluations)
        });
        if timing {
            row.push(secs(r.seconds));
        }
        if let Some(p) = &r.problem {
            notes.push(format!("{} {}: {p}", r.geometry, r.name));
        }
        if let Some(n) = &r.note {
            notes.push(format!("{} {}: {n}", r.geometry, r.name));
        }
        rows.push(row);
    }
    let mut s = format!("{} ({})\n{}\n\n", material.name, material.file, material.brdf.describe());
    // numbers right-aligned, words left-aligned
    s.push_str(&super::pad_table(&rows, &[2, 4, 5, 6]));
    if readings.iter().any(|r| !r.converged && r.value.is_some()) {
        s.push_str("* not converged: a budget (evaluations or wall-clock time, see the notes) ran out before the tolerance was met\n");
    }
    if readings.iter().any(|r| r.value.is_some()) {
        s.push_str("numerical error: the integration's error estimate, not the uncertainty of the prediction\n");
    }
    for n in notes {
        s.push_str(&format!("note: {n}\n"));
    }
    s
}

/// One reading as `measure --format json` writes it (the schema is `output_schema::measure`).
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

/// The envelope as a table after the readings.
pub fn envelope_table(readings: &[Reading], envelopes: &[Option<Envelope>]) -> String {
    let mut out = String::from("\ntolerance envelope (the standard's tolerances and the plausible ranges of assumed numbers; docs/instrument.md §Tolerance envelope)\n");
    out += &format!(
        "{:<13} {:<11} {:>12} {:>12} {:>12}  {}\n",
        "geometry", "reading", "min", "nominal", "max", "variants"
    );
    for (r, e) in readings.iter().zip(envelopes) {
        let nominal = r.value.map(|v| format!("{v:.6}")).unwrap_or_else(|| "—".into());
        match e {
            Some(e) => {
                let how = if e.corners { "corners" } else { "one at a time" };
                out += &format!(
                    "{:<13} {:<11} {:>12.6} {:>12} {:>12.6}  {} ({how}, {} numbers varied)\n",
                    r.geometry,
                    r.name,
                    e.min,
                    nominal,
                    e.max,
                    e.variants,
                    e.variations.len()
                )
            }
            None => {
                out += &format!(
                    "{:<13} {:<11} {:>12} {:>12} {:>12}  no tolerances in the standard data\n",
                    r.geometry, r.name, "—", nominal, "—"
                )
            }
        }
    }
    out
}

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::plan::{Plan, PlanOptions};

    /// The "not converged" mark and footnote belong to printed values: a reading without a value (and not
    /// converged) gets neither, a value that did not converge gets both.
    #[test]
    fn the_not_converged_footnote_only_for_printed_values() {
        let m = crate::recipe::parse_str(r#"{"model": "lambert", "albedo": 0.5}"#, "l.json").unwrap();
        let geos = vec![crate::instrument::standards::find("astm-d523-60").unwrap()];
        let r = Plan::compile(m.brdf.clone(), geos, PlanOptions::default()).unwrap().execute();
        let mut no_value = r[0].clone();
        no_value.value = None;
        no_value.converged = false;
        no_value.problem = Some("no value here".into());
        let t = table(&m, &[no_value], false);
        assert!(!t.contains("not converged") && !t.contains(" *"), "{t}");
        let mut unconverged = r[0].clone();
        unconverged.converged = false;
        let t = table(&m, &[unconverged], false);
        assert!(t.contains("* not converged") && t.contains(" *\n"), "{t}");
    }
}
