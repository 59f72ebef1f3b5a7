//! JSON Schemas (draft 2020-12) of the JSON outputs of `measure` (one recipe or many), `compare`, `fit` and
//! the JSON lines of `sweep`: the contract that scripts and CI rely on, printed by
//! `glossmeter schema --output-format measure|compare|sweep|fit`. `tests/schemas.rs` validates real outputs
//! against them, so a field added to an output without its schema fails the tests.
use serde_json::{json, Value};

const DRAFT: &str = "https://json-schema.org/draft/2020-12/schema";

fn num_or_null() -> Value {
    json!({"type": ["number", "null"]})
}

/// One reading of `measure` (the fields of the one-recipe JSON; a batch adds `material` and `file`).
fn reading(batch: bool) -> Value {
    let mut props = json!({
        "geometry": {"type": "string", "description": "the geometry id"},
        "name": {"type": "string", "description": "the reading's name (e.g. haze-narrow)"},
        "quantity": {"type": "string", "enum": ["gloss", "haze", "log-haze", "haze-compensated",
            "log-haze-compensated", "doi", "haze-index", "X", "Y", "Z", "L*", "a*", "b*", "C*", "h"]},
        "value": {"type": ["number", "null"], "description": "null when there is no finite value (see problem)"},
        "unit": {"type": "string"},
        "error_estimate": {"type": ["number", "null"], "minimum": 0, "description": "numerical error estimate (of the integration)"},
        "data_uncertainty": {"type": "number", "minimum": 0, "description": "a measured table's data (resolution) uncertainty, in the reading's unit: the reading through the table on every second sample against the reading through the table (docs/accuracy.md); absent for models and readings without a value"},
        "evaluations": {"type": "integer", "minimum": 0},
        "converged": {"type": "boolean"},
        "seconds": {"type": "number", "minimum": 0, "description": "wall time; absent with --no-timing"},
        "problem": {"type": "string"},
        "note": {"type": "string"},
        "envelope_min": {"type": ["number", "null"], "description": "with --envelope: the least reading within the tolerances"},
        "envelope_max": {"type": ["number", "null"], "description": "with --envelope: the greatest reading within the tolerances"},
        "envelope": {"type": "object", "description": "with --envelope: how the envelope was read (variants, method, numbers varied)"},
        "envelope_cut": {"const": true, "description": "with --envelope and --max-seconds: the limit (the whole command's) was reached before this geometry's envelope was read, so it is null (exit 1)"},
    });
    let mut required =
        vec!["geometry", "name", "quantity", "value", "unit", "error_estimate", "evaluations", "converged"];
    if batch {
        props["material"] = json!({"type": "string"});
        props["file"] = json!({"type": "string"});
        required.extend(["material", "file"]);
    }
    json!({"type": "object", "properties": props, "required": required, "additionalProperties": false})
}

fn material(batch: bool) -> Value {
    let mut m = json!({"type": "object", "required": ["name", "file", "model"], "additionalProperties": false,
           "properties": {"name": {"type": "string"}, "file": {"type": "string"}, "model": {"type": "string"}}});
    if batch {
        m["properties"]["evaluations"] = plan_evaluations("of this material's plan");
        m["required"] = json!(["name", "file", "model", "evaluations"]);
    }
    m
}

/// The `"evaluations"` of a plan (`plan::Execution::evaluations`).
fn plan_evaluations(whose: &str) -> Value {
    json!({"type": "integer", "minimum": 0, "description": format!(
        "BRDF evaluations {whose}: every distinct aperture integral (the gloss standards' included) counted once; \
         a reading's own evaluations count every integral it uses, so shared integrals appear in several readings")})
}

fn baseline() -> Value {
    json!({"type": "object", "required": ["file", "checks", "moved"], "additionalProperties": false,
      "properties": {
        "file": {"type": "string"},
        "moved": {"type": "integer", "minimum": 0},
        "checks": {"type": "array", "items": {"type": "object", "additionalProperties": false,
          "required": ["material", "geometry", "reading", "now", "then", "allowed", "moved"],
          "properties": {"material": {"type": "string"}, "geometry": {"type": "string"}, "reading": {"type": "string"},
            "now": {"type": "number"}, "then": {"type": "number"}, "allowed": {"type": "number", "minimum": 0},
            "moved": {"type": "boolean"}}}}}})
}

/// `measure --format json`: one recipe (`material`), or many (`materials`, and `material` on each reading).
pub fn measure() -> Value {
    json!({
        "$schema": DRAFT,
        "title": "glossmeter measure --format json",
        "oneOf": [
            {"type": "object", "required": ["material", "readings", "evaluations"], "additionalProperties": false,
             "properties": {"material": material(false), "readings": {"type": "array", "items": reading(false)},
                            "evaluations": plan_evaluations("of the whole plan"), "baseline": baseline()}},
            {"type": "object", "required": ["materials", "readings", "evaluations"], "additionalProperties": false,
             "properties": {"materials": {"type": "array", "items": material(true)},
                            "readings": {"type": "array", "items": reading(true)},
                            "evaluations": plan_evaluations("of all the materials' plans together"),
                            "baseline": baseline()}},
        ],
    })
}

/// One compared (sample, reading).
fn comparison() -> Value {
    let props = json!({
        "sample": {"type": "string"}, "material": {"type": "string"}, "recipe": {"type": "string"},
        "geometry": {"type": "string"}, "reading": {"type": "string"},
        "predicted_reading": {"type": ["string", "null"]},
        "lines": {"type": "array", "items": {"type": "integer", "minimum": 1}},
        "columns": {"type": "array", "items": {"type": "string"}},
        "values": {"type": "array", "items": {"type": "number"}},
        "n": {"type": "integer", "minimum": 1}, "mean": {"type": "number"},
        "std": {"type": "number", "minimum": 0}, "min": {"type": "number"}, "max": {"type": "number"},
        "uncertainty": num_or_null(), "predicted": num_or_null(), "error_estimate": num_or_null(),
        "difference": {"type": ["number", "null"], "description": "predicted − measured mean"},
        "allowance": allowance(),
        "verdict": {"type": "string", "enum": ["ok", "OUTSIDE", "unchecked", "not predicted"],
                    "description": "unchecked (no value, or no allowance) and OUTSIDE fail the check (exit 1)"},
        "inside": {"type": ["boolean", "null"]},
        "reason": {"type": ["string", "null"], "description": "why not predicted, or why the prediction has no value"},
        "unchecked": {"type": ["string", "null"], "description": "why the row could not be checked"},
    });
    let required: Vec<&str> = props.as_object().expect("object").keys().map(String::as_str).collect();
    json!({"type": "object", "additionalProperties": false, "required": required, "properties": props})
}

fn allowance() -> Value {
    let nonneg = json!({"type": "number", "minimum": 0});
    json!({"oneOf": [{"type": "null"}, {"type": "object", "additionalProperties": false,
        "required": ["statistical", "stated", "prediction", "total"],
        "properties": {"statistical": nonneg, "stated": nonneg, "prediction": nonneg, "total": nonneg}}]})
}

/// `compare --format json`.
pub fn compare() -> Value {
    let count = json!({"type": "integer", "minimum": 0});
    let lab = json!({"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3,
                     "description": "L*, a*, b*"});
    json!({
        "$schema": DRAFT,
        "title": "glossmeter compare --format json",
        "type": "object",
        "required": ["sheet", "rule", "comparisons", "summary", "colour_differences"],
        "additionalProperties": false,
        "properties": {
            "sheet": {"type": "object", "additionalProperties": false,
              "required": ["file", "encoding", "delimiter", "layout", "metadata", "ignored_columns"],
              "properties": {"file": {"type": "string"}, "encoding": {"type": "string"},
                "delimiter": {"type": "string", "enum": [",", ";", "\t"]}, "layout": {"type": "string", "enum": ["long", "wide", "colour"]},
                "metadata": {"type": "object", "additionalProperties": {"type": "string"},
                             "description": "the sheet's `# key: value` lines"},
                "ignored_columns": {"type": "array", "items": {"type": "string"}}}},
            "rule": {"type": "object", "additionalProperties": false, "required": ["k", "tolerance"],
              "properties": {"k": {"type": "number", "minimum": 0}, "tolerance": num_or_null()}},
            "comparisons": {"type": "array", "items": comparison()},
            "summary": {"type": "object", "additionalProperties": false,
              "required": ["readings", "inside", "outside", "no_value", "no_allowance", "not_predicted"],
              "properties": {"readings": count, "inside": count, "outside": count, "no_value": count,
                             "no_allowance": count, "not_predicted": count}},
            "colour_differences": {"type": "array", "description": "CIEDE2000 per (sample, geometry) with L*, a*, b*",
              "items": {"type": "object", "additionalProperties": false,
                "required": ["sample", "geometry", "line", "measured", "predicted", "de00", "inside"],
                "properties": {"sample": {"type": "string"}, "geometry": {"type": "string"},
                  "line": {"type": "integer", "minimum": 1},
                  "measured": lab.clone(), "predicted": lab,
                  "de00": {"type": "number", "minimum": 0}, "inside": {"type": ["boolean", "null"]}}}},
            "baseline": baseline(),
        },
    })
}

/// One line of `sweep --format jsonl`.
pub fn sweep() -> Value {
    json!({
        "$schema": DRAFT,
        "title": "glossmeter sweep --format jsonl (one object per line)",
        "type": "object",
        "required": ["index", "parameters"],
        "additionalProperties": false,
        "properties": {
            "index": {"type": "integer", "minimum": 0},
            "parameters": {"type": "object", "additionalProperties": {"type": "number"},
                           "description": "the varied values, by JSON Pointer"},
            "readings": {"type": "array", "items": {"type": "object", "additionalProperties": false,
              "required": ["geometry", "name", "unit", "value", "error_estimate", "converged"],
              "properties": {"geometry": {"type": "string"}, "name": {"type": "string"}, "unit": {"type": "string"},
                "value": num_or_null(), "error_estimate": num_or_null(), "converged": {"type": "boolean"},
                "problem": {"type": "string"}}}},
            "problem": {"type": "string", "description": "why the recipe at this point is invalid (then no readings)"},
            "seconds": {"type": "number", "minimum": 0},
        },
    })
}

/// `fit --format json`: the contract of docs/inverse.md §Output, and `verdict` (the table's words).
pub fn fit() -> Value {
    let num = json!({"type": "number"});
    let stderr = json!({"type": ["number", "null"], "minimum": 0,
                        "description": "null when the linear error analysis gives none (the targets do not determine the parameter, or the readings are stationary there)"});
    let report = json!({
        "type": "object",
        "required": ["parameters", "targets", "converged", "identifiable", "stationary", "chi2", "dof", "p_value",
                     "reproduces", "error_scale", "singular_values", "correlation", "verdict", "evaluations",
                     "seconds", "recipe"],
        "additionalProperties": false,
        "properties": {
            "parameters": {"type": "array", "minItems": 1, "items": {"type": "object", "additionalProperties": false,
              "required": ["path", "value", "std_error", "lower", "upper", "at_bound"],
              "properties": {"path": {"type": "string", "description": "JSON Pointer into the recipe"},
                "value": num_or_null(), "std_error": stderr, "lower": num, "upper": num,
                "at_bound": {"type": "boolean"}}}},
            "targets": {"type": "array", "minItems": 1, "items": {"type": "object", "additionalProperties": false,
              "required": ["geometry", "name", "measured", "uncertainty", "predicted", "residual"],
              "properties": {"geometry": {"type": "string"}, "name": {"type": "string"}, "measured": num,
                "uncertainty": {"type": "number", "minimum": 0}, "predicted": num_or_null(),
                "residual": {"type": ["number", "null"], "description": "predicted − measured"}}}},
            "converged": {"type": "boolean"},
            "identifiable": {"type": "boolean"},
            "stationary": {"type": "boolean",
              "description": "the readings are stationary at the fit in a direction the targets see (an extremum or a saddle): no standard error there"},
            "chi2": {"type": ["number", "null"], "minimum": 0, "description": "Σ of the weighted residuals squared"},
            "dof": {"type": "integer", "minimum": 0, "description": "degrees of freedom: targets − free parameters"},
            "p_value": {"type": ["number", "null"], "minimum": 0, "maximum": 1,
              "description": "chi-square survival function Q(dof/2, χ²/2); null when dof = 0"},
            "reproduces": {"type": "boolean",
              "description": "goodness of fit: p ≥ 0.001, or with dof = 0 every target within its uncertainty"},
            "error_scale": {"type": ["number", "null"], "minimum": 1,
              "description": "the factor on the standard errors, √(χ²/dof) when above 1 (PDG scale factor), else 1"},
            "singular_values": {"type": "array", "items": {"type": ["number", "null"], "minimum": 0},
              "description": "of the weighted Jacobian, columns scaled by the bound widths, largest first"},
            "correlation": {"type": "array", "items": {"type": "array", "items": num_or_null()}},
            "verdict": {"type": "array", "items": {"type": "string"}},
            "evaluations": {"type": "integer", "minimum": 0,
              "description": "forward runs (each a full set of readings): the solver's, the Jacobians', the linearity check's and any restarts'"},
            "seconds": {"type": ["number", "null"], "minimum": 0, "description": "null with --no-timing"},
            "recipe": {"type": "object", "description": "the recipe with the fitted values"},
        },
    });
    // A fit that could not run to a report (its start or final point has no finite readings; exit 1).
    let failure = json!({
        "type": "object",
        "required": ["converged", "failure", "parameters", "targets"],
        "additionalProperties": false,
        "properties": {
            "converged": {"enum": [false]},
            "failure": {"type": "string", "description": "why the fit could not run"},
            "parameters": {"type": "array", "items": {"type": "object", "additionalProperties": false,
              "required": ["path", "lower", "upper"],
              "properties": {"path": {"type": "string"}, "lower": num, "upper": num}}},
            "targets": {"type": "array", "items": {"type": "object", "additionalProperties": false,
              "required": ["geometry", "name", "measured", "uncertainty"],
              "properties": {"geometry": {"type": "string"}, "name": {"type": "string"}, "measured": num,
                "uncertainty": {"type": ["number", "null"], "minimum": 0}}}},
        },
    });
    json!({"$schema": DRAFT, "title": "glossmeter fit --format json", "oneOf": [report, failure]})
}
