//! Benchmarks of the aperture integrator against the baselines a grid- or sampling-based tool would use
//! (`docs/performance.md`). Plain `main` (harness = false), `std::time::Instant`, every measurement repeated until it
//! has taken ≥ 100 ms in total and reported as the median time per run.
//!
//! Run: `cargo bench --bench integrators` (release). `BENCH_QUICK=1` shrinks the baselines for a smoke
//! test. `BENCH_CASES=B1,B3,NARROW,B5,BATCH,WIDE` runs only the sections named (the cases B1–B4, the narrow-GGX
//! rows, the B5 panel with its side-by-side rule table, the batch throughput, the lobes as wide as the stops); unset, all of them. The Markdown tables go to stdout and to `bench/results/latest.md`; see `bench/README.md` and
//! `docs/performance.md`. `BENCH_JSON=FILE` also writes the specimen integrals of the WIDE section to FILE as JSON
//! (read by `bench/side_by_side.py`).
//!
//! Cases (the specimen flux Φ = ∫_source ∫_receptor f cos θi cos θo dωi dωo through the gloss receptor):
//! * B1 Lambert, albedo 0.5, astm-d523-60: reference = Lambert's closed form (projected solid angles).
//! * B2 Beckmann m = 0.1, n = 1.5, astm-d523-20.
//! * B3 Beckmann m = 1e-4, n = 1.5, astm-d523-20 (a lobe 1e-4 wide inside apertures 1e-2 wide).
//! * B4 GGX α = 0.3, n = 1.5, astm-d523-85.
//!
//!   For B2–B4 the reference is our engine at rtol 1e-12, cross-checked by the baselines where they
//!   converge. The baselines integrate the *same* BRDF object over the plain variables (p_s, q_s, p_r, q_r)
//!   of the stops, with the same cosines and solid-angle densities.
//! * B5 the Cerulean Blue paints (fixtures/recipes/cerulean-blue-{a,b,c}.json) over the default panel, via
//!   the measurement plan, with the plan's ablations; the narrow-flake `-literal` panel with the planner's
//!   methods beside Genz–Malik and the tensor rule forced on every specimen integral (whole panel and per
//!   integral, with where Genz–Malik's refinement goes); and batch throughput over rayon pools of 1 and 2.
//!
//! Every "forced rule" row of every section goes through one helper (`rule_rows`), and says what actually
//! ran (`rule_label`: the final rule and chart of the frozen method, so a fallback shows).
mod b1_b4;
mod b5;
mod baselines;
mod batch;
mod cases;
mod materials;
mod narrow;
mod panel;
mod report;
mod wide;

use std::fmt::Write as _;
use std::path::Path;

use crate::b1_b4::where_the_evaluations_go;
use crate::b5::{b5, b5_rules};
use crate::batch::batch;
use crate::cases::wants;
use crate::narrow::narrow_ggx;
use crate::report::{date, dirty_src, git_commit, loadavg};
use crate::wide::wide_lobes;

fn main() {
    let quick = std::env::var("BENCH_QUICK").is_ok();
    let mut md = String::new();
    let _ = writeln!(md, "# glossmeter integrator benchmarks\n");
    let _ = writeln!(
        md,
        "Commit {} (working tree), {}; load average at start {}; {} logical cores; release build.{}\n",
        git_commit(),
        date(),
        loadavg(),
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(0),
        if quick { " **QUICK mode (reduced baselines)**" } else { "" }
    );
    let _ = writeln!(md, "Uncommitted changes under src/ compiled into this run: {}.\n", dirty_src());

    let cases = b1_b4::cases(&mut md, quick);
    where_the_evaluations_go(&mut md, &cases);
    if wants("NARROW") {
        narrow_ggx(&mut md);
    }
    if wants("B5") {
        b5(&mut md);
        b5_rules(&mut md);
    }
    if wants("BATCH") {
        batch(&mut md, quick);
    }
    if wants("WIDE") {
        wide_lobes(&mut md);
    }

    print!("{md}");
    let out = Path::new(env!("CARGO_MANIFEST_DIR")).join("bench/results/latest.md");
    if let Some(dir) = out.parent() {
        let _ = std::fs::create_dir_all(dir);
    }
    match std::fs::write(&out, &md) {
        Ok(()) => eprintln!("[bench] wrote {}", out.display()),
        Err(e) => eprintln!("[bench] could not write {}: {e}", out.display()),
    }
}
