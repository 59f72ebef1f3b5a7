//! The prediction's uncertainty (docs/instrument.md §The prediction's uncertainty): a recipe's stated
//! uncertainties of its numbers propagated to every reading to first order (`comparison::propagation`), checked
//! against a closed form (the Fresnel reflectance's derivative in the index, through an independent
//! Gauss–Legendre mirror flux) and against a seeded Monte Carlo of the inputs; the recipe block's bad inputs;
//! and a two-sample sheet that is OUTSIDE on every row when the prediction's uncertainty is ignored and inside
//! when the recipes state plausible uncertainties.
mod common;
use std::path::{Path, PathBuf};

use glossmeter::comparison::propagation::{self, Difference};
use glossmeter::comparison::sheet::{self, SheetOptions};
use glossmeter::comparison::{self, Recipes, Verdict, VerdictRule};
use glossmeter::instrument::plan::{Plan, PlanOptions};
use glossmeter::instrument::reading::Scale;
use glossmeter::instrument::reference::mirror_flux_reference;
use glossmeter::instrument::standards;
use glossmeter::optics::fresnel::fr_dielectric;
use glossmeter::recipe;
use serde_json::{json, Value};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// ∂R/∂n of the unpolarised Fresnel reflectance R = (r_s² + r_p²)/2 of a dielectric of index n in air, at
/// cos θᵢ = c (Born & Wolf §1.5.2; differentiated by hand: cos θₜ = √(1 − (1 − c²)/n²), so
/// d cos θₜ/dn = (1 − c²)/(n³ cos θₜ)).
fn d_fresnel_dn(c: f64, n: f64) -> f64 {
    let ct = (1.0 - (1.0 - c * c) / (n * n)).sqrt();
    let dct = (1.0 - c * c) / (n * n * n * ct);
    // r_s = (c − n cos θₜ)/(c + n cos θₜ)
    let b = n * ct;
    let db = ct + n * dct;
    let rs = (c - b) / (c + b);
    let drs = -2.0 * c * db / ((c + b) * (c + b));
    // r_p = (n c − cos θₜ)/(n c + cos θₜ)
    let (a, da) = (n * c, c);
    let rp = (a - ct) / (a + ct);
    let drp = 2.0 * (da * ct - a * dct) / ((a + ct) * (a + ct));
    rs * drs + rp * drp
}

/// The closed form: a smooth black-backed dielectric reads G(n) = V·Φ_R(n)/Φ_R(n_std) on a black-glass scale
/// (Φ_R the mirror flux weighted by R), so ∂G/∂n = V·Φ_{∂R/∂n}(n)/Φ_R(n_std), each flux by the independent
/// Gauss–Legendre mirror rule (`instrument::reference`, no code shared with the quadrature). The first-order
/// u_pred = |∂G/∂n|·u(n); the central difference with step u differs from the derivative by u²·G'''/6, about
/// 10⁻⁵ relative at u = 0.01, so the check holds to 10⁻³.
#[test]
fn a_smooth_dielectrics_uncertainty_is_the_fresnel_derivative_times_u() {
    let (n, u) = (1.5, 0.01);
    let m = recipe::parse_str(
        &json!({"model": "smooth-dielectric", "ior": n, "uncertainty": {"/ior": u}}).to_string(),
        "g.json",
    )
    .unwrap();
    for id in ["astm-d523-20", "astm-d523-60", "astm-d523-85"] {
        let g = standards::find(id).unwrap();
        let geo = &g.geometry;
        let Scale::BlackGlass { index, value } = geo.scale else { panic!("{id} is on the black-glass scale") };
        let rec = *geo.receptor("gloss").unwrap();
        let flux = |f: &dyn Fn(f64) -> f64| mirror_flux_reference(geo.theta, geo.source, rec, f);
        let standard = flux(&|c| fr_dielectric(c, index));
        let reading = value * flux(&|c| fr_dielectric(c, n)) / standard;
        let slope = value * flux(&|c| d_fresnel_dn(c, n)) / standard;
        let geos = vec![g.clone()];
        let options = PlanOptions { rtol: 1e-9, ..PlanOptions::default() };
        let centre = Plan::compile(m.brdf.clone(), geos.clone(), options.clone()).unwrap().execute();
        let v = centre[0].value.unwrap();
        assert!((v - reading).abs() < 1e-7 * reading, "{id}: reads {v}, the closed form {reading}");
        let p = propagation::propagate(&m, &geos, &options, &centre).unwrap().remove(0).unwrap();
        let c = &p.contributions[0];
        assert_eq!((c.pointer.as_str(), c.difference), ("/ior", Difference::Central));
        assert!((c.sensitivity - slope).abs() < 1e-3 * slope.abs(), "{id}: ∂G/∂n {} against {slope}", c.sensitivity);
        assert!((p.u - slope.abs() * u).abs() < 1e-3 * p.u, "{id}: u_pred {} against {}", p.u, slope.abs() * u);
        // The derivative checked itself: against a difference quotient of the closed form with a tiny step.
        let h = 1e-6;
        let fd =
            value * (flux(&|c| fr_dielectric(c, n + h)) - flux(&|c| fr_dielectric(c, n - h))) / (2.0 * h) / standard;
        assert!((fd - slope).abs() < 1e-5 * slope.abs(), "{id}: the hand derivative {slope} against {fd}");
    }
}

/// splitmix64 (Steele, Lea & Flood 2014) and Box–Muller: normal deviates from a seed, the same on every machine.
struct Normal(u64);
impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn next(&mut self) -> f64 {
        let (a, b) = (self.uniform(), self.uniform());
        (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
    }
}

/// JCGM 101:2008 (GUM Supplement 1) propagates the inputs' distributions by sampling them; its standard
/// deviation of the output is what the first-order law approximates. A rough GGX interface (α = 0.05 ± 0.002,
/// n = 1.5 ± 0.01, both normal and independent) read at 20°, 60° and 85°: 2000 samples. The sample standard
/// deviation of 2000 normal values is itself uncertain by 1/√(2·1999) ≈ 1.6 %, and the response's curvature
/// over ±u adds about 1 % here (16 000 draws put the Monte Carlo 0.5–1.1 % above first order), so the two agree
/// within 5 % (three of the sampling's standard deviations; this seed gives 2.0–2.8 %).
#[test]
fn first_order_agrees_with_a_monte_carlo_of_the_inputs() {
    let (alpha, u_alpha, n, u_n) = (0.05, 0.002, 1.5, 0.01);
    let recipe_at = |a: f64, m: f64| {
        json!({"model": "microfacet", "distribution": "ggx", "roughness": a, "ior": m,
               "uncertainty": {"/roughness": u_alpha, "/ior": u_n}})
    };
    let m = recipe::parse_str(&recipe_at(alpha, n).to_string(), "mc.json").unwrap();
    let geos: Vec<_> =
        ["astm-d523-20", "astm-d523-60", "astm-d523-85"].iter().map(|id| standards::find(id).unwrap()).collect();
    let options = PlanOptions::default();
    let plan = Plan::compile(m.brdf.clone(), geos.clone(), options.clone()).unwrap();
    let centre = plan.execute();
    let first_order = propagation::propagate(&m, &geos, &options, &centre).unwrap();
    // The samples are read through the centre's frozen plan, as a fitter reads nearby points.
    let (_, frozen) = plan.freeze();
    let mut rng = Normal(0x05EE_D0F6_1055);
    let samples = 2000;
    let mut values: Vec<Vec<f64>> = vec![vec![]; centre.len()];
    for _ in 0..samples {
        let (a, m) = (alpha + u_alpha * rng.next(), n + u_n * rng.next());
        let mut r = recipe_at(a, m);
        r.as_object_mut().unwrap().remove("uncertainty");
        let brdf = recipe::parse_str(&r.to_string(), "mc.json").unwrap().brdf;
        for (j, reading) in frozen.with_material(brdf).unwrap().execute().iter().enumerate() {
            values[j].push(reading.value.unwrap());
        }
    }
    for (j, r) in centre.iter().enumerate() {
        let v = &values[j];
        let mean = v.iter().sum::<f64>() / samples as f64;
        let sd = (v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (samples - 1) as f64).sqrt();
        let u = first_order[j].as_ref().unwrap().u;
        assert!(
            u > 0.0 && (sd - u).abs() < 0.05 * u,
            "{} {}: Monte Carlo sd {sd}, first order {u}",
            r.geometry,
            r.name
        );
        // Both inputs contribute, each as |c|·u.
        for c in &first_order[j].as_ref().unwrap().contributions {
            assert!((c.contribution - c.sensitivity.abs() * c.u).abs() <= 1e-15 * c.contribution.max(1.0));
        }
    }
}

fn load_err(v: &Value) -> String {
    recipe::parse_str(&v.to_string(), "bad.json").unwrap_err().to_string()
}

#[test]
fn bad_uncertainty_blocks_name_the_file_the_pointer_and_what_is_allowed() {
    let paint: Value =
        serde_json::from_str(&std::fs::read_to_string(root().join("fixtures/recipes/semigloss-white.json")).unwrap())
            .unwrap();
    let with = |u: Value| {
        let mut p = paint.clone();
        p["uncertainty"] = u;
        p
    };
    // The brief's own spelling of the coat is not this format's: the error lists the numbers there are.
    let e = load_err(&with(json!({"/coat/roughness": 0.002})));
    assert!(e.contains("bad.json") && e.contains("/uncertainty/~1coat~1roughness"), "{e}");
    assert!(e.contains("`/coat/roughness`") && e.contains("/clear_coat/roughness"), "{e}");
    let e = load_err(&with(json!({"/clear_coat/roughness": 0})));
    assert!(e.contains("finite number > 0"), "{e}");
    let e = load_err(&with(json!({"/clear_coat/roughness": -0.001})));
    assert!(e.contains("finite number > 0"), "{e}");
    let e = load_err(&with(json!({"/clear_coat/distribution": 0.1})));
    assert!(e.contains("not a numeric parameter"), "{e}");
    let e = load_err(&with(json!({"/pigmented_layer/primer_reflectance": 0.01})));
    assert!(e.contains("/pigmented_layer/primer_reflectance/0"), "{e}");
    let e = load_err(&with(json!({"/clear_coat/index": 3.0})));
    assert!(e.contains("outside the allowed range"), "{e}");
    let e = load_err(&with(json!("0.01")));
    assert!(e.contains("/uncertainty") && e.contains("expected an object"), "{e}");
    // A valid block loads, and the recipe's schema (generated from the registry) takes it.
    let good = with(json!({"/clear_coat/roughness": 0.00175, "/clear_coat/index": 0.0144}));
    let m = recipe::parse_str(&good.to_string(), "good.json").unwrap();
    assert_eq!(m.uncertainty.len(), 2);
    let schema = glossmeter::recipe::schema::schema();
    let validator = jsonschema::validator_for(&schema).unwrap();
    assert!(validator.is_valid(&good));
    assert!(!validator.is_valid(&with(json!({"/clear_coat/roughness": 0}))));
}

/// A displaced recipe that is not valid (a cross-field limit) is an input error naming the number, exit 2.
#[test]
fn a_displacement_that_breaks_the_recipe_is_refused_with_the_number() {
    let m = recipe::parse_str(
        &json!({"model": "phong", "exponent": 50, "ks": 0.5, "kd": 0.5, "uncertainty": {"/kd": 0.01}}).to_string(),
        "edge.json",
    )
    .unwrap();
    let geos = vec![standards::find("astm-d523-60").unwrap()];
    let centre = Plan::compile(m.brdf.clone(), geos.clone(), PlanOptions::default()).unwrap().execute();
    let e = propagation::propagate(&m, &geos, &PlanOptions::default(), &centre).unwrap_err();
    assert!(matches!(e, glossmeter::Error::Input { .. }), "{e}");
    let e = e.to_string();
    assert!(e.contains("edge.json") && e.contains("/uncertainty/~1kd") && e.contains("smaller u"), "{e}");
}

fn compare(sheet_file: &Path, recipes: &[(&str, PathBuf)]) -> Vec<comparison::Comparison> {
    let sheet = sheet::load(sheet_file, &SheetOptions::default()).unwrap();
    let recipes = Recipes {
        default: None,
        dir: None,
        per_sample: recipes.iter().map(|(s, p)| (s.to_string(), p.clone().into())).collect(),
    };
    comparison::compare_sheet(&sheet, &recipes, &VerdictRule::default(), &PlanOptions::default()).unwrap()
}

/// The case of the newcomer review: two samples, differences of 0.3–3 GU, every row OUTSIDE when only the
/// mean's spread and the numerical error are allowed; with the recipes' stated uncertainties
/// (fixtures/uncertainty/README.md says where each comes from) every row is inside, and the allowance's parts
/// add up to its total.
#[test]
fn a_two_sample_sheet_is_judged_with_the_predictions_uncertainty() {
    let sheet = root().join("fixtures/sheets/byk-smart-chart-two-samples.csv");
    let plain = compare(
        &sheet,
        &[
            ("Black 2K", root().join("fixtures/recipes/solid-black.json")),
            ("Satin white", root().join("fixtures/recipes/semigloss-white.json")),
        ],
    );
    assert_eq!(plain.len(), 6);
    for c in &plain {
        let d = c.difference().unwrap().abs();
        assert!((0.3..=3.0).contains(&d), "{} {}: difference {d}", c.group.sample, c.group.geometry);
        assert_eq!(c.verdict, Verdict::Outside, "{} {}", c.group.sample, c.group.geometry);
        assert!(c.prediction_uncertainty.is_none());
    }
    let stated = compare(
        &sheet,
        &[
            ("Black 2K", root().join("fixtures/uncertainty/solid-black.json")),
            ("Satin white", root().join("fixtures/uncertainty/semigloss-white.json")),
        ],
    );
    for (c, p) in stated.iter().zip(&plain) {
        // The same recipe but for the block: the same prediction, bit for bit.
        assert_eq!(
            c.predicted.as_ref().unwrap().value.unwrap().to_bits(),
            p.predicted.as_ref().unwrap().value.unwrap().to_bits()
        );
        assert_eq!(c.verdict, Verdict::Inside, "{} {}: {:?}", c.group.sample, c.group.geometry, c.allowance);
        let a = c.allowance.unwrap();
        let u = c.prediction_uncertainty.as_ref().unwrap().u;
        assert_eq!(a.prediction_uncertainty, u);
        let s = c.group.stats;
        let random = 2.0 * (s.std * s.std / s.n as f64 + u * u).sqrt();
        assert!((a.random - random).abs() < 1e-12 * random, "{a:?}");
        assert_eq!(a.parts().iter().map(|p| p.2).sum::<f64>(), a.total());
    }
    // The fixtures differ from the shipped recipes only by the block.
    for name in ["solid-black.json", "semigloss-white.json"] {
        let read = |p: PathBuf| -> Value { serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap() };
        let mut with = read(root().join("fixtures/uncertainty").join(name));
        let without = read(root().join("fixtures/recipes").join(name));
        assert!(with.as_object_mut().unwrap().remove("uncertainty").is_some());
        for key in ["clear_coat", "pigmented_layer", "model"] {
            assert_eq!(with[key], without[key], "{name}: {key}");
        }
    }
}

/// The command line: the same sheet fails (exit 1) without the blocks and passes (exit 0) with them; the JSON
/// names each part of the allowance and they add up to its total; `measure` prints u_pred under its table.
#[cfg(feature = "cli")]
#[test]
fn the_command_line_reports_the_allowances_parts() {
    let gm = |args: &[&str]| {
        let out = common::glossmeter().current_dir(root()).args(args).output().unwrap();
        (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stdout).into_owned())
    };
    let sheet = "fixtures/sheets/byk-smart-chart-two-samples.csv";
    let (code, table) = gm(&[
        "compare",
        sheet,
        "--recipe",
        "Black 2K=fixtures/recipes/solid-black.json",
        "--recipe",
        "Satin white=fixtures/recipes/semigloss-white.json",
    ]);
    assert_eq!(code, 1, "{table}");
    assert!(
        table.contains("6 reading(s) of 2 sample(s): 0 ok, 6 outside") && table.contains("allowance = 2·s/√n"),
        "{table}"
    );
    let with = [
        "compare",
        sheet,
        "--recipe",
        "Black 2K=fixtures/uncertainty/solid-black.json",
        "--recipe",
        "Satin white=fixtures/uncertainty/semigloss-white.json",
    ];
    let (code, table) = gm(&with);
    assert_eq!(code, 0, "{table}");
    assert!(table.contains("6 ok, 0 outside") && table.contains("allowance = 2·√(s²/n + u_pred²)"), "{table}");
    assert!(table.contains("u_pred = ") && table.contains("/clear_coat/roughness"), "{table}");
    let (code, junit) = gm(&[&with[..], &["--format", "junit"]].concat());
    assert_eq!(code, 0);
    assert!(junit.contains("(k·√(s²/n + u_pred²)) + 0 (stated)"), "{junit}");
    let (code, json) = gm(&[&with[..], &["--format", "json"]].concat());
    assert_eq!(code, 0);
    let doc: Value = serde_json::from_str(&json).unwrap();
    for c in doc["comparisons"].as_array().unwrap() {
        let a = &c["allowance"];
        let parts = a["parts"].as_array().unwrap();
        let names: Vec<&str> = parts.iter().map(|p| p["name"].as_str().unwrap()).collect();
        assert_eq!(names, ["statistical and prediction uncertainty", "stated", "numerical"]);
        let sum: f64 = parts.iter().map(|p| p["value"].as_f64().unwrap()).sum();
        assert_eq!(sum, a["total"].as_f64().unwrap());
        assert_eq!(c["prediction_uncertainty"], a["prediction_uncertainty"]);
        assert_eq!(c["verdict"], "ok");
    }
    // The CSV has the allowance's parts as columns (docs/instrument.md §The prediction's uncertainty), each
    // the JSON's number to ten significant digits, the columns before them as they were.
    let (code, csv) = gm(&[&with[..], &["--format", "csv"]].concat());
    assert_eq!(code, 0);
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        head,
        [
            "line",
            "sample",
            "material",
            "geometry",
            "reading",
            "n",
            "mean",
            "std",
            "min",
            "max",
            "predicted",
            "error_estimate",
            "difference",
            "allowance",
            "verdict",
            "note",
            "prediction_uncertainty",
            "allowance_statistical",
            "allowance_random",
            "allowance_stated",
            "allowance_prediction"
        ]
    );
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<String>> = lines.map(|l| l.split(',').map(String::from).collect()).collect();
    assert_eq!(rows.len(), doc["comparisons"].as_array().unwrap().len());
    for (r, c) in rows.iter().zip(doc["comparisons"].as_array().unwrap()) {
        let a = &c["allowance"];
        for (column, json) in [
            ("prediction_uncertainty", &c["prediction_uncertainty"]),
            ("allowance_statistical", &a["statistical"]),
            ("allowance_random", &a["random"]),
            ("allowance_stated", &a["stated"]),
            ("allowance_prediction", &a["prediction"]),
            ("allowance", &a["total"]),
        ] {
            let (x, y): (f64, f64) = (r[col(column)].parse().unwrap(), json.as_f64().unwrap());
            assert!((x - y).abs() <= 1e-9 * y.abs(), "{column}: {x} vs {y}");
        }
        assert!(r[col("prediction_uncertainty")].parse::<f64>().unwrap() > 0.0);
    }
    // Without the blocks the part columns are there, the prediction's uncertainty empty.
    let (_, csv) = gm(&[
        "compare",
        sheet,
        "--recipe",
        "Black 2K=fixtures/recipes/solid-black.json",
        "--recipe",
        "Satin white=fixtures/recipes/semigloss-white.json",
        "--format",
        "csv",
    ]);
    let row: Vec<&str> = csv.lines().nth(1).unwrap().split(',').collect();
    assert_eq!(row.len(), head.len());
    assert_eq!(row[col("prediction_uncertainty")], "");
    assert_eq!(row[col("allowance_random")], row[col("allowance_statistical")], "{csv}");
    // The table shows each reading as the instrument displays it (0.1 GU, the spread 0.01 GU): the JSON's
    // numbers rounded to the display step.
    let (_, table) = gm(&with);
    for c in doc["comparisons"].as_array().unwrap() {
        let shown = |v: &Value, step: f64| {
            format!("{:.*}", if step < 0.05 { 2 } else { 1 }, (v.as_f64().unwrap() / step + 0.5).floor() * step)
        };
        let line = table
            .lines()
            .find(|l| l.contains(c["sample"].as_str().unwrap()) && l.contains(c["geometry"].as_str().unwrap()))
            .unwrap_or_else(|| panic!("{table}"));
        let want = [
            format!("{} ± {}", shown(&c["mean"], 0.1), shown(&c["std"], 0.01)),
            shown(&c["predicted"], 0.1),
            shown(&c["difference"], 0.1),
            shown(&c["allowance"]["total"], 0.1),
        ];
        for w in &want {
            assert!(line.contains(&format!(" {w} ")), "{w} not in {line:?}");
        }
        assert!(!line.contains(&format!("{:.3}", c["predicted"].as_f64().unwrap())), "{line}");
    }
    let (code, table) = gm(&["measure", "fixtures/uncertainty/solid-black.json", "-g", "astm-d523-20", "--no-timing"]);
    assert_eq!(code, 0);
    assert!(
        table.contains("astm-d523-20 gloss: u_pred = 3.77 GU (largest part: /clear_coat/index ± 0.0144"),
        "{table}"
    );
    // Many recipes: the one with a block gets the fields, the other none.
    let (code, json) = gm(&[
        "measure",
        "fixtures/uncertainty/solid-black.json",
        "fixtures/recipes/glass-n1.5.json",
        "-g",
        "astm-d523-20",
        "--format",
        "json",
    ]);
    assert_eq!(code, 0);
    let doc: Value = serde_json::from_str(&json).unwrap();
    let rs = doc["readings"].as_array().unwrap();
    assert_eq!(rs.len(), 2);
    let u = |r: &Value| r["prediction_uncertainty"].as_f64();
    assert!(u(&rs[0]).is_some_and(|u| (u - 3.77).abs() < 0.01) && u(&rs[1]).is_none(), "{json}");
}

/// The server converts its bodies into the same library requests: `/api/measure` gives each reading its
/// prediction uncertainty and `/api/compare` counts it in the allowance (docs/serve.md).
#[cfg(feature = "serve")]
#[test]
fn the_server_propagates_a_recipes_stated_uncertainties() {
    use glossmeter::serve::{ServeOptions, Server};
    use std::io::{Read, Write};
    let server = Server::bind(ServeOptions { port: 0, ..ServeOptions::default() }).unwrap();
    let addr = server.addr();
    std::thread::spawn(move || server.run());
    // HTTP/1.0, so that the answer is the body as it is (no chunks) up to the close.
    let post = |path: &str, body: &Value| -> Value {
        let body = body.to_string();
        let mut s = std::net::TcpStream::connect(addr).unwrap();
        write!(
            s,
            "POST {path} HTTP/1.0\r\nHost: {addr}\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
            body.len()
        )
        .unwrap();
        let mut raw = String::new();
        s.read_to_string(&mut raw).unwrap();
        let (head, body) = raw.split_once("\r\n\r\n").unwrap();
        assert!(head.split(' ').nth(1) == Some("200"), "{head}\n{body}");
        serde_json::from_str(body).unwrap()
    };
    let text = std::fs::read_to_string(root().join("fixtures/uncertainty/semigloss-white.json")).unwrap();
    let recipe: Value = serde_json::from_str(&text).unwrap();
    let m = post("/api/measure", &json!({"recipe": recipe, "geometries": ["astm-d523-60"]}));
    let r = &m["readings"][0];
    assert!((r["prediction_uncertainty"].as_f64().unwrap() - 2.43).abs() < 0.01, "{m}");
    assert_eq!(r["uncertainty_budget"].as_array().map(Vec::len), Some(2));
    let sheet = std::fs::read_to_string(root().join("fixtures/sheets/byk-smart-chart-two-samples.csv")).unwrap();
    let doc = post("/api/compare", &json!({"recipe": recipe, "sheet": {"name": "two.csv", "text": sheet}}));
    let satin: Vec<&Value> =
        doc["comparisons"].as_array().unwrap().iter().filter(|c| c["sample"] == "Satin white").collect();
    assert_eq!(satin.len(), 3);
    for c in satin {
        assert_eq!(c["verdict"], "ok", "{c}");
        assert_eq!(c["allowance"]["parts"][0]["name"], "statistical and prediction uncertainty");
    }
}
