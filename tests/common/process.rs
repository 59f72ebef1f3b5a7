//! The binary, temporary files and fixtures, for every test file (`mod common;`).
use std::path::PathBuf;
use std::process::Command;

/// The repository's root (tests run there; `fixtures/…` paths resolve from it).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A path under `fixtures/`.
pub fn fixture_path(rel: &str) -> PathBuf {
    root().join("fixtures").join(rel)
}

/// The `glossmeter` binary of this build, to be given its arguments, run from the repository's root.
pub fn glossmeter() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_glossmeter"));
    c.current_dir(root());
    c
}

/// Run `glossmeter ARGS`: its exit status (-1 when a signal ended it), standard output and standard error.
pub fn gm(args: &[&str]) -> (i32, String, String) {
    let out = glossmeter().args(args).output().expect("run glossmeter");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Run `glossmeter ARGS`: its exit status and standard output (standard error left out).
pub fn gm_out(args: &[&str]) -> (i32, String) {
    let (code, out, _) = gm(args);
    (code, out)
}

/// This test binary's own temporary directory (one per binary and process, created).
fn own_dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("glossmeter-{}-{}", env!("CARGO_CRATE_NAME"), std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A path `name` in this test binary's temporary directory (a file there is left as it is).
pub fn tmp(name: &str) -> PathBuf {
    own_dir().join(name)
}

/// [`tmp`], with any file already there removed (for a test that checks a file is written).
pub fn fresh(name: &str) -> PathBuf {
    let p = tmp(name);
    let _ = std::fs::remove_file(&p);
    p
}

/// A directory `name` in this test binary's temporary directory (created; its contents are left).
pub fn tmp_dir(name: &str) -> PathBuf {
    let d = own_dir().join(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// [`tmp_dir`], emptied first.
pub fn fresh_dir(name: &str) -> PathBuf {
    let d = own_dir().join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}
