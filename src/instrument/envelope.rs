//! The tolerance envelope: how far a reading can move within what the standard allows. A real meter is
//! built to the standard's tolerances, not to its nominal numbers, and several numbers in the shipped
//! geometries are assumed; a user comparing with a real meter needs the spread, not only the nominal value.
//!
//! The standards files carry the variations beside each number (`standards/sourced.rs`, `check_variation`):
//! `"tolerance"` (the number ± t, as a standard's Table gives it) and `"plausible"` (the range an assumed
//! number may lie in). Each variation has its own source and status. The envelope is read at the corners of
//! the box they span: every number at its low or high end, all combinations (2^k geometries), when
//! k ≤ [`MAX_CORNER_VARIATIONS`]; beyond that, one number at a time at each end with the others nominal
//! (2k geometries), which is exact for a reading monotone in each number separately and otherwise a lower
//! bound of the spread. The minimum and maximum over the variants and the nominal reading are reported.
use super::standards::{self, StandardGeometry};
use crate::{Error, Result};
use serde_json::Value;

/// Largest number of variations read at all 2^k corners.
pub(crate) const MAX_CORNER_VARIATIONS: usize = 6;

/// One number of a geometry that the standard (or the uncertainty of an assumption) lets vary.
#[derive(Clone, Debug, PartialEq)]
pub struct Variation {
    /// JSON Pointer (RFC 6901) of the sourced number in the geometry file, e.g. `/receptors/0/in_plane_deg`.
    pub pointer: String,
    pub nominal: f64,
    pub low: f64,
    pub high: f64,
    /// `"tolerance"` or `"plausible"`.
    pub kind: &'static str,
    /// The variation's own status (`verified`, `secondary`, `assumed`).
    pub status: String,
}

/// The variations of a geometry specification, in document order.
pub(crate) fn variations(spec: &Value) -> Vec<Variation> {
    let mut out = Vec::new();
    walk(spec, String::new(), &mut out);
    out
}

fn walk(v: &Value, pointer: String, out: &mut Vec<Variation>) {
    match v {
        Value::Object(m) => {
            if let Some(nominal) = m.get("value").and_then(Value::as_f64) {
                let status = |t: &Value| t.get("status").and_then(Value::as_str).unwrap_or("?").to_string();
                if let Some(t) = m.get("tolerance") {
                    if let Some(tol) = t.get("value").and_then(Value::as_f64) {
                        out.push(Variation {
                            pointer: pointer.clone(),
                            nominal,
                            low: nominal - tol,
                            high: nominal + tol,
                            kind: "tolerance",
                            status: status(t),
                        });
                    }
                }
                if let Some(t) = m.get("plausible") {
                    if let (Some(lo), Some(hi)) =
                        (t.get("low").and_then(Value::as_f64), t.get("high").and_then(Value::as_f64))
                    {
                        out.push(Variation {
                            pointer: pointer.clone(),
                            nominal,
                            low: lo,
                            high: hi,
                            kind: "plausible",
                            status: status(t),
                        });
                    }
                }
                return;
            }
            for (k, x) in m {
                walk(x, format!("{pointer}/{}", k.replace('~', "~0").replace('/', "~1")), out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                walk(x, format!("{pointer}/{i}"), out);
            }
        }
        _ => {}
    }
}

/// The values every variant gives each variation (one vector per variant, in `variations` order).
pub(crate) fn variant_values(vars: &[Variation]) -> Vec<Vec<f64>> {
    let k = vars.len();
    if k == 0 {
        return Vec::new();
    }
    if k <= MAX_CORNER_VARIATIONS {
        (0..1usize << k)
            .map(|bits| vars.iter().enumerate().map(|(j, v)| if bits >> j & 1 == 1 { v.high } else { v.low }).collect())
            .collect()
    } else {
        let mut out = Vec::with_capacity(2 * k);
        for j in 0..k {
            for end in [vars[j].low, vars[j].high] {
                out.push(vars.iter().enumerate().map(|(i, v)| if i == j { end } else { v.nominal }).collect());
            }
        }
        out
    }
}

/// The variant geometries of `g` (empty if its data give no variation). The same number may vary twice
/// (tolerance and plausible range): the variants then take the extreme of both ends.
pub fn variants(g: &StandardGeometry) -> Result<(Vec<Variation>, Vec<StandardGeometry>)> {
    let vars = variations(&g.spec);
    let mut out = Vec::new();
    for values in variant_values(&vars) {
        let mut spec = Value::clone(&g.spec);
        for (v, x) in vars.iter().zip(&values) {
            let slot = spec
                .pointer_mut(&format!("{}/value", v.pointer))
                .ok_or_else(|| Error::Numeric(format!("envelope: {} has no value", v.pointer)))?;
            *slot = serde_json::json!(x);
        }
        let text = serde_json::to_string(&spec).map_err(|e| Error::Numeric(format!("envelope: {e}")))?;
        let label = format!("<envelope of {}>", g.geometry.id);
        let mut variant = standards::parse(&text, &label)?;
        variant.origin = g.origin.clone();
        out.push(variant);
    }
    Ok((vars, out))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_and_one_at_a_time() {
        let v = |lo, hi| Variation {
            pointer: String::new(),
            nominal: 0.5 * (lo + hi),
            low: lo,
            high: hi,
            kind: "tolerance",
            status: "assumed".into(),
        };
        let two = variant_values(&[v(0.0, 1.0), v(2.0, 3.0)]);
        assert_eq!(two, vec![vec![0.0, 2.0], vec![1.0, 2.0], vec![0.0, 3.0], vec![1.0, 3.0]]);
        let many: Vec<Variation> = (0..8).map(|i| v(i as f64, i as f64 + 2.0)).collect();
        let vals = variant_values(&many);
        assert_eq!(vals.len(), 16);
        assert_eq!(vals[1][0], 2.0);
        assert_eq!(vals[1][1], 2.0);
    }

    #[test]
    fn the_d523_files_state_their_tolerances() {
        let g = standards::find("astm-d523-60").unwrap();
        let (vars, geos) = variants(&g).unwrap();
        assert!(vars.iter().any(|v| v.pointer == "/angle_deg" && v.kind == "tolerance"), "{vars:?}");
        assert!(vars.iter().any(|v| v.pointer == "/source/perpendicular_deg" && v.kind == "plausible"));
        assert_eq!(geos.len(), 1 << vars.len());
    }
}

/// The envelope of one reading: the extremes over the variants and the nominal reading.
#[derive(Clone, Debug, PartialEq)]
pub struct Envelope {
    pub geometry: String,
    pub name: String,
    pub min: f64,
    pub max: f64,
    /// How many variant geometries were read (0: the data give no tolerance for this geometry).
    pub variants: usize,
    /// Whether the variants are all 2^k corners (else one number at a time).
    pub corners: bool,
    /// The numbers varied.
    pub variations: Vec<Variation>,
}

/// The envelopes of a set of readings ([`read`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Envelopes {
    /// One per reading of the nominal set, in its order ([`read`]).
    pub of: Vec<Option<Envelope>>,
    /// The geometries (ids) whose envelope the wall-clock limit cut: a variant not started before the deadline,
    /// or one with a reading the limit left without a value. Their envelopes are `None`: an extreme over the
    /// variants read in time would depend on the machine's speed (docs/instrument.md §Bounded work).
    pub cut: Vec<String>,
}

/// Read `brdf` through every variant of every geometry; one envelope per reading of `nominal` (in its
/// order) that has a value, `None` for a reading without a value, of a composite geometry, of a geometry
/// without variations, or of one the limit cut. `deadline` is the command's own wall-clock limit
/// (`PlanOptions::max_seconds` counted from the start of the command, not of each variant; None: none): every
/// variant plan runs under it ([`Plan::run_until`](super::plan::Plan::run_until)), and a variant that would
/// start after it is not read.
pub fn read(
    brdf: std::sync::Arc<dyn crate::brdf::Brdf>,
    geometries: &[StandardGeometry],
    nominal: &[super::plan::Reading],
    options: super::plan::PlanOptions,
    deadline: Option<std::time::Instant>,
) -> Result<Envelopes> {
    let mut out: Vec<Option<Envelope>> = vec![None; nominal.len()];
    let mut cut = Vec::new();
    for g in geometries {
        if g.geometry.is_composite() {
            continue;
        }
        let (vars, geos) = variants(g)?;
        if geos.is_empty() {
            continue;
        }
        let n = geos.len();
        let mut readings = Vec::with_capacity(n);
        let mut late = false;
        for v in geos {
            if deadline.is_some_and(|d| std::time::Instant::now() >= d) {
                late = true;
                break;
            }
            let plan = super::plan::Plan::compile(brdf.clone(), vec![v], options.clone())?;
            let run = plan.run_until(deadline);
            late |= run.fluxes.iter().any(|f| f.out_of_time);
            readings.push(run.readings);
        }
        if late {
            cut.push(g.geometry.id.clone());
            continue;
        }
        for (i, r) in nominal.iter().enumerate() {
            let (true, Some(value)) = (r.geometry == g.geometry.id, r.value) else { continue };
            let (mut lo, mut hi) = (value, value);
            let mut complete = true;
            for rs in &readings {
                match rs.iter().find(|x| x.name == r.name).and_then(|x| x.value) {
                    Some(x) => {
                        lo = lo.min(x);
                        hi = hi.max(x);
                    }
                    None => complete = false,
                }
            }
            if complete {
                out[i] = Some(Envelope {
                    geometry: r.geometry.clone(),
                    name: r.name.clone(),
                    min: lo,
                    max: hi,
                    variants: n,
                    corners: vars.len() <= MAX_CORNER_VARIATIONS,
                    variations: vars.clone(),
                });
            }
        }
    }
    Ok(Envelopes { of: out, cut })
}
