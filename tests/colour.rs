//! Colour readings against independent references: colour-science's `sd_to_XYZ` / `XYZ_to_Lab` for Lambertian
//! ColorChecker spectra on the d/8 sphere (after the SCE aperture factor), the white diffuser's L* = 100, the flop
//! of a metallic, the refusal of RGB materials, sharing with gloss, and the CLI. Colour readings go through the
//! same plan as gloss (the X, Y, Z rows of the k × n weighting folded into the integrand).
mod common;
use std::sync::Arc;

use glossmeter::brdf::Brdf;
use glossmeter::colorimetry::{Conditions, Illuminant, Observer};
use glossmeter::instrument::plan::{Plan, PlanOptions, Reading};
use glossmeter::instrument::standards::colour::{self, ColourKind};
use glossmeter::instrument::standards::{self, StandardGeometry};
use glossmeter::recipe;
use serde_json::Value;

fn geos(ids: &[&str]) -> Vec<StandardGeometry> {
    ids.iter().map(|id| standards::find(id).unwrap()).collect()
}

fn options(colour: Conditions, rtol: f64) -> PlanOptions {
    PlanOptions { rtol, colour, ..PlanOptions::default() }
}

fn measure(m: Arc<dyn Brdf>, ids: &[&str], colour: Conditions, rtol: f64) -> Vec<Reading> {
    Plan::compile(m, geos(ids), options(colour, rtol)).unwrap().execute()
}

fn brdf(json: &str) -> Arc<dyn Brdf> {
    recipe::parse_str(json, "<test>").unwrap().brdf
}

fn value(rs: &[Reading], geometry: &str, q: &str) -> (f64, f64) {
    let r = rs.iter().find(|r| r.geometry == geometry && r.quantity == q).unwrap();
    (r.value.unwrap(), r.error_estimate)
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

/// The SCE aperture factor of a Lambertian: 1 − P_port/π = 1 − sin²β cos 8° (projected solid angle of a cone of
/// half-angle β whose axis is 8° from the normal: π sin²β cos 8°).
fn aperture_factor() -> f64 {
    let g = standards::find("d8-sce").unwrap();
    let Some(ColourKind::Sphere { viewing, port: Some(beta) }) = colour::colour_kind(&g.geometry) else {
        panic!("d8-sce is a sphere with a port")
    };
    1.0 - beta.sin().powi(2) * viewing.cos()
}

#[test]
fn lambertian_colorchecker_on_d8_matches_colour_science() {
    let v: Value = serde_json::from_str(include_str!("../fixtures/reference/colorimetry.json")).unwrap();
    let grid = nums(&v["wavelengths_nm"]);
    let factor = aperture_factor();
    let mut worst: f64 = 0.0;
    for case in v["cases"].as_array().unwrap().iter().filter(|c| c["illuminant"] == "D65" || c["patch"] == "red") {
        let r = nums(&case["reflectance"]);
        let json = serde_json::json!({"model": "lambert", "wavelengths_nm": grid, "albedo": r}).to_string();
        let cond = Conditions {
            illuminant: Illuminant::parse(case["illuminant"].as_str().unwrap()).unwrap(),
            observer: Observer::parse(case["observer"].as_str().unwrap()).unwrap(),
        };
        let rs = measure(brdf(&json), &["d8-sci", "d8-sce"], cond, 1e-8);
        let theirs = nums(&case["XYZ"]);
        for (i, q) in ["X", "Y", "Z"].iter().enumerate() {
            let (sci, esci) = value(&rs, "d8-sci", q);
            let (sce, esce) = value(&rs, "d8-sce", q);
            let rel_sci = (sci - theirs[i]).abs() / theirs[i];
            let rel_sce = (sce / factor - theirs[i]).abs() / theirs[i];
            worst = worst.max(rel_sci).max(rel_sce);
            assert!(rel_sci < 1e-6, "{} {q} SCI {sci} vs colour-science {}", case["patch"], theirs[i]);
            assert!(rel_sce < 1e-6, "{} {q} SCE {sce}/{factor} vs colour-science {}", case["patch"], theirs[i]);
            // The error estimates cover the actual differences (beyond the reference's own rounding).
            assert!((sci - theirs[i]).abs() <= esci + 1e-12 * theirs[i], "{} {q}: error {esci}", case["patch"]);
            assert!(
                (sce - factor * theirs[i]).abs() <= esce + 1e-12 * theirs[i],
                "{} {q}: error {esce}",
                case["patch"]
            );
        }
        let lab = nums(&case["Lab"]);
        for (i, q) in ["L*", "a*", "b*"].iter().enumerate() {
            let (ours, _) = value(&rs, "d8-sci", q);
            assert!((ours - lab[i]).abs() < 1e-6, "{} {q}: {ours} vs colour-science {}", case["patch"], lab[i]);
        }
    }
    eprintln!("worst relative difference from colour-science on d/8: {worst:e}");
}

#[test]
fn white_diffuser_reads_l_100_on_d8() {
    let rs =
        measure(brdf(r#"{"model": "lambert", "albedo": 1.0}"#), &["d8-sci", "d8-sce"], Conditions::default(), 1e-6);
    let (l, e) = value(&rs, "d8-sci", "L*");
    assert!((l - 100.0).abs() < 1e-6 && (l - 100.0).abs() <= e + 1e-12, "L* = {l} ± {e}");
    for q in ["a*", "b*", "C*"] {
        assert!(value(&rs, "d8-sci", q).0.abs() < 1e-6, "{q}");
    }
    // SCE: the port removes sin²β cos 8° of the light; L* below 100 by exactly that in Y.
    let y = value(&rs, "d8-sce", "Y").0;
    assert!((y / 100.0 - aperture_factor()).abs() < 1e-7, "Y_SCE = {y}");
    // The hue of a neutral is undefined: not printed as a number.
    let h = rs.iter().find(|r| r.geometry == "d8-sci" && r.quantity == "h").unwrap();
    assert!(h.value.is_none() || value(&rs, "d8-sci", "C*").0 > 0.0);
}

#[test]
fn lambertian_on_multi_angle_geometries_reads_its_albedo() {
    // A Lambertian's reflectance factor is ρ in every geometry: X, Y, Z = ρ × white point.
    let rs = measure(
        brdf(r#"{"model": "lambert", "wavelengths_nm": [400, 550, 700], "albedo": [0.5, 0.5, 0.5]}"#),
        &["astm-e2194-15", "astm-e2194-45", "astm-e2194-110", "astm-e2539-m15"],
        Conditions::default(),
        1e-8,
    );
    for id in ["astm-e2194-15", "astm-e2194-45", "astm-e2194-110", "astm-e2539-m15"] {
        let (y, e) = value(&rs, id, "Y");
        assert!((y - 50.0).abs() < 1e-6 && (y - 50.0).abs() <= e + 1e-12, "{id}: Y = {y} ± {e}");
    }
}

#[test]
fn metallic_flop_goes_light_to_dark() {
    let m = recipe::load_file(std::path::Path::new("fixtures/recipes/blue-metallic-spectral.json")).unwrap();
    let ids = ["astm-e2194-15", "astm-e2194-45", "astm-e2194-110"];
    let rs = measure(m.brdf, &ids, Conditions::default(), 1e-5);
    let l: Vec<(f64, f64)> = ids.iter().map(|id| value(&rs, id, "L*")).collect();
    eprintln!("L* at 15°, 45°, 110°: {l:?}");
    assert!(l[0].0 - l[0].1 > l[1].0 + l[1].1, "L*15 > L*45: {l:?}");
    assert!(l[1].0 - l[1].1 > l[2].0 + l[2].1, "L*45 > L*110: {l:?}");
    // A blue: b* < 0 at every angle.
    for id in ids {
        assert!(value(&rs, id, "b*").0 < 0.0, "{id}");
    }
}

#[test]
fn rgb_materials_are_refused_with_the_reason() {
    let m = recipe::load_file(std::path::Path::new("fixtures/recipes/cerulean-blue-a.json")).unwrap();
    let e = Plan::compile(m.brdf, geos(&["d8-sci"]), PlanOptions::default()).err().expect("RGB refused").to_string();
    assert!(e.contains("RGB") && e.contains("wavelengths_nm") && e.contains("d8-sci"), "{e}");
}

#[test]
fn identical_geometries_share_their_integral_and_gloss_keeps_its_bits() {
    let m = brdf(r#"{"model": "lambert", "albedo": 0.5}"#);
    let ids = ["astm-e2194-15", "astm-e2539-15", "d8-sci", "d8-sce", "astm-d523-60"];
    let plan = Plan::compile(m.clone(), geos(&ids), PlanOptions::default()).unwrap();
    let used: Vec<String> = plan.jobs.iter().map(|j| j.used_by.join(", ")).collect();
    assert!(used.contains(&"astm-e2194-15/receptor, astm-e2539-15/receptor".to_string()), "{used:?}");
    assert!(used.contains(&"d8-sci/hemisphere, d8-sce/hemisphere".to_string()), "{used:?}");
    // Colour fluxes have the three components X, Y, Z; the gloss flux stays one luminous component.
    for j in &plan.jobs {
        let k = j.method.weighting.len();
        if j.used_by.iter().any(|u| u.starts_with("astm-d523")) {
            assert_eq!(k, 1, "{:?}", j.used_by);
        } else {
            assert_eq!(k, 3, "{:?}", j.used_by);
        }
    }
    let e = plan.explain();
    assert!(e.contains("not folded"), "{e}");
    // The gloss reading is the same bits with or without colour geometries in the plan.
    let with = plan.execute();
    let alone = Plan::compile(m, geos(&["astm-d523-60"]), PlanOptions::default()).unwrap().execute();
    let g = with.iter().find(|r| r.geometry == "astm-d523-60").unwrap();
    assert_eq!(g.value.unwrap().to_bits(), alone[0].value.unwrap().to_bits());
    assert_eq!(g.evaluations, alone[0].evaluations);
}

#[test]
fn a_frozen_colour_plan_reproduces_its_bits() {
    // What `fit` needs: the frozen plan re-runs the kept partitions and gives the same bits on the same material.
    let m = brdf(r#"{"model": "lambert", "wavelengths_nm": [400, 550, 700], "albedo": [0.2, 0.5, 0.4]}"#);
    let plan = Plan::compile(m, geos(&["astm-e2194-45"]), PlanOptions::default()).unwrap();
    let (frozen_readings, frozen) = plan.freeze();
    let again = frozen.execute();
    for (a, b) in frozen_readings.iter().zip(&again) {
        assert_eq!(a.value.map(f64::to_bits), b.value.map(f64::to_bits), "{} {}", a.geometry, a.name);
    }
}

#[test]
fn cli_measures_colour_and_refuses_bad_options() {
    let bin = env!("CARGO_BIN_EXE_glossmeter");
    let out = std::process::Command::new(bin)
        .args(["measure", "fixtures/recipes/white-pearl-spectral.json", "-g", "d8-sce", "-g", "astm-e2539-m15"])
        .args(["--format", "json", "--no-timing", "--rtol", "1e-4", "--observer", "2", "--illuminant", "D50"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let text = v.to_string();
    for q in ["\"X\"", "\"L*\"", "\"C*\"", "\"h\""] {
        assert!(text.contains(q), "{q} missing: {text}");
    }
    let bad = std::process::Command::new(bin)
        .args(["measure", "fixtures/recipes/white-pearl-spectral.json", "-g", "d8-sce", "--illuminant", "F11"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("D65"));
    let rgb = std::process::Command::new(bin)
        .args(["measure", "fixtures/recipes/cerulean-blue-a.json", "-g", "astm-e2194-15"])
        .output()
        .unwrap();
    assert_eq!(rgb.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&rgb.stderr).contains("wavelengths_nm"));
}

#[test]
fn error_estimates_cover_the_actual_error() {
    // The readings at rtol 1e-5 against the same readings at rtol 1e-11 (the reference): every difference is
    // within the coarse run's error estimate.
    for path in ["fixtures/recipes/blue-metallic-spectral.json", "fixtures/recipes/white-pearl-spectral.json"] {
        let m = recipe::load_file(std::path::Path::new(path)).unwrap();
        let ids = colour::builtin_ids();
        let coarse = measure(m.brdf.clone(), &ids, Conditions::default(), 1e-5);
        let fine = measure(m.brdf.clone(), &ids, Conditions::default(), 1e-11);
        for (c, f) in coarse.iter().zip(&fine) {
            let (Some(cv), Some(fv)) = (c.value, f.value) else { continue };
            let actual = (cv - fv).abs();
            assert!(
                actual <= c.error_estimate + f.error_estimate + 1e-12 * fv.abs(),
                "{path} {} {}: {cv} ± {} vs {fv}: actual error {actual:e}",
                c.geometry,
                c.quantity,
                c.error_estimate
            );
        }
    }
}

#[test]
fn compare_reports_de00_for_colour_sheets() {
    let bin = env!("CARGO_BIN_EXE_glossmeter");
    let run = |extra: &[&str]| {
        std::process::Command::new(bin)
            .args([
                "compare",
                "fixtures/recipes/blue-metallic-spectral.json",
                "fixtures/sheets/colour-blue-metallic.csv",
            ])
            .args(["--format", "json", "--rtol", "1e-5"])
            .args(extra)
            .output()
            .unwrap()
    };
    let out = run(&["--max-de00", "100"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let des = v["colour_differences"].as_array().unwrap();
    assert_eq!(des.len(), 3);
    for d in des {
        let (m, p) = (nums(&d["measured"]), nums(&d["predicted"]));
        let lab = |x: &[f64]| glossmeter::colorimetry::Lab { l: x[0], a: x[1], b: x[2] };
        let de = glossmeter::colorimetry::ciede2000(lab(&m), lab(&p));
        assert!((d["de00"].as_f64().unwrap() - de).abs() < 1e-12);
        assert!(de > 0.0 && de < 100.0, "{d}");
        assert_eq!(d["inside"], Value::Bool(true));
    }
    // Each L*, a*, b* row was predicted by the colour plan.
    for c in v["comparisons"].as_array().unwrap() {
        assert!(c["predicted"].is_number(), "{c}");
    }
    let strict = run(&["--max-de00", "0"]);
    assert_eq!(strict.status.code(), Some(1), "{}", String::from_utf8_lossy(&strict.stderr));
    assert!(String::from_utf8_lossy(&strict.stderr).contains("ΔE00"));
}

/// A colour sheet that states its illuminant and observer is compared (and fitted) only under them: at every
/// door, any other request is refused, naming the sheet's line and what to ask for; under them, the
/// predictions are `measure`'s under the same flags.
#[test]
fn a_colour_sheet_is_compared_only_under_the_conditions_it_states() {
    let bin = env!("CARGO_BIN_EXE_glossmeter");
    let dir = common::tmp_dir("stated-conditions");
    std::fs::create_dir_all(&dir).unwrap();
    let shipped = std::fs::read_to_string("fixtures/sheets/colour-blue-metallic.csv").unwrap();
    let sheet = dir.join("a2.csv");
    std::fs::write(&sheet, shipped.replace("# illuminant/observer: D65/10°", "Illuminant: A,Observer: 2°")).unwrap();
    let sheet = sheet.to_str().unwrap();
    let recipe = "fixtures/recipes/blue-metallic-spectral.json";
    let run = |args: &[&str]| std::process::Command::new(bin).args(args).output().unwrap();
    // The shipped sheet states D65 / 10°, the default: read as before.
    let shipped_run = run(&["compare", recipe, "fixtures/sheets/colour-blue-metallic.csv", "--max-de00", "100"]);
    assert!(shipped_run.status.success(), "{}", String::from_utf8_lossy(&shipped_run.stderr));
    // Under the default, the A / 2° sheet is refused, with its line and the flags that ask for its conditions.
    for colour in [&[][..], &["--illuminant", "A"][..], &["--observer", "2"][..]] {
        let out = run(&[&["compare", recipe, sheet][..], colour].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{colour:?}: {err}");
        assert!(err.contains("a2.csv") && err.contains("not comparable"), "{err}");
        assert!(err.contains("give --illuminant A --observer 2 (the sheet's)"), "{err}");
    }
    let fit_refused = run(&["fit", recipe, "--sheet", sheet, "--free", "/clear_coat/roughness=0.01..0.2"]);
    assert_eq!(fit_refused.status.code(), Some(2), "{}", String::from_utf8_lossy(&fit_refused.stderr));
    assert!(String::from_utf8_lossy(&fit_refused.stderr).contains("--illuminant A --observer 2 (the sheet's)"));
    // Under them, every colour prediction is measure's under the same flags.
    let under_a2 = |sheet: &str| -> Value {
        let colour = ["--illuminant", "A", "--observer", "2", "--format", "json", "--max-de00", "100"];
        let out = run(&[&["compare", recipe, sheet][..], &colour].concat());
        assert!(out.status.success(), "{sheet}: {}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let doc = under_a2(sheet);
    let m = run(&[
        "measure",
        recipe,
        "-g",
        "astm-e2194-15",
        "-g",
        "astm-e2194-45",
        "-g",
        "astm-e2194-110",
        "--illuminant",
        "A",
        "--observer",
        "2",
        "--format",
        "json",
        "--no-timing",
    ]);
    let measured: Value = serde_json::from_slice(&m.stdout).unwrap();
    let rows = doc["comparisons"].as_array().unwrap();
    assert_eq!(rows.len(), 9);
    for c in rows {
        let r = measured["readings"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["geometry"] == c["geometry"] && r["name"] == c["reading"])
            .unwrap();
        assert_eq!(c["predicted"], r["value"], "{c}");
        assert_eq!((c["illuminant"].as_str(), c["observer"].as_str()), (Some("A"), Some("2")));
    }
    // The colour columns' headers may state them instead (`L* (A/2°)`), or columns row by row (`Illuminant`,
    // `Observer`): the same refusal under the default, naming the column; under A / 2° the same predictions.
    let write = |name: &str, text: String| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let unstated = shipped.replace("# illuminant/observer: D65/10°\n", "");
    let headed = write("headed.csv", unstated.replace("L*,a*,b*", "L* (A/2°),a* (A/2°),b* (A/2°)"));
    let by_rows = unstated
        .replace("sample,geometry,", "sample,geometry,Illuminant,Observer,")
        .lines()
        .map(|l| match l.strip_prefix("panel-1,").and_then(|rest| rest.split_once(',')) {
            Some((geometry, lab)) => format!("panel-1,{geometry},A,2°,{lab}\n"),
            None => format!("{l}\n"),
        })
        .collect();
    let by_rows = write("rows.csv", by_rows);
    let predicted =
        |d: &Value| d["comparisons"].as_array().unwrap().iter().map(|c| c["predicted"].clone()).collect::<Vec<_>>();
    for (stated, place) in [(&headed, "column 3 (L* (A/2°))"), (&by_rows, "column 3 (Illuminant)")] {
        let out = run(&["compare", recipe, stated]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(place) && err.contains("--illuminant A --observer 2 (the sheet's)"), "{err}");
        assert_eq!(predicted(&under_a2(stated)), predicted(&doc), "{stated}: the metadata sheet's predictions");
    }
    // An export under two illuminants: refused as duplicate columns; read under one once the others are skipped.
    let two = dir.join("two.csv");
    let both = shipped
        .replace("# illuminant/observer: D65/10°\n", "")
        .replace("L*,a*,b*", "L* (D65/10°),a* (D65/10°),b* (D65/10°),L* (A/2°),a* (A/2°),b* (A/2°)")
        .lines()
        .map(|l| if l.starts_with("panel") { format!("{l},1,2,3") } else { l.to_string() })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&two, both).unwrap();
    let two = two.to_str().unwrap();
    let out = run(&["compare", recipe, two]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("one illuminant and observer at a time") && err.contains("--ignore-column"), "{err}");
    let skip = ["--ignore-column", "L* (A/2°)", "--ignore-column", "a* (A/2°)", "--ignore-column", "b* (A/2°)"];
    let out = run(&[&["compare", recipe, two, "--max-de00", "100"][..], &skip[..]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // A condition glossmeter does not compute under is refused as such.
    let f11 = dir.join("f11.csv");
    std::fs::write(&f11, shipped.replace("D65/10°", "F11/10°")).unwrap();
    let out = run(&["compare", recipe, f11.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("F11") && err.contains("D65, D50, A, C"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_long_lived_planner_knows_the_colour_geometries() {
    // `fit` and the bindings look geometries up through a Planner.
    let p = glossmeter::instrument::plan::Planner::new().unwrap();
    for id in colour::builtin_ids() {
        assert!(p.geometry(id).unwrap().geometry.is_colour(), "{id}");
    }
    assert!(!p.geometry("astm-d523-60").unwrap().geometry.is_colour());
}

#[test]
fn fit_takes_colour_targets() {
    // A spectral Lambertian whose 550 nm albedo is 0.5 reads L* = 73.0519 at E2194 45° (D65, 10°); fitting that
    // albedo from 0.3 to this one colour target recovers it.
    let dir = common::tmp_dir("colour-fit");
    std::fs::create_dir_all(&dir).unwrap();
    let recipe = dir.join("start.json");
    std::fs::write(&recipe, r#"{"model": "lambert", "wavelengths_nm": [400, 550, 700], "albedo": [0.2, 0.3, 0.4]}"#)
        .unwrap();
    let out = common::glossmeter()
        .args(["fit", recipe.to_str().unwrap(), "--free", "/albedo/1=0.05..0.95"])
        .args(["--target", "astm-e2194-45/L*=73.05188932989438±0.01", "--format", "json", "--no-timing"])
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let p = &v["parameters"][0];
    let (x, se) = (p["value"].as_f64().unwrap(), p["std_error"].as_f64().unwrap());
    assert!((x - 0.5).abs() < 1e-6 && (x - 0.5).abs() <= 3.0 * se + 1e-9, "{p}");
}

/// A neutral colour's hue is undefined on every shipped colour geometry (docs/colour.md §Neutral colours): no
/// value, the reason as its note, converged, and no failed reading for the exit status; a chroma of rounding
/// noise (C* ≈ 5e-14 on the directional geometries) is neutral too, never a hue of 0°, 90° or 348.7°.
#[test]
fn a_neutral_colour_has_no_hue_on_any_geometry_and_fails_nothing() {
    let colour: Vec<String> =
        glossmeter::instrument::standards::builtin_colour().unwrap().into_iter().map(|g| g.geometry.id).collect();
    let ids: Vec<&str> = colour.iter().map(String::as_str).collect();
    for recipe in [
        r#"{"model": "lambert", "wavelengths_nm": [400, 550, 700], "albedo": [0.5, 0.5, 0.5]}"#,
        r#"{"model": "lambert", "albedo": 1.0}"#,
        r#"{"model": "phong", "exponent": 754.36, "ks": 0.26, "kd": 0.56}"#,
        r#"{"model": "microfacet", "distribution": "beckmann", "roughness": 0.2, "ior": [0.685, 1.174]}"#,
    ] {
        let rs = measure(brdf(recipe), &ids, Conditions::default(), 1e-6);
        for r in rs.iter().filter(|r| r.quantity == "h") {
            assert!(r.value.is_none() && r.converged && r.problem.is_none(), "{recipe} {}: {r:?}", r.geometry);
            assert!(r.note.as_deref().is_some_and(|n| n.starts_with("neutral colour")), "{r:?}");
        }
        glossmeter::cli::common::readings_status(&rs, false).unwrap_or_else(|e| panic!("{recipe}: {e}"));
    }
}

/// Every document says what its colour readings are computed under, and only on colour readings (docs/
/// instrument.md §Output): `measure`'s JSON, CSV and table, a `sweep` line, a `compare` row and a `fit` target.
#[test]
fn every_document_names_the_illuminant_and_observer_of_its_colour_readings() {
    let bin = env!("CARGO_BIN_EXE_glossmeter");
    let pearl = "fixtures/recipes/white-pearl-spectral.json";
    let run = |args: &[&str]| -> String {
        let out = std::process::Command::new(bin).args(args).output().unwrap();
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8(out.stdout).unwrap()
    };
    let colour = ["--illuminant", "A", "--observer", "2"];
    let geos = ["-g", "astm-d523-60", "-g", "astm-e2194-15"];
    // JSON: every reading of the colour geometry has the pair, the gloss reading has neither.
    let doc: Value =
        serde_json::from_str(&run(
            &[&["measure", pearl, "--format", "json", "--no-timing"][..], &geos, &colour].concat()
        ))
        .unwrap();
    let readings = doc["readings"].as_array().unwrap();
    assert_eq!(readings.len(), 9);
    for r in readings {
        let is_colour = r["geometry"] == "astm-e2194-15";
        assert_eq!(r.get("illuminant").cloned(), is_colour.then(|| Value::from("A")), "{r}");
        assert_eq!(r.get("observer").cloned(), is_colour.then(|| Value::from("2")), "{r}");
    }
    // The default pair is D65 / 10°, said as such.
    let plain: Value =
        serde_json::from_str(&run(&[&["measure", pearl, "--format", "json", "--no-timing"][..], &geos].concat()))
            .unwrap();
    let b = plain["readings"].as_array().unwrap().iter().find(|r| r["name"] == "b*").unwrap();
    assert_eq!((b["illuminant"].as_str(), b["observer"].as_str()), (Some("D65"), Some("10")));
    // CSV: the two columns, filled on colour rows only.
    let text = run(&[&["measure", pearl, "--format", "csv", "--no-timing"][..], &geos, &colour].concat());
    let mut csv = csv::Reader::from_reader(text.as_bytes());
    let head: Vec<String> = csv.headers().unwrap().iter().map(String::from).collect();
    let (i, o) =
        (head.iter().position(|h| h == "illuminant").unwrap(), head.iter().position(|h| h == "observer").unwrap());
    for rec in csv.records() {
        let rec = rec.unwrap();
        let want = if &rec[0] == "astm-e2194-15" { ("A", "2") } else { ("", "") };
        assert_eq!((&rec[i], &rec[o]), want, "{rec:?}");
    }
    // The table: one line under it.
    let table = run(&[&["measure", pearl, "--no-timing"][..], &geos, &colour].concat());
    assert!(table.contains("\ncolour: illuminant A, CIE 1931 2° observer\n"), "{table}");
    let gloss_only = run(&["measure", pearl, "--no-timing", "-g", "astm-d523-60"]);
    assert!(!gloss_only.contains("colour:"), "{gloss_only}");
    // A sweep line.
    let line = run(&[
        &["sweep", pearl, "--vary", "/clear_coat/index=1.5..1.6:2", "--format", "jsonl", "--no-timing"][..],
        &geos,
        &colour,
    ]
    .concat());
    let point: Value = serde_json::from_str(line.lines().next().unwrap()).unwrap();
    for r in point["readings"].as_array().unwrap() {
        let is_colour = r["geometry"] == "astm-e2194-15";
        assert_eq!(r.get("illuminant").is_some() && r.get("observer").is_some(), is_colour, "{r}");
    }
    // The sweep's CSV says them beside each colour column's unit.
    let rows = run(&[
        &["sweep", pearl, "--vary", "/clear_coat/index=1.5..1.6:2", "--format", "csv", "--no-timing"][..],
        &geos,
        &colour,
    ]
    .concat());
    let head = rows.lines().next().unwrap();
    for column in ["astm-d523-60 gloss (GU)", "astm-e2194-15 b* (A / 2°)", "astm-e2194-15 h (°, A / 2°)"] {
        assert!(head.contains(column), "{column} not in {head}");
    }
    // A convergence study: JSON rows, CSV columns, the table; by default under D65 / 10°.
    let study = ["convergence", pearl, "-g", "astm-d523-60", "-g", "astm-e2194-15", "--tolerances", "1e-3"];
    let quick = ["--min-time-ms", "0", "--max-repetitions", "1"];
    let conv: Value = serde_json::from_str(&run(&[&study[..], &quick, &["--format", "json"]].concat())).unwrap();
    let rows = conv["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 9);
    for r in rows {
        let want = (r["geometry"] == "astm-e2194-15").then(|| (Value::from("D65"), Value::from("10")));
        assert_eq!(r.get("illuminant").cloned().zip(r.get("observer").cloned()), want, "{r}");
    }
    let conv_csv = run(&[&study[..], &quick, &["--format", "csv"]].concat());
    assert!(conv_csv.lines().next().unwrap().contains(",illuminant,observer,"), "{conv_csv}");
    let conv_table = run(&[&study[..], &quick].concat());
    assert!(conv_table.contains("colour: illuminant D65, CIE 1964 10° observer"), "{conv_table}");
    // Under a pair asked for, every row is measure's reading under the same flags and tolerance, bit for bit.
    let conv: Value =
        serde_json::from_str(&run(&[&study[..], &quick, &["--format", "json"], &colour].concat())).unwrap();
    let measured: Value = serde_json::from_str(&run(&[
        &["measure", pearl, "--format", "json", "--no-timing", "--rtol", "1e-3"][..],
        &geos,
        &colour,
    ]
    .concat()))
    .unwrap();
    let rows = conv["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 9);
    for r in rows {
        let want = (r["geometry"] == "astm-e2194-15").then(|| (Value::from("A"), Value::from("2")));
        assert_eq!(r.get("illuminant").cloned().zip(r.get("observer").cloned()), want, "{r}");
        let m = measured["readings"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["geometry"] == r["geometry"] && m["name"] == r["reading"])
            .unwrap_or_else(|| panic!("{r}"));
        assert_eq!(m["value"], r["value"], "{r}");
    }
    // A compare row and a fit target: the colour ones have the pair.
    let dir = common::tmp_dir("colour-conditions");
    std::fs::create_dir_all(&dir).unwrap();
    let sheet = dir.join("sheet.csv");
    std::fs::write(
        &sheet,
        "sample,geometry,reading,value,uncertainty\npearl,astm-d523-60,gloss,95,5\npearl,astm-e2194-15,b*,8,5\n",
    )
    .unwrap();
    let cmp: Value =
        serde_json::from_str(&run(
            &[&["compare", pearl, sheet.to_str().unwrap(), "--format", "json"][..], &colour].concat()
        ))
        .unwrap();
    let rows = cmp["comparisons"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    for r in rows {
        let want = (r["geometry"] == "astm-e2194-15").then(|| Value::from("A"));
        assert_eq!(r.get("illuminant").cloned(), want, "{r}");
    }
    let compare_table = run(&[&["compare", pearl, sheet.to_str().unwrap()][..], &colour].concat());
    assert!(compare_table.contains("colour: illuminant A, CIE 1931 2° observer"), "{compare_table}");
    let junit = run(&[&["compare", pearl, sheet.to_str().unwrap(), "--format", "junit"][..], &colour].concat());
    assert_eq!(junit.matches("(error estimate; illuminant A, CIE 1931 2° observer)").count(), 1, "{junit}");
    assert_eq!(junit.matches("(error estimate);").count(), 1, "the gloss row: {junit}");
    let fit: Value = serde_json::from_str(&run(&[
        &["fit", pearl, "--free", "/pearlescent_flakes/tio2_thickness_nm=30..90", "--restarts", "0"][..],
        &["--target", "astm-e2194-15/b*=8±0.05", "--target", "astm-d523-60/gloss=95±1"],
        &["--format", "json", "--no-timing"],
        &colour,
    ]
    .concat()))
    .unwrap();
    assert_eq!(fit["targets"].as_array().unwrap().len(), 2, "{fit}");
    for t in fit["targets"].as_array().unwrap() {
        let want = (t["geometry"] == "astm-e2194-15").then(|| Value::from("2"));
        assert_eq!(t.get("observer").cloned(), want, "{t}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
