//! [`Rule::LobePolar`]: a lobe with GGX's heavy tail, its (u, v) range cut at the overlap kinks into up to
//! 3 × 3 pieces — the one that holds the lobe centre in polar variables, the others in tail variables — each
//! raised level by level ([`POLAR_LEVELS`], [`TAIL_LEVELS`]) where the error is largest.
use super::shape::{Integrand, Outcome, RuleRun, ShapedRule};
use super::Rule;
use crate::quadrature::{
    legendre_on_into, mapped_legendre_into, polar_rectangle_into, Estimate, Map, Options, PolarBuffers, Refine,
};

/// The (φ nodes per sector, β nodes, t nodes per axis) of the polar piece of [`Rule::LobePolar`], level by
/// level: 4·3·6·2² = 288 points on a square's four sectors, then 512, 2 592, 8 192, 28 800, 73 728 (a quarter
/// more for each sector cut in two, `quadrature::polar::MAX_SECTOR`). From level 1 on every level has more t
/// nodes than the one below, so that the difference of two levels, the piece's estimate, sees the t rule's
/// error too (with the t nodes shared, it cannot: `docs/instrument.md` §Quadrature, "Polar variables for a
/// narrow GGX lobe", *Orders and the estimate*).
pub(crate) const POLAR_LEVELS: [(usize, usize, usize); 6] =
    [(3, 6, 2), (4, 8, 2), (6, 12, 3), (8, 16, 4), (12, 24, 5), (16, 32, 6)];

/// The (tail-axis nodes, cross-axis nodes, t nodes per axis) of a tail piece of [`Rule::LobePolar`], level by
/// level: 3·3·2² = 36 points, then 64, 324, 1 024, 3 600, 9 216 (the t nodes rise with the level as in
/// [`POLAR_LEVELS`]).
pub(crate) const TAIL_LEVELS: [(usize, usize, usize); 6] =
    [(3, 3, 2), (4, 4, 2), (6, 6, 3), (8, 8, 4), (12, 12, 5), (16, 16, 6)];

/// One piece of [`Rule::LobePolar`]: its u and v intervals, whether it holds the lobe centre (the polar
/// piece), its level and its sums at that level and the one below.
struct PolarPiece {
    index: usize,
    interval: [[f64; 2]; 2],
    central: bool,
    level: usize,
    below: Vec<f64>,
    at: Vec<f64>,
}

/// The buffers [`Rule::LobePolar`] works in, made once per execution and reused level after level
/// (`docs/instrument.md` §Quadrature, "Allocation in the shaped rules": nothing in the hot path allocates; they only
/// grow, to the largest level reached).
#[derive(Default)]
struct PolarScratch {
    /// (x, y, weight) in the scaled lobe variables.
    plane: Vec<(f64, f64, f64)>,
    rect: Vec<([f64; 2], f64)>,
    buffers: PolarBuffers,
    outer: (Vec<f64>, Vec<f64>),
    inner: (Vec<f64>, Vec<f64>),
    t: (Vec<f64>, Vec<f64>),
    pts: Vec<[f64; 4]>,
    wts: Vec<f64>,
    vals: Vec<f64>,
}

/// The points of a piece of [`Rule::LobePolar`] at one level, in the lobe chart's variables (u, t_p, v, t_q),
/// with their weights, in a fixed order, into `s.pts` and `s.wts`.
fn polar_piece_points(width: [f64; 2], interval: [[f64; 2]; 2], central: bool, level: usize, s: &mut PolarScratch) {
    let [w0, w1] = width;
    let scaled = [[interval[0][0] / w0, interval[0][1] / w0], [interval[1][0] / w1, interval[1][1] / w1]];
    // (x, y, weight) in the scaled lobe variables x = u/w_u, y = v/w_v.
    s.plane.clear();
    let nt = if central {
        let (nphi, nr, nt) = POLAR_LEVELS[level];
        let lo = [scaled[0][0], scaled[1][0]];
        let hi = [scaled[0][1], scaled[1][1]];
        polar_rectangle_into(lo, hi, nphi, nr, Map::Tan { scale: 1.0 }, &mut s.buffers, &mut s.rect);
        s.plane.extend(s.rect.iter().map(|&([x, y], w)| (x, y, w)));
        nt
    } else {
        // The tail coordinate is the axis whose interval does not hold 0 (the first when neither does): σ = 1/x
        // along it; across it the kernel 1/(c² + y²)² (c² = 1 + x²) in y = c·tan γ.
        let (no, ni, nt) = TAIL_LEVELS[level];
        let outer = if scaled[0][0] < 0.0 && scaled[0][1] > 0.0 { 1 } else { 0 };
        let inner = 1 - outer;
        let (xo, wo) = &mut s.outer;
        mapped_legendre_into(no, scaled[outer][0], scaled[outer][1], Map::Reciprocal, xo, wo);
        let (y, wy) = &mut s.inner;
        for (x, wx) in xo.iter().zip(wo.iter()) {
            let map = Map::Tan { scale: (1.0 + x * x).sqrt() };
            mapped_legendre_into(ni, scaled[inner][0], scaled[inner][1], map, y, wy);
            for (y, wy) in y.iter().zip(wy.iter()) {
                s.plane.push(if outer == 0 { (*x, *y, wx * wy) } else { (*y, *x, wx * wy) });
            }
        }
        nt
    };
    let (tl, wl) = &mut s.t;
    legendre_on_into(nt, 0.0, 1.0, tl, wl);
    s.pts.clear();
    s.wts.clear();
    for &(x, y, w) in &s.plane {
        for (tp, wp) in tl.iter().zip(wl.iter()) {
            for (tq, wq) in tl.iter().zip(wl.iter()) {
                s.pts.push([w0 * x, *tp, w1 * y, *tq]);
                s.wts.push(w * w0 * w1 * wp * wq);
            }
        }
    }
}

/// The sum of the points in `s` per component into `sum` (non-finite values count as 0, as in
/// `gauss::lobe_tensor_sum`).
fn polar_piece_sum(f: &mut Integrand, ncomp: usize, s: &mut PolarScratch, sum: &mut [f64]) {
    s.vals.clear();
    s.vals.resize(s.pts.len() * ncomp, 0.0);
    f(&s.pts, &mut s.vals);
    sum.iter_mut().for_each(|x| *x = 0.0);
    for (w, v) in s.wts.iter().zip(s.vals.chunks_exact(ncomp)) {
        for c in 0..ncomp {
            if v[c].is_finite() {
                sum[c] += w * v[c];
            }
        }
    }
}

/// [`Rule::LobePolar`]'s parameters: the lobe's widths, the cuts of u and v, the pieces' levels.
pub(super) struct Polar {
    pub width: [f64; 2],
    pub breaks: [[f64; 4]; 2],
    pub levels: [u8; 9],
}

impl ShapedRule for Polar {
    /// The pieces raised where the error is largest until the sum meets the tolerance (frozen: the levels
    /// reached before).
    fn estimate(&self, f: &mut Integrand, run: &RuleRun) -> Outcome {
        let (width, [u, v]) = (self.width, self.breaks);
        let (done, spent) = lobe_polar(f, run.ncomp, width, self.breaks, self.levels, run.opts, run.refine);
        Outcome::shaped(done.map(|(est, levels)| (est, Rule::LobePolar { width, u, v, levels })), spent)
    }
}

/// Run [`Rule::LobePolar`]: every piece at its level and the one below; while the summed differences exceed
/// max(atol, rtol·|I|) in some component, the piece with the largest difference (relative to that tolerance;
/// the first on ties) goes one level up (adaptive; a frozen rule keeps its levels). Returns the estimate and
/// the pieces' levels when the sum meets the tolerance, None when the piece to raise has no level left or the
/// budget would be exceeded, and the evaluations spent either way. Its buffers are made once here (per
/// piece and per execution, not per level).
fn lobe_polar(
    f: &mut Integrand,
    ncomp: usize,
    width: [f64; 2],
    breaks: [[f64; 4]; 2],
    levels: [u8; 9],
    opts: &Options,
    refine: Refine,
) -> (Option<(Estimate, [u8; 9])>, usize) {
    let mut evals = 0;
    let mut pieces = Vec::with_capacity(9);
    for i in 0..3 {
        for j in 0..3 {
            let interval = [[breaks[0][i], breaks[0][i + 1]], [breaks[1][j], breaks[1][j + 1]]];
            if !(interval[0][1] > interval[0][0] && interval[1][1] > interval[1][0]) {
                continue;
            }
            let holds = |a: [f64; 2]| a[0] < 0.0 && a[1] > 0.0;
            let central = holds(interval[0]) && holds(interval[1]);
            let top = if central { POLAR_LEVELS.len() } else { TAIL_LEVELS.len() } - 1;
            let level = (levels[3 * i + j] as usize).clamp(1, top);
            let (below, at) = (vec![0.0; ncomp], vec![0.0; ncomp]);
            pieces.push(PolarPiece { index: 3 * i + j, interval, central, level, below, at });
        }
    }
    let mut scratch = PolarScratch::default();
    // The sums of one piece at one level into `sum`; false when the budget would be exceeded.
    let mut run = |p: &PolarPiece, level: usize, evals: &mut usize, sum: &mut [f64]| -> bool {
        polar_piece_points(width, p.interval, p.central, level, &mut scratch);
        if *evals + scratch.pts.len() > opts.max_evals {
            return false;
        }
        *evals += scratch.pts.len();
        polar_piece_sum(f, ncomp, &mut scratch, sum);
        true
    };
    for p in &mut pieces {
        let mut below = std::mem::take(&mut p.below);
        let mut at = std::mem::take(&mut p.at);
        if !run(p, p.level - 1, &mut evals, &mut below) || !run(p, p.level, &mut evals, &mut at) {
            return (None, evals);
        }
        p.below = below;
        p.at = at;
    }
    let (mut value, mut error, mut tol) = (vec![0.0; ncomp], vec![0.0; ncomp], vec![0.0; ncomp]);
    loop {
        for c in 0..ncomp {
            value[c] = pieces.iter().map(|p| p.at[c]).sum();
            error[c] = pieces.iter().map(|p| (p.at[c] - p.below[c]).abs()).sum();
            tol[c] = opts.atol.max(opts.rtol * value[c].abs());
        }
        let converged = error.iter().zip(&tol).all(|(e, t)| e <= t);
        if converged || refine == Refine::Frozen {
            let mut reached = [1u8; 9];
            for p in &pieces {
                reached[p.index] = p.level as u8;
            }
            let regions = pieces.len();
            let est = Estimate { value, error, evaluations: 0, regions, converged, out_of_time: false };
            return (Some((est, reached)), evals);
        }
        let excess = |p: &PolarPiece| {
            (0..ncomp)
                .map(|c| {
                    let e = (p.at[c] - p.below[c]).abs();
                    if tol[c] > 0.0 {
                        e / tol[c]
                    } else if e > 0.0 {
                        f64::INFINITY
                    } else {
                        0.0
                    }
                })
                .fold(0.0, f64::max)
        };
        let mut worst = 0;
        for k in 1..pieces.len() {
            if excess(&pieces[k]) > excess(&pieces[worst]) {
                worst = k;
            }
        }
        let top = if pieces[worst].central { POLAR_LEVELS.len() } else { TAIL_LEVELS.len() } - 1;
        if pieces[worst].level >= top {
            return (None, evals);
        }
        let level = pieces[worst].level + 1;
        // The level below becomes the old level: its buffer is reused for the new sums.
        let p = &mut pieces[worst];
        std::mem::swap(&mut p.below, &mut p.at);
        let mut at = std::mem::take(&mut p.at);
        if !run(&pieces[worst], level, &mut evals, &mut at) {
            return (None, evals);
        }
        let p = &mut pieces[worst];
        p.at = at;
        p.level = level;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::geometry::Stop;
    use crate::quadrature::Cell;

    /// ∫₀^a ∫₀^b dx dy / (1 + x² + y²)²: the GGX kernel over a rectangle with a corner at its centre (the
    /// form factor of a rectangle; checked against a 3 000² midpoint sum to 3·10⁻⁹).
    fn corner(a: f64, b: f64) -> f64 {
        let (ra, rb) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
        a / (2.0 * ra) * (b / ra).atan() + b / (2.0 * rb) * (a / rb).atan()
    }

    #[test]
    fn the_polar_rule_integrates_the_ggx_kernel_over_its_nine_pieces() {
        let w = [0.002, 0.0015];
        // The u and v ranges cut at ±2 and ±(5, 4) widths: a polar centre and eight tail pieces.
        let (bu, bv) = ([-5.0, -2.0, 2.0, 5.0], [-4.0, -2.0, 2.0, 4.0]);
        let breaks = [bu.map(|x| x * w[0]), bv.map(|x| x * w[1])];
        let exact = w[0] * w[1] * 4.0 * corner(5.0, 4.0);
        let mut f = |pts: &[[f64; 4]], out: &mut [f64]| {
            for (x, o) in pts.iter().zip(out.iter_mut()) {
                let (u, v) = (x[0] / w[0], x[2] / w[1]);
                *o = 1.0 / (1.0 + u * u + v * v).powi(2);
            }
        };
        let opts = Options { rtol: 1e-9, ..Options::default() };
        let stop = Stop { p: [-0.02, 0.02], q: [-0.02, 0.02] };
        let run = RuleRun {
            ncomp: 1,
            opts: &opts,
            refine: Refine::Adaptive,
            stops: (stop, stop),
            cells: &[] as &[Cell<4>],
            keep: false,
        };
        let out = Polar { width: w, breaks, levels: [1; 9] }.estimate(&mut f, &run);
        let (est, frozen, _) = out.done.expect("converges");
        let actual = (est.value[0] - exact).abs();
        assert!(actual <= est.error[0] && est.error[0] <= 1e-9 * exact, "{actual:e} {:e}", est.error[0]);
        let Rule::LobePolar { levels, .. } = frozen else { panic!("{frozen:?}") };
        assert!(levels.iter().all(|&l| l >= 1) && levels.iter().any(|&l| l > 1), "{levels:?}");
        // Frozen at the levels it reached: the same bits again, at the same cost.
        let again = RuleRun { refine: Refine::Frozen, ..run };
        let out2 = Polar { width: w, breaks, levels }.estimate(&mut f, &again);
        let (est2, _, _) = out2.done.unwrap();
        assert_eq!(est2.value[0].to_bits(), est.value[0].to_bits());
    }
}
