//! The binary's contract: exit statuses, errors that name the file, outputs that never overwrite.
#![cfg(feature = "cli")]
use glossmeter::cli::run;
fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("glossmeter-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

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
