//! A rough interface whose facet slopes are a mixture of populations (`"populations"` of a `microfacet`
//! recipe): f = F(ωi·h)·D(h)·G(ωi, ωo)/(4 cos θi cos θo) with D = Σ wᵢ Dᵢ and the Smith G of the mixture,
//! Λ = Σ wᵢ Λᵢ (`optics::slope_mixture`, `docs/optics.md` §4.1), exact Fresnel of a dielectric or conductor as
//! [`super::dielectric::MicrofacetSurface`]. A real lacquer's orange peel beside a few per cent of steep
//! slopes (craters, inclusions, a coarse texture) is such a surface (`docs/instrument.md` §1.10). Each
//! population is a lobe for the planner, of its own width and tail. Every population is rough (roughness ≥
//! [`Microfacet::SMOOTH_THRESHOLD`]; the recipe refuses a delta population).
use super::dielectric::{check_iors, describe_facets, describe_iors, describe_shadowing, Ior};
use super::{below_horizon, Brdf, Hints, Lobe, Term, TermKind};
use crate::optics::microfacet::{Microfacet, Shadowing};
use crate::optics::slope_mixture::SlopeMixture;
use crate::spectrum::Sampling;
use crate::{Error, Vec3};

#[derive(Clone, Debug, PartialEq)]
pub struct MixtureSurface {
    pub facets: SlopeMixture,
    pub shadowing: Shadowing,
    /// Index per spectral sample.
    pub ior: Vec<Ior>,
    pub sampling: Sampling,
}

impl MixtureSurface {
    /// One finite index per spectral sample; at least one population, each rough, weights in (0, 1] summing
    /// to 1 within 1e-9 (the recipe parser names the field of a violation; this is the library's check).
    pub fn new(facets: SlopeMixture, shadowing: Shadowing, ior: Vec<Ior>, sampling: Sampling) -> crate::Result<Self> {
        check_iors(&ior, &sampling)?;
        let pops = &facets.populations;
        if pops.is_empty() {
            return Err(Error::Usage("slope mixture: no population".into()));
        }
        if let Some((w, m)) = pops
            .iter()
            .find(|(w, m)| !(*w > 0.0 && *w <= 1.0 && m.alpha >= Microfacet::SMOOTH_THRESHOLD && m.alpha.is_finite()))
        {
            return Err(Error::Usage(format!(
                "slope mixture: population of weight {w} and roughness {}; allowed: weight in (0, 1], roughness ≥ {}",
                m.alpha,
                Microfacet::SMOOTH_THRESHOLD
            )));
        }
        let sum: f64 = pops.iter().map(|p| p.0).sum();
        if (sum - 1.0).abs() > 1e-9 {
            return Err(Error::Usage(format!("slope mixture: the weights sum to {sum}; allowed: 1 (within 1e-9)")));
        }
        Ok(MixtureSurface { facets, shadowing, ior, sampling })
    }
}

impl Brdf for MixtureSurface {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    /// As `MicrofacetSurface::eval` (the same operations in the same order, so one population gives the same
    /// bits), with the mixture's D and G.
    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        if below_horizon(wi, wo, out) {
            return;
        }
        let h = (wi + wo).normalize();
        let cos_d = wi.dot(h).clamp(0.0, 1.0);
        let d = self.facets.d(h);
        if d == 0.0 {
            out.fill(0.0);
            return;
        }
        let g = self.facets.g(wi, wo, h, self.shadowing);
        let dg = d * g / (4.0 * wi.z * wo.z);
        for (o, ior) in out.iter_mut().zip(&self.ior) {
            *o = if dg == 0.0 { 0.0 } else { ior.reflectance(cos_d) * dg };
        }
    }

    /// Σ wᵢ·Dᵢ(ψ/2)/4, as `MicrofacetSurface::tail_majorant` for each population (F ≤ 1, G ≤ 1, θh ≥ ψ/2;
    /// docs/instrument.md §Quadrature, "A receptor the lobe cannot reach"): None if any population's D is not
    /// monotone in the tilt. One population of weight 1 gives the same bits as the one-population model
    /// (0 + 1·x = x), so that the two read alike.
    fn tail_majorant(&self, psi: f64) -> Option<f64> {
        let mut sum = 0.0;
        for (w, m) in &self.facets.populations {
            sum += w * m.d_majorant(0.5 * psi)?;
        }
        Some(0.25 * sum)
    }

    /// One lobe per population, of its width and tail (the planner splits at each). The Fresnel factor
    /// F(ωi·h) of every index below 1 kinks at its critical angle. Smooth with a Smith G; the V-cavity G's
    /// min() is a kink it does not report.
    fn hints(&self) -> Hints {
        let n = self.facets.populations.len();
        let terms = self
            .facets
            .populations
            .iter()
            .enumerate()
            .map(|(i, (w, m))| {
                let label = format!(
                    "slope population {} of {n} (weight {}, {})",
                    i + 1,
                    crate::error::number(*w),
                    describe_facets(m)
                );
                Term { label: label.clone(), kind: TermKind::Lobe(Lobe::of_facets(m, 1.0, label)) }
            })
            .collect();
        Hints::new(terms)
            .with_kinks(super::fresnel_kinks(self.ior.iter().map(Ior::critical_cosine), false))
            .with_smooth(self.shadowing != Shadowing::VCavity)
    }

    fn describe(&self) -> String {
        let pops: Vec<String> = self
            .facets
            .populations
            .iter()
            .map(|(w, m)| format!("{} × {}", crate::error::number(*w), describe_facets(m)))
            .collect();
        format!(
            "microfacet slope mixture ({}; {}, {})",
            pops.join(" + "),
            describe_iors(&self.ior),
            describe_shadowing(self.shadowing)
        )
    }
}
