//! Time to build a paint with a rough clear coat (`docs/performance.md` §"Building a rough paint": under
//! the 10 ms target), beside the same paint with a smooth coat (the baseline: no coat albedo), in the same run.
//! A rough coat's E(μ) comes from the shipped table (`optics::coat_albedo`): its build sums a fixed number of
//! table coefficients (printed, exact) and evaluates no lobe; for comparison the same E from the reference
//! rule (`CoatAlbedo::from_rule`, what the table was generated from) is timed on two coats, with its lobe
//! evaluations (exact).
//!
//! Plain `main` (harness = false), `std::time::Instant`: each case is built repeatedly for ≥ 200 ms and the
//! median of the per-build times is reported. Run at normal priority: `cargo bench --bench paint_build`; the
//! table goes to stdout (copy it to docs/performance.md with the load average). `PAINT_BUILD=sweep` runs only
//! the sweep-point rows (`sweep_points`).
use std::time::Instant;

use glossmeter::brdf::paint::{Paint, PaintBuild, TableBuild, TableMemo, TableWork};
use glossmeter::optics::coat_albedo::CoatAlbedo;
use glossmeter::optics::microfacet::{Distribution, Microfacet};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Sets one field of a recipe.
type Setter = Box<dyn Fn(&mut serde_json::Value, f64)>;

/// A sweep point's paint built from its recipe text as `Sweep::plan_point` builds it (the JSON read, the spec
/// validated, the paint built), built as `build` says (how the flake tables are fitted, in which memo), with the
/// film-stack work that build did.
fn build_paint(text: &str, build: PaintBuild<'_>) -> (Paint, TableWork) {
    let json = glossmeter::input::json::parse_json(text, "bench.json").expect("json");
    let obj = glossmeter::input::json::Obj::new("bench.json", "", &json).expect("object");
    let spec = glossmeter::recipe::paint::parse_paint_spec(&obj).expect("recipe");
    Paint::build(spec, build).expect("paint")
}

/// What one sweep point rebuilds (`docs/performance.md` §"Paint rebuilds in sweeps"): the recipe of a point is
/// parsed and its paint built anew (`Sweep::plan_point` → `recipe::parse_str` → `Paint::new`), so the median time of
/// building a paint fixture whose one field alternates between two values is what a sweep over that field pays per
/// point before its integrals. Rows: the coat index (every flake table depends on it: a metal flake's relative index
/// (n + ik)/η, the pearl stack's surrounding resin η) and the flake area ratio (no table depends on it).
fn sweep_points() {
    println!("### What a sweep point rebuilds: building a paint whose one field alternates between two values\n");
    println!(
        "| fixture | field | values | no memo, tables per sample | memo, tables per sample (before) | memo, \
         samples at once (after) | builds timed each | stack set-ups / ρ(μ, λ) a point, before → after |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let fixtures = [
        "cerulean-blue-c",
        "cerulean-blue-c-literal",
        "white-pearl",
        "white-pearl-spectral",
        "blue-metallic-spectral",
        "silver-metallic",
    ];
    for f in fixtures {
        let Ok(text) = std::fs::read_to_string(format!("fixtures/recipes/{f}.json")) else { continue };
        let Ok(base) = serde_json::from_str::<serde_json::Value>(&text) else { continue };
        let area = ["metallic_flakes", "pearlescent_flakes"].into_iter().find(|k| base.get(*k).is_some());
        let mut fields: Vec<(String, [f64; 2], Setter)> =
            vec![("/clear_coat/index".into(), [1.5, 1.52], Box::new(|v, x| v["clear_coat"]["index"] = x.into()))];
        if let Some(k) = area {
            let a0 = base[k]["area_ratio"].as_f64().unwrap_or(0.3);
            fields.push((
                format!("/{k}/area_ratio"),
                [a0, 0.9 * a0],
                Box::new(move |v, x| v[k]["area_ratio"] = x.into()),
            ));
        }
        for (name, values, set) in fields {
            let texts: Vec<String> = values
                .iter()
                .map(|&x| {
                    let mut v = base.clone();
                    set(&mut v, x);
                    serde_json::to_string(&v).expect("json")
                })
                .collect();
            // Interleaved: a build without a memo, tables one sample at a time (every table computed, the engine
            // before both), one with a memo and tables one sample at a time (the engine before `docs/model.md`
            // §Evaluation cost "shared across samples"), one with a memo and the samples fitted at once (after).
            // A memo build is timed right after an untimed build of the other value into a fresh memo of its own
            // (which then holds what a sweep's previous point left), the values alternating. The process's memo
            // is never read.
            let modes = [(true, TableBuild::PerSample), (false, TableBuild::PerSample), (false, TableBuild::Shared)];
            let mut times: [Vec<f64>; 3] = Default::default();
            let mut work = [TableWork::default(); 3];
            let start = Instant::now();
            let mut i = 0;
            while start.elapsed().as_secs_f64() < 0.9 || times[2].len() < 6 {
                for (m, &(cold, tables)) in modes.iter().enumerate() {
                    let memo = TableMemo::new();
                    let build = PaintBuild { tables, memo: (!cold).then_some(&memo) };
                    if !cold {
                        std::hint::black_box(build_paint(&texts[(i + 1) % 2], build));
                    }
                    let t = Instant::now();
                    let b = build_paint(&texts[i % 2], build);
                    let dt = t.elapsed().as_secs_f64();
                    times[m].push(dt);
                    work[m] = b.1;
                    std::hint::black_box(b);
                }
                i += 1;
            }
            let n = times[2].len();
            let [cold, before, after] = times.map(median);
            println!(
                "| {f} | `{name}` | {} / {} | {:.3} ms | {:.3} ms | {:.3} ms | {n} | {} / {} → {} / {} |",
                values[0],
                values[1],
                cold * 1e3,
                before * 1e3,
                after * 1e3,
                work[1].stack_setups,
                work[1].stack_evaluations,
                work[2].stack_setups,
                work[2].stack_evaluations
            );
        }
    }
    println!();
}

/// What a coat-index sweep point costs at every coat index from 1.3 to 1.8 (`docs/performance.md` §"Coat-index
/// points from 1.3 to 1.8"): each shipped paint with flakes, its coat index set to η, built with an empty memo
/// (a coat-index point always misses it: every flake table depends on η), the median of the build times; beside it
/// the ratio to the cost at η = 1.5 and whether every flake is read from its tables (`Paint::flake_tables`) or
/// evaluated directly; η in steps of 0.02 (`PAINT_COAT_STEP=0.01`: every coat index of `tests/paint.rs`), and the
/// film-stack reflectances ρ(μ, λ) a build computes (`TableWork`, exact) against η = 1.5. `PAINT_BUILD=coat`.
fn coat_index_points() {
    println!("### A coat-index sweep point from 1.3 to 1.8: building the paint with its coat index set to η\n");
    let fixtures = [
        "cerulean-blue-b-literal",
        "cerulean-blue-c",
        "cerulean-blue-c-literal",
        "white-pearl",
        "white-pearl-spectral",
        "blue-metallic-spectral",
        "silver-metallic",
    ];
    let step = if std::env::var("PAINT_COAT_STEP").is_ok_and(|v| v == "0.01") { 1 } else { 2 };
    let etas: Vec<f64> = (0..=50 / step).map(|i| ((130 + step * i) as f64) / 100.0).collect();
    print!("| fixture | η = 1.5 |");
    for e in &etas {
        print!(" {e:.2} |");
    }
    println!(" worst / η = 1.5 | builds timed each | ρ(μ, λ) at η = 1.5, worst / η = 1.5 (at η) |");
    println!("|---|---|{}---|---|---|", "---|".repeat(etas.len()));
    for f in fixtures {
        let Ok(text) = std::fs::read_to_string(format!("fixtures/recipes/{f}.json")) else { continue };
        let Ok(base) = serde_json::from_str::<serde_json::Value>(&text) else { continue };
        let time_at = |eta: f64| -> (f64, usize, bool, u64) {
            let mut v = base.clone();
            v["clear_coat"]["index"] = eta.into();
            let t = serde_json::to_string(&v).expect("json");
            let mut times = vec![];
            let mut tabulated = true;
            let mut rho = 0;
            let start = Instant::now();
            while start.elapsed().as_secs_f64() < 0.25 || times.len() < 3 {
                let t0 = Instant::now();
                let (p, work) = build_paint(&t, PaintBuild { tables: TableBuild::Shared, memo: None });
                times.push(t0.elapsed().as_secs_f64());
                rho = work.stack_evaluations;
                tabulated &= p.flake_tables().iter().all(|(_, d)| d.is_some());
                std::hint::black_box(p);
            }
            (median(times.clone()), times.len(), tabulated, rho)
        };
        let (at_15, _, _, rho_15) = time_at(1.5);
        print!("| {f} | {:.3} ms |", at_15 * 1e3);
        let mut worst: f64 = 0.0;
        let mut fewest = usize::MAX;
        let (mut rho_worst, mut rho_at) = (rho_15, 1.5);
        for &e in &etas {
            let (t, n, tabulated, rho) = time_at(e);
            worst = worst.max(t / at_15);
            fewest = fewest.min(n);
            if rho > rho_worst {
                (rho_worst, rho_at) = (rho, e);
            }
            print!(" {:.3}{} |", t * 1e3, if tabulated { "" } else { " (direct)" });
        }
        let ratio =
            if rho_15 > 0 { format!("{:.2}× ({rho_at:.2})", rho_worst as f64 / rho_15 as f64) } else { "-".into() };
        println!(" {worst:.2}× | ≥ {fewest} | {rho_15}, {ratio} |");
    }
    println!("\n(ms a build; \"(direct)\": a flake evaluated directly, no table met 10⁻¹²)\n");
}

fn main() {
    if std::env::var("PAINT_BUILD").is_ok_and(|v| v == "sweep") {
        sweep_points();
        return;
    }
    if std::env::var("PAINT_BUILD").is_ok_and(|v| v == "coat") {
        coat_index_points();
        return;
    }
    let base: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("fixtures/recipes/solid-white.json").expect("fixture"))
            .expect("json");
    let eta = base["clear_coat"]["index"].as_f64().unwrap_or(1.5);
    // The first table use in the process parses the compiled-in table once.
    let t = Instant::now();
    let first = CoatAlbedo::new(&Microfacet::new(Distribution::Beckmann, 0.1), eta).expect("in range");
    let first_ms = t.elapsed().as_secs_f64() * 1e3;
    std::hint::black_box(first);
    let (kept, rows) = glossmeter::optics::coat_albedo::table_size();
    println!("### Building a paint (fixtures/recipes/solid-white.json, coat index {eta}) with a rough clear coat\n");
    println!("First coat-albedo use in the process (parses the table, {kept} coefficients in {rows} rows): {first_ms:.2} ms\n");
    println!("| coat | median build time | builds timed | lobe evaluations | table coefficients summed |");
    println!("|---|---|---|---|---|");
    let cases: &[(&str, f64)] = &[
        ("beckmann", 0.0),
        ("beckmann", 1e-5),
        ("beckmann", 0.01),
        ("beckmann", 0.05),
        ("beckmann", 0.3),
        ("beckmann", 1.0),
        ("ggx", 1e-5),
        ("ggx", 0.02),
        ("ggx", 0.1),
        ("ggx", 0.5),
        ("ggx", 1.0),
        // The baseline again, last: the first case of a run also pays the warm-up.
        ("beckmann", 0.0),
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
        let (evals, terms) = if alpha > 0.0 {
            let a = CoatAlbedo::new(&Microfacet::new(d, alpha), eta).expect("in range");
            (a.evaluations.to_string(), a.table_terms.to_string())
        } else {
            ("0".into(), "0 (smooth: no table)".into())
        };
        let label = if alpha > 0.0 { format!("{dist} {alpha}") } else { "smooth (baseline)".into() };
        println!("| {label} | {:.3} ms | {} | {evals} | {terms} |", median(times.clone()) * 1e3, times.len());
    }
    println!("\nThe same E from the reference rule (CoatAlbedo::from_rule, 126 rule runs; not what a paint does):\n");
    println!("| coat | median time | runs | lobe evaluations |");
    println!("|---|---|---|---|");
    for (d, name, alpha) in [(Distribution::Beckmann, "beckmann", 0.05), (Distribution::Ggx, "ggx", 0.02)] {
        let mf = Microfacet::new(d, alpha);
        let mut times = vec![];
        let mut evals = 0;
        for _ in 0..3 {
            let t = Instant::now();
            let a = CoatAlbedo::from_rule(&mf, eta).expect("finite");
            times.push(t.elapsed().as_secs_f64());
            evals = a.evaluations;
        }
        println!("| {name} {alpha} | {:.1} ms | 3 | {evals} |", median(times) * 1e3);
    }
}
