//! The binary's contract: exit statuses, errors that name the file, outputs that never overwrite.
#![cfg(feature = "cli")]
mod common;
use common::tmp;
use glossmeter::cli::run;
#[test]
fn measure_succeeds_and_bad_input_exits_2() {
    assert_eq!(run(["glossmeter", "measure", "fixtures/recipes/glass-n1.5.json", "-g", "astm-d523-60"]), 0);
    assert_eq!(run(["glossmeter", "measure", "fixtures/recipes/does-not-exist.json"]), 2);
    assert_eq!(run(["glossmeter", "measure", "fixtures/recipes/glass-n1.5.json", "-g", "astm-d523-61"]), 2);
    for rtol in ["0", "-1e-6", "NaN", "1.5"] {
        assert_eq!(
            run(["glossmeter", "measure", "fixtures/recipes/glass-n1.5.json", "--rtol", rtol]),
            2,
            "rtol {rtol}"
        );
    }
    let bad = tmp("bad.json");
    std::fs::write(&bad, "{\"model\": \"lambert\", \"albedo\": }").unwrap();
    assert_eq!(run(["glossmeter", "measure", bad.to_str().unwrap()]), 2);
}

#[test]
fn output_files_are_never_overwritten() {
    let out = tmp("readings.json");
    let _ = std::fs::remove_file(&out);
    let args = |o: &str| {
        vec![
            "glossmeter",
            "measure",
            "fixtures/recipes/glass-n1.5.json",
            "-g",
            "astm-d523-20",
            "--format",
            "json",
            "--no-timing",
            "-o",
        ]
        .into_iter()
        .map(String::from)
        .chain([o.to_string()])
        .collect::<Vec<_>>()
    };
    assert_eq!(run(args(out.to_str().unwrap())), 0);
    let first = std::fs::read_to_string(&out).unwrap();
    let v: serde_json::Value = serde_json::from_str(&first).unwrap();
    let r = &v["readings"][0];
    assert_eq!(r["geometry"], "astm-d523-20");
    assert!(r["value"].as_f64().unwrap() > 80.0 && r["error_estimate"].as_f64().unwrap() >= 0.0);
    assert!(r.get("seconds").is_none(), "--no-timing drops the timings");
    std::fs::write(&out, "user data").unwrap();
    assert_eq!(run(args(out.to_str().unwrap())), 2);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "user data", "the existing file is untouched");
}

#[test]
fn json_output_is_reproducible_bit_for_bit() {
    let (a, b) = (tmp("a.json"), tmp("b.json"));
    for p in [&a, &b] {
        let _ = std::fs::remove_file(p);
        let code = run([
            "glossmeter",
            "measure",
            "fixtures/recipes/rough-dielectric-beckmann.json",
            "--format",
            "json",
            "--no-timing",
            "-o",
            p.to_str().unwrap(),
        ]);
        assert_eq!(code, 0);
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn compare_passes_within_and_fails_outside_the_sheet() {
    let ok = ["glossmeter", "compare", "fixtures/recipes/black-glass.json", "fixtures/sheets/black-glass-check.csv"];
    assert_eq!(run(ok), 0);
    // n = 1.5 glass against its nominal-angle Fresnel sheet: aperture averaging moves the readings by less
    // than 0.2 GU (tests/instrument.rs pins the aperture-averaged values).
    let near = [
        "glossmeter",
        "compare",
        "fixtures/recipes/glass-n1.5.json",
        "fixtures/sheets/glass-n1.5-trigloss.csv",
        "--tolerance",
        "0.2",
    ];
    assert_eq!(run(near), 0);
    let wrong = [
        "glossmeter",
        "compare",
        "fixtures/recipes/black-glass.json",
        "fixtures/sheets/glass-n1.5-trigloss.csv",
        "--tolerance",
        "0.2",
    ];
    assert_eq!(run(wrong), 1);
    let sheet = tmp("bad.csv");
    std::fs::write(&sheet, "geometry,value\nastm-d523-60,eighty\n").unwrap();
    assert_eq!(run(["glossmeter", "compare", "fixtures/recipes/black-glass.json", sheet.to_str().unwrap()]), 2);
    std::fs::write(&sheet, "geometry,value\nastm-d523-99,80\n").unwrap();
    assert_eq!(run(["glossmeter", "compare", "fixtures/recipes/black-glass.json", sheet.to_str().unwrap()]), 2);
}

fn stderr_of(args: &[&str]) -> (Option<i32>, String, String) {
    let out = common::glossmeter().current_dir(env!("CARGO_MANIFEST_DIR")).args(args).output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn write(name: &str, text: &str) -> String {
    let p = tmp(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

/// A row whose prediction has no value was once "—", no note, exit 0; it is unchecked, exit 1 (`docs/instrument.md`
/// §Exit statuses).
#[test]
fn compare_fails_a_check_it_could_not_make() {
    let black = write("black-lambert.json", r#"{"model":"lambert","albedo":0}"#);
    let sheet = write("doi.csv", "geometry,quantity,value,uncertainty\nastm-e430-30,doi,50,0.01\n");
    let (code, out, _) = stderr_of(&["compare", &black, &sheet]);
    assert_eq!(code, Some(1), "{out}");
    assert!(out.contains("unchecked") && out.contains("not checked: the prediction has no value"), "{out}");
    // A row with neither an uncertainty nor --tolerance cannot be checked either.
    let sheet = write("no-allowance.csv", "geometry,value\nastm-d523-60,100\n");
    let glass = "fixtures/recipes/black-glass.json";
    let (code, out, _) = stderr_of(&["compare", glass, &sheet]);
    assert_eq!(code, Some(1), "{out}");
    assert!(out.contains("no allowed difference"), "{out}");
    assert_eq!(run(["glossmeter", "compare", glass, &sheet, "--tolerance", "0.01"]), 0);
}

/// An unconverged reading exits 1 unless --allow-unconverged (`docs/instrument.md` §Exit statuses); DOI of a black
/// specimen says that the specimen's specular flux is zero, not that the stops miss the mirror direction.
#[test]
fn unconverged_readings_exit_1_and_reasons_say_what_is_zero() {
    let rough = "fixtures/recipes/rough-dielectric-beckmann.json";
    // rtol 1e-9: at the default the calibrated estimate (`docs/accuracy.md` §5) already converges on the initial boxes.
    let base = ["measure", rough, "-g", "astm-d523-60", "--max-evals", "200", "--rtol", "1e-9", "--no-timing"];
    let (code, out, err) = stderr_of(&base);
    assert_eq!(code, Some(1), "{out}{err}");
    assert!(err.contains("did not converge") && out.contains("* not converged"), "{out}{err}");
    let allowed: Vec<&str> = base.iter().copied().chain(["--allow-unconverged"]).collect();
    assert_eq!(stderr_of(&allowed).0, Some(0));
    for recipe in [r#"{"model":"lambert","albedo":0}"#, r#"{"model":"smooth-dielectric","ior":1.0}"#] {
        let p = write("zero-specular.json", recipe);
        let (code, out, _) = stderr_of(&["measure", &p, "-g", "astm-e430-30"]);
        assert_eq!(code, Some(1), "{out}");
        assert!(out.contains("the specimen reflects no flux into the specular receptor"), "{out}");
        assert!(!out.contains("below the horizon"), "{out}");
    }
    // Albedo 1e-300: the ratio's error propagation underflowed into "non-finite result".
    let p = write("tiny.json", r#"{"model":"lambert","albedo":1e-300}"#);
    let (code, out, err) = stderr_of(&["measure", &p, "-g", "astm-e430-30", "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(code, Some(0), "{out}{err}");
    assert!(v["readings"].as_array().unwrap().iter().all(|r| r["value"].is_number()), "{out}");
}

/// `-o` naming an existing file is refused before any work (here: before the recipe is even read;
/// `docs/instrument.md` §Exit statuses).
#[test]
fn output_is_checked_before_the_work() {
    let existing = write("existing.txt", "user data");
    let (code, _, err) = stderr_of(&["measure", "fixtures/recipes/does-not-exist.json", "-o", &existing]);
    assert_eq!(code, Some(2));
    assert!(err.contains("already exists") && !err.contains("does-not-exist"), "{err}");
    let sheet = "fixtures/sheets/black-glass-check.csv";
    let (code, _, err) = stderr_of(&["compare", "fixtures/recipes/does-not-exist.json", sheet, "-o", &existing]);
    assert_eq!(code, Some(2));
    assert!(err.contains("already exists"), "{err}");
    assert_eq!(std::fs::read_to_string(&existing).unwrap(), "user data");
}

/// A table cell longer than 65 535 characters once panicked in `format!`'s width.
#[test]
fn a_huge_table_cell_does_not_panic() {
    let name = "s".repeat(70_000);
    let sheet = write("long-cell.csv", &format!("sample,geometry,value,uncertainty\n{name},astm-d523-60,100,0.01\n"));
    let (code, out, err) = stderr_of(&["compare", "fixtures/recipes/black-glass.json", &sheet]);
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains(&name) && out.contains("predicted − measured"));
}

/// CSV numbers are plain decimals and the notes are kept (`docs/instrument.md` §Output).
#[test]
fn csv_has_plain_decimals_and_notes() {
    let (code, out, _) =
        stderr_of(&["measure", "fixtures/recipes/cerulean-blue-c-literal.json", "--format", "csv", "--no-timing"]);
    assert_eq!(code, Some(0));
    let mut r = csv::Reader::from_reader(out.as_bytes());
    let head: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(head.last().map(String::as_str), Some("note"));
    let mut notes = 0;
    for rec in r.records() {
        let rec = rec.unwrap();
        for c in [3, 5] {
            let cell = &rec[c];
            assert!(!cell.contains('e') && cell.parse::<f64>().unwrap().is_finite(), "{cell}");
        }
        notes += usize::from(rec[head.len() - 1].contains("ASTM D4039"));
    }
    assert_eq!(notes, 1, "the D4039 scope note is kept");
}

/// Smaller input cases (`docs/instrument.md` §Exit statuses, status 2): duplicate keys, a BOM, a user geometry reusing
/// a shipped id.
#[test]
fn smaller_input_cases_exit_2_naming_file_and_field() {
    let dup = write("dup.json", r#"{"model":"lambert","albedo":0.5,"albedo":0.9}"#);
    let (code, _, err) = stderr_of(&["measure", &dup, "-g", "astm-d523-60"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("dup.json") && err.contains("`/albedo`") && err.contains("twice"), "{err}");
    let bom = write("bom.json", "\u{feff}{\"model\":\"lambert\",\"albedo\":0.5}");
    assert_eq!(run(["glossmeter", "measure", &bom, "-g", "astm-d523-60"]), 0);
    let (code, _, err) = stderr_of(&["measure", &bom, "--geometry-file", "fixtures/geometry/bad-shipped-id.json"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("bad-shipped-id.json") && err.contains("`/id`"), "{err}");
    let (code, _, err) = stderr_of(&["measure", "/dev/zero"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("/dev/zero") && err.contains("MiB"), "{err}");
}

/// A `--baseline` that checks nothing never passes (docs/instrument.md §Exit statuses): one that matches no
/// reading exits 1; one with no reading, a non-number where a number belongs, or a negative error estimate is
/// malformed (exit 2, naming the field); a BOM and a good baseline pass.
#[test]
fn a_baseline_that_checks_nothing_never_passes() {
    let glass = "fixtures/recipes/glass-n1.5.json";
    let (code, good, _) = stderr_of(&["measure", glass, "-g", "astm-d523-60", "--format", "json", "--no-timing"]);
    assert_eq!(code, Some(0));
    let doc: serde_json::Value = serde_json::from_str(&good).unwrap();
    let variant = |name: &str, f: &dyn Fn(&mut serde_json::Value)| {
        let mut d = doc.clone();
        f(&mut d);
        write(name, &serde_json::to_string(&d).unwrap())
    };
    let base = |b: &str| stderr_of(&["measure", glass, "-g", "astm-d523-60", "--baseline", b]);
    assert_eq!(base(&write("base-good.json", &good)).0, Some(0));
    assert_eq!(base(&write("base-bom.json", &format!("\u{feff}{good}"))).0, Some(0), "a BOM is no part of JSON");
    let renamed = variant("base-renamed.json", &|d| d["material"]["name"] = "another panel".into());
    let (code, _, err) = base(&renamed);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("nothing was checked"), "{err}");
    let strings = variant("base-strings.json", &|d| {
        let v = d["readings"][0]["value"].to_string();
        d["readings"][0]["value"] = v.into();
    });
    let (code, _, err) = base(&strings);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("/readings/0/value") && err.contains("number"), "{err}");
    let negative = variant("base-negative.json", &|d| d["readings"][0]["error_estimate"] = (-1.0).into());
    let (code, _, err) = base(&negative);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("/readings/0/error_estimate"), "{err}");
    let empty = variant("base-empty.json", &|d| d["readings"] = serde_json::json!([]));
    let (code, _, err) = base(&empty);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("check nothing"), "{err}");
}

/// Numbers past 10¹⁵ (and tiny ones) are written in scientific notation in tables, CSV, descriptions and
/// messages, never as 300 digits (`docs/instrument.md` §Numbers in text).
#[test]
fn huge_and_tiny_numbers_are_printed_in_scientific_notation() {
    let tiny = write("tiny-albedo.json", r#"{"model":"lambert","albedo":1e-300}"#);
    let (code, out, _) = stderr_of(&["measure", &tiny, "-g", "astm-d523-60", "--no-timing"]);
    assert_eq!(code, Some(0));
    assert!(out.contains("Lambert (albedo 1e-300)"), "{out}");
    let (code, _, err) = stderr_of(&["measure", &tiny, "-g", "astm-d523-60", "--rtol", "1e-300"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("`1e-300`") && err.len() < 400, "{err}");
    // A table whose one cell is 1e300, inside the 60° receptor: a reading of order 1e298 GU.
    let mut rows = String::from("QUANTITY: BRDF\ntheta_i phi_i theta_s phi_s BRDF\n");
    for ts in (0..90).step_by(2) {
        let v = if ts == 60 { 1e300 } else { 0.02 };
        rows.push_str(&format!("60 0 {ts} 180 {v:e}\n"));
    }
    write("huge-cell.txt", &rows);
    let recipe = write("huge-cell.json", r#"{"model":"e1392","file":"huge-cell.txt"}"#);
    for format in ["table", "csv"] {
        let (code, out, _) = stderr_of(&[
            "measure",
            &recipe,
            "-g",
            "astm-d523-60",
            "--max-evals",
            "20000",
            "--format",
            format,
            "--no-timing",
        ]);
        assert!(matches!(code, Some(0 | 1)), "{format}: {out}");
        let rows = out.lines().filter(|l| l.starts_with("astm-d523-60"));
        let longest = rows.flat_map(|l| l.split([',', ' '])).map(str::len).max().unwrap();
        assert!(longest < 40, "{format}: a field of {longest} characters:\n{out}");
        assert!(out.contains("e29") || out.contains("e30"), "{format}: {out}");
    }
}
