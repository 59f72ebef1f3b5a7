//! The documented 6-parameter two-lobe fit (`docs/performance.md` §Fit) on one thread and on two, in the same
//! run: wall time, the process's CPU time (user + system, from `/proc/self/stat` on Linux; "—"
//! elsewhere), exact forward-run counts, and whether the two reports are the same bits.
//!
//! Plain `main` (harness = false): each case runs `FIT_BENCH_REPEATS` times (default 1; a fit is seconds) in a
//! local rayon pool, and the median wall time is reported. The machine's load average is printed beside it:
//! on a shared machine the wall-time speed-up is bounded by the cores actually free. Run:
//! `cargo bench --bench fit`; copy the table to docs/performance.md §Converging again, and in parallel.
use std::time::Instant;

use glossmeter::fit::{fit, FitOptions, FitReport, FreeParameter, TargetReading};

const FREE: [&str; 6] = [
    "/lobes/0/ks=0.01..0.5",
    "/lobes/0/r=0.01..1",
    "/lobes/0/m=log:0.05..1",
    "/lobes/1/ks=0.01..0.5",
    "/lobes/1/r=0.01..1",
    "/lobes/1/m=log:0.002..0.05",
];

const TARGETS: [&str; 6] = [
    "astm-d523-20/gloss=4.1710866589983855±0.05",
    "astm-d523-60/gloss=9.249996919020543±0.05",
    "astm-d523-85/gloss=6.125263942815233±0.05",
    "astm-e430-30/haze-narrow=0.06987461790651268±0.01",
    "astm-e430-30/haze-wide=0.04787939877399124±0.01",
    "astm-e430-30/doi=5.844518030248825±0.05",
];

/// The process's CPU seconds so far (utime + stime of /proc/self/stat, in clock ticks of 1/100 s).
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let after = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = after.split_whitespace().collect();
    let (u, s): (f64, f64) = (f.get(11)?.parse().ok()?, f.get(12)?.parse().ok()?);
    Some((u + s) / 100.0)
}

fn load() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or("—".into())
}

fn main() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let start: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root.join("fixtures/inverse/two-lobe-start.json")).unwrap())
            .unwrap();
    let free: Vec<FreeParameter> = FREE.iter().map(|s| FreeParameter::parse(s).unwrap()).collect();
    let targets: Vec<TargetReading> = TARGETS.iter().map(|s| TargetReading::parse(s).unwrap()).collect();
    let repeats: usize = std::env::var("FIT_BENCH_REPEATS").ok().and_then(|s| s.parse().ok()).unwrap_or(1).max(1);
    println!("### The 6-parameter two-lobe fit on 1 and 2 threads (load average before: {})\n", load());
    println!(
        "| threads | forward runs | converged | χ² | wall (median of {repeats}) | CPU (user + sys) | load after |"
    );
    println!("|---:|---:|---|---:|---:|---:|---|");
    let mut reports: Vec<String> = Vec::new();
    let mut walls = Vec::new();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let mut times = Vec::new();
        let mut cpu = Vec::new();
        let mut last: Option<FitReport> = None;
        for _ in 0..repeats {
            let (c0, t0) = (cpu_seconds(), Instant::now());
            let r =
                pool.install(|| fit(&start, "two-lobe-start.json", &free, &targets, &FitOptions::default()).unwrap());
            times.push(t0.elapsed().as_secs_f64());
            cpu.push(cpu_seconds().zip(c0).map(|(a, b)| a - b));
            last = Some(r);
        }
        times.sort_by(f64::total_cmp);
        let wall = times[times.len() / 2];
        walls.push(wall);
        let mut r = last.unwrap();
        let cpu = cpu[cpu.len() / 2].map_or("—".to_string(), |c| format!("{c:.2} s"));
        println!(
            "| {threads} | {} | {} | {:.3e} | {wall:.2} s | {cpu} | {} |",
            r.evaluations,
            r.converged,
            r.chi2,
            load()
        );
        r.seconds = 0.0;
        reports.push(format!("{r:?}"));
    }
    println!(
        "\nspeed-up, 2 threads over 1: {:.2}×; the two reports are {}",
        walls[0] / walls[1],
        if reports[0] == reports[1] { "the same bits" } else { "DIFFERENT" }
    );
}
