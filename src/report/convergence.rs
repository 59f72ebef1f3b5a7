//! The document of `glossmeter convergence --format json` ([`ConvergenceDoc`]): the material, the tolerances,
//! the reference and one row per (tolerance, reading), from which `report::schema::convergence` derives its
//! JSON Schema. Written through a `serde_json::Value`, so its keys are in alphabetical order, as they always
//! were.
use schemars::JsonSchema;
use serde::Serialize;

use super::profile::ProfileMaterialDoc;
use crate::instrument::convergence::{ReferenceKind, Sweep};
use crate::recipe::Material;

/// One reading at one tolerance.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = convergence_row_nullable)]
pub struct ConvergenceRowDoc {
    /// The tolerance the reading was asked for.
    pub rtol: f64,
    pub geometry: String,
    pub reading: String,
    pub quantity: String,
    pub unit: String,
    /// The reading; null when the engine gave no finite value (see problem).
    pub value: Option<f64>,
    /// The engine's error estimate; null without a value.
    pub error_estimate: Option<f64>,
    /// |value − reference|; null if either is missing.
    pub actual_error: Option<f64>,
    pub reference: Option<f64>,
    /// The reference's own error estimate; null for a closed form.
    pub reference_error: Option<f64>,
    /// "closed form" or "rtol=… run".
    pub reference_kind: String,
    pub evaluations: usize,
    /// Minimum over the executions of the reading's own time, seconds.
    pub seconds: f64,
    /// Minimum wall time of a whole execution of the plan at this tolerance, seconds.
    pub plan_seconds: f64,
    /// Executions timed.
    pub repetitions: usize,
    pub converged: bool,
    pub problem: Option<String>,
    /// A colour reading's CIE illuminant and observer ([`ConditionsDoc`]); absent on every other row.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub colour: Option<super::ConditionsDoc>,
}

fn convergence_row_nullable(schema: &mut schemars::Schema) {
    super::nullable_but_written(
        schema,
        &["value", "error_estimate", "actual_error", "reference", "reference_error", "problem"],
    );
}

/// What the actual errors are measured against.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = reference_nullable)]
pub struct ReferenceDoc {
    /// "closed form" or "rtol=… run".
    pub kind: String,
    /// The reference run's tolerance; null for a closed form.
    pub rtol: Option<f64>,
    /// The reference run's wall time; null for a closed form.
    pub seconds: Option<f64>,
}

fn reference_nullable(schema: &mut schemars::Schema) {
    super::nullable_but_written(schema, &["rtol", "seconds"]);
}

/// How the times were taken.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct TimingDoc {
    pub statistic: String,
    pub min_seconds: f64,
    pub max_repetitions: usize,
}

/// `convergence --format json`.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct ConvergenceDoc {
    pub material: ProfileMaterialDoc,
    pub tolerances: Vec<f64>,
    pub reference: ReferenceDoc,
    pub timing: TimingDoc,
    pub rows: Vec<ConvergenceRowDoc>,
}

impl ConvergenceDoc {
    pub fn new(material: &Material, sweep: &Sweep) -> ConvergenceDoc {
        let reference = match &sweep.reference {
            ReferenceKind::ClosedForm => ReferenceDoc { kind: "closed form".into(), rtol: None, seconds: None },
            ReferenceKind::Run { rtol } => ReferenceDoc {
                kind: sweep.reference.label(),
                rtol: Some(*rtol),
                seconds: Some(sweep.reference_seconds),
            },
        };
        ConvergenceDoc {
            material: ProfileMaterialDoc::of(material),
            tolerances: sweep.tolerances.clone(),
            reference,
            timing: TimingDoc {
                statistic: "minimum over repeated executions".into(),
                min_seconds: sweep.options.min_seconds,
                max_repetitions: sweep.options.max_repetitions,
            },
            rows: sweep
                .rows
                .iter()
                .map(|r| ConvergenceRowDoc {
                    rtol: r.rtol,
                    geometry: r.geometry.clone(),
                    reading: r.reading.clone(),
                    quantity: r.quantity.clone(),
                    unit: r.unit.clone(),
                    value: r.value,
                    error_estimate: r.error_estimate,
                    actual_error: r.actual_error,
                    reference: r.reference,
                    reference_error: r.reference_error,
                    reference_kind: r.reference_kind.clone(),
                    evaluations: r.evaluations,
                    seconds: r.seconds,
                    plan_seconds: r.plan_seconds,
                    repetitions: r.repetitions,
                    converged: r.converged,
                    problem: r.problem.clone(),
                    colour: r.colour.map(super::ConditionsDoc::new),
                })
                .collect(),
        }
    }

    /// The JSON text (pretty, keys in alphabetical order, a final newline).
    pub(crate) fn text(&self) -> String {
        super::pretty(&super::to_json(self))
    }
}
