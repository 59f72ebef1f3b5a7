//! The parameter registry (`src/registry.rs`) drives validation, the JSON Schema and the docs table:
//! the committed table in `docs/recipe-format.md` equals the generated one (regenerate it with
//! `GLOSSMETER_BLESS=1 cargo test --test registry`), every numeric entry's range is the validator's and the
//! schema's (a value at a closed bound loads, one just beyond is refused with the entry's pointer), and
//! error paths are RFC 6901 pointers that `lookup` resolves back to the entry.
use glossmeter::recipe::{self, schema::schema};
use glossmeter::registry::{self, Param, Presence, Type, PARAMS};
use glossmeter::Error;
use serde_json::{json, Value};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn docs_table_is_the_generated_one() {
    let path = root().join("docs/recipe-format.md");
    let doc = std::fs::read_to_string(&path).unwrap();
    let fresh = registry::with_tables(&doc).unwrap_or_else(|e| panic!("docs/recipe-format.md: {e}"));
    // Every entry is in some table: its model's (for shared entries, one of its models') or the common one.
    let has = |m: &str| doc.contains(&format!("{}{m} -->", registry::TABLE_BEGIN));
    assert!(has("common"));
    for e in PARAMS {
        assert!(e.models == recipe::MODELS || e.models.iter().any(|m| has(m)), "{} is in no docs table", e.pointer);
    }
    if std::env::var_os("GLOSSMETER_BLESS").is_some() {
        if fresh != doc {
            std::fs::write(&path, &fresh).unwrap();
        }
        return;
    }
    assert!(
        fresh == doc,
        "docs/recipe-format.md: the parameter table differs from src/registry.rs; regenerate it with \
         `GLOSSMETER_BLESS=1 cargo test --test registry`"
    );
}

/// A valid recipe of each model, the base that the range probes edit.
fn base(model: &str) -> Value {
    let paint: Value =
        serde_json::from_str(&std::fs::read_to_string(root().join("fixtures/recipes/cerulean-blue-c.json")).unwrap())
            .unwrap();
    match model {
        "smooth-dielectric" => json!({"model": model, "ior": 1.5}),
        "conductor" => json!({"model": model, "ior": [[0.2, 3.0], [0.9, 6.0], [1.0, 7.0]]}),
        "lambert" => json!({"model": model, "albedo": [0.5, 0.5, 0.5]}),
        "microfacet" => json!({"model": model, "distribution": "ggx", "roughness": 0.1, "ior": 1.5}),
        "phong" | "blinn-phong" => {
            json!({"model": model, "exponent": 50, "ks": [0.1, 0.1, 0.1], "kd": [0.1, 0.1, 0.1]})
        }
        "ward" => json!({"model": model, "alpha": 0.1, "rho_s": [0.1, 0.1, 0.1], "rho_d": [0.1, 0.1, 0.1]}),
        "cook-torrance-lobes" => {
            json!({"model": model, "kd": [0.1, 0.1, 0.1], "lobes": [{"ks": [0.1, 0.1, 0.1], "r": 0.5, "m": 0.2}]})
        }
        "paint" => paint,
        _ => Value::Null,
    }
}

/// The concrete pointer of the first number an entry governs in `v` (index 0 for `*` and for arrays).
fn first_number(e: &Param, v: &Value) -> Option<String> {
    let p = e.pointer.replace('*', "0");
    match v.pointer(&p)? {
        Value::Number(_) => Some(p),
        Value::Array(a) if e.ty != Type::Number && a.first().is_some_and(Value::is_number) => Some(format!("{p}/0")),
        _ => None,
    }
}

fn load(v: &Value) -> glossmeter::Result<recipe::Material> {
    recipe::parse_str(&v.to_string(), "probe.json")
}

/// Every numeric entry that the base recipes have: at a closed bound the recipe loads (unless a cross-field
/// constraint forbids it), beyond a bound it is refused with the concrete pointer, and `lookup` of that
/// pointer gives the entry back.
#[test]
fn every_range_is_enforced_at_the_entrys_pointer() {
    let mut probed = 0;
    for e in PARAMS.iter().filter(|e| e.range.is_some()) {
        for model in e.models {
            let v = base(model);
            let Some(ptr) = first_number(e, &v) else { continue };
            assert_eq!(registry::lookup(model, &ptr), Some(*e), "lookup({model}, {ptr})");
            let r = e.range();
            let beyond = [
                r.lo.is_finite().then(|| if r.lo_closed { r.lo - 1e-9 * r.lo.abs().max(1.0) } else { r.lo }),
                r.hi.is_finite().then(|| if r.hi_closed { r.hi + 1e-9 * r.hi.abs().max(1.0) } else { r.hi }),
            ];
            for x in beyond.into_iter().flatten() {
                let mut w = v.clone();
                *w.pointer_mut(&ptr).unwrap() = json!(x);
                match load(&w) {
                    Err(Error::Input { field, message, .. }) => {
                        assert_eq!(field, ptr, "{model} {ptr} = {x}: {message}");
                        probed += 1;
                    }
                    other => panic!("{model} {ptr} = {x}: expected an input error, got {other:?}"),
                }
            }
            // At a closed finite bound the value itself is accepted by the number check (a cross-field
            // constraint may still refuse it, but then not with an out-of-range message).
            for x in
                [r.lo_closed.then_some(r.lo), (r.hi_closed && r.hi.is_finite()).then_some(r.hi)].into_iter().flatten()
            {
                let mut w = v.clone();
                *w.pointer_mut(&ptr).unwrap() = json!(x);
                if let Err(e) = load(&w) {
                    assert!(!e.to_string().contains("out of range"), "{model} {ptr} = {x}: {e}");
                }
            }
        }
    }
    assert!(probed >= 40, "only {probed} bounds probed");
}

/// Walk the schema along a concrete pointer (through properties, items, prefixItems and oneOf) and collect
/// the numeric leaves found there.
fn schema_leaves<'a>(s: &'a Value, tokens: &[&str], out: &mut Vec<&'a Value>) {
    if let Some(alts) = s.get("oneOf").and_then(Value::as_array) {
        for a in alts {
            schema_leaves(a, tokens, out);
        }
    }
    match tokens.split_first() {
        None => {
            if s["type"] == "number" {
                out.push(s);
            } else if let Some(items) = s.get("items").filter(|i| i.is_object()) {
                schema_leaves(items, tokens, out);
            }
        }
        Some((t, rest)) => {
            if let Some(p) = s.get("properties").and_then(|p| p.get(*t)) {
                schema_leaves(p, rest, out);
            }
            if let Ok(i) = t.parse::<usize>() {
                if let Some(p) = s.get("prefixItems").and_then(|p| p.get(i)) {
                    schema_leaves(p, rest, out);
                } else if let Some(items) = s.get("items").filter(|i| i.is_object()) {
                    schema_leaves(items, rest, out);
                }
            }
        }
    }
}

#[test]
fn schema_bounds_are_the_registrys() {
    let s = schema();
    let mut checked = 0;
    for e in PARAMS.iter().filter(|e| e.range.is_some()) {
        for model in e.models {
            let sub = s["oneOf"].as_array().unwrap().iter().find(|m| m["properties"]["model"]["const"] == *model);
            let sub = sub.unwrap_or_else(|| panic!("no subschema for {model}"));
            let concrete = e.pointer.replace('*', "0");
            let tokens: Vec<&str> = concrete.trim_start_matches('/').split('/').collect();
            let mut leaves = Vec::new();
            schema_leaves(sub, &tokens, &mut leaves);
            assert!(!leaves.is_empty(), "{model} {}: no numeric leaf in the schema", e.pointer);
            let r = e.range();
            for l in leaves {
                let (lo_key, hi_key) = (
                    if r.lo_closed { "minimum" } else { "exclusiveMinimum" },
                    if r.hi_closed { "maximum" } else { "exclusiveMaximum" },
                );
                if r.lo.is_finite() {
                    assert_eq!(l[lo_key].as_f64(), Some(r.lo), "{model} {}: {l}", e.pointer);
                }
                if r.hi.is_finite() {
                    assert_eq!(l[hi_key].as_f64(), Some(r.hi), "{model} {}: {l}", e.pointer);
                } else {
                    assert!(l.get("maximum").is_none() && l.get("exclusiveMaximum").is_none(), "{l}");
                }
                checked += 1;
            }
        }
    }
    assert!(checked >= 50, "{checked}");
    // Required fields of the schema are the registry's required entries.
    let lambert = s["oneOf"].as_array().unwrap().iter().find(|m| m["title"] == "lambert").unwrap();
    assert_eq!(lambert["required"], json!(["model", "albedo"]));
    let req: Vec<&str> = registry::of_model("paint")
        .filter(|e| e.presence == Presence::Required && e.pointer.matches('/').count() == 1)
        .map(|e| e.pointer)
        .collect();
    assert_eq!(req, ["/model", "/clear_coat", "/pigmented_layer"]);
}

/// An error names the field as a JSON Pointer with RFC 6901 escaping, which resolves in the recipe.
#[test]
fn error_paths_are_json_pointers() {
    let v = json!({"model": "lambert", "albedo": 0.5, "a/b~c": 1});
    match load(&v) {
        Err(Error::Input { field, .. }) => {
            assert_eq!(field, "/a~1b~0c");
            assert_eq!(v.pointer(&field), Some(&json!(1)), "the path resolves in the recipe");
        }
        other => panic!("{other:?}"),
    }
    let mut v = base("cook-torrance-lobes");
    v["lobes"][0]["m"] = json!(-1);
    let e = load(&v).unwrap_err();
    assert!(e.to_string().contains("field `/lobes/0/m`: -1 is out of range; allowed: [0, 10]"), "{e}");
    let mut v = base("paint");
    v["pigmented_layer"]["pigments"][0]["concentration"] = json!("x");
    let e = load(&v).unwrap_err().to_string();
    assert!(e.contains("/pigmented_layer/pigments/0/concentration") && e.contains("≥ 0"), "{e}");
}

/// Every field a shipped fixture has is registered (the validator refuses unregistered keys, so this is
/// the converse: nothing is registered at a place the schema does not have).
#[test]
fn every_entry_is_typed_and_described() {
    for e in PARAMS {
        assert!(!e.description.trim().is_empty(), "{}", e.pointer);
        assert!(!e.description.contains('\n'), "{}: one line", e.pointer);
        if let Type::Choice(c) = e.ty {
            assert!(!c.is_empty());
        }
    }
}
