//! The measurement plan as a designer (`docs/architecture.md`): its switches give the same readings, a long-lived
//! planner caches the standards, a plan is reused on another material of the same shape, and a frozen plan re-runs
//! the same partition (same bits on the same material; a smooth function of the material's parameters).
mod common;
use common::TestBeckmann;
use std::sync::Arc;

use glossmeter::brdf::Brdf;
use glossmeter::instrument::plan::{Engine, Plan, PlanOptions, Planner, Reading};
use glossmeter::instrument::standards::{self, StandardGeometry};
use glossmeter::spectrum::Sampling;

fn panel() -> Vec<StandardGeometry> {
    glossmeter::DEFAULT_PANEL.iter().map(|id| standards::find(id).unwrap()).collect()
}

fn fixture(name: &str) -> Arc<dyn Brdf> {
    glossmeter::recipe::load_file(std::path::Path::new(&format!("fixtures/recipes/{name}"))).unwrap().brdf
}

fn run(brdf: Arc<dyn Brdf>, options: PlanOptions) -> Vec<Reading> {
    Plan::compile(brdf, panel(), options).unwrap().execute()
}

fn run_engine(brdf: Arc<dyn Brdf>, engine: Engine) -> Vec<Reading> {
    Plan::compile_with_engine(brdf, panel(), PlanOptions::default(), engine).unwrap().execute()
}

fn bits(r: &Reading) -> (Option<u64>, u64, usize, bool) {
    (r.value.map(f64::to_bits), r.error_estimate.to_bits(), r.evaluations, r.converged)
}

/// Sharing on and off: every flux has the same method either way, so every reading is the same bits (value,
/// error estimate, evaluation count, converged flag). Folding on and off: the cubature integrates one
/// luminous component or one per sample, so its partitions differ; the two readings must agree within the
/// sum of their error estimates, |a − b| ≤ e_a + e_b, on every reading of every fixture below (grey,
/// RGB, 21-sample spectral; delta, diffuse and lobe terms).
#[test]
fn folding_and_sharing_switches_give_the_same_readings() {
    for name in ["cerulean-blue-c.json", "white-pearl-spectral.json", "rgb-lambert.json", "rough-conductor-ggx.json"] {
        let brdf = fixture(name);
        let base = run(brdf.clone(), PlanOptions::default());
        let unshared = run_engine(brdf.clone(), Engine { share_fluxes: false, ..Engine::default() });
        let unfolded = run_engine(brdf.clone(), Engine { fold_spectral: false, ..Engine::default() });
        assert_eq!(base.len(), unshared.len());
        assert_eq!(base.len(), unfolded.len());
        for ((a, b), c) in base.iter().zip(&unshared).zip(&unfolded) {
            assert_eq!((&a.geometry, &a.name), (&b.geometry, &b.name));
            assert_eq!(bits(a), bits(b), "{name} {} {}: sharing changed the reading", a.geometry, a.name);
            let (x, y) = (a.value.unwrap(), c.value.unwrap());
            assert!(
                (x - y).abs() <= a.error_estimate + c.error_estimate,
                "{name} {} {}: folded {x} ± {:e} vs separate {y} ± {:e}",
                a.geometry,
                a.name,
                a.error_estimate,
                c.error_estimate
            );
        }
    }
}

#[test]
fn a_long_lived_planner_caches_the_standards_across_materials() {
    let planner = Planner::new().unwrap();
    let a = planner.compile(fixture("cerulean-blue-c.json"), panel(), PlanOptions::default()).unwrap();
    let cached = planner.cached_standards();
    assert!(cached > 0);
    let b = planner.compile(fixture("black-glass.json"), panel(), PlanOptions::default()).unwrap();
    assert_eq!(planner.cached_standards(), cached, "the second material needs no new standard flux");
    // The cached standards give the same bits as a fresh planner's.
    for (p, name) in [(a, "cerulean-blue-c.json"), (b, "black-glass.json")] {
        let fresh = run(fixture(name), PlanOptions::default());
        let here = p.execute();
        assert_eq!(here.iter().map(bits).collect::<Vec<_>>(), fresh.iter().map(bits).collect::<Vec<_>>());
    }
    // Another tolerance is another standard flux.
    planner
        .compile(fixture("black-glass.json"), panel(), PlanOptions { rtol: 1e-4, ..PlanOptions::default() })
        .unwrap();
    assert!(planner.cached_standards() > cached);
}

fn beckmann(m: f64) -> Arc<dyn Brdf> {
    Arc::new(TestBeckmann { m, n: 1.5, s: Sampling::grey() })
}

#[test]
fn a_plan_is_reused_on_a_material_of_the_same_shape_only() {
    let plan = Plan::compile(beckmann(0.1), panel(), PlanOptions::default()).unwrap();
    // The same material through with_material: the same bits.
    let again = plan.with_material(beckmann(0.1)).unwrap().execute();
    assert_eq!(plan.execute().iter().map(bits).collect::<Vec<_>>(), again.iter().map(bits).collect::<Vec<_>>());
    // Another sampling, or other terms: refused with a message.
    let rgb: Arc<dyn Brdf> = Arc::new(TestBeckmann { m: 0.1, n: 1.5, s: Sampling::rgb() });
    let e = plan.with_material(rgb).err().expect("another sampling is another shape").to_string();
    assert!(e.contains("another shape"), "{e}");
    assert!(plan.with_material(fixture("black-glass.json")).is_err());
}

/// A frozen plan: on the material it was frozen on, the same value and error bits as the adaptive run; on
/// nearby materials (Beckmann m = 0.1·(1 + k·h), h = 1e-5, k = −2…2) the gloss readings are a smooth
/// function of m: the third difference is below 1e-6 of the first (a partition jump would show up as a
/// third difference of the size of the tolerance, 1e-6 relative, against a first difference of ~1e-5).
#[test]
fn a_frozen_plan_repeats_its_bits_and_moves_smoothly() {
    let plan = Plan::compile(beckmann(0.1), panel(), PlanOptions::default()).unwrap();
    let adaptive = plan.execute();
    let (readings, frozen) = plan.freeze();
    assert!(frozen.is_frozen() && !plan.is_frozen());
    assert_eq!(
        readings.iter().map(bits).collect::<Vec<_>>(),
        adaptive.iter().map(bits).collect::<Vec<_>>(),
        "freezing executes the same adaptive run"
    );
    let again = frozen.execute();
    for (a, f) in adaptive.iter().zip(&again) {
        assert_eq!(a.value.map(f64::to_bits), f.value.map(f64::to_bits), "{} {}", a.geometry, a.name);
        assert_eq!(a.error_estimate.to_bits(), f.error_estimate.to_bits(), "{} {}", a.geometry, a.name);
        assert!(f.evaluations <= a.evaluations, "a frozen run refines nothing");
    }
    let h = 1e-5;
    let values: Vec<Vec<f64>> = (-2..=2)
        .map(|k| {
            let m = 0.1 * (1.0 + k as f64 * h);
            frozen.with_material(beckmann(m)).unwrap().execute().iter().map(|r| r.value.unwrap()).collect()
        })
        .collect();
    for (i, r) in adaptive.iter().enumerate().filter(|(_, r)| r.quantity == "gloss") {
        let v: Vec<f64> = values.iter().map(|x| x[i]).collect();
        let d1 = (v[3] - v[1]) / 2.0;
        let d3 = (v[4] - 2.0 * v[3] + 2.0 * v[1] - v[0]) / 2.0;
        assert!(d1.abs() > 0.0, "{}: the reading moves with m", r.geometry);
        assert!(d3.abs() <= 1e-6 * d1.abs(), "{}: third difference {d3:e} vs first {d1:e}: {v:?}", r.geometry);
    }
}

/// Bounded work (`docs/instrument.md` §Quadrature, "Bounded work"): the paper-eq1 pearl that ran 80 s to the 50 M
/// budget without converging.
fn pearl() -> Arc<dyn Brdf> {
    let recipe = r#"{"model": "paint", "form": "paper-eq1",
        "clear_coat": {"index": 1.5},
        "pigmented_layer": {"thickness_mm": 0.1, "primer_reflectance": [0.5, 0.5, 0.5], "pigments": []},
        "pearlescent_flakes": {"spread_deg": 0.35, "area_ratio": 0.5, "depth_mm": 0, "tio2_thickness_nm": 100000,
                               "tio2_index": 1.0, "mica_thickness_nm": 400, "mica_index": 1.58}}"#;
    glossmeter::recipe::parse_str(recipe, "<pearl>").unwrap().brdf
}

#[test]
fn a_budget_ends_in_not_converged_with_the_best_estimate() {
    let g20 = vec![standards::find("astm-d523-20").unwrap()];
    // The evaluation budget (deterministic): hit, reported, a finite best estimate.
    let budget = 300_000;
    let opts = PlanOptions { max_evals: budget, max_seconds: None, ..PlanOptions::default() };
    let r = &Plan::compile(pearl(), g20.clone(), opts).unwrap().execute()[0];
    assert!(!r.converged && r.value.is_some_and(f64::is_finite) && r.error_estimate.is_finite(), "{r:?}");
    assert!(r.problem.as_deref().unwrap().contains("evaluation budget"), "{r:?}");
    // The budget is per part of each integral: the specimen's delta and regular parts and the standard.
    assert!(r.evaluations <= 3 * budget, "{r:?}");
    // The opt-in wall-clock limit: the same case with the evaluation budget out of reach stops at the
    // deadline, and gives no value (it would depend on the machine's speed).
    let opts = PlanOptions { max_seconds: Some(0.2), ..PlanOptions::default() };
    let r = &Plan::compile(pearl(), g20, opts).unwrap().execute()[0];
    assert!(!r.converged && r.value.is_none(), "{r:?}");
    assert!(r.problem.as_deref().unwrap().contains("wall-clock limit"), "{r:?}");
    assert!(r.evaluations < PlanOptions::default().max_evals, "{r:?}");
}

/// No default reading depends on the machine's speed (docs/instrument.md §Bounded work): the default options
/// have no wall-clock limit, and the RGL fixture's default panel, cut by a small evaluation budget, gives the
/// same bits when the machine is loaded (four spinning threads beside it, for at most a few seconds).
#[test]
fn a_budget_in_evaluations_gives_the_same_bits_under_load() {
    assert_eq!(PlanOptions::default().max_seconds, None);
    let m = glossmeter::recipe::load_file(std::path::Path::new("fixtures/materials/rgl/beckmann-iso-32.json")).unwrap();
    let panel: Vec<_> = glossmeter::api::DEFAULT_PANEL.iter().map(|id| standards::find(id).unwrap()).collect();
    // At rtol 10⁻⁶ as given (the data tolerance converges this panel within the budget).
    let opts = PlanOptions { max_evals: 20_000, rtol_from_data: false, ..PlanOptions::default() };
    let bits = |readings: Vec<glossmeter::Reading>| -> Vec<(Option<u64>, u64, usize, bool)> {
        readings
            .iter()
            .map(|r| (r.value.map(f64::to_bits), r.error_estimate.to_bits(), r.evaluations, r.converged))
            .collect()
    };
    let quiet = bits(Plan::compile(m.brdf.clone(), panel.clone(), opts.clone()).unwrap().execute());
    assert!(quiet.iter().any(|r| !r.3), "the budget is meant to cut some integral short");
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let spinners: Vec<_> = (0..4)
        .map(|_| {
            let stop = stop.clone();
            std::thread::spawn(move || {
                let start = std::time::Instant::now();
                let mut x = 1.0f64;
                while !stop.load(std::sync::atomic::Ordering::Relaxed) && start.elapsed().as_secs() < 30 {
                    x = (x * 1.000001).sin() + 1.0;
                }
                x
            })
        })
        .collect();
    let loaded = bits(Plan::compile(m.brdf.clone(), panel, opts).unwrap().execute());
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    for s in spinners {
        s.join().unwrap();
    }
    assert_eq!(quiet, loaded);
}

/// The opt-in wall-clock limit is one deadline for the whole plan (the default panel of the pearl once ran
/// minutes, each of its 12 integrals with a budget of its own): the default panel ends near the limit, not
/// near 12 × the limit / threads; a reading it cuts has no value, every other one a finite value.
#[test]
fn the_wall_clock_budget_is_shared_by_the_plan() {
    let budget = 0.5;
    let panel: Vec<_> = glossmeter::api::DEFAULT_PANEL.iter().map(|id| standards::find(id).unwrap()).collect();
    let opts = PlanOptions { max_seconds: Some(budget), ..PlanOptions::default() };
    let plan = Plan::compile(pearl(), panel, opts).unwrap();
    let start = std::time::Instant::now();
    let readings = plan.execute();
    let wall = start.elapsed().as_secs_f64();
    // The bound: the budget, plus the late starters' grace, plus generous slack for a loaded machine (a
    // budget per integral would be ≥ 6 × 0.5 s here on 2 threads).
    let late = glossmeter::instrument::method::LATE_START_SHARE;
    assert!(wall < budget * (1.0 + 12.0 * late) + 1.5, "{wall} s");
    assert!(readings.iter().any(|r| !r.converged), "the pearl does not converge in 0.5 s");
    for r in &readings {
        // A composite (the haze index) of a cut reading has no value either.
        let cut = r.problem.as_deref().is_some_and(|p| p.contains("wall-clock limit") || p.contains("has no value"));
        assert!(if cut { r.value.is_none() } else { r.value.is_some_and(f64::is_finite) }, "{r:?}");
    }
}

#[test]
fn the_tolerance_floor_is_stated_and_enforced() {
    let g = vec![standards::find("astm-d523-60").unwrap()];
    let glass = fixture("black-glass.json");
    for rtol in [1e-300, 1e-13] {
        let e = Plan::compile(glass.clone(), g.clone(), PlanOptions { rtol, ..PlanOptions::default() })
            .err()
            .expect("below the floor")
            .to_string();
        assert!(e.contains("1e-12") && e.contains("double precision"), "{e}");
    }
    let r =
        &Plan::compile(glass, g, PlanOptions { rtol: glossmeter::instrument::plan::MIN_RTOL, ..Default::default() })
            .unwrap()
            .execute()[0];
    assert!(r.converged, "the floor itself is reachable: {r:?}");
    assert!(glossmeter::instrument::convergence::validate_tolerances(&[1e-6, 1e-11]).is_err());
    assert!(glossmeter::instrument::convergence::validate_tolerances(&[1e-6, 1e-10]).is_ok());
}

/// A narrow Gaussian lobe far from the overlap kinks is read by the Gauss–Hermite lobe rule (`docs/instrument.md`
/// §Quadrature, "A shaped rule for a narrow Gaussian lobe"), which `--explain` names with its fallback; a lobe over a
/// diffuse body keeps Genz–Malik; a frozen re-run of the shaped rule gives the same bits.
#[test]
fn the_planner_names_the_shaped_rule_it_chooses_and_freezes_it() {
    let g = vec![standards::find("astm-d523-20").unwrap()];
    let b3 = Plan::compile(fixture("bench-b3-beckmann-1e-4.json"), g.clone(), PlanOptions::default()).unwrap();
    let text = b3.explain();
    assert!(text.contains("Gauss–Hermite in (u, v) scaled to the lobe"), "{text}");
    assert!(text.contains("fallback: Genz–Malik 7/5"), "{text}");
    let readings = b3.execute();
    assert!(readings[0].converged && readings[0].evaluations <= 500, "{:?}", readings[0]);
    let (first, frozen) = b3.freeze();
    assert_eq!(bits(&first[0]), bits(&readings[0]));
    assert_eq!(bits(&frozen.execute()[0]), bits(&readings[0]));
    let paint = Plan::compile(fixture("cerulean-blue-c-literal.json"), g, PlanOptions::default()).unwrap();
    assert!(!paint.explain().contains("Gauss–Hermite"), "a lobe over a diffuse body keeps the adaptive rule");
}

/// Why a reading did not converge is named truly (docs/instrument.md §Bounded work): a frozen plan run on a
/// material far from the one it was frozen on misses its tolerance with no budget involved, and says so; a
/// plan that runs out of evaluations says that.
#[test]
fn an_unconverged_reading_names_its_true_cause() {
    let geometry = vec![standards::find("astm-d523-60").unwrap()];
    let options = PlanOptions { rtol: 1e-6, max_seconds: None, ..PlanOptions::default() };
    let wide: Arc<dyn Brdf> = Arc::new(TestBeckmann { m: 0.5, n: 1.5, s: Sampling::grey() });
    let narrow: Arc<dyn Brdf> = Arc::new(TestBeckmann { m: 0.01, n: 1.5, s: Sampling::grey() });
    let (_, frozen) = Plan::compile(wide, geometry.clone(), options.clone()).unwrap().freeze();
    let far = frozen.with_material(narrow.clone()).unwrap().execute();
    assert!(!far[0].converged, "{:?}", far[0]);
    let why = far[0].problem.as_deref().unwrap();
    assert!(why.contains("frozen method") && !why.contains("budget exhausted"), "{why}");
    let starved = PlanOptions { max_evals: 2_000, ..options };
    let short = Plan::compile(narrow, geometry, starved).unwrap().execute();
    assert!(!short[0].converged);
    assert!(short[0].problem.as_deref().unwrap().contains("evaluation budget exhausted"), "{:?}", short[0]);
}
