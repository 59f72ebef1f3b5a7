//! Smooth-surface scatter: the Rayleigh–Rice (first-order vector perturbation) BRDF of a slightly rough
//! interface from the power spectral density (PSD) of its topography, and its band-limited total integrated
//! scatter (TIS). Formulas, conventions and validity: `docs/optics.md` §Near-specular scatter (sources:
//! Stover, *Optical Scattering*, 3rd ed. 2012, Ch. 4–5; Church, Takacs & Leonard 1989; Elson & Bennett 1979).
//!
//! Units: wavelengths and the rms roughness in nm, lateral lengths in µm, spatial frequencies in 1/µm, the
//! isotropic 2-D PSD S₂(f) in nm²·µm² (so ∫∫ S₂ d²f = σ² in nm²).
//!
//! * f_r(ωi, ωo) = (16π²/λ⁴)·cos θi·cos θs·Q(ωi, ωo)·S₂(f), f = (ωo,xy + ωi,xy)/λ (the distance of the
//!   scattered direction cosines from the specular ones, over λ; Stover Ch. 5, with our ωi pointing to the
//!   source);
//! * Q the polarisation (Fresnel) factor of a surface of relative permittivity ε, unpolarised:
//!   Q = (Q_ss + Q_sp + Q_ps + Q_pp)/2, which is the Fresnel reflectance R(θi) at the specular direction;
//! * the K-correlation ("ABC") PSD of Church & Takacs: one-sided profile PSD S₁(fx) = A/(1 + (B fx)²)^{C/2},
//!   isotropic 2-D S₂(f) = K/(1 + (B f)²)^{(C+1)/2}, K = A·B·Γ((C+1)/2)/(2√π Γ(C/2)), finite σ² for C > 1;
//! * the Gaussian PSD (autocovariance σ² exp(−r²/ℓ²)): S₂(f) = π ℓ² σ² exp(−(π ℓ f)²).
use num_complex::Complex64;
use std::f64::consts::PI;

/// The largest 4πσ/λ (at normal incidence, the shortest sampled wavelength) the first-order theory is used
/// for: the Debye–Waller exponent g = (4πσ cos θi/λ)² ≤ 0.25, where the first-order specular loss g differs
/// from a Gaussian surface's 1 − exp(−g) by less than g²/2 ≤ 3.1 % of the mirror, and far less at the
/// angles and wavelengths that matter (at 20° and 560 nm, σ = 10 nm: g = 0.045, 0.1 %; docs/optics.md
/// §Validity).
pub(crate) const MAX_PHASE: f64 = 0.5;

/// Points of the periodic trapezoid rule over the azimuth ψ of the propagating disc ([`Psd::band_limited`]):
/// the integrand is analytic and periodic, so the rule converges geometrically (checked against 4096 points
/// in the tests to 10⁻¹⁰ relative up to θi = 85° for ℓ = 1 µm).
const AZIMUTH_POINTS: usize = 256;

/// An isotropic surface PSD.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Psd {
    /// Church–Takacs K-correlation: A in nm²·µm (the one-sided profile PSD's level), B in µm, C > 1.
    KCorrelation { a: f64, b: f64, c: f64 },
    /// Gaussian autocovariance σ² exp(−r²/ℓ²): σ in nm, ℓ in µm.
    Gaussian { sigma: f64, ell: f64 },
}

impl Psd {
    /// The K-correlation PSD of rms roughness σ (nm) and correlation length ℓ (µm): B = 2πℓ (for C = 2 the
    /// autocovariance is exactly σ² exp(−r/ℓ)), A from σ² = A√π Γ((C−1)/2)/(2B Γ(C/2)).
    pub fn k_correlation(sigma: f64, ell: f64, c: f64) -> Psd {
        let b = 2.0 * PI * ell;
        let a = sigma * sigma * 2.0 * b * gamma_ratio(c / 2.0, (c - 1.0) / 2.0) / PI.sqrt();
        Psd::KCorrelation { a, b, c }
    }

    /// The rms roughness σ in nm: √(∫∫ S₂ d²f) over all frequencies.
    pub fn sigma(&self) -> f64 {
        match *self {
            Psd::KCorrelation { a, b, c } => (a * PI.sqrt() * gamma_ratio((c - 1.0) / 2.0, c / 2.0) / (2.0 * b)).sqrt(),
            Psd::Gaussian { sigma, .. } => sigma,
        }
    }

    /// The correlation length in µm (B/2π for the K-correlation PSD).
    pub fn correlation_length(&self) -> f64 {
        match *self {
            Psd::KCorrelation { b, .. } => b / (2.0 * PI),
            Psd::Gaussian { ell, .. } => ell,
        }
    }

    /// The frequency (1/µm) at which the PSD has fallen markedly from its level at 0: 1/B (the K-correlation's
    /// knee) or 1/(πℓ) (the Gaussian's e⁻¹ point).
    pub(crate) fn knee(&self) -> f64 {
        match *self {
            Psd::KCorrelation { b, .. } => 1.0 / b,
            Psd::Gaussian { ell, .. } => 1.0 / (PI * ell),
        }
    }

    /// The 2-D isotropic PSD S₂(f), nm²·µm², at |f| = `f` (1/µm).
    pub(crate) fn s2(&self, f: f64) -> f64 {
        match *self {
            Psd::KCorrelation { a, b, c } => {
                let k = a * b * gamma_ratio((c + 1.0) / 2.0, c / 2.0) / (2.0 * PI.sqrt());
                k * (1.0 + (b * f) * (b * f)).powf(-(c + 1.0) / 2.0)
            }
            Psd::Gaussian { sigma, ell } => PI * ell * ell * sigma * sigma * (-(PI * ell * f).powi(2)).exp(),
        }
    }

    /// P(ρ) = ∫₀^ρ S₂(f) f df (nm²), closed form; 2π·P(∞) = σ².
    pub(crate) fn radial_cumulative(&self, rho: f64) -> f64 {
        match *self {
            Psd::KCorrelation { a, b, c } => {
                let k = a * b * gamma_ratio((c + 1.0) / 2.0, c / 2.0) / (2.0 * PI.sqrt());
                let x = (b * rho) * (b * rho);
                // 1 − (1 + x)^{−(C−1)/2} without cancellation for small x.
                let one_minus = -(-(c - 1.0) / 2.0 * x.ln_1p()).exp_m1();
                k / (b * b * (c - 1.0)) * one_minus
            }
            Psd::Gaussian { sigma, ell } => sigma * sigma / (2.0 * PI) * -(-(PI * ell * rho).powi(2)).exp_m1(),
        }
    }

    /// The band-limited mean-square roughness σ²_bl (nm²): ∫∫ S₂ d²f over the propagating frequencies of
    /// incidence sin θi = `sin_i` at wavelength `lambda_um`, the disc |λ f + s| ≤ 1 with s the specular
    /// direction's tangential component. In polar coordinates about f = 0, ∫₀^{2π} P(ρ_max(ψ)) dψ with
    /// λ ρ_max = −s cos ψ + √(s² cos² ψ + 1 − s²), by the periodic trapezoid rule.
    pub fn band_limited(&self, sin_i: f64, lambda_um: f64) -> f64 {
        let s = sin_i.clamp(0.0, 1.0);
        let rest = (1.0 - s * s).max(0.0);
        let h = 2.0 * PI / AZIMUTH_POINTS as f64;
        let mut sum = 0.0;
        for k in 0..AZIMUTH_POINTS {
            let sc = s * (k as f64 * h).cos();
            let rho = (-sc + (sc * sc + rest).sqrt()) / lambda_um;
            sum += self.radial_cumulative(rho);
        }
        sum * h
    }
}

/// Γ(x)/Γ(y) through ln Γ (libm's `lgamma`), for x, y > 0.
fn gamma_ratio(x: f64, y: f64) -> f64 {
    (libm::lgamma(x) - libm::lgamma(y)).exp()
}

/// The unpolarised Rayleigh–Rice polarisation factor Q = (Q_ss + Q_sp + Q_ps + Q_pp)/2 of a surface of
/// relative permittivity ε (Stover 2012, Ch. 5; Elson & Bennett 1979; Church, Jenkinson & Zavada 1979), at incidence
/// θi, scatter θs and scatter azimuth φs from the plane of incidence (φs = 0 forward, the specular side).
/// At the specular direction (θs = θi, φs = 0) Q is the Fresnel reflectance (R_s + R_p)/2.
pub(crate) fn polarisation_factor(eps: Complex64, cos_i: f64, cos_s: f64, cos_phi: f64, sin_phi: f64) -> f64 {
    let (ci, cs) = (cos_i.clamp(0.0, 1.0), cos_s.clamp(0.0, 1.0));
    let (si, ss) = ((1.0 - ci * ci).max(0.0).sqrt(), (1.0 - cs * cs).max(0.0).sqrt());
    let qi = (eps - si * si).sqrt();
    let qs = (eps - ss * ss).sqrt();
    let e1 = eps - 1.0;
    let (s_i, s_s) = (ci + qi, cs + qs);
    let (p_i, p_s) = (eps * ci + qi, eps * cs + qs);
    let q_ss = (e1 * cos_phi / (s_i * s_s)).norm_sqr();
    let q_sp = (e1 * qs * sin_phi / (s_i * p_s)).norm_sqr();
    let q_ps = (e1 * qi * sin_phi / (p_i * s_s)).norm_sqr();
    let q_pp = (e1 * (qs * qi * cos_phi - eps * si * ss) / (p_i * p_s)).norm_sqr();
    0.5 * (q_ss + q_sp + q_ps + q_pp)
}

/// The Rayleigh–Rice BRDF (sr⁻¹) of a surface of permittivity `eps` and topography `psd` at wavelength
/// `lambda_nm`, for unit directions `wi` (to the source) and `wo` (to the receptor) given by their components
/// (x, y, z), z the normal. Zero below the horizon.
pub fn rayleigh_rice(psd: &Psd, eps: Complex64, lambda_nm: f64, wi: [f64; 3], wo: [f64; 3]) -> f64 {
    if !(wi[2] > 0.0 && wo[2] > 0.0) {
        return 0.0;
    }
    rayleigh_rice_with_q(psd, polarisation(eps, wi, wo), lambda_nm, wi, wo)
}

/// Q of [`polarisation_factor`] for the directions `wi`, `wo` (components x, y, z): the one factor of
/// [`rayleigh_rice`] that depends on ε and not on λ, so a model whose ε is the same at every sample computes
/// it once per direction pair.
pub(crate) fn polarisation(eps: Complex64, wi: [f64; 3], wo: [f64; 3]) -> f64 {
    let (cos_phi, sin_phi) = scatter_azimuth(wi, wo);
    polarisation_factor(eps, wi[2], wo[2], cos_phi, sin_phi)
}

/// [`rayleigh_rice`] given its polarisation factor `q` (the same bits as [`rayleigh_rice`] with
/// `q = polarisation(eps, wi, wo)`); zero below the horizon.
pub(crate) fn rayleigh_rice_with_q(psd: &Psd, q: f64, lambda_nm: f64, wi: [f64; 3], wo: [f64; 3]) -> f64 {
    if !(wi[2] > 0.0 && wo[2] > 0.0) {
        return 0.0;
    }
    let lambda_um = lambda_nm * 1e-3;
    let (fx, fy) = ((wo[0] + wi[0]) / lambda_um, (wo[1] + wi[1]) / lambda_um);
    let f = fx.hypot(fy);
    16.0 * PI * PI * wi[2].min(1.0) * wo[2].min(1.0) * q * psd.s2(f) / (lambda_nm * lambda_nm * lambda_um * lambda_um)
}

/// cos φs, sin φs of the scattered direction's azimuth measured from the specular azimuth (−ωi,xy). At
/// normal incidence or normal scatter the azimuth is undefined, and Q does not depend on it there (the
/// sums Q_ss + Q_ps and Q_sp + Q_pp are then independent of φs): φs = 0 is taken.
fn scatter_azimuth(wi: [f64; 3], wo: [f64; 3]) -> (f64, f64) {
    let (ix, iy) = (-wi[0], -wi[1]);
    let ni = ix.hypot(iy);
    let no = wo[0].hypot(wo[1]);
    if ni < 1e-300 || no < 1e-300 {
        return (1.0, 0.0);
    }
    let (ex, ey) = (ix / ni, iy / ni);
    let (ox, oy) = (wo[0] / no, wo[1] / no);
    (ex * ox + ey * oy, ex * oy - ey * ox)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fresnel(n: f64, c: f64) -> f64 {
        crate::optics::fresnel::fr_dielectric(c, n)
    }

    #[test]
    fn q_is_fresnel_at_the_specular_direction() {
        for &n in &[1.3, 1.5, 1.8] {
            for &c in &[1.0, 0.9, 0.5, 0.1] {
                let q = polarisation_factor(Complex64::new(n * n, 0.0), c, c, 1.0, 0.0);
                assert!((q - fresnel(n, c)).abs() < 1e-14, "n {n} cos {c}: {q}");
            }
        }
    }

    #[test]
    fn psd_normalisations() {
        for psd in [
            Psd::k_correlation(3.0, 10.0, 2.0),
            Psd::k_correlation(2.0, 5.0, 3.7),
            Psd::Gaussian { sigma: 4.0, ell: 7.0 },
        ] {
            let total = 2.0 * PI * psd.radial_cumulative(1e9);
            assert!((total - psd.sigma().powi(2)).abs() < 1e-9 * total, "{psd:?}: {total}");
            // Radial integral of S₂ by a fine rule in u = ln f against the closed form.
            let (lo, hi, n) = ((1e-6f64).ln(), (1e4f64).ln(), 200_000);
            let h = (hi - lo) / n as f64;
            let num: f64 = (0..n)
                .map(|i| {
                    let f = (lo + (i as f64 + 0.5) * h).exp();
                    psd.s2(f) * f * f * h
                })
                .sum();
            let exact = psd.radial_cumulative(1e4) - psd.radial_cumulative(1e-6);
            assert!((num - exact).abs() < 1e-6 * exact, "{psd:?}: {num} vs {exact}");
        }
        let p = Psd::k_correlation(3.0, 10.0, 2.0);
        assert!((p.sigma() - 3.0).abs() < 1e-12 && (p.correlation_length() - 10.0).abs() < 1e-12);
    }

    #[test]
    fn band_limit_converges_and_is_below_sigma2() {
        let psd = Psd::k_correlation(3.0, 1.0, 2.0);
        for &deg in &[0.0f64, 20.0, 60.0, 85.0] {
            let s = deg.to_radians().sin();
            let a = psd.band_limited(s, 0.56);
            // Reference: 4096 points.
            let h = 2.0 * PI / 4096.0;
            let r: f64 = (0..4096)
                .map(|k| {
                    let sc = s * (k as f64 * h).cos();
                    psd.radial_cumulative((-sc + (sc * sc + 1.0 - s * s).sqrt()) / 0.56)
                })
                .sum::<f64>()
                * h;
            assert!((a - r).abs() <= 1e-10 * r, "{deg}: {a} vs {r}");
            assert!(a < 9.0 && a > 0.0);
        }
    }

    #[test]
    fn reciprocal_and_azimuth_free_at_normal_incidence() {
        let psd = Psd::k_correlation(3.0, 2.0, 2.5);
        let eps = Complex64::new(1.5f64.powi(2), 0.0);
        let dir = |t: f64, p: f64| {
            let (t, p) = (t.to_radians(), p.to_radians());
            [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()]
        };
        for (a, b) in [((20.0, 180.0), (25.0, 10.0)), ((60.0, 170.0), (40.0, -30.0)), ((5.0, 90.0), (80.0, 200.0))] {
            let (wi, wo) = (dir(a.0, a.1), dir(b.0, b.1));
            let (x, y) = (rayleigh_rice(&psd, eps, 560.0, wi, wo), rayleigh_rice(&psd, eps, 560.0, wo, wi));
            assert!((x - y).abs() <= 1e-13 * x, "{x} {y}");
        }
        let wi = [0.0, 0.0, 1.0];
        let v: Vec<f64> =
            [0.0, 45.0, 90.0, 200.0].iter().map(|&p| rayleigh_rice(&psd, eps, 560.0, wi, dir(30.0, p))).collect();
        assert!(v.iter().all(|x| (x - v[0]).abs() <= 1e-13 * v[0]), "{v:?}");
    }
}
