//! The output schemas (`glossmeter schema --output-format ...`) against real outputs, validated with the
//! `jsonschema` crate (draft 2020-12), so a field added to an output without its schema fails here, and so does
//! a schema that is not a valid JSON Schema.
mod common;
use common::gm_out;

use serde_json::Value;

/// Every violation, as "pointer: what".
fn violations(s: &Value, v: &Value) -> Vec<String> {
    let validator = jsonschema::validator_for(s).unwrap_or_else(|e| panic!("not a valid schema: {e}"));
    validator.iter_errors(v).map(|e| format!("{}: {e}", e.instance_path())).collect()
}

fn schema(kind: &str) -> Value {
    let (code, text) = gm_out(&["schema", "--output-format", kind]);
    assert_eq!(code, 0);
    let s: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(s["$schema"], "https://json-schema.org/draft/2020-12/schema", "{kind}");
    if let Err(e) = jsonschema::meta::validate(&s) {
        panic!("the {kind} schema is not a valid JSON Schema: {e}");
    }
    s
}

fn assert_valid(s: &Value, v: &Value, what: &str) {
    let e = violations(s, v);
    assert!(e.is_empty(), "{what}: {e:#?}");
}

#[test]
fn outputs_follow_their_schemas() {
    // A previous run as the baseline (measure JSON of one reading).
    let dir = common::tmp_dir("schemas-test");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let base = dir.join("glass-n1.5.json");
    let base = base.to_str().unwrap();
    let glass = "fixtures/recipes/glass-n1.5.json";
    assert_eq!(gm_out(&["measure", glass, "-g", "astm-d523-60", "--format", "json", "-o", base]).0, 0);
    let m = schema("measure");
    for args in [
        &["measure", "fixtures/recipes/glass-n1.5.json", "--format", "json"][..],
        &["measure", "fixtures/recipes/glass-n1.5.json", "--format", "json", "--no-timing"],
        &["measure", "fixtures/recipes/glass-n1.5.json", "fixtures/recipes/black-glass.json", "--format", "json"],
        // many recipes, one of which states uncertainties
        &["measure", "fixtures/uncertainty/solid-black.json", "fixtures/recipes/glass-n1.5.json", "--format", "json"],
        &["measure", "fixtures/recipes/glass-n1.5.json", "-g", "astm-d523-60", "--format", "json", "--baseline", base],
        // the tolerance envelope on each reading (null where a standard gives no tolerance)
        &[
            "measure",
            "fixtures/recipes/glass-n1.5.json",
            "-g",
            "astm-d523-60",
            "-g",
            "iso-13803-20",
            "--envelope",
            "--format",
            "json",
        ],
        &[
            "measure",
            "fixtures/recipes/glass-n1.5.json",
            "fixtures/recipes/black-glass.json",
            "--format",
            "json",
            "--baseline",
            base,
        ],
    ] {
        let (_, out) = gm_out(args);
        assert_valid(&m, &serde_json::from_str(&out).unwrap(), &format!("{args:?}"));
    }
    // A reading without a value (the DOI of a black body) and a note (the D4039 scope) are in the schema too.
    let (_, out) = gm_out(&["measure", "fixtures/recipes/phong.json", "--format", "json"]);
    assert_valid(&m, &serde_json::from_str(&out).unwrap(), "phong");
    // A recipe that states uncertainties: each reading's prediction_uncertainty and its budget.
    let (code, out) =
        gm_out(&["measure", "fixtures/uncertainty/semigloss-white.json", "-g", "astm-d523-60", "--format", "json"]);
    assert_eq!(code, 0);
    let doc: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(doc["readings"][0]["uncertainty_budget"].as_array().map(Vec::len), Some(2), "{out}");
    assert_valid(&m, &doc, "stated uncertainties");
    let c = schema("compare");
    for (recipe, sheet) in [
        ("glass-n1.5.json", "rhopoint-iq.csv"),
        ("glass-n1.5.json", "byk-windows-1252.csv"),
        ("glass-n1.5.json", "tab-separated.csv"),
        ("blue-metallic-spectral.json", "colour-blue-metallic.csv"),
    ] {
        let (_, out) = gm_out(&[
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
    let (_, out) = gm_out(&[
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
    // Recipes that state uncertainties: each comparison's prediction_uncertainty, its budget, and the
    // allowance's parts.
    let (code, out) = gm_out(&[
        "compare",
        "fixtures/sheets/byk-smart-chart-two-samples.csv",
        "--recipe",
        "Black 2K=fixtures/uncertainty/solid-black.json",
        "--recipe",
        "Satin white=fixtures/uncertainty/semigloss-white.json",
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{out}");
    let doc: Value = serde_json::from_str(&out).unwrap();
    assert!(
        doc["comparisons"][0]["uncertainty_budget"].is_array()
            && doc["comparisons"][0]["allowance"]["parts"].is_array()
    );
    assert_valid(&c, &doc, "stated uncertainties");
    let s = schema("sweep");
    let (code, out) = gm_out(&[
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
        let (code, out) = gm_out(args);
        assert!(code == 0 || code == 1, "{args:?}: exit {code}");
        let doc: Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{args:?}: {e}: {out}"));
        assert_valid(&f, &doc, &format!("{args:?}"));
    }
}

/// The schemas are strict where the outputs are: a document with a field unknown to its type, a missing
/// field, a wrong type or a number out of range is refused (so the validation above can fail).
#[test]
fn the_schemas_refuse_what_no_output_holds() {
    let m = schema("measure");
    let (_, out) = gm_out(&["measure", "fixtures/recipes/glass-n1.5.json", "-g", "astm-d523-60", "--format", "json"]);
    let good: Value = serde_json::from_str(&out).unwrap();
    assert!(violations(&m, &good).is_empty());
    let bad = |f: &dyn Fn(&mut Value)| {
        let mut d = good.clone();
        f(&mut d);
        violations(&m, &d)
    };
    assert!(!bad(&|d| d["extra"] = 1.into()).is_empty(), "an unknown top-level field");
    assert!(!bad(&|d| d["readings"][0]["colour"] = "red".into()).is_empty(), "an unknown reading field");
    assert!(!bad(&|d| d["readings"][0]["material"] = "x".into()).is_empty(), "a batch field in one recipe");
    assert!(!bad(&|d| {
        d["readings"][0].as_object_mut().unwrap().remove("value");
    })
    .is_empty());
    assert!(!bad(&|d| d["readings"][0]["value"] = "40".into()).is_empty(), "a string value");
    assert!(!bad(&|d| d["readings"][0]["error_estimate"] = (-1.0).into()).is_empty(), "a negative estimate");
    assert!(!bad(&|d| d["readings"][0]["quantity"] = "shine".into()).is_empty(), "an unknown quantity");
    assert!(!bad(&|d| d["evaluations"] = (-3).into()).is_empty(), "a negative count");
    // null where the output writes null (a reading without a value) is allowed
    assert!(bad(&|d| {
        d["readings"][0]["value"] = Value::Null;
        d["readings"][0]["error_estimate"] = Value::Null;
    })
    .is_empty());
    let f = schema("fit");
    let failure = serde_json::json!({"converged": true, "failure": "x", "parameters": [], "targets": []});
    assert!(!violations(&f, &failure).is_empty(), "a failure document says converged: false");
    let s = schema("sweep");
    assert!(violations(&s, &serde_json::json!({"index": 0, "parameters": {"/a": 0.5}})).is_empty());
    assert!(!violations(&s, &serde_json::json!({"index": 0, "parameters": {"/a": "0.5"}})).is_empty());
}

#[test]
fn profile_and_convergence_follow_their_schemas() {
    // A profile with a value on every pixel, and one whose budget leaves pixels without one (nulls).
    let p = schema("profile");
    let required = |s: &Value, def: &str| -> Vec<String> {
        s["$defs"][def]["required"].as_array().unwrap().iter().map(|v| v.as_str().unwrap().to_string()).collect()
    };
    assert!(required(&p, "ProfileRowDoc").contains(&"problem".to_string()), "nullable fields are written");
    for args in [
        &["profile", "fixtures/recipes/black-glass.json", "--format", "json"][..],
        &["profile", "fixtures/recipes/black-glass.json", "--format", "json", "--max-total-evals", "1000"],
    ] {
        let (_, text) = gm_out(args);
        let v: Value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{args:?}: {e}: {text}"));
        assert!(v["rows"].as_array().is_some_and(|r| !r.is_empty()), "{args:?}");
        assert_valid(&p, &v, &format!("{args:?}"));
    }
    // Against a closed form (Lambert) and against a reference run (glass).
    let c = schema("convergence");
    for recipe in ["fixtures/recipes/grey-lambert.json", "fixtures/recipes/glass-n1.5.json"] {
        let args = [
            "convergence",
            recipe,
            "-g",
            "astm-d523-60",
            "--tolerances",
            "1e-3,1e-4",
            "--format",
            "json",
            "--max-repetitions",
            "1",
        ];
        let (code, text) = gm_out(&args);
        assert_eq!(code, 0, "{args:?}");
        let v: Value = serde_json::from_str(&text).unwrap();
        assert_valid(&c, &v, &format!("{args:?}"));
    }
}

#[test]
fn sheets_as_read_follow_their_schema() {
    // The document of the one sheet reader (the Python bindings' `read_sheet`): text sheets of every layout,
    // a workbook, statistics rows, uncertainties and a column that is recognised but not predicted.
    let s = schema("sheet");
    for file in [
        "black-glass-check.csv",
        "byk-smart-chart-export.xlsx",
        "byk-smart-chart-report.csv",
        "colour-blue-metallic.csv",
        "rhopoint-iq-export.csv",
        "elcometer-408-export.csv",
    ] {
        let path = std::path::Path::new("fixtures/sheets").join(file);
        let sheet = glossmeter::comparison::sheet::load(&path, &Default::default()).unwrap();
        let doc = glossmeter::report::to_json(&glossmeter::report::compare::SheetReadDoc::new(&sheet));
        assert_valid(&s, &doc, file);
        assert_eq!(doc["rows"].as_array().unwrap().len(), sheet.rows.len(), "{file}");
    }
    // The `sheet` part is `compare`'s own.
    let (_, text) = gm_out(&[
        "compare",
        "fixtures/recipes/black-glass.json",
        "fixtures/sheets/black-glass-check.csv",
        "--format",
        "json",
    ]);
    let cmp: Value = serde_json::from_str(&text).unwrap();
    let sheet =
        glossmeter::comparison::sheet::load("fixtures/sheets/black-glass-check.csv".as_ref(), &Default::default())
            .unwrap();
    let doc = glossmeter::report::to_json(&glossmeter::report::compare::SheetReadDoc::new(&sheet));
    assert_eq!(doc["sheet"], cmp["sheet"]);
}

#[test]
fn topography_follows_its_schema() {
    let s = schema("topography");
    for file in ["fixtures/topography/gaussian.x3p", "fixtures/topography/gaussian-masked.x3p"] {
        let (code, text) = gm_out(&["topography", file, "--format", "json"]);
        assert_eq!(code, 0, "{file}");
        let v: Value = serde_json::from_str(&text).unwrap();
        assert_valid(&s, &v, file);
    }
    // A flat map has no skewness nor kurtosis: nulls, which the schema allows.
    let flat = std::env::temp_dir().join(format!("glossmeter-schemas-flat-{}.csv", std::process::id()));
    std::fs::write(&flat, "1 1 1\n1 1 1\n1 1 1\n").unwrap();
    let (code, text) = gm_out(&[
        "topography",
        flat.to_str().unwrap(),
        "--format",
        "json",
        "--pixel-size",
        "1um",
        "--height-unit",
        "um",
    ]);
    assert_eq!(code, 0);
    let v: Value = serde_json::from_str(&text).unwrap();
    assert!(v["heights"]["ssk"].is_null());
    assert_valid(&s, &v, "flat");
    let _ = std::fs::remove_file(&flat);
}
