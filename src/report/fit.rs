//! The document of `fit`: the fitted parameters, the targets with their residuals, the verdict and the fitted
//! recipe as JSON. The table for people is the command line's.
use serde_json::{json, Value};

use crate::fit::{FitReport, FreeParameter, TargetReading};

/// A finite number, or null.
fn num(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

/// The fit's report as `fit --format json` writes it: the JSON contract of docs/inverse.md §Output (the schema
/// is [`super::schema::fit`]), and `verdict`: the same words as the table's.
pub fn json(r: &FitReport, timing: bool) -> Value {
    json!({
        "parameters": r.parameters.iter().map(|p| json!({
            "path": p.pointer, "value": num(p.value), "std_error": p.std_error.map(num), "lower": p.lower,
            "upper": p.upper, "at_bound": p.at_bound,
        })).collect::<Vec<_>>(),
        "targets": r.targets.iter().map(|t| json!({
            "geometry": t.target.geometry, "name": t.target.name, "measured": t.target.value,
            "uncertainty": t.uncertainty, "predicted": num(t.predicted), "residual": num(t.residual),
        })).collect::<Vec<_>>(),
        "converged": r.converged,
        "identifiable": r.identifiable,
        "stationary": r.stationary,
        "chi2": num(r.chi2),
        "dof": r.dof,
        "p_value": r.p_value.map(num),
        "reproduces": r.reproduces,
        "error_scale": num(r.error_scale),
        "singular_values": r.singular_values.iter().map(|s| num(*s)).collect::<Vec<_>>(),
        "correlation": r.correlation.iter().map(|row| row.iter().map(|c| c.map(num)).collect::<Vec<_>>()).collect::<Vec<_>>(),
        "verdict": r.verdict,
        "evaluations": r.evaluations,
        "seconds": if timing { num(r.seconds) } else { Value::Null },
        "recipe": r.recipe,
    })
}

/// The document of a fit that could not run to a report (its start or its final point has no finite
/// readings): the failure, and what was asked, so that `fit --format json` always writes a document
/// (docs/inverse.md §Verdicts and exit statuses; the schema is the second form of [`super::schema::fit`]).
pub fn failure_json(free: &[FreeParameter], targets: &[TargetReading], failure: &str) -> Value {
    json!({
        "converged": false,
        "failure": failure,
        "parameters": free.iter().map(|p| json!({"path": p.pointer, "lower": p.lower, "upper": p.upper}))
            .collect::<Vec<_>>(),
        "targets": targets.iter().map(|t| json!({
            "geometry": t.geometry, "name": t.name, "measured": t.value, "uncertainty": t.uncertainty,
        })).collect::<Vec<_>>(),
    })
}
