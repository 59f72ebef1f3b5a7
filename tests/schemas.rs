//! The output schemas (`glossmeter schema --output-format ...`) against real outputs: a small validator of
//! the keywords the schemas use (type, properties, required, additionalProperties, items, enum, minimum,
//! oneOf), so a field added to an output without its schema fails here.
use std::process::Command;

use serde_json::Value;

fn gm(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_glossmeter")).args(args).output().expect("run glossmeter");
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stdout).into_owned())
}

fn type_ok(t: &str, v: &Value) -> bool {
    match t {
        "object" => v.is_object(),
        "array" => v.is_array(),
        "string" => v.is_string(),
        "number" => v.is_number(),
        "integer" => v.is_u64() || v.is_i64(),
        "boolean" => v.is_boolean(),
        "null" => v.is_null(),
        _ => panic!("unknown type {t}"),
    }
}

/// Every violation, as "pointer: what".
fn validate(s: &Value, v: &Value, at: &str, out: &mut Vec<String>) {
    if let Some(t) = s.get("type") {
        let ok = match t {
            Value::String(t) => type_ok(t, v),
            Value::Array(ts) => ts.iter().any(|t| type_ok(t.as_str().unwrap(), v)),
            _ => panic!("bad type"),
        };
        if !ok {
            out.push(format!("{at}: {v} is not {t}"));
            return;
        }
    }
    if let Some(e) = s.get("enum").and_then(|e| e.as_array()) {
        if !e.contains(v) {
            out.push(format!("{at}: {v} not in {e:?}"));
        }
    }
    if let (Some(m), Some(x)) = (s.get("minimum").and_then(|m| m.as_f64()), v.as_f64()) {
        if x < m {
            out.push(format!("{at}: {x} < {m}"));
        }
    }
    if let Some(alts) = s.get("oneOf").and_then(|a| a.as_array()) {
        let passing = alts
            .iter()
            .filter(|a| {
                let mut e = vec![];
                validate(a, v, at, &mut e);
                e.is_empty()
            })
            .count();
        if passing != 1 {
            out.push(format!("{at}: {passing} of the oneOf alternatives match"));
        }
    }
    if let Some(o) = v.as_object() {
        for r in s.get("required").and_then(|r| r.as_array()).into_iter().flatten() {
            if !o.contains_key(r.as_str().unwrap()) {
                out.push(format!("{at}: missing {r}"));
            }
        }
        let props = s.get("properties").and_then(|p| p.as_object());
        for (k, x) in o {
            match props.and_then(|p| p.get(k)) {
                Some(ps) => validate(ps, x, &format!("{at}/{k}"), out),
                None => match s.get("additionalProperties") {
                    Some(Value::Bool(false)) => out.push(format!("{at}: unexpected {k}")),
                    Some(a @ Value::Object(_)) => validate(a, x, &format!("{at}/{k}"), out),
                    _ => {}
                },
            }
        }
    }
    if let (Some(items), Some(a)) = (s.get("items"), v.as_array()) {
        for (i, x) in a.iter().enumerate() {
            validate(items, x, &format!("{at}/{i}"), out);
        }
    }
}

fn schema(kind: &str) -> Value {
    let (code, text) = gm(&["schema", "--output-format", kind]);
    assert_eq!(code, 0);
    serde_json::from_str(&text).unwrap()
}

fn assert_valid(s: &Value, v: &Value, what: &str) {
    let mut e = vec![];
    validate(s, v, "", &mut e);
    assert!(e.is_empty(), "{what}: {e:#?}");
}

#[test]
fn outputs_follow_their_schemas() {
    // A previous run as the baseline (measure JSON of one reading).
    let dir = std::env::temp_dir().join(format!("glossmeter-schemas-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let base = dir.join("glass-n1.5.json");
    let base = base.to_str().unwrap();
    let glass = "fixtures/recipes/glass-n1.5.json";
    assert_eq!(gm(&["measure", glass, "-g", "astm-d523-60", "--format", "json", "-o", base]).0, 0);
    let m = schema("measure");
    for args in [
        &["measure", "fixtures/recipes/glass-n1.5.json", "--format", "json"][..],
        &["measure", "fixtures/recipes/glass-n1.5.json", "--format", "json", "--no-timing"],
        &["measure", "fixtures/recipes/glass-n1.5.json", "fixtures/recipes/black-glass.json", "--format", "json"],
        &["measure", "fixtures/recipes/glass-n1.5.json", "-g", "astm-d523-60", "--format", "json", "--baseline", base],
    ] {
        let (_, out) = gm(args);
        assert_valid(&m, &serde_json::from_str(&out).unwrap(), &format!("{args:?}"));
    }
    // A reading without a value (the DOI of a black body) and a note (the D4039 scope) are in the schema too.
    let (_, out) = gm(&["measure", "fixtures/recipes/phong.json", "--format", "json"]);
    assert_valid(&m, &serde_json::from_str(&out).unwrap(), "phong");
    let c = schema("compare");
    for (recipe, sheet) in [
        ("glass-n1.5.json", "rhopoint-iq.csv"),
        ("glass-n1.5.json", "byk-windows-1252.csv"),
        ("glass-n1.5.json", "tab-separated.csv"),
        ("blue-metallic-spectral.json", "colour-blue-metallic.csv"),
    ] {
        let (_, out) = gm(&[
            "compare",
            &format!("fixtures/recipes/{recipe}"),
            &format!("fixtures/sheets/{sheet}"),
            "--format",
            "json",
        ]);
        let doc: Value = serde_json::from_str(&out).unwrap();
        if sheet.starts_with("colour") {
            assert!(!doc["colour_differences"].as_array().unwrap().is_empty(), "{out}");
        }
        assert_valid(&c, &doc, sheet);
    }
    let (_, out) = gm(&[
        "compare",
        "fixtures/sheets/qc-many-samples.csv",
        "--recipe-dir",
        "fixtures/recipes",
        "--format",
        "json",
        "--baseline",
        base,
    ]);
    assert_valid(&c, &serde_json::from_str(&out).unwrap(), "many samples with a baseline");
    let s = schema("sweep");
    let (code, out) = gm(&[
        "sweep",
        "fixtures/recipes/rgb-lambert.json",
        "--vary",
        "/albedo/0=0.2..1.4:3",
        "-g",
        "astm-d523-60",
        "--format",
        "jsonl",
    ]);
    assert_eq!(code, 0);
    for line in out.lines() {
        assert_valid(&s, &serde_json::from_str(line).unwrap(), line);
    }
    // fit: one roughness to one gloss (exactly determined), with and without timing; two parameters of which
    // the targets see one (an undetermined standard error, a null); a fit that hits a bound; a fit that
    // cannot run.
    let f = schema("fit");
    let rough = "fixtures/recipes/rough-dielectric-beckmann.json";
    for args in [
        &[
            "fit",
            rough,
            "--free",
            "/roughness=log:1e-3..0.5",
            "--target",
            "astm-d523-60/gloss=40±0.2",
            "--format",
            "json",
        ][..],
        &[
            "fit",
            rough,
            "--free",
            "/roughness=log:1e-3..0.5",
            "--target",
            "astm-d523-60/gloss=40±0.2",
            "--format",
            "json",
            "--no-timing",
        ],
        &[
            "fit",
            rough,
            "--free",
            "/roughness=log:1e-3..0.5",
            "--free",
            "/ior=1.3..1.8",
            "--target",
            "astm-d523-60/gloss=40±0.2",
            "--target",
            "astm-d523-20/gloss=12±0.2",
            "--target",
            "astm-d523-85/gloss=80±0.2",
            "--format",
            "json",
        ],
        &["fit", rough, "--free", "/roughness=0.05..0.5", "--target", "astm-d523-60/gloss=99±0.2", "--format", "json"],
        // A fit that cannot run (the hue of a grey has no value): the failure document, exit 1.
        &[
            "fit",
            "fixtures/recipes/grey-lambert.json",
            "--free",
            "/albedo=0.1..0.9",
            "--target",
            "astm-e2539-15/h=30±1",
            "--format",
            "json",
        ],
    ] {
        let (code, out) = gm(args);
        assert!(code == 0 || code == 1, "{args:?}: exit {code}");
        let doc: Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{args:?}: {e}: {out}"));
        assert_valid(&f, &doc, &format!("{args:?}"));
    }
    // The validator itself rejects what it should.
    let mut e = vec![];
    validate(&m, &serde_json::json!({"material": {"name": "x"}, "readings": [], "extra": 1}), "", &mut e);
    assert!(!e.is_empty());
}
