//! Kubelka–Munk two-flux theory.
//!
//! Sources: Kubelka & Munk, *Z. techn. Physik* 12 (1931) 593 (the two-flux equations and R∞);
//! Kubelka, *JOSA* 38 (1948) 448 (the hyperbolic solution: a = 1 + K/S, b = √(a² − 1),
//! R = (1 − Rg(a − b coth bSX)) / (a − Rg + b coth bSX), and the layer reflectance/transmittance
//! r0 = sinh bSX/(a sinh bSX + b cosh bSX), t = b/(a sinh bSX + b cosh bSX), with the identity
//! a = (1 + r0² − t²)/(2 r0)); Curtis et al., SIGGRAPH 1997 §4 (inversion from reflectances over white and
//! black). The paper (Ďurikovič & Ágošton 2007) Eqs. (3), (5), (8) print the first factor of the numerator as
//! (1 − R∞); it must be 1/R∞ (X = 0 must give R = Rg). Numerical choices: R∞ in the
//! rationalised form 1/(1 + x + √(x² + 2x)) (the textbook 1 + x − √(x² + 2x) cancels catastrophically for large
//! x = K/S: Goldberg, "What every computer scientist should know about floating-point arithmetic", ACM Comput.
//! Surv. 23 (1991) §1.4), coth through expm1 (no overflow for thick layers); tested below.

/// Reflectance of an infinitely thick layer, R∞ = 1 + K/S − sqrt((K/S)² + 2K/S) (paper Eq. 4), evaluated
/// free of cancellation for K/S up to 1e12 and beyond.
///
/// Rationalised form (multiply by the conjugate; R∞·(1/R∞) = 1 since R∞ = a − b, 1/R∞ = a + b):
/// R∞ = 1 / (1 + x + √x·√(x + 2)), x = K/S. The product √x·√(x+2) does not overflow for x up to f64::MAX.
/// x = 0 gives 1 (no absorption), x = +∞ gives 0.
pub fn r_infinity(k_over_s: f64) -> f64 {
    let x = k_over_s;
    if x > 1e150 {
        // 1 + x + √(x² + 2x) = 2x(1 + 1/x) to double precision; avoids overflow of the sum near f64::MAX.
        return (0.5 / x) / (1.0 + 1.0 / x);
    }
    1.0 / (1.0 + x + x.sqrt() * (x + 2.0).sqrt())
}

/// Diffuse reflectance (over black) and transmittance of a layer with absorption K, scattering S and
/// thickness X (K, S in inverse units of X). Over a background of reflectance Rg the layer reflects
/// R = r0 + t²·Rg / (1 − r0·Rg), which equals the corrected paper Eq. (3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layer {
    pub r0: f64,
    pub t: f64,
}

impl Layer {
    /// Reflectance of the layer over a background of reflectance `rg` ∈ [0, 1].
    ///
    /// Adding the multiple reflections between layer and background (Kubelka 1948 Eq. 7; a geometric
    /// series): R = r0 + t² Rg / (1 − r0 Rg). When t = 0 (opaque layer) the result is r0 exactly, which also
    /// avoids 0/0 for r0 = Rg = 1. If r0·Rg rounds to 1 (a non-absorbing layer so thick that r0 = 1 in f64,
    /// over a white background) the limit is R = r0 + t (≤ 1; exactly 1 for K = 0, where 1 − r0 = t).
    pub fn over(&self, rg: f64) -> f64 {
        let tt = self.t * self.t * rg;
        if tt == 0.0 {
            return self.r0;
        }
        let den = 1.0 - self.r0 * rg;
        if den <= 0.0 {
            return (self.r0 + self.t).min(1.0);
        }
        self.r0 + tt / den
    }
}

/// The layer operator for K, S ≥ 0 and X ≥ 0, exact for S·X → 0, S·X → ∞ (no overflow), K = 0 and S = 0.
///
/// Kubelka (1948): with a = 1 + K/S, b = √(a² − 1), z = bSX,
/// r0 = sinh z / (a sinh z + b cosh z), t = b / (a sinh z + b cosh z).
/// Evaluated stably (no overflow of cosh/sinh for large z, no 0/0 at K = 0) by dividing numerator and denominator by e^z and by b:
/// with m = −expm1(−2z) = 2e^{−z} sinh z, p = 1 + e^{−2z} = 2e^{−z} cosh z and u = m/b,
/// r0 = u/(a u + p), t = 2e^{−z}/(a u + p).
/// u = m/b is formed as 2SX·f(z), f(z) = −expm1(−2z)/(2z) (f(0) = 1), while z < 1/2, so that b → 0 (K → 0)
/// is regular; expm1 is correct to rounding for small z, which is what a Taylor series (1 − z + 2z²/3 …)
/// would provide. b² = (K/S)(2 + K/S) is formed as a product (no cancellation in a² − 1).
/// S·X → ∞: m, p → 1, e^{−z} → 0: r0 → 1/(a + b) = R∞, t → 0, no overflow.
/// Exact special cases: X = 0 → (0, 1); S = 0 → (0, e^{−KX}); K = 0 → (SX/(1 + SX), 1/(1 + SX));
/// K/S = +∞ (S negligible against K in f64) → (0, e^{−KX}).
pub fn layer(k: f64, s: f64, x: f64) -> Layer {
    if x == 0.0 {
        return Layer { r0: 0.0, t: 1.0 };
    }
    if s == 0.0 {
        return Layer { r0: 0.0, t: (-k * x).exp() };
    }
    let sx = s * x;
    let q = k / s;
    if q == 0.0 {
        // K = 0, or K/S below the smallest subnormal: the non-absorbing closed form.
        if sx.is_infinite() {
            return Layer { r0: 1.0, t: 0.0 };
        }
        return Layer { r0: sx / (1.0 + sx), t: 1.0 / (1.0 + sx) };
    }
    if q.is_infinite() {
        return Layer { r0: 0.0, t: (-k * x).exp() };
    }
    let a = 1.0 + q;
    let b = q.sqrt() * (2.0 + q).sqrt();
    let z = b * sx;
    let e1 = (-z).exp();
    let m = -(-2.0 * z).exp_m1();
    let p = 1.0 + e1 * e1;
    let u = if z == 0.0 {
        2.0 * sx // S·X underflowed (or b did): f(0) = 1
    } else if z < 0.5 {
        2.0 * sx * (m / (2.0 * z))
    } else {
        m / b
    };
    if u > 1.0 {
        // Divide through by u: no overflow of a·u when S·X is huge and b tiny.
        let den = a + p / u;
        Layer { r0: 1.0 / den, t: (2.0 * e1 / u) / den }
    } else {
        let den = a * u + p;
        Layer { r0: u / den, t: 2.0 * e1 / den }
    }
}

/// Reflectance of a layer over a background (paper Eq. 3, corrected), = `layer(k, s, x).over(rg)`.
pub fn layer_reflectance(k: f64, s: f64, x: f64, rg: f64) -> f64 {
    layer(k, s, x).over(rg)
}

/// Mixing by concentration: K = Σ Cᵢ Kᵢ, S = Σ Cᵢ Sᵢ (Duncan's rule). Items are (C, K, S).
pub(crate) fn mix(pigments: impl IntoIterator<Item = (f64, f64, f64)>) -> (f64, f64) {
    pigments.into_iter().fold((0.0, 0.0), |(k, s), (c, ki, si)| (k + c * ki, s + c * si))
}

/// K and S of a layer of thickness `x` from its reflectance over a white background of reflectance
/// `white_bg` and over an ideal black background (Curtis et al. 1997 §4 generalised to a non-ideal white).
///
/// Over black the layer reflects r0 = R_b. Over the white background g, R_w = r0 + t² g/(1 − r0 g), hence
/// t² = (R_w − r0)(1 − r0 g)/g. Kubelka (1948): a = (1 + r0² − t²)/(2 r0), computed as
/// a − 1 = K/S = (1 − r0 − t)(1 − r0 + t)/(2 r0) (no cancellation); b = √((a − 1)(a + 1));
/// coth(bSX) = (1 − a r0)/(b r0), so SX = arcoth((1 − a r0)/(b r0))/b = atanh(w)/b with w = b r0/(1 − a r0),
/// evaluated as SX = r0/(1 − a r0) · atanh(w)/w, which is regular as b → 0 (K → 0: SX = r0/t).
/// Then S = SX/X, K = S (a − 1).
///
/// Errors (with the reason) when the data cannot come from a Kubelka–Munk layer: non-finite input, X ≤ 0,
/// g ∉ (0, 1], R_b ≤ 0 (no scattering information), R_w ≤ R_b, R_w > 1, r0 + t > 1 (more light out than
/// in), or r0 ≥ R∞(a) (the layer would be thicker than infinite).
pub(crate) fn invert_white_black(
    r_over_white: f64,
    r_over_black: f64,
    white_bg: f64,
    x: f64,
) -> Result<(f64, f64), String> {
    let (rw, r0, g) = (r_over_white, r_over_black, white_bg);
    if ![rw, r0, g, x].iter().all(|v| v.is_finite()) {
        return Err(format!(
            "Kubelka–Munk inversion: inputs must be finite (R_white = {rw}, R_black = {r0}, white background = {g}, X = {x})"
        ));
    }
    if x <= 0.0 {
        return Err(format!("Kubelka–Munk inversion: thickness X must be > 0, got {x}"));
    }
    if !(g > 0.0 && g <= 1.0) {
        return Err(format!("Kubelka–Munk inversion: white background reflectance must be in (0, 1], got {g}"));
    }
    if r0 <= 0.0 {
        return Err(format!(
            "Kubelka–Munk inversion: reflectance over black must be > 0 (got {r0}); a layer that reflects nothing \
             over black has no measurable scattering"
        ));
    }
    if rw > 1.0 {
        return Err(format!("Kubelka–Munk inversion: reflectance over white must be ≤ 1, got {rw}"));
    }
    if rw <= r0 {
        return Err(format!(
            "Kubelka–Munk inversion: reflectance over white ({rw}) must exceed reflectance over black ({r0}); \
             equal values mean an opaque layer, whose K and S cannot be separated"
        ));
    }
    let t2 = (rw - r0) * (1.0 - r0 * g) / g;
    let t = t2.sqrt();
    let excess = 1.0 - r0 - t;
    if excess < -1e-12 {
        return Err(format!(
            "Kubelka–Munk inversion: inconsistent data, R_black + transmittance = {} > 1 (R_white = {rw}, \
             R_black = {r0}, white background = {g})",
            r0 + t
        ));
    }
    let q = (excess.max(0.0) * (1.0 - r0 + t) / (2.0 * r0)).max(0.0); // a − 1 = K/S
    let a = 1.0 + q;
    let b = (q * (2.0 + q)).sqrt();
    let d = 1.0 - a * r0;
    let w = b * r0 / d;
    if d <= 0.0 || w >= 1.0 {
        return Err(format!(
            "Kubelka–Munk inversion: inconsistent data, reflectance over black ({r0}) is not below the \
             reflectance of an infinitely thick layer with the implied K/S = {q}"
        ));
    }
    let atanh_ratio = if w == 0.0 { 1.0 } else { w.atanh() / w };
    let sx = r0 / d * atanh_ratio;
    let s = sx / x;
    Ok((q * s, s))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Paper Eq. (3) with the corrected first factor 1/R∞, typed straight from the paper (exponential form).
    /// Test-only: it overflows for large S·X and is 0/0 for K = 0; used where it is numerically fine.
    fn paper_eq3_corrected(k: f64, s: f64, x: f64, rg: f64) -> f64 {
        let ri = 1.0 + k / s - ((k / s).powi(2) + 2.0 * k / s).sqrt(); // Eq. (4) as printed
        let e = (s * x * (1.0 / ri - ri)).exp();
        ((1.0 / ri) * (rg - ri) - ri * (rg - 1.0 / ri) * e) / ((rg - ri) - (rg - 1.0 / ri) * e)
    }

    /// Paper Eq. (3) exactly as printed, with (1 − R∞) as the first factor.
    fn paper_eq3_as_printed(k: f64, s: f64, x: f64, rg: f64) -> f64 {
        let ri = 1.0 + k / s - ((k / s).powi(2) + 2.0 * k / s).sqrt();
        let e = (s * x * (1.0 / ri - ri)).exp();
        ((1.0 - ri) * (rg - ri) - ri * (rg - 1.0 / ri) * e) / ((rg - ri) - (rg - 1.0 / ri) * e)
    }

    fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
        (0..n).map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64)).collect()
    }

    /// R∞ is the root < 1 of the Kubelka–Munk function: (1 − R∞)²/(2R∞) = K/S, for K/S from 1e-12 to 1e12
    /// (tolerance accounts for the conditioning of the check itself, 1/(1 − R∞)); limits 0 → 1, ∞ → 0.
    #[test]
    fn r_infinity_solves_km_function() {
        for q in log_grid(1e-12, 1e12, 97) {
            let r = r_infinity(q);
            assert!(r > 0.0 && r < 1.0);
            let back = (1.0 - r) * (1.0 - r) / (2.0 * r);
            let tol = 8.0 * f64::EPSILON / (1.0 - r) + 4.0 * f64::EPSILON;
            assert!(((back - q) / q).abs() < tol, "q={q} back={back}");
        }
        assert_eq!(r_infinity(0.0), 1.0);
        assert_eq!(r_infinity(f64::INFINITY), 0.0);
        // asymptote R∞ = 1/(2q) − 1/q² + O(q⁻³) for large q (no cancellation to 0)
        for q in [1e12, 1e100, 1e300, f64::MAX] {
            let r = r_infinity(q);
            assert!(r > 0.0 && ((r * 2.0 * q) - 1.0).abs() < 1e-11, "q={q} r={r}");
        }
    }

    /// The naive printed Eq. (4) agrees where it has no cancellation (K/S ≤ 1).
    #[test]
    fn r_infinity_matches_printed_form_where_benign() {
        for q in log_grid(1e-6, 1.0, 25) {
            let naive = 1.0 + q - (q * q + 2.0 * q).sqrt();
            assert!((r_infinity(q) - naive).abs() < 1e-15);
        }
    }

    /// X = 0 gives the background; so does the corrected Eq. (3), while the printed Eq. (3) does not.
    #[test]
    fn zero_thickness_gives_background() {
        for &(k, s) in &[(0.0, 0.0), (0.0, 2.0), (3.0, 0.0), (0.5, 2.0), (100.0, 0.01)] {
            for rg in [0.0, 0.2, 0.7, 1.0] {
                assert_eq!(layer(k, s, 0.0), Layer { r0: 0.0, t: 1.0 });
                assert_eq!(layer_reflectance(k, s, 0.0, rg), rg);
            }
        }
        for rg in [0.0, 0.2, 0.7] {
            assert!((paper_eq3_corrected(0.5, 2.0, 0.0, rg) - rg).abs() < 1e-14);
            // the printed form gives something else: proves the (1 − R∞) → 1/R∞ correction
            assert!((paper_eq3_as_printed(0.5, 2.0, 0.0, rg) - rg).abs() > 1e-2, "rg={rg}");
        }
    }

    /// S·X → ∞ gives R∞ whatever the background, no NaN or inf (S·X = 1e4, 1e6, 1e300).
    #[test]
    fn infinite_thickness_gives_r_infinity() {
        for q in [1e-6, 0.01, 1.0, 100.0, 1e8] {
            for sx in [1e4, 1e6, 1e300] {
                let l = layer(q, 1.0, sx);
                assert!(l.r0.is_finite() && l.t.is_finite());
                for rg in [0.0, 0.5, 1.0] {
                    let r = l.over(rg);
                    let ri = r_infinity(q);
                    // for q = 1e-6, z = √(2q)·SX = 14 at SX = 1e4: e^{-2z} ≈ 7e-13 remains
                    assert!((r - ri).abs() < 2e-12, "q={q} sx={sx} rg={rg} r={r} ri={ri}");
                }
            }
        }
        assert_eq!(layer(1.0, 1.0, 1e6).t, 0.0);
    }

    /// K = 0 closed form SX/(1+SX), 1/(1+SX) (Kubelka 1948) and continuity of the general path as K → 0+;
    /// S = 0 closed form (0, e^{−KX}) and continuity as S → 0+; energy: r0 + t = 1 when K = 0.
    #[test]
    fn closed_form_limits() {
        for sx in [1e-8, 1e-3, 0.5, 1.0, 7.0, 1e3] {
            let l = layer(0.0, sx, 1.0);
            assert!((l.r0 - sx / (1.0 + sx)).abs() < 1e-16 && (l.t - 1.0 / (1.0 + sx)).abs() < 1e-16);
            assert!((l.r0 + l.t - 1.0).abs() < 1e-15);
            // K/S = q perturbs r0 and t by O(q·SX²): keep that below 1e-13.
            let q = 1e-13 / (1.0 + sx * sx);
            let near = layer(q * sx, sx, 1.0);
            assert!((near.r0 - l.r0).abs() < 1e-11 && (near.t - l.t).abs() < 1e-11, "sx={sx} {near:?} {l:?}");
        }
        for kx in [1e-8, 1e-3, 0.5, 1.0, 7.0, 30.0] {
            let l = layer(kx, 0.0, 1.0);
            assert_eq!(l.r0, 0.0);
            assert!((l.t - (-kx).exp()).abs() < 1e-16);
            let near = layer(kx, 1e-13 * kx, 1.0);
            assert!(near.r0 < 1e-12 && (near.t - l.t).abs() < 1e-12, "kx={kx} {near:?}");
        }
        assert_eq!(layer(0.0, 0.0, 5.0), Layer { r0: 0.0, t: 1.0 });
    }

    /// The hyperbolic operator agrees with the corrected paper Eq. (3) (exponential form) to 1e-13 where
    /// the latter is numerically fine (moderate K/S and S·X).
    #[test]
    fn agrees_with_corrected_paper_eq3() {
        for q in [0.01, 0.1, 0.5, 1.0, 3.0, 10.0] {
            for sx in [0.01, 0.1, 0.5, 1.0, 2.0, 5.0] {
                for rg in [0.0, 0.1, 0.5, 0.9, 1.0] {
                    let s = 2.0;
                    let (k, x) = (q * s, sx / s);
                    let a = layer_reflectance(k, s, x, rg);
                    let b = paper_eq3_corrected(k, s, x, rg);
                    assert!((a - b).abs() < 1e-13, "q={q} sx={sx} rg={rg}: {a} vs {b}");
                }
            }
        }
    }

    /// Kubelka (1948) identity of a layer: a = (1 + r0² − t²)/(2 r0), a = 1 + K/S, and r0 + t ≤ 1.
    #[test]
    fn kubelka_identity() {
        for q in [1e-4, 0.01, 0.3, 1.0, 5.0, 50.0] {
            for sx in [1e-3, 0.1, 1.0, 3.0, 10.0] {
                let l = layer(q, 1.0, sx);
                let a = (1.0 + l.r0 * l.r0 - l.t * l.t) / (2.0 * l.r0);
                assert!((a - (1.0 + q)).abs() < 1e-12 * (1.0 + q) / l.r0.min(1.0), "q={q} sx={sx} a={a}");
                assert!(l.r0 + l.t <= 1.0 + 1e-15);
            }
        }
    }

    /// Stacking: a layer of thickness X1 + X2 equals a layer X1 over a layer X2 over the background (the
    /// two-flux equations are linear and homogeneous in depth), for several backgrounds.
    #[test]
    fn composition_of_sublayers() {
        for &(k, s) in &[(0.0, 1.0), (0.3, 1.0), (2.0, 0.5), (10.0, 30.0), (1.0, 0.0)] {
            for &(x1, x2) in &[(0.1, 0.2), (1.0, 1.0), (0.01, 3.0), (5.0, 0.5)] {
                for rg in [0.0, 0.4, 1.0] {
                    let whole = layer_reflectance(k, s, x1 + x2, rg);
                    let split = layer_reflectance(k, s, x1, layer_reflectance(k, s, x2, rg));
                    assert!((whole - split).abs() < 1e-14, "k={k} s={s} x={x1}+{x2} rg={rg}");
                }
            }
        }
    }

    /// Inversion round-trips (K, S) to 1e-10 for ideal and non-ideal white backgrounds. The inversion is
    /// ill-conditioned for nearly opaque layers (R_w − R_b ∝ t² loses digits), so cases with t < 0.05 are
    /// skipped; at least 30 cases must remain.
    #[test]
    fn inversion_round_trip() {
        let mut n = 0;
        for &(k, s) in &[(0.05, 2.0), (0.5, 2.0), (1.0, 1.0), (3.0, 10.0), (1e-6, 1.0), (0.2, 0.3)] {
            for x in [0.05, 0.1, 0.5, 1.0] {
                for g in [1.0, 0.8] {
                    let l = layer(k, s, x);
                    if l.t < 0.05 {
                        continue;
                    }
                    n += 1;
                    let (rw, rb) = (l.over(g), l.r0);
                    let (k2, s2) = invert_white_black(rw, rb, g, x).unwrap();
                    assert!((k2 - k).abs() < 1e-10 * k.max(1.0), "k: {k} vs {k2} (s={s} x={x} g={g})");
                    assert!((s2 - s).abs() < 1e-10 * s.max(1.0), "s: {s} vs {s2} (k={k} x={x} g={g})");
                }
            }
        }
        assert!(n >= 30, "{n}");
        // K = 0 exactly: r0 + t = 1, recovered K is 0 (to rounding) and S = r0/(t X).
        let l = layer(0.0, 2.0, 0.5);
        let (k2, s2) = invert_white_black(l.over(1.0), l.r0, 1.0, 0.5).unwrap();
        assert!(k2.abs() < 1e-12 && (s2 - 2.0).abs() < 1e-12, "{k2} {s2}");
    }

    /// Inconsistent data are rejected with a message naming the problem.
    #[test]
    fn inversion_rejects_inconsistent_data() {
        let cases = [
            (0.5, 0.5, 1.0, 1.0, "must exceed"),
            (0.4, 0.5, 1.0, 1.0, "must exceed"),
            (0.5, 0.0, 1.0, 1.0, "over black must be > 0"),
            (0.5, 0.2, 1.0, 0.0, "thickness"),
            (0.5, 0.2, 0.0, 1.0, "white background"),
            (1.2, 0.2, 1.0, 1.0, "≤ 1"),
            (f64::NAN, 0.2, 1.0, 1.0, "finite"),
            (0.95, 0.6, 0.5, 1.0, "> 1"), // t² = 0.35·0.7/0.5 = 0.49: r0 + t = 1.3 > 1
        ];
        for (rw, rb, g, x, msg) in cases {
            let e = invert_white_black(rw, rb, g, x).unwrap_err();
            assert!(e.contains(msg), "({rw},{rb},{g},{x}) -> {e}");
        }
    }

    /// Robustness: any finite non-negative input gives finite r0, t in [0, 1] with r0 + t ≤ 1.
    #[test]
    fn no_nan_for_extreme_inputs() {
        let vals = [0.0, 5e-324, 1e-300, 1e-12, 1.0, 1e12, 1e300, f64::MAX];
        for &k in &vals {
            for &s in &vals {
                for &x in &vals {
                    let l = layer(k, s, x);
                    assert!(l.r0.is_finite() && l.t.is_finite(), "k={k:e} s={s:e} x={x:e} {l:?}");
                    assert!((0.0..=1.0).contains(&l.r0) && (0.0..=1.0).contains(&l.t), "k={k:e} s={s:e} x={x:e} {l:?}");
                    assert!(l.r0 + l.t <= 1.0 + 1e-15, "k={k:e} s={s:e} x={x:e} {l:?}");
                    for rg in [0.0, 0.5, 1.0] {
                        let r = l.over(rg);
                        assert!(r.is_finite() && (0.0..=1.0 + 1e-15).contains(&r), "k={k:e} s={s:e} x={x:e} rg={rg}");
                    }
                }
            }
        }
    }
}
