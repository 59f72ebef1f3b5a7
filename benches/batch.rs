//! Throughput of the batch `measure` (`glossmeter::batch::measure_many`) and of `sweep`
//! (`glossmeter::sweep::Sweep::run`) in rayon pools of 1 and 2 threads (issue 12, item 5: ≥ 1.8× on 100
//! recipes), each beside the way they ran before `Plan::run_all` (the baseline: a parallel loop over recipes,
//! each with a fresh planner and its own parallel loop over its integrals, `Plan::run`; for the sweep, the
//! points in chunks of 16 × threads through `Sweep::run_point`). Plain `main` (harness = false): the
//! configurations take turns, `REPS` rounds (default 11); the median is reported, and the readings of every
//! run are compared bit for bit with the 1-thread run of the library path.
//!
//! Beside the wall time: the CPU time of all the process's threads per run and the time they waited on the
//! run queue for a CPU (`/proc/self/task/*/schedstat`, Linux; "n/a" elsewhere). On a shared machine the wait
//! says how much of a 2-thread time is other processes' load rather than the program.
//!
//! Run: `nice cargo bench --bench batch`; the tables go to stdout (copy them to docs/performance.md).
use std::time::Instant;

use glossmeter::batch::measure_many;
use glossmeter::instrument::plan::{Plan, PlanOptions, Reading};
use glossmeter::instrument::standards::StandardGeometry;
use glossmeter::recipe::{self, Material};
use glossmeter::sweep::{parse_vary, Design, PointResult, Sweep};
use glossmeter::{resolve_geometries, DEFAULT_PANEL};
use rayon::prelude::*;

type Bits = Vec<(Option<u64>, u64, usize)>;

fn bits(rs: &[Vec<Reading>]) -> Bits {
    rs.iter().flatten().map(|r| (r.value.map(f64::to_bits), r.error_estimate.to_bits(), r.evaluations)).collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// CPU time and run-queue wait of every thread of the process so far (ns), if the kernel says.
fn schedstat() -> Option<(u64, u64)> {
    let mut out = (0, 0);
    for t in std::fs::read_dir("/proc/self/task").ok()? {
        let s = std::fs::read_to_string(t.ok()?.path().join("schedstat")).ok()?;
        let mut f = s.split_whitespace().map(|x| x.parse::<u64>().ok());
        out.0 += f.next()??;
        out.1 += f.next()??;
    }
    Some(out)
}

/// Wall seconds, CPU seconds and run-queue seconds of `f`.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64, Option<(f64, f64)>) {
    let s0 = schedstat();
    let t = Instant::now();
    let out = f();
    let wall = t.elapsed().as_secs_f64();
    let s1 = schedstat();
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

struct Row {
    walls: Vec<f64>,
    cpus: Vec<f64>,
    waits: Vec<f64>,
}

impl Row {
    fn new() -> Row {
        Row { walls: vec![], cpus: vec![], waits: vec![] }
    }
    fn push(&mut self, wall: f64, cpu: Option<(f64, f64)>) {
        self.walls.push(wall);
        if let Some((c, w)) = cpu {
            self.cpus.push(c);
            self.waits.push(w);
        }
    }
    fn cpu(&self) -> String {
        if self.cpus.is_empty() {
            return "n/a | n/a".into();
        }
        let n = self.cpus.len() as f64;
        format!(
            "{:.1} ms | {:.1} ms",
            self.cpus.iter().sum::<f64>() / n * 1e3,
            self.waits.iter().sum::<f64>() / n * 1e3
        )
    }
}

/// The table rows of one section: per strategy and thread count, the median wall time, the throughput over
/// `items`, the speed-up over the same strategy on 1 thread, CPU and wait, and `(size, identical)` from `tail`
/// (evaluations or bytes, and whether the output equals the library path's on 1 thread).
fn print_rows(names: &[&str; 2], rows: &[Vec<Row>], items: f64, tail: impl Fn(usize, usize) -> (usize, bool)) {
    for (s, (name, row)) in names.iter().zip(rows).enumerate() {
        let t1 = median(row[0].walls.clone());
        for (k, r) in row.iter().enumerate() {
            let t = median(r.walls.clone());
            let (size, identical) = tail(s, k);
            println!(
                "| {} | {} | {:.1} ms | {:.0} | {:.2}× | {} | {} | {} |",
                name,
                k + 1,
                t * 1e3,
                items / t,
                t1 / t,
                r.cpu(),
                size,
                identical
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
    let load = || std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim().to_string();
    println!("load average before: {}\n", load());

    // Batch: (strategy, threads) take turns.
    let names = ["`measure_many` (`Plan::run_all`)", "baseline: nested `Plan::run`"];
    let mut rows: Vec<Vec<Row>> = (0..2).map(|_| (0..2).map(|_| Row::new()).collect()).collect();
    let mut out: Vec<Vec<Bits>> = vec![vec![vec![]; 2]; 2];
    let mut evals = [[0usize; 2]; 2];
    for _ in 0..reps {
        for (s, row) in rows.iter_mut().enumerate() {
            for (k, pool) in pools.iter().enumerate() {
                let (rs, wall, cpu) = timed(|| {
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
    println!("| strategy | threads | median time | recipes / s | speed-up (same strategy) | CPU time / run | run-queue wait / run | evaluations | bit-identical to `measure_many` on 1 thread |");
    println!("|---|---|---|---|---|---|---|---|---|");
    print_rows(&names, &rows, n as f64, |s, k| (evals[s][k], out[s][k] == out[0][0]));

    let template: serde_json::Value = serde_json::from_str(&texts[1]).expect("json");
    let axes = vec![parse_vary("/roughness=0.02..0.5:100").expect("axis")];
    let sw = Sweep::new(template, "bench.json", axes, Design::Grid, geos.clone(), opts.clone()).expect("sweep");
    let names = ["`Sweep::run` (`Plan::run_all` per chunk)", "baseline: chunks of `run_point`"];
    let mut rows: Vec<Vec<Row>> = (0..2).map(|_| (0..2).map(|_| Row::new()).collect()).collect();
    let mut out: Vec<Vec<String>> = vec![vec![String::new(); 2]; 2];
    for _ in 0..reps {
        for (s, row) in rows.iter_mut().enumerate() {
            for (k, pool) in pools.iter().enumerate() {
                let mut text = String::new();
                let ((), wall, cpu) = timed(|| {
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
    println!("| strategy | threads | median time | points / s | speed-up (same strategy) | CPU time / run | run-queue wait / run | bytes | byte-identical to `Sweep::run` on 1 thread |");
    println!("|---|---|---|---|---|---|---|---|---|");
    print_rows(&names, &rows, sw.len() as f64, |s, k| (out[s][k].len(), out[s][k] == out[0][0]));
    println!("\nload average after: {}", load());
}
