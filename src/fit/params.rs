//! What is fitted to what: the free parameters (JSON Pointers into the recipe with bounds, fitted linearly or
//! in the logarithm), the target readings (from the command line's words or from a sheet), and the check of
//! the free parameters against the recipe and the parameter registry.
use serde_json::Value;

use crate::error::Words;
use crate::registry;
use crate::{Error, Result};

/// A free parameter: a JSON Pointer into the recipe, bounds, and whether its logarithm is fitted.
#[derive(Clone, Debug, PartialEq)]
pub struct FreeParameter {
    pub pointer: String,
    pub lower: f64,
    pub upper: f64,
    pub log: bool,
}

impl FreeParameter {
    /// Parse `PATH=LO..HI` or `PATH=log:LO..HI` (the `--free` argument).
    pub fn parse(arg: &str) -> Result<FreeParameter> {
        let bad = |m: String| Error::argument("free", format!(" {arg}: {m}"));
        let (pointer, bounds) = arg
            .split_once('=')
            .ok_or_else(|| bad("expected PATH=LO..HI (or PATH=log:LO..HI), e.g. /roughness=log:1e-3..0.5".into()))?;
        if !pointer.starts_with('/') {
            return Err(bad(format!("{pointer:?} is not a JSON Pointer (RFC 6901); it starts with '/'")));
        }
        let (log, range) = match bounds.strip_prefix("log:") {
            Some(r) => (true, r),
            None => (false, bounds),
        };
        let (lo, hi) = range.split_once("..").ok_or_else(|| bad(format!("bounds {bounds:?} are not LO..HI")))?;
        let num = |s: &str, what: &str| -> Result<f64> {
            s.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad(format!("{what} bound {s:?} is not a finite number")))
        };
        let (lower, upper) = (num(lo, "lower")?, num(hi, "upper")?);
        if lower >= upper {
            return Err(bad(format!("the lower bound {lower} must be below the upper bound {upper} (LO < HI)")));
        }
        if log && lower <= 0.0 {
            return Err(bad(format!("log: bounds must be positive, got {lower}..{upper}")));
        }
        Ok(FreeParameter { pointer: pointer.to_string(), lower, upper, log })
    }

    /// The fitted variable t of a value x (x or ln x).
    pub(super) fn t_of_x(&self, x: f64) -> f64 {
        if self.log {
            x.ln()
        } else {
            x
        }
    }

    pub(super) fn x_of(&self, t: f64) -> f64 {
        if self.log {
            t.exp()
        } else {
            t
        }
    }

    /// Bounds in t.
    pub(super) fn t_bounds(&self) -> (f64, f64) {
        (self.t_of_x(self.lower), self.t_of_x(self.upper))
    }
}

/// A target: a reading of a geometry with its measured value and (optional) uncertainty.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetReading {
    pub geometry: String,
    /// A reading name (`gloss`, `haze-narrow`, `doi`, …) or quantity, as `compare` matches them.
    pub name: String,
    pub value: f64,
    pub uncertainty: Option<f64>,
}

impl TargetReading {
    /// Parse `GEOMETRY/READING=VALUE`, `…=VALUE±U` or `…=VALUE+-U` (the `--target` argument).
    pub fn parse(arg: &str) -> Result<TargetReading> {
        let bad = |m: String| Error::argument("target", format!(" {arg}: {m}"));
        let (left, right) = arg
            .split_once('=')
            .ok_or_else(|| bad("expected GEOMETRY/READING=VALUE[±U], e.g. astm-d523-60/gloss=85±0.5".into()))?;
        let (geometry, name) = left
            .split_once('/')
            .ok_or_else(|| bad(format!("{left:?} is not GEOMETRY/READING (e.g. astm-d523-20/gloss)")))?;
        if geometry.is_empty() || name.is_empty() {
            return Err(bad("the geometry and the reading must both be given".into()));
        }
        let (v, u) = match right.split_once('±').or_else(|| right.split_once("+-")) {
            Some((v, u)) => (v, Some(u)),
            None => (right, None),
        };
        let value = v
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| bad(format!("value {v:?} is not a finite number")))?;
        let uncertainty = match u {
            None => None,
            Some(u) => Some(
                u.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite() && *x > 0.0)
                    .ok_or_else(|| bad(format!("uncertainty {u:?} is not a finite number > 0")))?,
            ),
        };
        Ok(TargetReading { geometry: geometry.to_string(), name: name.to_string(), value, uncertainty })
    }
}

/// Targets from a parsed glossmeter sheet (`comparison::sheet`, every layout `compare` reads): the rows of one
/// sample (`sample`, or the sheet's only sample), grouped by reading as `compare` groups them
/// ([`crate::comparison::group_rows`]). A group's value is the mean x̄ of its n repeated readings and its
/// uncertainty is √(u² + s²/n), u the largest stated `uncertainty` of its rows (an allowance that averaging
/// does not reduce) and s/√n the standard error of the mean (n ≥ 2); a group with neither (one reading, no
/// stated uncertainty) gets `None`, the fit's default. Rows whose reading glossmeter does not predict (the
/// sheet reader marks them) are left out and named in the returned notes. A sample the sheet lacks, or a
/// sheet of several samples without `sample`, is an [`Error::Argument`] naming `sample`.
pub fn targets_from_sheet(
    sheet: &crate::comparison::sheet::Sheet,
    sample: Option<&str>,
) -> Result<(Vec<TargetReading>, Vec<String>)> {
    let mut samples: Vec<&str> = Vec::new();
    for r in &sheet.rows {
        if !samples.contains(&r.sample.as_str()) {
            samples.push(&r.sample);
        }
    }
    let chosen = match sample {
        Some(s) if samples.contains(&s) => s,
        Some(s) => {
            return Err(Error::argument(
                "sample",
                format!(" {s}: {} has no sample {s:?}; it has {}", sheet.file, samples.join(", ")),
            ))
        }
        None if samples.len() == 1 => samples[0],
        None => {
            return Err(Error::Argument(
                Words::argument("sheet")
                    .and(format!(
                        " {}: the sheet has {} samples ({}); choose one with ",
                        sheet.file,
                        samples.len(),
                        samples.join(", ")
                    ))
                    .and_argument("sample"),
            ))
        }
    };
    let rows: Vec<_> = sheet.rows.iter().filter(|r| r.sample == chosen).cloned().collect();
    let mut targets = Vec::new();
    let mut notes = Vec::new();
    for g in crate::comparison::group_rows(&rows) {
        if let Some(why) = &g.not_predicted {
            notes.push(format!(
                "{} line {}: column {} is not a target: {why}",
                sheet.file,
                g.lines[0],
                g.columns.join(", ")
            ));
            continue;
        }
        let n = g.stats.n as f64;
        let sem2 = if g.stats.n > 1 { g.stats.std * g.stats.std / n } else { 0.0 };
        let u2 = g.uncertainty.map_or(0.0, |u| u * u);
        let combined = (u2 + sem2).sqrt();
        targets.push(TargetReading {
            geometry: g.geometry,
            name: g.reading,
            value: g.stats.mean,
            uncertainty: (combined > 0.0 && combined.is_finite()).then_some(combined),
        });
    }
    if targets.is_empty() {
        return Err(Error::argument(
            "sheet",
            format!(" {}: sample {chosen:?} has no reading glossmeter predicts, so no targets", sheet.file),
        ));
    }
    Ok((targets, notes))
}

/// Check the free parameters against the recipe and the registry: an unknown or non-numeric path, bounds
/// outside the registry's range, a start outside its bounds are usage errors naming the argument.
pub(super) fn check_free(recipe: &Value, free: &[FreeParameter]) -> Result<Vec<f64>> {
    let model = recipe.get("model").and_then(Value::as_str).unwrap_or("");
    let mut start = Vec::new();
    for (i, p) in free.iter().enumerate() {
        let bad = |m: String| Error::argument("free", format!(" {}: {m}", p.pointer));
        if free[..i].iter().any(|q| q.pointer == p.pointer) {
            return Err(bad("the same parameter is free twice".into()));
        }
        let entry = registry::lookup(model, &p.pointer).ok_or_else(|| {
            let numeric: Vec<&str> =
                registry::of_model(model).filter(|e| e.ty.is_numeric()).map(|e| e.pointer).collect();
            bad(format!("not a parameter of a {model:?} recipe; its numeric parameters are {}", numeric.join(", ")))
        })?;
        let v = recipe.pointer(&p.pointer).ok_or_else(|| {
            bad(format!(
                "the recipe has no value at {} (add it with a starting value: the fit starts from the recipe)",
                p.pointer
            ))
        })?;
        let x = v.as_f64().filter(|_| v.is_number()).ok_or_else(|| {
            bad(format!(
                "the value at {} is {}, not a number; address one number (e.g. {}/0)",
                p.pointer,
                crate::input::json::kind(v),
                p.pointer
            ))
        })?;
        let r = entry.range.ok_or_else(|| bad(format!("{} is not numeric", entry.pointer)))?;
        if !(r.contains(p.lower) || p.lower == r.lo) || !(r.contains(p.upper) || p.upper == r.hi) {
            return Err(bad(format!(
                "bounds {}..{} leave the allowed range of {} ({}: {})",
                crate::error::number(p.lower),
                crate::error::number(p.upper),
                entry.pointer,
                r.describe(),
                entry.description
            )));
        }
        if !(x > p.lower && x < p.upper) {
            return Err(bad(format!(
                "the start (the recipe's value {}) is outside the bounds; it must lie strictly between {} and {}",
                crate::error::number(x),
                crate::error::number(p.lower),
                crate::error::number(p.upper)
            )));
        }
        start.push(x);
    }
    Ok(start)
}
