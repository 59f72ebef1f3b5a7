//! The README shows the output of its main command; this test keeps that output true. The output is
//! deterministic (everything but the time column, which `--no-timing` drops), so the comparison is exact.
#![cfg(feature = "cli")]
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
