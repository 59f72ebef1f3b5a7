//! Output that cannot be written (issue 7 item 1, issue 8 items 2–3): a reader that went away ends the run
//! quietly with status 0, as ripgrep does; a full disk is an error (status 2) with the file named, never a
//! panic (101) and never a silent success.
#![cfg(feature = "cli")]
use std::process::{Command, Stdio};

fn glossmeter() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_glossmeter"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

/// Run with standard output on a pipe whose reading end is closed before the process starts, so every
/// write fails with EPIPE (no race with a reader). `std::io::pipe` is Rust 1.87; the crate's MSRV (1.85) is
/// the library's, the tests may use newer std.
#[allow(clippy::incompatible_msrv)]
fn on_closed_pipe(args: &[&str]) -> std::process::Output {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    glossmeter().args(args).stdout(writer).stderr(Stdio::piped()).output().unwrap()
}

const CASES: &[&[&str]] = &[
    &["standards"],
    &["standards", "astm-d523-60"],
    &["schema"],
    &["measure", "fixtures/recipes/glass-n1.5.json", "-g", "astm-d523-60"],
    &["measure", "fixtures/recipes/glass-n1.5.json", "-g", "astm-d523-60", "--format", "json"],
    &["compare", "fixtures/recipes/black-glass.json", "fixtures/sheets/black-glass-check.csv"],
];

#[test]
fn a_closed_pipe_ends_quietly_with_status_0() {
    for args in CASES {
        let out = on_closed_pipe(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {stderr}");
        assert!(stderr.is_empty(), "{args:?}: quiet, got {stderr}");
    }
}

#[test]
fn a_full_disk_on_stdout_is_an_error_not_a_panic() {
    if !std::path::Path::new("/dev/full").exists() {
        return;
    }
    for args in CASES {
        let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        let out = glossmeter().args(*args).stdout(full).stderr(Stdio::piped()).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains("<stdout>") && stderr.contains("No space left"), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}
