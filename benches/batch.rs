//! Throughput of the batch `measure` (`glossmeter::batch::measure_many`) and of `sweep`
//! (`glossmeter::sweep::Sweep::run`) in rayon pools of 1 and 2 threads (`docs/performance.md` §"Batch and sweep
//! throughput, 1 against 2 threads": ≥ 1.8× on 100 recipes), each beside the way they ran before `Plan::run_all` (the
//! baseline: a parallel loop over recipes, each with a fresh planner and its own parallel loop over its integrals,
//! `Plan::run`; for the sweep, the points in chunks of 16 × threads through `Sweep::run_point`). Plain `main`
//! (harness = false): the configurations take turns, `REPS` rounds (default 11; in each round a strategy's 1- and
//! 2-thread runs are back to back, in alternating order); the median time is reported, and the speed-up as the median
//! of the rounds' own ratios; the readings of every run are compared bit for bit with the 1-thread run of the library
//! path.
//!
//! Beside the wall time: the CPU time of all the process's threads per run, the time they waited on the run
//! queue for a CPU, of the pool's threads (`/proc/self/task/TID/schedstat`, Linux; "n/a" elsewhere), and the idle time, threads ×
//! wall − CPU − wait: the time a pool thread had nothing to do (a serial phase, a tail). On a shared machine
//! the wait is other processes' load, not the program; the "speed-up net of the wait" (CPU + idle on 1
//! thread over (CPU + idle)/2 on 2) is what is left of the ratio without it, the figure that survives load
//! (a thread preempted at the end still shows as the other's idle, so under load it is a lower bound).
//!
//! Run: `cargo bench --bench batch` (at normal priority); the tables go to stdout (copy them to
//! docs/performance.md).
use std::time::Instant;

use glossmeter::batch::measure_many;
use glossmeter::instrument::plan::{Plan, PlanOptions, Reading};
use glossmeter::instrument::standards::StandardGeometry;
use glossmeter::recipe::{self, Material};
use glossmeter::sweep::{parse_vary, PointResult, Sweep, SweepDesign};
use glossmeter::{resolve_geometries, DEFAULT_PANEL};
use rayon::prelude::*;

type Bits = Vec<(Option<u64>, u64, usize)>;

fn bits(rs: &[Vec<Reading>]) -> Bits {
    rs.iter().flatten().map(|r| (r.value.map(f64::to_bits), r.error_estimate.to_bits(), r.evaluations)).collect()
}

/// The order of the thread counts in a round: 1 then 2, then 2 then 1, so that a load that drifts during a
/// round does not always favour the same one.
fn turns(round: usize) -> [usize; 2] {
    if round.is_multiple_of(2) {
        [0, 1]
    } else {
        [1, 0]
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The kernel's ids of a pool's threads (Linux: `/proc/thread-self` links to `PID/task/TID`).
fn thread_ids(pool: &rayon::ThreadPool) -> Option<Vec<String>> {
    let ids = std::sync::Mutex::new(vec![None; pool.current_num_threads()]);
    pool.broadcast(|c| {
        let id = std::fs::read_link("/proc/thread-self").ok().and_then(|l| l.to_str().map(str::to_string));
        ids.lock().unwrap()[c.index()] = id.and_then(|l| l.rsplit('/').next().map(str::to_string));
    });
    ids.into_inner().unwrap().into_iter().collect()
}

/// CPU time and run-queue wait so far (ns) of the threads `ids` (a pool's: the other pool's idle threads
/// and the blocked caller are not counted), if the kernel says.
fn schedstat(ids: &Option<Vec<String>>) -> Option<(u64, u64)> {
    let mut out = (0, 0);
    for t in ids.as_ref()? {
        let s = std::fs::read_to_string(format!("/proc/self/task/{t}/schedstat")).ok()?;
        let mut f = s.split_whitespace().map(|x| x.parse::<u64>().ok());
        out.0 += f.next()??;
        out.1 += f.next()??;
    }
    Some(out)
}

/// Wall seconds, and CPU seconds and run-queue seconds of the threads `ids`, of `f`.
fn timed<T>(ids: &Option<Vec<String>>, f: impl FnOnce() -> T) -> (T, f64, Option<(f64, f64)>) {
    let s0 = schedstat(ids);
    let t = Instant::now();
    let out = f();
    let wall = t.elapsed().as_secs_f64();
    let s1 = schedstat(ids);
    let cpu = s0.zip(s1).map(|(a, b)| ((b.0 - a.0) as f64 * 1e-9, (b.1 - a.1) as f64 * 1e-9));
    (out, wall, cpu)
}

/// The baseline batch: every recipe compiled with its own planner and run with its own parallel loop.
fn nested(materials: &[Material], geos: &[StandardGeometry], opts: &PlanOptions) -> Vec<Vec<Reading>> {
    materials
        .par_iter()
        .map(|m| Plan::compile(m.brdf.clone(), geos.to_vec(), opts.clone()).expect("plan").execute())
        .collect()
}

/// The baseline sweep: chunks of 16 × threads points, each point planned and run alone.
fn sweep_by_point(s: &Sweep, sink: &mut dyn FnMut(PointResult)) {
    let chunk = 16 * rayon::current_num_threads() as u64;
    let mut start = 0;
    while start < s.len() {
        let end = (start + chunk).min(s.len());
        let rs: Vec<PointResult> = (start..end).into_par_iter().map(|i| s.run_point(i)).collect();
        rs.into_iter().for_each(&mut *sink);
        start = end;
    }
}

/// One configuration's runs, round by round.
struct Row {
    threads: usize,
    walls: Vec<f64>,
    /// Per run: (CPU seconds of all threads, their run-queue wait), if the kernel says.
    sched: Vec<Option<(f64, f64)>>,
}

impl Row {
    fn new(threads: usize) -> Row {
        Row { threads, walls: vec![], sched: vec![] }
    }
    fn push(&mut self, wall: f64, sched: Option<(f64, f64)>) {
        self.walls.push(wall);
        self.sched.push(sched);
    }
    /// Per run: (CPU, wait, idle) seconds, idle = threads × wall − CPU − wait (the time the pool's threads
    /// had neither work nor a wait for a CPU: serial phases and tails).
    fn accounts(&self) -> Vec<Option<(f64, f64, f64)>> {
        self.walls
            .iter()
            .zip(&self.sched)
            .map(|(&w, s)| s.map(|(c, q)| (c, q, (self.threads as f64 * w - c - q).max(0.0))))
            .collect()
    }
    fn mean_accounts(&self) -> Option<(f64, f64, f64)> {
        let a: Vec<(f64, f64, f64)> = self.accounts().into_iter().collect::<Option<_>>()?;
        let n = a.len() as f64;
        Some(a.iter().fold((0.0, 0.0, 0.0), |s, x| (s.0 + x.0 / n, s.1 + x.1 / n, s.2 + x.2 / n)))
    }
}

/// The table rows of one section: per strategy and thread count, the median wall time, the throughput over
/// `items`, the median over the rounds of each round's speed-up (the 1- and 2-thread runs of a round are
/// made back to back, so a round's ratio sees the same load), the mean CPU time, run-queue wait and idle time
/// per run, the median over the rounds of the speed-up net of the wait ((CPU + idle) on 1 thread over
/// (CPU + idle)/2 on 2: what the runs would take if no other process wanted the CPUs and the CPU times
/// stayed as measured), and `(size, identical)` from `tail` (evaluations or bytes, and whether the output
/// equals the library path's on 1 thread).
fn print_rows(names: &[&str; 2], rows: &[Vec<Row>], items: f64, tail: impl Fn(usize, usize) -> (usize, bool)) {
    for (s, (name, row)) in names.iter().zip(rows).enumerate() {
        for (k, r) in row.iter().enumerate() {
            let t = median(r.walls.clone());
            let ratio = median(row[0].walls.iter().zip(&r.walls).map(|(a, b)| a / b).collect());
            let (one, this) = (row[0].accounts(), r.accounts());
            let net: Option<Vec<f64>> = one
                .iter()
                .zip(&this)
                .map(|(a, b)| {
                    let (a, b) = (a.as_ref()?, b.as_ref()?);
                    Some((a.0 + a.2) / ((b.0 + b.2) / r.threads as f64))
                })
                .collect();
            let acc = match r.mean_accounts() {
                Some((c, q, i)) => format!("{:.1} ms | {:.1} ms | {:.1} ms", c * 1e3, q * 1e3, i * 1e3),
                None => "n/a | n/a | n/a".into(),
            };
            let net = net.map_or("n/a".into(), |v| format!("{:.2}×", median(v)));
            let (size, identical) = tail(s, k);
            println!(
                "| {} | {} | {:.1} ms | {:.0} | {:.2}× | {} | {} | {} | {} |",
                name,
                r.threads,
                t * 1e3,
                items / t,
                ratio,
                acc,
                net,
                size,
                identical
            );
        }
    }
}

/// The library path's CPU time over the baseline's, per thread count (the median over the rounds).
fn cpu_line(rows: &[Vec<Row>]) {
    for (lib, base) in rows[0].iter().zip(&rows[1]) {
        let r: Option<Vec<f64>> =
            lib.sched.iter().zip(&base.sched).map(|(a, b)| Some(a.as_ref()?.0 / b.as_ref()?.0)).collect();
        if let Some(r) = r {
            println!(
                "\nCPU time of the library path over the baseline's on {} thread(s): {:.3}",
                lib.threads,
                median(r)
            );
        }
    }
}

fn main() {
    let reps: usize = std::env::var("REPS").ok().and_then(|r| r.parse().ok()).unwrap_or(11);
    let n = 100;
    let texts: Vec<String> = (0..n)
        .map(|i| {
            let dist = if i % 2 == 0 { "beckmann" } else { "ggx" };
            let r = 0.02 + 0.48 * i as f64 / (n - 1) as f64;
            format!(r#"{{"model": "microfacet", "distribution": "{dist}", "roughness": {r}, "ior": 1.5}}"#)
        })
        .collect();
    let materials: Vec<_> = texts.iter().map(|t| recipe::parse_str(t, "bench.json").expect("recipe")).collect();
    let geos = resolve_geometries(DEFAULT_PANEL, &[] as &[&str]).expect("panel");
    let opts = PlanOptions { rtol: 1e-6, ..PlanOptions::default() };
    let pools: Vec<rayon::ThreadPool> =
        [1usize, 2].iter().map(|&k| rayon::ThreadPoolBuilder::new().num_threads(k).build().expect("pool")).collect();
    let tids: Vec<Option<Vec<String>>> = pools.iter().map(thread_ids).collect();
    let load = || std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim().to_string();
    println!("load average before: {}\n", load());

    // Batch: (strategy, threads) take turns.
    let names = ["`measure_many` (`Plan::run_all`)", "baseline: nested `Plan::run`"];
    let mut rows: Vec<Vec<Row>> = (0..2).map(|_| (1..=2).map(Row::new).collect()).collect();
    let mut out: Vec<Vec<Bits>> = vec![vec![vec![]; 2]; 2];
    let mut evals = [[0usize; 2]; 2];
    for round in 0..reps {
        for (s, row) in rows.iter_mut().enumerate() {
            for k in turns(round) {
                let (pool, ids) = (&pools[k], &tids[k]);
                let (rs, wall, cpu) = timed(ids, || {
                    pool.install(|| {
                        if s == 0 {
                            measure_many(&materials, &geos, &opts).expect("measure")
                        } else {
                            nested(&materials, &geos, &opts)
                        }
                    })
                });
                row[k].push(wall, cpu);
                evals[s][k] = rs.iter().flatten().map(|r| r.evaluations).sum();
                let b = bits(&rs);
                if !out[s][k].is_empty() && out[s][k] != b {
                    panic!("{} on {} threads: the bits changed between runs", names[s], k + 1);
                }
                out[s][k] = b;
            }
        }
    }
    println!("### Batch `measure`: {n} microfacet recipes (Beckmann/GGX, roughness 0.02–0.5, n = 1.5), default panel, rtol 1e-6, median of {reps}\n");
    println!("| strategy | threads | median time | recipes / s | speed-up (median of the rounds) | CPU time / run | run-queue wait / run | idle / run | speed-up net of the wait | evaluations | bit-identical to `measure_many` on 1 thread |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    print_rows(&names, &rows, n as f64, |s, k| (evals[s][k], out[s][k] == out[0][0]));
    cpu_line(&rows);

    let template: serde_json::Value = serde_json::from_str(&texts[1]).expect("json");
    let axes = vec![parse_vary("/roughness=0.02..0.5:100").expect("axis")];
    let sw = Sweep::new(template, "bench.json", axes, SweepDesign::Grid, geos.clone(), opts.clone()).expect("sweep");
    let names = ["`Sweep::run` (`Plan::run_all` per chunk)", "baseline: chunks of `run_point`"];
    let mut rows: Vec<Vec<Row>> = (0..2).map(|_| (1..=2).map(Row::new).collect()).collect();
    let mut out: Vec<Vec<String>> = vec![vec![String::new(); 2]; 2];
    for round in 0..reps {
        for (s, row) in rows.iter_mut().enumerate() {
            for k in turns(round) {
                let (pool, ids) = (&pools[k], &tids[k]);
                let mut text = String::new();
                let ((), wall, cpu) = timed(ids, || {
                    pool.install(|| {
                        let mut sink = |r: PointResult| text.push_str(&sw.csv_row(&r, false));
                        if s == 0 {
                            sw.run(0..sw.len(), |r| {
                                sink(r);
                                Ok(())
                            })
                            .expect("sweep")
                        } else {
                            sweep_by_point(&sw, &mut sink)
                        }
                    })
                });
                row[k].push(wall, cpu);
                if !out[s][k].is_empty() && out[s][k] != text {
                    panic!("{} on {} threads: the bytes changed between runs", names[s], k + 1);
                }
                out[s][k] = text;
            }
        }
    }
    println!("\n### `sweep`: GGX roughness 0.02..0.5, 100 grid points, default panel, rtol 1e-6, CSV rows without timing, median of {reps}\n");
    println!("| strategy | threads | median time | points / s | speed-up (median of the rounds) | CPU time / run | run-queue wait / run | idle / run | speed-up net of the wait | bytes | byte-identical to `Sweep::run` on 1 thread |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    print_rows(&names, &rows, sw.len() as f64, |s, k| (out[s][k].len(), out[s][k] == out[0][0]));
    cpu_line(&rows);
    println!("\nload average after: {}", load());
}
