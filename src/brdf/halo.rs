//! A smooth-surface scatter halo on the mirror of a model: the Rayleigh–Rice scatter of the top interface's
//! topography (`optics::scatter`), added to a model whose delta term contains that interface's Fresnel
//! mirror, which loses what the halo scatters (docs/optics.md §Near-specular scatter):
//!
//!   f = f_inner,regular + f_RR(ωi, ωo)     R_δ = R_δ,inner(θi) − R(θi)·g(θi),
//!   g(θi) = (4π cos θi/λ)²·σ²_bl(θi),
//!
//! with R the interface's Fresnel reflectance and σ²_bl the PSD integrated over the propagating frequencies.
//! The halo's hemispherical integral is R·g to first order in the halo's angular width (Q·cos θs ≈ R·cos θi
//! over the halo; `tests/scatter.rs` measures the difference), so the mirror, the halo and what the inner
//! model puts under the interface (T = 1 − R, unchanged) conserve energy to that order.
use super::{above_horizon, Brdf, Hints, Lobe, Tail, Term, TermKind};
use crate::optics::scatter::{polarisation, polarisation_factor, rayleigh_rice, rayleigh_rice_with_q, Psd};
use crate::spectrum::Sampling;
use crate::{Error, Result, Vec3};
use num_complex::Complex64;
use std::sync::Arc;

/// The scatter of one interface: its topography and its permittivity per spectral sample.
#[derive(Clone, Debug, PartialEq)]
pub struct Halo {
    pub psd: Psd,
    /// Relative permittivity ε = (n + ik)² of the interface, one per spectral sample.
    pub eps: Vec<Complex64>,
    /// Wavelengths in nm, one per sample (the material's sampling).
    pub lambda_nm: Vec<f64>,
}

impl Halo {
    /// The halo of `psd` on an interface of complex index `index` per sample of `sampling`. Refuses a PSD
    /// outside the smooth-surface theory: 4πσ/λ > [`crate::optics::scatter::MAX_PHASE`] at the shortest
    /// wavelength (the error says which σ is allowed; the recipe parser names the field).
    pub fn new(psd: Psd, index: &[Complex64], sampling: &Sampling) -> Result<Halo> {
        if index.len() != sampling.len() {
            return Err(Error::Usage(format!(
                "scatter halo: {} index value(s) for {} spectral sample(s)",
                index.len(),
                sampling.len()
            )));
        }
        let sigma_max = Halo::sigma_max(sampling);
        let sigma = psd.sigma();
        if !(sigma > 0.0 && sigma <= sigma_max) {
            return Err(Error::Usage(format!(
                "the rms roughness σ = {} nm is outside the smooth-surface (Rayleigh–Rice) theory at λ = {} nm; \
                 allowed: σ in (0, {}] nm (4πσ/λ ≤ {}, docs/optics.md §8, Validity)",
                crate::error::number(sigma),
                sampling.wavelengths_nm.iter().copied().fold(f64::INFINITY, f64::min),
                crate::error::number(sigma_max),
                crate::optics::scatter::MAX_PHASE
            )));
        }
        Ok(Halo { psd, eps: index.iter().map(|n| n * n).collect(), lambda_nm: sampling.wavelengths_nm.clone() })
    }

    /// The largest rms roughness (nm) the theory is used for with this sampling.
    pub(crate) fn sigma_max(sampling: &Sampling) -> f64 {
        let lambda_min = sampling.wavelengths_nm.iter().copied().fold(f64::INFINITY, f64::min);
        crate::optics::scatter::MAX_PHASE * lambda_min / (4.0 * std::f64::consts::PI)
    }

    /// The halo's value per sample, added to `out`.
    pub(crate) fn add(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        let (a, b) = ([wi.x, wi.y, wi.z], [wo.x, wo.y, wo.z]);
        if self.eps.windows(2).all(|w| w[0] == w[1]) {
            // One ε (a coat's real index): Q once per pair, the same bits as per sample.
            let q = self.eps.first().map_or(0.0, |e| polarisation(*e, a, b));
            for (o, lam) in out.iter_mut().zip(&self.lambda_nm) {
                *o += rayleigh_rice_with_q(&self.psd, q, *lam, a, b);
            }
            return;
        }
        for ((o, eps), lam) in out.iter_mut().zip(&self.eps).zip(&self.lambda_nm) {
            *o += rayleigh_rice(&self.psd, *eps, *lam, a, b);
        }
    }

    /// The Fresnel reflectance R(θi) of sample `k` (Q at the specular direction).
    pub fn mirror_reflectance(&self, k: usize, cos_i: f64) -> f64 {
        polarisation_factor(self.eps[k], cos_i, cos_i, 1.0, 0.0)
    }

    /// The Debye–Waller exponent g = (4π cos θi/λ)² σ²_bl of sample `k`: the fraction of the mirror the halo
    /// takes (first order).
    pub fn loss(&self, k: usize, cos_i: f64) -> f64 {
        let c = cos_i.clamp(0.0, 1.0);
        let lam = self.lambda_nm[k];
        let s = (1.0 - c * c).max(0.0).sqrt();
        let k4 = 4.0 * std::f64::consts::PI * c / lam;
        k4 * k4 * self.psd.band_limited(s, lam * 1e-3)
    }

    /// Take the halo's light from a mirror: out[k] −= R(θi)·g(θi) (first order, docs/optics.md §8).
    pub(crate) fn take_from_mirror(&self, wi: Vec3, out: &mut [f64]) {
        if wi.z > 0.0 {
            let c = wi.z.min(1.0);
            for (k, o) in out.iter_mut().enumerate() {
                *o -= self.mirror_reflectance(k, c) * self.loss(k, c);
            }
        }
    }

    /// The halo as a term of the model it is added to (its [`Halo::lobe`]).
    pub(crate) fn term(&self) -> Term {
        let lobe = self.lobe();
        Term { label: lobe.label.clone(), kind: TermKind::Lobe(lobe) }
    }

    /// The halo as a lobe for the planner: its width as a slope is half the spread of the scattered
    /// direction cosines at the PSD's knee at normal incidence, λ·f_knee/2 at the shortest wavelength (the
    /// halo widens as 1/cos θ off normal, so the splits are at least as fine as it needs); its tail is a power
    /// law (K-correlation) or a Gaussian in f that is not one in the planner's lobe variables, so it is
    /// reported as heavy and unstated ([`Tail::Unknown`]): splits out to the ends of the range, the adaptive
    /// partition, no shaped rule.
    pub(crate) fn lobe(&self) -> Lobe {
        let lambda_min = self.lambda_nm.iter().copied().fold(f64::INFINITY, f64::min);
        Lobe {
            slope_width: 0.5 * lambda_min * 1e-3 * self.psd.knee(),
            medium_eta: 1.0,
            label: format!("scatter halo ({})", self.describe()),
            tail: Tail::Unknown,
        }
    }

    /// The hints of a model `inner` with this halo added ([`WithHalo`], [`super::two_scale::RoughWithHalo`]):
    /// the inner model's, with the halo's term after its own. The halo is reciprocal (Q and S₂(|f|) are
    /// symmetric in ωi, ωo) and analytic in the upper hemispheres (a real ε > 1 has no critical angle from
    /// outside; a conductor's ε none at all), so the whole keeps the inner model's kinks, seams, reciprocity
    /// and smoothness.
    pub(crate) fn over(&self, inner: Hints) -> Hints {
        let mut h = inner;
        h.terms.push(self.term());
        h
    }

    pub fn describe(&self) -> String {
        let e = crate::error::number;
        match self.psd {
            Psd::KCorrelation { a, b, c } => format!(
                "Rayleigh–Rice, K-correlation PSD A = {} nm²·µm, B = {} µm, C = {} (σ = {} nm, ℓ = {} µm)",
                e(a),
                e(b),
                e(c),
                e(self.psd.sigma()),
                e(self.psd.correlation_length())
            ),
            Psd::Gaussian { sigma, ell } => {
                format!("Rayleigh–Rice, Gaussian PSD σ = {} nm, ℓ = {} µm", e(sigma), e(ell))
            }
        }
    }
}

/// A model with a scatter halo on its top interface's mirror.
#[derive(Clone, Debug)]
pub(crate) struct WithHalo {
    pub inner: Arc<dyn Brdf>,
    pub halo: Halo,
}

impl WithHalo {
    /// `inner` must have a delta term that contains the Fresnel mirror of the interface of `halo` (the
    /// recipe parser attaches halos only there: a smooth paint coat, a Cook–Torrance model's clear coat, a
    /// smooth microfacet interface).
    pub(crate) fn new(inner: Arc<dyn Brdf>, halo: Halo) -> Result<WithHalo> {
        if !inner.has_delta() {
            return Err(Error::Usage("a scatter halo needs a model with a mirror (delta) term".into()));
        }
        if halo.eps.len() != inner.sampling().len() {
            return Err(Error::Usage("scatter halo: sampling differs from the model's".into()));
        }
        Ok(WithHalo { inner, halo })
    }
}

impl Brdf for WithHalo {
    fn sampling(&self) -> &Sampling {
        self.inner.sampling()
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        self.inner.eval(wi, wo, out);
        if above_horizon(wi, wo) {
            self.halo.add(wi, wo, out);
        }
    }

    fn eval_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        self.inner.eval_batch(wi, wo, out);
        let n = self.sampling().len();
        for ((a, b), o) in wi.iter().zip(wo).zip(out.chunks_exact_mut(n)) {
            if above_horizon(*a, *b) {
                self.halo.add(*a, *b, o);
            }
        }
    }

    fn folds(&self, w: &[f64]) -> bool {
        self.inner.folds(w)
    }

    fn eval_batch_folded(&self, w: &[f64], wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) -> bool {
        if !self.inner.eval_batch_folded(w, wi, wo, out) {
            return false;
        }
        let mut h = vec![0.0; self.halo.eps.len()];
        for ((a, b), o) in wi.iter().zip(wo).zip(out.iter_mut()) {
            if above_horizon(*a, *b) {
                h.fill(0.0);
                self.halo.add(*a, *b, &mut h);
                *o += w.iter().zip(&h).map(|(w, h)| w * h).sum::<f64>();
            }
        }
        true
    }

    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        if !self.inner.delta_reflectance(wi, out) {
            return false;
        }
        self.halo.take_from_mirror(wi, out);
        true
    }

    fn hints(&self) -> Hints {
        self.halo.over(self.inner.hints())
    }

    fn describe(&self) -> String {
        format!("{}; with a scatter halo on the mirror ({})", self.inner.describe(), self.halo.describe())
    }
}
