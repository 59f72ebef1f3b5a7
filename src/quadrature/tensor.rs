//! Anisotropic tensor Gauss–Legendre rules with per-axis order adaptation (p-refinement), for smooth
//! integrands over a small fixed partition (`docs/instrument.md` §Quadrature, "A tensor rule for smooth anisotropic
//! integrands").
//!
//! Why: on an integrand that is analytic over each box, a product of Gauss–Legendre rules converges
//! geometrically in the order of every axis, and the orders an axis needs differ widely (a lobe narrower
//! than one stop but wider than the other: ~10 nodes on one axis, 2–3 on the rest). Genz–Malik bisection
//! spends its points isotropically and pays for every split with 57 new points; raising the order of the one
//! axis that needs it is far cheaper. The rule here is applied with the same orders on every box of the
//! partition it is given (the overlap-kink partition or the one plain box: few boxes, all smooth), so a
//! method can store its orders as plain data and a frozen re-run gives the same bits.
//!
//! The value is Q(n), the tensor rule of orders n = (n₁, …, n_D) summed over the boxes. The error estimate is
//! the difference of successive orders per axis: e = Σ_k |Q(n) − Q(n − e_k)|, where n − e_k lowers axis k one
//! step of [`ORDERS`]. It is the error of the lower rules, so when the orders converge it bounds the error of
//! the reported Q(n) with room to spare (for an analytic integrand the error of an n-point Gauss rule falls
//! like ρ^{−2n}: from 8 to 12 points the error shrinks by ρ⁸); an axis that is not yet resolved shows up as a
//! large term and is the one raised next. Starting from the given orders, the axis whose term is the largest
//! (relative to the tolerance) is raised until Σ_k e_k ≤ max(atol, rtol·|Q|) in every component, or until
//! an axis would pass the last order or the budget would be exceeded: then the rule reports failure and the
//! caller integrates its fallback. Deterministic: a fixed point order and no data-dependent parallelism.
use super::Options;

/// The Gauss–Legendre orders an axis steps through (index = level). Level 0 (the midpoint) is only ever the
/// lower rule of level 1's difference; no axis is reported below level 1 (2 points).
pub(crate) const ORDERS: [usize; 12] = [1, 2, 3, 4, 6, 8, 12, 16, 20, 24, 32, 48];

/// The result of [`integrate`]: the value Q(n) and the estimate per component, the final levels and
/// the evaluations spent.
#[derive(Clone, Debug, PartialEq)]
pub struct TensorEstimate<const D: usize> {
    pub value: Vec<f64>,
    pub error: Vec<f64>,
    /// The per-axis terms |Q(n) − Q(n − e_k)|, summed over the components (for `--explain` and the tests).
    pub axis_error: [f64; D],
    pub levels: [usize; D],
    pub converged: bool,
}

/// Gauss–Legendre nodes and weights on [0, 1] for every order of [`ORDERS`].
struct Rules {
    nodes: Vec<Vec<f64>>,
    weights: Vec<Vec<f64>>,
}

impl Rules {
    fn new() -> Rules {
        let (mut nodes, mut weights) = (Vec::new(), Vec::new());
        for &n in &ORDERS {
            let (x, w) = super::gauss_legendre(n);
            nodes.push(x.iter().map(|x| 0.5 * (x + 1.0)).collect());
            weights.push(w.iter().map(|w| 0.5 * w).collect());
        }
        Rules { nodes, weights }
    }
}

/// Points per call of the integrand (the batch the material evaluates at once).
const CHUNK: usize = 512;

/// The number of points of one box at these levels.
pub(crate) fn points_per_box<const D: usize>(levels: [usize; D]) -> usize {
    levels.iter().map(|&l| ORDERS[l]).product()
}

/// Q(levels) over the boxes, per component, and Σ|w f| (the scale of its rounding), in a fixed point order.
fn tensor_sum<const D: usize, F: FnMut(&[[f64; D]], &mut [f64])>(
    f: &mut F,
    ncomp: usize,
    boxes: &[([f64; D], [f64; D])],
    levels: [usize; D],
    rules: &Rules,
) -> (Vec<f64>, Vec<f64>) {
    let orders: [usize; D] = std::array::from_fn(|k| ORDERS[levels[k]]);
    let total = points_per_box(levels);
    let mut sum = vec![0.0; ncomp];
    let mut abs = vec![0.0; ncomp];
    let mut pts: Vec<[f64; D]> = Vec::with_capacity(CHUNK.min(total));
    let mut wts: Vec<f64> = Vec::with_capacity(CHUNK.min(total));
    let mut vals = vec![0.0; CHUNK.min(total) * ncomp];
    for (lo, hi) in boxes {
        let vol: f64 = (0..D).map(|k| hi[k] - lo[k]).product();
        let mut box_sum = vec![0.0; ncomp];
        let mut start = 0;
        while start < total {
            let end = (start + CHUNK).min(total);
            pts.clear();
            wts.clear();
            for flat in start..end {
                let mut rest = flat;
                let mut x = [0.0; D];
                let mut w = 1.0;
                for k in (0..D).rev() {
                    let i = rest % orders[k];
                    rest /= orders[k];
                    x[k] = lo[k] + (hi[k] - lo[k]) * rules.nodes[levels[k]][i];
                    w *= rules.weights[levels[k]][i];
                }
                pts.push(x);
                wts.push(w);
            }
            let v = &mut vals[..pts.len() * ncomp];
            v.iter_mut().for_each(|v| *v = 0.0);
            f(&pts, v);
            for (w, v) in wts.iter().zip(v.chunks_exact(ncomp)) {
                for c in 0..ncomp {
                    let v = if v[c].is_finite() { v[c] } else { 0.0 };
                    box_sum[c] += w * v;
                    abs[c] += (w * v).abs() * vol;
                }
            }
            start = end;
        }
        for c in 0..ncomp {
            sum[c] += box_sum[c] * vol;
        }
    }
    (sum, abs)
}

/// The calibration of an axis's term from its last two differences (DCUHRE's scheme, as
/// `genz_malik::calibrated`, with the same constants): when the differences fall by r = d/d_prev with
/// 3·r < 1 the orders are in their asymptotic range and the error of the reported (higher) rule is taken as
/// 3·r·d, but never below d/`max_shrink`; otherwise d itself.
pub(crate) fn calibrate(d: f64, d_prev: f64, max_shrink: f64) -> f64 {
    use super::genz_malik::CALIBRATION;
    if !(d_prev > 0.0) {
        return d;
    }
    let r = d / d_prev;
    if CALIBRATION * r < 1.0 {
        (CALIBRATION * r * d).max(d / max_shrink)
    } else {
        d
    }
}

/// The most a term summed with its sign over several boxes of shared orders may shrink ([`calibrate`]) when
/// the boxes' differences cancel in the sum (|Σ d_b| < ½ Σ |d_b|): the ratios of such a sum are not those of
/// one rule's asymptotics (a critical-angle conductor at D523 85° has the differences of three boxes cancel
/// to 1 % and an actual error of d/2.9; `docs/accuracy.md` §5.2). Otherwise `genz_malik::MAX_SHRINK`.
pub(crate) const SIGNED_MAX_SHRINK: f64 = 2.0;

/// The most raises a run may make ([`Path`]).
pub(crate) const MAX_STEPS: usize = 64;
/// The most boxes the rule takes (a step stores its box in six bits; 63 is every box).
pub(crate) const MAX_BOXES: usize = 63;
/// A step that raised the axis on every box (shared orders).
const ALL: usize = 63;

/// How [`integrate`] adapts: the highest level an axis may reach, and whether the boxes share their orders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Adapt {
    pub max_level: usize,
    pub shared: bool,
}

/// The raises of one adaptive run, in order (box and axis of each), so that a frozen method replays exactly
/// the same computations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Path {
    pub len: u8,
    /// box · 4 + axis, per step.
    pub steps: [u8; MAX_STEPS],
}

impl Default for Path {
    fn default() -> Path {
        Path { len: 0, steps: [0; MAX_STEPS] }
    }
}

impl Path {
    fn push(&mut self, b: usize, axis: usize) {
        self.steps[self.len as usize] = (b * 4 + axis) as u8;
        self.len += 1;
    }
    /// Step i: (box, axis).
    fn step(&self, i: usize) -> (usize, usize) {
        let s = self.steps[i] as usize;
        (s / 4, s % 4)
    }
    /// The highest level of each axis over the boxes after the path's raises from `start`.
    pub(crate) fn replayed<const D: usize>(&self, start: [usize; D], boxes: usize) -> [usize; D] {
        let mut n = vec![start.map(|l| l.max(1)); boxes.max(1)];
        for i in 0..self.len as usize {
            let (b, k) = self.step(i);
            for (j, l) in n.iter_mut().enumerate() {
                if b == ALL || b == j {
                    l[k] += 1;
                }
            }
        }
        std::array::from_fn(|k| n.iter().map(|l| l[k]).max().unwrap_or(1))
    }
}

/// One box's state: its levels, its sum and rounding scale, and per axis the last difference of successive
/// orders and the one before it.
struct BoxState<const D: usize> {
    n: [usize; D],
    q: Vec<f64>,
    abs: Vec<f64>,
    terms: Vec<Vec<f64>>,
    previous: Vec<Option<Vec<f64>>>,
}

/// Integrate over `boxes` with the tensor rule (D ≤ 4, at most [`MAX_BOXES`] boxes), every box starting at
/// `levels` (each ≥ 1); with `shared` the boxes keep the same orders (an axis is raised on all of them at
/// once), otherwise each box adapts its own.
///
/// First each box's Q(n) and its D lower neighbours Q(n − e_k) give one term |Q(n) − Q(n − e_k)| per axis.
/// Then, while the sum of the terms over boxes and axes exceeds the tolerance, the (box, axis) with the
/// largest term (relative to its component's tolerance) is raised one level: the new Q(n + e_k) costs one
/// tensor rule on that box, its lower neighbour on that axis is the Q(n) just computed, so the raised axis's
/// term is renewed; the other axes keep the term of their last raise. A term is calibrated from the axis's
/// last two differences ([`calibrate`]). The value is the sum of the boxes' last Q(n), the estimate the sum
/// of the calibrated terms. With `replay` (a frozen method) the stored path of raises is replayed without
/// any test, so the same material gives the same bits. Returns the estimate and the path (None when the
/// levels or the budget ran out first) and the evaluations spent either way.
pub fn integrate<const D: usize, F: FnMut(&[[f64; D]], &mut [f64])>(
    f: &mut F,
    ncomp: usize,
    boxes: &[([f64; D], [f64; D])],
    levels: [usize; D],
    how: Adapt,
    opts: &Options,
    replay: Option<Path>,
) -> (Option<(TensorEstimate<D>, Path)>, usize) {
    let Adapt { max_level, shared } = how;
    assert!(D <= 4, "two bits per axis in a path");
    if boxes.is_empty() || boxes.len() > MAX_BOXES {
        return (None, 0);
    }
    let rules = Rules::new();
    let max_level = max_level.min(ORDERS.len() - 1);
    let n0 = levels.map(|l| l.clamp(1, max_level));
    let out_of_budget = |evals: usize, extra: usize| {
        evals + extra > opts.max_evals || opts.deadline.is_some_and(|d| std::time::Instant::now() >= d)
    };
    let lower = |n: [usize; D], k: usize| {
        let mut m = n;
        m[k] -= 1;
        m
    };
    let start_cost: usize =
        boxes.len() * (points_per_box(n0) + (0..D).map(|k| points_per_box(lower(n0, k))).sum::<usize>());
    if out_of_budget(0, start_cost) {
        return (None, 0);
    }
    let mut evals = start_cost;
    let mut state: Vec<BoxState<D>> = boxes
        .iter()
        .map(|b| {
            let one = std::slice::from_ref(b);
            let (q, abs) = tensor_sum(f, ncomp, one, n0, &rules);
            let terms = (0..D)
                .map(|k| {
                    let (ql, _) = tensor_sum(f, ncomp, one, lower(n0, k), &rules);
                    (0..ncomp).map(|c| q[c] - ql[c]).collect()
                })
                .collect();
            BoxState { n: n0, q, abs, terms, previous: vec![None; D] }
        })
        .collect();
    // The calibrated term of axis k, component c, of a set of boxes raised together: from the differences
    // summed over the set (signed: with shared orders the boxes are one rule).
    let term = |ss: &[BoxState<D>], k: usize, c: usize| {
        let d = ss.iter().map(|s| s.terms[k][c]).sum::<f64>().abs();
        if ss.iter().all(|s| s.previous[k].is_some()) {
            let p = ss.iter().map(|s| s.previous[k].as_ref().map_or(0.0, |p| p[c])).sum::<f64>().abs();
            let unsigned = ss.iter().map(|s| s.terms[k][c].abs()).sum::<f64>();
            let max_shrink = if d < 0.5 * unsigned { SIGNED_MAX_SHRINK } else { super::genz_malik::MAX_SHRINK };
            calibrate(d, p, max_shrink)
        } else {
            d
        }
    };
    // The groups the estimate is formed over: all boxes with shared orders, else each box.
    let groups: Vec<(usize, usize)> =
        if shared { vec![(0, boxes.len())] } else { (0..boxes.len()).map(|b| (b, b + 1)).collect() };
    let mut path = Path::default();
    loop {
        let value: Vec<f64> = (0..ncomp).map(|c| state.iter().map(|s| s.q[c]).sum()).collect();
        let abs: Vec<f64> = (0..ncomp).map(|c| state.iter().map(|s| s.abs[c]).sum()).collect();
        let error: Vec<f64> = (0..ncomp)
            .map(|c| groups.iter().map(|g| (0..D).map(|k| term(&state[g.0..g.1], k, c)).sum::<f64>()).sum())
            .collect();
        // The tolerance per component: rtol·|Q|, atol, and the rounding of the sum (64 ε Σ|w f|, below which
        // the differences are noise).
        let tol: Vec<f64> =
            (0..ncomp).map(|c| opts.atol.max(opts.rtol * value[c].abs()).max(64.0 * f64::EPSILON * abs[c])).collect();
        let converged = (0..ncomp).all(|c| error[c] <= tol[c]);
        let done = match replay {
            Some(p) => path.len >= p.len,
            None => converged,
        };
        if done {
            let axis_error: [f64; D] = std::array::from_fn(|k| {
                groups.iter().map(|g| (0..ncomp).map(|c| term(&state[g.0..g.1], k, c)).sum::<f64>()).sum()
            });
            let levels: [usize; D] = std::array::from_fn(|k| state.iter().map(|s| s.n[k]).max().unwrap_or(1));
            let est = TensorEstimate { value, error, axis_error, levels, converged };
            return (Some((est, path)), evals);
        }
        // Raise the (box, axis) with the largest term relative to its component's tolerance (the first on
        // ties).
        // (With shared orders the axis whose terms summed over the boxes are the largest, on every box.)
        let (b, k) = match replay {
            Some(p) => p.step(path.len as usize),
            None => {
                let score = |ss: &[BoxState<D>], k: usize| {
                    (0..ncomp).map(|c| term(ss, k, c) / tol[c].max(f64::MIN_POSITIVE)).fold(0.0, f64::max)
                };
                let mut best = (0, 0, -1.0);
                if shared {
                    for k in 0..D {
                        let sc = score(&state, k);
                        if sc > best.2 {
                            best = (ALL, k, sc);
                        }
                    }
                } else {
                    for (b, s) in state.iter().enumerate() {
                        for k in 0..D {
                            let sc = score(std::slice::from_ref(s), k);
                            if sc > best.2 {
                                best = (b, k, sc);
                            }
                        }
                    }
                }
                (best.0, best.1)
            }
        };
        let raised: Vec<usize> = if b == ALL { (0..state.len()).collect() } else { vec![b] };
        if raised.iter().any(|&b| b >= state.len() || state[b].n[k] >= max_level) || path.len as usize >= MAX_STEPS {
            return (None, evals);
        }
        for &b in &raised {
            let s = &mut state[b];
            s.n[k] += 1;
            if out_of_budget(evals, points_per_box(s.n)) {
                return (None, evals);
            }
            evals += points_per_box(s.n);
            let (qn, an) = tensor_sum(f, ncomp, std::slice::from_ref(&boxes[b]), s.n, &rules);
            s.previous[k] = Some(s.terms[k].clone());
            for ((t, new), old) in s.terms[k].iter_mut().zip(&qn).zip(&s.q) {
                *t = new - old;
            }
            (s.q, s.abs) = (qn, an);
        }
        path.push(b, k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn opts(rtol: f64) -> Options {
        Options { rtol, atol: 0.0, max_evals: 10_000_000, deadline: None, ..Default::default() }
    }

    /// A separable analytic integrand with one sharp axis: the sharp axis is raised, the others stay low, and
    /// the estimate is above the actual error.
    #[test]
    fn the_sharp_axis_is_raised_and_the_estimate_bounds_the_error() {
        // ∫₀¹ e^{−x}·1/(1 + 25 y²)·(1 + z)·cos(w) over [0, 1]⁴ = (1 − e⁻¹)·atan(5)/5·1.5·sin 1.
        let exact = (1.0 - (-1.0f64).exp()) * 5.0f64.atan() / 5.0 * 1.5 * 1.0f64.sin();
        let mut f = |pts: &[[f64; 4]], out: &mut [f64]| {
            for (p, o) in pts.iter().zip(out.iter_mut()) {
                *o = (-p[0]).exp() / (1.0 + 25.0 * p[1] * p[1]) * (1.0 + p[2]) * p[3].cos();
            }
        };
        for rtol in [1e-4, 1e-7, 1e-10] {
            let (est, evals) = integrate(
                &mut f,
                1,
                &[([0.0; 4], [1.0; 4])],
                [1; 4],
                Adapt { max_level: ORDERS.len() - 1, shared: false },
                &opts(rtol),
                None,
            );
            let (est, path) = est.expect("converges");
            let actual = (est.value[0] - exact).abs();
            assert!(actual <= est.error[0], "rtol {rtol}: actual {actual:e} > estimate {:e}", est.error[0]);
            assert!(est.error[0] <= rtol * exact, "{est:?}");
            assert!(est.levels[1] > est.levels[2] && est.levels[1] > est.levels[3], "{est:?}");
            assert!(est.levels[2] == 1, "a linear axis needs 2 points: {est:?}");
            assert!(evals > 0);
            // Frozen: the same levels give the same bits.
            let (again, spent) = integrate(
                &mut f,
                1,
                &[([0.0; 4], [1.0; 4])],
                [1; 4],
                Adapt { max_level: ORDERS.len() - 1, shared: false },
                &opts(rtol),
                Some(path),
            );
            assert_eq!(again.expect("frozen"), (est, path));
            assert_eq!(spent, evals);
        }
    }

    /// A kink inside the box does not converge geometrically: the rule gives up (None) instead of claiming a
    /// value, when the levels run out.
    #[test]
    fn a_kink_inside_the_box_ends_in_none() {
        let mut f = |pts: &[[f64; 2]], out: &mut [f64]| {
            for (p, o) in pts.iter().zip(out.iter_mut()) {
                *o = (p[0] - 0.3141).abs() + p[1];
            }
        };
        let (est, _) = integrate(
            &mut f,
            1,
            &[([0.0; 2], [1.0; 2])],
            [1; 2],
            Adapt { max_level: 6, shared: false },
            &opts(1e-12),
            None,
        );
        assert!(est.is_none());
    }

    /// Several boxes and components: the sums add up; a polynomial of degree 3 in each variable is exact at
    /// 2 points (the estimate is then the difference to the midpoint rule).
    #[test]
    fn boxes_and_components_add_up() {
        let mut f = |pts: &[[f64; 2]], out: &mut [f64]| {
            for (p, o) in pts.iter().zip(out.chunks_exact_mut(2)) {
                o[0] = p[0].powi(3) * p[1];
                o[1] = 1.0;
            }
        };
        let boxes = [([0.0, 0.0], [0.5, 2.0]), ([0.5, 0.0], [1.0, 2.0])];
        let (est, evals) =
            integrate(&mut f, 2, &boxes, [1; 2], Adapt { max_level: 8, shared: true }, &opts(1e-9), None);
        let (est, _) = est.expect("converges");
        // ∫₀¹ x³ dx ∫₀² y dy = 1/4 · 2 = 0.5; the area is 2.
        assert!((est.value[0] - 0.5).abs() < 1e-14 && (est.value[1] - 2.0).abs() < 1e-14, "{est:?}");
        assert!(est.error[0] + 1e-14 >= (est.value[0] - 0.5).abs(), "within rounding");
        assert!(evals >= 2 * 4);
    }
}
