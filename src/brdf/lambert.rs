//! The Lambertian (ideal diffuse) reflector: f_r = ρ/π.
//!
//! Source: J. H. Lambert, *Photometria* (1760); in modern form e.g. Pharr, Jakob & Humphreys, *Physically
//! Based Rendering* 4th ed. (pbrt-v4) §9.2 `DiffuseBxDF`. Its directional albedo ∫ f cos θo dωo = ρ for every
//! incident direction (the closed form checked in `tests/brdf_models.rs`).
use super::{below_horizon, Brdf, Hints, Term, TermKind};
use crate::spectrum::Sampling;
use crate::Vec3;
use std::f64::consts::PI;

/// Lambertian reflector with directional-hemispherical albedo ρ ∈ [0, 1] per spectral sample.
#[derive(Clone, Debug, PartialEq)]
pub struct Lambert {
    /// Albedo ρ per spectral sample (`albedo.len() == sampling.len()`).
    pub albedo: Vec<f64>,
    pub sampling: Sampling,
}

impl Lambert {
    /// One finite albedo per spectral sample, else an error.
    pub fn new(albedo: Vec<f64>, sampling: Sampling) -> crate::Result<Self> {
        super::per_sample("albedo", &albedo, &sampling)?;
        Ok(Lambert { albedo, sampling })
    }
}

impl Brdf for Lambert {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        if below_horizon(wi, wo, out) {
            return;
        }
        for (o, r) in out.iter_mut().zip(&self.albedo) {
            *o = r / PI;
        }
    }

    /// Analytic everywhere (`Hints::smooth`).
    fn hints(&self) -> Hints {
        Hints::new(vec![Term { label: "Lambertian".into(), kind: TermKind::Diffuse }]).with_smooth(true)
    }

    fn describe(&self) -> String {
        format!("Lambert (albedo {})", fmt_values(&self.albedo))
    }
}

/// Format per-sample values compactly: one number, or `[a, b, c]`.
pub(crate) fn fmt_values(v: &[f64]) -> String {
    if v.len() == 1 {
        crate::error::number(v[0])
    } else {
        format!("[{}]", v.iter().map(|&x| crate::error::number(x)).collect::<Vec<_>>().join(", "))
    }
}
