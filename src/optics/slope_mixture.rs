//! A mixture of microfacet slope populations: D = Σ wᵢ Dᵢ with Smith masking of the mixture.
//!
//! A surface whose facet slopes are drawn from one population with probability wᵢ (Σ wᵢ = 1) has the slope
//! distribution P₂₂ = Σ wᵢ P₂₂,ᵢ, so its distribution of normals is D = Σ wᵢ Dᵢ (D = P₂₂/cos⁴θh, Heitz 2014
//! Eq. 9; Walter et al. 2007 Eq. 25/33 for each Dᵢ), normalised because each Dᵢ is. Smith's Λ is linear in
//! P₂₂ (Heitz 2014 Eq. 72: Λ(ω) = (1/μ) ∫ (x̃ − μ)⁺ P²(x̃) dx̃ with P² the marginal slope distribution along
//! ω's azimuth, itself linear in P₂₂), so the mixture's Λ is Σ wᵢ Λᵢ exactly, and the masking-shadowing of
//! the mixture is the project's one-population form with that Λ (Heitz 2014 Eqs. 98–99). Derivation:
//! `docs/optics.md` §4.1.
use super::microfacet::{g_with_lambda, Microfacet, Shadowing};
use crate::Vec3;

/// Weighted slope populations (weights in (0, 1], summing to 1; the caller checks).
#[derive(Clone, Debug, PartialEq)]
pub struct SlopeMixture {
    /// (weight, distribution) per population.
    pub populations: Vec<(f64, Microfacet)>,
}

impl SlopeMixture {
    pub fn new(populations: Vec<(f64, Microfacet)>) -> Self {
        SlopeMixture { populations }
    }

    /// D(h) = Σ wᵢ Dᵢ(h); with one population of weight 1 the same bits as its D (1·x = x, 0 + x = x).
    pub(crate) fn d(&self, h: Vec3) -> f64 {
        self.populations.iter().fold(0.0, |s, (w, m)| s + w * m.d(h))
    }

    /// Λ(ω) = Σ wᵢ Λᵢ(ω) (Heitz 2014 Eq. 72 is linear in the slope distribution); each Λᵢ as it enters G
    /// (`Microfacet::lambda_in_g`: 0 where 1 + Λᵢ rounds to 1), +∞ at or below the horizon.
    pub(crate) fn lambda_in_g(&self, w: Vec3) -> f64 {
        self.populations.iter().fold(0.0, |s, (wt, m)| s + wt * m.lambda_in_g(w))
    }

    /// G(ωi, ωo) for the half vector `h`, as `Microfacet::g` with the mixture's Λ (the V-cavity G does not
    /// depend on the distribution). Symmetric in (ωi, ωo) bit for bit, in [0, 1].
    pub(crate) fn g(&self, wi: Vec3, wo: Vec3, h: Vec3, shadowing: Shadowing) -> f64 {
        g_with_lambda(wi, wo, h, shadowing, |w| self.lambda_in_g(w))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::microfacet::Distribution;
    use std::f64::consts::PI;

    fn dirs() -> Vec<Vec3> {
        (0..14)
            .flat_map(|i| (0..7).map(move |j| (i, j)))
            .map(|(i, j)| {
                let th = (i as f64 * 6.5 + 0.3).to_radians();
                let ph = j as f64 * 0.9;
                Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos())
            })
            .collect()
    }

    /// One population of weight 1: D, Λ and G are the same bits as the population's own.
    #[test]
    fn one_population_is_the_population_bit_for_bit() {
        for dist in [Distribution::Beckmann, Distribution::Ggx] {
            for alpha in [1e-4, 0.0074, 0.1, 0.7] {
                let m = Microfacet::new(dist, alpha);
                let mix = SlopeMixture::new(vec![(1.0, m)]);
                let ds = dirs();
                for (k, &wi) in ds.iter().enumerate() {
                    for &wo in ds.iter().skip(k % 3).step_by(3) {
                        let h = (wi + wo).normalize();
                        assert_eq!(mix.d(h).to_bits(), m.d(h).to_bits());
                        for sh in [Shadowing::SmithHeightCorrelated, Shadowing::SmithSeparable, Shadowing::VCavity] {
                            assert_eq!(mix.g(wi, wo, h, sh).to_bits(), m.g(wi, wo, h, sh).to_bits());
                        }
                    }
                }
            }
        }
    }

    /// ∫ D cos θh dω = 1 for mixtures of unlike widths and shapes, integrated population-blind: the polar
    /// integral in t = tan θh split at multiples of every width (composite Simpson on each piece).
    #[test]
    fn mixture_d_is_normalised() {
        let cases = [
            vec![
                (0.9325, Microfacet::new(Distribution::Beckmann, 0.0074)),
                (0.0675, Microfacet::new(Distribution::Beckmann, 0.074)),
            ],
            vec![
                (0.5, Microfacet::new(Distribution::Ggx, 0.01)),
                (0.3, Microfacet::new(Distribution::Beckmann, 0.3)),
                (0.2, Microfacet::new(Distribution::Ggx, 1.0)),
            ],
        ];
        for pops in cases {
            let mix = SlopeMixture::new(pops.clone());
            // Break points: 0, then geometric from the narrowest width / 10 to 1e6 (GGX's tail).
            let amin = pops.iter().map(|p| p.1.alpha).fold(f64::INFINITY, f64::min);
            let mut edges = vec![0.0];
            let mut t = amin / 10.0;
            while t < 1e6 {
                edges.push(t);
                t *= 1.25;
            }
            let f = |t: f64| {
                let c4 = 1.0 / ((1.0 + t * t) * (1.0 + t * t));
                2.0 * PI * mix.d(Vec3::new(t, 0.0, 1.0)) * c4 * t
            };
            let mut total = 0.0;
            for w in edges.windows(2) {
                let (a, b) = (w[0], w[1]);
                let n = 64;
                let hstep = (b - a) / n as f64;
                let mut s = f(a) + f(b);
                for i in 1..n {
                    s += f(a + hstep * i as f64) * if i % 2 == 1 { 4.0 } else { 2.0 };
                }
                total += s * hstep / 3.0;
            }
            // GGX beyond t = 1e6: ∫ 2α²/t³ dt ≈ α²·1e-12, below the tolerance.
            assert!((total - 1.0).abs() < 1e-8, "{pops:?}: {total}");
        }
    }

    /// Λ of the mixture is the weighted sum, and the weak white furnace of the mixture holds with it: the
    /// projected area of the visible mixture facets is cos θo, ∫ G1(ωo) ⟨ωo, h⟩⁺ D(h) dω = cos θo (Heitz 2014
    /// Eqs. 17–18), which fails for any Λ other than Σ wᵢ Λᵢ (checked: the per-population G1 mean differs).
    #[test]
    fn weak_white_furnace_of_the_mixture() {
        let pops =
            vec![(0.7, Microfacet::new(Distribution::Beckmann, 0.1)), (0.3, Microfacet::new(Distribution::Ggx, 0.6))];
        let mix = SlopeMixture::new(pops);
        for deg in [20.0f64, 60.0, 80.0, 85.0] {
            let th_o = deg.to_radians();
            let wo = Vec3::new(th_o.sin(), 0.0, th_o.cos());
            // ∫ over θh ∈ [0, π/2) in t = tan θh (dω = sin θh dθh dφ, dθh = cos²θh dt) with the azimuthal
            // integral of ⟨ωo, h⟩⁺ in closed form.
            let f = |t: f64| {
                let (c, s) = (1.0 / (1.0 + t * t).sqrt(), t / (1.0 + t * t).sqrt());
                let (a, b) = (th_o.sin() * s, th_o.cos() * c);
                let phi = if a <= b { 2.0 * PI * b } else { 2.0 * (a * (-b / a).acos().sin() + b * (-b / a).acos()) };
                mix.d(Vec3::new(t, 0.0, 1.0)) * phi * s * c * c
            };
            let tk = 1.0 / th_o.tan();
            let mut edges = vec![0.0];
            let mut t = 1e-3;
            while t < 1e9 {
                edges.push(t);
                t *= 1.1;
            }
            edges.push(tk);
            edges.sort_by(f64::total_cmp);
            let mut integral = 0.0;
            for w in edges.windows(2) {
                let (a, b) = (w[0], w[1]);
                let n = 32;
                let hs = (b - a) / n as f64;
                let mut s = f(a) + f(b);
                for i in 1..n {
                    s += f(a + hs * i as f64) * if i % 2 == 1 { 4.0 } else { 2.0 };
                }
                integral += s * hs / 3.0;
            }
            let lam = mix.lambda_in_g(wo);
            let ratio = integral / (1.0 + lam) / th_o.cos();
            assert!((ratio - 1.0).abs() < 1e-6, "θo = {deg}: {ratio}");
            // The per-population mean of G1 is not the mixture's masking (it differs by far more than the
            // tolerance once the broad population's Λ matters, from 60°).
            if deg >= 60.0 {
                let mean_g1: f64 = mix.populations.iter().map(|(w, m)| w * m.g1(wo)).sum();
                assert!((integral * mean_g1 / th_o.cos() - 1.0).abs() > 1e-4, "θo = {deg}");
            }
        }
    }
}
