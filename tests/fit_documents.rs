//! The fit's output documents, byte for byte: a few `glossmeter fit … --format json --no-timing` runs whose
//! whole JSON document is stored under `tests/fit_documents/` and compared as bytes, so that a change of the
//! fit's shape (docs/architecture.md, the fit's stages) that moves any number, count or word of its report
//! fails here. The cases cover each stage: the scan of the bounds and its restarts (two roots, a plateau), the
//! linearity check and correlations (the orange-peel panel's five-parameter fit), the reach of a target
//! beyond the model (a stationary point, a constraint), and the classification of what the targets cannot
//! determine.
//!
//! A change that is meant to move a document re-blesses it: `GLOSSMETER_BLESS_FIT=1 cargo test --test
//! fit_documents`, then review the diff of `tests/fit_documents/` like any other change of results.
mod common;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Run `glossmeter fit ARGS --format json --no-timing` on `threads` rayon threads (the machine's default for
/// `None`); the exit code and stdout.
fn fit(args: &[&str], threads: Option<usize>) -> (i32, String, String) {
    let mut command = common::glossmeter();
    if let Some(t) = threads {
        command.env("RAYON_NUM_THREADS", t.to_string());
    }
    let out = command
        .arg("fit")
        .args(args)
        .args(["--format", "json", "--no-timing"])
        .current_dir(root())
        .output()
        .expect("run glossmeter");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).expect("UTF-8 stdout"),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A recipe written for one case (a shipped fixture with one value changed) under the target dir.
fn recipe_with(fixture: &str, pointer: &str, value: serde_json::Value, name: &str) -> String {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root().join(fixture)).unwrap()).unwrap();
    *v.pointer_mut(pointer).unwrap() = value;
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fit_documents");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, v.to_string()).unwrap();
    path.to_str().unwrap().to_string()
}

fn check(name: &str, want_exit: i32, args: &[&str]) {
    check_on(name, want_exit, args, None);
}

/// The document of a run on `threads` threads.
fn check_on(name: &str, want_exit: i32, args: &[&str], threads: Option<usize>) {
    let (code, stdout, stderr) = fit(args, threads);
    assert_eq!(code, want_exit, "{name}: {stdout}{stderr}");
    let file = root().join("tests/fit_documents").join(format!("{name}.json"));
    if std::env::var_os("GLOSSMETER_BLESS_FIT").is_some() {
        std::fs::write(&file, &stdout).unwrap();
        return;
    }
    let want = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    if stdout != want {
        let line = stdout.lines().zip(want.lines()).position(|(a, b)| a != b).unwrap_or(0);
        panic!(
            "{name} ({threads:?} threads): the document differs from {} at line {}:\n now: {}\n was: {}",
            file.display(),
            line + 1,
            stdout.lines().nth(line).unwrap_or(""),
            want.lines().nth(line).unwrap_or("")
        );
    }
}

/// Two parameters, two readings (exactly determined): the scan of the bounds seeds the restarts.
#[test]
fn sample_a_two_parameters_scan_and_restarts() {
    for threads in [Some(1), Some(2), Some(3)] {
        sample_a(threads);
    }
}

/// The scan's points, the restarts and a Jacobian's displaced points run in parallel (docs/inverse.md
/// §Method, "Parallel runs"): the same document, byte for byte, on one, two and three threads.
fn sample_a(threads: Option<usize>) {
    check_on(
        "sample-a",
        0,
        &[
            "fixtures/real/models/sample-a-beckmann.json",
            "--sheet",
            "fixtures/real/konica-rspec-panels.csv",
            "--sample",
            "sample-A",
            "--free",
            "/roughness=log:1e-4..0.1",
            "--free",
            "/ior=1.3..1.8",
        ],
        threads,
    );
}

/// Five parameters, six readings: the linearity check, the correlations, no scan.
#[test]
fn orange_peel_panel_five_parameters() {
    for threads in [Some(1), Some(2)] {
        panel(threads);
    }
}

fn panel(threads: Option<usize>) {
    let args = [
        &["fixtures/real/models/panel-three-populations.json"][..],
        &common::PANEL_TARGETS,
        &common::THREE_POPULATION_FREE,
    ]
    .concat();
    check_on("panel-three-populations", 0, &args, threads);
}

/// A target beyond a constraint (Kd + Σ Ks ≤ 1): refused trial points, the reach line.
#[test]
fn constraint_and_reach() {
    check(
        "cook-torrance-2000",
        1,
        &[
            "fixtures/recipes/cook-torrance-lobes.json",
            "--free",
            "/lobes/1/ks=0.01..0.9",
            "--target",
            "astm-d523-60/gloss=2000±0.2",
            "--rtol",
            "1e-5",
        ],
    );
}

/// ISO 13803 haze beyond its maximum over the roughness: a stationary point; and E430 haze-narrow with two
/// roots (a second solution).
#[test]
fn stationary_and_two_roots() {
    for (name, target) in [
        ("beckmann-haze-8", "iso-13803-20/haze=8±0.05"),
        ("beckmann-haze-narrow-two-roots", "astm-e430-30/haze-narrow=0.6±0.02"),
    ] {
        check(
            name,
            1,
            &[
                "fixtures/recipes/rough-dielectric-beckmann.json",
                "--free",
                "/roughness=log:0.001..0.5",
                "--target",
                target,
                "--rtol",
                "1e-5",
            ],
        );
    }
}

/// A parameter no target sees (a non-absorbing coat's thickness), and two that enter as a product
/// (Kubelka–Munk's C·X): the undetermined lines of the verdict.
#[test]
fn undetermined_parameters() {
    let thick =
        recipe_with("fixtures/recipes/cerulean-blue-a.json", "/clear_coat/thickness_um", 40.0.into(), "a40.json");
    check(
        "cerulean-thickness-unseen",
        1,
        &[
            &thick,
            "--free",
            "/clear_coat/index=1.3..1.8",
            "--free",
            "/clear_coat/thickness_um=1..100",
            "--target",
            "astm-d523-20/gloss=30",
            "--target",
            "astm-d523-60/gloss=60",
            "--target",
            "astm-d523-85/gloss=90",
            "--rtol",
            "1e-6",
        ],
    );
    check(
        "cerulean-product",
        1,
        &[
            "fixtures/recipes/cerulean-blue-a.json",
            "--free",
            "/pigmented_layer/thickness_mm=log:0.01..1",
            "--free",
            "/pigmented_layer/pigments/0/concentration=log:0.05..4",
            "--target",
            "astm-d523-20/gloss=20±0.002",
            "--target",
            "astm-d523-60/gloss=60±0.002",
            "--target",
            "astm-e430-30/haze-narrow=1±0.002",
            "--target",
            "astm-e430-30/haze-wide=2±0.002",
            "--rtol",
            "1e-6",
        ],
    );
}
