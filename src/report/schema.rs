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
