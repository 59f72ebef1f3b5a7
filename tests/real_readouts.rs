//! Published readouts of real panels (`fixtures/real/`), reproduced by `glossmeter fit` with one physically
//! plausible BRDF each (docs/instrument.md §1.10): every fit exits 0 and every reading is reproduced within two
//! of its uncertainties. The starts (`fixtures/real/models/`) are near the solutions, so each fit takes a few
//! seconds.
mod common;

use serde_json::Value;

fn fit(args: &[&str]) -> (i32, Value, String) {
    let out = common::glossmeter()
        .arg("fit")
        .args(args)
        .args(["--format", "json", "--no-timing"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run glossmeter");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let doc = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {stderr}"));
    (out.status.code().unwrap_or(-1), doc, stderr)
}

/// Every target within two uncertainties, and as many targets as `want` (the readings the sheet gives that
/// glossmeter predicts).
fn check(doc: &Value, want: usize) {
    let targets = doc["targets"].as_array().unwrap();
    assert_eq!(targets.len(), want, "{doc}");
    for t in targets {
        let (r, u) = (t["residual"].as_f64().unwrap(), t["uncertainty"].as_f64().unwrap());
        assert!(r.abs() <= 2.0 * u, "{}/{}: residual {r} > 2 × {u}", t["geometry"], t["name"]);
    }
    assert_eq!(doc["reproduces"], true, "{doc}");
}

#[test]
fn the_konica_rspec_panels_are_lacquers_with_orange_peel() {
    // Gloss and Rspec only: two readings, two parameters (exactly determined; the fit restarts to look for a
    // second solution). A Beckmann slope distribution under exact Fresnel (n of a lacquer) reproduces both.
    for (sample, start, m_range, n_range) in [
        ("sample-A", "fixtures/real/models/sample-a-beckmann.json", (9e-4, 1.05e-3), (1.47, 1.49)),
        ("sample-B", "fixtures/real/models/sample-b-beckmann.json", (4.5e-3, 5.1e-3), (1.51, 1.53)),
    ] {
        let (code, doc, err) = fit(&[
            start,
            "--sheet",
            "fixtures/real/konica-rspec-panels.csv",
            "--sample",
            sample,
            "--free",
            "/roughness=log:1e-4..0.1",
            "--free",
            "/ior=1.3..1.8",
        ]);
        assert_eq!(code, 0, "{sample}: {err}");
        check(&doc, 2);
        let p = doc["parameters"].as_array().unwrap();
        let m = p[0]["value"].as_f64().unwrap();
        let n = p[1]["value"].as_f64().unwrap();
        assert!(m_range.0 < m && m < m_range.1, "{sample}: m = {m}");
        assert!(n_range.0 < n && n < n_range.1, "{sample}: n = {n}");
    }
}

#[test]
fn the_orange_peel_panel_is_not_reproduced_and_the_85_degree_gloss_is_why() {
    // The full readout (20°, 60°, 85° gloss, haze read as log haze, DOI, Rspec) against the best two-scale
    // lacquer (GGX facet slopes with a Rayleigh–Rice halo at the smooth-surface bound, σ = 22 nm), started at
    // its best fit (docs/instrument.md §1.10). It reproduces 20° gloss and haze within about 2u; with the facet
    // slopes that Rspec and DOI set (~0.1°) and the halo that 20° gloss and haze set, it reads 85° gloss ~98
    // against 94.0 (only a second, steep slope population lowers 85° gloss with 60° gloss near 88: §1.10, and
    // the next test): one slope scale with a halo must say it cannot reproduce the readings (exit 1) and name
    // 85° gloss as the largest residual.
    let (code, doc, err) = fit(&[
        &["fixtures/real/models/panel-two-scale.json"][..],
        &common::PANEL_TARGETS,
        &[
            "--free",
            "/roughness=log:1e-4..0.02",
            "--free",
            "/ior=1.3..1.8",
            "--free",
            "/scatter/correlation_length_um=log:0.3..100",
        ],
    ]
    .concat());
    assert_eq!(code, 1, "{err}");
    assert_eq!(doc["reproduces"], false);
    let targets = doc["targets"].as_array().unwrap();
    let weighted = |t: &Value| (t["residual"].as_f64().unwrap() / t["uncertainty"].as_f64().unwrap()).abs();
    let worst = targets.iter().max_by(|a, b| weighted(a).total_cmp(&weighted(b))).unwrap();
    assert_eq!((worst["geometry"].as_str(), worst["name"].as_str()), (Some("astm-d523-85"), Some("gloss")));
    assert!(worst["residual"].as_f64().unwrap() > 3.0, "{worst}");
    for (g, n) in [("astm-d523-20", "gloss"), ("rhopoint-iq-20", "log-haze")] {
        let t = targets.iter().find(|t| t["geometry"] == g && t["name"] == n).unwrap();
        assert!(weighted(t) < 2.5, "{g}/{n}: {t}");
    }
}

/// The orange-peel panel's whole readout (20°, 60°, 85° gloss, haze read as log haze, DOI, Rspec) by a lacquer of
/// three slope populations under exact Fresnel (`microfacet` with `populations`, docs/optics.md §4.1): a core
/// narrower than the source image (GGX 6.4·10⁻⁴, fixed: the readings barely see its width), orange peel
/// (Beckmann 8·10⁻³, 57 %) and a steep texture (Beckmann 2.8·10⁻², 13 %) that lowers 85° gloss with 60° gloss
/// (docs/instrument.md §1.10). Five free parameters for six readings: the fit must exit 0 with every reading
/// within 2u, and the index must be a lacquer's.
#[test]
fn the_orange_peel_panel_is_a_lacquer_of_three_slope_populations() {
    let (code, doc, err) = fit(&[
        &["fixtures/real/models/panel-three-populations.json"][..],
        &common::PANEL_TARGETS,
        &common::THREE_POPULATION_FREE,
    ]
    .concat());
    assert_eq!(code, 0, "{err}");
    check(&doc, 6);
    let p = doc["parameters"].as_array().unwrap();
    let n = p[0]["value"].as_f64().unwrap();
    assert!(1.50 < n && n < 1.54, "n = {n}");
    let (w1, w2) = (p[2]["value"].as_f64().unwrap(), p[4]["value"].as_f64().unwrap());
    assert!(w1 + w2 < 1.0 && w2 > 0.05, "weights {w1}, {w2}");
}

/// The same five-parameter fit from a neutral start, every free parameter at the middle of its bounds (the
/// geometric mean of `log:` bounds: the solver's variable at its origin, docs/inverse.md §Method,
/// "Variables"), instead of the fixture's values: it reaches the documented solution of docs/instrument.md
/// §1.10 (n = 1.5202 ± 0.0019, m₂ = 8.05·10⁻³ ± 1.9·10⁻⁴, w₂ = 0.568 ± 0.010, m₃ = 2.80·10⁻² ± 1.5·10⁻³,
/// w₃ = 0.132 ± 0.009), each within one of its standard errors, and exits 0.
#[test]
fn the_three_population_fit_reaches_its_solution_from_the_middle_of_its_bounds() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut start: Value = serde_json::from_str(
        &std::fs::read_to_string(root.join("fixtures/real/models/panel-three-populations.json")).unwrap(),
    )
    .unwrap();
    let free: [(&str, f64, f64, bool); 5] = [
        ("/ior", 1.3, 1.8, false),
        ("/populations/1/roughness", 1e-3, 0.05, true),
        ("/populations/1/weight", 0.001, 0.7, false),
        ("/populations/2/roughness", 0.01, 0.5, true),
        ("/populations/2/weight", 0.001, 0.5, false),
    ];
    let mut args: Vec<String> = Vec::new();
    for (pointer, lo, hi, log) in free {
        let mid: f64 = if log { (lo * hi).sqrt() } else { 0.5 * (lo + hi) };
        *start.pointer_mut(pointer).unwrap() = mid.into();
        args.extend(["--free".to_string(), format!("{pointer}={}{lo}..{hi}", if log { "log:" } else { "" })]);
    }
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("real_readouts");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("panel-neutral-start.json");
    std::fs::write(&file, start.to_string()).unwrap();
    let mut all: Vec<&str> = vec![file.to_str().unwrap()];
    all.extend(common::PANEL_TARGETS);
    all.extend(args.iter().map(String::as_str));
    let (code, doc, err) = fit(&all);
    assert_eq!(code, 0, "{err}");
    check(&doc, 6);
    let documented = [(1.5202, 0.0019), (8.05e-3, 1.9e-4), (0.568, 0.010), (2.80e-2, 1.5e-3), (0.132, 0.009)];
    for (p, (value, se)) in doc["parameters"].as_array().unwrap().iter().zip(documented) {
        let v = p["value"].as_f64().unwrap();
        assert!((v - value).abs() <= se, "{}: {v}, documented {value} ± {se}", p["pointer"]);
    }
}

/// The leave-one-out predictions of the three-population lacquer (docs/instrument.md §1.10, the table after
/// "**Leave-one-out predictions.**"): for each core width α₁ the table names (fixed, as the data cannot set it)
/// and each of the six readings held out, the five free parameters of the fit above (the same `--free` bounds)
/// fitted to the other five readings with the command the docs give (`--restarts 0`: five targets for five
/// parameters make each fit exactly determined, and the restarts would only look for a second solution), the
/// fitted recipe written by `-o` and read by `glossmeter measure` on the held-out reading's geometry. The
/// table's exit status, prediction and miss must be the command's. Tolerance 0.005 in the reading's unit: the
/// table's last digit is 0.001; a fit stops when its remaining step is below 0.01 standard uncertainties
/// (0.002 here, docs/inverse.md §Method, "Convergence"), and a prediction at the default rtol is within
/// 10⁻⁴ of its exact value. Cost: the 18 fits take ~2 700 forward runs, 65 s in the test profile on a shared
/// 2-core machine.
#[test]
fn leave_one_out_predictions_are_those_the_docs_state() {
    let docs = std::fs::read_to_string(common::root().join("docs/instrument.md")).unwrap();
    let start = docs.find("**Leave-one-out predictions.**").expect("docs/instrument.md §1.10 has the table");
    let rows: Vec<Vec<String>> = docs[start..]
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .map(|l| l.trim_matches('|').split('|').map(|c| c.trim().trim_matches('`').replace('−', "-")).collect())
        .collect();
    assert_eq!(rows.len(), 3 * 6, "three core widths, six readings held out each: {rows:?}");
    let targets: Vec<&str> = common::PANEL_TARGETS.iter().copied().filter(|a| *a != "--target").collect();
    let fixture: Value = serde_json::from_str(
        &std::fs::read_to_string(common::fixture_path("real/models/panel-three-populations.json")).unwrap(),
    )
    .unwrap();
    let dir = common::fresh_dir("leave-one-out");
    for (k, row) in rows.iter().enumerate() {
        let [alpha, held, measured, predicted, miss, exit, chi2] = &row[..] else { panic!("row {row:?}") };
        let alpha: f64 = alpha.parse().unwrap_or_else(|e| panic!("α₁ {alpha:?}: {e}"));
        let mut recipe = fixture.clone();
        recipe["populations"][0]["roughness"] = alpha.into();
        let start = dir.join(format!("start-{k}.json"));
        std::fs::write(&start, recipe.to_string()).unwrap();
        let fitted = dir.join(format!("fitted-{k}.json"));
        let (geometry, name) = held.split_once('/').unwrap();
        let mut args = vec!["fit", start.to_str().unwrap()];
        for &t in targets.iter().filter(|t| !t.starts_with(&format!("{held}="))) {
            args.extend(["--target", t]);
        }
        assert_eq!(args.len(), 2 + 2 * 5, "{held} is one of the six readings");
        args.extend(common::THREE_POPULATION_FREE);
        args.extend(["--restarts", "0", "--format", "json", "--no-timing", "-o", fitted.to_str().unwrap()]);
        let (code, report, err) = common::gm(&args);
        assert_eq!(code.to_string(), *exit, "α₁ {alpha}, {held} held out: {err}");
        let report: Value = serde_json::from_str(&report).unwrap();
        let want = |s: &str| -> f64 { s.parse().unwrap_or_else(|e| panic!("{s:?}: {e}")) };
        let fitted_chi2 = report["chi2"].as_f64().unwrap();
        assert!((fitted_chi2 - want(chi2)).abs() <= 0.01, "α₁ {alpha}, {held}: χ² {fitted_chi2}, docs {chi2}");
        let (code, out, err) = common::gm(&["measure", fitted.to_str().unwrap(), "-g", geometry, "--format", "json"]);
        assert_eq!(code, 0, "{err}");
        let doc: Value = serde_json::from_str(&out).unwrap();
        let reading = doc["readings"].as_array().unwrap().iter().find(|r| r["name"] == name).unwrap();
        let value = reading["value"].as_f64().unwrap();
        let m = want(measured);
        let target = targets.iter().find(|t| t.starts_with(&format!("{held}="))).unwrap();
        assert_eq!(m, want(target.split_once('=').unwrap().1), "{held}: the docs' measured value is the readout's");
        assert!((value - want(predicted)).abs() <= 0.005, "α₁ {alpha}, {held}: predicted {value}, docs {predicted}");
        assert!((value - m - want(miss)).abs() <= 0.005, "α₁ {alpha}, {held}: miss {}, docs {miss}", value - m);
    }
}
