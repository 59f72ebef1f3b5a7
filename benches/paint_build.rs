//! Time to build a paint with a rough clear coat (issue 9 item 5: "building a rough paint stays under
//! 10 ms"), beside the same paint with a smooth coat (the baseline: no coat albedo table), in the same run.
//! The rough coat's cost is its directional-albedo table E(μ) (`optics::coat_albedo`): a fixed rule, so its
//! lobe evaluations are an exact count, printed beside the time.
//!
//! Plain `main` (harness = false), `std::time::Instant`: each case is built repeatedly for ≥ 200 ms and the
//! median of the per-build times is reported. Run: `nice -n 10 cargo bench --bench paint_build`; the table
//! goes to stdout (copy it to docs/performance.md with the load average).
use std::time::Instant;

use glossmeter::optics::coat_albedo::CoatAlbedo;
use glossmeter::optics::microfacet::{Distribution, Microfacet};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let base: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("fixtures/recipes/solid-white.json").expect("fixture"))
            .expect("json");
    let eta = base["clear_coat"]["index"].as_f64().unwrap_or(1.5);
    println!("### Building a paint (fixtures/recipes/solid-white.json, coat index {eta}) with a rough clear coat\n");
    println!("| coat | median build time | builds timed | coat-albedo lobe evaluations |");
    println!("|---|---|---|---|");
    let cases: &[(&str, f64)] = &[
        ("beckmann", 0.0),
        ("beckmann", 0.01),
        ("beckmann", 0.05),
        ("beckmann", 0.3),
        ("beckmann", 1.0),
        ("ggx", 0.02),
        ("ggx", 0.1),
        ("ggx", 0.5),
    ];
    for &(dist, alpha) in cases {
        let mut v = base.clone();
        v["clear_coat"]["roughness"] = alpha.into();
        v["clear_coat"]["distribution"] = dist.into();
        let text = serde_json::to_string(&v).expect("json");
        let mut times = vec![];
        let start = Instant::now();
        while start.elapsed().as_secs_f64() < 0.2 || times.len() < 5 {
            let t = Instant::now();
            let m = glossmeter::recipe::parse_str(&text, "bench.json").expect("recipe");
            times.push(t.elapsed().as_secs_f64());
            std::hint::black_box(m);
        }
        let d = if dist == "ggx" { Distribution::Ggx } else { Distribution::Beckmann };
        let evals = if alpha > 0.0 {
            CoatAlbedo::new(&Microfacet::new(d, alpha), eta)
                .map_or("table refused".into(), |t| t.evaluations.to_string())
        } else {
            "0 (smooth: no table)".into()
        };
        let label = if alpha > 0.0 { format!("{dist} {alpha}") } else { "smooth (baseline)".into() };
        println!("| {label} | {:.2} ms | {} | {evals} |", median(times.clone()) * 1e3, times.len());
    }
}
