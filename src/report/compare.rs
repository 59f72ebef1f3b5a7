//! The documents of `compare`: the predictions beside an instrument sheet as JSON (the sheet, the rule, one
//! object per (sample, reading) with its statistics, allowance and verdict, the summary, the colour
//! differences and the baseline checks; the schema is [`super::schema::compare`]) and as CSV, one record per
//! (sample, reading). The JUnit XML and the table for people are the command line's.
use std::path::Path;

use serde_json::{json, Value};

use super::{csv_text, drift_json};
use crate::comparison::sheet::{self, Sheet};
use crate::comparison::{ColourDifference, Comparison, Drift, Verdict, VerdictRule};
use crate::Result;

/// One comparison (a sample's reading against its prediction) as the `comparisons` entry of [`json_doc`].
pub fn comparison_json(c: &Comparison) -> Value {
    let p = c.predicted.as_ref();
    let s = c.group.stats;
    json!({
        "sample": c.group.sample, "material": c.material, "recipe": c.recipe,
        "geometry": c.group.geometry, "reading": c.group.reading,
        "predicted_reading": p.map(|p| p.name.clone()),
        "lines": c.group.lines, "columns": c.group.columns,
        "values": c.group.values,
        "n": s.n, "mean": s.mean, "std": s.std, "min": s.min, "max": s.max,
        "uncertainty": c.group.uncertainty,
        "predicted": p.and_then(|p| p.value),
        "error_estimate": p.filter(|p| p.value.is_some()).map(|p| p.error_estimate),
        "difference": c.difference(),
        "allowance": c.allowance.map(|a| json!({
            "statistical": a.statistical, "stated": a.stated, "prediction": a.prediction, "total": a.total()
        })),
        "verdict": c.verdict.label(),
        "inside": match c.verdict { Verdict::Inside => Some(true), Verdict::Outside => Some(false), _ => None },
        "reason": match &c.verdict { Verdict::NotPredicted(w) | Verdict::NoValue(w) => Some(w.clone()), _ => None },
        "unchecked": c.verdict.why_unchecked(),
    })
}

/// The JSON document of `compare` (printed pretty, [`super::pretty`]).
pub fn json_doc(
    sheet: &Sheet,
    cmp: &[Comparison],
    rule: &VerdictRule,
    drift: &[Drift],
    baseline: Option<&Path>,
    des: &[ColourDifference],
) -> Value {
    let mut doc = json!({
        "sheet": {
            "file": sheet.file, "encoding": sheet.encoding, "delimiter": (sheet.delimiter as char).to_string(),
            "layout": match sheet.layout {
                sheet::Layout::Long => "long",
                sheet::Layout::Wide => "wide",
                sheet::Layout::Colour => "colour",
            },
            "metadata": sheet.metadata_json(), "ignored_columns": sheet.ignored_columns,
        },
        "rule": {"k": rule.k, "tolerance": rule.tolerance},
        "comparisons": cmp.iter().map(comparison_json).collect::<Vec<_>>(),
        "summary": {
            "readings": cmp.len(),
            "inside": cmp.iter().filter(|c| c.verdict == Verdict::Inside).count(),
            "outside": cmp.iter().filter(|c| c.verdict == Verdict::Outside).count(),
            "no_value": cmp.iter().filter(|c| matches!(c.verdict, Verdict::NoValue(_))).count(),
            "no_allowance": cmp.iter().filter(|c| c.verdict == Verdict::NoAllowance).count(),
            "not_predicted": cmp.iter().filter(|c| matches!(c.verdict, Verdict::NotPredicted(_))).count(),
        },
    });
    doc["colour_differences"] = des
        .iter()
        .map(|d| {
            json!({
                "sample": d.sample, "geometry": d.geometry, "line": d.line,
                "measured": [d.measured.l, d.measured.a, d.measured.b],
                "predicted": [d.predicted.l, d.predicted.a, d.predicted.b],
                "de00": d.de00, "inside": d.inside,
            })
        })
        .collect::<Vec<_>>()
        .into();
    if let Some(b) = baseline {
        doc["baseline"] = json!({"file": b.display().to_string(), "checks": drift.iter().map(drift_json).collect::<Vec<_>>(),
                                 "moved": drift.iter().filter(|d| d.moved).count()});
    }
    doc
}

/// The CSV of `compare`: a header, then one record per comparison.
pub fn csv(cmp: &[Comparison]) -> Result<String> {
    let head = [
        "line",
        "sample",
        "material",
        "geometry",
        "reading",
        "n",
        "mean",
        "std",
        "min",
        "max",
        "predicted",
        "error_estimate",
        "difference",
        "allowance",
        "verdict",
        "note",
    ];
    // Numbers to their precision (docs/instrument.md §Numbers in text); the JSON keeps every digit.
    let e = |v: Option<f64>| v.map(super::measured).unwrap_or_default();
    let rows = cmp.iter().map(|c| {
        let p = c.predicted.as_ref();
        let s = c.group.stats;
        let (predicted, error) =
            p.and_then(|p| p.value.map(|v| super::with_error(v, p.error_estimate))).unwrap_or_default();
        [
            c.group.lines[0].to_string(),
            c.group.sample.clone(),
            c.material.clone(),
            c.group.geometry.clone(),
            c.group.reading.clone(),
            s.n.to_string(),
            e(Some(s.mean)),
            e(Some(s.std)),
            e(Some(s.min)),
            e(Some(s.max)),
            predicted,
            error,
            e(c.difference()),
            e(c.allowance.map(|a| a.total())),
            c.verdict.label().to_string(),
            match &c.verdict {
                Verdict::NotPredicted(why) => format!("not predicted: {why}"),
                v => v.why_unchecked().map(|w| format!("not checked: {w}")).unwrap_or_default(),
            },
        ]
    });
    csv_text(&head, rows)
}
