//! Lobes about as wide as the stops.
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;

use glossmeter::brdf::Brdf;
use glossmeter::instrument::method::{Chart, Rule, Target};
use glossmeter::instrument::plan::{Plan, PlanOptions};
use glossmeter::instrument::standards::{self, StandardGeometry};

use crate::cases::{rule_label, PANEL};
use crate::report::{date, dirty_src, fmt_time, git_commit, loadavg, timed};

/// Lobes about as wide as the stops (`docs/performance.md` §"Lobes as wide as the stops"): Beckmann and GGX m = 0.003,
/// 0.01, 0.03 (n = 1.5) at D523 20°/60°/85° and E430 30°, the Günther presets
/// (fixtures/materials/guenther-2005) and `cook-torrance-lobes` over the default panel, rtol 1e-6. Per recipe, the
/// specimen integrals' exact evaluation counts with the planner's methods (today: the Genz–Malik partition for all of
/// them), beside two alternatives forced on the same methods in the same run: Genz–Malik on the overlap-kink partition
/// alone (no lobe splits) and the tensor Gauss–Legendre rule with orders shared by the kink partition's boxes
/// (`Chart::Lobe`, falling back to the Genz–Malik partition). For each, the largest actual / estimate over the
/// recipe's integrals against a Genz–Malik run at 10⁻³ of the integral's tolerances (skipping integrals whose flux is
/// below the absolute floor). The limit a rule can reach is measured by independent code (`tools/limit_wide_lobes.py`).
///
/// With `BENCH_JSON=FILE` set, also writes every specimen integral of this section to FILE as JSON (recipe, the
/// readings that use it, the planner's rule, evaluations, value, error estimate, the Genz–Malik run at 10⁻³ of its
/// tolerances, and the two alternatives' evaluations): what `bench/side_by_side.py` reads (`bench/README.md`).
pub(crate) fn wide_lobes(md: &mut String) {
    use glossmeter::instrument::aperture::{lobe_boxes, AxisMap};
    use glossmeter::quadrature::Cell;
    let _ = writeln!(md, "\n## Lobes as wide as the stops (one run; load average at the start {})\n", loadavg());
    let _ = writeln!(md, "| recipe | geometries | specimen integrals | planner: evaluations | time (1 thread) | worst actual/est. | Genz–Malik, kink partition: evaluations | worst actual/est. | tensor GL shared orders, kink partition: evaluations | worst actual/est. |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    let set = ["astm-d523-20", "astm-d523-60", "astm-d523-85", "astm-e430-30"];
    let mut cases: Vec<(String, Arc<dyn Brdf>, Vec<&str>)> = vec![];
    // The microfacet lobes' (distribution, roughness), by recipe name, for the JSON records.
    let mut lobes: std::collections::HashMap<String, (&str, f64)> = Default::default();
    for d in ["beckmann", "ggx"] {
        for m in [0.003, 0.01, 0.03] {
            let text = format!(r#"{{"model":"microfacet","distribution":"{d}","roughness":{m},"ior":1.5}}"#);
            lobes.insert(format!("{d} m = {m}"), (d, m));
            match glossmeter::recipe::parse_str(&text, "wide.json") {
                Ok(r) => cases.push((format!("{d} m = {m}"), r.brdf, set.to_vec())),
                Err(e) => eprintln!("[bench] {d} {m}: {e}"),
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut presets: Vec<_> = std::fs::read_dir(root.join("fixtures/materials/guenther-2005"))
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    presets.sort();
    presets.push(root.join("fixtures/recipes/cook-torrance-lobes.json"));
    for p in presets {
        match glossmeter::recipe::load_file(&p) {
            Ok(r) => cases.push((
                p.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned()),
                r.brdf,
                PANEL.to_vec(),
            )),
            Err(e) => eprintln!("[bench] {}: {e}", p.display()),
        }
    }
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    let opts = PlanOptions { rtol: 1e-6, ..Default::default() };
    let mut totals = [0usize; 3];
    let mut records: Vec<serde_json::Value> = vec![];
    for (name, brdf, geoms) in cases {
        let geo: Vec<StandardGeometry> = geoms.iter().filter_map(|g| standards::find(g).ok()).collect();
        let Ok(plan) = Plan::compile(brdf.clone(), geo, opts.clone()) else { continue };
        let (_, secs, _) = pool.install(|| timed(|| plan.execute()));
        let mut evals = [0usize; 3];
        let mut worst = [0.0f64; 3];
        let mut n = 0;
        for job in plan.jobs.iter().filter(|j| j.method.aperture.target == Target::Specimen) {
            n += 1;
            let mut tight = job.method.clone();
            if let Some(p) = tight.regular.as_mut() {
                (p.rule, p.rtol, p.atol) = (Rule::GenzMalik75, 1e-3 * p.rtol, 1e-3 * p.atol);
            }
            if let Some(p) = tight.delta.as_mut() {
                (p.rtol, p.atol) = (1e-3 * p.rtol, 1e-3 * p.atol);
            }
            let r = tight.execute(brdf.as_ref()).value[0];
            let floor = job.method.regular.as_ref().map_or(0.0, |p| p.atol);
            let mut record = serde_json::json!({
                "recipe": name,
                "distribution": lobes.get(&name).map(|l| l.0),
                "roughness": lobes.get(&name).map(|l| l.1),
                "used_by": job.used_by,
                "rule": rule_label(&job.method, brdf.as_ref()),
                "boxes": job.method.regular.as_ref().map_or(0, |p| p.cells.len()),
                "atol": floor,
                "reference_gm_1e-3": r,
            });
            for (v, slot) in [0usize, 1, 2].into_iter().zip(evals.iter_mut()) {
                let mut m = job.method.clone();
                let clipped = m.clipped;
                if let (Some(p), Some((src, rec))) = (m.regular.as_mut(), clipped) {
                    let eligible = p.chart == Chart::Lobe && p.kinks.is_empty() && p.rule == Rule::GenzMalik75;
                    if eligible && v == 1 {
                        // The range ends and the overlap kinks (as `tensor_boxes` splits the lobe chart).
                        let kinks = |a: AxisMap| a.splits(&[]);
                        let sp = [kinks(AxisMap { s: src.p, r: rec.p }), kinks(AxisMap { s: src.q, r: rec.q })];
                        p.cells = Cell::from_boxes(&lobe_boxes(&sp));
                    }
                    if eligible && v == 2 {
                        p.rule = Rule::TensorGauss { chart: Chart::Lobe, levels: [1; 4], path: Default::default() };
                    }
                }
                let f = m.execute(brdf.as_ref());
                *slot += f.evaluations;
                let actual = (f.value[0] - r).abs();
                if r.abs() > floor && f.error[0] > 0.0 {
                    worst[v] = worst[v].max(actual / f.error[0]);
                }
                let key = ["planner", "gm_kink_partition", "tensor_kink_partition"][v];
                record[key] = serde_json::json!({
                    "evaluations": f.evaluations,
                    "value": f.value[0],
                    "error": f.error[0],
                    "converged": f.converged,
                });
            }
            records.push(record);
        }
        for k in 0..3 {
            totals[k] += evals[k];
        }
        let _ = writeln!(
            md,
            "| {name} | {} | {n} | {} | {} | {:.3} | {} | {:.3} | {} | {:.3} |",
            geoms.len(),
            evals[0],
            fmt_time(secs),
            worst[0],
            evals[1],
            worst[1],
            evals[2],
            worst[2]
        );
    }
    let _ = writeln!(md, "| **total** | | | {} | | | {} | | {} | |", totals[0], totals[1], totals[2]);
    let _ = writeln!(md, "\nLoad average at the end of this section {}.", loadavg());
    if let Some(path) = std::env::var_os("BENCH_JSON") {
        let doc = serde_json::json!({
            "commit": git_commit(),
            "date": date(),
            "uncommitted_src": dirty_src(),
            "rtol": opts.rtol,
            "integrals": records,
        });
        match std::fs::write(&path, serde_json::to_string_pretty(&doc).expect("json")) {
            Ok(()) => eprintln!("[bench] wrote {}", Path::new(&path).display()),
            Err(e) => eprintln!("[bench] could not write {}: {e}", Path::new(&path).display()),
        }
    }
}
