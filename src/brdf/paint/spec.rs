//! What a paint is made of, as read from a recipe: [`PaintSpec`] and its parts (the clear coat, the pigmented
//! layer and its pigments, the two kinds of flakes and their [`Spread`]), the [`Form`] and [`FlakeLight`]
//! readings of the paper, and the range checks of the registry's entries that `Paint::new` runs on them.
use crate::optics::microfacet::Distribution;
use crate::registry::{Param, Range};
use crate::spectrum::Sampling;
use crate::{Error, Result};

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
    /// The Beckmann rms slope m.
    pub(crate) fn slope(self) -> f64 {
        match self {
            Spread::Degrees(d) => spread_to_slope(d),
            Spread::Slope(m) => m,
        }
    }

    /// Check against the registry entries of the two forms.
    pub(super) fn check(self, deg: &Param, slope: &Param) -> Result<()> {
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

pub(super) fn usage(msg: impl Into<String>) -> Error {
    Error::Usage(format!("paint: {}", msg.into()))
}

/// `v` against the range of registry entry `p`; the message names the entry's JSON Pointer.
pub(super) fn check_range(p: &Param, v: f64) -> Result<()> {
    check_in(p.pointer, v, p.range())
}

pub(super) fn check_in(what: &str, v: f64, r: Range) -> Result<()> {
    if r.contains(v) {
        Ok(())
    } else {
        Err(usage(format!("{what} = {v} must be a finite number {}", r.describe())))
    }
}

pub(super) fn check_spectral(p: &Param, v: &[f64], n: usize) -> Result<()> {
    if v.len() != n {
        return Err(usage(format!("{} has {} values; the sampling has {n}", p.pointer, v.len())));
    }
    for (i, &x) in v.iter().enumerate() {
        check_in(&format!("{}/{i}", p.pointer), x, p.range())?;
    }
    Ok(())
}

/// Beckmann rms slope m = tan σ of a flake spread σ in degrees.
pub(crate) fn spread_to_slope(spread_deg: f64) -> f64 {
    spread_deg.to_radians().tan()
}
