//! Output that cannot be written (`docs/reliability.md` §Output that cannot be written): a reader that went away ends
//! the run quietly with status 0, as ripgrep does; a full disk is an error (status 2) with the file named, never a
//! panic (101) and never a silent success.
#![cfg(feature = "cli")]
mod common;
use common::glossmeter;
use std::process::{Command, Stdio};

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
    CONVERGENCE,
];

/// A quick `convergence` (once missing from the closed-pipe cases).
const CONVERGENCE: &[&str] = &[
    "convergence",
    "fixtures/recipes/grey-lambert.json",
    "-g",
    "astm-d523-60",
    "--tolerances",
    "1e-3",
    "--max-repetitions",
    "1",
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

/// A small tmpfs filled to the last byte, unmounted when dropped (even when the test fails). Mounting needs
/// root, so the test that uses it is opt-in (`.ci/run`, as root, runs it with `-- --ignored`); where it cannot be
/// mounted the test fails saying so, never passing unchecked (in a plain `cargo test` the library-level test
/// `cli::output::tests::a_failed_write_leaves_no_file_and_an_error` covers the same path).
struct FullDisk(std::path::PathBuf);

impl FullDisk {
    fn mount(name: &str) -> FullDisk {
        let dir = std::env::temp_dir().join(format!("glossmeter-full-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", "size=64k", "tmpfs"])
            .arg(&dir)
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        if !ok {
            let _ = std::fs::remove_dir(&dir);
            panic!("{name}: cannot mount a tmpfs at {} (this opt-in test needs root and tmpfs)", dir.display());
        }
        let disk = FullDisk(dir);
        // Fill it: write until the disk refuses.
        let mut filler = std::fs::File::create(disk.0.join("filler")).unwrap();
        let block = vec![b'x'; 4096];
        while std::io::Write::write_all(&mut filler, &block).is_ok() {}
        let _ = std::io::Write::write_all(&mut filler, b"x");
        disk
    }

    fn entries(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(&self.0)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }
}

impl Drop for FullDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
        let _ = std::fs::remove_dir(&self.0);
    }
}

/// `-o` and `--plot` on a full filesystem once left a 0-byte file (and exited 0 for `-o`). Now:
/// status 2, the file named with the system's reason, and no file (not even an empty one, nor the
/// temporary) left behind, so a rerun under the same name is not blocked.
#[test]
#[ignore = "needs root to mount a small tmpfs; .ci/run runs it with `cargo test --test output_errors -- --ignored`"]
fn a_full_disk_leaves_no_file_and_exits_2() {
    let disk = FullDisk::mount("files");
    let target = |name: &str| disk.0.join(name).to_string_lossy().into_owned();
    let cases: Vec<(Vec<String>, String)> = vec![
        (
            ["measure", "fixtures/recipes/glass-n1.5.json", "-g", "astm-d523-60", "-o"]
                .iter()
                .map(|s| s.to_string())
                .chain([target("readings.txt")])
                .collect(),
            target("readings.txt"),
        ),
        (
            ["compare", "fixtures/recipes/black-glass.json", "fixtures/sheets/black-glass-check.csv", "-o"]
                .iter()
                .map(|s| s.to_string())
                .chain([target("compare.txt")])
                .collect(),
            target("compare.txt"),
        ),
        (
            CONVERGENCE.iter().map(|s| s.to_string()).chain(["-o".into(), target("sweep.txt")]).collect(),
            target("sweep.txt"),
        ),
        (
            CONVERGENCE.iter().map(|s| s.to_string()).chain(["--plot".into(), target("plot.svg")]).collect(),
            target("plot.svg"),
        ),
        (
            ["compare", "fixtures/recipes/black-glass.json", "fixtures/sheets/black-glass-check.csv", "--plot"]
                .iter()
                .map(|s| s.to_string())
                .chain([target("compare.svg")])
                .collect(),
            target("compare.svg"),
        ),
    ];
    for (args, file) in &cases {
        let out = glossmeter().args(args).stdout(Stdio::null()).stderr(Stdio::piped()).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(file.as_str()) && stderr.contains("No space left"), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert_eq!(disk.entries(), ["filler"], "{args:?}: a file was left behind");
    }
}

/// Help and version on a full disk: the write fails, so the exit status is 2 with a message, never a silent 0
/// (docs/instrument.md §Exit statuses); on a working stdout they still exit 0.
#[test]
fn help_and_version_on_a_full_disk_exit_2() {
    if !std::path::Path::new("/dev/full").exists() {
        return;
    }
    for args in [&["--help"][..], &["--version"], &["measure", "--help"]] {
        let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        let out = common::glossmeter().args(args).stdout(full).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("<stdout>") && err.contains("No space left"), "{args:?}: {err}");
        let ok = common::glossmeter().args(args).output().unwrap();
        assert_eq!(ok.status.code(), Some(0), "{args:?}");
        assert!(!ok.stdout.is_empty());
    }
}
