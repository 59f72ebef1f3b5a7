//! The Kirchhoff (Beckmann–Kirchhoff, FFT) reading of a topography against an independent NumPy reference
//! (docs/topography.md §Fixtures: the kirchhoff/ folder): `tools/kirchhoff_reference.py` generated the maps of
//! `fixtures/topography/kirchhoff/` and computed, from the f32 heights it wrote, the ASTM D523 20°/60°/85°
//! gloss of each map with each edge treatment (`reference.json`, with its own discretisation-error estimate
//! `gloss_error`). Each map is read here as a `topography` recipe with `"method": "kirchhoff"` through the
//! command (`measure --format json`), and its gloss compared with the reference.
#![cfg(feature = "cli")]
mod common;
use common::{gm, root, tmp};
use serde_json::Value;

const GEOMETRIES: [&str; 3] = ["astm-d523-20", "astm-d523-60", "astm-d523-85"];

fn reference() -> Value {
    let path = root().join("fixtures/topography/kirchhoff/reference.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The gloss readings of one map read by the Kirchhoff method with one edge treatment, by geometry: the value
/// and its error estimate (the numerical error; the speckle uncertainty is no difference between two readings
/// of the same map).
fn measure(name: &str, file: &str, edge: &str) -> Vec<(String, f64, f64)> {
    let map = root().join(file);
    let recipe = tmp(&format!("{name}-{edge}.json"));
    let text = serde_json::json!({
        "name": format!("{name} ({edge})"),
        "model": "topography",
        "file": map.to_str().unwrap(),
        "ior": 1.5,
        "method": "kirchhoff",
        "edge": edge,
    });
    std::fs::write(&recipe, text.to_string()).unwrap();
    let mut args = vec!["measure", recipe.to_str().unwrap()];
    for g in GEOMETRIES {
        args.extend(["-g", g]);
    }
    args.extend(["--format", "json", "--no-timing"]);
    let (code, out, err) = gm(&args);
    assert_eq!(code, 0, "{name} {edge}: {err}");
    let doc: Value = serde_json::from_str(&out).unwrap();
    doc["readings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["quantity"] == "gloss")
        .map(|r| {
            let g = r["geometry"].as_str().unwrap().to_string();
            (g, r["value"].as_f64().unwrap(), r["error_estimate"].as_f64().unwrap())
        })
        .collect()
}

/// Each reading within the sum of the two error estimates: the Rust reading's (its fine rule against its
/// coarse one, docs/optics.md §11.3) and the reference's (`gloss_error`, from its independent replicates).
#[test]
fn the_kirchhoff_gloss_of_each_map_matches_the_numpy_reference() {
    let doc = reference();
    let surfaces = doc["surfaces"].as_object().unwrap();
    assert_eq!(surfaces.len(), 4);
    let mut failures = Vec::new();
    for (name, s) in surfaces {
        for edge in ["periodic", "taper"] {
            let got = measure(name, s["file"].as_str().unwrap(), edge);
            assert_eq!(got.len(), GEOMETRIES.len(), "{name} {edge}: {got:?}");
            for (geometry, value, error) in got {
                let want = &s["readings"][edge][&geometry];
                let (g, e) = (want["gloss"].as_f64().unwrap(), want["gloss_error"].as_f64().unwrap());
                let allowed = e + error;
                eprintln!(
                    "{name} {edge} {geometry}: {value:.6} ± {error:.1e} GU, reference {g:.4} ± {e:.1e}, difference \
                     {:.1e}",
                    value - g
                );
                if (value - g).abs() > allowed {
                    failures.push(format!("{name} {edge} {geometry}: {value} vs {g} (allowed {allowed})"));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// What can be checked without the Kirchhoff method: the reference's maps and numbers are where the test
/// above expects them, and its self-checks passed when it was written (docs/topography.md §Fixtures).
#[test]
fn the_reference_is_complete_and_its_self_checks_passed() {
    let doc = reference();
    let surfaces = doc["surfaces"].as_object().unwrap();
    assert_eq!(surfaces.len(), 4);
    for (name, s) in surfaces {
        let file = root().join(s["file"].as_str().unwrap());
        assert!(file.is_file(), "{name}: {}", file.display());
        for edge in ["periodic", "taper"] {
            for g in GEOMETRIES {
                let r = &s["readings"][edge][g];
                let (gloss, err) = (r["gloss"].as_f64().unwrap(), r["gloss_error"].as_f64().unwrap());
                assert!(gloss > 0.0 && gloss < 100.0 && (0.0..0.05).contains(&err), "{name} {edge} {g}: {r}");
                assert!((r["sum_p"].as_f64().unwrap() - 1.0).abs() < 1e-12, "{name} {edge} {g}: Parseval");
            }
        }
    }
    for (g, flat) in doc["self_checks"]["flat_map"].as_object().unwrap() {
        assert!((flat["gloss_n_ref"].as_f64().unwrap() - 100.0).abs() < 1e-12, "{g}: {flat}");
    }
    for (g, b) in doc["self_checks"]["grating_bessel"].as_object().unwrap() {
        assert!(b["max_abs_error_orders_-4..4"].as_f64().unwrap() < 1e-12, "{g}: {b}");
    }
}
