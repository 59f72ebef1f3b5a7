//! The server's connections (docs/serve.md §Connections): its own accept loop and HTTP/1.1 connections
//! (hyper, as axum's own server would run them), so that
//!
//! * every accept error is survived and logged: a connection error (reset before it was accepted) skips
//!   that connection; a resource error (out of file descriptors, `EMFILE`/`ENFILE`, or memory) closes the connection
//!   idle longest and waits 50 ms before the next accept. Repeats of one kind of error are logged at most
//!   once a second, with their count;
//! * the open connections are capped below the process's open-file limit ([`connection_cap`], said in the
//!   start-up line): at the cap, the connection idle longest (no request being answered on it) is closed to
//!   make room for the new one, and when every connection is answering a request the new one gets a 503 and
//!   is closed;
//! * a client has `Limits::header_seconds` to send a request's headers, counted from the connection's
//!   opening or the previous answer (so an idle keep-alive connection is closed after as long).
//!
//! A request is "being answered" from its headers to the last byte of its answer (a streamed sweep's too).
use std::collections::HashMap;
use std::convert::Infallible;
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::task::{Context, Poll};
use std::time::{Duration, Instant};

use axum::body::{Body, Bytes};
use axum::Router;
use hyper_util::rt::{TokioIo, TokioTimer};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::Notify;

use super::security::{Limits, FDS_PER_JOB, RESERVED_FDS};
use crate::{Error, Result};

/// The process's soft open-file limit (`ulimit -n`; None: unlimited or unknown).
pub(crate) fn open_file_limit() -> Option<u64> {
    #[cfg(unix)]
    return rustix::process::getrlimit(rustix::process::Resource::Nofile).current;
    #[cfg(not(unix))]
    None
}

/// The most connections the server keeps open: `wanted` (`--max-connections`), and at most the open-file
/// limit less [`RESERVED_FDS`] + [`FDS_PER_JOB`]·`jobs`. An error when that leaves room for fewer than 8.
pub(crate) fn connection_cap(wanted: usize, fd_limit: Option<u64>, jobs: usize) -> Result<usize> {
    if wanted == 0 {
        return Err(Error::argument("max_connections", " must be at least 1"));
    }
    let Some(limit) = fd_limit else { return Ok(wanted) };
    let reserved = RESERVED_FDS.saturating_add(FDS_PER_JOB.saturating_mul(jobs as u64));
    let room = limit.saturating_sub(reserved);
    if room < 8 {
        return Err(Error::Usage(format!(
            "the open-file limit (ulimit -n) is {limit}: the server needs at least {} (8 connections and \
             {reserved} descriptors for itself and {jobs} computation(s)); raise it with `ulimit -n`",
            reserved + 8
        )));
    }
    Ok(wanted.min(usize::try_from(room).unwrap_or(usize::MAX)))
}

/// One open connection, as the accept loop sees it.
struct Conn {
    id: u64,
    /// Requests being answered on it (from their headers to the end of their answer).
    answering: AtomicUsize,
    /// Milliseconds from the table's start to when it last became idle (opened, or an answer ended).
    idle_since: AtomicU64,
    /// Set when it was chosen to be closed; the task closes it at `close`.
    closing: AtomicBool,
    close: Notify,
}

/// The open connections.
struct Table {
    start: Instant,
    conns: Mutex<HashMap<u64, Arc<Conn>>>,
    next: AtomicU64,
}

impl Table {
    fn now_ms(&self) -> u64 {
        self.start.elapsed().as_millis() as u64
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<u64, Arc<Conn>>> {
        self.conns.lock().unwrap_or_else(PoisonError::into_inner)
    }

    fn len(&self) -> usize {
        self.lock().len()
    }

    /// Connections open and not being closed.
    fn live(&self) -> usize {
        self.lock().values().filter(|c| !c.closing.load(Ordering::Relaxed)).count()
    }

    fn open(&self) -> Arc<Conn> {
        let c = Arc::new(Conn {
            id: self.next.fetch_add(1, Ordering::Relaxed),
            answering: AtomicUsize::new(0),
            idle_since: AtomicU64::new(self.now_ms()),
            closing: AtomicBool::new(false),
            close: Notify::new(),
        });
        self.lock().insert(c.id, c.clone());
        c
    }

    fn remove(&self, id: u64) {
        self.lock().remove(&id);
    }

    /// Close the connection idle longest (none answering a request); false if there is none.
    fn close_idlest(&self) -> bool {
        let conns = self.lock();
        let idlest = conns
            .values()
            .filter(|c| !c.closing.load(Ordering::Relaxed) && c.answering.load(Ordering::Relaxed) == 0)
            .min_by_key(|c| (c.idle_since.load(Ordering::Relaxed), c.id));
        match idlest {
            Some(c) => {
                c.closing.store(true, Ordering::Relaxed);
                c.close.notify_one();
                true
            }
            None => false,
        }
    }
}

/// Marks a connection as answering a request while it lives (moved into the answer's body, so that it
/// lives until the last byte is sent or the answer is dropped).
struct Answering {
    conn: Arc<Conn>,
    table: Arc<Table>,
}

impl Answering {
    fn new(conn: Arc<Conn>, table: Arc<Table>) -> Answering {
        conn.answering.fetch_add(1, Ordering::Relaxed);
        Answering { conn, table }
    }
}

impl Drop for Answering {
    fn drop(&mut self) {
        self.conn.idle_since.store(self.table.now_ms(), Ordering::Relaxed);
        self.conn.answering.fetch_sub(1, Ordering::Relaxed);
    }
}

/// An answer's body, holding its connection's [`Answering`] mark.
struct MarkedBody {
    body: Body,
    _mark: Answering,
}

impl http_body::Body for MarkedBody {
    type Data = Bytes;
    type Error = axum::Error;

    fn poll_frame(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<std::result::Result<http_body::Frame<Bytes>, axum::Error>>> {
        Pin::new(&mut self.body).poll_frame(cx)
    }

    fn is_end_stream(&self) -> bool {
        self.body.is_end_stream()
    }

    fn size_hint(&self) -> http_body::SizeHint {
        self.body.size_hint()
    }
}

/// Logs accept errors to standard error: one line per kind of error at most once a second, with the count of
/// those of the kind not logged since its last line.
#[derive(Default)]
struct ErrorLog {
    kinds: HashMap<std::io::ErrorKind, (Instant, u64)>,
}

impl ErrorLog {
    fn log(&mut self, e: &std::io::Error, what: &str) {
        if let Some(line) = self.line(e, what, Instant::now()) {
            eprintln!("{line}");
        }
    }

    /// The line to log for an error at `now`, if one is due.
    fn line(&mut self, e: &std::io::Error, what: &str, now: Instant) -> Option<String> {
        let quiet = match self.kinds.get_mut(&e.kind()) {
            Some((at, quiet)) if now.duration_since(*at) < Duration::from_secs(1) => {
                *quiet += 1;
                return None;
            }
            Some((_, quiet)) => *quiet,
            None => 0,
        };
        self.kinds.insert(e.kind(), (now, 0));
        let more = match quiet {
            0 => String::new(),
            n => format!(" ({n} more since the last line)"),
        };
        Some(format!("glossmeter serve: accept failed: {e}{more}; {what}"))
    }
}

/// Whether an accept error is about that one connection (gone before it was accepted), not the server.
fn is_connection_error(e: &std::io::Error) -> bool {
    use std::io::ErrorKind::*;
    matches!(e.kind(), ConnectionRefused | ConnectionAborted | ConnectionReset | Interrupted | WouldBlock)
}

/// The answer to a connection beyond the cap when every open one is answering a request.
fn full_answer() -> Vec<u8> {
    let body = "{\"error\": \"the server has as many connections open as it takes, every one answering a request; \
                try again shortly\", \"status\": 503}\n";
    format!(
        "HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/json\r\nRetry-After: 1\r\nConnection: close\r\n\
         Content-Length: {}\r\n\r\n{body}",
        body.len()
    )
    .into_bytes()
}

/// Accept and serve connections until the process ends: no accept error ends it.
pub async fn serve(listener: TcpListener, app: Router, limits: &Limits, cap: usize) {
    let table = Arc::new(Table { start: Instant::now(), conns: Mutex::new(HashMap::new()), next: AtomicU64::new(0) });
    let header_timeout = Duration::try_from_secs_f64(limits.header_seconds).unwrap_or(Duration::from_secs(10));
    let mut log = ErrorLog::default();
    loop {
        // Connections chosen to be closed close at once; wait for them rather than run over the reserve.
        while table.len() >= cap + 16 {
            tokio::time::sleep(Duration::from_millis(1)).await;
        }
        let stream = match listener.accept().await {
            Ok((stream, _)) => stream,
            Err(e) if is_connection_error(&e) => {
                log.log(&e, "that connection is skipped");
                continue;
            }
            Err(e) => {
                let freed = table.close_idlest();
                log.log(&e, if freed { "closed the idlest connection; retrying" } else { "retrying in 50 ms" });
                tokio::time::sleep(Duration::from_millis(50)).await;
                continue;
            }
        };
        if table.live() >= cap && !table.close_idlest() {
            refuse(stream);
            continue;
        }
        let conn = table.open();
        tokio::spawn(connection(stream, app.clone(), conn, table.clone(), header_timeout));
    }
}

/// Answer 503 to a connection the server has no room for, without waiting, and close it.
fn refuse(stream: TcpStream) {
    let _ = stream.try_write(&full_answer());
    drop(stream);
}

/// Serve one connection until the client closes it, its header timeout passes, or it is chosen to be
/// closed to make room.
async fn connection(stream: TcpStream, app: Router, conn: Arc<Conn>, table: Arc<Table>, header_timeout: Duration) {
    let _ = stream.set_nodelay(true);
    let (mark_conn, mark_table) = (conn.clone(), table.clone());
    let service = hyper::service::service_fn(move |req: hyper::Request<hyper::body::Incoming>| {
        let mark = Answering::new(mark_conn.clone(), mark_table.clone());
        let mut app = app.clone();
        async move {
            let answer = tower_service::Service::call(&mut app, req.map(Body::new)).await?;
            Ok::<_, Infallible>(answer.map(|body| Body::new(MarkedBody { body, _mark: mark })))
        }
    });
    let mut http = hyper::server::conn::http1::Builder::new();
    http.timer(TokioTimer::new()).header_read_timeout(header_timeout);
    let served = http.serve_connection(TokioIo::new(stream), service);
    tokio::pin!(served);
    tokio::select! {
        _ = served.as_mut() => {}
        _ = conn.close.notified() => {}
    }
    table.remove(conn.id);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cap_stays_below_the_open_file_limit() {
        assert_eq!(connection_cap(1024, None, 2).unwrap(), 1024);
        assert_eq!(connection_cap(1024, Some(256), 2).unwrap(), 256 - 32 - 2 * 4);
        assert_eq!(connection_cap(1024, Some(64), 2).unwrap(), 64 - 32 - 2 * 4);
        assert_eq!(connection_cap(100, Some(20_000), 2).unwrap(), 100);
        let reserved = RESERVED_FDS + FDS_PER_JOB;
        assert!(connection_cap(1024, Some(reserved + 7), 1).unwrap_err().to_string().contains("ulimit -n"));
        assert_eq!(connection_cap(1024, Some(reserved + 8), 1).unwrap(), 8);
        assert!(connection_cap(0, Some(20_000), 2).is_err());
        let full = full_answer();
        let head = full.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
        let body: serde_json::Value = serde_json::from_slice(&full[head + 4..]).unwrap();
        assert_eq!(body["status"], 503);
        let length = format!("Content-Length: {}\r\n", full.len() - head - 4);
        assert!(String::from_utf8_lossy(&full[..head + 2]).contains(&length));
    }

    #[test]
    fn accept_errors_are_logged_once_a_second_per_kind_with_the_count_between() {
        let mut log = ErrorLog::default();
        let t = Instant::now();
        let emfile = std::io::Error::from_raw_os_error(24);
        let first = log.line(&emfile, "retrying", t).unwrap();
        assert!(first.contains("accept failed") && first.contains("retrying"), "{first}");
        for k in 1..=5 {
            assert!(log.line(&emfile, "retrying", t + Duration::from_millis(100 * k)).is_none());
        }
        let other = std::io::Error::new(std::io::ErrorKind::OutOfMemory, "no memory");
        assert!(log.line(&other, "retrying", t + Duration::from_millis(600)).is_some(), "another kind at once");
        assert!(log.line(&emfile, "retrying", t + Duration::from_millis(700)).is_none());
        let again = log.line(&emfile, "retrying", t + Duration::from_millis(1000)).unwrap();
        assert!(again.contains("(6 more since the last line)"), "{again}");
    }

    #[test]
    fn the_idlest_connection_not_answering_is_closed_first() {
        let t = Table { start: Instant::now(), conns: Mutex::new(HashMap::new()), next: AtomicU64::new(0) };
        let t = Arc::new(t);
        let a = t.open();
        let b = t.open();
        let c = t.open();
        a.idle_since.store(5, Ordering::Relaxed);
        b.idle_since.store(1, Ordering::Relaxed);
        c.idle_since.store(0, Ordering::Relaxed);
        let busy = Answering::new(c.clone(), t.clone());
        assert!(t.close_idlest());
        assert!(b.closing.load(Ordering::Relaxed) && !c.closing.load(Ordering::Relaxed));
        assert!(t.close_idlest());
        assert!(a.closing.load(Ordering::Relaxed));
        assert!(!t.close_idlest(), "the one answering a request is never closed to make room");
        assert_eq!(t.live(), 1);
        drop(busy);
        assert!(t.close_idlest());
    }
}
