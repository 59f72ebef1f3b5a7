//! The Rhopoint IQ-class pixel-array readings (`rhopoint-iq-20`, `docs/instrument.md` §1.9): the pixel windows
//! are the union of their pixels, a smooth dielectric reads Rspec = gloss = its D523 20° gloss with DOI 100 and no
//! haze, a Lambertian body reads the closed forms of its windows' projected solid angles (computed here from the
//! pixel edges, not through the engine's windows), and windows outside the array are refused with exit 2 naming the
//! file, the field and the range allowed.
mod common;
use common::{gm, tmp};
use std::sync::Arc;

use glossmeter::brdf::Brdf;
use glossmeter::instrument::geometry::Stop;
use glossmeter::instrument::plan::{Plan, PlanOptions, Reading};
use glossmeter::instrument::reference::gauss_legendre;
use glossmeter::instrument::standards;
use glossmeter::recipe::parse_str;
use serde_json::Value;

const W: f64 = 0.02832; // degrees per pixel (the shipped array)

fn brdf(text: &str) -> Arc<dyn Brdf> {
    parse_str(text, "<test>").unwrap().brdf
}

fn read(material: &str, ids: &[&str]) -> Vec<Reading> {
    let geos = ids.iter().map(|id| standards::find(id).unwrap()).collect();
    Plan::compile(brdf(material), geos, PlanOptions::default()).unwrap().execute()
}

fn value(rs: &[Reading], geometry: &str, name: &str) -> f64 {
    rs.iter().find(|r| r.geometry == geometry && r.name == name).unwrap().value.unwrap()
}

/// The stop of pixels first..=last written out from the array's definition: pixel k is centred (k − 255.5)·w.
fn window(first: usize, last: usize, height_deg: f64) -> Stop {
    let lo = ((first as f64 - 255.5) * W - 0.5 * W).to_radians();
    let hi = ((last as f64 - 255.5) * W + 0.5 * W).to_radians();
    Stop { p: [lo.tan(), hi.tan()], q: [-(0.5 * height_deg).to_radians().tan(), (0.5 * height_deg).to_radians().tan()] }
}

#[test]
fn the_windows_are_their_pixels() {
    let g = standards::find("rhopoint-iq-20").unwrap();
    let spec = standards::profile::of(&g).unwrap();
    for (name, first, last) in [
        ("gloss", 224, 287),
        ("rspec", 252, 258),
        ("doi-minus", 241, 247),
        ("doi-plus", 263, 269),
        ("haze-minus", 182, 195),
        ("haze-plus", 316, 329),
    ] {
        let stop = g.geometry.receptor(name).unwrap();
        // The left edge of the first pixel and the right edge of the last, to rounding.
        assert!((stop.p[0] - spec.stop(first).p[0]).abs() < 1e-15, "{name}");
        assert!((stop.p[1] - spec.stop(last).p[1]).abs() < 1e-15, "{name}");
        assert_eq!(stop.q, spec.stop(first).q, "{name}");
        let w = window(first, last, 3.6);
        assert!((stop.p[0] - w.p[0]).abs() < 1e-14 && (stop.p[1] - w.p[1]).abs() < 1e-14, "{name}");
    }
    // The gloss window spans ±32 pixels = ±0.90624° (ISO 2813's 1.8° to the nearest whole pixels).
    let gl = g.geometry.receptor("gloss").unwrap();
    assert!((gl.p[1].atan().to_degrees() - 32.0 * W).abs() < 1e-12);
}

#[test]
fn a_smooth_dielectric_reads_its_gloss_everywhere_and_no_haze() {
    let rs = read(r#"{"model": "smooth-dielectric", "ior": 1.5}"#, &["rhopoint-iq-20", "astm-d523-20"]);
    let d523 = value(&rs, "astm-d523-20", "gloss");
    // The assumed 0.1° source image lies inside the Rspec window and far from the DOI and haze windows.
    // Rspec equals the array's gloss (both windows hold the whole image), and D523's 20° gloss to within the
    // Fresnel factor's variation over the different source sizes (0.1° against 0.75°).
    let (gloss, rspec) = (value(&rs, "rhopoint-iq-20", "gloss"), value(&rs, "rhopoint-iq-20", "rspec"));
    assert!((gloss - rspec).abs() < 1e-6, "{gloss} {rspec}");
    assert!((gloss - d523).abs() < 0.01, "{gloss} {d523}");
    assert_eq!(value(&rs, "rhopoint-iq-20", "doi"), 100.0);
    assert_eq!(value(&rs, "rhopoint-iq-20", "haze"), 0.0);
    assert_eq!(value(&rs, "rhopoint-iq-20", "log-haze"), 0.0);
    let glass = read(r#"{"model": "smooth-dielectric", "ior": 1.567}"#, &["rhopoint-iq-20"]);
    assert!((value(&glass, "rhopoint-iq-20", "rspec") - 100.0).abs() < 1e-6);
}

/// Unpolarised Fresnel reflectance of a real index η (Born & Wolf §1.5.2).
fn fresnel(c: f64, eta: f64) -> f64 {
    let w = (eta * eta - (1.0 - c * c)).sqrt();
    let rs = (c - w) / (c + w);
    let rp = (eta * eta * c - w) / (eta * eta * c + w);
    0.5 * (rs * rs + rp * rp)
}

/// The black glass's flux through `rec`: ∫ R cos θi dω over the source points whose mirror image lies in `rec`
/// (40 × 40 Gauss–Legendre; the integrand is smooth there).
fn mirror_flux(theta: f64, src: Stop, rec: Stop, eta: f64) -> f64 {
    let p = [src.p[0].max(-rec.p[1]), src.p[1].min(-rec.p[0])];
    let q = [src.q[0].max(-rec.q[1]), src.q[1].min(-rec.q[0])];
    let gl = gauss_legendre(40);
    let mut total = 0.0;
    for (xp, wp) in &gl {
        let pp = 0.5 * (p[0] + p[1]) + 0.5 * (p[1] - p[0]) * xp;
        for (xq, wq) in &gl {
            let qq = 0.5 * (q[0] + q[1]) + 0.5 * (q[1] - q[0]) * xq;
            let r2 = 1.0 + pp * pp + qq * qq;
            let c = (theta.cos() + pp * theta.sin()) / r2.sqrt();
            total += wp * wq * fresnel(c, eta) * c / (r2 * r2.sqrt());
        }
    }
    total * 0.25 * (p[1] - p[0]) * (q[1] - q[0])
}

#[test]
fn a_lambertian_body_reads_the_closed_forms_of_its_windows() {
    // Flux of a Lambertian body of albedo ρ into a window R: (ρ/π)·Ω⊥(R)·P_source (closed-form projected solid
    // angles, `Stop::projected_solid_angle`); the standard's flux by the quadrature above.
    let g = standards::find("rhopoint-iq-20").unwrap();
    let geo = &g.geometry;
    let theta = geo.theta;
    let p_source = geo.source.projected_solid_angle(-theta);
    let rho = 0.5;
    let flux = |s: Stop| rho / std::f64::consts::PI * s.projected_solid_angle(theta) * p_source;
    let standard = mirror_flux(theta, geo.source, window(224, 287, 3.6), 1.567);
    let haze = 100.0 * 0.5 * (flux(window(182, 195, 3.6)) + flux(window(316, 329, 3.6))) / standard;
    let doi =
        100.0 * (1.0 - 0.5 * (flux(window(241, 247, 3.6)) + flux(window(263, 269, 3.6))) / flux(window(252, 258, 3.6)));
    let gloss = 100.0 * flux(window(224, 287, 3.6)) / standard;
    let rs = read(r#"{"model": "lambert", "albedo": 0.5}"#, &["rhopoint-iq-20"]);
    for (name, want) in
        [("gloss", gloss), ("haze", haze), ("doi", doi), ("log-haze", 1285.1 * (haze / 20.0 + 1.0).log10())]
    {
        let got = value(&rs, "rhopoint-iq-20", name);
        assert!((got - want).abs() <= 1e-6 * want.abs().max(1e-3), "{name}: {got} vs {want}");
    }
    // A Lambertian body's DOI is small and negative here: the R0.3 windows see a little more cos θ-weighted
    // solid angle on the normal side than they lose on the grazing side.
    assert!(doi.abs() < 1.0, "{doi}");
}

/// An edit of the shipped geometry's JSON.
type Edit = Box<dyn Fn(&mut Value)>;

fn iq_with(edit: impl Fn(&mut Value)) -> std::path::PathBuf {
    let mut g: Value = serde_json::from_str(include_str!("../standards/rhopoint-iq-20.json")).unwrap();
    g["id"] = "my-iq".into();
    edit(&mut g);
    let path = tmp(&format!("iq-{}.json", rand_name(&g)));
    std::fs::write(&path, serde_json::to_string(&g).unwrap()).unwrap();
    path
}

fn rand_name(v: &Value) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    v.to_string().hash(&mut h);
    h.finish()
}

#[test]
fn windows_outside_the_array_are_refused_naming_file_and_field() {
    let recipe = tmp("glass.json");
    std::fs::write(&recipe, r#"{"model": "smooth-dielectric", "ior": 1.5}"#).unwrap();
    let recipe = recipe.to_str().unwrap();
    let cases: Vec<(Edit, &str, &str)> = vec![
        (
            Box::new(|g: &mut Value| g["receptors"][5]["pixel_last"]["value"] = 512.into()),
            "/receptors/5/pixel_last",
            "511",
        ),
        (
            Box::new(|g: &mut Value| g["receptors"][4]["pixel_first"]["value"] = (-1).into()),
            "/receptors/4/pixel_first",
            "511",
        ),
        (
            Box::new(|g: &mut Value| g["receptors"][1]["pixel_first"]["value"] = 2.5.into()),
            "/receptors/1/pixel_first",
            "whole",
        ),
        (
            Box::new(|g: &mut Value| g["receptors"][0]["pixel_first"]["value"] = 300.into()),
            "/receptors/0/pixel_last",
            "pixel_first ≤ pixel_last",
        ),
        (
            Box::new(|g: &mut Value| {
                g.as_object_mut().unwrap().remove("profile");
            }),
            "/receptors/0/shape",
            "profile",
        ),
        (
            Box::new(|g: &mut Value| {
                g["receptors"][2]["offset_deg"] = serde_json::json!({"value": 1, "source": "x", "status": "assumed"})
            }),
            "/receptors/2",
            "offset_deg",
        ),
    ];
    for (edit, field, allowed) in cases {
        let file = iq_with(edit);
        let f = file.to_str().unwrap();
        let (code, _, err) = gm(&["measure", recipe, "--geometry-file", f]);
        assert_eq!(code, 2, "{field}: {err}");
        assert!(err.contains(f) && err.contains(field) && err.contains(allowed), "{field}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn standards_and_explain_show_the_pixel_readings_and_what_is_assumed() {
    let (code, out, _) = gm(&["standards", "rhopoint-iq-20"]);
    assert_eq!(code, 0);
    for needle in ["pixels of the profile array", "first pixel: 224", "last pixel: 287", "[assumed]", "RIQ", "0.0991"] {
        assert!(out.contains(needle), "{needle}: {out}");
    }
    let recipe = tmp("glass-explain.json");
    std::fs::write(&recipe, r#"{"model": "smooth-dielectric", "ior": 1.5}"#).unwrap();
    let (code, out, err) = gm(&["measure", recipe.to_str().unwrap(), "-g", "rhopoint-iq-20", "--explain"]);
    assert_eq!(code, 0, "{err}");
    let all = format!("{out}{err}");
    for needle in [
        "pixel-array readings",
        "window rspec: pixels 252–258",
        "/source/in_plane_deg = 0.1",
        "assumed numbers",
        "doi (DOI) = 100·(Φ(rspec)",
    ] {
        assert!(all.contains(needle), "{needle}: {all}");
    }
}
