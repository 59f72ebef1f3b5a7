//! A recipe's `uncertainty` block: the standard uncertainties of some of its numbers, which the readings'
//! prediction uncertainty is propagated from (`comparison::propagation`; docs/instrument.md §The prediction's
//! uncertainty).
//!
//! ```json
//! "uncertainty": {"/clear_coat/roughness": 0.002, "/clear_coat/index": 0.01}
//! ```
//!
//! Each key is an RFC 6901 JSON Pointer to one number of the recipe that a numeric entry of its model's
//! registry governs (`/clear_coat/roughness`, an element such as `/albedo/1` or `/ior/0`); each value is that
//! number's standard uncertainty u > 0 (JCGM 100:2008 §2.3.1: the uncertainty expressed as a standard
//! deviation), in the entry's unit. The inputs are taken as uncorrelated. Every error names the file, the
//! block's own pointer of the key (`/uncertainty/~1clear_coat~1roughness`), the key as written and what is
//! allowed.
use crate::input::json::{kind, show};
use crate::registry::{self, Param};
use crate::{Error, Result};
use serde_json::Value;

/// The key of the block in a recipe.
pub(crate) const KEY: &str = "uncertainty";

/// At most this many numbers may carry an uncertainty (each costs two runs of the plan).
pub(crate) const MAX_STATED: usize = 64;

/// One number of the recipe with its standard uncertainty.
#[derive(Clone, Debug, PartialEq)]
pub struct Stated {
    /// The concrete JSON Pointer of the number in the recipe (the key as written).
    pub pointer: String,
    /// The recipe's value there.
    pub value: f64,
    /// The standard uncertainty, > 0, in the entry's unit.
    pub u: f64,
    /// The registry entry that governs the number: its range bounds the displaced values.
    pub param: &'static Param,
}

/// The numbers of the recipe `json` (of `model`) that a numeric registry entry governs, as concrete pointers in
/// document order (the block itself left out): what an `uncertainty` key may name.
pub(crate) fn candidates(json: &Value, model: &str) -> Vec<String> {
    fn walk(v: &Value, at: String, model: &str, out: &mut Vec<String>) {
        match v {
            Value::Number(_) if registry::lookup(model, &at).is_some_and(|e| e.ty.is_numeric()) => out.push(at),
            Value::Object(m) => {
                for (k, x) in m {
                    if at.is_empty() && k == KEY {
                        continue;
                    }
                    walk(x, registry::child(&at, k), model, out);
                }
            }
            Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    walk(x, format!("{at}/{i}"), model, out);
                }
            }
            _ => {}
        }
    }
    let mut out = vec![];
    walk(json, String::new(), model, &mut out);
    out
}

/// The `uncertainty` block of the recipe `json` (of `model`, read from `file`), checked: none when absent.
pub fn parse(json: &Value, file: &str, model: &str) -> Result<Vec<Stated>> {
    let Some(block) = json.get(KEY) else { return Ok(vec![]) };
    let at = registry::child("", KEY);
    let example = "{\"/clear_coat/roughness\": 0.002}";
    let Value::Object(map) = block else {
        return Err(Error::input(
            file,
            at,
            format!("expected an object of JSON Pointers to the recipe's numbers and their standard uncertainties (e.g. {example}), got {}", kind(block)),
        ));
    };
    if map.len() > MAX_STATED {
        return Err(Error::input(
            file,
            at,
            format!("{} numbers carry an uncertainty; allowed: at most {MAX_STATED}", map.len()),
        ));
    }
    let allowed = || {
        let c = candidates(json, model);
        if c.is_empty() {
            format!("a `{model}` recipe has no number that can carry an uncertainty")
        } else {
            let more = if c.len() > 12 { format!(" and {} more", c.len() - 12) } else { String::new() };
            format!(
                "allowed: a pointer to one of this recipe's numbers: {}{more}",
                c.into_iter().take(12).collect::<Vec<_>>().join(", ")
            )
        }
    };
    let mut out = Vec::with_capacity(map.len());
    for (key, v) in map {
        let field = registry::child(&at, key);
        let bad = |why: String| Error::input(file, field.clone(), format!("`{key}`: {why}"));
        if !key.starts_with('/') {
            return Err(bad(format!("not a JSON Pointer (one starts with `/`, e.g. {example}); {}", allowed())));
        }
        let Some(param) = registry::lookup(model, key).filter(|e| e.ty.is_numeric()) else {
            return Err(bad(format!("not a numeric parameter of a `{model}` recipe; {}", allowed())));
        };
        let value = match json.pointer(key) {
            Some(Value::Number(n)) => n.as_f64().unwrap_or(f64::NAN),
            Some(Value::Array(_)) => {
                return Err(bad(format!(
                    "the recipe has an array there ({}); an uncertainty belongs to one number: name an element \
                     ({key}/0, ...); {}",
                    param.ty.describe(),
                    allowed()
                )))
            }
            Some(x) => return Err(bad(format!("the recipe has {} there, not a number; {}", kind(x), allowed()))),
            None => {
                return Err(bad(format!(
                    "the recipe has no value there (an uncertainty is stated for a number the recipe gives); {}",
                    allowed()
                )))
            }
        };
        let unit = if param.unit.is_empty() { String::new() } else { format!(" {}", param.unit) };
        let u = match v {
            Value::Number(n) => n.as_f64().filter(|u| u.is_finite() && *u > 0.0).ok_or_else(|| {
                bad(format!(
                    "{} is not a standard uncertainty; allowed: a finite number > 0 (in the unit of {}{unit})",
                    crate::error::given(n.as_f64().unwrap_or(f64::NAN)),
                    param.pointer
                ))
            })?,
            _ => {
                return Err(bad(format!(
                    "expected the standard uncertainty of {key}, a finite number > 0{unit}, got {}",
                    kind(v)
                )))
            }
        };
        // A difference needs the value displaced by u on at least one side within the entry's range.
        let range = param.range();
        if !range.contains(value + u) && !range.contains(value - u) {
            return Err(bad(format!(
                "u = {} puts both {} ± u outside the allowed range of {} ({}); allowed: a smaller u",
                crate::error::given(u),
                show(value),
                param.pointer,
                range.describe()
            )));
        }
        out.push(Stated { pointer: key.clone(), value, u, param });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn keys_name_the_recipes_numbers() {
        let r = json!({"model": "microfacet", "roughness": 0.1, "ior": 1.5,
                       "uncertainty": {"/roughness": 0.002, "/ior": 0.01}});
        let s = parse(&r, "r.json", "microfacet").unwrap();
        assert_eq!(s.len(), 2);
        assert_eq!((s[0].pointer.as_str(), s[0].value, s[0].u), ("/ior", 1.5, 0.01));
        assert_eq!(s[1].param, &registry::MICROFACET_ROUGHNESS);
        assert_eq!(candidates(&r, "microfacet"), ["/ior", "/roughness"]);
        let c = json!({"model": "conductor", "ior": [0.2, 3.0], "uncertainty": {"/ior/1": 0.1}});
        assert_eq!(parse(&c, "c.json", "conductor").unwrap()[0].param, &registry::CONDUCTOR_K);
    }

    #[test]
    fn bad_blocks_name_the_key_and_what_is_allowed() {
        let err = |u: Value| {
            let r = json!({"model": "microfacet", "roughness": 0.1, "ior": 1.5, "uncertainty": u});
            parse(&r, "r.json", "microfacet").unwrap_err().to_string()
        };
        let e = err(json!({"/coat/roughness": 0.002}));
        assert!(e.contains("r.json") && e.contains("/uncertainty/~1coat~1roughness"), "{e}");
        assert!(e.contains("not a numeric parameter") && e.contains("/ior, /roughness"), "{e}");
        assert!(err(json!({"roughness": 0.1})).contains("not a JSON Pointer"));
        assert!(err(json!({"/roughness": 0})).contains("finite number > 0"));
        assert!(err(json!({"/roughness": -1})).contains("finite number > 0"));
        assert!(err(json!({"/roughness": "0.1"})).contains("got string"), "{}", err(json!({"/roughness": "0.1"})));
        assert!(err(json!({"/distribution": 0.1})).contains("not a numeric parameter"));
        assert!(err(json!({"/scatter/rms_roughness_nm": 1})).contains("no value there"));
        assert!(err(json!([0.1])).contains("expected an object"));
        assert!(err(json!({"/ior": 5})).contains("outside the allowed range"));
        let a = json!({"model": "lambert", "albedo": [0.5, 0.5, 0.5], "uncertainty": {"/albedo": 0.01}});
        let e = parse(&a, "a.json", "lambert").unwrap_err().to_string();
        assert!(e.contains("/albedo/0") && e.contains("array"), "{e}");
    }
}
