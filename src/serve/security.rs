//! What makes the server safe to leave running (docs/serve.md §Safety): the limits of one request
//! ([`Limits`]), the check of `Host` and `Origin` against DNS rebinding and cross-site requests ([`Guard`]),
//! and the one way a recipe may name a table file: a relative path inside `--data-dir`, without `..`, that
//! does not lead out of it through a symbolic link ([`table_path`]).
use std::net::SocketAddr;
use std::path::{Component, Path, PathBuf};

use crate::instrument::plan::DEFAULT_MAX_EVALS;
use crate::{Error, Result};

/// The bounds of the work one request may ask for and of the server as a whole. Every request's work is
/// bounded in evaluations: each aperture integral by `max_evals`, the integrals of a request by the
/// geometries (`geometries`), the points of a sweep or a plot (`sweep_points`, `plot_points`) and the
/// forward runs of a fit (`fit_iterations`, `fit_restarts`, `fit_free`, `fit_targets`).
#[derive(Clone, Debug, PartialEq)]
pub struct Limits {
    /// Largest request body, bytes (a sheet arrives in the body, base64-encoded).
    pub body_bytes: usize,
    /// Requests computing at once; the excess is answered 503 at once.
    pub jobs: usize,
    /// Evaluation budget of each aperture integral (a request may ask for less, never more).
    pub max_evals: usize,
    /// Geometries of one request.
    pub geometries: usize,
    /// Points of one sweep.
    pub sweep_points: u64,
    /// Points of one gloss-vs-parameter picture.
    pub plot_points: usize,
    /// Solver runs of one fit (Jacobians excluded, as `FitOptions::max_iterations`).
    pub fit_iterations: usize,
    /// Restarts of one exactly determined fit.
    pub fit_restarts: usize,
    /// Free parameters and targets of one fit.
    pub fit_free: usize,
    pub fit_targets: usize,
    /// Seconds a client has to send a request's headers, counted from the connection's opening or from the
    /// previous answer on it (so also how long an idle keep-alive connection stays open); then it is closed.
    pub header_seconds: f64,
    /// Seconds a client has to send a request's body once its headers are in (else 408).
    pub body_seconds: f64,
    /// Wall-clock seconds of one computation (`--request-seconds`): the integrals running then stop, those
    /// not started are skipped, and the answer has the readings finished, the others without a value.
    pub request_seconds: f64,
    /// Open connections at most (`--max-connections`); the server also stays [`RESERVED_FDS`] +
    /// [`FDS_PER_JOB`]·`jobs` below the process's open-file limit (`ulimit -n`), whichever is lower.
    pub connections: usize,
}

/// File descriptors the server keeps free of connections: standard streams, the listener, the runtime's
/// poller and room for connections being closed; and [`FDS_PER_JOB`] more for each computation (the table
/// files it reads).
pub(crate) const RESERVED_FDS: u64 = 32;
pub(crate) const FDS_PER_JOB: u64 = 4;

impl Default for Limits {
    fn default() -> Self {
        Limits {
            body_bytes: 8 << 20,
            jobs: 2,
            max_evals: DEFAULT_MAX_EVALS,
            geometries: 16,
            sweep_points: 400,
            plot_points: 41,
            fit_iterations: 200,
            fit_restarts: 4,
            fit_free: 6,
            fit_targets: 32,
            header_seconds: 10.0,
            body_seconds: 60.0,
            request_seconds: 60.0,
            connections: 1024,
        }
    }
}

/// The `Host` values the server answers to and the `Origin`s it accepts: the loopback names (`localhost`,
/// `127.0.0.1`, `[::1]`) and the names given with `--allow-host` (and the bound address when it is not a
/// wildcard), each with the bound port. A browser on a page of another site sends that site's `Origin`; a
/// DNS-rebinding page reaches the server under its own name in `Host`: both are refused (403).
#[derive(Clone, Debug)]
pub(crate) struct Guard {
    hosts: Vec<String>,
}

impl Guard {
    pub(crate) fn new(addr: SocketAddr, allow: &[String]) -> Guard {
        let port = addr.port();
        let mut names: Vec<String> = vec!["localhost".into(), "127.0.0.1".into(), "[::1]".into()];
        if !addr.ip().is_unspecified() {
            names.push(match addr {
                SocketAddr::V4(a) => a.ip().to_string(),
                SocketAddr::V6(a) => format!("[{}]", a.ip()),
            });
        }
        names.extend(allow.iter().map(|a| a.to_ascii_lowercase()));
        let mut hosts: Vec<String> = names.iter().map(|n| format!("{n}:{port}")).collect();
        if port == 80 {
            hosts.extend(names);
        }
        Guard { hosts }
    }

    /// Whether a request with these headers may be answered ([`Guard::check`]); the reason if not. A `Host`
    /// or an `Origin` sent twice is refused, whatever the two say (no browser sends either twice, and which
    /// of two a proxy or a framework would read is not this server's to guess).
    pub(crate) fn check_headers(&self, headers: &axum::http::HeaderMap) -> std::result::Result<(), String> {
        for name in ["host", "origin", "sec-fetch-site"] {
            let n = headers.get_all(name).iter().count();
            if n > 1 {
                return Err(format!("the request has {n} {name} headers; one at most is allowed"));
            }
        }
        let h = |name: &str| headers.get(name).map(|v| v.to_str().unwrap_or("\u{fffd}"));
        self.check(h("host"), h("origin"), h("sec-fetch-site"))
    }

    /// Whether a request with this `Host` (and `Origin`, `Sec-Fetch-Site`, if sent) may be answered; the
    /// reason if not.
    pub(crate) fn check(
        &self,
        host: Option<&str>,
        origin: Option<&str>,
        fetch_site: Option<&str>,
    ) -> std::result::Result<(), String> {
        let Some(host) = host else {
            return Err("the request has no Host header".into());
        };
        let host = host.trim().to_ascii_lowercase();
        if !self.hosts.contains(&host) {
            return Err(format!(
                "Host `{host}` is not this server's name (allowed: {}; start it with --allow-host NAME to add one)",
                self.hosts.join(", ")
            ));
        }
        if let Some(origin) = origin {
            let o = origin.trim().to_ascii_lowercase();
            let ok = o.strip_prefix("http://").is_some_and(|h| self.hosts.iter().any(|a| a == h));
            if !ok {
                return Err(format!("Origin `{origin}` is another site: cross-site requests are refused"));
            }
        }
        if fetch_site.is_some_and(|f| f.trim().eq_ignore_ascii_case("cross-site")) {
            return Err("a cross-site request (Sec-Fetch-Site: cross-site) is refused".into());
        }
        Ok(())
    }
}

/// The file a recipe's table path `given` names inside `data_dir`, canonical: refused without a data
/// directory, for an absolute path or one with `..`, for a file that is not there, and for a path that leads
/// out of the directory through a symbolic link. `file` and `field` name the recipe and its field in messages.
pub(crate) fn table_path(data_dir: Option<&Path>, given: &str, file: &str, field: &str) -> Result<PathBuf> {
    let Some(root) = data_dir else {
        return Err(Error::input(
            file,
            field,
            "this server reads no table files (start it with --data-dir DIR to let recipes name the tables in DIR)",
        ));
    };
    let p = Path::new(given);
    let plain = p.components().all(|c| matches!(c, Component::Normal(_) | Component::CurDir));
    if given.is_empty() || p.is_absolute() || !plain || given.contains('\0') {
        return Err(Error::input(
            file,
            field,
            format!(
                "`{given}`: a table is named by a path relative to the server's data directory, without `..` \
                 (absolute paths are refused)"
            ),
        ));
    }
    let root = root
        .canonicalize()
        .map_err(|e| Error::input(file, field, format!("the server's data directory cannot be read: {e}")))?;
    // A path that does not resolve and one that resolves outside (through a symbolic link) get the same
    // answer, so that a link to an outside directory does not tell whether a file exists there.
    let none = || {
        Error::input(
            file,
            field,
            format!("`{given}`: no such file in the data directory (a symbolic link out of it counts as none)"),
        )
    };
    let found = root.join(p).canonicalize().map_err(|_| none())?;
    if !found.starts_with(&root) {
        return Err(none());
    }
    if !found.is_file() {
        return Err(Error::input(file, field, format!("`{given}`: not a file in the data directory")));
    }
    Ok(found)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_guard_answers_loopback_names_on_its_port_only() {
        let g = Guard::new("127.0.0.1:8080".parse().unwrap(), &[]);
        assert!(g.check(Some("localhost:8080"), None, None).is_ok());
        assert!(g.check(Some("127.0.0.1:8080"), Some("http://localhost:8080"), Some("same-origin")).is_ok());
        assert!(g.check(Some("evil.example:8080"), None, None).is_err());
        assert!(g.check(Some("localhost:8081"), None, None).is_err());
        assert!(g.check(None, None, None).is_err());
        assert!(g.check(Some("localhost:8080"), Some("http://evil.example"), None).is_err());
        assert!(g.check(Some("localhost:8080"), Some("null"), None).is_err());
        assert!(g.check(Some("localhost:8080"), None, Some("cross-site")).is_err());
        assert!(g.check(Some("localhost:8080"), None, Some("Cross-Site")).is_err());
        assert!(g.check(Some("localhost:8080"), None, Some("same-origin")).is_ok());
        let headers = |pairs: &[(&'static str, &'static str)]| {
            let mut h = axum::http::HeaderMap::new();
            for (k, v) in pairs {
                h.append(*k, axum::http::HeaderValue::from_static(v));
            }
            h
        };
        assert!(g.check_headers(&headers(&[("host", "localhost:8080")])).is_ok());
        for twice in [
            headers(&[("host", "localhost:8080"), ("host", "evil.example")]),
            headers(&[("host", "localhost:8080"), ("host", "localhost:8080")]),
            headers(&[
                ("host", "localhost:8080"),
                ("origin", "http://localhost:8080"),
                ("origin", "http://evil.example"),
            ]),
        ] {
            let e = g.check_headers(&twice).unwrap_err();
            assert!(e.contains("one at most"), "{e}");
        }
        let g = Guard::new("0.0.0.0:80".parse().unwrap(), &["Lab-PC".into()]);
        assert!(g.check(Some("lab-pc"), None, None).is_ok());
        assert!(g.check(Some("0.0.0.0"), None, None).is_err());
    }

    #[test]
    fn tables_only_from_the_data_directory() {
        let dir = std::env::temp_dir().join(format!("glossmeter-serve-sec-{}", std::process::id()));
        let inner = dir.join("data");
        std::fs::create_dir_all(inner.join("sub")).unwrap();
        std::fs::write(inner.join("sub/t.csv"), "x").unwrap();
        std::fs::write(dir.join("secret.csv"), "x").unwrap();
        let ok = table_path(Some(&inner), "sub/t.csv", "r", "/file").unwrap();
        assert!(ok.ends_with("sub/t.csv"));
        for bad in ["../secret.csv", "/etc/passwd", "sub/../../secret.csv", "", "missing.csv", "sub"] {
            assert!(table_path(Some(&inner), bad, "r", "/file").is_err(), "{bad}");
        }
        assert!(table_path(None, "sub/t.csv", "r", "/file").is_err());
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(dir.join("secret.csv"), inner.join("link.csv")).unwrap();
            let e = table_path(Some(&inner), "link.csv", "r", "/file").unwrap_err().to_string();
            assert!(e.contains("a symbolic link out of it counts as none"), "{e}");
            // A link to an outside directory: a file there and a file not there get the same words.
            std::os::unix::fs::symlink(&dir, inner.join("dirlink")).unwrap();
            let there = table_path(Some(&inner), "dirlink/secret.csv", "r", "/file").unwrap_err().to_string();
            let not_there = table_path(Some(&inner), "dirlink/nothing.csv", "r", "/file").unwrap_err().to_string();
            assert_eq!(there.replace("secret", "nothing"), not_there);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
