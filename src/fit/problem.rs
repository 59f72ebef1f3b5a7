//! The forward model and the least-squares problem: recipe values → predictions of the targets (adaptively,
//! keeping the final partitions, or on a Jacobian centre's frozen methods), and the weighted residuals and
//! Jacobian that the Levenberg–Marquardt solver sees in the unbounded variables u.
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use levenberg_marquardt::LeastSquaresProblem;
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use rayon::prelude::*;
use serde_json::Value;

use super::params::{FreeParameter, TargetReading};
use crate::brdf::Brdf;
use crate::colorimetry::Conditions;
use crate::instrument::plan::{Plan, PlanOptions, Planner, Reading};
use crate::instrument::standards::StandardGeometry;
use crate::{recipe, Error, Result};

/// The forward model: recipe values → predictions (value, error) of the targets.
pub(super) struct Forward<'a> {
    pub(super) recipe: &'a Value,
    pub(super) file: &'a str,
    pub(super) free: &'a [FreeParameter],
    pub(super) planner: Planner,
    pub(super) geometries: Vec<StandardGeometry>,
    pub(super) options: PlanOptions,
    /// The options of the scan's runs ([`Mode::Scan`]): the fit's, at a looser tolerance.
    pub(super) scan_options: PlanOptions,
    /// Index of each target in the plan's readings.
    pub(super) index: Vec<usize>,
    /// Each target's colour conditions (its reading's, docs/colour.md); None for a target that is no colour.
    pub(super) colour: Vec<Option<Conditions>>,
    /// Forward runs so far (counted from every thread; runs that do not depend on each other run in parallel,
    /// docs/inverse.md §Method, "Parallel runs").
    pub(super) runs: AtomicUsize,
}

/// How a forward run integrates.
pub(super) enum Mode<'p> {
    /// Adaptively, keeping the final partitions: the solver's trial points and every Jacobian's centre.
    Freeze,
    /// On the centre's frozen methods (a Jacobian's displaced points). `None` from [`Forward::run`] when the
    /// material at the displaced point has another shape than the centre's (another kind of term), so the
    /// frozen methods do not apply to it.
    Frozen(&'p Plan),
    /// Adaptively at the scan's loose tolerance (`Forward::scan_options`), keeping nothing: the coarse scan of
    /// the bounds that seeds the restarts (docs/inverse.md §Every root).
    Scan,
}

/// Predictions (value, error estimate) of the targets, and the frozen plan of a `Mode::Freeze` run.
pub(super) type Predictions = (Vec<(f64, f64)>, Option<Plan>);

impl Forward<'_> {
    /// Forward runs so far.
    pub(super) fn runs(&self) -> usize {
        self.runs.load(Ordering::Relaxed)
    }

    /// x of t, each clamped to its bounds (the same as [`Problem::x_of_t`]).
    pub(super) fn x_of_t(&self, t: &[f64]) -> Vec<f64> {
        self.free.iter().zip(t).map(|(p, &ti)| p.x_of(ti).clamp(p.lower, p.upper)).collect()
    }

    pub(super) fn recipe_at(&self, x: &[f64]) -> Value {
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
    pub(super) fn run(&self, x: &[f64], mode: Mode) -> Result<Option<Predictions>> {
        self.runs.fetch_add(1, Ordering::Relaxed);
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
            Mode::Scan => {
                (self.planner.compile(brdf, self.geometries.clone(), self.scan_options.clone())?.execute(), None)
            }
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

/// The weighted residuals (v − target)/√(u² + e²) of predictions (v, e) against the targets, u their
/// uncertainties.
pub(super) fn weighted(targets: &[TargetReading], u_sigma: &[f64], pred: &[(f64, f64)]) -> DVector<f64> {
    DVector::from_iterator(
        pred.len(),
        pred.iter().enumerate().map(|(i, &(v, e))| (v - targets[i].value) / (u_sigma[i].powi(2) + e * e).sqrt()),
    )
}

pub(super) fn describe_point(free: &[FreeParameter], x: &[f64]) -> String {
    free.iter().zip(x).map(|(p, v)| format!("{} = {v}", p.pointer)).collect::<Vec<_>>().join(", ")
}

/// The solver's current point: the predictions and the frozen plan of its adaptive run.
pub(super) struct Current {
    pub(super) predictions: Vec<(f64, f64)>,
    pub(super) frozen: Plan,
}

/// The least-squares problem seen by the solver, in the unbounded variables u.
pub(super) struct Problem<'a> {
    pub(super) fwd: &'a Forward<'a>,
    pub(super) targets: &'a [TargetReading],
    pub(super) u_sigma: Vec<f64>,
    pub(super) u: DVector<f64>,
    /// The current point (computed in `set_params`), or the error that prevented it.
    pub(super) current: std::result::Result<Current, String>,
    pub(super) last_error: std::cell::RefCell<Option<String>>,
    /// Trial points refused because the recipe does not evaluate there (outside the model's constraints).
    pub(super) refused: std::cell::Cell<usize>,
}

/// The origin of the solver's variable u: t = a + (b − a)(1 + sin u)/2 maps u = U_ORIGIN + asin(2(t − a)/(b − a)
/// − 1) to t. MINPACK's first trust region and its xtol test are relative to the scaled norm ‖D u‖, which is
/// zero at u = 0; with the sine's own origin the midpoint of every bound (u = 0) would be a start that never
/// moves. Shifting u by a whole period, 2π, changes no t and keeps ‖D u‖ ≥ (3π/2)·‖D‖ for every start
/// (docs/inverse.md §Method, "Variables").
pub(super) const U_ORIGIN: f64 = 2.0 * std::f64::consts::PI;

/// The solver's variable u of a fitted value t in the bounds [a, b] of t.
pub(super) fn u_of_t(t: f64, (a, b): (f64, f64)) -> f64 {
    U_ORIGIN + (2.0 * (t - a) / (b - a) - 1.0).clamp(-1.0, 1.0).asin()
}

/// A residual of this size (in uncertainties) stands for a trial point outside the model's constraints: a
/// barrier. It is finite, and ten times any residual norm a point inside could have is below it, so the
/// Levenberg–Marquardt step is refused (its actual reduction is −1) and the trust region shrinks, which keeps
/// the search inside the constraints without ever ending it (docs/inverse.md §Constraints).
const BARRIER: f64 = 1e100;

/// A point whose χ² is at most this (every residual within 10⁻³ of its uncertainty, as a whole) is an exact
/// fit for the solver: its residuals are handed to it as zero, so it stops there (an exact fit).
/// The Gauss–Newton step that remains from such a point is at most ‖r‖ = 10⁻³ uncertainties, a tenth of what
/// the fit's own check of a converged stop accepts (`STEP_TOLERANCE`); polishing further only follows the
/// forward model's noise, and along a direction the targets barely see (a curved valley of exact fits) it
/// used to spend the whole budget (docs/inverse.md §Method, "Solver"). The report's residuals and χ² are
/// always the point's own.
pub(super) const EXACT_CHI2: f64 = 1e-6;

impl Problem<'_> {
    /// The problem at the start u0 (its point evaluated; see `current`).
    pub(super) fn new<'a>(
        fwd: &'a Forward<'a>,
        targets: &'a [TargetReading],
        u_sigma: &[f64],
        u0: &DVector<f64>,
    ) -> Problem<'a> {
        let mut p = Problem {
            fwd,
            targets,
            u_sigma: u_sigma.to_vec(),
            u: u0.clone(),
            current: Err(String::new()),
            last_error: std::cell::RefCell::new(None),
            refused: std::cell::Cell::new(0),
        };
        p.set_params(u0);
        p
    }

    pub(super) fn t_of_u(&self, u: &DVector<f64>) -> Vec<f64> {
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

    pub(super) fn x_of_t(&self, t: &[f64]) -> Vec<f64> {
        self.fwd.x_of_t(t)
    }

    fn sigma(&self, i: usize, e: f64) -> f64 {
        (self.u_sigma[i].powi(2) + e * e).sqrt()
    }

    pub(super) fn weighted(&self, pred: &[(f64, f64)]) -> DVector<f64> {
        weighted(self.targets, &self.u_sigma, pred)
    }

    /// The weighted Jacobian in t (m × n) at t, whose adaptive run gave `centre` and `frozen`: central
    /// differences on the frozen methods, so that every displaced point of one Jacobian is integrated on the
    /// same partitions and the differences see the change of the material only, not a change of partition.
    /// The step balances the O(h²) truncation of a central difference against the O(ε/h) error of the
    /// readings, ε their largest relative error estimate: h = ε^{1/3}·scale. A displaced point outside the
    /// bounds, or whose material has another shape (the frozen methods do not apply), is replaced by the
    /// centre (a one-sided difference), and so is one that does not evaluate (outside the model's constraints,
    /// Kd + ΣKs ≤ 1 and the like); a parameter with neither side usable gets a zero column and is listed in the
    /// second value (docs/inverse.md §Method, "Jacobian").
    pub(super) fn jacobian_t(&self, t: &[f64], centre: &[(f64, f64)], frozen: &Plan) -> (DMatrix<f64>, Vec<usize>) {
        let m = centre.len();
        let n = t.len();
        let eps = centre.iter().map(|&(v, e)| e / v.abs().max(1e-300)).fold(1e-13, f64::max).min(1e-2);
        let fwd = self.fwd;
        // The steps, and the 2n displaced points in t (None outside the bounds), k-th column's lower then upper.
        let steps: Vec<f64> = (0..n)
            .map(|k| {
                let p = &fwd.free[k];
                let (a, b) = p.t_bounds();
                let scale = if p.log { 1.0 } else { t[k].abs().max(1e-3 * (b - a)) };
                (eps.cbrt() * scale).clamp(1e-9 * (b - a), 0.05 * (b - a))
            })
            .collect();
        let points: Vec<Option<Vec<f64>>> = (0..2 * n)
            .map(|i| {
                let (k, sign) = (i / 2, if i % 2 == 0 { -1.0 } else { 1.0 });
                let tk = t[k] + sign * steps[k];
                let (a, b) = fwd.free[k].t_bounds();
                (a..=b).contains(&tk).then(|| {
                    let mut tt = t.to_vec();
                    tt[k] = tk;
                    tt
                })
            })
            .collect();
        // The displaced points do not depend on each other: they run in parallel, each on the same frozen
        // methods, and land in their own slot, so the Jacobian is the same bits for any number of threads.
        let runs: Vec<Option<Vec<(f64, f64)>>> = points
            .par_iter()
            .map(|tt| {
                let tt = tt.as_ref()?;
                fwd.run(&fwd.x_of_t(tt), Mode::Frozen(frozen)).ok().flatten().map(|r| r.0)
            })
            .collect();
        let mut runs = runs.into_iter();
        let mut j = DMatrix::zeros(m, n);
        let mut dead = Vec::new();
        for k in 0..n {
            let h = steps[k];
            let (lo, hi) = (runs.next().flatten(), runs.next().flatten());
            let (f_lo, t_lo, f_hi, t_hi) = match (lo, hi) {
                (Some(l), Some(u)) => (l, t[k] - h, u, t[k] + h),
                (Some(l), None) => (l, t[k] - h, centre.to_vec(), t[k]),
                (None, Some(u)) => (centre.to_vec(), t[k], u, t[k] + h),
                (None, None) => {
                    dead.push(k);
                    continue;
                }
            };
            for i in 0..m {
                let s = self.sigma(i, centre[i].1);
                j[(i, k)] = (f_hi[i].0 - f_lo[i].0) / (t_hi - t_lo) / s;
            }
        }
        (j, dead)
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
            Ok(c) => {
                let r = self.weighted(&c.predictions);
                Some(if r.norm_squared() <= EXACT_CHI2 { DVector::zeros(r.len()) } else { r })
            }
            Err(e) => {
                // A trial point that does not evaluate: the barrier, so the step is refused (see BARRIER).
                *self.last_error.borrow_mut() = Some(e.clone());
                self.refused.set(self.refused.get() + 1);
                let m = self.targets.len();
                Some(DVector::from_element(m, BARRIER / (m as f64).sqrt()))
            }
        }
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let c = self.current.as_ref().ok()?;
        let t = self.t_of_u(&self.u);
        let (mut ju, _) = self.jacobian_t(&t, &c.predictions, &c.frozen);
        // Chain rule: dt/du = (b − a)/2 · cos u.
        for (k, p) in self.fwd.free.iter().enumerate() {
            let (a, b) = p.t_bounds();
            let d = 0.5 * (b - a) * self.u[k].cos();
            ju.column_mut(k).scale_mut(d);
        }
        Some(ju)
    }
}
