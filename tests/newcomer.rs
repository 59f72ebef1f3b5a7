//! What a newcomer meets first at the command line: a mistyped geometry id gets the ids it was probably meant as,
//! a recipe given where the sheet goes is named as such, and the help describes what the commands read.
#![cfg(feature = "cli")]
mod common;
use common::gm;

/// Run the binary from the checkout; (exit status, stdout, stderr).
#[test]
fn a_bare_angle_as_geometry_gets_a_did_you_mean() {
    let (code, out, err) = gm(&["measure", "fixtures/recipes/glass-n1.5.json", "-g", "60"]);
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains(r#"unknown geometry id "60"; did you mean one of "astm-d523-60", "iso-2813-60"?"#), "{err}");
    let (code, _, err) = gm(&["measure", "fixtures/recipes/glass-n1.5.json", "-g", "d523-60"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains(r#"did you mean "astm-d523-60"?"#), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn compare_with_a_recipe_for_the_sheet_says_it_is_a_recipe() {
    let recipe = "fixtures/recipes/glass-n1.5.json";
    let (code, _, err) = gm(&["compare", recipe, recipe]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("glass-n1.5.json") && err.contains("not an instrument sheet"), "{err}");
    assert!(!err.contains("unrecognised column"), "{err}");
}

#[test]
fn the_help_of_compare_names_workbooks_not_only_csv() {
    let (code, out, _) = gm(&["--help"]);
    assert_eq!(code, 0);
    let line = out.lines().find(|l| l.trim_start().starts_with("compare")).expect("compare in --help");
    assert!(line.contains("instrument sheet") && !line.contains("(CSV)"), "{line}");
}

#[test]
fn completions_and_the_man_page_come_from_the_same_definition_as_help() {
    let (code, bash, err) = gm(&["completions", "bash"]);
    assert_eq!(code, 0, "{err}");
    assert!(bash.contains("_glossmeter()") && bash.contains("complete ") && bash.contains("--tolerance"), "{bash}");
    let (code, zsh, _) = gm(&["completions", "zsh"]);
    assert_eq!(code, 0);
    assert!(zsh.starts_with("#compdef glossmeter"), "{zsh}");
    let (code, _, err) = gm(&["completions", "tcsh"]);
    assert_eq!(code, 2, "an unknown shell is a usage error: {err}");
    let (code, man, err) = gm(&["man"]);
    assert_eq!(code, 0, "{err}");
    assert!(man.contains(".TH glossmeter") && man.contains("compare") && man.contains("\\-\\-force"), "{man}");
}

#[test]
fn force_replaces_an_existing_output_and_without_it_the_file_is_kept() {
    let dir = common::tmp_dir("newcomer-force");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("readings.csv");
    std::fs::write(&out, "earlier run\n").unwrap();
    let o = out.to_str().unwrap();
    let args = ["measure", "fixtures/recipes/glass-n1.5.json", "-g", "astm-d523-60", "--format", "csv", "--no-timing"];
    let (code, _, err) = gm(&[&args[..], &["-o", o]].concat());
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("already exists") && err.contains("--force"), "{err}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "earlier run\n");
    let (code, _, err) = gm(&[&args[..], &["-o", o, "--force"]].concat());
    assert_eq!(code, 0, "{err}");
    let (_, stdout, _) = gm(&args);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), stdout, "the file is the new run's output");
    // `--force` before the subcommand works too (a global flag), and a directory is never replaced.
    let (code, _, err) = gm(&[&["--force"][..], &args[..], &["-o", dir.to_str().unwrap()]].concat());
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("directory"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_compare_table_fits_120_columns() {
    for args in [
        &["compare", "fixtures/recipes/glass-n1.5.json", "fixtures/sheets/rhopoint-iq.csv", "--tolerance", "1"][..],
        &["compare", "fixtures/sheets/qc-many-samples.csv", "--recipe-dir", "fixtures/recipes"][..],
        &["compare", "fixtures/recipes/glass-n1.5.json", "fixtures/sheets/byk-smart-chart-export.xlsx"][..],
    ] {
        let (code, out, err) = gm(args);
        assert_eq!(code, 0, "{err}");
        // The table and its legend; the sheet's own metadata lines (`# key: value`), the notes and the line naming
        // each sample's material and recipe file are the user's words, printed as they are.
        let own_words =
            |l: &str| l.starts_with("# ") || l.starts_with("note: ") || l.starts_with("sample ") && l.contains(": ");
        let table: Vec<&str> = out.lines().filter(|l| !own_words(l)).collect();
        assert!(table.iter().any(|l| l.contains("mean ± std") && l.contains("verdict")), "{out}");
        for line in &table {
            assert!(line.chars().count() <= 120, "{} columns: {line}\n{out}", line.chars().count());
        }
        assert!(out.contains("difference = predicted − measured"), "{out}");
    }
}

/// The README's colour example: the commands it shows, with the exit statuses and the numbers it quotes.
#[test]
fn the_readme_colour_example_is_what_the_binary_does() {
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    let text = readme.split_whitespace().collect::<Vec<_>>().join(" ");
    let measure =
        "glossmeter measure fixtures/recipes/blue-metallic-spectral.json -g astm-e2194-15 -g astm-e2194-45 -g d8-sce";
    let compare = "glossmeter compare fixtures/recipes/blue-metallic-spectral.json fixtures/sheets/colour-blue-metallic.csv --max-de00 4";
    assert!(
        readme.contains(measure) && readme.contains(compare),
        "README.md's colour example changed: update this test"
    );
    let args = |command: &str| command.split(' ').skip(1).map(String::from).collect::<Vec<_>>();
    let run = |a: Vec<String>| gm(&a.iter().map(String::as_str).collect::<Vec<_>>());

    let (code, out, err) = run([args(measure), vec!["--format".into(), "json".into()]].concat());
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    let l_star = |g: &str| {
        let r = doc["readings"].as_array().unwrap().iter().find(|r| r["geometry"] == g && r["name"] == "L*").unwrap();
        format!("{:.1}", r["value"].as_f64().unwrap())
    };
    let quoted = format!(
        "L* {} at 15°, {} at 45°, {} on the d/8 sphere",
        l_star("astm-e2194-15"),
        l_star("astm-e2194-45"),
        l_star("d8-sce")
    );
    assert!(text.contains(&quoted), "README should say {quoted:?}");

    let (code, out, err) = run([args(compare), vec!["--format".into(), "json".into()]].concat());
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    let de: Vec<String> = doc["colour_differences"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| format!("{:.1}", d["de00"].as_f64().unwrap()))
        .collect();
    let quoted = format!("(ΔE00 = {} at 15°, {} at 45°, {} at 110°)", de[0], de[1], de[2]);
    assert!(text.contains(&quoted), "README should say {quoted:?}");
    let mut strict = args(compare);
    *strict.last_mut().unwrap() = "2".into();
    assert_eq!(run(strict).0, 1, "--max-de00 2 exits 1, as the README says");
}
