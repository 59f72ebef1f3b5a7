//! Measured topographies (docs/topography.md): every reader on the fixtures of
//! `tools/make_topography_fixtures.py`, against the statistics NumPy computed for them there
//! (`fixtures/topography/expected.json`), and bad files refused with exit status 2, naming the file and the
//! field.
#![cfg(feature = "cli")]
mod common;
use common::tmp;
use std::path::Path;

use glossmeter::cli::run;
use glossmeter::request::TopographyRequest;
use glossmeter::topography::analysis::analyse;
use glossmeter::topography::level::Levelling;
use glossmeter::topography::map::Format;
use glossmeter::topography::text::Calibration;
use serde_json::Value;

const DIR: &str = "fixtures/topography";

fn expected(which: &str) -> Value {
    let text = std::fs::read_to_string(format!("{DIR}/expected.json")).unwrap();
    serde_json::from_str::<Value>(&text).unwrap()[which].clone()
}

/// The statistics glossmeter reads from a fixture, plane levelled.
fn read(file: &str, calibration: Option<Calibration>) -> (Format, Value) {
    let map = glossmeter::topography::load(Path::new(&format!("{DIR}/{file}")), calibration).unwrap();
    let a = analyse(&map, Levelling::Plane).unwrap();
    let v = serde_json::json!({
        "sq_um": a.heights.sq * 1e6,
        "sa_um": a.heights.sa * 1e6,
        "sdq": a.slope_stats.sdq,
        "psd_power_um2": a.psd.power() * 1e12,
        "tilt_x": a.tilt[0],
        "tilt_y": a.tilt[1],
    });
    (map.format, v)
}

fn close(got: &Value, want: &Value, rtol: f64, what: &str) {
    for key in ["sq_um", "sa_um", "sdq", "psd_power_um2", "tilt_x", "tilt_y"] {
        let (g, w) = (got[key].as_f64().unwrap(), want[key].as_f64().unwrap());
        assert!((g - w).abs() <= rtol * w.abs(), "{what}: {key} = {g}, NumPy {w} (rtol {rtol})");
    }
}

#[test]
fn every_reader_agrees_with_numpy_on_the_same_surface() {
    // f64 heights: X3P exactly; SDF and CSV through 17-digit decimals (nm and µm), so to a few ulps.
    let cal = Some(Calibration { dx: 1e-6, dy: 1e-6, z_unit: 1e-6 });
    for (file, format, calibration) in [
        ("gaussian.x3p", Format::X3p, None),
        ("gaussian-binary.sdf", Format::SdfBinary, None),
        ("gaussian-text.sdf", Format::SdfText, None),
        ("gaussian.csv", Format::Text, cal),
    ] {
        let (f, got) = read(file, calibration);
        assert_eq!(f, format, "{file}");
        close(&got, &expected("gaussian"), 1e-11, file);
    }
    // GSF holds f32: NumPy computed its statistics on the same f32 values.
    close(&read("gaussian.gsf", None).1, &expected("gaussian_f32"), 1e-11, "gaussian.gsf");
    // i16 nm data with three points masked: the mask is read (the statistics move) and matches NumPy's.
    let (_, masked) = read("gaussian-masked.x3p", None);
    close(&masked, &expected("gaussian_masked"), 1e-9, "gaussian-masked.x3p");
    let map = glossmeter::topography::load(Path::new(&format!("{DIR}/gaussian-masked.x3p")), None).unwrap();
    assert_eq!(map.nx * map.ny - map.valid(), 3);
    // Digital Surf: i32 counts of an f32 Z step plus an offset, three points non-measured; NumPy computed its
    // statistics on the same heights.
    let (f, sur) = read("gaussian.sur", None);
    assert_eq!(f, Format::Sur);
    close(&sur, &expected("gaussian_sur"), 1e-9, "gaussian.sur");
    let map = glossmeter::topography::load(Path::new(&format!("{DIR}/gaussian.sur")), None).unwrap();
    assert_eq!(map.nx * map.ny - map.valid(), 3);
    assert!(map.z[3].is_nan() && map.z[20 * 64 + 10].is_nan() && map.z[64 * 64 - 1].is_nan());
}

#[test]
fn the_command_prints_the_statistics_and_refuses_what_it_cannot_read() {
    let out = tmp("gaussian.json");
    let _ = std::fs::remove_file(&out);
    let o = out.to_str().unwrap();
    assert_eq!(run(["glossmeter", "topography", "fixtures/topography/gaussian.x3p", "--format", "json", "-o", o]), 0);
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let want = expected("gaussian");
    assert!((doc["heights"]["sq_um"].as_f64().unwrap() - want["sq_um"].as_f64().unwrap()).abs() < 1e-12);
    assert!((doc["slopes"]["sdq"].as_f64().unwrap() - want["sdq"].as_f64().unwrap()).abs() < 1e-12);
    assert_eq!(doc["map"]["format"], "x3p");
    assert_eq!(doc["map"]["points_x"], 64);
    // The radial PSD holds all the power: Σ S̄·count·Δfx·Δfy = Sq².
    let (sx, sy) = (doc["psd"]["step_x_per_um"].as_f64().unwrap(), doc["psd"]["step_y_per_um"].as_f64().unwrap());
    let power: f64 = doc["psd"]["radial"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["psd_nm2_um2"].as_f64().unwrap() * 1e-6 * b["count"].as_f64().unwrap() * sx * sy)
        .sum();
    let sq = doc["heights"]["sq_um"].as_f64().unwrap();
    assert!((power - sq * sq).abs() < 1e-10 * sq * sq, "{power} {}", sq * sq);
    // The histogram of slope angles sums to 1.
    let total: f64 =
        doc["slopes"]["angle_histogram"].as_array().unwrap().iter().map(|b| b["fraction"].as_f64().unwrap()).sum();
    assert!((total - 1.0).abs() < 1e-12);
    // The table, every format, and a text matrix with its calibration.
    for file in ["gaussian.gsf", "gaussian-text.sdf", "gaussian-binary.sdf", "gaussian-masked.x3p", "gaussian.sur"] {
        assert_eq!(run(["glossmeter", "topography", &format!("{DIR}/{file}")]), 0, "{file}");
    }
    let csv = "fixtures/topography/gaussian.csv";
    assert_eq!(run(["glossmeter", "topography", csv, "--pixel-size", "1um", "--height-unit", "um"]), 0);
    // A text matrix without its calibration, and bad arguments: exit 2.
    assert_eq!(run(["glossmeter", "topography", csv]), 2);
    assert_eq!(run(["glossmeter", "topography", csv, "--pixel-size", "1um"]), 2);
    assert_eq!(run(["glossmeter", "topography", csv, "--pixel-size", "1", "--height-unit", "um"]), 2);
    assert_eq!(run(["glossmeter", "topography", csv, "--pixel-size", "1um", "--height-unit", "inch"]), 2);
    assert_eq!(run(["glossmeter", "topography", "fixtures/topography/gaussian.x3p", "--levelling", "poly9"]), 2);
    assert_eq!(run(["glossmeter", "topography", "fixtures/topography/missing.x3p"]), 2);
    // The recipe of the same surface reads through the default panel.
    assert_eq!(run(["glossmeter", "measure", "fixtures/topography/gaussian-panel.json"]), 0);
}

/// The error of reading `bytes` as `name`, and the command's exit status on the same file.
fn refused(name: &str, bytes: &[u8], calibration: &[&str]) -> String {
    let p = tmp(name);
    std::fs::write(&p, bytes).unwrap();
    let path = p.to_str().unwrap();
    let mut args = vec!["glossmeter", "topography", path];
    args.extend_from_slice(calibration);
    assert_eq!(run(args), 2, "{name}");
    let req = TopographyRequest {
        pixel_size: calibration.get(1).map(|s| s.to_string()),
        height_unit: calibration.get(3).map(|s| s.to_string()),
        ..TopographyRequest::default()
    };
    let ext = name.rsplit('.').next().unwrap();
    let e = req.read(bytes, path, ext).map(|_| ()).unwrap_err().to_string();
    assert!(e.starts_with(path), "the message names the file: {e}");
    e
}

#[test]
fn bad_files_exit_2_naming_the_file_and_the_field() {
    let cal = ["--pixel-size", "1um", "--height-unit", "nm"];
    // Truncated files of every binary format.
    let x3p = std::fs::read(format!("{DIR}/gaussian.x3p")).unwrap();
    let e = refused("truncated.x3p", &x3p[..x3p.len() / 2], &[]);
    assert!(e.contains("damaged or truncated"), "{e}");
    let sdf = std::fs::read(format!("{DIR}/gaussian-binary.sdf")).unwrap();
    let e = refused("truncated.sdf", &sdf[..sdf.len() - 9], &[]);
    assert!(e.contains("field `NumPoints`") && e.contains("truncated"), "{e}");
    let gsf = std::fs::read(format!("{DIR}/gaussian.gsf")).unwrap();
    let e = refused("truncated.gsf", &gsf[..gsf.len() - 4], &[]);
    assert!(e.contains("field `data`") && e.contains("truncated"), "{e}");
    let sur = std::fs::read(format!("{DIR}/gaussian.sur")).unwrap();
    let e = refused("truncated.sur", &sur[..sur.len() - 4], &[]);
    assert!(e.contains("field `data`") && e.contains("truncated"), "{e}");
    let e = refused("short.sur", &sur[..100], &[]);
    assert!(e.contains("field `header`") && e.contains("truncated"), "{e}");
    // A hostile SUR header: 2³¹ − 1 points a line, refused before anything is allocated; a point size of 8 bits.
    let mut huge = sur.clone();
    huge[108..112].copy_from_slice(&i32::MAX.to_le_bytes());
    let e = refused("huge.sur", &huge, &[]);
    assert!(e.contains("too large") && e.contains("field `number of points per line`"), "{e}");
    let mut bits = sur.clone();
    bits[98..100].copy_from_slice(&8i16.to_le_bytes());
    let e = refused("bits.sur", &bits, &[]);
    assert!(e.contains("field `point size`") && e.contains("16 or 32"), "{e}");
    // Inconsistent dimensions: a ragged matrix; an SDF whose header says more points than it has.
    let e = refused("ragged.csv", b"1 2 3\n4 5 6\n7 8\n", &cal);
    assert!(e.contains("field `line 3`"), "{e}");
    let text = std::fs::read_to_string(format!("{DIR}/gaussian-text.sdf")).unwrap();
    let e = refused("wide.sdf", text.replace("NumPoints   = 64", "NumPoints   = 65").as_bytes(), &[]);
    assert!(e.contains("field `NumPoints`"), "{e}");
    // No lateral calibration.
    let e = refused("nocal.sdf", text.replace("Xscale      = 1e-06", "Xscale      = 0").as_bytes(), &[]);
    assert!(e.contains("field `Xscale`"), "{e}");
    let header = String::from_utf8_lossy(&gsf[..200]).into_owned();
    let at = header.find("XReal").unwrap();
    let mut nocal = gsf.clone();
    nocal[at..at + 5].copy_from_slice(b"XRexl");
    let e = refused("nocal.gsf", &nocal, &[]);
    assert!(e.contains("field `XReal`") && e.contains("lateral calibration"), "{e}");
    // All invalid, and NaN heights where the format has no invalid marker.
    let all_bad: String = "-32768 ".repeat(64 * 64);
    let body = text.split("*\n").nth(1).unwrap();
    let e = refused(
        "allbad.sdf",
        text.replace(body, &all_bad).replace("DataType    = 7", "DataType    = 5").as_bytes(),
        &[],
    );
    assert!(e.contains("every point"), "{e}");
    let e = refused("nan.csv", b"1 2\n3 NaN\n", &cal);
    assert!(e.contains("field `line 2`") && e.contains("NaN"), "{e}");
    // Absurd sizes: a header of 60000 × 60000 points, refused before anything is allocated; a height of 2 m.
    let e = refused(
        "huge.sdf",
        text.replace("NumPoints   = 64", "NumPoints   = 60000")
            .replace("NumProfiles = 64", "NumProfiles = 60000")
            .as_bytes(),
        &[],
    );
    assert!(e.contains("too large") && e.contains("field `NumPoints`"), "{e}");
    let e = refused("tall.csv", b"1 2\n3 4\n", &["--pixel-size", "1um", "--height-unit", "m"]);
    assert!(e.contains("|height|"), "{e}");
    // Not a topography at all.
    let e = refused("noise.x3p", b"this is not a zip", &[]);
    assert!(e.contains("zip archive"), "{e}");
}

/// A periodic surface of `k` cosines of random direction, frequency and phase (SplitMix64, seeded), whose
/// slopes are close to Gaussian (a sum of many independent terms), written as a GSF file of n × n points 1 µm
/// apart, scaled to the rms slope `sdq`.
fn random_cosines(path: &Path, n: usize, k: usize, sdq: f64, seed: u64) {
    let mut state = seed;
    let mut next = || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let terms: Vec<(f64, f64, f64)> = (0..k)
        .map(|_| {
            let (kx, ky) = ((next() * 25.0).floor() - 12.0, (next() * 25.0).floor() - 12.0);
            let (kx, ky) = if kx == 0.0 && ky == 0.0 { (1.0, 0.0) } else { (kx, ky) };
            (kx, ky, next() * 2.0 * std::f64::consts::PI)
        })
        .collect();
    let mut z: Vec<f64> = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let t = |(kx, ky, ph): &(f64, f64, f64)| {
                (2.0 * std::f64::consts::PI * (kx * i as f64 + ky * j as f64) / n as f64 + ph).cos()
            };
            z.push(terms.iter().map(t).sum::<f64>());
        }
    }
    // Scale to the rms slope wanted (the cells' slopes, in units of 1 µm spacing).
    let s = glossmeter::topography::slopes::slopes(&z, n, n, 1.0, 1.0, "s").unwrap().stats().sdq;
    let mut b = b"Gwyddion Simple Field 1.0\n".to_vec();
    b.extend_from_slice(
        format!("XRes = {n}\nYRes = {n}\nXReal = {n}\nYReal = {n}\nXYUnits = um\nZUnits = um\n").as_bytes(),
    );
    let pad = 4 - b.len() % 4;
    b.extend(std::iter::repeat_n(0u8, pad));
    for v in &z {
        b.extend_from_slice(&((v * sdq / s) as f32).to_le_bytes());
    }
    std::fs::write(path, b).unwrap();
}

#[test]
fn the_facets_of_a_gaussian_slope_map_read_as_beckmann_of_the_same_rms_slope() {
    use glossmeter::instrument::plan::PlanOptions;
    use glossmeter::optics::slope_table::SlopeTable;
    let map_path = tmp("cosines.gsf");
    random_cosines(&map_path, 256, 400, 0.1, 41);
    let recipe = tmp("cosines.json");
    std::fs::write(&recipe, r#"{"model": "topography", "file": "cosines.gsf", "ior": 1.5, "levelling": "mean"}"#)
        .unwrap();
    let material = glossmeter::recipe::load_file(&recipe).unwrap();
    // The same table, built here from the map, for its rms slope (the cells' Sdq widened by the kernel).
    let map = glossmeter::topography::load(&map_path, None).unwrap();
    let s = glossmeter::topography::slopes::slopes(&map.z, 256, 256, map.dx, map.dy, "m").unwrap();
    let m = SlopeTable::from_slopes(&s.sx, &s.sy).unwrap().rms_slope();
    assert!((m - 0.1).abs() < 0.01, "{m}");
    let beckmann = glossmeter::recipe::parse_str(
        &format!(r#"{{"model": "microfacet", "distribution": "beckmann", "roughness": {m}, "ior": 1.5}}"#),
        "beckmann.json",
    )
    .unwrap();
    let ids = ["astm-d523-20", "astm-d523-60", "astm-d523-85"];
    let geos = glossmeter::resolve_geometries(&ids, &[] as &[&str]).unwrap();
    let options = PlanOptions { rtol: 1e-5, ..PlanOptions::default() };
    let a = glossmeter::measure(&material, &geos, &options).unwrap();
    let b = glossmeter::measure(&beckmann, &geos, &options).unwrap();
    for ((x, y), id) in a.iter().zip(&b).zip(ids) {
        let (x, y) = (x.value.unwrap(), y.value.unwrap());
        eprintln!("{id}: topography {x:.4} GU, Beckmann m = {m:.5} {y:.4} GU");
        // The stated tolerance (docs/topography.md §The facet term of a measured surface): 3 % of the reading.
        assert!((x - y).abs() < 0.03 * y, "{x} vs {y}");
    }
}

#[test]
fn a_topography_recipe_refuses_what_it_cannot_read() {
    let dir = tmp("recipes");
    std::fs::create_dir_all(&dir).unwrap();
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    write("plain.csv", "1 2\n3 4\n");
    let e = |text: &str| glossmeter::recipe::load_file(&write("r.json", text)).unwrap_err().to_string();
    let csv = e(r#"{"model": "topography", "file": "plain.csv", "ior": 1.5}"#);
    assert!(csv.contains("field `/file`") && csv.contains("carry their calibration"), "{csv}");
    let missing = e(r#"{"model": "topography", "file": "none.x3p", "ior": 1.5}"#);
    assert!(missing.contains("field `/file`") && missing.contains("cannot read"), "{missing}");
    let x3p = std::fs::canonicalize(format!("{DIR}/gaussian.x3p")).unwrap();
    let ok = format!(r#"{{"model": "topography", "file": "{}", "ior": 1.5}}"#, x3p.display());
    assert!(glossmeter::recipe::load_file(&write("ok.json", &ok)).is_ok());
    assert!(e(&ok.replace("1.5}", "1.5, \"levelling\": \"poly9\"}")).contains("field `/levelling`"));
    assert!(e(&ok.replace("1.5}", "0.5}")).contains("field `/ior`"));
    assert!(e(&ok.replace("1.5}", "1.5, \"roughness\": 0.1}")).contains("unknown field"));
}

#[test]
fn the_picture_is_drawn_and_never_overwritten() {
    let (svg, png) = (tmp("map.svg"), tmp("map.png"));
    let _ = std::fs::remove_file(&svg);
    let _ = std::fs::remove_file(&png);
    let x3p = "fixtures/topography/gaussian-masked.x3p";
    assert_eq!(run(["glossmeter", "topography", x3p, "--plot", svg.to_str().unwrap()]), 0);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("<svg") && text.contains("radial PSD"), "{}", &text[..200.min(text.len())]);
    assert_eq!(run(["glossmeter", "topography", x3p, "--plot", png.to_str().unwrap()]), 0);
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (1200, 560));
    // An existing picture is not replaced, and nothing is written.
    let before = std::fs::read(&png).unwrap();
    assert_eq!(run(["glossmeter", "topography", x3p, "--plot", png.to_str().unwrap()]), 2);
    assert_eq!(std::fs::read(&png).unwrap(), before);
    assert_eq!(run(["glossmeter", "topography", x3p, "--plot", "map.gif"]), 2);
}

/// A GSF file of n × n heights `z` (µm), `dx` µm apart.
fn write_gsf(path: &Path, n: usize, dx: f64, z: &[f64]) {
    let mut b = b"Gwyddion Simple Field 1.0\n".to_vec();
    let side = n as f64 * dx;
    b.extend_from_slice(
        format!("XRes = {n}\nYRes = {n}\nXReal = {side}\nYReal = {side}\nXYUnits = um\nZUnits = um\n").as_bytes(),
    );
    let pad = 4 - b.len() % 4;
    b.extend(std::iter::repeat_n(0u8, pad));
    for v in z {
        b.extend_from_slice(&(*v as f32).to_le_bytes());
    }
    std::fs::write(path, b).unwrap();
}

/// Cosines (kx, ky, amplitude µm, phase) summed on an n × n grid of periodic indices.
fn cosines(n: usize, terms: &[(f64, f64, f64, f64)]) -> Vec<f64> {
    (0..n * n)
        .map(|k| {
            let (i, j) = ((k % n) as f64, (k / n) as f64);
            let t = |(kx, ky, a, p): &(f64, f64, f64, f64)| {
                a * (2.0 * std::f64::consts::PI * (kx * i + ky * j) / n as f64 + p).cos()
            };
            terms.iter().map(t).sum()
        })
        .collect()
}

#[test]
fn short_waves_added_to_a_long_wave_map_raise_the_haze_and_lower_the_gloss() {
    use glossmeter::instrument::plan::PlanOptions;
    // A 512 µm map (256 points 2 µm apart): long waves of 0.4 µm amplitude at 1-3 grid steps (≤ 0.006/µm),
    // and short waves of σ ≈ 10 nm (within the bound 22.3 nm at 560 nm) at 10-40 steps (0.02-0.08/µm: a halo
    // 0.6°-2.6° from the specular direction at 20°-30°, over the haze windows).
    let n = 256;
    let long = [(1.0, 0.0, 0.4, 0.3), (2.0, 1.0, 0.4, 1.1), (-1.0, 3.0, 0.3, 2.0), (3.0, -2.0, 0.2, 0.7)];
    let mut short = Vec::new();
    for k in 0..60u32 {
        let kx = 10.0 + ((k * 37) % 31) as f64;
        let ky = ((k * 53) % 41) as f64 - 20.0;
        short.push((kx, ky, 0.01 * (2.0f64 / 60.0).sqrt(), k as f64 * 0.9));
    }
    let both: Vec<_> = long.iter().chain(&short).copied().collect();
    write_gsf(&tmp("long.gsf"), n, 2.0, &cosines(n, &long));
    write_gsf(&tmp("long-short.gsf"), n, 2.0, &cosines(n, &both));
    let recipe = |name: &str, map: &str, extra: &str| {
        let p = tmp(name);
        std::fs::write(
            &p,
            format!(r#"{{"model": "topography", "file": "{map}", "ior": 1.5, "levelling": "mean"{extra}}}"#),
        )
        .unwrap();
        glossmeter::recipe::load_file(&p).unwrap()
    };
    let facets = recipe("long-facets.json", "long.gsf", "");
    let long2 = recipe("long-two.json", "long.gsf", r#", "scale_split": "rayleigh""#);
    let both2 = recipe("both-two.json", "long-short.gsf", r#", "scale_split": "rayleigh""#);
    assert!(both2.brdf.describe().contains("two-scale"), "{}", both2.brdf.describe());
    let geos = glossmeter::resolve_geometries(&["astm-d523-20", "astm-e430-30"], &[] as &[&str]).unwrap();
    let options = PlanOptions { rtol: 1e-5, ..PlanOptions::default() };
    let read = |m: &glossmeter::recipe::Material| glossmeter::measure(m, &geos, &options).unwrap();
    let (a, b, c) = (read(&facets), read(&long2), read(&both2));
    let value = |r: &[glossmeter::Reading], geo: &str, q: &str| {
        r.iter().find(|x| x.geometry == geo && x.quantity == q).and_then(|x| x.value).unwrap()
    };
    for (x, y, z) in a.iter().zip(&b).zip(&c).map(|((x, y), z)| (x, y, z)) {
        eprintln!(
            "{} {} {}: facets {:?}, two-scale {:?}, with short waves {:?}",
            x.geometry, x.name, x.quantity, x.value, y.value, z.value
        );
        // (1) Long waves alone: the two-scale surface reads as the facets (its halo has no power), within the
        // integration tolerance.
        if let (Some(p), Some(q)) = (x.value, y.value) {
            assert!((p - q).abs() <= 1e-4 * p.abs().max(1.0), "{}: {p} vs {q}", x.name);
        }
    }
    let gloss = |r: &[glossmeter::Reading]| value(r, "astm-d523-20", "gloss");
    let haze = |r: &[glossmeter::Reading]| value(r, "astm-e430-30", "haze");
    // (3) Short waves: less 20° gloss (the facets keep 1 − g, g ≈ 4.5 % at 20° less what the halo returns to
    // the aperture; measured 35.66 -> 34.53 GU), more haze (E430 narrow haze 0.906 -> 0.958).
    assert!(gloss(&c) < 0.98 * gloss(&b), "{} vs {}", gloss(&c), gloss(&b));
    assert!(haze(&c) > 1.03 * haze(&b), "{} vs {}", haze(&c), haze(&b));
}

#[test]
fn a_two_scale_split_whose_short_waves_break_the_bound_is_refused() {
    let dir = tmp("two-scale");
    std::fs::create_dir_all(&dir).unwrap();
    let x3p = std::fs::canonicalize(format!("{DIR}/gaussian.x3p")).unwrap();
    let e = |extra: &str| {
        let p = dir.join("r.json");
        std::fs::write(&p, format!(r#"{{"model": "topography", "file": "{}", "ior": 1.5{extra}}}"#, x3p.display()))
            .unwrap();
        glossmeter::recipe::load_file(&p).map(|m| m.brdf.describe())
    };
    // The fixture's Sq is 100 nm: split at 0.01/µm, its short waves break 4πσ/λ ≤ 0.5 at 560 nm.
    let low = e(r#", "split_frequency": 0.01"#).unwrap_err().to_string();
    assert!(low.contains("field `/split_frequency`") && low.contains("gaussian.x3p") && low.contains("σ_>"), "{low}");
    // The rule splits where the bound holds; a split above the map's band leaves the facets alone.
    assert!(e(r#", "scale_split": "rayleigh""#).unwrap().contains("two-scale"));
    assert!(e(r#", "split_frequency": 100"#).unwrap().contains("σ_> = 0 nm"));
    let both = e(r#", "scale_split": "rayleigh", "split_frequency": 0.2"#).unwrap_err().to_string();
    assert!(both.contains("field `/split_frequency`"), "{both}");
    assert!(e(r#", "scale_split": "fourier""#).unwrap_err().to_string().contains("field `/scale_split`"));
}

/// A real measured surface (fixtures/topography/real/README.md): its statistics agree with NumPy's reading of
/// the same file, and its `topography` recipe reads through the default panel with no fitted parameter.
#[test]
fn a_real_measured_x3p_reads_through_the_default_panel() {
    let file = "fixtures/topography/real/sample-land.x3p";
    let map = glossmeter::topography::load(Path::new(file), None).unwrap();
    let a = analyse(&map, Levelling::Polynomial(2)).unwrap();
    let text = std::fs::read_to_string("fixtures/topography/real/expected.json").unwrap();
    let want = serde_json::from_str::<Value>(&text).unwrap()["sample_land_poly2"].clone();
    assert_eq!((map.nx, map.ny), (918, 256));
    assert_eq!((map.nx * map.ny - map.valid()) as u64, want["invalid"].as_u64().unwrap());
    let got = serde_json::json!({
        "sq_um": a.heights.sq * 1e6,
        "sa_um": a.heights.sa * 1e6,
        "sdq": a.slope_stats.sdq,
        "psd_power_um2": a.psd.power() * 1e12,
        "tilt_x": a.tilt[0],
        "tilt_y": a.tilt[1],
    });
    close(&got, &want, 1e-9, file);
    // The orange-peel bands the 2.37 mm map resolves, against NumPy's (docs/topography.md §Orange-peel bands);
    // the longer ones refused.
    for w in &a.waves {
        match want["waves_um"].get(w.band.name).and_then(Value::as_f64) {
            Some(v) => {
                let got = w.rms.clone().unwrap() * 1e6;
                assert!((got - v).abs() <= 1e-9 * v, "{}: {got} µm, NumPy {v}", w.band.name);
            }
            None => assert!(w.rms.is_err(), "{}: {:?}", w.band.name, w.rms),
        }
    }
    assert_eq!(a.waves.iter().filter(|w| w.rms.is_ok()).count(), 3);

    let out = tmp("land-replica.json");
    let _ = std::fs::remove_file(&out);
    let o = out.to_str().unwrap();
    let recipe = "fixtures/topography/real/land-replica.json";
    assert_eq!(run(["glossmeter", "measure", recipe, "--format", "json", "-o", o]), 0);
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let readings = doc["readings"].as_array().unwrap();
    // The default panel: D523 20/60/85, E430, ISO 13803 and D4039, every reading converged with its estimate.
    for geometry in ["astm-d523-20", "astm-d523-60", "astm-d523-85", "astm-e430-30", "iso-13803-20", "astm-d4039"] {
        assert!(readings.iter().any(|r| r["geometry"] == geometry), "{geometry} missing");
    }
    for r in readings {
        let (v, e) = (r["value"].as_f64().unwrap(), r["error_estimate"].as_f64().unwrap());
        assert!(v.is_finite() && e.is_finite() && e >= 0.0 && r["converged"] == true, "{r}");
    }
    // A matte surface (Sdq 0.71: facets up to 88°): its specular gloss is a few units at most, far below the
    // smooth interface of the same index (about 90 GU at 60°), and above zero.
    let gloss = |g: &str| {
        readings.iter().find(|r| r["geometry"] == g && r["name"] == "gloss").unwrap()["value"].as_f64().unwrap()
    };
    // The display fixtures/topography/real/README.md and docs/topography.md §Fixtures show: 0.3 / 3.3 / 1.3 GU.
    for (g, shown) in [("astm-d523-20", "0.3"), ("astm-d523-60", "3.3"), ("astm-d523-85", "1.3")] {
        assert!(gloss(g) > 0.0 && gloss(g) < 10.0, "{g}: {}", gloss(g));
        assert_eq!(format!("{:.1}", gloss(g)), shown, "{g}");
    }
}
