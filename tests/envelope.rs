//! `measure --envelope`: every reading read at the corners of the tolerances in the standards files (and the
//! plausible ranges of assumed numbers) brackets the nominal reading; geometries whose data give no tolerance
//! say so (null), and the extremes are those of independent single-geometry runs at the corners.
#![cfg(feature = "cli")]
mod common;
use common::tmp;
use glossmeter::cli::run;
use glossmeter::instrument::envelope;
use glossmeter::instrument::plan::{Plan, PlanOptions};
use glossmeter::instrument::standards;
use glossmeter::recipe;

#[test]
fn envelope_brackets_the_nominal_reading_in_json() {
    let out = tmp("env.json");
    let _ = std::fs::remove_file(&out);
    let args = [
        "glossmeter",
        "measure",
        "fixtures/recipes/rough-dielectric-beckmann.json",
        "-g",
        "astm-d523-60",
        "-g",
        "astm-e430-30",
        "--rtol",
        "1e-5",
        "--envelope",
        "--format",
        "json",
        "--no-timing",
        "-o",
        out.to_str().unwrap(),
    ];
    assert_eq!(run(args), 0);
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let rs = doc["readings"].as_array().unwrap();
    let g60 = &rs[0];
    assert_eq!(g60["geometry"], "astm-d523-60");
    let (lo, v, hi) =
        (g60["envelope_min"].as_f64().unwrap(), g60["value"].as_f64().unwrap(), g60["envelope_max"].as_f64().unwrap());
    assert!(lo < v && v < hi, "{lo} {v} {hi}");
    assert_eq!(g60["envelope"]["variants"], 32);
    // E430 has no tolerances in the shipped data: null, not a made-up spread.
    let e430 = rs.iter().find(|r| r["geometry"] == "astm-e430-30").unwrap();
    assert!(e430["envelope_min"].is_null() && e430["envelope_max"].is_null());
    // CSV does not carry the envelope: refused rather than silently dropped.
    assert_eq!(run(["glossmeter", "measure", "fixtures/recipes/glass-n1.5.json", "--envelope", "--format", "csv"]), 2);
}

#[test]
fn envelope_extremes_are_those_of_the_corner_geometries() {
    let m = recipe::load_file(std::path::Path::new("fixtures/recipes/rough-dielectric-beckmann.json")).unwrap();
    let g = standards::find("astm-d523-20").unwrap();
    let options = PlanOptions { rtol: 1e-5, ..Default::default() };
    let nominal = Plan::compile(m.brdf.clone(), vec![g.clone()], options.clone()).unwrap().execute();
    let env = envelope::read(m.brdf.clone(), std::slice::from_ref(&g), &nominal, options.clone(), None).unwrap();
    assert!(env.cut.is_empty());
    let e = env.of[0].clone().unwrap();
    // The same 2^k corner geometries read one by one, each in its own plan: the envelope is their extremes
    // together with the nominal reading, and a lobe wider than the receptor makes them differ.
    let (vars, corners) = envelope::variants(&g).unwrap();
    assert_eq!(corners.len(), 1 << vars.len());
    let mut values = vec![];
    for c in corners {
        values.push(Plan::compile(m.brdf.clone(), vec![c], options.clone()).unwrap().execute()[0].value.unwrap());
    }
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min).min(nominal[0].value.unwrap());
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max).max(nominal[0].value.unwrap());
    assert_eq!((e.min, e.max), (lo, hi));
    assert!(e.max > e.min);
}

/// `--max-seconds` with `--envelope` is a limit for the whole command, counted from its start, not one per
/// variant (97 s were seen for `--max-seconds 1`: each of the 32 variants had the whole limit). With a limit
/// far below any run, the command ends with exit 1 and says the envelope was cut; no envelope is reported
/// (null, `"envelope_cut": true`), and every reading that has a value is the unlimited run's, bit for bit:
/// nothing in the output depends on the machine's speed (docs/instrument.md §Bounded work). No timing is
/// asserted.
#[test]
fn the_wall_clock_limit_is_the_whole_command_s_and_cuts_the_envelope_honestly() {
    let recipe = "fixtures/recipes/rough-dielectric-beckmann.json";
    let read = |limit: Option<&str>, name: &str| -> (i32, serde_json::Value) {
        let out = tmp(name);
        let _ = std::fs::remove_file(&out);
        let mut args = vec!["glossmeter", "measure", recipe, "-g", "astm-d523-60", "-g", "astm-d523-85"];
        args.extend(["--rtol", "1e-5", "--envelope", "--format", "json", "--no-timing", "-o", out.to_str().unwrap()]);
        if let Some(s) = limit {
            args.extend(["--max-seconds", s]);
        }
        let code = run(args);
        let doc = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        let _ = std::fs::remove_file(&out);
        (code, doc)
    };
    let (code, free) = read(None, "free.json");
    assert_eq!(code, 0);
    let (code, cut) = read(Some("1e-9"), "cut.json");
    assert_eq!(code, 1, "a cut envelope is no complete result");
    let (free, cut) = (free["readings"].as_array().unwrap(), cut["readings"].as_array().unwrap());
    assert_eq!(free.len(), cut.len());
    for (f, c) in free.iter().zip(cut) {
        assert!(f["envelope_min"].is_f64() && f.get("envelope_cut").is_none(), "{f}");
        assert!(c["envelope_min"].is_null() && c["envelope_max"].is_null(), "{c}");
        assert_eq!(c["envelope_cut"], true, "{c}");
        if let Some(v) = c["value"].as_f64() {
            assert_eq!(v.to_bits(), f["value"].as_f64().unwrap().to_bits(), "{c}");
        }
    }
}
