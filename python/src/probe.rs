//! Finding the lobe of a black-box BRDF.
//!
//! Why: the integrator splits its lobe variables at multiples of each lobe's width so that a lobe of any
//! width is seen by the first samples (`docs/instrument.md` §Quadrature). A model in Rust states its widths in
//! `Hints::terms`; a Python function does not, and adaptive cubature over the apertures would silently return
//! ≈ 0 for a lobe narrower than its first sample spacing. So, when the caller gives no hint, we probe f along a
//! geometric ladder of deviations from the specular direction (in the plane of measurement and across it, at
//! the centre of the source aperture of every angle measured) and take the smallest deviation at which f has
//! changed by [`CHANGE`] as the lobe's scale.
//!
//! From that deviation to a slope width: for a Gaussian (Beckmann-like) lobe D ∝ exp(−tan²θh / m²), f falls by
//! 5 % where tan θh = m·√(−ln 0.95) = 0.2265·m, so m = tan θh / 0.2265 with θh the half-vector's tilt at the
//! last ladder step still within 5 %. A lobe that falls faster than a Gaussian near its peak (GGX: 5 % at
//! 0.161·α) is reported narrower than it is, which only adds splits; the tail is always taken as heavy (the
//! splits go on geometrically to the ends of the range), since nothing is known of it.
use glossmeter::brdf::{Lobe, Tail};
use glossmeter::instrument::geometry::Axes;
use glossmeter::Vec3;

/// Relative change of f that marks the lobe's scale.
pub const CHANGE: f64 = 0.05;
/// tan θh / m at which a Gaussian lobe has fallen by [`CHANGE`]: √(−ln(1 − CHANGE)).
pub fn gaussian_fraction() -> f64 {
    (-(1.0 - CHANGE).ln()).sqrt()
}
/// Deviations from the specular direction (radians): 1e-7 to 1, four steps a decade.
pub fn ladder() -> Vec<f64> {
    (0..=28).map(|k| 1e-7 * 10f64.powf(k as f64 / 4.0)).collect()
}

/// The probe points of one angle θ: (wi, wo) pairs, the specular pair first, then the in-plane ladder (the
/// receptor turned towards the normal), then the perpendicular one.
pub fn points(theta: f64) -> Vec<(Vec3, Vec3)> {
    let axes = Axes::new(theta);
    let wi = axes.source_dir(0.0, 0.0);
    let mut out = vec![(wi, axes.receptor_dir(0.0, 0.0))];
    for d in ladder() {
        out.push((wi, axes.receptor_dir(-d.tan(), 0.0)));
    }
    for d in ladder() {
        out.push((wi, axes.receptor_dir(0.0, d.tan())));
    }
    out
}

/// tan of the half vector's tilt from the normal.
fn half_slope(wi: Vec3, wo: Vec3) -> f64 {
    let h = (wi + wo).normalize();
    (h.x * h.x + h.y * h.y).sqrt() / h.z
}

/// What the probe found at one angle.
#[derive(Clone, Debug, PartialEq)]
pub enum Found {
    /// f is zero (or not positive) at the specular direction: nothing to centre a lobe on.
    NoPeak,
    /// f is within [`CHANGE`] of its specular value along the whole ladder: smooth (diffuse-like).
    Flat,
    /// A lobe of this slope width; `finer_than_ladder` if f had already changed at the first step.
    Lobe { slope_width: f64, finer_than_ladder: bool, axis: &'static str },
}

/// Analyse the luminous values of f at [`points`]`(theta)`.
pub fn analyse(theta: f64, values: &[f64]) -> Found {
    let pts = points(theta);
    assert_eq!(pts.len(), values.len());
    let v0 = values[0];
    if !(v0 > 0.0) {
        return Found::NoPeak;
    }
    let n = ladder().len();
    let mut best: Option<(f64, bool, &'static str)> = None;
    for (axis, range) in [("in-plane", 1..=n), ("perpendicular", n + 1..=2 * n)] {
        let start = *range.start();
        for i in range {
            if (values[i] - v0).abs() > CHANGE * v0 {
                // The last step still within CHANGE (or the first step itself when f changed at once).
                let finer = i == start;
                let j = if finer { i } else { i - 1 };
                let (wi, wo) = pts[j];
                let m = half_slope(wi, wo) / gaussian_fraction();
                let m = if finer { m * 0.1 } else { m };
                if best.is_none_or(|b| m < b.0) {
                    best = Some((m, finer, axis));
                }
                break;
            }
        }
    }
    match best {
        None => Found::Flat,
        Some((slope_width, finer_than_ladder, axis)) => Found::Lobe { slope_width, finer_than_ladder, axis },
    }
}

/// The lobe to give the integrator from the findings at every angle (the narrowest), and the note saying so.
pub fn conclude(found: &[(f64, Found)]) -> (Vec<Lobe>, String) {
    let mut best: Option<(f64, f64, bool, &'static str)> = None;
    for (theta, f) in found {
        if let Found::Lobe { slope_width, finer_than_ladder, axis } = f {
            if best.is_none_or(|b| *slope_width < b.1) {
                best = Some((*theta, *slope_width, *finer_than_ladder, axis));
            }
        }
    }
    let n = found.len();
    match best {
        None => {
            let no_peak = found.iter().filter(|(_, f)| *f == Found::NoPeak).count();
            let note = if no_peak > 0 {
                format!(
                    "lobes probed (no `lobes` hint): f is not positive at the specular direction at {no_peak} of {n} \
                     angle(s) and varies by less than {:.0} % along the probe elsewhere; integrated as smooth. If f \
                     has a lobe elsewhere, pass lobes=[...]",
                    CHANGE * 100.0
                )
            } else {
                format!(
                    "lobes probed (no `lobes` hint): f varies by less than {:.0} % within 1 rad of the specular \
                     direction at {n} angle(s); integrated as smooth (no lobe splits)",
                    CHANGE * 100.0
                )
            };
            (vec![], note)
        }
        Some((theta, m, finer, axis)) => {
            let mut note = format!(
                "lobe probed (no `lobes` hint): f changes by {:.0} % at a facet slope ≈ {m:.3e} ({axis}, θ = \
                 {:.2}°); integrated as one heavy-tailed lobe of slope width {m:.3e}. Pass lobes=[...] to skip the probe",
                CHANGE * 100.0,
                theta.to_degrees()
            );
            if finer {
                note.push_str(
                    "; f changed already at the probe's first step (1e-7 rad), so the width is only bounded: if f \
                     has a mirror component, pass it as delta=",
                );
            }
            let lobe =
                Lobe { slope_width: m, medium_eta: 1.0, label: "lobe of f (probed)".into(), tail: Tail::Unknown };
            (vec![lobe], note)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn beckmann(m: f64) -> impl Fn(Vec3, Vec3) -> f64 {
        move |wi, wo| {
            let t = half_slope(wi, wo);
            (-(t * t) / (m * m)).exp()
        }
    }

    #[test]
    fn a_gaussian_lobe_is_found_within_one_ladder_step() {
        for m in [1e-4, 3e-3, 0.1] {
            for theta in [20f64.to_radians(), 60f64.to_radians(), 85f64.to_radians()] {
                let f = beckmann(m);
                let v: Vec<f64> = points(theta).iter().map(|(a, b)| f(*a, *b)).collect();
                match analyse(theta, &v) {
                    Found::Lobe { slope_width, finer_than_ladder: false, .. } => {
                        // at most one step (10^¼) narrower, never wider
                        assert!(slope_width <= m * 1.0001 && slope_width > m / 1.8, "m {m} θ {theta}: {slope_width}");
                    }
                    other => panic!("m {m}: {other:?}"),
                }
            }
        }
    }

    #[test]
    fn a_constant_is_flat_and_zero_has_no_peak() {
        let n = points(0.3).len();
        assert_eq!(analyse(0.3, &vec![0.5; n]), Found::Flat);
        assert_eq!(analyse(0.3, &vec![0.0; n]), Found::NoPeak);
        let (lobes, note) = conclude(&[(0.3, Found::Flat)]);
        assert!(lobes.is_empty() && note.contains("smooth"));
    }
}
