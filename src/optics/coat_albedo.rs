//! Directional albedo E(μ) of a rough dielectric interface's single-scattering reflection lobe, and its
//! cosine-weighted hemispherical average Ē, computed once per (distribution, roughness, index).
//!
//! Why: an energy-exact rough clear coat (Kelemen & Szirmay-Kalos 2001, "A microfacet based coupled
//! specular-matte BRDF model with importance sampling", Eurographics 2001 short papers) lets into the coat what
//! the lobe does not reflect, 1 − E(θ), and reflects back inside r_i = 1 − (1 − Ē)/η² (`docs/model.md`
//! §Energy-exact rough clear coat). The white furnace holds to the accuracy of E (10⁻⁹ is asked), and the
//! aperture integral evaluates the paint millions of times, so E is neither an adaptive integral nor computed
//! per call: a fixed rule builds a table once.
//!
//! The fixed rule, in scaled slope variables. With ωi = (sin θ, 0, μ), the half vector h ∝ (X, Y, 1) and the
//! slope distribution P22 (D(h) = P22·(1 + r²)², r² = X² + Y²), dω_o = 4(ωi·h) dω_h and
//! dω_h = dX dY/(1 + r²)^{3/2} give
//!
//!   E(μ) = ∬ P22(X, Y) · F(ωi·h) · G(ωi, ωo) · (r a + μ)/μ dX dY,   a = sin θ cos φ,
//!
//! over the slopes whose mirror direction ωo = 2(ωi·h)h − ωi is above the horizon: r < r_max(φ) =
//! (a + √(a² + μ²))/μ. In polar scaled slopes X + iY = α t e^{iφ}, P22 dX dY = w(t) dt dφ/(2π) with
//! w(t) = 2t e^{−t²} (Beckmann) or 2t/(1 + t²)² (GGX), the same for every α. The rule resolves the two
//! singularities that make a uniform tensor rule fail near grazing:
//! * in φ (on [0, π]; the integrand is even), r_max(φ) has branch points at φ = π/2 ± i·asinh(μ/sin θ), which
//!   approach the real axis as μ → 0: Gauss–Legendre panels of [`PHI_NODES`] graded geometrically towards π/2,
//!   the finest asinh(μ/sin θ) wide;
//! * radially, Smith G has a complex singularity about 1/|dωo,z/dr| beyond the horizon t_max = r_max/α (in t):
//!   Beckmann, [`CORE_NODES`] on t ∈ [0, 2.5] and [`TAIL_NODES`] on [2.5, 6.5] (e^{−6.5²} = 5·10⁻¹⁹), cut at
//!   t_max; GGX, [`CORE_NODES`] on t ∈ [0, 1] and the heavy tail in λ = ln t on [0, ln t_max] in
//!   [`TAIL_NODES`]-node panels graded towards the horizon, the finest 1/(|dωo,z/dr|·t_max) wide.
//!
//! Against scipy's adaptive integral over the outgoing direction (`tools/ref_coat_albedo.py`) the rule is
//! within 6.3·10⁻¹¹ for Beckmann 0.01–1, GGX 0.02–0.5, θ 0–89° (`tests/paint.rs`).
//!
//! The table: E on μ ∈ [μ₀, 1], μ₀ = 1/64 (θ = 89.1°), in Chebyshev pieces ([`NODES`] Chebyshev–Gauss nodes
//! each) graded towards grazing (where E varies on the scale of α) and towards the normal (where Λ(ωi) ∝
//! exp(−μ²/(α² sin²θ)) is not analytic at μ = 1, felt for α ~ 1), checked against the rule at every piece's
//! middle and ends when built (the largest deviation is kept: `max_error`). Below μ₀ the table holds E(μ₀) (no
//! instrument reaches 89°). Ē is the exact cosine-weighted mean of the tabulated function (so the coupled coat
//! conserves energy to the table's own error); it is integrated piecewise by Gauss–Legendre, exact for the
//! polynomial pieces. Cost: 0.3–1.1·10⁶ lobe evaluations per table (`benches/paint_build.rs`).
use super::fresnel::fr_dielectric;
use super::microfacet::{Distribution, Microfacet};
use crate::quadrature::gauss_legendre;
use crate::Vec3;
use std::f64::consts::PI;

/// Gauss–Legendre nodes of each azimuthal panel.
pub const PHI_NODES: usize = 8;
/// Gauss–Legendre nodes of the core radial panel (Beckmann t ∈ [0, 2.5], GGX t ∈ [0, 1]).
pub const CORE_NODES: usize = 32;
/// Gauss–Legendre nodes of the Beckmann tail panel t ∈ [2.5, 6.5] and of each graded GGX tail panel.
pub const TAIL_NODES: usize = 16;
/// Where the Beckmann core panel ends (scaled slope).
const BECKMANN_SPLIT: f64 = 2.5;
/// Beckmann's scaled-slope cut: e^{−T²} = 5·10⁻¹⁹.
const BECKMANN_CUT: f64 = 6.5;
/// Smallest μ tabulated (θ = 89.105°).
pub const MU_MIN: f64 = 1.0 / 64.0;
/// Break points of the table's pieces: [μ₀2^k, μ₀2^{k+1}] up to 1/2 (graded towards grazing, where E varies
/// on the scale of α), then [1 − 2^{−k}, 1 − 2^{−k−1}] up to 15/16 and [15/16, 1] (graded towards the normal,
/// where Λ(ωi) ∝ exp(−μ²/(α² sin²θ)) makes E non-analytic at μ = 1: negligible for small α, not for α ~ 1).
const BREAKS: [f64; 10] = [MU_MIN, 1.0 / 32.0, 1.0 / 16.0, 0.125, 0.25, 0.5, 0.75, 0.875, 0.9375, 1.0];
/// Pieces of the table.
const PIECES: usize = BREAKS.len() - 1;
/// Chebyshev nodes per piece.
pub const NODES: usize = 14;
/// Largest deviation of the table from the rule accepted at the check points.
pub const TABLE_TOLERANCE: f64 = 1e-10;

/// The rule's fixed nodes.
struct Rule {
    phi: (Vec<f64>, Vec<f64>),
    core: (Vec<f64>, Vec<f64>),
    tail: (Vec<f64>, Vec<f64>),
}

/// ∫_lo^hi f by the Gauss–Legendre rule `(x, w)` on [−1, 1].
fn gl(rule: &(Vec<f64>, Vec<f64>), lo: f64, hi: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
    let (m, h) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    rule.0.iter().zip(&rule.1).map(|(&x, &w)| w * f(m + h * x)).sum::<f64>() * h
}

/// Break points of [0, len] graded geometrically towards `len`: len − finest·2^k (k = 0, 1, …) while
/// positive, then 0 (ascending). The panel next to `len` is `finest` wide (or all of it).
fn graded_towards_end(len: f64, finest: f64) -> Vec<f64> {
    let mut b = vec![len];
    let mut d = finest;
    while d < len {
        b.push(len - d);
        d *= 2.0;
    }
    b.push(0.0);
    b.reverse();
    b
}

impl Rule {
    fn new() -> Rule {
        Rule { phi: gauss_legendre(PHI_NODES), core: gauss_legendre(CORE_NODES), tail: gauss_legendre(TAIL_NODES) }
    }
}

/// E(μ) by the fixed rule (module docs).
pub fn lobe_albedo(mf: &Microfacet, eta: f64, mu: f64) -> f64 {
    lobe_albedo_with(&Rule::new(), mf, eta, mu).0
}

/// E(μ) and the number of lobe evaluations the rule spent.
pub fn lobe_albedo_counted(mf: &Microfacet, eta: f64, mu: f64) -> (f64, usize) {
    lobe_albedo_with(&Rule::new(), mf, eta, mu)
}

fn lobe_albedo_with(rule: &Rule, mf: &Microfacet, eta: f64, mu: f64) -> (f64, usize) {
    let c = mu.clamp(1e-12, 1.0);
    let s = (1.0 - c * c).max(0.0).sqrt();
    let wi = Vec3::new(s, 0.0, c);
    let alpha = mf.alpha;
    let lambda_i = mf.lambda(wi);
    let mut evals = 0usize;
    // The radial line integral ∫ w(t) g(t) dt along the azimuth φ.
    let mut line = |phi: f64| -> f64 {
        let (sp, cp) = phi.sin_cos();
        let a = s * cp;
        let root = a.hypot(c);
        let r_max = if a >= 0.0 { (a + root) / c } else { c / (root - a) };
        let t_max = r_max / alpha;
        // F·G·(r a + μ)/μ at scaled slope t along φ.
        let mut g = |t: f64| -> f64 {
            evals += 1;
            let r = alpha * t;
            let inv = 1.0 / (1.0 + r * r).sqrt();
            let h = Vec3::new(r * cp * inv, r * sp * inv, inv);
            let wih = (r * a + c) * inv;
            if wih <= 0.0 {
                return 0.0;
            }
            let wo = 2.0 * wih * h - wi;
            if wo.z <= 0.0 {
                return 0.0;
            }
            let v = fr_dielectric(wih.min(1.0), eta) / (1.0 + (lambda_i + mf.lambda_in_g(wo))) * (1.0 + r * a / c);
            if v.is_finite() {
                v
            } else {
                0.0
            }
        };
        match mf.distribution {
            Distribution::Beckmann => {
                let w = |t: f64| 2.0 * t * (-t * t).exp();
                let hi = t_max.min(BECKMANN_CUT);
                let core = gl(&rule.core, 0.0, hi.min(BECKMANN_SPLIT), |t| w(t) * g(t));
                let tail = if hi > BECKMANN_SPLIT { gl(&rule.tail, BECKMANN_SPLIT, hi, |t| w(t) * g(t)) } else { 0.0 };
                core + tail
            }
            Distribution::Ggx => {
                let core = gl(&rule.core, 0.0, t_max.min(1.0), |t| 2.0 * t / ((1.0 + t * t) * (1.0 + t * t)) * g(t));
                if t_max <= 1.0 {
                    return core;
                }
                // λ = ln t on [0, ln t_max], graded towards the horizon: G's nearest complex singularity lies
                // about 1/|dωo,z/dr| beyond t_max in t (module docs), 1/(|dωo,z/dr|·t_max) in λ.
                let dz_dr = 2.0 * root / (1.0 + r_max * r_max);
                let len = t_max.ln();
                let b = graded_towards_end(len, 1.0 / (dz_dr * t_max));
                let mut tail = 0.0;
                for p in b.windows(2) {
                    tail += gl(&rule.tail, p[0], p[1], |l| {
                        let t = l.exp();
                        let q = 1.0 + t * t;
                        2.0 * t * t / (q * q) * g(t)
                    });
                }
                core + tail
            }
        }
    };
    // φ on [0, π] (the integrand is even in φ), graded towards π/2 from both sides: the horizon radius r_max(φ)
    // has branch points at φ = π/2 ± i·asinh(μ/sin θ) (module docs).
    let delta = if s > 0.0 { (c / s).asinh() } else { f64::INFINITY };
    let b = graded_towards_end(PI / 2.0, delta);
    let mut total = 0.0;
    for p in b.windows(2) {
        total += gl(&rule.phi, p[0], p[1], &mut line);
        total += gl(&rule.phi, PI - p[1], PI - p[0], &mut line);
    }
    // (1/2π)·∫₀^{2π} = (1/π)·∫₀^π.
    (total / PI, evals)
}

/// E(μ) tabulated, with its hemispherical average Ē = ∫₀¹ E(μ) 2μ dμ.
#[derive(Clone, Debug, PartialEq)]
pub struct CoatAlbedo {
    /// PIECES × NODES Chebyshev coefficients.
    coeffs: Vec<f64>,
    /// Ē of the tabulated function.
    pub mean: f64,
    /// Largest |table − rule| at the check points.
    pub max_error: f64,
    /// Lobe evaluations the rule spent building and checking the table.
    pub evaluations: usize,
}

fn piece_bounds(p: usize) -> (f64, f64) {
    (BREAKS[p], BREAKS[p + 1])
}

fn piece_of(mu: f64) -> usize {
    BREAKS[1..PIECES].iter().take_while(|&&b| mu >= b).count()
}

impl CoatAlbedo {
    /// Build the table for a rough interface (its lobe `mf`) of index `eta`; `None` if the table deviates
    /// from the rule by more than [`TABLE_TOLERANCE`] at a check point (never observed: `tests/paint.rs`).
    pub fn new(mf: &Microfacet, eta: f64) -> Option<CoatAlbedo> {
        Self::build(mf, eta).filter(|t| t.max_error <= TABLE_TOLERANCE)
    }

    /// The table and its check, whatever the deviation found (`max_error`); `None` only if the rule gave a
    /// non-finite value.
    pub fn build(mf: &Microfacet, eta: f64) -> Option<CoatAlbedo> {
        let rule = Rule::new();
        let evaluations = std::cell::Cell::new(0usize);
        let e = |mu: f64| {
            let (v, n) = lobe_albedo_with(&rule, mf, eta, mu);
            evaluations.set(evaluations.get() + n);
            v
        };
        let mut coeffs = Vec::with_capacity(PIECES * NODES);
        let mut vals = [0.0; NODES];
        for p in 0..PIECES {
            let (lo, hi) = piece_bounds(p);
            for (j, v) in vals.iter_mut().enumerate() {
                let x = (PI * (j as f64 + 0.5) / NODES as f64).cos();
                *v = e(0.5 * (lo + hi) + 0.5 * (hi - lo) * x);
                if !v.is_finite() {
                    return None;
                }
            }
            for k in 0..NODES {
                let c: f64 = vals
                    .iter()
                    .enumerate()
                    .map(|(j, v)| v * (PI * k as f64 * (j as f64 + 0.5) / NODES as f64).cos())
                    .sum();
                coeffs.push(if k == 0 { c / NODES as f64 } else { 2.0 * c / NODES as f64 });
            }
        }
        let mut table = CoatAlbedo { coeffs, mean: 0.0, max_error: 0.0, evaluations: 0 };
        // Check between the nodes: the ends and the middle of every piece (where an interpolant errs most;
        // a shared end is checked once, from the piece above it, which `at` uses there).
        let mut max_error: f64 = 0.0;
        for p in 0..PIECES {
            let (lo, hi) = piece_bounds(p);
            let mut points = vec![lo, 0.5 * (lo + hi)];
            if p + 1 == PIECES {
                points.push(hi);
            }
            for x in points {
                max_error = max_error.max((table.at(x) - e(x)).abs());
            }
        }
        if !max_error.is_finite() {
            return None;
        }
        table.max_error = max_error;
        // Ē of the function `at` evaluates: E(μ₀)·μ₀² on [0, μ₀], then each piece by Gauss–Legendre
        // (exact: the integrand is a polynomial of degree NODES on each piece).
        let (gx, gw) = gauss_legendre(NODES / 2 + 2);
        let mut mean = table.at(MU_MIN) * MU_MIN * MU_MIN;
        for p in 0..PIECES {
            let (lo, hi) = piece_bounds(p);
            let (m, h) = (0.5 * (lo + hi), 0.5 * (hi - lo));
            mean +=
                gx.iter().zip(&gw).map(|(&x, &w)| w * table.piece_eval(p, m + h * x) * 2.0 * (m + h * x)).sum::<f64>()
                    * h;
        }
        table.mean = mean;
        table.evaluations = evaluations.get();
        Some(table)
    }

    fn piece_eval(&self, p: usize, mu: f64) -> f64 {
        let (lo, hi) = piece_bounds(p);
        let x = (2.0 * mu - lo - hi) / (hi - lo);
        let c = &self.coeffs[p * NODES..(p + 1) * NODES];
        // Clenshaw.
        let (mut b1, mut b2) = (0.0, 0.0);
        for &ck in c[1..].iter().rev() {
            let b0 = 2.0 * x * b1 - b2 + ck;
            b2 = b1;
            b1 = b0;
        }
        x * b1 - b2 + c[0]
    }

    /// E(μ) from the table (E(μ₀) below μ₀; μ is clamped to 1).
    #[inline]
    pub fn at(&self, mu: f64) -> f64 {
        let mu = mu.clamp(MU_MIN, 1.0);
        self.piece_eval(piece_of(mu), mu)
    }
}
