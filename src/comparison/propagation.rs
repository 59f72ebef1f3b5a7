//! The prediction's uncertainty: the standard uncertainties a recipe states for its numbers (its `uncertainty`
//! block, `recipe::uncertainty`) propagated to every reading to first order (docs/instrument.md §The
//! prediction's uncertainty).
//!
//! GUM's law of propagation for uncorrelated inputs (JCGM 100:2008 §5.1.2, eq. (10)):
//!
//! ```text
//! u_pred² = Σᵢ cᵢ² u(xᵢ)²,      cᵢ = ∂y/∂xᵢ,
//! ```
//!
//! each sensitivity cᵢ by a central difference with the step hᵢ = u(xᵢ):
//! cᵢ = [y(xᵢ + uᵢ) − y(xᵢ − uᵢ)] / (2uᵢ). Why that step: GUM §5.1.3 reads cᵢ·u(xᵢ) as the variation of y
//! that the input's standard uncertainty generates, and the spreadsheet method (Kragten 1994; EURACHEM/CITAC
//! QUAM:2012 Appendix E.2) computes it by displacing each input by u(xᵢ). The central form cancels the
//! curvature's leading term (its error is u²·y‴/6, not u·y″/2), the slope is taken over the span the input
//! actually varies in, and the step is far larger than the readings' numerical error, which a step near the
//! rounding level would difference into noise. Where one side leaves the registry's range of the number (a
//! roughness of 0.001 with u = 0.002), the difference is one-sided on the other side (forward or backward),
//! with the same step.
//!
//! Every displaced recipe is read through the same plan: the plan of the recipe, compiled and frozen once
//! (`Plan::freeze`), so that each reading moves smoothly with the number and the difference holds no change
//! of quadrature partition; a displaced material of another shape (`Plan::with_material` refuses it) gets a
//! plan of its own.
use rayon::prelude::*;
use serde_json::Value;

use crate::instrument::plan::{Plan, PlanOptions, Reading};
use crate::instrument::standards::StandardGeometry;
use crate::recipe::uncertainty::{self, Stated};
use crate::recipe::{self, Material};
use crate::{Error, Result};

/// How a sensitivity was differenced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Difference {
    /// [y(x + u) − y(x − u)] / 2u.
    Central,
    /// [y(x + u) − y(x)] / u (x − u is outside the number's range).
    Forward,
    /// [y(x) − y(x − u)] / u (x + u is outside the number's range).
    Backward,
}

impl Difference {
    pub(crate) fn label(&self) -> &'static str {
        match self {
            Difference::Central => "central",
            Difference::Forward => "forward",
            Difference::Backward => "backward",
        }
    }
}

/// One input's share of a reading's prediction uncertainty (a line of its uncertainty budget).
#[derive(Clone, Debug, PartialEq)]
pub struct Contribution {
    /// The JSON Pointer of the recipe's number.
    pub pointer: String,
    /// Its standard uncertainty u(xᵢ), in its unit.
    pub u: f64,
    /// cᵢ = ∂y/∂xᵢ, in the reading's unit per the number's unit.
    pub sensitivity: f64,
    /// |cᵢ|·u(xᵢ), in the reading's unit.
    pub contribution: f64,
    pub difference: Difference,
}

/// A reading's prediction uncertainty: u_pred = √(Σ (cᵢ u(xᵢ))²) and its budget.
#[derive(Clone, Debug, PartialEq)]
pub struct PredictionUncertainty {
    /// u_pred, a standard uncertainty in the reading's unit.
    pub u: f64,
    /// One per stated number, in the order of the recipe's block.
    pub contributions: Vec<Contribution>,
}

/// The recipe `json` with the number at `pointer` set to `x` and without its `uncertainty` block (a displaced
/// recipe is a point, not a statement of uncertainty).
pub(crate) fn displaced(json: &Value, pointer: &str, x: f64) -> Value {
    let mut v = json.clone();
    if let Some(slot) = v.pointer_mut(pointer) {
        *slot = serde_json::json!(x);
    }
    if let Some(o) = v.as_object_mut() {
        o.remove(uncertainty::KEY);
    }
    v
}

/// The readings of the material displaced at one stated number to `x`, through `frozen` (or a plan of its
/// own for a material of another shape).
fn read_at(
    material: &Material,
    s: &Stated,
    x: f64,
    frozen: &Plan,
    geometries: &[StandardGeometry],
    options: &PlanOptions,
) -> Result<Vec<Reading>> {
    let text = displaced(&material.json, &s.pointer, x).to_string();
    let m = recipe::parse_str(&text, &material.file).map_err(|e| {
        Error::input(
            &material.file,
            crate::registry::child(&crate::registry::child("", uncertainty::KEY), &s.pointer),
            format!(
                "`{}`: the recipe with this number displaced by its uncertainty ({} → {}) is not a valid recipe, so \
                 no sensitivity can be differenced there ({e}); allowed: a smaller u",
                s.pointer,
                crate::error::number(s.value),
                crate::error::number(x)
            ),
        )
    })?;
    match frozen.with_material(m.brdf.clone()) {
        Ok(p) => Ok(p.execute()),
        Err(_) => Ok(Plan::compile(m.brdf, geometries.to_vec(), options.clone())?.execute()),
    }
}

/// The value of the reading of `like`'s geometry and name among `readings` (index `i` first: one plan's
/// readings come in one order).
fn value_of(readings: &[Reading], i: usize, like: &Reading) -> std::result::Result<f64, String> {
    let r = readings
        .get(i)
        .filter(|r| r.geometry == like.geometry && r.name == like.name)
        .or_else(|| readings.iter().find(|r| r.geometry == like.geometry && r.name == like.name));
    match r {
        Some(r) => r.value.ok_or_else(|| r.problem.clone().unwrap_or_else(|| "no finite value".into())),
        None => Err("the reading is missing".into()),
    }
}

/// The prediction uncertainty of each of `centre` (the material's readings through `geometries` at
/// `options`), in its order: None for a reading without a value, and for every reading of a material whose
/// recipe states no uncertainty (then nothing is run). A displaced recipe that is not valid is an input error
/// naming the number; a displaced reading without a value is a numeric error.
pub fn propagate(
    material: &Material,
    geometries: &[StandardGeometry],
    options: &PlanOptions,
    centre: &[Reading],
) -> Result<Vec<Option<PredictionUncertainty>>> {
    if material.uncertainty.is_empty() || centre.iter().all(|r| r.value.is_none()) {
        return Ok(vec![None; centre.len()]);
    }
    let (at_centre, frozen) = Plan::compile(material.brdf.clone(), geometries.to_vec(), options.clone())?.freeze();
    // The displaced points: x + u and x − u where the range holds them.
    let mut points: Vec<(usize, f64)> = vec![];
    let mut schemes = vec![];
    for (i, s) in material.uncertainty.iter().enumerate() {
        let range = s.param.range();
        let (up, down) = (s.value + s.u, s.value - s.u);
        let scheme = match (range.contains(up), range.contains(down)) {
            (true, true) => Difference::Central,
            (true, false) => Difference::Forward,
            _ => Difference::Backward, // `uncertainty::parse` checked that one side is in the range
        };
        if scheme != Difference::Backward {
            points.push((i, up));
        }
        if scheme != Difference::Forward {
            points.push((i, down));
        }
        schemes.push(scheme);
    }
    // Each point into its own slot: the same bits on any number of threads.
    let runs: Vec<Vec<Reading>> = points
        .par_iter()
        .map(|&(i, x)| read_at(material, &material.uncertainty[i], x, &frozen, geometries, options))
        .collect::<Result<_>>()?;
    let mut out = Vec::with_capacity(centre.len());
    for (j, r) in centre.iter().enumerate() {
        if r.value.is_none() {
            out.push(None);
            continue;
        }
        let mut contributions = Vec::with_capacity(material.uncertainty.len());
        for (i, s) in material.uncertainty.iter().enumerate() {
            let at = |x: f64| -> Result<f64> {
                let k = points.iter().position(|&(pi, px)| pi == i && px == x).expect("point listed");
                value_of(&runs[k], j, r).map_err(|why| {
                    Error::Numeric(format!(
                        "{}/{}: no value with {} = {} (the value ± its stated uncertainty), so its sensitivity to \
                         it cannot be differenced: {why}",
                        r.geometry,
                        r.name,
                        s.pointer,
                        crate::error::number(x)
                    ))
                })
            };
            let centre_value = || {
                value_of(&at_centre, j, r).map_err(|why| Error::Numeric(format!("{}/{}: {why}", r.geometry, r.name)))
            };
            let (up, down) = (s.value + s.u, s.value - s.u);
            let sensitivity = match schemes[i] {
                Difference::Central => (at(up)? - at(down)?) / (up - down),
                Difference::Forward => (at(up)? - centre_value()?) / (up - s.value),
                Difference::Backward => (centre_value()? - at(down)?) / (s.value - down),
            };
            contributions.push(Contribution {
                pointer: s.pointer.clone(),
                u: s.u,
                sensitivity,
                contribution: sensitivity.abs() * s.u,
                difference: schemes[i],
            });
        }
        let u = contributions.iter().map(|c| c.contribution * c.contribution).sum::<f64>().sqrt();
        out.push(Some(PredictionUncertainty { u, contributions }));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::standards;

    #[test]
    fn a_lambert_albedos_sensitivity_is_its_reading_per_albedo() {
        // A Lambertian reading is linear in the albedo (y = a·Φ(1)), so the central difference is exact:
        // c = y / a, and u_pred = u·y/a.
        let m = recipe::parse_str(r#"{"model": "lambert", "albedo": 0.5, "uncertainty": {"/albedo": 0.01}}"#, "l.json")
            .unwrap();
        let geos = vec![standards::find("astm-d523-60").unwrap()];
        let options = PlanOptions::default();
        let centre = Plan::compile(m.brdf.clone(), geos.clone(), options.clone()).unwrap().execute();
        let u = propagate(&m, &geos, &options, &centre).unwrap();
        let y = centre[0].value.unwrap();
        let p = u[0].as_ref().unwrap();
        assert_eq!(p.contributions[0].difference, Difference::Central);
        assert!((p.u - 0.01 * y / 0.5).abs() <= 1e-9 * y, "u_pred {} against {}", p.u, 0.01 * y / 0.5);
        // Near the end of the range the difference is one-sided, with the same result for a linear reading.
        let edge =
            recipe::parse_str(r#"{"model": "lambert", "albedo": 0.995, "uncertainty": {"/albedo": 0.01}}"#, "l.json")
                .unwrap();
        let c = Plan::compile(edge.brdf.clone(), geos.clone(), options.clone()).unwrap().execute();
        let p = propagate(&edge, &geos, &options, &c).unwrap().remove(0).unwrap();
        assert_eq!(p.contributions[0].difference, Difference::Backward);
        let y = c[0].value.unwrap();
        assert!((p.u - 0.01 * y / 0.995).abs() <= 1e-9 * y, "{} against {}", p.u, 0.01 * y / 0.995);
    }

    #[test]
    fn without_a_block_nothing_is_run() {
        let m = recipe::parse_str(r#"{"model": "lambert", "albedo": 0.5}"#, "l.json").unwrap();
        let r = Reading {
            geometry: "g".into(),
            name: "gloss".into(),
            quantity: "gloss".into(),
            unit: "GU".into(),
            value: Some(1.0),
            error_estimate: 0.0,
            evaluations: 0,
            seconds: 0.0,
            converged: true,
            problem: None,
            note: None,
            data_uncertainty: None,
            colour: None,
        };
        // No geometry at all: a run would fail; none is made.
        assert_eq!(propagate(&m, &[], &PlanOptions::default(), &[r]).unwrap(), vec![None]);
    }
}
