//! [`Rule::TailBound`]'s executor (docs/instrument.md §Quadrature, "A receptor the lobe cannot reach"): the
//! regular part settled by the material's majorant of its tail ([`Brdf::tail_majorant`]) instead of a
//! partition. Over the source stop S and the receptor stop R every pair's ωo is at least ψ from the mirror
//! image of ωi ([`mirror_gap`]), so 0 ≤ f_j·cos θi·cos θo ≤ B(ψ) for every sample j, and the flux's component
//! c, Σ_j W_cj ∫_S ∫_R f_j cos θi cos θo dωi dωo (docs/instrument.md §1.4), lies in [L_c, U_c] with
//! U_c = Σ_j max(W_cj, 0)·B·Ω_S·Ω_R and L_c = Σ_j min(W_cj, 0)·B·Ω_S·Ω_R. The reading is the middle of that
//! interval and its error the half width (an estimate that covers the actual error), accepted when the half
//! width meets the part's tolerance; otherwise the partition runs ([`Rule::fallback`]). No evaluation is spent.
use super::shape::Outcome;
use super::{Method, Projection, Rule};
use crate::brdf::Brdf;
use crate::instrument::geometry::{Axes, Stop};
use crate::quadrature::{Estimate, Options};
use crate::Vec3;

/// Rounding margin on the bound (the solid angles' closed form, the angles' trigonometry).
const MARGIN: f64 = 1e-9;

/// The angle between two unit vectors, atan2(|a × b|, a·b) (accurate at small angles).
fn angle(a: Vec3, b: Vec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// The direction of a stop's centre and its angular radius about it: the largest angle to a corner (the set of
/// directions within an angle of a direction is convex in tangent coordinates, a conic section's interior,
/// so a rectangle lies in it when its corners do).
fn cone(stop: Stop, dir: impl Fn(f64, f64) -> Vec3) -> (Vec3, f64) {
    let c = dir(0.5 * (stop.p[0] + stop.p[1]), 0.5 * (stop.q[0] + stop.q[1]));
    let r =
        [(0, 0), (0, 1), (1, 0), (1, 1)].iter().map(|&(i, j)| angle(c, dir(stop.p[i], stop.q[j]))).fold(0.0, f64::max);
    (c, r)
}

/// A lower bound of the angle between ωo and the mirror image of ωi over the source stop `src` (on the axes of
/// `theta`) and the receptor stop `rec` (on the axes of `viewing`): the angle between the receptor's centre
/// and the mirrored source centre, less the two stops' angular radii (the triangle inequality on the sphere;
/// the mirror is an isometry), less a rounding margin; 0 when that is negative.
pub(crate) fn mirror_gap(theta: f64, viewing: f64, src: Stop, rec: Stop) -> f64 {
    let (s_axes, r_axes) = (Axes::new(theta), Axes::new(viewing));
    let (s, rs) = cone(src, |p, q| s_axes.source_dir(p, q));
    let (r, rr) = cone(rec, |p, q| r_axes.receptor_dir(p, q));
    let mirrored = Vec3::new(-s.x, -s.y, s.z);
    (angle(r, mirrored) - rs - rr - 1e-12).max(0.0)
}

/// Slabs of u = p_s + p_r over which the bound is summed on the mirror axis ([`flux_bound`]).
const SLABS: usize = 64;

/// The area of {(x, y) ∈ [a0, a1] × [b0, b1] : x + y ≤ u} (inclusion–exclusion of the four corners' ramps).
fn area_below(a: [f64; 2], b: [f64; 2], u: f64) -> f64 {
    let ramp = |c: f64| (u - c).max(0.0).powi(2);
    0.5 * (ramp(a[0] + b[0]) - ramp(a[1] + b[0]) - ramp(a[0] + b[1]) + ramp(a[1] + b[1]))
}

/// A bound of ∫_S ∫_R f_j cos θi cos θo dωi dωo for every sample j from the material's majorant `majorant`
/// (ψ ↦ B(ψ), [`Brdf::tail_majorant`]). Off the mirror axis: B at [`mirror_gap`] times the two solid angles.
/// On it (receptor point (p_r, q_r) and the mirror image (−p_s, −q_s) of a source point in one tangent plane,
/// docs/instrument.md §1.3): with a = (p_r, q_r), b = (−p_s, −q_s), sin ψ = |(1, a) × (1, b)| /
/// (|(1, a)|·|(1, b)|) ≥ |a − b| / (1 + X²), X² the largest |x|² of either rectangle, and |a − b|² ≥ u² + g²
/// with u = p_s + p_r and g the gap between the q ranges; dω ≤ dp dq. So the integral is at most
/// Σ_k B(ψ_k)·|S_q|·|R_q|·A_k over [`SLABS`] slabs of u, A_k the area of the slab in (p_s, p_r)
/// ([`area_below`]) and ψ_k from the slab's smallest |u|.
fn flux_bound(theta: f64, viewing: f64, src: Stop, rec: Stop, majorant: impl Fn(f64) -> Option<f64>) -> Option<f64> {
    if viewing != theta {
        return Some(majorant(mirror_gap(theta, viewing, src, rec))? * src.solid_angle() * rec.solid_angle());
    }
    let corner = |s: Stop| (s.p[0].abs().max(s.p[1].abs())).powi(2) + (s.q[0].abs().max(s.q[1].abs())).powi(2);
    let shrink = 1.0 / (1.0 + corner(src).max(corner(rec)));
    // q_r − (−q_s) = q_r + q_s over the two q ranges: its smallest magnitude.
    let (q_lo, q_hi) = (src.q[0] + rec.q[0], src.q[1] + rec.q[1]);
    let g = if q_lo > 0.0 {
        q_lo
    } else if q_hi < 0.0 {
        -q_hi
    } else {
        0.0
    };
    let (u_lo, u_hi) = (src.p[0] + rec.p[0], src.p[1] + rec.p[1]);
    let q_area = (src.q[1] - src.q[0]) * (rec.q[1] - rec.q[0]);
    let mut sum = 0.0;
    for k in 0..SLABS {
        let (a, b) = (
            u_lo + (u_hi - u_lo) * k as f64 / SLABS as f64,
            if k + 1 == SLABS { u_hi } else { u_lo + (u_hi - u_lo) * (k + 1) as f64 / SLABS as f64 },
        );
        let u_min = if a > 0.0 {
            a
        } else if b < 0.0 {
            -b
        } else {
            0.0
        };
        let sin = ((u_min * u_min + g * g).sqrt() * shrink).min(1.0);
        let psi = (sin.asin() - 1e-12).max(0.0);
        let area = (area_below(src.p, rec.p, b) - area_below(src.p, rec.p, a)).max(0.0);
        if area > 0.0 {
            sum += majorant(psi)? * area;
        }
    }
    Some(sum * q_area)
}

impl Method {
    /// Settle the regular part by the material's tail majorant, if it has one that meets the part's tolerance
    /// `opts` (the module documentation); `ncomp` components.
    pub(super) fn settle_by_tail(
        &self,
        brdf: &dyn Brdf,
        (src, rec): (Stop, Stop),
        ncomp: usize,
        opts: &Options,
    ) -> Outcome {
        let refused = Outcome { done: None, spent: 0 };
        let majorant = |psi: f64| brdf.tail_majorant(psi).filter(|b| b.is_finite() && *b >= 0.0);
        let Some(b) = flux_bound(self.aperture.theta, self.aperture.viewing, src, rec, majorant) else {
            return refused;
        };
        let bound = b * (1.0 + MARGIN);
        let (lower, upper): (Vec<f64>, Vec<f64>) = match self.projection {
            Projection::Separate => (vec![0.0; ncomp], vec![bound; ncomp]),
            Projection::Fold | Projection::FoldInMaterial => self
                .weighting
                .rows
                .iter()
                .map(|row| {
                    let sum = |sign: f64| row.iter().map(|w| (sign * w).max(0.0)).sum::<f64>() * bound;
                    (-sum(-1.0), sum(1.0))
                })
                .unzip(),
        };
        let value: Vec<f64> = lower.iter().zip(&upper).map(|(l, u)| 0.5 * (l + u)).collect();
        let error: Vec<f64> = lower.iter().zip(&upper).map(|(l, u)| 0.5 * (u - l)).collect();
        if error.iter().zip(&value).any(|(e, v)| *e > opts.atol.max(opts.rtol * v.abs())) {
            return refused;
        }
        let est = Estimate { value, error, evaluations: 0, regions: 0, converged: true, out_of_time: false };
        Outcome { done: Some((est, Rule::TailBound, None)), spent: 0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::standards;

    fn material(distribution: &str, roughness: f64) -> std::sync::Arc<dyn Brdf> {
        let text =
            format!(r#"{{"model":"microfacet","distribution":"{distribution}","roughness":{roughness:e},"ior":1.5}}"#);
        crate::recipe::parse_str(&text, "<tail>").unwrap().brdf
    }

    /// The majorant bounds f·cos θi·cos θo at every point of the two stops (random points, their corners and
    /// the points nearest the mirror image on a fine grid of the edges), for Beckmann and GGX at several
    /// roughnesses, on every off-specular receptor of E430 30° and E430 20° and on receptors moved off the
    /// D523 axes by 1–10°.
    #[test]
    fn the_tail_majorant_bounds_the_integrand_over_the_stops() {
        let mut cases: Vec<(f64, f64, Stop, Stop)> = Vec::new();
        for id in ["astm-e430-30", "astm-e430-20"] {
            let g = standards::find(id).unwrap().geometry;
            for (name, rec) in &g.receptors {
                if name != "specular" && !name.starts_with("doi") {
                    cases.push((g.theta, g.theta, g.source, *rec));
                }
            }
        }
        for id in ["astm-d523-20", "astm-d523-60"] {
            let g = standards::find(id).unwrap().geometry;
            let rec = *g.receptor("gloss").unwrap();
            for off in [1.0f64, 3.0, 10.0] {
                cases.push((g.theta, g.theta + off.to_radians(), g.source, rec));
                cases.push((g.theta, g.theta - off.to_radians(), g.source, rec));
            }
        }
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut f = [0.0];
        let (mut checked, mut tight) = (0, 0.0f64);
        for d in ["beckmann", "ggx"] {
            for m in [0.001, 0.003, 0.01, 0.03, 0.1, 0.3] {
                let brdf = material(d, m);
                for &(theta, viewing, src, rec) in &cases {
                    let psi = mirror_gap(theta, viewing, src, rec);
                    let bound = brdf.tail_majorant(psi).unwrap();
                    let (sa, ra) = (Axes::new(theta), Axes::new(viewing));
                    let lerp = |s: [f64; 2], t: f64| s[0] + t * (s[1] - s[0]);
                    for k in 0..4000 {
                        // Corners and edge points first, then random interior points.
                        let t: [f64; 4] = if k < 256 {
                            let e = |b: usize| ((k >> b) & 1) as f64;
                            [e(0), e(1), e(2), e(3)].map(|x| x.clamp(0.0, 1.0))
                        } else if k < 1000 {
                            let mut t = [uniform(), uniform(), uniform(), uniform()];
                            t[k % 4] = (k / 4 % 2) as f64;
                            t
                        } else {
                            [uniform(), uniform(), uniform(), uniform()]
                        };
                        let wi = sa.source_dir(lerp(src.p, t[0]), lerp(src.q, t[1]));
                        let wo = ra.receptor_dir(lerp(rec.p, t[2]), lerp(rec.q, t[3]));
                        if wi.z <= 0.0 || wo.z <= 0.0 {
                            continue;
                        }
                        brdf.eval(wi, wo, &mut f);
                        let value = f[0] * wi.z * wo.z;
                        assert!(value <= bound, "{d} {m}: {value:e} > {bound:e} at ψ = {psi}");
                        checked += 1;
                        if value > 0.0 {
                            tight = tight.max(value / bound);
                        }
                    }
                }
            }
        }
        eprintln!("{checked} points, largest value/bound {tight:e}");
        assert!(checked > 100_000 && tight > 0.0, "{checked} points, largest value/bound {tight:e}");
    }

    /// The gap is the angle from the mirrored source to the receptor less the radii: on D523 60° the receptor
    /// sees the mirror image (0); moved 10° off, 10° less the two half-diagonals (0.11 and 0.03 rad).
    #[test]
    fn the_mirror_gap_of_a_receptor_that_sees_the_image_is_zero() {
        let g = standards::find("astm-d523-60").unwrap().geometry;
        let rec = *g.receptor("gloss").unwrap();
        assert_eq!(mirror_gap(g.theta, g.theta, g.source, rec), 0.0);
        let off = mirror_gap(g.theta, g.theta + 0.1745, g.source, rec);
        assert!(off > 0.1745 - 0.15 && off < 0.1745, "{off}");
    }
}
