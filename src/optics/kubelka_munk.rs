//! Kubelka–Munk two-flux theory. (Signatures fixed; bodies being written.)

/// Reflectance of an infinitely thick layer, R∞ = 1 + K/S − sqrt((K/S)² + 2K/S) (paper Eq. 4), evaluated
/// free of cancellation for K/S up to 1e12 and beyond.
pub fn r_infinity(k_over_s: f64) -> f64 {
    let _ = k_over_s;
    todo!()
}

/// Diffuse reflectance (over black) and transmittance of a layer with absorption K, scattering S and
/// thickness X (K, S in inverse units of X). Over a background of reflectance Rg the layer reflects
/// R = r0 + t²·Rg / (1 − r0·Rg), which equals the corrected paper Eq. (3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layer {
    pub r0: f64,
    pub t: f64,
}

impl Layer {
    /// Reflectance of the layer over a background of reflectance `rg` ∈ [0, 1].
    pub fn over(&self, rg: f64) -> f64 {
        let _ = rg;
        todo!()
    }
}

/// The layer operator for K, S ≥ 0 and X ≥ 0, exact for S·X → 0, S·X → ∞ (no overflow), K = 0 and S = 0.
pub fn layer(k: f64, s: f64, x: f64) -> Layer {
    let _ = (k, s, x);
    todo!()
}

/// Reflectance of a layer over a background (paper Eq. 3, corrected), = `layer(k, s, x).over(rg)`.
pub fn layer_reflectance(k: f64, s: f64, x: f64, rg: f64) -> f64 {
    layer(k, s, x).over(rg)
}

/// Mixing by concentration: K = Σ Cᵢ Kᵢ, S = Σ Cᵢ Sᵢ (Duncan's rule). Items are (C, K, S).
pub fn mix(pigments: impl IntoIterator<Item = (f64, f64, f64)>) -> (f64, f64) {
    pigments.into_iter().fold((0.0, 0.0), |(k, s), (c, ki, si)| (k + c * ki, s + c * si))
}

/// K and S of a layer of thickness `x` from its reflectance over a white background of reflectance
/// `white_bg` and over an ideal black background (Curtis et al. 1997 §4 generalised to a non-ideal white).
pub fn invert_white_black(r_over_white: f64, r_over_black: f64, white_bg: f64, x: f64) -> Result<(f64, f64), String> {
    let _ = (r_over_white, r_over_black, white_bg, x);
    todo!()
}
