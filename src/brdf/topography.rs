//! The facet term of a measured surface (`"model": "topography"`): a dielectric interface whose distribution
//! of normals is the topography's own slope distribution (`optics::slope_table`), with Smith masking from the
//! same slopes' second moments, and no fitted parameter:
//! f = F(ωi·h)·D(h)·G(ωi, ωo)/(4 cos θi cos θo) (Walter et al. 2007 Eq. 20), F the dielectric Fresnel
//! reflectance of the index beneath (docs/topography.md §The facet term of a measured surface).
//!
//! The map's x axis is the plane of measurement's (a surface's anisotropy is kept: D is the 2-D slope
//! density, not its radial average). For the planner it is one lobe as wide as the largest Gaussian-equivalent
//! α of the slopes, of unknown tail (a measured density is no Gaussian nor GGX, so no shaped rule applies:
//! the adaptive partition integrates it).
use super::dielectric::Ior;
use super::{fresnel_kinks, Brdf, Kink, Lobe, Tail, Term, TermKind};
use crate::optics::microfacet::{g_with_lambda, Shadowing};
use crate::optics::slope_table::SlopeTable;
use crate::spectrum::Sampling;
use crate::Vec3;

#[derive(Clone, Debug, PartialEq)]
pub struct TopographySurface {
    pub slopes: SlopeTable,
    /// The index beneath the surface (real: a dielectric).
    pub ior: f64,
    /// What the slopes came from, for `describe` (the file, the levelling).
    pub source: String,
    sampling: Sampling,
}

impl TopographySurface {
    /// A finite index > 0 (the recipe's range is narrower; this is the library's check).
    pub fn new(slopes: SlopeTable, ior: f64, source: String) -> crate::Result<Self> {
        if !(ior.is_finite() && ior > 0.0) {
            return Err(crate::Error::Usage(format!("topography surface: index {ior}; allowed: a finite n > 0")));
        }
        Ok(TopographySurface { slopes, ior, source, sampling: Sampling::grey() })
    }
}

impl Brdf for TopographySurface {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            out.fill(0.0);
            return;
        }
        let h = (wi + wo).normalize();
        let cos_d = wi.dot(h).clamp(0.0, 1.0);
        let d = self.slopes.d(h);
        if d == 0.0 {
            out.fill(0.0);
            return;
        }
        let g = g_with_lambda(wi, wo, h, Shadowing::SmithHeightCorrelated, |w| self.slopes.lambda(w));
        let f = Ior::Dielectric(self.ior).reflectance(cos_d) * d * g / (4.0 * wi.z * wo.z);
        out.fill(f);
    }

    fn terms(&self) -> Vec<Term> {
        let label = format!("measured facets ({} slopes, rms {:.4})", self.slopes.samples, self.slopes.rms_slope());
        let lobe =
            Lobe { slope_width: self.slopes.width(), medium_eta: 1.0, label: label.clone(), tail: Tail::Unknown };
        vec![Term { label, kind: TermKind::Lobe(lobe) }]
    }

    fn kinks(&self) -> Vec<Kink> {
        fresnel_kinks([Ior::Dielectric(self.ior).critical_cosine()], false)
    }

    fn describe(&self) -> String {
        format!(
            "topography facets ({}; {} slopes, rms slope {:.4}, kernel h = {:.2e}; n = {}, Smith height-correlated with \
             the Gaussian-equivalent Λ)",
            self.source,
            self.slopes.samples,
            self.slopes.rms_slope(),
            self.slopes.bandwidth,
            self.ior
        )
    }
}
