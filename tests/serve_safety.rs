//! `glossmeter serve` is safe to leave running (docs/serve.md §Safety, §Connections, §Limits). It stays up
//! and frees its work: at an open-file limit of 256 with 2 000 idle connections it still answers a new client
//! and is alive afterwards (and it kept fewer connections open than its cap); a client that sends no
//! headers, or too slow a body, is closed or answered 408; a computation whose client leaves gives its slot
//! back at its next integral; one that runs past the time limit answers with the readings it finished. Time
//! bounds here are generous liveness checks, not speed assertions: each failure mode they catch would take
//! minutes. And it tells a client nothing it should not: a `Host` or `Origin` sent twice and
//! `Sec-Fetch-Site: Cross-Site` are refused, no answer shows the data directory's absolute path, a link to an
//! outside directory does not tell whether a file exists there, and refusals name their field.
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

use glossmeter::serve::{Limits, ServeOptions, Server};
use serde_json::{json, Value};

fn start(limits: Limits) -> SocketAddr {
    let server = Server::bind(ServeOptions { port: 0, limits, ..ServeOptions::default() }).expect("binds");
    let addr = server.addr();
    std::thread::spawn(move || server.run());
    addr
}

/// One request with `Connection: close`; the status and the body (None: no answer, the connection closed).
fn request(addr: SocketAddr, method: &str, path: &str, body: &[u8]) -> Option<(u16, String)> {
    let mut s = TcpStream::connect(addr).ok()?;
    s.set_read_timeout(Some(Duration::from_secs(120))).unwrap();
    let head = format!(
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\nContent-Type: application/json\r\n\
         Content-Length: {}\r\n\r\n",
        body.len()
    );
    s.write_all(head.as_bytes()).ok()?;
    s.write_all(body).ok()?;
    let mut raw = Vec::new();
    let _ = s.read_to_end(&mut raw);
    let text = String::from_utf8_lossy(&raw).to_string();
    let status = text.split(' ').nth(1)?.parse().ok()?;
    let body = text.split_once("\r\n\r\n").map(|(_, b)| b.to_string()).unwrap_or_default();
    Some((status, body))
}

fn recipe(path: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Every shipped geometry with readings of its own (14: the server takes at most 16).
const ALL: [&str; 14] = [
    "astm-d2457-45",
    "astm-d523-20",
    "astm-d523-60",
    "astm-d523-85",
    "astm-e430-20",
    "astm-e430-30",
    "iso-13803-20",
    "iso-2813-20",
    "iso-2813-60",
    "iso-2813-85",
    "rhopoint-iq-20",
    "rspec-20",
    "tappi-t480-75",
    "astm-d4039",
];

/// A request of minutes made of many short integrals: the gloss-vs-parameter picture of a three-population
/// panel over 41 values on 14 geometries at rtol 1e-12 (over 150 s in the 8134dee review).
fn heavy_plot() -> Vec<u8> {
    json!({
        "kind": "gloss-vs-parameter",
        "vary": "/populations/0/roughness=0.05..0.3",
        "points": 41,
        "geometries": ALL,
        "rtol": 1e-12,
        "max_evals": 100_000_000,
        "recipe": recipe("fixtures/real/models/panel-three-populations.json"),
    })
    .to_string()
    .into_bytes()
}

fn cheap_measure() -> Vec<u8> {
    json!({"recipe": {"model": "lambert", "albedo": 0.5}, "geometries": ["astm-d523-60"]}).to_string().into_bytes()
}

/// Raise this process's soft open-file limit to `want` if the hard limit allows (the test opens 2 000
/// sockets); the limit it has after.
fn raise_open_files(want: u64) -> u64 {
    use rustix::process::{getrlimit, setrlimit, Resource, Rlimit};
    let r = getrlimit(Resource::Nofile);
    let hard = r.maximum.unwrap_or(u64::MAX);
    let now = r.current.unwrap_or(u64::MAX);
    if now < want {
        let _ = setrlimit(Resource::Nofile, Rlimit { current: Some(want.min(hard)), maximum: r.maximum });
    }
    getrlimit(Resource::Nofile).current.unwrap_or(u64::MAX)
}

#[test]
fn at_an_open_file_limit_of_256_two_thousand_idle_connections_do_not_stop_the_server() {
    // 2 000 where the hard limit allows (it does on Linux by default); at least twice the server's cap of 216.
    let have = raise_open_files(2_300);
    let n = 2_000.min(have.saturating_sub(200) as usize);
    assert!(n >= 432, "this test needs an open-file limit of at least 632 (the hard limit allows {have})");
    let mut child = std::process::Command::new("sh")
        .args(["-c", &format!("ulimit -n 256 && exec {} serve --port 0", env!("CARGO_BIN_EXE_glossmeter"))])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).unwrap();
    // "glossmeter serve: http://127.0.0.1:PORT/ (stop with Ctrl-C; at most 216 connections, open-file limit 256; …)"
    assert!(line.contains("at most 216 connections, open-file limit 256"), "{line}");
    let port: u16 = line.split("127.0.0.1:").nth(1).unwrap().split('/').next().unwrap().parse().unwrap();
    let addr: SocketAddr = format!("127.0.0.1:{port}").parse().unwrap();

    let clock = Instant::now();
    let mut idle = Vec::with_capacity(n);
    let mut refused = 0;
    for _ in 0..n {
        match TcpStream::connect_timeout(&addr, Duration::from_secs(5)) {
            Ok(s) => idle.push(s),
            Err(_) => refused += 1,
        }
    }
    eprintln!("{} idle connections opened ({refused} not) in {:?}", idle.len(), clock.elapsed());
    // A new client is answered while the idle ones are held (the server closes the idlest to make room).
    let clock = Instant::now();
    let answer = request(addr, "POST", "/api/measure", &cheap_measure());
    eprintln!("the new client was answered in {:?}", clock.elapsed());
    assert_eq!(answer.as_ref().map(|a| a.0), Some(200), "{answer:?}");
    assert!(clock.elapsed() < Duration::from_secs(30), "answered after {:?}", clock.elapsed());
    // The server kept at most its cap open: the others were closed (EOF or reset on a read).
    let mut open = 0;
    for s in &idle {
        s.set_nonblocking(true).unwrap();
        let mut b = [0u8; 1];
        if matches!((&*s).read(&mut b), Err(e) if e.kind() == std::io::ErrorKind::WouldBlock) {
            open += 1;
        }
    }
    eprintln!("{open} of the idle connections still open");
    assert!(open <= 216, "{open} connections open, over the cap of 216");
    drop(idle);
    // Alive afterwards, and computing.
    assert_eq!(request(addr, "POST", "/api/measure", &cheap_measure()).map(|a| a.0), Some(200));
    assert!(child.try_wait().unwrap().is_none(), "the server is still running");
    child.kill().unwrap();
    let _ = child.wait();
    let mut err = String::new();
    child.stderr.take().unwrap().read_to_string(&mut err).unwrap();
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn a_client_that_sends_no_headers_is_closed_after_the_header_timeout() {
    let addr = start(Limits { header_seconds: 1.0, ..Limits::default() });
    let mut silent = TcpStream::connect(addr).unwrap();
    let mut partial = TcpStream::connect(addr).unwrap();
    partial.write_all(b"POST /api/measure HTTP/1.1\r\nHost: ").unwrap();
    for s in [&mut silent, &mut partial] {
        s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
        let clock = Instant::now();
        let mut raw = Vec::new();
        let read = s.read_to_end(&mut raw);
        assert!(read.is_ok() || clock.elapsed() < Duration::from_secs(60), "{read:?}");
        assert!(clock.elapsed() < Duration::from_secs(60), "still open after {:?}", clock.elapsed());
    }
    // An idle keep-alive connection is closed the same way after its answer.
    let mut keep = TcpStream::connect(addr).unwrap();
    keep.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    keep.write_all(format!("GET /api/registry HTTP/1.1\r\nHost: {addr}\r\n\r\n").as_bytes()).unwrap();
    let clock = Instant::now();
    let mut raw = Vec::new();
    let _ = keep.read_to_end(&mut raw);
    assert!(raw.starts_with(b"HTTP/1.1 200"), "{}", String::from_utf8_lossy(&raw[..raw.len().min(200)]));
    assert!(clock.elapsed() < Duration::from_secs(60));
    // The server still answers.
    assert_eq!(request(addr, "GET", "/api/registry", b"").map(|a| a.0), Some(200));
}

#[test]
fn a_body_slower_than_the_body_timeout_is_answered_408() {
    let addr = start(Limits { body_seconds: 1.0, ..Limits::default() });
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    let head = format!("POST /api/measure HTTP/1.1\r\nHost: {addr}\r\nContent-Length: 100\r\n\r\n{{\"recipe\"");
    s.write_all(head.as_bytes()).unwrap();
    let mut raw = Vec::new();
    let _ = s.read_to_end(&mut raw);
    let text = String::from_utf8_lossy(&raw);
    assert!(text.starts_with("HTTP/1.1 408"), "{text}");
    assert!(text.contains("did not arrive within 1 s"), "{text}");
}

#[test]
fn a_client_that_leaves_frees_its_slot_at_the_next_integral() {
    // The plot's budget is fifty times the default, so that it holds the slot for longer than the polling below
    // takes on any machine (under the default budget a fast machine finished it before a poll saw it busy).
    let addr = start(Limits { jobs: 1, request_seconds: 3600.0, max_evals: 100_000_000, ..Limits::default() });
    let mut leaver = TcpStream::connect(addr).unwrap();
    let body = heavy_plot();
    let head = format!("POST /api/plot HTTP/1.1\r\nHost: {addr}\r\nContent-Length: {}\r\n\r\n", body.len());
    leaver.write_all(head.as_bytes()).unwrap();
    leaver.write_all(&body).unwrap();
    // Let the plot reach the server and take the slot before the first poll: a poll that arrived first would
    // take the only slot itself and the plot would be refused, after which no poll sees the slot busy (a race
    // that a loaded machine lost, while another test of this file ran beside it).
    std::thread::sleep(Duration::from_millis(500));
    // It holds the only slot: a cheap request is refused while it computes.
    let clock = Instant::now();
    let mut busy = false;
    while clock.elapsed() < Duration::from_secs(30) && !busy {
        busy = request(addr, "POST", "/api/measure", &cheap_measure()).is_some_and(|a| a.0 == 503);
    }
    assert!(busy, "the heavy request holds the only slot");
    std::thread::sleep(Duration::from_millis(500));
    assert_eq!(request(addr, "POST", "/api/measure", &cheap_measure()).map(|a| a.0), Some(503));
    drop(leaver);
    let left = Instant::now();
    let mut served = None;
    while left.elapsed() < Duration::from_secs(60) {
        match request(addr, "POST", "/api/measure", &cheap_measure()) {
            Some((200, body)) => {
                served = Some(body);
                break;
            }
            _ => std::thread::sleep(Duration::from_millis(100)),
        }
    }
    eprintln!("the slot was free {:?} after the client left", left.elapsed());
    let body = served.expect("the next request is served once the client has left");
    assert!(body.contains("\"readings\""), "{body}");
}

#[test]
fn a_computation_past_the_time_limit_answers_with_the_readings_it_finished() {
    // The budget is fifty times the default, so that no machine finishes every reading within the limit (a
    // fast one did 22 million evaluations in 0.8 s under the default budget).
    let addr = start(Limits { request_seconds: 1.0, max_evals: 100_000_000, ..Limits::default() });
    let body = json!({
        "geometries": ALL,
        "rtol": 1e-12,
        "max_evals": 100_000_000,
        "recipe": recipe("fixtures/real/models/panel-three-populations.json"),
    })
    .to_string();
    let clock = Instant::now();
    let (status, text) = request(addr, "POST", "/api/measure", body.as_bytes()).expect("an answer");
    eprintln!("answered {status} in {:?}", clock.elapsed());
    assert_eq!(status, 200, "{text}");
    let doc: Value = serde_json::from_str(&text).unwrap();
    let readings = doc["readings"].as_array().unwrap();
    let cut: Vec<&Value> = readings.iter().filter(|r| r.get("value").is_none_or(Value::is_null)).collect();
    assert!(cut.iter().any(|r| r["problem"].as_str().unwrap_or_default().contains("wall-clock limit")), "{text}");
    for r in &cut {
        let why = r["problem"].as_str().unwrap_or_default();
        assert!(why.contains("wall-clock limit") || why.contains("combines has no value"), "{r}");
    }
    assert!(clock.elapsed() < Duration::from_secs(120), "the limit bounds the request: {:?}", clock.elapsed());
    // A fit cut by the limit says so.
    let fit = json!({
        "free": ["/populations/2/roughness=0.01..0.1"],
        "target": ["astm-d523-60/gloss=40", "astm-d523-20/gloss=10"],
        "rtol": 1e-12,
        "recipe": recipe("fixtures/real/models/panel-three-populations.json"),
    })
    .to_string();
    let clock = Instant::now();
    let (status, text) = request(addr, "POST", "/api/fit", fit.as_bytes()).expect("an answer");
    eprintln!("the fit answered {status} in {:?}: {}", clock.elapsed(), &text[..text.len().min(400)]);
    assert!(clock.elapsed() < Duration::from_secs(120), "the limit bounds the fit: {:?}", clock.elapsed());
    if status != 200 {
        assert!(text.contains("time limit of 1 s"), "{status} {text}");
    }
}

/// One request with any headers (`Host` among them as given); the status and the body.
fn raw_request(addr: SocketAddr, path: &str, body: &[u8], headers: &[(&str, &str)]) -> (u16, String) {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(120))).unwrap();
    let mut head = format!("POST {path} HTTP/1.1\r\nConnection: close\r\nContent-Length: {}\r\n", body.len());
    for (k, v) in headers {
        head.push_str(&format!("{k}: {v}\r\n"));
    }
    s.write_all(format!("{head}\r\n").as_bytes()).unwrap();
    s.write_all(body).unwrap();
    let mut raw = Vec::new();
    let _ = s.read_to_end(&mut raw);
    let text = String::from_utf8_lossy(&raw).to_string();
    let status = text.split(' ').nth(1).unwrap().parse().unwrap();
    (status, text.split_once("\r\n\r\n").map(|(_, b)| b.to_string()).unwrap_or_default())
}

#[test]
fn a_host_or_origin_sent_twice_and_a_cross_site_fetch_in_any_case_are_refused() {
    let addr = start(Limits::default());
    let me = addr.to_string();
    let origin = format!("http://{addr}");
    let body = cheap_measure();
    assert_eq!(raw_request(addr, "/api/measure", &body, &[("Host", &me)]).0, 200);
    assert_eq!(raw_request(addr, "/api/measure", &body, &[("Host", &me), ("Origin", &origin)]).0, 200);
    for headers in [
        vec![("Host", me.as_str()), ("Host", "evil.example")],
        vec![("Host", me.as_str()), ("Host", me.as_str())],
        vec![("Host", me.as_str()), ("Origin", origin.as_str()), ("Origin", "http://evil.example")],
        vec![("Host", me.as_str()), ("Sec-Fetch-Site", "Cross-Site")],
        vec![("Host", me.as_str()), ("Sec-Fetch-Site", "CROSS-SITE")],
    ] {
        let (status, text) = raw_request(addr, "/api/measure", &body, &headers);
        assert_eq!(status, 403, "{headers:?}: {text}");
    }
}

fn scratch(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("glossmeter-serve-safety-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn no_answer_shows_the_data_directory_and_a_link_out_tells_nothing() {
    let root = scratch("paths");
    let data = root.join("data");
    std::fs::create_dir_all(data.join("tables")).unwrap();
    std::fs::copy("fixtures/materials/inplane/beckmann.csv", data.join("tables/good.csv")).unwrap();
    std::fs::write(data.join("tables/bad.csv"), "theta_o,theta_i,brdf\n0,0,oops\n").unwrap();
    std::fs::create_dir_all(root.join("outside")).unwrap();
    std::fs::write(root.join("outside/there.csv"), "x").unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(root.join("outside"), data.join("dirlink")).unwrap();
    let server = Server::bind(ServeOptions { port: 0, data_dir: Some(data.clone()), ..ServeOptions::default() });
    let server = server.unwrap();
    let addr = server.addr();
    std::thread::spawn(move || server.run());
    let canonical = data.canonicalize().unwrap().display().to_string();
    let given = data.display().to_string();
    let body = |file: &str| {
        json!({"recipe": {"model": "inplane-csv", "file": file}, "geometries": ["astm-d523-60"]}).to_string()
    };
    let mut answers = Vec::new();
    for file in ["tables/good.csv", "tables/bad.csv", "tables/missing.csv", "dirlink/there.csv", "dirlink/not.csv"] {
        for path in ["/api/measure", "/api/explain"] {
            let (status, text) = request(addr, "POST", path, body(file).as_bytes()).unwrap();
            assert!(!text.contains(&canonical) && !text.contains(&given), "{file} {path}: {text}");
            answers.push((file, path, status, text));
        }
    }
    let find = |f: &str| answers.iter().find(|a| a.0 == f && a.1 == "/api/measure").unwrap();
    assert_eq!(find("tables/good.csv").2, 200, "{}", find("tables/good.csv").3);
    let bad = find("tables/bad.csv");
    assert_eq!(bad.2, 400);
    assert!(bad.3.contains("tables/bad.csv"), "the table is named as the recipe named it: {}", bad.3);
    if cfg!(unix) {
        let (there, not) = (find("dirlink/there.csv"), find("dirlink/not.csv"));
        assert_eq!((there.2, not.2), (400, 400));
        assert_eq!(there.3.replace("there.csv", "not.csv"), not.3, "a link out tells nothing of what is there");
    }
    std::fs::remove_dir_all(&root).unwrap();
}

#[test]
fn refusals_name_their_field_and_print_no_long_numbers() {
    let addr = start(Limits::default());
    let (status, text) = request(
        addr,
        "POST",
        "/api/measure",
        json!({"recipe": {"model": "lambert", "albedo": 0.5}, "rtol": 1e-13}).to_string().as_bytes(),
    )
    .unwrap();
    assert_eq!(status, 400);
    assert!(text.contains("request: field `/rtol`") && text.contains("1e-13"), "{text}");
    // A start of 1e-300 outside the bounds is printed as 1e-300, not with 300 zeros.
    let recipe = json!({"model": "microfacet", "distribution": "ggx", "ior": 1.5,
        "populations": [{"roughness": 0.01}, {"weight": 1e-300, "roughness": 0.1}]});
    let fit =
        json!({"recipe": recipe, "free": ["/populations/1/weight=0.1..0.9"], "target": ["astm-d523-60/gloss=50"]});
    let (status, text) = request(addr, "POST", "/api/fit", fit.to_string().as_bytes()).unwrap();
    assert_eq!(status, 400, "{text}");
    assert!(text.contains("1e-300") && !text.contains("00000000"), "{text}");
}
