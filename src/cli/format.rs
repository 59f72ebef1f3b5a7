//! The text tables of `measure` for people (the JSON and CSV documents are the library's, `crate::report`): the
//! readings, the tolerance envelope, durations. A reading without a finite value is printed as "—", with the
//! reason: never as NaN or inf.
use crate::cli::common::pad_table;
use crate::colorimetry::Conditions;
use crate::comparison::propagation::PredictionUncertainty;
use crate::instrument::envelope::Envelopes;
use crate::instrument::plan::Reading;
use crate::recipe::Material;
use crate::report::{decimals, shown};

/// The prediction uncertainties of a recipe that states uncertainties of its numbers, one line per reading with
/// its largest contribution (docs/instrument.md §The prediction's uncertainty); empty without them.
pub fn uncertainty_text(readings: &[Reading], uncertainties: &[Option<PredictionUncertainty>]) -> String {
    if uncertainties.iter().all(Option::is_none) {
        return String::new();
    }
    let mut s =
        String::from("\nPrediction uncertainty (standard, from the recipe's stated uncertainties, first order):\n");
    for (r, u) in readings.iter().zip(uncertainties) {
        let Some(u) = u else { continue };
        let largest = u.contributions.iter().max_by(|a, b| a.contribution.total_cmp(&b.contribution));
        s.push_str(&format!("  {} {}: u_pred = {:.2} {}", r.geometry, r.name, u.u, r.unit));
        if let Some(c) = largest {
            s.push_str(&format!(" (largest part: {} ± {}, {:.2} {})", c.pointer, c.u, c.contribution, r.unit));
        }
        s.push('\n');
    }
    s
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
    // A measured table's readings carry a data uncertainty beside the numerical error: a column of its own.
    let data = readings.iter().any(|r| r.data_uncertainty.is_some());
    let mut head = vec!["geometry", "reading", "value", "unit", "numerical error"];
    if data {
        head.push("data uncertainty");
    }
    head.push("evaluations");
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
                let shown = shown(v, decimals(r.error_estimate));
                let shown = if shown.trim_start_matches('-').chars().all(|c| c == '0' || c == '.') {
                    shown.trim_start_matches('-').to_string()
                } else {
                    shown
                };
                row.push(shown);
                row.push(r.unit.clone());
                row.push(format!("{:.1e}", r.error_estimate));
                if data {
                    row.push(r.data_uncertainty.map_or("—".into(), |u| format!("{u:.1e}")));
                }
            }
            None => {
                row.push("—".into());
                row.push(r.unit.clone());
                row.push("—".into());
                if data {
                    row.push("—".into());
                }
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
    s.push_str(&pad_table(&rows, if data { &[2, 4, 5, 6, 7] } else { &[2, 4, 5, 6] }));
    if readings.iter().any(|r| !r.converged && r.value.is_some()) {
        s.push_str("* not converged: a budget (evaluations or wall-clock time, see the notes) ran out before the tolerance was met\n");
    }
    if readings.iter().any(|r| r.value.is_some()) {
        s.push_str("numerical error: the integration's error estimate, not the uncertainty of the prediction\n");
    }
    s.push_str(&colour_line(readings.iter().map(|r| r.colour)));
    if data {
        s.push_str(
            "data uncertainty: how far the table's resolution may put the reading from that of the surface it \
             samples (the reading through the table on every second sample, docs/accuracy.md)\n",
        );
    }
    for n in notes {
        s.push_str(&format!("note: {n}\n"));
    }
    s
}

/// The line that says what the colour readings are computed under (`colour: illuminant A, CIE 1931 2°
/// observer`), empty when there are none: a colour coordinate means nothing without them (docs/colour.md).
pub fn colour_line(conditions: impl IntoIterator<Item = Option<Conditions>>) -> String {
    let all: std::collections::BTreeSet<Conditions> = conditions.into_iter().flatten().collect();
    let said: Vec<String> = all.iter().map(|c| c.describe()).collect();
    match said.is_empty() {
        true => String::new(),
        false => format!("colour: {}\n", said.join("; ")),
    }
}

/// The envelope as a table after the readings.
pub fn envelope_table(readings: &[Reading], envelopes: &Envelopes) -> String {
    let mut out = String::from("\ntolerance envelope (the standard's tolerances and the plausible ranges of assumed numbers; docs/instrument.md §Tolerance envelope)\n");
    out += &format!(
        "{:<13} {:<11} {:>12} {:>12} {:>12}  {}\n",
        "geometry", "reading", "min", "nominal", "max", "variants"
    );
    for (r, e) in readings.iter().zip(&envelopes.of) {
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
                let why = if envelopes.cut.contains(&r.geometry) {
                    "cut by the wall-clock limit"
                } else {
                    "no tolerances in the standard data"
                };
                out += &format!("{:<13} {:<11} {:>12} {:>12} {:>12}  {why}\n", r.geometry, r.name, "—", nominal, "—")
            }
        }
    }
    out
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
