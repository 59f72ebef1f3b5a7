//! The Kirchhoff method against closed forms (docs/optics.md §11.5): a flat map is the Fresnel mirror, a
//! sinusoidal grating's orders carry J_m²(q_z a), a Gaussian surface's specular cell exp(−(q_z σ)²), a periodic
//! map reads the same with either edge, and each validity refusal names the file, the field and the reason.
use std::f64::consts::PI;

use glossmeter::instrument::plan::PlanOptions;
use glossmeter::optics::kirchhoff::{Edge, KirchhoffMap};
use glossmeter::topography::synthetic::{generate, Family};
use glossmeter::Reading;

mod common;
use common::{tmp, write_gsf};

/// The readings of a topography recipe on `file` with `extra` fields, through these geometries.
fn read(name: &str, n: usize, dx: f64, z: &[f64], extra: &str, ids: &[&str]) -> Vec<Reading> {
    let map = tmp(&format!("{name}.gsf"));
    write_gsf(&map, n, dx, z);
    let recipe = tmp(&format!("{name}.json"));
    let text = format!(r#"{{"model": "topography", "file": "{name}.gsf", "ior": 1.567, "levelling": "mean"{extra}}}"#);
    std::fs::write(&recipe, text).unwrap();
    let (_, r) = glossmeter::measure_file(&recipe, ids, &PlanOptions::default()).unwrap();
    r
}

fn value(r: &[Reading], geometry: &str, quantity: &str) -> f64 {
    let x = r.iter().find(|x| x.geometry == geometry && x.quantity == quantity).unwrap();
    x.value.unwrap_or_else(|| panic!("{geometry} {quantity}: {:?}", x.problem))
}

/// J_m(x) by its power series (x ≤ 3: the terms fall below 1e-17 long before k = 40).
fn bessel_j(m: usize, x: f64) -> f64 {
    let (mut term, mut sum) = ((0.5 * x).powi(m as i32) / (1..=m).map(|k| k as f64).product::<f64>(), 0.0);
    for k in 0..40 {
        sum += term;
        term *= -(0.25 * x * x) / ((k + 1) as f64 * (k + 1 + m) as f64);
    }
    sum
}

#[test]
fn a_flat_map_reads_as_the_fresnel_mirror() {
    // Black glass itself (n = 1.567) as a flat 0.512 mm map (2 µm apart, fine enough to reach the 60°
    // receptor's 0.10 in direction cosines): gloss 100 at every D523 angle, both edges (the specular cell's
    // Fresnel factor is that of its own half angle, θi, as the standard's; docs/optics.md §11.3).
    let n = 256;
    let z = vec![0.0; n * n];
    for edge in ["periodic", "taper"] {
        let r = read(
            &format!("flat-{edge}"),
            n,
            2e-6,
            &z,
            &format!(r#", "method": "kirchhoff", "edge": "{edge}""#),
            &["astm-d523-20", "astm-d523-60", "astm-d523-85"],
        );
        for g in ["astm-d523-20", "astm-d523-60", "astm-d523-85"] {
            let v = value(&r, g, "gloss");
            eprintln!("{edge} {g}: {v:.6}");
            // Periodic: the one specular cell, exact to rounding. Taper: the Hann window puts a third of the
            // power in the 8 neighbouring cells, whose Fresnel factors differ: measured +5e-6 GU at 20°, +5.4e-4
            // at 60° and +0.105 at 85°, where a cell λ/L = 1.1e-3 in direction cosine is 0.7° of polar angle (the
            // diffraction spread of a 0.5 mm spot, real at grazing incidence).
            let tol = if edge == "periodic" { 1e-9 } else { 0.15 };
            assert!((v - 100.0).abs() < tol, "{edge} {g}: {v}");
        }
    }
}

#[test]
fn a_sinusoidal_grating_diffracts_j_m_squared_into_its_orders() {
    // z = a cos(2π·8x/L), 16 points a period: order m carries J_m²(q_z a) (Jacobi–Anger; the sampled grating
    // aliases order m with m ± 16, J_16(1.3) ≈ 1e-15).
    let n = 128;
    let (dx, lambda) = (1e-6, 560e-9);
    let k = 2.0 * PI / lambda;
    let qz = 2.0 * k * 20f64.to_radians().cos();
    let a = 1.3 / qz;
    let z: Vec<f64> = (0..n * n).map(|i| a * (2.0 * PI * 8.0 * (i % n) as f64 / n as f64).cos()).collect();
    let m = KirchhoffMap::new(&z, (n, n), (dx, dx), lambda, 1.5, Edge::Periodic).unwrap();
    let p = m.power(qz).unwrap();
    let total: f64 = p.iter().sum();
    assert!((total - 1.0).abs() < 1e-12, "Parseval: {total}");
    for order in 0..=3usize {
        let want = bessel_j(order, 1.3).powi(2);
        let plus = p[8 * order];
        let minus = p[(n - 8 * order) % n];
        eprintln!("order ±{order}: {plus:.9} {minus:.9} J² = {want:.9}");
        assert!((plus - want).abs() < 1e-9 && (minus - want).abs() < 1e-9, "order {order}: {plus} {minus} {want}");
    }
}

#[test]
fn a_gaussian_surfaces_specular_cell_is_the_debye_waller_factor() {
    // σ = 25 nm, ℓ = 2 µm on a 256² map 1 µm apart, q_z σ = 0.53 at 20°: p(0) = |⟨e^{i q_z z}⟩|², whose
    // expectation is exp(−(q_z σ)²) and whose spread, over N_eff = L²/(πℓ²) ≈ 5 200 independent patches, is
    // 2√(p(1 − p)/N_eff) ≈ 0.011; the test allows 4 of those, for each of four seeds and their mean 2.
    let (n, dx, lambda, sigma) = (256, 1e-6, 560e-9, 25e-9);
    let qz = 2.0 * (2.0 * PI / lambda) * 20f64.to_radians().cos();
    let want = (-(qz * sigma).powi(2)).exp();
    let n_eff = (n as f64 * dx).powi(2) / (PI * 4e-12);
    let spread = 2.0 * (want * (1.0 - want) / n_eff).sqrt();
    let mut mean = 0.0;
    for seed in 1..=4 {
        let z = generate(&Family::Gaussian { sigma, ell: 2e-6 }, n, dx, seed);
        let p0 = KirchhoffMap::new(&z, (n, n), (dx, dx), lambda, 1.5, Edge::Periodic).unwrap().power(qz).unwrap()[0];
        eprintln!("seed {seed}: p(0) = {p0:.5}, exp(−(q_z σ)²) = {want:.5}, spread {spread:.5}");
        assert!((p0 - want).abs() < 4.0 * spread, "seed {seed}: {p0} vs {want}");
        mean += p0 / 4.0;
    }
    assert!((mean - want).abs() < 2.0 * spread, "mean {mean} vs {want}");
}

#[test]
fn periodic_and_taper_agree_on_a_periodic_map() {
    // Three whole-period cosines (wavelengths 256, about 160 and 171 µm, 20-60 nm) on a 0.512 mm map: the
    // taper spreads each order over its neighbouring cells, and the orders that carry power lie well inside the
    // receptors (an order on a receptor's edge is where the two edges differ most: a 51 µm cosine put its first
    // order there at 20° and the two read 0.053 GU apart); measured 0.005 GU apart at 20°, 0.001 at 60°, 0.074
    // at 85° (its receptor is 11 cells wide in plane): within the display's 0.1 GU.
    let n = 256;
    let dx = 2e-6;
    let z: Vec<f64> = (0..n * n)
        .map(|k| {
            let (i, j) = ((k % n) as f64 / n as f64, (k / n) as f64 / n as f64);
            60e-9 * (2.0 * PI * 2.0 * i).cos()
                + 40e-9 * (2.0 * PI * (3.0 * i + 1.0 * j)).sin()
                + 20e-9 * (2.0 * PI * (3.0 * j)).cos()
        })
        .collect();
    let ids = ["astm-d523-20", "astm-d523-60", "astm-d523-85"];
    let per = read("grating-p", n, dx, &z, r#", "method": "kirchhoff", "edge": "periodic""#, &ids);
    let tap = read("grating-t", n, dx, &z, r#", "method": "kirchhoff", "edge": "taper""#, &ids);
    for g in ids {
        let (a, b) = (value(&per, g, "gloss"), value(&tap, g, "gloss"));
        eprintln!("{g}: periodic {a:.4}, taper {b:.4}");
        assert!((a - b).abs() < 0.1, "{g}: {a} vs {b}");
    }
}

fn problem(r: &[Reading], geometry: &str) -> String {
    r.iter().find(|x| x.geometry == geometry).and_then(|x| x.problem.clone()).unwrap_or_default()
}

#[test]
fn each_validity_refusal_names_the_file_the_field_and_the_reason() {
    // Too small: a 64 µm map cannot resolve the 85° receptor (4° in plane, 0.006 in direction cosines).
    let r = read("small", 64, 1e-6, &vec![0.0; 64 * 64], r#", "method": "kirchhoff""#, &["astm-d523-85"]);
    let p = problem(&r, "astm-d523-85");
    assert!(p.contains("small.json: /file:") && p.contains("too small to resolve the receptor"), "{p}");
    // Too coarse: 40 µm spacing reaches |λf| ≤ 0.007, less than the 60° receptor's half-width, and a white
    // roughness of 20 nm puts as much power at the Nyquist edge as anywhere, so most of what the receptor may
    // receive is beyond what the map resolves.
    let white: Vec<f64> = (0..64 * 64u64)
        .map(|k| {
            let h = k.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 11;
            20e-9 * 3f64.sqrt() * (2.0 * (h as f64 / (1u64 << 53) as f64) - 1.0)
        })
        .collect();
    let r = read("coarse", 64, 40e-6, &white, r#", "method": "kirchhoff""#, &["astm-d523-60"]);
    let p = problem(&r, "astm-d523-60");
    assert!(p.contains("coarse.json: /file:") && p.contains("too coarse for the receptor"), "{p}");
    // A flat map at that spacing is a mirror whatever the sampling: it reads, with nothing unresolved.
    let r = read("coarse-flat", 64, 40e-6, &vec![0.0; 64 * 64], r#", "method": "kirchhoff""#, &["astm-d523-60"]);
    assert!(problem(&r, "astm-d523-60").is_empty() && value(&r, "astm-d523-60", "gloss") > 0.0);
    // Phase aliasing: a 0.5 µm step between neighbours at 20° (q_z·Δz ≈ 10.5 rad).
    let z: Vec<f64> = (0..128 * 128).map(|k| if (k % 128) % 2 == 0 { 0.5e-6 } else { 0.0 }).collect();
    let r = read("steep", 128, 4e-6, &z, r#", "method": "kirchhoff""#, &["astm-d523-20"]);
    let p = problem(&r, "astm-d523-20");
    assert!(p.contains("steep.json: /file:") && p.contains("phase aliasing"), "{p}");
    assert!(r.iter().all(|x| x.value.is_none()));
    // The recipe's own fields: an unknown method or edge, an edge without the method, a split with it.
    for (extra, field) in [
        (r#", "method": "wave""#, "/method"),
        (r#", "method": "kirchhoff", "edge": "soft""#, "/edge"),
        (r#", "edge": "taper""#, "/edge"),
        (r#", "method": "kirchhoff", "scale_split": "rayleigh""#, "/scale_split"),
    ] {
        let map = tmp("fields.gsf");
        write_gsf(&map, 64, 4e-6, &vec![0.0; 64 * 64]);
        let recipe = tmp("fields.json");
        std::fs::write(&recipe, format!(r#"{{"model": "topography", "file": "fields.gsf", "ior": 1.567{extra}}}"#))
            .unwrap();
        let e = glossmeter::recipe::load_file(&recipe).unwrap_err().to_string();
        assert!(e.contains("fields.json") && e.contains(field), "{extra}: {e}");
    }
}
