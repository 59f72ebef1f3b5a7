//! Thin-film interference in a layer stack. (Signatures fixed; bodies being written.)
use num_complex::Complex64;

/// One layer of a stack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilmLayer {
    /// Complex refractive index n + ik (k ≥ 0).
    pub n: Complex64,
    /// Physical thickness in nm (≥ 0).
    pub thickness_nm: f64,
    /// False for a layer too thick to interfere (e.g. the mica platelet): treated incoherently.
    pub coherent: bool,
}

/// Power reflectance and transmittance of a stack, s and p (transmittance into the exit medium, with the
/// n cos θ factor).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StackResult {
    pub rs: f64,
    pub rp: f64,
    pub ts: f64,
    pub tp: f64,
}

impl StackResult {
    pub fn r(&self) -> f64 {
        0.5 * (self.rs + self.rp)
    }
    pub fn t(&self) -> f64 {
        0.5 * (self.ts + self.tp)
    }
}

/// Reflectance and transmittance of `layers` between a real incident medium `n_in` (light arrives at
/// cos θ = `cos_i`) and an exit medium `n_out` (complex allowed), at `wavelength_nm`.
pub fn stack(n_in: f64, layers: &[FilmLayer], n_out: Complex64, cos_i: f64, wavelength_nm: f64) -> StackResult {
    let _ = (n_in, layers, n_out, cos_i, wavelength_nm);
    todo!()
}
