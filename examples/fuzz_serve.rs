//! The server's fuzz driver (docs/reliability.md §The server over loopback), run by hand; it starts the
//! `glossmeter` binary built beside it (the same profile), under `ulimit -n 256`:
//!
//! ```text
//! cargo build --release --bin glossmeter --example fuzz_serve
//! nice -n 19 target/release/examples/fuzz_serve CASES [SEED]
//! ```
//!
//! One server (`--data-dir` a scratch copy of the table fixtures, `--request-seconds 5`, `--jobs 2`) takes
//! CASES cases from one client process, round-robin over five kinds, each replayable from its number and SEED:
//!
//! * *requests*: a random method, path (the endpoints, unknown ones, long and encoded ones), headers (`Host`
//!   right, foreign, missing or twice; `Origin`, `Sec-Fetch-Site` in random case; `Content-Length` right,
//!   short, long, huge, negative or twice; `Transfer-Encoding: chunked` with good or broken framing; up to
//!   200 extra headers) and body (a valid request of each endpoint, mutated like the recipe fuzzing: spans
//!   deleted or duplicated, JSON punctuation, numbers replaced by edge values, truncation; random bytes;
//!   nesting 10⁴ deep);
//! * *slow clients*: a valid request sent in pieces over up to 3 s;
//! * *vanishing clients*: a heavy request (a 41-point picture at rtol 1e-12, a 14-geometry measure at 1e-12,
//!   a fit) whose client closes after 0–700 ms;
//! * *idle floods*: 300 idle connections (over the server's cap of 216) held while a normal request is made;
//! * *garbage*: random bytes, or an HTTP/1.1 head cut anywhere, then the connection closed or left open.
//!
//! Checks: every answer is a well-formed HTTP/1.1 response whose status is one of 200, 400, 403, 404, 405,
//! 408, 413, 431 and 503 (never 500: a panic inside an endpoint), within 90 s (else a hang); a JSON error
//! body has an `error`; no answer holds "panicked" or the data directory's absolute path; after a vanishing
//! client, a cheap request is served (200) within 30 s (its slot was freed); after an idle flood a normal
//! request is answered 200; the server is alive after every case. At the end: the server's standard error
//! holds no panic, and its peak resident memory (`VmHWM`) is stated. It prints a Markdown summary.
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// SplitMix64: small, seeded, and the same on every machine.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    fn chance(&mut self, p: f64) -> bool {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 <= p
    }
    fn pick<'a, T>(&mut self, xs: &'a [T]) -> &'a T {
        &xs[self.below(xs.len())]
    }
}

const STATUSES: [u16; 9] = [200, 400, 403, 404, 405, 408, 413, 431, 503];
/// Longer than the server's body timeout (60 s), after which a body shorter than its `Content-Length` gets 408.
const ANSWER_S: u64 = 90;
const KINDS: [&str; 5] = ["requests", "slow clients", "vanishing clients", "idle floods", "garbage"];

const ALL: &str = r#"["astm-d2457-45","astm-d523-20","astm-d523-60","astm-d523-85","astm-e430-20","astm-e430-30","iso-13803-20","iso-2813-20","iso-2813-60","iso-2813-85","rhopoint-iq-20","rspec-20","tappi-t480-75","astm-d4039"]"#;

/// Valid bodies of every endpoint (the seeds the mutations start from).
fn bodies(panel: &str) -> Vec<(&'static str, String)> {
    let lambert = r#"{"model": "lambert", "albedo": 0.5}"#;
    let glass = std::fs::read_to_string("fixtures/recipes/glass-n1.5.json").unwrap();
    vec![
        ("/api/measure", format!(r#"{{"recipe": {lambert}, "geometries": ["astm-d523-60"]}}"#)),
        ("/api/measure", format!(r#"{{"recipe": {glass}, "rtol": 1e-4}}"#)),
        (
            "/api/measure",
            r#"{"recipe": {"model": "inplane-csv", "file": "inplane/beckmann.csv"}, "geometries": ["astm-d523-60"]}"#
                .into(),
        ),
        (
            "/api/measure",
            r#"{"recipe": {"model": "merl", "file": "merl/lambert-tiny.binary"}, "geometries": ["astm-d523-60"]}"#
                .into(),
        ),
        ("/api/explain", format!(r#"{{"recipe": {glass}}}"#)),
        ("/api/plot", format!(r#"{{"recipe": {glass}, "kind": "section"}}"#)),
        (
            "/api/plot",
            format!(
                r#"{{"recipe": {glass}, "kind": "gloss-vs-parameter", "vary": "/ior=1.4..1.6", "points": 3, "rtol": 1e-3}}"#
            ),
        ),
        (
            "/api/sweep",
            format!(
                r#"{{"recipe": {glass}, "vary": ["/ior=1.4..1.6:3"], "rtol": 1e-3, "geometries": ["astm-d523-60"]}}"#
            ),
        ),
        ("/api/compare", format!(r#"{{"recipe": {glass}, "sheet": {{"text": "sample,60°\na,90\n"}}}}"#)),
        (
            "/api/fit",
            format!(
                r#"{{"recipe": {glass}, "free": ["/ior=1.3..1.8"], "target": ["astm-d523-60/gloss=90"], "rtol": 1e-4}}"#
            ),
        ),
        ("/api/measure", format!(r#"{{"recipe": {glass}, "geometries": {panel}}}"#)),
    ]
}

/// Heavy requests, for the clients that vanish.
fn heavy() -> Vec<(&'static str, String)> {
    let panel = std::fs::read_to_string("fixtures/real/models/panel-three-populations.json").unwrap();
    vec![
        (
            "/api/plot",
            format!(
                r#"{{"recipe": {panel}, "kind": "gloss-vs-parameter", "vary": "/populations/2/roughness=0.01..0.1", "points": 41, "geometries": {ALL}, "rtol": 1e-12}}"#
            ),
        ),
        ("/api/measure", format!(r#"{{"recipe": {panel}, "geometries": {ALL}, "rtol": 1e-12}}"#)),
        (
            "/api/fit",
            format!(
                r#"{{"recipe": {panel}, "free": ["/populations/2/roughness=0.01..0.1", "/ior=1.3..1.8"], "target": ["astm-d523-60/gloss=40", "astm-d523-20/gloss=10", "astm-d523-85/gloss=90"], "rtol": 1e-12}}"#
            ),
        ),
        (
            "/api/sweep",
            format!(r#"{{"recipe": {panel}, "vary": ["/ior=1.3..1.8:20"], "geometries": {ALL}, "rtol": 1e-12}}"#),
        ),
    ]
}

/// A text mutated by 1–4 edits, as the recipe fuzzing mutates.
fn mutate(text: &str, rng: &mut Rng) -> Vec<u8> {
    let mut b = text.as_bytes().to_vec();
    for _ in 0..1 + rng.below(4) {
        let n = b.len().max(1);
        let i = rng.below(n);
        match rng.below(7) {
            0 => {
                let j = (i + rng.below(20)).min(b.len());
                b.drain(i.min(b.len())..j);
            }
            1 => {
                let j = (i + rng.below(20)).min(b.len());
                let span = b[i.min(b.len())..j].to_vec();
                b.splice(i.min(b.len())..i.min(b.len()), span);
            }
            2 => {
                let p = *rng.pick(&[b"{".as_slice(), b"}", b"[", b"]", b",", b":", b"\"", b"null", b"\\u0000"]);
                b.splice(i.min(b.len())..i.min(b.len()), p.iter().copied());
            }
            3 => {
                let x = *rng.pick(&["1e400", "-1", "0", "1e-300", "NaN", "1e308", "99999999999999999999", "-0"]);
                b.splice(i.min(b.len())..i.min(b.len()), x.bytes());
            }
            4 => b.truncate(i),
            5 => {
                if i < b.len() {
                    b[i] = rng.next() as u8;
                }
            }
            _ => {
                let s = *rng.pick(&["\u{feff}", "é", "\u{202e}", "\r\n", "%2e%2e/", "../../etc/passwd"]);
                b.splice(i.min(b.len())..i.min(b.len()), s.bytes());
            }
        }
    }
    b
}

struct Server {
    child: Child,
    addr: SocketAddr,
    data: std::path::PathBuf,
}

fn start(bin: &std::path::Path, data: &std::path::Path) -> Server {
    let cmd = format!(
        "ulimit -n 256 && exec {} serve --port 0 --data-dir {} --request-seconds 5",
        bin.display(),
        data.display()
    );
    let mut child =
        Command::new("sh").args(["-c", &cmd]).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).unwrap();
    let port: u16 = line.split("127.0.0.1:").nth(1).unwrap().split('/').next().unwrap().parse().unwrap();
    Server { child, addr: format!("127.0.0.1:{port}").parse().unwrap(), data: data.canonicalize().unwrap() }
}

/// Send `head` and `body` (in pieces, with pauses, if `pause_ms`), read the answer until the server closes
/// or ANSWER_S pass. The answer's bytes, or why there is none.
fn exchange(addr: SocketAddr, head: &[u8], body: &[u8], pieces: usize, pause_ms: u64) -> Result<Vec<u8>, String> {
    let mut s = TcpStream::connect_timeout(&addr, Duration::from_secs(10)).map_err(|e| format!("connect: {e}"))?;
    s.set_read_timeout(Some(Duration::from_secs(ANSWER_S))).unwrap();
    let all = [head, body].concat();
    let step = all.len().div_ceil(pieces.max(1)).max(1);
    for chunk in all.chunks(step) {
        if s.write_all(chunk).is_err() {
            break; // answered (413, 400) and closed before the rest
        }
        if pause_ms > 0 {
            std::thread::sleep(Duration::from_millis(pause_ms));
        }
    }
    let clock = Instant::now();
    let mut raw = Vec::new();
    match s.read_to_end(&mut raw) {
        Ok(_) => Ok(raw),
        Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {
            Err(format!("a hang: no end of the answer after {:.0} s", clock.elapsed().as_secs_f64()))
        }
        Err(_) if !raw.is_empty() => Ok(raw),
        Err(e) => Err(format!("read: {e}")),
    }
}

/// The checks of one answer: well-formed, an allowed status, no panic, no data-directory path, and a JSON
/// error body with its message (but for the answer to a HEAD request, which has no body).
fn check(raw: &[u8], data: &str, head_request: bool) -> Result<u16, String> {
    let text = String::from_utf8_lossy(raw);
    if raw.is_empty() {
        return Ok(0); // closed without an answer (a cut head, a header timeout): allowed
    }
    let status: u16 = text
        .strip_prefix("HTTP/1.1 ")
        .and_then(|t| t.get(..3))
        .and_then(|c| c.parse().ok())
        .ok_or_else(|| format!("not an HTTP/1.1 answer: {:?}", &text[..text.len().min(120)]))?;
    if !STATUSES.contains(&status) {
        return Err(format!("status {status}: {}", &text[..text.len().min(600)]));
    }
    if text.contains("panicked") {
        return Err(format!("a panic in the answer: {}", &text[..text.len().min(600)]));
    }
    if text.contains(data) {
        return Err(format!("the data directory's path in the answer: {}", &text[..text.len().min(600)]));
    }
    if status != 200 && text.contains("application/json") && !head_request {
        let body = text.split_once("\r\n\r\n").map(|x| x.1).unwrap_or("");
        let v: serde_json::Value = serde_json::from_str(body)
            .map_err(|e| format!("a {status} whose JSON body does not parse ({e}): {body}"))?;
        if v.get("error").and_then(|e| e.as_str()).is_none() {
            return Err(format!("a {status} without an error message: {body}"));
        }
    }
    Ok(status)
}

fn head(method: &str, path: &str, headers: &[(String, String)]) -> Vec<u8> {
    let mut h = format!("{method} {path} HTTP/1.1\r\n");
    for (k, v) in headers {
        h.push_str(&format!("{k}: {v}\r\n"));
    }
    h.push_str("\r\n");
    h.into_bytes()
}

fn cheap_served(addr: SocketAddr, within: Duration) -> Result<Duration, String> {
    let body = br#"{"recipe": {"model": "lambert", "albedo": 0.5}, "geometries": ["astm-d523-60"]}"#;
    let h = head(
        "POST",
        "/api/measure",
        &[
            ("Host".into(), addr.to_string()),
            ("Content-Length".into(), body.len().to_string()),
            ("Connection".into(), "close".into()),
        ],
    );
    let clock = Instant::now();
    loop {
        let raw = exchange(addr, &h, body, 1, 0)?;
        if raw.starts_with(b"HTTP/1.1 200") {
            return Ok(clock.elapsed());
        }
        if clock.elapsed() > within {
            return Err(format!(
                "no 200 for a cheap request within {within:?}: {}",
                String::from_utf8_lossy(&raw[..raw.len().min(200)])
            ));
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// One case; Ok(what it saw) or the failure.
fn run(
    kind: usize,
    rng: &mut Rng,
    s: &Server,
    bodies: &[(&str, String)],
    heavy: &[(&str, String)],
) -> Result<String, String> {
    let addr = s.addr;
    let data = s.data.display().to_string();
    let me = addr.to_string();
    match kind {
        0 => {
            let method = *rng.pick(&["POST", "POST", "POST", "GET", "PUT", "DELETE", "OPTIONS", "HEAD", "BREW", ""]);
            let (path, seed) = rng.pick(bodies).clone();
            let path = match rng.below(10) {
                0 => rng.pick(&["/", "/app.js", "/api/registry", "/api/geometries", "/api/fixtures"]).to_string(),
                1 => rng.pick(&["/api/nope", "/api/measure/../../etc", "/%2e%2e/", "//api//measure", "*"]).to_string(),
                2 => format!("/api/{}", "a".repeat(rng.below(20_000))),
                _ => path.to_string(),
            };
            let body: Vec<u8> = match rng.below(8) {
                0 => (0..rng.below(4000)).map(|_| rng.next() as u8).collect(),
                1 => format!("{{\"recipe\": {}}}", "[".repeat(10_000)).into_bytes(),
                2 => seed.into_bytes(),
                _ => mutate(&seed, rng),
            };
            let mut hs: Vec<(String, String)> = Vec::new();
            match rng.below(10) {
                0 => {}
                1 => hs.push(("Host".into(), "evil.example".into())),
                2 => {
                    hs.push(("Host".into(), me.clone()));
                    hs.push(("Host".into(), rng.pick(&[me.as_str(), "evil.example"]).to_string()));
                }
                _ => hs.push(("Host".into(), me.clone())),
            }
            if rng.chance(0.2) {
                hs.push((
                    "Origin".into(),
                    rng.pick(&[format!("http://{me}"), "http://evil.example".into(), "null".into()]).clone(),
                ));
            }
            if rng.chance(0.2) {
                hs.push((
                    "Sec-Fetch-Site".into(),
                    rng.pick(&["cross-site", "Cross-Site", "same-origin", "none"]).to_string(),
                ));
            }
            let chunked = rng.chance(0.15);
            let mut payload = body.clone();
            if chunked {
                hs.push(("Transfer-Encoding".into(), "chunked".into()));
                payload = format!("{:x}\r\n", body.len()).into_bytes();
                payload.extend_from_slice(&body);
                payload.extend_from_slice(if rng.chance(0.8) { b"\r\n0\r\n\r\n" } else { b"\r\nzz\r\n" });
            }
            match rng.below(12) {
                0 => hs.push(("Content-Length".into(), (body.len() + 1 + rng.below(100)).to_string())),
                1 => hs.push((
                    "Content-Length".into(),
                    rng.pick(&["-1", "1e20", "99999999999999999999", "x"]).to_string(),
                )),
                2 => {
                    hs.push(("Content-Length".into(), body.len().to_string()));
                    hs.push(("Content-Length".into(), (body.len() + 1).to_string()));
                }
                3 => hs.push(("Content-Length".into(), (body.len() / 2).to_string())),
                _ if !chunked => hs.push(("Content-Length".into(), body.len().to_string())),
                _ => {}
            }
            for i in 0..(if rng.chance(0.1) { rng.below(200) } else { 0 }) {
                hs.push((format!("X-Fuzz-{i}"), "v".repeat(rng.below(100))));
            }
            hs.push(("Connection".into(), "close".into()));
            let raw = match exchange(addr, &head(method, &path, &hs), &payload, 1, 0) {
                Ok(raw) => raw,
                // The server may close before the client is done; a short answer is checked below.
                Err(e) if e.starts_with("read") => Vec::new(),
                Err(e) => return Err(e),
            };
            check(&raw, &data, method == "HEAD").map(|st| format!("status {st}"))
        }
        1 => {
            let (path, body) = rng.pick(bodies).clone();
            let hs = [
                ("Host".into(), me.clone()),
                ("Content-Length".into(), body.len().to_string()),
                ("Connection".into(), "close".into()),
            ];
            let pieces = 2 + rng.below(10);
            let pause = rng.below(3000 / pieces) as u64;
            let raw = exchange(addr, &head("POST", path, &hs), body.as_bytes(), pieces, pause)?;
            let st = check(&raw, &data, false)?;
            if st != 200 && st != 503 && st != 400 {
                return Err(format!("a slow valid request answered {st}"));
            }
            Ok(format!("status {st}"))
        }
        2 => {
            let (path, body) = rng.pick(heavy).clone();
            let mut c = TcpStream::connect(addr).map_err(|e| format!("connect: {e}"))?;
            let h =
                head("POST", path, &[("Host".into(), me.clone()), ("Content-Length".into(), body.len().to_string())]);
            c.write_all(&h).map_err(|e| e.to_string())?;
            c.write_all(body.as_bytes()).map_err(|e| e.to_string())?;
            std::thread::sleep(Duration::from_millis(rng.below(700) as u64));
            drop(c);
            let t = cheap_served(addr, Duration::from_secs(30))?;
            Ok(format!("slot free after {:.2} s", t.as_secs_f64()))
        }
        3 => {
            let n = 300;
            let idle: Vec<TcpStream> =
                (0..n).filter_map(|_| TcpStream::connect_timeout(&addr, Duration::from_secs(5)).ok()).collect();
            let t = cheap_served(addr, Duration::from_secs(30))?;
            drop(idle);
            Ok(format!("served in {:.3} s beside {n} idle connections", t.as_secs_f64()))
        }
        _ => {
            let (path, body) = rng.pick(bodies).clone();
            let full = [
                head("POST", path, &[("Host".into(), me.clone()), ("Content-Length".into(), body.len().to_string())]),
                body.into_bytes(),
            ]
            .concat();
            let bytes: Vec<u8> = if rng.chance(0.5) {
                (0..rng.below(2000)).map(|_| rng.next() as u8).collect()
            } else {
                full[..rng.below(full.len())].to_vec()
            };
            let mut c = TcpStream::connect(addr).map_err(|e| format!("connect: {e}"))?;
            let _ = c.write_all(&bytes);
            if rng.chance(0.5) {
                let _ = c.shutdown(std::net::Shutdown::Write);
                c.set_read_timeout(Some(Duration::from_secs(ANSWER_S))).unwrap();
                let mut raw = Vec::new();
                let _ = c.read_to_end(&mut raw);
                check(&raw, &data, false).map(|st| format!("status {st}"))
            } else {
                Ok("left".into())
            }
        }
    }
}

/// The server's peak resident memory, kB (Linux).
fn peak_kb(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let cases: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1000);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let exe = std::env::current_exe().unwrap();
    let bin = exe.parent().and_then(|d| d.parent()).unwrap().join("glossmeter");
    assert!(bin.exists(), "{} not built: cargo build --bin glossmeter (same profile) first", bin.display());
    let data = std::env::temp_dir().join(format!("glossmeter-fuzz-serve-{}", std::process::id()));
    for (from, to) in [
        ("fixtures/materials/inplane", "inplane"),
        ("fixtures/materials/merl", "merl"),
        ("fixtures/materials/rgl", "rgl"),
    ] {
        std::fs::create_dir_all(data.join(to)).unwrap();
        for f in std::fs::read_dir(from).unwrap() {
            let f = f.unwrap().path();
            if f.is_file() {
                std::fs::copy(&f, data.join(to).join(f.file_name().unwrap())).unwrap();
            }
        }
    }
    let mut server = start(&bin, &data);
    let pid = server.child.id();
    let bodies = bodies(ALL);
    let heavy = heavy();
    let mut tally: BTreeMap<&str, (usize, usize, f64, f64)> = BTreeMap::new();
    let mut statuses: BTreeMap<u16, usize> = BTreeMap::new();
    let mut failures: Vec<String> = Vec::new();
    let start_clock = Instant::now();
    for k in 0..cases {
        let kind = k % KINDS.len();
        let mut rng = Rng(seed.wrapping_mul(1_000_003).wrapping_add(k as u64));
        let t0 = Instant::now();
        let out = run(kind, &mut rng, &server, &bodies, &heavy);
        let dt = t0.elapsed().as_secs_f64();
        let t = tally.entry(KINDS[kind]).or_default();
        t.0 += 1;
        t.2 += dt;
        t.3 = t.3.max(dt);
        match out {
            Ok(what) => {
                if let Some(st) = what.strip_prefix("status ").and_then(|s| s.parse().ok()) {
                    *statuses.entry(st).or_default() += 1;
                }
            }
            Err(e) => {
                t.1 += 1;
                failures.push(format!("case {k} ({}): {e}", KINDS[kind]));
                eprintln!("FAILURE {}", failures.last().unwrap());
            }
        }
        if let Ok(Some(status)) = server.child.try_wait() {
            failures.push(format!("case {k} ({}): the server exited ({status})", KINDS[kind]));
            eprintln!("FAILURE {}", failures.last().unwrap());
            server = start(&bin, &data);
        }
        if (k + 1) % 100 == 0 {
            eprintln!("{} cases, {:.0} s, {} failures", k + 1, start_clock.elapsed().as_secs_f64(), failures.len());
        }
    }
    let peak = peak_kb(pid);
    let _ = server.child.kill();
    let _ = server.child.wait();
    let mut err = String::new();
    let _ = server.child.stderr.take().unwrap().read_to_string(&mut err);
    if err.contains("panicked") {
        failures.push(format!("the server's standard error holds a panic: {}", &err[..err.len().min(600)]));
    }
    let _ = std::fs::remove_dir_all(&data);
    println!(
        "Server fuzz run: {cases} cases, seed {seed}, one server under ulimit -n 256 (cap 216 connections), {:.0} s wall\n",
        start_clock.elapsed().as_secs_f64()
    );
    println!("| kind | cases | failures | seconds | slowest case (s) |\n|---|---|---|---|---|");
    for (kind, (n, f, secs, slowest)) in &tally {
        println!("| {kind} | {n} | {f} | {secs:.0} | {slowest:.2} |");
    }
    let shown: Vec<String> = statuses.iter().map(|(s, n)| format!("{s}: {n}")).collect();
    println!("\nAnswers by status (0: closed without an answer): {}", shown.join(", "));
    println!("Peak resident memory of the server (VmHWM): {} kB", peak.map_or("unknown".into(), |k| k.to_string()));
    let accept_lines = err.lines().filter(|l| l.contains("accept failed")).count();
    println!("Accept errors logged by the server: {accept_lines} lines");
    println!("\nFailures: {}", failures.len());
    for f in failures.iter().take(40) {
        println!("- {f}");
    }
    if !failures.is_empty() {
        std::process::exit(1);
    }
}
