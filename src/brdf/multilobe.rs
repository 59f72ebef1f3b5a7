//! Lambertian base plus K Cook–Torrance lobes: the multi-lobe model Günther, Chen, Goesele, Wald & Seidel
//! (2005), "Efficient acquisition and realistic rendering of car paint", VMV 2005, fitted to measured car
//! paints, in the "guenther" interpretation documented in `docs/recipe-format.md` §cook-torrance-lobes:
//!
//!   f = Kd/π + Σₖ Ksₖ · Fₖ(ωi·h) · Dₖ(h) · G(ωi, ωo) / (4 cos θi cos θo),
//!
//! * Dₖ: normalised Beckmann distribution with rms slope m = Mₖ (Cook & Torrance 1982 Eq. 10, with the 1/π
//!   that makes ∫ D cos θh dω = 1), or GGX with α = Mₖ if the recipe asks;
//! * Fₖ: Schlick's approximation with the fitted scale Rₖ as F0: F = R + (1 − R)(1 − ωi·h)⁵ (Schlick 1994,
//!   "An inexpensive BRDF model for physically-based rendering", CGF 13(3) Eq. 15);
//! * G: Smith height-correlated for the lobe's distribution (Heitz 2014 Eq. 99), or the V-cavity G;
//! * the 1/(4 cos θi cos θo) of the modern microfacet form (Walter et al. 2007 Eq. 20). Cook & Torrance
//!   (1982) wrote 1/(π cos θi cos θo) with an unnormalised D; with a normalised D that form is 4× ours, so Ks
//!   fitted under it would read 4× smaller. LuxCore (`slg/materials/carpaint.cpp`) evaluates the same presets
//!   with Schlick's rational distribution at r = M² and Schlick's G instead; that reading is not implemented.
//!
//! Reciprocal (F depends on ωi·h = ωo·h). With every Rₖ ≤ 1 the lobe k reflects at most Ksₖ, so
//! Kd + Σ Ks ≤ 1 per sample bounds the albedo by 1. A lobe with Mₖ below [`Microfacet::SMOOTH_THRESHOLD`]
//! becomes a delta of weight Ksₖ·Fₖ(cos θi), continuous with the rough lobe.
use super::dielectric::{describe_facets, describe_shadowing, microfacet_factor};
use super::lambert::fmt_values;
use super::{below_horizon, Brdf, Hints, Lobe, Term, TermKind};
use crate::optics::fresnel::fr_dielectric;
use crate::optics::microfacet::{Microfacet, Shadowing};
use crate::spectrum::Sampling;
use crate::Vec3;
use std::f64::consts::PI;

/// Schlick's Fresnel approximation F = F0 + (1 − F0)(1 − cos θ)⁵ (Schlick 1994 Eq. 15).
pub(crate) fn schlick_fresnel(f0: f64, cos_theta: f64) -> f64 {
    let m = (1.0 - cos_theta.clamp(0.0, 1.0)).powi(5);
    f0 + (1.0 - f0) * m
}

/// One Cook–Torrance lobe.
#[derive(Clone, Debug, PartialEq)]
pub struct CtLobe {
    /// Lobe weight Ks per sample.
    pub ks: Vec<f64>,
    /// Schlick F0-like scale R ∈ [0, 1].
    pub r: f64,
    /// Facet distribution (roughness M as the Beckmann m or the GGX α).
    pub facets: Microfacet,
}

#[derive(Clone, Debug, PartialEq)]
pub struct CookTorranceLobes {
    /// Lambertian albedo Kd per sample.
    pub kd: Vec<f64>,
    pub lobes: Vec<CtLobe>,
    pub shadowing: Shadowing,
    pub sampling: Sampling,
    /// A smooth clear coat of this index on top (`"clear_coat": {"index": n}`): a Fresnel mirror ρ(θi), the
    /// lobes and Kd seen through it weighted by T(θi)·T(θo), T = 1 − ρ (energy-conserving and reciprocal).
    pub clear_coat: Option<f64>,
}

impl CookTorranceLobes {
    /// One finite Kd and, per lobe, one finite Ks per spectral sample, else an error.
    pub fn new(kd: Vec<f64>, lobes: Vec<CtLobe>, shadowing: Shadowing, sampling: Sampling) -> crate::Result<Self> {
        super::per_sample("kd", &kd, &sampling)?;
        for (i, l) in lobes.iter().enumerate() {
            super::per_sample(&format!("lobe {i} ks"), &l.ks, &sampling)?;
        }
        Ok(CookTorranceLobes { kd, lobes, shadowing, sampling, clear_coat: None })
    }

    /// Put a smooth clear coat of index `index` on top (docs/recipe-format.md §cook-torrance-lobes).
    pub(crate) fn with_clear_coat(mut self, index: f64) -> Self {
        self.clear_coat = Some(index);
        self
    }

    /// T(θ) = 1 − ρ(θ) of the clear coat (1 without one).
    fn coat_t(&self, cos_theta: f64) -> f64 {
        self.clear_coat.map_or(1.0, |n| 1.0 - fr_dielectric(cos_theta.clamp(0.0, 1.0), n))
    }
}

impl Brdf for CookTorranceLobes {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        if below_horizon(wi, wo, out) {
            return;
        }
        for (o, kd) in out.iter_mut().zip(&self.kd) {
            *o = kd / PI;
        }
        for lobe in self.lobes.iter().filter(|l| !l.facets.effectively_smooth()) {
            if let Some((dg, cos_d)) = microfacet_factor(&lobe.facets, self.shadowing, wi, wo) {
                if dg > 0.0 {
                    let w = schlick_fresnel(lobe.r, cos_d) * dg;
                    for (o, ks) in out.iter_mut().zip(&lobe.ks) {
                        *o += ks * w;
                    }
                }
            }
        }
        if self.clear_coat.is_some() {
            let tt = self.coat_t(wi.z) * self.coat_t(wo.z);
            out.iter_mut().for_each(|o| *o *= tt);
        }
    }

    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        let smooth: Vec<&CtLobe> = self.lobes.iter().filter(|l| l.facets.effectively_smooth()).collect();
        if smooth.is_empty() && self.clear_coat.is_none() {
            return false;
        }
        out.fill(0.0);
        // The mirror direction has θo = θi: a smooth lobe under the coat is weighted T(θi)².
        let tt = self.coat_t(wi.z).powi(2);
        for lobe in smooth {
            let f = schlick_fresnel(lobe.r, wi.z) * tt;
            for (o, ks) in out.iter_mut().zip(&lobe.ks) {
                *o += ks * f;
            }
        }
        if let Some(n) = self.clear_coat {
            let rho = fr_dielectric(wi.z.clamp(0.0, 1.0), n);
            out.iter_mut().for_each(|o| *o += rho);
        }
        true
    }

    /// Smooth with a Smith G and no clear coat (the V-cavity G's min() is a kink it does not report; a coat
    /// is not claimed).
    fn hints(&self) -> Hints {
        let mut t = Vec::new();
        if self.clear_coat.is_some() {
            t.push(Term { label: "clear coat (Fresnel, delta)".into(), kind: TermKind::Delta });
        }
        if self.kd.iter().any(|&k| k > 0.0) {
            t.push(Term { label: "Lambertian".into(), kind: TermKind::Diffuse });
        }
        for (i, lobe) in self.lobes.iter().enumerate() {
            if lobe.facets.effectively_smooth() {
                t.push(Term { label: format!("lobe {} (smooth limit)", i + 1), kind: TermKind::Delta });
            } else {
                let label = format!("Cook–Torrance lobe {} ({})", i + 1, describe_facets(&lobe.facets));
                t.push(Term { label: label.clone(), kind: TermKind::Lobe(Lobe::of_facets(&lobe.facets, 1.0, label)) });
            }
        }
        Hints::new(t).with_smooth(self.shadowing != Shadowing::VCavity && self.clear_coat.is_none())
    }

    fn describe(&self) -> String {
        let lobes: Vec<String> = self
            .lobes
            .iter()
            .map(|l| format!("Ks = {}, R = {}, {}", fmt_values(&l.ks), l.r, describe_facets(&l.facets)))
            .collect();
        let coat = match self.clear_coat {
            Some(n) => format!("; under a smooth clear coat η = {n} (Fresnel mirror on top, T(θi)T(θo) below)"),
            None => String::new(),
        };
        format!(
            "Cook–Torrance lobes (Kd = {}; {}; Schlick F; {}{coat})",
            fmt_values(&self.kd),
            lobes.join("; "),
            describe_shadowing(self.shadowing)
        )
    }
}
