//! [`Rule::LobeDelta`](super::Rule::LobeDelta): the delta limit of a narrow Gaussian-tailed lobe and its majorant, at
//! the Gauss–Legendre nodes of (t_p, t_q) — the executor ([`lobe_delta`]), the fit at one node ([`delta_fit`],
//! [`DeltaFit`], on the points of [`delta_stencil`]) and the constants of its stencil and bound.
use super::shape::{Integrand, Outcome, RuleRun, ShapedRule};
use super::Rule;
use crate::quadrature::{legendre_on_into, Estimate, Options, Refine};

/// The radii (in lobe widths) of the rings on which [`Rule::LobeDelta`](super::Rule::LobeDelta) samples the even part
/// of h (four directions, 0°, 45°, 90°, 135°, each with its opposite point; with the curvature ring): the majorant's
/// second differences.
pub const DELTA_RADII: [f64; 2] = [2.5, 5.0];

/// The radius (in lobe widths) of the disc inside which [`Rule::LobeDelta`](super::Rule::LobeDelta) bounds the
/// correction by second differences (in the metric of the fitted curvature B); beyond it the tail, bounded by a
/// Gaussian of the decay rate measured on that ring ([`DELTA_TAIL_SAFETY`]). It is the last of [`DELTA_RADII`]; the
/// overlap kinks are ≥ [`LOBE_REACH`](super::LOBE_REACH) = 8 widths away.
pub(crate) const DELTA_RADIUS: f64 = DELTA_RADII[DELTA_RADII.len() - 1];

/// The factor by which [`Rule::LobeDelta`](super::Rule::LobeDelta) multiplies the largest sampled second difference to
/// stand for a bound over the whole disc: one of the two assumptions of its majorant (`docs/instrument.md` §Quadrature;
/// checked against a stencil of 24 directions × 30 radii by `tests/delta_limit.rs`, where the dense maximum
/// is at most 1.1× the sampled one).
pub const DELTA_SAFETY: f64 = 4.0;

/// The factor by which [`Rule::LobeDelta`](super::Rule::LobeDelta) divides the decay rate λ of the lobe measured on its
/// outer ring (the smallest ln(F(0)/F(x))/xᵀBx there) before it bounds the tail beyond the ring by F(0)·e^{−λ·xᵀBx}:
/// the other assumption of its majorant. (A Gaussian of the fitted curvature, |h| ≤ its largest value on the
/// ring, does not hold: at grazing incidence the lobe's exponent in these variables falls a few per cent
/// short of xᵀBx at 12 widths, and h = F·e^{xᵀBx} grows there by 100× — measured by the same test.)
pub const DELTA_TAIL_SAFETY: f64 = 1.25;

/// The Gauss–Legendre orders per t axis of [`Rule::LobeDelta`](super::Rule::LobeDelta): the second-difference stencil
/// on the lower's nodes, the value on the higher's, their difference the t rule's error.
pub const DELTA_T_ORDERS: (usize, usize) = (2, 3);

/// The points per t node of [`Rule::LobeDelta`](super::Rule::LobeDelta): the centre and the curvature ring (four
/// directions, both signs) at the higher order's nodes, and with them the bound's rings at the lower order's.
const DELTA_NODE_POINTS: (usize, usize) = (1 + 8, 1 + 8 * (1 + DELTA_RADII.len()));

/// The evaluations of one [`Rule::LobeDelta`](super::Rule::LobeDelta) (181).
pub(crate) const DELTA_COST: usize = DELTA_T_ORDERS.1 * DELTA_T_ORDERS.1 * DELTA_NODE_POINTS.0
    + DELTA_T_ORDERS.0 * DELTA_T_ORDERS.0 * DELTA_NODE_POINTS.1;
const _: () = assert!(DELTA_COST == 181, "the docs and --explain's cost figures say 181");

/// The directions of the stencil of [`Rule::LobeDelta`](super::Rule::LobeDelta) in the scaled lobe variables (each with
/// its opposite point): 0°, 45°, 90°, 135°.
pub(crate) const DELTA_DIRECTIONS: [[f64; 2]; 4] = [
    [1.0, 0.0],
    [std::f64::consts::FRAC_1_SQRT_2, std::f64::consts::FRAC_1_SQRT_2],
    [0.0, 1.0],
    [-std::f64::consts::FRAC_1_SQRT_2, std::f64::consts::FRAC_1_SQRT_2],
];

/// The radius (in lobe widths) of the ring on which [`Rule::LobeDelta`](super::Rule::LobeDelta) measures the lobe's
/// curvature.
pub const DELTA_FIT_RADIUS: f64 = 1.0;

/// [`Rule::LobeDelta`]'s parameters: the lobe's widths in (u, v).
pub(super) struct Delta {
    pub width: [f64; 2],
}

impl ShapedRule for Delta {
    /// The delta limit, accepted when its majorant meets the tolerance (or when frozen: the same points);
    /// otherwise not (the lobe's Gauss–Hermite rule runs next, [`Rule::fallback`]).
    fn estimate(&self, f: &mut Integrand, run: &RuleRun) -> Outcome {
        let (est, spent) = lobe_delta(f, run.ncomp, self.width, run.opts);
        let done = est.filter(|e| e.converged || run.refine == Refine::Frozen);
        Outcome::shaped(done.map(|e| (e, Rule::LobeDelta { width: self.width })), spent)
    }
}

/// Run [`Rule::LobeDelta`](super::Rule::LobeDelta): the delta limit and its majorant (see [`delta_node`]); `converged`
/// when the majorant meets max(atol, rtol·|I|) in every component. None when an evaluation is not finite, the lobe is
/// not log-concave at its peak (the curvature fit fails) or the budget would be exceeded; and the evaluations
/// spent either way.
fn lobe_delta(f: &mut Integrand, ncomp: usize, width: [f64; 2], opts: &Options) -> (Option<Estimate>, usize) {
    let (lo, hi) = DELTA_T_ORDERS;
    let ((ring, full), cost) = (DELTA_NODE_POINTS, DELTA_COST);
    if cost > opts.max_evals {
        return (None, 0);
    }
    let radii = [DELTA_FIT_RADIUS, DELTA_RADII[0], DELTA_RADII[1]];
    let mut pts = Vec::with_capacity(cost);
    let mut wts = Vec::with_capacity(hi * hi + lo * lo);
    let (mut t, mut w) = (Vec::new(), Vec::new());
    for (order, rings) in [(hi, 1), (lo, radii.len())] {
        legendre_on_into(order, 0.0, 1.0, &mut t, &mut w);
        for (tp, wp) in t.iter().zip(&w) {
            for (tq, wq) in t.iter().zip(&w) {
                wts.push(wp * wq);
                delta_stencil(width, *tp, *tq, &radii[..rings], &mut pts);
            }
        }
    }
    let mut vals = vec![0.0; pts.len() * ncomp];
    f(&pts, &mut vals);
    if vals.iter().any(|v| !v.is_finite()) {
        return (None, cost);
    }
    let scale = std::f64::consts::PI * width[0] * width[1];
    let (mut value, mut error) = (vec![0.0; ncomp], vec![0.0; ncomp]);
    let mut converged = true;
    for c in 0..ncomp {
        let (mut v_hi, mut v_lo, mut bound) = (0.0, 0.0, 0.0);
        let mut start = 0;
        for (k, wt) in wts.iter().enumerate() {
            let n = if k < hi * hi { ring } else { full };
            // This node's values of component c (at most `full` of them), without allocating per node.
            let mut node = [0.0; 1 + 8 * (1 + DELTA_RADII.len())];
            for (slot, i) in node.iter_mut().zip(start..start + n) {
                *slot = vals[i * ncomp + c];
            }
            start += n;
            let Some((mass, b)) = delta_node(&node[..n], &radii[..(n - 1) / 8]) else {
                return (None, cost);
            };
            if k < hi * hi {
                v_hi += wt * mass;
            } else {
                v_lo += wt * mass;
                bound += wt * b;
            }
        }
        value[c] = scale * v_hi;
        error[c] = scale * bound + scale * (v_hi - v_lo).abs();
        converged &= error[c] <= opts.atol.max(opts.rtol * value[c].abs());
    }
    let est = Estimate { value, error, evaluations: 0, regions: 1, converged, out_of_time: false };
    (Some(est), cost)
}

/// One t node of [`Rule::LobeDelta`](super::Rule::LobeDelta), relative to π (the caller multiplies by π·w_u·w_v): the
/// delta limit's mass and (when `radii` holds the bound's rings too) its majorant, from the values `vals` at the centre
/// and, per ring of `radii` (the first the curvature ring) and direction of [`DELTA_DIRECTIONS`], the point
/// and its opposite. None when the values are not positive where the curvature is measured or the fitted
/// curvature is not positive definite.
///
/// *The curvature*: along direction d at radius r, b(d) = −(½ ln(F(rd)·F(−rd)) − ln F(0))/r² (the even part
/// of ln F, so the odd terms of the lobe and of the rest cancel); B = [[b(0°), β], [β, b(90°)]] with
/// β = ½(b(45°) − b(135°)). *The delta limit* at this node is Laplace's: ∫ F ≈ π·F(0)/√det B (for the exact
/// Gaussian lobe of the linearised widths, B = I and this is π·F(0), the one-node Gauss–Hermite rule).
/// *The majorant*: with h = F·e^{xᵀBx}, h_e(x) = ½(h(x) + h(−x)) and the weight e^{−xᵀBx} even,
///
///   ∫ F − π F(0)/√det B = ∫ e^{−xᵀBx} (h_e(x) − h(0)) dx,
///
/// and if |h_e(x) − h(0)| ≤ Q·xᵀBx on the ellipse xᵀBx ≤ R² and 0 ≤ F(x) ≤ F(0)·e^{−λ·xᵀBx} outside it,
/// then, in y = B^{1/2}x (and as e^{−xᵀBx}·h_e is the even part of F ≥ 0),
///
///   |∫_{xᵀBx≤R²}| ≤ Q ∫ |y|² e^{−|y|²} dy / √det B = π Q / √det B,
///   |∫_{xᵀBx>R²}| ≤ ∫_{xᵀBx>R²} F + |h(0)| π e^{−R²} / √det B ≤ F(0)·π (e^{−λR²}/λ + e^{−R²}) / √det B.
///
/// Q is [`DELTA_SAFETY`] times the largest sampled |h_e − h(0)|/xᵀBx on all rings, R² the smallest xᵀBx on
/// the outer ring and λ the smallest ln(F(0)/F(x))/xᵀBx there, divided by [`DELTA_TAIL_SAFETY`]; None also
/// when λ is not positive (a lobe that does not fall by its outer ring).
pub(super) fn delta_node(vals: &[f64], radii: &[f64]) -> Option<(f64, f64)> {
    if vals.iter().all(|v| *v == 0.0) {
        return Some((0.0, 0.0));
    }
    let fit = delta_fit(vals, radii)?;
    if radii.len() == 1 {
        return Some((fit.mass(), 0.0));
    }
    let lambda = fit.lambda / DELTA_TAIL_SAFETY;
    if !(lambda > 0.0) {
        return None;
    }
    Some((fit.mass(), fit.majorant(DELTA_SAFETY * fit.q, lambda)))
}

/// What [`Rule::LobeDelta`](super::Rule::LobeDelta) measures at one t node ([`delta_fit`]), before its safety factors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeltaFit {
    /// The fitted curvature (b_xx, b_yy, b_xy).
    pub b: [f64; 3],
    /// F(0).
    pub f0: f64,
    /// The largest |h_e − h(0)|/xᵀBx on the rings (0 with the curvature ring only).
    pub q: f64,
    /// The smallest decay rate ln(F(0)/F(x))/xᵀBx on the outer ring (∞ with the curvature ring only).
    pub lambda: f64,
    /// The smallest xᵀBx on the outer ring (∞ with the curvature ring only).
    pub r2: f64,
}

impl DeltaFit {
    /// √det B.
    pub(crate) fn root(&self) -> f64 {
        (self.b[0] * self.b[1] - self.b[2] * self.b[2]).sqrt()
    }

    /// The delta limit's mass relative to π·w_u·w_v: F(0)/√det B.
    pub fn mass(&self) -> f64 {
        self.f0 / self.root()
    }

    /// The majorant of [`delta_node`] (relative to π·w_u·w_v) for the constants `q` and `lambda`:
    /// (q + F(0)·(e^{−λR²}/λ + e^{−R²}))/√det B. The rule passes its sampled constants with
    /// [`DELTA_SAFETY`] and [`DELTA_TAIL_SAFETY`] applied; `tests/delta_limit.rs` passes a denser stencil's.
    pub fn majorant(&self, q: f64, lambda: f64) -> f64 {
        let tail = if lambda.is_finite() { (-lambda * self.r2).exp() / lambda } else { 0.0 };
        (q + self.f0 * (tail + (-self.r2).exp())) / self.root()
    }
}

/// The curvature and the bound's sampled constants at one t node of [`Rule::LobeDelta`](super::Rule::LobeDelta) from
/// the values `vals` on its stencil ([`delta_stencil`] with `radii`; see [`delta_node`] for the formulas). None when
/// the values are not positive where the curvature is measured or the fitted curvature is not positive
/// definite.
pub fn delta_fit(vals: &[f64], radii: &[f64]) -> Option<DeltaFit> {
    let f0 = vals[0];
    if f0 <= 0.0 || vals[1..9].iter().any(|v| *v <= 0.0) {
        return None;
    }
    let r = radii[0];
    let b: [f64; 4] = std::array::from_fn(|k| -(0.5 * (vals[1 + 2 * k] * vals[2 + 2 * k]).ln() - f0.ln()) / (r * r));
    let (bxx, byy, bxy) = (b[0], b[2], 0.5 * (b[1] - b[3]));
    let det = bxx * byy - bxy * bxy;
    if !(bxx > 0.0 && byy > 0.0 && det > 0.0) {
        return None;
    }
    let (mut q, mut lambda, mut r2) = (0.0f64, f64::INFINITY, f64::INFINITY);
    if radii.len() > 1 {
        let mut i = 1;
        for (j, r) in radii.iter().enumerate() {
            for d in DELTA_DIRECTIONS {
                let (x, y) = (r * d[0], r * d[1]);
                let quad = bxx * x * x + 2.0 * bxy * x * y + byy * y * y;
                let grow = quad.exp();
                let (a, c) = (vals[i] * grow, vals[i + 1] * grow);
                q = q.max(((0.5 * (a + c) - f0) / quad).abs());
                if j == radii.len() - 1 {
                    r2 = r2.min(quad);
                    for v in [vals[i], vals[i + 1]] {
                        // A zero (outside the overlap, or underflow) decays as fast as any rate.
                        if v != 0.0 {
                            lambda = lambda.min((f0 / v.abs()).ln() / quad);
                        }
                    }
                }
                i += 2;
            }
        }
    }
    Some(DeltaFit { b: [bxx, byy, bxy], f0, q, lambda, r2 })
}

/// Append the stencil of one t node (t_p, t_q) of [`Rule::LobeDelta`](super::Rule::LobeDelta) to `pts`, in the order
/// [`delta_fit`] reads it: the centre, then per ring of `radii` (in lobe widths) and direction of [`DELTA_DIRECTIONS`]
/// the point and its opposite, in the chart (u, t_p, v, t_q) with the lobe widths `width`.
pub fn delta_stencil(width: [f64; 2], tp: f64, tq: f64, radii: &[f64], pts: &mut Vec<[f64; 4]>) {
    pts.push([0.0, tp, 0.0, tq]);
    for r in radii {
        for d in DELTA_DIRECTIONS {
            for s in [1.0, -1.0] {
                pts.push([s * r * d[0] * width[0], tp, s * r * d[1] * width[1], tq]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::geometry::Stop;
    use crate::quadrature::{Cell, Refine};

    fn run(opts: &Options) -> RuleRun<'_> {
        let stop = Stop { p: [-0.02, 0.02], q: [-0.02, 0.02] };
        RuleRun { ncomp: 1, opts, refine: Refine::Adaptive, stops: (stop, stop), cells: &[] as &[Cell<4>], keep: false }
    }

    /// A Gaussian of widths `a` in (u, v) times a polynomial of degree 3 in (t_p, t_q), optionally with a kink
    /// (1 + |u|/a₀) at its centre.
    fn lobe(a: [f64; 2], kink: bool) -> impl FnMut(&[[f64; 4]], &mut [f64]) {
        move |pts: &[[f64; 4]], out: &mut [f64]| {
            for (x, o) in pts.iter().zip(out.iter_mut()) {
                let (u, v) = (x[0] / a[0], x[2] / a[1]);
                let k = if kink { 1.0 + u.abs() } else { 1.0 };
                *o = (-u * u - v * v).exp() * k * (1.0 + x[1] + x[3] * x[3]);
            }
        }
    }

    #[test]
    fn the_delta_limit_is_exact_on_a_gaussian_narrower_than_its_scale() {
        // The lobe 0.8 times the rule's widths: the fitted curvature B = I/0.64, the mass 0.64 × F(0).
        let w = [0.001, 0.0007];
        let a = [0.8 * w[0], 0.8 * w[1]];
        let exact = std::f64::consts::PI * a[0] * a[1] * (1.0 + 0.5 + 1.0 / 3.0);
        let opts = Options { rtol: 1e-9, ..Options::default() };
        let out = Delta { width: w }.estimate(&mut lobe(a, false), &run(&opts));
        let (est, frozen, _) = out.done.expect("the majorant meets 1e-9 on an exact Gaussian");
        let actual = (est.value[0] - exact).abs();
        assert!(actual <= 1e-12 * exact && actual <= est.error[0] + 1e-15 * exact, "{actual:e} {:e}", est.error[0]);
        assert_eq!((frozen, out.spent), (Rule::LobeDelta { width: w }, DELTA_COST));
    }

    #[test]
    fn the_delta_limit_refuses_a_kink_at_the_peak() {
        let w = [0.001, 0.0007];
        let opts = Options { rtol: 1e-6, ..Options::default() };
        let out = Delta { width: w }.estimate(&mut lobe(w, true), &run(&opts));
        assert!(out.done.is_none(), "{:?}", out.done);
        assert_eq!(out.spent, DELTA_COST);
        assert_eq!(
            Rule::LobeDelta { width: w }.fallback(),
            Some(Rule::LobeGaussHermite { width: w, levels: (0, super::super::LOBE_LEVELS.len() - 1) })
        );
    }
}
