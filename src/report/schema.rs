//! JSON Schemas (draft 2020-12) of the JSON outputs of `measure` (one recipe or many), `compare`, `fit`,
//! `profile`, `convergence`, `topography` and the JSON lines of `sweep`: the contract that scripts and CI rely on, printed by
//! `glossmeter schema --output-format measure|compare|sweep|fit|profile|convergence|topography`. Each is derived (`schemars`) from the types
//! the writers serialise, so the schema and the output cannot drift apart: a field exists in both or in
//! neither, and its doc comment is its description. `tests/schemas.rs` validates real outputs against them
//! with the `jsonschema` crate.
use schemars::schema_for;
use serde_json::Value;

use super::compare::{CompareDoc, SheetReadDoc};
use super::convergence::ConvergenceDoc;
use super::fit::FitOutput;
use super::measure::MeasureOutput;
use super::profile::ProfileDoc;
use super::topography::TopographyDoc;
use super::{to_json, SweepLineDoc};

/// `measure --format json`: one recipe (`material`), or many (`materials`, and `material` on each reading).
pub fn measure() -> Value {
    to_json(&schema_for!(MeasureOutput))
}

/// `compare --format json`.
pub fn compare() -> Value {
    to_json(&schema_for!(CompareDoc))
}

/// One line of `sweep --format jsonl`.
pub fn sweep() -> Value {
    to_json(&schema_for!(SweepLineDoc))
}

/// `fit --format json`: the contract of docs/inverse.md §Output, and `verdict` (the table's words); or the
/// document of a fit that could not run.
pub fn fit() -> Value {
    to_json(&schema_for!(FitOutput))
}

/// `profile --format json`.
pub fn profile() -> Value {
    to_json(&schema_for!(ProfileDoc))
}

/// `convergence --format json`.
pub fn convergence() -> Value {
    to_json(&schema_for!(ConvergenceDoc))
}

/// A sheet as the one sheet reader reads it (the Python bindings' `read_sheet`).
pub fn sheet() -> Value {
    to_json(&schema_for!(SheetReadDoc))
}

/// `topography --format json`.
pub(crate) fn topography() -> Value {
    to_json(&schema_for!(TopographyDoc))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colorimetry::{Illuminant, Observer};

    /// Every `enum` listed under a key named `key`, anywhere in the schema.
    fn enums_of(v: &Value, key: &str, out: &mut Vec<Vec<String>>) {
        match v {
            Value::Object(m) => {
                for (k, x) in m {
                    if k == key {
                        if let Some(e) = x.get("enum").and_then(Value::as_array) {
                            out.push(e.iter().filter_map(Value::as_str).map(String::from).collect());
                        }
                    }
                    enums_of(x, key, out);
                }
            }
            Value::Array(a) => a.iter().for_each(|x| enums_of(x, key, out)),
            _ => {}
        }
    }

    /// The colour conditions' names written into the schemas (`#[schemars(extend("enum" = …))]`, a literal)
    /// are every one the library computes under, in its order.
    #[test]
    fn the_schemas_list_every_illuminant_and_observer() {
        let illuminants: Vec<String> = Illuminant::ALL.iter().map(|i| i.id().to_owned()).collect();
        let observers: Vec<String> = Observer::ALL.iter().map(|o| o.id().to_owned()).collect();
        for (name, schema) in [
            ("measure", measure()),
            ("compare", compare()),
            ("sweep", sweep()),
            ("fit", fit()),
            ("convergence", convergence()),
        ] {
            let (mut i, mut o) = (vec![], vec![]);
            enums_of(&schema, "illuminant", &mut i);
            enums_of(&schema, "observer", &mut o);
            assert!(!i.is_empty() && !o.is_empty(), "{name}: no illuminant or observer in the schema");
            assert!(i.iter().all(|e| *e == illuminants), "{name}: {i:?}");
            assert!(o.iter().all(|e| *e == observers), "{name}: {o:?}");
        }
    }
}
