//! Reproducibility (`docs/instrument.md` §Quadrature, "Determinism"): the same readings, bit for bit, whatever the
//! number of threads the plan runs on, and from one run to the next in the same thread. Compared: `f64::to_bits` of
//! every value and error estimate, the evaluation counts and the convergence flags.
mod common;
use common::TestBeckmann;
use std::path::Path;
use std::sync::Arc;

use glossmeter::brdf::Brdf;
use glossmeter::instrument::plan::{Plan, PlanOptions, Reading};
use glossmeter::instrument::standards::{self, StandardGeometry};
use glossmeter::spectrum::Sampling;

/// The default panel of the CLI.
const PANEL: &[&str] = glossmeter::DEFAULT_PANEL;

fn panel() -> Vec<StandardGeometry> {
    PANEL.iter().map(|id| standards::find(id).unwrap()).collect()
}

/// What must be identical, as bits.
#[derive(Debug, PartialEq, Eq)]
struct Bits {
    geometry: String,
    name: String,
    value: Option<u64>,
    error: u64,
    evaluations: usize,
    converged: bool,
}

fn bits(r: &[Reading]) -> Vec<Bits> {
    r.iter()
        .map(|x| Bits {
            geometry: x.geometry.clone(),
            name: x.name.clone(),
            value: x.value.map(f64::to_bits),
            error: x.error_estimate.to_bits(),
            evaluations: x.evaluations,
            converged: x.converged,
        })
        .collect()
}

fn in_pool(threads: usize, plan: &Plan) -> Vec<Bits> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    bits(&pool.install(|| plan.execute()))
}

/// Execute the plan in pools of 1, 2 and 4 threads and twice in the calling thread; all must agree.
fn check(brdf: Arc<dyn Brdf>, label: &str) {
    let plan = Plan::compile(brdf, panel(), PlanOptions { rtol: 1e-6, ..Default::default() }).unwrap();
    let here = bits(&plan.execute());
    assert!(!here.is_empty(), "{label}: no readings");
    assert!(here.iter().all(|b| b.value.is_some()), "{label}: a reading has no value: {here:?}");
    assert_eq!(here, bits(&plan.execute()), "{label}: two runs in the same thread differ");
    for k in [1, 2, 4] {
        assert_eq!(here, in_pool(k, &plan), "{label}: a pool of {k} thread(s) gives different bits");
    }
}

fn recipe(name: &str) -> Arc<dyn Brdf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/recipes").join(name);
    glossmeter::recipe::load_file(&path).unwrap().brdf
}

#[test]
fn test_beckmann_panel_is_bitwise_reproducible_across_thread_counts() {
    for m in [0.1, 1e-3] {
        check(Arc::new(TestBeckmann { m, n: 1.5, s: Sampling::rgb() }), &format!("test Beckmann m = {m}"));
    }
}

#[test]
fn ward_recipe_is_bitwise_reproducible_across_thread_counts() {
    let m = glossmeter::recipe::parse_str(
        r#"{"model": "ward", "alpha": 0.05, "rho_s": [0.04, 0.05, 0.06], "rho_d": 0.3}"#,
        "ward.json",
    )
    .unwrap();
    check(m.brdf, "ward recipe");
}

#[test]
fn microfacet_recipe_is_bitwise_reproducible_across_thread_counts() {
    let m = glossmeter::recipe::parse_str(
        r#"{"model": "microfacet", "distribution": "ggx", "roughness": 0.05, "ior": 1.5}"#,
        "mf.json",
    )
    .unwrap();
    check(m.brdf, "microfacet recipe");
}

#[test]
fn cerulean_blue_a_is_bitwise_reproducible_across_thread_counts() {
    check(recipe("cerulean-blue-a.json"), "cerulean-blue-a");
}

#[test]
fn cerulean_blue_c_is_bitwise_reproducible_across_thread_counts() {
    check(recipe("cerulean-blue-c.json"), "cerulean-blue-c");
}

/// Running many plans as one flat loop of integrals (`Plan::run_all`, behind the batch `measure` and `sweep`;
/// `docs/instrument.md` §Many recipes) gives every plan the bits of its own `Plan::run`, fluxes included, on 1, 2 and 4
/// threads; and a batch through one shared planner (`batch::measure_many`) the bits of one-by-one plans.
#[test]
fn many_plans_in_one_flat_loop_give_each_plans_own_bits() {
    let brdfs: Vec<Arc<dyn Brdf>> = vec![
        recipe("cerulean-blue-a.json"),
        Arc::new(TestBeckmann { m: 1e-3, n: 1.5, s: Sampling::rgb() }),
        Arc::new(TestBeckmann { m: 0.1, n: 1.5, s: Sampling::rgb() }),
        recipe("cerulean-blue-c.json"),
    ];
    let opts = PlanOptions { rtol: 1e-6, ..Default::default() };
    let plans: Vec<Plan> = brdfs.iter().map(|b| Plan::compile(b.clone(), panel(), opts.clone()).unwrap()).collect();
    let flux_bits = |e: &glossmeter::instrument::plan::Execution| -> Vec<(Vec<u64>, Vec<u64>, usize, bool)> {
        e.fluxes
            .iter()
            .map(|f| {
                (
                    f.value.iter().map(|v| v.to_bits()).collect(),
                    f.error.iter().map(|v| v.to_bits()).collect(),
                    f.evaluations,
                    f.converged,
                )
            })
            .collect()
    };
    let alone: Vec<_> = plans.iter().map(|p| p.run()).collect();
    for k in [1, 2, 4] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(k).build().unwrap();
        let all = pool.install(|| Plan::run_all(&plans));
        assert_eq!(all.len(), plans.len());
        for (i, (a, b)) in alone.iter().zip(&all).enumerate() {
            assert_eq!(bits(&a.readings), bits(&b.readings), "plan {i} on {k} thread(s): readings differ");
            assert_eq!(flux_bits(a), flux_bits(b), "plan {i} on {k} thread(s): fluxes differ");
        }
        let materials: Vec<glossmeter::recipe::Material> =
            ["cerulean-blue-a.json", "rgb-lambert.json", "cerulean-blue-c.json"]
                .iter()
                .map(|n| {
                    glossmeter::recipe::load_file(
                        &Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/recipes").join(n),
                    )
                    .unwrap()
                })
                .collect();
        let batch = pool.install(|| glossmeter::batch::measure_many(&materials, &panel(), &opts)).unwrap();
        for (m, rs) in materials.iter().zip(&batch) {
            let one = Plan::compile(m.brdf.clone(), panel(), opts.clone()).unwrap().execute();
            assert_eq!(bits(&one), bits(rs), "{} in a batch on {k} thread(s)", m.name);
        }
    }
    assert_eq!(Plan::run_all(&[]).len(), 0);
}

/// Every build reads a JSON number as the same bits: the nearest f64, as `str::parse` does. serde_json's
/// default parser may land one ulp away; its `float_roundtrip` feature is exact, and a dev-dependency
/// (jsonschema) turns it on in test builds, so a shipped binary without it in `Cargo.toml` would read recipes
/// other than the tests read them (it did: `fit` of the two-roots document, docs/performance.md §Determinism).
#[test]
fn the_shipped_build_parses_json_numbers_as_the_tests_do() {
    let manifest = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml")).unwrap();
    let line = manifest.lines().find(|l| l.starts_with("serde_json =")).expect("serde_json is a dependency");
    assert!(line.contains("\"float_roundtrip\""), "serde_json without float_roundtrip: {line}");
}
