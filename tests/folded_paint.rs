//! The paint's folded luminous evaluation (`Brdf::eval_batch_folded`, docs/model.md §Folded
//! evaluation) against its per-sample evaluation weighted afterwards: the same function, summed in another
//! order, so equal to rounding. Stated tolerance: 1e-13 relative to the luminous value (plus 1e-13 of the
//! largest weighted sample term, for values near 0), pointwise; and the readings of every paint fixture with
//! folding on and off within 1e-11 relative (or the sum of their error estimates).
use std::path::Path;
use std::sync::Arc;

use glossmeter::brdf::Brdf;
use glossmeter::colorimetry::weighting::Weighting;
use glossmeter::instrument::plan::{Engine, Plan, PlanOptions};
use glossmeter::instrument::standards;
use glossmeter::Vec3;
use serde_json::Value;

const PAINTS: [&str; 11] = [
    "blue-metallic-spectral",
    "cerulean-blue-a",
    "cerulean-blue-b-literal",
    "cerulean-blue-b",
    "cerulean-blue-c-literal",
    "cerulean-blue-c",
    "silver-metallic",
    "solid-black",
    "solid-white",
    "white-pearl-spectral",
    "white-pearl",
];

fn json(name: &str) -> Value {
    let text = std::fs::read_to_string(format!("fixtures/recipes/{name}.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn brdf(v: &Value) -> Arc<dyn Brdf> {
    glossmeter::recipe::parse_str(&v.to_string(), "test.json").unwrap().brdf
}

/// The fixtures and variants that take every branch of the folded path: paper Eq. 1 form, the paper's
/// Eq. 5 flake light (no split: one precomputed table), a rough coat, a grey cover (one τ for all samples:
/// one precomputed table), different flake depths (no shared transmissions), delta flakes.
fn variants() -> Vec<(String, Arc<dyn Brdf>)> {
    let mut out: Vec<(String, Arc<dyn Brdf>)> = PAINTS.iter().map(|n| (n.to_string(), brdf(&json(n)))).collect();
    let c = json("cerulean-blue-c");
    let mut edit = |label: &str, f: &dyn Fn(&mut Value)| {
        let mut v = c.clone();
        f(&mut v);
        out.push((format!("cerulean-blue-c, {label}"), brdf(&v)));
    };
    edit("paper eq1", &|v| v["form"] = "paper-eq1".into());
    edit("flake light paper", &|v| v["flake_light"] = "paper".into());
    edit("rough coat", &|v| v["clear_coat"]["roughness"] = 0.05.into());
    edit("grey cover", &|v| {
        v["pigmented_layer"]["pigments"][0]["k_per_mm"] = serde_json::json!([0.5, 0.5, 0.5]);
        v["pigmented_layer"]["pigments"][0]["s_per_mm"] = serde_json::json!([0.2, 0.2, 0.2]);
    });
    edit("deep pearls", &|v| v["pearlescent_flakes"]["depth_mm"] = 0.1.into());
    edit("thick absorbing cover", &|v| {
        v["pigmented_layer"]["thickness_mm"] = 2.0.into();
        v["metallic_flakes"]["depth_mm"] = 1.5.into();
        v["pearlescent_flakes"]["depth_mm"] = 0.5.into();
        v["pigmented_layer"]["pigments"][0]["k_per_mm"] = serde_json::json!([3.0, 0.5, 0.1]);
    });
    let lit = json("cerulean-blue-c-literal");
    let mut v = lit.clone();
    v["metallic_flakes"]["spread_slope"] = 1e-9.into();
    v.as_object_mut().unwrap().get_mut("metallic_flakes").unwrap().as_object_mut().unwrap().remove("spread_deg");
    out.push(("cerulean-blue-c-literal, delta metallic flakes".into(), brdf(&v)));
    out
}

fn dir(theta_deg: f64, phi_deg: f64) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

#[test]
fn folded_luminous_sum_equals_the_weighted_samples() {
    // Pairs near the mirror direction (the flake lobes), off it, at grazing angles and below the horizon.
    let mut wi = vec![];
    let mut wo = vec![];
    for ti in [0.0, 5.0, 20.0, 45.0, 60.0, 75.0, 85.0, 89.9] {
        for (dt, dp) in [(0.0, 180.0), (0.3, 179.0), (2.0, 175.0), (-7.0, 150.0), (15.0, 90.0), (-30.0, 10.0)] {
            wi.push(dir(ti, 0.0));
            wo.push(dir((ti + dt).clamp(-89.95f64, 89.95).abs(), dp));
        }
    }
    wi.push(dir(30.0, 0.0));
    wo.push(Vec3::new(0.1, 0.0, -0.5).normalize());
    let m = wi.len();
    let mut checked = 0;
    for (label, b) in variants() {
        let n = b.sampling().len();
        let w = Weighting::luminous(b.sampling()).unwrap().rows.remove(0);
        assert!(b.folds(&w), "{label}: a paint prepares its luminous row");
        let other: Vec<f64> = w.iter().map(|x| x * 0.5).collect();
        assert!(!b.folds(&other), "{label}: and no other");
        let mut bad = vec![7.0; m];
        assert!(!b.eval_batch_folded(&other, &wi, &wo, &mut bad), "{label}");
        assert!(bad.iter().all(|&x| x == 7.0), "{label}: a refused row leaves out alone");

        let mut samples = vec![f64::NAN; m * n];
        b.eval_batch(&wi, &wo, &mut samples);
        let mut folded = vec![f64::NAN; m];
        assert!(b.eval_batch_folded(&w, &wi, &wo, &mut folded), "{label}");
        for i in 0..m {
            let s = &samples[i * n..(i + 1) * n];
            let reference: f64 = s.iter().zip(&w).map(|(a, b)| a * b).sum();
            let scale = s.iter().zip(&w).map(|(a, b)| (a * b).abs()).fold(0.0, f64::max);
            let diff = (folded[i] - reference).abs();
            assert!(folded[i].is_finite() && folded[i] >= 0.0, "{label} #{i}: {}", folded[i]);
            assert!(
                diff <= 1e-13 * reference.abs() + 1e-13 * scale,
                "{label} pair #{i}: folded {} vs weighted samples {reference} (rel {:e})",
                folded[i],
                diff / reference.abs()
            );
            checked += 1;
        }
        // One pair at a time: the same bits as the batch (no dependence on batching).
        for i in [0, m / 2, m - 1] {
            let mut one = [f64::NAN];
            b.eval_batch_folded(&w, &wi[i..=i], &wo[i..=i], &mut one);
            assert_eq!(one[0].to_bits(), folded[i].to_bits(), "{label} #{i}");
        }
    }
    assert!(checked >= 18 * 49, "{checked} pairs");
}

/// The readings of every paint fixture over the default panel, the material summing its samples or the
/// integrand weighting them: the integrands differ only in rounding, so the readings agree far inside their
/// error estimates (1e-11 relative, or the sum of the two estimates where that is larger).
#[test]
fn readings_with_and_without_folding_in_the_material_agree() {
    let panel: Vec<_> = glossmeter::DEFAULT_PANEL.iter().map(|id| standards::find(id).unwrap()).collect();
    let mut worst: f64 = 0.0;
    for name in PAINTS {
        let b = glossmeter::recipe::load_file(Path::new(&format!("fixtures/recipes/{name}.json"))).unwrap().brdf;
        let on = Plan::compile(b.clone(), panel.clone(), PlanOptions::default()).unwrap().execute();
        let unfolded = Engine { fold_in_material: false, ..Engine::default() };
        let off = Plan::compile_with_engine(b, panel.clone(), PlanOptions::default(), unfolded).unwrap().execute();
        for (a, z) in on.iter().zip(&off) {
            let (x, y) = (a.value.unwrap(), z.value.unwrap());
            let d = (x - y).abs();
            assert!(
                d <= (1e-11 * x.abs()).max(a.error_estimate + z.error_estimate),
                "{name} {}/{}: {x} vs {y}",
                a.geometry,
                a.name
            );
            if x != 0.0 {
                worst = worst.max(d / x.abs());
            }
        }
    }
    eprintln!("largest relative difference between folded and unfolded readings: {worst:e}");
}
