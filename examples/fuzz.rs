//! The fuzz driver (`docs/reliability.md`), run by hand in release mode (the command-line category runs the binary, so
//! build it first):
//!
//! ```text
//! cargo build --release --bin glossmeter --example fuzz
//! nice -n 19 target/release/examples/fuzz CASES [SEED] [LIGHT_EVERY] [FULL_EVERY] [CLI_EVERY] [FIRST]
//! ```
//!
//! Cases FIRST .. FIRST + CASES are run (FIRST defaults to 0), so a range of a long run can be replayed
//! alone. Each failure is printed on stderr as it happens, and the summary so far every 100 000 cases on
//! stdout, so that a run stopped early still says what it found.
//!
//! It runs CASES cases over the eleven categories of `tests/common/fuzz_cases.rs`: every CLI_EVERY-th case
//! (default 200) is a command line run as a process (`measure`, `compare`, `convergence`, `sweep`, `fit`, `plot`,
//! `profile` with small budgets, `--baseline` files, and the rest); the others go round-robin over recipes
//! generated from the parameter registry or from random fields, mutated recipes, mutated geometry files,
//! generated and mutated sheets, generated and mutated MERL, RGL, in-plane CSV and E1392 tables (read through
//! their recipes), generated and mutated baselines and generated and mutated workbooks (`.xlsx`, `.ods`, `.xls`), checked in the library. Each case is replayable from its
//! number and SEED. Every case must be accepted, or refused with an error naming the file and a field or line
//! (a command line: exit 0, 1 or 2, no panic, no NaN/inf printed outside the quoted input, no file lost or left
//! behind, ended within `CLI_TIMEOUT_S`); anything else is a failure.
//!
//! Accepted recipes and tables are measured on the default panel: every LIGHT_EVERY-th (default 50) with a
//! small budget (rtol 1e-3, 200 000 evaluations per integral, 1 s per plan), every FULL_EVERY-th (default
//! 1000) with the default options of `glossmeter measure` (`PlanOptions::default()`: rtol 1e-6, the default
//! evaluation budget per integral, no wall-clock limit), timed. Every reading must be finite or absent with a
//! reason; a measurement still running after `HANG_S` would be a hang (it is timed, not interrupted: the
//! library has no way to stop it from outside). It prints a Markdown summary for docs/reliability.md.
#[path = "../tests/common/fuzz_cases.rs"]
mod fuzz_cases;

use std::collections::BTreeMap;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use fuzz_cases::{case_text, check_readings, run_case, Category, Outcome, Rng, Seeds, BINARY};
use glossmeter::{measure, resolve_geometries, PlanOptions, DEFAULT_PANEL};

#[derive(Default)]
struct Tally {
    cases: usize,
    accepted: usize,
    refused: usize,
    failures: usize,
    light: usize,
    full: usize,
    unconverged_full: usize,
    seconds: f64,
    slowest_case: f64,
}

/// A case slower than this is named on stderr (not a failure).
const SLOW_S: f64 = 20.0;

/// A measurement slower than this is reported as a hang. The default options bound every integral by its
/// evaluation budget (deterministic), not by time: a measured table whose integrals all run to 2·10⁶ evaluations
/// takes tens of seconds on a loaded machine (49 s seen at a load of ≈ 4 on 2 cores), so the bound is that of a
/// command line, [`fuzz_cases::CLI_TIMEOUT_S`].
const HANG_S: f64 = fuzz_cases::CLI_TIMEOUT_S;

/// The watchdog's bound: a case's own bound ([`HANG_S`], which a command line's timeout enforces) and a margin,
/// so that a command line killed at its timeout is reported by the loop, not by the watchdog.
const WATCHDOG_S: f64 = HANG_S + 30.0;

/// The case running now (its number, its text, when it or its measurement started), for [`watchdog`].
static CURRENT: Mutex<Option<(usize, String, Instant)>> = Mutex::new(None);

/// Mark the case `k` running (or, with `None`, nothing).
fn running(now: Option<(usize, &str)>) {
    *CURRENT.lock().unwrap() = now.map(|(k, text)| (k, text.to_string(), Instant::now()));
}

/// A case that never returns (a reader waiting for good) would stall the loop, which checks a case's time only
/// once it returns: this thread ends the run with the case named once it has run [`WATCHDOG_S`].
fn watchdog() {
    std::thread::spawn(|| loop {
        std::thread::sleep(Duration::from_secs(1));
        if let Some((k, text, t0)) = CURRENT.lock().unwrap().as_ref() {
            if t0.elapsed().as_secs_f64() > WATCHDOG_S {
                eprintln!("FAILURE case {k}: a hang, no answer after {WATCHDOG_S:.0} s on {text:?}");
                std::process::exit(1);
            }
        }
    });
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, d: u64| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let cases = arg(1, 10_000) as usize;
    let seed = arg(2, 1);
    let light_every = arg(3, 50) as usize;
    let full_every = arg(4, 1000) as usize;
    let cli_every = arg(5, 200) as usize;
    let first = arg(6, 0) as usize;
    // target/release/examples/fuzz → target/release/glossmeter
    let exe = std::env::current_exe().unwrap();
    let bin = exe.parent().and_then(|d| d.parent()).unwrap().join("glossmeter");
    assert!(bin.exists(), "{} not built: cargo build --release --bin glossmeter first", bin.display());
    BINARY.set(bin).unwrap();
    std::panic::set_hook(Box::new(|_| {}));
    watchdog();
    let seeds = Seeds::load();
    let panel = resolve_geometries(DEFAULT_PANEL, &[] as &[&str]).unwrap();
    let light = PlanOptions { rtol: 1e-3, max_evals: 200_000, max_seconds: Some(1.0), ..PlanOptions::default() };
    let full = PlanOptions::default();
    let mut tally: BTreeMap<Category, Tally> = BTreeMap::new();
    let mut failures: Vec<String> = Vec::new();
    let mut slowest: Vec<(f64, String)> = Vec::new();
    let mut slowest_light = 0f64;
    let mut over_10s = 0usize;
    let mut accepted_recipes = 0usize;
    let start = Instant::now();
    let in_library = Category::IN_LIBRARY;
    for k in first..first + cases {
        let cat = if k % cli_every == cli_every - 1 {
            Category::CommandLine
        } else {
            in_library[(k - k / cli_every) % in_library.len()]
        };
        let mut rng = Rng::new(seed.wrapping_mul(1_000_003).wrapping_add(k as u64));
        let t0 = Instant::now();
        let text = case_text(cat, &seeds, &mut rng);
        let t = tally.entry(cat).or_default();
        t.cases += 1;
        running(Some((k, &text)));
        let outcome = std::panic::catch_unwind(|| run_case(cat, &text));
        running(None);
        match outcome {
            Err(_) => {
                t.failures += 1;
                failures.push(format!("case {k} ({}): panic on {text:?}", cat.name()));
                eprintln!("FAILURE {}", failures.last().unwrap());
            }
            Ok(Err(e)) => {
                t.failures += 1;
                failures.push(format!("case {k} ({}): {e}", cat.name()));
                eprintln!("FAILURE {}", failures.last().unwrap());
            }
            Ok(Ok(Outcome::Refused)) => t.refused += 1,
            Ok(Ok(Outcome::Accepted(m))) => {
                t.accepted += 1;
                if let Some(m) = m {
                    accepted_recipes += 1;
                    let which = if accepted_recipes.is_multiple_of(full_every) {
                        Some(&full)
                    } else if accepted_recipes.is_multiple_of(light_every) {
                        Some(&light)
                    } else {
                        None
                    };
                    if let Some(opts) = which {
                        let is_full = std::ptr::eq(opts, &full);
                        let t1 = Instant::now();
                        running(Some((k, &text)));
                        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| measure(&m, &panel, opts)));
                        running(None);
                        let secs = t1.elapsed().as_secs_f64();
                        let verdict = match r {
                            Err(_) => Err("panic while measuring".to_string()),
                            Ok(Err(e)) => Err(format!("measure failed: {e}")),
                            Ok(Ok(readings)) => {
                                if is_full && readings.iter().any(|r| !r.converged) {
                                    t.unconverged_full += 1;
                                }
                                check_readings(&readings)
                            }
                        };
                        let verdict =
                            verdict.and_then(
                                |()| {
                                    if secs > HANG_S {
                                        Err(format!("a hang: {secs:.0} s"))
                                    } else {
                                        Ok(())
                                    }
                                },
                            );
                        if let Err(e) = verdict {
                            t.failures += 1;
                            failures.push(format!("case {k} ({}): {e} on {text:?}", cat.name()));
                            eprintln!("FAILURE {}", failures.last().unwrap());
                        }
                        if is_full {
                            t.full += 1;
                            if secs > 10.0 {
                                over_10s += 1;
                            }
                            slowest.push((secs, format!("case {k} ({}): {}", cat.name(), text.replace('\n', " "))));
                            slowest.sort_by(|a, b| b.0.total_cmp(&a.0));
                            slowest.truncate(8);
                        } else {
                            t.light += 1;
                            slowest_light = slowest_light.max(secs);
                        }
                    }
                }
            }
        }
        let dt = t0.elapsed().as_secs_f64();
        if dt > SLOW_S {
            let shown: String = text.chars().take(400).collect();
            eprintln!("SLOW case {k} ({}): {dt:.1} s: {shown}", cat.name());
        }
        t.seconds += dt;
        t.slowest_case = t.slowest_case.max(dt);
        if (k + 1) % 10_000 == 0 {
            eprintln!("{} cases, {:.0} s, {} failures", k + 1, start.elapsed().as_secs_f64(), failures.len());
        }
        if (k + 1 - first).is_multiple_of(100_000) {
            println!("\n## After {} cases\n", k + 1 - first);
            let wall = start.elapsed().as_secs_f64();
            let so_far = Summary { cases: k + 1 - first, seed, first, light_every, full_every, cli_every, wall };
            so_far.print(&tally, slowest_light, over_10s, &slowest, &failures);
        }
    }
    let _ = std::fs::remove_dir_all(fuzz_cases::scratch("x").parent().unwrap());
    println!("\n## Final\n");
    let summary =
        Summary { cases, seed, first, light_every, full_every, cli_every, wall: start.elapsed().as_secs_f64() };
    summary.print(&tally, slowest_light, over_10s, &slowest, &failures);
    // The driver's peak resident memory (every library case runs in this process, workbooks included).
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    if let Some(hwm) = status.lines().find(|l| l.starts_with("VmHWM:")) {
        println!("\nPeak resident memory of the driver: {}", hwm.trim_start_matches("VmHWM:").trim());
    }
    // A campaign that found failures does not pass (docs/reliability.md).
    if !failures.is_empty() {
        std::process::exit(1);
    }
}

struct Summary {
    cases: usize,
    seed: u64,
    first: usize,
    light_every: usize,
    full_every: usize,
    cli_every: usize,
    wall: f64,
}

impl Summary {
    fn print(
        &self,
        tally: &BTreeMap<Category, Tally>,
        slowest_light: f64,
        over_10s: usize,
        slowest: &[(f64, String)],
        failures: &[String],
    ) {
        let Summary { cases, seed, first, light_every, full_every, cli_every, wall } = self;
        println!(
            "Fuzz run: {cases} cases from case {first}, seed {seed}, light every {light_every}, full every \
         {full_every}, command line every {cli_every}; {wall:.0} s wall\n"
        );
        println!(
            "| category | cases | accepted | refused | measured (small budget) | measured (default options) | of \
         them not converged | failures | seconds | slowest case (s) |"
        );
        println!("|---|---|---|---|---|---|---|---|---|---|");
        for (cat, t) in tally {
            println!(
                "| {} | {} | {} | {} | {} | {} | {} | {} | {:.0} | {:.2} |",
                cat.name(),
                t.cases,
                t.accepted,
                t.refused,
                t.light,
                t.full,
                t.unconverged_full,
                t.failures,
                t.seconds,
                t.slowest_case
            );
        }
        println!("\nSlowest small-budget measurement: {slowest_light:.2} s");
        println!("Default-option measurements over 10 s: {over_10s}");
        println!("\nSlowest measured inputs (default panel, default options):\n");
        for (s, t) in slowest {
            let t: String = t.chars().take(300).collect();
            println!("- {s:.2} s: `{t}`");
        }
        println!("\nFailures: {}", failures.len());
        for f in failures.iter().take(40) {
            println!("- {f}");
        }
    }
}
