//! Rspec and the 20° goniophotometric profile (`docs/instrument.md` §1.8): the profile of a smooth dielectric and of a
//! Lambertian body against closed forms computed here independently of the engine, Rspec of smooth
//! specimens, the CSV / JSON schema of `glossmeter profile`, its picture, and bad input (exit 2 naming the
//! file and the field).
mod common;
use common::{fresh, gm};
use std::sync::Arc;

use glossmeter::brdf::Brdf;
use glossmeter::instrument::geometry::Stop;
use glossmeter::instrument::plan::{Plan, PlanOptions};
use glossmeter::instrument::profile;
use glossmeter::instrument::reference::gauss_legendre;
use glossmeter::instrument::standards;
use glossmeter::recipe::parse_str;
use serde_json::Value;

fn brdf(text: &str) -> Arc<dyn Brdf> {
    parse_str(text, "<test>").unwrap().brdf
}

/// Unpolarised Fresnel reflectance of a real index η (Born & Wolf §1.5.2), written out here.
fn fresnel(c: f64, eta: f64) -> f64 {
    let w = (eta * eta - (1.0 - c * c)).sqrt();
    let rs = (c - w) / (c + w);
    let rp = (eta * eta * c - w) / (eta * eta * c + w);
    0.5 * (rs * rs + rp * rp)
}

/// ∫ R(cos θi) cos θi dω over the source points (p, q) whose mirror image (−p, −q) lies in `rec`, by a
/// 40 × 40 Gauss–Legendre product rule on the (smooth) integrand; cos θi = (cos θ + p sin θ)/√(1 + p² + q²),
/// dω = dp dq/(1 + p² + q²)^{3/2} (docs/instrument.md §1.1).
fn mirror_flux(theta: f64, src: Stop, rec: Stop, eta: f64) -> f64 {
    let p = [src.p[0].max(-rec.p[1]), src.p[1].min(-rec.p[0])];
    let q = [src.q[0].max(-rec.q[1]), src.q[1].min(-rec.q[0])];
    if !(p[1] > p[0] && q[1] > q[0]) {
        return 0.0;
    }
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

fn rspec20() -> standards::StandardGeometry {
    standards::find("rspec-20").unwrap()
}

#[test]
fn the_shipped_array_is_512_pixels_of_0_02832_degrees_about_the_specular_direction() {
    let p = standards::profile::of(&rspec20()).unwrap();
    assert_eq!(p.pixels, 512);
    assert_eq!(p.pixel_deg, 0.02832);
    // Centres at ±255.5 pixels, edges at ±256 pixels = ±7.24992°.
    assert!((p.centre_deg(0) + 7.23576).abs() < 1e-12 && (p.centre_deg(511) - 7.23576).abs() < 1e-12);
    assert!((p.stop(0).p[0].atan().to_degrees() + 7.24992).abs() < 1e-9);
    assert!((p.stop(511).p[1].atan().to_degrees() - 7.24992).abs() < 1e-9);
    // Neighbouring pixels share their edges (to rounding), so the array has no gaps.
    for k in 0..511 {
        assert!((p.stop(k).p[1] - p.stop(k + 1).p[0]).abs() < 1e-15, "{k}");
    }
}

#[test]
fn a_smooth_dielectric_profile_is_each_pixels_share_of_the_mirror_image() {
    let g = rspec20();
    let spec = standards::profile::of(&g).unwrap();
    let geo = &g.geometry;
    let reference = Stop::from_angles(spec.pixel, spec.perpendicular, 0.0);
    let standard = mirror_flux(geo.theta, geo.source, reference, 1.567);
    let prof = profile::measure(
        brdf(r#"{"model": "smooth-dielectric", "ior": 1.5}"#),
        &g,
        PlanOptions::default(),
        profile::Budget::default(),
    )
    .unwrap();
    let (mut lit, mut dark) = (0, 0);
    for r in &prof.rows {
        let expected = 100.0 * mirror_flux(geo.theta, geo.source, spec.stop(r.pixel), 1.5) / standard;
        let v = r.reading.value.unwrap();
        assert!(r.reading.converged);
        if expected == 0.0 {
            // Outside the mirror image of the source: exactly nothing.
            assert_eq!(v, 0.0, "pixel {}", r.pixel);
            dark += 1;
        } else {
            lit += 1;
            assert!((v - expected).abs() <= 1e-7 * 100.0, "pixel {}: {v} vs {expected}", r.pixel);
            assert!((v - expected).abs() <= r.reading.error_estimate + 1e-12 * 100.0, "pixel {}", r.pixel);
        }
    }
    // The 0.75° source image covers 0.75/0.02832 = 26.5 pixels: 26 whole ones and two partial ones.
    assert_eq!((lit, dark), (28, 484));
    // The pixels fully inside the image read the glass's gloss on this scale, about 82 (Fresnel ratio).
    let centre = &prof.rows[256];
    let ratio = 100.0 * fresnel(20f64.to_radians().cos(), 1.5) / fresnel(20f64.to_radians().cos(), 1.567);
    assert!((centre.reading.value.unwrap() - ratio).abs() < 0.01, "{:?} vs {ratio}", centre.reading.value);
}

#[test]
fn a_lambertian_profile_is_its_closed_form_pixel_by_pixel() {
    // (ρ/π)·Ω⊥(pixel)·P_source, Ω⊥ and P_source by the closed-form projected solid angle of a stop
    // (the source lens is the receptor's mirror: its cos θ is (cos θ + p sin θ)/√…, i.e. the formula at −θ).
    let g = rspec20();
    let spec = standards::profile::of(&g).unwrap();
    let geo = &g.geometry;
    let reference = Stop::from_angles(spec.pixel, spec.perpendicular, 0.0);
    let standard = mirror_flux(geo.theta, geo.source, reference, 1.567);
    let p_source = geo.source.projected_solid_angle(-geo.theta);
    let rho = 0.5;
    let prof = profile::measure(
        brdf(r#"{"model": "lambert", "albedo": 0.5}"#),
        &g,
        PlanOptions::default(),
        profile::Budget::default(),
    )
    .unwrap();
    for r in &prof.rows {
        let flux = rho / std::f64::consts::PI * spec.stop(r.pixel).projected_solid_angle(geo.theta) * p_source;
        let expected = 100.0 * flux / standard;
        let v = r.reading.value.unwrap();
        assert!((v - expected).abs() <= 1e-6 * expected, "pixel {}: {v} vs {expected}", r.pixel);
        assert!((v - expected).abs() <= r.reading.error_estimate + 1e-13, "pixel {}", r.pixel);
    }
}

#[test]
fn rspec_of_a_smooth_surface_is_its_20_degree_gloss_and_texture_lowers_it() {
    let read = |text: &str, ids: &[&str]| {
        let gs: Vec<_> = ids.iter().map(|id| standards::find(id).unwrap()).collect();
        Plan::compile(brdf(text), gs, PlanOptions::default()).unwrap().execute()
    };
    let glass = read(r#"{"model": "smooth-dielectric", "ior": 1.567}"#, &["rspec-20"]);
    assert_eq!((glass[0].name.as_str(), glass[0].unit.as_str()), ("rspec", "GU"));
    assert!((glass[0].value.unwrap() - 100.0).abs() < 1e-9, "{:?}", glass[0].value);
    let g15 = read(r#"{"model": "smooth-dielectric", "ior": 1.5}"#, &["rspec-20", "astm-d523-20"]);
    let (rspec, gloss) = (g15[0].value.unwrap(), g15[1].value.unwrap());
    assert!((rspec - gloss).abs() < 0.05, "rspec {rspec} vs gloss {gloss}");
    // A slightly hazy surface (Beckmann m = 0.02, about 1.1°) keeps most of its 20° gloss but loses Rspec.
    let hazy = read(
        r#"{"model": "microfacet", "ior": 1.5, "distribution": "beckmann", "roughness": 0.02}"#,
        &["rspec-20", "astm-d523-20"],
    );
    let (rspec, gloss) = (hazy[0].value.unwrap(), hazy[1].value.unwrap());
    assert!(rspec < 0.8 * gloss, "rspec {rspec} vs gloss {gloss}");
}

#[test]
fn csv_json_and_plot() {
    let recipe = "fixtures/recipes/cerulean-blue-c.json";
    let svg = fresh("cerulean.svg");
    let (code, out, err) = gm(&["profile", recipe, "--plot", svg.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let mut lines = out.lines();
    assert_eq!(
        lines.next().unwrap(),
        "pixel,angle_deg,angle_half_width_deg,value,error_estimate,unit,converged,evaluations"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 512);
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r.len(), 8);
        assert_eq!(r[0], k.to_string());
        let angle: f64 = r[1].parse().unwrap();
        assert!((angle - (k as f64 - 255.5) * 0.02832).abs() < 1e-12);
        assert_eq!(r[2].parse::<f64>().unwrap(), 0.01416);
        let (v, e): (f64, f64) = (r[3].parse().unwrap(), r[4].parse().unwrap());
        assert!(v.is_finite() && v >= 0.0 && e.is_finite() && e >= 0.0 && e < 1e-4 * v.max(1.0));
        assert_eq!((r[5], r[6]), ("GU", "true"));
    }
    let picture = std::fs::read_to_string(&svg).unwrap();
    assert!(picture.starts_with("<svg") && picture.contains("</svg>") && picture.contains("polyline"));
    // The picture is never overwritten.
    let (code, _, err) = gm(&["profile", recipe, "--plot", svg.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("exists"), "{err}");

    let (code, out, err) = gm(&["profile", recipe, "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    let doc: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(doc["geometry"], "rspec-20");
    assert_eq!(doc["pixels"], 512);
    assert_eq!(doc["pixel_deg"], 0.02832);
    let rows = doc["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 512);
    let keys: Vec<&str> = rows[0].as_object().unwrap().keys().map(|s| s.as_str()).collect();
    for k in profile_columns() {
        assert!(keys.contains(&k), "{k} missing from {keys:?}");
    }
    // The CSV and the JSON carry the same numbers, the CSV's to their precision (docs/instrument.md §Numbers in
    // text): the printed error estimate covers the computed one and the printed value's rounding.
    let (_, csv_out, _) = gm(&["profile", recipe]);
    let cells: Vec<f64> =
        csv_out.lines().nth(257).unwrap().split(',').skip(3).take(2).map(|c| c.parse().unwrap()).collect();
    let (v, e) = (rows[256]["value"].as_f64().unwrap(), rows[256]["error_estimate"].as_f64().unwrap());
    assert!(cells[1] >= e && (cells[0] - v).abs() <= cells[1] - e + 1e-12 * v.abs(), "{cells:?} against {v} ± {e}");
    let _ = std::fs::remove_file(&svg);
}

fn profile_columns() -> Vec<&'static str> {
    glossmeter::cli::profile::COLUMNS.to_vec()
}

#[test]
fn bad_profiles_are_refused_with_the_file_and_the_field() {
    let base: Value = serde_json::from_str(include_str!("../standards/rspec-20.json")).unwrap();
    let cases: &[(&str, Value, &str)] = &[
        ("zero.json", serde_json::json!(0), "/profile/pixels/value"),
        ("half.json", serde_json::json!(2.5), "/profile/pixels/value"),
        ("huge.json", serde_json::json!(1_000_000), "/profile/pixels/value"),
    ];
    for (name, pixels, field) in cases {
        let mut g = base.clone();
        g["id"] = Value::from("my-profile");
        g["profile"]["pixels"]["value"] = pixels.clone();
        let f = fresh(name);
        std::fs::write(&f, serde_json::to_string(&g).unwrap()).unwrap();
        let (code, _, err) =
            gm(&["profile", "fixtures/recipes/glass-n1.5.json", "--geometry-file", f.to_str().unwrap()]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(err.contains(f.to_str().unwrap()) && err.contains(field), "{name}: {err}");
        // The same file is refused by `measure` too (it is checked when the geometry is read).
        let (code, _, _) = gm(&["measure", "fixtures/recipes/glass-n1.5.json", "--geometry-file", f.to_str().unwrap()]);
        assert_eq!(code, 2);
        let _ = std::fs::remove_file(&f);
    }
    // A profile block with an unknown field, and one whose array would reach below the specimen plane.
    let mut g = base.clone();
    g["id"] = Value::from("my-profile");
    g["profile"]["pixel_deg"]["value"] = Value::from(0.5);
    let f = fresh("wide.json");
    std::fs::write(&f, serde_json::to_string(&g).unwrap()).unwrap();
    let (code, _, err) = gm(&["profile", "fixtures/recipes/glass-n1.5.json", "--geometry-file", f.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("/profile/pixels/value") && err.contains("±45°"), "{err}");
    let _ = std::fs::remove_file(&f);
    // A geometry without a profile array.
    let (code, _, err) = gm(&["profile", "fixtures/recipes/glass-n1.5.json", "-g", "astm-d523-20"]);
    assert_eq!(code, 2);
    assert!(err.contains("/profile") && err.contains("no profile array"), "{err}");
    // An unknown geometry id, a bad recipe.
    let (code, _, err) = gm(&["profile", "fixtures/recipes/glass-n1.5.json", "-g", "no-such"]);
    assert_eq!(code, 2, "{err}");
    let (code, _, _) = gm(&["profile", "no/such/recipe.json"]);
    assert_eq!(code, 2);
}

/// A profile that cannot converge within its budget ends within its deterministic evaluation budget
/// (docs/instrument.md §1.8): each part of each pixel gets min(--max-evals, --max-total-evals / (2·pixels)) for
/// its refinement, every pixel that reached it says so and is not converged, the command exits 1 (0 with
/// --allow-unconverged), and a second run gives the same bytes. The case: a Beckmann lobe of rms slope 10⁻⁴ at
/// rtol 10⁻¹⁰, whose pixels near the specular direction need more than 195 evaluations a part. (It was a
/// constant 10³⁰⁸ table, which ran 8 minutes at the measurement's 2·10⁶ a part; since tables are split at
/// their lobe and first ring instead of every cell, docs/instrument.md §Quadrature, it converges at once.)
#[test]
fn a_profile_that_cannot_converge_ends_within_its_evaluation_budget() {
    let recipe = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/recipes/bench-b3-beckmann-1e-4.json");
    let r = recipe.to_str().unwrap();
    let args = &["profile", r, "--format", "json", "--rtol", "1e-10", "--max-total-evals", "200000"];
    let (code, out, err) = gm(args);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("converge"), "{err}");
    let doc: Value = serde_json::from_str(&out).unwrap();
    // 200 000 / (2 · 512) = 195 per part.
    assert_eq!(doc["budget"]["per_part"], 195, "{}", doc["budget"]);
    assert_eq!(doc["budget"]["max_total_evals"], 200_000);
    assert_eq!(doc["budget"]["max_evals"], profile::DEFAULT_PIXEL_EVALS);
    let rows = doc["rows"].as_array().unwrap();
    let unconverged: Vec<&Value> = rows.iter().filter(|r| r["converged"] == false).collect();
    assert!(!unconverged.is_empty());
    for row in &unconverged {
        let problem = row["problem"].as_str().unwrap_or_default();
        assert!(problem.contains("budget") || row["value"].is_null(), "pixel {}: {problem}", row["pixel"]);
    }
    // Deterministic: the same budget, the same bytes.
    let (code2, out2, _) = gm(args);
    assert_eq!((code2, &out2), (1, &out));
    // A budget of 0 is a usage error.
    let (code, _, err) = gm(&["profile", r, "--max-evals", "0"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--max-evals"), "{err}");
    let (code, _, _) = gm(&["profile", r, "--max-total-evals", "0"]);
    assert_eq!(code, 2);
}

/// The budget's share per part is the counts' alone: min(per part, total / (2·pixels)), at least 1.
#[test]
fn the_profile_budget_is_shared_equally_by_the_pixels() {
    let b = profile::Budget { per_part: 1000, total: 1_000_000 };
    assert_eq!(b.part_budget(512), 976);
    assert_eq!(b.part_budget(100), 1000);
    assert_eq!(profile::Budget { per_part: 1000, total: 10 }.part_budget(512), 1);
    assert_eq!(profile::Budget::default().part_budget(512), 19_531);
}
