//! Instrument sheets end to end (`docs/instrument.md` §Sheets): every shipped dialect under fixtures/sheets/, repeated
//! readings and their statistics, many samples with their own recipes, JUnit XML (parsed back), baselines, and every
//! malformed sheet (exit 2 with the file, the line and the column).
mod common;
use common::{fresh, gm};

use serde_json::Value;

const GLASS: &str = "fixtures/recipes/glass-n1.5.json";

/// Run the binary; (exit status, stdout, stderr).
fn json_of(args: &[&str]) -> (i32, Value) {
    let mut a = args.to_vec();
    a.extend(["--format", "json"]);
    let (code, out, err) = gm(&a);
    (code, serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out} {err}")))
}

#[test]
fn every_dialect_reads_the_same_panel() {
    // The BYK sheet in four encodings/dialects: `;` + decimal commas + CRLF (UTF-8 and Windows-1252).
    for (f, enc) in [
        ("fixtures/sheets/byk-semicolon-decimal-comma.csv", "UTF-8"),
        ("fixtures/sheets/byk-windows-1252.csv", "windows-1252"),
    ] {
        let (code, doc) = json_of(&["compare", GLASS, f]);
        assert_eq!(code, 0, "{f}");
        assert_eq!(doc["sheet"]["encoding"], enc);
        assert_eq!(doc["sheet"]["delimiter"], ";");
        assert_eq!(doc["sheet"]["metadata"]["instrument"], "BYK micro-TRI-gloss");
        assert_eq!(doc["sheet"]["metadata"]["batch"], "2026-12-01 A");
        let c = &doc["comparisons"][0];
        assert_eq!(c["sample"], "glass; n = 1,50");
        assert_eq!(c["geometry"], "astm-d523-20");
        // 81.9, 82.2, 82.0, 82.1, 81.9: mean 82.02, s = sqrt(0.068/4), min 81.9, max 82.2.
        assert_eq!(c["n"], 5);
        assert!((c["mean"].as_f64().unwrap() - 82.02).abs() < 1e-12);
        assert!((c["std"].as_f64().unwrap() - (0.068f64 / 4.0).sqrt()).abs() < 1e-12);
        assert_eq!((c["min"].as_f64(), c["max"].as_f64()), (Some(81.9), Some(82.2)));
        assert_eq!(c["lines"], serde_json::json!([6, 7, 8, 9, 10]));
        let a = &c["allowance"];
        let k_sd = 2.0 * (0.068f64 / 4.0).sqrt() / 5f64.sqrt();
        assert!((a["statistical"].as_f64().unwrap() - k_sd).abs() < 1e-12);
        assert_eq!(c["verdict"], "ok");
    }
    let (code, doc) = json_of(&["compare", GLASS, "fixtures/sheets/utf8-bom.csv"]);
    assert_eq!((code, doc["sheet"]["encoding"].as_str()), (0, Some("UTF-8 with BOM")));
    assert_eq!(doc["comparisons"].as_array().unwrap().len(), 3);
    // One reading per column and no uncertainty: unchecked (exit 1) without --tolerance.
    let (code, doc) = json_of(&["compare", GLASS, "fixtures/sheets/tab-separated.csv"]);
    assert_eq!((code, doc["sheet"]["delimiter"].as_str()), (1, Some("\t")));
    assert_eq!(
        (doc["comparisons"][0]["verdict"].as_str(), doc["summary"]["no_allowance"].as_u64()),
        (Some("unchecked"), Some(3))
    );
    let (code, _) = json_of(&["compare", GLASS, "fixtures/sheets/tab-separated.csv", "--tolerance", "0.2"]);
    assert_eq!(code, 0);
    assert_eq!(doc["comparisons"][1]["mean"].as_f64(), Some(89.1));
    // A delimiter given by hand overrides detection (and then the header is one unknown column).
    let (code, _, err) = gm(&["compare", GLASS, "fixtures/sheets/tab-separated.csv", "--delimiter", ";"]);
    assert_eq!(code, 2, "{err}");
    let (code, doc) = json_of(&["compare", GLASS, "fixtures/sheets/repeat-columns.csv"]);
    assert_eq!(code, 0);
    let c = &doc["comparisons"][0];
    assert_eq!((c["n"].as_u64(), c["columns"].as_array().unwrap().len()), (Some(5), 5));
}

#[test]
fn recognised_columns_without_a_prediction_are_reported() {
    let (code, doc) = json_of(&["compare", GLASS, "fixtures/sheets/rhopoint-iq.csv"]);
    assert_eq!(code, 0);
    let verdicts: Vec<(&str, &str)> = doc["comparisons"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| (c["reading"].as_str().unwrap(), c["verdict"].as_str().unwrap()))
        .collect();
    assert_eq!(
        verdicts,
        [("gloss", "ok"), ("haze", "ok"), ("log-haze", "ok"), ("doi", "ok"), ("rspec", "ok"), ("riq", "not predicted")]
    );
    assert_eq!(doc["summary"]["not_predicted"], 1);
    let (_, table, _) = gm(&["compare", GLASS, "fixtures/sheets/rhopoint-iq.csv"]);
    assert!(table.contains("not predicted") && table.contains("formula is not public"), "{table}");
}

#[test]
fn many_samples_take_their_recipes_from_a_directory() {
    let sheet = "fixtures/sheets/qc-many-samples.csv";
    let (code, doc) = json_of(&["compare", sheet, "--recipe-dir", "fixtures/recipes"]);
    assert_eq!(code, 0);
    let cs = doc["comparisons"].as_array().unwrap();
    assert_eq!(cs.len(), 5);
    assert_eq!(cs[0]["recipe"], "fixtures/recipes/black-glass.json");
    assert_eq!(cs[2]["recipe"], "fixtures/recipes/glass-n1.5.json");
    // --recipe SAMPLE=FILE takes precedence: black glass read as n = 1.50 glass is 10 GU off.
    let (code, doc) =
        json_of(&["compare", sheet, "--recipe-dir", "fixtures/recipes", "--recipe", &format!("black-glass={GLASS}")]);
    assert_eq!(code, 1);
    assert_eq!(doc["summary"]["outside"], 2);
    // A sample without a recipe: file, line and column.
    let (code, _, err) = gm(&["compare", "fixtures/sheets/bad/unknown-sample.csv", "--recipe-dir", "fixtures/recipes"]);
    assert_eq!(code, 2);
    assert!(err.contains("unknown-sample.csv") && err.contains("line 3, column 1 (sample)"), "{err}");
    // No recipe at all is a usage error.
    assert_eq!(gm(&["compare", sheet]).0, 2);
}

#[test]
fn the_verdict_uses_the_standard_error_of_the_mean() {
    // utf8-bom.csv: 20° readings 82.0, 82.1 (s = 0.0707, n = 2), prediction 82.0454: inside with k = 2
    // (allowance 0.1), outside with k = 0 (|82.045 − 82.05| = 0.0046 > e_P).
    assert_eq!(gm(&["compare", GLASS, "fixtures/sheets/utf8-bom.csv"]).0, 0);
    let (code, doc) = json_of(&["compare", GLASS, "fixtures/sheets/utf8-bom.csv", "-k", "0"]);
    assert_eq!(code, 1);
    assert_eq!(doc["rule"]["k"], 0.0);
    assert_eq!(doc["comparisons"][0]["verdict"], "OUTSIDE");
    assert_eq!(gm(&["compare", GLASS, "fixtures/sheets/utf8-bom.csv", "-k", "-1"]).0, 2);
}

/// The attributes of the first element named `tag`, and the number of such elements.
fn xml_elements(xml: &str, tag: &str) -> Vec<Vec<(String, String)>> {
    use quick_xml::events::Event;
    let mut r = quick_xml::Reader::from_str(xml);
    let mut out = vec![];
    loop {
        match r.read_event().expect("well-formed XML") {
            Event::Start(e) | Event::Empty(e) if e.name().as_ref() == tag.as_bytes() => {
                out.push(
                    e.attributes()
                        .map(|a| {
                            let a = a.unwrap();
                            (
                                String::from_utf8(a.key.as_ref().to_vec()).unwrap(),
                                a.normalized_value(quick_xml::XmlVersion::Implicit1_0).unwrap().into_owned(),
                            )
                        })
                        .collect(),
                );
            }
            Event::Eof => break,
            _ => {}
        }
    }
    out
}

fn attr<'a>(e: &'a [(String, String)], k: &str) -> &'a str {
    e.iter().find(|(a, _)| a == k).map(|(_, v)| v.as_str()).unwrap_or_else(|| panic!("no attribute {k}"))
}

#[test]
fn junit_xml_parses_and_counts_failures() {
    let (code, xml, _) = gm(&["compare", GLASS, "fixtures/sheets/rhopoint-iq.csv", "--format", "junit"]);
    assert_eq!(code, 0);
    let suites = xml_elements(&xml, "testsuites");
    assert_eq!(attr(&suites[0], "tests"), "6");
    // The skipped count is the suite's (the JUnit schema has none on <testsuites>: tests/junit_report.rs).
    let suite = xml_elements(&xml, "testsuite");
    assert_eq!((attr(&suites[0], "failures"), attr(&suite[0], "skipped")), ("0", "1"));
    let cases = xml_elements(&xml, "testcase");
    assert_eq!(attr(&cases[0], "name"), "glass-1.50 astm-d523-20 gloss");
    let skipped = xml_elements(&xml, "skipped");
    assert!(attr(&skipped[0], "message").contains("not public"));
    // The wrong recipe: three failures, each message with measured, predicted, allowance and error estimate.
    let (code, xml, _) = gm(&[
        "compare",
        "fixtures/recipes/black-glass.json",
        "fixtures/sheets/glass-n1.5-trigloss.csv",
        "--tolerance",
        "0.2",
        "--format",
        "junit",
    ]);
    assert_eq!(code, 1);
    assert_eq!(attr(&xml_elements(&xml, "testsuites")[0], "failures"), "3");
    let f = xml_elements(&xml, "failure");
    assert_eq!(f.len(), 3);
    let m = attr(&f[0], "message");
    for w in ["measured mean 82", "predicted 100", "error estimate", "allowance 0.2"] {
        assert!(m.contains(w), "{w}: {m}");
    }
}

#[test]
fn a_baseline_fails_predictions_that_moved() {
    let sheet = "fixtures/sheets/qc-many-samples.csv";
    let base = fresh("baseline.json");
    let b = base.to_str().unwrap();
    assert_eq!(gm(&["compare", sheet, "--recipe-dir", "fixtures/recipes", "--format", "json", "-o", b]).0, 0);
    let (code, doc) = json_of(&["compare", sheet, "--recipe-dir", "fixtures/recipes", "--baseline", b]);
    assert_eq!(code, 0);
    assert_eq!((doc["baseline"]["checks"].as_array().unwrap().len(), doc["baseline"]["moved"].as_u64()), (5, Some(0)));
    // A preset that drifted by 1e-6 GU, far more than both error estimates (~1e-9).
    let mut old: Value = serde_json::from_str(&std::fs::read_to_string(&base).unwrap()).unwrap();
    let p = old["comparisons"][2]["predicted"].as_f64().unwrap();
    old["comparisons"][2]["predicted"] = serde_json::json!(p + 1e-6);
    let drifted = fresh("drifted.json");
    std::fs::write(&drifted, serde_json::to_string(&old).unwrap()).unwrap();
    let d = drifted.to_str().unwrap();
    let (code, doc) = json_of(&["compare", sheet, "--recipe-dir", "fixtures/recipes", "--baseline", d]);
    assert_eq!(code, 1);
    assert_eq!(doc["baseline"]["moved"], 1);
    let (code, xml, _) =
        gm(&["compare", sheet, "--recipe-dir", "fixtures/recipes", "--baseline", d, "--format", "junit"]);
    assert_eq!(code, 1);
    assert_eq!(attr(&xml_elements(&xml, "testsuites")[0], "failures"), "1");
    assert!(attr(&xml_elements(&xml, "failure")[0], "message").contains("moved"));
    // A file that is not a baseline.
    assert_eq!(gm(&["compare", sheet, "--recipe-dir", "fixtures/recipes", "--baseline", sheet]).0, 2);
}

#[test]
fn malformed_sheets_name_the_file_line_and_column() {
    for (f, wants) in [
        ("wrong-column-count.csv", &["line 3, column 3", "2 fields"][..]),
        ("non-numeric.csv", &["line 3, column 3 (60°)", "\"high\""]),
        ("duplicate-headers.csv", &["line 1, column 3 (Gloss 20)", "duplicate"]),
        ("empty.csv", &["empty"]),
        ("header-only.csv", &["line 2", "no readings"]),
        ("unknown-column.csv", &["line 1, column 3 (Colour)", "--ignore-column"]),
        ("thousands-separator.csv", &["line 2, column 2 (20°)", "thousands"]),
        ("unknown-geometry.csv", &["line 2, column 1 (geometry)", "astm-d523-99"]),
    ] {
        let path = format!("fixtures/sheets/bad/{f}");
        let (code, out, err) = gm(&["compare", GLASS, &path]);
        assert_eq!(code, 2, "{f}: {err}");
        assert!(out.is_empty(), "{f}: {out}");
        assert!(err.contains(&path), "{f}: {err}");
        for w in wants {
            assert!(err.contains(w), "{f}: {w}: {err}");
        }
    }
    // --ignore-column skips the unknown one.
    let (code, doc) = json_of(&[
        "compare",
        GLASS,
        "fixtures/sheets/bad/unknown-column.csv",
        "--ignore-column",
        "colour",
        "--tolerance",
        "0.2",
    ]);
    assert_eq!(code, 0);
    assert_eq!(doc["sheet"]["ignored_columns"], serde_json::json!(["Colour"]));
}

/// A sample whose name holds `=` (a BYK-style name "glass; n = 1,50") can be given its recipe with
/// `--recipe 'NAME=FILE'`: the argument splits at its last `=`, and the advice the error gives works.
#[test]
fn a_sample_name_with_an_equals_sign_takes_its_recipe() {
    let dir = common::tmp_dir("eq");
    std::fs::create_dir_all(&dir).unwrap();
    let sheet = dir.join("eq.csv");
    std::fs::write(&sheet, "sample;geometry;value;uncertainty\na=b;astm-d523-60;100;0.1\n").unwrap();
    let sheet = sheet.to_str().unwrap();
    let (code, _, err) = gm(&["compare", sheet, "--recipe", "other=fixtures/recipes/black-glass.json"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--recipe 'a=b=FILE'"), "{err}");
    let (code, out, err) = gm(&["compare", sheet, "--recipe", "a=b=fixtures/recipes/black-glass.json"]);
    assert_eq!(code, 0, "{out}{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Exports as they are (docs/instrument.md §Sheets, "Title rows and statistics rows"): the BYK smart-chart,
/// Rhopoint IQ and Elcometer 408 shaped exports (fixtures/sheets/PROVENANCE.md) compare without edits, their
/// title and metadata rows kept as the sheet's metadata and their statistics rows checked.
#[test]
fn instrument_exports_compare_without_edits() {
    for (file, stats, meta) in [
        ("fixtures/sheets/byk-smart-chart-report.csv", 12, ("instrument", "micro-TRI-gloss")),
        ("fixtures/sheets/rhopoint-iq-export.csv", 0, ("", "")),
        ("fixtures/sheets/elcometer-408-export.csv", 5, ("gauge", "Elcometer 408 Gloss & DOI Meter")),
    ] {
        let (code, doc) = json_of(&["compare", GLASS, file, "--tolerance", "1"]);
        assert_eq!(code, 0, "{file}: {doc}");
        let (_, table, _) = gm(&["compare", GLASS, file, "--tolerance", "1"]);
        assert_eq!(stats > 0, table.contains(&format!("statistics: {stats} stated value(s)")), "{file}: {table}");
        if !meta.0.is_empty() {
            assert_eq!(doc["sheet"]["metadata"][meta.0], meta.1, "{file}: {}", doc["sheet"]);
        }
    }
    // A statistics row that disagrees with the readings above it is an error naming its cell.
    let bad = fresh("byk-wrong-mean.csv");
    let text = std::fs::read_to_string("fixtures/sheets/byk-smart-chart-report.csv").unwrap();
    std::fs::write(&bad, text.replace(",Mean,,82.02,", ",Mean,,83.02,")).unwrap();
    let (code, _, err) = gm(&["compare", GLASS, bad.to_str().unwrap(), "--tolerance", "1"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("line 12, column 4 (20° [GU])") && err.contains("mean"), "{err}");
    // --header-row names the header; the rows above are metadata, whatever they hold.
    let (code, doc) = json_of(&[
        "compare",
        GLASS,
        "fixtures/sheets/byk-smart-chart-report.csv",
        "--header-row",
        "5",
        "--tolerance",
        "1",
    ]);
    assert_eq!(code, 0, "{doc}");
    assert_eq!(doc["sheet"]["metadata"]["title"], "BYK-Gardner smart-chart 4.2 - Gloss report");
    let (code, _, err) = gm(&["compare", GLASS, "fixtures/sheets/byk-smart-chart-report.csv", "--header-row", "6"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("unrecognised column"), "{err}");
}

/// `compare --max-evals N` predicts with `measure --max-evals N`'s plan: the same values and error estimates, bit
/// for bit (a budget that binds moves both alike), and a budget of 0 is refused (exit 2).
#[test]
fn compare_predicts_under_the_evaluation_budget_of_measure() {
    let recipe = "fixtures/recipes/rough-dielectric-ggx-vcavity.json";
    let sheet = "fixtures/sheets/glass-n1.5-trigloss.csv";
    for budget in ["60", "2000000"] {
        let (code, out, err) =
            gm(&["compare", recipe, sheet, "--max-evals", budget, "--tolerance", "1", "--format", "json"]);
        assert!(code == 0 || code == 1, "{err}");
        let cmp: Value = serde_json::from_str(&out).unwrap();
        let (code, out, err) =
            gm(&["measure", recipe, "-g", "astm-d523-20", "-g", "astm-d523-60", "-g", "astm-d523-85"]
                .into_iter()
                .chain(["--max-evals", budget, "--format", "json", "--no-timing", "--allow-unconverged"])
                .collect::<Vec<_>>());
        assert_eq!(code, 0, "{err}");
        let measured: Value = serde_json::from_str(&out).unwrap();
        let rows = cmp["comparisons"].as_array().unwrap();
        assert_eq!(rows.len(), 3);
        for c in rows {
            let m = measured["readings"].as_array().unwrap().iter().find(|r| r["geometry"] == c["geometry"]).unwrap();
            assert_eq!(c["predicted"], m["value"], "{budget}: {}", c["geometry"]);
            assert_eq!(c["error_estimate"], m["error_estimate"], "{budget}: {}", c["geometry"]);
        }
    }
    let (code, _, err) = gm(&["compare", recipe, sheet, "--max-evals", "0"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("max-evals") || err.contains("max_evals"), "{err}");
}
