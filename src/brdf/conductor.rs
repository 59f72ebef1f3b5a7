//! The ideally smooth conductor: f = R(θi)·δ(ωo − mirror(ωi))/cos θo with R the unpolarised Fresnel
//! reflectance of a complex index n + ik (Born & Wolf, *Principles of Optics* §14.2; pbrt-v4 `FrConductor`).
//! A rough conductor is [`super::dielectric::MicrofacetSurface`] with [`super::dielectric::Ior::Conductor`].
use super::dielectric::Ior;
use super::{Brdf, Hints, Term, TermKind};
use crate::optics::fresnel::critical_cosine_complex;
use crate::spectrum::Sampling;
use crate::Vec3;
use num_complex::Complex64;

/// A smooth conductor with a complex index per spectral sample.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SmoothConductor {
    /// n + ik (k ≥ 0) per spectral sample, relative to air.
    pub ior: Vec<Complex64>,
    pub sampling: Sampling,
}

impl SmoothConductor {
    /// One finite complex index per spectral sample, else an error.
    pub(crate) fn new(ior: Vec<Complex64>, sampling: Sampling) -> crate::Result<Self> {
        let parts: Vec<f64> = ior.iter().map(|c| c.re + c.im).collect();
        super::per_sample("conductor index", &parts, &sampling)?;
        Ok(SmoothConductor { ior, sampling })
    }
}

impl Brdf for SmoothConductor {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    fn eval(&self, _wi: Vec3, _wo: Vec3, out: &mut [f64]) {
        out.fill(0.0);
    }

    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        for (o, eta) in out.iter_mut().zip(&self.ior) {
            *o = Ior::Conductor(*eta).reflectance(wi.z);
        }
        true
    }

    /// A real index below 1 (k = 0) has a critical angle, its kink; analytic everywhere else (`Hints::smooth`).
    fn hints(&self) -> Hints {
        Hints::new(vec![Term { label: "specular reflection (conductor Fresnel)".into(), kind: TermKind::Delta }])
            .with_kinks(super::fresnel_kinks(self.ior.iter().map(|e| critical_cosine_complex(*e)), true))
            .with_smooth(true)
    }

    fn describe(&self) -> String {
        let parts: Vec<String> = self.ior.iter().map(|e| format!("{} + {}i", e.re, e.im)).collect();
        format!("smooth conductor (n = {})", parts.join("; "))
    }
}
