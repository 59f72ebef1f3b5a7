//! One-dimensional Gauss rules: the n-point Gauss–Legendre rule (fixed panels of smooth 1-D integrals: the
//! paint's diffuse Fresnel reflectance) and an adaptive Gauss–Kronrod G7/K15 driver (the directional albedo's
//! radial and azimuthal integrals). The crate's one copy of each; the independent references in
//! `instrument/reference.rs` and `tests/` keep their own on purpose, so that they share no code with these.
use std::f64::consts::PI;

/// Nodes and weights of the n-point Gauss–Legendre rule on [−1, 1] (Newton iteration on P_n from the
/// Tricomi initial guesses; Abramowitz & Stegun 25.4.29; Press et al., Numerical Recipes §4.6 `gauleg`).
pub(crate) fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    let nf = n as f64;
    for i in 0..n.div_ceil(2) {
        let mut z = (PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(z) and P_{n−1}(z) by the three-term recurrence.
            let (mut p_prev, mut p) = (0.0, 1.0);
            for j in 0..n {
                let jf = j as f64;
                let p_next = ((2.0 * jf + 1.0) * z * p - jf * p_prev) / (jf + 1.0);
                p_prev = p;
                p = p_next;
            }
            dp = nf * (z * p - p_prev) / (z * z - 1.0);
            let dz = p / dp;
            z -= dz;
            if dz.abs() <= 1e-15 {
                break;
            }
        }
        x[i] = -z;
        x[n - 1 - i] = z;
        let wi = 2.0 / ((1.0 - z * z) * dp * dp);
        w[i] = wi;
        w[n - 1 - i] = wi;
    }
    (x, w)
}

/// The largest order [`gauss_legendre_table`] holds.
pub(crate) const TABLE_MAX_ORDER: usize = 64;

/// The n-point Gauss–Legendre rule on [−1, 1] (1 ≤ n ≤ [`TABLE_MAX_ORDER`]) from a table computed once per
/// process by [`gauss_legendre`] (the same bits), so that a rule raised level by level in a hot loop
/// (`instrument::method`'s polar and Gauss–Hermite rules) neither recomputes nor allocates its nodes.
pub(crate) fn gauss_legendre_table(n: usize) -> (&'static [f64], &'static [f64]) {
    static TABLE: RuleTable = RuleTable::new();
    from_table(&TABLE, n, TABLE_MAX_ORDER, gauss_legendre, "Gauss–Legendre")
}

/// Rules of orders 1..=max, built once per process.
pub(crate) type RuleTable = std::sync::OnceLock<Vec<(Vec<f64>, Vec<f64>)>>;

/// The n-point rule of `table`, which `build` fills with the orders 1..=`max` on first use (the same bits as
/// `build(n)`); `name` is the rule's, for the message if n is outside the table.
pub(crate) fn from_table(
    table: &'static RuleTable,
    n: usize,
    max: usize,
    build: fn(usize) -> (Vec<f64>, Vec<f64>),
    name: &str,
) -> (&'static [f64], &'static [f64]) {
    assert!((1..=max).contains(&n), "{name} order {n} outside the table");
    let (x, w) = &table.get_or_init(|| (1..=max).map(build).collect())[n - 1];
    (x, w)
}

/// Kronrod 15-point nodes (non-negative half) and weights, and the embedded Gauss 7-point weights
/// (QUADPACK `qk15`).
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
/// Gauss weights for the nodes XGK[1], XGK[3], XGK[5], XGK[7].
const WG: [f64; 4] =
    [0.129_484_966_168_869_7, 0.279_705_391_489_276_7, 0.381_830_050_505_118_9, 0.417_959_183_673_469_4];

/// One G7/K15 panel of a vector integrand of `n` components: (K15 values, max |K15 − G7| over the first
/// `checked` components).
fn gk15(
    f: &mut dyn FnMut(f64, &mut [f64]),
    a: f64,
    b: f64,
    n: usize,
    checked: usize,
    tmp: &mut [f64],
) -> (Vec<f64>, f64) {
    let c = 0.5 * (a + b);
    let hw = 0.5 * (b - a);
    let mut k = vec![0.0; n];
    let mut g = vec![0.0; n];
    for j in 0..8 {
        let signs: &[f64] = if j == 7 { &[0.0] } else { &[-1.0, 1.0] };
        for &s in signs {
            f(c + s * hw * XGK[j], tmp);
            for i in 0..n {
                k[i] += WGK[j] * tmp[i];
                if j % 2 == 1 {
                    g[i] += WG[j / 2] * tmp[i];
                }
            }
        }
    }
    let mut err: f64 = 0.0;
    for i in 0..n {
        k[i] *= hw;
        g[i] *= hw;
        if i < checked {
            err = err.max((k[i] - g[i]).abs());
        }
    }
    (k, err)
}

/// Adaptive G7/K15 over the partition `breaks` (increasing), bisecting the worst panel until the summed
/// error is ≤ `tol` or `max_panels` is reached. Returns (integral, error estimate).
/// Only the first `checked` components drive the error (the others are carried along).
pub(crate) fn adaptive(
    f: &mut dyn FnMut(f64, &mut [f64]),
    breaks: &[f64],
    n: usize,
    checked: usize,
    tol: f64,
    max_panels: usize,
) -> (Vec<f64>, f64) {
    let mut tmp = vec![0.0; n];
    let mut panels: Vec<(f64, f64, Vec<f64>, f64)> = breaks
        .windows(2)
        .filter(|w| w[1] > w[0])
        .map(|w| {
            let (v, e) = gk15(f, w[0], w[1], n, checked, &mut tmp);
            (w[0], w[1], v, e)
        })
        .collect();
    loop {
        let total: f64 = panels.iter().map(|p| p.3).sum();
        if total <= tol || panels.len() >= max_panels {
            break;
        }
        // Bisect the panel with the largest error (first one on ties: deterministic).
        let (idx, _) =
            panels.iter().enumerate().fold((0, -1.0), |acc, (i, p)| if p.3 > acc.1 { (i, p.3) } else { acc });
        let (a, b, _, _) = panels.swap_remove(idx);
        let m = 0.5 * (a + b);
        if !(m > a && m < b) {
            break; // cannot bisect further in floating point
        }
        let (v1, e1) = gk15(f, a, m, n, checked, &mut tmp);
        let (v2, e2) = gk15(f, m, b, n, checked, &mut tmp);
        panels.push((a, m, v1, e1));
        panels.push((m, b, v2, e2));
    }
    // Sum in a fixed (left-to-right) order so the result does not depend on the bisection history's order.
    panels.sort_by(|p, q| p.0.total_cmp(&q.0));
    let mut sum = vec![0.0; n];
    let mut err = 0.0;
    for p in &panels {
        for (s, v) in sum.iter_mut().zip(&p.2) {
            *s += v;
        }
        err += p.3;
    }
    (sum, err)
}
