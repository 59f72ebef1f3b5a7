//! The scalar Beckmann–Kirchhoff far field of a height map by one FFT, and the flux it sends into an
//! instrument's receptor stop (docs/optics.md §11).
//!
//! Why: the facet BRDF needs σ ≫ λ and the Rayleigh–Rice halo σ ≪ λ; the Kirchhoff integral of the map itself
//! needs neither, so it is the ground truth the two-scale model is checked against (docs/optics.md §11.5).
//!
//! With levelled heights z on an nx × ny grid (dx, dy), weights w (1, or a separable Hann window; 0 at invalid
//! points), u = w·exp(i q_z z), U = FFT2(u) (forward, e^{−2πi f·x}), the fraction of the reflected power
//! scattered into the direction cell of spatial frequency f is p(f) = |U(f)|² / (N·Σw²) (Σ_f p = 1, Parseval).
//! The scattered ray's direction cosines are the mirror ray's minus λf (the sign that sends a tilt z = αx's
//! light where the tilted mirror sends it, §11.2). q_z = k(cos θi + cos θo,c) is held at the receptor centre.
use rustfft::num_complex::Complex64;
use rustfft::FftPlannerScalar;
use std::f64::consts::PI;

use super::fresnel::fresnel_dielectric;

/// Panels per axis of the source stop a reading is taken with, two Gauss–Legendre points each
/// (docs/optics.md §11.3).
pub const FINE: usize = 16;

/// The panels per axis whose difference from [`FINE`] is the reading's error estimate (docs/optics.md §11.3).
pub const COARSE: usize = 8;

/// The largest cell λ/L allowed, as a fraction of the receptor's smallest extent in direction cosines
/// (docs/optics.md §11.4).
pub const RESOLUTION_FRACTION: f64 = 0.25;

/// The largest bound on the flux beyond the map's Nyquist frequencies allowed, as a fraction of the flux
/// (docs/optics.md §11.4); below it the bound is part of the error estimate.
pub const UNRESOLVED_FRACTION: f64 = 0.01;

/// The edge treatment (docs/optics.md §11.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Edge {
    /// w = 1: the map is one period of the surface.
    Periodic,
    /// w = separable Hann window: the edge of the illuminated spot.
    Taper,
}

impl Edge {
    pub fn parse(s: &str) -> Option<Edge> {
        match s {
            "periodic" => Some(Edge::Periodic),
            "taper" => Some(Edge::Taper),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Edge::Periodic => "periodic",
            Edge::Taper => "taper",
        }
    }
}

/// A stop in tangent coordinates, as `instrument::geometry::Stop` (p in the plane of measurement).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StopBox {
    pub p: [f64; 2],
    pub q: [f64; 2],
}

/// One aperture integral: the source axis angle θ, the receptor axis angle (signed), the two stops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aperture {
    pub theta: f64,
    pub viewing: f64,
    pub source: StopBox,
    pub receptor: StopBox,
}

/// The flux of one aperture integral (docs/instrument.md §1.4 units: ∫ R·P cos θi dωi).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ApertureFlux {
    pub value: f64,
    /// The estimate of the discretisation error of `value` (docs/optics.md §11.3): the larger of |value − the
    /// same flux on [`COARSE`] panels| and a quarter of |that − the flux on half as many|, plus `unresolved`.
    pub error: f64,
    /// The part carried by the specular cell f = 0 (the coherent reflection).
    pub coherent: f64,
    /// Independent speckle cells in the receptor (cells of size λ/L, at the source's centre).
    pub cells: f64,
    /// The bound on the flux the cells beyond the map's Nyquist frequencies send into the receptor (each at
    /// the largest power on the grid's outer rings, docs/optics.md §11.4); part of `error`.
    pub unresolved: f64,
}

impl ApertureFlux {
    /// The speckle uncertainty of the flux: the incoherent part / √N_cells (docs/optics.md §11.4).
    pub fn speckle(&self) -> f64 {
        (self.value - self.coherent).abs() / self.cells.max(1.0).sqrt()
    }
}

/// Why a receptor cannot be read from this map (docs/optics.md §11.4).
#[derive(Clone, Debug, PartialEq)]
pub enum Refusal {
    /// The map is too small: λ/L exceeds a quarter of the receptor's smallest extent.
    Resolution(String),
    /// The sampling is too coarse: what the receptor may receive beyond the Nyquist frequency is more than
    /// [`UNRESOLVED_FRACTION`] of its flux.
    Nyquist(String),
    /// q_z·max|Δz| > π between neighbouring points.
    Aliasing(String),
}

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Refusal::Resolution(m) | Refusal::Nyquist(m) | Refusal::Aliasing(m) => f.write_str(m),
        }
    }
}

/// A levelled height map prepared for the Kirchhoff far field.
#[derive(Clone, Debug)]
pub struct KirchhoffMap {
    pub nx: usize,
    pub ny: usize,
    pub dx: f64,
    pub dy: f64,
    /// Heights, m (0 at invalid points, whose weight is 0).
    z: Vec<f64>,
    w: Vec<f64>,
    sum_w2: f64,
    pub wavelength: f64,
    pub ior: f64,
    pub edge: Edge,
    /// The largest |Δz| between valid neighbours within the map (not across a periodic wrap), m.
    pub max_step: f64,
}

/// The Hann weight of point i of n in its periodic ("DFT-even") form, sin²(πi/n) (docs/optics.md §11.1).
fn hann(i: usize, n: usize) -> f64 {
    let s = (PI * i as f64 / n as f64).sin();
    s * s
}

/// The signed frequency index of a discrete Fourier transform's bin k of n (k ≤ n/2 the non-negative
/// frequencies, the rest the negative ones, numpy.fft.fftfreq's order); the one place the topography's
/// transforms (`topography::psd`, `topography::synthetic`) and the scatter integral take it from.
pub(crate) fn signed_bin(k: usize, n: usize) -> i64 {
    if k <= n / 2 {
        k as i64
    } else {
        k as i64 - n as i64
    }
}

impl KirchhoffMap {
    /// Levelled heights `z` (nx × ny, row-major, NaN invalid), spacings in metres, wavelength in metres.
    pub fn new(
        z: &[f64],
        (nx, ny): (usize, usize),
        (dx, dy): (f64, f64),
        wavelength: f64,
        ior: f64,
        edge: Edge,
    ) -> Result<KirchhoffMap, String> {
        if nx < 2 || ny < 2 || z.len() != nx * ny {
            return Err(format!("a {nx} × {ny} map with {} heights; allowed: at least 2 × 2, nx·ny heights", z.len()));
        }
        if !(dx > 0.0 && dy > 0.0 && dx.is_finite() && dy.is_finite()) {
            return Err(format!("spacings {dx} × {dy} m; allowed: finite and > 0"));
        }
        let mut w = vec![0.0; nx * ny];
        for j in 0..ny {
            for i in 0..nx {
                let k = j * nx + i;
                if z[k].is_finite() {
                    w[k] = match edge {
                        Edge::Periodic => 1.0,
                        Edge::Taper => hann(i, nx) * hann(j, ny),
                    };
                }
            }
        }
        let sum_w2: f64 = w.iter().map(|v| v * v).sum();
        if sum_w2 <= 0.0 {
            return Err("no valid point in the map".into());
        }
        let zz: Vec<f64> = z.iter().map(|&v| if v.is_finite() { v } else { 0.0 }).collect();
        // Steps between neighbours within the map only: the step across a periodic map's wrap is its edge, which
        // the periodic continuation makes (§11.1), not a slope the sampling fails to follow.
        let mut max_step: f64 = 0.0;
        for j in 0..ny {
            for i in 0..nx {
                let k = j * nx + i;
                if !z[k].is_finite() {
                    continue;
                }
                let right = (i + 1 < nx).then_some(k + 1);
                let up = (j + 1 < ny).then_some(k + nx);
                for n in [right, up].into_iter().flatten() {
                    if z[n].is_finite() {
                        max_step = max_step.max((z[n] - z[k]).abs());
                    }
                }
            }
        }
        Ok(KirchhoffMap { nx, ny, dx, dy, z: zz, w, sum_w2, wavelength, ior, edge, max_step })
    }

    pub fn k(&self) -> f64 {
        2.0 * PI / self.wavelength
    }

    /// The map's extents L_x, L_y, m.
    pub fn extent(&self) -> (f64, f64) {
        (self.nx as f64 * self.dx, self.ny as f64 * self.dy)
    }

    /// The spatial frequency of bin (kx, ky), 1/m.
    pub fn frequency(&self, kx: usize, ky: usize) -> (f64, f64) {
        let (lx, ly) = self.extent();
        (signed_bin(kx, self.nx) as f64 / lx, signed_bin(ky, self.ny) as f64 / ly)
    }

    /// p(f) for a fixed q_z (1/m), in the transform's order (`p[ky·nx + kx]`); refused when q_z·max|Δz| > π.
    pub fn power(&self, qz: f64) -> Result<Vec<f64>, Refusal> {
        let phase = qz * self.max_step;
        if phase > PI {
            return Err(Refusal::Aliasing(format!(
                "phase aliasing: q_z·max|Δz| = {phase:.3} rad between neighbouring points (q_z = {:.4} /µm, \
                 max|Δz| = {:.4} µm); allowed: ≤ π (docs/optics.md §11.4: a finer sampling is needed)",
                qz * 1e-6,
                self.max_step * 1e6
            )));
        }
        let (nx, ny) = (self.nx, self.ny);
        let mut rows: Vec<Complex64> =
            self.z.iter().zip(&self.w).map(|(&z, &w)| Complex64::from_polar(w, qz * z)).collect();
        let mut planner = FftPlannerScalar::<f64>::new();
        planner.plan_fft_forward(nx).process(&mut rows);
        let mut cols = vec![Complex64::new(0.0, 0.0); nx * ny];
        for j in 0..ny {
            for i in 0..nx {
                cols[i * ny + j] = rows[j * nx + i];
            }
        }
        planner.plan_fft_forward(ny).process(&mut cols);
        let norm = (nx * ny) as f64 * self.sum_w2;
        let mut p = vec![0.0; nx * ny];
        for j in 0..ny {
            for i in 0..nx {
                p[j * nx + i] = cols[i * ny + j].norm_sqr() / norm;
            }
        }
        Ok(p)
    }

    /// The flux into `a.receptor` for a source uniformly filling `a.source` (docs/optics.md §11.3).
    pub fn aperture_flux(&self, a: &Aperture) -> Result<ApertureFlux, Refusal> {
        let lambda = self.wavelength;
        let rx = Receptor::new(a.viewing, a.receptor);
        let (sin_t, cos_t) = a.theta.sin_cos();
        let source_dir = |p: f64, q: f64| -> [f64; 3] {
            let n = (1.0 + p * p + q * q).sqrt();
            [(-sin_t + p * cos_t) / n, q / n, (cos_t + p * sin_t) / n]
        };
        // The receptor's centre and q_z there.
        let c = rx.dir(0.5 * (a.receptor.p[0] + a.receptor.p[1]), 0.5 * (a.receptor.q[0] + a.receptor.q[1]));
        let s0 = source_dir(0.0, 0.0);
        let qz = self.k() * (s0[2] + c[2]);
        // The receptor's extent in direction cosines (its boundary sampled), for the checks and the cell range.
        let bb = rx.bounds();
        let (lx, ly) = self.extent();
        let (cx, cy) = (lambda / lx, lambda / ly);
        let smallest = (bb[1] - bb[0]).min(bb[3] - bb[2]);
        if cx.max(cy) > RESOLUTION_FRACTION * smallest {
            return Err(Refusal::Resolution(format!(
                "the map ({:.4} × {:.4} mm) is too small to resolve the receptor: its cell λ/L = {:.3e} is more \
                 than {RESOLUTION_FRACTION} of the receptor's smallest extent in direction cosines ({smallest:.3e}); \
                 allowed: L ≥ {:.4} mm (docs/optics.md §11.4)",
                lx * 1e3,
                ly * 1e3,
                cx.max(cy),
                lambda / (RESOLUTION_FRACTION * smallest) * 1e3
            )));
        }
        let p = self.power(qz)?;
        let edge = self.edge_power(&p);
        let fine = self.source_average(&p, edge, &rx, &bb, a.source, &source_dir, FINE);
        let coarse = self.source_average(&p, edge, &rx, &bb, a.source, &source_dir, COARSE);
        let coarsest = self.source_average(&p, edge, &rx, &bb, a.source, &source_dir, COARSE / 2);
        if fine.unresolved > UNRESOLVED_FRACTION * fine.value {
            return Err(Refusal::Nyquist(format!(
                "the sampling ({:.3} × {:.3} µm) is too coarse for the receptor: the part of it beyond the map's \
                 Nyquist frequencies (|λf| > λ/(2Δ) = ({:.4}, {:.4}) in direction cosines) may receive {:.2e} of \
                 the flux {:.2e} (bounded by the map's power at its Nyquist edge); allowed: at most \
                 {UNRESOLVED_FRACTION} of it (docs/optics.md §11.4: a finer sampling is needed)",
                self.dx * 1e6,
                self.dy * 1e6,
                0.5 * lambda / self.dx,
                0.5 * lambda / self.dy,
                fine.unresolved,
                fine.value
            )));
        }
        // The fine rule's error by the coarse one's, or by the coarse rule's own error a quarter as large (the
        // second-order convergence of panels across kinks), whichever is larger: the one difference alone was
        // once accidentally small (docs/optics.md §11.3).
        let step = (fine.value - coarse.value).abs().max(0.25 * (coarse.value - coarsest.value).abs());
        Ok(ApertureFlux { error: step + fine.unresolved, ..fine })
    }

    /// The largest p(f) on the two outermost rings of the frequency grid: the bound assumed for every cell
    /// beyond the Nyquist frequencies (docs/optics.md §11.4).
    fn edge_power(&self, p: &[f64]) -> f64 {
        let (hx, hy) = ((self.nx / 2) as i64, (self.ny / 2) as i64);
        let mut most: f64 = 0.0;
        for ky in 0..self.ny {
            for kx in 0..self.nx {
                let (sx, sy) = (signed_bin(kx, self.nx), signed_bin(ky, self.ny));
                if sx.abs() >= hx - 1 || sy.abs() >= hy - 1 {
                    most = most.max(p[ky * self.nx + kx]);
                }
            }
        }
        most
    }

    /// The flux for the source uniformly filling `source` by `panels` × `panels` panels of 2 × 2 Gauss points
    /// (docs/optics.md §11.3); `error` 0, and
    /// `unresolved` the bound on what the cells beyond the Nyquist frequencies send, each taken as `edge`.
    #[allow(clippy::too_many_arguments)]
    fn source_average(
        &self,
        p: &[f64],
        edge: f64,
        rx: &Receptor,
        bb: &[f64; 4],
        source: StopBox,
        source_dir: &dyn Fn(f64, f64) -> [f64; 3],
        panels: usize,
    ) -> ApertureFlux {
        // The composite two-point Gauss rule on `panels` equal panels: the integrand is continuous but kinked
        // wherever a cell's corner crosses the receptor's edge, which one high-order Gauss rule does not converge
        // on steadily (§11.3); smooth between kinks, which two points a panel integrate to third order.
        let h = 2.0 / panels as f64;
        let g = h / (2.0 * 3f64.sqrt());
        let xs: Vec<f64> =
            (0..panels).flat_map(|i| [-1.0 + (i as f64 + 0.5) * h - g, -1.0 + (i as f64 + 0.5) * h + g]).collect();
        let ws = vec![h / 2.0; 2 * panels];
        let nodes = xs.len();
        let (mut value, mut coherent, mut cells, mut unresolved) = (0.0, 0.0, 0.0, 0.0);
        let [p0, p1] = source.p;
        let [q0, q1] = source.q;
        for (i, (&u, &wu)) in xs.iter().zip(&ws).enumerate() {
            for (j, (&v, &wv)) in xs.iter().zip(&ws).enumerate() {
                let (ps, qs) = (p0 + (p1 - p0) * 0.5 * (u + 1.0), q0 + (q1 - q0) * 0.5 * (v + 1.0));
                let r2 = 1.0 + ps * ps + qs * qs;
                let s = source_dir(ps, qs);
                // cos θi dωi of this node (dω = dp dq/(1+p²+q²)^{3/2}, docs/instrument.md §1.2).
                let weight = wu * wv * 0.25 * (p1 - p0) * (q1 - q0) / (r2 * r2.sqrt()) * s[2];
                let centre = i == nodes / 2 && j == nodes / 2;
                let c = self.cells_in(p, edge, rx, bb, s, centre);
                value += weight * c.sum;
                coherent += weight * c.coherent;
                unresolved += weight * c.unresolved;
                if centre {
                    cells = c.count;
                }
            }
        }
        ApertureFlux { value, error: 0.0, coherent, cells, unresolved }
    }

    /// Σ_f R_F(θ_h)·p(f)·(fraction of cell f inside the receptor) for the source direction `s` (θ_h the half
    /// angle between s and the cell's direction, §11.3), its parts (see [`CellSums`]).
    #[allow(clippy::too_many_arguments)]
    fn cells_in(&self, p: &[f64], edge: f64, rx: &Receptor, bb: &[f64; 4], s: [f64; 3], count: bool) -> CellSums {
        let m = [-s[0], -s[1]];
        let lambda = self.wavelength;
        let (lx, ly) = self.extent();
        let (cx, cy) = (lambda / lx, lambda / ly);
        // Direction cosines of cell (kx, ky): m − λ f, f = (kx/Lx, ky/Ly).
        let kx_lo = ((m[0] - bb[1]) / cx).floor() as i64 - 1;
        let kx_hi = ((m[0] - bb[0]) / cx).ceil() as i64 + 1;
        let ky_lo = ((m[1] - bb[3]) / cy).floor() as i64 - 1;
        let ky_hi = ((m[1] - bb[2]) / cy).ceil() as i64 + 1;
        let (hx, hy) = ((self.nx / 2) as i64, (self.ny / 2) as i64);
        let mut c = CellSums::default();
        for ky in ky_lo..=ky_hi {
            for kx in kx_lo..=kx_hi {
                let ox = m[0] - kx as f64 * cx;
                let oy = m[1] - ky as f64 * cy;
                let frac = rx.fraction(ox, oy, cx, cy);
                if frac == 0.0 {
                    continue;
                }
                let oz = (1.0 - ox * ox - oy * oy).max(0.0).sqrt();
                let cos_h = (0.5 * (1.0 + s[0] * ox + s[1] * oy + s[2] * oz)).max(0.0).sqrt();
                let rf = fresnel_dielectric(cos_h, self.ior).r();
                if kx <= -hx || kx > hx || ky <= -hy || ky > hy {
                    // Beyond the Nyquist frequencies: the map cannot say; bounded by its edge's power.
                    c.unresolved += rf * edge * frac;
                    continue;
                }
                let bx = kx.rem_euclid(self.nx as i64) as usize;
                let by = ky.rem_euclid(self.ny as i64) as usize;
                let v = rf * p[by * self.nx + bx] * frac;
                c.sum += v;
                if kx == 0 && ky == 0 {
                    c.coherent += v;
                }
                if count {
                    c.count += frac;
                }
            }
        }
        c
    }
}

/// What the cells send into the receptor for one source direction (`KirchhoffMap::cells_in`).
#[derive(Clone, Copy, Debug, Default)]
struct CellSums {
    /// Σ R_F·p·fraction over the cells the map resolves.
    sum: f64,
    /// The f = 0 cell's part of `sum`.
    coherent: f64,
    /// The fraction-weighted number of resolved cells (when asked).
    count: f64,
    /// The bound on what the cells beyond the Nyquist frequencies send (each taken at the edge's power).
    unresolved: f64,
}

/// A receptor stop on its lens axis: directions ↔ tangent coordinates (docs/instrument.md §1.1–1.2).
struct Receptor {
    sin: f64,
    cos: f64,
    stop: StopBox,
}

impl Receptor {
    fn new(viewing: f64, stop: StopBox) -> Receptor {
        let (sin, cos) = viewing.sin_cos();
        Receptor { sin, cos, stop }
    }

    /// Direction of stop point (p, q): (r0 + p e∥ + q e⊥)/√(1+p²+q²), e∥ = (cos θ, 0, −sin θ).
    fn dir(&self, p: f64, q: f64) -> [f64; 3] {
        let n = (1.0 + p * p + q * q).sqrt();
        [(self.sin + p * self.cos) / n, q / n, (self.cos - p * self.sin) / n]
    }

    /// Tangent coordinates of the direction with cosines (ox, oy), if it propagates and faces the lens.
    fn tangent(&self, ox: f64, oy: f64) -> Option<(f64, f64)> {
        let r2 = ox * ox + oy * oy;
        if r2 >= 1.0 {
            return None;
        }
        let oz = (1.0 - r2).sqrt();
        let a = ox * self.sin + oz * self.cos;
        (a > 0.0).then(|| ((ox * self.cos - oz * self.sin) / a, oy / a))
    }

    fn inside(&self, ox: f64, oy: f64) -> bool {
        self.tangent(ox, oy).is_some_and(|(p, q)| {
            p >= self.stop.p[0] && p <= self.stop.p[1] && q >= self.stop.q[0] && q <= self.stop.q[1]
        })
    }

    /// The bounding box [ox0, ox1, oy0, oy1] of the stop in direction cosines (its boundary, 64 points a side).
    fn bounds(&self) -> [f64; 4] {
        let mut b = [f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY];
        let [p0, p1] = self.stop.p;
        let [q0, q1] = self.stop.q;
        for k in 0..=64 {
            let t = k as f64 / 64.0;
            for (p, q) in
                [(p0 + t * (p1 - p0), q0), (p0 + t * (p1 - p0), q1), (p0, q0 + t * (q1 - q0)), (p1, q0 + t * (q1 - q0))]
            {
                let d = self.dir(p, q);
                b = [b[0].min(d[0]), b[1].max(d[0]), b[2].min(d[1]), b[3].max(d[1])];
            }
        }
        b
    }

    /// The fraction of the cell centred on (ox, oy), cx × cy in direction cosines, inside the stop (§11.3):
    /// 1 or 0 when its four corners agree (all inside, or all beyond one edge); else the cell's outline
    /// (`EDGE_POINTS` points a side) is taken to the stop's tangent coordinates, clipped by the stop's
    /// rectangle there, and the clipped polygon's vertices taken back to direction cosines, where its area over
    /// the cell's is the fraction. A point that does not reach the lens (beyond the horizon) falls back on the
    /// share of `FALLBACK_SUBSAMPLES`² points.
    fn fraction(&self, ox: f64, oy: f64, cx: f64, cy: f64) -> f64 {
        let corners = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
            .map(|(a, b)| self.tangent(ox + a * cx, oy + b * cy).unwrap_or((f64::NAN, f64::NAN)));
        let all = |f: &dyn Fn(f64, f64) -> bool| corners.iter().all(|&(p, q)| f(p, q));
        let s = self.stop;
        if corners.iter().all(|c| c.0.is_finite()) {
            if all(&|p, q| p >= s.p[0] && p <= s.p[1] && q >= s.q[0] && q <= s.q[1]) {
                return 1.0;
            }
            if all(&|p, _| p < s.p[0]) || all(&|p, _| p > s.p[1]) || all(&|_, q| q < s.q[0]) || all(&|_, q| q > s.q[1])
            {
                return 0.0;
            }
            let k = EDGE_POINTS;
            let mut outline = Vec::with_capacity(4 * k);
            for side in 0..4 {
                let (a, b) = (
                    [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)][side],
                    [(0.5, -0.5), (0.5, 0.5), (-0.5, 0.5), (-0.5, -0.5)][side],
                );
                for i in 0..k {
                    let t = i as f64 / k as f64;
                    let (u, v) = (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
                    outline.push(self.tangent(ox + u * cx, oy + v * cy));
                }
            }
            if let Some(poly) = outline.into_iter().collect::<Option<Vec<_>>>() {
                // Back in direction cosines, where p(f) is uniform over the cell (the map's Jacobian varies
                // across a cell near grazing, so areas in (p, q) would weight it wrongly).
                let inside: Vec<(f64, f64)> = clip(&poly, s)
                    .into_iter()
                    .map(|(p, q)| {
                        let d = self.dir(p, q);
                        (d[0], d[1])
                    })
                    .collect();
                return (area(&inside) / (cx * cy)).clamp(0.0, 1.0);
            }
        }
        let m = FALLBACK_SUBSAMPLES;
        let mut hits = 0;
        for a in 0..m {
            for b in 0..m {
                let u = (a as f64 + 0.5) / m as f64 - 0.5;
                let v = (b as f64 + 0.5) / m as f64 - 0.5;
                if self.inside(ox + u * cx, oy + v * cy) {
                    hits += 1;
                }
            }
        }
        hits as f64 / (m * m) as f64
    }
}

/// Sub-samples per axis of a cell whose outline does not all reach the lens (docs/optics.md §11.3).
const FALLBACK_SUBSAMPLES: usize = 16;

/// Points per side of a cut cell's outline (docs/optics.md §11.3).
const EDGE_POINTS: usize = 8;

/// The polygon `poly` (vertices in order, simple) clipped by the rectangle `stop`: Sutherland–Hodgman, one
/// half-plane of the rectangle at a time (empty when nothing is inside).
fn clip(poly: &[(f64, f64)], stop: StopBox) -> Vec<(f64, f64)> {
    // Each half-plane as (axis, bound, keep the side ≥ bound?).
    let planes = [(0, stop.p[0], true), (0, stop.p[1], false), (1, stop.q[0], true), (1, stop.q[1], false)];
    let mut poly: Vec<(f64, f64)> = poly.to_vec();
    for (axis, bound, above) in planes {
        let coord = |v: (f64, f64)| if axis == 0 { v.0 } else { v.1 };
        let inside = |v: (f64, f64)| if above { coord(v) >= bound } else { coord(v) <= bound };
        let mut out = Vec::with_capacity(poly.len() + 2);
        for i in 0..poly.len() {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            if inside(a) {
                out.push(a);
            }
            if inside(a) != inside(b) {
                let t = (bound - coord(a)) / (coord(b) - coord(a));
                out.push((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)));
            }
        }
        poly = out;
        if poly.len() < 3 {
            return Vec::new();
        }
    }
    poly
}

/// The area of a simple polygon (the shoelace formula).
fn area(poly: &[(f64, f64)]) -> f64 {
    let n = poly.len();
    0.5 * (0..n).map(|i| poly[i].0 * poly[(i + 1) % n].1 - poly[(i + 1) % n].0 * poly[i].1).sum::<f64>().abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cut_cells_share_is_what_dense_points_inside_it_give() {
        // The D523 85° receptor (4° × 6° at 85°) and cells of 5.5e-4 in direction cosines about its edges.
        let (a, b) = (4f64.to_radians(), 6f64.to_radians());
        let stop = StopBox { p: [(-a / 2.0).tan(), (a / 2.0).tan()], q: [(-b / 2.0).tan(), (b / 2.0).tan()] };
        let rx = Receptor::new(85f64.to_radians(), stop);
        let bb = rx.bounds();
        let c = 5.5e-4;
        let mut worst: f64 = 0.0;
        for k in 0..400 {
            let t = (k as f64 + 0.37) / 400.0;
            for (ox, oy) in [
                (bb[0] + t * 1e-3 - 5e-4, 0.3 * bb[3] * t),
                (bb[1] + t * 1e-3 - 5e-4, -0.5 * bb[3] * t),
                (0.5 * (bb[0] + bb[1]) + (t - 0.5) * 1e-3, bb[3] + t * 1e-3 - 5e-4),
            ] {
                let m = 400;
                let mut hits = 0;
                for i in 0..m {
                    for j in 0..m {
                        let u = (i as f64 + 0.5) / m as f64 - 0.5;
                        let v = (j as f64 + 0.5) / m as f64 - 0.5;
                        hits += rx.inside(ox + u * c, oy + v * c) as usize;
                    }
                }
                let dense = hits as f64 / (m * m) as f64;
                let got = rx.fraction(ox, oy, c, c);
                if (got - dense).abs() > 2e-3 {
                    eprintln!("cell ({ox}, {oy}): clip {got} dense {dense}");
                }
                worst = worst.max((got - dense).abs());
            }
        }
        assert!(worst < 2e-3, "{worst}");
    }

    #[test]
    fn a_clipped_square_has_the_share_of_its_area_inside() {
        let stop = StopBox { p: [0.0, 1.0], q: [0.0, 1.0] };
        let clipped_share = |poly: &[(f64, f64)], stop| area(&clip(poly, stop)) / area(poly);
        let square = |x: f64, y: f64| [(x, y), (x + 0.5, y), (x + 0.5, y + 0.5), (x, y + 0.5)];
        assert_eq!(clipped_share(&square(0.25, 0.25), stop), 1.0);
        assert!((clipped_share(&square(0.75, 0.25), stop) - 0.5).abs() < 1e-15);
        assert!((clipped_share(&square(0.75, 0.75), stop) - 0.25).abs() < 1e-15);
        assert_eq!(clipped_share(&square(1.5, 0.25), stop), 0.0);
        // A diamond over the corner (1, 1): the triangle below-left of it is 1/4 of its area.
        let diamond = [(1.0, 0.5), (1.5, 1.0), (1.0, 1.5), (0.5, 1.0)];
        assert!((clipped_share(&diamond, stop) - 0.25).abs() < 1e-15);
    }

    #[test]
    fn a_tilt_sends_its_light_where_the_tilted_mirror_does() {
        // z = αx on a periodic map whose tilt is a whole number of phase turns at q_z: the power is one cell,
        // f = q_z α/2π, and the ray's direction cosine is the mirror's minus λf = sin θ − 2α cos θ (§11.2).
        let n = 64;
        let (dx, lambda) = (1e-6, 0.5e-6);
        let k = 2.0 * PI / lambda;
        let qz = 2.0 * k;
        // α such that q_z α·n·dx = 2π·3 (3 cells).
        let alpha = 3.0 * 2.0 * PI / (qz * n as f64 * dx);
        let z: Vec<f64> = (0..n * n).map(|i| alpha * ((i % n) as f64) * dx).collect();
        let m = KirchhoffMap::new(&z, (n, n), (dx, dx), lambda, 1.5, Edge::Periodic).unwrap();
        let p = m.power(qz).unwrap();
        assert!((p[3] - 1.0).abs() < 1e-12, "{}", p[3]);
        let (fx, _) = m.frequency(3, 0);
        assert!((lambda * fx - 2.0 * alpha).abs() < 1e-12);
    }
}
