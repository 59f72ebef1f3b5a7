//! `glossmeter measure A.json B.json DIR ...`: many recipes in one process (`crate::batch`), the table for
//! people with a material column (the JSON and CSV are `report::measure`'s), and the baseline lines of
//! `--baseline PREVIOUS.json` for one or many recipes.
use crate::cli::common::pad_table;
use crate::cli::format;
use crate::comparison::Drift;
use crate::instrument::plan::Reading;
use crate::recipe::Material;
use crate::report;

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
                    row.push(report::shown(v, report::decimals(r.error_estimate)));
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
    s.push_str(&format::colour_line(all().map(|r| r.colour)));
    for n in notes {
        s.push_str(&format!("note: {n}\n"));
    }
    s
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
