//! Tolerances per reading at the command line (docs/instrument.md §Repeated readings and the verdict): the most
//! specific `--tolerance KEY=NUMBER` decides each row, the JSON says which, and a key that names no reading of the
//! sheet is refused.
#![cfg(feature = "cli")]
mod common;

use serde_json::Value;

/// Run `compare` on black glass against the n = 1.50 tri-gloss sheet (three single readings: 20°, 60°, 85°).
fn compare(extra: &[&str]) -> (i32, Value, String) {
    let out = common::glossmeter()
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["compare", "fixtures/recipes/black-glass.json", "fixtures/sheets/glass-n1.5-trigloss.csv"])
        .args(["--format", "json"])
        .args(extra)
        .output()
        .expect("run glossmeter");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    let doc = serde_json::from_slice(&out.stdout).unwrap_or(Value::Null);
    (out.status.code().unwrap_or(-1), doc, err)
}

fn by_geometry<'a>(doc: &'a Value, geometry: &str) -> &'a Value {
    doc["comparisons"].as_array().unwrap().iter().find(|c| c["geometry"] == geometry).unwrap()
}

#[test]
fn each_row_takes_its_most_specific_tolerance() {
    // The differences, from a run with a tolerance that lets every row through.
    let (code, wide, err) = compare(&["--tolerance", "1000"]);
    assert_eq!(code, 0, "{err}");
    let diff = |g: &str| {
        let c = by_geometry(&wide, g);
        (c["predicted"].as_f64().unwrap() - c["mean"].as_f64().unwrap()).abs()
    };
    let (d20, d60) = (diff("astm-d523-20"), diff("astm-d523-60"));
    assert!(d20 > 0.5 && d60 > 0.5, "black glass reads below n = 1.50 glass: {d20} {d60}");
    // gloss= covers all three; the 60° key narrows one row to below its difference: only that row is outside.
    let g = format!("gloss={}", 2.0 * d20.max(d60).max(diff("astm-d523-85")));
    let narrow = format!("astm-d523-60/gloss={}", 0.5 * d60);
    let (code, doc, err) = compare(&["--tolerance", &g, "--tolerance", &narrow]);
    assert_eq!(code, 1, "{err}");
    for (geometry, verdict) in [("astm-d523-20", "ok"), ("astm-d523-60", "OUTSIDE"), ("astm-d523-85", "ok")] {
        let c = by_geometry(&doc, geometry);
        assert_eq!(c["verdict"], verdict, "{c}");
    }
    let stated = by_geometry(&doc, "astm-d523-60")["allowance"]["stated"].as_f64().unwrap();
    assert_eq!(stated, 0.5 * d60);
    assert_eq!(doc["rule"]["tolerance"], Value::Null);
    assert_eq!(doc["rule"]["tolerances"]["astm-d523-60/gloss"].as_f64(), Some(0.5 * d60));
}

#[test]
fn a_key_that_names_no_reading_of_the_sheet_is_refused() {
    let (code, _, err) = compare(&["--tolerance", "doi=3"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--tolerance") && err.contains("doi=3") && err.contains("names no reading"), "{err}");
    assert!(err.contains("astm-d523-60/gloss"), "the readings there are: {err}");
    let (code, _, err) = compare(&["--tolerance", "gloss=x"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("not a number"), "{err}");
}
