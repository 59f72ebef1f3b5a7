//! Published readouts of real panels (`fixtures/real/`), reproduced by `glossmeter fit` with one physically
//! plausible BRDF each (docs/instrument.md §1.10): every fit exits 0 and every reading is reproduced within two
//! of its uncertainties. The starts (`fixtures/real/models/`) are near the solutions, so each fit takes a few
//! seconds.
use std::process::Command;

use serde_json::Value;

fn fit(args: &[&str]) -> (i32, Value, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_glossmeter"))
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
