//! Recipe loading and validation: every fixture loads, every invalid recipe under `fixtures/bad/` is refused
//! with the file, the field path and what is allowed, and every fixture matches the JSON Schema's required
//! and allowed keys for its model.
use glossmeter::recipe::{self, schema::schema};
use glossmeter::spectrum::SamplingKind;
use glossmeter::Error;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn json_files(dir: &str) -> Vec<PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(root().join(dir))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    v.sort();
    v
}

#[test]
fn every_fixture_loads() {
    let mut files = json_files("fixtures/recipes");
    files.extend(json_files("fixtures/materials/guenther-2005"));
    assert!(files.len() >= 20);
    for p in files {
        let m = recipe::load_file(&p).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.file, p.display().to_string());
        assert!(!m.name.is_empty());
        assert_eq!(
            m.brdf.sampling().len(),
            glossmeter::colorimetry::weighting::Weighting::luminous(m.brdf.sampling()).unwrap().rows[0].len()
        );
    }
}

#[test]
fn the_documented_forms_load() {
    let forms = [
        r#"{"model": "smooth-dielectric", "ior": 1.5}"#,
        r#"{"model": "conductor", "ior": [0.93, 6.33]}"#,
        r#"{"model": "lambert", "albedo": 0.5}"#,
        r#"{"model": "lambert", "albedo": [0.5, 0.4, 0.3]}"#,
        r#"{"model": "microfacet", "distribution": "beckmann", "roughness": 0.1, "ior": 1.5}"#,
        r#"{"model": "microfacet", "distribution": "ggx", "roughness": 0.1, "ior": [0.93, 6.33], "shadowing": "v-cavity"}"#,
        r#"{"model": "microfacet", "distribution": "ggx", "roughness": 0, "ior": 1.5, "shadowing": "smith"}"#,
        r#"{"model": "phong", "exponent": 50, "ks": 0.1}"#,
        r#"{"model": "blinn-phong", "exponent": 50, "ks": 0.1, "kd": [0.2, 0.3, 0.4], "name": "x"}"#,
        r#"{"model": "ward", "alpha": 0.1, "rho_s": 0.1, "rho_d": 0.5}"#,
        r#"{"model": "cook-torrance-lobes", "kd": 0.1, "lobes": [{"ks": 0.1, "r": 0.9, "m": 0.2}], "notes": ["a", "b"]}"#,
    ];
    for text in forms {
        recipe::parse_str(text, "<test>").unwrap_or_else(|e| panic!("{text}: {e}"));
    }
}

#[test]
fn name_and_sampling() {
    let m = recipe::parse_str(r#"{"model": "lambert", "albedo": 0.5}"#, "dir/grey-thing.json").unwrap();
    assert_eq!(m.name, "grey-thing", "the name defaults to the file stem");
    assert_eq!(m.brdf.sampling().kind, SamplingKind::Grey);
    let m = recipe::parse_str(r#"{"model": "lambert", "albedo": [0.5, 0.4, 0.3], "name": "Rgb"}"#, "x.json").unwrap();
    assert_eq!(m.name, "Rgb");
    assert_eq!(m.brdf.sampling().kind, SamplingKind::Rgb);
    // One RGB colour makes the whole material RGB; a grey value is broadcast.
    let m =
        recipe::parse_str(r#"{"model": "ward", "alpha": 0.1, "rho_s": 0.1, "rho_d": [0.2, 0.3, 0.4]}"#, "x").unwrap();
    let mut f = vec![0.0; 3];
    m.brdf.eval(glossmeter::Vec3::Z, glossmeter::Vec3::new(0.6, 0.0, 0.8), &mut f);
    assert!(f[0] < f[1] && f[1] < f[2]);
    assert_eq!(m.json["alpha"], 0.1);
}

#[test]
fn io_error_names_the_file() {
    let p = root().join("fixtures/recipes/does-not-exist.json");
    match recipe::load_file(&p) {
        Err(Error::Io { file, .. }) => assert!(file.ends_with("does-not-exist.json")),
        other => panic!("expected an I/O error, got {other:?}"),
    }
}

/// (file under fixtures/bad, expected field path, substrings the message must contain)
const BAD: &[(&str, &str, &[&str])] = &[
    ("malformed.json", "", &["malformed JSON", "line 3"]),
    ("unknown-model.json", "/model", &["unknown model \"glass\"", "\"smooth-dielectric\"", "\"paint\""]),
    ("missing-model.json", "/model", &["missing required field", "\"lambert\""]),
    ("missing-field.json", "/roughness", &["missing required field"]),
    ("unknown-field.json", "/albdo", &["unknown field", "albedo"]),
    ("nan-string.json", "/albedo", &["string \"NaN\"", "[0, 1]"]),
    ("infinite.json", "", &["line 1, column", "number out of range"]),
    ("string-number.json", "/roughness", &["finite number", "string \"0.1\""]),
    ("negative-roughness.json", "/roughness", &["-0.1 is out of range", "[0, 10]"]),
    ("roughness-too-large.json", "/roughness", &["12 is out of range", "[0, 10]"]),
    ("negative-albedo.json", "/albedo", &["out of range", "[0, 1]"]),
    ("albedo-above-one.json", "/albedo/1", &["1.2 is out of range", "[0, 1]"]),
    ("albedo-wrong-length.json", "/albedo", &["[r, g, b]", "an array of 2"]),
    ("dielectric-ior-low.json", "/ior", &["0.8 is out of range", "[1, 4]"]),
    ("dielectric-ior-high.json", "/ior", &["4.5 is out of range", "[1, 4]"]),
    ("conductor-n-range.json", "/ior/0", &["out of range", "[0.01, 10]"]),
    ("conductor-k-range.json", "/ior/1", &["25 is out of range", "[0, 20]"]),
    ("conductor-real.json", "/ior", &["[n, k]", "number 1.5"]),
    ("unknown-distribution.json", "/distribution", &["\"phong\"", "\"beckmann\", \"ggx\""]),
    ("unknown-shadowing.json", "/shadowing", &["\"smith\"", "\"v-cavity\""]),
    ("energy-phong.json", "/ks", &["kd + ks = 1.1", "≤ 1"]),
    ("energy-lobes.json", "/lobes", &["channel G", "≤ 1"]),
    ("lobe-unknown-field.json", "/lobes/0/n", &["unknown field", "ks, r, m"]),
    ("no-lobes.json", "/lobes", &["0 lobes", "1 to 8"]),
    ("ward-alpha-zero.json", "/alpha", &["out of range", "[0.000001, 1]"]),
    ("phong-exponent-negative.json", "/exponent", &["-5 is out of range"]),
    ("not-an-object.json", "", &["expected a JSON object"]),
    ("name-not-string.json", "/name", &["expected a string"]),
    ("scatter-c-diverges.json", "/scatter/c", &["1 is out of range", "(1, 10]", "σ² diverges at C ≤ 1"]),
    (
        "scatter-sigma-not-smooth.json",
        "/clear_coat/scatter/rms_roughness_nm",
        &["σ = 40 nm", "allowed: σ ≤ 22.28", "4πσ/λ ≤ 0.5"],
    ),
    ("scatter-a-nonpositive.json", "/scatter/a_nm2_um", &["0 is out of range", "> 0"]),
    ("scatter-correlation-length-range.json", "/scatter/correlation_length_um", &["out of range", "[0.01, 5000]"]),
];

#[test]
fn every_bad_recipe_is_refused_with_file_field_and_allowed() {
    let listed: Vec<&str> = BAD.iter().map(|b| b.0).collect();
    for p in json_files("fixtures/bad") {
        let name = p.file_name().unwrap().to_str().unwrap().to_string();
        assert!(listed.contains(&name.as_str()), "fixtures/bad/{name} has no expectation in BAD");
    }
    for (name, field, needles) in BAD {
        let p = root().join("fixtures/bad").join(name);
        let e = recipe::load_file(&p).err().unwrap_or_else(|| panic!("{name} was accepted"));
        let shown = e.to_string();
        match &e {
            Error::Input { file, field: f, message } => {
                assert_eq!(file, &p.display().to_string(), "{name}: file");
                assert_eq!(f, field, "{name}: field (message: {message})");
                for n in *needles {
                    assert!(message.contains(n), "{name}: message {message:?} lacks {n:?}");
                }
                assert!(shown.starts_with(&p.display().to_string()));
            }
            other => panic!("{name}: expected an input error, got {other:?}"),
        }
    }
}

/// The schema's subschema for `model`, found through `oneOf`.
fn subschema<'a>(s: &'a Value, model: &str) -> &'a Value {
    s["oneOf"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["properties"]["model"]["const"] == model)
        .unwrap_or_else(|| panic!("no subschema for {model}"))
}

fn resolve<'a>(s: &'a Value, v: &'a Value) -> &'a Value {
    match v.get("$ref").and_then(Value::as_str) {
        Some(r) => resolve(s, &s["$defs"][r.trim_start_matches("#/$defs/")]),
        None => v,
    }
}

/// Light structural check: required keys present, no keys outside `properties` when additionalProperties is
/// false, recursively into objects and arrays of objects.
fn check(s: &Value, sub: &Value, v: &Value, path: &str, errors: &mut Vec<String>) {
    let sub = resolve(s, sub);
    if let (Some(props), Some(obj)) = (sub.get("properties").and_then(Value::as_object), v.as_object()) {
        for r in sub["required"].as_array().into_iter().flatten() {
            if !obj.contains_key(r.as_str().unwrap()) {
                errors.push(format!("{path}: missing required {r}"));
            }
        }
        for (k, x) in obj {
            match props.get(k) {
                Some(p) => check(s, p, x, &format!("{path}.{k}"), errors),
                None if sub["additionalProperties"] == false => errors.push(format!("{path}: {k} not allowed")),
                None => {}
            }
        }
    }
    if let (Some(items), Some(arr)) = (sub.get("items").filter(|i| i.is_object()), v.as_array()) {
        for (i, x) in arr.iter().enumerate() {
            check(s, items, x, &format!("{path}[{i}]"), errors);
        }
    }
}

#[test]
fn schema_covers_every_model_and_every_fixture_matches_it() {
    let s = schema();
    assert_eq!(s["$schema"], "https://json-schema.org/draft/2020-12/schema");
    let models: Vec<&str> =
        s["properties"]["model"]["enum"].as_array().unwrap().iter().map(|m| m.as_str().unwrap()).collect();
    assert_eq!(models, recipe::MODELS);
    for m in recipe::MODELS {
        subschema(&s, m);
    }
    let mut files = json_files("fixtures/recipes");
    files.extend(json_files("fixtures/materials/guenther-2005"));
    for p in files {
        let v: Value = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
        let sub = subschema(&s, v["model"].as_str().unwrap());
        let mut errors = Vec::new();
        check(&s, sub, &v, "", &mut errors);
        assert!(errors.is_empty(), "{}: {errors:?}", p.display());
    }
    // The check can fail: a recipe with an extra key or a missing required one does not match.
    let mut errors = Vec::new();
    let bad: Value = serde_json::json!({"model": "lambert", "albdo": 0.5});
    check(&s, subschema(&s, "lambert"), &bad, "", &mut errors);
    assert_eq!(errors.len(), 2, "{errors:?}");
}

/// The schema's ranges are the validator's: a value at a schema bound loads, one beyond it is refused.
#[test]
fn schema_ranges_agree_with_validator() {
    let s = schema();
    let ior = &subschema(&s, "smooth-dielectric")["properties"]["ior"];
    let (lo, hi) = (ior["minimum"].as_f64().unwrap(), ior["maximum"].as_f64().unwrap());
    let load = |x: f64| recipe::parse_str(&format!(r#"{{"model": "smooth-dielectric", "ior": {x}}}"#), "t").is_ok();
    assert!(load(lo) && load(hi) && !load(hi + 1e-9) && !load(lo - 1e-9));
    let r = &subschema(&s, "microfacet")["properties"]["roughness"];
    let hi = r["maximum"].as_f64().unwrap();
    let load = |x: f64| {
        recipe::parse_str(
            &format!(r#"{{"model": "microfacet", "distribution": "ggx", "roughness": {x}, "ior": 1.5}}"#),
            "t",
        )
        .is_ok()
    };
    assert!(load(hi) && !load(hi * 1.0001));
    assert!(Path::new(&root().join("docs/recipe-format.md")).exists(), "docs/recipe-format.md documents the format");
}

/// The schema once stated 360–830 nm but not the validator's limit of 128 wavelengths (`docs/recipe-format.md`
/// §Paint).
#[test]
fn schema_states_the_wavelength_count_limit() {
    let s = schema();
    let w = resolve(&s, &subschema(&s, "paint")["properties"]["wavelengths_nm"]);
    assert_eq!(w["maxItems"].as_u64(), Some(glossmeter::brdf::paint::MAX_SAMPLES as u64), "{w}");
    assert_eq!((w["items"]["minimum"].as_f64(), w["items"]["maximum"].as_f64()), (Some(360.0), Some(830.0)));
}
