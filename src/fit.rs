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
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt, TerminationReason};
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use serde_json::Value;

use crate::brdf::Brdf;
use crate::instrument::plan::{Plan, PlanOptions, Planner, Reading};
use crate::instrument::standards::StandardGeometry;
use crate::registry;
use crate::{recipe, Error, Result};

/// Uncertainty of a target given without one, in the reading's unit: the 0.2 GU repeatability that
/// `docs/inverse.md` assumes for a glossmeter (issue 11's example), used for haze and DOI units alike.
pub const DEFAULT_UNCERTAINTY: f64 = 0.2;

/// The largest Gauss–Newton step, in standard uncertainties of the targets, that may remain at a fit called
/// converged (an independent check of the solver's own stopping rule; see [`fit`]).
pub const STEP_TOLERANCE: f64 = 0.01;

/// A free parameter: a JSON Pointer into the recipe, bounds, and whether its logarithm is fitted.
#[derive(Clone, Debug, PartialEq)]
pub struct FreeParameter {
    pub pointer: String,
    pub lower: f64,
    pub upper: f64,
    pub log: bool,
}

impl FreeParameter {
    /// Parse `PATH=LO..HI` or `PATH=log:LO..HI` (the `--free` argument).
    pub fn parse(arg: &str) -> Result<FreeParameter> {
        let bad = |m: String| Error::Usage(format!("--free {arg}: {m}"));
        let (pointer, bounds) = arg
            .split_once('=')
            .ok_or_else(|| bad("expected PATH=LO..HI (or PATH=log:LO..HI), e.g. /roughness=log:1e-3..0.5".into()))?;
        if !pointer.starts_with('/') {
            return Err(bad(format!("{pointer:?} is not a JSON Pointer (RFC 6901); it starts with '/'")));
        }
        let (log, range) = match bounds.strip_prefix("log:") {
            Some(r) => (true, r),
            None => (false, bounds),
        };
        let (lo, hi) = range.split_once("..").ok_or_else(|| bad(format!("bounds {bounds:?} are not LO..HI")))?;
        let num = |s: &str, what: &str| -> Result<f64> {
            s.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad(format!("{what} bound {s:?} is not a finite number")))
        };
        let (lower, upper) = (num(lo, "lower")?, num(hi, "upper")?);
        if lower >= upper {
            return Err(bad(format!("the lower bound {lower} must be below the upper bound {upper} (LO < HI)")));
        }
        if log && lower <= 0.0 {
            return Err(bad(format!("log: bounds must be positive, got {lower}..{upper}")));
        }
        Ok(FreeParameter { pointer: pointer.to_string(), lower, upper, log })
    }

    /// The fitted variable t of a value x (x or ln x).
    fn t_of_x(&self, x: f64) -> f64 {
        if self.log {
            x.ln()
        } else {
            x
        }
    }

    fn x_of(&self, t: f64) -> f64 {
        if self.log {
            t.exp()
        } else {
            t
        }
    }

    /// Bounds in t.
    fn t_bounds(&self) -> (f64, f64) {
        (self.t_of_x(self.lower), self.t_of_x(self.upper))
    }
}

/// A target: a reading of a geometry with its measured value and (optional) uncertainty.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetReading {
    pub geometry: String,
    /// A reading name (`gloss`, `haze-narrow`, `doi`, …) or quantity, as `compare` matches them.
    pub name: String,
    pub value: f64,
    pub uncertainty: Option<f64>,
}

impl TargetReading {
    /// Parse `GEOMETRY/READING=VALUE`, `…=VALUE±U` or `…=VALUE+-U` (the `--target` argument).
    pub fn parse(arg: &str) -> Result<TargetReading> {
        let bad = |m: String| Error::Usage(format!("--target {arg}: {m}"));
        let (left, right) = arg
            .split_once('=')
            .ok_or_else(|| bad("expected GEOMETRY/READING=VALUE[±U], e.g. astm-d523-60/gloss=85±0.5".into()))?;
        let (geometry, name) = left
            .split_once('/')
            .ok_or_else(|| bad(format!("{left:?} is not GEOMETRY/READING (e.g. astm-d523-20/gloss)")))?;
        if geometry.is_empty() || name.is_empty() {
            return Err(bad("the geometry and the reading must both be given".into()));
        }
        let (v, u) = match right.split_once('±').or_else(|| right.split_once("+-")) {
            Some((v, u)) => (v, Some(u)),
            None => (right, None),
        };
        let value = v
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| bad(format!("value {v:?} is not a finite number")))?;
        let uncertainty = match u {
            None => None,
            Some(u) => Some(
                u.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite() && *x > 0.0)
                    .ok_or_else(|| bad(format!("uncertainty {u:?} is not a finite number > 0")))?,
            ),
        };
        Ok(TargetReading { geometry: geometry.to_string(), name: name.to_string(), value, uncertainty })
    }
}

/// Targets from a parsed glossmeter sheet (`comparison::sheet`, every layout `compare` reads): the rows of one
/// sample (`sample`, or the sheet's only sample), grouped by reading as `compare` groups them
/// ([`crate::comparison::group_rows`]). A group's value is the mean x̄ of its n repeated readings and its
/// uncertainty is √(u² + s²/n), u the largest stated `uncertainty` of its rows (an allowance that averaging
/// does not reduce) and s/√n the standard error of the mean (n ≥ 2); a group with neither (one reading, no
/// stated uncertainty) gets `None`, the fit's default. Rows whose reading glossmeter does not predict (the
/// sheet reader marks them) are left out and named in the returned notes. A sample the sheet lacks, or a
/// sheet of several samples without `sample`, is a usage error naming `--sample`.
pub fn targets_from_sheet(
    sheet: &crate::comparison::sheet::Sheet,
    sample: Option<&str>,
) -> Result<(Vec<TargetReading>, Vec<String>)> {
    let mut samples: Vec<&str> = Vec::new();
    for r in &sheet.rows {
        if !samples.contains(&r.sample.as_str()) {
            samples.push(&r.sample);
        }
    }
    let chosen = match sample {
        Some(s) if samples.contains(&s) => s,
        Some(s) => {
            return Err(Error::Usage(format!(
                "--sample {s}: {} has no sample {s:?}; it has {}",
                sheet.file,
                samples.join(", ")
            )))
        }
        None if samples.len() == 1 => samples[0],
        None => {
            return Err(Error::Usage(format!(
                "--sheet {}: the sheet has {} samples ({}); choose one with --sample",
                sheet.file,
                samples.len(),
                samples.join(", ")
            )))
        }
    };
    let rows: Vec<_> = sheet.rows.iter().filter(|r| r.sample == chosen).cloned().collect();
    let mut targets = Vec::new();
    let mut notes = Vec::new();
    for g in crate::comparison::group_rows(&rows) {
        if let Some(why) = &g.not_predicted {
            notes.push(format!(
                "{} line {}: column {} is not a target: {why}",
                sheet.file,
                g.lines[0],
                g.columns.join(", ")
            ));
            continue;
        }
        let n = g.stats.n as f64;
        let sem2 = if g.stats.n > 1 { g.stats.std * g.stats.std / n } else { 0.0 };
        let u2 = g.uncertainty.map_or(0.0, |u| u * u);
        let combined = (u2 + sem2).sqrt();
        targets.push(TargetReading {
            geometry: g.geometry,
            name: g.reading,
            value: g.stats.mean,
            uncertainty: (combined > 0.0 && combined.is_finite()).then_some(combined),
        });
    }
    if targets.is_empty() {
        return Err(Error::Usage(format!(
            "--sheet {}: sample {chosen:?} has no reading glossmeter predicts, so no targets",
            sheet.file
        )));
    }
    Ok((targets, notes))
}

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

/// The forward model: recipe values → predictions (value, error) of the targets.
struct Forward<'a> {
    recipe: &'a Value,
    file: &'a str,
    free: &'a [FreeParameter],
    planner: Planner,
    geometries: Vec<StandardGeometry>,
    options: PlanOptions,
    /// Index of each target in the plan's readings.
    index: Vec<usize>,
    runs: std::cell::Cell<usize>,
}

/// How a forward run integrates.
enum Mode<'p> {
    /// Adaptively, keeping the final partitions: the solver's trial points and every Jacobian's centre.
    Freeze,
    /// On the centre's frozen methods (a Jacobian's displaced points). `None` from [`Forward::run`] when the
    /// material at the displaced point has another shape than the centre's (another kind of term), so the
    /// frozen methods do not apply to it.
    Frozen(&'p Plan),
}

/// Predictions (value, error estimate) of the targets, and the frozen plan of a `Mode::Freeze` run.
type Predictions = (Vec<(f64, f64)>, Option<Plan>);

impl Forward<'_> {
    fn recipe_at(&self, x: &[f64]) -> Value {
        let mut v = self.recipe.clone();
        for (p, xi) in self.free.iter().zip(x) {
            if let Some(slot) = v.pointer_mut(&p.pointer) {
                *slot = serde_json::json!(xi);
            }
        }
        v
    }

    fn material(&self, x: &[f64]) -> Result<Arc<dyn Brdf>> {
        let v = self.recipe_at(x);
        let text = v.to_string();
        Ok(recipe::parse_str(&text, self.file)?.brdf)
    }

    /// Predictions of the targets at x (see [`Mode`]); `Ok(None)` only for `Mode::Frozen` on a material of
    /// another shape.
    fn run(&self, x: &[f64], mode: Mode) -> Result<Option<Predictions>> {
        self.runs.set(self.runs.get() + 1);
        let brdf = self.material(x)?;
        let (readings, frozen): (Vec<Reading>, Option<Plan>) = match mode {
            Mode::Freeze => {
                let (r, p) = self.planner.compile(brdf, self.geometries.clone(), self.options.clone())?.freeze();
                (r, Some(p))
            }
            Mode::Frozen(plan) => match plan.with_material(brdf) {
                Ok(p) => (p.execute(), None),
                Err(_) => return Ok(None),
            },
        };
        let mut out = Vec::with_capacity(self.index.len());
        for &i in &self.index {
            let r = &readings[i];
            match r.value {
                Some(v) if v.is_finite() && r.error_estimate.is_finite() => out.push((v, r.error_estimate)),
                _ => {
                    return Err(Error::Numeric(format!(
                        "{}/{} has no finite value at {}: {}",
                        r.geometry,
                        r.name,
                        describe_point(self.free, x),
                        r.problem.clone().unwrap_or_default()
                    )))
                }
            }
        }
        Ok(Some((out, frozen)))
    }
}

fn describe_point(free: &[FreeParameter], x: &[f64]) -> String {
    free.iter().zip(x).map(|(p, v)| format!("{} = {v}", p.pointer)).collect::<Vec<_>>().join(", ")
}

/// The solver's current point: the predictions and the frozen plan of its adaptive run.
struct Current {
    predictions: Vec<(f64, f64)>,
    frozen: Plan,
}

/// The least-squares problem seen by the solver, in the unbounded variables u.
struct Problem<'a> {
    fwd: &'a Forward<'a>,
    targets: &'a [TargetReading],
    u_sigma: Vec<f64>,
    u: DVector<f64>,
    /// The current point (computed in `set_params`), or the error that prevented it.
    current: std::result::Result<Current, String>,
    last_error: std::cell::RefCell<Option<String>>,
}

impl Problem<'_> {
    fn t_of_u(&self, u: &DVector<f64>) -> Vec<f64> {
        self.fwd
            .free
            .iter()
            .zip(u.iter())
            .map(|(p, &ui)| {
                let (a, b) = p.t_bounds();
                a + (b - a) * 0.5 * (1.0 + ui.sin())
            })
            .collect()
    }

    fn x_of_t(&self, t: &[f64]) -> Vec<f64> {
        self.fwd.free.iter().zip(t).map(|(p, &ti)| p.x_of(ti).clamp(p.lower, p.upper)).collect()
    }

    fn sigma(&self, i: usize, e: f64) -> f64 {
        (self.u_sigma[i].powi(2) + e * e).sqrt()
    }

    fn weighted(&self, pred: &[(f64, f64)]) -> DVector<f64> {
        DVector::from_iterator(
            pred.len(),
            pred.iter().enumerate().map(|(i, &(v, e))| (v - self.targets[i].value) / self.sigma(i, e)),
        )
    }

    /// The weighted Jacobian in t (m × n) at t, whose adaptive run gave `centre` and `frozen`: central
    /// differences on the frozen methods, so that every displaced point of one Jacobian is integrated on the
    /// same partitions and the differences see the change of the material only, not a change of partition.
    /// The step balances the O(h²) truncation of a central difference against the O(ε/h) error of the
    /// readings, ε their largest relative error estimate: h = ε^{1/3}·scale. A displaced point outside the
    /// bounds, or whose material has another shape (the frozen methods do not apply), is replaced by the
    /// centre (a one-sided difference); a parameter with neither side usable is an error.
    fn jacobian_t(&self, t: &[f64], centre: &[(f64, f64)], frozen: &Plan) -> Result<DMatrix<f64>> {
        let m = centre.len();
        let n = t.len();
        let eps = centre.iter().map(|&(v, e)| e / v.abs().max(1e-300)).fold(1e-13, f64::max).min(1e-2);
        let mut j = DMatrix::zeros(m, n);
        for k in 0..n {
            let p = &self.fwd.free[k];
            let (a, b) = p.t_bounds();
            let scale = if p.log { 1.0 } else { t[k].abs().max(1e-3 * (b - a)) };
            let h = (eps.cbrt() * scale).clamp(1e-9 * (b - a), 0.05 * (b - a));
            let eval = |tk: f64| -> Result<Option<Vec<(f64, f64)>>> {
                if !(a..=b).contains(&tk) {
                    return Ok(None);
                }
                let mut tt = t.to_vec();
                tt[k] = tk;
                Ok(self.fwd.run(&self.x_of_t(&tt), Mode::Frozen(frozen))?.map(|r| r.0))
            };
            let (lo, hi) = (eval(t[k] - h)?, eval(t[k] + h)?);
            let (f_lo, t_lo, f_hi, t_hi) = match (lo, hi) {
                (Some(l), Some(u)) => (l, t[k] - h, u, t[k] + h),
                (Some(l), None) => (l, t[k] - h, centre.to_vec(), t[k]),
                (None, Some(u)) => (centre.to_vec(), t[k], u, t[k] + h),
                (None, None) => {
                    return Err(Error::Numeric(format!(
                        "{}: the Jacobian has no usable point on either side of {} (step {h:e} in the fitted \
                         variable): the material changes kind there",
                        p.pointer,
                        p.x_of(t[k])
                    )))
                }
            };
            for i in 0..m {
                let s = self.sigma(i, centre[i].1);
                j[(i, k)] = (f_hi[i].0 - f_lo[i].0) / (t_hi - t_lo) / s;
            }
        }
        Ok(j)
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, u: &DVector<f64>) {
        self.u.copy_from(u);
        let x = self.x_of_t(&self.t_of_u(u));
        self.current = match self.fwd.run(&x, Mode::Freeze) {
            Ok(Some((predictions, Some(frozen)))) => Ok(Current { predictions, frozen }),
            Ok(_) => Err("an adaptive run returned no frozen plan".into()),
            Err(e) => Err(e.to_string()),
        };
    }

    fn params(&self) -> DVector<f64> {
        self.u.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        match &self.current {
            Ok(c) => Some(self.weighted(&c.predictions)),
            Err(e) => {
                *self.last_error.borrow_mut() = Some(e.clone());
                None
            }
        }
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let c = self.current.as_ref().ok()?;
        let t = self.t_of_u(&self.u);
        match self.jacobian_t(&t, &c.predictions, &c.frozen) {
            Ok(jt) => {
                // Chain rule: dt/du = (b − a)/2 · cos u.
                let mut ju = jt;
                for (k, p) in self.fwd.free.iter().enumerate() {
                    let (a, b) = p.t_bounds();
                    let d = 0.5 * (b - a) * self.u[k].cos();
                    ju.column_mut(k).scale_mut(d);
                }
                Some(ju)
            }
            Err(e) => {
                *self.last_error.borrow_mut() = Some(e.to_string());
                None
            }
        }
    }
}

/// Check the free parameters against the recipe and the registry: an unknown or non-numeric path, bounds
/// outside the registry's range, a start outside its bounds are usage errors naming the argument.
fn check_free(recipe: &Value, free: &[FreeParameter]) -> Result<Vec<f64>> {
    let model = recipe.get("model").and_then(Value::as_str).unwrap_or("");
    let mut start = Vec::new();
    for (i, p) in free.iter().enumerate() {
        let arg = format!("--free {}", p.pointer);
        if free[..i].iter().any(|q| q.pointer == p.pointer) {
            return Err(Error::Usage(format!("{arg}: the same parameter is free twice")));
        }
        let entry = registry::lookup(model, &p.pointer).ok_or_else(|| {
            let numeric: Vec<&str> =
                registry::of_model(model).filter(|e| e.ty.is_numeric()).map(|e| e.pointer).collect();
            Error::Usage(format!(
                "{arg}: not a parameter of a {model:?} recipe; its numeric parameters are {}",
                numeric.join(", ")
            ))
        })?;
        let v = recipe.pointer(&p.pointer).ok_or_else(|| {
            Error::Usage(format!(
                "{arg}: the recipe has no value at {} (add it with a starting value: the fit starts from the recipe)",
                p.pointer
            ))
        })?;
        let x = v.as_f64().filter(|_| v.is_number()).ok_or_else(|| {
            Error::Usage(format!(
                "{arg}: the value at {} is {}, not a number; address one number (e.g. {}/0)",
                p.pointer,
                crate::input::json::kind(v),
                p.pointer
            ))
        })?;
        let r = entry.range.ok_or_else(|| Error::Usage(format!("{arg}: {} is not numeric", entry.pointer)))?;
        if !(r.contains(p.lower) || p.lower == r.lo) || !(r.contains(p.upper) || p.upper == r.hi) {
            return Err(Error::Usage(format!(
                "{arg}: bounds {}..{} leave the allowed range of {} ({}: {})",
                p.lower,
                p.upper,
                entry.pointer,
                r.describe(),
                entry.description
            )));
        }
        if !(x > p.lower && x < p.upper) {
            return Err(Error::Usage(format!(
                "{arg}: the start (the recipe's value {x}) is outside the bounds; it must lie strictly between {} and {}",
                p.lower, p.upper
            )));
        }
        start.push(x);
    }
    Ok(start)
}

/// Fit the free parameters of `recipe` (the JSON of a recipe file named `file`) to the targets.
/// Bad arguments (paths, bounds, starts, targets, counts) are `Error::Usage` naming the argument; a fit
/// that runs returns its report whatever its outcome (see [`FitReport::ok`]).
pub fn fit(
    recipe_json: &Value,
    file: &str,
    free: &[FreeParameter],
    targets: &[TargetReading],
    options: &FitOptions,
) -> Result<FitReport> {
    let clock = Instant::now();
    if targets.is_empty() {
        return Err(Error::Usage("no targets: give --target GEOMETRY/READING=VALUE[±U] or --sheet".into()));
    }
    if free.is_empty() {
        return Err(Error::Usage("no free parameters: give --free PATH=LO..HI".into()));
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
        .map(|id| planner.geometry(id).map_err(|e| Error::Usage(format!("--target {id:?}: {e}"))))
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
                Error::Usage(format!(
                    "--target {:?}: geometry {:?} has no reading {:?}; its readings are {}",
                    format!("{}/{}", t.geometry, t.name),
                    t.geometry,
                    t.name,
                    has.join(", ")
                ))
            })?;
        index.push(i);
    }
    let mut seen: HashMap<usize, usize> = HashMap::new();
    for (k, i) in index.iter().enumerate() {
        if let Some(prev) = seen.insert(*i, k) {
            return Err(Error::Usage(format!(
                "--target {:?}: the same reading is targeted twice (also target {})",
                format!("{}/{}", targets[k].geometry, targets[k].name),
                prev + 1
            )));
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
