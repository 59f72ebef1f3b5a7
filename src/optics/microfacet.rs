//! Microfacet distributions (Beckmann, GGX) with Smith masking. (Signatures fixed; bodies being written.)
use crate::Vec3;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Distribution {
    Beckmann,
    Ggx,
}

/// Masking-shadowing function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shadowing {
    /// Smith, height-correlated: G = 1 / (1 + Λ(ωi) + Λ(ωo)) (Heitz 2014, Eq. 99). The default.
    SmithHeightCorrelated,
    /// Cook & Torrance (1982) V-cavity: G = min(1, 2 cosθh cosθo / (ωo·h), 2 cosθh cosθi / (ωi·h)).
    VCavity,
}

/// An isotropic microfacet distribution of roughness `alpha` (Beckmann rms slope m, or GGX α).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    pub distribution: Distribution,
    pub alpha: f64,
}

impl Microfacet {
    /// Below this roughness the lobe is treated as its delta limit (`effectively_smooth`).
    pub const SMOOTH_THRESHOLD: f64 = 1e-7;

    pub fn new(distribution: Distribution, alpha: f64) -> Self {
        Microfacet { distribution, alpha }
    }

    pub fn effectively_smooth(&self) -> bool {
        self.alpha < Self::SMOOTH_THRESHOLD
    }

    /// Normalised distribution of normals, ∫ D(h) cos θh dω = 1; tan²θh from components.
    pub fn d(&self, h: Vec3) -> f64 {
        let _ = h;
        todo!()
    }

    /// Smith Λ(ω) (Beckmann through erfc).
    pub fn lambda(&self, w: Vec3) -> f64 {
        let _ = w;
        todo!()
    }

    /// G1(ω) = 1 / (1 + Λ(ω)).
    pub fn g1(&self, w: Vec3) -> f64 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Masking-shadowing G(ωi, ωo) for the half vector `h` under the chosen shadowing model.
    pub fn g(&self, wi: Vec3, wo: Vec3, h: Vec3, shadowing: Shadowing) -> f64 {
        let _ = (wi, wo, h, shadowing);
        todo!()
    }
}
