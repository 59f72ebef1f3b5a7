//! Smooth and rough interfaces: the ideal mirror of a dielectric and the Torrance–Sparrow / Cook–Torrance
//! microfacet model of a rough dielectric or conductor.
//!
//! * [`SmoothDielectric`]: f = R(θi)·δ(ωo − mirror(ωi))/cos θo with R the unpolarised Fresnel reflectance
//!   (Born & Wolf, *Principles of Optics* §1.5.2; pbrt-v4 `FrDielectric`). Light transmitted into the body
//!   is lost: the model is an opaque black-backed glass such as the polished black-glass gloss standard
//!   (ISO 2813 §5.4 / ASTM D523 §7.1, n_D = 1.567).
//! * [`MicrofacetSurface`]: f = F(ωi·h)·D(h)·G(ωi, ωo)/(4 cos θi cos θo), h = normalize(ωi + ωo) (Torrance &
//!   Sparrow 1967; Cook & Torrance 1982 with the 1/4 of Walter et al. 2007 Eq. 20), D Beckmann or GGX, G
//!   Smith height-correlated (Heitz 2014 Eq. 99, default) or the V-cavity G of Cook & Torrance (1982). Below
//!   [`Microfacet::SMOOTH_THRESHOLD`] the lobe is replaced by its delta limit R(θi) = F(cos θi) (D → δ(h − n),
//!   G → 1, ωi·h → cos θi), so the directional albedo is continuous across the switch.
use super::{above_horizon, Brdf, Hints, Lobe, Term, TermKind};
use crate::optics::fresnel::{critical_cosine, critical_cosine_complex, fr_conductor, fr_dielectric};
use crate::optics::microfacet::{Distribution, Microfacet, Shadowing};
use crate::spectrum::Sampling;
use crate::Vec3;
use num_complex::Complex64;

/// Refractive index of the body, relative to the ambient medium (air, n = 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Ior {
    /// A real index n (dielectric; the transmitted light is lost).
    Dielectric(f64),
    /// A complex index n + ik, k ≥ 0 (conductor; the transmitted light is absorbed).
    Conductor(Complex64),
}

impl Ior {
    /// Unpolarised Fresnel reflectance at cos θ = `cos_i` (Born & Wolf §1.5.2 / §14.2; pbrt-v4 `FrDielectric`,
    /// `FrConductor`).
    pub(crate) fn reflectance(&self, cos_i: f64) -> f64 {
        let c = cos_i.clamp(0.0, 1.0);
        match *self {
            Ior::Dielectric(n) => fr_dielectric(c, n),
            Ior::Conductor(eta) => fr_conductor(c, eta),
        }
    }

    /// The cosine of the critical angle, if the index has one (a real index below 1, as a dielectric or as a
    /// conductor with k = 0).
    pub(crate) fn critical_cosine(&self) -> Option<f64> {
        match *self {
            Ior::Dielectric(n) => critical_cosine(n),
            Ior::Conductor(eta) => critical_cosine_complex(eta),
        }
    }

    pub fn describe(&self) -> String {
        match self {
            Ior::Dielectric(n) => format!("n = {n}"),
            Ior::Conductor(e) => format!("n = {} + {}i", e.re, e.im),
        }
    }
}

pub(crate) fn describe_iors(ior: &[Ior]) -> String {
    if ior.len() == 1 || ior.windows(2).all(|w| w[0] == w[1]) {
        ior[0].describe()
    } else {
        format!("[{}]", ior.iter().map(Ior::describe).collect::<Vec<_>>().join("; "))
    }
}

/// An ideally smooth, opaque (black-backed) dielectric: a delta reflection of weight gain·F(cos θi, n).
///
/// The one smooth-dielectric type: a specimen (`"model": "smooth-dielectric"`, gain 1) and every gloss
/// standard (`instrument::reading::Scale::standard`): polished black glass of the scale's index with gain
/// 100/V when the scale assigns it V GU (gain 1 for the usual 100 GU, so that standard is the specimen of the
/// same index to the bit), or the perfect mirror of the mirror scale, n = ∞ (the n → ∞ limit of Fresnel,
/// R = 1 at every angle) with gain 100/V.
#[derive(Clone, Debug, PartialEq)]
pub struct SmoothDielectric {
    /// Real refractive index n relative to air; `f64::INFINITY` is the perfect mirror.
    pub ior: f64,
    /// Factor on the Fresnel reflectance: 1 for a physical surface, 100/V for a gloss standard assigned V.
    pub gain: f64,
    pub sampling: Sampling,
}

impl SmoothDielectric {
    pub fn new(ior: f64) -> Self {
        SmoothDielectric { ior, gain: 1.0, sampling: Sampling::grey() }
    }

    /// The delta reflection's weight at cos θi = `cos_i`: gain·F(cos θi, n), gain for the perfect mirror.
    pub(crate) fn reflectance(&self, cos_i: f64) -> f64 {
        if self.ior == f64::INFINITY {
            self.gain
        } else {
            Ior::Dielectric(self.ior).reflectance(cos_i) * self.gain
        }
    }
}

impl Brdf for SmoothDielectric {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    fn eval(&self, _wi: Vec3, _wo: Vec3, out: &mut [f64]) {
        out.fill(0.0);
    }

    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        out.fill(self.reflectance(wi.z));
        true
    }

    /// Analytic everywhere but on the kink of its critical angle (`Hints::smooth`).
    fn hints(&self) -> Hints {
        Hints::new(vec![Term { label: "specular reflection (Fresnel)".into(), kind: TermKind::Delta }])
            .with_kinks(super::fresnel_kinks([critical_cosine(self.ior)], true))
            .with_smooth(true)
    }

    fn describe(&self) -> String {
        let surface = if self.ior == f64::INFINITY {
            "perfect mirror".to_string()
        } else {
            format!("smooth dielectric (n = {}, black-backed)", self.ior)
        };
        if self.gain == 1.0 {
            surface
        } else {
            format!("{surface} × {}", self.gain)
        }
    }
}

/// One finite index per spectral sample (a conductor's n + k checked as one number), else an error.
pub(crate) fn check_iors(ior: &[Ior], sampling: &Sampling) -> crate::Result<()> {
    let parts: Vec<f64> = ior
        .iter()
        .map(|i| match i {
            Ior::Dielectric(n) => *n,
            Ior::Conductor(c) => c.re + c.im,
        })
        .collect();
    super::per_sample("index of refraction", &parts, sampling)
}

/// A rough interface (dielectric or conductor) with a single microfacet lobe; see the module documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct MicrofacetSurface {
    pub facets: Microfacet,
    pub shadowing: Shadowing,
    /// Index per spectral sample.
    pub ior: Vec<Ior>,
    pub sampling: Sampling,
}

impl MicrofacetSurface {
    /// One finite index per spectral sample, else an error.
    pub fn new(facets: Microfacet, shadowing: Shadowing, ior: Vec<Ior>, sampling: Sampling) -> crate::Result<Self> {
        check_iors(&ior, &sampling)?;
        Ok(MicrofacetSurface { facets, shadowing, ior, sampling })
    }
}

/// "Beckmann m = 0.1" / "GGX α = 0.1".
pub(crate) fn describe_facets(f: &Microfacet) -> String {
    match f.distribution {
        Distribution::Beckmann => format!("Beckmann m = {}", crate::error::number(f.alpha)),
        Distribution::Ggx => format!("GGX α = {}", crate::error::number(f.alpha)),
    }
}

pub(crate) fn describe_shadowing(s: Shadowing) -> &'static str {
    match s {
        Shadowing::SmithHeightCorrelated => "Smith height-correlated",
        Shadowing::SmithSeparable => "Smith separable (G1·G1)",
        Shadowing::VCavity => "V-cavity",
    }
}

/// D(h)·G/(4 cos θi cos θo) and ωi·h for a microfacet lobe, or None when the pair is not
/// [`above_horizon`] (the regular part is zero there).
pub(crate) fn microfacet_factor(facets: &Microfacet, shadowing: Shadowing, wi: Vec3, wo: Vec3) -> Option<(f64, f64)> {
    if !above_horizon(wi, wo) {
        return None;
    }
    let h = (wi + wo).normalize();
    let cos_d = wi.dot(h).clamp(0.0, 1.0);
    let d = facets.d(h);
    if d == 0.0 {
        return Some((0.0, cos_d));
    }
    let g = facets.g(wi, wo, h, shadowing);
    Some((d * g / (4.0 * wi.z * wo.z), cos_d))
}

impl Brdf for MicrofacetSurface {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        if self.facets.effectively_smooth() {
            out.fill(0.0);
            return;
        }
        match microfacet_factor(&self.facets, self.shadowing, wi, wo) {
            None => out.fill(0.0),
            Some((dg, cos_d)) => {
                for (o, ior) in out.iter_mut().zip(&self.ior) {
                    *o = if dg == 0.0 { 0.0 } else { ior.reflectance(cos_d) * dg };
                }
            }
        }
    }

    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        if !self.facets.effectively_smooth() {
            return false;
        }
        for (o, ior) in out.iter_mut().zip(&self.ior) {
            *o = ior.reflectance(wi.z);
        }
        true
    }

    /// f·cos θi·cos θo = F·D·G/4 ≤ D(θh)/4 (F ≤ 1, G ≤ 1; Walter et al. 2007 Eq. 20), and θh ≥ ψ/2: the
    /// reflections of ωi about h and about the normal differ by a rotation of 2θh (docs/instrument.md
    /// §Quadrature, "A receptor the lobe cannot reach").
    fn tail_majorant(&self, psi: f64) -> Option<f64> {
        if self.facets.effectively_smooth() {
            return Some(0.0);
        }
        self.facets.d_majorant(0.5 * psi).map(|d| 0.25 * d)
    }

    /// The Fresnel factor F(ωi·h) of every index below 1 kinks at its critical angle (in cos θi in the
    /// smooth limit). Smooth with a Smith G; the V-cavity G is a min() of three terms, a kink it does not
    /// report.
    fn hints(&self) -> Hints {
        let smooth_limit = self.facets.effectively_smooth();
        let term = if smooth_limit {
            Term { label: "specular reflection (smooth limit of the microfacet lobe)".into(), kind: TermKind::Delta }
        } else {
            let label = format!("microfacet lobe ({})", describe_facets(&self.facets));
            Term { label: label.clone(), kind: TermKind::Lobe(Lobe::of_facets(&self.facets, 1.0, label)) }
        };
        Hints::new(vec![term])
            .with_kinks(super::fresnel_kinks(self.ior.iter().map(Ior::critical_cosine), smooth_limit))
            .with_smooth(self.shadowing != Shadowing::VCavity)
    }

    fn describe(&self) -> String {
        let smooth = if self.facets.effectively_smooth() { ", evaluated as its smooth (delta) limit" } else { "" };
        format!(
            "microfacet ({}, {}, {}{smooth})",
            describe_facets(&self.facets),
            describe_iors(&self.ior),
            describe_shadowing(self.shadowing)
        )
    }
}
