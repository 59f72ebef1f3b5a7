//! The inverse problem: fit recipe parameters to gloss, haze and DOI readings, with honest uncertainty.
//!
//! Why it exists: the question users bring most often is the inverse one (which roughness reads 85 GU at
//! 20°? which coat roughness and flake spread give these readings?). [`fit`] answers it for any recipe:
//!
//! * the free parameters are RFC 6901 JSON Pointers into the recipe ([`FreeParameter`], bounds checked
//!   against the parameter registry, [`crate::registry::lookup`]), fitted linearly or in the logarithm;
//! * the targets are readings with uncertainties ([`TargetReading`]); each residual is weighted by
//!   σ = √(u² + e²), u the target's uncertainty, e the prediction's own error estimate;
//! * the solver is the MINPACK Levenberg–Marquardt of the `levenberg-marquardt` crate on an unbounded
//!   variable u per parameter, t = lo + (hi − lo)(1 + sin u)/2 (the MINUIT bound transform; James & Roos,
//!   "MINUIT", CERN D506, §1.3), t = x or t = ln x;
//! * the Jacobian is by central differences in t with the plan's methods frozen between the points of one
//!   Jacobian ([`crate::instrument::plan::Plan::freeze`]): the adaptive partition of the centre is kept for
//!   x ± h, so its jumps cannot enter the differences; the step is chosen against the quadrature's error,
//!   h = ε^{1/3}·scale with ε the largest relative error estimate of the predictions (the step that balances
//!   the O(h²) truncation of a central difference against the O(ε/h) noise; Press et al., *Numerical
//!   Recipes* 3rd ed., §5.7);
//! * the answer carries standard errors from the Jacobian (covariance (JᵀWJ)⁻¹ scaled by χ²/(m − n) when
//!   m > n), the correlation matrix, the singular values of the weighted Jacobian with each column scaled by
//!   its parameter's bound width, and a verdict in plain words on what the targets cannot determine.
//!
//! The formulas and the worked example are in `docs/inverse.md`.
//!
//! The folder:
//! * `mod.rs`: the options ([`FitOptions`]), the result ([`FitReport`], [`FittedParameter`],
//!   [`FittedTarget`]), the deterministic restarts ([`restart_fractions`]) and [`fit`] itself: the checks, the
//!   solver run, the error analysis and its checks, the restarts and the verdict;
//! * `params.rs`: what is fitted to what: [`FreeParameter`], [`TargetReading`], [`targets_from_sheet`], and
//!   the check of the free parameters against the recipe and the registry;
//! * `problem.rs`: the forward model (recipe values → predictions, on adaptive or frozen methods) and the
//!   least-squares problem the solver sees, with its Jacobian.
mod params;
mod problem;

pub use params::{targets_from_sheet, FreeParameter, TargetReading};

use std::collections::HashMap;
use std::time::Instant;

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt, TerminationReason};
use nalgebra::{DMatrix, DVector};
use serde_json::Value;

use crate::error::Words;
use crate::instrument::plan::{PlanOptions, Planner};
use crate::instrument::standards::StandardGeometry;
use crate::{recipe, Error, Result};
use params::check_free;
use problem::{describe_point, Forward, Mode, Problem};

/// Uncertainty of a target given without one, in the reading's unit: the 0.2 GU repeatability that
/// `docs/inverse.md` assumes for a glossmeter (its opening list, "Weights"), used for haze and DOI units alike.
pub const DEFAULT_UNCERTAINTY: f64 = 0.2;

/// The largest Gauss–Newton step, in standard uncertainties of the targets, that may remain at a fit called
/// converged (an independent check of the solver's own stopping rule; see [`fit`]).
pub const STEP_TOLERANCE: f64 = 0.01;

/// Knobs of the fit.
#[derive(Clone, Debug)]
pub struct FitOptions {
    /// Relative tolerance of every forward reading. The default is `measure`'s (1e-6): the Jacobians run on
    /// frozen methods, so their differences do not need a tighter one, and a reading's 1e-6 is far below a
    /// glossmeter's repeatability (60 GU × 1e-6 = 6·10⁻⁵ GU against 0.2 GU).
    pub rtol: f64,
    /// Uncertainty of a target without one.
    pub default_uncertainty: f64,
    /// Most forward-model runs (each a full set of readings) the solver may spend, Jacobians excluded.
    pub max_iterations: usize,
    /// For an exactly determined fit (as many targets as free parameters), how many further solver runs
    /// from deterministic starts check that the solution is the only one ([`restart_fractions`]); 0 says
    /// in the verdict that uniqueness is not checked. Ignored when there are more targets than parameters.
    pub restarts: usize,
}

/// Restarts of an exactly determined fit by default.
pub const DEFAULT_RESTARTS: usize = 2;

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            rtol: 1e-6,
            default_uncertainty: DEFAULT_UNCERTAINTY,
            max_iterations: 200,
            restarts: DEFAULT_RESTARTS,
        }
    }
}

/// The k-th deterministic restart (k = 1, 2, …) as fractions of each parameter's bound width (in the fitted
/// variable, so in the logarithm for `log:` bounds): the k-th point of the Halton sequence in bases 2, 3, 5,
/// 7, … (Halton 1960), k = 1 giving 1/2, 1/3, 1/5, …; well spread over the box and the same on every run.
pub fn restart_fractions(k: usize, n: usize) -> Vec<f64> {
    const PRIMES: [usize; 12] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37];
    (0..n)
        .map(|j| {
            let base = PRIMES[j % PRIMES.len()];
            // A further shift for more than 12 parameters keeps the columns apart.
            let (mut i, mut f, mut r) = (k + j / PRIMES.len(), 1.0, 0.0);
            while i > 0 {
                f /= base as f64;
                r += f * (i % base) as f64;
                i /= base;
            }
            r
        })
        .collect()
}

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
    /// Singular values of the weighted Jacobian, columns scaled by each parameter's bound width (in the
    /// fitted variable), largest first.
    pub singular_values: Vec<f64>,
    /// Correlation matrix of the parameters (`None` entries where a standard error is infinite).
    pub correlation: Vec<Vec<Option<f64>>>,
    /// What the targets cannot determine, and other remarks, in plain words.
    pub verdict: Vec<String>,
    /// χ² = Σ weighted residual².
    pub chi2: f64,
    /// Forward-model runs (each a full set of readings): the solver's points, the Jacobians' displaced
    /// points, the final Jacobian, the linearity check's and the restarts' (all of them).
    pub evaluations: usize,
    /// Of `evaluations`, the runs of the linearity check (one standard error each way along every
    /// determined direction).
    pub linearity_evaluations: usize,
    /// Of `evaluations`, the runs of the restarts of an exactly determined fit.
    pub restart_evaluations: usize,
    pub seconds: f64,
    /// The recipe with the fitted values.
    pub recipe: Value,
}

impl FitReport {
    /// Whether the fit is one to trust: converged, no parameter at a bound, every parameter determined.
    pub fn ok(&self) -> bool {
        self.converged && self.identifiable && !self.parameters.iter().any(|p| p.at_bound)
    }
}

/// Fit the free parameters of `recipe` (the JSON of a recipe file named `file`) to the targets.
/// Bad arguments (paths, bounds, starts, targets, counts) are usage errors, [`Error::Argument`] where they
/// name the argument (`free`, `target`, `sheet`); a fit that runs returns its report whatever its outcome
/// (see [`FitReport::ok`]).
pub fn fit(
    recipe_json: &Value,
    file: &str,
    free: &[FreeParameter],
    targets: &[TargetReading],
    options: &FitOptions,
) -> Result<FitReport> {
    let clock = Instant::now();
    if targets.is_empty() {
        return Err(Error::Argument(
            Words::from("no targets: give ")
                .and_argument("target")
                .and(" GEOMETRY/READING=VALUE[±U] or ")
                .and_argument("sheet"),
        ));
    }
    if free.is_empty() {
        return Err(Error::Argument(Words::from("no free parameters: give ").and_argument("free").and(" PATH=LO..HI")));
    }
    if free.len() > targets.len() {
        return Err(Error::Usage(format!(
            "{} free parameters but {} target(s): a fit needs at least as many targets as free parameters",
            free.len(),
            targets.len()
        )));
    }
    if !(options.default_uncertainty.is_finite() && options.default_uncertainty > 0.0) {
        return Err(Error::Usage("the default uncertainty must be a finite number > 0".into()));
    }
    // The recipe must load as it is.
    recipe::parse_str(&recipe_json.to_string(), file)?;
    let start = check_free(recipe_json, free)?;

    let planner = Planner::new()?;
    let mut ids: Vec<String> = Vec::new();
    for t in targets {
        if !ids.contains(&t.geometry) {
            ids.push(t.geometry.clone());
        }
    }
    let geometries: Vec<StandardGeometry> = ids
        .iter()
        .map(|id| planner.geometry(id).map_err(|e| Error::argument("target", format!(" {id:?}: {e}"))))
        .collect::<Result<_>>()?;
    let plan_options = PlanOptions { rtol: options.rtol, ..PlanOptions::default() };
    // Match every target to a reading of the plan.
    let probe = planner.compile(
        recipe::parse_str(&recipe_json.to_string(), file)?.brdf,
        geometries.clone(),
        plan_options.clone(),
    )?;
    let names: Vec<(String, String, String)> = probe
        .readings
        .iter()
        .filter(|r| r.reported)
        .map(|r| (r.geometry.clone(), r.name.clone(), r.spec.quantity().to_string()))
        .collect();
    let mut index = Vec::new();
    for t in targets {
        let i = names
            .iter()
            .position(|(g, n, _)| *g == t.geometry && *n == t.name)
            .or_else(|| names.iter().position(|(g, _, q)| *g == t.geometry && *q == t.name))
            .ok_or_else(|| {
                let has: Vec<&str> =
                    names.iter().filter(|(g, _, _)| *g == t.geometry).map(|(_, n, _)| n.as_str()).collect();
                Error::argument(
                    "target",
                    format!(
                        " {:?}: geometry {:?} has no reading {:?}; its readings are {}",
                        format!("{}/{}", t.geometry, t.name),
                        t.geometry,
                        t.name,
                        has.join(", ")
                    ),
                )
            })?;
        index.push(i);
    }
    let mut seen: HashMap<usize, usize> = HashMap::new();
    for (k, i) in index.iter().enumerate() {
        if let Some(prev) = seen.insert(*i, k) {
            return Err(Error::argument(
                "target",
                format!(
                    " {:?}: the same reading is targeted twice (also target {})",
                    format!("{}/{}", targets[k].geometry, targets[k].name),
                    prev + 1
                ),
            ));
        }
    }

    let fwd = Forward {
        recipe: recipe_json,
        file,
        free,
        planner,
        geometries,
        options: plan_options,
        index,
        runs: std::cell::Cell::new(0),
    };
    let u_sigma: Vec<f64> = targets.iter().map(|t| t.uncertainty.unwrap_or(options.default_uncertainty)).collect();
    let u0 = DVector::from_iterator(
        free.len(),
        free.iter().zip(&start).map(|(p, &x)| {
            let (a, b) = p.t_bounds();
            (2.0 * (p.t_of_x(x) - a) / (b - a) - 1.0).clamp(-1.0, 1.0).asin()
        }),
    );
    let mut problem = Problem {
        fwd: &fwd,
        targets,
        u_sigma: u_sigma.clone(),
        u: u0.clone(),
        current: Err(String::new()),
        last_error: std::cell::RefCell::new(None),
    };
    problem.set_params(&u0);
    if let Err(e) = &problem.current {
        return Err(Error::Numeric(format!("the start does not evaluate: {e}")));
    }
    let solver = || {
        LevenbergMarquardt::new()
            .with_ftol(1e-12)
            .with_xtol(1e-10)
            .with_gtol(1e-12)
            .with_patience(options.max_iterations.div_ceil(free.len() + 1).max(1))
    };
    let (problem, report) = solver().minimize(problem);
    let (converged, termination) = match &report.termination {
        TerminationReason::Converged { .. } => (true, "converged (ftol/xtol)".to_string()),
        TerminationReason::Orthogonal => (true, "converged (the residuals are orthogonal to the Jacobian)".into()),
        TerminationReason::ResidualsZero => (true, "converged (the residuals are zero)".into()),
        TerminationReason::NoImprovementPossible(w) => {
            (true, format!("converged to the noise floor of the forward model ({w} cannot improve further)"))
        }
        TerminationReason::LostPatience => (false, "did not converge: the evaluation budget ran out".into()),
        TerminationReason::User(_) => (
            false,
            format!(
                "did not converge: a forward run failed ({})",
                problem.last_error.borrow().clone().unwrap_or_default()
            ),
        ),
        other => (false, format!("did not converge: {other:?}")),
    };

    // The answer at the final point: Jacobian in t (on the frozen methods of its adaptive run), covariance,
    // SVD. `current` always belongs to `u` (both are set together in `set_params`).
    let t = problem.t_of_u(&problem.u);
    let x = problem.x_of_t(&t);
    let current = match &problem.current {
        Ok(c) => c,
        Err(e) => return Err(Error::Numeric(format!("the final point does not evaluate: {e}"))),
    };
    let centre = current.predictions.clone();
    let jt = problem.jacobian_t(&t, &centre, &current.frozen)?;
    let n = free.len();
    let m = targets.len();
    let r = problem.weighted(&centre);
    let chi2 = r.norm_squared();
    // The covariance is scaled by the residuals (the Birge ratio χ²/(m − n)) when they scatter more than the
    // targets' uncertainties say, and never shrunk below what those uncertainties give: exact or lucky
    // targets (χ² ≈ 0) would otherwise report standard errors of nothing (the Particle Data Group's scale
    // factor S = √(χ²/(N − 1)), applied only when S > 1; PDG, Review of Particle Physics, Introduction §5.2.2).
    let s2 = if m > n { (chi2 / (m - n) as f64).max(1.0) } else { 1.0 };
    let widths: Vec<f64> = free.iter().map(|p| p.t_bounds().1 - p.t_bounds().0).collect();
    let mut js = jt.clone();
    for (k, w) in widths.iter().enumerate() {
        js.column_mut(k).scale_mut(*w);
    }
    let svd = js.clone().svd(true, true);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
    let singular_values: Vec<f64> = order.iter().map(|&i| svd.singular_values[i]).collect();
    let v_t = svd.v_t.clone().expect("V requested");
    let smax = singular_values.first().copied().unwrap_or(0.0);
    // Covariance in t: s²·V Σ⁻² Vᵀ / (width_a width_b), exact null directions left out. A parameter that
    // takes part (component ≥ 0.2) in a direction with singular value < 1 (see the verdict below) has a
    // standard error larger than its bound width: it is reported undetermined (None), as is any parameter in
    // an exact null direction.
    let null = |s: f64| s <= 1e-12 * smax || s == 0.0;
    let mut cov = DMatrix::<f64>::zeros(n, n);
    let mut undetermined = vec![false; n];
    for &i in &order {
        let s = svd.singular_values[i];
        let v = v_t.row(i).transpose();
        for k in 0..n {
            if (null(s) && v[k].abs() > 1e-3) || (s < 1.0 && v[k].abs() >= 0.2) {
                undetermined[k] = true;
            }
        }
        if !null(s) {
            cov += (&v * v.transpose()) / (s * s);
        }
    }
    for a in 0..n {
        for b in 0..n {
            cov[(a, b)] *= s2 * widths[a] * widths[b];
        }
    }
    let std_t: Vec<Option<f64>> = (0..n).map(|k| (!undetermined[k]).then(|| cov[(k, k)].max(0.0).sqrt())).collect();
    let std_t_unscaled: Vec<Option<f64>> = std_t.iter().map(|s| s.map(|s| s / s2.sqrt())).collect();
    let correlation: Vec<Vec<Option<f64>>> = (0..n)
        .map(|a| {
            (0..n)
                .map(|b| match (std_t[a], std_t[b]) {
                    (Some(sa), Some(sb)) if sa > 0.0 && sb > 0.0 => Some((cov[(a, b)] / (sa * sb)).clamp(-1.0, 1.0)),
                    _ => None,
                })
                .collect()
        })
        .collect();
    let at_bound: Vec<bool> = (0..n)
        .map(|k| {
            let (a, b) = free[k].t_bounds();
            let tol = 1e-6 * widths[k];
            t[k] - a <= tol || b - t[k] <= tol
        })
        .collect();

    // An independent check of the solver's stop: the Gauss–Newton step that remains from the final point,
    // over the parameters not at a bound and in the directions the targets determine, measured in units of
    // the targets' uncertainties (|Uᵀr| over those directions). A solver that stopped early (a budget, a
    // noise floor met far from the optimum) leaves a step of a sizeable fraction of a standard error.
    let inner: Vec<usize> = (0..n).filter(|&k| !at_bound[k]).collect();
    let remaining = if inner.is_empty() {
        0.0
    } else {
        let ji = DMatrix::from_fn(m, inner.len(), |i, c| js[(i, inner[c])]);
        let svd_i = ji.svd(true, false);
        let u_i = svd_i.u.expect("U requested");
        let smax_i = svd_i.singular_values.max();
        (0..svd_i.singular_values.len())
            .filter(|&c| svd_i.singular_values[c] >= 1.0 && svd_i.singular_values[c] > 1e-12 * smax_i)
            .map(|c| u_i.column(c).dot(&r).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let (converged, termination) = if converged && remaining > STEP_TOLERANCE {
        (
            false,
            format!(
                "did not converge: the solver stopped ({termination}) a Gauss–Newton step of {remaining:.3} standard \
                 uncertainties from the optimum (at most {STEP_TOLERANCE} is accepted)"
            ),
        )
    } else {
        (converged, termination)
    };

    // The linear error analysis, checked: along every determined direction (singular value s ≥ 1) step one
    // standard error each way, t ± δ with δ_k = width_k·v_k/s, integrate adaptively there, and compare the
    // actual change of χ² with the change the linearised model predicts, ‖r + Jδ‖² − ‖r‖² (≈ 1 at the
    // optimum). A ratio outside [1/2, 2] means the readings are not linear in the parameters over one
    // standard error (a curved valley, a kink, a switch of model): the standard errors and correlations are
    // then not to be trusted and the fit is not reported identifiable (Bates & Watts, *Nonlinear Regression
    // Analysis and Its Applications*, 1988, ch. 7, on when linear approximation intervals fail).
    let mut nonlinear: Vec<String> = Vec::new();
    let runs_before_linearity = fwd.runs.get();
    for &i in &order {
        let s = svd.singular_values[i];
        if s < 1.0 || null(s) {
            continue;
        }
        let v = v_t.row(i);
        for sign in [1.0, -1.0] {
            let delta: Vec<f64> = (0..n).map(|k| sign * widths[k] * v[k] / s).collect();
            let tt: Vec<f64> = (0..n).map(|k| t[k] + delta[k]).collect();
            let inside = (0..n).all(|k| {
                let (a, b) = free[k].t_bounds();
                tt[k] >= a && tt[k] <= b
            });
            if !inside {
                continue;
            }
            let step = DVector::from_column_slice(&delta);
            let expected = (&r + &jt * &step).norm_squared() - chi2;
            let actual = match fwd.run(&problem.x_of_t(&tt), Mode::Freeze) {
                Ok(Some((pred, _))) => problem.weighted(&pred).norm_squared() - chi2,
                _ => f64::NAN,
            };
            let ratio = actual / expected;
            if !(ratio.is_finite() && (0.5..=2.0).contains(&ratio)) {
                let combo: Vec<String> = (0..n)
                    .filter(|&k| v[k].abs() >= 0.2)
                    .map(|k| format!("{:+.2}·Δ{}", v[k], free[k].pointer))
                    .collect();
                nonlinear.push(format!(
                    "the readings are not linear in the parameters over one standard error along {}: one standard \
                     error that way changes χ² by {actual:.3}, where the linear error analysis says {expected:.3}; the \
                     standard errors and correlations are not to be trusted here (a profile of χ² or a Monte Carlo \
                     over the noise would be)",
                    combo.join(" ")
                ));
                break;
            }
        }
    }

    // An exactly determined fit (m = n) has zero residuals at any exact solution, and the readings may have
    // more than one (a gloss that rises and falls with a parameter; two parameters that trade off): the
    // covariance at one solution says nothing of another. Restart the solver from deterministic starts
    // spread over the bounds and compare where each lands: at this solution (every parameter within three
    // standard errors), at another one that fits the targets as well (χ² within 1 of this one: a second
    // solution the targets cannot tell from this one), or at a worse local minimum.
    let linearity_evaluations = fwd.runs.get() - runs_before_linearity;
    let mut uniqueness: Vec<String> = Vec::new();
    let mut second_solution = false;
    let runs_before_restarts = fwd.runs.get();
    if m == n {
        if options.restarts == 0 {
            uniqueness.push(format!(
                "the fit is exactly determined ({m} target(s) for {n} free parameter(s)): the residuals vanish at any \
                 exact solution, and whether another one exists is not checked (restarts 0)"
            ));
        } else {
            let (mut same, mut worse, mut failed) = (0usize, 0usize, 0usize);
            let mut others: Vec<String> = Vec::new();
            for k in 1..=options.restarts {
                let fr = restart_fractions(k, n);
                let u_k = DVector::from_iterator(n, fr.iter().map(|f| (2.0 * f - 1.0).clamp(-1.0, 1.0).asin()));
                let mut p_k = Problem {
                    fwd: &fwd,
                    targets,
                    u_sigma: u_sigma.clone(),
                    u: u_k.clone(),
                    current: Err(String::new()),
                    last_error: std::cell::RefCell::new(None),
                };
                p_k.set_params(&u_k);
                if p_k.current.is_err() {
                    failed += 1;
                    continue;
                }
                let (p_k, _) = solver().minimize(p_k);
                let Ok(c_k) = &p_k.current else {
                    failed += 1;
                    continue;
                };
                let t_k = p_k.t_of_u(&p_k.u);
                let chi2_k = p_k.weighted(&c_k.predictions).norm_squared();
                let apart = (0..n).any(|j| match std_t[j] {
                    Some(sd) if sd > 0.0 => (t_k[j] - t[j]).abs() > 3.0 * sd,
                    // An undetermined parameter: apart if it moved by more than 1e-3 of its bound width.
                    _ => (t_k[j] - t[j]).abs() > 1e-3 * widths[j],
                });
                if !apart {
                    same += 1;
                } else if chi2_k <= chi2 + 1.0 {
                    let x_k = p_k.x_of_t(&t_k);
                    others.push(format!("{} (χ² = {chi2_k:.3})", describe_point(free, &x_k)));
                } else {
                    worse += 1;
                }
            }
            let restarts = options.restarts;
            let mut line = format!(
                "the fit is exactly determined ({m} target(s) for {n} free parameter(s)); {restarts} restart(s) from \
                 deterministic starts spread over the bounds (Halton points): {same} returned to this solution"
            );
            if worse > 0 {
                line.push_str(&format!(", {worse} stopped at a worse local minimum"));
            }
            if failed > 0 {
                line.push_str(&format!(", {failed} could not be evaluated"));
            }
            if !others.is_empty() {
                line.push_str(&format!(
                    ", {} found another solution that fits the targets as well: {}; the targets do not single out \
                     one recipe",
                    others.len(),
                    others.join("; ")
                ));
                second_solution = true;
            } else {
                line.push_str("; no second solution was found from these starts (which does not prove there is none)");
            }
            uniqueness.push(line);
        }
    }

    let restart_evaluations = fwd.runs.get() - runs_before_restarts;

    // Verdict: every direction whose full-range move changes the weighted residuals by less than one.
    let mut verdict = Vec::new();
    let mut identifiable = true;
    for &i in &order {
        let s = svd.singular_values[i];
        if s >= 1.0 {
            continue;
        }
        identifiable = false;
        let v = v_t.row(i);
        let involved: Vec<usize> = (0..n).filter(|&k| v[k].abs() >= 0.2).collect();
        let what = if involved.len() == 1 {
            let p = &free[involved[0]];
            format!(
                "{} is not determined by these targets: moving it across its whole range {}..{}{} changes the \
                 readings by {s:.3} of their uncertainty",
                p.pointer,
                p.lower,
                p.upper,
                if p.log { " (log)" } else { "" },
            )
        } else {
            let combo: Vec<String> = involved.iter().map(|&k| format!("{:+.2}·Δ{}", v[k], free[k].pointer)).collect();
            format!(
                "these targets cannot tell apart {}: they fix only a combination; moving along {} (each Δ in units \
                 of its bound width{}) changes the readings by {s:.3} of their uncertainty",
                involved.iter().map(|&k| free[k].pointer.as_str()).collect::<Vec<_>>().join(" and "),
                combo.join(" "),
                if involved.iter().any(|&k| free[k].log) { ", in the logarithm for log: parameters" } else { "" },
            )
        };
        verdict.push(what);
    }
    if !nonlinear.is_empty() {
        identifiable = false;
        verdict.extend(nonlinear);
    }
    if second_solution {
        identifiable = false;
    }
    verdict.extend(uniqueness);
    for a in 0..n {
        for b in a + 1..n {
            if let Some(c) = correlation[a][b] {
                if c.abs() > 0.95 && identifiable {
                    verdict.push(format!(
                        "{} and {} are strongly correlated (ρ = {c:.3}): the targets determine them mostly together",
                        free[a].pointer, free[b].pointer
                    ));
                }
            }
        }
    }

    let parameters: Vec<FittedParameter> = free
        .iter()
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
        .collect();
    for p in parameters.iter().filter(|p| p.at_bound) {
        verdict.push(format!(
            "{} = {} is at a bound of {}..{}: the best fit may lie outside; widen the bounds or check the targets",
            p.pointer, p.value, p.lower, p.upper
        ));
    }
    if !converged {
        verdict.push(format!("the fit {termination}"));
    }
    let fitted_targets: Vec<FittedTarget> = targets
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let (v, e) = centre[i];
            FittedTarget {
                target: t.clone(),
                uncertainty: u_sigma[i],
                predicted: v,
                prediction_error: e,
                residual: v - t.value,
                weighted_residual: r[i],
            }
        })
        .collect();
    let recipe = fwd.recipe_at(&x);
    Ok(FitReport {
        parameters,
        targets: fitted_targets,
        converged,
        termination,
        identifiable,
        singular_values,
        correlation,
        verdict,
        chi2,
        evaluations: fwd.runs.get(),
        linearity_evaluations,
        restart_evaluations,
        seconds: clock.elapsed().as_secs_f64(),
        recipe,
    })
}
