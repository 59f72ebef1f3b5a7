//! Timing (median over ≥ 100 ms of repeats), result rows and their formatting, and what the run was
//! (commit, uncommitted files, load, date).
use std::panic::AssertUnwindSafe;
use std::time::Instant;

use glossmeter::instrument::method::Flux;

/// Run `f` until ≥ 100 ms have been spent (at least once); return the last result, the median seconds per
/// run and the number of runs.
pub(crate) fn timed<T>(mut f: impl FnMut() -> T) -> (T, f64, usize) {
    let mut times = Vec::new();
    let mut total = 0.0;
    let mut out;
    loop {
        let t = Instant::now();
        out = f();
        let dt = t.elapsed().as_secs_f64();
        times.push(dt);
        total += dt;
        if total >= 0.1 {
            break;
        }
    }
    times.sort_by(f64::total_cmp);
    let n = times.len();
    let median = if n % 2 == 1 { times[n / 2] } else { 0.5 * (times[n / 2 - 1] + times[n / 2]) };
    (out, median, n)
}

pub(crate) struct Row {
    pub(crate) case: &'static str,
    pub(crate) method: String,
    pub(crate) value: f64,
    /// The method's own error claim (our estimate; MC 1-σ standard error); NaN if none.
    pub(crate) claimed: f64,
    pub(crate) rel_err: f64,
    pub(crate) evals: usize,
    pub(crate) seconds: f64,
    pub(crate) runs: usize,
    pub(crate) note: String,
}

impl Row {
    /// A row of our engine: its flux on `case` against `reference`, timed `secs` over `runs` runs.
    pub(crate) fn of_flux(
        case: &'static str,
        method: String,
        f: &Flux,
        reference: f64,
        secs: f64,
        runs: usize,
        note: String,
    ) -> Row {
        Row {
            case,
            method,
            value: f.value[0],
            claimed: f.error[0] / f.value[0].abs(),
            rel_err: (f.value[0] - reference).abs() / reference,
            evals: f.evaluations,
            seconds: secs,
            runs,
            note,
        }
    }
}

pub(crate) fn fmt_time(s: f64) -> String {
    if s < 1e-3 {
        format!("{:.1} µs", s * 1e6)
    } else if s < 1.0 {
        format!("{:.2} ms", s * 1e3)
    } else {
        format!("{:.2} s", s)
    }
}

pub(crate) fn fmt_e(x: f64) -> String {
    if x.is_nan() {
        "–".into()
    } else {
        format!("{x:.1e}")
    }
}

/// Catch a panic (an engine part still marked `todo!()` by another engineer) and say what it was.
pub(crate) fn try_run<T>(what: &str, f: impl FnOnce() -> T) -> Option<T> {
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let r = std::panic::catch_unwind(AssertUnwindSafe(f));
    std::panic::set_hook(hook);
    match r {
        Ok(v) => Some(v),
        Err(e) => {
            let msg = e
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| e.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "panic".into());
            eprintln!("[bench] {what}: not available ({msg})");
            None
        }
    }
}

pub(crate) fn git_commit() -> String {
    std::process::Command::new("git")
        .args(["rev-parse", "--short", "HEAD"])
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|| "?".into())
}

/// Files under src/ that differ from HEAD (other engineers' work in progress is compiled into the bench).
pub(crate) fn dirty_src() -> String {
    std::process::Command::new("git")
        .args(["status", "--short", "--", "src"])
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| {
            let files: Vec<&str> = s.lines().map(|l| l[3..].trim()).collect();
            if files.is_empty() {
                "none".into()
            } else {
                files.join(", ")
            }
        })
        .unwrap_or_else(|| "?".into())
}

pub(crate) fn loadavg() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "?".into())
}

pub(crate) fn date() -> String {
    std::process::Command::new("date")
        .args(["-u", "+%Y-%m-%d %H:%M UTC"])
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|| "?".into())
}
