//! Golden readings: every reading of every shipped fixture recipe, on every builtin geometry, stored as bits
//! (`fixtures/golden/readings.json`) and compared bit for bit. A refactor must leave them identical;
//! a change that moves readings on purpose regenerates the file with
//! `GLOSSMETER_BLESS=1 cargo test --test golden` and explains every moved reading in its commit and the docs.
//!
//! Compared per reading: the value and the error estimate as `f64::to_bits`, the evaluation count and the
//! convergence flag (rtol 1e-6, the default). Builtin geometries are measured one plan per recipe; the colour
//! geometries (`standards/colour`, D65 and the 10° observer) join that plan for every recipe that is not RGB
//! (their fluxes carry only their own X, Y, Z rows, so the gloss readings are the same bits with or without them).
use std::collections::BTreeMap;
use std::path::Path;

use glossmeter::instrument::plan::PlanOptions;

mod common;

const GOLDEN: &str = "fixtures/golden/readings.json";

/// One line per reading: "recipe|geometry|name" → "value-bits error-bits evaluations converged".
fn current() -> BTreeMap<String, String> {
    common::every_fixture_reading(&PlanOptions::default())
        .into_iter()
        .map(|(key, r)| {
            let v = match r.value {
                Some(x) => format!("{:016x}", x.to_bits()),
                None => "none".to_string(),
            };
            (key, format!("{v} {:016x} {} {}", r.error_estimate.to_bits(), r.evaluations, r.converged))
        })
        .collect()
}

#[test]
fn every_reading_of_every_fixture_is_bit_identical_to_the_stored_one() {
    let now = current();
    if std::env::var_os("GLOSSMETER_BLESS").is_some() {
        std::fs::create_dir_all("fixtures/golden").unwrap();
        std::fs::write(GOLDEN, serde_json::to_string_pretty(&now).unwrap() + "\n").unwrap();
        return;
    }
    let text = std::fs::read_to_string(Path::new(GOLDEN)).expect("fixtures/golden/readings.json (bless it first)");
    let stored: BTreeMap<String, String> = serde_json::from_str(&text).unwrap();
    let mut diffs = Vec::new();
    for (k, v) in &stored {
        match now.get(k) {
            None => diffs.push(format!("{k}: missing now (stored {v})")),
            Some(n) if n != v => diffs.push(format!("{k}: stored {v}, now {n}")),
            _ => {}
        }
    }
    for k in now.keys().filter(|k| !stored.contains_key(*k)) {
        diffs.push(format!("{k}: new reading (not stored)"));
    }
    assert!(diffs.is_empty(), "{} reading(s) moved:\n{}", diffs.len(), diffs.join("\n"));
}
