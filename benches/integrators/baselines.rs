//! The baselines a grid- or sampling-based tool would use, on the same BRDF object over the plain variables
//! (p_s, q_s, p_r, q_r) of the stops: Monte Carlo, a midpoint grid, Genz–Malik on the raw box; and the
//! Lambertian closed form.

use glossmeter::brdf::Brdf;
use glossmeter::instrument::geometry::{solid_angle_density, Axes};

use crate::cases::Case;

/// SplitMix64 (Steele, Lea & Flood 2014; the reference constants of Vigna's `splitmix64.c`).
pub(crate) struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1) with 53 random bits.
    fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// The plain 4-D integrand in (p_s, q_s, p_r, q_r): luminous f · cos θi cos θo · both solid-angle densities.
pub(crate) struct Plain<'a> {
    pub(crate) brdf: &'a dyn Brdf,
    pub(crate) axes: Axes,
    pub(crate) weights: Vec<f64>,
    pub(crate) scratch: Vec<f64>,
}

impl<'a> Plain<'a> {
    fn new(c: &'a Case) -> Self {
        let b: &dyn Brdf = c.brdf.as_ref();
        let weights =
            glossmeter::colorimetry::weighting::Weighting::luminous(b.sampling()).expect("luminous weighting").rows[0]
                .clone();
        Plain { brdf: b, axes: Axes::new(c.theta), scratch: vec![0.0; weights.len()], weights }
    }
    #[inline]
    fn f(&mut self, ps: f64, qs: f64, pr: f64, qr: f64) -> f64 {
        let wi = self.axes.source_dir(ps, qs);
        let wo = self.axes.receptor_dir(pr, qr);
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        self.brdf.eval(wi, wo, &mut self.scratch);
        let lum: f64 = self.weights.iter().zip(&self.scratch).map(|(w, v)| w * v).sum();
        lum * wi.z * wo.z * solid_angle_density(ps, qs) * solid_angle_density(pr, qr)
    }
}

/// Plain Monte Carlo over the product of the stops: (value, 1-σ standard error).
pub(crate) fn monte_carlo(c: &Case, n: usize, seed: u64) -> (f64, f64) {
    let mut p = Plain::new(c);
    let mut rng = SplitMix64(seed);
    let (s, r) = (c.source, c.receptor);
    let vol = (s.p[1] - s.p[0]) * (s.q[1] - s.q[0]) * (r.p[1] - r.p[0]) * (r.q[1] - r.q[0]);
    // Welford's running mean and variance.
    let (mut mean, mut m2) = (0.0f64, 0.0f64);
    for k in 0..n {
        let ps = s.p[0] + (s.p[1] - s.p[0]) * rng.next_f64();
        let qs = s.q[0] + (s.q[1] - s.q[0]) * rng.next_f64();
        let pr = r.p[0] + (r.p[1] - r.p[0]) * rng.next_f64();
        let qr = r.q[0] + (r.q[1] - r.q[0]) * rng.next_f64();
        let x = p.f(ps, qs, pr, qr);
        let d = x - mean;
        mean += d / (k + 1) as f64;
        m2 += d * (x - mean);
    }
    let var = if n > 1 { m2 / (n - 1) as f64 } else { 0.0 };
    (vol * mean, vol * (var / n as f64).sqrt())
}

/// Uniform midpoint product grid of N⁴ points over the stops.
pub(crate) fn midpoint_grid(c: &Case, n: usize) -> f64 {
    let mut p = Plain::new(c);
    let (s, r) = (c.source, c.receptor);
    let mid = |a: [f64; 2], n: usize| -> Vec<f64> {
        (0..n).map(|i| a[0] + (a[1] - a[0]) * (i as f64 + 0.5) / n as f64).collect()
    };
    let (ps, qs, pr, qr) = (mid(s.p, n), mid(s.q, n), mid(r.p, n), mid(r.q, n));
    let vol = (s.p[1] - s.p[0]) * (s.q[1] - s.q[0]) * (r.p[1] - r.p[0]) * (r.q[1] - r.q[0]);
    let mut total = 0.0;
    for &a in &ps {
        for &b in &qs {
            let mut inner = 0.0;
            for &cc in &pr {
                for &d in &qr {
                    inner += p.f(a, b, cc, d);
                }
            }
            total += inner;
        }
    }
    total * vol / (n as f64).powi(4)
}

/// The crate's own Genz–Malik driver on the raw 4-D box (p_s, q_s, p_r, q_r), one initial region: what
/// `hcubature` does when it is not told where the lobe is.
pub(crate) fn raw_box_genz_malik(c: &Case, rtol: f64, max_evals: usize) -> glossmeter::quadrature::Estimate {
    let mut p = Plain::new(c);
    let (s, r) = (c.source, c.receptor);
    glossmeter::quadrature::integrate::<4, _>(
        glossmeter::quadrature::pointwise(1, |x: &[f64; 4], out: &mut [f64]| out[0] = p.f(x[0], x[1], x[2], x[3])),
        1,
        &[([s.p[0], s.q[0], r.p[0], r.q[0]], [s.p[1], s.q[1], r.p[1], r.q[1]])],
        &glossmeter::quadrature::Options { rtol, atol: 0.0, max_evals, deadline: None, ..Default::default() },
    )
}

/// The closed-form Lambertian flux (Lambert's polygon formula for each stop), from the crate's independent
/// references (`instrument::reference`, which shares no code with the quadrature).
pub(crate) fn lambert_exact(c: &Case, albedo: f64) -> f64 {
    glossmeter::instrument::reference::lambertian_flux_reference(
        c.theta,
        c.source,
        c.receptor,
        albedo / std::f64::consts::PI,
    )
}
