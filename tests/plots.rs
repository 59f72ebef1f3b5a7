//! The pictures: every kind in PNG and SVG exists, has a plausible size and is not blank (a PNG has several
//! colours and a share of non-white pixels; an SVG has lines and text, drawn with the embedded font), and an
//! existing file is never overwritten.
#![cfg(feature = "cli")]
mod common;
use common::fresh;
use glossmeter::cli::run;
use std::path::PathBuf;

fn check_png(p: &PathBuf) {
    let bytes = std::fs::read(p).unwrap();
    assert!(bytes.len() > 10_000, "{}: {} bytes", p.display(), bytes.len());
    let img = image::load_from_memory(&bytes).unwrap().to_rgb8();
    let (w, h) = img.dimensions();
    assert!(w >= 800 && h >= 400, "{w} × {h}");
    let mut colours = std::collections::HashSet::new();
    let mut ink = 0usize;
    for px in img.pixels() {
        colours.insert(px.0);
        if px.0 != [255, 255, 255] {
            ink += 1;
        }
    }
    let share = ink as f64 / (w * h) as f64;
    assert!(colours.len() >= 5 && share > 0.01, "{}: {} colours, {share:.4} ink", p.display(), colours.len());
}

fn check_svg(p: &PathBuf) {
    let s = std::fs::read_to_string(p).unwrap();
    assert!(s.len() > 5_000, "{}: {} bytes", p.display(), s.len());
    assert!(
        s.starts_with("<svg") && s.contains("<text") && (s.contains("<polyline") || s.contains("<path")),
        "{}",
        p.display()
    );
}

/// A PNG or an SVG, by the file's extension.
fn check_picture(p: &PathBuf) {
    match p.extension().and_then(|e| e.to_str()) {
        Some("png") => check_png(p),
        Some("svg") => check_svg(p),
        other => panic!("{}: not a picture ({other:?})", p.display()),
    }
}

#[test]
fn section_plots_in_both_formats() {
    for ext in ["png", "svg"] {
        let p = fresh(&format!("section.{ext}"));
        let args = [
            "glossmeter",
            "plot",
            "fixtures/recipes/rough-dielectric-beckmann.json",
            "--kind",
            "section",
            "-g",
            "astm-d523-20",
            "-g",
            "astm-d523-60",
            "-o",
            p.to_str().unwrap(),
        ];
        assert_eq!(run(args), 0);
        check_picture(&p);
        // Never overwritten: the second run refuses and leaves the file as it was.
        let before = std::fs::read(&p).unwrap();
        assert_eq!(run(args), 2);
        assert_eq!(std::fs::read(&p).unwrap(), before);
    }
    let bad = fresh("section.jpg");
    assert_eq!(
        run([
            "glossmeter",
            "plot",
            "fixtures/recipes/grey-lambert.json",
            "--kind",
            "section",
            "-o",
            bad.to_str().unwrap()
        ]),
        2
    );
    assert!(!bad.exists());
}

#[test]
fn gloss_vs_parameter_plots() {
    for ext in ["png", "svg"] {
        let p = fresh(&format!("vary.{ext}"));
        let args = [
            "glossmeter",
            "plot",
            "fixtures/recipes/rough-dielectric-beckmann.json",
            "--kind",
            "gloss-vs-parameter",
            "--vary",
            "/roughness=0.05..0.3",
            "--points",
            "4",
            "-g",
            "astm-d523-60",
            "-g",
            "astm-d523-85",
            "-o",
            p.to_str().unwrap(),
        ];
        assert_eq!(run(args), 0);
        check_picture(&p);
    }
    // A pointer that names no number is bad input.
    let p = fresh("vary-bad.svg");
    let args = [
        "glossmeter",
        "plot",
        "fixtures/recipes/rough-dielectric-beckmann.json",
        "--kind",
        "gloss-vs-parameter",
        "--vary",
        "/nothing=0..1",
        "-o",
        p.to_str().unwrap(),
    ];
    assert_eq!(run(args), 2);
    assert!(!p.exists());
}

#[test]
fn compare_and_convergence_plots() {
    for ext in ["png", "svg"] {
        let p = fresh(&format!("compare.{ext}"));
        let args = [
            "glossmeter",
            "compare",
            "fixtures/recipes/black-glass.json",
            "fixtures/sheets/black-glass-check.csv",
            "--plot",
            p.to_str().unwrap(),
        ];
        assert_eq!(run(args), 0);
        check_picture(&p);
    }
    let p = fresh("convergence.png");
    assert_eq!(
        run([
            "glossmeter",
            "convergence",
            "fixtures/recipes/grey-lambert.json",
            "-g",
            "astm-d523-60",
            "--tolerances",
            "1e-3,1e-5",
            "--min-time-ms",
            "0",
            "--max-repetitions",
            "1",
            "--plot",
            p.to_str().unwrap(),
        ]),
        0
    );
    check_png(&p);
}

/// Readings of several units never share an axis (docs/instrument.md §Pictures): a gloss-vs-parameter picture of
/// gloss, haze, DOI and colour readings has one chart per unit, colour's CIELAB and X, Y, Z each their own; a
/// residual chart of a gloss, haze and DOI sheet too. Readings of one unit keep the one chart.
#[test]
fn every_unit_and_colour_get_an_axis_of_their_own() {
    let p = fresh("units.svg");
    let args = [
        "glossmeter",
        "plot",
        "fixtures/recipes/blue-metallic-spectral.json",
        "--kind",
        "gloss-vs-parameter",
        "--vary",
        "/clear_coat/index=1.45..1.55",
        "--points",
        "2",
        "-g",
        "astm-d523-60",
        "-g",
        "astm-e430-30",
        "-g",
        "astm-e2194-45",
        "-o",
        p.to_str().unwrap(),
    ];
    assert_eq!(run(args), 0);
    let svg = std::fs::read_to_string(&p).unwrap();
    for axis in [
        "reading (GU)",
        "reading (HU)",
        "reading (DOI)",
        "colour: L*, a*, b*, C* (no unit)",
        "colour: X, Y, Z (no unit)",
        "reading (°)",
    ] {
        assert!(svg.contains(axis), "no axis {axis:?}");
    }
    assert!(!svg.contains("unit in the legend"), "no shared axis");
    let p = fresh("one-unit.svg");
    let one = ["glossmeter", "plot", "fixtures/recipes/cerulean-blue-c.json", "--kind", "gloss-vs-parameter"];
    let rest = ["--vary", "/clear_coat/index=1.45..1.55", "--points", "2", "-o", p.to_str().unwrap()];
    assert_eq!(run(one.iter().chain(&rest).copied()), 0);
    let svg = std::fs::read_to_string(&p).unwrap();
    assert!(svg.contains("reading (GU)") && svg.contains("height=\"640\""), "one unit, one chart as before");
    let p = fresh("residual-units.svg");
    let args = [
        "glossmeter",
        "compare",
        "fixtures/recipes/glass-n1.5.json",
        "fixtures/sheets/rhopoint-iq.csv",
        "--tolerance",
        "1",
        "--plot",
        p.to_str().unwrap(),
    ];
    run(args);
    let svg = std::fs::read_to_string(&p).unwrap();
    for axis in ["predicted − measured (GU)", "predicted − measured (HU)", "predicted − measured (DOI)"] {
        assert!(svg.contains(axis), "no axis {axis:?}");
    }
    assert!(!svg.contains("predicted − measured (GU, "), "no shared axis");
}

/// Readings against a parameter read colour under `--illuminant` and `--observer`, as `measure` does (the server's
/// plot took them already): the curves under A / 2° are not D65 / 10°'s, and an unknown illuminant is refused
/// before any work (exit 2).
#[test]
fn gloss_vs_parameter_reads_colour_under_the_given_conditions() {
    let svg = |name: &str, colour: &[&str]| -> (i32, String) {
        let p = fresh(name);
        let mut args = vec!["glossmeter", "plot", "fixtures/recipes/white-pearl-spectral.json", "--kind"];
        args.extend(["gloss-vs-parameter", "--vary", "/pearlescent_flakes/tio2_thickness_nm=60..69", "--points"]);
        args.extend(["2", "-g", "astm-e2194-15", "-o", p.to_str().unwrap()]);
        args.extend(colour);
        let code = run(args);
        (code, std::fs::read_to_string(&p).unwrap_or_default())
    };
    let (code, a2) = svg("colour-a2.svg", &["--illuminant", "A", "--observer", "2"]);
    assert_eq!(code, 0);
    let (code, d65) = svg("colour-d65.svg", &[]);
    assert_eq!(code, 0);
    assert!(a2.contains("b*") && a2 != d65, "the same curves under A / 2° as under D65 / 10°");
    let (code, none) = svg("colour-d99.svg", &["--illuminant", "D99"]);
    assert_eq!((code, none.is_empty()), (2, true), "an unknown illuminant is refused and nothing is drawn");
    let (code, none) = svg("budget-0.svg", &["--max-evals", "0"]);
    assert_eq!((code, none.is_empty()), (2, true), "a budget of 0 is refused and nothing is drawn");
}
