//! `-` is standard input for every input file (recipes, sheets and workbooks, geometry files, baselines, sweep
//! templates) and standard output for `-o` (docs/instrument.md §Standard input and output): the same results
//! as from files, one `-` per run (a second is an error, not an empty file), errors naming `<stdin>`.
mod common;
use std::io::Write;
use std::process::Stdio;

use serde_json::Value;

/// Run the binary with `input` on standard input; (status, stdout, stderr).
fn piped(args: &[&str], input: &[u8]) -> (i32, String, String) {
    let mut child = common::glossmeter()
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run glossmeter");
    // A run that fails before reading its input closes the pipe: that write error is not the test's.
    let _ = child.stdin.take().unwrap().write_all(input);
    let out = child.wait_with_output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn read(p: &str) -> Vec<u8> {
    std::fs::read(p).unwrap()
}

fn readings(json: &str) -> Value {
    let doc: Value = serde_json::from_str(json).unwrap_or_else(|e| panic!("{e}: {json}"));
    doc["readings"].clone()
}

const GLASS: &str = "fixtures/recipes/glass-n1.5.json";

#[test]
fn a_recipe_from_stdin_measures_as_from_its_file() {
    // `cat recipe.json | glossmeter measure -`
    let (code, out, err) = piped(&["measure", "-", "--format", "json", "--no-timing"], &read(GLASS));
    assert_eq!(code, 0, "{err}");
    let (_, file, _) = piped(&["measure", GLASS, "--format", "json", "--no-timing"], b"");
    assert_eq!(readings(&out), readings(&file));
    // In a batch with files, and with `-o -` (standard output).
    let (code, out, err) =
        piped(&["measure", "fixtures/recipes/black-glass.json", "-", "--format", "csv", "-o", "-"], &read(GLASS));
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("Black-backed glass, n = 1.50") && out.contains("<stdin>"), "{out}");
    // A broken recipe on stdin is named so.
    let (code, _, err) = piped(&["measure", "-"], b"{\"model\": \"lambert\", \"albedo\": 2}");
    assert_eq!(code, 2);
    assert!(err.contains("<stdin>") && err.contains("/albedo"), "{err}");
}

#[test]
fn sheets_workbooks_geometry_files_baselines_and_templates_from_stdin() {
    for sheet in ["fixtures/sheets/byk-semicolon-decimal-comma.csv", "fixtures/sheets/byk-smart-chart-export.xlsx"] {
        let (code, out, err) = piped(&["compare", GLASS, "-", "--format", "csv"], &read(sheet));
        assert_eq!(code, 0, "{sheet}: {err}");
        let (_, file, _) = piped(&["compare", GLASS, sheet, "--format", "csv"], b"");
        assert_eq!(out, file, "{sheet}");
    }
    let (code, out, err) = piped(
        &["measure", GLASS, "--geometry-file", "-", "--format", "json", "--no-timing"],
        &read("fixtures/geometry/user-grazing-89.json"),
    );
    assert_eq!(code, 0, "{err}");
    assert!(readings(&out).as_array().unwrap().iter().any(|r| r["geometry"] == "user-grazing-89"), "{out}");
    // A baseline from stdin: the run's own JSON.
    let (_, base, _) = piped(&["measure", GLASS, "--format", "json"], b"");
    let (code, out, err) = piped(&["measure", GLASS, "--baseline", "-"], base.as_bytes());
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("baseline"), "{out}");
    // A sweep template.
    let (code, out, err) =
        piped(&["sweep", "-", "--vary", "/ior=1.4..1.6:3", "-g", "astm-d523-60", "--no-timing"], &read(GLASS));
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.lines().count(), 4, "{out}");
}

#[test]
fn standard_input_is_read_once() {
    for args in [&["compare", "-", "-"][..], &["measure", "-", "--baseline", "-"], &["measure", GLASS, "-", "-"]] {
        let (code, _, err) = piped(args, &read(GLASS));
        assert_eq!(code, 2, "{args:?}");
        assert!(err.contains("`-` (standard input) is given for a second input"), "{args:?}: {err}");
    }
}
