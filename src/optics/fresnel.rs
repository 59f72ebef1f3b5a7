//! Fresnel equations for dielectric and conducting interfaces. (Signatures fixed; bodies being written.)
use crate::Vec3;
use num_complex::Complex64;

/// Power reflectances and transmittances of a planar interface, s and p polarisation.
/// Transmittances carry the factor (n2 cos θt)/(n1 cos θi) so that R + T = 1 on a lossless interface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FresnelPower {
    pub rs: f64,
    pub rp: f64,
    pub ts: f64,
    pub tp: f64,
}

impl FresnelPower {
    /// Unpolarised reflectance (Rs + Rp)/2.
    pub fn r(&self) -> f64 {
        0.5 * (self.rs + self.rp)
    }
    /// Unpolarised transmittance (Ts + Tp)/2.
    pub fn t(&self) -> f64 {
        0.5 * (self.ts + self.tp)
    }
}

/// Complex amplitude coefficients of an interface (for thin-film stacks).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Amplitudes {
    pub rs: Complex64,
    pub rp: Complex64,
    pub ts: Complex64,
    pub tp: Complex64,
}

/// cos θt by Snell's law for relative index `eta` = n2/n1 and cos θi ∈ [0, 1]; `None` on total internal
/// reflection.
pub fn cos_transmitted(cos_i: f64, eta: f64) -> Option<f64> {
    let _ = (cos_i, eta);
    todo!()
}

/// s/p power coefficients of a dielectric interface, relative index `eta` = n2/n1 > 0, cos θi ∈ [0, 1].
/// Beyond the critical angle Rs = Rp = 1, Ts = Tp = 0.
pub fn fresnel_dielectric(cos_i: f64, eta: f64) -> FresnelPower {
    let _ = (cos_i, eta);
    todo!()
}

/// Unpolarised reflectance of a dielectric interface (pbrt-v4 `FrDielectric`).
pub fn fr_dielectric(cos_i: f64, eta: f64) -> f64 {
    fresnel_dielectric(cos_i, eta).r()
}

/// s/p reflectance of an interface from a real medium into a conductor of relative complex index
/// `eta` = (n + ik)/n1, k ≥ 0. The transmitted wave is the decaying one. Ts, Tp are 1 − Rs, 1 − Rp (absorbed).
pub fn fresnel_conductor(cos_i: f64, eta: Complex64) -> FresnelPower {
    let _ = (cos_i, eta);
    todo!()
}

/// Unpolarised conductor reflectance (pbrt-v4 `FrConductor`).
pub fn fr_conductor(cos_i: f64, eta: Complex64) -> f64 {
    fresnel_conductor(cos_i, eta).r()
}

/// n2·cos θ2 = sqrt(n2² − n1² sin² θ1) for complex indices, with the branch of the decaying (or, for real
/// media, forward-propagating) wave chosen explicitly, signed zeros included. Returns cos θ2.
pub fn complex_cos_transmitted(n1: Complex64, cos1: Complex64, n2: Complex64) -> Complex64 {
    let _ = (n1, cos1, n2);
    todo!()
}

/// Amplitude coefficients r, t (s and p) from medium n1 at cos θ1 into medium n2 at cos θ2.
pub fn amplitudes(n1: Complex64, cos1: Complex64, n2: Complex64, cos2: Complex64) -> Amplitudes {
    let _ = (n1, cos1, n2, cos2);
    todo!()
}

/// The direction inside a medium of relative index `eta` = n2/n1 of a ray that crosses a smooth interface
/// with normal +z along the exterior direction `w` (z > 0). The result also points away from the surface
/// (z > 0): the same ray path, seen from inside. `None` on total internal reflection (possible when eta < 1).
pub fn refract_into(w: Vec3, eta: f64) -> Option<Vec3> {
    let _ = (w, eta);
    todo!()
}
