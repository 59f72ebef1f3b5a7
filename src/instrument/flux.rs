//! The aperture integral Φ = ∫_source ∫_receptor f(ωi, ωo) cos θi cos θo dωi dωo for one source stop,
//! one receptor stop and one BRDF: the hot path of the crate.
//!
//! Why the change of variables: the glossy mass of a paint lies on the specular manifold p_s + p_r = 0,
//! q_s + q_r = 0, a 2-D ridge in the 4-D domain. Axis-aligned cubature over (p_s, q_s, p_r, q_r) cannot see
//! a ridge narrower than its first sample spacing and returns 0 with a tiny error estimate
//! (`../shared/reference/numerics-notes.md` §1.3). We integrate instead over the lobe variables
//! u = p_s + p_r, v = q_s + q_r, and over the position t ∈ [0, 1] along the exact overlap of the stops for
//! that u: per axis, p_s ∈ [max(s0, u − r1), min(s1, u − r0)], p_s = lo + t·(hi − lo), Jacobian hi − lo.
//! The overlap length is piecewise linear in u with kinks at s0 + r0, s1 + r0, s0 + r1, s1 + r1: those are
//! split points. Each lobe adds split points at 0 and ±k·w (k = 1, 3, 10, 30, … out to the range) with w its
//! width in u,
//! so a lobe of any width is resolved by the initial partition. An ideal-mirror (delta) component is
//! integrated analytically in u (it sits at u = v = 0) as a 2-D integral over the stops' mirror overlap.
use crate::brdf::{Brdf, Lobe};
use crate::instrument::geometry::{solid_angle_density, Axes, Stop};
use crate::quadrature::{integrate, Estimate, Options};

/// Fraction of a flux's tolerance given to its delta part. The delta part is a smooth 2-D integral that
/// converges to near machine precision in a few hundred evaluations, so it is asked for much more than its
/// half and the expensive 4-D regular part gets the rest.
pub const DELTA_SHARE: f64 = 0.01;

/// How the spectral samples enter the integral.
#[derive(Clone, Debug, PartialEq)]
pub enum Spectral {
    /// Integrate the luminous sum Σ w_k f_k: one component (the plan folds the weights in).
    Folded(Vec<f64>),
    /// Integrate every sample separately, then weight (costlier; kept to measure what folding saves).
    Separate(Vec<f64>),
}

impl Spectral {
    pub fn weights(&self) -> &[f64] {
        match self {
            Spectral::Folded(w) | Spectral::Separate(w) => w,
        }
    }
}

/// The result of one aperture integral, luminous.
#[derive(Clone, Debug, PartialEq)]
pub struct Flux {
    /// Luminous flux (sr² units of the BRDF integral; the same units for specimen and standard).
    pub value: f64,
    /// Error estimate (absolute).
    pub error: f64,
    /// The analytic (delta) and numerical (regular) parts.
    pub delta: f64,
    pub regular: f64,
    pub evaluations: usize,
    pub regions: usize,
    pub converged: bool,
    pub seconds: f64,
    /// The variables the regular part was integrated in.
    pub variables: Variables,
}

/// Write the integrand: the per-sample values times the geometric factor `g`, either one component per
/// sample (`separate`) or folded into the luminous sum Σ w_k f_k·g.
#[inline]
fn store(out: &mut [f64], values: &[f64], weights: &[f64], g: f64, separate: bool) {
    if separate {
        for (o, v) in out.iter_mut().zip(values) {
            *o = v * g;
        }
    } else {
        out[0] = weights.iter().zip(values).map(|(a, b)| a * b).sum::<f64>() * g;
    }
}

/// Width in u (in-plane) and v (perpendicular) of a lobe at geometry angle θ.
/// A facet/flake tilt δ inside a medium of index η turns the internal reflected ray by 2δ; leaving the
/// medium, the in-plane deviation becomes 2δ·η cos θt / cos θ and the perpendicular one 2δ·η cos θt
/// (Snell's law for the tangential component), with sin θt = sin θ / η. For η = 1: (2δ, 2δ cos θ).
pub fn lobe_widths_uv(lobe: &Lobe, theta: f64) -> [f64; 2] {
    let eta = lobe.medium_eta.max(1e-6);
    let st = (theta.sin() / eta).min(1.0);
    let ct = (1.0 - st * st).max(0.0).sqrt();
    let c = theta.cos().max(1e-6);
    let m = lobe.slope_width;
    [2.0 * m * eta * ct / c, 2.0 * m * eta * ct]
}

/// The variables the regular part is integrated in, chosen per integral by [`choose_variables`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variables {
    /// The plain product of the stops, (p_s, q_s, p_r, q_r): one box, no kinks. Right when every lobe is at
    /// least as wide as the whole lobe-variable range on both axes (or there is none): the integrand is then
    /// smooth over the product and one 57-point Genz–Malik region may already meet the tolerance.
    Plain,
    /// The lobe variables (u, t_p, v, t_q) with splits at the overlap kinks and at multiples of the lobe
    /// widths: needed as soon as one lobe is narrower than the apertures.
    Lobe,
}

/// Choose the variables of the regular part for these (clipped) stops and lobes at angle θ.
pub fn choose_variables(lobes: &[Lobe], theta: f64, source: Stop, receptor: Stop) -> Variables {
    let range_u = (source.p[1] - source.p[0]) + (receptor.p[1] - receptor.p[0]);
    let range_v = (source.q[1] - source.q[0]) + (receptor.q[1] - receptor.q[0]);
    let wide = |l: &Lobe| {
        let w = lobe_widths_uv(l, theta);
        w[0] >= range_u && w[1] >= range_v
    };
    if lobes.iter().all(wide) {
        Variables::Plain
    } else {
        Variables::Lobe
    }
}

/// A list of boxes (lower corner, upper corner) in the 4-D lobe coordinates (u, t_p, v, t_q).
type Boxes4 = Vec<([f64; 4], [f64; 4])>;

/// One axis of the (source, receptor) pair in lobe coordinates.
#[derive(Clone, Copy, Debug)]
struct AxisMap {
    s: [f64; 2],
    r: [f64; 2],
}

impl AxisMap {
    fn range(&self) -> [f64; 2] {
        [self.s[0] + self.r[0], self.s[1] + self.r[1]]
    }

    /// (p_s, p_r, Jacobian) at lobe coordinate u and overlap position t.
    #[inline]
    fn at(&self, u: f64, t: f64) -> (f64, f64, f64) {
        let lo = self.s[0].max(u - self.r[1]);
        let hi = self.s[1].min(u - self.r[0]);
        let len = (hi - lo).max(0.0);
        let ps = lo + t * len;
        (ps, u - ps, len)
    }

    /// Split points of u: the range ends, the kinks of the overlap length, the lobe centre and multiples
    /// of each lobe width.
    fn splits(&self, widths: &[(f64, bool)]) -> Vec<f64> {
        let [a, b] = self.range();
        let mut pts = vec![a, b, self.s[1] + self.r[0], self.s[0] + self.r[1]];
        // Lobes within a factor 3 of a narrower one share its splits: the splits are geometric (×3 apart),
        // so they already resolve it, and each extra set multiplies the number of initial boxes. A shared
        // set reaches as far as the heaviest tail among the lobes it serves.
        let mut ws: Vec<(f64, bool)> = widths.iter().copied().filter(|(w, _)| *w > 0.0).collect();
        ws.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut kept: Vec<(f64, bool)> = Vec::new();
        for (w, heavy) in ws {
            match kept.last_mut() {
                Some(k) if w <= 3.0 * k.0 => k.1 |= heavy,
                _ => kept.push((w, heavy)),
            }
        }
        // Geometric splits at ±w, ±3w, ±10w, … For a heavy tail they go on (±30w, ±100w, …) to the end of the
        // range, so that no box spans more than a factor ≈ 3 in distance from the lobe centre and a tail
        // falling off as u⁻⁴ (GGX holds ~1e-4 of its mass beyond 100 widths) is seen by the first samples of
        // every box. A Gaussian tail is below e⁻¹⁰⁰ of the peak beyond 10w: the splits stop there.
        let range_reach = a.abs().max(b.abs());
        for &(w, heavy) in &kept {
            if w > 0.0 && w < 0.5 * (b - a) {
                pts.push(0.0);
                let reach = if heavy { range_reach } else { range_reach.min(10.0 * w * (1.0 + 1e-12)) };
                let mut k = 1.0;
                let mut step = 3.0;
                while k * w <= reach {
                    pts.push(k * w);
                    pts.push(-k * w);
                    k *= step;
                    step = if step == 3.0 { 10.0 / 3.0 } else { 3.0 };
                }
            }
        }
        pts.retain(|x| *x >= a && *x <= b);
        pts.sort_by(f64::total_cmp);
        let tiny = 1e-14 * (b - a).max(1e-300);
        pts.dedup_by(|x, y| (*x - *y).abs() <= tiny);
        pts
    }
}

/// Clip a stop to the upper hemisphere. For the source, z ∝ cos θ + p sin θ; for the receptor,
/// z ∝ cos θ − p sin θ: the horizon is the line p = ∓cot θ, independent of q, so clipping is exact.
pub fn clip(stop: Stop, theta: f64, is_source: bool) -> Option<Stop> {
    let mut s = stop;
    if theta > 0.0 {
        let cot = theta.cos() / theta.sin();
        if is_source {
            s.p[0] = s.p[0].max(-cot);
        } else {
            s.p[1] = s.p[1].min(cot);
        }
    }
    (s.p[1] > s.p[0] && s.q[1] > s.q[0]).then_some(s)
}

/// Everything needed for one aperture integral.
pub struct FluxProblem<'a> {
    pub brdf: &'a dyn Brdf,
    pub theta: f64,
    pub source: Stop,
    pub receptor: Stop,
    pub spectral: Spectral,
    /// Lobes of the BRDF (from `terms()`), for the split points.
    pub lobes: Vec<Lobe>,
    pub include_delta: bool,
    pub include_regular: bool,
    /// Relative tolerance on the flux, and an absolute floor.
    pub rtol: f64,
    pub atol: f64,
    pub max_evals: usize,
}

impl FluxProblem<'_> {
    /// The initial boxes of the regular integral in (u, t_p, v, t_q), and the axis maps.
    fn partition(&self, src: Stop, rec: Stop) -> (AxisMap, AxisMap, Boxes4) {
        let ap = AxisMap { s: src.p, r: rec.p };
        let aq = AxisMap { s: src.q, r: rec.q };
        let widths: Vec<[f64; 2]> = self.lobes.iter().map(|l| lobe_widths_uv(l, self.theta)).collect();
        let up = ap.splits(&widths.iter().zip(&self.lobes).map(|(w, l)| (w[0], l.heavy_tail)).collect::<Vec<_>>());
        let uq = aq.splits(&widths.iter().zip(&self.lobes).map(|(w, l)| (w[1], l.heavy_tail)).collect::<Vec<_>>());
        let mut boxes = Vec::with_capacity((up.len() - 1) * (uq.len() - 1));
        for a in up.windows(2) {
            for b in uq.windows(2) {
                boxes.push(([a[0], 0.0, b[0], 0.0], [a[1], 1.0, b[1], 1.0]));
            }
        }
        (ap, aq, boxes)
    }

    /// Compute the flux.
    pub fn solve(&self) -> Flux {
        let start = std::time::Instant::now();
        let weights = self.spectral.weights().to_vec();
        let n = weights.len();
        let axes = Axes::new(self.theta);
        let (Some(src), Some(rec)) = (clip(self.source, self.theta, true), clip(self.receptor, self.theta, false))
        else {
            return Flux {
                value: 0.0,
                error: 0.0,
                delta: 0.0,
                regular: 0.0,
                evaluations: 0,
                regions: 0,
                converged: true,
                seconds: 0.0,
                variables: Variables::Plain,
            };
        };
        let (separate, ncomp) = match self.spectral {
            Spectral::Folded(_) => (false, 1),
            Spectral::Separate(_) => (true, n),
        };
        let lum = |e: &Estimate| -> (f64, f64) {
            if separate {
                (
                    weights.iter().zip(&e.value).map(|(w, v)| w * v).sum(),
                    weights.iter().zip(&e.error).map(|(w, v)| w * v).sum(),
                )
            } else {
                (e.value[0], e.error[0])
            }
        };
        let mut scratch = vec![0.0; n];
        let mut evaluations = 0;
        let mut regions = 0;
        let mut converged = true;

        // 1. The delta part: source points whose mirror (−p, −q) lies in the receptor. It gets DELTA_SHARE
        // of the budget when a regular part follows, all of it otherwise (the gloss standard).
        let delta_share = if self.include_regular { DELTA_SHARE } else { 1.0 };
        let (mut delta, mut delta_err) = (0.0, 0.0);
        if self.include_delta {
            let lo = [src.p[0].max(-rec.p[1]), src.q[0].max(-rec.q[1])];
            let hi = [src.p[1].min(-rec.p[0]), src.q[1].min(-rec.q[0])];
            if hi[0] > lo[0] && hi[1] > lo[1] {
                let brdf = self.brdf;
                let w = &weights;
                let est = integrate::<2, _>(
                    |x, out| {
                        let wi = axes.source_dir(x[0], x[1]);
                        if wi.z <= 0.0 || !brdf.delta_reflectance(wi, &mut scratch) {
                            return;
                        }
                        store(out, &scratch, w, wi.z * solid_angle_density(x[0], x[1]), separate);
                    },
                    ncomp,
                    &[(lo, hi)],
                    &Options {
                        rtol: delta_share * self.rtol,
                        atol: delta_share * self.atol,
                        max_evals: self.max_evals,
                    },
                );
                (delta, delta_err) = lum(&est);
                evaluations += est.evaluations;
                regions += est.regions;
                converged &= est.converged;
            }
        }

        // 2. The regular part, in the plain variables or in lobe coordinates (`choose_variables`).
        let (mut regular, mut regular_err) = (0.0, 0.0);
        let variables = choose_variables(&self.lobes, self.theta, src, rec);
        if self.include_regular {
            let (ap, aq, boxes) = match variables {
                Variables::Lobe => self.partition(src, rec),
                Variables::Plain => (
                    AxisMap { s: src.p, r: rec.p },
                    AxisMap { s: src.q, r: rec.q },
                    vec![([src.p[0], src.q[0], rec.p[0], rec.q[0]], [src.p[1], src.q[1], rec.p[1], rec.q[1]])],
                ),
            };
            let plain = variables == Variables::Plain;
            let brdf = self.brdf;
            let w = &weights;
            // The regular part gets the rest of the budget: err_r ≤ max(atol, r·|Φ_δ|, r·|Φ_r|) with
            // r = (1 − DELTA_SHARE)·rtol, so err_δ + err_r ≤ rtol·(|Φ_δ| + |Φ_r|) (+ the floor) as both parts are ≥ 0.
            let share = 1.0 - DELTA_SHARE;
            let atol = (share * self.atol).max(share * self.rtol * delta.abs());
            let est = integrate::<4, _>(
                |x, out| {
                    let (ps, qs, pr, qr, jac) = if plain {
                        (x[0], x[1], x[2], x[3], 1.0)
                    } else {
                        let (ps, pr, jp) = ap.at(x[0], x[1]);
                        let (qs, qr, jq) = aq.at(x[2], x[3]);
                        (ps, qs, pr, qr, jp * jq)
                    };
                    if jac <= 0.0 {
                        return;
                    }
                    let wi = axes.source_dir(ps, qs);
                    let wo = axes.receptor_dir(pr, qr);
                    if wi.z <= 0.0 || wo.z <= 0.0 {
                        return;
                    }
                    brdf.eval(wi, wo, &mut scratch);
                    let g = wi.z * wo.z * solid_angle_density(ps, qs) * solid_angle_density(pr, qr) * jac;
                    store(out, &scratch, w, g, separate);
                },
                ncomp,
                &boxes,
                &Options { rtol: share * self.rtol, atol, max_evals: self.max_evals },
            );
            (regular, regular_err) = lum(&est);
            evaluations += est.evaluations;
            regions += est.regions;
            converged &= est.converged;
        }
        Flux {
            value: delta + regular,
            error: delta_err + regular_err,
            delta,
            regular,
            evaluations,
            regions,
            converged,
            seconds: start.elapsed().as_secs_f64(),
            variables,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlap_map_covers_the_product_exactly() {
        // ∫ du ∫ dt Jacobian = area of the product of the two intervals.
        let m = AxisMap { s: [-0.01, 0.02], r: [-0.03, 0.05] };
        let sp = m.splits(&[(1e-4, true)]);
        let mut total = 0.0;
        for w in sp.windows(2) {
            // the overlap length is linear on each piece: the midpoint rule is exact
            let u = 0.5 * (w[0] + w[1]);
            total += m.at(u, 0.5).2 * (w[1] - w[0]);
        }
        assert!((total - 0.03 * 0.08).abs() < 1e-15, "{total}");
    }

    #[test]
    fn mirror_point_is_the_mirror_direction() {
        let axes = Axes::new(0.9);
        let wi = axes.source_dir(0.013, -0.02);
        let wo = axes.receptor_dir(-0.013, 0.02);
        let m = crate::brdf::mirror(wi);
        assert!((m - wo).length() < 1e-15);
    }
}
