//! The stiff and extreme suite (`docs/stability.md`). For every case: every reading has a finite value, its
//! actual error lies within its error estimate, and results are continuous across every internal switch.
//!
//! "Actual error" is measured against an independent reference written in this file (it shares only the
//! Gauss–Legendre nodes of `instrument::reference`, itself independent of the engine's quadrature): a closed form
//! (Lambert's projected solid angle of a spherical polygon, Kubelka–Munk in hyperbolic form, Fresnel in
//! complex form) combined with nested Gauss–Legendre integrals of smooth 2-D integrands, or, where no
//! closed form exists (lobes), a run of the engine at a relative tolerance 100× tighter. Continuity: the two
//! sides of a threshold agree to the requested tolerance.
//!
//! Every case prints one line `STAB|test|case|value|estimate|actual|bound|ok` (run with `--nocapture`);
//! `docs/stability.md` tabulates them.
use glossmeter::instrument::reference::gauss_legendre;
use std::f64::consts::PI;
use std::sync::Arc;

use glossmeter::brdf::albedo::directional_albedo;
use glossmeter::brdf::{Brdf, TermKind};
use glossmeter::instrument::geometry::{Geometry, Stop};
use glossmeter::instrument::method::Method;
use glossmeter::instrument::plan::{Plan, PlanOptions, Reading};
use glossmeter::instrument::reading::{ReadingSpec, Scale};
use glossmeter::instrument::standards::{self, StandardGeometry};
use glossmeter::optics::microfacet::Microfacet;
use glossmeter::optics::thin_film::{stack, FilmLayer};
use glossmeter::recipe::parse_str;
use glossmeter::Vec3;
use num_complex::Complex64;
use serde_json::{json, Value};

/// Relative tolerance of the readings under test, and of the tight reference runs (100× tighter).
const RTOL: f64 = 1e-5;
const RTOL_REF: f64 = 1e-7;

// ---------------------------------------------------------------------------------------------------------
// Reporting

/// One summary line per case; returns `ok` so callers can collect failures.
fn stab(test: &str, case: &str, value: f64, est: f64, actual: f64, bound: f64, ok: bool) -> bool {
    println!("STAB|{test}|{case}|{value:.10e}|{est:.3e}|{actual:.3e}|{bound:.3e}|{}", if ok { "ok" } else { "FAIL" });
    ok
}

fn finite_value(r: &Reading) -> Option<f64> {
    r.value.filter(|v| v.is_finite() && r.error_estimate.is_finite())
}

/// Check a reading against a reference value with its own error bound `ref_err`: finite, and
/// |value − reference| ≤ estimate + ref_err.
fn check(test: &str, case: &str, r: &Reading, reference: f64, ref_err: f64, fails: &mut Vec<String>) {
    let label = format!("{case} {}/{}", r.geometry, r.name);
    let Some(v) = finite_value(r) else {
        stab(test, &label, f64::NAN, r.error_estimate, f64::NAN, 0.0, false);
        fails.push(format!("{label}: no finite value ({:?})", r.problem));
        return;
    };
    let actual = (v - reference).abs();
    let bound = r.error_estimate + ref_err;
    if !stab(test, &label, v, r.error_estimate, actual, bound, actual <= bound) {
        fails.push(format!("{label}: {v} vs reference {reference}: actual {actual:e} > estimate {bound:e}"));
    }
}

/// Continuity across a switch: the two sides agree to the requested tolerance, |a − b| ≤ rtol·max(|a|, |b|)
/// (plus `extra`, the size of any genuine physical difference between the two sides, stated by the caller).
fn check_gap(test: &str, case: &str, a: &Reading, b: &Reading, rtol: f64, extra: f64, fails: &mut Vec<String>) {
    let label = format!("{case} {}/{}", a.geometry, a.name);
    let (Some(x), Some(y)) = (finite_value(a), finite_value(b)) else {
        stab(test, &label, f64::NAN, f64::NAN, f64::NAN, 0.0, false);
        fails.push(format!("{label}: no finite value ({:?} / {:?})", a.problem, b.problem));
        return;
    };
    let gap = (x - y).abs();
    let bound = rtol * x.abs().max(y.abs()) + extra;
    if !stab(test, &format!("{label} [gap]"), x, a.error_estimate + b.error_estimate, gap, bound, gap <= bound) {
        fails.push(format!("{label}: sides {x} and {y} differ by {gap:e} > {bound:e}"));
    }
}

fn finish(test: &str, fails: Vec<String>) {
    assert!(fails.is_empty(), "{test}: {} failure(s):\n{}", fails.len(), fails.join("\n"));
}

// ---------------------------------------------------------------------------------------------------------
// Engine access

fn run(brdf: &Arc<dyn Brdf>, geoms: &[StandardGeometry], rtol: f64) -> Vec<Reading> {
    Plan::compile(brdf.clone(), geoms.to_vec(), PlanOptions { rtol, ..Default::default() }).unwrap().execute()
}

fn recipe(v: &Value) -> Arc<dyn Brdf> {
    parse_str(&v.to_string(), "<stability>").unwrap_or_else(|e| panic!("recipe {v}: {e}")).brdf
}

fn geoms(ids: &[&str]) -> Vec<StandardGeometry> {
    ids.iter().map(|id| standards::find(id).unwrap()).collect()
}

fn d523() -> Vec<StandardGeometry> {
    geoms(&["astm-d523-20", "astm-d523-60", "astm-d523-85"])
}

fn user_89() -> StandardGeometry {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/geometry/user-grazing-89.json");
    standards::load_file(&p).unwrap()
}

/// The 89° user geometry with stops enlarged so that part of each lies below the horizon (a file with such
/// stops is refused by the geometry validator, so it is built here): source 4° × 2°, receptor 6° × 4°; the
/// horizon is 1° from the axis.
fn user_89_clipped() -> StandardGeometry {
    let mut g = user_89();
    g.geometry.id = "user-89-clipped".into();
    g.geometry.source = Stop::from_angles(4f64.to_radians(), 2f64.to_radians(), 0.0);
    g.geometry.receptors = vec![("gloss".into(), Stop::from_angles(6f64.to_radians(), 4f64.to_radians(), 0.0))];
    g
}

/// Run at RTOL and at RTOL_REF; check every reading against the tight one (|a − b| ≤ est_a + est_b).
fn check_against_tight(
    test: &str,
    case: &str,
    brdf: &Arc<dyn Brdf>,
    g: &[StandardGeometry],
    fails: &mut Vec<String>,
) -> Vec<Reading> {
    let loose = run(brdf, g, RTOL);
    let tight = run(brdf, g, RTOL_REF);
    for (a, b) in loose.iter().zip(&tight) {
        assert_eq!((&a.geometry, &a.name), (&b.geometry, &b.name));
        match finite_value(b) {
            Some(t) => check(test, case, a, t, b.error_estimate, fails),
            None => {
                stab(test, &format!("{case} {}/{} (tight run)", b.geometry, b.name), f64::NAN, 0.0, 0.0, 0.0, false);
                fails.push(format!("{case} {}/{}: tight run has no finite value: {:?}", b.geometry, b.name, b.problem));
            }
        }
    }
    loose
}

// ---------------------------------------------------------------------------------------------------------
// Independent references

/// ∫_a^b f by n-point Gauss–Legendre.
fn gl1(f: &dyn Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    gauss_legendre(n).iter().map(|(x, w)| w * f(0.5 * (a + b) + 0.5 * (b - a) * x)).sum::<f64>() * 0.5 * (b - a)
}

/// Unpolarised Fresnel reflectance from a medium of index 1 into index η (complex, decaying branch), in
/// the textbook complex form (Born & Wolf §1.5.2, §14.2): w = √(η² − sin²θ) = η cos θt,
/// r_s = (c − w)/(c + w), r_p = (η² c − w)/(η² c + w). A real η < 1 beyond the critical angle gives |r| = 1.
fn fresnel(c: f64, eta: Complex64) -> f64 {
    let s2 = (1.0 - c) * (1.0 + c);
    let mut w = (eta * eta - s2).sqrt();
    if w.im < 0.0 {
        w = -w;
    }
    let e2c = eta * eta * c;
    let rs = (c - w) / (c + w);
    let rp = (e2c - w) / (e2c + w);
    0.5 * (rs.norm_sqr() + rp.norm_sqr())
}

fn fresnel_real(c: f64, eta: f64) -> f64 {
    fresnel(c, Complex64::new(eta, 0.0))
}

/// Cosine of the direction of stop point (p, q) with the normal, for the source (towards the source) or the
/// receptor, from the unnormalised vector axis + p·e∥ + q·e⊥ (docs/instrument.md §1.1–1.2).
fn stop_cos(theta: f64, p: f64, q: f64, source: bool) -> f64 {
    let (c, s) = (theta.cos(), theta.sin());
    let z = if source { c + p * s } else { c - p * s };
    z / (1.0 + p * p + q * q).sqrt()
}

/// ∫ g(cos θ) cos θ dω over the rectangle p ∈ [p0, p1], q ∈ [q0, q1] of a stop, restricted to the upper
/// hemisphere (the p where cos θ = 0 is found here from cos θ + p sin θ = 0), by a 48×48 Gauss–Legendre
/// product rule. Zero for an empty rectangle.
fn stop_integral(theta: f64, p: [f64; 2], q: [f64; 2], source: bool, g: &dyn Fn(f64) -> f64) -> f64 {
    let horizon = theta.cos() / theta.sin();
    let (mut p0, mut p1) = (p[0], p[1]);
    if source {
        p0 = p0.max(-horizon);
    } else {
        p1 = p1.min(horizon);
    }
    if !(p1 > p0 && q[1] > q[0]) {
        return 0.0;
    }
    let gl = gauss_legendre(48);
    let mut total = 0.0;
    for (xp, wp) in &gl {
        let pp = 0.5 * (p0 + p1) + 0.5 * (p1 - p0) * xp;
        for (xq, wq) in &gl {
            let qq = 0.5 * (q[0] + q[1]) + 0.5 * (q[1] - q[0]) * xq;
            let c = stop_cos(theta, pp, qq, source).max(0.0);
            let r2 = 1.0 + pp * pp + qq * qq;
            total += wp * wq * g(c) * c / (r2 * r2.sqrt());
        }
    }
    total * 0.25 * (p1 - p0) * (q[1] - q[0])
}

/// Mirror flux ∫ R(θi) cos θi dω over the source points whose mirror image (−p, −q) lies in the receptor.
fn mirror_flux(theta: f64, src: Stop, rec: Stop, refl: &dyn Fn(f64) -> f64) -> f64 {
    let p = [src.p[0].max(-rec.p[1]), src.p[1].min(-rec.p[0])];
    let q = [src.q[0].max(-rec.q[1]), src.q[1].min(-rec.q[0])];
    stop_integral(theta, p, q, true, refl)
}

/// Projected solid angle ∫ cos θ dω of a stop, clipped to the upper hemisphere, in closed form: the
/// rectangle's corner vectors axis + p e∥ + q e⊥ are clipped against the plane z = 0 (Sutherland–Hodgman;
/// the edges are great-circle arcs, so clipping the unnormalised vectors is exact) and Lambert's formula for
/// a spherical polygon, ½ |Σ_edges γ_e (n_e · z)|, is applied (Lambert 1760; Arvo 1995 Eq. 3).
fn projected_solid_angle(theta: f64, stop: Stop, source: bool) -> f64 {
    let (c, s) = (theta.cos(), theta.sin());
    let (axis, e_par) = if source {
        (Vec3::new(-s, 0.0, c), Vec3::new(c, 0.0, s))
    } else {
        (Vec3::new(s, 0.0, c), Vec3::new(c, 0.0, -s))
    };
    let e_perp = Vec3::new(0.0, 1.0, 0.0);
    let corners = [(stop.p[0], stop.q[0]), (stop.p[1], stop.q[0]), (stop.p[1], stop.q[1]), (stop.p[0], stop.q[1])];
    let v: Vec<Vec3> = corners.iter().map(|(p, q)| axis + *p * e_par + *q * e_perp).collect();
    let mut clipped: Vec<Vec3> = Vec::new();
    for i in 0..v.len() {
        let (a, b) = (v[i], v[(i + 1) % v.len()]);
        if a.z >= 0.0 {
            clipped.push(a);
        }
        if (a.z >= 0.0) != (b.z >= 0.0) {
            clipped.push(a + (b - a) * (a.z / (a.z - b.z)));
        }
    }
    let v: Vec<Vec3> = clipped.iter().map(|x| x.normalize()).collect();
    let mut total = 0.0;
    for i in 0..v.len() {
        let (a, b) = (v[i], v[(i + 1) % v.len()]);
        let cr = a.cross(b);
        if cr.length() == 0.0 {
            continue;
        }
        total += cr.length().atan2(a.dot(b)) * cr.normalize().z;
    }
    0.5 * total.abs()
}

/// Reference value of one (non-composite) reading from reference fluxes, per docs/instrument.md §1.6.
fn reference_reading(
    spec: &ReadingSpec,
    g: &Geometry,
    specimen: &dyn Fn(Stop) -> f64,
    standard: &dyn Fn(Stop) -> f64,
) -> f64 {
    let stop = |name: &String| *g.receptor(name).unwrap();
    let mean = |names: &[String]| names.iter().map(|n| specimen(stop(n))).sum::<f64>() / names.len() as f64;
    match spec {
        ReadingSpec::Gloss { receptor } => 100.0 * specimen(stop(receptor)) / standard(stop(receptor)),
        ReadingSpec::Profile { receptor, reference } => 100.0 * specimen(stop(receptor)) / standard(stop(reference)),
        ReadingSpec::Haze { receptors, specular } => 100.0 * mean(receptors) / standard(stop(specular)),
        ReadingSpec::LogHaze { receptors, specular, k } => {
            k * ((100.0 * mean(receptors) / standard(stop(specular))) / 20.0 + 1.0).log10()
        }
        ReadingSpec::HazeCompensated { receptors, specular, compensation, factor } => {
            100.0 * (mean(receptors) - factor * specimen(stop(compensation))) / standard(stop(specular))
        }
        ReadingSpec::LogHazeCompensated { receptors, specular, compensation, factor, k } => {
            let h = 100.0 * (mean(receptors) - factor * specimen(stop(compensation))) / standard(stop(specular));
            k * (h / 20.0 + 1.0).log10()
        }
        ReadingSpec::Doi { specular, offset } => 100.0 * (1.0 - mean(offset) / specimen(stop(specular))),
        ReadingSpec::HazeIndex { .. } => unreachable!("composites are combined by the caller"),
        ReadingSpec::Colour { .. } => unreachable!("colour geometries are not in this test's panels"),
    }
}

/// References for every reading of `gs` (composites as the difference of their parts' references), in the
/// order `Plan::execute` reports them.
fn references(gs: &[StandardGeometry], specimen: &dyn Fn(&Geometry, Stop) -> f64) -> Vec<(String, String, f64)> {
    let one = |g: &Geometry, spec: &ReadingSpec| -> f64 {
        let theta = g.theta;
        // The scale written out: value × specimen / standard, the standard black glass or a perfect mirror.
        let (n_ref, assigned) = match g.scale {
            Scale::BlackGlass { index, value } => (Some(index), value),
            Scale::Mirror { value } => (None, value),
        };
        let std = move |rec: Stop| {
            let r = |c: f64| n_ref.map_or(1.0, |n| fresnel_real(c, n));
            mirror_flux(theta, g.source, rec, &r) * 100.0 / assigned
        };
        reference_reading(spec, g, &|s| specimen(g, s), &std)
    };
    let gloss_of = |id: &str| -> f64 {
        let g = standards::find(id).unwrap().geometry;
        let spec = g.readings.iter().find(|r| matches!(r, ReadingSpec::Gloss { .. })).unwrap().clone();
        one(&g, &spec)
    };
    let mut out = Vec::new();
    for sg in gs {
        let g = &sg.geometry;
        for (i, spec) in g.readings.iter().enumerate() {
            let v = match spec {
                ReadingSpec::HazeIndex { minuend, subtrahend } => gloss_of(minuend) - gloss_of(subtrahend),
                _ => one(g, spec),
            };
            out.push((g.id.clone(), sg.reading_names[i].clone(), v));
        }
    }
    out
}

/// Relative error bound of the Gauss–Legendre references (48×48 nodes on smooth integrands over boxes a few
/// degrees wide: converged to rounding; 1e-12 covers rounding in the sums and ratios).
const GL_REL: f64 = 1e-12;

fn check_all(test: &str, case: &str, readings: &[Reading], refs: &[(String, String, f64)], fails: &mut Vec<String>) {
    assert_eq!(readings.len(), refs.len(), "{case}: number of readings");
    for (r, (id, name, v)) in readings.iter().zip(refs) {
        assert_eq!((&r.geometry, &r.name), (id, name));
        check(test, case, r, *v, GL_REL * v.abs().max(1.0), fails);
    }
}

// ---------------------------------------------------------------------------------------------------------
// Kubelka–Munk and the paint's body term, independently

/// KM reflectance of a layer (K, S per unit of X) over a background Rg, closed forms (Kubelka 1948):
/// X = 0: Rg. S = 0: Rg·e^{−2KX} (pure absorption, there and back). K = 0: (SX(1 − Rg) + Rg)/(SX(1 − Rg) + 1).
/// Otherwise the hyperbolic solution R = (1 − Rg(a − b coth z))/(a − Rg + b coth z), a = 1 + K/S,
/// b = √(a² − 1), z = bSX, with a − b coth z written as (1 − b²/sinh²z)/(a + b coth z) (the product of the
/// two is a² − b² coth² z) so that K/S = 1e12 does not cancel.
fn km(k: f64, s: f64, x: f64, rg: f64) -> f64 {
    if x == 0.0 {
        return rg;
    }
    if s == 0.0 {
        return rg * (-2.0 * k * x).exp();
    }
    if k == 0.0 {
        let sx = s * x;
        return (sx * (1.0 - rg) + rg) / (sx * (1.0 - rg) + 1.0);
    }
    let a = 1.0 + k / s;
    let b = (a * a - 1.0).sqrt();
    let z = b * s * x;
    let coth = 1.0 / z.tanh();
    let bs = b / z.sinh();
    let a_minus = (1.0 - bs * bs) / (a + b * coth);
    (1.0 - rg * a_minus) / (a - rg + b * coth)
}

/// External diffuse reflectance of the air→coat interface, r_e = ∫₀¹ F(μ) 2μ dμ.
fn r_external(eta: f64) -> f64 {
    gl1(&|mu| fresnel_real(mu, eta) * 2.0 * mu, 0.0, 1.0, 64)
}

/// Internal diffuse reflectance of the coat→air interface computed directly (not from the identity the
/// model uses): ∫₀¹ F_{coat→air}(μ) 2μ dμ, which is total internal reflection (F = 1) for μ < μc = √(1 − 1/η²)
/// and Fresnel from the denser side above; the square-root behaviour at μc is removed by μ = μc + (1 − μc)v².
fn r_internal(eta: f64) -> f64 {
    let mu_c = (1.0 - 1.0 / (eta * eta)).sqrt();
    let above = gl1(
        &|v| {
            fresnel_real(mu_c + (1.0 - mu_c) * v * v, 1.0 / eta)
                * 2.0
                * (mu_c + (1.0 - mu_c) * v * v)
                * 2.0
                * (1.0 - mu_c)
                * v
        },
        0.0,
        1.0,
        64,
    );
    mu_c * mu_c + above
}

/// Reference specimen flux of a paint with a smooth coat and no flakes: the coat's Fresnel mirror flux plus
/// the body term, which factorises: ∫_S∫_R T(θi)T(θo)/η²·B cos θi cos θo dωi dωo = B/η²·I_S·I_R with
/// I = ∫ T(θ) cos θ dω over each stop, T = 1 − F, B = (1 − Am − Ap)·R_l/π/(1 − r_i R_l) (docs/model.md).
fn paint_flux(theta: f64, src: Stop, rec: Stop, eta: f64, body_weight: f64, r_l: f64) -> f64 {
    let b = body_weight * r_l / PI / (1.0 - r_internal(eta) * r_l);
    let t = |c: f64| 1.0 - fresnel_real(c, eta);
    let is = stop_integral(theta, src.p, src.q, true, &t);
    let ir = stop_integral(theta, rec.p, rec.q, false, &t);
    mirror_flux(theta, src, rec, &|c| fresnel_real(c, eta)) + b / (eta * eta) * is * ir
}

/// A paint recipe with one pigment and one wavelength (560 nm: one spectral sample, luminous weight 1).
fn paint_recipe(eta: f64, k: f64, s: f64, x: f64, rg: f64) -> Value {
    json!({
        "model": "paint",
        "wavelengths_nm": [560.0],
        "clear_coat": {"index": eta},
        "pigmented_layer": {
            "thickness_mm": x,
            "primer_reflectance": [rg],
            "pigments": [{"concentration": 1.0, "k_per_mm": [k], "s_per_mm": [s]}]
        }
    })
}

// ---------------------------------------------------------------------------------------------------------
// Tests

/// Every shipped geometry (and the 89° user geometry, as shipped and with stops reaching below the horizon)
/// with a Lambertian (closed form: ρ/π × the projected solid angles of the two stops) and a smooth
/// dielectric (Gauss–Legendre of the mirror overlap); the gloss standard by the same Gauss–Legendre rule.
#[test]
fn every_geometry_lambert_and_smooth_dielectric() {
    let test = "every_geometry_lambert_and_smooth_dielectric";
    let mut fails = Vec::new();
    let mut gs = standards::builtin().unwrap();
    gs.push(user_89());
    gs.push(user_89_clipped());
    let rho = 0.5;
    let lambert = recipe(&json!({"model": "lambert", "albedo": rho}));
    let refs = references(&gs, &|g, rec| {
        rho / PI * projected_solid_angle(g.theta, g.source, true) * projected_solid_angle(g.theta, rec, false)
    });
    check_all(test, "lambert 0.5", &run(&lambert, &gs, RTOL), &refs, &mut fails);

    let n = 1.5;
    let glass = recipe(&json!({"model": "smooth-dielectric", "ior": n}));
    let refs = references(&gs, &|g, rec| mirror_flux(g.theta, g.source, rec, &|c| fresnel_real(c, n)));
    check_all(test, "dielectric 1.5", &run(&glass, &gs, RTOL), &refs, &mut fails);

    // The clipped stop's projected solid angle, two ways: the closed form above, and a direct
    // Gauss–Legendre over the part of the stop above the horizon. Also: the clip really removes something.
    let g = user_89_clipped().geometry;
    for (source, stop) in [(true, g.source), (false, g.receptors[0].1)] {
        let closed = projected_solid_angle(g.theta, stop, source);
        let gl = stop_integral(g.theta, stop.p, stop.q, source, &|_| 1.0);
        let horizon = g.theta.cos() / g.theta.sin();
        let reaches_below = if source { stop.p[0] < -horizon } else { stop.p[1] > horizon };
        let ok = (closed - gl).abs() <= 1e-12 * closed && reaches_below;
        stab(
            test,
            &format!("89° clipped {} stop: projected solid angle", if source { "source" } else { "receptor" }),
            closed,
            0.0,
            (closed - gl).abs(),
            1e-12 * closed,
            ok,
        );
        if !ok {
            fails.push(format!("clipped PSA: closed {closed} vs GL {gl} (reaches below: {reaches_below})"));
        }
    }
    // A Method on the clipped stops directly: the Lambertian flux is the clipped closed form.
    let b = lambert.as_ref();
    let f = Method::for_material(b, g.theta, g.source, g.receptors[0].1, (RTOL, 0.0), 10_000_000).unwrap().execute(b);
    let exact = rho / PI
        * projected_solid_angle(g.theta, g.source, true)
        * projected_solid_angle(g.theta, g.receptors[0].1, false);
    let actual = (f.value[0] - exact).abs();
    if !stab(
        test,
        "89° clipped flux (Method, lambert)",
        f.value[0],
        f.error[0],
        actual,
        f.error[0],
        f.value[0].is_finite() && actual <= f.error[0],
    ) {
        fails.push(format!("clipped lambert flux {} vs {exact}: est {:e}", f.value[0], f.error[0]));
    }
    finish(test, fails);
}

/// Microfacet surfaces (n = 1.5) from roughness 1e-6 to 1, Beckmann and GGX, on every D523 geometry, against
/// runs 100× tighter; continuity across the "effectively smooth" switch (roughness 1e-7 × (1 ± 1e-4)) and
/// across the flux engine's lobe-split switch (splits only where the lobe is narrower than the range of the
/// lobe variable; w_u = 2m, w_v = 2m cos θ for a surface lobe, docs/instrument.md §Quadrature).
#[test]
fn microfacet_roughness_sweep_and_switches() {
    let test = "microfacet_roughness_sweep_and_switches";
    let mut fails = Vec::new();
    let mf = microfacet;
    let gs = d523();
    for dist in ["beckmann", "ggx"] {
        for m in [1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 0.1, 0.3, 1.0] {
            if dist == "ggx" && m <= 1e-6 {
                continue; // covered, with the smooth switch, by `ggx_narrow_lobe_below_1e_6`
            }
            check_against_tight(test, &format!("{dist} m={m:e}"), &mf(dist, m), &gs, &mut fails);
        }
        if dist == "beckmann" {
            smooth_switch(test, dist, &gs, &mut fails);
        }
        // Lobe-split switch at 60°, for the u axis (in-plane) and the v axis (perpendicular).
        let g60 = &geoms(&["astm-d523-60"]);
        let g = &g60[0].geometry;
        let rec = g.receptor("gloss").unwrap();
        let range_u = (g.source.p[1] + rec.p[1]) - (g.source.p[0] + rec.p[0]);
        let range_v = (g.source.q[1] + rec.q[1]) - (g.source.q[0] + rec.q[0]);
        for (axis, m_star) in [("u", range_u / 2.0), ("v", range_v / (2.0 * g.theta.cos()))] {
            let a = run(&mf(dist, m_star * (1.0 - 1e-9)), g60, RTOL);
            let b = run(&mf(dist, m_star * (1.0 + 1e-9)), g60, RTOL);
            // Evidence that the partition changed: the initial boxes differ, so do the evaluation counts.
            assert_ne!(a[0].evaluations, b[0].evaluations, "{dist} {axis}: the split switch was not crossed");
            check_gap(
                test,
                &format!("{dist} split switch {axis} m={m_star:.5e}(1±1e-9)"),
                &a[0],
                &b[0],
                RTOL,
                0.0,
                &mut fails,
            );
        }
    }
    // Split sharing: a lobe within a factor 3 of a narrower one shares its splits (aperture.rs `splits`).
    let lobes = |m2: f64| {
        recipe(&json!({"model": "cook-torrance-lobes", "kd": 0.0,
            "lobes": [{"ks": 0.5, "r": 0.04, "m": 0.003}, {"ks": 0.5, "r": 0.04, "m": m2}]}))
    };
    let (a, b) = (run(&lobes(0.009 * (1.0 - 1e-9)), &gs, RTOL), run(&lobes(0.009 * (1.0 + 1e-9)), &gs, RTOL));
    for (x, y) in a.iter().zip(&b) {
        assert_ne!(x.evaluations, y.evaluations, "the split-sharing switch was not crossed");
        check_gap(test, "two lobes, split-sharing switch m2=3·m1(1±1e-9)", x, y, RTOL, 0.0, &mut fails);
    }
    finish(test, fails);
}

fn microfacet(dist: &str, m: f64) -> Arc<dyn Brdf> {
    recipe(&json!({"model": "microfacet", "distribution": dist, "roughness": m, "ior": 1.5}))
}

/// Continuity across the microfacet "effectively smooth" switch: roughness 1e-7 × (1 ± 1e-4).
fn smooth_switch(test: &str, dist: &str, gs: &[StandardGeometry], fails: &mut Vec<String>) {
    let t = Microfacet::SMOOTH_THRESHOLD;
    let (above, below) = (microfacet(dist, t * (1.0 + 1e-4)), microfacet(dist, t * (1.0 - 1e-4)));
    assert!(!above.has_delta() && below.has_delta(), "the two sides must be on either side of the switch");
    for (a, b) in run(&above, gs, RTOL).iter().zip(&run(&below, gs, RTOL)) {
        check_gap(test, &format!("{dist} smooth switch m=1e-7(1±1e-4)"), a, b, RTOL, 0.0, fails);
    }
}

/// GGX lobes of roughness ≤ 1e-6: the reading at rtol 1e-5 falls short of the run 100× tighter (and of the
/// smooth limit) by about 3e-5 relative, ten times its error estimate, and the two sides of the smooth switch
/// differ by 6e-5 relative. GGX keeps a fraction 1/(1 + (t/α)²) of its mass beyond slope t, i.e. 1e-4 beyond
/// the last split point at 100 widths; between there and the edge of the range (hundreds to thousands of
/// widths away for α ≤ 1e-6) the 1/t⁴ tail sits in one box per side, which the degree-7/degree-5 pair
/// under-integrates with a small |I₇ − I₅|.
#[test]
fn ggx_narrow_lobe_below_1e_6() {
    let test = "ggx_narrow_lobe_below_1e_6";
    let mut fails = Vec::new();
    let gs = d523();
    check_against_tight(test, "ggx m=1e-6", &microfacet("ggx", 1e-6), &gs, &mut fails);
    smooth_switch(test, "ggx", &gs, &mut fails);
    finish(test, fails);
}

/// A clear coat of index 1.8 (internal diffuse reflectance with total internal reflection beyond 33.7°)
/// read at 85° and 89° (as shipped, and with stops reaching below the horizon): the readings against the
/// factorised closed form of `paint_flux` with r_i integrated directly through the TIR region; the model's
/// r_i; energy ≤ 1 by the crate's white-furnace integrator.
#[test]
fn clear_coat_1_8_total_internal_reflection() {
    let test = "clear_coat_1_8_total_internal_reflection";
    let mut fails = Vec::new();
    let (eta, k, s, x, rg) = (1.8, 0.5, 2.0, 0.15, 0.7);
    let v = paint_recipe(eta, k, s, x, rg);
    let brdf = recipe(&v);
    let gs = vec![standards::find("astm-d523-85").unwrap(), user_89(), user_89_clipped()];
    let refs = references(&gs, &|g, rec| paint_flux(g.theta, g.source, rec, eta, 1.0, km(k, s, x, rg)));
    check_all(test, "coat 1.8", &run(&brdf, &gs, RTOL), &refs, &mut fails);

    let p = paint_of(&v);
    let (model, direct) = (p.internal_diffuse_reflectance(), r_internal(eta));
    let ok = (model - direct).abs() <= 1e-12;
    if !stab(test, "r_i(1.8): model vs direct TIR integral", model, 0.0, (model - direct).abs(), 1e-12, ok) {
        fails.push(format!("r_i: model {model} vs direct {direct}"));
    }
    let identity = 1.0 - (1.0 - r_external(eta)) / (eta * eta);
    let ok = (identity - direct).abs() <= 1e-12;
    if !stab(
        test,
        "r_i(1.8): identity 1 − (1 − r_e)/η² vs direct TIR integral",
        identity,
        0.0,
        (identity - direct).abs(),
        1e-12,
        ok,
    ) {
        fails.push(format!("r_i identity {identity} vs direct {direct}"));
    }
    for th in [0.0, 60.0, 85.0, 89.0, 89.9] {
        let wi = dir(th);
        let (a, err) = directional_albedo(brdf.as_ref(), wi);
        let ok = a[0].is_finite() && err.is_finite() && a[0] <= 1.0 + err;
        if !stab(test, &format!("coat 1.8 albedo at {th}°"), a[0], err, (a[0] - 1.0).max(0.0), err, ok) {
            fails.push(format!("albedo at {th}°: {} ± {err}", a[0]));
        }
    }
    finish(test, fails);
}

fn dir(theta_deg: f64) -> Vec3 {
    let t = theta_deg.to_radians();
    Vec3::new(-t.sin(), 0.0, t.cos())
}

/// The recipe as a `Paint` (to reach R_l and r_i), through the same parser as `parse_str`.
fn paint_of(v: &Value) -> glossmeter::brdf::paint::Paint {
    let obj = glossmeter::input::json::Obj::new("<stability>", "", v).unwrap();
    glossmeter::brdf::paint::Paint::new(glossmeter::recipe::paint::parse_paint_spec(&obj).unwrap()).unwrap()
}

/// Kubelka–Munk extremes: K/S → 0 and 1e12, S·X → 0 and 1e4, K = 0, S = 0, X = 0. R_l against the closed
/// forms of `km`; the paints' readings against the factorised closed form; continuity between K/S = 1e-12 and
/// K = 0, between S·X = 1e-12 and S = 0, and between K/S = 1e12 and a body of reflectance 0 (the smooth
/// dielectric of the coat's index); R_l over a sweep of S·X through the engine's internal switches.
#[test]
fn kubelka_munk_extremes() {
    let test = "kubelka_munk_extremes";
    let mut fails = Vec::new();
    let eta = 1.5;
    let cases: [(&str, f64, f64, f64, f64); 9] = [
        ("K/S=1e-12 SX=1", 1e-12, 1.0, 1.0, 0.7),
        ("K=0 SX=1", 0.0, 1.0, 1.0, 0.7),
        ("K/S=1e12 SX=1", 1e12, 1.0, 1.0, 0.7),
        ("SX=1e-12 KX=0.5", 0.5, 1e-12, 1.0, 0.7),
        ("S=0 KX=0.5", 0.5, 0.0, 1.0, 0.7),
        ("SX=1e4 K/S=1e-4", 1.0, 1e4, 1.0, 0.7),
        ("SX=1e4 K=0", 0.0, 1e4, 1.0, 0.7),
        ("K=S=0", 0.0, 0.0, 1.0, 0.7),
        ("X=0", 0.5, 2.0, 0.0, 0.7),
    ];
    let gs = geoms(&["astm-d523-60", "astm-d523-85"]);
    let mut readings = Vec::new();
    for (name, k, s, x, rg) in cases {
        let v = paint_recipe(eta, k, s, x, rg);
        let r_l = paint_of(&v).pigmented_reflectance()[0];
        let want = km(k, s, x, rg);
        let dev = (r_l - want).abs();
        let ok = r_l.is_finite() && dev <= 1e-12 * want.max(1e-300) + 1e-300;
        if !stab(test, &format!("{name}: R_l vs closed form"), r_l, 0.0, dev, 1e-12 * want, ok) {
            fails.push(format!("{name}: R_l {r_l} vs closed form {want}"));
        }
        let refs = references(&gs, &|g, rec| paint_flux(g.theta, g.source, rec, eta, 1.0, want));
        let r = run(&recipe(&v), &gs, RTOL);
        check_all(test, name, &r, &refs, &mut fails);
        readings.push(r);
    }
    // Limits that hold exactly in the closed forms: K/S = 1e12 → R∞ ≈ 5e-13; S·X ≥ 1e4 → R∞ (K > 0).
    let checks = [
        (
            "K/S=1e12: R_l = R∞ = 1/(a + b)",
            km(1e12, 1.0, 1.0, 0.7),
            1.0 / (1.0 + 1e12 + (1e12f64 * (2.0 + 1e12)).sqrt()),
        ),
        ("SX=1e4 K/S=1e-4: R_l = R∞", km(1.0, 1e4, 1.0, 0.7), 1.0 / (1.0 + 1e-4 + (1e-4f64 * (2.0 + 1e-4)).sqrt())),
    ];
    for (name, got, want) in checks {
        let ok = (got - want).abs() <= 1e-9 * want;
        if !stab(test, name, got, 0.0, (got - want).abs(), 1e-9 * want, ok) {
            fails.push(format!("{name}: {got} vs {want}"));
        }
    }
    let glass = run(&recipe(&json!({"model": "smooth-dielectric", "ior": eta})), &gs, RTOL);
    for i in 0..gs.len() {
        check_gap(test, "K/S=1e-12 vs K=0", &readings[0][i], &readings[1][i], RTOL, 0.0, &mut fails);
        check_gap(test, "SX=1e-12 vs S=0", &readings[3][i], &readings[4][i], RTOL, 0.0, &mut fails);
        check_gap(
            test,
            "K/S=1e12 vs body 0 (smooth dielectric 1.5)",
            &readings[2][i],
            &glass[i],
            RTOL,
            0.0,
            &mut fails,
        );
    }
    // R_l over S·X from 1e-8 to 1e5 for K/S from 1e-12 to 1e12 (crosses the engine's z = 1/2 and u = 1
    // switches), and on both sides of z = bSX = 1/2 for K/S = 1.
    let mut worst: f64 = 0.0;
    for q in [1e-12, 1e-6, 1e-2, 1.0, 1e2, 1e6, 1e12] {
        for i in 0..=260 {
            let sx = 10f64.powf(-8.0 + 13.0 * i as f64 / 260.0);
            for rg in [0.0, 0.7, 1.0] {
                let got = glossmeter::optics::kubelka_munk::layer(q * 1.0, 1.0, sx).over(rg);
                let want = km(q, 1.0, sx, rg);
                worst = worst.max((got - want).abs() / want.max(1e-300));
            }
        }
    }
    let ok = worst <= 1e-10;
    if !stab(test, "R_l sweep SX 1e-8..1e5, K/S 1e-12..1e12, Rg 0/0.7/1: max rel dev", worst, 0.0, worst, 1e-10, ok) {
        fails.push(format!("R_l sweep: worst relative deviation {worst:e}"));
    }
    let sx_half = 0.5 / 3f64.sqrt();
    // Each side against the closed form at its own S·X (the sides are 2e-9 apart in S·X, so they differ
    // physically by about 1e-9; the closed form has no switch there).
    let (sx_lo, sx_hi) = (sx_half * (1.0 - 1e-9), sx_half * (1.0 + 1e-9));
    let lo = glossmeter::optics::kubelka_munk::layer(1.0, 1.0, sx_lo).over(0.7);
    let hi = glossmeter::optics::kubelka_munk::layer(1.0, 1.0, sx_hi).over(0.7);
    let dev = (lo - km(1.0, 1.0, sx_lo, 0.7)).abs().max((hi - km(1.0, 1.0, sx_hi, 0.7)).abs());
    let ok = dev <= 1e-13;
    if !stab(test, "R_l on both sides of z = 1/2 (K/S = 1) vs closed form", lo, 0.0, dev, 1e-13, ok) {
        fails.push(format!("z = 1/2 switch: {lo} / {hi}, deviation from the closed form {dev:e}"));
    }
    finish(test, fails);
}

/// Conductors: k ≫ n (0.05 + 10i) reads close to a perfect mirror, and equals 100·Φ(Fresnel)/Φ_std with
/// Φ from a separate Gauss–Legendre rule and Fresnel in complex form; k = 0 reads as the smooth dielectric of
/// the same n. Every shipped geometry and the 89° user geometries.
#[test]
fn conductors_k_much_larger_than_n_and_k_zero() {
    let test = "conductors_k_much_larger_than_n_and_k_zero";
    let mut fails = Vec::new();
    let mut gs = standards::builtin().unwrap();
    gs.push(user_89());
    gs.push(user_89_clipped());
    let eta = Complex64::new(0.05, 10.0);
    let metal = run(&recipe(&json!({"model": "conductor", "ior": [0.05, 10.0]})), &gs, RTOL);
    let refs = references(&gs, &|g, rec| mirror_flux(g.theta, g.source, rec, &|c| fresnel(c, eta)));
    check_all(test, "conductor 0.05+10i", &metal, &refs, &mut fails);
    let mirror = references(&gs, &|g, rec| mirror_flux(g.theta, g.source, rec, &|_| 1.0));
    for (r, (_, _, m)) in metal.iter().zip(&mirror) {
        if r.quantity != "gloss" {
            continue;
        }
        let ratio = r.value.unwrap_or(f64::NAN) / m;
        let ok = (0.99..=1.0).contains(&ratio);
        if !stab(test, &format!("0.05+10i / perfect mirror {}", r.geometry), ratio, 0.0, 1.0 - ratio, 0.01, ok) {
            fails.push(format!("{}: conductor/mirror = {ratio}", r.geometry));
        }
    }
    let k0 = run(&recipe(&json!({"model": "conductor", "ior": [1.5, 0.0]})), &gs, RTOL);
    let glass = run(&recipe(&json!({"model": "smooth-dielectric", "ior": 1.5})), &gs, RTOL);
    for (a, b) in k0.iter().zip(&glass) {
        check_gap(test, "conductor 1.5+0i vs dielectric 1.5", a, b, RTOL, 0.0, &mut fails);
    }
    finish(test, fails);
}

fn pearl_recipe(tio2_nm: f64, tio2_index: f64) -> Value {
    let mut v = paint_recipe(1.5, 0.5, 2.0, 0.15, 0.7);
    v["pearlescent_flakes"] = json!({"spread_deg": 0.35, "area_ratio": 0.2, "depth_mm": 0.075,
        "tio2_thickness_nm": tio2_nm, "tio2_index": tio2_index, "mica_thickness_nm": 400.0, "mica_index": 1.58});
    v
}

/// s and p Fresnel power reflectances of a real interface (relative index η).
fn fresnel_sp(c: f64, eta: f64) -> (f64, f64) {
    let w = (eta * eta - (1.0 - c) * (1.0 + c)).sqrt();
    let (rs, rp) = ((c - w) / (c + w), (eta * eta * c - w) / (eta * eta * c + w));
    (rs * rs, rp * rp)
}

/// Pearlescent flakes with TiO2 films 0, 50 nm, 1 µm and 100 µm thick (coherent), against runs 100× tighter
/// (60°); a zero-thickness film equals an index-matched one (both leave the resin | mica | resin slab); at
/// the optics level the zero-thickness flake is the incoherent slab 2r/(1 + r) per polarisation, and an
/// absorbing TiO2 (2.5 + 0.5i, which recipes cannot express: `tio2_index` is real) gives finite R, T with
/// R + T ≤ 1, and a 100 µm absorbing film reflects as the bare resin | TiO2 interface.
#[test]
fn thin_films_zero_to_100_um_and_absorbing() {
    let test = "thin_films_zero_to_100_um_and_absorbing";
    let mut fails = Vec::new();
    let gs = geoms(&["astm-d523-60"]);
    let mut zero = Vec::new();
    for t in [0.0, 50.0, 1000.0, 1e5] {
        let r =
            check_against_tight(test, &format!("pearl TiO2 {t} nm"), &recipe(&pearl_recipe(t, 2.5)), &gs, &mut fails);
        if t == 0.0 {
            zero = r;
        }
    }
    let matched = run(&recipe(&pearl_recipe(50.0, 1.5)), &gs, RTOL);
    check_gap(test, "TiO2 0 nm vs 50 nm index-matched (n = 1.5)", &zero[0], &matched[0], RTOL, 0.0, &mut fails);

    let film = |n: Complex64, d: f64| FilmLayer { n, thickness_nm: d, coherent: true };
    let mica = FilmLayer { n: Complex64::new(1.58, 0.0), thickness_nm: 400.0, coherent: false };
    let mut worst: f64 = 0.0;
    for c in [1.0, 0.8, 0.5, 0.2, 0.05, 1e-3] {
        let st = stack(
            1.5,
            &[film(Complex64::new(2.5, 0.0), 0.0), mica, film(Complex64::new(2.5, 0.0), 0.0)],
            Complex64::new(1.5, 0.0),
            c,
            560.0,
        );
        let (rs, rp) = fresnel_sp(c, 1.58 / 1.5);
        let want = 0.5 * (2.0 * rs / (1.0 + rs) + 2.0 * rp / (1.0 + rp));
        worst = worst.max((st.r() - want).abs());
    }
    let ok = worst <= 1e-12;
    if !stab(test, "zero-thickness TiO2: stack = incoherent slab 2r/(1+r)", worst, 0.0, worst, 1e-12, ok) {
        fails.push(format!("zero-thickness stack deviates by {worst:e}"));
    }
    let tio2 = Complex64::new(2.5, 0.5);
    let (mut bad, mut worst_thick) = (0, 0.0f64);
    for d in [0.0, 50.0, 1000.0, 1e5] {
        for c in [1.0, 0.8, 0.5, 0.2, 0.05, 1e-3] {
            let st = stack(1.5, &[film(tio2, d), mica, film(tio2, d)], Complex64::new(1.5, 0.0), c, 560.0);
            let fine = [st.rs, st.rp, st.ts, st.tp].iter().all(|x| x.is_finite() && *x >= 0.0)
                && st.rs + st.ts <= 1.0 + 1e-12
                && st.rp + st.tp <= 1.0 + 1e-12;
            if !fine {
                bad += 1;
                fails.push(format!("absorbing TiO2 {d} nm, cos {c}: {st:?}"));
            }
            if d == 1e5 {
                worst_thick = worst_thick.max((st.r() - fresnel(c, tio2 / 1.5)).abs());
            }
        }
    }
    stab(
        test,
        "absorbing TiO2 2.5+0.5i, 0..100 µm: finite, R+T ≤ 1 (bad count)",
        bad as f64,
        0.0,
        bad as f64,
        0.0,
        bad == 0,
    );
    let ok = worst_thick <= 1e-12;
    if !stab(test, "absorbing TiO2 100 µm: R = bare resin/TiO2 Fresnel", worst_thick, 0.0, worst_thick, 1e-12, ok) {
        fails.push(format!("thick absorbing film deviates from the bare interface by {worst_thick:e}"));
    }
    finish(test, fails);
}

fn metallic_recipe(spread_deg: f64, area: f64) -> Value {
    let mut v = paint_recipe(1.5, 0.5, 2.0, 0.15, 0.7);
    v["metallic_flakes"] =
        json!({"n": 0.93, "k": 6.33, "spread_deg": spread_deg, "area_ratio": area, "depth_mm": 0.075});
    v
}

/// Metallic flakes with orientation spreads 0.25° (the paper's), 0.01° and 0.001°, all narrower than the
/// source aperture (0.75°), against runs 100× tighter on every D523 geometry; continuity across the flake
/// and the rough-coat "effectively smooth" switches (slope 1e-7 × (1 ± 1e-4)).
#[test]
fn narrow_flakes_and_smooth_switches() {
    let test = "narrow_flakes_and_smooth_switches";
    let mut fails = Vec::new();
    let gs = d523();
    for spread in [0.25, 0.01, 0.001] {
        check_against_tight(
            test,
            &format!("metallic spread {spread}°"),
            &recipe(&metallic_recipe(spread, 0.4)),
            &gs,
            &mut fails,
        );
    }
    let t = Microfacet::SMOOTH_THRESHOLD;
    let spread = |m: f64| m.atan().to_degrees();
    let (above, below) = (
        recipe(&metallic_recipe(spread(t * (1.0 + 1e-4)), 0.4)),
        recipe(&metallic_recipe(spread(t * (1.0 - 1e-4)), 0.4)),
    );
    let kinds = |b: &Arc<dyn Brdf>| b.hints().terms.iter().filter(|t| matches!(t.kind, TermKind::Lobe(_))).count();
    assert_eq!((kinds(&above), kinds(&below)), (1, 0), "the two sides must be on either side of the switch");
    for (a, b) in run(&above, &gs, RTOL).iter().zip(&run(&below, &gs, RTOL)) {
        check_gap(test, "flake smooth switch slope 1e-7(1±1e-4)", a, b, RTOL, 0.0, &mut fails);
    }
    let coat = |m: f64| {
        let mut v = paint_recipe(1.5, 0.5, 2.0, 0.15, 0.7);
        v["clear_coat"]["roughness"] = json!(m);
        recipe(&v)
    };
    let (above, below) = (coat(t * (1.0 + 1e-4)), coat(t * (1.0 - 1e-4)));
    assert!(!above.has_delta() && below.has_delta());
    for (a, b) in run(&above, &gs, RTOL).iter().zip(&run(&below, &gs, RTOL)) {
        check_gap(test, "rough-coat smooth switch 1e-7(1±1e-4)", a, b, RTOL, 0.0, &mut fails);
    }
    finish(test, fails);
}

/// Area ratios: metallic A = 0 reads bit-identically to no metallic flakes; A = 1 has no body term, finite
/// readings within their estimates (against runs 100× tighter) and directional albedo ≤ 1.
#[test]
fn area_ratios_zero_and_one() {
    let test = "area_ratios_zero_and_one";
    let mut fails = Vec::new();
    let gs = d523();
    let none = run(&recipe(&paint_recipe(1.5, 0.5, 2.0, 0.15, 0.7)), &gs, RTOL);
    let zero = run(&recipe(&metallic_recipe(0.25, 0.0)), &gs, RTOL);
    for (a, b) in zero.iter().zip(&none) {
        let same = a.value.map(f64::to_bits) == b.value.map(f64::to_bits)
            && a.error_estimate.to_bits() == b.error_estimate.to_bits();
        let diff = (a.value.unwrap_or(f64::NAN) - b.value.unwrap_or(f64::NAN)).abs();
        if !stab(
            test,
            &format!("metallic A=0 vs none {} (bitwise)", a.geometry),
            a.value.unwrap_or(f64::NAN),
            a.error_estimate,
            diff,
            0.0,
            same,
        ) {
            fails.push(format!("{}: A = 0 {:?} vs none {:?}", a.geometry, a.value, b.value));
        }
    }
    let full = recipe(&metallic_recipe(0.25, 1.0));
    // The flakes' scattered light (split flake light) is a diffuse term of its own; the pigmented layer's body
    // term is what A = 1 removes.
    let has_body =
        full.hints().terms.iter().any(|t| t.kind == TermKind::Diffuse && t.label.starts_with("pigmented layer"));
    if !stab(test, "metallic A=1: no body term", has_body as u8 as f64, 0.0, 0.0, 0.0, !has_body) {
        fails.push("A = 1 still has a diffuse body term".into());
    }
    check_against_tight(test, "metallic A=1", &full, &gs, &mut fails);
    for th in [0.0, 20.0, 60.0, 85.0, 89.0] {
        let (a, err) = directional_albedo(full.as_ref(), dir(th));
        let ok = a[0].is_finite() && err.is_finite() && a[0] <= 1.0 + err;
        if !stab(test, &format!("metallic A=1 albedo at {th}°"), a[0], err, (a[0] - 1.0).max(0.0), err, ok) {
            fails.push(format!("A = 1 albedo at {th}°: {} ± {err}", a[0]));
        }
    }
    finish(test, fails);
}
