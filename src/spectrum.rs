//! Spectral sampling and luminous weighting.
//!
//! A material is evaluated at a fixed set of spectral samples: one grey sample, three RGB samples (as in
//! Ďurikovič & Ágošton 2007), or a wavelength grid. A gloss reading is *luminous*: ISO 2813 / ASTM D523
//! weight the flux by the CIE photopic luminous efficiency V(λ) = ȳ(λ) under CIE illuminant C. Because the
//! weighting is linear, the luminous flux is the integral of the weighted sum Σ w_k f_k, which is what lets
//! the measurement plan fold the spectral dimension away before integrating (see `docs/model.md` §Spectral).
//!
//! Tables: `standards/cie/illuminant-c.csv` and `standards/cie/cie1931-ybar.csv`, each citing its source in
//! its header. They are embedded at compile time so the binary works from any directory.
use crate::{Error, Result};

/// The CIE tables shipped under `standards/cie/`, embedded.
pub(crate) const ILLUMINANT_C_CSV: &str = include_str!("../standards/cie/illuminant-c.csv");
pub(crate) const YBAR_CSV: &str = include_str!("../standards/cie/cie1931-ybar.csv");

/// Luminance weights of the RGB samples. The samples *are* the CIE 1931 RGB primaries ([`RGB_WAVELENGTHS_NM`]),
/// so they are weighted by those primaries' luminances: the Y row of the CIE 1931 RGB→XYZ matrix,
/// Y = 0.17697 R + 0.81240 G + 0.01063 B (CIE 1931; CIE 15:2004 §3; the luminance ratio 1 : 4.5907 : 0.0601 of
/// Wright–Guild's primaries, Wyszecki & Stiles, *Color Science*, 2nd ed., §3.3.2). They sum to 1, so a grey
/// material's reading does not depend on them. (Earlier these were the sRGB / BT.709 weights
/// 0.2126/0.7152/0.0722, which belong to different primaries; `docs/model.md` §Spectral gives the effect.)
pub(crate) const RGB_LUMINANCE_WEIGHTS: [f64; 3] = [0.17697, 0.81240, 0.01063];

/// Relative radiant powers of the CIE 1931 RGB primaries that match the equal-energy white, 72.0962 : 1.3791 : 1
/// (Wyszecki & Stiles, *Color Science*, 2nd ed., §3.3.2). Their products with ȳ at the primaries' wavelengths
/// are the luminances behind [`RGB_LUMINANCE_WEIGHTS`] (test `rgb_weights_are_the_cie_primaries_luminances`).
#[cfg(test)]
pub(crate) const CIE_RGB_RADIANT_POWER_RATIOS: [f64; 3] = [72.0962, 1.3791, 1.0];

/// Wavelengths at which an RGB material's wavelength-dependent optics (thin-film interference) are evaluated:
/// the CIE 1931 RGB primaries 700 nm, 546.1 nm and 435.8 nm (CIE 15:2004 §3.1 / Wright–Guild primaries).
pub(crate) const RGB_WAVELENGTHS_NM: [f64; 3] = [700.0, 546.1, 435.8];

/// How a material is sampled in wavelength.
#[derive(Clone, Debug, PartialEq)]
pub enum SamplingKind {
    /// Wavelength-independent: one sample.
    Grey,
    /// Three samples, linear R, G, B.
    Rgb,
    /// A wavelength grid in nanometres (strictly increasing).
    Spectral,
}

/// The spectral samples of a material: where it is evaluated in wavelength, nothing more. How the samples are
/// combined into what a reading reports (luminous Y for gloss; later X, Y, Z) is a
/// [`Weighting`](crate::colorimetry::weighting::Weighting), chosen by the measurement plan from the readings asked
/// for.
#[derive(Clone, Debug, PartialEq)]
pub struct Sampling {
    pub kind: SamplingKind,
    /// Wavelength of each sample in nm (for Grey, 560 nm, the peak region of V(λ) (CIE 15:2004 Table T.1:
    /// ȳ = 0.995 at 560 nm), where a wavelength-dependent optic of a grey material is evaluated; for RGB,
    /// [`RGB_WAVELENGTHS_NM`]).
    pub wavelengths_nm: Vec<f64>,
}

impl Sampling {
    pub fn grey() -> Self {
        Sampling { kind: SamplingKind::Grey, wavelengths_nm: vec![560.0] }
    }

    pub fn rgb() -> Self {
        Sampling { kind: SamplingKind::Rgb, wavelengths_nm: RGB_WAVELENGTHS_NM.to_vec() }
    }

    /// A spectral grid: strictly increasing, finite, within [`SPECTRAL_RANGE_NM`], 360–830 nm (the CIE 1931 ȳ table; illuminant C is held at its 780 nm value beyond 780 nm, where the CIE does not tabulate it), and carrying some
    /// luminous weight (so a gloss reading of it is defined).
    pub fn spectral(wavelengths_nm: &[f64]) -> Result<Self> {
        luminous_grid_weights(wavelengths_nm)?;
        Ok(Sampling { kind: SamplingKind::Spectral, wavelengths_nm: wavelengths_nm.to_vec() })
    }

    pub fn len(&self) -> usize {
        self.wavelengths_nm.len()
    }

    pub fn is_empty(&self) -> bool {
        self.wavelengths_nm.is_empty()
    }

    pub fn describe(&self) -> String {
        match self.kind {
            SamplingKind::Grey => "grey (one sample)".to_string(),
            SamplingKind::Rgb => "RGB (3 samples)".to_string(),
            SamplingKind::Spectral => format!(
                "spectral, {} samples {}–{} nm",
                self.len(),
                self.wavelengths_nm[0],
                self.wavelengths_nm[self.len() - 1]
            ),
        }
    }
}

/// A (wavelength nm, value) table.
type Table = Vec<(f64, f64)>;

/// The parsed CIE tables (illuminant C, ȳ), parsed once.
fn cie_tables() -> Result<&'static (Table, Table)> {
    static TABLES: std::sync::OnceLock<(Table, Table)> = std::sync::OnceLock::new();
    if let Some(t) = TABLES.get() {
        return Ok(t);
    }
    let illum = parse_table(ILLUMINANT_C_CSV, "standards/cie/illuminant-c.csv")?;
    let ybar = parse_table(YBAR_CSV, "standards/cie/cie1931-ybar.csv")?;
    Ok(TABLES.get_or_init(|| (illum, ybar)))
}

/// The wavelengths a spectral grid may use: those of the CIE 1931 ȳ table (`standards/cie/cie1931-ybar.csv`).
pub(crate) const SPECTRAL_RANGE_NM: (f64, f64) = (360.0, 830.0);

/// Illuminant C at `lam`. CIE 15:2004 Table T.1 tabulates C only to 780 nm; from 780 to 830 nm its 780 nm
/// value is held. This cannot move a luminous weight by more than about 2e-5 of the total: ȳ there is at
/// most 1.5e-5 of its peak, and C changes by a few per cent per 10 nm near 780 nm.
fn illuminant_c(table: &[(f64, f64)], lam: f64) -> Option<f64> {
    let last = table.last()?;
    if lam > last.0 && lam <= SPECTRAL_RANGE_NM.1 {
        return Some(last.1);
    }
    interp(table, lam)
}

/// The luminous weights of a wavelength grid: the weight of sample k is S_C(λk)·ȳ(λk)·Δλk (trapezoid
/// widths), normalised to sum 1, with S_C and ȳ linearly interpolated from the embedded tables (CIE 15:2004
/// §7.1, the weighted-ordinate method). Errors name what is wrong with the grid.
pub(crate) fn luminous_grid_weights(wavelengths_nm: &[f64]) -> Result<Vec<f64>> {
    let bad = |m: String| Error::Usage(format!("spectral grid: {m}"));
    if wavelengths_nm.is_empty() {
        return Err(bad("needs at least one wavelength".into()));
    }
    for w in wavelengths_nm.windows(2) {
        if !(w[1] > w[0]) {
            return Err(bad("wavelengths must be strictly increasing".into()));
        }
    }
    let (illum, ybar) = cie_tables()?;
    let n = wavelengths_nm.len();
    let mut weights = Vec::with_capacity(n);
    for (k, &lam) in wavelengths_nm.iter().enumerate() {
        if !lam.is_finite() {
            return Err(bad("wavelengths must be finite".into()));
        }
        let (Some(s), Some(y)) = (illuminant_c(illum, lam), interp(ybar, lam)) else {
            return Err(bad(format!(
                "{lam} nm is outside {}–{} nm, the range of the CIE 1931 observer table",
                SPECTRAL_RANGE_NM.0, SPECTRAL_RANGE_NM.1
            )));
        };
        let width = if n == 1 {
            1.0
        } else if k == 0 {
            0.5 * (wavelengths_nm[1] - lam)
        } else if k == n - 1 {
            0.5 * (lam - wavelengths_nm[k - 1])
        } else {
            0.5 * (wavelengths_nm[k + 1] - wavelengths_nm[k - 1])
        };
        weights.push(s * y * width);
    }
    let total: f64 = weights.iter().sum();
    if !(total > 0.0) {
        return Err(bad("the grid carries no luminous weight".into()));
    }
    weights.iter_mut().for_each(|w| *w /= total);
    Ok(weights)
}

/// Parse a two-column CSV table `wavelength_nm,value`; lines starting with `#` are comments (provenance).
pub(crate) fn parse_table(text: &str, file: &str) -> Result<Vec<(f64, f64)>> {
    Ok(parse_columns(text, file, 1)?.into_iter().map(|(l, v)| (l, v[0])).collect())
}

/// Parse a CSV table `wavelength_nm,v1,…,vn` with `ncols` value columns: the one format of every table under
/// `standards/cie/` (`#` lines are provenance, a line starting with `wavelength` is the header). Wavelengths must
/// increase strictly; every value must be a finite number.
pub(crate) fn parse_columns(text: &str, file: &str, ncols: usize) -> Result<Vec<(f64, Vec<f64>)>> {
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with("wavelength") {
            continue;
        }
        let cells: Vec<Option<f64>> =
            line.split(',').map(|v| v.trim().parse::<f64>().ok().filter(|v| v.is_finite())).collect();
        if cells.len() != ncols + 1 || cells.iter().any(Option::is_none) {
            let cols = if ncols == 1 {
                "`wavelength_nm,value`".to_string()
            } else {
                format!("wavelength_nm and {ncols} values")
            };
            return Err(Error::input(file, format!("line {}", i + 1), format!("expected {cols}")));
        }
        let cells: Vec<f64> = cells.into_iter().flatten().collect();
        rows.push((cells[0], cells[1..].to_vec()));
    }
    if rows.len() < 2 || rows.windows(2).any(|w| !(w[1].0 > w[0].0)) {
        return Err(Error::input(file, "", "table needs at least two rows with increasing wavelengths"));
    }
    Ok(rows)
}

/// Linear interpolation in a table; None outside its range.
pub(crate) fn interp(table: &[(f64, f64)], x: f64) -> Option<f64> {
    let (first, last) = (table.first()?, table.last()?);
    if x < first.0 || x > last.0 {
        return None;
    }
    let i = table.partition_point(|r| r.0 <= x);
    if i == 0 {
        return Some(first.1);
    }
    if i >= table.len() {
        return Some(last.1);
    }
    let (a, b) = (table[i - 1], table[i]);
    Some(a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 781–830 nm were allowed by the docs and the schema (`docs/recipe-format.md` §Paint) but once refused by the
    /// tables.
    #[test]
    fn the_whole_documented_range_is_accepted() {
        let grid: Vec<f64> = (0..=94).map(|k| 360.0 + 5.0 * k as f64).collect();
        assert_eq!(*grid.last().unwrap(), 830.0);
        let w = luminous_grid_weights(&grid).unwrap();
        let beyond: f64 = grid.iter().zip(&w).filter(|(l, _)| **l > 780.0).map(|(_, w)| w).sum();
        assert!(beyond > 0.0 && beyond < 2e-5, "{beyond}");
        assert!(Sampling::spectral(&[781.0, 830.0]).is_ok());
        let e = Sampling::spectral(&[500.0, 831.0]).unwrap_err().to_string();
        assert!(e.contains("831 nm is outside 360–830 nm"), "{e}");
    }

    #[test]
    fn bad_grids_are_refused() {
        assert!(Sampling::spectral(&[]).is_err());
        assert!(Sampling::spectral(&[500.0, 500.0]).is_err());
        assert!(Sampling::spectral(&[600.0, 500.0]).is_err());
        assert!(Sampling::spectral(&[300.0, 500.0]).is_err());
        assert!(Sampling::spectral(&[500.0, f64::NAN]).is_err());
    }

    #[test]
    fn interpolation_and_tables() {
        let t = parse_table("# c\nwavelength_nm,value\n400,1\n500,3\n", "t.csv").unwrap();
        assert_eq!(interp(&t, 450.0), Some(2.0));
        assert_eq!(interp(&t, 399.0), None);
        assert!(parse_table("400,1\n400,2\n", "t.csv").is_err());
        assert!(parse_table("400,x\n", "t.csv").unwrap_err().to_string().contains("t.csv"));
    }
}
