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
//! * the fit is judged by its χ² against its degrees of freedom ([`chi2_survival`], [`P_THRESHOLD`]), a target
//!   out of the model's reach is named as such, the model's constraints hold inside the search (a barrier),
//!   and with one or two free parameters a scan of the bounds seeds the restarts that look for other roots;
//! * the answer carries standard errors from the Jacobian (covariance (JᵀWJ)⁻¹ scaled by χ²/(m − n) when
//!   m > n), the correlation matrix, the singular values of the weighted Jacobian with each column scaled by
//!   its parameter's bound width, and a verdict in plain words on what the targets cannot determine.
//!
//! The formulas and the worked example are in `docs/inverse.md`.
//!
//! The folder:
//! * `mod.rs`: the options ([`FitOptions`]), the result ([`FitReport`], [`FittedParameter`],
//!   [`FittedTarget`]), the deterministic restarts ([`restart_fractions`], the scan of the bounds) and [`fit`]
//!   itself: the checks, the solver runs, the error analysis and its checks, goodness of fit and reach, the
//!   restarts and the verdict;
//! * `goodness.rs`: the goodness of fit, the chi-square survival function from the regularized incomplete
//!   gamma function, and the threshold below which the model cannot reproduce the readings;
//! * `params.rs`: what is fitted to what: [`FreeParameter`], [`TargetReading`], [`targets_from_sheet`], and
//!   the check of the free parameters against the recipe and the registry;
//! * `problem.rs`: the forward model (recipe values → predictions, on adaptive or frozen methods) and the
//!   least-squares problem the solver sees, with its Jacobian.
mod goodness;
mod params;
mod problem;

pub use goodness::{chi2_survival, gamma_q, P_THRESHOLD};
pub use params::{targets_from_sheet, FreeParameter, TargetReading};

use std::collections::HashMap;
use std::time::Instant;

use levenberg_marquardt::{LevenbergMarquardt, TerminationReason};
use nalgebra::{DMatrix, DVector};
use serde_json::Value;

use crate::error::Words;
use crate::instrument::plan::{PlanOptions, Planner};
use crate::instrument::standards::StandardGeometry;
use crate::{recipe, Error, Result};
use params::check_free;
use problem::{describe_point, u_of_t, Forward, Mode, Problem};

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
    /// in the verdict that uniqueness is not checked. With one or two free parameters it also switches the
    /// scan of the bounds, which seeds restarts for any number of targets (docs/inverse.md §Every root).
    pub restarts: usize,
    /// User geometries (loaded from geometry files) that targets may name besides the shipped ones; a
    /// target's geometry id is looked up here first.
    pub geometries: Vec<StandardGeometry>,
}

/// Restarts of an exactly determined fit by default.
pub const DEFAULT_RESTARTS: usize = 2;

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            rtol: crate::instrument::plan::DEFAULT_RTOL,
            default_uncertainty: DEFAULT_UNCERTAINTY,
            max_iterations: 200,
            restarts: DEFAULT_RESTARTS,
            geometries: Vec::new(),
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
        .map(|id| match options.geometries.iter().find(|g| g.geometry.id == *id) {
            Some(g) => Ok(g.clone()),
            None => planner.geometry(id).map_err(|e| {
                let user: Vec<&str> = options.geometries.iter().map(|g| g.geometry.id.as_str()).collect();
                let also = if user.is_empty() {
                    String::new()
                } else {
                    format!("; the user geometries given are {}", user.join(", "))
                };
                Error::argument("target", format!(" {id:?}: {e}{also}"))
            }),
        })
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

    let n = free.len();
    let m = targets.len();
    let scan_options = PlanOptions { rtol: options.rtol.max(SCAN_RTOL), ..plan_options.clone() };
    let fwd = Forward {
        recipe: recipe_json,
        file,
        free,
        planner,
        geometries,
        options: plan_options,
        scan_options,
        index,
        runs: std::cell::Cell::new(0),
    };
    let u_sigma: Vec<f64> = targets.iter().map(|t| t.uncertainty.unwrap_or(options.default_uncertainty)).collect();
    let widths: Vec<f64> = free.iter().map(|p| p.t_bounds().1 - p.t_bounds().0).collect();
    let u0 = DVector::from_iterator(n, free.iter().zip(&start).map(|(p, &x)| u_of_t(p.t_of_x(x), p.t_bounds())));
    let first = Problem::new(&fwd, targets, &u_sigma, &u0);
    if let Err(e) = &first.current {
        return Err(Error::Numeric(format!("the start does not evaluate: {e}")));
    }
    let patience = options.max_iterations.div_ceil(n + 1).max(1);
    // A restart only has to show where its start leads (back here, to another solution, a plateau or a worse
    // minimum), not to polish it: a quarter of the budget (docs/inverse.md §Every root, docs/performance.md).
    let restart_patience = patience.div_ceil(RESTART_BUDGET_DIVISOR);
    let main = solve(first, patience);
    let runs_before_restarts = fwd.runs.get();

    // The scan of the bounds (one or two free parameters, restarts asked for): a coarse grid in t, each point
    // integrated adaptively at the scan's loose tolerance; the grid's local minima of χ² seed the restarts
    // (docs/inverse.md §Every root).
    let scan: Vec<ScanPoint> = if n <= 2 && options.restarts > 0 {
        scan_grid(n)
            .into_iter()
            .map(|f| {
                let t: Vec<f64> = (0..n).map(|k| free[k].t_bounds().0 + f[k] * widths[k]).collect();
                let pred = fwd.run(&main.problem.x_of_t(&t), Mode::Scan).ok().flatten().map(|p| p.0);
                let r = pred.as_ref().map(|p| main.problem.weighted(p));
                let chi2 = r.as_ref().map_or(f64::INFINITY, |r| r.norm_squared());
                ScanPoint { t, pred, r, chi2 }
            })
            .collect()
    } else {
        Vec::new()
    };
    let scan_evaluations = fwd.runs.get() - runs_before_restarts;
    let seeds = scan_minima(&scan, n);
    let halton = if m == n && options.restarts > 0 {
        if n <= 2 {
            options.restarts.saturating_sub(seeds.len())
        } else {
            options.restarts
        }
    } else {
        0
    };
    let mut starts: Vec<DVector<f64>> = seeds
        .iter()
        .map(|&i| DVector::from_iterator(n, (0..n).map(|k| u_of_t(scan[i].t[k], free[k].t_bounds()))))
        .collect();
    for k in 1..=halton {
        let fr = restart_fractions(k, n);
        starts.push(DVector::from_iterator(
            n,
            (0..n).map(|j| u_of_t(free[j].t_bounds().0 + fr[j] * widths[j], free[j].t_bounds())),
        ));
    }
    let mut failed = 0usize;
    let mut ends: Vec<Solved> = vec![main];
    for u_k in &starts {
        let p_k = Problem::new(&fwd, targets, &u_sigma, u_k);
        if p_k.current.is_err() {
            failed += 1;
            continue;
        }
        ends.push(solve(p_k, restart_patience));
    }
    let runs_after_restarts = fwd.runs.get();
    // The fit reported is the solver's from the recipe's start, unless a restart reached a clearly lower χ²
    // (by more than 1): then the start led to a worse local minimum or a plateau, and the best end is the fit.
    let chi2_of = |s: &Solved| s.chi2().unwrap_or(f64::INFINITY);
    let best = (1..ends.len()).min_by(|&a, &b| chi2_of(&ends[a]).total_cmp(&chi2_of(&ends[b])));
    let chosen = match best {
        Some(b) if chi2_of(&ends[b]) < chi2_of(&ends[0]) - 1.0 => b,
        _ => 0,
    };
    let problem = &ends[chosen].problem;
    let (converged, termination) = (ends[chosen].converged, ends[chosen].termination.clone());

    // The answer at the final point: Jacobian in t (on the frozen methods of its adaptive run), covariance,
    // SVD. `current` always belongs to `u` (both are set together in `set_params`), and the solver's final
    // point is one it accepted, so it evaluates.
    let t = problem.t_of_u(&problem.u);
    let x = problem.x_of_t(&t);
    let current = match &problem.current {
        Ok(c) => c,
        Err(e) => return Err(Error::Numeric(format!("the final point does not evaluate: {e}"))),
    };
    let centre = current.predictions.clone();
    let (jt, dead) = problem.jacobian_t(&t, &centre, &current.frozen);
    let r = problem.weighted(&centre);
    let chi2 = r.norm_squared();
    let dof = m - n;
    let p_value = goodness::chi2_survival(chi2, dof);
    // Goodness of fit (docs/inverse.md §Goodness of fit): with degrees of freedom, χ² must be probable for
    // them (p ≥ P_THRESHOLD); an exactly determined fit must reach every target within its uncertainty.
    let reproduces = match p_value {
        Some(p) => p >= goodness::P_THRESHOLD,
        None => r.iter().all(|ri| ri.abs() <= 1.0),
    };
    // The covariance is scaled by the residuals (the Birge ratio χ²/(m − n)) when they scatter more than the
    // targets' uncertainties say, and never shrunk below what those uncertainties give: exact or lucky
    // targets (χ² ≈ 0) would otherwise report standard errors of nothing (the Particle Data Group's scale
    // factor S = √(χ²/(N − 1)), applied only when S > 1; PDG, Review of Particle Physics, Introduction §5.2.2).
    let s2 = if m > n { (chi2 / (m - n) as f64).max(1.0) } else { 1.0 };
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
    // standard error larger than its bound width, or none the linearization can give: it is reported without
    // one (None), as is any parameter in an exact null direction.
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
    // Analysis and Its Applications*, 1988, ch. 7, on when linear approximation intervals fail). A side that
    // leaves the bounds or the model's constraints is skipped.
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
                _ => continue,
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
    let linearity_evaluations = fwd.runs.get() - runs_before_linearity;

    // Where each restart ended, against the fit: at this solution (every parameter within three standard
    // errors), at another one that fits the targets as well (χ² within 1 of this one: a second solution the
    // targets cannot tell from this one), on a plateau (moving any parameter by a twentieth of its bound
    // width changes the readings by less than one uncertainty: the solver stopped because nothing changes,
    // not at a minimum; checked first, so that points of one plateau are not called solutions), or at a
    // worse local minimum.
    let runs_before_classify = fwd.runs.get();
    let (mut same, mut plateau, mut worse) = (0usize, 0usize, 0usize);
    let mut others: Vec<String> = Vec::new();
    for (j, end) in ends.iter().enumerate() {
        if j == chosen {
            continue;
        }
        let Ok(c_j) = &end.problem.current else {
            failed += 1;
            continue;
        };
        let t_j = end.problem.t_of_u(&end.problem.u);
        let r_j = end.problem.weighted(&c_j.predictions);
        let chi2_j = r_j.norm_squared();
        let apart = (0..n).any(|k| match std_t[k] {
            Some(sd) if sd > 0.0 => (t_j[k] - t[k]).abs() > 3.0 * sd,
            // An undetermined parameter: apart if it moved by more than 1e-3 of its bound width.
            _ => (t_j[k] - t[k]).abs() > 1e-3 * widths[k],
        });
        if !apart {
            same += 1;
            continue;
        }
        let flat = (0..n).all(|k| {
            [1.0, -1.0].iter().all(|sign| {
                let mut tt = t_j.clone();
                let (a, b) = free[k].t_bounds();
                tt[k] = (tt[k] + sign * PLATEAU_STEP * widths[k]).clamp(a, b);
                match fwd.run(&end.problem.x_of_t(&tt), Mode::Freeze) {
                    Ok(Some((pred, _))) => (end.problem.weighted(&pred) - &r_j).norm() < 1.0,
                    _ => true,
                }
            })
        });
        if flat {
            plateau += 1;
        } else if chi2_j <= chi2 + 1.0 {
            others.push(format!("{} (χ² = {chi2_j:.3})", describe_point(free, &end.problem.x_of_t(&t_j))));
        } else {
            worse += 1;
        }
    }
    let runs_after_classify = fwd.runs.get();
    let second_solution = !others.is_empty();
    let restarts_run = ends.len() - 1 + failed;
    let mut uniqueness: Vec<String> = Vec::new();
    if m == n && options.restarts == 0 {
        uniqueness.push(format!(
            "the fit is exactly determined ({m} target(s) for {n} free parameter(s)): the residuals vanish at any \
             exact solution, and whether another one exists is not checked (restarts 0)"
        ));
    } else if restarts_run > 0 || !scan.is_empty() {
        let mut from = Vec::new();
        if !scan.is_empty() {
            from.push(format!(
                "{} local minim{} of χ² on a scan of the bounds ({} points in the fitted variables)",
                seeds.len(),
                if seeds.len() == 1 { "um" } else { "a" },
                scan.len()
            ));
        }
        if halton > 0 {
            from.push(format!("{halton} deterministic Halton point(s) spread over the bounds"));
        }
        let mut line = if m == n {
            format!("the fit is exactly determined ({m} target(s) for {n} free parameter(s)); ")
        } else {
            String::new()
        };
        line.push_str(&format!(
            "{restarts_run} restart(s) from {}: {same} returned to this solution",
            from.join(" and ")
        ));
        if chosen != 0 {
            line.push_str(" (the solver from the recipe's start is one of the others: it stopped at a higher χ²)");
        }
        if plateau > 0 {
            line.push_str(&format!(
                ", {plateau} stopped on a plateau (the readings do not change there: a flat region, not a minimum)"
            ));
        }
        if worse > 0 {
            line.push_str(&format!(
                ", {worse} stopped at a worse χ² (a local minimum, or the end of a restart's budget, a quarter of the \
                 fit's)"
            ));
        }
        if failed > 0 {
            line.push_str(&format!(", {failed} started outside the model's constraints"));
        }
        if second_solution {
            line.push_str(&format!(
                ", {} found another solution that fits the targets as well: {}; the targets do not single out one \
                 recipe",
                others.len(),
                others.join("; ")
            ));
        } else {
            line.push_str("; no second solution was found from these starts (which does not prove there is none)");
        }
        uniqueness.push(line);
    }

    // Every direction whose linear full-range move changes the weighted residuals by less than one is probed
    // at the two ends of the box along it (adaptive runs): if the readings there do differ from the fit's by
    // an uncertainty or more, the parameters are seen and the point is stationary in them (an extremum or a
    // saddle of the readings, where a target beyond the model's reach leaves the solver), not undetermined
    // (docs/inverse.md §Reach).
    let mut verdict = Vec::new();
    let mut identifiable = true;
    let mut stationary = false;
    let mut weak_lines = Vec::new();
    for &i in &order {
        let s = svd.singular_values[i];
        if s >= 1.0 {
            continue;
        }
        let v = v_t.row(i);
        let dir: Vec<f64> = (0..n).map(|k| v[k] * widths[k]).collect();
        let measured = across_box(&t, &dir, free).and_then(|(lo, hi)| {
            let mut most: Option<f64> = None;
            for end in [lo, hi] {
                if (0..n).all(|k| (end[k] - t[k]).abs() <= 1e-12 * widths[k]) {
                    continue;
                }
                match fwd.run(&problem.x_of_t(&end), Mode::Freeze) {
                    Ok(Some((pred, _))) => {
                        let d = (problem.weighted(&pred) - &r).norm();
                        most = Some(most.map_or(d, |m: f64| m.max(d)));
                    }
                    _ => return None,
                }
            }
            most
        });
        let involved: Vec<usize> = (0..n).filter(|&k| v[k].abs() >= 0.2).collect();
        let combo: Vec<String> = involved.iter().map(|&k| format!("{:+.2}·Δ{}", v[k], free[k].pointer)).collect();
        let log_note =
            if involved.iter().any(|&k| free[k].log) { ", in the logarithm for log: parameters" } else { "" };
        match measured {
            // With one parameter a direction seen at the ends of the bounds is an extremum (or a plateau's
            // edge); with several it may also be a curved valley of equally good fits, which is what it is
            // taken for when the restarts found another solution.
            Some(d) if d >= 1.0 && !(n >= 2 && second_solution) => {
                stationary = true;
                weak_lines.push(format!(
                    "the readings are stationary at the fit along {} (each Δ in units of its bound width{log_note}): \
                     their local slope times the bound width is {s:.3} of their uncertainty, yet at the ends of the \
                     bounds that way they differ from the fit's by {d:.4} uncertainties; so the targets do see {}, \
                     and this point is an extremum, a saddle or a plateau of the readings{}, where the linear error \
                     analysis gives no standard error",
                    combo.join(" "),
                    involved.iter().map(|&k| free[k].pointer.as_str()).collect::<Vec<_>>().join(" and "),
                    if n >= 2 {
                        ", or lies in a curved valley along which other parameter sets fit as well"
                    } else {
                        ""
                    },
                ));
            }
            _ => {
                identifiable = false;
                let change = match measured {
                    Some(d) if d >= 1.0 => format!(
                        "by {s:.3} of their uncertainty to first order (the valley is curved: at the ends of the \
                         bounds that way they differ by {d:.4}, and the restarts found other solutions along it)"
                    ),
                    Some(d) => format!("by at most {d:.3} of their uncertainty (at the ends of the bounds)"),
                    None => format!("by {s:.3} of their uncertainty (the local slope times the bound width)"),
                };
                weak_lines.push(if involved.len() == 1 {
                    let p = &free[involved[0]];
                    format!(
                        "{} is not determined by these targets: moving it across its whole range {}..{}{} changes the \
                         readings {change}",
                        p.pointer,
                        p.lower,
                        p.upper,
                        if p.log { " (log)" } else { "" },
                    )
                } else {
                    format!(
                        "these targets cannot tell apart {}: they fix only a combination; moving along {} (each Δ in \
                         units of its bound width{log_note}) changes the readings {change}",
                        involved.iter().map(|&k| free[k].pointer.as_str()).collect::<Vec<_>>().join(" and "),
                        combo.join(" "),
                    )
                });
            }
        }
    }
    let restart_evaluations = runs_after_restarts - runs_before_restarts + (runs_after_classify - runs_before_classify);

    // Goodness of fit and reach first: a model that cannot reproduce the readings makes everything else moot.
    let fitted_targets: Vec<FittedTarget> = targets
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
                weighted_residual: r[i],
            }
        })
        .collect();
    if !reproduces {
        verdict.extend(cannot_reproduce(
            &fitted_targets,
            chi2,
            dof,
            p_value,
            &Reached { scan: &scan, ends: &ends, free, x_of_t: &|t: &[f64]| problem.x_of_t(t), u_sigma: &u_sigma },
        ));
    }
    if chosen != 0 {
        verdict.push(format!(
            "the solver from the recipe's start stopped at χ² = {:.4} ({}); a restart reached χ² = {chi2:.4}, and \
             that is the fit reported",
            chi2_of(&ends[0]),
            describe_point(free, &ends[0].problem.x_of_t(&ends[0].problem.t_of_u(&ends[0].problem.u))),
        ));
    }
    verdict.extend(weak_lines);
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
    for &k in &dead {
        identifiable = false;
        verdict.push(format!(
            "{}: the derivative could not be taken (neither side of {} evaluates: the material changes kind, or \
             leaves the model's constraints, there)",
            free[k].pointer, x[k]
        ));
    }
    let refused: usize = ends.iter().map(|e| e.problem.refused.get()).sum();
    if refused > 0 {
        verdict.push(format!(
            "{refused} trial point(s) of the solver lay outside the model's constraints (the recipe does not load \
             there) and were refused; the search stayed inside them"
        ));
    }
    if !converged {
        verdict.push(format!("the fit {termination}"));
    }
    let recipe = fwd.recipe_at(&x);
    Ok(FitReport {
        parameters,
        targets: fitted_targets,
        converged,
        termination,
        identifiable,
        stationary,
        singular_values,
        correlation,
        verdict,
        chi2,
        dof,
        p_value,
        reproduces,
        error_scale: s2.sqrt(),
        evaluations: fwd.runs.get(),
        linearity_evaluations,
        restart_evaluations,
        scan_evaluations,
        seconds: clock.elapsed().as_secs_f64(),
        recipe,
    })
}

/// Tolerance of the scan's runs (at least; the fit's own when looser): the scan only seeds the restarts, and
/// a coarse grid needs readings to a few digits.
const SCAN_RTOL: f64 = 1e-3;

/// Points of the scan per fitted variable: 24 for one free parameter, 8 × 8 for two.
const SCAN_POINTS: [usize; 2] = [24, 8];

/// A restart's evaluation budget is the fit's divided by this.
const RESTART_BUDGET_DIVISOR: usize = 4;

/// The plateau probe's step, as a fraction of each bound width.
const PLATEAU_STEP: f64 = 0.05;

/// One point of the scan of the bounds: t, the predictions (None where it does not evaluate), χ².
struct ScanPoint {
    t: Vec<f64>,
    pred: Option<Vec<(f64, f64)>>,
    /// The weighted residuals.
    r: Option<DVector<f64>>,
    chi2: f64,
}

/// The scan's grid as fractions of the bound widths in t: the cell centres (i + ½)/N of N cells per variable,
/// the first variable fastest.
fn scan_grid(n: usize) -> Vec<Vec<f64>> {
    let g = SCAN_POINTS[n.clamp(1, 2) - 1];
    let f = |i: usize| (i as f64 + 0.5) / g as f64;
    if n == 1 {
        (0..g).map(|i| vec![f(i)]).collect()
    } else {
        (0..g * g).map(|i| vec![f(i % g), f(i / g)]).collect()
    }
}

/// The scan's local minima of χ²: points that evaluate, no higher than any neighbour (the 2 or 8 around it),
/// and whose readings differ from at least one neighbour's by an uncertainty or more (‖r_q − r_p‖ ≥ 1 in the
/// weighted residuals: a flat stretch, where the loose tolerance's noise alone makes minima, seeds
/// nothing); lowest first, at most [`MAX_SEEDS`].
fn scan_minima(scan: &[ScanPoint], n: usize) -> Vec<usize> {
    if scan.is_empty() {
        return Vec::new();
    }
    let g = SCAN_POINTS[n.clamp(1, 2) - 1] as isize;
    let at = |i: isize, j: isize| -> Option<usize> {
        (i >= 0 && i < g && j >= 0 && (j < g || n == 1) && (n == 2 || j == 0)).then(|| (i + g * j) as usize)
    };
    let mut seeds: Vec<usize> = (0..scan.len())
        .filter(|&p| {
            let c = scan[p].chi2;
            let Some(rp) = scan[p].r.as_ref().filter(|_| c.is_finite()) else {
                return false;
            };
            let (i, j) = ((p as isize) % g, (p as isize) / g);
            let mut lower_than_one = false; // … and apart from one by an uncertainty
            for dj in -1..=1isize {
                for di in -1..=1isize {
                    if (di, dj) == (0, 0) {
                        continue;
                    }
                    if let Some(q) = at(i + di, j + dj) {
                        let cq = scan[q].chi2;
                        if cq < c {
                            return false;
                        }
                        if scan[q].r.as_ref().is_some_and(|rq| (rq - rp).norm() >= 1.0) {
                            lower_than_one = true;
                        }
                    }
                }
            }
            lower_than_one
        })
        .collect();
    seeds.sort_by(|&a, &b| scan[a].chi2.total_cmp(&scan[b].chi2));
    seeds.truncate(MAX_SEEDS);
    seeds
}

/// The most restarts the scan seeds.
const MAX_SEEDS: usize = 6;

/// The two ends of the box [a, b] in t along the line t + λ·dir (λ < 0 and λ > 0), or None for a zero
/// direction.
fn across_box(t: &[f64], dir: &[f64], free: &[FreeParameter]) -> Option<(Vec<f64>, Vec<f64>)> {
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    for (k, p) in free.iter().enumerate() {
        let (a, b) = p.t_bounds();
        if dir[k].abs() < 1e-300 {
            continue;
        }
        let (l1, l2) = ((a - t[k]) / dir[k], (b - t[k]) / dir[k]);
        lo = lo.max(l1.min(l2));
        hi = hi.min(l1.max(l2));
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let point = |l: f64| -> Vec<f64> {
        free.iter().enumerate().map(|(k, p)| (t[k] + l * dir[k]).clamp(p.t_bounds().0, p.t_bounds().1)).collect()
    };
    Some((point(lo), point(hi)))
}

/// One solver run from a start: where it ended, and whether and why it stopped.
struct Solved<'a> {
    problem: Problem<'a>,
    converged: bool,
    termination: String,
}

impl Solved<'_> {
    fn chi2(&self) -> Option<f64> {
        self.problem.current.as_ref().ok().map(|c| self.problem.weighted(&c.predictions).norm_squared())
    }
}

/// Run the solver from the problem's start (MINPACK tolerances of docs/inverse.md §Method, "Solver").
fn solve(problem: Problem<'_>, patience: usize) -> Solved<'_> {
    let (problem, report) = LevenbergMarquardt::new()
        .with_ftol(1e-12)
        .with_xtol(1e-10)
        .with_gtol(1e-12)
        .with_patience(patience)
        .minimize(problem);
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
    Solved { problem, converged, termination }
}

/// What was read where, for the reach of a target: the scan's points and the solver's ends.
struct Reached<'r, 'a> {
    scan: &'r [ScanPoint],
    ends: &'r [Solved<'a>],
    free: &'r [FreeParameter],
    x_of_t: &'r dyn Fn(&[f64]) -> Vec<f64>,
    u_sigma: &'r [f64],
}

/// The verdict of a fit whose χ² the model cannot make probable (docs/inverse.md §Goodness of fit, §Reach):
/// χ², the degrees of freedom and p; the targets with the largest residuals; and, for each of those, whether
/// it lies beyond everything the model read at the points tried (the scan of the bounds, the solver's ends):
/// the extremum reached, where, and by how many uncertainties it misses.
fn cannot_reproduce(
    targets: &[FittedTarget],
    chi2: f64,
    dof: usize,
    p_value: Option<f64>,
    reached: &Reached,
) -> Vec<String> {
    let mut out = Vec::new();
    let mut worst: Vec<usize> = (0..targets.len()).filter(|&i| targets[i].weighted_residual.abs() > 1.0).collect();
    worst.sort_by(|&a, &b| targets[b].weighted_residual.abs().total_cmp(&targets[a].weighted_residual.abs()));
    worst.truncate(3);
    let named: Vec<String> = worst
        .iter()
        .map(|&i| {
            let t = &targets[i];
            format!(
                "{}/{} = {} ± {} predicted {:.4} ({:+.1} uncertainties)",
                t.target.geometry, t.target.name, t.target.value, t.uncertainty, t.predicted, t.weighted_residual
            )
        })
        .collect();
    let how = match p_value {
        Some(p) => format!("χ² = {chi2:.4} for {dof} degree(s) of freedom, p = {p:.2e} < {}", goodness::P_THRESHOLD),
        None => format!(
            "the fit is exactly determined (no degrees of freedom) and still misses a target by more than its \
             uncertainty (χ² = {chi2:.4})"
        ),
    };
    out.push(format!(
        "the model cannot reproduce these readings: {how}; largest residuals: {}",
        if named.is_empty() { "none above one uncertainty".to_string() } else { named.join(", ") }
    ));
    // Every prediction of target i that was computed: the scan's points and the solver's ends, with their t.
    for &i in &worst {
        let mut seen: Vec<(f64, Vec<f64>)> = Vec::new();
        for s in reached.scan {
            if let Some(p) = &s.pred {
                seen.push((p[i].0, s.t.clone()));
            }
        }
        for e in reached.ends {
            if let Ok(c) = &e.problem.current {
                seen.push((c.predictions[i].0, e.problem.t_of_u(&e.problem.u)));
            }
        }
        let Some(hi) = seen.iter().max_by(|a, b| a.0.total_cmp(&b.0)) else { continue };
        let Some(lo) = seen.iter().min_by(|a, b| a.0.total_cmp(&b.0)) else { continue };
        let t = &targets[i];
        let sigma = reached.u_sigma[i].hypot(t.prediction_error);
        let where_ = if reached.scan.is_empty() {
            "at the points tried (the fit and its restarts)".to_string()
        } else {
            format!("over a scan of the bounds ({} points) and the fits", reached.scan.len())
        };
        let (extreme, side, word) = if t.target.value > hi.0 {
            (hi, (t.target.value - hi.0) / sigma, "largest")
        } else if t.target.value < lo.0 {
            (lo, (lo.0 - t.target.value) / sigma, "smallest")
        } else {
            if !reached.scan.is_empty() {
                out.push(format!(
                    "{}/{} = {} alone is within the model's reach ({where_} it reads {:.4} to {:.4}), but not together \
                     with the other targets",
                    t.target.geometry, t.target.name, t.target.value, lo.0, hi.0
                ));
            }
            continue;
        };
        if side <= 1.0 {
            continue;
        }
        out.push(format!(
            "{}/{} = {} ± {} is beyond the model's reach {where_}: its {word} reading there is {:.4}, at {}, {:.1} \
             uncertainties short",
            t.target.geometry,
            t.target.name,
            t.target.value,
            t.uncertainty,
            extreme.0,
            describe_point(reached.free, &(reached.x_of_t)(&extreme.1)),
            side
        ));
    }
    out
}
