//! Piecewise Chebyshev tables of smooth optical functions of one variable, with their error verified
//! when they are built.
//!
//! Why: a flake's reflectance depends on direction only through the local cosine, but computing it
//! (a thin-film stack: complex square roots and exponentials for two polarisations and three interfaces)
//! costs hundreds of nanoseconds, and the aperture integral evaluates it tens of thousands of times per
//! reading. The function is smooth on [0, 1], so a piecewise Chebyshev interpolant reproduces it to
//! ~1e-15 in a few nanoseconds. The table is accepted only if its deviation from the function, measured at
//! check points interleaved with the interpolation nodes on every piece, is below the requested
//! tolerance; otherwise the caller keeps evaluating the function directly.
//!
//! Method: on each of `pieces` equal sub-intervals, the degree-(N−1) interpolant at the N Chebyshev–Gauss
//! nodes, stored as Chebyshev coefficients c_k = (2/N) Σ_j f(x_j) cos(πk(j + ½)/N) (c₀ halved) and
//! evaluated by Clenshaw's recurrence (Trefethen, *Approximation Theory and Approximation Practice*, 2013,
//! ch. 3–4; Press et al., *Numerical Recipes* §5.8).
//!
//! A function that is continuous but kinks like √|x − c| at known points c (a reflectance at a critical angle
//! of total internal reflection) converges only algebraically under one interpolant across c, so no table of
//! at most `MAX_PIECES` pieces meets a tolerance of 10⁻¹². For it the table is cut at every kink and midway
//! between two, and each segment that ends on a kink c is tabulated in s ∈ [0, 1] with x = c + h·s² (h the
//! signed distance from c to the segment's other end), which turns √|x − c| into the smooth |h|^½·s: the
//! substitution the hemispherical mean already uses (`brdf::paint::hemispherical_mean`; `docs/model.md`
//! §Evaluation cost, "Tables cut at the kinks"). Each segment has the same number of equal pieces in s.
//!
//! At the kink: the function's own value within a few ulp of c is ill-conditioned (√ of a rounding error: a
//! Fresnel reflectance at the computed critical cosine is off by ~10⁻⁸ when the computed c is an ulp on the
//! other side of where the function's own arithmetic puts the edge), so the check points of a segment that
//! ends on a kink leave out the kink itself (s = 0); the table's value there is the limit of both segments.
//! Interpolation nodes never fall on it (Chebyshev–Gauss nodes are interior).

/// Interpolation nodes per piece (degree N − 1).
pub(crate) const N: usize = 16;
/// Largest number of pieces tried before giving up.
const MAX_PIECES: usize = 1024;

/// A verified piecewise Chebyshev table on [a, b].
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ChebTable {
    a: f64,
    b: f64,
    pieces: usize,
    /// pieces × N coefficients.
    coeffs: Vec<f64>,
    /// Empty: `pieces` equal pieces of [a, b]. Otherwise the segments cut at the kinks ([`Segment`], in
    /// increasing x), each of `pieces / segments.len()` equal pieces in s.
    segments: Vec<Segment>,
    /// Largest |table − f| found at the check points.
    pub max_error: f64,
}

/// A point at which a table asks for its function's value: x and, on a segment at a kink c, x's offset from c
/// as the segment variable gives it, h·s² (x is c + h·s² rounded, so x − c recomputed from x can lose the low
/// bits that the offset keeps). A function whose own arithmetic cancels next to c (a layer's cosine at its
/// critical cosine, `optics::fresnel::ncos_near_critical`) takes the offset (`docs/model.md` §Evaluation
/// cost, "Where the direct evaluation is the noise").
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Abscissa {
    pub x: f64,
    pub kink: Option<KinkOffset>,
}

/// x − c for a kink c, exactly as the caller has it ([`Abscissa`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct KinkOffset {
    /// The kink c.
    pub at: f64,
    /// x − c.
    pub offset: f64,
}

/// A segment of a table cut at kinks: x = from + h·s², s ∈ [0, 1], `from` a kink; it covers [lo, hi].
#[derive(Clone, Copy, Debug, PartialEq)]
struct Segment {
    from: f64,
    h: f64,
    lo: f64,
    hi: f64,
}

impl Segment {
    /// x = from + h·s² at s, and its offset h·s² from the kink.
    #[inline]
    fn at(&self, s: f64) -> Abscissa {
        let offset = self.h * s * s;
        Abscissa { x: self.from + offset, kink: Some(KinkOffset { at: self.from, offset }) }
    }

    /// s at x (clamped into [0, 1]).
    #[inline]
    fn s(&self, x: f64) -> f64 {
        ((x - self.from) / self.h).max(0.0).sqrt().min(1.0)
    }
}

/// The segments of [a, b] cut at `kinks` (sorted, distinct, inside (a, b)) and midway between two: from each
/// kink down to the cut below it and up to the cut above it. Empty without kinks.
fn segments(a: f64, b: f64, kinks: &[f64]) -> Vec<Segment> {
    let mut out = Vec::with_capacity(2 * kinks.len());
    for (i, &c) in kinks.iter().enumerate() {
        let below = if i == 0 { a } else { 0.5 * (kinks[i - 1] + c) };
        let above = if i + 1 == kinks.len() { b } else { 0.5 * (c + kinks[i + 1]) };
        out.push(Segment { from: c, h: below - c, lo: below, hi: c });
        out.push(Segment { from: c, h: above - c, lo: c, hi: above });
    }
    out
}

impl ChebTable {
    /// Fit `f` on [a, b] with doubling numbers of pieces (from 8) until the deviation at the check points
    /// (the N + 1 Chebyshev–Lobatto points of every piece, which interleave the nodes and include the piece
    /// ends) is ≤ `tol`. `None` if no table of at most `MAX_PIECES` pieces meets it, or if `f` is not finite.
    pub(crate) fn fit(f: impl Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> Option<ChebTable> {
        ChebTable::fit_each(|x, _, v| v[0] = f(x), 1, a, b, tol).pop().flatten()
    }

    /// [`ChebTable::fit`] of `count` functions f_0 … f_{count−1} on the same [a, b] at once: the same tables to
    /// the bit as fitting each alone, but every point is asked of all the functions that need it in one call,
    /// `f(x, which, values)` setting `values[i]` = f_{which[i]}(x), so that work they share at one x (a film
    /// stack's angles and interface amplitudes, the same for every wavelength) is done once. A function whose
    /// table is met leaves `which` at the next piece count.
    pub(crate) fn fit_each(
        f: impl FnMut(f64, &[usize], &mut [f64]),
        count: usize,
        a: f64,
        b: f64,
        tol: f64,
    ) -> Vec<Option<ChebTable>> {
        let mut f = f;
        ChebTable::fit_each_kinked(|p: Abscissa, w: &[usize], v: &mut [f64]| f(p.x, w, v), count, a, b, &[], tol)
    }

    /// [`ChebTable::fit`] of a function that kinks at `kinks` (sorted, distinct; those outside (a, b) are
    /// ignored): the table cut there (module doc). Without kinks, `fit` itself.
    #[cfg(test)]
    pub(crate) fn fit_kinked(f: impl Fn(f64) -> f64, a: f64, b: f64, kinks: &[f64], tol: f64) -> Option<ChebTable> {
        ChebTable::fit_each_kinked(|p: Abscissa, _: &[usize], v: &mut [f64]| v[0] = f(p.x), 1, a, b, kinks, tol)
            .pop()
            .flatten()
    }

    /// [`ChebTable::fit_each`] of functions that all kink at `kinks` ([`ChebTable::fit_kinked`]), asked at
    /// [`Abscissa`]s (with the offset from the kink on a segment at one). The piece counts tried are those of
    /// `fit_each` (8, 16, …), shared among the segments (at least one each).
    pub(crate) fn fit_each_kinked(
        mut f: impl FnMut(Abscissa, &[usize], &mut [f64]),
        count: usize,
        a: f64,
        b: f64,
        kinks: &[f64],
        tol: f64,
    ) -> Vec<Option<ChebTable>> {
        let kinks: Vec<f64> = kinks.iter().copied().filter(|&c| c > a && c < b).collect();
        let segs = segments(a, b, &kinks);
        let mut out = vec![None; count];
        let mut which: Vec<usize> = (0..count).collect();
        let mut pieces = 8usize.next_multiple_of(segs.len().max(1));
        while !which.is_empty() && pieces <= MAX_PIECES {
            let fits = ChebTable::fit_pieces(&mut f, &which, a, b, &segs, pieces, tol);
            let mut missed = Vec::new();
            for (&i, fit) in which.iter().zip(fits) {
                match fit {
                    Fit::Met(t) => out[i] = Some(t),
                    Fit::NotFinite => {}
                    Fit::Missed => missed.push(i),
                }
            }
            which = missed;
            pieces *= 2;
        }
        out
    }

    /// The tables of `pieces` pieces of the functions `which` of `f` at once (as [`ChebTable::fit_each`]),
    /// each if its deviation at the check points is ≤ `tol`: one result per entry of `which`.
    #[cfg(test)]
    pub(crate) fn fit_each_with_pieces(
        f: impl FnMut(f64, &[usize], &mut [f64]),
        which: &[usize],
        a: f64,
        b: f64,
        pieces: usize,
        tol: f64,
    ) -> Vec<Option<ChebTable>> {
        let mut f = f;
        let g = |p: Abscissa, w: &[usize], v: &mut [f64]| f(p.x, w, v);
        ChebTable::fit_each_kinked_with_pieces(g, which, a, b, &[], pieces, tol)
    }

    /// [`ChebTable::fit_each_with_pieces`] of functions that kink at `kinks` ([`ChebTable::fit_kinked`]);
    /// `pieces` counts the pieces of all segments (a multiple of their number, as [`ChebTable::pieces`] gives).
    pub(crate) fn fit_each_kinked_with_pieces(
        mut f: impl FnMut(Abscissa, &[usize], &mut [f64]),
        which: &[usize],
        a: f64,
        b: f64,
        kinks: &[f64],
        pieces: usize,
        tol: f64,
    ) -> Vec<Option<ChebTable>> {
        let kinks: Vec<f64> = kinks.iter().copied().filter(|&c| c > a && c < b).collect();
        let segs = segments(a, b, &kinks);
        if !pieces.is_multiple_of(segs.len().max(1)) {
            return vec![None; which.len()];
        }
        ChebTable::fit_pieces(&mut f, which, a, b, &segs, pieces, tol)
            .into_iter()
            .map(|fit| match fit {
                Fit::Met(t) => Some(t),
                _ => None,
            })
            .collect()
    }

    /// One piece count for the functions `which` of `f`: each one's outcome. Piece by piece from a: a piece's
    /// nodes, then its check points (after the nodes of every piece they lie in, the next one at its upper
    /// end), so a function stops being evaluated at the first piece where it misses `tol` or is not finite
    /// (`docs/model.md` §Evaluation cost, "A failed attempt stops at its first missed piece"). A met table
    /// is the same bits as with every node first: the same nodes, coefficients and check points.
    fn fit_pieces(
        f: &mut impl FnMut(Abscissa, &[usize], &mut [f64]),
        which: &[usize],
        a: f64,
        b: f64,
        segments: &[Segment],
        pieces: usize,
        tol: f64,
    ) -> Vec<Fit> {
        if which.is_empty() {
            return Vec::new();
        }
        // cos(πk(j + ½)/N) and the nodes cos(π(j + ½)/N), once per fit rather than per piece.
        let nodes: [f64; N] = std::array::from_fn(|j| (std::f64::consts::PI * (j as f64 + 0.5) / N as f64).cos());
        let basis: [[f64; N]; N] = std::array::from_fn(|k| {
            std::array::from_fn(|j| (std::f64::consts::PI * k as f64 * (j as f64 + 0.5) / N as f64).cos())
        });
        let m = which.len();
        let width = (b - a) / pieces as f64;
        // Piece p's variable: x itself on [a, b] (no segments), else s of its segment, and x at a value of it.
        let per = pieces / segments.len().max(1);
        let (sw, seg) = (1.0 / per as f64, |p: usize| segments[p / per]);
        let range = |p: usize| match segments.is_empty() {
            true => (a + p as f64 * width, a + (p + 1) as f64 * width),
            false => ((p % per) as f64 * sw, (p % per + 1) as f64 * sw),
        };
        let to_x = |p: usize, u: f64| match segments.is_empty() {
            true => Abscissa { x: u, kink: None },
            false => seg(p).at(u),
        };
        let mut tables: Vec<ChebTable> = (0..m)
            .map(|_| ChebTable {
                a,
                b,
                pieces,
                coeffs: vec![0.0; pieces * N],
                segments: segments.to_vec(),
                max_error: 0.0,
            })
            .collect();
        // The functions still evaluated (indices into `which`), and the outcome of those that are not.
        let mut live: Vec<usize> = (0..m).collect();
        let mut out: Vec<Option<Fit>> = (0..m).map(|_| None).collect();
        let mut worst = vec![0.0f64; m];
        let mut vals = vec![[0.0; N]; m];
        let mut at = vec![0.0; m];
        let mut done = 0; // pieces whose coefficients are in `tables`
        for p in 0..pieces {
            if live.is_empty() {
                break;
            }
            let (lo, hi) = range(p);
            for j in 0..=N {
                // Not at a kink itself (s = 0, the first piece's lower end): there the function's own value is
                // ill-conditioned, not the table's (module doc, "At the kink").
                if !segments.is_empty() && p % per == 0 && j == N {
                    continue;
                }
                let u = 0.5 * (lo + hi) + 0.5 * (hi - lo) * (std::f64::consts::PI * j as f64 / N as f64).cos();
                let x = to_x(p, u);
                let q = tables[0].locate(x.x).0.max(p);
                while done <= q && !live.is_empty() {
                    ChebTable::fit_piece(
                        f,
                        which,
                        &mut live,
                        &mut out,
                        &mut tables,
                        &mut vals,
                        &mut at,
                        done,
                        |u| {
                            let (lo, hi) = range(done);
                            to_x(done, 0.5 * (lo + hi) + 0.5 * (hi - lo) * u)
                        },
                        &nodes,
                        &basis,
                    );
                    done += 1;
                }
                if live.is_empty() {
                    break;
                }
                let sub: Vec<usize> = live.iter().map(|&i| which[i]).collect();
                f(x, &sub, &mut at[..live.len()]);
                for (&i, y) in live.iter().zip(&at) {
                    worst[i] = worst[i].max((tables[i].eval(x.x) - y).abs());
                }
                live.retain(|&i| match worst[i] <= tol {
                    true => true,
                    false => {
                        out[i] = Some(Fit::Missed);
                        false
                    }
                });
            }
        }
        tables
            .into_iter()
            .zip(worst)
            .zip(out)
            .map(|((mut table, worst), out)| {
                out.unwrap_or_else(|| {
                    table.max_error = worst;
                    Fit::Met(table)
                })
            })
            .collect()
    }

    /// Piece `p` of the tables of the functions `live` (indices into `which`): f at its N nodes (`node(t)`
    /// the abscissa at t ∈ [−1, 1]) and their Chebyshev coefficients; a function with a value that is not
    /// finite leaves `live` as [`Fit::NotFinite`].
    #[allow(clippy::too_many_arguments)]
    fn fit_piece(
        f: &mut impl FnMut(Abscissa, &[usize], &mut [f64]),
        which: &[usize],
        live: &mut Vec<usize>,
        out: &mut [Option<Fit>],
        tables: &mut [ChebTable],
        vals: &mut [[f64; N]],
        at: &mut [f64],
        p: usize,
        node: impl Fn(f64) -> Abscissa,
        nodes: &[f64; N],
        basis: &[[f64; N]; N],
    ) {
        let sub: Vec<usize> = live.iter().map(|&i| which[i]).collect();
        for (j, x) in nodes.iter().enumerate() {
            f(node(*x), &sub, &mut at[..live.len()]);
            for (&i, y) in live.iter().zip(at.iter()) {
                vals[i][j] = *y;
            }
        }
        live.retain(|&i| match vals[i].iter().all(|y| y.is_finite()) {
            true => true,
            false => {
                out[i] = Some(Fit::NotFinite);
                false
            }
        });
        for &i in live.iter() {
            let c = &mut tables[i].coeffs[p * N..(p + 1) * N];
            for (k, row) in basis.iter().enumerate() {
                let mut s = 0.0;
                for (v, b) in vals[i].iter().zip(row) {
                    s += v * b;
                }
                c[k] = if k == 0 { s / N as f64 } else { 2.0 * s / N as f64 };
            }
        }
    }

    pub(crate) fn pieces(&self) -> usize {
        self.pieces
    }

    /// Whether `other` has the same interval and pieces (so one [`ChebTable::locate`] serves both).
    pub(crate) fn same_grid(&self, other: &ChebTable) -> bool {
        self.a == other.a && self.b == other.b && self.pieces == other.pieces && self.segments == other.segments
    }

    /// Whether the table is cut at kinks ([`ChebTable::fit_kinked`]).
    pub(crate) fn kinked(&self) -> bool {
        !self.segments.is_empty()
    }

    /// The piece of x (clamped into [a, b]) and x's position t ∈ [−1, 1] in it (in s on a segment at a kink).
    #[inline]
    pub(crate) fn locate(&self, x: f64) -> (usize, f64) {
        let x = x.clamp(self.a, self.b);
        if !self.segments.is_empty() {
            return self.locate_on_segments(x);
        }
        let width = (self.b - self.a) / self.pieces as f64;
        let p = (((x - self.a) / width) as usize).min(self.pieces - 1);
        let lo = self.a + p as f64 * width;
        (p, 2.0 * (x - lo) / width - 1.0)
    }

    /// [`ChebTable::locate`] on a table cut at kinks: the segment holding x (the last whose lower end is ≤ x),
    /// s there, and the piece of s.
    fn locate_on_segments(&self, x: f64) -> (usize, f64) {
        let i = self.segments.iter().rposition(|g| g.lo <= x).unwrap_or(0);
        let per = self.pieces / self.segments.len();
        let s = self.segments[i].s(x);
        let width = 1.0 / per as f64;
        let p = ((s / width) as usize).min(per - 1);
        (i * per + p, 2.0 * (s - p as f64 * width) / width - 1.0)
    }

    /// The N Chebyshev coefficients of piece `p`.
    #[inline]
    pub(crate) fn piece(&self, p: usize) -> &[f64; N] {
        self.coeffs[p * N..(p + 1) * N].try_into().expect("N coefficients per piece")
    }

    /// The interpolant at x (clamped into [a, b]).
    #[inline]
    pub(crate) fn eval(&self, x: f64) -> f64 {
        let (p, t) = self.locate(x);
        clenshaw(self.piece(p), t)
    }

    /// The table Σ_j w_j T_j of tables on one grid: its coefficients are the weighted sums of theirs (the
    /// interpolant is linear in the coefficients), so it interpolates Σ_j w_j f_j with a deviation of at most
    /// Σ_j |w_j|·(T_j's deviation) plus rounding, which `max_error` states. None if the grids differ.
    pub(crate) fn combine(tables: &[ChebTable], weights: &[f64]) -> Option<ChebTable> {
        let first = tables.first()?;
        if tables.len() != weights.len() || tables.iter().any(|t| !t.same_grid(first)) {
            return None;
        }
        let mut coeffs = vec![0.0; first.coeffs.len()];
        for (t, w) in tables.iter().zip(weights) {
            for (c, x) in coeffs.iter_mut().zip(&t.coeffs) {
                *c += w * x;
            }
        }
        let max_error = tables.iter().zip(weights).map(|(t, w)| w.abs() * t.max_error).sum::<f64>();
        Some(ChebTable {
            a: first.a,
            b: first.b,
            pieces: first.pieces,
            coeffs,
            segments: first.segments.clone(),
            max_error,
        })
    }
}

/// The outcome of one piece count.
enum Fit {
    Met(ChebTable),
    Missed,
    NotFinite,
}

/// The Chebyshev polynomials T_0(t) … T_{N−1}(t) by their recurrence T_{k+1} = 2t T_k − T_{k−1} (stable on
/// [−1, 1], |T_k| ≤ 1): with them, Σ_k c_k T_k(t) of several coefficient sets at one t is one dot product
/// each ([`dot`]), where Clenshaw's recurrence would be run once per set.
#[inline]
pub(crate) fn basis(t: f64) -> [f64; N] {
    let mut b = [0.0; N];
    basis_into(t, &mut b);
    b
}

/// T_0(t) … T_{n−1}(t) into `out` (n = its length), by the recurrence T_k = 2t T_{k−1} − T_{k−2}.
#[inline]
pub(crate) fn basis_into(t: f64, out: &mut [f64]) {
    let n = out.len();
    if n > 0 {
        out[0] = 1.0;
    }
    if n > 1 {
        out[1] = t;
    }
    for k in 2..n {
        out[k] = 2.0 * t * out[k - 1] - out[k - 2];
    }
}

/// The k-th of n Chebyshev–Gauss nodes on [lo, hi], (lo + hi)/2 + (hi − lo)/2 · cos(π(k + ½)/n) (descending
/// in k, the order [`coefficients`] takes its values in).
pub fn node_on(k: usize, n: usize, lo: f64, hi: f64) -> f64 {
    0.5 * (lo + hi) + 0.5 * (hi - lo) * (std::f64::consts::PI * (k as f64 + 0.5) / n as f64).cos()
}

/// Chebyshev coefficients c_k = (2/n) Σ_j f(x_j) cos(πk(j + ½)/n) (c₀ halved) of the interpolant through the
/// values at the n Chebyshev–Gauss nodes ([`node_on`]), for any n (the tables above use n = [`N`]).
pub fn coefficients(vals: &[f64]) -> Vec<f64> {
    let n = vals.len();
    (0..n)
        .map(|k| {
            let c: f64 = vals
                .iter()
                .enumerate()
                .map(|(j, v)| v * (std::f64::consts::PI * k as f64 * (j as f64 + 0.5) / n as f64).cos())
                .sum();
            if k == 0 {
                c / n as f64
            } else {
                2.0 * c / n as f64
            }
        })
        .collect()
}

/// Σ_k c_k T_k(t) from the [`basis`] at t.
#[inline]
pub(crate) fn dot(c: &[f64; N], basis: &[f64; N]) -> f64 {
    // Four partial sums (independent chains) added pairwise.
    let mut s = [0.0; 4];
    for (cc, bb) in c.chunks_exact(4).zip(basis.chunks_exact(4)) {
        for i in 0..4 {
            s[i] += cc[i] * bb[i];
        }
    }
    (s[0] + s[1]) + (s[2] + s[3])
}

/// Σ_k c_k T_k(t) by Clenshaw's recurrence: b_k = c_k + 2t b_{k+1} − b_{k+2}; f = c_0 + t b_1 − b_2.
#[inline]
pub(crate) fn clenshaw(c: &[f64; N], t: f64) -> f64 {
    let (mut b1, mut b2) = (0.0, 0.0);
    for &ck in c[1..].iter().rev() {
        let b0 = ck + 2.0 * t * b1 - b2;
        b2 = b1;
        b1 = b0;
    }
    c[0] + t * b1 - b2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_smooth_functions_and_reports_its_error() {
        let f = |x: f64| (3.0 * x).sin() * (-x).exp() + x.powi(5);
        let t = ChebTable::fit(f, 0.0, 1.0, 1e-13).unwrap();
        assert!(t.max_error <= 1e-13);
        for i in 0..=1000 {
            let x = i as f64 / 1000.0;
            assert!((t.eval(x) - f(x)).abs() < 1e-13, "x = {x}");
        }
    }

    #[test]
    fn refuses_what_it_cannot_represent() {
        // A jump cannot be interpolated to 1e-12 with any number of pieces that misses it...
        assert!(ChebTable::fit(|x| if x > 0.3141 { 1.0 } else { 0.0 }, 0.0, 1.0, 1e-12).is_none());
        assert!(ChebTable::fit(|x| 1.0 / (x - 0.5), 0.0, 1.0, 1e-12).is_none());
    }

    /// Fitted together, the functions get the tables each gets alone, to the bit (also one that needs more
    /// pieces than the others, and one that is not finite); no point is asked of no function.
    #[test]
    fn fitting_together_gives_each_function_its_own_table() {
        let fs: [fn(f64) -> f64; 4] = [
            |x| (3.0 * x).sin(),
            |x| (40.0 * x).cos() * (-x).exp(),
            |x| if x > 0.5 { f64::NAN } else { x },
            |x| x.powi(3),
        ];
        let calls = std::cell::Cell::new(0);
        let together = ChebTable::fit_each(
            |x, which, v| {
                assert!(!which.is_empty());
                calls.set(calls.get() + 1);
                for (v, &k) in v.iter_mut().zip(which) {
                    *v = fs[k](x);
                }
            },
            fs.len(),
            0.0,
            1.0,
            1e-12,
        );
        for (k, f) in fs.iter().enumerate() {
            let alone = ChebTable::fit(f, 0.0, 1.0, 1e-12);
            assert_eq!(format!("{alone:?}"), format!("{:?}", together[k]), "function {k}");
        }
        assert!(
            together[2].is_none() && together[1].as_ref().unwrap().pieces() > together[0].as_ref().unwrap().pieces()
        );
        let none = ChebTable::fit_each_with_pieces(|_, _, _| unreachable!(), &[], 0.0, 1.0, 8, 1e-12);
        assert!(none.is_empty() && calls.get() > 0);
    }

    /// A function that kinks like √|x − c| (a dielectric's Fresnel reflectance at its critical cosine, seen from
    /// the denser side) defeats every uniform table, and the table cut at the kink meets the tolerance with as
    /// few pieces as a smooth function (also at two kinks, one near an end), and reproduces it off its nodes.
    #[test]
    fn tables_cut_at_kinks_meet_the_tolerance_where_uniform_ones_cannot() {
        use crate::optics::fresnel::{critical_cosine_complex, fr_dielectric};
        let eta = 1.58 / 1.8;
        let c = critical_cosine_complex(num_complex::Complex64::new(eta, 0.0)).unwrap();
        let f = |x: f64| fr_dielectric(x, eta);
        assert!(ChebTable::fit(f, 0.0, 1.0, 1e-12).is_none());
        let t = ChebTable::fit_kinked(f, 0.0, 1.0, &[c], 1e-12).unwrap();
        assert!(t.kinked() && t.max_error <= 1e-12 && t.pieces() <= 16, "{} pieces", t.pieces());
        let two = |x: f64| (x - 0.3).abs().sqrt() * (2.0 * x).cos() + (x - 0.97).abs().sqrt();
        let t2 = ChebTable::fit_kinked(two, 0.0, 1.0, &[0.3, 0.97], 1e-12).unwrap();
        assert_eq!(t2.segments.len(), 4);
        for i in 0..=4999 {
            let x = i as f64 / 4999.0;
            assert!((t.eval(x) - f(x)).abs() < 2e-12, "x = {x}");
            assert!((t2.eval(x) - two(x)).abs() < 2e-12, "x = {x}");
        }
        // Kinks outside (a, b) are no kinks: the uniform table, to the bit.
        let smooth = |x: f64| (3.0 * x).sin();
        let plain = ChebTable::fit(smooth, 0.0, 1.0, 1e-12);
        assert_eq!(plain, ChebTable::fit_kinked(smooth, 0.0, 1.0, &[0.0, 1.0], 1e-12));
        // Tables cut at the same kinks share a grid and combine; cut elsewhere, they do not.
        let sum = ChebTable::combine(&[t.clone(), t.clone()], &[1.0, 0.5]).unwrap();
        assert!((sum.eval(0.5 * c) - 1.5 * f(0.5 * c)).abs() < 4e-12);
        assert!(ChebTable::combine(&[t, t2], &[1.0, 1.0]).is_none());
    }

    #[test]
    fn fresnel_conductor_and_thin_film_tables() {
        use crate::optics::fresnel::fr_conductor;
        use crate::optics::thin_film::{stack, FilmLayer};
        use num_complex::Complex64;
        let eta = Complex64::new(0.93, 6.33) / 1.5;
        let t = ChebTable::fit(|c| fr_conductor(c, eta), 0.0, 1.0, 1e-12).unwrap();
        let tio2 = FilmLayer { n: Complex64::new(2.5, 0.0), thickness_nm: 135.0, coherent: true };
        let mica = FilmLayer { n: Complex64::new(1.58, 0.0), thickness_nm: 400.0, coherent: false };
        let f = |c: f64| stack(1.5, &[tio2, mica, tio2], Complex64::new(1.5, 0.0), c, 546.1).r();
        let s = ChebTable::fit(f, 0.0, 1.0, 1e-12).unwrap();
        for i in 0..=997 {
            let c = i as f64 / 997.0;
            assert!((t.eval(c) - fr_conductor(c, eta)).abs() < 1e-12);
            assert!((s.eval(c) - f(c)).abs() < 1e-12);
        }
    }

    /// The Cerulean (c) pearl's stack (TiO₂ 135 nm / mica 400 nm / TiO₂ in resin η) at η = 1.5, 1.54, 1.56,
    /// 1.59 and 1.60 and 700, 546.1, 435.8 nm: its tables meet 10⁻¹² with at most 16 pieces, and at η = 1.58 (the
    /// mica's index: ρ's poles near μ = 0, a truncation error, `tools/pearl_table_noise.py` finds it too) with 32
    /// (`docs/model.md` §Evaluation cost, "Where the direct evaluation is the noise"). With the exit resin's cosine recomputed as
    /// √(η² − η²(1 − μ²)) and the mica's from μ next to the kink, the deviation found grew with the pieces and no
    /// table up to 1 024 pieces met it at 1.54, 1.56 and 1.59.
    #[test]
    fn pearl_tables_near_the_mica_index_meet_the_tolerance_at_16_pieces() {
        use crate::optics::fresnel::critical_cosine_complex;
        use crate::optics::thin_film::{stack_spectrum, FilmLayer};
        use num_complex::Complex64;
        let tio2 = FilmLayer { n: Complex64::new(2.5, 0.0), thickness_nm: 135.0, coherent: true };
        let mica = FilmLayer { n: Complex64::new(1.58, 0.0), thickness_nm: 400.0, coherent: false };
        let lambdas = [700.0, 546.1, 435.8];
        for eta in [1.5, 1.54, 1.56, 1.58, 1.59, 1.6] {
            let f = |at: Abscissa, which: &[usize], v: &mut [f64]| {
                let ls = which.iter().map(|&i| lambdas[i]);
                let n = Complex64::new(eta, 0.0);
                stack_spectrum(eta, &[tio2, mica, tio2], n, at.x, at.kink, ls, |i, r| v[i] = r.r().clamp(0.0, 1.0));
            };
            let kinks: Vec<f64> = critical_cosine_complex(mica.n / eta).into_iter().collect();
            assert_eq!(kinks.is_empty(), eta <= 1.58);
            for (t, l) in ChebTable::fit_each_kinked(f, 3, 0.0, 1.0, &kinks, 1e-12).iter().zip(lambdas) {
                let t = t.as_ref().unwrap_or_else(|| panic!("η {eta}, {l} nm: no table"));
                let most = if eta == 1.58 { 32 } else { 16 };
                assert!(t.pieces() <= most && t.max_error <= 1e-12, "η {eta}, {l} nm: {} pieces", t.pieces());
            }
        }
    }

    /// The numbers of `docs/model.md` §Evaluation cost, "Where the direct evaluation is the noise": for the
    /// Cerulean (c) pearl's stack at 546.1 nm, the largest deviation of the table from the direct evaluation at
    /// each piece count, where it is (piece, check point), and the exit cosine's relative error as
    /// [`complex_cos_transmitted`](crate::optics::fresnel::complex_cos_transmitted) computed it (before the cure)
    /// and as the stack computes it now (`ncos_from_real`; the stack itself takes μ). A tool, not a check:
    /// `cargo test --lib pearl_deviation_near_grazing -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn pearl_deviation_near_grazing() {
        use crate::optics::fresnel::{complex_cos_transmitted, critical_cosine_complex, ncos_from_real};
        use crate::optics::thin_film::{stack_spectrum, FilmLayer};
        use num_complex::Complex64;
        let tio2 = FilmLayer { n: Complex64::new(2.5, 0.0), thickness_nm: 135.0, coherent: true };
        let mica = FilmLayer { n: Complex64::new(1.58, 0.0), thickness_nm: 400.0, coherent: false };
        for eta in [1.5, 1.54, 1.56, 1.58, 1.59, 1.6] {
            let f = |at: Abscissa| {
                let (mut r, n) = (1.0, Complex64::new(eta, 0.0));
                stack_spectrum(eta, &[tio2, mica, tio2], n, at.x, at.kink, [546.1], |_, s| r = s.r().clamp(0.0, 1.0));
                r
            };
            let kinks: Vec<f64> = critical_cosine_complex(mica.n / eta).into_iter().collect();
            let mut line = format!("η {eta}: deviation (piece, check point) at");
            for pieces in [8usize, 16, 32, 64, 128, 1024] {
                let f1 = |x, _: &[usize], v: &mut [f64]| v[0] = f(x);
                let t = ChebTable::fit_each_kinked_with_pieces(f1, &[0], 0.0, 1.0, &kinks, pieces, 1.0).pop().flatten();
                let Some(t) = t else { continue };
                let (segs, per) = (t.segments.clone(), pieces / t.segments.len().max(1));
                let (mut worst, mut at) = (0.0f64, (0, 0));
                for p in 0..pieces {
                    for j in 0..=N {
                        if !segs.is_empty() && p % per == 0 && j == N {
                            continue;
                        }
                        let u = 0.5 - 0.5 * (std::f64::consts::PI * j as f64 / N as f64).cos();
                        let x = match segs.is_empty() {
                            true => Abscissa { x: (p as f64 + u) / pieces as f64, kink: None },
                            false => segs[p / per].at(((p % per) as f64 + 1.0 - u) / per as f64),
                        };
                        let e = (t.eval(x.x) - f(x)).abs();
                        if e > worst {
                            (worst, at) = (e, (p, j));
                        }
                    }
                }
                line += &format!(" {pieces}: {worst:.1e} {at:?};");
            }
            println!("{line}");
            let mut near = "   exit cosine's relative error, before and now:".to_string();
            for mu in [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9] {
                let n = Complex64::new(eta, 0.0);
                let before = complex_cos_transmitted(n, Complex64::new(mu, 0.0), n);
                let now = ncos_from_real(eta, mu, n) / n;
                near += &format!(" μ {mu:.0e}: {:.1e}, {:.1e};", (before.re - mu) / mu, (now.re - mu) / mu);
            }
            println!("{near}");
        }
    }
}
