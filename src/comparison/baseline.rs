//! Baselines: a previous run's JSON (`measure` or `compare`) read as readings, and today's readings checked
//! against it (docs/instrument.md §CI reports and baselines): a reading moved when |now − then| > e_now + e_then, the two
//! error estimates being bounds.
use std::path::Path;

use crate::input::Source;
use crate::instrument::plan::Reading;
use crate::{Error, Result};

/// One reading of a baseline (a previous `measure` or `compare` JSON).
#[derive(Clone, Debug, PartialEq)]
pub struct BaselineEntry {
    pub material: String,
    pub geometry: String,
    pub reading: String,
    pub value: f64,
    pub error_estimate: f64,
}

/// Read a baseline file: the JSON of `measure` (one or many recipes) or of `compare`.
pub fn load_baseline(path: &Path) -> Result<Vec<BaselineEntry>> {
    load_baseline_source(&path.into())
}

/// [`load_baseline`] of a source (a file, or standard input as a front end read it).
pub(crate) fn load_baseline_source(source: &Source) -> Result<Vec<BaselineEntry>> {
    let file = source.name();
    // Read as every JSON input is: the size limit, a BOM, duplicate keys refused.
    let text = source.text("baseline")?;
    let doc = crate::input::json::parse_json(&text, &file)?;
    let entries = parse_baseline(&doc, &file)?;
    if entries.is_empty() {
        return Err(Error::input(&file, "", "the baseline holds no reading with a value, so it would check nothing"));
    }
    Ok(entries)
}

pub(crate) fn parse_baseline(doc: &serde_json::Value, file: &str) -> Result<Vec<BaselineEntry>> {
    let bad = |ptr: String, m: &str| Error::input(file, ptr, m.to_string());
    // A number, or absent / null (no value then); anything else is not a `measure` or `compare` JSON.
    let number_at = |v: &serde_json::Value, k: &str, ptr: &str| -> Result<Option<f64>> {
        match v.get(k) {
            None | Some(serde_json::Value::Null) => Ok(None),
            Some(x) => x.as_f64().map(Some).ok_or_else(|| bad(format!("{ptr}/{k}"), "expected a number or null")),
        }
    };
    let check_estimate = |e: f64, ptr: &str| -> Result<()> {
        if e.is_finite() && e >= 0.0 {
            Ok(())
        } else {
            Err(bad(ptr.to_string(), "an error estimate is a finite number ≥ 0"))
        }
    };
    let mut out = vec![];
    let str_at = |v: &serde_json::Value, k: &str, ptr: &str| -> Result<String> {
        v.get(k)
            .and_then(|x| x.as_str())
            .map(String::from)
            .ok_or_else(|| bad(format!("{ptr}/{k}"), "expected a string"))
    };
    if let Some(rs) = doc.get("readings").and_then(|r| r.as_array()) {
        // measure: one material at /material/name, or many with a `material` on each reading.
        let top = doc.pointer("/material/name").and_then(|n| n.as_str()).map(String::from);
        for (i, r) in rs.iter().enumerate() {
            let ptr = format!("/readings/{i}");
            let material = match r.get("material").and_then(|m| m.as_str()) {
                Some(m) => m.to_string(),
                None => top.clone().ok_or_else(|| bad(format!("{ptr}/material"), "no material name"))?,
            };
            let (Some(value), Some(e)) = (number_at(r, "value", &ptr)?, number_at(r, "error_estimate", &ptr)?) else {
                continue; // a reading without a value then: nothing to compare with
            };
            check_estimate(e, &format!("{ptr}/error_estimate"))?;
            out.push(BaselineEntry {
                material,
                geometry: str_at(r, "geometry", &ptr)?,
                reading: str_at(r, "name", &ptr)?,
                value,
                error_estimate: e,
            });
        }
    } else if let Some(cs) = doc.get("comparisons").and_then(|r| r.as_array()) {
        for (i, c) in cs.iter().enumerate() {
            let ptr = format!("/comparisons/{i}");
            let (Some(value), Some(e)) = (number_at(c, "predicted", &ptr)?, number_at(c, "error_estimate", &ptr)?)
            else {
                continue;
            };
            check_estimate(e, &format!("{ptr}/error_estimate"))?;
            out.push(BaselineEntry {
                material: str_at(c, "material", &ptr)?,
                geometry: str_at(c, "geometry", &ptr)?,
                reading: str_at(c, "predicted_reading", &ptr)?,
                value,
                error_estimate: e,
            });
        }
    } else {
        return Err(bad(String::new(), "neither a `measure` JSON (`readings`) nor a `compare` JSON (`comparisons`)"));
    }
    Ok(out)
}

/// A reading checked against its baseline: it moved if |now − then| > e_now + e_then.
#[derive(Clone, Debug, PartialEq)]
pub struct Drift {
    pub material: String,
    pub geometry: String,
    pub reading: String,
    pub now: f64,
    pub then: f64,
    pub allowed: f64,
    pub moved: bool,
}

/// Check readings (material, reading) against a baseline; readings the baseline lacks are not checked.
pub fn check_baseline<'a>(
    now: impl IntoIterator<Item = (&'a str, &'a Reading)>,
    baseline: &[BaselineEntry],
) -> Vec<Drift> {
    let mut out = vec![];
    for (material, r) in now {
        let Some(v) = r.value else { continue };
        let Some(b) =
            baseline.iter().find(|b| b.material == material && b.geometry == r.geometry && b.reading == r.name)
        else {
            continue;
        };
        let allowed = r.error_estimate + b.error_estimate;
        out.push(Drift {
            material: material.to_string(),
            geometry: r.geometry.clone(),
            reading: r.name.clone(),
            now: v,
            then: b.value,
            allowed,
            moved: (v - b.value).abs() > allowed,
        });
    }
    out
}
