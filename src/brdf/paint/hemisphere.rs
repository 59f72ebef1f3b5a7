//! Hemispherical means 2∫₀¹ f(μ) μ dμ by Gauss–Legendre in the cosine: the coat's diffuse Fresnel
//! reflectances r_e (from outside) and r_i (from inside), and [`hemispherical_mean`], the rule cut at the
//! kinks of a total-internal-reflection edge that the split flake light's ρ_d uses.
use crate::optics::fresnel::fr_dielectric;
use crate::quadrature::gauss_legendre;

/// Gauss–Legendre order used for the diffuse Fresnel reflectance r_e (the integrand is smooth in cos θ on
/// [0, 1], so 64 nodes give it to rounding; checked against an independent Simpson rule in `tests/paint.rs`).
pub(crate) const DIFFUSE_FRESNEL_NODES: usize = 64;

/// The hemispherical mean 2∫₀¹ f(μ) μ dμ of a function of the cosine that is smooth on [0, 1] except at the
/// cosines `kinks` (sorted, in (0, 1)), where it is continuous but its derivative is not.
///
/// Without kinks: the [`DIFFUSE_FRESNEL_NODES`]-point Gauss–Legendre rule on [0, 1] (the rule the smooth
/// integrands of the paint model use, to rounding). With kinks, a single rule across one converges only
/// algebraically (a Fresnel reflectance behaves like √(μ − μc) beside its critical cosine μc, and a 64-point
/// rule across it is off by ~10⁻³ for mica in a denser resin): the interval is cut at every kink and at the
/// midpoints between them, and each piece that ends on a kink is mapped by μ = μc ± h·s² (s ∈ [0, 1]), which
/// turns √(μ − μc) into the smooth h^½·s, so that each piece's rule again converges like a smooth integrand's
/// (docs/model.md §Pearlescent flakes).
pub(crate) fn hemispherical_mean(f: impl Fn(f64) -> f64, kinks: &[f64]) -> f64 {
    hemispherical_means(|mu, v| v[0] = f(mu), 1, kinks)[0]
}

/// [`hemispherical_mean`] of `count` functions with the same kinks at once: `f(μ, values)` sets every
/// function's value at μ (so what they share at one μ is computed once), and each mean is summed in the same
/// order, to the same bits, as [`hemispherical_mean`] sums it alone.
pub(crate) fn hemispherical_means(mut f: impl FnMut(f64, &mut [f64]), count: usize, kinks: &[f64]) -> Vec<f64> {
    let (x, w) = gauss_legendre(DIFFUSE_FRESNEL_NODES);
    let mut at = vec![0.0; count];
    let mut sums = vec![0.0; count];
    if kinks.is_empty() {
        for (&xi, &wi) in x.iter().zip(&w) {
            let mu = 0.5 * (xi + 1.0);
            f(mu, &mut at);
            for (s, v) in sums.iter_mut().zip(&at) {
                *s += wi * mu * v;
            }
        }
        return sums;
    }
    // Pieces (from, to) with `from` a kink: μ = from + (to − from)·s², from the kink towards the piece's
    // other end (which is 0, 1 or a midpoint between kinks).
    let mut pieces = Vec::with_capacity(2 * kinks.len());
    for (i, &c) in kinks.iter().enumerate() {
        let below = if i == 0 { 0.0 } else { 0.5 * (kinks[i - 1] + c) };
        let above = if i + 1 == kinks.len() { 1.0 } else { 0.5 * (c + kinks[i + 1]) };
        pieces.push((c, below));
        pieces.push((c, above));
    }
    let mut piece = vec![0.0; count];
    for (from, to) in pieces {
        let h = to - from;
        piece.iter_mut().for_each(|p| *p = 0.0);
        for (&xi, &wi) in x.iter().zip(&w) {
            let s = 0.5 * (xi + 1.0);
            let mu = from + h * s * s;
            f(mu, &mut at);
            // dμ = 2h·s ds, and ds = wi/2 on [0, 1]: 2 f μ dμ = 2 f μ · h s wi.
            for (p, v) in piece.iter_mut().zip(&at) {
                *p += wi * 2.0 * h.abs() * s * mu * v;
            }
        }
        for (s, p) in sums.iter_mut().zip(&piece) {
            *s += p;
        }
    }
    sums
}

/// Diffuse (hemispherical) reflectance of the air → coat interface for light incident from air,
/// r_e = ∫₀^{π/2} F(θ) 2 sin θ cos θ dθ = ∫₀¹ F(μ) 2μ dμ (Judd 1942; Stern 1964), by Gauss–Legendre.
pub fn diffuse_fresnel_reflectance(eta: f64) -> f64 {
    let (x, w) = gauss_legendre(DIFFUSE_FRESNEL_NODES);
    x.iter()
        .zip(&w)
        .map(|(&xi, &wi)| {
            let mu = 0.5 * (xi + 1.0);
            0.5 * wi * fr_dielectric(mu, eta) * 2.0 * mu
        })
        .sum()
}

/// Diffuse reflectance of the coat–air interface for diffuse light incident from inside the coat:
/// r_i = 1 − (1 − r_e)/η² (the exit cone carries 1/η² of the internal diffuse flux, and Fresnel
/// transmittance is the same both ways; Saunderson 1942, Stern 1964). For η = 1.5, r_i ≈ 0.596.
pub fn internal_diffuse_reflectance(eta: f64) -> f64 {
    1.0 - (1.0 - diffuse_fresnel_reflectance(eta)) / (eta * eta)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::fresnel::critical_cosine;
    use crate::optics::thin_film::{stack, FilmLayer};
    use num_complex::Complex64;

    /// Inside a coat of index η, the hemispherical reflectance of the coat–air interface is
    /// r_i = 1 − (1 − r_e)/η² (Stern 1964; r_e from the smooth outside rule): an independent closed form of
    /// 2∫F(μ, 1/η)μ dμ, whose integrand kinks at the critical cosine.
    #[test]
    fn the_kinked_internal_reflectance_meets_stern_s_closed_form_to_rounding() {
        for eta in [1.3, 1.5, 1.8, 2.4] {
            let closed = internal_diffuse_reflectance(eta);
            let mu_c = critical_cosine(1.0 / eta).unwrap();
            let split = hemispherical_mean(|mu| fr_dielectric(mu, 1.0 / eta), &[mu_c]);
            assert!((split - closed).abs() < 2e-15, "η = {eta}: split {split} vs closed form {closed}");
            // The rule across the kink is not good enough: the test would fail without the split.
            let across = hemispherical_mean(|mu| fr_dielectric(mu, 1.0 / eta), &[]);
            assert!((across - closed).abs() > 1e-7, "η = {eta}: the unsplit rule is already exact?");
        }
    }

    /// The pearl flake's ρ_d for mica (1.55) below the resin (1.8): the split rule against an adaptive
    /// Gauss–Kronrod integral with the kink as a break point, to 1e-13.
    #[test]
    fn the_pearl_flake_s_hemispherical_reflectance_is_right_below_the_resin_index() {
        let medium = 1.8;
        let tio2 = FilmLayer { n: Complex64::new(2.5, 0.0), thickness_nm: 60.0, coherent: true };
        let mica = FilmLayer { n: Complex64::new(1.55, 0.0), thickness_nm: 400.0, coherent: false };
        let layers = [tio2, mica, tio2];
        for wavelength in [450.0, 550.0, 650.0] {
            let rho = |mu: f64| stack(medium, &layers, Complex64::new(medium, 0.0), mu, wavelength).r().clamp(0.0, 1.0);
            let mu_c = critical_cosine(1.55 / medium).unwrap();
            let mut f = |mu: f64, out: &mut [f64]| out[0] = 2.0 * mu * rho(mu);
            let (reference, err) =
                crate::quadrature::gauss_kronrod_adaptive(&mut f, &[0.0, mu_c, 1.0], 1, 1, 1e-15, 4000);
            assert!(err < 1e-13, "reference error {err}");
            let split = hemispherical_mean(rho, &[mu_c]);
            assert!((split - reference[0]).abs() < 1e-13, "{wavelength} nm: {split} vs {}", reference[0]);
            let across = hemispherical_mean(rho, &[]);
            eprintln!("{wavelength} nm: ρ_d {split:.15}, the rule across the kink is off by {:.2e}", across - split);
            assert!((across - split).abs() > 1e-6, "{wavelength} nm: the unsplit rule is already exact?");
        }
    }
}
