//! `glossmeter serve` (docs/serve.md): the API on a server on an ephemeral loopback port, and its safety:
//! foreign `Host`/`Origin`, oversize bodies, table paths out of the data directory, and a flood of 200
//! concurrent requests (every one answered, 200 with the right bits or 503, and the server still answering).
//! The client is a few lines of HTTP/1.1 over a `TcpStream`, so that a test can send any `Host` it likes.
mod common;

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use glossmeter::serve::{Limits, ServeOptions, Server};
use serde_json::{json, Value};

fn start(options: ServeOptions) -> SocketAddr {
    let server = Server::bind(ServeOptions { port: 0, ..options }).expect("binds");
    let addr = server.addr();
    std::thread::spawn(move || server.run());
    addr
}

fn default_server() -> SocketAddr {
    start(ServeOptions::default())
}

struct Answer {
    status: u16,
    headers: Vec<(String, String)>,
    body: String,
}

impl Answer {
    fn json(&self) -> Value {
        serde_json::from_str(&self.body).unwrap_or_else(|e| panic!("not JSON ({e}): {}", self.body))
    }
    fn header(&self, name: &str) -> Option<&str> {
        self.headers.iter().find(|(k, _)| k.eq_ignore_ascii_case(name)).map(|(_, v)| v.as_str())
    }
}

/// One request with `Connection: close`; `extra` headers as given (a `Host` among them replaces the right one).
fn request(addr: SocketAddr, method: &str, path: &str, body: &[u8], extra: &[(&str, &str)]) -> Answer {
    let mut s = TcpStream::connect(addr).expect("connects");
    s.set_read_timeout(Some(Duration::from_secs(300))).unwrap();
    let mut head = format!("{method} {path} HTTP/1.1\r\nConnection: close\r\nContent-Length: {}\r\n", body.len());
    if !extra.iter().any(|(k, _)| k.eq_ignore_ascii_case("host")) {
        head.push_str(&format!("Host: {addr}\r\n"));
    }
    for (k, v) in extra {
        head.push_str(&format!("{k}: {v}\r\n"));
    }
    head.push_str("Content-Type: application/json\r\n\r\n");
    s.write_all(head.as_bytes()).unwrap();
    // The server may answer (413) before reading a large body and close: a failed write is not a failure.
    let _ = s.write_all(body);
    let mut raw = Vec::new();
    let _ = s.read_to_end(&mut raw);
    parse(&raw)
}

fn parse(raw: &[u8]) -> Answer {
    let split = raw.windows(4).position(|w| w == b"\r\n\r\n").expect("a complete head");
    let head = String::from_utf8_lossy(&raw[..split]).to_string();
    let mut lines = head.split("\r\n");
    let status: u16 = lines.next().unwrap().split(' ').nth(1).unwrap().parse().unwrap();
    let headers: Vec<(String, String)> =
        lines.filter_map(|l| l.split_once(':').map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))).collect();
    let mut body = raw[split + 4..].to_vec();
    if headers.iter().any(|(k, v)| k.eq_ignore_ascii_case("transfer-encoding") && v.contains("chunked")) {
        body = dechunk(&body);
    }
    Answer { status, headers, body: String::from_utf8(body).expect("UTF-8 body") }
}

fn dechunk(mut b: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let end = b.windows(2).position(|w| w == b"\r\n").expect("chunk size line");
        let n = usize::from_str_radix(std::str::from_utf8(&b[..end]).unwrap().trim(), 16).unwrap();
        if n == 0 {
            return out;
        }
        out.extend_from_slice(&b[end + 2..end + 2 + n]);
        b = &b[end + 2 + n + 2..];
    }
}

fn post(addr: SocketAddr, path: &str, body: &Value) -> Answer {
    request(addr, "POST", path, body.to_string().as_bytes(), &[])
}

fn fixture(name: &str) -> String {
    std::fs::read_to_string(format!("fixtures/recipes/{name}.json")).unwrap()
}

/// A request body with the recipe's text spliced in as it is in the file.
fn with_recipe(recipe_text: &str, rest: Value) -> Vec<u8> {
    let mut rest = rest.to_string();
    assert!(rest.ends_with('}'));
    rest.pop();
    let sep = if rest == "{" { "" } else { "," };
    format!("{rest}{sep}\"recipe\":{recipe_text}}}").into_bytes()
}

fn cli_measure_json(file: &str, geometries: &[&str]) -> Value {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_glossmeter"));
    cmd.args(["measure", "--format", "json", "--no-timing", file]);
    for g in geometries {
        cmd.args(["-g", g]);
    }
    let out = cmd.output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn measure_gives_the_bits_of_the_command_line() {
    let addr = default_server();
    for (name, geos) in [("cerulean-blue-c", vec![]), ("semigloss-white", vec!["astm-d523-60", "astm-e430-30"])] {
        let body = with_recipe(&fixture(name), json!({"geometries": geos}));
        let a = request(addr, "POST", "/api/measure", &body, &[]);
        assert_eq!(a.status, 200, "{}", a.body);
        assert_eq!(a.header("content-type"), Some("application/json"));
        let served = a.json();
        let cli = cli_measure_json(&format!("fixtures/recipes/{name}.json"), &geos);
        // Everything but the file name the material came from is the same document, bit for bit.
        assert_eq!(served["readings"], cli["readings"], "{name}");
        assert_eq!(served["evaluations"], cli["evaluations"]);
        assert_eq!(served["material"]["name"], cli["material"]["name"]);
        assert_eq!(served["material"]["file"], "recipe");
        assert!(!served["readings"].as_array().unwrap().is_empty());
    }
}

/// The colour conditions the registry offers (the page's choice) are the ones the requests take: every pair reads
/// a spectral recipe as `measure --illuminant I --observer O` does, and the default pair is a request's without
/// them.
#[test]
fn every_offered_colour_condition_reads_as_the_command_line_does() {
    let addr = default_server();
    let offered = request(addr, "GET", "/api/registry", b"", &[]).json()["colour_conditions"].clone();
    let ids = |key: &str| -> Vec<String> {
        offered[key].as_array().unwrap().iter().map(|x| x["id"].as_str().unwrap().to_owned()).collect()
    };
    let (illuminants, observers) = (ids("illuminants"), ids("observers"));
    assert_eq!(illuminants, ["D65", "D50", "A", "C"]);
    assert_eq!(observers, ["2", "10"]);
    assert_eq!(offered["default"], json!({"illuminant": "D65", "observer": "10"}));
    let file = "fixtures/recipes/white-pearl-spectral.json";
    let text = fixture("white-pearl-spectral");
    let geometry = "astm-e2194-15";
    let plain = request(addr, "POST", "/api/measure", &with_recipe(&text, json!({"geometries": [geometry]})), &[]);
    let mut b_stars = Vec::new();
    for i in &illuminants {
        for o in &observers {
            let body = with_recipe(&text, json!({"geometries": [geometry], "illuminant": i, "observer": o}));
            let a = request(addr, "POST", "/api/measure", &body, &[]);
            assert_eq!(a.status, 200, "{i} {o}: {}", a.body);
            let out = std::process::Command::new(env!("CARGO_BIN_EXE_glossmeter"))
                .args(["measure", "--format", "json", "--no-timing", file, "-g", geometry])
                .args(["--illuminant", i, "--observer", o])
                .output()
                .unwrap();
            assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
            let cli: Value = serde_json::from_slice(&out.stdout).unwrap();
            assert_eq!(a.json()["readings"], cli["readings"], "{i} {o}");
            if (i.as_str(), o.as_str()) == ("D65", "10") {
                assert_eq!(a.json()["readings"], plain.json()["readings"], "the default pair");
            }
            let b = cli["readings"].as_array().unwrap().iter().find(|r| r["name"] == "b*").unwrap()["value"].clone();
            b_stars.push(b.as_f64().unwrap());
        }
    }
    // Eight pairs, eight different colours: the conditions reach the reading.
    b_stars.sort_by(f64::total_cmp);
    b_stars.dedup();
    assert_eq!(b_stars.len(), 8, "{b_stars:?}");
}

/// Objects of a geometry file with `"status": "assumed"` and a number for `value`.
fn assumed_in(v: &Value) -> usize {
    match v {
        Value::Object(o) => {
            usize::from(o.get("status") == Some(&json!("assumed")) && o.get("value").is_some_and(Value::is_number))
                + o.values().map(assumed_in).sum::<usize>()
        }
        Value::Array(a) => a.iter().map(assumed_in).sum(),
        _ => 0,
    }
}

#[test]
fn the_geometries_name_their_instrument_and_their_assumed_numbers() {
    let addr = default_server();
    let geos = request(addr, "GET", "/api/geometries", b"", &[]).json();
    let mut checked = 0;
    for g in geos["geometries"].as_array().unwrap() {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("standards");
        let name = format!("{}.json", g["id"].as_str().unwrap());
        let path = [dir.join(&name), dir.join("colour").join(&name)].into_iter().find(|p| p.exists()).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let file: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(g["title"], file["title"], "{path:?}");
        assert_eq!(g["standards"], file["standards"], "{path:?}");
        let assumed = g["assumed"].as_array().unwrap();
        assert_eq!(assumed.len(), assumed_in(&file), "{path:?}");
        for a in assumed {
            let at = file.pointer(a["pointer"].as_str().unwrap()).unwrap_or_else(|| panic!("{path:?}: {a}"));
            assert_eq!(at["status"], "assumed", "{a}");
            assert_eq!(at["value"], a["value"], "{a}");
            assert_eq!(at["source"], a["source"], "{a}");
        }
        checked += 1;
    }
    assert_eq!(checked, geos["geometries"].as_array().unwrap().len());
    assert!(checked >= 20, "{checked} geometry files checked");
}

#[test]
fn the_endpoints_answer_on_the_command_lines_documents() {
    let addr = default_server();
    let glass = fixture("black-glass");
    // The page and its data.
    let page = request(addr, "GET", "/", b"", &[]);
    assert_eq!(page.status, 200);
    assert!(page.body.contains("<title>glossmeter"));
    assert!(page.header("content-security-policy").is_some());
    let reg = request(addr, "GET", "/api/registry", b"", &[]).json();
    assert!(reg["parameters"].as_array().unwrap().iter().any(|p| p["pointer"] == "/ior" && p["unit"].is_string()));
    let geos = request(addr, "GET", "/api/geometries", b"", &[]).json();
    assert!(geos["geometries"].as_array().unwrap().iter().any(|g| g["id"] == "astm-d523-60" && g["default"] == true));
    let fix = request(addr, "GET", "/api/fixtures", b"", &[]).json();
    assert!(fix["fixtures"].as_array().unwrap().len() > 10);
    assert_eq!(request(addr, "GET", "/nothing", b"", &[]).status, 404);
    // explain: the plan's text.
    let a = request(addr, "POST", "/api/explain", &with_recipe(&glass, json!({"geometries": ["astm-d523-60"]})), &[]);
    assert_eq!(a.status, 200, "{}", a.body);
    assert!(a.json()["plan"].as_str().unwrap().contains("astm-d523-60"));
    // plot: SVG from the library's pictures (the drawing the command line uses).
    for kind in [
        json!({"kind": "section"}),
        json!({"kind": "profile"}),
        json!({"kind": "gloss-vs-parameter", "vary": "/ior=1.4..1.6", "points": 3}),
    ] {
        let a = request(addr, "POST", "/api/plot", &with_recipe(&glass, kind.clone()), &[]);
        assert_eq!(a.status, 200, "{kind}: {}", a.body);
        assert_eq!(a.header("content-type"), Some("image/svg+xml"));
        assert!(a.body.starts_with("<svg"), "{kind}");
    }
    // sweep: the JSON lines of `sweep --format jsonl --no-timing`, streamed, with the count in X-Points.
    let a = request(
        addr,
        "POST",
        "/api/sweep",
        &with_recipe(&glass, json!({"vary": ["/ior=1.4..1.6:3"], "geometries": ["astm-d523-60"]})),
        &[],
    );
    assert_eq!(a.status, 200, "{}", a.body);
    assert_eq!(a.header("x-points"), Some("3"));
    let rows: Vec<Value> = a.body.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(rows.len(), 3);
    let cli = std::process::Command::new(env!("CARGO_BIN_EXE_glossmeter"))
        .args([
            "sweep",
            "fixtures/recipes/black-glass.json",
            "--vary",
            "/ior=1.4..1.6:3",
            "-g",
            "astm-d523-60",
            "--format",
            "jsonl",
            "--no-timing",
        ])
        .output()
        .unwrap();
    let cli_rows: Vec<Value> =
        String::from_utf8(cli.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(
        rows.iter().map(|r| &r["readings"]).collect::<Vec<_>>(),
        cli_rows.iter().map(|r| &r["readings"]).collect::<Vec<_>>()
    );
    // compare: the verdicts of a shipped sheet, in JSON, CSV and JUnit.
    let sheet = std::fs::read_to_string("fixtures/sheets/black-glass-check.csv").unwrap();
    for format in ["json", "csv", "junit"] {
        let a = request(
            addr,
            "POST",
            "/api/compare",
            &with_recipe(&glass, json!({"sheet": {"name": "black-glass-check.csv", "text": sheet}, "format": format})),
            &[],
        );
        assert_eq!(a.status, 200, "{format}: {}", a.body);
        match format {
            "json" => {
                let doc = a.json();
                let cmp = doc["comparisons"].as_array().unwrap();
                assert!(!cmp.is_empty());
                assert!(cmp.iter().all(|c| c["verdict"] == "ok"), "{doc}");
            }
            "csv" => assert!(a.body.lines().count() > 1),
            _ => assert!(a.body.contains("<testsuite")),
        }
    }
    // fit: one free parameter to one target.
    let a = request(
        addr,
        "POST",
        "/api/fit",
        &with_recipe(
            &glass,
            json!({"free": ["/ior=1.3..1.8"], "target": ["astm-d523-60/gloss=90±0.1"], "restarts": 0}),
        ),
        &[],
    );
    assert_eq!(a.status, 200, "{}", a.body);
    let doc = a.json();
    assert_eq!(doc["converged"], true, "{doc}");
    assert!((doc["targets"][0]["predicted"].as_f64().unwrap() - 90.0).abs() < 0.1);
}

/// A fit's colour conditions and evaluation budget are `measure`'s fields, and the served fit is the command
/// line's with the same flags (`fit --illuminant A --observer 2 --max-evals N`), parameter for parameter; so
/// is a served sweep (`sweep --illuminant A --observer 2`), reading for reading.
#[test]
fn a_served_fit_and_sweep_read_colour_under_the_given_conditions_as_the_command_line_does() {
    let addr = default_server();
    let pearl = "fixtures/recipes/white-pearl-spectral.json";
    let (free, target) = ("/pearlescent_flakes/tio2_thickness_nm=30..90", "astm-e2194-15/b*=22.75±0.05");
    let body = with_recipe(
        &std::fs::read_to_string(pearl).unwrap(),
        json!({"free": [free], "target": [target], "restarts": 0, "illuminant": "A", "observer": "2",
               "max_evals": 100000}),
    );
    let a = request(addr, "POST", "/api/fit", &body, &[]);
    assert_eq!(a.status, 200, "{}", a.body);
    let served = a.json();
    let cli = |colour: &[&str]| -> Value {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_glossmeter"))
            .args(["fit", pearl, "--free", free, "--target", target, "--restarts", "0", "--max-evals", "100000"])
            .args(colour)
            .args(["--format", "json", "--no-timing"])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let same = cli(&["--illuminant", "A", "--observer", "2"]);
    for key in ["parameters", "targets", "converged"] {
        assert_eq!(served[key], same[key], "{key}");
    }
    // Under the default D65 / 10° the same target gives another thickness.
    let d65 = cli(&[]);
    assert_ne!(served["parameters"][0]["value"], d65["parameters"][0]["value"]);
    // A served sweep under the same conditions is the command line's `sweep --illuminant A --observer 2`.
    let vary = "/pearlescent_flakes/tio2_thickness_nm=60..69:2";
    let body = with_recipe(
        &std::fs::read_to_string(pearl).unwrap(),
        json!({"vary": [vary], "geometries": ["astm-e2194-15"], "illuminant": "A", "observer": "2"}),
    );
    let a = request(addr, "POST", "/api/sweep", &body, &[]);
    assert_eq!(a.status, 200, "{}", a.body);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_glossmeter"))
        .args(["sweep", pearl, "--vary", vary, "-g", "astm-e2194-15", "--illuminant", "A", "--observer", "2"])
        .args(["--format", "jsonl", "--no-timing"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(a.body.lines().count(), 2);
    for (s, c) in a.body.lines().zip(String::from_utf8(out.stdout).unwrap().lines()) {
        let (s, c): (Value, Value) = (serde_json::from_str(s).unwrap(), serde_json::from_str(c).unwrap());
        assert_eq!(s["readings"], c["readings"]);
    }
    // A bad condition is refused under its own field.
    let bad = with_recipe(
        &std::fs::read_to_string(pearl).unwrap(),
        json!({"free": [free], "target": [target], "illuminant": "D99"}),
    );
    let a = request(addr, "POST", "/api/fit", &bad, &[]);
    assert_eq!(a.status, 400, "{}", a.body);
    assert!(a.body.contains("/illuminant"), "{}", a.body);
}

/// The bytes of a file in base64 (the page's upload), written here so that the test needs no crate for it.
fn base64(bytes: &[u8]) -> String {
    const ABC: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            out.push(if k <= c.len() { ABC[(n >> (18 - 6 * k) & 63) as usize] as char } else { '=' });
        }
    }
    out
}

#[test]
fn a_workbook_upload_gives_the_verdicts_of_the_command_line() {
    // The page's file picker offers .xlsx: the server reads it as `compare` reads the same bytes
    // (`comparison::sheet::from_bytes`), verdict for verdict and number for number.
    let addr = default_server();
    let book = "fixtures/sheets/byk-smart-chart-export.xlsx";
    let bytes = std::fs::read(book).unwrap();
    let recipe = std::fs::read_to_string("fixtures/recipes/glass-n1.5.json").unwrap();
    let body = with_recipe(
        &recipe,
        json!({"sheet": {"name": "byk-smart-chart-export.xlsx", "base64": base64(&bytes)}, "format": "json"}),
    );
    let a = request(addr, "POST", "/api/compare", &body, &[]);
    assert_eq!(a.status, 200, "{}", a.body);
    let served = a.json();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_glossmeter"))
        .args(["compare", "fixtures/recipes/glass-n1.5.json", book, "--format", "json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let cli: Value = serde_json::from_slice(&out.stdout).unwrap();
    let (s, c) = (served["comparisons"].as_array().unwrap(), cli["comparisons"].as_array().unwrap());
    assert_eq!(s.len(), 3);
    assert_eq!(s.len(), c.len());
    for (s, c) in s.iter().zip(c) {
        for key in ["geometry", "reading", "verdict", "n", "mean", "std", "predicted"] {
            assert_eq!(s[key], c[key], "{key}: {s} vs {c}");
        }
    }
    assert_eq!(served["sheet"]["encoding"], "xlsx workbook");
    // `fit` reads the same upload.
    let body = with_recipe(
        &recipe,
        json!({"free": ["/ior=1.3..1.8"], "sheet": {"name": "book.xlsx", "base64": base64(&bytes)}, "restarts": 0}),
    );
    let a = request(addr, "POST", "/api/fit", &body, &[]);
    assert_eq!(a.status, 200, "{}", a.body);
    let ior = a.json()["parameters"][0]["value"].as_f64().unwrap();
    assert!((ior - 1.5).abs() < 0.01, "{ior}");
}

#[test]
fn bad_requests_get_the_librarys_message_as_json_400() {
    let addr = default_server();
    let cases: &[(&str, &[u8], &str)] = &[
        ("/api/measure", b"{not json", "malformed JSON"),
        ("/api/measure", br#"{"recipe": {"model": "lambert", "albedo": 7}}"#, "/albedo"),
        ("/api/measure", br#"{"recipe": {"model": "nope"}}"#, "unknown model"),
        ("/api/measure", br#"{"geometries": ["astm-d523-60"]}"#, "/recipe"),
        ("/api/measure", br#"{"recipe": {"model": "lambert", "albedo": 0.5}, "rtol": 2}"#, "/rtol"),
        ("/api/measure", br#"{"recipe": {"model": "lambert", "albedo": 0.5}, "geometries": ["no-such"]}"#, "no-such"),
        ("/api/measure", br#"{"recipe": {"model": "lambert", "albedo": 0.5}, "max_evals": 1e12}"#, "/max_evals"),
        ("/api/measure", br#"{"recipe": {"model": "lambert", "albedo": 0.5}, "bogus": 1}"#, "unknown field"),
        ("/api/plot", br#"{"recipe": {"model": "lambert", "albedo": 0.5}, "kind": "pie"}"#, "/kind"),
        (
            "/api/sweep",
            br#"{"recipe": {"model": "lambert", "albedo": 0.5}, "vary": ["/albedo=0..1:100000"]}"#,
            "at most",
        ),
        ("/api/compare", br#"{"recipe": {"model": "lambert", "albedo": 0.5}, "sheet": {"base64": "!!"}}"#, "base64"),
        ("/api/fit", br#"{"recipe": {"model": "lambert", "albedo": 0.5}, "free": [], "target": []}"#, "target"),
    ];
    for (path, body, says) in cases {
        let a = request(addr, "POST", path, body, &[]);
        assert_eq!(a.status, 400, "{path} {}: {}", String::from_utf8_lossy(body), a.body);
        let e = a.json()["error"].as_str().unwrap().to_string();
        assert!(e.contains(says), "{path}: {e:?} should say {says:?}");
        assert!(!e.contains("panicked") && !e.contains("src/"), "{e}");
    }
}

/// The plan's fields (`rtol`, `max_evals`, `illuminant`, `observer`) are checked in one place for every
/// endpoint that plans, and each refusal names its own field.
#[test]
fn every_planning_endpoint_refuses_a_bad_plan_field_by_its_name() {
    let addr = default_server();
    let sheet = r#""sheet": {"name": "s.csv", "text": "sample,geometry,value\ns,astm-d523-60,90\n"}"#;
    let endpoints = [
        ("/api/measure", String::new()),
        ("/api/explain", String::new()),
        ("/api/sweep", r#""vary": ["/albedo=0.1..0.9:2"]"#.to_owned()),
        ("/api/plot", r#""kind": "profile""#.to_owned()),
        ("/api/plot", r#""kind": "gloss-vs-parameter", "vary": "/albedo=0.1..0.9""#.to_owned()),
        ("/api/compare", sheet.to_owned()),
        ("/api/fit", r#""free": ["/albedo=0.1..0.9"], "target": ["astm-d523-60/gloss=1±0.1"]"#.to_owned()),
    ];
    let bad = [
        (r#""rtol": -1"#, "/rtol"),
        (r#""rtol": "tight""#, "/rtol"),
        (r#""max_evals": 0"#, "/max_evals"),
        (r#""illuminant": "D99""#, "/illuminant"),
        (r#""observer": "5""#, "/observer"),
    ];
    for (path, rest) in &endpoints {
        for (field, pointer) in bad {
            let sep = if rest.is_empty() { "" } else { ", " };
            let body = format!(r#"{{"recipe": {{"model": "lambert", "albedo": 0.5}}{sep}{rest}, {field}}}"#);
            let a = request(addr, "POST", path, body.as_bytes(), &[]);
            assert_eq!(a.status, 400, "{path} {body}: {}", a.body);
            let e = a.json()["error"].as_str().unwrap().to_string();
            assert!(e.contains(pointer), "{path} {body}: {e:?} should name {pointer}");
        }
    }
}

/// A colour sheet that states A / 2° is refused under the default conditions, naming the fields to give, and
/// read under them (docs/instrument.md §Sheets, "Colour conditions").
#[test]
fn a_served_colour_sheet_is_compared_only_under_its_stated_conditions() {
    let addr = default_server();
    let text = std::fs::read_to_string("fixtures/sheets/colour-blue-metallic.csv")
        .unwrap()
        .replace("# illuminant/observer: D65/10°", "# illuminant/observer: A/2°");
    let recipe = fixture("blue-metallic-spectral");
    let body = |colour: &[(&str, &str)]| {
        let mut rest = json!({"sheet": {"name": "a2.csv", "text": text}, "max_de00": 100});
        for (k, v) in colour {
            rest[*k] = json!(v);
        }
        with_recipe(&recipe, rest)
    };
    let a = request(addr, "POST", "/api/compare", &body(&[]), &[]);
    assert_eq!(a.status, 400, "{}", a.body);
    let e = a.json()["error"].as_str().unwrap().to_string();
    assert!(
        e.contains("not comparable") && e.contains(r#"give "illuminant": "A" "observer": "2" (the sheet's)"#),
        "{e}"
    );
    let a = request(addr, "POST", "/api/compare", &body(&[("illuminant", "A"), ("observer", "2")]), &[]);
    assert_eq!(a.status, 200, "{}", a.body);
    assert!(a.json()["comparisons"].as_array().unwrap().iter().all(|c| c["illuminant"] == "A"));
}

#[test]
fn foreign_host_and_origin_are_refused() {
    let addr = default_server();
    let port = addr.port();
    let body = br#"{"recipe": {"model": "lambert", "albedo": 0.5}, "geometries": ["astm-d523-60"]}"#;
    let own = format!("localhost:{port}");
    let refused: Vec<Vec<(&str, String)>> = vec![
        vec![("Host", "evil.example".into())],
        vec![("Host", format!("evil.example:{port}"))],
        vec![("Host", "localhost:1".into())],
        vec![("Host", own.clone()), ("Origin", "http://evil.example".into())],
        vec![("Host", own.clone()), ("Origin", "null".into())],
        vec![("Host", own.clone()), ("Sec-Fetch-Site", "cross-site".into())],
    ];
    for headers in &refused {
        let h: Vec<(&str, &str)> = headers.iter().map(|(k, v)| (*k, v.as_str())).collect();
        for (method, path) in [("POST", "/api/measure"), ("GET", "/")] {
            let a = request(addr, method, path, if method == "POST" { body } else { b"" }, &h);
            assert_eq!(a.status, 403, "{h:?} {path}: {}", a.body);
            assert!(a.json()["error"].is_string());
        }
    }
    let origin = format!("http://localhost:{port}");
    let a = request(addr, "POST", "/api/measure", body, &[("Host", &own), ("Origin", &origin)]);
    assert_eq!(a.status, 200, "{}", a.body);
}

#[test]
fn oversize_bodies_are_refused_with_413() {
    let addr =
        start(ServeOptions { limits: Limits { body_bytes: 4096, ..Limits::default() }, ..ServeOptions::default() });
    let big =
        format!(r#"{{"recipe": {{"model": "lambert", "albedo": 0.5, "description": "{}"}}}}"#, "x".repeat(10_000));
    let a = request(addr, "POST", "/api/measure", big.as_bytes(), &[]);
    assert_eq!(a.status, 413, "{}", a.body);
    assert!(a.json()["error"].as_str().unwrap().contains("4096"));
    // A body that says it is small and is not: read up to the cap, then refused.
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    let head = format!(
        "POST /api/measure HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\nTransfer-Encoding: chunked\r\n\r\n"
    );
    s.write_all(head.as_bytes()).unwrap();
    let chunk = "y".repeat(3000);
    for _ in 0..3 {
        let _ = s.write_all(format!("{:x}\r\n{chunk}\r\n", chunk.len()).as_bytes());
    }
    let _ = s.write_all(b"0\r\n\r\n");
    let mut raw = Vec::new();
    let _ = s.read_to_end(&mut raw);
    assert_eq!(parse(&raw).status, 413);
    // The server still answers.
    let a = post(
        addr,
        "/api/measure",
        &json!({"recipe": {"model": "lambert", "albedo": 0.5}, "geometries": ["astm-d523-60"]}),
    );
    assert_eq!(a.status, 200, "{}", a.body);
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("glossmeter-serve-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn tables_are_read_only_inside_the_data_directory() {
    let root = scratch("data");
    let data = root.join("data");
    std::fs::create_dir_all(data.join("merl")).unwrap();
    std::fs::copy("fixtures/materials/merl/lambert-tiny.binary", data.join("merl/lambert-tiny.binary")).unwrap();
    std::fs::copy("fixtures/materials/merl/lambert-tiny.binary", root.join("outside.binary")).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(root.join("outside.binary"), data.join("link.binary")).unwrap();
    let addr = start(ServeOptions { data_dir: Some(data.clone()), ..ServeOptions::default() });
    let body = |file: &str| json!({"recipe": {"model": "merl", "file": file}, "geometries": ["astm-d523-60"]});
    let a = post(addr, "/api/measure", &body("merl/lambert-tiny.binary"));
    assert_eq!(a.status, 200, "{}", a.body);
    assert!(a.json()["readings"][0]["value"].is_number());
    let outside = root.join("outside.binary").display().to_string();
    let mut refused =
        vec!["../outside.binary", "merl/../../outside.binary", outside.as_str(), "missing.binary", "merl"];
    if cfg!(unix) {
        refused.push("link.binary");
    }
    for f in refused {
        for path in ["/api/measure", "/api/plot", "/api/sweep", "/api/compare", "/api/fit"] {
            let mut b = body(f);
            match path {
                "/api/plot" => b["kind"] = json!("section"),
                "/api/sweep" => b["vary"] = json!(["/interpolation=0..1:2"]),
                "/api/compare" => {
                    b.as_object_mut().unwrap().remove("geometries");
                    b["sheet"] = json!({"text": "sample,60°\na,10\n"});
                }
                "/api/fit" => {
                    b = json!({"recipe": b["recipe"], "free": ["/x=0..1"], "target": ["astm-d523-60/gloss=1"]});
                }
                _ => {}
            }
            let a = post(addr, path, &b);
            assert_eq!(a.status, 400, "{f} {path}: {}", a.body);
            let e = a.json()["error"].as_str().unwrap().to_string();
            assert!(e.contains("/file"), "{f} {path}: {e}");
            // The message repeats what the client sent and nothing of where the server keeps its files.
            if !f.starts_with('/') {
                assert!(!e.contains(&root.display().to_string()), "the message shows no server path: {e}");
            }
        }
    }
    // Without --data-dir no table is read at all.
    let bare = default_server();
    let a = post(bare, "/api/measure", &body("merl/lambert-tiny.binary"));
    assert_eq!(a.status, 400);
    assert!(a.body.contains("--data-dir"));
    std::fs::remove_dir_all(&root).unwrap();
}

#[test]
fn a_flood_of_200_concurrent_requests_is_bounded_and_nothing_is_lost() {
    let addr = start(ServeOptions { limits: Limits { jobs: 2, ..Limits::default() }, ..ServeOptions::default() });
    let body = with_recipe(&fixture("cerulean-blue-c"), json!({}));
    let expected = cli_measure_json("fixtures/recipes/cerulean-blue-c.json", &[]);
    let clock = Instant::now();
    let handles: Vec<_> = (0..200)
        .map(|_| {
            let body = body.clone();
            std::thread::spawn(move || request(addr, "POST", "/api/measure", &body, &[]))
        })
        .collect();
    let answers: Vec<Answer> = handles.into_iter().map(|h| h.join().expect("every request is answered")).collect();
    let elapsed = clock.elapsed();
    let ok: Vec<&Answer> = answers.iter().filter(|a| a.status == 200).collect();
    let busy = answers.iter().filter(|a| a.status == 503).count();
    eprintln!("flood: {} served, {busy} answered busy, in {elapsed:?}", ok.len());
    assert_eq!(
        ok.len() + busy,
        200,
        "every answer is 200 or 503: {:?}",
        answers.iter().map(|a| a.status).collect::<Vec<_>>()
    );
    assert!(!ok.is_empty(), "some requests were served");
    assert!(busy > 0, "the concurrency cap answered the excess 503");
    for a in &ok {
        assert_eq!(a.json()["readings"], expected["readings"], "a served reading is the command line's");
    }
    for a in answers.iter().filter(|a| a.status == 503) {
        assert_eq!(a.header("retry-after"), Some("1"));
        assert!(a.json()["error"].as_str().unwrap().contains("busy"));
    }
    // Bounded in time: the excess is refused at once, so the flood ends in about the time of a few readings
    // (a generous bound, not a benchmark).
    assert!(elapsed < Duration::from_secs(120), "the flood took {elapsed:?}");
    // Still answering, and computing.
    let a = request(addr, "POST", "/api/measure", &body, &[]);
    assert_eq!(a.status, 200, "{}", a.body);
    assert_eq!(a.json()["readings"], expected["readings"]);
}

#[test]
fn a_table_s_tolerance_is_chosen_as_the_command_line_chooses_it() {
    // Without `rtol` a measured table's tolerance comes from its data; with one it is used as given, as
    // `measure --rtol` uses it: the two readings differ, and each is the command line's to the bit.
    const RECIPE: &str = "fixtures/materials/rgl/beckmann-iso-32.json";
    let addr = start(ServeOptions { data_dir: Some("fixtures/materials/rgl".into()), ..ServeOptions::default() });
    let cli = |rtol: Option<&str>| {
        let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_glossmeter"));
        cmd.args(["measure", "--format", "json", "--no-timing", RECIPE, "-g", "astm-d523-60"]);
        if let Some(r) = rtol {
            cmd.args(["--rtol", r]);
        }
        let out = cmd.output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice::<Value>(&out.stdout).unwrap()
    };
    let text = std::fs::read_to_string(RECIPE).unwrap();
    let from_data =
        request(addr, "POST", "/api/measure", &with_recipe(&text, json!({"geometries": ["astm-d523-60"]})), &[]);
    let given = request(
        addr,
        "POST",
        "/api/measure",
        &with_recipe(&text, json!({"geometries": ["astm-d523-60"], "rtol": 1e-4})),
        &[],
    );
    assert_eq!(from_data.status, 200, "{}", from_data.body);
    assert_eq!(given.status, 200, "{}", given.body);
    assert_eq!(from_data.json()["readings"], cli(None)["readings"]);
    assert_eq!(given.json()["readings"], cli(Some("1e-4"))["readings"]);
    assert_ne!(from_data.json()["readings"], given.json()["readings"]);
}

/// The table files a recipe may name (`GET /api/tables`, which the page fills a table model's `/file` from):
/// the data directory's files each table model reads, relative to it, a link out of it not listed; none
/// without `--data-dir`. The first listed file reads as `measure` reads it.
#[test]
fn the_tables_of_the_data_directory_are_listed_per_model() {
    let root = scratch("tables");
    let data = root.join("data");
    std::fs::create_dir_all(data.join("merl")).unwrap();
    std::fs::create_dir_all(data.join("inplane")).unwrap();
    std::fs::copy("fixtures/materials/merl/lambert-tiny.binary", data.join("merl/lambert-tiny.binary")).unwrap();
    std::fs::copy("fixtures/materials/inplane/beckmann.csv", data.join("inplane/beckmann.csv")).unwrap();
    std::fs::copy("fixtures/materials/merl/lambert-tiny.binary", root.join("outside.binary")).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(root.join("outside.binary"), data.join("link.binary")).unwrap();
    let addr = start(ServeOptions { data_dir: Some(data.clone()), ..ServeOptions::default() });
    let doc = request(addr, "GET", "/api/tables", b"", &[]).json();
    assert_eq!(doc["data_dir"], true);
    let files =
        |model: &str| doc["models"].as_array().unwrap().iter().find(|m| m["model"] == model).unwrap()["files"].clone();
    assert_eq!(files("merl"), json!(["merl/lambert-tiny.binary"]), "the link out is not listed: {doc}");
    assert_eq!(files("inplane-csv"), json!(["inplane/beckmann.csv"]));
    assert_eq!(files("rgl"), json!([]));
    assert!(!doc.to_string().contains(&root.display().to_string()), "no server path: {doc}");
    let a = post(addr, "/api/measure", &json!({"recipe": {"model": "merl", "file": "merl/lambert-tiny.binary"}}));
    assert_eq!(a.status, 200, "{}", a.body);
    let cli = std::process::Command::new(env!("CARGO_BIN_EXE_glossmeter"))
        .args(["measure", "--format", "json", "--no-timing", "fixtures/recipes/merl-lambert-tiny.json"])
        .output()
        .unwrap();
    let cli: Value = serde_json::from_slice(&cli.stdout).unwrap();
    assert_eq!(a.json()["readings"], cli["readings"]);
    let bare = request(default_server(), "GET", "/api/tables", b"", &[]).json();
    assert_eq!(bare["data_dir"], false);
    assert!(bare["models"].as_array().unwrap().iter().all(|m| m["files"] == json!([])), "{bare}");
    std::fs::remove_dir_all(&root).unwrap();
}

/// An RGB recipe through a colour geometry: the library's refusal (docs/colour.md: three R, G, B values are no
/// spectrum), 400 with the command line's message naming the geometry and `wavelengths_nm`, while the same
/// recipe reads without the colour geometry; `/api/geometries` marks the colour geometries, so that the page
/// can leave them out and say why in place (docs/serve.md §The page).
#[test]
fn an_rgb_recipe_is_refused_colour_as_the_command_line_refuses_it() {
    let addr = default_server();
    let geos = request(addr, "GET", "/api/geometries", b"", &[]).json();
    let colour: Vec<&str> = geos["geometries"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|g| g["colour"] == true)
        .map(|g| g["id"].as_str().unwrap())
        .collect();
    for id in ["d8-sci", "d8-sce"] {
        assert!(colour.contains(&id), "{colour:?}");
    }
    assert!(colour.iter().any(|id| id.contains("e2194")) && !colour.contains(&"astm-d523-60"), "{colour:?}");
    let text = fixture("rgb-lambert");
    let a = request(
        addr,
        "POST",
        "/api/measure",
        &with_recipe(&text, json!({"geometries": ["astm-d523-60", "d8-sci"]})),
        &[],
    );
    assert_eq!(a.status, 400, "{}", a.body);
    let e = a.json()["error"].as_str().unwrap().to_string();
    assert!(e.contains("d8-sci") && e.contains("wavelengths_nm") && e.contains("RGB"), "{e}");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_glossmeter"))
        .args(["measure", "fixtures/recipes/rgb-lambert.json", "-g", "astm-d523-60", "-g", "d8-sci"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let cli = String::from_utf8_lossy(&out.stderr);
    let why = e.split_once("colour readings").unwrap().1;
    assert!(cli.contains(why), "the command line says the same: {cli}");
    let a = request(addr, "POST", "/api/measure", &with_recipe(&text, json!({"geometries": ["astm-d523-60"]})), &[]);
    assert_eq!(a.status, 200, "{}", a.body);
    let gloss = cli_measure_json("fixtures/recipes/rgb-lambert.json", &["astm-d523-60"]);
    assert_eq!(a.json()["readings"], gloss["readings"]);
    assert!(a.json().get("refused").is_none());
    // `omit_refused_colour` (the page's): the refused colour geometries left out and the refusal in the
    // document, the other readings the same bits.
    let body = json!({"geometries": ["astm-d523-60", "d8-sci", "astm-e2194-45"], "omit_refused_colour": true});
    let a = request(addr, "POST", "/api/measure", &with_recipe(&text, body), &[]);
    assert_eq!(a.status, 200, "{}", a.body);
    let doc = a.json();
    assert_eq!(doc["readings"], gloss["readings"]);
    assert_eq!(doc["evaluations"], gloss["evaluations"]);
    assert_eq!(doc["refused"]["geometries"], json!(["d8-sci", "astm-e2194-45"]));
    let m = doc["refused"]["message"].as_str().unwrap();
    assert!(m.starts_with("d8-sci, astm-e2194-45: ") && m.ends_with(why), "{m}");
    let only = json!({"geometries": ["d8-sci"], "omit_refused_colour": true});
    let doc = request(addr, "POST", "/api/measure", &with_recipe(&text, only), &[]).json();
    assert_eq!((doc["readings"].clone(), doc["refused"]["geometries"].clone()), (json!([]), json!(["d8-sci"])));
    // A spectral recipe is not touched by the option: the same document as without it.
    let spectral = fixture("white-pearl-spectral");
    let with = json!({"geometries": ["d8-sci"], "omit_refused_colour": true});
    let a = request(addr, "POST", "/api/measure", &with_recipe(&spectral, with), &[]).json();
    let b =
        request(addr, "POST", "/api/measure", &with_recipe(&spectral, json!({"geometries": ["d8-sci"]})), &[]).json();
    assert_eq!(a, b);
    assert!(a["readings"].as_array().unwrap().iter().any(|r| r["name"] == "L*"));
}

const GLASS: &str = "fixtures/recipes/glass-n1.5.json";

/// `glossmeter ARGS…`: its exit code, standard output and standard error.
fn cli(args: &[&str]) -> (Option<i32>, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_glossmeter")).args(args).output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The command line's error as the server words it: without `error: `, with the file's path given as the name
/// the upload carries, and an argument named as the body's field (the library's words, each front end naming
/// its arguments its own way: `--ignore-column`, `` `ignore_columns` ``).
fn cli_error(stderr: &str, path: &str, name: &str) -> String {
    let line = stderr.trim_end();
    line.strip_prefix("error: ").unwrap_or(line).replace(path, name).replace("--ignore-column", "`ignore_columns`")
}

/// A `compare` or `fit` body: `rest` with the file at `path` uploaded as `sheet` (its base64, under its name).
fn upload(path: &str, rest: Value) -> Vec<u8> {
    let name = path.rsplit('/').next().unwrap();
    let mut rest = rest;
    rest["sheet"] = json!({"name": name, "base64": base64(&std::fs::read(path).unwrap())});
    with_recipe(&std::fs::read_to_string(GLASS).unwrap(), rest)
}

/// A `compare` document with the paths of the command line's files given as the server names them.
fn as_served(cli_json: &str, sheet_path: &str) -> Value {
    let name = sheet_path.rsplit('/').next().unwrap();
    let mut doc: Value = serde_json::from_str(cli_json).unwrap_or_else(|e| panic!("{e}: {cli_json}"));
    let text = doc.to_string().replace(sheet_path, name).replace(GLASS, "recipe");
    doc = serde_json::from_str(&text).unwrap();
    doc
}

/// `sheet_name` (with `delimiter`, `ignore_columns` and `header_row`, docs/serve.md §The API) reads an uploaded
/// workbook's sheet as `compare --sheet-name` and `fit --sheet-name` read the file's: the named sheet, and for a
/// sheet the workbook does not have (or one without readings) the command line's message.
#[test]
fn sheet_name_reads_the_named_sheet_of_an_uploaded_workbook() {
    let addr = default_server();
    let book = "fixtures/sheets/byk-smart-chart-export.xlsx";
    let first = request(addr, "POST", "/api/compare", &upload(book, json!({})), &[]);
    assert_eq!(first.status, 200, "{}", first.body);
    let named = request(addr, "POST", "/api/compare", &upload(book, json!({"sheet_name": "Measurements"})), &[]);
    assert_eq!(named.status, 200, "{}", named.body);
    assert_eq!(named.json(), first.json());
    let (code, out, err) = cli(&["compare", GLASS, book, "--sheet-name", "Measurements", "--format", "json"]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(named.json(), as_served(&out, book));
    for (sheet, says) in [("Instrument", r#"sheet "Instrument", row 1"#), ("Readings", r#"no sheet "Readings""#)] {
        let a = request(addr, "POST", "/api/compare", &upload(book, json!({"sheet_name": sheet})), &[]);
        assert_eq!(a.status, 400, "{sheet}: {}", a.body);
        let served = a.json()["error"].as_str().unwrap().to_string();
        assert!(served.contains(says), "{served}");
        let (code, _, err) = cli(&["compare", GLASS, book, "--sheet-name", sheet]);
        assert_eq!(code, Some(2));
        assert_eq!(served, cli_error(&err, book, "byk-smart-chart-export.xlsx"));
        let fit = json!({"free": ["/ior=1.3..1.8"], "sheet_name": sheet, "restarts": 0});
        let a = request(addr, "POST", "/api/fit", &upload(book, fit), &[]);
        assert_eq!(a.status, 400, "{sheet}: {}", a.body);
        let (code, _, err) = cli(&["fit", GLASS, "--sheet", book, "--sheet-name", sheet, "--free", "/ior=1.3..1.8"]);
        assert_eq!(code, Some(2));
        assert_eq!(a.json()["error"].as_str().unwrap(), cli_error(&err, book, "byk-smart-chart-export.xlsx"));
    }
    // A sheet's options without a sheet are refused, as `fit --sheet-name` without `--sheet` is.
    let body = with_recipe(
        &std::fs::read_to_string(GLASS).unwrap(),
        json!({"free": ["/ior=1.3..1.8"], "target": ["astm-d523-60/gloss=89±0.1"], "sheet_name": "Measurements"}),
    );
    let a = request(addr, "POST", "/api/fit", &body, &[]);
    assert_eq!(a.status, 400, "{}", a.body);
    assert!(a.json()["error"].as_str().unwrap().contains("field `/sheet_name`"), "{}", a.body);
    // The delimiter is the command line's too: `;` is not the separator of a comma sheet.
    let csv = "fixtures/sheets/glass-n1.5-trigloss.csv";
    let a = request(addr, "POST", "/api/compare", &upload(csv, json!({"delimiter": "|"})), &[]);
    assert_eq!(a.status, 400, "{}", a.body);
    let (_, _, err) = cli(&["compare", GLASS, csv, "--delimiter", "|"]);
    let e = a.json()["error"].as_str().unwrap().to_string();
    assert!(e.contains("field `/delimiter`") && err.contains("--delimiter"), "{e} / {err}");
    assert_eq!(e.split_once("must be").unwrap().1, err.trim_end().split_once("must be").unwrap().1);
}

/// `tolerance` as `compare --tolerance` takes it (docs/serve.md §The API): per reading, as an array of
/// `KEY=NUMBER` strings or as an object, gives the command line's document; a refused entry is named by its
/// JSON Pointer with the command line's reason.
#[test]
fn per_reading_tolerances_give_the_command_lines_document() {
    let addr = default_server();
    let csv = "fixtures/sheets/glass-n1.5-trigloss.csv";
    let (code, out, err) = cli(&[
        "compare",
        GLASS,
        csv,
        "--format",
        "json",
        "--tolerance",
        "gloss=0.01",
        "--tolerance",
        "astm-d523-60/gloss=1",
    ]);
    assert_eq!(code, Some(1), "one reading is inside, two outside: {err}");
    let cli_doc = as_served(&out, csv);
    let verdicts: Vec<&Value> = cli_doc["comparisons"].as_array().unwrap().iter().map(|c| &c["verdict"]).collect();
    assert_eq!(verdicts, [&json!("OUTSIDE"), &json!("ok"), &json!("OUTSIDE")], "{cli_doc}");
    for tolerance in [json!(["gloss=0.01", "astm-d523-60/gloss=1"]), json!({"gloss": 0.01, "astm-d523-60/gloss": 1})] {
        let a = request(addr, "POST", "/api/compare", &upload(csv, json!({"tolerance": tolerance})), &[]);
        assert_eq!(a.status, 200, "{}", a.body);
        assert_eq!(a.body, report_pretty(&cli_doc), "{tolerance}");
    }
    // A plain number is every reading's, as `--tolerance 1` is.
    let a = request(addr, "POST", "/api/compare", &upload(csv, json!({"tolerance": 1})), &[]);
    let (_, out, _) = cli(&["compare", GLASS, csv, "--format", "json", "--tolerance", "1"]);
    assert_eq!(a.json(), as_served(&out, csv));
    for (tolerance, pointer) in [
        (json!(["gloss=2", "gloss=x"]), "/tolerance/1"),
        (json!(["gloss=2", 3]), "/tolerance/1"),
        (json!({"gloss": "2"}), "/tolerance/gloss"),
        (json!({"no-such/gloss": 2}), "/tolerance/no-such~1gloss"),
        (json!(true), "/tolerance"),
        (json!(["gloss=1", "gloss=2"]), "/tolerance"),
    ] {
        let a = request(addr, "POST", "/api/compare", &upload(csv, json!({"tolerance": tolerance})), &[]);
        assert_eq!(a.status, 400, "{tolerance}: {}", a.body);
        let e = a.json()["error"].as_str().unwrap().to_string();
        assert!(e.starts_with(&format!("request: field `{pointer}`: ")), "{tolerance}: {e}");
    }
    let a = request(addr, "POST", "/api/compare", &upload(csv, json!({"tolerance": ["gloss=x"]})), &[]);
    let (code, _, err) = cli(&["compare", GLASS, csv, "--tolerance", "gloss=x"]);
    assert_eq!(code, Some(2));
    let e = a.json()["error"].as_str().unwrap().to_string();
    let why = e.split_once("`/tolerance/0`: ").unwrap().1;
    assert!(err.contains(why), "the command line gives the same reason: {why:?} in {err}");
}

/// The server's JSON text of a document (`report::pretty`).
fn report_pretty(doc: &Value) -> String {
    glossmeter::report::pretty(doc)
}

/// Workbook uploads are read as `compare` reads the files (docs/serve.md §The page): an `.xls` and an `.ods`
/// (and the `.xlsx`) give the command line's document; each hostile workbook of docs/reliability.md
/// §Workbooks gets 400 with the command line's message.
#[test]
fn workbook_uploads_are_answered_as_compare_answers_the_files() {
    let addr = default_server();
    for book in [
        "fixtures/sheets/byk-smart-chart-export.xls",
        "fixtures/sheets/byk-smart-chart-export.ods",
        "fixtures/sheets/byk-smart-chart-export.xlsx",
    ] {
        let a = request(addr, "POST", "/api/compare", &upload(book, json!({})), &[]);
        assert_eq!(a.status, 200, "{book}: {}", a.body);
        let (code, out, err) = cli(&["compare", GLASS, book, "--format", "json"]);
        assert_eq!(code, Some(0), "{book}: {err}");
        let cli_doc = as_served(&out, book);
        assert_eq!(a.body, report_pretty(&cli_doc), "{book}");
        let cmp = cli_doc["comparisons"].as_array().unwrap();
        assert_eq!(cmp.len(), 3, "{book}");
        assert!(cmp.iter().all(|c| c["verdict"] == "ok" && c["n"] == 5), "{book}: {cli_doc}");
    }
    for (name, path) in &common::hostile_workbooks() {
        let a = request(addr, "POST", "/api/compare", &upload(path, json!({})), &[]);
        assert_eq!(a.status, 400, "{name}: {}", a.body);
        let (code, _, err) = cli(&["compare", GLASS, path]);
        assert_eq!(code, Some(2), "{name}: {err}");
        let served = a.json()["error"].as_str().unwrap().to_string();
        assert!(served.contains(name.as_str()) && !served.contains("panicked"), "{served}");
        assert_eq!(served, cli_error(&err, path, name), "{name}");
    }
}

/// `/api/plot` of `kind: gloss-vs-parameter` and `plot --kind gloss-vs-parameter` with the same numbers give the
/// same SVG, byte for byte: both convert into the library's request and draw with the library's pictures.
#[test]
fn a_gloss_vs_parameter_picture_is_the_command_lines_svg() {
    let addr = default_server();
    let out = scratch("vs-parameter").join("picture.svg");
    let (code, _, err) = cli(&[
        "plot",
        "fixtures/recipes/black-glass.json",
        "--kind",
        "gloss-vs-parameter",
        "--vary",
        "/ior=1.4..1.6",
        "--points",
        "4",
        "--rtol",
        "1e-4",
        "-g",
        "astm-d523-20",
        "-g",
        "astm-d523-85",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let file = std::fs::read_to_string(&out).unwrap();
    let _ = std::fs::remove_file(&out);
    let body = json!({"kind": "gloss-vs-parameter", "vary": "/ior=1.4..1.6", "points": 4, "rtol": 1e-4,
                      "geometries": ["astm-d523-20", "astm-d523-85"]});
    let a = request(addr, "POST", "/api/plot", &with_recipe(&fixture("black-glass"), body), &[]);
    assert_eq!(a.status, 200, "{}", a.body);
    assert!(file.starts_with("<svg") && file.contains("astm-d523-85"), "{file}");
    assert_eq!(a.body, file);
}
