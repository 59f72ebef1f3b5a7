//! The fuzz campaign in `cargo test` (`docs/reliability.md`): property tests over generated and mutated recipes,
//! geometry files and sheets, and tables (MERL, RGL, in-plane CSV, E1392), baselines and command lines, in bounded time (a few hundred cases per category). Every case is either
//! accepted or refused with an error naming the file and a field or line; nothing panics; a recipe that is
//! accepted is measured (cheap tolerance, small budget) and no reading is NaN or infinite, in the library and
//! through the command line (exit 0, 1 or 2; no "NaN"/"inf" in the output). The 10⁶-case run by hand is
//! `examples/fuzz.rs` (docs/reliability.md).
#[path = "common/fuzz_cases.rs"]
mod fuzz_cases;

use fuzz_cases::{case_text, check_readings, run_case, Category, Outcome, Rng, Seeds};
use glossmeter::{measure, resolve_geometries, PlanOptions};
use proptest::prelude::*;
use std::sync::OnceLock;

fn seeds() -> &'static Seeds {
    static S: OnceLock<Seeds> = OnceLock::new();
    S.get_or_init(Seeds::load)
}

fn one(cat: Category, seed: u64) -> Result<Outcome, String> {
    let text = case_text(cat, seeds(), &mut Rng::new(seed));
    match std::panic::catch_unwind(|| run_case(cat, &text)) {
        Ok(r) => r.map_err(|e| format!("{e}\ninput: {text}")),
        Err(_) => Err(format!("panic on input: {text}")),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn generated_recipes(seed in any::<u64>()) {
        prop_assert!(one(Category::GeneratedRecipe, seed).is_ok(), "{:?}", one(Category::GeneratedRecipe, seed));
    }

    #[test]
    fn mutated_recipes(seed in any::<u64>()) {
        prop_assert!(one(Category::MutatedRecipe, seed).is_ok(), "{:?}", one(Category::MutatedRecipe, seed));
    }

    #[test]
    fn mutated_geometry_files(seed in any::<u64>()) {
        prop_assert!(one(Category::MutatedGeometry, seed).is_ok(), "{:?}", one(Category::MutatedGeometry, seed));
    }

    #[test]
    fn sheets(seed in any::<u64>()) {
        prop_assert!(one(Category::Sheet, seed).is_ok(), "{:?}", one(Category::Sheet, seed));
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, failure_persistence: None, ..ProptestConfig::default() })]

    /// Generated and mutated `.xlsx`, `.ods` and `.xls` workbooks through the one sheet reader: accepted with
    /// finite rows or refused naming the file; never a panic or an abort (an abort ends the test binary).
    #[test]
    fn workbooks(seed in any::<u64>()) {
        prop_assert!(one(Category::Workbook, seed).is_ok(), "{:?}", one(Category::Workbook, seed));
    }
}

/// The workbook generator makes readable workbooks, not only broken ones: of 200 cases some are accepted
/// and some refused (a generator whose every case is refused at the archive would test nothing past it).
#[test]
fn the_workbook_cases_reach_the_cells() {
    let (mut accepted, mut refused) = (0, 0);
    for seed in 0..200u64 {
        match one(Category::Workbook, seed) {
            Ok(Outcome::Accepted(_)) => accepted += 1,
            Ok(Outcome::Refused) => refused += 1,
            Err(e) => panic!("seed {seed}: {e}"),
        }
    }
    assert!(accepted >= 10 && refused >= 10, "accepted {accepted}, refused {refused} of 200");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, failure_persistence: None, ..ProptestConfig::default() })]

    /// Accepted recipes are measured (one geometry, rtol 1e-2, 20 000 evaluations per integral): every reading
    /// finite or absent with a reason; the command line prints no NaN or inf and exits 0, 1 or 2.
    #[test]
    fn accepted_recipes_measure_without_nan(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let cat = if rng.chance(0.5) { Category::GeneratedRecipe } else { Category::MutatedRecipe };
        let text = case_text(cat, seeds(), &mut rng);
        if let Ok(Outcome::Accepted(Some(m))) = run_case(cat, &text) {
            let g = resolve_geometries(&["astm-e430-30"], &[] as &[&str]).unwrap();
            let opts = PlanOptions { rtol: 1e-2, max_evals: 20_000, ..PlanOptions::default() };
            let readings = measure(&m, &g, &opts).unwrap();
            prop_assert!(check_readings(&readings).is_ok(), "{:?}\n{text}", check_readings(&readings));
            let input = fuzz_cases::scratch(&format!("r-{seed}.json"));
            let out = fuzz_cases::scratch(&format!("o-{seed}.json"));
            std::fs::write(&input, &text).unwrap();
            let _ = std::fs::remove_file(&out);
            let code = glossmeter::cli::run([
                "glossmeter", "measure", input.to_str().unwrap(), "-g", "astm-e430-30", "--rtol", "1e-2",
                "--max-evals", "20000", "--format", "json", "--no-timing", "-o", out.to_str().unwrap(),
            ]);
            prop_assert!(code == 0 || code == 1, "exit {code}\n{text}");
            let printed = std::fs::read_to_string(&out).unwrap();
            prop_assert!(!printed.contains("NaN") && !printed.contains("inf"), "{printed}");
            let _ = std::fs::remove_file(&input);
            let _ = std::fs::remove_file(&out);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn merl_tables(seed in any::<u64>()) {
        prop_assert!(one(Category::MerlTable, seed).is_ok(), "{:?}", one(Category::MerlTable, seed));
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, failure_persistence: None, ..ProptestConfig::default() })]

    /// Generated and mutated RGL `.bsdf` files, read through an `rgl` recipe.
    #[test]
    fn rgl_tables(seed in any::<u64>()) {
        prop_assert!(one(Category::RglTable, seed).is_ok(), "{:?}", one(Category::RglTable, seed));
    }

    /// Generated and mutated in-plane CSV tables, read through an `inplane-csv` recipe.
    #[test]
    fn inplane_tables(seed in any::<u64>()) {
        prop_assert!(one(Category::InplaneTable, seed).is_ok(), "{:?}", one(Category::InplaneTable, seed));
    }

    /// Generated and mutated ASTM E1392 tables, read through an `e1392` recipe.
    #[test]
    fn e1392_tables(seed in any::<u64>()) {
        prop_assert!(one(Category::E1392Table, seed).is_ok(), "{:?}", one(Category::E1392Table, seed));
    }

    /// Generated and mutated baselines, read as `--baseline` reads them and checked against real readings.
    #[test]
    fn baselines(seed in any::<u64>()) {
        prop_assert!(one(Category::Baseline, seed).is_ok(), "{:?}", one(Category::Baseline, seed));
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, failure_persistence: None, ..ProptestConfig::default() })]

    /// Accepted tables (MERL, RGL, in-plane CSV, E1392; generated or mutated) are measured (one geometry, rtol
    /// 1e-2, 20 000 evaluations per integral): every reading finite or absent with a reason.
    #[test]
    fn accepted_tables_measure_without_nan(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let cat = *rng.pick(&[Category::MerlTable, Category::RglTable, Category::InplaneTable, Category::E1392Table]);
        let text = case_text(cat, seeds(), &mut rng);
        if let Ok(Outcome::Accepted(Some(m))) = run_case(cat, &text) {
            let g = resolve_geometries(&["astm-d523-60"], &[] as &[&str]).unwrap();
            let opts = PlanOptions { rtol: 1e-2, max_evals: 20_000, ..PlanOptions::default() };
            let readings = measure(&m, &g, &opts).unwrap();
            prop_assert!(check_readings(&readings).is_ok(), "{:?}\n{text}", check_readings(&readings));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 100, failure_persistence: None, ..ProptestConfig::default() })]

    /// Command lines run as a process (`measure`, `compare`, `convergence`, `sweep`, `fit`, `plot`, `profile`,
    /// with `--baseline` files, and the rest): exit 0, 1 or 2, no panic, no NaN/inf printed, no file lost or left.
    #[test]
    fn command_lines(seed in any::<u64>()) {
        fuzz_cases::BINARY.get_or_init(|| env!("CARGO_BIN_EXE_glossmeter").into());
        prop_assert!(one(Category::CommandLine, seed).is_ok(), "{:?}", one(Category::CommandLine, seed));
    }
}

/// The checker's rule on printed non-finite numbers exempts the user's quoted input (the 10⁶-case run of
/// 2026-12-01 had 22 false positives such as `got string "NaN-"`), and still catches glossmeter's own.
#[test]
fn the_non_finite_check_exempts_quoted_input_only() {
    use fuzz_cases::prints_non_finite;
    for quoted in [
        r#"fuzz.json: /albedo: expected a number, got string "NaN-""#,
        r#"fuzz.json: /model: unknown model "lambertbeNaN"; allowed: …"#,
        r#"geometry `inf` is unknown"#,
        r#"got string "a \"NaN\" inside""#,
        "not a finite number (1e400 is too large); infinite values are refused",
        "error: invalid value 'NaN' for '--max-evals <MAX_EVALS>': invalid digit found in string",
        "--rtol must be a number in (0, 1), got `inf`",
    ] {
        assert!(!prints_non_finite(quoted), "{quoted}");
    }
    for own in [
        "value NaN ± 0",
        "gloss: inf GU",
        "error -inf",
        "x = Infinity",
        // An unbalanced quote quotes nothing: it cannot hide what follows.
        r#"got "x, value NaN"#,
        "field `a: NaN",
        "it doesn't converge: NaN",
    ] {
        assert!(prints_non_finite(own), "{own}");
    }
}

/// The registry generator makes mostly valid recipes (the random-field generator made 91 of 250 000), so
/// that the valid inputs of the campaign are not only the mutated fixtures.
#[test]
fn registry_recipes_are_mostly_accepted() {
    let n = 400usize;
    let accepted = (0..n)
        .filter(|&k| {
            let text = fuzz_cases::generate_registry_recipe(&mut Rng::new(k as u64));
            matches!(run_case(Category::GeneratedRecipe, &text), Ok(Outcome::Accepted(_)))
        })
        .count();
    assert!(accepted * 2 >= n, "{accepted} of {n} accepted");
}

/// The command line that `command_lines` found printing `inf` (seed 4146925888915634337): `measure --explain` of an
/// RGL table whose lobe does not fall to half within 40° of tilt printed its slope width and its widths in the lobe
/// variables as `inf`; they are "unbounded" now (`plan::explain`).
#[test]
fn command_line_seed_4146925888915634337_prints_no_inf() {
    fuzz_cases::BINARY.get_or_init(|| env!("CARGO_BIN_EXE_glossmeter").into());
    let seed = 4146925888915634337;
    assert!(one(Category::CommandLine, seed).is_ok(), "{:?}", one(Category::CommandLine, seed));
}

/// The sheets case that made `sheets` flaky on main (seed 14908795379597200520): a quoted "NaN" in the
/// sheet, echoed back in the error, was taken for a NaN printed by glossmeter.
#[test]
fn sheet_seed_14908795379597200520_is_not_a_false_positive() {
    let seed = 14908795379597200520;
    let text = case_text(Category::Sheet, seeds(), &mut Rng::new(seed));
    if let Err(e) = sheet_error(&text) {
        eprintln!("error shown: {e}");
    }
    assert!(one(Category::Sheet, seed).is_ok(), "{:?}", one(Category::Sheet, seed));
}

fn sheet_error(text: &str) -> Result<(), String> {
    glossmeter::comparison::sheet::parse(text, "fuzz.csv", &Default::default()).map(|_| ()).map_err(|e| e.to_string())
}

/// Found by the campaign (seed 7, case 550): a sheet cell holding quotes (`89."NaN"`) was echoed inside
/// "…" unescaped (`got "89."NaN""`), so the quoted part ended early and the message read as if glossmeter
/// printed a NaN. The cell is now shown escaped (`got "89.\"NaN\""`).
#[test]
fn a_sheet_cell_with_quotes_is_echoed_escaped() {
    let text = "sample,geometry,quantity,value,uncertainty\np,astm-d523-60,gloss,\"89.\"\"NaN\"\"\",0.5\n";
    let e = sheet_error(text).unwrap_err();
    assert!(e.contains(r#"got "89.\"NaN\"""#), "{e}");
    assert!(matches!(run_case(Category::Sheet, text), Ok(Outcome::Refused)), "{:?}", run_case(Category::Sheet, text));
}

/// The same for recipe strings: a JSON string holding a quote is echoed escaped, so the quoted part of the
/// message is the user's whole string.
#[test]
fn a_recipe_string_with_quotes_is_echoed_escaped() {
    for text in [r#"{"model": "lambert\"NaN"}"#, r#"{"model": "lambert", "albedo": "x\"inf"}"#] {
        let e = glossmeter::recipe::parse_str(text, "fuzz.json").unwrap_err().to_string();
        assert!(e.contains(r#"\""#), "{e}");
        assert!(!fuzz_cases::prints_non_finite(&e), "{e}");
    }
}

/// The 10⁶-case run's 9 failures (docs/reliability.md): `fixtures/bad/nan-string.json`, the user's own file
/// name, echoed unquoted at the head of an error, was taken for a NaN printed by glossmeter.
#[test]
fn the_cli_check_ignores_the_arguments_echoed_back() {
    fuzz_cases::BINARY.get_or_init(|| env!("CARGO_BIN_EXE_glossmeter").into());
    let case = r#"["measure", "fixtures/bad/nan-string.json", "--max-seconds", "1"]"#;
    assert!(matches!(fuzz_cases::run_cli(case), Ok(Outcome::Refused)), "{:?}", fuzz_cases::run_cli(case));
    let args = ["measure".to_string(), "fixtures/bad/nan-string.json".to_string()];
    let shown = "error: fixtures/bad/nan-string.json: field `/albedo`: got string \"NaN\"";
    assert!(!fuzz_cases::prints_non_finite(&fuzz_cases::without_args(shown, &args)));
    // glossmeter's own text still counts.
    assert!(fuzz_cases::prints_non_finite(&fuzz_cases::without_args("fixtures/x.json: value NaN", &args)));
}

/// Found by the extended campaign (seed 11, cases 744, 1348, …): a `sweep` shard that holds no point (one point
/// in three shards) rightly writes an empty `-o` file (the shards' outputs concatenated are the whole run),
/// which the checker took for a lost file. It now computes the shard's range; a shard with points, or shard 1 of
/// a CSV (the header), must still write something.
#[test]
fn an_empty_sweep_shard_is_no_lost_file() {
    fuzz_cases::BINARY.get_or_init(|| env!("CARGO_BIN_EXE_glossmeter").into());
    let args = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let case = r#"["sweep", "fixtures/recipes/glass-n1.5.json", "--vary", "/ior=1.3..1.8:1", "--shard", "2/3",
        "-o", "@NEW", "--rtol", "1e-2", "--max-evals", "20000"]"#;
    assert!(matches!(fuzz_cases::run_cli(case), Ok(Outcome::Accepted(_))), "{:?}", fuzz_cases::run_cli(case));
    assert!(fuzz_cases::sweep_shard_is_empty(&args(&["sweep", "t.json", "--vary", "/a=0..1:1", "--shard", "2/3"])));
    // Shard 1 of a CSV writes the header; shard 3 of 3 holds the point; jsonl shard 1 of 3 holds none.
    assert!(!fuzz_cases::sweep_shard_is_empty(&args(&["sweep", "t.json", "--vary", "/a=0..1:1", "--shard", "1/3"])));
    assert!(!fuzz_cases::sweep_shard_is_empty(&args(&["sweep", "t.json", "--vary", "/a=0..1:1", "--shard", "3/3"])));
    assert!(fuzz_cases::sweep_shard_is_empty(&args(&[
        "sweep",
        "t.json",
        "--vary",
        "/a=0..1:1",
        "--shard",
        "1/3",
        "--format",
        "jsonl"
    ])));
    let n = "18446744073709551615";
    assert!(!fuzz_cases::sweep_shard_is_empty(&args(&["sweep", "t.json", "--lhs", n, "--shard", &format!("{n}/{n}")])));
}

/// Run the binary on `args` (in the crate root), killed after `secs`: the exit code, or None if it was still
/// running.
fn run_for(args: &[&str], secs: f64) -> Option<i32> {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_glossmeter"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s.code();
        }
        if t0.elapsed().as_secs_f64() > secs {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}

/// Found by the extended campaign's tables on the command line: `plot --kind section` of a table whose largest
/// value is subnormal (1e-320: the log axis' floor, 10⁻⁶ of it, is 0) or near the top of f64 (1e308: the axis'
/// top, 3× it, is infinite) never ended, and one with an infinite value ran out of memory. The axis is now kept
/// within the normal finite numbers.
#[test]
fn a_section_plot_of_an_extreme_table_ends() {
    // brdf_cos of 1e308 is an infinite f_r near grazing (f_r = value / cos θo): the 10⁶-case run's case 200999,
    // an RGL table with an infinite value, made plotters' log scale push key points until memory ran out.
    for (name, value, column) in [
        ("subnormal", "1e-320", "brdf"),
        ("huge", "1e308", "brdf"),
        ("zero", "0", "brdf"),
        ("infinite", "1e308", "brdf_cos"),
    ] {
        let table = fuzz_cases::scratch(&format!("section-{name}.csv"));
        let mut text = format!("theta_i,theta_o,{column}\n");
        for ti in [20, 60] {
            for to in -89..90 {
                text.push_str(&format!("{ti},{to},{value}\n"));
            }
        }
        std::fs::write(&table, text).unwrap();
        let recipe = fuzz_cases::scratch(&format!("section-{name}.json"));
        let json = serde_json::json!({"model": "inplane-csv", "file": table.to_string_lossy()});
        std::fs::write(&recipe, json.to_string()).unwrap();
        let svg = fuzz_cases::scratch(&format!("section-{name}.svg"));
        let _ = std::fs::remove_file(&svg);
        let args =
            ["plot", recipe.to_str().unwrap(), "--kind", "section", "-g", "astm-d523-60", "-o", svg.to_str().unwrap()];
        assert_eq!(run_for(&args, 60.0), Some(0), "{name}: {args:?}");
        assert!(std::fs::metadata(&svg).unwrap().len() > 0, "{name}");
        for f in [table, recipe, svg] {
            let _ = std::fs::remove_file(f);
        }
    }
}

/// Found beside the campaign (the same log/linear axis pattern as the section plot): `compare --plot` of a
/// sheet reading 1e308 ± 1e308 never ended (the axis' top, value + uncertainty + 5 % padding, is infinite).
#[test]
fn a_comparison_plot_of_extreme_values_ends() {
    for (name, rows) in [
        ("top", "s,astm-d523-60,gloss,1e308,1e308\n"),
        ("both", "s,astm-d523-60,gloss,-1e308,1\ns,astm-d523-20,gloss,1e308,1\n"),
        ("above", "s,astm-d523-60,gloss,1e308,1\n"),
    ] {
        let sheet = fuzz_cases::scratch(&format!("cmp-{name}.csv"));
        std::fs::write(&sheet, format!("sample,geometry,quantity,value,uncertainty\n{rows}")).unwrap();
        let svg = fuzz_cases::scratch(&format!("cmp-{name}.svg"));
        let _ = std::fs::remove_file(&svg);
        let args = [
            "compare",
            "fixtures/recipes/grey-lambert.json",
            sheet.to_str().unwrap(),
            "--rtol",
            "1e-3",
            "--plot",
            svg.to_str().unwrap(),
        ];
        let code = run_for(&args, 60.0);
        assert!(matches!(code, Some(0 | 1)), "{name}: {code:?} {args:?}");
        assert!(std::fs::metadata(&svg).unwrap().len() > 0, "{name}");
        for f in [sheet, svg] {
            let _ = std::fs::remove_file(f);
        }
    }
}
