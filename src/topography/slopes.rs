//! The local slopes of a map and their distribution (docs/topography.md §Slopes): one slope per cell of four
//! valid points, the gradient of the bilinear surface through them at the cell's centre,
//! ∂z/∂x = (z₁₀ − z₀₀ + z₁₁ − z₀₁)/(2Δx), ∂z/∂y = (z₀₁ − z₀₀ + z₁₁ − z₁₀)/(2Δy) (second-order accurate there);
//! Sdq = √⟨|∇z|²⟩ and Sdr = ⟨√(1 + |∇z|²)⟩ − 1 (ISO 25178-2) as means over the cells, and the histogram of
//! the slope angle atan|∇z|.
use crate::{Error, Result};

/// The cells' slopes (dz/dx, dz/dy), in row order of the cells with four valid corners.
#[derive(Clone, Debug, PartialEq)]
pub struct Slopes {
    pub sx: Vec<f64>,
    pub sy: Vec<f64>,
}

/// The slope parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlopeStats {
    /// Root mean square gradient Sdq = √⟨(∂z/∂x)² + (∂z/∂y)²⟩.
    pub sdq: f64,
    /// The rms slopes along x and y, √⟨(∂z/∂x)²⟩ and √⟨(∂z/∂y)²⟩ (Sdq² is the sum of their squares).
    pub rms_x: f64,
    pub rms_y: f64,
    /// The mean slopes (a tilt left by the levelling).
    pub mean_x: f64,
    pub mean_y: f64,
    /// Developed interfacial area ratio Sdr = ⟨√(1 + |∇z|²)⟩ − 1.
    pub sdr: f64,
    /// The steepest cell's slope angle, degrees.
    pub max_angle_deg: f64,
    /// The cells the means are over.
    pub cells: usize,
}

/// The slope of every cell of four valid points of the heights `z` (nx × ny, NaN: invalid; spacings dx, dy).
pub fn slopes(z: &[f64], nx: usize, ny: usize, dx: f64, dy: f64, file: &str) -> Result<Slopes> {
    let mut s = Slopes { sx: Vec::new(), sy: Vec::new() };
    for j in 0..ny.saturating_sub(1) {
        for i in 0..nx - 1 {
            let (z00, z10, z01, z11) = (z[j * nx + i], z[j * nx + i + 1], z[(j + 1) * nx + i], z[(j + 1) * nx + i + 1]);
            if z00.is_nan() || z10.is_nan() || z01.is_nan() || z11.is_nan() {
                continue;
            }
            s.sx.push((z10 - z00 + z11 - z01) / (2.0 * dx));
            s.sy.push((z01 - z00 + z11 - z10) / (2.0 * dy));
        }
    }
    if s.sx.is_empty() {
        return Err(Error::input(
            file,
            "",
            "no cell of 2 × 2 valid points: the map's slopes cannot be read (too many invalid points)",
        ));
    }
    Ok(s)
}

impl Slopes {
    /// The slope parameters.
    pub fn stats(&self) -> SlopeStats {
        let n = self.sx.len() as f64;
        let (mut sxx, mut syy, mut mx, mut my, mut area, mut max) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0f64);
        for (&a, &b) in self.sx.iter().zip(&self.sy) {
            sxx += a * a;
            syy += b * b;
            mx += a;
            my += b;
            let g2 = a * a + b * b;
            // √(1 + g²) − 1 without the cancellation of small slopes.
            area += g2 / ((1.0 + g2).sqrt() + 1.0);
            max = max.max(g2);
        }
        SlopeStats {
            sdq: ((sxx + syy) / n).sqrt(),
            rms_x: (sxx / n).sqrt(),
            rms_y: (syy / n).sqrt(),
            mean_x: mx / n,
            mean_y: my / n,
            sdr: area / n,
            max_angle_deg: max.sqrt().atan().to_degrees(),
            cells: self.sx.len(),
        }
    }

    /// The histogram of the slope angle atan|∇z| in `bins` bins of `width_deg` degrees from 0: the fraction of
    /// the cells in each (the last bin takes every steeper cell).
    pub fn angle_histogram(&self, width_deg: f64, bins: usize) -> Vec<f64> {
        let mut h = vec![0.0; bins];
        for (&a, &b) in self.sx.iter().zip(&self.sy) {
            let angle = a.hypot(b).atan().to_degrees();
            let k = ((angle / width_deg) as usize).min(bins - 1);
            h[k] += 1.0;
        }
        let n = self.sx.len() as f64;
        h.iter_mut().for_each(|v| *v /= n);
        h
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn grid(nx: usize, ny: usize, dx: f64, dy: f64, f: impl Fn(f64, f64) -> f64) -> Vec<f64> {
        (0..ny).flat_map(|j| (0..nx).map(move |i| (i, j))).map(|(i, j)| f(i as f64 * dx, j as f64 * dy)).collect()
    }

    #[test]
    fn a_tilted_plane_has_sdq_the_tangent_of_its_tilt() {
        let (tx, ty) = (5f64.to_radians().tan(), 3f64.to_radians().tan());
        let z = grid(12, 7, 1e-6, 2e-6, |x, y| tx * x + ty * y);
        let s = slopes(&z, 12, 7, 1e-6, 2e-6, "t").unwrap().stats();
        assert!((s.sdq - tx.hypot(ty)).abs() < 1e-12 * s.sdq, "{}", s.sdq);
        assert!((s.mean_x - tx).abs() < 1e-12 && (s.mean_y - ty).abs() < 1e-12);
        assert!((s.sdr - ((1.0 + tx * tx + ty * ty).sqrt() - 1.0)).abs() < 1e-12);
        assert!((s.max_angle_deg - tx.hypot(ty).atan().to_degrees()).abs() < 1e-9);
    }

    #[test]
    fn a_sinusoid_has_the_sampled_closed_form_of_its_rms_slope() {
        // z = A sin(2πx/λ) over whole periods: the cells' slope is the centred difference of spacing Δ at the cell
        // centre, A·(2/Δ)·sin(πΔ/λ)·cos(...), so Sdq = (2A/Δ)·sin(πΔ/λ)/√2, which tends to 2πA/(λ√2).
        // 1025 points: 1024 cells, 16 whole periods of 64 cells, over which the mean of cos² is exactly 1/2.
        let (a, lambda, n) = (0.2e-6, 64e-6, 1025);
        let dx = lambda / 64.0;
        let z = grid(n, 3, dx, dx, |x, _| a * (2.0 * PI * x / lambda).sin());
        let s = slopes(&z, n, 3, dx, dx, "t").unwrap().stats();
        let sampled = 2.0 * a / dx * (PI * dx / lambda).sin() / 2f64.sqrt();
        let continuous = 2.0 * PI * a / (lambda * 2f64.sqrt());
        assert!((s.sdq - sampled).abs() < 1e-12 * sampled, "{} {}", s.sdq, sampled);
        // The sampling's bias, 1 − sin(πΔ/λ)/(πΔ/λ) ≈ (πΔ/λ)²/6 = 4.0e-4 here.
        assert!((s.sdq - continuous).abs() < 5e-4 * continuous && s.sdq < continuous);
        assert!(s.rms_y.abs() < 1e-15);
    }

    #[test]
    fn cells_with_an_invalid_corner_are_left_out() {
        let mut z = grid(3, 3, 1.0, 1.0, |x, _| x);
        z[4] = f64::NAN;
        assert!(slopes(&z, 3, 3, 1.0, 1.0, "t").unwrap_err().to_string().contains("no cell"));
        let z = grid(3, 3, 1.0, 1.0, |x, _| x);
        let h = slopes(&z, 3, 3, 1.0, 1.0, "t").unwrap().angle_histogram(10.0, 9);
        assert_eq!(h[4], 1.0); // 45°
    }
}
