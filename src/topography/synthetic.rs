//! Synthetic surfaces: seeded random-phase height maps from an isotropic PSD (docs/topography.md §Synthetic
//! surfaces), for studies against the wave-optics ground truth (docs/optics.md §11.5).
//!
//! Each component of a surface is z = Re(IFFT(A(f)·e^{iφ_k}))·scale with A(f) = √S(f) on the map's frequency
//! grid (S the family's shape), φ_k uniform on [0, 2π) from SplitMix64 (Steele, Lea & Flood 2014) seeded by
//! the surface's seed and the component's index, A(0) = 0, and `scale` chosen so that the realised rms height
//! is exactly the σ asked for. The same seed gives the same bits on every machine.
use rustfft::num_complex::Complex64;
use rustfft::FftPlannerScalar;
use std::f64::consts::PI;

use crate::optics::kirchhoff::signed_bin;

/// SplitMix64 (Steele, Lea & Flood, "Fast splittable pseudorandom number generators", OOPSLA 2014): the
/// state advances by 0x9E3779B97F4A7C15 and each output is the state mixed by two xor-shift-multiplies.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> SplitMix64 {
        SplitMix64(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform on [0, 1): the top 53 bits.
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// A PSD family (lengths in metres, heights in metres; docs/topography.md §Synthetic surfaces).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Family {
    /// Gaussian correlation, ACF σ²·exp(−r²/ℓ²): S(f) ∝ exp(−π²ℓ²f²).
    Gaussian { sigma: f64, ell: f64 },
    /// K-correlation (ABC): S(f) ∝ 1/(1 + (B f)²)^{(C+1)/2}.
    Abc { sigma: f64, b: f64, c: f64 },
    /// Fractal: S(f) ∝ f^{−α} between the cut-offs f_lo ≤ f ≤ f_hi (1/m), 0 outside.
    Fractal { sigma: f64, alpha: f64, f_lo: f64, f_hi: f64 },
    /// Orange peel: a band of long waves, S ∝ exp(−((f − 1/Λ)/w)²) (Λ the peel's wavelength, w the band's
    /// width, 1/m) of rms σ_long, plus Gaussian micro roughness (σ_micro, ℓ_micro).
    OrangePeel { sigma_long: f64, wavelength: f64, width: f64, sigma_micro: f64, ell_micro: f64 },
}

/// One component of a surface: its rms height and its PSD's shape S(f).
type Component = (f64, Box<dyn Fn(f64) -> f64>);

impl Family {
    /// The components: (rms height, shape S(f)).
    fn components(&self) -> Vec<Component> {
        match *self {
            Family::Gaussian { sigma, ell } => vec![(sigma, Box::new(move |f: f64| (-(PI * ell * f).powi(2)).exp()))],
            Family::Abc { sigma, b, c } => {
                vec![(sigma, Box::new(move |f: f64| (1.0 + (b * f).powi(2)).powf(-(c + 1.0) / 2.0)))]
            }
            Family::Fractal { sigma, alpha, f_lo, f_hi } => {
                vec![(sigma, Box::new(move |f: f64| if f >= f_lo && f <= f_hi { f.powf(-alpha) } else { 0.0 }))]
            }
            Family::OrangePeel { sigma_long, wavelength, width, sigma_micro, ell_micro } => vec![
                (sigma_long, Box::new(move |f: f64| (-((f - 1.0 / wavelength) / width).powi(2)).exp())),
                (sigma_micro, Box::new(move |f: f64| (-(PI * ell_micro * f).powi(2)).exp())),
            ],
        }
    }
}

/// An n × n map, `dx` metres apart, of the family's surface for `seed` (heights in metres, row-major).
pub fn generate(family: &Family, n: usize, dx: f64, seed: u64) -> Vec<f64> {
    let mut z = vec![0.0; n * n];
    for (c, (sigma, shape)) in family.components().into_iter().enumerate() {
        let part = component(&*shape, n, dx, seed.wrapping_add(0x1000_0000 * c as u64));
        let rms = (part.iter().map(|v| v * v).sum::<f64>() / (n * n) as f64).sqrt();
        let scale = if rms > 0.0 { sigma / rms } else { 0.0 };
        for (a, b) in z.iter_mut().zip(&part) {
            *a += b * scale;
        }
    }
    z
}

/// One random-phase component of shape S (any scale), mean 0.
fn component(shape: &dyn Fn(f64) -> f64, n: usize, dx: f64, seed: u64) -> Vec<f64> {
    let mut rng = SplitMix64::new(seed);
    let l = n as f64 * dx;
    let signed = |k: usize| signed_bin(k, n) as f64;
    let mut spec = vec![Complex64::new(0.0, 0.0); n * n];
    for ky in 0..n {
        for kx in 0..n {
            let phase = 2.0 * PI * rng.next_f64();
            if kx == 0 && ky == 0 {
                continue;
            }
            let f = (signed(kx) / l).hypot(signed(ky) / l);
            spec[ky * n + kx] = Complex64::from_polar(shape(f).max(0.0).sqrt(), phase);
        }
    }
    let mut planner = FftPlannerScalar::<f64>::new();
    let fft = planner.plan_fft_inverse(n);
    for row in spec.chunks_mut(n) {
        fft.process(row);
    }
    let mut cols = vec![Complex64::new(0.0, 0.0); n * n];
    for j in 0..n {
        for i in 0..n {
            cols[i * n + j] = spec[j * n + i];
        }
    }
    for col in cols.chunks_mut(n) {
        fft.process(col);
    }
    let mut z = vec![0.0; n * n];
    for j in 0..n {
        for i in 0..n {
            z[j * n + i] = cols[i * n + j].re;
        }
    }
    let mean = z.iter().sum::<f64>() / (n * n) as f64;
    z.iter_mut().for_each(|v| *v -= mean);
    z
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix64_gives_the_reference_sequence() {
        // The first outputs for seed 1234567, computed by a transcription of Vigna's splitmix64.c in Python's
        // arbitrary-precision integers (masking to 64 bits).
        let mut r = SplitMix64::new(1234567);
        assert_eq!(r.next_u64(), 6457827717110365317);
        assert_eq!(r.next_u64(), 3203168211198807973);
    }

    #[test]
    fn a_surface_has_its_sigma_and_the_same_seed_the_same_bits() {
        let fam =
            Family::OrangePeel { sigma_long: 0.3e-6, wavelength: 2e-4, width: 2e3, sigma_micro: 5e-9, ell_micro: 5e-6 };
        let a = generate(&fam, 64, 4e-6, 7);
        let b = generate(&fam, 64, 4e-6, 7);
        assert_eq!(a, b);
        let g = generate(&Family::Gaussian { sigma: 20e-9, ell: 10e-6 }, 64, 2e-6, 3);
        let rms = (g.iter().map(|v| v * v).sum::<f64>() / g.len() as f64).sqrt();
        assert!((rms - 20e-9).abs() < 1e-15, "{rms}");
    }
}
