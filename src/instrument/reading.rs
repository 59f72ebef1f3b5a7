//! What a geometry reads: the compiled form of a geometry file's `readings` ([`ReadingSpec`]: gloss, haze,
//! DOI, a profile pixel, a composite's haze index, a colour quantity), what each reading says about the spectral
//! weighting its fluxes need, and the scale the readings are on ([`Scale`]: the gloss standard and the value it
//! is assigned). The stops and axes these readings are taken through are `instrument::geometry`.
use crate::colorimetry::weighting::WeightingKind;
use crate::colorimetry::Conditions;

/// What a geometry reads, compiled from a standard's `readings` list.
#[derive(Clone, Debug, PartialEq)]
pub enum ReadingSpec {
    /// Specular gloss, GU: 100·Φ(specimen, receptor) / Φ(standard, receptor).
    Gloss { receptor: String },
    /// Reflection haze, HU: 100·mean_r Φ(specimen, r) / Φ(standard, `specular`) over the haze receptors.
    Haze { receptors: Vec<String>, specular: String },
    /// Logarithmic haze: k·log10(H/20 + 1) of the linear haze above (BYK micro-haze plus, k = 1285.1).
    LogHaze { receptors: Vec<String>, specular: String, k: f64 },
    /// Brightness-compensated haze, HU: 100·(mean_r Φ(specimen, r) − factor·Φ(specimen, compensation)) /
    /// Φ(standard, `specular`). `factor` = mean_r Ω⊥(r) / Ω⊥(compensation), the ratio of the receptors'
    /// projected solid angles
    /// ([`Stop::projected_solid_angle`](crate::instrument::geometry::Stop::projected_solid_angle)), is what
    /// makes a Lambertian body read 0 (`docs/instrument.md` §1.7).
    HazeCompensated { receptors: Vec<String>, specular: String, compensation: String, factor: f64 },
    /// Logarithmic compensated haze: k·log10(H_c/20 + 1) of the compensated linear haze H_c above.
    LogHazeCompensated { receptors: Vec<String>, specular: String, compensation: String, factor: f64, k: f64 },
    /// Distinctness of image: 100·(Φ(specular) − mean_r Φ(r)) / Φ(specular), all on the specimen.
    Doi { specular: String, offset: Vec<String> },
    /// One pixel of a goniophotometric profile (`instrument::profile`), GU: 100·Φ(specimen, `receptor`) /
    /// Φ(standard, `reference`), the reference being a pixel-sized window centred on the specular direction.
    /// Built by the profile module, not written in geometry files.
    Profile { receptor: String, reference: String },
    /// Haze index (ASTM D4039): gloss of one geometry minus the gloss of another.
    HazeIndex { minuend: String, subtrahend: String },
    /// A colour reading (`docs/colour.md`): from X, Y, Z = Σ sign·Φ_XYZ(integral) / `white` over the named
    /// integrals (a directional geometry's receptor; a sphere's hemisphere, minus its specular port for SCE),
    /// `white` being the same sum for the perfect reflecting diffuser (so it reads Y = 100).
    Colour { quantity: ColourQuantity, terms: Vec<(String, f64)>, white: f64 },
}

/// What a colour reading reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColourQuantity {
    X,
    Y,
    Z,
    L,
    A,
    B,
    C,
    H,
}

impl ColourQuantity {
    /// Every colour quantity, in output order.
    pub(crate) const ALL: [ColourQuantity; 8] = [
        ColourQuantity::X,
        ColourQuantity::Y,
        ColourQuantity::Z,
        ColourQuantity::L,
        ColourQuantity::A,
        ColourQuantity::B,
        ColourQuantity::C,
        ColourQuantity::H,
    ];

    /// The reading's name: X, Y, Z, L*, a*, b*, C* (C*ab), h (hab).
    pub(crate) fn name(self) -> &'static str {
        match self {
            ColourQuantity::X => "X",
            ColourQuantity::Y => "Y",
            ColourQuantity::Z => "Z",
            ColourQuantity::L => "L*",
            ColourQuantity::A => "a*",
            ColourQuantity::B => "b*",
            ColourQuantity::C => "C*",
            ColourQuantity::H => "h",
        }
    }
}

impl ReadingSpec {
    pub(crate) fn quantity(&self) -> &'static str {
        match self {
            ReadingSpec::Gloss { .. } => "gloss",
            ReadingSpec::Haze { .. } => "haze",
            ReadingSpec::LogHaze { .. } => "log-haze",
            ReadingSpec::HazeCompensated { .. } => "haze-compensated",
            ReadingSpec::LogHazeCompensated { .. } => "log-haze-compensated",
            ReadingSpec::Doi { .. } => "doi",
            ReadingSpec::Profile { .. } => "profile",
            ReadingSpec::HazeIndex { .. } => "haze-index",
            ReadingSpec::Colour { quantity, .. } => quantity.name(),
        }
    }

    /// The spectral weighting the reading's fluxes need: gloss, haze and DOI are luminous (ISO 2813 and
    /// ASTM D523 weight the flux by V(λ) under CIE illuminant C); a colour reading needs X, Y, Z under the
    /// plan's colour conditions (`colorimetry::weighting::WeightingKind::Xyz`).
    pub(crate) fn weighting(&self, colour: Conditions) -> WeightingKind {
        match self {
            ReadingSpec::Colour { .. } => WeightingKind::Xyz(colour),
            _ => WeightingKind::Luminous,
        }
    }

    pub(crate) fn unit(&self) -> &'static str {
        match self {
            ReadingSpec::Gloss { .. } | ReadingSpec::HazeIndex { .. } | ReadingSpec::Profile { .. } => "GU",
            ReadingSpec::Haze { .. } | ReadingSpec::HazeCompensated { .. } => "HU",
            ReadingSpec::LogHaze { .. } | ReadingSpec::LogHazeCompensated { .. } => "HU(log)",
            ReadingSpec::Doi { .. } => "DOI",
            ReadingSpec::Colour { quantity: ColourQuantity::H, .. } => "°",
            ReadingSpec::Colour { .. } => "",
        }
    }
}

/// The scale of a geometry's readings (`docs/instrument.md` §1.5): every reading is `value` × (specimen flux) /
/// (flux of the standard) through the same stops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scale {
    /// Polished black glass of refractive index `index` (a smooth, non-absorbing dielectric whose back is not
    /// seen) is assigned `value` GU: ASTM D523 / ISO 2813 n = 1.567 → 100; TAPPI T480 n = 1.540 → 100.
    BlackGlass { index: f64, value: f64 },
    /// The mirror scale: specular reflectance × `value` (a perfect mirror is assigned `value`), as ASTM C346
    /// and D2457's 45° procedure (× 1000).
    Mirror { value: f64 },
}

impl Scale {
    /// The gloss standard of this scale, rescaled to read 100: black glass of the scale's index, or the perfect
    /// mirror, with gain 100/value (exactly 1 for the usual 100 GU, so those standards are bit-identical to
    /// plain glass). The plan integrates it by the same engine as any specimen and multiplies every ratio by
    /// 100, which puts readings on this scale.
    pub(crate) fn standard(&self) -> crate::brdf::dielectric::SmoothDielectric {
        let (ior, value) = match *self {
            Scale::BlackGlass { index, value } => (index, value),
            Scale::Mirror { value } => (f64::INFINITY, value),
        };
        crate::brdf::dielectric::SmoothDielectric {
            gain: 100.0 / value,
            ..crate::brdf::dielectric::SmoothDielectric::new(ior)
        }
    }

    /// Reflectance at cos θ of the gloss standard rescaled to read 100: R_standard(θ)·100/value.
    pub(crate) fn standard_reflectance(&self, cos_theta: f64) -> f64 {
        self.standard().reflectance(cos_theta)
    }

    /// The black glass's index, or None on the mirror scale.
    pub fn black_glass_index(&self) -> Option<f64> {
        match *self {
            Scale::BlackGlass { index, .. } => Some(index),
            Scale::Mirror { .. } => None,
        }
    }

    /// Bits identifying the standard (for sharing integrals between geometries).
    pub(crate) fn key(&self) -> [u64; 3] {
        match *self {
            Scale::BlackGlass { index, value } => [0, index.to_bits(), value.to_bits()],
            Scale::Mirror { value } => [1, value.to_bits(), 0],
        }
    }

    /// One line, e.g. "black glass n = 1.567 = 100 GU" or "mirror scale: reflectance × 1000".
    pub fn describe(&self) -> String {
        match *self {
            Scale::BlackGlass { index, value } => format!("black glass n = {index} = {value} GU"),
            Scale::Mirror { value } => format!("mirror scale: reflectance × {value}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Scale;
    use crate::brdf::dielectric::SmoothDielectric;

    #[test]
    fn the_standard_of_a_100_gu_scale_is_the_smooth_dielectric_specimen_itself() {
        let s = Scale::BlackGlass { index: 1.567, value: 100.0 };
        assert_eq!(s.standard(), SmoothDielectric::new(1.567));
        for c in [0.05, 0.5, 0.94, 1.0] {
            assert_eq!(s.standard_reflectance(c).to_bits(), SmoothDielectric::new(1.567).reflectance(c).to_bits());
        }
    }

    #[test]
    fn the_mirror_scale_standard_is_a_perfect_mirror_rescaled() {
        let s = Scale::Mirror { value: 1000.0 };
        for c in [0.0, 0.3, 0.6, 1.0] {
            assert_eq!(s.standard_reflectance(c), 0.1);
        }
        // A black-glass scale assigning 50 GU doubles the standard's reflectance.
        let g = Scale::BlackGlass { index: 1.54, value: 50.0 };
        let plain = SmoothDielectric::new(1.54).reflectance(0.8);
        assert!((g.standard_reflectance(0.8) - 2.0 * plain).abs() <= 1e-16);
    }
}
