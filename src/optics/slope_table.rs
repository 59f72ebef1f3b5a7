//! A measured slope distribution as a microfacet distribution: the surface's own slopes (a topography's
//! cells, `topography::slopes`) smoothed into a density P₂₂(x̃, ỹ) of slopes, from which D follows by Heitz's
//! relation D(h) = P₂₂(−h_x/h_z, −h_y/h_z)/h_z⁴ (Heitz 2014 Eq. 9), with no fitted parameter
//! (docs/topography.md §The facet term of a measured surface).
//!
//! * The density: the slopes binned linearly onto a square grid of spacing δ (each slope shared between the
//!   four nodes around it, in proportion to its nearness: "linear binning", Wand & Jones, *Kernel Smoothing*,
//!   1995, §D.2), convolved with a Gaussian kernel of standard deviation h per axis, h by Silverman's rule for
//!   two dimensions, h = σ̄·N^(−1/6) (Silverman, *Density Estimation*, 1986, Eq. 4.14; σ̄² the mean of the two
//!   axes' slope variances, N the slopes), δ = h/2; the nodes' values are the coefficients of a uniform cubic
//!   B-spline surface, which is P₂₂ (C², non-negative).
//! * Its normalisation: the cubic B-spline integrates to δ per axis, so ∫∫P₂₂ = δ²·Σ c = 1 exactly when the
//!   coefficients sum to 1/δ², which they are scaled to. This is the projected-area normalisation
//!   ∫ D(h) cos θh dω = 1 (Heitz 2014 Eq. 4).
//! * Masking: the Smith Λ of the Gaussian slope distribution with the table's own second moments (an
//!   approximation, stated: exact for Gaussian slopes): along the azimuth φ of ω the slopes' variance is
//!   σ_φ² = cos²φ⟨x̃²⟩ + 2 sinφ cosφ⟨x̃ỹ⟩ + sin²φ⟨ỹ²⟩ and Λ is Beckmann's with α = √2·σ_φ (Heitz 2014 Eq. 80;
//!   anisotropic: Eq. 82's projected roughness).
use super::microfacet::{Distribution, Microfacet};
use crate::Vec3;

/// The most nodes along each axis of the table.
pub(crate) const MAX_NODES: usize = 513;

/// A smoothed, normalised 2-D slope density.
#[derive(Clone, Debug, PartialEq)]
pub struct SlopeTable {
    /// Nodes per axis, the first node's slope (both axes) and the spacing δ.
    nodes: usize,
    first: f64,
    step: f64,
    /// B-spline coefficients, `c[j·nodes + i]` at slopes (first + i·δ, first + j·δ).
    c: Vec<f64>,
    /// The kernel's standard deviation h, per axis.
    pub bandwidth: f64,
    /// The density's second moments about the origin: ⟨x̃²⟩, ⟨x̃ỹ⟩, ⟨ỹ²⟩ (the kernel's and the spline's
    /// widths included).
    pub moments: [f64; 3],
    /// How many slopes it was built from.
    pub samples: usize,
}

/// The uniform cubic B-spline of unit spacing (support [−2, 2], integral 1, variance 1/3).
fn b3(t: f64) -> f64 {
    let a = t.abs();
    if a < 1.0 {
        (4.0 - 6.0 * a * a + 3.0 * a * a * a) / 6.0
    } else if a < 2.0 {
        let u = 2.0 - a;
        u * u * u / 6.0
    } else {
        0.0
    }
}

impl SlopeTable {
    /// The table of the slopes (x̃ᵢ, ỹᵢ) (dz/dx, dz/dy); `Err` with the reason if they are too few, not finite,
    /// or all zero (a mirror has no facet distribution).
    pub fn from_slopes(sx: &[f64], sy: &[f64]) -> Result<SlopeTable, String> {
        let n = sx.len();
        if n < 16 || sy.len() != n {
            return Err(format!("{n} slopes; at least 16 are needed to estimate a slope distribution"));
        }
        if sx.iter().chain(sy).any(|v| !v.is_finite()) {
            return Err("a slope is not a finite number".into());
        }
        let var = |s: &[f64]| s.iter().map(|v| v * v).sum::<f64>() / n as f64;
        let sigma = ((var(sx) + var(sy)) / 2.0).sqrt();
        if !(sigma >= Microfacet::SMOOTH_THRESHOLD) {
            return Err(format!(
                "the rms slope is {}: the surface is a mirror at this sampling, with no facet distribution",
                crate::error::number(sigma * 2f64.sqrt())
            ));
        }
        let h = sigma * (n as f64).powf(-1.0 / 6.0);
        let reach = sx.iter().chain(sy).fold(0.0f64, |a, v| a.max(v.abs())) + 5.0 * h;
        // δ = h/2, coarser only if the nodes would exceed MAX_NODES (slopes far out in the tail).
        let mut step = h / 2.0;
        let half = |step: f64| ((reach / step).ceil() as usize) + 2;
        if 2 * half(step) + 1 > MAX_NODES {
            step = reach / ((MAX_NODES - 1) / 2 - 2) as f64;
        }
        let k = half(step);
        let nodes = 2 * k + 1;
        let first = -(k as f64) * step;
        // Linear binning.
        let mut grid = vec![0.0; nodes * nodes];
        for (&x, &y) in sx.iter().zip(sy) {
            let (tx, ty) = ((x - first) / step, (y - first) / step);
            let (i, j) = (tx.floor() as usize, ty.floor() as usize);
            let (fx, fy) = (tx - i as f64, ty - j as f64);
            grid[j * nodes + i] += (1.0 - fx) * (1.0 - fy);
            grid[j * nodes + i + 1] += fx * (1.0 - fy);
            grid[(j + 1) * nodes + i] += (1.0 - fx) * fy;
            grid[(j + 1) * nodes + i + 1] += fx * fy;
        }
        // The Gaussian kernel on the nodes, truncated at 5h and normalised to sum 1 (mass kept exactly).
        let r = (5.0 * h / step).ceil() as isize;
        let mut kernel: Vec<f64> = (-r..=r).map(|m| (-0.5 * (m as f64 * step / h).powi(2)).exp()).collect();
        let total: f64 = kernel.iter().sum();
        kernel.iter_mut().for_each(|v| *v /= total);
        let convolve = |src: &[f64], along_x: bool| -> Vec<f64> {
            let mut out = vec![0.0; nodes * nodes];
            for j in 0..nodes {
                for i in 0..nodes {
                    let v = src[j * nodes + i];
                    if v == 0.0 {
                        continue;
                    }
                    for (m, w) in (-r..=r).zip(&kernel) {
                        let (ii, jj) =
                            if along_x { (i as isize + m, j as isize) } else { (i as isize, j as isize + m) };
                        if ii >= 0 && jj >= 0 && (ii as usize) < nodes && (jj as usize) < nodes {
                            out[jj as usize * nodes + ii as usize] += v * w;
                        }
                    }
                }
            }
            out
        };
        let mut c = convolve(&convolve(&grid, true), false);
        let mass: f64 = c.iter().sum();
        let scale = 1.0 / (mass * step * step);
        c.iter_mut().for_each(|v| *v *= scale);
        // The moments of the spline surface: the coefficients' moments plus the B-spline's variance δ²/3.
        let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
        for j in 0..nodes {
            let y = first + j as f64 * step;
            for i in 0..nodes {
                let x = first + i as f64 * step;
                let w = c[j * nodes + i] * step * step;
                xx += w * x * x;
                xy += w * x * y;
                yy += w * y * y;
            }
        }
        let spline = step * step / 3.0;
        Ok(SlopeTable { nodes, first, step, c, bandwidth: h, moments: [xx + spline, xy, yy + spline], samples: n })
    }

    /// The slope density P₂₂(x̃, ỹ), per unit slope² (0 outside the table).
    pub(crate) fn p22(&self, x: f64, y: f64) -> f64 {
        let (tx, ty) = ((x - self.first) / self.step, (y - self.first) / self.step);
        let last = (self.nodes - 1) as f64;
        if !(tx > -2.0 && ty > -2.0 && tx < last + 2.0 && ty < last + 2.0) {
            return 0.0;
        }
        let (i0, j0) = (tx.floor() as isize, ty.floor() as isize);
        let mut s = 0.0;
        for dj in -1..=2 {
            let j = j0 + dj;
            if j < 0 || j as usize >= self.nodes {
                continue;
            }
            let wy = b3(ty - j as f64);
            let mut row = 0.0;
            for di in -1..=2 {
                let i = i0 + di;
                if i < 0 || i as usize >= self.nodes {
                    continue;
                }
                row += self.c[j as usize * self.nodes + i as usize] * b3(tx - i as f64);
            }
            s += wy * row;
        }
        s
    }

    /// The distribution of normals D(h) = P₂₂(−h_x/h_z, −h_y/h_z)/h_z⁴ (Heitz 2014 Eq. 9); 0 for h_z ≤ 0.
    pub(crate) fn d(&self, h: Vec3) -> f64 {
        let len = h.length();
        if !(h.z > 0.0 && len > 0.0) {
            return 0.0;
        }
        let cos = h.z / len;
        let p = self.p22(-h.x / h.z, -h.y / h.z);
        if p == 0.0 {
            0.0
        } else {
            p / (cos * cos * cos * cos)
        }
    }

    /// The Gaussian-equivalent α along the azimuth of ω: √2·σ_φ (for ω along the normal, the mean of the two
    /// axes').
    pub(crate) fn alpha_along(&self, w: Vec3) -> f64 {
        let r2 = w.x * w.x + w.y * w.y;
        let [xx, xy, yy] = self.moments;
        let var =
            if r2 > 0.0 { (w.x * w.x * xx + 2.0 * w.x * w.y * xy + w.y * w.y * yy) / r2 } else { (xx + yy) / 2.0 };
        (2.0 * var.max(0.0)).sqrt()
    }

    /// Smith Λ(ω) as it enters G: Beckmann's with the Gaussian-equivalent α along ω's azimuth.
    pub(crate) fn lambda(&self, w: Vec3) -> f64 {
        Microfacet::new(Distribution::Beckmann, self.alpha_along(w)).lambda_in_g(w)
    }

    /// The lobe's width for the planner: the largest Gaussian-equivalent α over the azimuths, √(2·λ_max) with
    /// λ_max the larger eigenvalue of the moment matrix.
    pub(crate) fn width(&self) -> f64 {
        let [xx, xy, yy] = self.moments;
        let mean = (xx + yy) / 2.0;
        let lmax = mean + (((xx - yy) / 2.0).powi(2) + xy * xy).sqrt();
        (2.0 * lmax).sqrt()
    }

    /// The rms slope of the density, √(⟨x̃²⟩ + ⟨ỹ²⟩) (the map's Sdq widened by the kernel and the spline:
    /// ≈ √(Sdq² + 2h² + 2δ²/3 + …)).
    pub fn rms_slope(&self) -> f64 {
        (self.moments[0] + self.moments[2]).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Slopes of a Gaussian distribution of rms slope m (each axis m/√2): a deterministic quasi-random set
    /// (the Box–Muller map of a 2-D Halton sequence).
    pub(crate) fn gaussian_slopes(m: f64, n: usize) -> (Vec<f64>, Vec<f64>) {
        let halton = |mut i: usize, b: usize| {
            let (mut f, mut r) = (1.0, 0.0);
            while i > 0 {
                f /= b as f64;
                r += f * (i % b) as f64;
                i /= b;
            }
            r
        };
        let s = m / 2f64.sqrt();
        (1..=n)
            .map(|i| {
                let (u, v) = (halton(i, 2), halton(i, 3));
                let rad = (-2.0 * u.ln()).sqrt() * s;
                (rad * (2.0 * PI * v).cos(), rad * (2.0 * PI * v).sin())
            })
            .unzip()
    }

    #[test]
    fn the_density_integrates_to_one_and_its_moments_are_the_splines() {
        let (sx, sy) = gaussian_slopes(0.1, 4000);
        let t = SlopeTable::from_slopes(&sx, &sy).unwrap();
        // ∫∫ P₂₂ by the midpoint rule over the table's support, and its second moment.
        let (lo, hi, n) = (t.first - 2.0 * t.step, -t.first + 2.0 * t.step, 800);
        let d = (hi - lo) / n as f64;
        let (mut mass, mut xx) = (0.0, 0.0);
        for j in 0..n {
            for i in 0..n {
                let (x, y) = (lo + (i as f64 + 0.5) * d, lo + (j as f64 + 0.5) * d);
                let p = t.p22(x, y);
                mass += p * d * d;
                xx += p * x * x * d * d;
            }
        }
        assert!((mass - 1.0).abs() < 1e-6, "{mass}");
        assert!((xx - t.moments[0]).abs() < 1e-5 * t.moments[0], "{xx} {:?}", t.moments);
        // The rms slope: the samples' widened by the kernel (2h²) and the spline and binning (≈ δ²).
        let sample = (sx.iter().chain(&sy).map(|v| v * v).sum::<f64>() / sx.len() as f64).sqrt();
        let widened = (sample * sample + 2.0 * t.bandwidth * t.bandwidth).sqrt();
        assert!((t.rms_slope() - widened).abs() < 0.02 * widened, "{} {widened}", t.rms_slope());
    }

    #[test]
    fn projected_area_normalisation_holds() {
        // ∫ D(h) cos θh dω = 1 over the hemisphere (Heitz 2014 Eq. 4), by a product rule in (θ, φ).
        let (sx, sy) = gaussian_slopes(0.2, 4000);
        let t = SlopeTable::from_slopes(&sx, &sy).unwrap();
        let (nt, np) = (2000, 256);
        let mut s = 0.0;
        let tmax = 1.2f64; // D is 0 beyond the table's slopes, tan 1.2 rad ≫ the widest slope.
        for a in 0..nt {
            let th = (a as f64 + 0.5) * tmax / nt as f64;
            for b in 0..np {
                let ph = (b as f64 + 0.5) * 2.0 * PI / np as f64;
                let h = Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                s += t.d(h) * th.cos() * th.sin() * (tmax / nt as f64) * (2.0 * PI / np as f64);
            }
        }
        assert!((s - 1.0).abs() < 1e-4, "{s}");
    }

    #[test]
    fn gaussian_slopes_give_beckmanns_d_and_lambda() {
        // A table of Gaussian slopes, rms m, against Beckmann of the table's own rms slope: D within 2 % over
        // two widths of the centre (the estimate's error: the quasi-random set is not exactly Gaussian in a
        // finite sample), Λ the same bits (the same formula on the isotropic moments).
        let (sx, sy) = gaussian_slopes(0.1, 20000);
        let t = SlopeTable::from_slopes(&sx, &sy).unwrap();
        let m = t.rms_slope();
        let beckmann = Microfacet::new(Distribution::Beckmann, m);
        for k in 0..=20 {
            let tan = k as f64 * 0.1 * m;
            let h = Vec3::new(tan, 0.0, 1.0).normalize();
            let (a, b) = (t.d(h), beckmann.d(h));
            assert!((a - b).abs() < 0.02 * beckmann.d(Vec3::new(0.0, 0.0, 1.0)), "tan {tan}: {a} {b}");
        }
        assert!((t.width() - m).abs() < 0.01 * m && (t.alpha_along(Vec3::new(0.3, 0.4, 0.8)) - m).abs() < 0.01 * m);
        assert!(SlopeTable::from_slopes(&[0.0; 20], &[0.0; 20]).is_err());
    }
}
