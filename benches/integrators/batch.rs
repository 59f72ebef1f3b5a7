//! Batch throughput: recipes per second in pools of 1 and 2.
use std::fmt::Write as _;

use glossmeter::instrument::plan::{Plan, PlanOptions};
use glossmeter::Vec3;

use crate::panel::{panel, total_evaluations};
use crate::report::{fmt_time, timed, try_run};

/// 64 recipes of varying roughness (microfacet if the engine's microfacet model works, else Ward), each
/// parsed, planned and measured over the panel at rtol 1e-6; recipes per second in pools of 1 and 2.
pub(crate) fn batch(md: &mut String, quick: bool) {
    use rayon::prelude::*;
    let n = if quick { 16 } else { 64 };
    let microfacet = |i: usize| -> String {
        let dist = if i.is_multiple_of(2) { "beckmann" } else { "ggx" };
        let r = 0.02 + 0.48 * i as f64 / (n - 1) as f64;
        format!(r#"{{"model": "microfacet", "distribution": "{dist}", "roughness": {r}, "ior": 1.5}}"#)
    };
    let ward = |i: usize| -> String {
        let a = 0.02 + 0.48 * i as f64 / (n - 1) as f64;
        format!(r#"{{"model": "ward", "alpha": {a}, "rho_s": 0.05, "rho_d": 0.3}}"#)
    };
    let probe = glossmeter::recipe::parse_str(&microfacet(0), "probe.json").ok();
    let works = probe
        .and_then(|m| {
            try_run("microfacet recipe", || {
                m.brdf.eval(Vec3::new(-0.3, 0.0, 0.95).normalize(), Vec3::new(0.3, 0.0, 0.95).normalize(), &mut [0.0])
            })
        })
        .is_some();
    let (kind, texts): (&str, Vec<String>) = if works {
        ("microfacet (Beckmann/GGX, roughness 0.02–0.5, n = 1.5)", (0..n).map(microfacet).collect())
    } else {
        ("ward (α 0.02–0.5; the microfacet model was not implemented yet)", (0..n).map(ward).collect())
    };
    let one = |text: &String| -> usize {
        let m = glossmeter::recipe::parse_str(text, "batch.json").expect("batch recipe");
        let plan = Plan::compile(m.brdf, panel(), PlanOptions { rtol: 1e-6, ..Default::default() }).expect("plan");
        total_evaluations(&plan.execute())
    };
    let _ = writeln!(md, "### Batch throughput: {n} {kind} recipes, default panel, rtol 1e-6\n");
    let _ = writeln!(md, "| threads | time | recipes / s | speed-up | runs |");
    let _ = writeln!(md, "|---|---|---|---|---|");
    let mut base = 0.0;
    for k in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(k).build().expect("pool");
        let (_, secs, runs) = timed(|| pool.install(|| texts.par_iter().map(one).sum::<usize>()));
        if k == 1 {
            base = secs;
        }
        let _ = writeln!(md, "| {k} | {} | {:.0} | {:.2}× | {runs} |", fmt_time(secs), n as f64 / secs, base / secs);
    }
}
