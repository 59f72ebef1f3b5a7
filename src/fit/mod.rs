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
//! The folder, one stage a file, in the order [`fit`] runs them:
//! * `targets.rs`: target matching (the request's counts, each target's geometry and reading);
//! * `problem.rs`: the forward model (recipe values → predictions, on adaptive or frozen methods) and the
//!   least-squares problem the solver sees, with its Jacobian;
//! * `search.rs`: the solver's runs, the scan of the bounds, the restarts ([`restart_fractions`]) and the
//!   choice of the fit among their ends;
//! * `analysis.rs`: the error analysis (SVD, covariance, standard errors, correlations) and the remaining
//!   Gauss–Newton step that checks the solver's stop;
//! * `linearity.rs`: the check of the linear error analysis one standard error out;
//! * `classify.rs`: where each restart ended (same, another solution, plateau, worse) and the uniqueness line;
//! * `reach.rs`: the weak directions (undetermined or stationary) and the targets beyond the model's reach;
//! * `goodness.rs`: the goodness of fit, the chi-square survival function from the regularized incomplete
//!   gamma function, and the threshold below which the model cannot reproduce the readings;
//! * `report.rs`: the result ([`FitReport`], [`FittedParameter`], [`FittedTarget`]) and the verdict;
//! * `params.rs`: what is fitted to what: [`FreeParameter`], [`TargetReading`], [`targets_from_sheet`], and
//!   the check of the free parameters against the recipe and the registry;
//! * `options.rs`: the options ([`FitOptions`]) and their defaults;
//! * `mod.rs`: [`fit`], the stages in order.
mod analysis;
mod classify;
mod goodness;
mod linearity;
mod options;
mod params;
mod problem;
mod reach;
mod report;
mod search;
mod targets;

pub use goodness::{chi2_survival, gamma_q, P_THRESHOLD};
pub use options::FitOptions;
pub(crate) use options::{DEFAULT_RESTARTS, DEFAULT_UNCERTAINTY};
pub use params::{targets_from_sheet, FreeParameter, TargetReading};
pub use report::FitReport;
pub use search::restart_fractions;

use std::time::Instant;

use nalgebra::DVector;
use serde_json::Value;

use crate::instrument::plan::{PlanOptions, Planner};
use crate::{recipe, Error, Result};
use params::check_free;
use problem::{describe_point, u_of_t, Forward, Mode, Problem};

/// The largest Gauss–Newton step, in standard uncertainties of the targets, that may remain at a fit called
/// converged (an independent check of the solver's own stopping rule; see [`fit`]).
pub(crate) const STEP_TOLERANCE: f64 = 0.01;

/// Fit the free parameters of `recipe` (the JSON of a recipe file named `file`) to the targets.
/// Bad arguments (paths, bounds, starts, targets, counts) are usage errors, [`Error::Argument`] where they
/// name the argument (`free`, `target`, `sheet`); a fit that runs returns its report whatever its outcome
/// (see [`FitReport::ok`]).
///
/// The stages: target matching, the search (solver, scan, restarts), the error analysis at the fit and the
/// check of the solver's stop, the linearity check, the classification of the restarts' ends, the reach of
/// the weak directions and of the targets, and the report with its verdict.
pub fn fit(
    recipe_json: &Value,
    file: &str,
    free: &[FreeParameter],
    targets: &[TargetReading],
    options: &FitOptions,
) -> Result<FitReport> {
    let clock = Instant::now();
    let (fwd, start) = forward(recipe_json, file, free, targets, options)?;
    let (n, m) = (free.len(), targets.len());
    let u_sigma: Vec<f64> = targets.iter().map(|t| t.uncertainty.unwrap_or(options.default_uncertainty)).collect();
    let bounds: Vec<(f64, f64)> = free.iter().map(|p| p.t_bounds()).collect();
    let widths: Vec<f64> = bounds.iter().map(|(a, b)| b - a).collect();
    let u0 = DVector::from_iterator(n, free.iter().zip(&start).map(|(p, &x)| u_of_t(p.t_of_x(x), p.t_bounds())));
    let first = Problem::new(&fwd, targets, &u_sigma, &u0);
    if let Err(e) = &first.current {
        return Err(Error::Numeric(format!("the start does not evaluate: {e}")));
    }
    let budget = search::Budget { max_iterations: options.max_iterations, restarts: options.restarts };
    let found = search::search(first, &budget);
    let problem = &found.ends[found.chosen].problem;

    // The error analysis at the final point: Jacobian in t (on the frozen methods of its adaptive run),
    // covariance, SVD. `current` always belongs to `u` (both are set together in `set_params`), and the
    // solver's final point is one it accepted, so it evaluates.
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
    let analysis = analysis::analyse(&jt, chi2, &widths);
    let at_bound = analysis::at_bounds(&t, &bounds, &widths);
    let (converged, termination) =
        stop_checked(&found.ends[found.chosen], analysis::remaining_step(&analysis.scaled, &r, &at_bound));

    // Every later stage reads the model through this: the weighted residuals of an adaptive run at t.
    let residuals_at = |tt: &[f64]| match fwd.run(&problem.x_of_t(tt), Mode::Freeze) {
        Ok(Some((pred, _))) => Some(problem.weighted(&pred)),
        _ => None,
    };
    let runs_before_linearity = fwd.runs();
    let pointers: Vec<&str> = free.iter().map(|p| p.pointer.as_str()).collect();
    let at = linearity::At { t: &t, r: &r, jt: &jt, bounds: &bounds, widths: &widths, names: &pointers };
    let nonlinear = linearity::check(&analysis, &at, residuals_at);
    let linearity_evaluations = fwd.runs() - runs_before_linearity;

    let runs_before_classify = fwd.runs();
    let ends: Vec<classify::End> = found
        .ends
        .iter()
        .map(|e| classify::End {
            t: e.problem.t_of_u(&e.problem.u),
            r: e.problem.current.as_ref().ok().map(|c| e.problem.weighted(&c.predictions)),
        })
        .collect();
    let against = classify::Fit { t: &t, chi2, std_t: &analysis.std_t, bounds: &bounds, widths: &widths };
    let classes = classify::classify(&ends, found.chosen, &against, residuals_at);
    let restart_evaluations = found.restart_evaluations + (fwd.runs() - runs_before_classify);
    let others: Vec<String> = classes
        .others
        .iter()
        .map(|(t_j, chi2_j)| format!("{} (χ² = {chi2_j:.3})", describe_point(free, &problem.x_of_t(t_j))))
        .collect();
    let failed = found.failed + classes.failed;
    let restarts = classify::Restarts {
        m,
        n,
        asked: options.restarts,
        run: found.ends.len() - 1 + failed,
        failed,
        scan_points: found.scan.len(),
        seeds: found.seeds.len(),
        halton: found.halton,
        chosen_restart: found.chosen != 0,
    };
    let uniqueness = classify::uniqueness(&restarts, &classes, &others);
    let weak = reach::weak_directions(&analysis.directions, &t, &r, free, !others.is_empty(), residuals_at);

    // The report: goodness of fit and reach first (a model that cannot reproduce the readings makes
    // everything else moot), then what the other stages found.
    let fitted_targets = report::fitted_targets(targets, &fwd.colour, &u_sigma, &centre, &r);
    let cannot_reproduce = if reproduces {
        Vec::new()
    } else {
        let seen = seen_points(&found);
        let describe = |t: &[f64]| describe_point(free, &problem.x_of_t(t));
        reach::cannot_reproduce(&fitted_targets, (chi2, dof, p_value), &seen, found.scan.len(), &describe)
    };
    let chosen_restart = (found.chosen != 0).then(|| restart_chosen(&found, free, chi2));
    let parameters = report::fitted_parameters(free, &x, (&analysis.std_t, &analysis.std_t_unscaled), &at_bound, &jt);
    let findings = report::Findings {
        cannot_reproduce,
        chosen_restart,
        weak: weak.lines,
        weak_undetermined: weak.undetermined,
        nonlinear,
        second_solution: !others.is_empty(),
        uniqueness,
        dead: dead.iter().map(|&k| (free[k].pointer.clone(), x[k])).collect(),
        refused: found.ends.iter().map(|e| e.problem.refused.get()).sum(),
        not_converged: (!converged).then(|| termination.clone()),
    };
    let (verdict, identifiable) = report::verdict(findings, &parameters, &analysis.correlation);
    Ok(FitReport {
        parameters,
        targets: fitted_targets,
        converged,
        termination,
        identifiable,
        stationary: weak.stationary,
        singular_values: analysis.singular_values(),
        correlation: analysis.correlation,
        verdict,
        chi2,
        dof,
        p_value,
        reproduces,
        error_scale: analysis.s2.sqrt(),
        evaluations: fwd.runs(),
        linearity_evaluations,
        restart_evaluations,
        scan_evaluations: found.scan_evaluations,
        seconds: clock.elapsed().as_secs_f64(),
        recipe: fwd.recipe_at(&x),
    })
}

/// Target matching: the request checked, the recipe loaded, each target's geometry found and matched to a
/// reading of the plan; the forward model of the fit and the start (the recipe's values of the free
/// parameters).
fn forward<'a>(
    recipe_json: &'a Value,
    file: &'a str,
    free: &'a [FreeParameter],
    targets: &[TargetReading],
    options: &FitOptions,
) -> Result<(Forward<'a>, Vec<f64>)> {
    targets::check_counts(free, targets, options)?;
    // The recipe must load as it is.
    recipe::parse_str(&recipe_json.to_string(), file)?;
    let start = check_free(recipe_json, free)?;
    let planner = Planner::new()?;
    let geometries = targets::geometries(&planner, targets, &options.geometries)?;
    let plan_options = PlanOptions {
        rtol: options.rtol,
        max_evals: options.max_evals,
        colour: options.colour,
        cancel: options.cancel.clone(),
        ..PlanOptions::default()
    };
    // Match every target to a reading of the plan.
    let probe = planner.compile(
        recipe::parse_str(&recipe_json.to_string(), file)?.brdf,
        geometries.clone(),
        plan_options.clone(),
    )?;
    let reported: Vec<_> = probe.readings.iter().filter(|r| r.reported).collect();
    let names: Vec<targets::ReadingName> =
        reported.iter().map(|r| (r.geometry.clone(), r.name.clone(), r.spec.quantity().to_string())).collect();
    let index = targets::match_targets(&names, targets)?;
    let colour = index.iter().map(|&i| reported[i].kind.conditions()).collect();
    let scan_options = PlanOptions { rtol: options.rtol.max(search::SCAN_RTOL), ..plan_options.clone() };
    let fwd = Forward {
        recipe: recipe_json,
        file,
        free,
        planner,
        geometries,
        options: plan_options,
        scan_options,
        index,
        colour,
        runs: Default::default(),
    };
    Ok((fwd, start))
}

/// The solver's own stop, checked independently: a fit called converged that leaves a Gauss–Newton step of
/// more than [`STEP_TOLERANCE`] standard uncertainties (`remaining`, from [`analysis::remaining_step`]) did
/// not converge.
fn stop_checked(end: &search::Solved, remaining: f64) -> (bool, String) {
    let termination = end.termination.clone();
    if end.converged && remaining > STEP_TOLERANCE {
        (
            false,
            format!(
                "did not converge: the solver stopped ({termination}) a Gauss–Newton step of {remaining:.3} standard \
                 uncertainties from the optimum (at most {STEP_TOLERANCE} is accepted)"
            ),
        )
    } else {
        (end.converged, termination)
    }
}

/// The verdict's line when a restart's end is the fit: where the solver from the recipe's start stopped.
fn restart_chosen(found: &search::Search, free: &[FreeParameter], chi2: f64) -> String {
    let e0 = &found.ends[0].problem;
    format!(
        "the solver from the recipe's start stopped at χ² = {:.4} ({}); a restart reached χ² = {chi2:.4}, and that \
         is the fit reported",
        found.ends[0].chi2().unwrap_or(f64::INFINITY),
        describe_point(free, &e0.x_of_t(&e0.t_of_u(&e0.u))),
    )
}

/// Every point where the targets were read, for their reach: the scan's points that evaluate, then the
/// solver's ends that do.
fn seen_points(found: &search::Search) -> Vec<reach::Seen> {
    let scan = found.scan.iter().filter_map(|s| {
        s.pred.as_ref().map(|p| reach::Seen { t: s.t.clone(), values: p.iter().map(|v| v.0).collect() })
    });
    let ends = found.ends.iter().filter_map(|e| {
        e.problem.current.as_ref().ok().map(|c| reach::Seen {
            t: e.problem.t_of_u(&e.problem.u),
            values: c.predictions.iter().map(|v| v.0).collect(),
        })
    });
    scan.chain(ends).collect()
}
