//! The two-dimensional power spectral density of a levelled map and its radial average (docs/topography.md
//! §Power spectral density).
//!
//! With the map's discrete Fourier transform Z(k) = Σₙ z(n) e^{−2πi(kₓnₓ/Nₓ + k_yn_y/N_y)} (rustfft, the
//! scalar planner, so the same bits on every machine), the PSD at the spatial frequency
//! f = (kₓ/(NₓΔx), k_y/(N_yΔy)) is
//!   S(f) = Δx·Δy·|Z(k)|² / (Nₓ·N_y) · (N / N_valid),
//! two-sided, in m⁴ (m² of height per 1/m² of frequency), so that Σ_k S(f_k)·Δfₓ·Δf_y = ⟨z²⟩ = Sq² exactly
//! (Parseval), Δfₓ = 1/(NₓΔx). Invalid points are set to the reference surface (0) and the factor N/N_valid
//! restores the power of the valid ones. The map is taken as one period (no window), which is why it is
//! levelled first: a tilt left in would leak as an edge step into every frequency.
use rustfft::num_complex::Complex64;
use rustfft::FftPlannerScalar;
use std::f64::consts::PI;

use crate::optics::kirchhoff::signed_bin;

/// The 2-D PSD on the map's frequency grid.
#[derive(Clone, Debug, PartialEq)]
pub struct Psd2 {
    pub nx: usize,
    pub ny: usize,
    /// The frequency steps, 1/m: Δfₓ = 1/(NₓΔx), Δf_y = 1/(N_yΔy).
    pub dfx: f64,
    pub dfy: f64,
    /// S at (kₓ, k_y), m⁴, at `s[k_y·nx + kₓ]` in the transform's order (index k above N/2 is the frequency
    /// k − N).
    pub s: Vec<f64>,
}

/// One annulus of the radial average.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadialBin {
    /// The mean |f| of the grid frequencies in the annulus, 1/m.
    pub f: f64,
    /// The mean of S over them, m⁴.
    pub s: f64,
    /// How many grid frequencies the annulus holds.
    pub count: usize,
}

/// The PSD of levelled heights `z` (nx × ny, NaN: invalid; spacings dx, dy in metres).
pub fn psd(z: &[f64], nx: usize, ny: usize, dx: f64, dy: f64) -> Psd2 {
    let n = nx * ny;
    let valid = z.iter().filter(|v| !v.is_nan()).count().max(1);
    let mut rows: Vec<Complex64> = z.iter().map(|&v| Complex64::new(if v.is_nan() { 0.0 } else { v }, 0.0)).collect();
    let mut planner = FftPlannerScalar::<f64>::new();
    planner.plan_fft_forward(nx).process(&mut rows);
    // Columns: transpose (ny fastest), transform, and read back by (kₓ, k_y).
    let mut cols = vec![Complex64::new(0.0, 0.0); n];
    for j in 0..ny {
        for i in 0..nx {
            cols[i * ny + j] = rows[j * nx + i];
        }
    }
    planner.plan_fft_forward(ny).process(&mut cols);
    let scale = dx * dy / n as f64 * (n as f64 / valid as f64);
    let mut s = vec![0.0; n];
    for ky in 0..ny {
        for kx in 0..nx {
            s[ky * nx + kx] = cols[kx * ny + ky].norm_sqr() * scale;
        }
    }
    Psd2 { nx, ny, dfx: 1.0 / (nx as f64 * dx), dfy: 1.0 / (ny as f64 * dy), s }
}

/// The heights `z` (nx × ny, NaN: invalid, left invalid) low-passed below `f_s` (1/m): every mode of the
/// map's transform with |f| ≥ f_s set to zero and the transform inverted, the long-wave part of the two-scale
/// split (docs/optics.md §Two-scale surface of a measured map). The map is one period, as for [`psd`].
pub(crate) fn low_pass(z: &[f64], nx: usize, ny: usize, dx: f64, dy: f64, f_s: f64) -> Vec<f64> {
    let n = nx * ny;
    let mut rows: Vec<Complex64> = z.iter().map(|&v| Complex64::new(if v.is_nan() { 0.0 } else { v }, 0.0)).collect();
    let mut planner = FftPlannerScalar::<f64>::new();
    let (fwd_x, fwd_y) = (planner.plan_fft_forward(nx), planner.plan_fft_forward(ny));
    let (inv_x, inv_y) = (planner.plan_fft_inverse(nx), planner.plan_fft_inverse(ny));
    fwd_x.process(&mut rows);
    let mut cols = vec![Complex64::new(0.0, 0.0); n];
    for j in 0..ny {
        for i in 0..nx {
            cols[i * ny + j] = rows[j * nx + i];
        }
    }
    fwd_y.process(&mut cols);
    let (dfx, dfy) = (1.0 / (nx as f64 * dx), 1.0 / (ny as f64 * dy));
    for kx in 0..nx {
        for ky in 0..ny {
            let f = (signed_bin(kx, nx) as f64 * dfx).hypot(signed_bin(ky, ny) as f64 * dfy);
            if f >= f_s {
                cols[kx * ny + ky] = Complex64::new(0.0, 0.0);
            }
        }
    }
    inv_y.process(&mut cols);
    for j in 0..ny {
        for i in 0..nx {
            rows[j * nx + i] = cols[i * ny + j];
        }
    }
    inv_x.process(&mut rows);
    z.iter().zip(&rows).map(|(v, c)| if v.is_nan() { f64::NAN } else { c.re / n as f64 }).collect()
}

impl Psd2 {
    /// The frequency of grid point (kₓ, k_y), 1/m.
    pub fn frequency(&self, kx: usize, ky: usize) -> (f64, f64) {
        (signed_bin(kx, self.nx) as f64 * self.dfx, signed_bin(ky, self.ny) as f64 * self.dfy)
    }

    /// Σ S·Δfₓ·Δf_y over the grid: Sq² (Parseval).
    pub fn power(&self) -> f64 {
        self.s.iter().sum::<f64>() * self.dfx * self.dfy
    }

    /// The rms slope of the band the grid holds, √(Σ (2π|f|)² S Δfₓ Δf_y): the spectral counterpart of Sdq,
    /// without the finite difference's attenuation of the shortest waves.
    pub fn rms_slope(&self) -> f64 {
        let mut sum = 0.0;
        for ky in 0..self.ny {
            for kx in 0..self.nx {
                let (fx, fy) = self.frequency(kx, ky);
                sum += (2.0 * PI).powi(2) * (fx * fx + fy * fy) * self.s[ky * self.nx + kx];
            }
        }
        (sum * self.dfx * self.dfy).sqrt()
    }

    /// Σ w(|f|)·(2π|f|)^j·S(f)·Δfₓ·Δf_y over the grid frequencies with lo ≤ |f| < hi (1/m): the power (j = 0,
    /// m²) or the mean-square slope (j = 2, rad²) of that band of the map, each mode weighted by w (a filter's
    /// power transfer, 1 for the map itself).
    pub(crate) fn weighted_moment(&self, j: i32, lo: f64, hi: f64, w: impl Fn(f64) -> f64) -> f64 {
        let mut sum = 0.0;
        for ky in 0..self.ny {
            for kx in 0..self.nx {
                let (fx, fy) = self.frequency(kx, ky);
                let f = fx.hypot(fy);
                if f >= lo && f < hi {
                    sum += w(f) * (2.0 * PI * f).powi(j) * self.s[ky * self.nx + kx];
                }
            }
        }
        sum * self.dfx * self.dfy
    }

    /// The radial (azimuthal) average: annuli of width Δf = max(Δfₓ, Δf_y) centred on multiples of Δf, each
    /// the mean of S over the grid frequencies in it. For an isotropic surface it estimates S(|f|), with
    /// ∫₀^∞ 2πf S(f) df = Sq²; on the grid, Σ S̄·count·Δfₓ·Δf_y = Sq² exactly. Annuli beyond the smaller Nyquist
    /// frequency hold only the grid's corners.
    pub fn radial(&self) -> Vec<RadialBin> {
        let df = self.dfx.max(self.dfy);
        let mut bins: Vec<(f64, f64, usize)> = Vec::new();
        for ky in 0..self.ny {
            for kx in 0..self.nx {
                let (fx, fy) = self.frequency(kx, ky);
                let f = fx.hypot(fy);
                let b = (f / df).round() as usize;
                if bins.len() <= b {
                    bins.resize(b + 1, (0.0, 0.0, 0));
                }
                bins[b].0 += f;
                bins[b].1 += self.s[ky * self.nx + kx];
                bins[b].2 += 1;
            }
        }
        bins.into_iter()
            .filter(|b| b.2 > 0)
            .map(|(f, s, c)| RadialBin { f: f / c as f64, s: s / c as f64, count: c })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parseval_holds_and_a_sinusoid_puts_its_power_at_its_frequency() {
        let (nx, ny, dx, dy, a) = (64, 32, 1e-6, 2e-6, 1e-7);
        // 4 periods along x and 3 along y.
        let z: Vec<f64> = (0..ny)
            .flat_map(|j| (0..nx).map(move |i| (i, j)))
            .map(|(i, j)| a * (2.0 * PI * (4.0 * i as f64 / nx as f64 + 3.0 * j as f64 / ny as f64)).cos())
            .collect();
        let p = psd(&z, nx, ny, dx, dy);
        let sq2 = a * a / 2.0;
        assert!((p.power() - sq2).abs() < 1e-12 * sq2);
        // Two delta peaks of power Sq²/2 each at ±f.
        let peak = p.s[3 * nx + 4] * p.dfx * p.dfy;
        assert!((peak - sq2 / 2.0).abs() < 1e-12 * sq2, "{peak}");
        let (fx, fy) = p.frequency(4, 3);
        let slope = 2.0 * PI * fx.hypot(fy) * a / 2f64.sqrt();
        assert!((p.rms_slope() - slope).abs() < 1e-10 * slope);
        let radial = p.radial();
        let total: f64 = radial.iter().map(|b| b.s * b.count as f64).sum::<f64>() * p.dfx * p.dfy;
        assert!((total - sq2).abs() < 1e-12 * sq2);
        // The weighted moments: unit weight gives the power and the slope; a band that excludes the peak, 0; a
        // weight scales the peak's power by its value at the peak's frequency.
        let f = fx.hypot(fy);
        assert!((p.weighted_moment(0, 0.0, f64::INFINITY, |_| 1.0) - sq2).abs() < 1e-12 * sq2);
        assert!((p.weighted_moment(2, 0.0, f64::INFINITY, |_| 1.0).sqrt() - slope).abs() < 1e-10 * slope);
        assert!(p.weighted_moment(0, 0.0, 0.5 * f, |_| 1.0) < 1e-12 * sq2);
        let w = p.weighted_moment(0, 0.5 * f, 2.0 * f, |g| if (g - f).abs() < 1e-9 * f { 0.25 } else { 0.0 });
        assert!((w - 0.25 * sq2).abs() < 1e-12 * sq2, "{w}");
    }

    #[test]
    fn low_pass_keeps_the_long_waves_and_removes_the_short() {
        let (nx, ny, dx, dy) = (32, 16, 1e-6, 1e-6);
        let wave = |kx: f64, ky: f64, i: usize, j: usize| {
            (2.0 * PI * (kx * i as f64 / nx as f64 + ky * j as f64 / ny as f64)).cos()
        };
        let long: Vec<f64> =
            (0..ny).flat_map(|j| (0..nx).map(move |i| 3.0 * wave(1.0, 1.0, i, j) + wave(2.0, 0.0, i, j))).collect();
        let z: Vec<f64> = (0..ny)
            .flat_map(|j| (0..nx).map(move |i| (i, j)))
            .zip(&long)
            .map(|((i, j), l)| l + 0.1 * wave(9.0, 5.0, i, j))
            .collect();
        // The split at 0.2/µm: (1, 1) is at 0.07/µm, (2, 0) at 0.06/µm, (9, 5) at 0.43/µm.
        let low = low_pass(&z, nx, ny, dx, dy, 0.2e6);
        assert!(low.iter().zip(&long).all(|(a, b)| (a - b).abs() < 1e-12), "{:?}", &low[..4]);
        let all = low_pass(&z, nx, ny, dx, dy, f64::INFINITY);
        assert!(all.iter().zip(&z).all(|(a, b)| (a - b).abs() < 1e-12));
        assert!(low_pass(&z, nx, ny, dx, dy, 0.0).iter().all(|v| v.abs() < 1e-12));
    }

    #[test]
    fn invalid_points_keep_the_power_of_the_valid_ones() {
        let mut z: Vec<f64> = (0..256).map(|k| ((k * 7919) % 13) as f64 - 6.0).collect();
        z[5] = f64::NAN;
        z[77] = f64::NAN;
        let sq2 = z.iter().filter(|v| !v.is_nan()).map(|v| v * v).sum::<f64>() / 254.0;
        let p = psd(&z, 16, 16, 1.0, 1.0);
        assert!((p.power() - sq2).abs() < 1e-12 * sq2);
    }
}
