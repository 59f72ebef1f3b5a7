//! Directional albedo E(μ) of a rough dielectric interface's single-scattering reflection lobe, and its
//! cosine-weighted hemispherical average Ē, computed once per (distribution, roughness, index).
//!
//! Why: an energy-exact rough clear coat (Kelemen & Szirmay-Kalos 2001, "A microfacet based coupled
//! specular-matte BRDF model with importance sampling", Eurographics 2001 short papers) lets into the coat what
//! the lobe does not reflect, 1 − E(θ), and reflects back inside r_i = 1 − (1 − Ē)/η² (`docs/model.md`
//! §Energy-exact rough clear coat). The white furnace holds to the accuracy of E (10⁻⁹ is asked), and the
//! aperture integral evaluates the paint millions of times, so E is neither an adaptive integral nor computed
//! per call: a fixed rule generated a table once, shipped as data, and a paint sums that table's series.
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
//! within 7.1·10⁻¹³ for Beckmann 0.01–1, GGX 0.02–0.5, θ 0–89° (`tests/paint.rs`).
//!
//! The reference rule's node counts ([`PHI_NODES`], [`CORE_NODES`], [`TAIL_NODES`]: 12, 48, 24) agree with
//! 16, 64 and 32 nodes to 1.4·10⁻¹² (Beckmann α = 1), ≤ 1.3·10⁻¹⁴ elsewhere, for
//! α 10⁻⁴–1 (both distributions, η = 1.5, 40 μ in [μ₀, 1]); it costs 6–40·10³ lobe evaluations per E, so a paint
//! does not run it: it reads the shipped table (below).
//!
//! The per-paint function: E on μ ∈ [μ₀, 1], μ₀ = 1/64 (θ = 89.1°), in Chebyshev pieces ([`NODES`]
//! coefficients each) graded towards grazing (where E varies on the scale of α) and towards the normal (where
//! Λ(ωi) ∝ exp(−μ²/(α² sin²θ)) is not analytic at μ = 1, felt for α ~ 1). Below μ₀ it holds E(μ₀) (no
//! instrument reaches 89°). Ē is the exact cosine-weighted mean of that function (so the coupled coat
//! conserves energy to the function's own error); it is integrated piecewise by Gauss–Legendre, exact for the
//! polynomial pieces.
//!
//! The shipped table (`assets/coat-albedo-table.bin`, provenance `assets/coat-albedo-table.json`, written by
//! `cargo run --release --example make_coat_albedo_table` from the reference rule): for each distribution, the
//! per-paint function's μ-Chebyshev coefficients as a tensor Chebyshev series in ln α (pieces [`ALPHA_BREAKS`],
//! [`ALPHA_NODES`] terms each) and η ∈ [[`ETA_MIN`], [`ETA_MAX`]] ([`ETA_NODES`] terms), trailing coefficients
//! dropped while their absolute sum stays within [`TRUNCATION_BUDGET`] per block. A paint's build sums the
//! series at its (α, η): no lobe evaluation. Supported: α ∈ [`ALPHA_BREAKS`] ends = [10⁻⁷, 1] (every rough coat: below 10⁻⁷ a coat is smooth), η ∈ [1.3, 1.8]
//! (the recipe's whole index range); outside, [`CoatAlbedo::new`] refuses. The table's error against the rule at
//! off-grid (α, η, μ) is tested (`tests/paint.rs`).
use super::fresnel::fr_dielectric;
use super::microfacet::{Distribution, Microfacet};
use super::tabulated::{basis_into, coefficients, node_on};
use crate::quadrature::gauss_legendre;
use crate::Vec3;
use std::f64::consts::PI;

/// Gauss–Legendre nodes of each azimuthal panel.
pub const PHI_NODES: usize = 12;
/// Gauss–Legendre nodes of the core radial panel (Beckmann t ∈ [0, 2.5], GGX t ∈ [0, 1]).
pub const CORE_NODES: usize = 48;
/// Gauss–Legendre nodes of the Beckmann tail panel t ∈ [2.5, 6.5] and of each graded GGX tail panel.
pub const TAIL_NODES: usize = 24;
/// Where the Beckmann core panel ends (scaled slope).
const BECKMANN_SPLIT: f64 = 2.5;
/// Beckmann's scaled-slope cut: e^{−T²} = 5·10⁻¹⁹.
const BECKMANN_CUT: f64 = 6.5;
/// Smallest μ tabulated (θ = 89.105°).
pub const MU_MIN: f64 = 1.0 / 64.0;
/// Break points of the per-paint function's pieces in μ: [μ₀2^k, μ₀2^{k+1}] up to 1/2 (graded towards
/// grazing, where E varies on the scale of α), then [1 − 2^{−k}, 1 − 2^{−k−1}] up to 15/16 and [15/16, 1]
/// (graded towards the normal, where Λ(ωi) ∝ exp(−μ²/(α² sin²θ)) makes E non-analytic at μ = 1: negligible
/// for small α, not for α ~ 1).
pub const BREAKS: [f64; 10] = [MU_MIN, 1.0 / 32.0, 1.0 / 16.0, 0.125, 0.25, 0.5, 0.75, 0.875, 0.9375, 1.0];
/// Pieces of the per-paint function.
pub const PIECES: usize = BREAKS.len() - 1;
/// Chebyshev coefficients (and nodes) per μ piece.
pub const NODES: usize = 14;
/// Break points of the shipped table's pieces in α (each piece a Chebyshev series in ln α); its ends are the
/// supported roughness range.
pub const ALPHA_BREAKS: [f64; 14] = [1e-7, 1e-5, 1e-4, 1e-3, 2e-3, 4e-3, 0.01, 0.02, 0.04, 0.09, 0.18, 0.3, 0.55, 1.0];
/// Chebyshev terms per α piece.
pub const ALPHA_NODES: usize = 16;
/// The shipped table's index range (the recipe's: `/clear_coat/index`).
pub const ETA_MIN: f64 = 1.3;
pub const ETA_MAX: f64 = 1.8;
/// Chebyshev terms in η.
pub const ETA_NODES: usize = 16;
/// Bound on the absolute sum of the coefficients the generator dropped per (distribution, α piece, μ piece)
/// block, so on the truncation's contribution to |E_table − E_series| anywhere.
pub const TRUNCATION_BUDGET: f64 = 1e-11;
/// The distributions in the table's order.
pub const DISTRIBUTIONS: [Distribution; 2] = [Distribution::Beckmann, Distribution::Ggx];

/// The rule's fixed nodes.
struct AlbedoNodes {
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

impl AlbedoNodes {
    fn new() -> AlbedoNodes {
        AlbedoNodes {
            phi: gauss_legendre(PHI_NODES),
            core: gauss_legendre(CORE_NODES),
            tail: gauss_legendre(TAIL_NODES),
        }
    }
}

/// E(μ) by the fixed rule (module docs).
pub fn lobe_albedo(mf: &Microfacet, eta: f64, mu: f64) -> f64 {
    lobe_albedo_with(&AlbedoNodes::new(), mf, eta, mu).0
}

fn lobe_albedo_with(rule: &AlbedoNodes, mf: &Microfacet, eta: f64, mu: f64) -> (f64, usize) {
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

/// E(μ) as the per-paint piecewise Chebyshev function, with its hemispherical average Ē = ∫₀¹ E(μ) 2μ dμ.
#[derive(Clone, Debug, PartialEq)]
pub struct CoatAlbedo {
    /// PIECES × NODES Chebyshev coefficients.
    coeffs: Vec<f64>,
    /// Ē of the function.
    pub mean: f64,
    /// Lobe evaluations spent building it: 0 from the shipped table.
    pub evaluations: usize,
    /// Table coefficients summed building it: 0 from the rule.
    pub table_terms: usize,
}

fn piece_bounds(p: usize) -> (f64, f64) {
    (BREAKS[p], BREAKS[p + 1])
}

fn piece_of(mu: f64) -> usize {
    BREAKS[1..PIECES].iter().take_while(|&&b| mu >= b).count()
}

/// Why the shipped table cannot give a coat's E.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OutOfTable {
    /// α outside [`ALPHA_BREAKS`]' ends.
    Roughness,
    /// η outside [[`ETA_MIN`], [`ETA_MAX`]].
    Index,
}

/// The shipped table, parsed once: rows of μ-Chebyshev coefficients, one row per (distribution, α piece,
/// μ piece, α term, η term), each of its stored length.
#[derive(Debug)]
struct Table {
    data: Vec<f64>,
    /// (offset into `data`, length) per row.
    rows: Vec<(u32, u8)>,
}

/// The bytes of `assets/coat-albedo-table.bin` (format: [`parse_table`]).
pub(crate) const TABLE_BYTES: &[u8] = include_bytes!("../../assets/coat-albedo-table.bin");
/// Its first eight bytes.
pub const TABLE_MAGIC: &[u8; 8] = b"GMCOAT01";

/// Rows of the table, in its order.
pub(crate) const TABLE_ROWS: usize = DISTRIBUTIONS.len() * (ALPHA_BREAKS.len() - 1) * PIECES * ALPHA_NODES * ETA_NODES;

fn row_index(dist: usize, ap: usize, mp: usize, ka: usize, ke: usize) -> usize {
    (((dist * (ALPHA_BREAKS.len() - 1) + ap) * PIECES + mp) * ALPHA_NODES + ka) * ETA_NODES + ke
}

/// Parse the table: the magic, then as little-endian u32 the counts (distributions, α pieces, ALPHA_NODES,
/// ETA_NODES, PIECES, NODES), as f64 the α breaks, η range and μ breaks (all checked against this module's
/// constants), then [`TABLE_ROWS`] rows in [`row_index`] order, each a u8 length L ≤ NODES and L f64.
fn parse_table(b: &[u8]) -> std::result::Result<Table, String> {
    let mut at = 0usize;
    let mut take = |n: usize| -> std::result::Result<&[u8], String> {
        let s = b.get(at..at + n).ok_or_else(|| format!("coat-albedo table truncated at byte {at}"))?;
        at += n;
        Ok(s)
    };
    if take(8)? != TABLE_MAGIC {
        return Err("coat-albedo table: bad magic".into());
    }
    let counts = [DISTRIBUTIONS.len(), ALPHA_BREAKS.len() - 1, ALPHA_NODES, ETA_NODES, PIECES, NODES];
    for c in counts {
        let v = u32::from_le_bytes(take(4)?.try_into().expect("4 bytes"));
        if v as usize != c {
            return Err(format!("coat-albedo table: layout count {v}, the code expects {c}"));
        }
    }
    let expect: Vec<f64> = ALPHA_BREAKS.iter().chain(&[ETA_MIN, ETA_MAX]).chain(&BREAKS).copied().collect();
    for e in expect {
        let v = f64::from_le_bytes(take(8)?.try_into().expect("8 bytes"));
        if v != e {
            return Err(format!("coat-albedo table: break point {v}, the code expects {e}"));
        }
    }
    let mut data = Vec::new();
    let mut rows = Vec::with_capacity(TABLE_ROWS);
    for _ in 0..TABLE_ROWS {
        let len = take(1)?[0];
        if len as usize > NODES {
            return Err(format!("coat-albedo table: row of {len} > {NODES} coefficients"));
        }
        rows.push((data.len() as u32, len));
        for _ in 0..len {
            data.push(f64::from_le_bytes(take(8)?.try_into().expect("8 bytes")));
        }
    }
    if at != b.len() {
        return Err(format!("coat-albedo table: {} trailing bytes", b.len() - at));
    }
    Ok(Table { data, rows })
}

fn table() -> &'static Table {
    static T: std::sync::OnceLock<Table> = std::sync::OnceLock::new();
    // The bytes are compiled in and checked by the unit test below: a failure here is a build defect.
    T.get_or_init(|| parse_table(TABLE_BYTES).expect("the shipped coat-albedo table parses"))
}

/// Coefficients stored in the shipped table (after truncation) and its rows.
pub fn table_size() -> (usize, usize) {
    let t = table();
    (t.data.len(), t.rows.len())
}

impl CoatAlbedo {
    /// E for a rough interface (its lobe `mf`) of index `eta`, from the shipped table (module docs): sums
    /// the table's series at (ln α, η); refused outside the table's range.
    pub fn new(mf: &Microfacet, eta: f64) -> std::result::Result<CoatAlbedo, OutOfTable> {
        let (a_lo, a_hi) = (ALPHA_BREAKS[0], ALPHA_BREAKS[ALPHA_BREAKS.len() - 1]);
        if !(a_lo..=a_hi).contains(&mf.alpha) {
            return Err(OutOfTable::Roughness);
        }
        if !(ETA_MIN..=ETA_MAX).contains(&eta) {
            return Err(OutOfTable::Index);
        }
        let dist = DISTRIBUTIONS.iter().position(|&d| d == mf.distribution).expect("both distributions tabulated");
        let ap = ALPHA_BREAKS[1..ALPHA_BREAKS.len() - 1].iter().take_while(|&&b| mf.alpha >= b).count();
        let (l0, l1) = (ALPHA_BREAKS[ap].ln(), ALPHA_BREAKS[ap + 1].ln());
        let xa = ((2.0 * mf.alpha.ln() - l0 - l1) / (l1 - l0)).clamp(-1.0, 1.0);
        let xe = ((2.0 * eta - ETA_MIN - ETA_MAX) / (ETA_MAX - ETA_MIN)).clamp(-1.0, 1.0);
        let (mut ta, mut te) = ([0.0; ALPHA_NODES], [0.0; ETA_NODES]);
        basis_into(xa, &mut ta);
        basis_into(xe, &mut te);
        let t = table();
        let mut coeffs = vec![0.0; PIECES * NODES];
        let mut terms = 0usize;
        for mp in 0..PIECES {
            let c = &mut coeffs[mp * NODES..(mp + 1) * NODES];
            for (ka, &wa) in ta.iter().enumerate() {
                for (ke, &we) in te.iter().enumerate() {
                    let (off, len) = t.rows[row_index(dist, ap, mp, ka, ke)];
                    let w = wa * we;
                    for (ck, &v) in c.iter_mut().zip(&t.data[off as usize..off as usize + len as usize]) {
                        *ck += w * v;
                    }
                    terms += len as usize;
                }
            }
        }
        Ok(Self::finish(coeffs, 0, terms))
    }

    /// E from the reference rule at the μ nodes (`PIECES × NODES` runs of [`lobe_albedo`]: 10⁵–10⁶ lobe
    /// evaluations, so for tests and the table's generator, never a paint); `None` if the rule gave a
    /// non-finite value.
    pub fn from_rule(mf: &Microfacet, eta: f64) -> Option<CoatAlbedo> {
        let rule = AlbedoNodes::new();
        let mut evaluations = 0usize;
        let mut coeffs = Vec::with_capacity(PIECES * NODES);
        for p in 0..PIECES {
            let (lo, hi) = piece_bounds(p);
            let mut vals = [0.0; NODES];
            for (j, v) in vals.iter_mut().enumerate() {
                let (e, n) = lobe_albedo_with(&rule, mf, eta, node_on(j, NODES, lo, hi));
                evaluations += n;
                if !e.is_finite() {
                    return None;
                }
                *v = e;
            }
            coeffs.extend(coefficients(&vals));
        }
        Some(Self::finish(coeffs, evaluations, 0))
    }

    /// The μ-Chebyshev coefficients, piece after piece.
    pub fn coefficients(&self) -> &[f64] {
        &self.coeffs
    }

    fn finish(coeffs: Vec<f64>, evaluations: usize, table_terms: usize) -> CoatAlbedo {
        let mut a = CoatAlbedo { coeffs, mean: 0.0, evaluations, table_terms };
        // Ē of the function `at` evaluates: E(μ₀)·μ₀² on [0, μ₀], then each piece by Gauss–Legendre
        // (exact: the integrand is a polynomial of degree NODES on each piece).
        let (gx, gw) = gauss_legendre(NODES / 2 + 2);
        let mut mean = a.at(MU_MIN) * MU_MIN * MU_MIN;
        for p in 0..PIECES {
            let (lo, hi) = piece_bounds(p);
            let (m, h) = (0.5 * (lo + hi), 0.5 * (hi - lo));
            mean +=
                gx.iter().zip(&gw).map(|(&x, &w)| w * a.piece_eval(p, m + h * x) * 2.0 * (m + h * x)).sum::<f64>() * h;
        }
        a.mean = mean;
        a
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

    /// E(μ) (E(μ₀) below μ₀; μ is clamped to 1).
    #[inline]
    pub fn at(&self, mu: f64) -> f64 {
        let mu = mu.clamp(MU_MIN, 1.0);
        self.piece_eval(piece_of(mu), mu)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shipped_table_parses_with_this_layout() {
        let t = parse_table(TABLE_BYTES).expect("parses");
        assert_eq!(t.rows.len(), TABLE_ROWS);
        assert!(t.data.iter().all(|v| v.is_finite()));
        // A corrupted copy is refused, not misread.
        let mut bad = TABLE_BYTES.to_vec();
        bad[8] ^= 1;
        assert!(parse_table(&bad).unwrap_err().contains("layout count"));
        assert!(parse_table(&TABLE_BYTES[..TABLE_BYTES.len() - 1]).unwrap_err().contains("truncated"));
    }

    #[test]
    fn chebyshev_transform_reproduces_its_nodes() {
        let vals: Vec<f64> = (0..NODES).map(|j| node_on(j, NODES, 0.2, 0.7).exp()).collect();
        let c = coefficients(&vals);
        let mut t = [0.0; NODES];
        for (j, v) in vals.iter().enumerate() {
            basis_into((PI * (j as f64 + 0.5) / NODES as f64).cos(), &mut t);
            let s: f64 = c.iter().zip(&t).map(|(a, b)| a * b).sum();
            assert!((s - v).abs() < 1e-14, "{s} vs {v}");
        }
    }
}
