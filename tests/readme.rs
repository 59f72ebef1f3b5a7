//! The README shows the output of its main command; this test keeps that output true. The output is
//! deterministic (everything but the time column, which `--no-timing` drops), so the comparison is exact.
#![cfg(feature = "cli")]
mod common;
use std::path::PathBuf;
#[test]
fn readme_example_is_the_actual_output() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let start = readme.find("    Cerulean Blue (c):").expect("README example block");
    let block: Vec<&str> = readme[start..].lines().take_while(|l| l.is_empty() || l.starts_with("    ")).collect();
    let shown: String = block.iter().map(|l| l.strip_prefix("    ").unwrap_or(l)).collect::<Vec<_>>().join("\n");
    let out = std::env::temp_dir().join(format!("glossmeter-readme-{}.txt", std::process::id()));
    let _ = std::fs::remove_file(&out);
    let recipe = root.join("fixtures/recipes/cerulean-blue-c.json");
    let code = glossmeter::cli::run([
        "glossmeter",
        "measure",
        recipe.to_str().unwrap(),
        "--no-timing",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    let actual = std::fs::read_to_string(&out).unwrap();
    // The file path in the header line differs (absolute here); compare from the model line on.
    let tail = |s: &str| s.lines().skip(1).map(str::trim_end).collect::<Vec<_>>().join("\n").trim().to_string();
    assert_eq!(tail(&shown), tail(&actual), "README.md's example output is stale: regenerate it");
}

/// The number after `key` in `text` (up to the first character that cannot be in a number), and its
/// decimal places.
fn number_after(text: &str, key: &str) -> (f64, usize) {
    let i = text.find(key).unwrap_or_else(|| panic!("{key:?} not in {text:?}")) + key.len();
    let s: String = text[i..].chars().take_while(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | '-')).collect();
    let s = s.trim_end_matches(['.', '-', 'e']);
    let decimals = s.split_once('.').map(|(_, d)| d.len()).unwrap_or(0);
    (s.parse().unwrap_or_else(|e| panic!("{s:?} after {key:?}: {e}")), decimals)
}

/// The README's fit example quotes the fitted value, its standard error and the forward runs by purpose;
/// they are what the binary prints for that command (the value and error to the README's decimals).
#[test]
fn readme_fit_example_is_the_actual_output() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let command = "fit fixtures/recipes/bench-b4-ggx-0.3.json --free /roughness=log:1e-3..0.5 \\\n        --target astm-d523-60/gloss=60±0.2";
    assert!(readme.contains(command), "README.md's fit command changed: update this test");
    let start = readme.find("It answers α = ").expect("README fit example");
    let quoted: String =
        readme[start..].split("It exits 1").next().unwrap().split_whitespace().collect::<Vec<_>>().join(" ");

    let out = common::glossmeter()
        .current_dir(&root)
        .args([
            "fit",
            "fixtures/recipes/bench-b4-ggx-0.3.json",
            "--free",
            "/roughness=log:1e-3..0.5",
            "--target",
            "astm-d523-60/gloss=60±0.2",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let printed = String::from_utf8(out.stdout).unwrap();
    let row = printed.lines().find(|l| l.starts_with("/roughness")).expect("the parameter row");
    let cells: Vec<f64> = row.split_whitespace().skip(1).take(2).map(|c| c.parse().unwrap()).collect();

    let within = |(quoted, decimals): (f64, usize), actual: f64, what: &str| {
        let half = 0.5 * 10f64.powi(-(decimals as i32));
        assert!((quoted - actual).abs() <= half * (1.0 + 1e-9), "{what}: README {quoted}, binary {actual}");
    };
    within(number_after(&quoted, "α = "), cells[0], "fitted α");
    within(number_after(&quoted, "± "), cells[1], "its standard error");

    let runs = |text: &str, key: &str| number_after(text, key).0 as usize;
    let head = &printed[..printed.find(" forward runs (of which").expect("the forward runs")];
    let total: usize = head.rsplit(' ').next().unwrap().parse().unwrap();
    let linearity = runs(&printed, "(of which ");
    let restarts = runs(&printed, "for the linearity check, ");
    let scan = runs(&printed, "and the restarts (");
    assert!(
        printed.contains(&format!("{total} forward runs (of which {linearity} for the linearity check")),
        "{printed}"
    );
    assert_eq!(runs(&quoted, " in "), total, "forward runs in all: {quoted}");
    assert_eq!(runs(&quoted, "forward runs ("), total - linearity - restarts, "to solve: {quoted}");
    assert_eq!(runs(&quoted, "to solve, "), linearity, "for the linearity check: {quoted}");
    assert_eq!(runs(&quoted, "error analysis, "), restarts, "for the scan and restarts: {quoted}");
    assert_eq!(runs(&quoted, "of the bounds at "), scan, "points of the scan: {quoted}");
}

/// The README's literal reading of the flakes: "read 665 GU at 20°", what the binary prints to the nearest GU.
#[test]
fn readme_literal_flakes_reading_is_the_actual_output() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let text = readme.split_whitespace().collect::<Vec<_>>().join(" ");
    let quoted = number_after(&text, "second mirror under the coat and read ");
    assert!(text.contains("GU at 20°: `fixtures/recipes/cerulean-blue-c-literal.json`"), "README changed");
    let out = common::glossmeter()
        .current_dir(&root)
        .args(["measure", "fixtures/recipes/cerulean-blue-c-literal.json", "-g", "astm-d523-20", "--format", "json"])
        .output()
        .unwrap();
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let value = doc["readings"][0]["value"].as_f64().unwrap();
    assert_eq!(quoted.1, 0);
    assert!((quoted.0 - value).abs() <= 0.5, "README {} GU, binary {value}", quoted.0);
}
