//! The vocabulary every geometry file format shares: numbers with their provenance
//! (`{"value": 1.8, "source": "…citation or reason…", "status": "verified" | "secondary" | "assumed"}`, read by
//! `sourced` within a [`Range`] and shown by `sourced_text`), the header every file opens with (`header`), the
//! shape and size of a stop (`aperture`), and what a file compiles to ([`StandardGeometry`]). The formats
//! (`gloss.rs`, `colour.rs`, `profile.rs`) read through it; it imports none of them.
use crate::input::json::{kind, Obj};
use crate::instrument::geometry::Geometry;
use crate::registry::Range;
use crate::{Error, Result};
use serde_json::Value;
use std::sync::Arc;

/// The allowed provenance words of a sourced number.
pub const STATUSES: &[&str] = &["verified", "secondary", "assumed"];

/// A compiled geometry together with its display names and the original specification.
#[derive(Clone, Debug)]
pub struct StandardGeometry {
    pub geometry: Geometry,
    /// One display name per entry of `geometry.readings` (the reading's `name`, or its quantity).
    pub reading_names: Vec<String>,
    /// The original JSON, kept for provenance display ([`describe`](super::describe)). Shared, not copied:
    /// every plan keeps its geometries, and a batch of a hundred recipes copying and freeing each file's JSON
    /// tree cost as much as a tenth of its integrals (docs/performance.md §Batch and sweep throughput).
    pub spec: Arc<Value>,
    /// `"builtin"` or the path of the user file.
    pub origin: String,
}

/// The value of a `{"value", "source", "status"}` object at `o.key`, with its provenance checked. The value
/// must lie in `range` (finite ends): outside [lo, hi] it gets the message of `Obj::num`, at an open end this
/// one ("must be > lo and < hi").
pub(crate) fn sourced(o: &Obj, key: &str, range: Range, what: &str) -> Result<f64> {
    let s = o.obj(key)?;
    s.deny_unknown(&["value", "source", "status", "tolerance", "plausible"])?;
    check_variation(&s)?;
    let (lo, hi) = (range.lo, range.hi);
    let value = s.num("value", lo, hi, what)?;
    if !range.contains(value) {
        let (above, below) = (if range.lo_closed { "≥" } else { ">" }, if range.hi_closed { "≤" } else { "<" });
        return Err(s.err("value", format!("{value} is out of range: {what} must be {above} {lo} and {below} {hi}")));
    }
    let source = s.str("source")?;
    if source.trim().is_empty() {
        return Err(s.err("source", "must not be empty: cite where the number comes from, or why it was chosen"));
    }
    let status = s.str("status")?;
    if !STATUSES.contains(&status) {
        return Err(s.err("status", format!("{status:?} is not a status; allowed: {}", STATUSES.join(", "))));
    }
    Ok(value)
}

/// The optional variations of a sourced number, for the tolerance envelope (`instrument::envelope`):
/// `"tolerance": {"value": t ≥ 0, "source", "status"}` (the standard allows value ± t) and, for a number
/// whose value is itself uncertain, `"plausible": {"low", "high", "source", "status"}` (low ≤ value ≤ high).
fn check_variation(s: &Obj) -> Result<()> {
    let provenance = |t: &Obj| -> Result<()> {
        t.deny_unknown(&["value", "low", "high", "source", "status"])?;
        if t.str("source")?.trim().is_empty() {
            return Err(t.err("source", "must not be empty: cite where the tolerance comes from, or why it was chosen"));
        }
        let status = t.str("status")?;
        if !STATUSES.contains(&status) {
            return Err(t.err("status", format!("{status:?} is not a status; allowed: {}", STATUSES.join(", "))));
        }
        Ok(())
    };
    if let Some(t) = s.opt_obj("tolerance")? {
        t.deny_unknown(&["value", "source", "status"])?;
        t.num("value", 0.0, 10.0, "a tolerance in the number's unit")?;
        provenance(&t)?;
    }
    if let Some(t) = s.opt_obj("plausible")? {
        t.deny_unknown(&["low", "high", "source", "status"])?;
        let lo = t.num("low", f64::MIN, f64::MAX, "the low end of the plausible range")?;
        let hi = t.num("high", f64::MIN, f64::MAX, "the high end of the plausible range")?;
        let v = s.num("value", f64::MIN, f64::MAX, "the value")?;
        if !(lo <= v && v <= hi) {
            return Err(t.err("low", format!("the plausible range [{lo}, {hi}] must contain the value {v}")));
        }
        provenance(&t)?;
    }
    Ok(())
}

/// The shape and size of a stop: (in-plane, perpendicular) full angles in degrees. The shape is checked
/// before unknown fields, so a circle's `diameter_deg` gets the circle message, not "unknown field".
pub(crate) fn aperture(o: &Obj, allowed: &[&str]) -> Result<(f64, f64)> {
    let shape = o.str("shape")?;
    match shape {
        "rectangle" => {}
        "circle" => return Err(o.err(
            "shape",
            "circular stops are not supported yet; give the rectangle circumscribing the circle (side = diameter), \
                 the inscribed one (side = diameter/√2) or the square of equal solid angle (side ≈ 0.886 × diameter), \
                 and say which in the numbers' \"source\"",
        )),
        other => {
            return Err(o.err(
                "shape",
                format!(
                    "unknown shape {other:?}; allowed: rectangle (and \"pixels\" for a receptor of a gloss geometry \
                     with a `profile` array, docs/instrument.md §1.9)"
                ),
            ))
        }
    }
    o.deny_unknown(allowed)?;
    let what = "a full aperture angle in degrees";
    let a = sourced(o, "in_plane_deg", Range::open(0.0, 20.0), what)?;
    let b = sourced(o, "perpendicular_deg", Range::open(0.0, 20.0), what)?;
    Ok((a, b))
}

/// The fields every geometry file opens with, gloss and colour alike: `id` (lower-case letters, digits, '-' and
/// '.'), a non-empty `title`, the `standards` it follows (strings) and optional `notes` (a string).
pub(crate) fn header<'a>(o: &Obj<'a>) -> Result<(&'a str, String)> {
    let id = o.str("id")?;
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-' || c == '.') {
        return Err(o.err("id", format!("{id:?} is not a valid id: use lower-case letters, digits, '-' and '.'")));
    }
    let title = nonempty_str(o, "title")?;
    string_list(o, "standards")?;
    if let Some(v) = o.get("notes") {
        if !v.is_string() {
            return Err(o.err("notes", format!("expected a string, got {}", kind(v))));
        }
    }
    Ok((id, title))
}

pub(crate) fn nonempty_str(o: &Obj, key: &str) -> Result<String> {
    let s = o.str(key)?;
    if s.trim().is_empty() {
        return Err(o.err(key, "must not be empty"));
    }
    Ok(s.to_string())
}

/// A non-empty array of non-empty strings.
pub(crate) fn string_list(o: &Obj, key: &str) -> Result<Vec<String>> {
    let a = o.array(key)?;
    if a.is_empty() {
        return Err(o.err(key, "must list at least one entry"));
    }
    a.iter()
        .enumerate()
        .map(|(i, v)| match v.as_str() {
            Some(s) if !s.trim().is_empty() => Ok(s.to_string()),
            _ => Err(Error::input(o.file, o.element(key, i), format!("expected a non-empty string, got {}", kind(v)))),
        })
        .collect()
}

/// One sourced number from the spec as "value unit [status] source".
pub(crate) fn sourced_text(v: Option<&Value>, unit: &str) -> String {
    let Some(v) = v else { return "(absent)".to_string() };
    let value = v.get("value").map(|x| x.to_string()).unwrap_or_default();
    let status = v.get("status").and_then(Value::as_str).unwrap_or("?");
    let source = v.get("source").and_then(Value::as_str).unwrap_or("");
    format!("{value}{unit} [{status}]\n        source: {source}")
}
