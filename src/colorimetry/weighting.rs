//! What a reading takes from a material's spectral samples: a weighting matrix whose rows turn the per-sample
//! fluxes into the components the reading reports (the luminous value of gloss, one value per sample, or the
//! tristimulus values X, Y, Z of colour). The plan chooses the kinds from the readings asked for and stacks
//! their rows into one matrix; the samples themselves are `spectrum::Sampling`.
use crate::spectrum::{luminous_grid_weights, Sampling, SamplingKind, RGB_LUMINANCE_WEIGHTS};
use crate::Result;

/// What a reading needs from the spectral samples. To add one (e.g. CIE X, Y, Z under an illuminant and
/// observer): add a variant here, its rows in [`Weighting::rows_of`] (one row of n sample weights per
/// component, with the source of the tables), and return it from `ReadingSpec::weighting` for the readings
/// that use it; the plan stacks the rows of every kind its readings ask for and each reading reads its
/// components at [`Weighting::offset`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum WeightingKind {
    /// One component, the luminous value: CIE illuminant C × ȳ(λ) for a spectral grid (ISO 2813 / ASTM D523:
    /// gloss is luminous), the luminances of the CIE 1931 primaries ([`RGB_LUMINANCE_WEIGHTS`]) for RGB, 1 for
    /// grey. Rows sum to 1, so a
    /// perfectly white material has luminous value 1.
    Luminous,
    /// One component per sample (no weighting): the fluxes per wavelength.
    Identity,
    /// Three components, the CIE tristimulus values X, Y, Z under an illuminant and observer (CIE 15:2004 /
    /// ASTM E308 weights, `colorimetry::weights`; the perfect reflecting diffuser has Y = 100): what colour
    /// readings need. An RGB material has none (its samples are not a spectrum) and is refused with a message.
    Xyz(crate::colorimetry::Conditions),
}

impl WeightingKind {
    /// The illuminant and observer of a colour weighting, None for the others: what a reading through it is
    /// computed under (docs/instrument.md §Output).
    pub(crate) fn conditions(self) -> Option<crate::colorimetry::Conditions> {
        match self {
            WeightingKind::Xyz(c) => Some(c),
            _ => None,
        }
    }
}

/// A k × n weighting matrix: component c of a weighted flux is Σ_j W[c][j] Φ_j over the n samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Weighting {
    /// The kinds stacked in this matrix, each with the index of its first row.
    pub parts: Vec<(WeightingKind, usize)>,
    /// k rows of n weights.
    pub rows: Vec<Vec<f64>>,
}

impl Weighting {
    /// The rows of one kind for this sampling.
    pub(crate) fn rows_of(kind: WeightingKind, sampling: &Sampling) -> Result<Vec<Vec<f64>>> {
        Ok(match kind {
            WeightingKind::Luminous => vec![match sampling.kind {
                SamplingKind::Grey => vec![1.0; sampling.len()],
                SamplingKind::Rgb => RGB_LUMINANCE_WEIGHTS.to_vec(),
                SamplingKind::Spectral => luminous_grid_weights(&sampling.wavelengths_nm)?,
            }],
            WeightingKind::Identity => (0..sampling.len())
                .map(|i| (0..sampling.len()).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
                .collect(),
            WeightingKind::Xyz(c) => crate::colorimetry::weights(sampling, c)?.rows.to_vec(),
        })
    }

    /// The kinds (each once, in the order given) stacked into one matrix.
    pub(crate) fn stack(kinds: &[WeightingKind], sampling: &Sampling) -> Result<Weighting> {
        let mut w = Weighting { parts: Vec::new(), rows: Vec::new() };
        for &kind in kinds {
            if w.parts.iter().all(|(k, _)| *k != kind) {
                w.parts.push((kind, w.rows.len()));
                w.rows.extend(Weighting::rows_of(kind, sampling)?);
            }
        }
        Ok(w)
    }

    /// The luminous weighting alone (one component).
    pub fn luminous(sampling: &Sampling) -> Result<Weighting> {
        Weighting::stack(&[WeightingKind::Luminous], sampling)
    }

    /// Number of components k.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Index of the first component of `kind`, if the matrix has it.
    pub(crate) fn offset(&self, kind: WeightingKind) -> Option<usize> {
        self.parts.iter().find(|(k, _)| *k == kind).map(|(_, o)| *o)
    }

    /// Component c of the weighted values: Σ_j W[c][j] v_j.
    #[inline]
    pub fn component(&self, c: usize, values: &[f64]) -> f64 {
        self.rows[c].iter().zip(values).map(|(w, v)| w * v).sum()
    }

    /// An error bound of component c from per-sample error bounds: Σ_j |W[c][j]| e_j.
    pub(crate) fn component_error(&self, c: usize, errors: &[f64]) -> f64 {
        self.rows[c].iter().zip(errors).map(|(w, e)| w.abs() * e).sum()
    }

    /// All k components of the weighted values.
    pub(crate) fn apply(&self, values: &[f64]) -> Vec<f64> {
        (0..self.len()).map(|c| self.component(c, values)).collect()
    }

    pub fn describe(&self) -> String {
        self.parts
            .iter()
            .map(|(k, _)| match k {
                WeightingKind::Luminous => {
                    "luminous (CIE illuminant C × ȳ; the CIE 1931 primaries' luminances for RGB; 1 for grey)"
                        .to_string()
                }
                WeightingKind::Identity => "identity (one component per sample)".to_string(),
                WeightingKind::Xyz(c) => format!(
                    "CIE X, Y, Z ({}; 1 nm summation, docs/colour.md): three components, the spectrum is not folded \
                     into one luminous value",
                    c.describe()
                ),
            })
            .collect::<Vec<_>>()
            .join(" + ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::{interp, parse_table, CIE_RGB_RADIANT_POWER_RATIOS, RGB_WAVELENGTHS_NM, YBAR_CSV};

    #[test]
    fn weights_are_normalised() {
        for s in [Sampling::grey(), Sampling::rgb(), Sampling::spectral(&[400.0, 500.0, 600.0, 700.0]).unwrap()] {
            let w = Weighting::luminous(&s).unwrap();
            let total: f64 = w.rows[0].iter().sum();
            assert!((total - 1.0).abs() < 1e-15, "{:?}", s.kind);
            assert!((w.component(0, &vec![0.37; s.len()]) - 0.37).abs() < 1e-15);
        }
    }

    #[test]
    fn luminous_reflectance_matches_colour_science() {
        // fixtures/reference/luminous.json: Y/100 under CIE illuminant C, CIE 1931 2°, from colour-science
        // (tools/ref_luminous.py). The end samples carry half weight here (trapezoid) and full weight there;
        // illuminant C × ȳ is ~1e-4 of its peak at 380 and 780 nm; the differences seen are ≤ 2.3e-7.
        let text = include_str!("../../fixtures/reference/luminous.json");
        let v: serde_json::Value = serde_json::from_str(text).unwrap();
        let grid: Vec<f64> = v["wavelengths_nm"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        let s = Weighting::luminous(&Sampling::spectral(&grid).unwrap()).unwrap();
        for case in v["cases"].as_array().unwrap() {
            let r: Vec<f64> = case["reflectance"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
            let y = case["Y_over_100"].as_f64().unwrap();
            let ours = s.component(0, &r);
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
        assert_eq!(Weighting::luminous(&Sampling::rgb()).unwrap().rows, vec![w.to_vec()]);
    }

    #[test]
    fn weightings_stack_and_identity_is_the_samples() {
        let s = Sampling::rgb();
        let w =
            Weighting::stack(&[WeightingKind::Luminous, WeightingKind::Identity, WeightingKind::Luminous], &s).unwrap();
        assert_eq!(w.len(), 4);
        assert_eq!(w.offset(WeightingKind::Luminous), Some(0));
        assert_eq!(w.offset(WeightingKind::Identity), Some(1));
        let l = RGB_LUMINANCE_WEIGHTS;
        assert_eq!(w.apply(&[0.2, 0.5, 0.7]), vec![l[0] * 0.2 + l[1] * 0.5 + l[2] * 0.7, 0.2, 0.5, 0.7]);
        assert_eq!(w.component_error(0, &[1.0, 1.0, 1.0]), l[0] + l[1] + l[2]);
    }
}
