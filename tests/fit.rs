//! `glossmeter fit` (`docs/inverse.md`): round trips (forward at known parameters → fit from a perturbed start →
//! the known parameters within 3 standard errors), a Monte Carlo check that the standard errors match the
//! spread of fits over noisy targets, degenerate cases reported as not identifiable, bounds that hold, and
//! every bad input refused with exit status 2.
use glossmeter::fit::{fit, FitOptions, FitReport, FreeParameter, TargetReading};
use glossmeter::{measure, recipe, resolve_geometries, PlanOptions};
use serde_json::{json, Value};
use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Exact (rtol 1e-10) readings of `recipe` for (geometry, reading) pairs.
fn readings(recipe: &Value, wanted: &[(&str, &str)]) -> Vec<f64> {
    let m = recipe::parse_str(&recipe.to_string(), "truth.json").unwrap();
    let mut ids: Vec<&str> = wanted.iter().map(|w| w.0).collect();
    ids.dedup();
    let geos = resolve_geometries(&ids, &[] as &[&str]).unwrap();
    let r = measure(&m, &geos, &PlanOptions { rtol: 1e-10, ..PlanOptions::default() }).unwrap();
    wanted.iter().map(|(g, n)| r.iter().find(|x| x.geometry == *g && x.name == *n).unwrap().value.unwrap()).collect()
}

fn targets(wanted: &[(&str, &str)], values: &[f64], u: f64) -> Vec<TargetReading> {
    wanted
        .iter()
        .zip(values)
        .map(|((g, n), v)| TargetReading {
            geometry: g.to_string(),
            name: n.to_string(),
            value: *v,
            uncertainty: Some(u),
        })
        .collect()
}

fn free(s: &str) -> FreeParameter {
    FreeParameter::parse(s).unwrap()
}

fn run(start: &Value, free_: &[FreeParameter], t: &[TargetReading], rtol: f64) -> FitReport {
    fit(start, "start.json", free_, t, &FitOptions { rtol, ..FitOptions::default() }).unwrap()
}

fn within_3_se(r: &FitReport, truth: &[f64]) {
    for (p, t) in r.parameters.iter().zip(truth) {
        let se = p.std_error.unwrap_or_else(|| panic!("{}: no standard error", p.pointer));
        assert!((p.value - t).abs() <= 3.0 * se, "{}: fitted {} ± {se}, true {t}", p.pointer, p.value);
    }
}

fn glass(distribution: &str, roughness: f64, ior: f64) -> Value {
    json!({"model": "microfacet", "distribution": distribution, "roughness": roughness, "ior": ior})
}

const G60: &[(&str, &str)] = &[("astm-d523-60", "gloss")];

#[test]
fn one_roughness_from_one_gloss() {
    let truth = glass("beckmann", 0.05, 1.5);
    let v = readings(&truth, G60);
    let r = run(&glass("beckmann", 0.12, 1.5), &[free("/roughness=log:1e-3..0.5")], &targets(G60, &v, 0.2), 1e-8);
    assert!(r.ok(), "{r:#?}");
    within_3_se(&r, &[0.05]);
    // Exact targets: the fit recovers the truth far better than the error bar.
    assert!((r.parameters[0].value - 0.05).abs() < 1e-4, "{}", r.parameters[0].value);
    assert!(r.targets[0].weighted_residual.abs() < 1e-3);
    assert_eq!(r.recipe["roughness"].as_f64(), Some(r.parameters[0].value));
    // The solver's runs; then the linearity check's (one standard error each way along the one direction) and
    // the restarts' of this exactly determined fit, all counted in `evaluations`.
    assert!(r.evaluations - r.linearity_evaluations - r.restart_evaluations < 80, "{} forward runs", r.evaluations);
    assert_eq!(r.linearity_evaluations, 2, "{r:#?}");
    assert!(r.restart_evaluations > 0, "{r:#?}");
    // One target for one parameter: the verdict says so, and the restarts (gloss falls monotonically with the
    // roughness, so there is one solution) all return to it.
    let line = r.verdict.iter().find(|v| v.contains("exactly determined")).expect("an m = n verdict line");
    assert!(line.contains("2 restart(s)") && line.contains("2 returned to this solution"), "{line}");
    // Without restarts the verdict says uniqueness is not checked, and nothing else changes.
    let r0 = fit(
        &glass("beckmann", 0.12, 1.5),
        "start.json",
        &[free("/roughness=log:1e-3..0.5")],
        &targets(G60, &v, 0.2),
        &FitOptions { rtol: 1e-8, restarts: 0, ..FitOptions::default() },
    )
    .unwrap();
    assert_eq!(r0.restart_evaluations, 0);
    assert!(r0.verdict.iter().any(|v| v.contains("exactly determined") && v.contains("not checked")), "{r0:#?}");
    assert_eq!(r0.parameters[0].value.to_bits(), r.parameters[0].value.to_bits());
    assert_eq!(r0.evaluations, r.evaluations - r.restart_evaluations);
}

/// Restart points are deterministic Halton points inside the bounds.
#[test]
fn restart_points_are_halton() {
    assert_eq!(glossmeter::fit::restart_fractions(1, 3), vec![0.5, 1.0 / 3.0, 0.2]);
    assert_eq!(glossmeter::fit::restart_fractions(2, 2), vec![0.25, 2.0 / 3.0]);
    for k in 1..20 {
        assert!(glossmeter::fit::restart_fractions(k, 5).iter().all(|f| *f > 0.0 && *f < 1.0));
    }
}

/// A small deterministic normal generator (xorshift64* + Box–Muller), so the test needs no extra crate.
struct Normal(u64);
impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545F4914F6CDD1D) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn sample(&mut self) -> f64 {
        let (a, b) = (self.uniform(), self.uniform());
        (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
    }
}

/// The standard errors agree with the spread of the fitted values over noisy targets. With N = 24 fits the
/// sample standard deviation has a relative spread of ≈ 1/√(2N) ≈ 14 %, so its ratio to the standard error
/// from the targets' uncertainties (which is what noise of exactly those uncertainties spreads by) must lie
/// in [0.6, 1.5] (about ±3 of those spreads; few draws and a loose band keep the test to seconds). The
/// reported standard error, scaled by the residuals only when they exceed the uncertainties, is never
/// below it.
#[test]
fn standard_errors_match_a_monte_carlo_over_the_noise() {
    let truth = glass("ggx", 0.08, 1.5);
    let wanted = &[("astm-d523-20", "gloss"), ("astm-d523-60", "gloss")];
    let exact = readings(&truth, wanted);
    let u = 2.0;
    let mut rng = Normal(0x9E3779B97F4A7C15);
    let (mut fitted, mut unscaled) = (Vec::new(), Vec::new());
    for _ in 0..24 {
        let noisy: Vec<f64> = exact.iter().map(|v| v + u * rng.sample()).collect();
        let r = run(&glass("ggx", 0.1, 1.5), &[free("/roughness=log:1e-3..0.5")], &targets(wanted, &noisy, u), 1e-7);
        assert!(r.converged && r.identifiable, "{r:#?}");
        let p = &r.parameters[0];
        assert!(p.std_error.unwrap() >= p.std_error_unscaled.unwrap(), "{p:?}");
        fitted.push(p.value);
        unscaled.push(p.std_error_unscaled.unwrap());
    }
    let n = fitted.len() as f64;
    let mean = fitted.iter().sum::<f64>() / n;
    let sd = (fitted.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let rms = (unscaled.iter().map(|s| s * s).sum::<f64>() / n).sqrt();
    let ratio = sd / rms;
    assert!((0.6..=1.5).contains(&ratio), "MC sd {sd} vs standard error {rms}: ratio {ratio}");
    assert!((mean - 0.08).abs() < 3.0 * sd / n.sqrt() + 1e-4, "bias: mean {mean}");
}

const D523: &[(&str, &str)] = &[("astm-d523-20", "gloss"), ("astm-d523-60", "gloss"), ("astm-d523-85", "gloss")];

#[test]
fn roughness_and_index_from_20_60_85() {
    let truth = glass("ggx", 0.1, 1.5);
    let v = readings(&truth, D523);
    let r = run(
        &glass("ggx", 0.16, 1.62),
        &[free("/roughness=log:1e-3..0.5"), free("/ior=1.3..2.0")],
        &targets(D523, &v, 0.2),
        1e-8,
    );
    assert!(r.ok(), "{r:#?}");
    within_3_se(&r, &[0.1, 1.5]);
    assert!((r.parameters[0].value - 0.1).abs() < 1e-3 && (r.parameters[1].value - 1.5).abs() < 1e-3, "{r:#?}");
    assert_eq!(r.singular_values.len(), 2);
    assert!(r.correlation[0][1].is_some_and(|c| c.abs() < 1.0));
}

fn cerulean(name: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(root().join(format!("fixtures/recipes/{name}.json"))).unwrap())
        .unwrap()
}

#[test]
fn coat_roughness_and_flake_spread_from_gloss_haze_and_doi() {
    let mut truth = cerulean("cerulean-blue-b");
    truth["clear_coat"]["roughness"] = json!(0.03);
    truth["metallic_flakes"]["spread_slope"] = json!(0.2);
    let wanted = &[
        ("astm-d523-20", "gloss"),
        ("astm-d523-60", "gloss"),
        ("astm-d523-85", "gloss"),
        ("astm-e430-30", "haze-narrow"),
        ("astm-e430-30", "haze-wide"),
        ("astm-e430-30", "doi"),
    ];
    let v = readings(&truth, wanted);
    let mut start = truth.clone();
    start["clear_coat"]["roughness"] = json!(0.045);
    start["metallic_flakes"]["spread_slope"] = json!(0.15);
    let r = run(
        &start,
        &[free("/clear_coat/roughness=log:1e-3..0.5"), free("/metallic_flakes/spread_slope=log:1e-3..1")],
        &targets(wanted, &v, 0.2),
        1e-7,
    );
    assert!(r.ok(), "{r:#?}");
    within_3_se(&r, &[0.03, 0.2]);
}

#[test]
fn a_parameter_no_target_sees_is_not_identifiable() {
    let mut start = cerulean("cerulean-blue-a");
    start["clear_coat"]["thickness_um"] = json!(40.0);
    let v = readings(&cerulean("cerulean-blue-a"), D523);
    let r = run(
        &start,
        &[free("/clear_coat/index=1.3..1.8"), free("/clear_coat/thickness_um=1..100")],
        &targets(D523, &v, 0.2),
        1e-7,
    );
    assert!(!r.identifiable && !r.ok(), "{r:#?}");
    assert!(r.parameters[1].std_error.is_none(), "{:?}", r.parameters[1]);
    assert!(r.verdict.iter().any(|v| v.contains("/clear_coat/thickness_um is not determined")), "{:?}", r.verdict);
    assert!(r.parameters[0].std_error.is_some(), "the index is still determined");
}

/// Concentration and layer thickness enter Kubelka–Munk only as the product C·X (K = C·k, S = C·s, and KM
/// depends on K·X and S·X): no set of readings can tell them apart.
#[test]
fn two_parameters_that_enter_as_a_product_are_not_identifiable() {
    let start = cerulean("cerulean-blue-a");
    let wanted = &[
        ("astm-d523-20", "gloss"),
        ("astm-d523-60", "gloss"),
        ("astm-e430-30", "haze-narrow"),
        ("astm-e430-30", "haze-wide"),
    ];
    let mut truth = start.clone();
    truth["pigmented_layer"]["thickness_mm"] = json!(0.1);
    let v = readings(&truth, wanted);
    let r = run(
        &start,
        &[
            free("/pigmented_layer/thickness_mm=log:0.01..1"),
            free("/pigmented_layer/pigments/0/concentration=log:0.05..4"),
        ],
        &targets(wanted, &v, 0.002),
        1e-7,
    );
    assert!(!r.identifiable, "{r:#?}");
    assert!(
        r.verdict.iter().any(|v| v.contains("cannot tell apart")
            && v.contains("/pigmented_layer/thickness_mm")
            && v.contains("/pigmented_layer/pigments/0/concentration")),
        "{:?}",
        r.verdict
    );
}

#[test]
fn bounds_hold() {
    let truth = glass("beckmann", 0.05, 1.5);
    let v = readings(&truth, G60);
    let r = run(&glass("beckmann", 0.02, 1.5), &[free("/roughness=log:1e-3..0.03")], &targets(G60, &v, 0.2), 1e-8);
    let p = &r.parameters[0];
    assert!(p.value <= 0.03 && p.value >= 1e-3, "{p:?}");
    assert!(p.at_bound && !r.ok(), "{r:#?}");
    assert!(r.verdict.iter().any(|v| v.contains("at a bound")), "{:?}", r.verdict);
}

// ---------------------------------------------------------------------------------------------------------
// The command line
// ---------------------------------------------------------------------------------------------------------

fn glossmeter(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_glossmeter")).args(args).current_dir(root()).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("glossmeter-fit-test-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

#[test]
fn cli_fits_writes_json_and_never_overwrites() {
    let recipe = tmp("rough.json");
    std::fs::write(&recipe, glass("ggx", 0.1, 1.5).to_string()).unwrap();
    let out = tmp("fitted.json");
    let _ = std::fs::remove_file(&out);
    let (code, stdout, stderr) = glossmeter(&[
        "fit",
        recipe.to_str().unwrap(),
        "--free",
        "/roughness=log:1e-3..0.5",
        "--target",
        "astm-d523-60/gloss=60±0.2",
        "--format",
        "json",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    let v: Value = serde_json::from_str(&stdout).unwrap();
    // The contract of `docs/inverse.md` §Output, exactly (plus `verdict`, the identifiability in words).
    let keys = |v: &Value| -> Vec<String> {
        let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
        k.sort();
        k
    };
    let sorted = |k: &[&str]| -> Vec<String> {
        let mut k: Vec<String> = k.iter().map(|s| s.to_string()).collect();
        k.sort();
        k
    };
    assert_eq!(
        keys(&v),
        sorted(&[
            "parameters",
            "targets",
            "converged",
            "identifiable",
            "singular_values",
            "correlation",
            "verdict",
            "evaluations",
            "seconds",
            "recipe"
        ])
    );
    assert_eq!(keys(&v["parameters"][0]), sorted(&["path", "value", "std_error", "lower", "upper", "at_bound"]));
    assert_eq!(
        keys(&v["targets"][0]),
        sorted(&["geometry", "name", "measured", "uncertainty", "predicted", "residual"])
    );
    assert!((v["targets"][0]["predicted"].as_f64().unwrap() - 60.0).abs() < 0.01);
    let fitted: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(fitted["roughness"], v["parameters"][0]["value"]);
    // The same -o again: refused, file untouched.
    let before = std::fs::read(&out).unwrap();
    let (code, _, stderr) = glossmeter(&[
        "fit",
        recipe.to_str().unwrap(),
        "--free",
        "/roughness=log:1e-3..0.5",
        "--target",
        "astm-d523-60/gloss=50",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("never overwrites"), "{stderr}");
    assert_eq!(std::fs::read(&out).unwrap(), before);
    // A sheet in the long layout, one sample chosen.
    let sheet = tmp("sheet.csv");
    std::fs::write(
        &sheet,
        "sample,geometry,quantity,value,uncertainty\na,astm-d523-60,gloss,60,0.2\nb,astm-d523-60,gloss,40,0.2\n",
    )
    .unwrap();
    let (code, stdout, stderr) = glossmeter(&[
        "fit",
        recipe.to_str().unwrap(),
        "--free",
        "/roughness=log:1e-3..0.5",
        "--sheet",
        sheet.to_str().unwrap(),
        "--sample",
        "b",
    ]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(stdout.contains("identifiable: yes"), "{stdout}");
    let (code, _, stderr) = glossmeter(&[
        "fit",
        recipe.to_str().unwrap(),
        "--free",
        "/roughness=log:1e-3..0.5",
        "--sheet",
        sheet.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("--sample"), "{stderr}");
    // Not identifiable → exit 1 (the report is still printed).
    let (code, stdout, _) = glossmeter(&[
        "fit",
        recipe.to_str().unwrap(),
        "--free",
        "/roughness=log:1e-3..0.5",
        "--free",
        "/ior=1.3..2",
        "--target",
        "astm-d523-60/gloss=60",
        "--target",
        "iso-2813-60/gloss=60",
    ]);
    assert_eq!(code, 1, "{stdout}");
    assert!(stdout.contains("identifiable: NO"), "{stdout}");
}

#[test]
fn bad_input_is_refused_with_exit_2_naming_the_argument() {
    let recipe = tmp("bad-args.json");
    std::fs::write(&recipe, glass("ggx", 0.1, 1.5).to_string()).unwrap();
    let r = recipe.to_str().unwrap();
    let t = "astm-d523-60/gloss=60";
    let cases: &[(&[&str], &str)] = &[
        (&["fit", r, "--free", "/roughnes=0..1", "--target", t], "--free /roughnes"),
        (&["fit", r, "--free", "/distribution=0..1", "--target", t], "--free /distribution"),
        (&["fit", r, "--free", "/ior/0=1..2", "--target", t], "--free /ior/0"),
        (&["fit", r, "--free", "/roughness=0.5..0.1", "--target", t], "LO < HI"),
        (&["fit", r, "--free", "/roughness=0.2..0.2", "--target", t], "LO < HI"),
        (&["fit", r, "--free", "/roughness=0.2..0.5", "--target", t], "outside the bounds"),
        (&["fit", r, "--free", "/roughness=log:0..0.5", "--target", t], "positive"),
        (&["fit", r, "--free", "/roughness=0..20", "--target", t], "allowed range"),
        (&["fit", r, "--free", "roughness=0..1", "--target", t], "JSON Pointer"),
        (&["fit", r, "--free", "/roughness=a..1", "--target", t], "not a finite number"),
        (&["fit", r, "--free", "/roughness=0..1", "--target", "astm-d523-60/haze=1"], "no reading \"haze\""),
        (&["fit", r, "--free", "/roughness=0..1", "--target", "astm-d523-61/gloss=1"], "astm-d523-61"),
        (&["fit", r, "--free", "/roughness=0..1", "--target", "astm-d523-60/gloss=x"], "--target"),
        (&["fit", r, "--free", "/roughness=0..1", "--target", "astm-d523-60/gloss=60±-1"], "uncertainty"),
        (&["fit", r, "--free", "/roughness=0..1"], "no targets"),
        (&["fit", r, "--free", "/roughness=0..1", "--free", "/ior=1..2", "--target", t], "at least as many targets"),
        (&["fit", r, "--free", "/roughness=0..1", "--target", t, "--rtol", "0"], "--rtol"),
        (&["fit", "fixtures/recipes/none.json", "--free", "/roughness=0..1", "--target", t], "none.json"),
    ];
    for (args, needle) in cases {
        let (code, stdout, stderr) = glossmeter(args);
        assert_eq!(code, 2, "{args:?}: {stdout}{stderr}");
        assert!(stderr.contains(needle), "{args:?}: stderr lacks {needle:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}

/// A sheet's repeated readings become one target: the mean, with √(u² + s²/n) as its uncertainty (u the
/// stated uncertainty, s/√n the standard error of the mean); a single reading without an uncertainty gets
/// the fit's default (None); a sheet of two samples needs --sample.
#[test]
fn sheet_rows_become_targets() {
    use glossmeter::comparison::sheet::{parse, SheetOptions};
    use glossmeter::fit::targets_from_sheet;
    let text = "sample,geometry,quantity,value,uncertainty\n\
                a,astm-d523-60,gloss,60,0.3\na,astm-d523-60,gloss,61,0.3\na,astm-d523-60,gloss,62,0.3\n\
                a,astm-d523-20,gloss,30,\nb,astm-d523-60,gloss,40,0.2\n";
    let sheet = parse(text, "s.csv", &SheetOptions::default()).unwrap();
    let (t, notes) = targets_from_sheet(&sheet, Some("a")).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    assert_eq!(t.len(), 2);
    assert_eq!((t[0].geometry.as_str(), t[0].name.as_str()), ("astm-d523-60", "gloss"));
    assert!((t[0].value - 61.0).abs() < 1e-12);
    // s = 1, n = 3: √(0.09 + 1/3).
    assert!((t[0].uncertainty.unwrap() - (0.09f64 + 1.0 / 3.0).sqrt()).abs() < 1e-12, "{:?}", t[0]);
    assert_eq!(t[1].uncertainty, None);
    let e = targets_from_sheet(&sheet, None).unwrap_err().to_string();
    // The library names the argument in its own words; the command line writes `--sample`.
    assert!(e.contains("`sample`") && e.contains("a, b"), "{e}");
    let e = targets_from_sheet(&sheet, Some("c")).unwrap_err().to_string();
    assert!(e.contains("`sample` c"), "{e}");
}

#[test]
fn cli_target_errors_escape_the_users_text_and_exit_2() {
    // A quote and a newline in a --target must come back escaped (one line per error, nothing the user typed
    // able to end or fake a line of the message), with exit status 2.
    let recipe = tmp("escape.json");
    std::fs::write(&recipe, glass("ggx", 0.1, 1.5).to_string()).unwrap();
    let fit = |target: &str| {
        glossmeter(&["fit", recipe.to_str().unwrap(), "--free", "/roughness=log:1e-3..0.5", "--target", target])
    };
    for (target, want) in [
        ("astm-d523-60/gl\"o\nss=60±0.2", r#"has no reading "gl\"o\nss""#),
        ("no\"such\n/gloss=60±0.2", r#"unknown geometry id "no\"such\n""#),
    ] {
        let (code, stdout, stderr) = fit(target);
        assert_eq!(code, 2, "{target:?}: {stdout}{stderr}");
        assert!(stderr.contains(want), "{target:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{target:?}: the message spans lines: {stderr}");
    }
}
