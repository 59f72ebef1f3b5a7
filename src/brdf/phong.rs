//! Energy-normalised Phong and Blinn–Phong.
//!
//! * Phong (lobe about the mirror direction r = mirror(ωi)), normalised as by Lewis (1994), "Making shaders
//!   more physically plausible", Computer Graphics Forum 13(2):109–120:
//!   f = kd/π + ks·(n + 2)/(2π)·max(0, r·ωo)ⁿ.
//!   At normal incidence r = n̂ and ∫ cos^(n+1)θ dω = 2π/(n + 2), so the specular albedo is exactly ks; at
//!   oblique incidence the horizon cuts the lobe and the albedo is below ks.
//! * Blinn–Phong (lobe in the half vector h = normalize(ωi + ωo)), normalised exactly at normal incidence:
//!   f = kd/π + ks·(n + 2)(n + 4) / (8π(2^(−n/2) + n))·cosⁿθh.
//!   Derivation (also Giesen 2009, "The Blinn–Phong normalization zoo"): at normal incidence θh = θo/2 and
//!   ∫ cosⁿ(θo/2) cos θo dωo = 8π ∫_{1/√2}^{1} cⁿ⁺¹(2c² − 1) dc = 8π(n + 2^(−n/2))/((n + 2)(n + 4)).
//!   The usual approximation (n + 8)/(8π) (Akenine-Möller, Haines & Hoffman, *Real-Time Rendering* 3rd ed.
//!   Eq. 7.49) is not used.
//!
//! Both are reciprocal (r·ωo = mirror(ωo)·ωi; h is symmetric). Equivalent Beckmann slope width for the
//! integrator's lobe hint: cosⁿθh ≈ exp(−n tan²θh/2) near the peak, so Blinn–Phong ↔ Beckmann
//! m = √(2/(n + 2)) (Walter et al. 2007, §5.2, αp = 2αb⁻² − 2); the Phong lobe in r·ωo is about twice as
//! narrow in the half-vector (the angle to the mirror is ≈ 2θh near normal incidence), m ≈ ½√(2/(n + 2)).
use super::lambert::fmt_values;
use super::{below_horizon, mirror, Brdf, Hints, Lobe, Term, TermKind};
use crate::spectrum::Sampling;
use crate::Vec3;
use std::f64::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhongVariant {
    /// Lobe cosⁿ of the angle between ωo and the mirror direction of ωi.
    Phong,
    /// Lobe cosⁿ θh of the half-vector angle.
    BlinnPhong,
}

/// Normalised Phong / Blinn–Phong with a Lambertian term; see the module documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct Phong {
    pub variant: PhongVariant,
    /// Exponent n ≥ 0.
    pub exponent: f64,
    /// Diffuse albedo kd per sample.
    pub kd: Vec<f64>,
    /// Specular albedo at normal incidence ks per sample.
    pub ks: Vec<f64>,
    pub sampling: Sampling,
}

impl Phong {
    /// One finite kd and ks per spectral sample and a finite exponent ≥ 0, else an error.
    pub fn new(
        variant: PhongVariant,
        exponent: f64,
        kd: Vec<f64>,
        ks: Vec<f64>,
        sampling: Sampling,
    ) -> crate::Result<Self> {
        super::per_sample("kd", &kd, &sampling)?;
        super::per_sample("ks", &ks, &sampling)?;
        if !(exponent.is_finite() && exponent >= 0.0) {
            return Err(crate::Error::Usage(format!("Phong exponent must be a finite number ≥ 0, got {exponent}")));
        }
        Ok(Phong { variant, exponent, kd, ks, sampling })
    }

    /// The normalisation constant of the lobe (see the module documentation).
    pub fn normalisation(&self) -> f64 {
        let n = self.exponent;
        match self.variant {
            PhongVariant::Phong => (n + 2.0) / (2.0 * PI),
            PhongVariant::BlinnPhong => (n + 2.0) * (n + 4.0) / (8.0 * PI * ((-0.5 * n).exp2() + n)),
        }
    }

    /// Equivalent Beckmann rms slope of the lobe, for the integrator's splits.
    pub(crate) fn equivalent_slope_width(&self) -> f64 {
        let m = (2.0 / (self.exponent + 2.0)).sqrt();
        match self.variant {
            PhongVariant::BlinnPhong => m,
            PhongVariant::Phong => 0.5 * m,
        }
    }

    fn name(&self) -> &'static str {
        match self.variant {
            PhongVariant::Phong => "Phong",
            PhongVariant::BlinnPhong => "Blinn–Phong",
        }
    }
}

impl Brdf for Phong {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        if below_horizon(wi, wo, out) {
            return;
        }
        let c = match self.variant {
            PhongVariant::Phong => mirror(wi).dot(wo),
            PhongVariant::BlinnPhong => (wi + wo).normalize().z,
        };
        let lobe = if c > 0.0 { self.normalisation() * c.min(1.0).powf(self.exponent) } else { 0.0 };
        for ((o, kd), ks) in out.iter_mut().zip(&self.kd).zip(&self.ks) {
            *o = kd / PI + ks * lobe;
        }
    }

    /// max(0, c)ⁿ has n − 1 continuous derivatives at c = 0: smooth enough for the degree-7 rule from n = 8.
    fn hints(&self) -> Hints {
        let mut t = Vec::new();
        if self.kd.iter().any(|&k| k > 0.0) {
            t.push(Term { label: "Lambertian".into(), kind: TermKind::Diffuse });
        }
        let label = format!("{} lobe (n = {})", self.name(), crate::error::number(self.exponent));
        t.push(Term {
            label: label.clone(),
            kind: TermKind::Lobe(Lobe {
                slope_width: self.equivalent_slope_width(),
                medium_eta: 1.0,
                label,
                tail: super::Tail::Gaussian,
            }),
        });
        Hints::new(t).with_smooth(self.exponent >= 8.0)
    }

    fn describe(&self) -> String {
        format!(
            "normalised {} (n = {}, kd = {}, ks = {})",
            self.name(),
            self.exponent,
            fmt_values(&self.kd),
            fmt_values(&self.ks)
        )
    }
}
