//! Fresnel equations for dielectric and conducting interfaces.
//!
//! Sources: Born & Wolf, *Principles of Optics*, 7th ed., §1.5.2 (Eqs. 20–21 for the amplitude ratios and
//! §1.5.3 for the power ratios with the n·cos θ factor), §14.2 (metals: complex index, decaying wave);
//! Byrnes, *Multilayer optical calculations*, arXiv:1603.02720, §2 and App. D (branch of n cos θ);
//! pbrt-v4 `util/scattering.h` (`FrDielectric`, `FrConductor`) for the interface of the functions.
//! The paper (Ďurikovič & Ágošton 2007) prints Eq. (2)'s transmittance factor with the cosine ratio
//! inverted; the implemented (correct) form is T = η₂ cos θt / (η₁ cos θi) · |t|², see `docs/optics.md`.
use crate::Vec3;
use num_complex::Complex64;

/// Power reflectances and transmittances of a planar interface, s and p polarisation.
/// Transmittances carry the factor (n2 cos θt)/(n1 cos θi) so that R + T = 1 on a lossless interface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FresnelPower {
    pub rs: f64,
    pub rp: f64,
    pub ts: f64,
    pub tp: f64,
}

impl FresnelPower {
    /// Unpolarised reflectance (Rs + Rp)/2.
    pub(crate) fn r(&self) -> f64 {
        0.5 * (self.rs + self.rp)
    }
    /// Unpolarised transmittance (Ts + Tp)/2.
    pub fn t(&self) -> f64 {
        0.5 * (self.ts + self.tp)
    }
}

/// Complex amplitude coefficients of an interface (for thin-film stacks).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Amplitudes {
    pub rs: Complex64,
    pub rp: Complex64,
    pub ts: Complex64,
    pub tp: Complex64,
}

/// cos θt by Snell's law for relative index `eta` = n2/n1 and cos θi ∈ [0, 1]; `None` on total internal
/// reflection.
///
/// Snell's law n₁ sin θi = n₂ sin θt (Born & Wolf §1.5.1, Eq. 8): sin²θt = (1 − cos²θi)/η², and
/// cos θt = √(1 − sin²θt) taken on the forward (positive) branch. `None` when sin²θt > 1 (beyond the
/// critical angle; only possible for η < 1). At exactly the critical angle the result is `Some(0.0)`.
/// `cos_i` is clamped to [0, 1] to absorb rounding in callers' dot products.
pub(crate) fn cos_transmitted(cos_i: f64, eta: f64) -> Option<f64> {
    let c = cos_i.clamp(0.0, 1.0);
    // 1 − c² = (1 − c)(1 + c): no cancellation near normal incidence.
    let sin2_t = (1.0 - c) * (1.0 + c) / (eta * eta);
    if sin2_t > 1.0 {
        None
    } else {
        Some(((1.0 - sin2_t).max(0.0)).sqrt())
    }
}

/// The cosine of the critical angle of an interface into a medium of relative index `eta` < 1, the cosine
/// below which total internal reflection sets in (sin θc = η, Born & Wolf §1.5.4); `None` for η ≥ 1 (no
/// critical angle). The reflectance is continuous there but its derivative is not: just above cos θc,
/// 1 − R ∝ √(cos θi − cos θc)·…, since cos θt = √(1 − sin²θi/η²) vanishes like a square root. A quadrature
/// needs this point on a boundary of its partition (`brdf::Kink`).
pub(crate) fn critical_cosine(eta: f64) -> Option<f64> {
    (eta > 0.0 && eta < 1.0).then(|| ((1.0 - eta) * (1.0 + eta)).sqrt())
}

/// The critical cosine of a conductor index n + ik: the same as [`critical_cosine`] when k = 0 (the index is
/// then a real index below 1 and the Fresnel reflectance has the same kink); `None` when k > 0 (n̂ cos θt
/// never vanishes and the reflectance is smooth, however sharp its knee is for a small k).
pub(crate) fn critical_cosine_complex(eta: Complex64) -> Option<f64> {
    if eta.im == 0.0 {
        critical_cosine(eta.re)
    } else {
        None
    }
}

/// s/p power coefficients of a dielectric interface, relative index `eta` = n2/n1 > 0, cos θi ∈ [0, 1].
/// Beyond the critical angle Rs = Rp = 1, Ts = Tp = 0.
///
/// Born & Wolf §1.5.2 Eq. (21) with η = n₂/n₁, c = cos θi, c′ = cos θt:
/// r_s = (c − η c′)/(c + η c′), r_p = (η c − c′)/(η c + c′), t_s = 2c/(c + η c′), t_p = 2c/(η c + c′);
/// power ratios (§1.5.3) R = r², T = (η c′/c)·t², i.e. T_s = 4ηcc′/(c + ηc′)², T_p = 4ηcc′/(ηc + c′)²
/// (written this way the grazing limit c = 0 gives T = 0 without 0/0). The paper's Eq. (2) prints the factor
/// as η₂ cos θi/(η₁ cos θt), which violates R + T = 1; see `docs/optics.md` §Corrections.
/// η = 1 is no interface: R = 0, T = 1 at every angle (also at grazing incidence, where the general
/// expressions are 0/0).
pub fn fresnel_dielectric(cos_i: f64, eta: f64) -> FresnelPower {
    if eta == 1.0 {
        return FresnelPower { rs: 0.0, rp: 0.0, ts: 1.0, tp: 1.0 };
    }
    let c = cos_i.clamp(0.0, 1.0);
    let Some(ct) = cos_transmitted(c, eta) else {
        return FresnelPower { rs: 1.0, rp: 1.0, ts: 0.0, tp: 0.0 };
    };
    let ds = c + eta * ct;
    let dp = eta * c + ct;
    let rs = (c - eta * ct) / ds;
    let rp = (eta * c - ct) / dp;
    let num = 4.0 * eta * c * ct;
    FresnelPower { rs: rs * rs, rp: rp * rp, ts: num / (ds * ds), tp: num / (dp * dp) }
}

/// Unpolarised reflectance of a dielectric interface (pbrt-v4 `FrDielectric`).
pub fn fr_dielectric(cos_i: f64, eta: f64) -> f64 {
    fresnel_dielectric(cos_i, eta).r()
}

/// s/p reflectance of an interface from a real medium into a conductor of relative complex index
/// `eta` = (n + ik)/n1, k ≥ 0. The transmitted wave is the decaying one. Ts, Tp are 1 − Rs, 1 − Rp (absorbed).
///
/// Born & Wolf §14.2: the Fresnel amplitudes hold unchanged with the complex index n̂ = n + ik and the
/// complex cos θt = √(n̂² − sin²θi)/n̂, on the branch Im(n̂ cos θt) ≥ 0 (wave decaying into the metal; Byrnes
/// arXiv:1603.02720 App. D). R = |r|² from [`amplitudes`] with n₁ = 1, n₂ = η. With k = 0 this reproduces
/// [`fresnel_dielectric`] (including total internal reflection for η < 1, where n̂ cos θt is purely
/// imaginary and |r| = 1).
pub fn fresnel_conductor(cos_i: f64, eta: Complex64) -> FresnelPower {
    let one = Complex64::new(1.0, 0.0);
    let c1 = Complex64::new(cos_i.clamp(0.0, 1.0), 0.0);
    if eta == one {
        return FresnelPower { rs: 0.0, rp: 0.0, ts: 1.0, tp: 1.0 };
    }
    let c2 = complex_cos_transmitted(one, c1, eta);
    let a = amplitudes(one, c1, eta, c2);
    let rs = a.rs.norm_sqr().min(1.0);
    let rp = a.rp.norm_sqr().min(1.0);
    FresnelPower { rs, rp, ts: 1.0 - rs, tp: 1.0 - rp }
}

/// Unpolarised conductor reflectance (pbrt-v4 `FrConductor`).
pub fn fr_conductor(cos_i: f64, eta: Complex64) -> f64 {
    fresnel_conductor(cos_i, eta).r()
}

/// n2·cos θ2 = sqrt(n2² − n1² sin² θ1) for complex indices, with the branch of the decaying (or, for real
/// media, forward-propagating) wave chosen explicitly, signed zeros included. Returns cos θ2.
///
/// Snell's law n₁ sin θ₁ = n₂ sin θ₂ gives (n₂ cos θ₂)² = n₂² − n₁²(1 − cos²θ₁) (Born & Wolf §14.2,
/// Byrnes arXiv:1603.02720 Eq. 3). Of the two square roots the one with Im ≥ 0 is the wave decaying
/// along +z (e^{i k₀ n₂ cos θ₂ z}); if Im = 0 the one with Re ≥ 0 propagates forward. `Complex64::sqrt` is
/// principal and honours signed zero (√(−a − 0i) = −i√a, the growing branch), so the branch is fixed
/// after the root: negate if Im < 0, or Im = 0 and Re < 0 (the decaying-wave branch, Im ≥ 0 under n + ik: Byrnes, "Multilayer optical calculations", arXiv:1603.02720, App. D).
/// If n₂ = 0 the cosine is undefined; the function then returns NaN (not a physical medium).
pub(crate) fn complex_cos_transmitted(n1: Complex64, cos1: Complex64, n2: Complex64) -> Complex64 {
    let one = Complex64::new(1.0, 0.0);
    let sin2 = (one - cos1) * (one + cos1);
    let n2cos2 = forward_sqrt(n2 * n2 - n1 * n1 * sin2);
    n2cos2 / n2
}

/// n₂ cos θ₂ in a medium of index `n2` (complex allowed) for light arriving from a real medium of index `n1` at
/// cos θ₁ = `mu` ∈ [0, 1], on the forward/decaying branch ([`forward_sqrt`]), without cancellation.
///
/// The same identity as [`complex_cos_transmitted`]'s, (n₂ cos θ₂)² = n₂² − n₁²(1 − μ²) (Snell, Born & Wolf
/// §1.5.1 and §14.2), regrouped as (n₂ − n₁)(n₂ + n₁) + (n₁μ)² (`docs/model.md` §Evaluation cost, "Where the
/// direct evaluation is the noise"): n₂ − n₁ is exact for real indices within a factor 2 of each other
/// (Sterbenz), so each term is good to a few ulp of itself, and where both are ≥ 0 (n₂ ≥ n₁, or n₂ = n₁: the
/// result is then n₁μ to an ulp) so is the sum: the error is relative to the result however small μ is,
/// where n₂² − n₁²(1 − μ)(1 + μ) is a difference of two numbers of size n₁² and loses digits like 10⁻¹⁶/cos².
/// Below n₁ (n₂ < n₁, a critical cosine μc) the sum still cancels next to μc: [`ncos_near_critical`]. For a
/// complex n₂ = a + ib the product is (a − n₁)(a + n₁) − b² + 2iab, the same value as before to rounding.
pub(crate) fn ncos_from_real(n1: f64, mu: f64, n2: Complex64) -> Complex64 {
    let nm = n1 * mu;
    forward_sqrt((n2 - n1) * (n2 + n1) + nm * nm)
}

/// n₂ cos θ₂ for a real n₂ < n₁ next to the critical cosine μc = √(1 − (n₂/n₁)²) ([`critical_cosine`]), from
/// the offset δ = μ − μc as the caller has it exactly (a table's segment variable, δ = h·s²,
/// `optics::tabulated`): n₂² − n₁²(1 − μ²) = n₁²(μ² − μc²) = n₁²·δ(2μc + δ), so
/// n₂ cos θ₂ = n₁√(δ(2μc + δ)), imaginary (i n₁√|…|, the decaying wave) below μc (`docs/model.md`
/// §Evaluation cost, "Where the direct evaluation is the noise"). Its relative error is a few ulp at any
/// δ, for the function whose kink is at the given (rounded) μc; computed from μ itself the cosine carries an
/// absolute error ~10⁻¹⁶/cos θ₂ there.
pub(crate) fn ncos_near_critical(n1: f64, mu_c: f64, offset: f64) -> Complex64 {
    forward_sqrt(Complex64::new(offset * (2.0 * mu_c + offset), 0.0)) * n1
}

/// √w on the forward/decaying branch: Im ≥ 0, and Re ≥ 0 when Im = 0 (signed zeros normalised).
pub(crate) fn forward_sqrt(w: Complex64) -> Complex64 {
    let r = w.sqrt();
    let r = if r.im < 0.0 || (r.im == 0.0 && r.re < 0.0) { -r } else { r };
    // Normalise a negative zero to +0 so that downstream signs are deterministic.
    Complex64::new(r.re + 0.0, r.im + 0.0)
}

/// Amplitude coefficients r, t (s and p) from medium n1 at cos θ1 into medium n2 at cos θ2.
///
/// Born & Wolf §1.5.2 Eq. (21), the convention also used by Byrnes (arXiv:1603.02720 Eqs. 5–8) and `tmm`:
/// r_s = (n₁c₁ − n₂c₂)/(n₁c₁ + n₂c₂), t_s = 2n₁c₁/(n₁c₁ + n₂c₂),
/// r_p = (n₂c₁ − n₁c₂)/(n₂c₁ + n₁c₂), t_p = 2n₁c₁/(n₂c₁ + n₁c₂).
/// With this convention r₂₁ = −r₁₂ and t₁₂t₂₁ − r₁₂r₂₁ = 1, as the Airy recursion of
/// [`crate::optics::thin_film`] requires.
pub(crate) fn amplitudes(n1: Complex64, cos1: Complex64, n2: Complex64, cos2: Complex64) -> Amplitudes {
    let s1 = n1 * cos1;
    let s2 = n2 * cos2;
    let p1 = n2 * cos1;
    let p2 = n1 * cos2;
    let ds = s1 + s2;
    let dp = p1 + p2;
    Amplitudes { rs: (s1 - s2) / ds, rp: (p1 - p2) / dp, ts: 2.0 * s1 / ds, tp: 2.0 * s1 / dp }
}

/// The direction inside a medium of relative index `eta` = n2/n1 of a ray that crosses a smooth interface
/// with normal +z along the exterior direction `w` (z > 0). The result also points away from the surface
/// (z > 0): the same ray path, seen from inside. `None` on total internal reflection (possible when eta < 1).
///
/// Snell's law in vector form (Born & Wolf §1.5.1; pbrt-v4 `Refract`): the tangential component scales by
/// 1/η and keeps its azimuth, w′ = (w_x/η, w_y/η, cos θt), cos θt = √(1 − (w_x² + w_y²)/η²). The
/// tangential part is taken from the components (not from 1 − w_z²) so that near-normal directions keep
/// full relative precision. `w` is assumed to be a unit vector; the result is then a unit vector.
pub(crate) fn refract_into(w: Vec3, eta: f64) -> Option<Vec3> {
    let sin2_t = (w.x * w.x + w.y * w.y) / (eta * eta);
    if sin2_t > 1.0 {
        return None;
    }
    Some(Vec3::new(w.x / eta, w.y / eta, (1.0 - sin2_t).max(0.0).sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }

    /// At the critical cosine the transmitted cosine is 0 (Snell's law at sin θi = η) and R = 1; just above it
    /// R < 1 with 1 − R growing like a square root (the kink), and just below it R = 1.
    #[test]
    fn the_critical_cosine_is_where_total_internal_reflection_starts() {
        for eta in [0.05, 0.3375, 0.5, 0.95] {
            let c = critical_cosine(eta).unwrap();
            assert!(cos_transmitted(c * (1.0 + 1e-12), eta).unwrap() < 1e-4, "η = {eta}");
            assert_eq!(fr_dielectric(c * (1.0 - 1e-12), eta), 1.0);
            let (d1, d2) = (1e-12, 4e-12);
            let (r1, r2) = (1.0 - fr_dielectric(c + d1, eta), 1.0 - fr_dielectric(c + d2, eta));
            assert!(r1 > 0.0 && (r2 / r1 - 2.0).abs() < 1e-2, "√ growth: {r1} {r2}");
            assert_eq!(critical_cosine_complex(c64(eta, 0.0)), Some(c));
            assert!((1.0 - fr_conductor(c * (1.0 - 1e-12), c64(eta, 0.0))).abs() < 1e-15);
        }
        assert_eq!(critical_cosine(1.0), None);
        assert_eq!(critical_cosine(1.5), None);
        assert_eq!(critical_cosine_complex(c64(0.3, 1e-3)), None);
    }

    fn c64(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }

    const ETAS: [f64; 9] = [0.25, 0.5, 1.0 / 1.5, 0.95, 1.0, 1.05, 1.5, 2.5, 4.0];

    /// Energy conservation on a lossless interface (Born & Wolf §1.5.3): R + T = 1 for s and p, for
    /// η above and below 1, at 0..90°, including the TIR region.
    #[test]
    fn dielectric_r_plus_t_is_one() {
        for &eta in &ETAS {
            for i in 0..=900 {
                let th = (i as f64) * 0.1_f64.to_radians();
                let f = fresnel_dielectric(th.cos(), eta);
                assert!((f.rs + f.ts - 1.0).abs() < 1e-14, "s eta={eta} th={th} {f:?}");
                assert!((f.rp + f.tp - 1.0).abs() < 1e-14, "p eta={eta} th={th} {f:?}");
                assert!((0.0..=1.0).contains(&f.rs) && (0.0..=1.0).contains(&f.rp));
            }
        }
    }

    /// The paper's Eq. (2) as printed, τ = η₂ cos θi/(η₁ cos θt)·t², violates R + T = 1 at oblique incidence;
    /// the implemented factor η₂ cos θt/(η₁ cos θi) satisfies it (see `dielectric_r_plus_t_is_one`).
    #[test]
    fn printed_eq2_transmittance_factor_is_wrong() {
        let (eta, th) = (1.5f64, 60f64.to_radians());
        let (ci, ct) = (th.cos(), cos_transmitted(th.cos(), eta).unwrap());
        let ts_amp = 2.0 * ci / (ci + eta * ct);
        let printed = eta * ci / ct * ts_amp * ts_amp;
        let f = fresnel_dielectric(ci, eta);
        assert!((f.rs + printed - 1.0).abs() > 0.1, "{}", f.rs + printed);
        assert!((f.rs + eta * ct / ci * ts_amp * ts_amp - 1.0).abs() < 1e-15);
    }

    /// Normal incidence: R = ((η − 1)/(η + 1))² for both polarisations (Born & Wolf §1.5.3 Eq. 33).
    #[test]
    fn normal_incidence_closed_form() {
        for &eta in &ETAS {
            let f = fresnel_dielectric(1.0, eta);
            let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
            assert!((f.rs - r0).abs() < 1e-16 && (f.rp - r0).abs() < 1e-16, "{eta}");
            assert!((fr_dielectric(1.0, eta) - r0).abs() < 1e-16);
        }
    }

    /// Brewster's angle tan θB = η: R_p vanishes (Born & Wolf §1.5.3), R_s does not.
    #[test]
    fn brewster_angle() {
        for &eta in &[0.5f64, 1.0 / 1.5, 1.5, 2.5] {
            let th_b = eta.atan();
            let f = fresnel_dielectric(th_b.cos(), eta);
            assert!(f.rp < 1e-30, "eta={eta} Rp={}", f.rp);
            assert!(f.rs > 1e-3);
            // and Rp is not identically small: it grows away from θB.
            assert!(fresnel_dielectric((th_b + 0.1).cos(), eta).rp > 1e-4);
        }
    }

    /// Beyond the critical angle sin θc = η (η < 1) the reflectance is 1 (TIR); just below it, it is < 1.
    #[test]
    fn total_internal_reflection() {
        for &eta in &[0.25f64, 0.5, 1.0 / 1.5, 0.95] {
            let th_c = eta.asin();
            assert!(cos_transmitted((th_c + 1e-9).cos(), eta).is_none());
            for k in 1..50 {
                let th = th_c + (std::f64::consts::FRAC_PI_2 - th_c) * k as f64 / 50.0;
                let f = fresnel_dielectric(th.cos(), eta);
                assert_eq!((f.rs, f.rp, f.ts, f.tp), (1.0, 1.0, 0.0, 0.0));
                let fc = fresnel_conductor(th.cos(), c(eta, 0.0));
                assert!((fc.rs - 1.0).abs() < 1e-14 && (fc.rp - 1.0).abs() < 1e-14);
            }
            let f = fresnel_dielectric((th_c - 1e-3).cos(), eta);
            assert!(f.r() < 1.0 && f.t() > 0.0);
        }
    }

    /// Snell's law: η sin θt = sin θi for `cos_transmitted` and for `refract_into`; the refracted
    /// direction is a unit vector that keeps the azimuth; None on TIR.
    #[test]
    fn snell_law_and_refract_into() {
        for &eta in &ETAS {
            for i in 0..90 {
                let th = (i as f64).to_radians();
                let phi = 0.3 * i as f64;
                let w = Vec3::new(th.sin() * phi.cos(), th.sin() * phi.sin(), th.cos());
                match (cos_transmitted(th.cos(), eta), refract_into(w, eta)) {
                    (Some(ct), Some(v)) => {
                        let st = (1.0 - ct * ct).sqrt();
                        assert!((eta * st - th.sin()).abs() < 1e-12);
                        assert!((v.z - ct).abs() < 1e-12);
                        assert!((v.length() - 1.0).abs() < 1e-14);
                        assert!(v.z >= 0.0);
                        // same azimuth: the tangential parts are parallel with the same sense
                        assert!((v.x * w.y - v.y * w.x).abs() < 1e-14);
                        assert!(v.x * w.x + v.y * w.y >= 0.0);
                    }
                    (None, None) => assert!(eta < 1.0 && th.sin() > eta),
                    other => panic!("disagree at eta={eta} th={th}: {other:?}"),
                }
            }
        }
        // Near the normal the tangential component keeps full relative precision.
        let w = Vec3::new(1e-9, 0.0, (1.0 - 1e-18f64).sqrt());
        let v = refract_into(w, 1.5).unwrap();
        assert!((v.x - 1e-9 / 1.5).abs() < 1e-24);
    }

    /// Reference value computed with tmm (Byrnes, arXiv:1603.02720) and independently in Python complex
    /// arithmetic, which agree: R_s(air → 0.2 + 3i, 60°).
    #[test]
    fn conductor_reference_value() {
        let f = fresnel_conductor(60f64.to_radians().cos(), c(0.2, 3.0));
        assert!((f.rs - 0.9624128703).abs() < 1e-9, "{}", f.rs);
        assert!(f.rp < f.rs && f.rp > 0.0);
        assert!((f.rs + f.ts - 1.0).abs() < 1e-15);
    }

    /// Conductor with k = 0 equals the dielectric, above and below η = 1.
    #[test]
    fn conductor_with_zero_k_is_dielectric() {
        for &eta in &ETAS {
            for i in 0..=90 {
                let ci = (i as f64).to_radians().cos();
                let d = fresnel_dielectric(ci, eta);
                let m = fresnel_conductor(ci, c(eta, 0.0));
                assert!((d.rs - m.rs).abs() < 1e-13 && (d.rp - m.rp).abs() < 1e-13, "eta={eta} i={i}");
                assert!((d.ts - m.ts).abs() < 1e-13 && (d.tp - m.tp).abs() < 1e-13);
            }
        }
    }

    /// A perfect-conductor limit: k ≫ n drives R → 1 at every angle (Born & Wolf §14.2), monotonically in k.
    #[test]
    fn conductor_large_k_tends_to_one() {
        for i in 0..90 {
            let ci = (i as f64).to_radians().cos();
            let mut prev = 0.0;
            for &k in &[1.0, 10.0, 100.0, 1e4] {
                let r = fr_conductor(ci, c(0.5, k));
                assert!(r > prev - 1e-15);
                prev = r;
            }
            assert!(1.0 - prev < 1e-3, "i={i} R={prev}");
        }
    }

    /// The branch is the decaying wave whatever the sign of the zero imaginary parts: n₂ = 1 − 0i from a
    /// denser medium beyond the critical angle (the num-complex signed-zero trap) gives Im(n cos θ) > 0 and
    /// |r| = 1, not a growing wave.
    #[test]
    fn signed_zero_branch() {
        let n1 = c(1.5, 0.0);
        let cos1 = c(45f64.to_radians().cos(), 0.0);
        for n2 in [c(1.0, 0.0), c(1.0, -0.0)] {
            let cos2 = complex_cos_transmitted(n1, cos1, n2);
            assert!((n2 * cos2).im > 0.0, "{cos2}");
            let a = amplitudes(n1, cos1, n2, cos2);
            assert!((a.rs.norm() - 1.0).abs() < 1e-14 && (a.rp.norm() - 1.0).abs() < 1e-14);
        }
        // A real square root on the negative axis with −0 imaginary part picks +i after the fix.
        assert_eq!(forward_sqrt(c(-4.0, -0.0)), c(0.0, 2.0));
        assert_eq!(forward_sqrt(c(4.0, -0.0)), c(2.0, 0.0));
        // Absorbing medium: decaying branch Im ≥ 0 for k > 0 at every angle.
        for i in 0..90 {
            let cos1 = c((i as f64).to_radians().cos(), 0.0);
            let nc = c(0.2, 3.0) * complex_cos_transmitted(c(1.0, 0.0), cos1, c(0.2, 3.0));
            assert!(nc.im > 0.0);
        }
    }

    /// Amplitude identities of the convention: r₂₁ = −r₁₂ and t₁₂t₂₁ − r₁₂r₂₁ = 1 (Stokes relations, Born &
    /// Wolf §1.6.4 / Byrnes Eq. 12), needed by the Airy recursion, for a complex pair of media.
    #[test]
    fn stokes_relations() {
        let (n1, n2) = (c(1.5, 0.0), c(2.5, 0.3));
        for i in 0..90 {
            let cos1 = c((i as f64).to_radians().cos(), 0.0);
            let cos2 = complex_cos_transmitted(n1, cos1, n2);
            let f = amplitudes(n1, cos1, n2, cos2);
            let b = amplitudes(n2, cos2, n1, cos1);
            for (r12, r21, t12, t21) in [(f.rs, b.rs, f.ts, b.ts), (f.rp, b.rp, f.tp, b.tp)] {
                assert!((r12 + r21).norm() < 1e-14);
                assert!((t12 * t21 - r12 * r21 - 1.0).norm() < 1e-14);
            }
        }
    }

    /// a·b as an unevaluated sum hi + lo, exact (the fused multiply-add's error term).
    fn two_prod(a: f64, b: f64) -> (f64, f64) {
        let p = a * b;
        (p, a.mul_add(b, -p))
    }

    /// a + b as hi + lo, exact (Knuth's TwoSum).
    fn two_sum(a: f64, b: f64) -> (f64, f64) {
        let s = a + b;
        let bb = s - a;
        (s, (a - (s - bb)) + (b - bb))
    }

    /// √(hi + lo) for hi + lo > 0, to well below an ulp: one Newton step from √hi.
    fn dd_sqrt((hi, lo): (f64, f64)) -> f64 {
        let r = hi.sqrt();
        let (r2, r2_lo) = two_prod(r, r);
        r + (((hi - r2) - r2_lo) + lo) / (2.0 * r)
    }

    /// n₂² − n₁² + (n₁μ)² in f64 pairs (about 32 digits), the reference for n₂ cos θ₂ = √ of it.
    fn dd_ncos2(n1: f64, mu: f64, n2: f64) -> (f64, f64) {
        let (a, a_lo) = two_prod(n2, n2);
        let (b, b_lo) = two_prod(n1, n1);
        let (m, m_lo) = two_prod(n1, mu);
        // (m + m_lo)² to the pair's precision.
        let (c, c_lo) = two_prod(m, m);
        let c_lo = c_lo + 2.0 * m * m_lo;
        let (s, s_lo) = two_sum(a, -b);
        let (s, s2) = two_sum(s, c);
        (s, s_lo + s2 + a_lo - b_lo + c_lo)
    }

    /// The cancellation-free n₂ cos θ₂ (`ncos_from_real`) against f64-pair references to a few ulp relative, at
    /// cosines down to 10⁻¹², for n₂ = n₁ (the closed form n₁μ: the pearl's exit resin), n₂ above n₁ (TiO₂,
    /// and mica 1.58 in a resin of 1.54, 1.56 and 1.5799), where the old form √(n₂² − n₁²(1 − μ)(1 + μ)) is
    /// off by up to 10⁻¹⁶/cos² relative; and complex n₂ as the old form (the same value to rounding).
    #[test]
    fn cancellation_free_cosine_is_good_to_a_few_ulp_at_every_cosine() {
        let mus = [1.0, 0.7, 0.3, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-8, 1e-10, 1e-12];
        let mut old_worst = 0.0f64;
        for &(n1, n2) in &[(1.54, 1.54), (1.5, 1.5), (1.54, 1.58), (1.56, 1.58), (1.5799, 1.58), (1.5, 2.5), (1.0, 1.5)]
        {
            for &mu in &mus {
                let now = ncos_from_real(n1, mu, c(n2, 0.0));
                let want = dd_sqrt(dd_ncos2(n1, mu, n2));
                assert!(now.im == 0.0 && ((now.re - want) / want).abs() < 6e-16, "{n1} {n2} {mu}: {now} vs {want}");
                if n1 == n2 {
                    assert!(((now.re - n1 * mu) / (n1 * mu)).abs() < 4.5e-16, "{n1} {mu}: {now}");
                }
                let old = c(n2, 0.0) * complex_cos_transmitted(c(n1, 0.0), c(mu, 0.0), c(n2, 0.0));
                old_worst = old_worst.max(((old.re - want) / want).abs());
            }
        }
        // The test can tell: the old form is off by far more at the small cosines (0.4 relative at μ = 10⁻⁸).
        assert!(old_worst > 1e-3, "{old_worst:e}");
        for n2 in [c(2.5, 0.3), c(0.2, 3.0), c(1.58, 1e-4)] {
            for &mu in &mus[..6] {
                let a = ncos_from_real(1.5, mu, n2);
                let b = n2 * complex_cos_transmitted(c(1.5, 0.0), c(mu, 0.0), n2);
                assert!((a - b).norm() <= 1e-14 * b.norm() && a.im >= 0.0, "{n2} {mu}: {a} vs {b}");
            }
        }
    }

    /// Next to the critical cosine μc of mica 1.58 in a resin of 1.59, 1.6 and 1.8, at μ = μc + δ (δ ≈ ±2⁻ᵏ·μc,
    /// δ = μ − μc exactly): `ncos_near_critical` from δ against n₁√(μ² − μc²) in f64 pairs, to a few ulp
    /// relative (imaginary, i n₁√(μc² − μ²), below μc); computed from μ, the cancellation-free form is off by
    /// ~10⁻¹⁶/cos² relative there, which the test also shows.
    #[test]
    fn cosine_near_the_critical_cosine_is_good_to_a_few_ulp() {
        let mut from_mu_worst = 0.0f64;
        for n1 in [1.59, 1.6, 1.8] {
            let mc = critical_cosine(1.58 / n1).unwrap();
            for k in [2, 5, 10, 20, 30, 40] {
                for sign in [1.0, -1.0] {
                    let mu = mc + sign * mc * 2f64.powi(-k);
                    // The offset of the representable μ, exact (Sterbenz: μ is within a factor 2 of μc).
                    let d = mu - mc;
                    // μ² − μc² = (μ − μc)(μ + μc) = d·(μ + μc), in pairs.
                    let (s, s_lo) = two_sum(mu, mc);
                    let (p, p_lo) = two_prod(d, s);
                    let want = n1 * dd_sqrt((p.abs(), (p_lo + d * s_lo) * p.signum()));
                    let got = ncos_near_critical(n1, mc, d);
                    let (g, z) = if sign > 0.0 { (got.re, got.im) } else { (got.im, got.re) };
                    assert!(z == 0.0 && ((g - want) / want).abs() < 8e-16, "{n1} {k} {sign}: {got} vs {want}");
                    let from_mu = ncos_from_real(n1, mu, c(1.58, 0.0));
                    let f = if sign > 0.0 { from_mu.re } else { from_mu.im };
                    from_mu_worst = from_mu_worst.max(((f - want) / want).abs());
                }
            }
        }
        assert!(from_mu_worst > 1e-6, "{from_mu_worst:e}");
    }
}
