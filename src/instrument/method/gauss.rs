//! The two Gauss product rules: [`Rule::LobeGaussHermite`] (Gauss–Hermite in the scaled lobe variables,
//! Gauss–Legendre in t, level by level through [`LOBE_LEVELS`]) and [`Rule::TensorGauss`] (the anisotropic
//! tensor Gauss–Legendre rule of `quadrature::tensor` on the boxes of [`tensor_boxes`]).
use super::{Rule, TensorChart};
use crate::instrument::aperture::{lobe_boxes, AxisMap};
use crate::instrument::geometry::Stop;
use crate::quadrature::{gauss_hermite_table, gauss_legendre_table, tensor, Estimate, Options, Refine};

/// The (Gauss–Hermite, Gauss–Legendre) orders per axis of [`Rule::LobeGaussHermite`], level by level:
/// 4²·2² = 64 points, then 324, 1 024, 3 600, 9 216.
pub const LOBE_LEVELS: [(usize, usize); 5] = [(4, 2), (6, 3), (8, 4), (12, 5), (16, 6)];

/// The highest level of [`Rule::TensorGauss`] an axis may reach (`tensor::ORDERS[TENSOR_MAX_LEVEL]` = 24
/// points): beyond it the integrand is not smooth at the scale of the box and the fallback does better.
pub const TENSOR_MAX_LEVEL: usize = 9;

/// The boxes of [`Rule::TensorGauss`] in its chart's variables: the stops' product (p_s, q_s, p_r, q_r) in the
/// plain chart; in the lobe chart (u, t_p, v, t_q) the products of the intervals between the range ends and
/// the overlap kinks s₁ + r₀, s₀ + r₁ of u and of v (where the overlap length is linear), t ∈ [0, 1].
pub fn tensor_boxes(chart: TensorChart, src: Stop, rec: Stop) -> Vec<([f64; 4], [f64; 4])> {
    // The range ends and the overlap kinks, no lobe splits.
    let kinks = |a: AxisMap| a.splits(&[]);
    match chart {
        TensorChart::Plain => {
            vec![([src.p[0], src.q[0], rec.p[0], rec.q[0]], [src.p[1], src.q[1], rec.p[1], rec.q[1]])]
        }
        TensorChart::Lobe => {
            lobe_boxes(&[kinks(AxisMap { s: src.p, r: rec.p }), kinks(AxisMap { s: src.q, r: rec.q })])
        }
        TensorChart::PlainPLobeQ => kinks(AxisMap { s: src.q, r: rec.q })
            .windows(2)
            .map(|v| ([src.p[0], rec.p[0], v[0], 0.0], [src.p[1], rec.p[1], v[1], 1.0]))
            .collect(),
    }
}

/// Run [`Rule::TensorGauss`]: the estimate and the rule with its path of raises when the orders converged (or
/// the path was replayed), else None; and the evaluations spent either way.
pub(super) fn tensor_gauss(
    f: &mut impl FnMut(&[[f64; 4]], &mut [f64]),
    ncomp: usize,
    chart: TensorChart,
    boxes: Vec<([f64; 4], [f64; 4])>,
    levels: [usize; 4],
    opts: &Options,
    replay: Option<tensor::Path>,
) -> (Option<(Estimate, Rule)>, usize) {
    let (r, spent) = tensor::integrate(
        f,
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
    f: &mut impl FnMut(&[[f64; 4]], &mut [f64]),
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
pub(super) fn lobe_gauss_hermite(
    f: &mut impl FnMut(&[[f64; 4]], &mut [f64]),
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
