//! The search (docs/inverse.md §Method, §Every root): the solver's run from the recipe's start, the scan of
//! the bounds that seeds restarts (one or two free parameters), the deterministic Halton restarts of an
//! exactly determined fit, each restart's run, and the choice of the fit among the ends.
use levenberg_marquardt::{LevenbergMarquardt, TerminationReason};
use nalgebra::DVector;
use rayon::prelude::*;

use super::params::FreeParameter;
use super::problem::{u_of_t, weighted, Mode, Problem};

/// Tolerance of the scan's runs (at least; the fit's own when looser): the scan only seeds the restarts, and
/// a coarse grid needs readings to a few digits.
pub(super) const SCAN_RTOL: f64 = 1e-3;

/// Points of the scan per fitted variable: 24 for one free parameter, 8 × 8 for two.
const SCAN_POINTS: [usize; 2] = [24, 8];

/// A restart's evaluation budget is the fit's divided by this.
pub(super) const RESTART_BUDGET_DIVISOR: usize = 4;

/// The most restarts the scan seeds.
const MAX_SEEDS: usize = 6;

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

/// One point of the scan of the bounds: t, the predictions (None where it does not evaluate), χ².
pub(super) struct ScanPoint {
    pub(super) t: Vec<f64>,
    pub(super) pred: Option<Vec<(f64, f64)>>,
    /// The weighted residuals.
    pub(super) r: Option<DVector<f64>>,
    pub(super) chi2: f64,
}

/// The scan's grid as fractions of the bound widths in t: the cell centres (i + ½)/N of N cells per variable,
/// the first variable fastest.
pub(super) fn scan_grid(n: usize) -> Vec<Vec<f64>> {
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
pub(super) fn scan_minima(scan: &[ScanPoint], n: usize) -> Vec<usize> {
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

/// One solver run from a start: where it ended, and whether and why it stopped.
pub(super) struct Solved<'a> {
    pub(super) problem: Problem<'a>,
    pub(super) converged: bool,
    pub(super) termination: String,
}

impl Solved<'_> {
    pub(super) fn chi2(&self) -> Option<f64> {
        self.problem.current.as_ref().ok().map(|c| self.problem.weighted(&c.predictions).norm_squared())
    }
}

/// Run the solver from the problem's start (MINPACK tolerances of docs/inverse.md §Method, "Solver").
pub(super) fn solve(problem: Problem<'_>, patience: usize) -> Solved<'_> {
    let (problem, report) = LevenbergMarquardt::new()
        .with_ftol(1e-12)
        .with_xtol(1e-10)
        .with_gtol(1e-12)
        .with_patience(patience)
        .minimize(problem);
    let (converged, termination) = match &report.termination {
        TerminationReason::Converged { .. } => (true, "converged (ftol/xtol)".to_string()),
        TerminationReason::Orthogonal => (true, "converged (the residuals are orthogonal to the Jacobian)".into()),
        TerminationReason::ResidualsZero => {
            (true, "converged (an exact fit: every residual within 10⁻³ of its uncertainty, χ² ≤ 10⁻⁶)".into())
        }
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

/// The whole search: every solver end (the first from the recipe's start), the one chosen as the fit, and
/// what seeded the restarts.
pub(super) struct Search<'a> {
    pub(super) ends: Vec<Solved<'a>>,
    pub(super) chosen: usize,
    pub(super) scan: Vec<ScanPoint>,
    pub(super) seeds: Vec<usize>,
    pub(super) halton: usize,
    /// Restarts whose start does not evaluate.
    pub(super) failed: usize,
    /// Forward runs of the scan, and of the scan and the restarts together.
    pub(super) scan_evaluations: usize,
    pub(super) restart_evaluations: usize,
}

/// How much searching: the solver's budget in forward runs and the restarts asked for.
pub(super) struct Budget {
    pub(super) max_iterations: usize,
    pub(super) restarts: usize,
}

/// The restarts' starts in u: the scan's seeds, then the Halton points (`halton` of them).
fn starts(free: &[FreeParameter], scan: &[ScanPoint], seeds: &[usize], halton: usize) -> Vec<DVector<f64>> {
    let n = free.len();
    let mut starts: Vec<DVector<f64>> = seeds
        .iter()
        .map(|&i| DVector::from_iterator(n, (0..n).map(|k| u_of_t(scan[i].t[k], free[k].t_bounds()))))
        .collect();
    for k in 1..=halton {
        let fr = restart_fractions(k, n);
        starts.push(DVector::from_iterator(
            n,
            (0..n).map(|j| {
                let (a, b) = free[j].t_bounds();
                u_of_t(a + fr[j] * (b - a), (a, b))
            }),
        ));
    }
    starts
}

/// The Halton restarts: an exactly determined fit's (m = n) restarts, less the scan's seeds for one or two
/// parameters; none otherwise.
pub(super) fn halton_count(m: usize, n: usize, restarts: usize, seeds: usize) -> usize {
    if m == n && restarts > 0 {
        if n <= 2 {
            restarts.saturating_sub(seeds)
        } else {
            restarts
        }
    } else {
        0
    }
}

/// The fit among the ends: the solver's from the recipe's start (0), unless a restart reached a clearly lower
/// χ² (by more than 1): then the start led to a worse local minimum or a plateau, and the best end is the fit.
pub(super) fn choose(chi2: &[f64]) -> usize {
    let best = (1..chi2.len()).min_by(|&a, &b| chi2[a].total_cmp(&chi2[b]));
    match best {
        Some(b) if chi2[b] < chi2[0] - 1.0 => b,
        _ => 0,
    }
}

/// Search from `first` (the problem at the recipe's start, which evaluates).
pub(super) fn search<'a>(first: Problem<'a>, budget: &Budget) -> Search<'a> {
    let fwd = first.fwd;
    let free = fwd.free;
    let n = free.len();
    let m = first.targets.len();
    let patience = budget.max_iterations.div_ceil(n + 1).max(1);
    // A restart only has to show where its start leads (back here, to another solution, a plateau or a worse
    // minimum), not to polish it: a quarter of the budget (docs/inverse.md §Every root, docs/performance.md).
    let restart_patience = patience.div_ceil(RESTART_BUDGET_DIVISOR);
    let (targets, u_sigma) = (first.targets, first.u_sigma.clone());
    let main = solve(first, patience);
    let runs_before_restarts = fwd.runs();
    // The scan of the bounds (one or two free parameters, restarts asked for): a coarse grid in t, each point
    // integrated adaptively at the scan's loose tolerance; the grid's local minima of χ² seed the restarts
    // (docs/inverse.md §Every root).
    let scan: Vec<ScanPoint> = if n <= 2 && budget.restarts > 0 {
        // The points do not depend on each other: they run in parallel, each into its own slot.
        scan_grid(n)
            .into_par_iter()
            .map(|f| {
                let t: Vec<f64> = (0..n)
                    .map(|k| {
                        let (a, b) = free[k].t_bounds();
                        a + f[k] * (b - a)
                    })
                    .collect();
                let pred = fwd.run(&fwd.x_of_t(&t), Mode::Scan).ok().flatten().map(|p| p.0);
                let r = pred.as_ref().map(|p| weighted(targets, &u_sigma, p));
                let chi2 = r.as_ref().map_or(f64::INFINITY, |r| r.norm_squared());
                ScanPoint { t, pred, r, chi2 }
            })
            .collect()
    } else {
        Vec::new()
    };
    let scan_evaluations = fwd.runs() - runs_before_restarts;
    let seeds = scan_minima(&scan, n);
    let halton = halton_count(m, n, budget.restarts, seeds.len());
    // The restarts do not depend on each other (nor on the main run's end): they run in parallel, and their
    // ends are kept in the order of their starts.
    let restarted: Vec<Option<Solved>> = starts(free, &scan, &seeds, halton)
        .par_iter()
        .map(|u_k| {
            let p_k = Problem::new(fwd, targets, &u_sigma, u_k);
            p_k.current.is_ok().then(|| solve(p_k, restart_patience))
        })
        .collect();
    let failed = restarted.iter().filter(|e| e.is_none()).count();
    let mut ends: Vec<Solved> = vec![main];
    ends.extend(restarted.into_iter().flatten());
    let restart_evaluations = fwd.runs() - runs_before_restarts;
    let chi2: Vec<f64> = ends.iter().map(|s| s.chi2().unwrap_or(f64::INFINITY)).collect();
    let chosen = choose(&chi2);
    Search { ends, chosen, scan, seeds, halton, failed, scan_evaluations, restart_evaluations }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(t: Vec<f64>, r: f64) -> ScanPoint {
        ScanPoint { t, pred: Some(vec![(r, 0.0)]), r: Some(DVector::from_element(1, r)), chi2: r * r }
    }

    #[test]
    fn the_grid_is_cell_centres() {
        let g1 = scan_grid(1);
        assert_eq!(g1.len(), 24);
        assert_eq!((g1[0][0], g1[23][0]), (0.5 / 24.0, 23.5 / 24.0));
        let g2 = scan_grid(2);
        assert_eq!(g2.len(), 64);
        assert_eq!(g2[9], vec![1.5 / 8.0, 1.5 / 8.0]);
    }

    /// Two basins on a one-parameter scan seed two restarts, the lower first; a flat stretch (neighbours within
    /// one uncertainty) and a point that does not evaluate seed nothing.
    #[test]
    fn local_minima_of_the_scan_seed_the_restarts() {
        let r = |x: f64| 100.0 * (x - 0.2) * (x - 0.7);
        let mut scan: Vec<ScanPoint> = scan_grid(1).into_iter().map(|t| point(t.clone(), r(t[0]).abs())).collect();
        let seeds = scan_minima(&scan, 1);
        assert_eq!(seeds.len(), 2, "{seeds:?}");
        assert!(seeds.iter().all(|&i| r(scan[i].t[0]).abs() < 2.0), "{seeds:?}");
        assert!(scan[seeds[0]].chi2 <= scan[seeds[1]].chi2);
        // A seed that does not evaluate seeds nothing.
        let gone = seeds[0];
        scan[gone].r = None;
        scan[gone].chi2 = f64::INFINITY;
        assert!(!scan_minima(&scan, 1).contains(&gone));
        for p in scan.iter_mut() {
            *p = point(p.t.clone(), 0.01 * p.t[0]);
        }
        assert!(scan_minima(&scan, 1).is_empty());
    }

    #[test]
    fn restarts_and_the_choice_of_the_fit() {
        assert_eq!(halton_count(2, 2, 2, 1), 1);
        assert_eq!(halton_count(3, 3, 2, 5), 2);
        assert_eq!(halton_count(3, 2, 2, 0), 0);
        assert_eq!(choose(&[5.0, 4.5, 9.0]), 0, "within 1 of the start's χ²: the start's fit");
        assert_eq!(choose(&[5.0, 3.0, 1.0]), 2);
        assert_eq!(choose(&[f64::INFINITY, 1.0]), 1);
        assert_eq!(choose(&[2.0]), 0);
        assert_eq!(restart_fractions(1, 3), vec![0.5, 1.0 / 3.0, 0.2]);
    }
}
