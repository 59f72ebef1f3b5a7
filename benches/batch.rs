//! Throughput of the batch `measure` (`glossmeter::batch::measure_many`) and of `sweep`
//! (`glossmeter::sweep::Sweep::run`) in rayon pools of 1 and 2 threads (issue 12, item 5: ≥ 1.8× on 100
//! recipes). Plain `main` (harness = false): each configuration runs 5 times, the median is reported, and
//! the readings of every run are compared bit for bit with the 1-thread run.
//!
//! Run: `nice cargo bench --bench batch`; the table goes to stdout (copy it to docs/performance.md).
use std::time::Instant;

use glossmeter::batch::measure_many;
use glossmeter::instrument::plan::{PlanOptions, Reading};
use glossmeter::recipe;
use glossmeter::sweep::{parse_vary, Design, Sweep};
use glossmeter::{resolve_geometries, DEFAULT_PANEL};

fn bits(rs: &[Vec<Reading>]) -> Vec<(Option<u64>, u64, usize)> {
    rs.iter().flatten().map(|r| (r.value.map(f64::to_bits), r.error_estimate.to_bits(), r.evaluations)).collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
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
    println!("### Batch `measure`: {n} microfacet recipes (Beckmann/GGX, roughness 0.02–0.5, n = 1.5), default panel, rtol 1e-6\n");
    println!("| threads | median time (5 runs) | recipes / s | speed-up | evaluations | bit-identical to 1 thread |");
    println!("|---|---|---|---|---|---|");
    let mut base = (0.0, vec![]);
    for k in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(k).build().expect("pool");
        let mut times = vec![];
        let mut last = vec![];
        for _ in 0..5 {
            let t = Instant::now();
            last = pool.install(|| measure_many(&materials, &geos, &opts)).expect("measure");
            times.push(t.elapsed().as_secs_f64());
        }
        let t = median(times);
        let evals: usize = last.iter().flatten().map(|r| r.evaluations).sum();
        if k == 1 {
            base = (t, bits(&last));
        }
        println!(
            "| {k} | {:.1} ms | {:.0} | {:.2}× | {evals} | {} |",
            t * 1e3,
            n as f64 / t,
            base.0 / t,
            bits(&last) == base.1
        );
    }
    let template: serde_json::Value = serde_json::from_str(&texts[1]).expect("json");
    let axes = vec![parse_vary("/roughness=0.02..0.5:100").expect("axis")];
    let s = Sweep::new(template, "bench.json", axes, Design::Grid, geos.clone(), opts.clone()).expect("sweep");
    println!(
        "\n### `sweep`: GGX roughness 0.02..0.5, 100 grid points, default panel, rtol 1e-6, CSV rows without timing\n"
    );
    println!("| threads | median time (5 runs) | points / s | speed-up | bytes | byte-identical to 1 thread |");
    println!("|---|---|---|---|---|---|");
    let mut base = (0.0, String::new());
    for k in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(k).build().expect("pool");
        let mut times = vec![];
        let mut out = String::new();
        for _ in 0..5 {
            out.clear();
            let t = Instant::now();
            pool.install(|| {
                s.run(0..s.len(), |r| {
                    out.push_str(&s.csv_row(&r, false));
                    Ok(())
                })
            })
            .expect("sweep");
            times.push(t.elapsed().as_secs_f64());
        }
        let t = median(times);
        if k == 1 {
            base = (t, out.clone());
        }
        println!(
            "| {k} | {:.1} ms | {:.0} | {:.2}× | {} | {} |",
            t * 1e3,
            100.0 / t,
            base.0 / t,
            out.len(),
            out == base.1
        );
    }
}
