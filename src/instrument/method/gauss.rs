//! The two Gauss product rules: [`Rule::LobeGaussHermite`] (Gauss–Hermite in the scaled lobe variables,
//! Gauss–Legendre in t, level by level through [`LOBE_LEVELS`]) and [`Rule::TensorGauss`] (the anisotropic
//! tensor Gauss–Legendre rule of `quadrature::tensor` on the boxes of [`tensor_boxes`]).
use super::shape::{Integrand, Outcome, RuleRun, ShapedRule};
use super::Rule;
use crate::instrument::aperture::{lobe_boxes, AxisMap, Chart};
use crate::instrument::geometry::Stop;
use crate::quadrature::{gauss_hermite_table, gauss_legendre_table, tensor, Estimate, Options, Refine};

/// The (Gauss–Hermite, Gauss–Legendre) orders per axis of [`Rule::LobeGaussHermite`], level by level:
/// 4²·2² = 64 points, then 324, 1 024, 3 600, 9 216.
pub const LOBE_LEVELS: [(usize, usize); 5] = [(4, 2), (6, 3), (8, 4), (12, 5), (16, 6)];

/// The highest level of [`Rule::TensorGauss`] an axis may reach (`tensor::ORDERS[TENSOR_MAX_LEVEL]` = 24
/// points): beyond it the integrand is not smooth at the scale of the box and the fallback does better.
pub(crate) const TENSOR_MAX_LEVEL: usize = 9;

/// The boxes of [`Rule::TensorGauss`] in its chart's variables: the stops' product (p_s, q_s, p_r, q_r) in the
/// plain chart; in the lobe chart (u, t_p, v, t_q) the products of the intervals between the range ends and
/// the overlap kinks s₁ + r₀, s₀ + r₁ of u and of v (where the overlap length is linear), t ∈ [0, 1].
pub fn tensor_boxes(chart: Chart, src: Stop, rec: Stop) -> Vec<([f64; 4], [f64; 4])> {
    // The range ends and the overlap kinks, no lobe splits.
    let kinks = |a: AxisMap| a.splits(&[]);
    match chart {
        Chart::Plain => {
            vec![([src.p[0], src.q[0], rec.p[0], rec.q[0]], [src.p[1], src.q[1], rec.p[1], rec.q[1]])]
        }
        Chart::Lobe => lobe_boxes(&[kinks(AxisMap { s: src.p, r: rec.p }), kinks(AxisMap { s: src.q, r: rec.q })]),
        Chart::PlainPLobeQ => kinks(AxisMap { s: src.q, r: rec.q })
            .windows(2)
            .map(|v| ([src.p[0], rec.p[0], v[0], 0.0], [src.p[1], rec.p[1], v[1], 1.0]))
            .collect(),
    }
}

/// [`Rule::TensorGauss`]'s parameters: its chart, starting levels and (frozen) path of raises.
pub(super) struct Tensor {
    pub chart: Chart,
    pub levels: [usize; 4],
    pub path: tensor::Path,
}

impl ShapedRule for Tensor {
    /// The tensor rule on its chart's boxes of the stops, raising orders until they agree (frozen: the kept
    /// path replayed).
    fn estimate(&self, f: &mut Integrand, run: &RuleRun) -> Outcome {
        let replay = (run.refine == Refine::Frozen).then_some(self.path);
        let boxes = tensor_boxes(self.chart, run.stops.0, run.stops.1);
        let (done, spent) = tensor_gauss(f, run.ncomp, self.chart, boxes, self.levels, run.opts, replay);
        Outcome::shaped(done, spent)
    }
}

/// Run [`Rule::TensorGauss`]: the estimate and the rule with its path of raises when the orders converged (or
/// the path was replayed), else None; and the evaluations spent either way.
fn tensor_gauss(
    f: &mut Integrand,
    ncomp: usize,
    chart: Chart,
    boxes: Vec<([f64; 4], [f64; 4])>,
    levels: [usize; 4],
    opts: &Options,
    replay: Option<tensor::Path>,
) -> (Option<(Estimate, Rule)>, usize) {
    let (r, spent) = tensor::integrate(
        &mut &mut *f,
        ncomp,
        &boxes,
        levels,
        tensor::Adapt { max_level: TENSOR_MAX_LEVEL, shared: true },
        opts,
        replay,
    );
    let r = r.map(|(t, path)| {
        let est = Estimate {
            value: t.value,
            error: t.error,
            evaluations: 0,
            regions: boxes.len(),
            converged: t.converged,
            out_of_time: false,
        };
        (est, Rule::TensorGauss { chart, levels, path })
    });
    (r, spent)
}

/// [`Rule::LobeGaussHermite`]'s parameters: the lobe's widths in (u, v) and the levels to run.
pub(super) struct GaussHermite {
    pub width: [f64; 2],
    pub levels: (usize, usize),
}

impl ShapedRule for GaussHermite {
    /// The levels until two successive ones agree; frozen, the two it reached.
    fn estimate(&self, f: &mut Integrand, run: &RuleRun) -> Outcome {
        let (done, spent) = lobe_gauss_hermite(f, run.ncomp, self.width, self.levels, run.opts, run.refine);
        let width = self.width;
        Outcome::shaped(
            done.map(|(est, level)| (est, Rule::LobeGaussHermite { width, levels: (level - 1, level) })),
            spent,
        )
    }
}

/// The buffers of [`Rule::LobeGaussHermite`], made once per execution and reused level after level
/// (`docs/instrument.md` §Quadrature, "Allocation in the shaped rules": nothing in the hot path allocates).
#[derive(Default)]
struct HermiteScratch {
    wh: Vec<f64>,
    t: (Vec<f64>, Vec<f64>),
    pts: Vec<[f64; 4]>,
    wts: Vec<f64>,
    vals: Vec<f64>,
}

/// One level of [`Rule::LobeGaussHermite`]: the tensor rule's sum per component into `sum`, in a fixed point
/// order.
fn lobe_tensor_sum(
    f: &mut Integrand,
    ncomp: usize,
    width: [f64; 2],
    (nh, nt): (usize, usize),
    s: &mut HermiteScratch,
    sum: &mut [f64],
) {
    let (xh, wh0) = gauss_hermite_table(nh);
    // ∫ g(u) du = w ∫ g(w x) e^{x²} e^{−x²} dx: the weights for g itself.
    s.wh.clear();
    s.wh.extend(xh.iter().zip(wh0).map(|(x, w)| w * (x * x).exp()));
    let (tl, wl) = &mut s.t;
    tl.clear();
    wl.clear();
    let (xl, wl0) = gauss_legendre_table(nt);
    tl.extend(xl.iter().map(|x| 0.5 * (x + 1.0)));
    wl.extend(wl0.iter().map(|w| 0.5 * w));
    s.vals.clear();
    s.vals.resize(nh * nt * nt * ncomp, 0.0);
    sum.iter_mut().for_each(|x| *x = 0.0);
    for (x, wx) in xh.iter().zip(&s.wh) {
        s.pts.clear();
        s.wts.clear();
        for (y, wy) in xh.iter().zip(&s.wh) {
            for (tp, wp) in tl.iter().zip(wl.iter()) {
                for (tq, wq) in tl.iter().zip(wl.iter()) {
                    s.pts.push([width[0] * x, *tp, width[1] * y, *tq]);
                    s.wts.push(wx * wy * wp * wq);
                }
            }
        }
        s.vals.iter_mut().for_each(|v| *v = 0.0);
        f(&s.pts, &mut s.vals);
        for (w, v) in s.wts.iter().zip(s.vals.chunks_exact(ncomp)) {
            for c in 0..ncomp {
                let v = if v[c].is_finite() { v[c] } else { 0.0 };
                sum[c] += w * v;
            }
        }
    }
    sum.iter_mut().for_each(|x| *x = *x * width[0] * width[1]);
}

/// Run [`Rule::LobeGaussHermite`]: levels `levels.0..=levels.1` of [`LOBE_LEVELS`] until two successive ones
/// agree to max(atol, rtol·|I|) in every component (adaptive), or just those levels (frozen). Returns the
/// estimate and its last level when they agree, else None, and the evaluations spent either way.
fn lobe_gauss_hermite(
    f: &mut Integrand,
    ncomp: usize,
    width: [f64; 2],
    levels: (usize, usize),
    opts: &Options,
    refine: Refine,
) -> (Option<(Estimate, usize)>, usize) {
    let cost = |(nh, nt): (usize, usize)| nh * nh * nt * nt;
    let mut evals = 0;
    let mut scratch = HermiteScratch::default();
    let (mut now, mut prev) = (vec![0.0; ncomp], vec![0.0; ncomp]);
    let mut have_previous = false;
    let last = levels.1.min(LOBE_LEVELS.len() - 1);
    for (level, &orders) in LOBE_LEVELS.iter().enumerate().take(last + 1).skip(levels.0) {
        if evals + cost(orders) > opts.max_evals {
            break;
        }
        lobe_tensor_sum(f, ncomp, width, orders, &mut scratch, &mut now);
        evals += cost(orders);
        if have_previous {
            let converged = now.iter().zip(&prev).all(|(v, p)| (v - p).abs() <= opts.atol.max(opts.rtol * v.abs()));
            if converged || refine == Refine::Frozen {
                let error: Vec<f64> = now.iter().zip(&prev).map(|(a, b)| (a - b).abs()).collect();
                let est = Estimate { value: now, error, evaluations: 0, regions: 1, converged, out_of_time: false };
                return (Some((est, level)), evals);
            }
        }
        std::mem::swap(&mut now, &mut prev);
        have_previous = true;
    }
    (None, evals)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::Cell;

    fn run(opts: &Options, refine: Refine, stops: (Stop, Stop)) -> RuleRun<'_> {
        RuleRun { ncomp: 1, opts, refine, stops, cells: &[] as &[Cell<4>], keep: false }
    }

    fn stops() -> (Stop, Stop) {
        (Stop { p: [-0.02, 0.03], q: [-0.04, 0.01] }, Stop { p: [-0.05, 0.01], q: [-0.03, 0.06] })
    }

    /// A Gaussian lobe of widths `a` in (u, v) times a polynomial of degree 3 in (t_p, t_q): its integral is
    /// π·a₀·a₁·(1 + ½ + ⅓).
    fn gaussian(a: [f64; 2]) -> impl FnMut(&[[f64; 4]], &mut [f64]) {
        move |pts: &[[f64; 4]], out: &mut [f64]| {
            for (x, o) in pts.iter().zip(out.iter_mut()) {
                let (u, v) = (x[0] / a[0], x[2] / a[1]);
                *o = (-u * u - v * v).exp() * (1.0 + x[1] + x[3] * x[3]);
            }
        }
    }

    #[test]
    fn gauss_hermite_is_exact_on_its_gaussian_and_bounds_a_wider_one() {
        let opts = Options { rtol: 1e-12, ..Options::default() };
        let r = run(&opts, Refine::Adaptive, stops());
        let w = [0.003, 0.002];
        let rule = GaussHermite { width: w, levels: (0, LOBE_LEVELS.len() - 1) };
        // The lobe the rule is scaled to: the first two levels agree to rounding.
        let exact = std::f64::consts::PI * w[0] * w[1] * (1.0 + 0.5 + 1.0 / 3.0);
        let out = rule.estimate(&mut gaussian(w), &r);
        let (est, frozen, cells) = out.done.expect("agrees");
        assert!((est.value[0] - exact).abs() <= 1e-14 * exact, "{} vs {exact}", est.value[0]);
        assert_eq!(frozen, Rule::LobeGaussHermite { width: w, levels: (0, 1) });
        assert!(cells.is_none() && out.spent == 64 + 324 && est.evaluations == out.spent);
        // A lobe 1.1 times wider than the rule's scale: more levels, the error estimate above the actual error.
        let a = [1.1 * w[0], 1.1 * w[1]];
        let exact = std::f64::consts::PI * a[0] * a[1] * (1.0 + 0.5 + 1.0 / 3.0);
        let opts = Options { rtol: 1e-8, ..Options::default() };
        let (est, frozen, _) = rule.estimate(&mut gaussian(a), &run(&opts, Refine::Adaptive, stops())).done.unwrap();
        let actual = (est.value[0] - exact).abs();
        assert!(actual <= est.error[0] && est.error[0] <= 1e-8 * exact, "{actual:e} {:e} {frozen:?}", est.error[0]);
        assert!(matches!(frozen, Rule::LobeGaussHermite { levels: (l, m), .. } if m == l + 1 && l >= 1));
    }

    #[test]
    fn gauss_hermite_refuses_a_kink_it_cannot_resolve() {
        // e^{−x²−y²}·(1 + |x|): the kink at the lobe centre keeps successive levels apart.
        let opts = Options { rtol: 1e-10, ..Options::default() };
        let w = [0.003, 0.002];
        let mut f = |pts: &[[f64; 4]], out: &mut [f64]| {
            for (x, o) in pts.iter().zip(out.iter_mut()) {
                let (u, v) = (x[0] / w[0], x[2] / w[1]);
                *o = (-u * u - v * v).exp() * (1.0 + u.abs());
            }
        };
        let rule = GaussHermite { width: w, levels: (0, LOBE_LEVELS.len() - 1) };
        let out = rule.estimate(&mut f, &run(&opts, Refine::Adaptive, stops()));
        assert!(out.done.is_none(), "{:?}", out.done);
        assert_eq!(out.spent, LOBE_LEVELS.iter().map(|(h, g)| h * h * g * g).sum::<usize>());
    }

    /// Π_k (1 + x_k + x_k² + x_k³) over a box: the product of its 1-D integrals.
    fn cubic(lo: [f64; 4], hi: [f64; 4]) -> f64 {
        let prim = |x: f64| x + x * x / 2.0 + x * x * x / 3.0 + x * x * x * x / 4.0;
        (0..4).map(|k| prim(hi[k]) - prim(lo[k])).product()
    }

    #[test]
    fn the_tensor_rule_is_exact_on_a_cubic_and_refuses_a_kink() {
        let s = stops();
        let [(lo, hi)] = tensor_boxes(Chart::Plain, s.0, s.1)[..] else { panic!("one box") };
        assert_eq!((lo, hi), ([-0.02, -0.04, -0.05, -0.03], [0.03, 0.01, 0.01, 0.06]));
        let mut f = |pts: &[[f64; 4]], out: &mut [f64]| {
            for (x, o) in pts.iter().zip(out.iter_mut()) {
                *o = x.iter().map(|x| 1.0 + x + x * x + x * x * x).product();
            }
        };
        let opts = Options { rtol: 1e-12, ..Options::default() };
        let rule = Tensor { chart: Chart::Plain, levels: [1; 4], path: tensor::Path::default() };
        let out = rule.estimate(&mut f, &run(&opts, Refine::Adaptive, s));
        let (est, frozen, _) = out.done.expect("a cubic is exact at 2 points per axis");
        let exact = cubic(lo, hi);
        assert!((est.value[0] - exact).abs() <= 1e-12 * exact.abs(), "{} vs {exact}", est.value[0]);
        assert!(matches!(frozen, Rule::TensorGauss { chart: Chart::Plain, .. }));
        // |p_s − c|: the orders never agree to 10⁻¹²; the rule gives up (its fallback runs).
        let mut kink = |pts: &[[f64; 4]], out: &mut [f64]| {
            for (x, o) in pts.iter().zip(out.iter_mut()) {
                *o = (x[0] - 0.0123).abs() + 1.0;
            }
        };
        assert!(rule.estimate(&mut kink, &run(&opts, Refine::Adaptive, s)).done.is_none());
    }
}
