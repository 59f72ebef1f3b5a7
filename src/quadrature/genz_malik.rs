//! Genz–Malik degree-7/5 rule and the globally adaptive driver.
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Stopping criteria.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Relative tolerance on each component of the integral.
    pub rtol: f64,
    /// Absolute tolerance on each component (a floor under the relative one).
    pub atol: f64,
    /// Hard limit on integrand evaluations; the result then says `converged: false`.
    pub max_evals: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options { rtol: 1e-6, atol: 0.0, max_evals: 20_000_000 }
    }
}

/// The result of an integration.
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    /// The integral, one value per component (degree-7 rule summed over all regions).
    pub value: Vec<f64>,
    /// Error estimate per component: Σ over regions of |I₇ − I₅|.
    pub error: Vec<f64>,
    pub evaluations: usize,
    pub regions: usize,
    /// True when every component met max(atol, rtol·|I|) before `max_evals`.
    pub converged: bool,
}

/// The Genz–Malik point set and weights for dimension `D` (2 ≤ D ≤ 8).
#[derive(Clone, Debug)]
pub struct Rule<const D: usize> {
    /// Points of the unit cube [−1, 1]^D with their weight index (0..5).
    points: Vec<([f64; D], usize)>,
    w7: [f64; 5],
    w5: [f64; 5],
}

const L2: f64 = 0.358_568_582_800_318_1; // sqrt(9/70)
const L4: f64 = 0.948_683_298_050_513_8; // sqrt(9/10)
const L5: f64 = 0.688_247_201_611_685_3; // sqrt(9/19)

impl<const D: usize> Default for Rule<D> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const D: usize> Rule<D> {
    /// The rule exists for 2 ≤ D ≤ 8 (Genz & Malik 1980); another D is refused at compile time.
    const DIMENSION_SUPPORTED: () = assert!(D >= 2 && D <= 8, "Genz–Malik needs 2 ≤ D ≤ 8");

    pub fn new() -> Self {
        let () = Self::DIMENSION_SUPPORTED;
        let d = D as f64;
        let mut points = Vec::new();
        points.push(([0.0; D], 0));
        for i in 0..D {
            for s in [-1.0, 1.0] {
                let mut x = [0.0; D];
                x[i] = s * L2;
                points.push((x, 1));
            }
        }
        for i in 0..D {
            for s in [-1.0, 1.0] {
                let mut x = [0.0; D];
                x[i] = s * L4;
                points.push((x, 2));
            }
        }
        for i in 0..D {
            for j in i + 1..D {
                for (si, sj) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
                    let mut x = [0.0; D];
                    x[i] = si * L4;
                    x[j] = sj * L4;
                    points.push((x, 3));
                }
            }
        }
        for mask in 0..(1usize << D) {
            let mut x = [0.0; D];
            for (k, xk) in x.iter_mut().enumerate() {
                *xk = if mask >> k & 1 == 1 { L5 } else { -L5 };
            }
            points.push((x, 4));
        }
        // Weights for the average over [-1,1]^D (they sum to 1 with multiplicities).
        let w7 = [
            (12824.0 - 9120.0 * d + 400.0 * d * d) / 19683.0,
            980.0 / 6561.0,
            (1820.0 - 400.0 * d) / 19683.0,
            200.0 / 19683.0,
            6859.0 / 19683.0 / (1u64 << D) as f64,
        ];
        let w5 = [
            (729.0 - 950.0 * d + 50.0 * d * d) / 729.0,
            245.0 / 486.0,
            (265.0 - 100.0 * d) / 1458.0,
            25.0 / 729.0,
            0.0,
        ];
        Rule { points, w7, w5 }
    }

    /// Number of integrand evaluations per region: 2^D + 2D² + 2D + 1.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

struct Region<const D: usize> {
    center: [f64; D],
    half: [f64; D],
    value: Vec<f64>,
    error: Vec<f64>,
    /// Largest component error: the priority.
    worst: f64,
    split_axis: usize,
    /// Creation order, for deterministic tie-breaking and final summation order.
    id: usize,
}

impl<const D: usize> PartialEq for Region<D> {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl<const D: usize> Eq for Region<D> {}
impl<const D: usize> PartialOrd for Region<D> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl<const D: usize> Ord for Region<D> {
    fn cmp(&self, other: &Self) -> Ordering {
        // Max-heap on error; among equal errors the older region first.
        self.worst.total_cmp(&other.worst).then_with(|| other.id.cmp(&self.id))
    }
}

/// Apply the rule to one box; `f(x, out)` writes `ncomp` values at point x.
fn apply<const D: usize, F: FnMut(&[f64; D], &mut [f64])>(
    rule: &Rule<D>,
    f: &mut F,
    center: [f64; D],
    half: [f64; D],
    ncomp: usize,
    buf: &mut Vec<f64>,
    id: usize,
) -> Region<D> {
    let vol: f64 = half.iter().map(|h| 2.0 * h).product();
    let mut s7 = vec![0.0; ncomp];
    let mut s5 = vec![0.0; ncomp];
    // Per-axis second differences for the split heuristic: f(±λ2) and f(±λ4) sums.
    let mut d2 = [0.0f64; D];
    let mut d4 = [0.0f64; D];
    let mut f0 = 0.0;
    buf.resize(ncomp, 0.0);
    for (x, class) in &rule.points {
        let mut pt = [0.0; D];
        for k in 0..D {
            pt[k] = center[k] + half[k] * x[k];
        }
        buf.iter_mut().for_each(|v| *v = 0.0);
        f(&pt, buf);
        let (w7, w5) = (rule.w7[*class], rule.w5[*class]);
        let mut norm1 = 0.0;
        for c in 0..ncomp {
            let v = if buf[c].is_finite() { buf[c] } else { 0.0 };
            s7[c] += w7 * v;
            s5[c] += w5 * v;
            norm1 += v.abs();
        }
        match class {
            0 => f0 = norm1,
            1 | 2 => {
                let axis = (0..D).find(|&k| x[k] != 0.0).unwrap_or(0);
                if *class == 1 {
                    d2[axis] += norm1;
                } else {
                    d4[axis] += norm1;
                }
            }
            _ => {}
        }
    }
    let value: Vec<f64> = s7.iter().map(|s| s * vol).collect();
    let error: Vec<f64> = s7.iter().zip(&s5).map(|(a, b)| ((a - b) * vol).abs()).collect();
    let worst = error.iter().cloned().fold(0.0, f64::max);
    // Fourth difference along each axis (ratio λ2²/λ4² = 1/7); ties → the widest axis.
    let mut split_axis = 0;
    let mut best = -1.0;
    for k in 0..D {
        let diff = ((d2[k] - 2.0 * f0) - (d4[k] - 2.0 * f0) / 7.0).abs();
        let better = diff > best * (1.0 + 1e-12) || (diff >= best * (1.0 - 1e-12) && half[k] > half[split_axis]);
        if better {
            best = diff.max(best);
            split_axis = k;
        }
    }
    Region { center, half, value, error, worst, split_axis, id }
}

/// Integrate `f` (ncomp components) over the union of the boxes `initial` (each `(lo, hi)`), adaptively,
/// until every component's summed error is ≤ max(atol, rtol·|I|) or `max_evals` is reached.
/// Non-finite integrand values are counted as 0 (callers never produce them on purpose; a test guards it).
pub fn integrate<const D: usize, F: FnMut(&[f64; D], &mut [f64])>(
    mut f: F,
    ncomp: usize,
    initial: &[([f64; D], [f64; D])],
    opts: &Options,
) -> Estimate {
    let rule = Rule::<D>::new();
    let npts = rule.len();
    let mut buf = Vec::with_capacity(ncomp);
    let mut heap = BinaryHeap::new();
    let mut total = vec![0.0; ncomp];
    let mut err = vec![0.0; ncomp];
    let mut evals = 0usize;
    let mut next_id = 0usize;
    for (lo, hi) in initial {
        let mut c = [0.0; D];
        let mut h = [0.0; D];
        let mut degenerate = false;
        for k in 0..D {
            c[k] = 0.5 * (lo[k] + hi[k]);
            h[k] = 0.5 * (hi[k] - lo[k]);
            if !(h[k] > 0.0) {
                degenerate = true;
            }
        }
        if degenerate {
            continue;
        }
        let r = apply(&rule, &mut f, c, h, ncomp, &mut buf, next_id);
        next_id += 1;
        evals += npts;
        for k in 0..ncomp {
            total[k] += r.value[k];
            err[k] += r.error[k];
        }
        heap.push(r);
    }
    let done =
        |total: &[f64], err: &[f64]| total.iter().zip(err).all(|(t, e)| *e <= opts.atol.max(opts.rtol * t.abs()));
    let mut converged = done(&total, &err);
    while !converged && evals + 2 * npts <= opts.max_evals {
        let Some(r) = heap.pop() else { break };
        let ax = r.split_axis;
        let mut half = r.half;
        half[ax] *= 0.5;
        let mut c1 = r.center;
        let mut c2 = r.center;
        c1[ax] -= half[ax];
        c2[ax] += half[ax];
        let a = apply(&rule, &mut f, c1, half, ncomp, &mut buf, next_id);
        let b = apply(&rule, &mut f, c2, half, ncomp, &mut buf, next_id + 1);
        next_id += 2;
        evals += 2 * npts;
        for k in 0..ncomp {
            total[k] += a.value[k] + b.value[k] - r.value[k];
            err[k] += a.error[k] + b.error[k] - r.error[k];
        }
        heap.push(a);
        heap.push(b);
        converged = done(&total, &err);
    }
    // Final sums recomputed in creation order with compensated summation: incremental updates drift.
    let mut regions: Vec<Region<D>> = heap.into_vec();
    regions.sort_by_key(|r| r.id);
    let mut value = vec![0.0; ncomp];
    let mut error = vec![0.0; ncomp];
    for k in 0..ncomp {
        value[k] = neumaier(regions.iter().map(|r| r.value[k]));
        error[k] = neumaier(regions.iter().map(|r| r.error[k]));
    }
    let converged = done(&value, &error);
    Estimate { value, error, evaluations: evals, regions: regions.len(), converged }
}

/// Neumaier's compensated sum.
fn neumaier(xs: impl Iterator<Item = f64>) -> f64 {
    let (mut s, mut c) = (0.0f64, 0.0f64);
    for x in xs {
        let t = s + x;
        if s.abs() >= x.abs() {
            c += (s - t) + x;
        } else {
            c += (x - t) + s;
        }
        s = t;
    }
    s + c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one() {
        for_dims();
        fn check<const D: usize>() {
            let r = Rule::<D>::new();
            let (mut s7, mut s5) = (0.0, 0.0);
            for (_, c) in &r.points {
                s7 += r.w7[*c];
                s5 += r.w5[*c];
            }
            assert!((s7 - 1.0).abs() < 1e-14, "D={D} s7={s7}");
            assert!((s5 - 1.0).abs() < 1e-14, "D={D} s5={s5}");
            assert_eq!(r.len(), (1 << D) + 2 * D * D + 2 * D + 1);
        }
        fn for_dims() {
            check::<2>();
            check::<3>();
            check::<4>();
        }
    }

    #[test]
    fn degree_seven_exact() {
        // x0^6 x1 ... the rule integrates polynomials of degree 7 exactly on one region.
        let est = integrate::<4, _>(
            |x, o| o[0] = x[0].powi(6) + x[1].powi(4) * x[2].powi(2) + x[3].powi(7) + 1.0,
            1,
            &[([-1.0; 4], [1.0; 4])],
            &Options { rtol: 1.0, atol: 1.0, max_evals: 57 },
        );
        let exact = 16.0 * (1.0 / 7.0 + 1.0 / 5.0 / 3.0 + 0.0 + 1.0);
        assert!((est.value[0] - exact).abs() < 1e-13, "{} vs {exact}", est.value[0]);
    }

    #[test]
    fn gaussian_2d_with_error_honesty() {
        // ∫∫ exp(-(x²+y²)/(2σ²)) over [-1,1]² = 2πσ² erf(1/(σ√2))²
        for sigma in [0.3, 0.05] {
            let est = integrate::<2, _>(
                |x, o| o[0] = (-(x[0] * x[0] + x[1] * x[1]) / (2.0 * sigma * sigma)).exp(),
                1,
                &[
                    ([-1.0, -1.0], [0.0, 0.0]),
                    ([0.0, -1.0], [1.0, 0.0]),
                    ([-1.0, 0.0], [0.0, 1.0]),
                    ([0.0, 0.0], [1.0, 1.0]),
                ],
                &Options { rtol: 1e-9, atol: 0.0, max_evals: 10_000_000 },
            );
            let e = libm::erf(1.0 / (sigma * 2f64.sqrt()));
            let exact = 2.0 * std::f64::consts::PI * sigma * sigma * e * e;
            let actual = (est.value[0] - exact).abs();
            assert!(est.converged);
            assert!(actual <= est.error[0], "σ={sigma}: actual {actual:e} > estimate {:e}", est.error[0]);
            assert!(actual / exact < 1e-9);
        }
    }

    #[test]
    fn deterministic_bits() {
        let run = || {
            integrate::<4, _>(
                |x, o| {
                    o[0] = (x[0] * x[1] + x[2]).sin().powi(2) / (1.0 + x[3] * x[3]);
                    o[1] = (-x[0] * x[0] * 30.0).exp();
                },
                2,
                &[([0.0; 4], [1.0; 4])],
                &Options { rtol: 1e-7, atol: 0.0, max_evals: 2_000_000 },
            )
        };
        let (a, b) = (run(), run());
        assert_eq!(a.value[0].to_bits(), b.value[0].to_bits());
        assert_eq!(a.value[1].to_bits(), b.value[1].to_bits());
        assert_eq!(a.evaluations, b.evaluations);
    }

    #[test]
    fn reports_non_convergence() {
        let est = integrate::<2, _>(
            |x, o| o[0] = if x[0] > 0.3 { 1.0 } else { 0.0 },
            1,
            &[([0.0, 0.0], [1.0, 1.0])],
            &Options { rtol: 1e-14, atol: 0.0, max_evals: 1000 },
        );
        assert!(!est.converged);
        assert!(est.evaluations <= 1000);
    }
}
