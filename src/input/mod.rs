//! Input files (recipes, geometry files, sheets) read as text with a size limit. It exists so that a file
//! that is not a recipe at all (`/dev/zero`, a multi-gigabyte log given by mistake) is refused with a clear
//! message instead of being read until memory runs out. (MERL tables are binary and checked against their
//! own header in `measured::merl`.)
//!
//! The folder:
//! * `mod.rs` (this): a [`Source`], a file or bytes already read, read as text ([`Source::text`]) or bytes
//!   ([`Source::bytes`]) with the text limit [`MAX_TEXT_BYTES`], or with the limit given (`_limited`: the
//!   measured tables use [`MAX_TABLE_BYTES`]); [`read_text`] and its kin for a file's path. Standard input is
//!   a source a front end opens ([`Stdin::open`]: the argument `-`, named [`STDIN`] in messages, which one
//!   input of a run may be, docs/instrument.md §Standard input and output) and hands to the readers: no
//!   reader knows `-`;
//! * `json.rs`: a JSON document read with errors that name the file and the field's JSON Pointer
//!   ([`json::parse_json`], which refuses duplicate keys, [`json::Obj`] and its typed accessors, [`json::kind`],
//!   [`json::show`]); every recipe and geometry-file parser reads through it.
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::{Error, Result};

pub mod json;

/// The largest text input file: 16 MiB. A recipe or a geometry file is a few kB; a sheet of 16 MiB holds
/// some 300 000 readings.
pub(crate) const MAX_TEXT_BYTES: u64 = 16 * 1024 * 1024;

/// The largest measured table (RGL `.bsdf`, in-plane CSV, ASTM E1392 text): 256 MiB. A MERL-resolution
/// isotropic table is 34 MB (90 × 90 × 180 × 3 doubles); RGL files of measured materials are 1–60 MB.
pub(crate) const MAX_TABLE_BYTES: u64 = 256 * 1024 * 1024;

/// How standard input is named in messages (the path `-`).
pub(crate) const STDIN: &str = "<stdin>";

/// Whether a command-line argument is `-`, standard input (a file named `-` is still reachable as `./-`). Only
/// front ends ask: a reader is handed a [`Source`], and the path `-` is a file of that name to it.
pub fn is_stdin(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// Refuse, before any reading, a run that names `-` for two inputs (standard input can be read once).
pub(crate) fn at_most_one_stdin<'a>(paths: impl IntoIterator<Item = &'a Path>) -> Result<()> {
    if paths.into_iter().filter(|p| is_stdin(p)).count() > 1 {
        return Err(Error::Usage(
            "`-` (standard input) is given for a second input: standard input can be read once, so at most one \
             input may be `-`"
                .into(),
        ));
    }
    Ok(())
}

/// An input as a front end hands it to a reader: a file the reader opens, or bytes the front end has already
/// read (standard input, [`Stdin::open`]) with the name messages give them.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Source {
    /// A file, by its path as given.
    File(PathBuf),
    /// Bytes already read (at most a reader's limit + 1, so that the reader still refuses a larger input), and
    /// their name in messages ([`STDIN`]).
    Read { name: String, bytes: Arc<[u8]> },
}

impl From<&Path> for Source {
    fn from(p: &Path) -> Source {
        Source::File(p.to_path_buf())
    }
}

impl From<PathBuf> for Source {
    fn from(p: PathBuf) -> Source {
        Source::File(p)
    }
}

impl Source {
    /// The source as messages name it: the path as given, or the name of bytes read ([`STDIN`]).
    pub(crate) fn name(&self) -> String {
        match self {
            Source::File(p) => p.display().to_string(),
            Source::Read { name, .. } => name.clone(),
        }
    }

    /// The bytes of the source, of at most [`MAX_TEXT_BYTES`] (for sheets, whose encoding is decided after
    /// reading).
    pub(crate) fn bytes(&self, what: &str) -> Result<Vec<u8>> {
        self.bytes_limited(what, MAX_TEXT_BYTES)
    }

    /// The source as UTF-8 text of at most [`MAX_TEXT_BYTES`]; `what` names the kind of file in messages.
    pub(crate) fn text(&self, what: &str) -> Result<String> {
        self.text_limited(what, MAX_TEXT_BYTES)
    }

    /// The bytes of the source, of at most `limit` bytes; a larger one (or an endless one, `/dev/zero`) is
    /// refused after reading `limit` + 1 bytes, naming the file and the limit.
    pub(crate) fn bytes_limited(&self, what: &str, limit: u64) -> Result<Vec<u8>> {
        let file = self.name();
        let bytes = match self {
            Source::File(path) => {
                let io = |source| Error::Io { file: file.clone(), source };
                let mut bytes = Vec::new();
                let f = std::fs::File::open(path).map_err(io)?;
                f.take(limit + 1).read_to_end(&mut bytes).map_err(io)?;
                bytes
            }
            Source::Read { bytes, .. } => bytes.to_vec(),
        };
        if bytes.len() as u64 > limit {
            return Err(Error::input(
                &file,
                "",
                format!("larger than {} MiB, the limit for a {what} (is this the right file?)", limit / (1024 * 1024)),
            ));
        }
        Ok(bytes)
    }

    /// [`Source::text`] with the limit given.
    pub(crate) fn text_limited(&self, what: &str, limit: u64) -> Result<String> {
        let bytes = self.bytes_limited(what, limit)?;
        String::from_utf8(bytes).map_err(|e| {
            Error::input(
                self.name(),
                "",
                format!(
                    "not UTF-8 text (invalid byte at offset {}); a {what} is JSON or CSV text",
                    e.utf8_error().valid_up_to()
                ),
            )
        })
    }
}

/// Standard input as a front end opens it: a value the front end owns for one run (never a flag of the
/// process), which reads standard input for the first `-` and refuses a second (it can be read once).
#[derive(Debug, Default)]
pub(crate) struct Stdin {
    read: bool,
}

impl Stdin {
    /// The source of a command-line argument: a file, or for `-` standard input read now (at most `limit` + 1
    /// bytes: the reader, which has the same limit, refuses more), named [`STDIN`]. `what` names the kind of
    /// input in the message refusing a second `-`.
    pub(crate) fn open(&mut self, path: &Path, what: &str, limit: u64) -> Result<Source> {
        if !is_stdin(path) {
            return Ok(Source::File(path.to_path_buf()));
        }
        if std::mem::replace(&mut self.read, true) {
            return Err(Error::Usage(format!(
                "`-` (standard input) is given for a second input (a {what}): standard input can be read once, so \
                 at most one input may be `-`"
            )));
        }
        let mut bytes = Vec::new();
        std::io::stdin()
            .lock()
            .take(limit + 1)
            .read_to_end(&mut bytes)
            .map_err(|source| Error::Io { file: STDIN.into(), source })?;
        Ok(Source::Read { name: STDIN.into(), bytes: bytes.into() })
    }

    /// [`Stdin::open`] of a text input ([`MAX_TEXT_BYTES`]: recipes, sheets, geometry files, baselines).
    pub(crate) fn open_text(&mut self, path: &Path, what: &str) -> Result<Source> {
        self.open(path, what, MAX_TEXT_BYTES)
    }

    /// [`Stdin::open_text`] of every path, in order.
    pub(crate) fn open_text_all(&mut self, paths: &[PathBuf], what: &str) -> Result<Vec<Source>> {
        paths.iter().map(|p| self.open_text(p, what)).collect()
    }
}

/// Read the UTF-8 text file `path` of at most [`MAX_TEXT_BYTES`]; `what` names the kind of file in messages.
pub fn read_text(path: &Path, what: &str) -> Result<String> {
    Source::from(path).text(what)
}

/// The bytes of the file `path`, of at most `limit` bytes ([`Source::bytes_limited`]).
pub(crate) fn read_bytes_limited(path: &Path, what: &str, limit: u64) -> Result<Vec<u8>> {
    Source::from(path).bytes_limited(what, limit)
}

/// [`read_text`] with the limit given.
pub(crate) fn read_text_limited(path: &Path, what: &str, limit: u64) -> Result<String> {
    Source::from(path).text_limited(what, limit)
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

    /// Standard input is the front end's: a reader given the path `-` opens a file of that name, and the bytes
    /// a front end read are held to the reader's limit and named `<stdin>`; a second `-` is refused.
    #[test]
    fn standard_input_is_a_source_the_front_end_opens() {
        let dash = Path::new("-");
        if !dash.exists() {
            let e = Source::from(dash).text("recipe").unwrap_err();
            assert!(matches!(&e, Error::Io { file, .. } if file == "-"), "{e}");
        }
        let read = Source::Read { name: STDIN.into(), bytes: vec![b'x'; 3].into() };
        assert_eq!(read.text_limited("recipe", 3).unwrap(), "xxx");
        let e = read.text_limited("recipe", 2).unwrap_err().to_string();
        assert!(e.contains(STDIN) && e.contains("larger than 0 MiB, the limit for a recipe"), "{e}");
        let mut stdin = Stdin { read: true };
        assert_eq!(stdin.open_text(Path::new("r.json"), "recipe").unwrap(), Source::File("r.json".into()));
        let e = stdin.open_text(dash, "geometry file").unwrap_err().to_string();
        assert!(e.contains("`-` (standard input) is given for a second input (a geometry file)"), "{e}");
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
