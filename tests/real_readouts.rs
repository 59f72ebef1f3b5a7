//! Published readouts of real panels (`fixtures/real/`), reproduced by `glossmeter fit` with one physically
//! plausible BRDF each (docs/instrument.md §1.10): every fit exits 0 and every reading is reproduced within two
//! of its uncertainties. The starts (`fixtures/real/models/`) are near the solutions, so each fit takes a few
//! seconds.
mod common;

use serde_json::Value;

/// The orange-peel panel's readout as printed (`fixtures/real/konica-orange-peel-panel.csv`), its haze read as
/// log haze (docs/instrument.md §1.10).
const PANEL_TARGETS: [&str; 12] = [
    "--target",
    "astm-d523-20/gloss=66.3",
    "--target",
    "astm-d523-60/gloss=88.3",
    "--target",
    "astm-d523-85/gloss=94.0",
    "--target",
    "rhopoint-iq-20/log-haze=14.2",
    "--target",
    "rhopoint-iq-20/doi=77.5",
    "--target",
    "rhopoint-iq-20/rspec=26.1",
];

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
        &PANEL_TARGETS,
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
        &PANEL_TARGETS,
        &[
            "--free",
            "/ior=1.3..1.8",
            "--free",
            "/populations/1/roughness=log:1e-3..0.05",
            "--free",
            "/populations/1/weight=0.001..0.7",
            "--free",
            "/populations/2/roughness=log:0.01..0.5",
            "--free",
            "/populations/2/weight=0.001..0.5",
        ],
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
    all.extend(PANEL_TARGETS);
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
