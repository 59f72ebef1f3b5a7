//! The two-scale surface of a measured map (`"model": "topography"` with a scale split; docs/optics.md
//! §Two-scale surface of a measured map, docs/topography.md §The two-scale surface): the map's spectrum is
//! split at a spatial frequency f_s; the long waves (|f| < f_s) are facets in geometric optics
//! (`brdf::topography`, the slopes of the map low-passed below f_s), the short waves (|f| ≥ f_s) scatter a
//! Rayleigh–Rice halo from their own 2-D PSD (`optics::scatter`'s formula, with the map's periodogram for S₂),
//! and the facets lose what the halo scatters:
//!
//!   f = (1 − g(θ̄))·f_facets(ωi, ωo) + f_RR(ωi, ωo),   g(θ) = (4π cos θ/λ)²·σ²_>,bl(θ),   cos θ̄ = (cos θi + cos θo)/2,
//!
//! or, when the long waves are flat (f_s at or below the map's lowest frequency), a Fresnel mirror
//! R(θi)·(1 − g(θi)) in place of the facets. Nothing is fitted: the map, the index and the sampling's
//! wavelengths give every number. The halo keeps the map's anisotropy (S₂ at (fx, fy), x the plane of
//! measurement's axis); g uses the azimuthal average of the short-wave PSD (exact for an isotropic map).
use super::dielectric::Ior;
use super::topography::TopographySurface;
use super::{above_horizon, below_horizon, fresnel_kinks, Brdf, Hints, Lobe, Tail, Term, TermKind};
use crate::optics::scatter::{polarisation, polarisation_factor};
use crate::spectrum::Sampling;
use crate::{Error, Result, Vec3};
use num_complex::Complex64;
use std::f64::consts::PI;

/// Points of the periodic trapezoid rule over the azimuth of the propagating disc (as `Psd::band_limited`).
const AZIMUTH_POINTS: usize = 256;
/// Intervals of the table of g over cos θ ∈ [0, 1] (linear interpolation between its nodes).
const LOSS_INTERVALS: usize = 512;

/// The short-wave part of a map's PSD: S₂ on the map's frequency grid in nm²·µm², zero below f_s and at
/// f = 0 (the mean height is no roughness), frequencies in 1/µm.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ShortWaves {
    nx: usize,
    ny: usize,
    dfx: f64,
    dfy: f64,
    s: Vec<f64>,
    /// The split frequency f_s, 1/µm (infinite: no short waves).
    pub f_s: f64,
    /// σ²_> = Σ S₂ Δfₓ Δf_y over the short waves, nm².
    pub sigma2: f64,
    /// The grid's |f| (1/µm) in increasing order with P(|f|) = Σ_{|f'| ≤ |f|} S₂ Δfₓ Δf_y / 2π, nm².
    radial: Vec<(f64, f64)>,
}

impl ShortWaves {
    /// The short waves of a map's PSD on its grid (`s[ky·nx + kx]` in the transform's order, index k above
    /// n/2 the frequency k − n, nm²·µm²), Δfₓ = `dfx`, Δf_y = `dfy` (1/µm): the modes with |f| ≥ `f_s` (1/µm)
    /// and f ≠ 0 kept, the rest set to zero.
    pub fn new(nx: usize, ny: usize, (dfx, dfy): (f64, f64), mut s: Vec<f64>, f_s: f64) -> ShortWaves {
        let signed = |k: usize, n: usize| if k <= n / 2 { k as f64 } else { k as f64 - n as f64 };
        let mut radial = Vec::new();
        for ky in 0..ny {
            for kx in 0..nx {
                let f = (signed(kx, nx) * dfx).hypot(signed(ky, ny) * dfy);
                let v = &mut s[ky * nx + kx];
                if f > 0.0 && f >= f_s {
                    radial.push((f, *v * dfx * dfy));
                } else {
                    *v = 0.0;
                }
            }
        }
        radial.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut acc = 0.0;
        for r in &mut radial {
            acc += r.1;
            r.1 = acc / (2.0 * PI);
        }
        ShortWaves { nx, ny, dfx, dfy, s, f_s, sigma2: acc, radial }
    }

    /// S₂(fx, fy), nm²·µm² (fx, fy in 1/µm): the grid values interpolated bilinearly on the periodic grid,
    /// zero outside the Nyquist box, so that its integral over the plane is σ²_> exactly.
    pub fn s2(&self, fx: f64, fy: f64) -> f64 {
        let (u, v) = (fx / self.dfx, fy / self.dfy);
        if !(u.abs() <= 0.5 * self.nx as f64 && v.abs() <= 0.5 * self.ny as f64) {
            return 0.0;
        }
        let (i0, j0) = (u.floor(), v.floor());
        let (t, w) = (u - i0, v - j0);
        let wrap = |k: f64, n: usize| (k as i64).rem_euclid(n as i64) as usize;
        let at = |i: f64, j: f64| self.s[wrap(j, self.ny) * self.nx + wrap(i, self.nx)];
        (1.0 - t) * (1.0 - w) * at(i0, j0)
            + t * (1.0 - w) * at(i0 + 1.0, j0)
            + (1.0 - t) * w * at(i0, j0 + 1.0)
            + t * w * at(i0 + 1.0, j0 + 1.0)
    }

    /// P(ρ) = Σ_{|f| < ρ} S₂ Δfₓ Δf_y / 2π, nm² (the map's counterpart of `Psd::radial_cumulative`).
    fn cumulative(&self, rho: f64) -> f64 {
        let k = self.radial.partition_point(|r| r.0 < rho);
        if k == 0 {
            0.0
        } else {
            self.radial[k - 1].1
        }
    }

    /// σ²_>,bl (nm²): the short-wave power over the propagating disc |λ f + s| ≤ 1 of incidence sin θi =
    /// `sin_i` at `lambda_um`, azimuthally averaged (the trapezoid rule of `Psd::band_limited`).
    pub fn band_limited(&self, sin_i: f64, lambda_um: f64) -> f64 {
        let s = sin_i.clamp(0.0, 1.0);
        let rest = (1.0 - s * s).max(0.0);
        let h = 2.0 * PI / AZIMUTH_POINTS as f64;
        let sum: f64 = (0..AZIMUTH_POINTS)
            .map(|k| {
                let sc = s * (k as f64 * h).cos();
                self.cumulative((-sc + (sc * sc + rest).sqrt()) / lambda_um)
            })
            .sum();
        sum * h
    }
}

/// The two-scale surface of a measured map: the long waves' facets (or a mirror where they are flat) and the
/// short waves' halo.
#[derive(Clone, Debug)]
pub(crate) struct MapTwoScale {
    /// The long waves' facets; None: flat long waves, a Fresnel mirror.
    pub facets: Option<TopographySurface>,
    pub ior: f64,
    pub short: ShortWaves,
    eps: Complex64,
    /// g(cos θ) per sample at `LOSS_INTERVALS` + 1 equally spaced cosines.
    loss: Vec<Vec<f64>>,
    sampling: Sampling,
    /// What the map came from, for `describe`.
    pub source: String,
}

impl MapTwoScale {
    /// Refuses short waves outside the smooth-surface theory at the sampling's shortest wavelength (σ_> >
    /// `Halo::sigma_max`, docs/optics.md §Validity); the recipe parser names the file and the field.
    pub fn new(
        facets: Option<TopographySurface>,
        short: ShortWaves,
        ior: f64,
        sampling: Sampling,
        source: String,
    ) -> Result<MapTwoScale> {
        let sigma_max = super::halo::Halo::sigma_max(&sampling);
        let sigma = short.sigma2.sqrt();
        if !(sigma <= sigma_max && ior.is_finite() && ior > 0.0) {
            return Err(Error::Usage(format!(
                "the short waves of the map (|f| ≥ {} /µm) have rms height σ_> = {} nm, outside the smooth-surface \
                 (Rayleigh–Rice) theory at λ = {} nm; allowed: σ_> ≤ {} nm (4πσ_>/λ ≤ {}, docs/optics.md §10): a \
                 higher split frequency",
                crate::error::number(short.f_s),
                crate::error::number(sigma),
                sampling.wavelengths_nm.iter().copied().fold(f64::INFINITY, f64::min),
                crate::error::number(sigma_max),
                crate::optics::scatter::MAX_PHASE
            )));
        }
        let loss = sampling
            .wavelengths_nm
            .iter()
            .map(|&lam| {
                (0..=LOSS_INTERVALS)
                    .map(|i| {
                        let c = i as f64 / LOSS_INTERVALS as f64;
                        let k4 = 4.0 * PI * c / lam;
                        k4 * k4 * short.band_limited((1.0 - c * c).max(0.0).sqrt(), lam * 1e-3)
                    })
                    .collect()
            })
            .collect();
        Ok(MapTwoScale { facets, ior, short, eps: Complex64::new(ior * ior, 0.0), loss, sampling, source })
    }

    /// The Debye–Waller exponent g(cos θ) of sample `k` (first order; the table's linear interpolation).
    pub fn loss(&self, k: usize, cos: f64) -> f64 {
        let x = cos.clamp(0.0, 1.0) * LOSS_INTERVALS as f64;
        let i = (x.floor() as usize).min(LOSS_INTERVALS - 1);
        let t = x - i as f64;
        let g = &self.loss[k];
        (1.0 - t) * g[i] + t * g[i + 1]
    }

    /// The halo f_RR = (16π²/λ⁴) cos θi cos θs Q S₂(f), f = (ωo,xy + ωi,xy)/λ (docs/optics.md §8), added to
    /// `out` per sample.
    pub fn add_halo(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        if self.short.sigma2 == 0.0 {
            return;
        }
        let q = polarisation(self.eps, [wi.x, wi.y, wi.z], [wo.x, wo.y, wo.z]);
        for (o, &lam) in out.iter_mut().zip(&self.sampling.wavelengths_nm) {
            let um = lam * 1e-3;
            let s = self.short.s2((wo.x + wi.x) / um, (wo.y + wi.y) / um);
            *o += 16.0 * PI * PI * wi.z.min(1.0) * wo.z.min(1.0) * q * s / (lam * lam * um * um);
        }
    }

    /// The halo as a lobe for the planner: as `Halo::lobe`, its width the spread λ·f/2 of the scattered
    /// direction cosines at the lowest short-wave frequency (the shortest wavelength), of unknown tail.
    fn halo_term(&self) -> Term {
        let lambda_min = self.sampling.wavelengths_nm.iter().copied().fold(f64::INFINITY, f64::min);
        let f_lo = self.short.f_s.max(self.short.dfx.min(self.short.dfy));
        let label = format!("scatter halo of the map's short waves (σ_> = {:.3} nm)", self.short.sigma2.sqrt());
        let lobe = Lobe {
            slope_width: 0.5 * lambda_min * 1e-3 * f_lo,
            medium_eta: 1.0,
            label: label.clone(),
            tail: Tail::Unknown,
        };
        Term { label, kind: TermKind::Lobe(lobe) }
    }
}

impl Brdf for MapTwoScale {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        if below_horizon(wi, wo, out) {
            return;
        }
        match &self.facets {
            Some(f) => {
                f.eval(wi, wo, out);
                let c = 0.5 * (wi.z + wo.z);
                for (k, o) in out.iter_mut().enumerate() {
                    *o *= (1.0 - self.loss(k, c)).max(0.0);
                }
            }
            None => out.fill(0.0),
        }
        if above_horizon(wi, wo) {
            self.add_halo(wi, wo, out);
        }
    }

    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        if self.facets.is_some() {
            return false;
        }
        let c = wi.z.clamp(0.0, 1.0);
        for (k, o) in out.iter_mut().enumerate() {
            *o = if wi.z > 0.0 { polarisation_factor(self.eps, c, c, 1.0, 0.0) * (1.0 - self.loss(k, c)) } else { 0.0 };
        }
        true
    }

    fn hints(&self) -> Hints {
        let mut h = match &self.facets {
            Some(f) => f.hints(),
            None => Hints::new(vec![Term { label: "specular reflection (Fresnel)".into(), kind: TermKind::Delta }])
                .with_kinks(fresnel_kinks([Ior::Dielectric(self.ior).critical_cosine()], true)),
        };
        if self.short.sigma2 > 0.0 {
            h.terms.push(self.halo_term());
        }
        h
    }

    fn describe(&self) -> String {
        let long = match &self.facets {
            Some(f) => format!("long waves: {}", f.describe()),
            None => format!("long waves flat: a Fresnel mirror, n = {}", self.ior),
        };
        format!(
            "two-scale surface of a measured map ({}; split at f_s = {} /µm): {long}; short waves: Rayleigh–Rice \
             halo of the map's 2-D PSD, σ_> = {} nm, the long waves' reflection times 1 − g",
            self.source,
            crate::error::number(self.short.f_s),
            crate::error::number(self.short.sigma2.sqrt())
        )
    }
}
