//! Independent references for the instrument integral: closed forms and plain Gauss–Legendre rules that
//! share no code with the engine's quadrature (`aperture.rs`, `method/`, `quadrature/`): they keep their own
//! Gauss–Legendre generator, horizon clipping and mirror overlap on purpose. Used by `glossmeter convergence`
//! to measure the actual error of Lambertian readings, and by the tests. (The stiff and extreme suite,
//! `tests/stability.rs`, keeps its own copy on purpose, with its own horizon clipping.)
//!
//! * [`projected_solid_angle`]: ∫ cos θ dω over a stop, by Lambert's formula for a spherical polygon;
//! * [`lambertian_flux_reference`]: f·P_s·P_r for a constant BRDF f;
//! * [`mirror_flux_reference`]: ∫ R(θi) cos θi dω over the mirror overlap of the stops, 64 × 64 Gauss–Legendre.
use crate::instrument::geometry::Stop;
use crate::Vec3;

/// Projected solid angle ∫ cos θ dω of the pyramid over a stop (tangent coordinates about `axis`, with
/// in-plane unit vector `e_par` and perpendicular unit vector y), by Lambert's formula for a spherical
/// polygon: ½ |Σ_edges γ_e (n_e · z)|, γ_e the angle subtended by the edge and n_e the unit normal of the
/// plane through the edge and the origin (Lambert 1760; Arvo 1995, "Applications of irradiance tensors",
/// Eq. 3). Valid for a polygon on or above the horizon.
pub fn projected_solid_angle(axis: Vec3, e_par: Vec3, stop: Stop) -> f64 {
    let e_perp = Vec3::new(0.0, 1.0, 0.0);
    let corners = [(stop.p[0], stop.q[0]), (stop.p[1], stop.q[0]), (stop.p[1], stop.q[1]), (stop.p[0], stop.q[1])];
    let v: Vec<Vec3> = corners.iter().map(|(p, q)| (axis + *p * e_par + *q * e_perp).normalize()).collect();
    let mut s = 0.0;
    for i in 0..4 {
        let (a, b) = (v[i], v[(i + 1) % 4]);
        let c = a.cross(b);
        let len = c.length();
        if len == 0.0 {
            continue;
        }
        let gamma = len.atan2(a.dot(b));
        s += gamma * c.z / len;
    }
    0.5 * s.abs()
}

/// The part of a stop above the horizon (this module's own copy of the clipping): a source direction has
/// z ∝ cos θ + p sin θ and a receptor direction z ∝ cos θ − p sin θ, so the horizon is the line p = ∓cot θ.
fn clip(stop: Stop, theta: f64, is_source: bool) -> Option<Stop> {
    let mut s = stop;
    if theta > 0.0 {
        let limit = theta.cos() / theta.sin();
        if is_source {
            s.p[0] = s.p[0].max(-limit);
        } else {
            s.p[1] = s.p[1].min(limit);
        }
    }
    (s.p[0] < s.p[1] && s.q[0] < s.q[1]).then_some(s)
}

/// Gauss–Legendre nodes and weights on [−1, 1], by Newton's iteration on P_n.
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// Independent mirror flux: ∫∫ R(θi) cos θi dω over the source points (p, q) whose mirror image (−p, −q)
/// lies in the receptor, by a 64 × 64 Gauss–Legendre product rule on that overlap box.
pub fn mirror_flux_reference(theta: f64, src: Stop, rec: Stop, refl: &dyn Fn(f64) -> f64) -> f64 {
    let (Some(src), Some(rec)) = (clip(src, theta, true), clip(rec, theta, false)) else {
        return 0.0;
    };
    let (p0, p1) = (src.p[0].max(-rec.p[1]), src.p[1].min(-rec.p[0]));
    let (q0, q1) = (src.q[0].max(-rec.q[1]), src.q[1].min(-rec.q[0]));
    if !(p1 > p0 && q1 > q0) {
        return 0.0;
    }
    let gl = gauss_legendre(64);
    let (c, s) = (theta.cos(), theta.sin());
    let mut total = 0.0;
    for (xp, wp) in &gl {
        let p = 0.5 * (p0 + p1) + 0.5 * (p1 - p0) * xp;
        for (xq, wq) in &gl {
            let q = 0.5 * (q0 + q1) + 0.5 * (q1 - q0) * xq;
            let r2 = 1.0 + p * p + q * q;
            let cos_i = ((c + p * s) / r2.sqrt()).max(0.0);
            total += wp * wq * refl(cos_i) * cos_i / (r2 * r2.sqrt());
        }
    }
    total * 0.25 * (p1 - p0) * (q1 - q0)
}

/// Independent Lambertian flux (f = `f_lum` everywhere) through one source and one receptor stop.
pub fn lambertian_flux_reference(theta: f64, src: Stop, rec: Stop, f_lum: f64) -> f64 {
    let (Some(src), Some(rec)) = (clip(src, theta, true), clip(rec, theta, false)) else {
        return 0.0;
    };
    let (s, c) = theta.sin_cos();
    let ps = projected_solid_angle(Vec3::new(-s, 0.0, c), Vec3::new(c, 0.0, s), src);
    let pr = projected_solid_angle(Vec3::new(s, 0.0, c), Vec3::new(c, 0.0, -s), rec);
    f_lum * ps * pr
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projected_solid_angle_of_a_small_stop_is_cos_times_solid_angle() {
        // A 1 mrad square stop about an axis at 60°: P ≈ cos 60° · Ω to second order in the size.
        let t: f64 = 60f64.to_radians();
        let stop = Stop { p: [-5e-4, 5e-4], q: [-5e-4, 5e-4] };
        let p = projected_solid_angle(Vec3::new(-t.sin(), 0.0, t.cos()), Vec3::new(t.cos(), 0.0, t.sin()), stop);
        let expect = t.cos() * stop.solid_angle();
        assert!((p - expect).abs() < 1e-6 * expect, "{p} vs {expect}");
    }

    #[test]
    fn projected_solid_angle_of_the_hemisphere_is_pi() {
        // The whole tangent plane about the normal, truncated far out, tends to π.
        let big = 1e7;
        let p = projected_solid_angle(Vec3::Z, Vec3::X, Stop { p: [-big, big], q: [-big, big] });
        assert!((p - std::f64::consts::PI).abs() < 1e-6, "{p}");
    }

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        let gl = gauss_legendre(64);
        let s: f64 = gl.iter().map(|(x, w)| w * x.powi(126)).sum();
        assert!((s - 2.0 / 127.0).abs() < 1e-14, "{s}");
        let w: f64 = gl.iter().map(|(_, w)| w).sum();
        assert!((w - 2.0).abs() < 1e-14);
    }
}
