//! The fit's report (docs/inverse.md §Output): the fitted parameters and targets, the verdict in plain words
//! assembled from the stages' findings, and the judgement [`FitReport::ok`].
use nalgebra::{DMatrix, DVector};
use serde_json::Value;

use super::params::{FreeParameter, TargetReading};
use crate::colorimetry::Conditions;

/// One fitted parameter.
#[derive(Clone, Debug)]
pub struct FittedParameter {
    pub pointer: String,
    pub value: f64,
    /// Standard error of the value; `None` when the targets do not determine it (infinite).
    pub std_error: Option<f64>,
    /// The standard error from the targets' uncertainties alone (not scaled by the residuals): what a
    /// Monte Carlo over noise of exactly those uncertainties spreads by.
    pub std_error_unscaled: Option<f64>,
    pub lower: f64,
    pub upper: f64,
    pub log: bool,
    pub at_bound: bool,
    /// The target whose weighted prediction moves most with this parameter (which reading determines it).
    pub most_sensitive: Option<usize>,
}

/// One target after the fit.
#[derive(Clone, Debug)]
pub struct FittedTarget {
    pub target: TargetReading,
    /// The uncertainty used (the target's, or the default).
    pub uncertainty: f64,
    pub predicted: f64,
    /// The prediction's own error estimate.
    pub prediction_error: f64,
    /// predicted − measured, in the reading's unit.
    pub residual: f64,
    /// A colour target's illuminant and observer (its prediction's); None for any other target.
    pub colour: Option<Conditions>,
    /// residual / √(u² + e²).
    pub weighted_residual: f64,
}

/// The result of [`fit`].
#[derive(Clone, Debug)]
pub struct FitReport {
    pub parameters: Vec<FittedParameter>,
    pub targets: Vec<FittedTarget>,
    pub converged: bool,
    /// Why the solver stopped, in words.
    pub termination: String,
    pub identifiable: bool,
    /// The readings are stationary at the fit in a direction the targets do see (an extremum or a saddle,
    /// where a target beyond the model's reach leaves the solver): no standard error there
    /// (docs/inverse.md §Reach).
    pub stationary: bool,
    /// Singular values of the weighted Jacobian, columns scaled by each parameter's bound width (in the
    /// fitted variable), largest first.
    pub singular_values: Vec<f64>,
    /// Correlation matrix of the parameters (`None` entries where a standard error is infinite).
    pub correlation: Vec<Vec<Option<f64>>>,
    /// What the targets cannot determine, and other remarks, in plain words.
    pub verdict: Vec<String>,
    /// χ² = Σ weighted residual².
    pub chi2: f64,
    /// Degrees of freedom, targets − free parameters.
    pub dof: usize,
    /// The probability of a χ² at least this large from noise of the stated uncertainties, Q(dof/2, χ²/2)
    /// ([`chi2_survival`]); `None` for an exactly determined fit (dof 0).
    pub p_value: Option<f64>,
    /// Goodness of fit: p ≥ [`P_THRESHOLD`], or for an exactly determined fit every target reached within
    /// its uncertainty (docs/inverse.md §Goodness of fit).
    pub reproduces: bool,
    /// The factor S ≥ 1 by which the standard errors are scaled, √(χ²/dof) when that exceeds 1 (the Particle
    /// Data Group's scale factor), else 1.
    pub error_scale: f64,
    /// Forward-model runs (each a full set of readings): the solver's points, the Jacobians' displaced
    /// points, the final Jacobian, the linearity check's, the scan's and the restarts' (with their plateau
    /// probes), and the identifiability probes at the ends of the box (all of them).
    pub evaluations: usize,
    /// Of `evaluations`, the runs of the linearity check (one standard error each way along every
    /// determined direction).
    pub linearity_evaluations: usize,
    /// Of `evaluations`, the runs of the scan of the bounds and of the restarts (and of their plateau probes).
    pub restart_evaluations: usize,
    /// Of `restart_evaluations`, the runs of the scan of the bounds.
    pub scan_evaluations: usize,
    pub seconds: f64,
    /// The recipe with the fitted values.
    pub recipe: Value,
}

impl FitReport {
    /// Whether the fit is one to trust: converged, reproducing the readings, no parameter at a bound, every
    /// parameter determined, not at a stationary point of the readings.
    pub fn ok(&self) -> bool {
        self.converged
            && self.reproduces
            && self.identifiable
            && !self.stationary
            && !self.parameters.iter().any(|p| p.at_bound)
    }
}

/// The targets after the fit: each with its uncertainty, prediction (value, error estimate) and residuals.
pub(super) fn fitted_targets(
    targets: &[TargetReading],
    colour: &[Option<Conditions>],
    u_sigma: &[f64],
    centre: &[(f64, f64)],
    r: &DVector<f64>,
) -> Vec<FittedTarget> {
    targets
        .iter()
        .enumerate()
        .map(|(i, tg)| {
            let (v, e) = centre[i];
            FittedTarget {
                target: tg.clone(),
                uncertainty: u_sigma[i],
                predicted: v,
                prediction_error: e,
                residual: v - tg.value,
                colour: colour[i],
                weighted_residual: r[i],
            }
        })
        .collect()
}

/// The parameters after the fit at x, with standard errors in t (`std_t`, `std_t_unscaled`) turned into x's
/// unit (x·σ_t for `log:` parameters), and for each the target whose weighted prediction moves most with it
/// (the column's largest entry of the weighted Jacobian `jt`; none for a zero column).
pub(super) fn fitted_parameters(
    free: &[FreeParameter],
    x: &[f64],
    (std_t, std_t_unscaled): (&[Option<f64>], &[Option<f64>]),
    at_bound: &[bool],
    jt: &DMatrix<f64>,
) -> Vec<FittedParameter> {
    let m = jt.nrows();
    free.iter()
        .enumerate()
        .map(|(k, p)| {
            let most_sensitive = (0..m).max_by(|&a, &b| jt[(a, k)].abs().total_cmp(&jt[(b, k)].abs()));
            FittedParameter {
                pointer: p.pointer.clone(),
                value: x[k],
                std_error: std_t[k].map(|s| if p.log { x[k] * s } else { s }),
                std_error_unscaled: std_t_unscaled[k].map(|s| if p.log { x[k] * s } else { s }),
                lower: p.lower,
                upper: p.upper,
                log: p.log,
                at_bound: at_bound[k],
                most_sensitive: most_sensitive.filter(|&i| jt[(i, k)] != 0.0),
            }
        })
        .collect()
}

/// What the stages found, in the order the verdict states it.
pub(super) struct Findings {
    /// The model cannot reproduce the readings (goodness of fit and reach), first: it makes the rest moot.
    pub(super) cannot_reproduce: Vec<String>,
    /// The fit is a restart's: the line saying where the solver from the recipe's start stopped.
    pub(super) chosen_restart: Option<String>,
    /// The weak directions (undetermined or stationary).
    pub(super) weak: Vec<String>,
    pub(super) weak_undetermined: bool,
    /// The directions the linearity check failed.
    pub(super) nonlinear: Vec<String>,
    pub(super) second_solution: bool,
    pub(super) uniqueness: Option<String>,
    /// Parameters whose derivative could not be taken, with their values.
    pub(super) dead: Vec<(String, f64)>,
    /// Trial points refused outside the model's constraints.
    pub(super) refused: usize,
    /// Why the solver stopped, when it did not converge.
    pub(super) not_converged: Option<String>,
}

/// The verdict in plain words and whether the targets determine every parameter: the findings in order, the
/// strong correlations (|ρ| > 0.95, only while every parameter is determined), the parameters at a bound.
pub(super) fn verdict(
    f: Findings,
    parameters: &[FittedParameter],
    correlation: &[Vec<Option<f64>>],
) -> (Vec<String>, bool) {
    let mut verdict = f.cannot_reproduce;
    let mut identifiable = !f.weak_undetermined;
    verdict.extend(f.chosen_restart);
    verdict.extend(f.weak);
    if !f.nonlinear.is_empty() {
        identifiable = false;
        verdict.extend(f.nonlinear);
    }
    if f.second_solution {
        identifiable = false;
    }
    verdict.extend(f.uniqueness);
    let n = parameters.len();
    for a in 0..n {
        for b in a + 1..n {
            if let Some(c) = correlation[a][b] {
                if c.abs() > 0.95 && identifiable {
                    verdict.push(format!(
                        "{} and {} are strongly correlated (ρ = {c:.3}): the targets determine them mostly together",
                        parameters[a].pointer, parameters[b].pointer
                    ));
                }
            }
        }
    }
    for p in parameters.iter().filter(|p| p.at_bound) {
        verdict.push(format!(
            "{} = {} is at a bound of {}..{}: the best fit may lie outside; widen the bounds or check the targets",
            p.pointer, p.value, p.lower, p.upper
        ));
    }
    for (pointer, x) in &f.dead {
        identifiable = false;
        verdict.push(format!(
            "{pointer}: the derivative could not be taken (neither side of {x} evaluates: the material changes kind, or \
             leaves the model's constraints, there)"
        ));
    }
    if f.refused > 0 {
        verdict.push(format!(
            "{} trial point(s) of the solver lay outside the model's constraints (the recipe does not load \
             there) and were refused; the search stayed inside them",
            f.refused
        ));
    }
    if let Some(t) = f.not_converged {
        verdict.push(format!("the fit {t}"));
    }
    (verdict, identifiable)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parameter(pointer: &str, at_bound: bool) -> FittedParameter {
        FittedParameter {
            pointer: pointer.into(),
            value: 1.0,
            std_error: Some(0.1),
            std_error_unscaled: Some(0.1),
            lower: 0.0,
            upper: 1.0,
            log: false,
            at_bound,
            most_sensitive: Some(0),
        }
    }

    fn findings() -> Findings {
        Findings {
            cannot_reproduce: Vec::new(),
            chosen_restart: None,
            weak: Vec::new(),
            weak_undetermined: false,
            nonlinear: Vec::new(),
            second_solution: false,
            uniqueness: None,
            dead: Vec::new(),
            refused: 0,
            not_converged: None,
        }
    }

    #[test]
    fn strong_correlations_are_named_only_while_everything_is_determined() {
        let p = [parameter("/a", false), parameter("/b", true)];
        let rho = vec![vec![Some(1.0), Some(-0.97)], vec![Some(-0.97), Some(1.0)]];
        let (v, ok) = verdict(findings(), &p, &rho);
        assert!(ok);
        assert_eq!(v.len(), 2, "{v:?}");
        assert!(
            v[0].contains("/a and /b are strongly correlated (ρ = -0.970)") && v[1].starts_with("/b = 1 is at a bound")
        );
        let (v, ok) = verdict(Findings { second_solution: true, ..findings() }, &p, &rho);
        assert!(!ok && v.len() == 1, "{v:?}");
    }

    #[test]
    fn the_verdict_keeps_the_stages_order() {
        let f = Findings {
            cannot_reproduce: vec!["reach".into()],
            chosen_restart: Some("restart".into()),
            weak: vec!["weak".into()],
            nonlinear: vec!["nonlinear".into()],
            uniqueness: Some("unique".into()),
            dead: vec![("/a".into(), 2.0)],
            refused: 3,
            not_converged: Some("did not converge: x".into()),
            ..findings()
        };
        let (v, ok) = verdict(f, &[parameter("/a", false)], &[vec![Some(1.0)]]);
        assert!(!ok);
        assert_eq!(&v[..5], &["reach", "restart", "weak", "nonlinear", "unique"]);
        assert!(v[5].starts_with("/a: the derivative could not be taken (neither side of 2 evaluates"));
        assert!(v[6].starts_with("3 trial point(s)") && v[7] == "the fit did not converge: x", "{v:?}");
    }

    #[test]
    fn targets_and_parameters_are_reported_in_their_units() {
        let t = [TargetReading { geometry: "g".into(), name: "gloss".into(), value: 50.0, uncertainty: None }];
        let ft = fitted_targets(&t, &[None], &[0.2], &[(50.5, 0.01)], &DVector::from_element(1, 2.4));
        assert_eq!((ft[0].residual, ft[0].weighted_residual, ft[0].uncertainty), (0.5, 2.4, 0.2));
        let free = [FreeParameter { pointer: "/m".into(), lower: 0.01, upper: 1.0, log: true }];
        let jt = DMatrix::from_row_slice(1, 1, &[0.0]);
        let p = fitted_parameters(&free, &[0.1], (&[Some(0.5)], &[None]), &[false], &jt);
        assert_eq!((p[0].std_error, p[0].std_error_unscaled, p[0].most_sensitive), (Some(0.05), None, None));
    }
}
