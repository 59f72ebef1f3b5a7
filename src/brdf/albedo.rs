//! Directional albedo a(ωi) = ∫ f_r(ωi, ωo) cos θo dωo + R_δ(ωi): the white-furnace quantity.
//!
//! The regular part is integrated in half-vector slope coordinates centred on the specular direction, where
//! every lobe of this crate lives (see [`super::Lobe`]): h ∝ (r cos φ, r sin φ, 1), ωo = 2(ωi·h)h − ωi, with
//!
//!   dωo = 4 (ωi·h) dωh  (Torrance & Sparrow 1967; Walter et al. 2007 Eq. 14),   dωh = cos³θh dp dq = (1 + r²)^(−3/2) r dr dφ.
//!
//! The domain is the set of slopes whose reflected direction is above the horizon: along the azimuth φ,
//! ωo·z = (c + 2ar − cr²)/(1 + r²) with a = ωi,x cos φ + ωi,y sin φ and c = cos θi, so
//! r ≤ r_max(φ) = (a + √(a² + c²))/c (computed as c/(√(a² + c²) − a) when a < 0, free of cancellation).
//!
//! The radial integral starts from a partition at w/16·2ᵏ (w the narrowest lobe's slope width, k = 0, 1, …)
//! so that a lobe of width 1e-4 or less is covered by panels of its own size and cannot be missed; each panel
//! and the outer azimuth integral (initial panels every π/8 from the plane of incidence) use adaptive
//! Gauss–Kronrod G7/K15 (Piessens et al., QUADPACK, 1983) with bisection. The error estimate returned is the
//! sum of |K15 − G7| over the final panels, inner errors integrated over φ: a conservative bound in practice,
//! provided no panel straddles a kink or a seam of the integrand, where |K15 − G7| is of the order of the
//! error itself and was measured 1–5× below it (a rough coat's E(μ) seams at normal incidence). So the radial
//! partition also breaks, along each azimuth, where the outgoing cosine crosses one of the model's seams
//! ([`Hints::seams`](super::Hints::seams): cos θo = μk at r = (a + √(a² + c² − μk²))/(c + μk)) and where ωi·h crosses a
//! half-angle kink ([`Kink::HalfAngle`]: (a r + c)/√(1 + r²) = k, the roots of
//! (a² − k²) r² + 2ac r + c² − k² = 0 with a r + c > 0).
use super::{Brdf, Kink, TermKind};
use crate::quadrature::gauss_kronrod_adaptive as adaptive;
use crate::Vec3;
use std::f64::consts::PI;

/// Absolute tolerance of the albedo integral (albedos are ≤ 1).
pub(crate) const ALBEDO_TOLERANCE: f64 = 1e-9;

/// Directional albedo of `brdf` for the incident direction `wi` (unit, z > 0), per spectral sample, with an
/// error estimate (absolute, max over samples). Includes the delta reflectance. Returns zeros for wi at or
/// below the horizon. The absolute tolerance is [`ALBEDO_TOLERANCE`].
pub fn directional_albedo(brdf: &dyn Brdf, wi: Vec3) -> (Vec<f64>, f64) {
    directional_albedo_to(brdf, wi, ALBEDO_TOLERANCE)
}

/// [`directional_albedo`] to the absolute tolerance `tolerance` (> 0; 1e-12 is about the floor of the
/// Gauss–Kronrod panels in double precision): a white-furnace check tighter than the integrator's default.
pub fn directional_albedo_to(brdf: &dyn Brdf, wi: Vec3, tolerance: f64) -> (Vec<f64>, f64) {
    let n = brdf.sampling().len();
    let mut total = vec![0.0; n];
    if wi.z.is_nan() || wi.z <= 0.0 {
        return (total, 0.0);
    }
    let wi = wi.normalize();
    if brdf.delta_reflectance(wi, &mut total) {
        // total holds R_δ
    } else {
        total.fill(0.0);
    }
    let hints = brdf.hints();
    let terms = &hints.terms;
    if terms.iter().all(|t| t.kind == TermKind::Delta) {
        return (total, 0.0);
    }
    // Narrowest lobe width (slope); with no lobe, the diffuse integrand is smooth on the scale of 1.
    let w_min = terms
        .iter()
        .filter_map(|t| match &t.kind {
            TermKind::Lobe(l) => Some(l.slope_width.min(l.slope_width * l.medium_eta)),
            _ => None,
        })
        .fold(1.0_f64, f64::min);
    let r0 = (w_min / 16.0).max(1e-12);
    let c = wi.z;
    let phi_i = wi.y.atan2(wi.x);

    let extra = Breaks { seams: hints.seams.clone(), half_angle: half_angle_kinks(&hints.kinks) };
    let inner_tol = tolerance / (4.0 * PI);
    let mut fval = vec![0.0; n];
    // The outer integrand carries the inner error estimate as an extra component, so that its integral over
    // φ is the inner contribution to the total error.
    let mut outer = |phi: f64, out: &mut [f64]| {
        let (s, co) = phi.sin_cos();
        let a = wi.x * co + wi.y * s;
        let root = a.hypot(c);
        let r_max = if a >= 0.0 { (a + root) / c } else { c / (root - a) };
        let mut breaks = vec![0.0];
        let mut r = r0;
        while r < r_max {
            breaks.push(r);
            r *= 2.0;
        }
        breaks.push(r_max);
        if !extra.is_empty() {
            breaks.extend(extra_breaks(&extra, a, c, r_max));
            breaks.sort_by(f64::total_cmp);
            breaks.dedup();
        }
        let mut radial = |r: f64, o: &mut [f64]| {
            let q = 1.0 + r * r;
            let inv = 1.0 / q.sqrt();
            let h = Vec3::new(r * co * inv, r * s * inv, inv);
            let wih = wi.dot(h);
            let wo = 2.0 * wih * h - wi;
            if wo.z <= 0.0 || wih <= 0.0 {
                o.fill(0.0);
                return;
            }
            let wo = wo.normalize();
            brdf.eval(wi, wo, &mut fval);
            let jac = wo.z * 4.0 * wih * inv * inv * inv * r;
            for (oi, fv) in o.iter_mut().zip(&fval) {
                *oi = fv * jac;
            }
        };
        let (v, e) = adaptive(&mut radial, &breaks, n, n, inner_tol, 4 * breaks.len() + 200);
        out[..n].copy_from_slice(&v);
        out[n] = e;
    };
    let breaks: Vec<f64> = (0..=16).map(|k| phi_i + k as f64 * PI / 8.0).collect();
    let (regular, outer_err) = adaptive(&mut outer, &breaks, n + 1, n, tolerance, 2000);
    for (t, r) in total.iter_mut().zip(&regular[..n]) {
        *t += r;
    }
    (total, outer_err + regular[n])
}

/// What breaks the radial partition besides the lobe's doubling panels (module doc).
struct Breaks {
    seams: Vec<f64>,
    half_angle: Vec<f64>,
}

impl Breaks {
    fn is_empty(&self) -> bool {
        self.seams.is_empty() && self.half_angle.is_empty()
    }
}

fn half_angle_kinks(kinks: &[Kink]) -> Vec<f64> {
    kinks
        .iter()
        .filter_map(|k| match *k {
            Kink::HalfAngle { cos } => Some(cos),
            Kink::Incidence { .. } => None,
        })
        .collect()
}

/// The slopes r ∈ (0, r_max) along an azimuth (a = ωi,x cos φ + ωi,y sin φ, c = cos θi) at which the outgoing
/// cosine meets a seam or ωi·h meets a half-angle kink (module doc).
fn extra_breaks(b: &Breaks, a: f64, c: f64, r_max: f64) -> Vec<f64> {
    let mut out = Vec::new();
    for &mu in &b.seams {
        let d = a * a + c * c - mu * mu;
        if d >= 0.0 {
            out.push((a + d.sqrt()) / (c + mu));
        }
    }
    for &k in &b.half_angle {
        // (a² − k²) r² + 2ac r + (c² − k²) = 0.
        let (qa, qb, qc) = (a * a - k * k, 2.0 * a * c, c * c - k * k);
        let roots: Vec<f64> = if qa.abs() < 1e-300 {
            if qb != 0.0 {
                vec![-qc / qb]
            } else {
                vec![]
            }
        } else {
            let disc = qb * qb - 4.0 * qa * qc;
            if disc < 0.0 {
                vec![]
            } else {
                let sq = disc.sqrt();
                vec![(-qb + sq) / (2.0 * qa), (-qb - sq) / (2.0 * qa)]
            }
        };
        out.extend(roots.into_iter().filter(|&r| a * r + c > 0.0));
    }
    out.retain(|&r| r.is_finite() && r > 0.0 && r < r_max);
    out
}
