//! The cost of a whole plan (`docs/instrument.md` §Output): `Execution::evaluations` and the top-level `"evaluations"`
//! of `measure --format json` count every distinct integral of the plan once, while each reading keeps counting
//! every integral it uses.
mod common;
use std::collections::BTreeSet;
use std::path::Path;
use std::sync::Arc;

use glossmeter::brdf::Brdf;
use glossmeter::instrument::plan::{Execution, Plan, PlanOptions};
use glossmeter::instrument::standards;

fn fixture(name: &str) -> Arc<dyn Brdf> {
    glossmeter::recipe::load_file(Path::new(&format!("fixtures/recipes/{name}"))).unwrap().brdf
}

fn run(name: &str, ids: &[&str]) -> (Plan, Execution) {
    let geos = ids.iter().map(|id| standards::find(id).unwrap()).collect();
    let plan = Plan::compile(fixture(name), geos, PlanOptions::default()).unwrap();
    let exec = plan.run();
    (plan, exec)
}

/// D523 20° and ISO 13803 20° share the gloss receptor (the specimen's integral and the standard's): the
/// plan's count has each once, the readings' counts have them in each reading that uses them.
#[test]
fn a_shared_integral_is_counted_once() {
    for name in ["cerulean-blue-c.json", "rough-dielectric-beckmann.json", "phong.json"] {
        let (plan, exec) = run(name, &["astm-d523-20", "iso-13803-20"]);
        // The sum of the distinct integrals' counts.
        assert_eq!(exec.evaluations(), exec.fluxes.iter().map(|f| f.evaluations).sum::<usize>(), "{name}");
        assert_eq!(exec.fluxes.len(), plan.jobs.len());
        // Each reading's count is the sum over the distinct integrals it uses (none of these is a composite).
        let reported: Vec<_> = plan.readings.iter().filter(|r| r.reported).collect();
        assert_eq!(reported.len(), exec.readings.len());
        let mut used = BTreeSet::new();
        for (p, r) in reported.iter().zip(&exec.readings) {
            let jobs: BTreeSet<usize> = p.specimen_jobs.values().chain(p.standard_jobs.values()).copied().collect();
            assert_eq!(r.evaluations, jobs.iter().map(|&j| exec.fluxes[j].evaluations).sum::<usize>(), "{name}");
            used.extend(jobs);
        }
        // Every integral of the plan is used by a reading, and the shared ones make the plan's count smaller
        // than the readings' sum.
        assert_eq!(used.len(), plan.jobs.len(), "{name}");
        let shared: Vec<&glossmeter::instrument::plan::Job> =
            plan.jobs.iter().filter(|j| j.used_by.len() > 1).collect();
        assert!(!shared.is_empty(), "{name}: the two geometries share the 20° gloss receptor");
        let readings_sum: usize = exec.readings.iter().map(|r| r.evaluations).sum();
        assert!(exec.evaluations() < readings_sum, "{name}: {} vs {readings_sum}", exec.evaluations());

        // Independently: the two geometries planned apart cost A and B; together the shared gloss integrals
        // (what D523 20°'s only reading uses) are paid once, so the plan costs A + B − gloss(D523 20°).
        let (_, a) = run(name, &["astm-d523-20"]);
        let (_, b) = run(name, &["iso-13803-20"]);
        assert_eq!(a.readings.len(), 1);
        assert_eq!(a.evaluations(), a.readings[0].evaluations, "{name}: one reading, its integrals");
        assert_eq!(exec.evaluations(), a.evaluations() + b.evaluations() - a.readings[0].evaluations, "{name}");
    }
}

/// The top-level `"evaluations"` of `measure --format json` is the plan's count, for one recipe and (summed,
/// with each material's own) for many.
#[test]
fn measure_json_reports_the_plan_cost() {
    let gm = |args: &[&str]| -> serde_json::Value {
        let out = common::glossmeter().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let ids = ["astm-d523-20", "iso-13803-20", "astm-e430-30"];
    let mut args = vec!["measure", "fixtures/recipes/cerulean-blue-c.json", "--format", "json", "--no-timing"];
    for id in ids {
        args.extend(["-g", id]);
    }
    let doc = gm(&args);
    let (_, exec) = run("cerulean-blue-c.json", &ids);
    assert_eq!(doc["evaluations"].as_u64(), Some(exec.evaluations() as u64));
    let per_reading: Vec<u64> =
        doc["readings"].as_array().unwrap().iter().map(|r| r["evaluations"].as_u64().unwrap()).collect();
    assert_eq!(
        per_reading,
        exec.readings.iter().map(|r| r.evaluations as u64).collect::<Vec<_>>(),
        "per-reading counts stay"
    );
    assert!(doc["evaluations"].as_u64().unwrap() < per_reading.iter().sum::<u64>());

    let batch = gm(&[
        "measure",
        "fixtures/recipes/cerulean-blue-c.json",
        "fixtures/recipes/phong.json",
        "-g",
        "astm-d523-20",
        "-g",
        "iso-13803-20",
        "--format",
        "json",
        "--no-timing",
    ]);
    let each: Vec<u64> =
        batch["materials"].as_array().unwrap().iter().map(|m| m["evaluations"].as_u64().unwrap()).collect();
    let expect: Vec<u64> = ["cerulean-blue-c.json", "phong.json"]
        .iter()
        .map(|n| run(n, &["astm-d523-20", "iso-13803-20"]).1.evaluations() as u64)
        .collect();
    assert_eq!(each, expect);
    assert_eq!(batch["evaluations"].as_u64(), Some(expect.iter().sum()));
}
