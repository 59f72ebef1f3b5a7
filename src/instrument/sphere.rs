//! The d/8 integrating sphere's two integrals (`docs/colour.md` §d/8), per spectral sample.
//!
//! Why a module of its own: a sphere illuminates the whole hemisphere, which no pair of field stops in tangent
//! coordinates covers, so these are not aperture integrals; they are what [`crate::instrument::method::Method`]
//! executes for [`Integral::Hemisphere`] and [`Integral::Port`] (the plan weights their per-sample results
//! with the same k × n weighting as any flux).
//!
//! * **Hemisphere**: R(λ) = ∫_H f(ωi, ω8) cos θi dωi (uniform diffuse illumination, viewing along ω8), computed as
//!   `brdf::albedo::directional_albedo` of the transposed BRDF at ω8: the 8° directional–hemispherical
//!   reflectance by Helmholtz reciprocity; the transposition makes it exact for non-reciprocal models too.
//! * **Port**: what the specular port (a cone of half-angle β about the mirror of ω8) removes for SCE: the delta
//!   reflectance and ∫_cone f(ω, ω8) cos θ dω, in polar tangent coordinates (t, φ) about the port axis,
//!   dω = t dt dφ / (1 + t²)^{3/2}, with radial splits at multiples of each lobe's width.
//!
//! [`Integral::Hemisphere`]: crate::instrument::geometry::Integral::Hemisphere
//! [`Integral::Port`]: crate::instrument::geometry::Integral::Port
use std::f64::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::brdf::albedo::directional_albedo;
use crate::brdf::{Brdf, Hints};
use crate::instrument::aperture::lobe_widths_uv;
use crate::quadrature::{integrate, pointwise, Options};
use crate::spectrum::Sampling;
use crate::Vec3;

/// A per-sample result: values, absolute error bounds, evaluations, converged.
pub(crate) struct PerSample {
    pub value: Vec<f64>,
    pub error: Vec<f64>,
    pub evaluations: usize,
    pub converged: bool,
}

/// The BRDF with its arguments exchanged, f_T(a, b) = f(b, a): what a sphere's viewing direction sees.
/// It counts its evaluations (the albedo integrator runs single-threaded, so the count is deterministic).
#[derive(Debug)]
struct Transposed<'a>(&'a dyn Brdf, AtomicUsize);

impl Brdf for Transposed<'_> {
    fn sampling(&self) -> &Sampling {
        self.0.sampling()
    }
    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        self.1.fetch_add(1, Ordering::Relaxed);
        self.0.eval(wo, wi, out)
    }
    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        // The mirror pair is symmetric: R_δ of the mirror direction of wi, which has the same polar angle.
        self.0.delta_reflectance(crate::brdf::mirror(wi), out)
    }
    /// The model's own: seams are in the cosine of either direction, so the transposition keeps them; a
    /// half-angle kink is symmetric (ωi·h = ωo·h) and the delta term's kink is in the polar angle of ωi, which
    /// the mirror pair shares; reciprocity and smoothness are kept by an exchange of the arguments.
    fn hints(&self) -> Hints {
        self.0.hints()
    }
    fn describe(&self) -> String {
        format!("transposed {}", self.0.describe())
    }
}

/// ∫_H f(ωi, ω_v) cos θi dωi per sample, ω_v at `viewing` radians from the normal in the x–z plane (delta
/// included). The error bound is the albedo integrator's (absolute, the same for every sample).
pub(crate) fn hemisphere_reflectance(brdf: &dyn Brdf, viewing: f64) -> PerSample {
    let n = brdf.sampling().len();
    let wv = Vec3::new(viewing.sin(), 0.0, viewing.cos());
    let t = Transposed(brdf, AtomicUsize::new(0));
    let (value, e) = directional_albedo(&t, wv);
    PerSample { value, error: vec![e; n], evaluations: t.1.load(Ordering::Relaxed), converged: true }
}

/// Reflectance into the specular port per sample: the delta reflectance (its mirror direction is the port's
/// axis) plus ∫_cone f(ω, ω_v) cos θ dω over the cone of half-angle `beta` about the mirror of the viewing
/// direction.
pub(crate) fn port_reflectance(brdf: &dyn Brdf, viewing: f64, beta: f64, rtol: f64, max_evals: usize) -> PerSample {
    let n = brdf.sampling().len();
    let (sv, cv) = viewing.sin_cos();
    let wv = Vec3::new(sv, 0.0, cv);
    let axis = Vec3::new(-sv, 0.0, cv);
    let e1 = Vec3::new(cv, 0.0, sv);
    let e2 = Vec3::new(0.0, 1.0, 0.0);
    let mut delta = vec![0.0; n];
    if !brdf.delta_reflectance(axis, &mut delta) {
        delta.fill(0.0);
    }
    if !brdf.has_regular() {
        return PerSample { value: delta, error: vec![0.0; n], evaluations: 0, converged: true };
    }
    let tmax = beta.tan();
    // Radial splits at 3ᵏ multiples of each lobe's width in the reflected direction (u of `aperture::lobe_widths_uv`).
    let mut ts = vec![0.0, tmax];
    for l in brdf.lobes() {
        let w = lobe_widths_uv(&l, viewing)[0];
        let mut k = 1.0;
        while k * w < tmax {
            ts.push(k * w);
            k *= 3.0;
        }
    }
    ts.sort_by(f64::total_cmp);
    ts.dedup();
    let phis = [0.0, 0.5 * PI, PI, 1.5 * PI, 2.0 * PI];
    let mut boxes = Vec::new();
    for t in ts.windows(2) {
        for p in phis.windows(2) {
            boxes.push(([t[0], p[0]], [t[1], p[1]]));
        }
    }
    let mut f = vec![0.0; n];
    let est = integrate::<2, _>(
        pointwise(n, |x: &[f64; 2], out: &mut [f64]| {
            let (t, phi) = (x[0], x[1]);
            let (s, c) = phi.sin_cos();
            let w = (axis + t * (c * e1 + s * e2)).normalize();
            if w.z <= 0.0 {
                return;
            }
            brdf.eval(w, wv, &mut f);
            let g = w.z * t / (1.0 + t * t).powf(1.5);
            for (o, v) in out.iter_mut().zip(&f) {
                *o = v * g;
            }
        }),
        n,
        &boxes,
        &Options { rtol, atol: 1e-4 * rtol, max_evals, deadline: None, ..Default::default() },
    );
    let value = delta.iter().zip(&est.value).map(|(d, r)| d + r).collect();
    PerSample { value, error: est.error, evaluations: est.evaluations, converged: est.converged }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::lambert::Lambert;

    #[test]
    fn a_lambertian_reflects_its_albedo_and_the_port_its_projected_solid_angle() {
        let l = Lambert::new(vec![0.4], Sampling::grey()).unwrap();
        let h = hemisphere_reflectance(&l, 8f64.to_radians());
        assert!((h.value[0] - 0.4).abs() < 1e-9, "{}", h.value[0]);
        // The cone's projected solid angle is π sin²β cos 8°: the port takes ρ sin²β cos 8°.
        let beta = 5f64.to_radians();
        let p = port_reflectance(&l, 8f64.to_radians(), beta, 1e-10, 1_000_000);
        let exact = 0.4 * beta.sin().powi(2) * 8f64.to_radians().cos();
        assert!((p.value[0] - exact).abs() < 1e-12 && (p.value[0] - exact).abs() <= p.error[0] + 1e-15);
    }
}
