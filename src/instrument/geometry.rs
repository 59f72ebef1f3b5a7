//! Instrument geometry: apertures as field stops in the focal planes of collimating lenses, and the map
//! from a point of a stop to a direction.
//!
//! The model (stated in full in `docs/instrument.md`): specimen normal z, plane of measurement x–z. For a
//! geometry of angle θ the source axis (pointing towards the source) is s0 = (−sin θ, 0, cos θ) and the
//! receptor axis r0 = (sin θ, 0, cos θ). A point (p, q) of a stop, in tangent coordinates (p = x/f, q = y/f),
//! is the direction normalize(axis + p·e∥ + q·e⊥) with e⊥ = (0, 1, 0), e∥ = e⊥ × axis, and solid-angle
//! element dω = dp dq / (1 + p² + q²)^{3/2}. The mirror image of source point (p, q) is receptor point
//! (−p, −q), so the specular manifold is p_s + p_r = 0, q_s + q_r = 0.
use crate::instrument::reading::{ReadingSpec, Scale};
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
    pub(crate) fn integral(&self, name: &str) -> Option<Integral> {
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
