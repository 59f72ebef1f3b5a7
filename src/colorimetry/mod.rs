//! Colorimetry: tristimulus values X, Y, Z of a reflectance per CIE 15:2004 / ASTM E308, CIELAB and CIEDE2000.
//!
//! Why it exists: the paint model computes a spectrum, and coatings QC reads colour (CIELAB at several
//! aspecular angles, or on a d/8 sphere) beside gloss. This module is pure colorimetry, independent of the
//! instrument: it turns a material's spectral samples into *weights*, one row per tristimulus value, so that a
//! colour reading is a linear functional of the per-sample fluxes (the same way the luminous weights of
//! `spectrum.rs` make a gloss reading one), and it turns X, Y, Z into L*, a*, b*, C*ab, hab and ΔE00.
//!
//! **Method** (stated once, used everywhere; `docs/colour.md`):
//! * summation at 1 nm over 360–780 nm (the common range of the CIE 15:2004 Table T.1 illuminants and the CMFs),
//!   X = k Σ_λ S(λ) x̄(λ) R(λ) Δλ with Δλ = 1 nm (CIE 15:2004 §7.1, "numerical summation at 1 nm"; ASTM E308's
//!   1 nm method), and likewise Y, Z;
//! * k = 100 / Σ_λ S(λ) ȳ(λ) Δλ, so that the perfect reflecting diffuser has Y = 100;
//! * the colour-matching functions are tabulated at 1 nm (exact); the illuminants at 5 nm, linearly interpolated to
//!   1 nm;
//! * the material's reflectance R(λ) is linearly interpolated between its samples and held constant beyond its
//!   first and last samples (the CIE's recommended extrapolation, the most extreme measured value: CIE 15.2:1986,
//!   as quoted by Westland & Ripamonti, *Computational Colour Science Using MATLAB*, 2004, §4.4). R is
//!   then linear in the samples, R(λ) = Σ_k φ_k(λ) R_k with hat functions φ_k, so
//!   X = Σ_k W_Xk R_k with W_Xk = k Σ_λ S x̄ φ_k Δλ: a 3 × n weighting matrix ([`Weights`]).
//!
//! A grey (one-sample) material is wavelength-flat: its weights are the white point. An RGB material has no
//! spectrum (its three samples are linear R, G, B at 700, 546.1 and 435.8 nm, not a reflectance curve) and is
//! refused with a message saying so.
//!
//! Tables: `standards/cie/*.csv`, each with its source in its header, exported by `tools/export_cie_tables.py`
//! from colour-science 0.4.7 (the independent reference; tested against its `sd_to_XYZ` and `XYZ_to_Lab`).
//!
//! The folder:
//! * `mod.rs` (this): the tristimulus weights of a sampling ([`weights`] → [`Weights`], [`Weights::xyz`]),
//!   the viewing [`Conditions`] ([`Illuminant`], [`Observer`]) and the CIE tables;
//! * `cielab.rs`: X, Y, Z to CIELAB and LCh ([`xyz_to_lab`], [`lab_to_lch`], [`Lab`], [`Lch`]) and CIEDE2000
//!   ([`ciede2000`]);
//! * `weighting.rs`: the matrix a reading takes from the spectral samples, luminous, one component per sample,
//!   or X, Y, Z through [`weights`] ([`weighting::WeightingKind`], [`weighting::Weighting`]: `rows_of`,
//!   `stack`, `luminous`, `component`).
use crate::spectrum::{interp, parse_columns, parse_table, Sampling, SamplingKind};
use crate::{Error, Result};

pub(crate) mod cielab;
pub mod weighting;

pub use cielab::{ciede2000, Lab};

/// CIE 1931 2° colour-matching functions, 1 nm, 360–830 nm.
pub(crate) const CIE1931_2DEG_CSV: &str = include_str!("../../standards/cie/cie1931-2deg-xyz.csv");
/// CIE 1964 10° colour-matching functions, 1 nm, 360–830 nm.
pub(crate) const CIE1964_10DEG_CSV: &str = include_str!("../../standards/cie/cie1964-10deg-xyz.csv");
pub(crate) const ILLUMINANT_D65_CSV: &str = include_str!("../../standards/cie/illuminant-d65.csv");
pub(crate) const ILLUMINANT_D50_CSV: &str = include_str!("../../standards/cie/illuminant-d50.csv");
pub(crate) const ILLUMINANT_A_CSV: &str = include_str!("../../standards/cie/illuminant-a.csv");

/// First and last wavelength of the summation, nm (1 nm steps).
pub(crate) const SUM_START_NM: u32 = 360;
pub(crate) const SUM_END_NM: u32 = 780;

/// A CIE standard colorimetric observer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Observer {
    /// CIE 1931 2°.
    Cie1931,
    /// CIE 1964 10° (the default of colour QC, e.g. ASTM E2194 and E308's recommendation for industrial colour).
    Cie1964,
}

impl Observer {
    /// Every observer, in the order a choice lists them.
    pub(crate) const ALL: [Observer; 2] = [Observer::Cie1931, Observer::Cie1964];

    /// The name [`Observer::parse`] takes: `2` or `10`.
    pub(crate) fn id(self) -> &'static str {
        match self {
            Observer::Cie1931 => "2",
            Observer::Cie1964 => "10",
        }
    }

    pub fn describe(self) -> &'static str {
        match self {
            Observer::Cie1931 => "CIE 1931 2°",
            Observer::Cie1964 => "CIE 1964 10°",
        }
    }

    /// `2` / `10` (also `2deg`, `10deg`, `1931`, `1964`).
    pub fn parse(s: &str) -> Result<Observer> {
        match s.trim().to_ascii_lowercase().trim_end_matches('°').trim_end_matches("deg") {
            "2" | "1931" => Ok(Observer::Cie1931),
            "10" | "1964" => Ok(Observer::Cie1964),
            _ => Err(Error::Usage(format!("unknown observer {s:?}; allowed: 2 (CIE 1931 2°), 10 (CIE 1964 10°)"))),
        }
    }

    fn table(self) -> (&'static str, &'static str) {
        match self {
            Observer::Cie1931 => (CIE1931_2DEG_CSV, "standards/cie/cie1931-2deg-xyz.csv"),
            Observer::Cie1964 => (CIE1964_10DEG_CSV, "standards/cie/cie1964-10deg-xyz.csv"),
        }
    }
}

/// A CIE illuminant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Illuminant {
    D65,
    D50,
    A,
    C,
}

impl Illuminant {
    /// Every illuminant, in the order a choice lists them.
    pub(crate) const ALL: [Illuminant; 4] = [Illuminant::D65, Illuminant::D50, Illuminant::A, Illuminant::C];

    /// What the illuminant stands for (CIE 15:2004 §3: A the incandescent lamp, C an older daylight made of A
    /// through a filter, D65 and D50 daylight phases; the tables are under `standards/cie/`).
    pub(crate) fn describe(self) -> &'static str {
        match self {
            Illuminant::D65 => "CIE D65 (daylight)",
            Illuminant::D50 => "CIE D50 (daylight, graphic arts)",
            Illuminant::A => "CIE A (incandescent lamp)",
            Illuminant::C => "CIE C (filtered A, an older daylight)",
        }
    }

    /// The name [`Illuminant::parse`] takes: `D65`, `D50`, `A`, `C`.
    pub(crate) fn id(self) -> &'static str {
        match self {
            Illuminant::D65 => "D65",
            Illuminant::D50 => "D50",
            Illuminant::A => "A",
            Illuminant::C => "C",
        }
    }

    pub fn parse(s: &str) -> Result<Illuminant> {
        match s.trim().to_ascii_uppercase().as_str() {
            "D65" => Ok(Illuminant::D65),
            "D50" => Ok(Illuminant::D50),
            "A" => Ok(Illuminant::A),
            "C" => Ok(Illuminant::C),
            _ => Err(Error::Usage(format!("unknown illuminant {s:?}; allowed: D65, D50, A, C"))),
        }
    }

    fn table(self) -> (&'static str, &'static str) {
        match self {
            Illuminant::D65 => (ILLUMINANT_D65_CSV, "standards/cie/illuminant-d65.csv"),
            Illuminant::D50 => (ILLUMINANT_D50_CSV, "standards/cie/illuminant-d50.csv"),
            Illuminant::A => (ILLUMINANT_A_CSV, "standards/cie/illuminant-a.csv"),
            Illuminant::C => (crate::spectrum::ILLUMINANT_C_CSV, "standards/cie/illuminant-c.csv"),
        }
    }
}

/// An illuminant/observer pair: what a colour reading is computed under.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Conditions {
    pub illuminant: Illuminant,
    pub observer: Observer,
}

impl Default for Conditions {
    /// D65 and the CIE 1964 10° observer, as colour QC uses.
    fn default() -> Self {
        Conditions { illuminant: Illuminant::D65, observer: Observer::Cie1964 }
    }
}

impl Conditions {
    pub fn describe(&self) -> String {
        format!("illuminant {}, {} observer", self.illuminant.id(), self.observer.describe())
    }
}

/// The summation grid: (λ, S(λ), x̄, ȳ, z̄) at 1 nm from [`SUM_START_NM`] to [`SUM_END_NM`].
fn summation_grid(c: Conditions) -> Result<Vec<(f64, f64, [f64; 3])>> {
    let (stext, sfile) = c.illuminant.table();
    let s = parse_table(stext, sfile)?;
    let (ctext, cfile) = c.observer.table();
    let cmf = parse_columns(ctext, cfile, 3)?;
    let cmf_col = |j: usize| -> Vec<(f64, f64)> { cmf.iter().map(|(l, v)| (*l, v[j])).collect() };
    let (xb, yb, zb) = (cmf_col(0), cmf_col(1), cmf_col(2));
    let mut grid = Vec::with_capacity((SUM_END_NM - SUM_START_NM + 1) as usize);
    for l in SUM_START_NM..=SUM_END_NM {
        let lam = f64::from(l);
        let missing = |f: &str| Error::Numeric(format!("{f} does not cover {lam} nm"));
        let sv = interp(&s, lam).ok_or_else(|| missing(sfile))?;
        let x = interp(&xb, lam).ok_or_else(|| missing(cfile))?;
        let y = interp(&yb, lam).ok_or_else(|| missing(cfile))?;
        let z = interp(&zb, lam).ok_or_else(|| missing(cfile))?;
        grid.push((lam, sv, [x, y, z]));
    }
    Ok(grid)
}

/// Tristimulus weights of a material's spectral samples under given conditions: X = Σ_k rows[0][k]·R_k, etc.,
/// with R_k the reflectance factor of sample k (1 for the perfect reflecting diffuser).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Weights {
    pub conditions: Conditions,
    /// rows[c][k], c = X, Y, Z; all ≥ 0.
    pub rows: [Vec<f64>; 3],
    /// X, Y, Z of the perfect reflecting diffuser (Y = 100): the row sums.
    pub white: [f64; 3],
}

impl Weights {
    /// X, Y, Z of per-sample reflectance factors `r`.
    #[cfg(test)]
    pub(crate) fn xyz(&self, r: &[f64]) -> [f64; 3] {
        let dot = |w: &Vec<f64>| w.iter().zip(r).map(|(a, b)| a * b).sum::<f64>();
        [dot(&self.rows[0]), dot(&self.rows[1]), dot(&self.rows[2])]
    }
}

/// The hat-function weights of a strictly increasing wavelength grid at wavelength `lam`: (index, weight) pairs,
/// constant extrapolation beyond the ends.
fn hat(wl: &[f64], lam: f64) -> [(usize, f64); 2] {
    let n = wl.len();
    if n == 1 || lam <= wl[0] {
        return [(0, 1.0), (0, 0.0)];
    }
    if lam >= wl[n - 1] {
        return [(n - 1, 1.0), (n - 1, 0.0)];
    }
    let i = wl.partition_point(|w| *w <= lam) - 1;
    let t = (lam - wl[i]) / (wl[i + 1] - wl[i]);
    [(i, 1.0 - t), (i + 1, t)]
}

/// Weights for samples at `wavelengths_nm` (strictly increasing; one wavelength = wavelength-flat).
pub(crate) fn weights_for_grid(wavelengths_nm: &[f64], c: Conditions) -> Result<Weights> {
    if wavelengths_nm.is_empty() || wavelengths_nm.windows(2).any(|w| !(w[1] > w[0])) {
        return Err(Error::Usage("colour weights need a strictly increasing, non-empty wavelength grid".into()));
    }
    let grid = summation_grid(c)?;
    let n = wavelengths_nm.len();
    let norm: f64 = grid.iter().map(|(_, s, cmf)| s * cmf[1]).sum();
    if !(norm > 0.0) {
        return Err(Error::Numeric("illuminant × ȳ sums to zero".into()));
    }
    let k = 100.0 / norm;
    let mut rows = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    for (lam, s, cmf) in &grid {
        for (idx, w) in hat(wavelengths_nm, *lam) {
            if w != 0.0 {
                for c in 0..3 {
                    rows[c][idx] += k * s * cmf[c] * w;
                }
            }
        }
    }
    let white = [rows[0].iter().sum(), rows[1].iter().sum(), rows[2].iter().sum()];
    Ok(Weights { conditions: c, rows, white })
}

/// Weights for a material's sampling. Grey: wavelength-flat. Spectral: its grid. RGB: refused (no spectrum).
pub(crate) fn weights(sampling: &Sampling, c: Conditions) -> Result<Weights> {
    match sampling.kind {
        SamplingKind::Grey => weights_for_grid(&[560.0], c),
        SamplingKind::Spectral => weights_for_grid(&sampling.wavelengths_nm, c),
        SamplingKind::Rgb => Err(Error::Usage(RGB_REFUSAL.to_string())),
    }
}

/// Why an RGB material has no colour readings.
pub(crate) const RGB_REFUSAL: &str =
    "colour readings need a spectral (or grey) material: an RGB material's three samples are \
     linear R, G, B values whose optics are evaluated at 700, 546.1 and 435.8 nm, not a reflectance spectrum, so \
     they define no X, Y, Z; give the recipe \"wavelengths_nm\" with one value per wavelength";

#[cfg(test)]
mod tests {
    use super::cielab::xyz_to_lab;
    use super::*;

    #[test]
    fn white_point_has_y_100_and_weights_sum_to_it() {
        for obs in Observer::ALL {
            for ill in Illuminant::ALL {
                let c = Conditions { illuminant: ill, observer: obs };
                let w = weights_for_grid(&[400.0, 500.0, 600.0, 700.0], c).unwrap();
                assert!((w.white[1] - 100.0).abs() < 1e-12, "{c:?}");
                let flat = w.xyz(&[1.0; 4]);
                for (f, w) in flat.iter().zip(&w.white) {
                    assert!((f - w).abs() < 1e-12);
                }
                assert!(w.rows.iter().all(|r| r.iter().all(|x| *x >= 0.0)));
                // Grey is the same white point.
                let g = weights_for_grid(&[560.0], c).unwrap();
                for (g, w) in g.white.iter().zip(&w.white) {
                    assert!((g - w).abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn hat_functions_partition_unity() {
        let wl = [380.0, 400.0, 450.0, 700.0];
        for lam in [360.0, 380.0, 390.0, 400.0, 449.0, 701.0, 780.0] {
            let h = hat(&wl, lam);
            assert!((h[0].1 + h[1].1 - 1.0).abs() < 1e-15);
        }
        assert_eq!(hat(&wl, 425.0), [(1, 0.5), (2, 0.5)]);
    }

    /// XYZ and CIELAB of ColorChecker spectra against colour-science's `sd_to_XYZ` / `XYZ_to_Lab`
    /// (`fixtures/reference/colorimetry.json`, `tools/ref_colorimetry.py`), all four illuminants and both observers.
    #[test]
    fn colorchecker_matches_colour_science() {
        let text = include_str!("../../fixtures/reference/colorimetry.json");
        let v: serde_json::Value = serde_json::from_str(text).unwrap();
        let nums =
            |x: &serde_json::Value| -> Vec<f64> { x.as_array().unwrap().iter().map(|y| y.as_f64().unwrap()).collect() };
        let grid = nums(&v["wavelengths_nm"]);
        let cond = |c: &serde_json::Value| Conditions {
            illuminant: Illuminant::parse(c["illuminant"].as_str().unwrap()).unwrap(),
            observer: Observer::parse(c["observer"].as_str().unwrap()).unwrap(),
        };
        for w in v["white"].as_array().unwrap() {
            let ours = weights_for_grid(&grid, cond(w)).unwrap().white;
            let theirs = nums(&w["XYZ"]);
            for j in 0..3 {
                assert!((ours[j] - theirs[j]).abs() <= 1e-9 * theirs[j], "white {w}: {ours:?}");
            }
        }
        let mut worst: f64 = 0.0;
        for case in v["cases"].as_array().unwrap() {
            let w = weights_for_grid(&grid, cond(case)).unwrap();
            let xyz = w.xyz(&nums(&case["reflectance"]));
            let (txyz, tlab) = (nums(&case["XYZ"]), nums(&case["Lab"]));
            let lab = xyz_to_lab(xyz, w.white);
            for j in 0..3 {
                let rel = (xyz[j] - txyz[j]).abs() / txyz[j];
                worst = worst.max(rel);
                assert!(rel < 1e-9, "{}: XYZ {xyz:?} vs {txyz:?}", case["patch"]);
            }
            for (o, t) in [lab.l, lab.a, lab.b].iter().zip(&tlab) {
                assert!(
                    (o - t).abs() < 1e-8,
                    "{} {}/{}: Lab {lab:?} vs {tlab:?}",
                    case["patch"],
                    case["illuminant"],
                    case["observer"]
                );
            }
        }
        eprintln!("worst relative XYZ difference from colour-science: {worst:e}");
    }

    #[test]
    fn rgb_is_refused_and_options_parse() {
        let e = weights(&Sampling::rgb(), Conditions::default()).unwrap_err().to_string();
        assert!(e.contains("wavelengths_nm"), "{e}");
        assert_eq!(Observer::parse("10").unwrap(), Observer::Cie1964);
        assert_eq!(Observer::parse("2deg").unwrap(), Observer::Cie1931);
        assert!(Observer::parse("5").is_err());
        assert_eq!(Illuminant::parse("d50").unwrap(), Illuminant::D50);
        assert!(Illuminant::parse("F2").is_err());
    }
}
