//! The fuzz driver (issue 8), run by hand:
//!
//! ```text
//! nice cargo run --release --example fuzz -- CASES [SEED] [MEASURE_EVERY]
//! ```
//!
//! It runs CASES cases, round-robin over the four categories of `tests/common/fuzz_cases.rs` (generated
//! recipes, mutated recipes, mutated geometry files, generated and mutated sheets), each replayable from its
//! number and SEED. Every case must be accepted, or refused with an error naming the file and a field or line;
//! a panic or a malformed error is a failure. Every MEASURE_EVERY-th accepted recipe (default 50) is measured
//! on the default panel at rtol 1e-3 with 200 000 evaluations per integral, and every reading must be finite
//! or absent with a reason. It prints a Markdown summary (cases, accepted, refused, failures per category; the
//! slowest measured inputs) for docs/reliability.md.
#[path = "../tests/common/fuzz_cases.rs"]
mod fuzz_cases;

use std::collections::BTreeMap;
use std::time::Instant;

use fuzz_cases::{case_text, check_readings, run_case, Category, Outcome, Rng, Seeds};
use glossmeter::{measure, resolve_geometries, PlanOptions, DEFAULT_PANEL};

#[derive(Default)]
struct Tally {
    cases: usize,
    accepted: usize,
    refused: usize,
    failures: usize,
    measured: usize,
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let cases: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(10_000);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let every: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(50);
    std::panic::set_hook(Box::new(|_| {}));
    let seeds = Seeds::load();
    let panel = resolve_geometries(DEFAULT_PANEL, &[] as &[&str]).unwrap();
    let opts = PlanOptions { rtol: 1e-3, max_evals: 200_000, ..PlanOptions::default() };
    let mut tally: BTreeMap<Category, Tally> = BTreeMap::new();
    let mut failures: Vec<String> = Vec::new();
    let mut slowest: Vec<(f64, String)> = Vec::new();
    let mut accepted_recipes = 0usize;
    let start = Instant::now();
    for k in 0..cases {
        let cat = Category::ALL[k % 4];
        let mut rng = Rng::new(seed.wrapping_mul(1_000_003).wrapping_add(k as u64));
        let text = case_text(cat, &seeds, &mut rng);
        let t = tally.entry(cat).or_default();
        t.cases += 1;
        match std::panic::catch_unwind(|| run_case(cat, &text)) {
            Err(_) => {
                t.failures += 1;
                failures.push(format!("case {k} ({}): panic on {text:?}", cat.name()));
            }
            Ok(Err(e)) => {
                t.failures += 1;
                failures.push(format!("case {k} ({}): {e}", cat.name()));
            }
            Ok(Ok(Outcome::Refused)) => t.refused += 1,
            Ok(Ok(Outcome::Accepted(m))) => {
                t.accepted += 1;
                if let Some(m) = m {
                    accepted_recipes += 1;
                    if accepted_recipes % every == 0 {
                        t.measured += 1;
                        let t0 = Instant::now();
                        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| measure(&m, &panel, &opts)));
                        let secs = t0.elapsed().as_secs_f64();
                        let verdict = match r {
                            Err(_) => Err("panic while measuring".to_string()),
                            Ok(Err(e)) => Err(format!("measure failed: {e}")),
                            Ok(Ok(readings)) => check_readings(&readings),
                        };
                        if let Err(e) = verdict {
                            t.failures += 1;
                            failures.push(format!("case {k} ({}): {e} on {text:?}", cat.name()));
                        }
                        slowest.push((secs, format!("case {k}: {}", text.replace('\n', " "))));
                        slowest.sort_by(|a, b| b.0.total_cmp(&a.0));
                        slowest.truncate(5);
                    }
                }
            }
        }
        if (k + 1) % 100_000 == 0 {
            eprintln!("{} cases, {:.0} s", k + 1, start.elapsed().as_secs_f64());
        }
    }
    println!("Fuzz run: {cases} cases, seed {seed}, {:.0} s wall\n", start.elapsed().as_secs_f64());
    println!("| category | cases | accepted | refused | measured (default panel) | failures |");
    println!("|---|---|---|---|---|---|");
    for (cat, t) in &tally {
        println!("| {} | {} | {} | {} | {} | {} |", cat.name(), t.cases, t.accepted, t.refused, t.measured, t.failures);
    }
    println!("\nSlowest measured inputs (default panel, rtol 1e-3, 200 000 evaluations per integral):\n");
    for (s, t) in &slowest {
        let t: String = t.chars().take(160).collect();
        println!("- {s:.2} s: `{t}`");
    }
    println!("\nFailures: {}", failures.len());
    for f in failures.iter().take(20) {
        println!("- {f}");
    }
}
