//! `glossmeter serve` (docs/serve.md): the virtual meter as a local web page and an HTTP API over the library,
//! one process, the page embedded. The server is a thin layer: routing, the request's body, the guards and
//! the concurrency cap here; the work of each endpoint in [`api`] (synchronous, run on tokio's blocking pool
//! under a semaphore); the guards and limits in [`security`]; the embedded page and recipes in [`assets`].
//!
//! Safe to leave running (docs/serve.md §Safety): it binds to loopback unless told otherwise (and warns
//! then), answers only to its own names in `Host` and to its own `Origin` (DNS rebinding, cross-site
//! requests), reads a body of at most `Limits::body_bytes` within `Limits::body_seconds`, bounds every
//! request's work in evaluations and in wall-clock time (`Limits::request_seconds`) and stops it when its
//! client leaves ([`Cancel`]), runs at most `Limits::jobs` computations at once and answers the excess 503 at
//! once, keeps its connections below the open-file limit and survives every accept error ([`connections`]),
//! reads table files only inside `--data-dir` and never shows that directory's path, and writes nothing to
//! disk. Errors are the library's messages as JSON with status 400 (403 for a refused Host or Origin, 408
//! for a body too slow, 413 for a body too large, 503 when busy).
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::sync::Arc;

use axum::body::Body;
use axum::extract::{Request, State};
use axum::http::{header, HeaderValue, StatusCode};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::Router;
use tokio::sync::Semaphore;

use crate::instrument::plan::Cancel;
use crate::request::ServeRequest;
use crate::{Error, Result};

pub(crate) mod api;
pub(crate) mod assets;
pub(crate) mod connections;
pub(crate) mod security;

use api::{Context, Reply};
pub(crate) use security::Guard;
pub use security::Limits;

/// How to start a server.
#[derive(Clone, Debug)]
pub struct ServeOptions {
    /// The address to listen on: an IP address or `localhost`.
    pub host: String,
    /// The port (0: any free one; [`Server::addr`] says which).
    pub port: u16,
    /// Where recipes may name table files (None: no table file is read).
    pub data_dir: Option<PathBuf>,
    /// Further names the server answers to in `Host` (the machine's name when it listens beyond loopback).
    pub allow_hosts: Vec<String>,
    pub limits: Limits,
}

impl Default for ServeOptions {
    fn default() -> Self {
        ServeOptions {
            host: "127.0.0.1".into(),
            port: 8080,
            data_dir: None,
            allow_hosts: vec![],
            limits: Limits::default(),
        }
    }
}

struct Shared {
    limits: Limits,
    data_dir: Option<PathBuf>,
    permits: Arc<Semaphore>,
}

impl Shared {
    fn context<'a>(&'a self, cancel: &'a Cancel) -> Context<'a> {
        Context { limits: &self.limits, data_dir: self.data_dir.as_deref(), cancel }
    }

    /// A message or an answer without the data directory's absolute path: a table's path reads relative to
    /// the directory, as the recipe named it (docs/serve.md §Safety). The path is taken out as written and as
    /// JSON writes it in a string.
    fn scrub(&self, text: String) -> String {
        let Some(dir) = &self.data_dir else { return text };
        let plain = dir.display().to_string();
        let json = serde_json::to_string(&plain).unwrap_or_default();
        let json = json.trim_matches('"').to_string();
        let mut out = text;
        for d in [plain, json] {
            if d.is_empty() || !out.contains(&d) {
                continue;
            }
            for sep in ["/", "\\\\", "\\"] {
                out = out.replace(&format!("{d}{sep}"), "");
            }
            out = out.replace(&d, "(the data directory)");
        }
        out
    }

    /// A library error as a 400 answer, scrubbed.
    fn refusal(&self, e: &Error) -> Response {
        message(StatusCode::BAD_REQUEST, &self.scrub(named(e)))
    }
}

/// A server bound to its address, not yet serving.
pub struct Server {
    listener: std::net::TcpListener,
    addr: SocketAddr,
    shared: Arc<Shared>,
    guard: Arc<Guard>,
    /// The process's open-file limit when bound, and the connections kept open at most.
    fd_limit: Option<u64>,
    connections: usize,
}

impl Server {
    /// Check the options and bind the address (an address in use, or a data directory that is not one, is
    /// an error before anything is served).
    pub fn bind(o: ServeOptions) -> Result<Server> {
        let data_dir = match &o.data_dir {
            None => None,
            Some(d) => Some(
                d.canonicalize()
                    .ok()
                    .filter(|c| c.is_dir())
                    .ok_or_else(|| Error::argument("data_dir", format!(" {}: not a directory", d.display())))?,
            ),
        };
        if o.limits.jobs == 0 {
            return Err(Error::argument("jobs", " must be at least 1"));
        }
        let ip: IpAddr = if o.host.eq_ignore_ascii_case("localhost") {
            IpAddr::V4(Ipv4Addr::LOCALHOST)
        } else {
            o.host
                .trim_start_matches('[')
                .trim_end_matches(']')
                .parse()
                .map_err(|_| Error::argument("host", format!(" {}: not an IP address (or `localhost`)", o.host)))?
        };
        let listener = std::net::TcpListener::bind((ip, o.port))
            .map_err(|e| Error::Usage(format!("cannot listen on {}: {e}", SocketAddr::new(ip, o.port))))?;
        listener.set_nonblocking(true).map_err(|e| Error::Usage(format!("cannot listen: {e}")))?;
        let addr = listener.local_addr().map_err(|e| Error::Usage(format!("cannot listen: {e}")))?;
        let fd_limit = connections::open_file_limit();
        let connections = connections::connection_cap(o.limits.connections, fd_limit, o.limits.jobs)?;
        let permits = Arc::new(Semaphore::new(o.limits.jobs));
        let guard = Arc::new(Guard::new(addr, &o.allow_hosts));
        let shared = Arc::new(Shared { limits: o.limits, data_dir, permits });
        Ok(Server { listener, addr, shared, guard, fd_limit, connections })
    }

    /// The connections the server keeps open at most ([`connections::connection_cap`]) and the open-file
    /// limit it stays below (None: none).
    pub(crate) fn connections(&self) -> (usize, Option<u64>) {
        (self.connections, self.fd_limit)
    }

    /// The bound address.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The page's address, under a name the server answers to.
    pub(crate) fn url(&self) -> String {
        let port = self.addr.port();
        match self.addr {
            a if a.ip().is_unspecified() || a.ip().is_loopback() && a.is_ipv4() => format!("http://127.0.0.1:{port}/"),
            SocketAddr::V6(a) => format!("http://[{}]:{port}/", a.ip()),
            SocketAddr::V4(a) => format!("http://{}:{port}/", a.ip()),
        }
    }

    /// Serve until the process is stopped.
    pub fn run(self) -> Result<()> {
        let io = |e: std::io::Error| Error::Usage(format!("the server stopped: {e}"));
        // Timers as well as I/O: the header, body and request timeouts, and the pause after an accept error.
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .max_blocking_threads(self.shared.limits.jobs + 2)
            .enable_all()
            .build()
            .map_err(io)?;
        let limits = self.shared.limits.clone();
        let app = router(self.shared, self.guard);
        runtime.block_on(async move {
            let listener = tokio::net::TcpListener::from_std(self.listener).map_err(io)?;
            connections::serve(listener, app, &limits, self.connections).await;
            Ok(())
        })
    }
}

/// `glossmeter serve`: bind, print the address (and a warning beyond loopback), serve until stopped.
pub fn run_command(a: &ServeRequest) -> Result<()> {
    let d = Limits::default();
    let limits = Limits {
        jobs: a.jobs,
        request_seconds: a.request_seconds.unwrap_or(d.request_seconds),
        connections: a.max_connections.unwrap_or(d.connections),
        ..d
    };
    if !(limits.request_seconds.is_finite() && limits.request_seconds > 0.0) {
        return Err(Error::argument(
            "request_seconds",
            format!(" must be a positive number of seconds, got {}", crate::error::given(limits.request_seconds)),
        ));
    }
    let server = Server::bind(ServeOptions {
        host: a.host.clone(),
        port: a.port,
        data_dir: a.data_dir.clone(),
        allow_hosts: a.allow_hosts.clone(),
        limits,
    })?;
    if !server.addr().ip().is_loopback() {
        eprintln!(
            "warning: listening on {}, which other machines can reach: the server has no authentication, and \
             anyone who reaches it can run computations (within its limits) and read the tables in --data-dir",
            server.addr()
        );
    }
    let (connections, fd_limit) = server.connections();
    let fd = fd_limit.map_or("no open-file limit".to_string(), |n| format!("open-file limit {n}"));
    println!(
        "glossmeter serve: {} (stop with Ctrl-C; at most {connections} connections, {fd}; {} s per computation)",
        server.url(),
        server.shared.limits.request_seconds
    );
    use std::io::Write;
    let _ = std::io::stdout().flush();
    server.run()
}

fn router(shared: Arc<Shared>, guard: Arc<Guard>) -> Router {
    Router::new()
        .route("/", get(|| async { asset(assets::INDEX_HTML, "text/html; charset=utf-8") }))
        .route("/app.js", get(|| async { asset(assets::APP_JS, "text/javascript; charset=utf-8") }))
        .route("/app.css", get(|| async { asset(assets::APP_CSS, "text/css; charset=utf-8") }))
        .route("/api/registry", get(|| async { reply(api::registry_doc()) }))
        .route(
            "/api/geometries",
            get(|| async { api::geometries_doc().map_or_else(|e| error(StatusCode::BAD_REQUEST, &e), reply) }),
        )
        .route("/api/fixtures", get(|| async { fixtures() }))
        .route(
            "/api/tables",
            get(|State(s): State<Arc<Shared>>| async move { reply(api::tables_doc(s.data_dir.as_deref())) }),
        )
        .route("/api/measure", post(|State(s): State<Arc<Shared>>, r: Request| work(s, r, api::measure)))
        .route("/api/explain", post(|State(s): State<Arc<Shared>>, r: Request| work(s, r, api::explain)))
        .route("/api/plot", post(|State(s): State<Arc<Shared>>, r: Request| work(s, r, api::plot)))
        .route("/api/compare", post(|State(s): State<Arc<Shared>>, r: Request| work(s, r, api::compare)))
        .route("/api/fit", post(|State(s): State<Arc<Shared>>, r: Request| work(s, r, api::fit)))
        .route("/api/sweep", post(sweep))
        .fallback(|| async {
            message(StatusCode::NOT_FOUND, "no such page or endpoint (the API is under /api/, docs/serve.md)")
        })
        .with_state(shared)
        .layer(middleware::from_fn_with_state(guard, check_request))
}

/// Refuse a request whose `Host` or `Origin` is not this server's (403).
async fn check_request(State(guard): State<Arc<Guard>>, req: Request, next: Next) -> Response {
    match guard.check_headers(req.headers()) {
        Ok(()) => next.run(req).await,
        Err(why) => message(StatusCode::FORBIDDEN, &why),
    }
}

fn secure(mut r: Response) -> Response {
    let h = r.headers_mut();
    h.insert(header::X_CONTENT_TYPE_OPTIONS, HeaderValue::from_static("nosniff"));
    h.insert(header::X_FRAME_OPTIONS, HeaderValue::from_static("DENY"));
    h.insert(header::REFERRER_POLICY, HeaderValue::from_static("no-referrer"));
    h.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    h.insert(
        header::CONTENT_SECURITY_POLICY,
        HeaderValue::from_static(
            "default-src 'self'; img-src 'self' blob: data:; object-src 'none'; frame-ancestors 'none'",
        ),
    );
    r
}

fn asset(body: &'static str, content_type: &'static str) -> Response {
    secure(([(header::CONTENT_TYPE, content_type)], body).into_response())
}

fn reply(r: Reply) -> Response {
    secure(([(header::CONTENT_TYPE, r.content_type)], r.body).into_response())
}

/// A refusal or an error as JSON: `{"error": message, "status": code}`.
fn message(status: StatusCode, text: &str) -> Response {
    let body = crate::report::pretty(&serde_json::json!({"error": text, "status": status.as_u16()}));
    secure((status, [(header::CONTENT_TYPE, "application/json")], body).into_response())
}

/// A library error: its message, the arguments named as the request's fields.
fn error(status: StatusCode, e: &Error) -> Response {
    message(status, &named(e))
}

/// A library error's message in the request's words: each argument as its field in backquotes (`` `rtol` ``),
/// and an argument given a value as the JSON member to send (`give "illuminant": "A"`).
fn named(e: &Error) -> String {
    e.naming_settings(&|a| format!("`{a}`"), &|a, v| format!("\"{a}\": \"{v}\""))
}

fn fixtures() -> Response {
    let list: Vec<serde_json::Value> =
        assets::FIXTURES.iter().map(|(name, text)| serde_json::json!({"name": name, "recipe": text})).collect();
    reply(Reply {
        content_type: "application/json",
        body: crate::report::pretty(&serde_json::json!({"fixtures": list})),
    })
}

/// The body, at most `limits.body_bytes` (else 413).
async fn body(s: &Shared, req: Request) -> std::result::Result<axum::body::Bytes, Response> {
    let limit = s.limits.body_bytes;
    let too_large = || {
        message(
            StatusCode::PAYLOAD_TOO_LARGE,
            &format!("the request body is larger than this server takes ({limit} bytes)"),
        )
    };
    let declared =
        req.headers().get(header::CONTENT_LENGTH).and_then(|v| v.to_str().ok()).and_then(|v| v.parse::<u64>().ok());
    if declared.is_some_and(|n| n > limit as u64) {
        return Err(too_large());
    }
    let wait = s.limits.body_seconds;
    let late = || message(StatusCode::REQUEST_TIMEOUT, &format!("the request body did not arrive within {wait} s"));
    let within = std::time::Duration::try_from_secs_f64(wait).unwrap_or(std::time::Duration::MAX);
    match tokio::time::timeout(within, axum::body::to_bytes(req.into_body(), limit)).await {
        Ok(read) => read.map_err(|_| too_large()),
        Err(_) => Err(late()),
    }
}

fn busy(s: &Shared) -> Response {
    let mut r = message(
        StatusCode::SERVICE_UNAVAILABLE,
        &format!("the server is busy: {} computation(s) are running, its limit; try again shortly", s.limits.jobs),
    );
    r.headers_mut().insert(header::RETRY_AFTER, HeaderValue::from_static("1"));
    r
}

/// A request's body (capped) and a permit to compute (or at once the 413 or 503 answer). The body is read
/// before the permit is taken, so that a slow upload holds no permit.
async fn admit(
    s: &Shared,
    req: Request,
) -> std::result::Result<(axum::body::Bytes, tokio::sync::OwnedSemaphorePermit), Response> {
    let bytes = body(s, req).await?;
    let permit = s.permits.clone().try_acquire_owned().map_err(|_| busy(s))?;
    Ok((bytes, permit))
}

type Endpoint = fn(&api::Request, Context) -> Result<Reply>;

/// Raises a request's [`Cancel`] when dropped: when the handler's future is dropped because the client went
/// away (hyper drops it on the connection's end), the computation stops at its next integral and gives its
/// permit back.
struct RaiseOnDrop(Cancel);

impl Drop for RaiseOnDrop {
    fn drop(&mut self) {
        self.0.raise();
    }
}

/// A request's stop signal: its computation's deadline, `limits.request_seconds` from now.
fn request_cancel(s: &Shared) -> Cancel {
    let now = std::time::Instant::now();
    Cancel::new(crate::instrument::method::deadline_after(now, s.limits.request_seconds))
}

/// An endpoint's failure after its time limit passed says so (the failure itself is the limit's doing).
fn late_error(s: &Shared, cancel: &Cancel, e: Error) -> Error {
    if cancel.is_late() {
        let limit = s.limits.request_seconds;
        Error::Usage(format!(
            "the request reached the server's time limit of {limit} s per computation (docs/serve.md §Limits) \
             before it could answer: {}",
            named(&e)
        ))
    } else {
        e
    }
}

/// Run an endpoint on the blocking pool, if a permit is free (else 503 at once). The computation stops
/// when its client goes away or its time limit passes ([`Cancel`]).
async fn work(s: Arc<Shared>, req: Request, f: Endpoint) -> Response {
    let (bytes, permit) = match admit(&s, req).await {
        Ok(a) => a,
        Err(r) => return r,
    };
    let shared = s.clone();
    let cancel = request_cancel(&s);
    let on_leave = RaiseOnDrop(cancel.clone());
    let out = tokio::task::spawn_blocking(move || {
        let _permit = permit;
        let req = api::Request::parse(&bytes)?;
        f(&req, shared.context(&cancel)).map_err(|e| late_error(&shared, &cancel, e))
    })
    .await;
    drop(on_leave);
    match out {
        Ok(Ok(r)) => reply(Reply { body: s.scrub(r.body), ..r }),
        Ok(Err(e)) => s.refusal(&e),
        Err(_) => message(
            StatusCode::INTERNAL_SERVER_ERROR,
            "the computation failed unexpectedly (a bug: please report the request)",
        ),
    }
}

/// `POST /api/sweep`: checked first (errors 400), then streamed as JSON lines while it runs (the total in
/// the `X-Points` header, so that a client can show progress). A failure after the first line ends the
/// stream with a line `{"error": …}`.
async fn sweep(State(s): State<Arc<Shared>>, req: Request) -> Response {
    let (bytes, permit) = match admit(&s, req).await {
        Ok(a) => a,
        Err(r) => return r,
    };
    let shared = s.clone();
    let cancel = request_cancel(&s);
    let (sweep_cancel, on_leave) = (cancel.clone(), cancel.clone());
    let checked = tokio::task::spawn_blocking(move || {
        let req = api::Request::parse(&bytes)?;
        api::sweep(&req, shared.context(&sweep_cancel))
    })
    .await;
    let sw = match checked {
        Ok(Ok(sw)) => sw,
        Ok(Err(e)) => return s.refusal(&e),
        Err(_) => return message(StatusCode::INTERNAL_SERVER_ERROR, "the sweep failed unexpectedly"),
    };
    let points = sw.len();
    let (tx, rx) = tokio::sync::mpsc::channel::<std::result::Result<String, std::io::Error>>(8);
    let shared = s.clone();
    tokio::task::spawn_blocking(move || {
        let _permit = permit;
        let gone = || Error::Usage("the client went away".into());
        let out = api::run_sweep(&sw, |line| {
            tx.blocking_send(Ok(shared.scrub(line))).map_err(|_| {
                cancel.raise();
                gone()
            })
        });
        if let Err(e) = out {
            let line = serde_json::json!({"error": shared.scrub(named(&e))}).to_string() + "\n";
            let _ = tx.blocking_send(Ok(line));
        }
    });
    let lines = RaisingStream { lines: tokio_stream::wrappers::ReceiverStream::new(rx), _raise: RaiseOnDrop(on_leave) };
    let mut r = Body::from_stream(lines).into_response();
    let h = r.headers_mut();
    h.insert(header::CONTENT_TYPE, HeaderValue::from_static("application/x-ndjson"));
    if let Ok(v) = HeaderValue::from_str(&points.to_string()) {
        h.insert("x-points", v);
    }
    secure(r)
}

/// A streamed answer's lines that raise the request's [`Cancel`] when the answer is dropped (the client went
/// away, or the stream ended), so that a sweep stops at its next integral, not after its current point.
struct RaisingStream<S> {
    lines: S,
    _raise: RaiseOnDrop,
}

impl<S: tokio_stream::Stream + Unpin> tokio_stream::Stream for RaisingStream<S> {
    type Item = S::Item;

    fn poll_next(
        mut self: std::pin::Pin<&mut Self>,
        cx: &mut std::task::Context<'_>,
    ) -> std::task::Poll<Option<S::Item>> {
        std::pin::Pin::new(&mut self.lines).poll_next(cx)
    }
}
