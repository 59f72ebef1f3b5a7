//! Measured topographies (docs/topography.md): every reader on the fixtures of
//! `tools/make_topography_fixtures.py`, against the statistics NumPy computed for them there
//! (`fixtures/topography/expected.json`), and bad files refused with exit status 2, naming the file and the
//! field.
#![cfg(feature = "cli")]
use std::path::{Path, PathBuf};

use glossmeter::cli::run;
use glossmeter::request::TopographyRequest;
use glossmeter::topography::analysis::analyse;
use glossmeter::topography::level::Levelling;
use glossmeter::topography::map::Format;
use glossmeter::topography::text::Calibration;
use serde_json::Value;

const DIR: &str = "fixtures/topography";

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("glossmeter-topography-test-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

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
    for file in ["gaussian.gsf", "gaussian-text.sdf", "gaussian-binary.sdf", "gaussian-masked.x3p"] {
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
