//! Product rules for a heavy-tailed peak inside a rectangle: polar variables about the peak with the radius
//! mapped by ρ = tan β, and the tensor Gauss–Legendre rule of a box (the pieces around it).
//!
//! Why: a GGX lobe of width w (`docs/instrument.md` §Quadrature, "Polar variables for a narrow GGX lobe") is, in its
//! scaled lobe variables x = u/w_u, y = v/w_v, to leading order the kernel 1/(1 + x² + y²)² (Walter et al., EGSR 2007,
//! Eq. 33): a peak of width 1 with an algebraic tail out to the edges of the domain, 10⁶ widths away at α = 10⁻⁸. No
//! box partition of fixed size resolves both the peak and the tail, and an adaptive one needs more boxes for every
//! decade of α (the splits of `instrument::aperture` at ±3ᵏ w). In polar variables x = ρ cos φ, y = ρ sin φ with
//! ρ = tan β the kernel's
//! area element becomes ρ dρ dφ / (1 + ρ²)² = sin β cos β dβ dφ, a polynomial-like function on β ∈ [0, π/2) whatever the width, so a Gauss–Legendre rule in β with a fixed
//! number of nodes integrates the lobe to the same relative accuracy at every α: the cost stops growing as
//! α → 0. The rectangle [x0, x1] × [y0, y1] (containing 0) is cut into four sectors at its corners' angles;
//! in each, the radius runs to the side it meets, ρ_max(φ) = x1/cos φ (right side) etc., and β = s·atan ρ_max
//! with s ∈ [0, 1]. A sector wider than [`MAX_SECTOR`] (100°) is cut into equal parts. Both rules are exact products of one-dimensional Gauss–Legendre rules (`gauss.rs`).
use super::gauss::gauss_legendre_table;
use std::f64::consts::PI;

/// The n-point Gauss–Legendre rule on [a, b]: (nodes, weights).
pub fn legendre_on(n: usize, a: f64, b: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut x, mut w) = (Vec::with_capacity(n), Vec::with_capacity(n));
    legendre_on_into(n, a, b, &mut x, &mut w);
    (x, w)
}

/// [`legendre_on`] into the caller's buffers (cleared first): no allocation once they have room for n.
pub(crate) fn legendre_on_into(n: usize, a: f64, b: f64, x: &mut Vec<f64>, w: &mut Vec<f64>) {
    let (gx, gw) = gauss_legendre_table(n);
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    x.clear();
    w.clear();
    x.extend(gx.iter().map(|x| c + h * x));
    w.extend(gw.iter().map(|w| h * w));
}

/// The radius ρ_max(φ) of the rectangle [x0, x1] × [y0, y1] (x0, y0 < 0 < x1, y1) along the direction φ: the
/// distance from the origin to the first side the ray meets.
fn radius_to_sides(phi: f64, lo: [f64; 2], hi: [f64; 2]) -> f64 {
    let (s, c) = phi.sin_cos();
    let rx = if c > 0.0 {
        hi[0] / c
    } else if c < 0.0 {
        lo[0] / c
    } else {
        f64::INFINITY
    };
    let ry = if s > 0.0 {
        hi[1] / s
    } else if s < 0.0 {
        lo[1] / s
    } else {
        f64::INFINITY
    };
    rx.min(ry)
}

/// The variable a one-dimensional Gauss–Legendre rule is taken in ([`mapped_legendre`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Map {
    /// x itself.
    Linear,
    /// σ = 1/x (an interval of one sign, away from 0): ∫ g dx = ∫ g(1/σ) dσ/σ², which turns a tail
    /// g ∝ x⁻² … x⁻⁴ into a low-degree polynomial in σ.
    Reciprocal,
    /// γ = atan(x/c): x = c·tan γ, dx = c sec²γ dγ, which turns a kernel 1/(c² + x²)ᵏ (k ≥ 1) into
    /// cos^{2k−2}γ / c^{2k−1}: a peak of width c at 0 and its algebraic tail, at any ratio of the interval to c.
    Tan { scale: f64 },
}

/// The n-point Gauss–Legendre rule for ∫_a^b g(x) dx taken in the variable `map`: nodes and weights in x
/// (Σ w g(x) ≈ ∫ g dx), in increasing order of the mapped variable.
pub fn mapped_legendre(n: usize, a: f64, b: f64, map: Map) -> (Vec<f64>, Vec<f64>) {
    let (mut x, mut w) = (Vec::with_capacity(n), Vec::with_capacity(n));
    mapped_legendre_into(n, a, b, map, &mut x, &mut w);
    (x, w)
}

/// [`mapped_legendre`] into the caller's buffers (cleared first; the same bits): no allocation once they
/// have room for n.
pub(crate) fn mapped_legendre_into(n: usize, a: f64, b: f64, map: Map, x: &mut Vec<f64>, w: &mut Vec<f64>) {
    match map {
        Map::Linear => legendre_on_into(n, a, b, x, w),
        Map::Reciprocal => {
            legendre_on_into(n, 1.0 / b, 1.0 / a, x, w);
            for (s, w) in x.iter_mut().zip(w.iter_mut()) {
                *w /= *s * *s;
                *s = 1.0 / *s;
            }
        }
        Map::Tan { scale } => {
            legendre_on_into(n, (a / scale).atan(), (b / scale).atan(), x, w);
            for (g, w) in x.iter_mut().zip(w.iter_mut()) {
                *w = *w * scale / (g.cos() * g.cos());
                *g = scale * g.tan();
            }
        }
    }
}

/// Nodes (x, y) and weights of the polar rule on the rectangle [lo[0], hi[0]] × [lo[1], hi[1]] around the
/// origin (lo < 0 < hi on both axes): per sector between the corners' angles (a sector wider than
/// [`MAX_SECTOR`] cut into equal parts, each a sector of its own), `n_phi` Gauss–Legendre nodes in
/// φ and `n_r` in the radius ρ ∈ [0, ρ_max(φ)] taken in `radial` ([`Map::Tan`] with scale 1: ρ = tan β, for an
/// algebraic tail; [`Map::Linear`] for a Gaussian one). The weight of a node includes the polar Jacobian ρ and
/// the sector lengths, so Σ w g(x, y) ≈ ∫∫ g dx dy; with ρ = tan β and g = 1/(1 + x² + y²)² the rule
/// integrates sin β cos β. Deterministic node order (sectors anticlockwise from the lower right corner, then
/// φ, then ρ).
pub fn polar_rectangle(lo: [f64; 2], hi: [f64; 2], n_phi: usize, n_r: usize, radial: Map) -> Vec<([f64; 2], f64)> {
    let mut out = Vec::with_capacity(4 * n_phi * n_r);
    polar_rectangle_into(lo, hi, n_phi, n_r, radial, &mut PolarBuffers::default(), &mut out);
    out
}

/// The one-dimensional node buffers [`polar_rectangle_into`] works in (kept by a caller that calls it level
/// after level, so that nothing is allocated once they have grown).
#[derive(Debug, Default)]
pub(crate) struct PolarBuffers {
    phi: (Vec<f64>, Vec<f64>),
    rho: (Vec<f64>, Vec<f64>),
}

/// [`polar_rectangle`] into `out` (cleared first; the same nodes, weights and order), working in `buffers`:
/// no allocation once the buffers and `out` have room.
pub(crate) fn polar_rectangle_into(
    lo: [f64; 2],
    hi: [f64; 2],
    n_phi: usize,
    n_r: usize,
    radial: Map,
    buffers: &mut PolarBuffers,
    out: &mut Vec<([f64; 2], f64)>,
) {
    let c1 = lo[1].atan2(hi[0]);
    let c2 = hi[1].atan2(hi[0]);
    let c3 = hi[1].atan2(lo[0]);
    let c4 = lo[1].atan2(lo[0]) + 2.0 * PI;
    let corners = [c1, c2, c3, c4, c1 + 2.0 * PI];
    out.clear();
    let PolarBuffers { phi: (px, pw), rho: (r, wr) } = buffers;
    for k in 0..4 {
        // A side seen at more than MAX_SECTOR is cut into equal parts of at most that angle.
        let span = corners[k + 1] - corners[k];
        let parts = (span / MAX_SECTOR).ceil().max(1.0) as usize;
        for j in 0..parts {
            let a = corners[k] + span * j as f64 / parts as f64;
            let b = if j + 1 == parts { corners[k + 1] } else { corners[k] + span * (j + 1) as f64 / parts as f64 };
            legendre_on_into(n_phi, a, b, px, pw);
            for (phi, wphi) in px.iter().zip(pw.iter()) {
                let (sphi, cphi) = phi.sin_cos();
                mapped_legendre_into(n_r, 0.0, radius_to_sides(*phi, lo, hi), radial, r, wr);
                for (rho, w) in r.iter().zip(wr.iter()) {
                    out.push(([rho * cphi, rho * sphi], wphi * w * rho));
                }
            }
        }
    }
}

/// The widest sector [`polar_rectangle`] integrates with one Gauss–Legendre rule in φ: 100°. A square's four
/// sectors are 90° each and stay whole; the sector of an elongated rectangle's short side (158° on GGX α =
/// 0.0058's kink square at D523 60°, 2.7 × 13.9 widths) is cut into equal parts. Over the whole 158° the φ
/// rule was still pre-asymptotic at 3 and 4 nodes (relative errors 5.8·10⁻⁵ and 5.2·10⁻⁵, whose difference,
/// the piece's error estimate, was 8.6× below the error); cut in two, 1.8·10⁻⁵ and 2.9·10⁻⁷
/// (`docs/instrument.md` §Quadrature, "Polar variables for a narrow GGX lobe").
pub(crate) const MAX_SECTOR: f64 = 100.0 * PI / 180.0;

#[cfg(test)]
mod tests {
    use super::*;

    /// The GGX kernel over a rectangle: ∫∫ dx dy / (1 + x² + y²)² has the closed form
    /// Σ over the four quadrant rectangles [0, a] × [0, b] of F(a, b) = ½·(a/√(1+a²))·atan(b/√(1+a²)) +
    /// ½·(b/√(1+b²))·atan(a/√(1+b²)) (integrate in y first: ∫ dy/(c² + y²)² = y/(2c²(c² + y²)) +
    /// atan(y/c)/(2c³), then in x), and it tends to π for a rectangle of any shape as it grows.
    #[test]
    fn the_polar_rule_integrates_the_ggx_kernel_at_every_scale() {
        let f = |a: f64, b: f64| {
            let (ra, rb) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
            0.5 * (a / ra) * (b / ra).atan() + 0.5 * (b / rb) * (a / rb).atan()
        };
        for scale in [3.0, 30.0, 1e3, 1e6, 1e9] {
            let (lo, hi) = ([-0.7 * scale, -1.3 * scale], [1.1 * scale, 0.9 * scale]);
            let exact = f(-lo[0], -lo[1]) + f(hi[0], -lo[1]) + f(hi[0], hi[1]) + f(-lo[0], hi[1]);
            let nodes = polar_rectangle(lo, hi, 12, 16, Map::Tan { scale: 1.0 });
            let sum: f64 = nodes.iter().map(|([x, y], w)| w / (1.0 + x * x + y * y).powi(2)).sum();
            assert!((sum - exact).abs() < 1e-11 * exact, "scale {scale}: {sum} vs {exact}");
            assert!(nodes.iter().all(|([x, y], _)| (lo[0]..=hi[0]).contains(x) && (lo[1]..=hi[1]).contains(y)));
        }
        // The area (g = 1) in the linear radius: ρ dρ is exact with 2 nodes, the sectors' ρ_max(φ)²/2 ∝ sec²φ
        // converges in φ (the 127° sector of the short side is cut in two, `MAX_SECTOR`).
        let area: f64 = polar_rectangle([-2.0, -3.0], [4.0, 1.0], 16, 2, Map::Linear).iter().map(|(_, w)| w).sum();
        assert!((area - 24.0).abs() < 1e-8 * 24.0, "{area}");
    }

    /// The mapped rules against closed forms: a GGX-like tail ∫_2^50 dx/x⁴ in σ = 1/x (a polynomial there:
    /// exact), and the kernel ∫_{−30}^{30} dx/(c² + x²)² in x = c·tan γ (cos²γ/c³: fast at any ratio to c).
    #[test]
    fn the_mapped_rules_integrate_the_tails_they_are_made_for() {
        let (x, w) = mapped_legendre(3, 2.0, 50.0, Map::Reciprocal);
        let s: f64 = x.iter().zip(&w).map(|(x, w)| w / x.powi(4)).sum();
        let exact = (1.0 / 8.0 - 1.0 / 125_000.0) / 3.0;
        assert!((s - exact).abs() < 1e-14 * exact, "{s} vs {exact}");
        let (x, w) = mapped_legendre(3, -5.0, -2.0, Map::Reciprocal);
        let s: f64 = x.iter().zip(&w).map(|(x, w)| w / x.powi(4)).sum();
        assert!((s - (1.0 / 8.0 - 1.0 / 125.0) / 3.0).abs() < 1e-15, "{s}");
        for c in [0.01f64, 1.0, 100.0] {
            let (x, w) = mapped_legendre(12, -30.0, 30.0, Map::Tan { scale: c });
            let s: f64 = x.iter().zip(&w).map(|(x, w)| w / (c * c + x * x).powi(2)).sum();
            let g = (30.0 / c).atan();
            let exact = (g + 0.5 * (2.0 * g).sin()) / c.powi(3);
            assert!((s - exact).abs() < 1e-12 * exact, "c={c}: {s} vs {exact}");
        }
    }

    #[test]
    fn legendre_on_an_interval_is_exact_for_its_degree() {
        let (x, w) = legendre_on(4, 1.0, 3.0);
        let s: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(7)).sum();
        assert!((s - (3f64.powi(8) - 1.0) / 8.0).abs() < 1e-11);
    }
}
