//! Instrument geometry: apertures as field stops in the focal planes of collimating lenses, and the map
//! from a point of a stop to a direction.
//!
//! The model (stated in full in `docs/instrument.md`): specimen normal z, plane of measurement x–z. For a
//! geometry of angle θ the source axis (pointing towards the source) is s0 = (−sin θ, 0, cos θ) and the
//! receptor axis r0 = (sin θ, 0, cos θ). A point (p, q) of a stop, in tangent coordinates (p = x/f, q = y/f),
//! is the direction normalize(axis + p·e∥ + q·e⊥) with e⊥ = (0, 1, 0), e∥ = e⊥ × axis, and solid-angle
//! element dω = dp dq / (1 + p² + q²)^{3/2}. The mirror image of source point (p, q) is receptor point
//! (−p, −q), so the specular manifold is p_s + p_r = 0, q_s + q_r = 0.
use crate::colorimetry::weighting::WeightingKind;
use crate::colorimetry::Conditions;
use crate::Vec3;

/// A rectangular field stop in tangent coordinates: p ∈ [p0, p1] in the plane of measurement (positive p
/// towards grazing for the receptor, towards the normal for the source), q ∈ [q0, q1] perpendicular to it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stop {
    pub p: [f64; 2],
    pub q: [f64; 2],
}

impl Stop {
    /// A stop of full angular size `in_plane` × `perpendicular` (radians) whose centre is offset by
    /// `offset` (radians, in the plane of measurement) from the lens axis: p spans
    /// [tan(offset − in_plane/2), tan(offset + in_plane/2)], q spans ±tan(perpendicular/2).
    pub fn from_angles(in_plane: f64, perpendicular: f64, offset: f64) -> Stop {
        Stop {
            p: [(offset - 0.5 * in_plane).tan(), (offset + 0.5 * in_plane).tan()],
            q: [-(0.5 * perpendicular).tan(), (0.5 * perpendicular).tan()],
        }
    }

    /// Solid angle of the stop, ∫∫ dp dq / (1 + p² + q²)^{3/2}, in closed form:
    /// Ω = Σ ± atan(p q / sqrt(1 + p² + q²)) over the four corners.
    pub fn solid_angle(&self) -> f64 {
        let f = |p: f64, q: f64| (p * q / (1.0 + p * p + q * q).sqrt()).atan();
        f(self.p[1], self.q[1]) - f(self.p[0], self.q[1]) - f(self.p[1], self.q[0]) + f(self.p[0], self.q[0])
    }

    /// Projected solid angle Ω⊥ = ∫ cos θo dω of this stop on the receptor lens of a geometry of angle θ
    /// (radians), in closed form. With cos θo = (cos θ − p sin θ)/√(1+p²+q²) and dω = dp dq/(1+p²+q²)^{3/2},
    /// Ω⊥ = cos θ·∬(1+p²+q²)⁻² dp dq − sin θ·∬ p(1+p²+q²)⁻² dp dq, each a corner sum of the antiderivatives
    /// G(P,Q) = ½[P/√(1+P²)·atan(Q/√(1+P²)) + Q/√(1+Q²)·atan(P/√(1+Q²))] (the differential-area-to-rectangle
    /// view factor × π; Howell, *A Catalog of Radiation Heat Transfer Configuration Factors*, B-3) and
    /// H(P,Q) = ½[atan Q − atan(Q/√(1+P²))/√(1+P²)] (∫ p/(a²+p²)² dp = −1/(2(a²+p²)), then ∫ dq/(b²+q²)).
    /// A Lambertian surface of albedo ρ sends (ρ/π)·Ω⊥(R)·∫_S cos θi dωi into stop R, so the ratio of two
    /// stops' Lambertian fluxes is the ratio of their Ω⊥, whatever the source.
    pub fn projected_solid_angle(&self, theta: f64) -> f64 {
        let g = |p: f64, q: f64| {
            let (a, b) = ((1.0 + p * p).sqrt(), (1.0 + q * q).sqrt());
            0.5 * (p / a * (q / a).atan() + q / b * (p / b).atan())
        };
        let h = |p: f64, q: f64| {
            let a = (1.0 + p * p).sqrt();
            0.5 * (q.atan() - (q / a).atan() / a)
        };
        let corners = |f: &dyn Fn(f64, f64) -> f64| {
            f(self.p[1], self.q[1]) - f(self.p[0], self.q[1]) - f(self.p[1], self.q[0]) + f(self.p[0], self.q[0])
        };
        theta.cos() * corners(&g) - theta.sin() * corners(&h)
    }
}

/// The two lens axes of a geometry of angle θ (radians from the normal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axes {
    pub theta: f64,
    sin: f64,
    cos: f64,
}

impl Axes {
    pub fn new(theta: f64) -> Self {
        Axes { theta, sin: theta.sin(), cos: theta.cos() }
    }

    /// Direction (towards the source) of source-stop point (p, q), and the factor 1/(1+p²+q²)^{1/2}.
    /// s0 = (−sin θ, 0, cos θ), e∥ = (cos θ, 0, sin θ).
    #[inline]
    pub fn source_dir(&self, p: f64, q: f64) -> Vec3 {
        let v = Vec3::new(-self.sin + p * self.cos, q, self.cos + p * self.sin);
        v / (1.0 + p * p + q * q).sqrt()
    }

    /// Direction (towards the receptor) of receptor-stop point (p, q). r0 = (sin θ, 0, cos θ),
    /// e∥ = (cos θ, 0, −sin θ).
    #[inline]
    pub fn receptor_dir(&self, p: f64, q: f64) -> Vec3 {
        let v = Vec3::new(self.sin + p * self.cos, q, self.cos - p * self.sin);
        v / (1.0 + p * p + q * q).sqrt()
    }
}

/// dω / (dp dq) = (1 + p² + q²)^{-3/2}.
#[inline]
pub fn solid_angle_density(p: f64, q: f64) -> f64 {
    let r2 = 1.0 + p * p + q * q;
    1.0 / (r2 * r2.sqrt())
}

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
    /// projected solid angles ([`Stop::projected_solid_angle`]), is what makes a Lambertian body read 0
    /// (`docs/instrument.md` §1.7).
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
    pub const ALL: [ColourQuantity; 8] = [
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
    pub fn name(self) -> &'static str {
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

/// What kind of integral a named receptor of a geometry is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integral {
    /// The aperture integral over source stop × receptor stop (gloss, and multi-angle colour with the receptor
    /// lens on its own axis).
    Aperture,
    /// A d/8 sphere's directional–hemispherical reflectance at the viewing angle (uniform diffuse illumination
    /// viewed along one direction; per sample, `instrument::sphere`).
    Hemisphere,
    /// The light a d/8 sphere's specular port (a cone of this half-angle, radians, about the mirror of the
    /// viewing direction) takes away: the delta reflectance plus ∫_cone f cos θ dω.
    Port { half_angle: f64 },
}

impl ReadingSpec {
    pub fn quantity(&self) -> &'static str {
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
    pub fn weighting(&self, colour: Conditions) -> WeightingKind {
        match self {
            ReadingSpec::Colour { .. } => WeightingKind::Xyz(colour),
            _ => WeightingKind::Luminous,
        }
    }

    pub fn unit(&self) -> &'static str {
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
    pub fn standard(&self) -> crate::brdf::dielectric::SmoothDielectric {
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
    pub fn standard_reflectance(&self, cos_theta: f64) -> f64 {
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
    pub fn key(&self) -> [u64; 3] {
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

/// A compiled instrument geometry: everything the engine needs, in radians and tangent coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct Geometry {
    pub id: String,
    pub title: String,
    /// Angle of incidence = angle of reflection, radians (0 for purely composite geometries); the
    /// illumination angle of a multi-angle colour geometry, the viewing angle of a sphere.
    pub theta: f64,
    /// The receptor lens axis, radians from the normal, signed (positive on the specular side): θ for gloss
    /// geometries (the receptor looks at the mirror direction), θ − aspecular for multi-angle colour.
    pub viewing: f64,
    /// The scale the readings are on: what the gloss standard is and what it is assigned.
    pub scale: Scale,
    pub source: Stop,
    /// Named receptor stops (all on the receptor lens, offsets inside its focal plane).
    pub receptors: Vec<(String, Stop)>,
    /// Named integrals that are not aperture integrals (a sphere's hemisphere and specular port); empty for
    /// gloss and multi-angle colour geometries.
    pub integrals: Vec<(String, Integral)>,
    pub readings: Vec<ReadingSpec>,
}

impl Geometry {
    pub fn receptor(&self, name: &str) -> Option<&Stop> {
        self.receptors.iter().find(|(n, _)| n == name).map(|(_, s)| s)
    }

    /// The non-aperture integral of this name, if any.
    pub fn integral(&self, name: &str) -> Option<Integral> {
        self.integrals.iter().find(|(n, _)| n == name).map(|(_, i)| *i)
    }

    /// True if the geometry reads colour (its readings are X, Y, Z, L*, a*, b*, C*, h).
    pub fn is_colour(&self) -> bool {
        self.readings.iter().any(|r| matches!(r, ReadingSpec::Colour { .. }))
    }

    /// True if this geometry only combines readings of other geometries (ASTM D4039).
    pub fn is_composite(&self) -> bool {
        self.readings.iter().all(|r| matches!(r, ReadingSpec::HazeIndex { .. }))
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
