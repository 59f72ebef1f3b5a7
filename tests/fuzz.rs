//! The fuzz campaign in `cargo test` (issue 8): property tests over generated and mutated recipes, geometry
//! files and sheets, in bounded time (a few hundred cases per category, a few seconds). Every case is either
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
