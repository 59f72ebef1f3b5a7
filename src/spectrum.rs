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
pub const ILLUMINANT_C_CSV: &str = include_str!("../standards/cie/illuminant-c.csv");
pub const YBAR_CSV: &str = include_str!("../standards/cie/cie1931-ybar.csv");

/// Luminance weights of the RGB samples. The samples *are* the CIE 1931 RGB primaries ([`RGB_WAVELENGTHS_NM`]),
/// so they are weighted by those primaries' luminances: the Y row of the CIE 1931 RGB→XYZ matrix,
/// Y = 0.17697 R + 0.81240 G + 0.01063 B (CIE 1931; CIE 15:2004 §3; the luminance ratio 1 : 4.5907 : 0.0601 of
/// Wright–Guild's primaries, Wyszecki & Stiles, *Color Science*, 2nd ed., §3.3.2). They sum to 1, so a grey
/// material's reading does not depend on them. (Until issue 9 these were the sRGB / BT.709 weights
/// 0.2126/0.7152/0.0722, which belong to different primaries; `docs/model.md` §Spectral gives the effect.)
pub const RGB_LUMINANCE_WEIGHTS: [f64; 3] = [0.17697, 0.81240, 0.01063];

/// Relative radiant powers of the CIE 1931 RGB primaries that match the equal-energy white, 72.0962 : 1.3791 : 1
/// (Wyszecki & Stiles, *Color Science*, 2nd ed., §3.3.2). Their products with ȳ at the primaries' wavelengths
/// are the luminances behind [`RGB_LUMINANCE_WEIGHTS`] (test `rgb_weights_are_the_cie_primaries_luminances`).
pub const CIE_RGB_RADIANT_POWER_RATIOS: [f64; 3] = [72.0962, 1.3791, 1.0];

/// Wavelengths at which an RGB material's wavelength-dependent optics (thin-film interference) are evaluated:
/// the CIE 1931 RGB primaries 700 nm, 546.1 nm and 435.8 nm (CIE 15:2004 §3.1 / Wright–Guild primaries).
pub const RGB_WAVELENGTHS_NM: [f64; 3] = [700.0, 546.1, 435.8];

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

/// The spectral samples of a material and the weights that turn them into a luminous quantity.
#[derive(Clone, Debug, PartialEq)]
pub struct Sampling {
    pub kind: SamplingKind,
    /// Wavelength of each sample in nm (for Grey, 560 nm; for RGB, [`RGB_WAVELENGTHS_NM`]).
    pub wavelengths_nm: Vec<f64>,
    /// Luminous weight of each sample; they sum to 1, so a perfectly white material has luminous value 1.
    pub luminous_weights: Vec<f64>,
}

impl Sampling {
    pub fn grey() -> Self {
        Sampling { kind: SamplingKind::Grey, wavelengths_nm: vec![560.0], luminous_weights: vec![1.0] }
    }

    pub fn rgb() -> Self {
        Sampling {
            kind: SamplingKind::Rgb,
            wavelengths_nm: RGB_WAVELENGTHS_NM.to_vec(),
            luminous_weights: RGB_LUMINANCE_WEIGHTS.to_vec(),
        }
    }

    /// A spectral grid. The weight of sample k is S_C(λk)·ȳ(λk)·Δλk (trapezoid widths), normalised to sum 1,
    /// with S_C and ȳ linearly interpolated from the embedded tables. The grid must lie within 360–830 nm.
    pub fn spectral(wavelengths_nm: &[f64]) -> Result<Self> {
        let bad = |m: String| Error::Usage(format!("spectral grid: {m}"));
        if wavelengths_nm.is_empty() {
            return Err(bad("needs at least one wavelength".into()));
        }
        for w in wavelengths_nm.windows(2) {
            if !(w[1] > w[0]) {
                return Err(bad("wavelengths must be strictly increasing".into()));
            }
        }
        let illum = parse_table(ILLUMINANT_C_CSV, "standards/cie/illuminant-c.csv")?;
        let ybar = parse_table(YBAR_CSV, "standards/cie/cie1931-ybar.csv")?;
        let n = wavelengths_nm.len();
        let mut weights = Vec::with_capacity(n);
        for (k, &lam) in wavelengths_nm.iter().enumerate() {
            if !lam.is_finite() {
                return Err(bad("wavelengths must be finite".into()));
            }
            let (Some(s), Some(y)) = (interp(&illum, lam), interp(&ybar, lam)) else {
                return Err(bad(format!("{lam} nm is outside the CIE tables")));
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
        Ok(Sampling {
            kind: SamplingKind::Spectral,
            wavelengths_nm: wavelengths_nm.to_vec(),
            luminous_weights: weights,
        })
    }

    pub fn len(&self) -> usize {
        self.luminous_weights.len()
    }

    pub fn is_empty(&self) -> bool {
        self.luminous_weights.is_empty()
    }

    /// Σ w_k v_k.
    pub fn luminous(&self, values: &[f64]) -> f64 {
        self.luminous_weights.iter().zip(values).map(|(w, v)| w * v).sum()
    }

    pub fn describe(&self) -> String {
        match self.kind {
            SamplingKind::Grey => "grey (one sample)".to_string(),
            SamplingKind::Rgb => {
                "RGB (3 samples at the CIE 1931 primaries; luminance weights 0.17697/0.81240/0.01063)".to_string()
            }
            SamplingKind::Spectral => format!(
                "spectral, {} samples {}–{} nm (weights CIE illuminant C × ȳ)",
                self.len(),
                self.wavelengths_nm[0],
                self.wavelengths_nm[self.len() - 1]
            ),
        }
    }
}

/// Parse a two-column CSV table `wavelength_nm,value`; lines starting with `#` are comments (provenance).
pub fn parse_table(text: &str, file: &str) -> Result<Vec<(f64, f64)>> {
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with("wavelength") {
            continue;
        }
        let mut it = line.split(',');
        let parse = |s: Option<&str>| s.and_then(|v| v.trim().parse::<f64>().ok()).filter(|v| v.is_finite());
        match (parse(it.next()), parse(it.next())) {
            (Some(l), Some(v)) => rows.push((l, v)),
            _ => return Err(Error::input(file, format!("line {}", i + 1), "expected `wavelength_nm,value`")),
        }
    }
    if rows.len() < 2 || rows.windows(2).any(|w| !(w[1].0 > w[0].0)) {
        return Err(Error::input(file, "", "table needs at least two rows with increasing wavelengths"));
    }
    Ok(rows)
}

/// Linear interpolation in a table; None outside its range.
pub fn interp(table: &[(f64, f64)], x: f64) -> Option<f64> {
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

    #[test]
    fn weights_are_normalised() {
        for s in [Sampling::grey(), Sampling::rgb(), Sampling::spectral(&[400.0, 500.0, 600.0, 700.0]).unwrap()] {
            let total: f64 = s.luminous_weights.iter().sum();
            assert!((total - 1.0).abs() < 1e-15, "{:?}", s.kind);
            assert!((s.luminous(&vec![0.37; s.len()]) - 0.37).abs() < 1e-15);
        }
    }

    #[test]
    fn luminous_reflectance_matches_colour_science() {
        // fixtures/reference/luminous.json: Y/100 under CIE illuminant C, CIE 1931 2°, from colour-science
        // (tools/ref_luminous.py). The end samples carry half weight here (trapezoid) and full weight there;
        // illuminant C × ȳ is ~1e-4 of its peak at 380 and 780 nm; the differences seen are ≤ 2.3e-7.
        let text = include_str!("../fixtures/reference/luminous.json");
        let v: serde_json::Value = serde_json::from_str(text).unwrap();
        let grid: Vec<f64> = v["wavelengths_nm"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        let s = Sampling::spectral(&grid).unwrap();
        for case in v["cases"].as_array().unwrap() {
            let r: Vec<f64> = case["reflectance"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
            let y = case["Y_over_100"].as_f64().unwrap();
            let ours = s.luminous(&r);
            eprintln!("{}: ours {ours}, colour-science {y}, difference {:e}", case["name"], ours - y);
            assert!((ours - y).abs() < 1e-6, "{}: {ours} vs colour-science {y}", case["name"]);
        }
    }

    /// The RGB weights are the luminances of the CIE 1931 primaries: radiant power ratio × ȳ(λ) at 700, 546.1
    /// and 435.8 nm, ȳ interpolated from the embedded 5 nm table (≈ 0.5 % off the 1 nm values at 435.8 nm,
    /// hence the tolerance), normalised. Independent of the constants' source: only ȳ and the power ratios.
    #[test]
    fn rgb_weights_are_the_cie_primaries_luminances() {
        let ybar = parse_table(YBAR_CSV, "ybar").unwrap();
        let lum: Vec<f64> =
            (0..3).map(|k| CIE_RGB_RADIANT_POWER_RATIOS[k] * interp(&ybar, RGB_WAVELENGTHS_NM[k]).unwrap()).collect();
        let total: f64 = lum.iter().sum();
        for k in 0..3 {
            let w = lum[k] / total;
            let rel = (w - RGB_LUMINANCE_WEIGHTS[k]).abs() / RGB_LUMINANCE_WEIGHTS[k];
            assert!(rel < 6e-3, "primary {k}: ȳ-derived weight {w} vs {}", RGB_LUMINANCE_WEIGHTS[k]);
        }
        // The luminance ratio of the primaries, 1 : 4.5907 : 0.0601 (CIE 1931).
        let w = RGB_LUMINANCE_WEIGHTS;
        assert!((w[1] / w[0] - 4.5907).abs() < 1e-3 && (w[2] / w[0] - 0.0601).abs() < 1e-4);
        assert_eq!(Sampling::rgb().luminous_weights, w.to_vec());
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
