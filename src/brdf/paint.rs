//! The paint model of Ďurikovič & Ágošton (2007), "Prediction of optical properties of paints",
//! Cent. Eur. J. Phys. 5(3):416, Eqs. (1)–(8), with the typesetting errors of the paper corrected and the
//! layering made physically consistent. The whole model, every formula with its source, the corrections to
//! the paper and every choice where the paper is silent are in `docs/model.md`; this file follows it.
//!
//! Structure (exterior directions ωi, ωo; interior directions ωi' = refract(ωi), ωo' = refract(ωo)):
//!
//! ```text
//! f_r(ωi, ωo) = ρ(θi)·δ(ωo − mirror ωi)/cos θo                      clear coat (Fresnel, delta)
//!             [or F·D·G/(4 cos θi cos θo) for a rough coat]
//!             + T(θi)·T(θo)/η² · f'(ωi', ωo')                         everything under the coat
//! f'(ωi', ωo') = (1 − Am − Ap)·R_l/π · 1/(1 − r_i·R_l)                pigmented layer (KM + Saunderson)
//!             + Am·R_m(ωi'·h')·D_m(h')·G/(4 cos θi' cos θo')          metallic flakes
//!             + Ap·R_p(ωi'·h')·D_p(h')·G/(4 cos θi' cos θo')          pearlescent flakes
//! ```
//!
//! with T = 1 − ρ the Fresnel power transmittance of the air–coat interface (paper Eq. 2 with its cosine
//! ratio corrected), R_l the Kubelka–Munk reflectance of the pigmented layer over the primer (Eq. 3
//! corrected), R_m, R_p the KM reflectance of the pigment above a flake of Fresnel reflectance ρ_m (Eq. 5
//! corrected) or thin-film reflectance ρ_p (Eqs. 6–8 corrected), D normalised Beckmann distributions and G
//! the Smith height-correlated masking-shadowing function. The alternative `Form::PaperEq1` evaluates Eq. (1)
//! as printed, for comparison only.
use super::{Brdf, Lobe, Term, TermKind};
use crate::colorimetry::weighting::Weighting;
use crate::optics::coat_albedo::{CoatAlbedo, OutOfTable, ALPHA_BREAKS, ETA_MAX, ETA_MIN};
use crate::optics::fresnel::{critical_cosine_complex, fr_conductor, fr_dielectric, fresnel_dielectric, refract_into};
use crate::optics::kubelka_munk::{self, Layer};
use crate::optics::microfacet::{Distribution, Microfacet, Shadowing};
use crate::optics::tabulated::{basis, dot, ChebTable};
use crate::optics::thin_film::{stack, FilmLayer};
use crate::quadrature::gauss_legendre;
use crate::registry::{self as reg, Param, Range};
use crate::spectrum::Sampling;
use crate::{Error, Result, Vec3};
use num_complex::Complex64;
use std::f64::consts::PI;

/// Largest number of spectral samples a paint accepts. It bounds the per-evaluation work (a pearlescent
/// paint evaluates a thin-film stack per sample and direction pair); recipes with more samples are refused.
pub const MAX_SAMPLES: usize = 128;

/// Gauss–Legendre order used for the diffuse Fresnel reflectance r_e (the integrand is smooth in cos θ on
/// [0, 1], so 64 nodes give it to rounding; checked against an independent Simpson rule in `tests/paint.rs`).
pub const DIFFUSE_FRESNEL_NODES: usize = 64;

/// Which reading of the paper's Eq. (1) is evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Form {
    /// The physically consistent reading (default): refraction into the coat, Fresnel transmittance in and
    /// out, radiance factor 1/η², energy-normalised lobes, Saunderson factor. Energy-conserving, reciprocal.
    Physical,
    /// Eq. (1) as printed: Cook–Torrance (1982) π normalisation, exterior directions, τ = T(θi) applied once,
    /// V-cavity G, R_l as a Lambertian R_l/π. Neither energy-conserving nor reciprocal; for comparison only.
    PaperEq1,
}

/// Where the light that a flake's covering pigment scatters goes (`docs/model.md` §Flake light through the
/// pigment). Only the physical form uses it; the paper-literal form keeps Eq. (5) as printed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FlakeLight {
    /// Physically split (default): the flake lobe carries ρ·τ(θi')·τ(θo'), the flake's reflectance
    /// attenuated by the unscattered (collimated) transmission of the pigment above it along the refracted
    /// paths in and out; the light the pigment scatters joins the diffuse body as a reciprocal diffuse term.
    Split,
    /// The paper's Eq. (5): the Kubelka–Munk reflectance R of the pigment over the flake (diffuse back-scatter
    /// included) inside the flake's narrow lobe.
    PaperEq5,
}

/// The clear coat: a non-absorbing resin over the pigmented layer.
#[derive(Clone, Debug, PartialEq)]
pub struct ClearCoat {
    /// Refractive index η of the resin (relative to air), 1.3–1.8.
    pub index: f64,
    /// Thickness in µm. Recorded only: a non-absorbing coat's thickness does not change the reading (the
    /// coat is far thicker than the coherence length of the instrument's light, so no interference either).
    pub thickness_um: f64,
    /// Surface roughness (Beckmann rms slope or GGX α); 0 = optically smooth.
    pub roughness: f64,
    pub distribution: Distribution,
}

/// One pigment of the pigmented layer: concentration and per-sample absorption and scattering.
#[derive(Clone, Debug, PartialEq)]
pub struct Pigment {
    pub name: String,
    pub concentration: f64,
    /// Absorption coefficient K per mm, one per spectral sample.
    pub k_per_mm: Vec<f64>,
    /// Scattering coefficient S per mm, one per spectral sample.
    pub s_per_mm: Vec<f64>,
}

/// The pigmented (base) layer over the primer.
#[derive(Clone, Debug, PartialEq)]
pub struct PigmentedLayer {
    /// Thickness X in mm.
    pub thickness_mm: f64,
    /// Primer reflectance Rg per spectral sample.
    pub primer_reflectance: Vec<f64>,
    pub pigments: Vec<Pigment>,
}

/// Metallic flakes embedded in the pigmented layer.
#[derive(Clone, Debug, PartialEq)]
pub struct MetallicFlakes {
    /// Complex index n + ik of the metal per spectral sample.
    pub n: Vec<f64>,
    pub k: Vec<f64>,
    /// Orientation spread: an angle σ (m = tan σ) or the Beckmann rms slope m itself.
    pub spread: Spread,
    /// Visible area ratio Am.
    pub area_ratio: f64,
    /// Mean depth X' of the visible flakes in mm (0 ≤ X' ≤ X).
    pub depth_mm: f64,
}

/// How a recipe gives the flake orientation spread (`docs/model.md` §Two readings of the flake spread).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Spread {
    /// `spread_deg`: an angle σ in degrees, read as the tilt whose tangent is the Beckmann rms slope, m = tan σ.
    Degrees(f64),
    /// `spread_slope`: the Cook–Torrance / Beckmann rms slope m itself (dimensionless).
    Slope(f64),
}

impl Spread {
    /// Largest accepted spread angle in degrees, and the slope it corresponds to (tan 60° = 1.732); the
    /// registry's ranges (`crate::registry::SPREAD_DEG_RANGE`, `SPREAD_SLOPE_RANGE`).
    pub const MAX_DEG: f64 = reg::SPREAD_DEG_RANGE.hi;
    pub const MAX_SLOPE: f64 = reg::SPREAD_SLOPE_RANGE.hi;

    /// The Beckmann rms slope m.
    pub fn slope(self) -> f64 {
        match self {
            Spread::Degrees(d) => spread_to_slope(d),
            Spread::Slope(m) => m,
        }
    }

    /// Check against the registry entries of the two forms.
    fn check(self, deg: &Param, slope: &Param) -> Result<()> {
        match self {
            Spread::Degrees(d) => check_range(deg, d),
            Spread::Slope(m) => check_range(slope, m),
        }
    }
}

/// Pearlescent flakes: TiO2 / mica / TiO2 platelets embedded in the resin.
#[derive(Clone, Debug, PartialEq)]
pub struct PearlescentFlakes {
    /// Orientation spread: an angle σ (m = tan σ) or the Beckmann rms slope m itself.
    pub spread: Spread,
    /// Visible area ratio Ap.
    pub area_ratio: f64,
    /// Mean depth X'' of the visible flakes in mm (0 ≤ X'' ≤ X).
    pub depth_mm: f64,
    /// TiO2 film thickness in nm (each of the two films).
    pub tio2_thickness_nm: f64,
    /// TiO2 refractive index (anatase ≈ 2.5, rutile ≈ 2.7).
    pub tio2_index: f64,
    /// Mica platelet thickness in nm (treated incoherently).
    pub mica_thickness_nm: f64,
    pub mica_index: f64,
}

/// Everything a paint is made of, as read from a recipe.
#[derive(Clone, Debug, PartialEq)]
pub struct PaintSpec {
    pub sampling: Sampling,
    pub coat: ClearCoat,
    pub layer: PigmentedLayer,
    pub metallic: Option<MetallicFlakes>,
    pub pearlescent: Option<PearlescentFlakes>,
    pub form: Form,
    /// How the flake light is split between the lobe and the diffuse body (physical form only).
    pub flake_light: FlakeLight,
    /// Apply the Saunderson multiple-internal-reflection factor 1/(1 − r_i R_l) to the body term.
    pub internal_reflection: bool,
}

/// Per-kind optics of a flake.
#[derive(Clone, Debug, PartialEq)]
enum FlakeOptics {
    /// Relative complex index (n + ik)/η_medium per sample.
    Metal(Vec<Complex64>),
    /// The film stack TiO2 / mica / TiO2, entered from and exited into resin of index `medium`.
    Pearl { layers: [FilmLayer; 3], medium: f64 },
}

/// A flake term, precomputed.
#[derive(Clone, Debug, PartialEq)]
struct FlakeTerm {
    label: &'static str,
    area: f64,
    facets: Microfacet,
    /// Spread below `Microfacet::SMOOTH_THRESHOLD`: evaluated as its delta limit.
    smooth: bool,
    /// KM operator of the pigment above the flake (thickness X' or X''), per sample.
    cover: Vec<Layer>,
    optics: FlakeOptics,
    /// R_m or R_p (paper Eq. 5) — or, for the split flake light, the bare flake reflectance ρ — per sample as a
    /// verified Chebyshev table over the local cosine ∈ [0, 1] (max deviation from the direct evaluation ≤
    /// `TABLE_TOLERANCE` at check points), or None when no table met it.
    table: Option<Vec<ChebTable>>,
    /// Split flake light: per sample, the optical depth ε·X' of the cover for collimated light, ε = (K + S)/2.
    depth: Vec<f64>,
    /// Split flake light: per sample, the diffuse part's weight R_d/(π(1 − τ̄)): R_d = KM cover over the
    /// flake's hemispherical reflectance, τ̄ = 2∫τ(μ)μ dμ. 0 where the cover does not scatter or absorb.
    diffuse: Vec<f64>,
    split: bool,
}

/// Largest accepted deviation of a flake-reflectance table from the direct evaluation (absolute, on a
/// reflectance ≤ 1): far below any tolerance a reading is asked for.
pub const TABLE_TOLERANCE: f64 = 1e-12;

/// The paint prepared for one weighted sum of its samples, Σ_j w_j f_j (the luminous row of its sampling:
/// what gloss, haze and DOI read; `Brdf::eval_batch_folded`). Everything that does not depend on direction is
/// summed over the samples once, here, so an evaluation does one sample's work where the per-sample path
/// does n (`docs/model.md` §Folded evaluation).
#[derive(Clone, Debug, PartialEq)]
struct Folded {
    /// The row w it was prepared for.
    weights: Vec<f64>,
    /// Σ_j w_j: the weight of the rough coat's grey lobe.
    coat: f64,
    /// Σ_j w_j·body_j.
    body: f64,
    /// One per flake term, in the order of `Paint::flakes`.
    flakes: Vec<FoldedFlake>,
    /// The second flake term's cover has the same optical depths as the first's (the same pigment at the same
    /// depth): the transmissions computed for the first serve the second.
    shared_depth: bool,
}

/// A flake term prepared for a weighted sum.
#[derive(Clone, Debug, PartialEq)]
struct FoldedFlake {
    /// Split light: w_j·(the diffuse weight of sample j).
    diffuse: Vec<f64>,
    /// The lobe's reflectance folded into one table, Σ_j w_j·T_j, when the per-sample factors in front of the
    /// tables do not depend on direction (light not split, or a grey cover: one τ for every sample).
    table: Option<ChebTable>,
    /// Otherwise the samples' tables on one grid: an evaluation sums their coefficients with the weights
    /// w_j·τ_j(θi')·τ_j(θo') and runs one Clenshaw recurrence (the interpolant is linear in its coefficients).
    grid: Option<Vec<ChebTable>>,
    /// Split light with a grey cover: every sample's τ is sample 0's.
    grey_cover: bool,
}

impl Folded {
    /// Prepare `paint` for the row `w` (n weights).
    fn new(paint: &Paint, w: &[f64]) -> Folded {
        let lambdas = &paint.spec.sampling.wavelengths_nm;
        let flakes = paint
            .flakes()
            .map(|fl| {
                let grey_cover = fl.depth.iter().all(|d| d.to_bits() == fl.depth[0].to_bits());
                let grid = fl.table.as_ref().and_then(|t| {
                    let pieces = t.iter().map(ChebTable::pieces).max().expect("one table per sample");
                    t.iter()
                        .enumerate()
                        .map(|(k, tk)| match tk.pieces() == pieces {
                            true => Some(tk.clone()),
                            false => ChebTable::fit_with_pieces(
                                |c| fl.reflectance_direct(k, c, lambdas[k]),
                                0.0,
                                1.0,
                                pieces,
                                TABLE_TOLERANCE,
                            ),
                        })
                        .collect::<Option<Vec<_>>>()
                });
                let constant = !fl.split || grey_cover;
                let table = grid.as_ref().filter(|_| constant).and_then(|g| ChebTable::combine(g, w));
                FoldedFlake {
                    diffuse: fl.diffuse.iter().zip(w).map(|(d, w)| w * d).collect(),
                    grid: if table.is_some() { None } else { grid },
                    table,
                    grey_cover,
                }
            })
            .collect();
        let shared_depth = match (&paint.metallic, &paint.pearlescent) {
            (Some(a), Some(b)) => {
                a.split && b.split && a.depth.iter().zip(&b.depth).all(|(x, y)| x.to_bits() == y.to_bits())
            }
            _ => false,
        };
        Folded {
            weights: w.to_vec(),
            coat: w.iter().sum(),
            body: paint.body.iter().zip(w).map(|(b, w)| w * b).sum(),
            flakes,
            shared_depth,
        }
    }
}

impl FlakeTerm {
    /// Flake reflectance ρ at the local cosine `cos_local` for sample `k` (before the pigment above it).
    #[inline]
    fn rho(&self, k: usize, cos_local: f64, wavelength_nm: f64) -> f64 {
        match &self.optics {
            FlakeOptics::Metal(eta) => fr_conductor(cos_local, eta[k]),
            FlakeOptics::Pearl { layers, medium } => {
                stack(*medium, layers, Complex64::new(*medium, 0.0), cos_local, wavelength_nm).r()
            }
        }
    }

    /// R_m or R_p: the KM reflectance of the pigment above the flake over the flake (Eqs. 5, 8 corrected),
    /// from the verified table when there is one.
    #[inline]
    fn reflectance(&self, k: usize, cos_local: f64, wavelength_nm: f64) -> f64 {
        match &self.table {
            Some(t) => t[k].eval(cos_local),
            None => self.reflectance_direct(k, cos_local, wavelength_nm),
        }
    }

    /// What the lobe carries per unit D·G/(4 cos cos), evaluated directly (no table): R_m or R_p (paper Eq. 5),
    /// or the bare flake reflectance ρ for the split flake light (the cover's attenuation is applied by the
    /// caller, it depends on both directions).
    fn reflectance_direct(&self, k: usize, cos_local: f64, wavelength_nm: f64) -> f64 {
        let rho = self.rho(k, cos_local, wavelength_nm).clamp(0.0, 1.0);
        if self.split {
            rho
        } else {
            self.cover[k].over(rho)
        }
    }

    /// Unscattered transmission τ = exp(−ε X'/μ) of the cover along an interior direction of cosine μ.
    #[inline]
    fn tau(&self, k: usize, mu: f64) -> f64 {
        if mu <= 0.0 {
            0.0
        } else {
            (-self.depth[k] / mu).exp()
        }
    }

    /// e = τ − 1 = expm1(−ε X'/μ) (−1 where μ ≤ 0, τ = 0 there): τ = 1 + e and 1 − τ = −e from one call.
    #[inline]
    fn expm1_tau(&self, k: usize, mu: f64) -> f64 {
        if mu <= 0.0 {
            -1.0
        } else {
            (-self.depth[k] / mu).exp_m1()
        }
    }

    /// 1 − τ without cancellation.
    #[inline]
    fn one_minus_tau(&self, k: usize, mu: f64) -> f64 {
        if mu <= 0.0 {
            1.0
        } else {
            -(-self.depth[k] / mu).exp_m1()
        }
    }

    /// The cosines in (0, 1) at which the flake reflectance ρ(μ) of sample `k` has a kink: the critical angles
    /// of total internal reflection (docs/model.md §Pearlescent flakes). Light in the resin of index η_r meets
    /// every layer of the stack at the same Snell invariant η_r sin θ, so a lossless layer of index n < η_r
    /// reflects totally below cos θc = √(1 − (n/η_r)²) (`optics::fresnel::critical_cosine`), and a metal whose
    /// relative index is real and below 1 likewise; an absorbing layer has no kink. Sorted, distinct.
    fn rho_kinks(&self, k: usize) -> Vec<f64> {
        let mut kinks: Vec<f64> = match &self.optics {
            FlakeOptics::Metal(eta) => critical_cosine_complex(eta[k]).into_iter().collect(),
            FlakeOptics::Pearl { layers, medium } => {
                layers.iter().filter_map(|l| critical_cosine_complex(l.n / *medium)).collect()
            }
        };
        kinks.retain(|&c| c > 0.0 && c < 1.0);
        kinks.sort_by(f64::total_cmp);
        kinks.dedup();
        kinks
    }

    /// Precompute the split flake light's per-sample constants (`depth`, `diffuse`).
    fn split_constants(&mut self, k_mix: &[f64], s_mix: &[f64], depth_mm: f64, wavelengths_nm: &[f64]) {
        let (x, w) = gauss_legendre(DIFFUSE_FRESNEL_NODES);
        let n = self.cover.len();
        self.depth = (0..n).map(|j| 0.5 * (k_mix[j] + s_mix[j]) * depth_mm).collect();
        self.diffuse = (0..n)
            .map(|j| {
                // ρ_d = 2∫ρ(μ)μ dμ (split at ρ's kinks) and 1 − τ̄ = 2∫(1 − τ(μ))μ dμ (smooth on [0, 1]), by
                // Gauss–Legendre in μ.
                let rho_d =
                    hemispherical_mean(|mu| self.rho(j, mu, wavelengths_nm[j]).clamp(0.0, 1.0), &self.rho_kinks(j));
                let mut one_minus_tau_bar = 0.0;
                for (&xi, &wi) in x.iter().zip(&w) {
                    let mu = 0.5 * (xi + 1.0);
                    one_minus_tau_bar += wi * mu * self.one_minus_tau(j, mu);
                }
                if one_minus_tau_bar <= 0.0 {
                    return 0.0;
                }
                self.cover[j].over(rho_d.clamp(0.0, 1.0)) / (PI * one_minus_tau_bar)
            })
            .collect();
    }

    /// Build the per-sample tables; all or none.
    fn tabulate(&mut self, wavelengths_nm: &[f64]) {
        let tables: Option<Vec<ChebTable>> = (0..self.cover.len())
            .map(|k| ChebTable::fit(|c| self.reflectance_direct(k, c, wavelengths_nm[k]), 0.0, 1.0, TABLE_TOLERANCE))
            .collect();
        self.table = tables;
    }
}

/// The paint BRDF.
#[derive(Clone, Debug)]
pub struct Paint {
    spec: PaintSpec,
    /// Weight of the body term 1 − Am − Ap.
    body_weight: f64,
    /// R_l per sample.
    r_l: Vec<f64>,
    /// (1 − Am − Ap)·R_l/π·S per sample, S the Saunderson factor (or 1).
    body: Vec<f64>,
    r_e: f64,
    r_i: f64,
    rough_coat: Option<Microfacet>,
    /// E(μ) and Ē of the rough coat's lobe (energy-exact coupling, `optics::coat_albedo`).
    coat_albedo: Option<CoatAlbedo>,
    metallic: Option<FlakeTerm>,
    pearlescent: Option<FlakeTerm>,
    /// Prepared for the luminous row of the sampling (None if the sampling has none).
    folded: Option<Folded>,
}

/// The hemispherical mean 2∫₀¹ f(μ) μ dμ of a function of the cosine that is smooth on [0, 1] except at the
/// cosines `kinks` (sorted, in (0, 1)), where it is continuous but its derivative is not.
///
/// Without kinks: the [`DIFFUSE_FRESNEL_NODES`]-point Gauss–Legendre rule on [0, 1] (the rule the smooth
/// integrands of this module use, to rounding). With kinks, a single rule across one converges only
/// algebraically (a Fresnel reflectance behaves like √(μ − μc) beside its critical cosine μc, and a 64-point
/// rule across it is off by ~10⁻³ for mica in a denser resin): the interval is cut at every kink and at the
/// midpoints between them, and each piece that ends on a kink is mapped by μ = μc ± h·s² (s ∈ [0, 1]), which
/// turns √(μ − μc) into the smooth h^½·s, so that each piece's rule again converges like a smooth integrand's
/// (docs/model.md §Pearlescent flakes).
pub fn hemispherical_mean(f: impl Fn(f64) -> f64, kinks: &[f64]) -> f64 {
    let (x, w) = gauss_legendre(DIFFUSE_FRESNEL_NODES);
    if kinks.is_empty() {
        let mut sum = 0.0;
        for (&xi, &wi) in x.iter().zip(&w) {
            let mu = 0.5 * (xi + 1.0);
            sum += wi * mu * f(mu);
        }
        return sum;
    }
    // Pieces (from, to) with `from` a kink: μ = from + (to − from)·s², from the kink towards the piece's
    // other end (which is 0, 1 or a midpoint between kinks).
    let mut pieces = Vec::with_capacity(2 * kinks.len());
    for (i, &c) in kinks.iter().enumerate() {
        let below = if i == 0 { 0.0 } else { 0.5 * (kinks[i - 1] + c) };
        let above = if i + 1 == kinks.len() { 1.0 } else { 0.5 * (c + kinks[i + 1]) };
        pieces.push((c, below));
        pieces.push((c, above));
    }
    let mut sum = 0.0;
    for (from, to) in pieces {
        let h = to - from;
        let mut piece = 0.0;
        for (&xi, &wi) in x.iter().zip(&w) {
            let s = 0.5 * (xi + 1.0);
            let mu = from + h * s * s;
            // dμ = 2h·s ds, and ds = wi/2 on [0, 1]: 2 f μ dμ = 2 f μ · h s wi.
            piece += wi * 2.0 * h.abs() * s * mu * f(mu);
        }
        sum += piece;
    }
    sum
}

/// Diffuse (hemispherical) reflectance of the air → coat interface for light incident from air,
/// r_e = ∫₀^{π/2} F(θ) 2 sin θ cos θ dθ = ∫₀¹ F(μ) 2μ dμ (Judd 1942; Stern 1964), by Gauss–Legendre.
pub fn diffuse_fresnel_reflectance(eta: f64) -> f64 {
    let (x, w) = gauss_legendre(DIFFUSE_FRESNEL_NODES);
    x.iter()
        .zip(&w)
        .map(|(&xi, &wi)| {
            let mu = 0.5 * (xi + 1.0);
            0.5 * wi * fr_dielectric(mu, eta) * 2.0 * mu
        })
        .sum()
}

/// Diffuse reflectance of the coat–air interface for diffuse light incident from inside the coat:
/// r_i = 1 − (1 − r_e)/η² (the exit cone carries 1/η² of the internal diffuse flux, and Fresnel
/// transmittance is the same both ways; Saunderson 1942, Stern 1964). For η = 1.5, r_i ≈ 0.596.
pub fn internal_diffuse_reflectance(eta: f64) -> f64 {
    1.0 - (1.0 - diffuse_fresnel_reflectance(eta)) / (eta * eta)
}

fn usage(msg: impl Into<String>) -> Error {
    Error::Usage(format!("paint: {}", msg.into()))
}

/// `v` against the range of registry entry `p`; the message names the entry's JSON Pointer.
fn check_range(p: &Param, v: f64) -> Result<()> {
    check_in(p.pointer, v, p.range())
}

fn check_in(what: &str, v: f64, r: Range) -> Result<()> {
    if r.contains(v) {
        Ok(())
    } else {
        Err(usage(format!("{what} = {v} must be a finite number {}", r.describe())))
    }
}

fn check_spectral(p: &Param, v: &[f64], n: usize) -> Result<()> {
    if v.len() != n {
        return Err(usage(format!("{} has {} values; the sampling has {n}", p.pointer, v.len())));
    }
    for (i, &x) in v.iter().enumerate() {
        check_in(&format!("{}/{i}", p.pointer), x, p.range())?;
    }
    Ok(())
}

/// Beckmann rms slope m = tan σ of a flake spread σ in degrees.
pub fn spread_to_slope(spread_deg: f64) -> f64 {
    spread_deg.to_radians().tan()
}

impl Paint {
    /// Validate `spec` and precompute everything that does not depend on direction.
    pub fn new(spec: PaintSpec) -> Result<Paint> {
        let n = spec.sampling.len();
        if n == 0 || n > MAX_SAMPLES {
            return Err(usage(format!("{n} spectral samples; a paint takes 1 to {MAX_SAMPLES}")));
        }
        // The ranges are the registry's (`crate::registry`), the same the recipe parser checks.
        let c = &spec.coat;
        check_range(&reg::COAT_INDEX, c.index)?;
        check_range(&reg::COAT_THICKNESS, c.thickness_um)?;
        check_range(&reg::COAT_ROUGHNESS, c.roughness)?;
        let l = &spec.layer;
        check_range(&reg::LAYER_THICKNESS, l.thickness_mm)?;
        check_spectral(&reg::LAYER_PRIMER, &l.primer_reflectance, n)?;
        for p in &l.pigments {
            check_range(&reg::PIGMENT_CONCENTRATION, p.concentration)?;
            check_spectral(&reg::PIGMENT_K, &p.k_per_mm, n)?;
            check_spectral(&reg::PIGMENT_S, &p.s_per_mm, n)?;
        }
        let am = spec.metallic.as_ref().map_or(0.0, |m| m.area_ratio);
        let ap = spec.pearlescent.as_ref().map_or(0.0, |p| p.area_ratio);
        let depth = |p: &Param, d: f64| check_in(p.pointer, d, Range::closed(0.0, l.thickness_mm));
        if let Some(m) = &spec.metallic {
            check_spectral(&reg::METALLIC_N, &m.n, n)?;
            check_spectral(&reg::METALLIC_K, &m.k, n)?;
            m.spread.check(&reg::METALLIC_SPREAD, &reg::METALLIC_SPREAD_SLOPE)?;
            check_range(&reg::METALLIC_AREA, m.area_ratio)?;
            depth(&reg::METALLIC_DEPTH, m.depth_mm)?;
        }
        if let Some(p) = &spec.pearlescent {
            p.spread.check(&reg::PEARL_SPREAD, &reg::PEARL_SPREAD_SLOPE)?;
            check_range(&reg::PEARL_AREA, p.area_ratio)?;
            depth(&reg::PEARL_DEPTH, p.depth_mm)?;
            check_range(&reg::PEARL_TIO2_THICKNESS, p.tio2_thickness_nm)?;
            check_range(&reg::PEARL_TIO2_INDEX, p.tio2_index)?;
            check_range(&reg::PEARL_MICA_THICKNESS, p.mica_thickness_nm)?;
            check_range(&reg::PEARL_MICA_INDEX, p.mica_index)?;
        }
        if am + ap > 1.0 {
            return Err(usage(format!("area ratios Am + Ap = {} exceed 1", am + ap)));
        }

        let eta = c.index;
        // Pigmented layer: Duncan mixing, then the KM layer over the primer (Eq. 3 corrected).
        let mut k_mix = vec![0.0; n];
        let mut s_mix = vec![0.0; n];
        for j in 0..n {
            let (k, s) = kubelka_munk::mix(l.pigments.iter().map(|p| (p.concentration, p.k_per_mm[j], p.s_per_mm[j])));
            k_mix[j] = k;
            s_mix[j] = s;
        }
        let r_l: Vec<f64> = (0..n)
            .map(|j| kubelka_munk::layer(k_mix[j], s_mix[j], l.thickness_mm).over(l.primer_reflectance[j]))
            .collect();
        let rough_coat =
            (c.roughness >= Microfacet::SMOOTH_THRESHOLD).then(|| Microfacet::new(c.distribution, c.roughness));
        // A rough coat lets in 1 − E(θ) and reflects back inside r_i = 1 − (1 − Ē)/η² (Kelemen &
        // Szirmay-Kalos 2001); a smooth one T(θ) = 1 − F(θ) and r_i = 1 − (1 − r_e)/η², its limit.
        // E comes from the shipped table (`optics::coat_albedo`), which covers roughness [10⁻⁷, 1] and the
        // whole index range; a rough coat outside it is refused, naming the field.
        let coat_albedo = match &rough_coat {
            Some(mf) => Some(CoatAlbedo::new(mf, eta).map_err(|why| {
                let (lo, hi) = (ALPHA_BREAKS[0], ALPHA_BREAKS[ALPHA_BREAKS.len() - 1]);
                match why {
                    OutOfTable::Roughness => usage(format!(
                        "{} = {}: a rough clear coat's roughness must lie in [{lo}, {hi}], the range of its \
                         directional-albedo table (docs/model.md §Energy-exact rough clear coat); below {} \
                         the coat is smooth",
                        reg::COAT_ROUGHNESS.pointer,
                        c.roughness,
                        Microfacet::SMOOTH_THRESHOLD
                    )),
                    OutOfTable::Index => usage(format!(
                        "{} = {}: a rough clear coat's index must lie in [{ETA_MIN}, {ETA_MAX}], the range of its \
                         directional-albedo table",
                        reg::COAT_INDEX.pointer,
                        c.index
                    )),
                }
            })?),
            None => None,
        };
        let r_e = coat_albedo.as_ref().map_or_else(|| diffuse_fresnel_reflectance(eta), |a| a.mean);
        let r_i = 1.0 - (1.0 - r_e) / (eta * eta);
        let body_weight = (1.0 - am - ap).max(0.0);
        let use_saunderson = spec.internal_reflection && spec.form == Form::Physical;
        let body: Vec<f64> = r_l
            .iter()
            .map(|&r| {
                let s = if use_saunderson { 1.0 / (1.0 - r_i * r) } else { 1.0 };
                body_weight * r / PI * s
            })
            .collect();
        let cover =
            |depth: f64| -> Vec<Layer> { (0..n).map(|j| kubelka_munk::layer(k_mix[j], s_mix[j], depth)).collect() };
        let split = spec.form == Form::Physical && spec.flake_light == FlakeLight::Split;
        let flake = |label, spread: Spread, area, depth, optics| {
            let facets = Microfacet::new(Distribution::Beckmann, spread.slope());
            let mut term = FlakeTerm {
                label,
                area,
                facets,
                smooth: facets.effectively_smooth(),
                cover: cover(depth),
                optics,
                table: None,
                depth: vec![0.0; n],
                diffuse: vec![0.0; n],
                split,
            };
            term.tabulate(&spec.sampling.wavelengths_nm);
            if split {
                term.split_constants(&k_mix, &s_mix, depth, &spec.sampling.wavelengths_nm);
            }
            term
        };
        let metallic = spec.metallic.as_ref().filter(|m| m.area_ratio > 0.0).map(|m| {
            let rel = (0..n).map(|j| Complex64::new(m.n[j], m.k[j]) / eta).collect();
            flake("metallic flakes", m.spread, m.area_ratio, m.depth_mm, FlakeOptics::Metal(rel))
        });
        let pearlescent = spec.pearlescent.as_ref().filter(|p| p.area_ratio > 0.0).map(|p| {
            let tio2 =
                FilmLayer { n: Complex64::new(p.tio2_index, 0.0), thickness_nm: p.tio2_thickness_nm, coherent: true };
            let mica =
                FilmLayer { n: Complex64::new(p.mica_index, 0.0), thickness_nm: p.mica_thickness_nm, coherent: false };
            let optics = FlakeOptics::Pearl { layers: [tio2, mica, tio2], medium: eta };
            flake("pearlescent flakes", p.spread, p.area_ratio, p.depth_mm, optics)
        });
        let mut paint = Paint {
            spec,
            body_weight,
            r_l,
            body,
            r_e,
            r_i,
            rough_coat,
            coat_albedo,
            metallic,
            pearlescent,
            folded: None,
        };
        let luminous = Weighting::luminous(&paint.spec.sampling).ok().and_then(|w| w.rows.into_iter().next());
        paint.folded = luminous.map(|w| Folded::new(&paint, &w));
        Ok(paint)
    }

    pub fn spec(&self) -> &PaintSpec {
        &self.spec
    }

    /// R_l per sample: the KM reflectance of the pigmented layer over the primer.
    pub fn pigmented_reflectance(&self) -> &[f64] {
        &self.r_l
    }

    /// r_e, the diffuse reflectance of the air–coat interface from outside.
    pub fn external_diffuse_reflectance(&self) -> f64 {
        self.r_e
    }

    /// r_i, the diffuse reflectance of the coat–air interface from inside.
    pub fn internal_diffuse_reflectance(&self) -> f64 {
        self.r_i
    }

    /// Power that crosses the coat at exterior cosine μ (either way): 1 − E(μ) for a rough coat, the
    /// Fresnel transmittance T(μ) for a smooth one.
    fn coat_transmittance(&self, mu: f64) -> f64 {
        match &self.coat_albedo {
            Some(a) => 1.0 - a.at(mu),
            None => fresnel_dielectric(mu.min(1.0), self.spec.coat.index).t(),
        }
    }

    fn flakes(&self) -> impl Iterator<Item = &FlakeTerm> {
        self.metallic.iter().chain(self.pearlescent.iter())
    }

    /// Σ_j w_j f_j(ωi, ωo) for the prepared row: the terms of [`Brdf::eval`] with the same formulas, summed
    /// over the samples once where they do not depend on direction (`docs/model.md` §Folded evaluation). It
    /// equals Σ_j w_j·eval_j to rounding (the summation order differs; `tests/paint.rs` bounds the difference).
    fn eval_folded(&self, fo: &Folded, wi: Vec3, wo: Vec3) -> f64 {
        if wi.z.is_nan() || wo.z.is_nan() || wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let eta = self.spec.coat.index;
        let mut coat = 0.0;
        if let Some(mf) = &self.rough_coat {
            let h = (wi + wo).normalize();
            let v = fr_dielectric(wi.dot(h).clamp(0.0, 1.0), eta)
                * mf.d(h)
                * mf.g(wi, wo, h, Shadowing::SmithHeightCorrelated)
                / (4.0 * wi.z * wo.z);
            if v.is_finite() && v > 0.0 {
                coat = v * fo.coat;
            }
        }
        let flakes = [self.metallic.as_ref(), self.pearlescent.as_ref()];
        let mut folded = fo.flakes.iter();
        let terms: [Option<(&FlakeTerm, &FoldedFlake)>; 2] =
            flakes.map(|f| f.map(|f| (f, folded.next().expect("one folded term per flake term"))));
        match self.spec.form {
            Form::Physical => {
                let (Some(wi_in), Some(wo_in)) = (refract_into(wi, eta), refract_into(wo, eta)) else {
                    return coat;
                };
                let (t_i, t_o) = (self.coat_transmittance(wi.z), self.coat_transmittance(wo.z));
                let factor = t_i * t_o / (eta * eta);
                let h = (wi_in + wo_in).normalize();
                let cos_local = wi_in.dot(h).clamp(0.0, 1.0);
                let (mu_i, mu_o) = (wi_in.z, wo_in.z);
                let geo = |fl: &FlakeTerm| -> f64 {
                    if fl.smooth {
                        return 0.0;
                    }
                    let g = fl.facets.d(h) * fl.facets.g(wi_in, wo_in, h, Shadowing::SmithHeightCorrelated)
                        / (4.0 * wi_in.z * wo_in.z);
                    if g.is_finite() && g > 0.0 {
                        g
                    } else {
                        0.0
                    }
                };
                let mut sum = fo.body;
                // Per-sample sums of the flake terms whose factors depend on direction and sample (split light
                // under a coloured cover): the diffuse part Σ w_j d_j (1 − τ_i)(1 − τ_o) and the lobe's
                // Σ w_j τ_i τ_o R_j. With τ = 1 + e and e = expm1(−ε_j X'/μ), 1 − τ = −e: two expm1 per
                // sample and cover, shared by the two flake terms when their covers have the same depths. Each
                // R_j is one dot product of its piece's coefficients with the Chebyshev basis at cos_local,
                // computed once for both terms when their tables share a grid.
                let mut diffuse = [0.0; 2];
                let mut lobe_sum = [0.0; 2];
                let mut lobe = [0.0; 2];
                let mut located = [(0usize, 0.0); 2];
                let mut bases = [[0.0; crate::optics::tabulated::N]; 2];
                let mut have_basis = false;
                for (f, t) in terms.iter().enumerate() {
                    if let Some((fl, ff)) = t {
                        lobe[f] = geo(fl);
                        if let Some(g) = ff.grid.as_deref().or(ff.table.as_ref().map(std::slice::from_ref)) {
                            located[f] = g[0].locate(cos_local);
                            // The basis depends on t alone: the second term reuses the first's at the same t.
                            bases[f] = if f == 1 && have_basis && located[1].1.to_bits() == located[0].1.to_bits() {
                                bases[0]
                            } else {
                                basis(located[f].1)
                            };
                            have_basis = true;
                        }
                    }
                }
                let joint = fo.shared_depth && terms[0].is_some_and(|(_, ff)| !ff.grey_cover);
                const TERMS: [usize; 2] = [0, 1];
                for f in 0..2 {
                    let Some((fl, ff)) = terms[f] else { continue };
                    if !fl.split || (joint && f == 1) {
                        continue; // not split (no per-sample factor), or summed with term 0
                    }
                    if ff.grey_cover {
                        let (ei, eo) = (fl.expm1_tau(0, mu_i), fl.expm1_tau(0, mu_o));
                        diffuse[f] = ei * eo * ff.diffuse.iter().sum::<f64>();
                        if lobe[f] > 0.0 {
                            lobe_sum[f] = (1.0 + ei) * (1.0 + eo) * self.unattenuated(fl, ff, fo, cos_local, &bases[f]);
                        }
                        continue;
                    }
                    let members: &[usize] = if joint { &TERMS } else { std::slice::from_ref(&TERMS[f]) };
                    for (j, &w) in fo.weights.iter().enumerate() {
                        let (ei, eo) = (fl.expm1_tau(j, mu_i), fl.expm1_tau(j, mu_o));
                        let att = w * (1.0 + ei) * (1.0 + eo);
                        for &m in members {
                            let Some((mfl, mff)) = terms[m] else { continue };
                            diffuse[m] += mff.diffuse[j] * (ei * eo);
                            if lobe[m] > 0.0 {
                                let r = match &mff.grid {
                                    Some(g) => dot(g[j].piece(located[m].0), &bases[m]),
                                    None => mfl.reflectance_direct(j, cos_local, self.lambda(j)),
                                };
                                lobe_sum[m] += att * r;
                            }
                        }
                    }
                }
                for (f, t) in terms.iter().enumerate() {
                    let Some((fl, ff)) = t else { continue };
                    sum += fl.area * diffuse[f];
                    if lobe[f] <= 0.0 {
                        continue;
                    }
                    let r = if fl.split { lobe_sum[f] } else { self.unattenuated(fl, ff, fo, cos_local, &bases[f]) };
                    sum += fl.area * lobe[f] * r;
                }
                coat + factor * sum
            }
            Form::PaperEq1 => {
                // Eq. (1) as printed: the smooth-interface transmittance on the way in only.
                let t_i = fresnel_dielectric(wi.z.min(1.0), eta).t();
                let h = (wi + wo).normalize();
                let cos_local = wi.dot(h).clamp(0.0, 1.0);
                let mut sum = fo.body;
                for (fl, ff) in terms.iter().flatten() {
                    if fl.smooth {
                        continue;
                    }
                    let d_ct = PI * fl.facets.d(h);
                    let geo = d_ct * fl.facets.g(wi, wo, h, Shadowing::VCavity) / (PI * wi.z * wo.z);
                    if !geo.is_finite() || geo <= 0.0 {
                        continue;
                    }
                    let b = ff.table.as_ref().map(|t| basis(t.locate(cos_local).1)).unwrap_or_default();
                    sum += fl.area * geo * self.unattenuated(fl, ff, fo, cos_local, &b);
                }
                coat + t_i * sum
            }
        }
    }

    /// Σ_j w_j R_j(cos_local) of a flake whose lobe has no per-sample factor in front of its tables (`b`: the
    /// Chebyshev basis at cos_local's position in the folded table's piece).
    fn unattenuated(
        &self,
        fl: &FlakeTerm,
        ff: &FoldedFlake,
        fo: &Folded,
        cos_local: f64,
        b: &[f64; crate::optics::tabulated::N],
    ) -> f64 {
        match &ff.table {
            Some(t) => dot(t.piece(t.locate(cos_local).0), b),
            None => fo.weights.iter().enumerate().map(|(j, w)| w * fl.reflectance(j, cos_local, self.lambda(j))).sum(),
        }
    }

    #[inline]
    fn lambda(&self, j: usize) -> f64 {
        self.spec.sampling.wavelengths_nm[j]
    }
}

impl Brdf for Paint {
    fn sampling(&self) -> &Sampling {
        &self.spec.sampling
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        let n = self.spec.sampling.len();
        let out = &mut out[..n];
        out.fill(0.0);
        if wi.z.is_nan() || wo.z.is_nan() || wi.z <= 0.0 || wo.z <= 0.0 {
            return;
        }
        let eta = self.spec.coat.index;
        let lambdas = &self.spec.sampling.wavelengths_nm;
        // Rough clear coat: a microfacet reflection lobe on the air side (medium 1).
        if let Some(mf) = &self.rough_coat {
            let h = (wi + wo).normalize();
            let v = fr_dielectric(wi.dot(h).clamp(0.0, 1.0), eta)
                * mf.d(h)
                * mf.g(wi, wo, h, Shadowing::SmithHeightCorrelated)
                / (4.0 * wi.z * wo.z);
            if v.is_finite() && v > 0.0 {
                out.iter_mut().for_each(|o| *o += v);
            }
        }
        match self.spec.form {
            Form::Physical => {
                let (Some(wi_in), Some(wo_in)) = (refract_into(wi, eta), refract_into(wo, eta)) else {
                    return;
                };
                let (t_i, t_o) = (self.coat_transmittance(wi.z), self.coat_transmittance(wo.z));
                let factor = t_i * t_o / (eta * eta);
                for (o, b) in out.iter_mut().zip(&self.body) {
                    *o += factor * b;
                }
                let h = (wi_in + wo_in).normalize();
                let cos_local = wi_in.dot(h).clamp(0.0, 1.0);
                for fl in self.flakes() {
                    if fl.split {
                        // The light the cover scatters: a reciprocal diffuse term whose interior albedo is
                        // A·R_d·(1 − τ(θi')) (docs/model.md §Flake light through the pigment).
                        let w = factor * fl.area;
                        for (k, o) in out.iter_mut().enumerate() {
                            *o += w * fl.diffuse[k] * fl.one_minus_tau(k, wi_in.z) * fl.one_minus_tau(k, wo_in.z);
                        }
                    }
                    if fl.smooth {
                        continue;
                    }
                    let geo = fl.facets.d(h) * fl.facets.g(wi_in, wo_in, h, Shadowing::SmithHeightCorrelated)
                        / (4.0 * wi_in.z * wo_in.z);
                    if !geo.is_finite() || geo <= 0.0 {
                        continue;
                    }
                    let w = factor * fl.area * geo;
                    for (k, o) in out.iter_mut().enumerate() {
                        let att = if fl.split { fl.tau(k, wi_in.z) * fl.tau(k, wo_in.z) } else { 1.0 };
                        *o += w * att * fl.reflectance(k, cos_local, lambdas[k]);
                    }
                }
            }
            Form::PaperEq1 => {
                // Eq. (1) as printed: the smooth-interface transmittance on the way in only.
                let t_i = fresnel_dielectric(wi.z.min(1.0), eta).t();
                let tau = t_i;
                for (o, b) in out.iter_mut().zip(&self.body) {
                    *o += tau * b;
                }
                let h = (wi + wo).normalize();
                let cos_local = wi.dot(h).clamp(0.0, 1.0);
                for fl in self.flakes().filter(|f| !f.smooth) {
                    // Cook–Torrance 1982: D_CT = π·D (their Beckmann has no 1/π), divided by π cos θi cos θo.
                    let d_ct = PI * fl.facets.d(h);
                    let geo = d_ct * fl.facets.g(wi, wo, h, Shadowing::VCavity) / (PI * wi.z * wo.z);
                    if !geo.is_finite() || geo <= 0.0 {
                        continue;
                    }
                    let w = tau * fl.area * geo;
                    for (k, o) in out.iter_mut().enumerate() {
                        *o += w * fl.reflectance(k, cos_local, lambdas[k]);
                    }
                }
            }
        }
    }

    fn folds(&self, w: &[f64]) -> bool {
        self.folded.as_ref().is_some_and(|f| f.weights == w)
    }

    fn eval_batch_folded(&self, w: &[f64], wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) -> bool {
        let Some(fo) = self.folded.as_ref().filter(|f| f.weights == w) else {
            return false;
        };
        for ((a, b), o) in wi.iter().zip(wo).zip(out.iter_mut()) {
            *o = self.eval_folded(fo, *a, *b);
        }
        true
    }

    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        let smooth_flakes = self.flakes().any(|f| f.smooth);
        if self.rough_coat.is_some() && !smooth_flakes {
            return false;
        }
        let n = self.spec.sampling.len();
        let out = &mut out[..n];
        out.fill(0.0);
        if wi.z.is_nan() || wi.z <= 0.0 {
            return true;
        }
        let eta = self.spec.coat.index;
        let cos_i = wi.z.min(1.0);
        if self.rough_coat.is_none() {
            let rho = fr_dielectric(cos_i, eta);
            out.iter_mut().for_each(|o| *o = rho);
        }
        let lambdas = &self.spec.sampling.wavelengths_nm;
        let t_i = match self.spec.form {
            Form::Physical => self.coat_transmittance(cos_i),
            Form::PaperEq1 => fresnel_dielectric(cos_i, eta).t(),
        };
        for fl in self.flakes().filter(|f| f.smooth) {
            // Mirror geometry: h = n, θo = θi. Physical: interior delta A·R·δ(ωo' − mirror ωi')/cos θo' maps
            // to the exterior delta with weight T(θi)·T(θo)·A·R (docs/model.md §Delta limit of the flakes).
            // Paper Eq. 1: A·R·D_CT·G/(π cos θi cos θo) → 4·τ·A·R (G_V-cavity = 1 at h = n).
            let (w, cos_local) = match self.spec.form {
                Form::Physical => match refract_into(wi, eta) {
                    Some(w_in) => (t_i * t_i * fl.area, w_in.z.min(1.0)),
                    None => continue,
                },
                Form::PaperEq1 => (4.0 * t_i * fl.area, cos_i),
            };
            for (k, o) in out.iter_mut().enumerate() {
                // Split flake light: the mirror path goes in and out at θi', attenuated τ(θi')² by the cover.
                let att = if fl.split { fl.tau(k, cos_local).powi(2) } else { 1.0 };
                *o += w * att * fl.reflectance(k, cos_local, lambdas[k]);
            }
        }
        true
    }

    fn terms(&self) -> Vec<Term> {
        let mut t = Vec::new();
        match &self.rough_coat {
            None => t.push(Term { label: "clear coat (Fresnel, delta)".into(), kind: TermKind::Delta }),
            Some(mf) => t.push(Term {
                label: "clear coat (rough, microfacet)".into(),
                kind: TermKind::Lobe(Lobe::of_facets(mf, 1.0, "clear coat".into())),
            }),
        }
        if self.body_weight > 0.0 {
            t.push(Term { label: "pigmented layer (Kubelka–Munk, diffuse)".into(), kind: TermKind::Diffuse });
        }
        let medium = match self.spec.form {
            Form::Physical => self.spec.coat.index,
            Form::PaperEq1 => 1.0,
        };
        for fl in self.flakes().filter(|f| f.split && f.diffuse.iter().any(|&d| d > 0.0)) {
            t.push(Term {
                label: format!("{}, light scattered by the pigment above them (diffuse)", fl.label),
                kind: TermKind::Diffuse,
            });
        }
        for fl in self.flakes() {
            let kind = if fl.smooth {
                TermKind::Delta
            } else {
                TermKind::Lobe(Lobe {
                    slope_width: fl.facets.alpha,
                    medium_eta: medium,
                    label: fl.label.into(),
                    tail: super::Tail::Gaussian,
                })
            };
            t.push(Term { label: fl.label.into(), kind });
        }
        t
    }

    /// Smooth in the physical form under a smooth (delta) coat: Fresnel T(θ) of the air → coat interface
    /// (η ≥ 1.3, so refraction into the coat never meets total internal reflection and ωi', ωo' are analytic
    /// in ωi, ωo over the whole upper hemisphere: the interior critical angle bounds which interior directions
    /// are reached, it is no cutoff in the exterior directions the instrument integrates over), the
    /// Kubelka–Munk body (a constant), the split light's τ = exp(−εX'/μ') (μ' ≥ √(1 − 1/η²)), and the flake
    /// lobes' Beckmann D with the Smith height-correlated G (erfc, no min). The flake reflectances are read
    /// from piecewise Chebyshev tables of smooth functions verified within `TABLE_TOLERANCE` (10⁻¹²) of the
    /// direct evaluation, so a seam is a jump of at most ~2·10⁻¹², far below the tolerances a reading is asked
    /// for. Not smooth: a rough coat (E(μ) from a table held constant below μ₀, measured dishonest when
    /// checked, `docs/accuracy.md` §5.1) and the paper's Eq. (1) form (V-cavity G, a min()).
    ///
    /// Nor is a flake whose reflectance ρ kinks at a critical angle of total internal reflection (mica below
    /// the resin's index, `FlakeTerm::rho_kinks`): its table fit fails on the kink, and the direct ρ the lobe
    /// then evaluates is not smooth at the local cosine μc, which is no [`Kink`] of the exterior directions.
    fn smooth(&self) -> bool {
        self.spec.form == Form::Physical
            && self.rough_coat.is_none()
            && self.flakes().all(|f| (0..f.cover.len()).all(|k| f.rho_kinks(k).is_empty()))
    }

    /// The rough coat's E(μ) (`optics::coat_albedo`) changes Chebyshev piece at its μ breaks and is held at
    /// E(μ₀) below μ₀: the coat transmittance 1 − E(μ) of both directions seams there.
    fn seams(&self) -> Vec<f64> {
        if self.coat_albedo.is_none() {
            return Vec::new();
        }
        crate::optics::coat_albedo::BREAKS.iter().copied().filter(|&c| c > 0.0 && c < 1.0).collect()
    }

    fn is_reciprocal(&self) -> bool {
        // Physical: T(θi)T(θo) symmetric, f' symmetric (h' and ωi'·h' = ωo'·h' are). Paper Eq. 1 applies
        // τ(θi) once, which breaks the symmetry whenever anything lies under the coat.
        match self.spec.form {
            Form::Physical => true,
            Form::PaperEq1 => self.body_weight == 0.0 && self.metallic.is_none() && self.pearlescent.is_none(),
        }
    }

    fn describe(&self) -> String {
        let s = &self.spec;
        let form = match s.form {
            Form::Physical => "physical form",
            Form::PaperEq1 => "paper Eq. 1 as printed",
        };
        let coat = match &self.rough_coat {
            None => format!("smooth coat η = {}", s.coat.index),
            Some(mf) => format!(
                "rough coat η = {} ({:?} {}; energy-exact coupling, directional albedo from the shipped table)",
                s.coat.index, mf.distribution, mf.alpha
            ),
        };
        let mut d = format!(
            "paint (Ďurikovič & Ágošton 2007, {form}): {coat}, KM layer X = {} mm with {} pigment(s)",
            s.layer.thickness_mm,
            s.layer.pigments.len()
        );
        if s.internal_reflection && s.form == Form::Physical {
            d.push_str(&format!(", Saunderson r_i = {:.4}", self.r_i));
        }
        if s.form == Form::Physical && self.flakes().next().is_some() {
            d.push_str(match s.flake_light {
                FlakeLight::Split => ", flake light split (lobe × cover transmission, scattered part diffuse)",
                FlakeLight::PaperEq5 => ", flake light as the paper's Eq. 5 (cover reflectance in the lobe)",
            });
        }
        for fl in self.flakes() {
            let table = match &fl.table {
                Some(t) => format!(
                    ", reflectance tabulated ({} pieces, max deviation {:.0e})",
                    t[0].pieces(),
                    t.iter().map(|x| x.max_error).fold(0.0, f64::max)
                ),
                None => String::new(),
            };
            d.push_str(&format!(
                ", {} A = {} m = {:.3e}{}{table}",
                fl.label,
                fl.area,
                fl.facets.alpha,
                if fl.smooth { " (delta)" } else { "" }
            ));
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::fresnel::critical_cosine;

    /// Inside a coat of index η, the hemispherical reflectance of the coat–air interface is
    /// r_i = 1 − (1 − r_e)/η² (Stern 1964; r_e from the smooth outside rule): an independent closed form of
    /// 2∫F(μ, 1/η)μ dμ, whose integrand kinks at the critical cosine.
    #[test]
    fn the_kinked_internal_reflectance_meets_stern_s_closed_form_to_rounding() {
        for eta in [1.3, 1.5, 1.8, 2.4] {
            let closed = internal_diffuse_reflectance(eta);
            let mu_c = critical_cosine(1.0 / eta).unwrap();
            let split = hemispherical_mean(|mu| fr_dielectric(mu, 1.0 / eta), &[mu_c]);
            assert!((split - closed).abs() < 2e-15, "η = {eta}: split {split} vs closed form {closed}");
            // The rule across the kink is not good enough: the test would fail without the split.
            let across = hemispherical_mean(|mu| fr_dielectric(mu, 1.0 / eta), &[]);
            assert!((across - closed).abs() > 1e-7, "η = {eta}: the unsplit rule is already exact?");
        }
    }

    /// The pearl flake's ρ_d for mica (1.55) below the resin (1.8): the split rule against an adaptive
    /// Gauss–Kronrod integral with the kink as a break point, to 1e-13.
    #[test]
    fn the_pearl_flake_s_hemispherical_reflectance_is_right_below_the_resin_index() {
        let medium = 1.8;
        let tio2 = FilmLayer { n: Complex64::new(2.5, 0.0), thickness_nm: 60.0, coherent: true };
        let mica = FilmLayer { n: Complex64::new(1.55, 0.0), thickness_nm: 400.0, coherent: false };
        let layers = [tio2, mica, tio2];
        for wavelength in [450.0, 550.0, 650.0] {
            let rho = |mu: f64| stack(medium, &layers, Complex64::new(medium, 0.0), mu, wavelength).r().clamp(0.0, 1.0);
            let mu_c = critical_cosine(1.55 / medium).unwrap();
            let mut f = |mu: f64, out: &mut [f64]| out[0] = 2.0 * mu * rho(mu);
            let (reference, err) =
                crate::quadrature::gauss_kronrod_adaptive(&mut f, &[0.0, mu_c, 1.0], 1, 1, 1e-15, 4000);
            assert!(err < 1e-13, "reference error {err}");
            let split = hemispherical_mean(rho, &[mu_c]);
            assert!((split - reference[0]).abs() < 1e-13, "{wavelength} nm: {split} vs {}", reference[0]);
            let across = hemispherical_mean(rho, &[]);
            eprintln!("{wavelength} nm: ρ_d {split:.15}, the rule across the kink is off by {:.2e}", across - split);
            assert!((across - split).abs() > 1e-6, "{wavelength} nm: the unsplit rule is already exact?");
        }
    }
}
