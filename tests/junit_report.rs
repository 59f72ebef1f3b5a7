//! `compare --format junit` read as CI servers read it (docs/instrument.md §CI reports and baselines): every
//! report validates against the JUnit schema Jenkins uses (tests/junit/junit-10.xsd, with `xmllint --schema`),
//! a real consumer (Python's `junitparser`) reads the same cases, counts and messages back, the class name is a
//! dotted identifier of the sheet and the sample (the free text is in the name), and no number in the text
//! carries binary noise (`99.99000000000001`) or digits beyond its precision.
//!
//! The checks by outside tools are opt-in, so that the README's `cargo test` passes on a machine with Rust
//! alone: they are `#[ignore]`d with the reason, and `.ci/run` installs `xmllint` (Debian's libxml2-utils) and
//! `junitparser` (in a venv named by `GLOSSMETER_JUNIT_PYTHON`) and runs them with
//! `cargo test --test junit_report -- --ignored`. There, a missing tool fails the test, saying what to install:
//! a check that cannot run does not pass. What needs no tool (exit statuses, counts, class names, numbers
//! without noise, read by quick-xml) runs in every `cargo test`.
mod common;
use common::{gm_out, tmp};
use std::process::Command;

use serde_json::Value;

fn xmllint(file: &std::path::Path) {
    let out = Command::new("xmllint")
        .args(["--noout", "--schema", "tests/junit/junit-10.xsd"])
        .arg(file)
        .output()
        .unwrap_or_else(|e| panic!("xmllint is needed for this test (Debian: apt-get install libxml2-utils): {e}"));
    assert!(
        out.status.success(),
        "{} does not validate against tests/junit/junit-10.xsd: {}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The cases as junitparser reads them: one JSON object per case.
fn junitparser(file: &std::path::Path) -> Vec<Value> {
    let python = std::env::var("GLOSSMETER_JUNIT_PYTHON").unwrap_or_else(|_| "python3".into());
    let script = "import sys, json, junitparser\n\
                  x = junitparser.JUnitXml.fromfile(sys.argv[1])\n\
                  for s in x:\n\
                  \x20   for c in s:\n\
                  \x20       print(json.dumps({'suite': s.name, 'tests': s.tests, 'failures': s.failures, \
                  'skipped': s.skipped, 'classname': c.classname, 'name': c.name, \
                  'results': [type(r).__name__ for r in c.result], 'messages': [r.message for r in c.result]}))\n";
    let out = Command::new(&python).args(["-c", script]).arg(file).output().unwrap_or_else(|e| panic!("{python}: {e}"));
    assert!(
        out.status.success(),
        "junitparser did not read {} ({python}; pip install junitparser): {}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).lines().map(|l| serde_json::from_str(l).unwrap()).collect()
}

fn is_dotted_identifier(s: &str) -> bool {
    s.split('.').all(|p| {
        p.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && p.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
    })
}

/// A run of ten or more 0s or 9s after a decimal point: binary noise printed as digits.
fn has_noise(text: &str) -> bool {
    text.split(|c: char| !(c.is_ascii_digit() || c == '.')).any(|n| {
        n.split_once('.')
            .is_some_and(|(_, f)| f.contains("0000000000") && !f.ends_with("0000000000") || f.contains("9999999999"))
    })
}

/// A report to check: label, arguments, exit status, tests, failures, skipped.
type Run<'a> = (&'a str, &'a [&'a str], i32, usize, usize, usize);

const RUNS: [Run; 4] = [
    (
        "pass",
        &["compare", "fixtures/recipes/glass-n1.5.json", "fixtures/sheets/byk-semicolon-decimal-comma.csv"],
        0,
        3,
        0,
        0,
    ),
    ("skipped", &["compare", "fixtures/recipes/glass-n1.5.json", "fixtures/sheets/rhopoint-iq.csv"], 0, 6, 0, 1),
    (
        "fail",
        &[
            "compare",
            "fixtures/recipes/black-glass.json",
            "fixtures/sheets/glass-n1.5-trigloss.csv",
            "--tolerance",
            "0.2",
        ],
        1,
        3,
        3,
        0,
    ),
    (
        "workbook",
        &["compare", "fixtures/recipes/glass-n1.5.json", "fixtures/sheets/byk-smart-chart-export.xlsx"],
        0,
        3,
        0,
        0,
    ),
];

/// Each report of `RUNS`, with its exit status checked: (label, report, tests, failures, skipped).
fn reports() -> Vec<(&'static str, String, usize, usize, usize)> {
    RUNS.iter()
        .map(|&(label, args, status, tests, failures, skipped)| {
            let mut a = args.to_vec();
            a.extend(["--format", "junit"]);
            let (code, xml) = gm_out(&a);
            assert_eq!(code, status, "{label}: {xml}");
            (label, xml, tests, failures, skipped)
        })
        .collect()
}

/// The values of attribute `attr` of every `<testcase` element, read without a parser (the class names are
/// dotted identifiers, the names free text with no quote in these reports).
fn attribute_values(xml: &str, element: &str, attr: &str) -> Vec<String> {
    xml.split(&format!("<{element} "))
        .skip(1)
        .filter_map(|e| {
            let head = &e[..e.find('>').unwrap_or(e.len())];
            let at =
                head.find(&format!(" {attr}=\"")).or_else(|| head.starts_with(&format!("{attr}=\"")).then_some(0))?;
            let rest = &head[at..];
            let v = &rest[rest.find('"')? + 1..];
            Some(v[..v.find('"')?].to_string())
        })
        .collect()
}

/// What needs no outside tool, in every `cargo test`: exit statuses, the counts of cases, failures and skips,
/// class names that are dotted identifiers, and no number with binary noise.
#[test]
fn reports_count_their_cases_name_their_classes_and_print_no_noise() {
    for (label, xml, tests, failures, skipped) in reports() {
        let classes = attribute_values(&xml, "testcase", "classname");
        assert_eq!(classes.len(), tests, "{label}: {xml}");
        assert_eq!(xml.matches("<failure ").count(), failures, "{label}: {xml}");
        assert_eq!(xml.matches("<skipped").count(), skipped, "{label}: {xml}");
        for class in &classes {
            assert!(is_dotted_identifier(class), "{label}: classname {class:?}");
            assert_eq!(class.split('.').count(), if label == "workbook" { 3 } else { 2 }, "{label}: {class}");
        }
        assert!(!has_noise(&xml), "{label}: {xml}");
    }
    let xml = reports().into_iter().find(|r| r.0 == "workbook").unwrap().1;
    assert!(xml.contains(r#"classname="byk_smart_chart_export.Measurements.glass_n_1_50""#), "{xml}");
    assert!(xml.contains(r#"name="glass n = 1.50 astm-d523-20 gloss""#), "{xml}");
}

#[test]
#[ignore = "needs xmllint (Debian: libxml2-utils) and Python's junitparser (GLOSSMETER_JUNIT_PYTHON); .ci/run installs them and runs `cargo test --test junit_report -- --ignored`"]
fn reports_validate_against_the_xsd_and_read_back_in_junitparser() {
    for (label, xml, tests, failures, skipped) in reports() {
        let file = tmp(&format!("{label}.xml"));
        std::fs::write(&file, &xml).unwrap();
        xmllint(&file);
        let cases = junitparser(&file);
        assert_eq!(cases.len(), tests, "{label}");
        assert_eq!(
            (cases[0]["tests"].as_u64(), cases[0]["failures"].as_u64()),
            (Some(tests as u64), Some(failures as u64))
        );
        assert_eq!(cases[0]["skipped"].as_u64(), Some(skipped as u64), "{label}");
        for c in &cases {
            let class = c["classname"].as_str().unwrap();
            // The sheet's file stem, (the workbook's sheet,) the sample: a CI server splits at the last dot.
            assert!(is_dotted_identifier(class), "{label}: classname {class:?}");
            let parts = class.split('.').count();
            assert_eq!(parts, if label == "workbook" { 3 } else { 2 }, "{label}: {class}");
            assert!(c["name"].as_str().unwrap().contains(" gloss") || c["name"].as_str().unwrap().contains(' '), "{c}");
            for m in c["messages"].as_array().unwrap() {
                let m = m.as_str().unwrap_or("");
                assert!(!has_noise(m), "{label}: a number with binary noise: {m}");
            }
        }
    }
}

/// The report of a comparison against a baseline (five samples of the QC sheet).
fn baseline_report() -> String {
    let sheet = "fixtures/sheets/qc-many-samples.csv";
    let base = tmp("baseline.json");
    let _ = std::fs::remove_file(&base);
    let b = base.to_str().unwrap();
    assert_eq!(gm_out(&["compare", sheet, "--recipe-dir", "fixtures/recipes", "--format", "json", "-o", b]).0, 0);
    let (code, xml) =
        gm_out(&["compare", sheet, "--recipe-dir", "fixtures/recipes", "--baseline", b, "--format", "junit"]);
    assert_eq!(code, 0);
    xml
}

#[test]
fn a_baseline_suite_has_a_case_per_sample() {
    let xml = baseline_report();
    let suite = xml.split("<testsuite name=\"baseline\"").nth(1).expect("a baseline suite");
    let suite = &suite[..suite.find("</testsuite>").unwrap()];
    let classes = attribute_values(suite, "testcase", "classname");
    assert_eq!(classes.len(), 5, "{suite}");
    assert!(classes.iter().all(|c| is_dotted_identifier(c)), "{classes:?}");
}

#[test]
#[ignore = "needs xmllint (Debian: libxml2-utils) and Python's junitparser (GLOSSMETER_JUNIT_PYTHON); .ci/run installs them and runs `cargo test --test junit_report -- --ignored`"]
fn a_baseline_suite_validates_too() {
    let xml = baseline_report();
    let file = tmp("baseline.xml");
    std::fs::write(&file, &xml).unwrap();
    xmllint(&file);
    let cases = junitparser(&file);
    let baseline: Vec<&Value> = cases.iter().filter(|c| c["suite"] == "baseline").collect();
    assert_eq!(baseline.len(), 5);
    assert!(baseline.iter().all(|c| is_dotted_identifier(c["classname"].as_str().unwrap())));
}

#[test]
fn csv_numbers_are_rounded_to_their_precision_and_json_keeps_every_digit() {
    let args = ["compare", "fixtures/recipes/glass-n1.5.json", "fixtures/sheets/byk-smart-chart-export.xlsx"];
    let (_, csv) = gm_out(&[&args[..], &["--format", "csv"]].concat());
    assert!(!has_noise(&csv), "{csv}");
    let (_, json) = gm_out(&[&args[..], &["--format", "json"]].concat());
    let doc: Value = serde_json::from_str(&json).unwrap();
    let mut rdr = csv::Reader::from_reader(csv.as_bytes());
    let head = rdr.headers().unwrap().clone();
    let col = |n: &str| head.iter().position(|h| h == n).unwrap();
    for (rec, c) in rdr.records().zip(doc["comparisons"].as_array().unwrap()) {
        let rec = rec.unwrap();
        let (p, e) = (c["predicted"].as_f64().unwrap(), c["error_estimate"].as_f64().unwrap());
        let (pt, et): (f64, f64) =
            (rec[col("predicted")].parse().unwrap(), rec[col("error_estimate")].parse().unwrap());
        // The printed estimate covers the computed one and the printed value's rounding.
        assert!(et >= e && (pt - p).abs() <= et - e + 1e-12, "{p} ± {e} printed {pt} ± {et}");
        let digits = rec[col("error_estimate")].trim_start_matches(['0', '.']).replace('.', "");
        assert!(digits.len() <= 2, "two significant digits: {}", &rec[col("error_estimate")]);
        let mean: f64 = rec[col("mean")].parse().unwrap();
        assert!((mean - c["mean"].as_f64().unwrap()).abs() <= 1e-9 * mean.abs());
    }
}
