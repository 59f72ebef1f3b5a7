//! Input files (recipes, geometry files, sheets) read as text with a size limit. It exists so that a file
//! that is not a recipe at all (`/dev/zero`, a multi-gigabyte log given by mistake) is refused with a clear
//! message instead of being read until memory runs out. (MERL tables are binary and checked against their
//! own header in `measured::merl`.)
//!
//! The folder:
//! * `mod.rs` (this): [`read_text`] and [`read_bytes`] with the text limit [`MAX_TEXT_BYTES`], and their
//!   `_limited` forms ([`read_text_limited`], [`read_bytes_limited`]) that the measured tables use with
//!   [`MAX_TABLE_BYTES`]; the path `-` is standard input ([`is_stdin`], named [`STDIN`] in messages), which
//!   one input of a run may be (docs/instrument.md §Standard input and output);
//! * `json.rs`: a JSON document read with errors that name the file and the field's JSON Pointer
//!   ([`json::parse_json`], which refuses duplicate keys, [`json::Obj`] and its typed accessors, [`json::kind`],
//!   [`json::show`]); every recipe and geometry-file parser reads through it.
use std::io::Read;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::{Error, Result};

pub mod json;

/// The largest text input file: 16 MiB. A recipe or a geometry file is a few kB; a sheet of 16 MiB holds
/// some 300 000 readings.
pub const MAX_TEXT_BYTES: u64 = 16 * 1024 * 1024;

/// The largest measured table (RGL `.bsdf`, in-plane CSV, ASTM E1392 text): 256 MiB. A MERL-resolution
/// isotropic table is 34 MB (90 × 90 × 180 × 3 doubles); RGL files of measured materials are 1–60 MB.
pub const MAX_TABLE_BYTES: u64 = 256 * 1024 * 1024;

/// How standard input is named in messages (the path `-`).
pub const STDIN: &str = "<stdin>";

/// Whether a path is `-`, standard input (a file named `-` is still reachable as `./-`).
pub fn is_stdin(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// A path as messages name it: the path as given, or [`STDIN`] for `-`.
pub fn name(path: &Path) -> String {
    if is_stdin(path) {
        STDIN.into()
    } else {
        path.display().to_string()
    }
}

/// Refuse, before any reading, a run that names `-` for two inputs (standard input can be read once).
pub fn at_most_one_stdin<'a>(paths: impl IntoIterator<Item = &'a Path>) -> Result<()> {
    if paths.into_iter().filter(|p| is_stdin(p)).count() > 1 {
        return Err(Error::Usage(
            "`-` (standard input) is given for a second input: standard input can be read once, so at most one \
             input may be `-`"
                .into(),
        ));
    }
    Ok(())
}

/// Set when standard input has been read: it can be read once, so a second `-` is an error, not an empty file.
static STDIN_READ: AtomicBool = AtomicBool::new(false);

/// Read a UTF-8 text file of at most [`MAX_TEXT_BYTES`]; `what` names the kind of file in messages.
pub fn read_text(path: &Path, what: &str) -> Result<String> {
    read_text_limited(path, what, MAX_TEXT_BYTES)
}

/// The bytes of a file of at most [`MAX_TEXT_BYTES`] (for sheets, whose encoding is decided after reading).
pub fn read_bytes(path: &Path, what: &str) -> Result<Vec<u8>> {
    read_bytes_limited(path, what, MAX_TEXT_BYTES)
}

/// The bytes of a file of at most `limit` bytes; a larger one (or an endless one, `/dev/zero`) is refused
/// after reading `limit` + 1 bytes, naming the file and the limit.
pub fn read_bytes_limited(path: &Path, what: &str, limit: u64) -> Result<Vec<u8>> {
    let file = name(path);
    let io = |source| Error::Io { file: file.clone(), source };
    let mut bytes = Vec::new();
    if is_stdin(path) {
        if STDIN_READ.swap(true, Ordering::SeqCst) {
            return Err(Error::Usage(format!(
                "`-` (standard input) is given for a second input (a {what}): standard input can be read once, so \
                 at most one input may be `-`"
            )));
        }
        std::io::stdin().lock().take(limit + 1).read_to_end(&mut bytes).map_err(io)?;
    } else {
        let f = std::fs::File::open(path).map_err(io)?;
        f.take(limit + 1).read_to_end(&mut bytes).map_err(io)?;
    }
    if bytes.len() as u64 > limit {
        return Err(Error::input(
            &file,
            "",
            format!("larger than {} MiB, the limit for a {what} (is this the right file?)", limit / (1024 * 1024)),
        ));
    }
    Ok(bytes)
}

/// [`read_text`] with the limit given.
pub fn read_text_limited(path: &Path, what: &str, limit: u64) -> Result<String> {
    let file = name(path);
    let bytes = read_bytes_limited(path, what, limit)?;
    String::from_utf8(bytes).map_err(|e| {
        Error::input(
            &file,
            "",
            format!(
                "not UTF-8 text (invalid byte at offset {}); a {what} is JSON or CSV text",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dev_zero_is_refused_at_the_limit() {
        if !Path::new("/dev/zero").exists() {
            return;
        }
        let e = read_text_limited(Path::new("/dev/zero"), "recipe", 1024 * 1024).unwrap_err().to_string();
        assert!(e.contains("/dev/zero") && e.contains("larger than 1 MiB"), "{e}");
    }

    #[test]
    fn every_table_reader_refuses_an_endless_file() {
        if !Path::new("/dev/zero").exists() {
            return;
        }
        let zero = Path::new("/dev/zero");
        for e in [
            crate::measured::inplane::load_csv(zero).map(|_| ()).unwrap_err(),
            crate::measured::e1392::load(zero).map(|_| ()).unwrap_err(),
            crate::measured::rgl::RglBrdf::load(zero).map(|_| ()).unwrap_err(),
        ] {
            let e = e.to_string();
            assert!(e.contains("/dev/zero") && e.contains("larger than 256 MiB"), "{e}");
        }
    }

    #[test]
    fn binary_and_missing_files_are_errors_naming_the_file() {
        let p = std::env::temp_dir().join(format!("glossmeter-input-{}.bin", std::process::id()));
        std::fs::write(&p, [0x7b, 0xff, 0xfe]).unwrap();
        let e = read_text(&p, "recipe").unwrap_err().to_string();
        assert!(e.contains("not UTF-8") && e.contains("offset 1"), "{e}");
        let _ = std::fs::remove_file(&p);
        assert!(matches!(read_text(Path::new("/nonexistent/x.json"), "recipe"), Err(Error::Io { .. })));
    }
}
