//! The stiff and extreme suite (issue 4, item 2). For every case: every reading has a finite value, its
//! actual error lies within its error estimate, and results are continuous across every internal switch.
//!
//! "Actual error" is measured against an independent reference written in this file: a closed form
//! (Lambert's projected solid angle of a spherical polygon, Kubelka–Munk in hyperbolic form, Fresnel in
//! complex form) combined with nested Gauss–Legendre integrals of smooth 2-D integrands, or, where no
//! closed form exists (lobes), a run of the engine at a relative tolerance 100× tighter. Continuity: the two
//! sides of a threshold agree to the requested tolerance.
//!
//! Every case prints one line `STAB|test|case|value|estimate|actual|bound|ok` (run with `--nocapture`);
//! `docs/stability.md` tabulates them.
use std::f64::consts::PI;
use std::sync::Arc;

use glossmeter::brdf::albedo::directional_albedo;
use glossmeter::brdf::{Brdf, TermKind};
use glossmeter::instrument::flux::{FluxProblem, Spectral};
use glossmeter::instrument::geometry::{Geometry, ReadingSpec, Stop};
use glossmeter::instrument::plan::{Plan, PlanOptions, Reading};
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

fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
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
        ReadingSpec::Haze { receptors, specular } => 100.0 * mean(receptors) / standard(stop(specular)),
        ReadingSpec::LogHaze { receptors, specular, k } => {
            k * ((100.0 * mean(receptors) / standard(stop(specular))) / 20.0 + 1.0).log10()
        }
        ReadingSpec::Doi { specular, offset } => 100.0 * (1.0 - mean(offset) / specimen(stop(specular))),
        ReadingSpec::HazeIndex { .. } => unreachable!("composites are combined by the caller"),
    }
}

/// References for every reading of `gs` (composites as the difference of their parts' references), in the
/// order `Plan::execute` reports them.
fn references(gs: &[StandardGeometry], specimen: &dyn Fn(&Geometry, Stop) -> f64) -> Vec<(String, String, f64)> {
    let one = |g: &Geometry, spec: &ReadingSpec| -> f64 {
        let n_ref = g.reference_index;
        let theta = g.theta;
        let std = move |rec: Stop| mirror_flux(theta, g.source, rec, &|c| fresnel_real(c, n_ref));
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
    let above =
        gl1(&|v| fresnel_real(mu_c + (1.0 - mu_c) * v * v, 1.0 / eta) * 2.0 * (mu_c + (1.0 - mu_c) * v * v) * 2.0 * (1.0 - mu_c) * v, 0.0, 1.0, 64);
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
        stab(test, &format!("89° clipped {} stop: projected solid angle", if source { "source" } else { "receptor" }), closed, 0.0, (closed - gl).abs(), 1e-12 * closed, ok);
        if !ok {
            fails.push(format!("clipped PSA: closed {closed} vs GL {gl} (reaches below: {reaches_below})"));
        }
    }
    // A FluxProblem on the clipped stops directly: the Lambertian flux is the clipped closed form.
    let b = lambert.as_ref();
    let f = FluxProblem {
        brdf: b,
        theta: g.theta,
        source: g.source,
        receptor: g.receptors[0].1,
        spectral: Spectral::Folded(vec![1.0]),
        lobes: vec![],
        include_delta: false,
        include_regular: true,
        rtol: RTOL,
        atol: 0.0,
        max_evals: 10_000_000,
    }
    .solve();
    let exact = rho / PI
        * projected_solid_angle(g.theta, g.source, true)
        * projected_solid_angle(g.theta, g.receptors[0].1, false);
    let actual = (f.value - exact).abs();
    if !stab(test, "89° clipped flux (FluxProblem, lambert)", f.value, f.error, actual, f.error, f.value.is_finite() && actual <= f.error) {
        fails.push(format!("clipped lambert flux {} vs {exact}: est {:e}", f.value, f.error));
    }
    finish(test, fails);
}
