//! The document of `fit`: the fitted parameters, the targets with their residuals, the verdict and the fitted
//! recipe as JSON. The table for people is the command line's.
use schemars::JsonSchema;
use serde::Serialize;
use serde_json::Value;

use crate::fit::{FitReport, FreeParameter, TargetReading};

/// A finite number, or None (null).
fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// A fitted parameter: its value, standard error and bounds.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = parameter_doc_nullable)]
#[serde(deny_unknown_fields)]
pub struct ParameterDoc {
    /// JSON Pointer into the recipe.
    pub path: String,
    pub value: Option<f64>,
    /// null when the linear error analysis gives none (the targets do not determine the parameter, or the
    /// readings are stationary there).
    #[schemars(range(min = 0))]
    pub std_error: Option<f64>,
    pub lower: f64,
    pub upper: f64,
    pub at_bound: bool,
}

/// A target reading with the fit's prediction and residual.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = target_doc_nullable)]
#[serde(deny_unknown_fields)]
pub struct TargetDoc {
    pub geometry: String,
    pub name: String,
    pub measured: f64,
    /// The uncertainty used (the target's, or the default).
    #[schemars(range(min = 0))]
    pub uncertainty: f64,
    pub predicted: Option<f64>,
    /// predicted − measured.
    pub residual: Option<f64>,
    /// A colour target's CIE illuminant and observer ([`ConditionsDoc`]); absent on every other target.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub colour: Option<super::ConditionsDoc>,
}

/// `fit --format json` of a fit that ran to a report: the JSON contract of docs/inverse.md §Output, and
/// `verdict` (the same words as the table's).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = fit_doc_nullable)]
#[serde(deny_unknown_fields)]
pub struct FitDoc {
    #[schemars(length(min = 1))]
    pub parameters: Vec<ParameterDoc>,
    #[schemars(length(min = 1))]
    pub targets: Vec<TargetDoc>,
    pub converged: bool,
    pub identifiable: bool,
    /// The readings are stationary at the fit in a direction the targets see (an extremum or a saddle): no
    /// standard error there.
    pub stationary: bool,
    /// Σ of the weighted residuals squared.
    #[schemars(range(min = 0))]
    pub chi2: Option<f64>,
    /// Degrees of freedom: targets − free parameters.
    pub dof: usize,
    /// Chi-square survival function Q(dof/2, χ²/2); null when dof = 0.
    #[schemars(range(min = 0, max = 1))]
    pub p_value: Option<f64>,
    /// Goodness of fit: p ≥ 0.001, or with dof = 0 every target within its uncertainty.
    pub reproduces: bool,
    /// The factor on the standard errors, √(χ²/dof) when above 1 (PDG scale factor), else 1.
    #[schemars(range(min = 1))]
    pub error_scale: Option<f64>,
    /// Of the weighted Jacobian, columns scaled by the bound widths, largest first.
    #[schemars(inner(range(min = 0)))]
    pub singular_values: Vec<Option<f64>>,
    pub correlation: Vec<Vec<Option<f64>>>,
    pub verdict: Vec<String>,
    /// Forward runs (each a full set of readings): the solver's, the Jacobians', the linearity check's and
    /// any restarts'.
    pub evaluations: usize,
    /// Wall time in seconds; null with --no-timing.
    #[schemars(range(min = 0))]
    pub seconds: Option<f64>,
    /// The recipe with the fitted values.
    #[schemars(with = "serde_json::Map<String, Value>")]
    pub recipe: Value,
}

/// A fitted parameter as asked for, in the failure document.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FreeParameterDoc {
    pub path: String,
    pub lower: f64,
    pub upper: f64,
}

/// A target as asked for, in the failure document.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = target_asked_doc_nullable)]
#[serde(deny_unknown_fields)]
pub struct TargetAskedDoc {
    pub geometry: String,
    pub name: String,
    pub measured: f64,
    #[schemars(range(min = 0))]
    pub uncertainty: Option<f64>,
}

/// `fit --format json` of a fit that could not run to a report (its start or final point has no finite
/// readings; exit 1): why, and what was asked.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FitFailureDoc {
    /// Always false.
    #[schemars(extend("const" = false))]
    pub converged: bool,
    /// Why the fit could not run.
    pub failure: String,
    pub parameters: Vec<FreeParameterDoc>,
    pub targets: Vec<TargetAskedDoc>,
}

/// `fit --format json`: the report of a fit, or why it could not run (its schema is `schema::fit`).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(untagged)]
#[schemars(title = "glossmeter fit --format json")]
pub enum FitOutput {
    Report(FitDoc),
    Failure(FitFailureDoc),
}

/// The fit's report as `fit --format json` writes it.
pub fn json(r: &FitReport, timing: bool) -> Value {
    super::to_json(&FitDoc {
        parameters: r
            .parameters
            .iter()
            .map(|p| ParameterDoc {
                path: p.pointer.clone(),
                value: finite(p.value),
                std_error: p.std_error.and_then(finite),
                lower: p.lower,
                upper: p.upper,
                at_bound: p.at_bound,
            })
            .collect(),
        targets: r
            .targets
            .iter()
            .map(|t| TargetDoc {
                geometry: t.target.geometry.clone(),
                name: t.target.name.clone(),
                measured: t.target.value,
                uncertainty: t.uncertainty,
                predicted: finite(t.predicted),
                residual: finite(t.residual),
                colour: t.colour.map(super::ConditionsDoc::new),
            })
            .collect(),
        converged: r.converged,
        identifiable: r.identifiable,
        stationary: r.stationary,
        chi2: finite(r.chi2),
        dof: r.dof,
        p_value: r.p_value.and_then(finite),
        reproduces: r.reproduces,
        error_scale: finite(r.error_scale),
        singular_values: r.singular_values.iter().map(|s| finite(*s)).collect(),
        correlation: r.correlation.iter().map(|row| row.iter().map(|c| c.and_then(finite)).collect()).collect(),
        verdict: r.verdict.clone(),
        evaluations: r.evaluations,
        seconds: if timing { finite(r.seconds) } else { None },
        recipe: r.recipe.clone(),
    })
}

/// The document of a fit that could not run to a report (its start or its final point has no finite
/// readings): the failure, and what was asked, so that `fit --format json` always writes a document
/// (docs/inverse.md §Verdicts and exit statuses).
pub(crate) fn failure_json(free: &[FreeParameter], targets: &[TargetReading], failure: &str) -> Value {
    super::to_json(&FitFailureDoc {
        converged: false,
        failure: failure.into(),
        parameters: free
            .iter()
            .map(|p| FreeParameterDoc { path: p.pointer.clone(), lower: p.lower, upper: p.upper })
            .collect(),
        targets: targets
            .iter()
            .map(|t| TargetAskedDoc {
                geometry: t.geometry.clone(),
                name: t.name.clone(),
                measured: t.value,
                uncertainty: t.uncertainty,
            })
            .collect(),
    })
}

fn parameter_doc_nullable(schema: &mut schemars::Schema) {
    super::nullable_but_written(schema, &["value", "std_error"]);
}

fn target_doc_nullable(schema: &mut schemars::Schema) {
    super::nullable_but_written(schema, &["predicted", "residual"]);
}

fn fit_doc_nullable(schema: &mut schemars::Schema) {
    super::nullable_but_written(schema, &["chi2", "p_value", "error_scale", "seconds"]);
}

fn target_asked_doc_nullable(schema: &mut schemars::Schema) {
    super::nullable_but_written(schema, &["uncertainty"]);
}
