//! One error type for the whole crate. Bad input must be reported with the file, the field and what is
//! allowed, so every input error carries those three things; the CLI turns any error into a message and a
//! non-zero exit, never a panic.
use std::fmt;

#[derive(Debug)]
pub enum Error {
    /// A value in an input file (recipe, geometry, sheet) is missing, malformed or out of range.
    Input {
        /// The file (or `<stdin>`, `<builtin:...>`) the value came from.
        file: String,
        /// The field as an RFC 6901 JSON Pointer, e.g. `/pigmented_layer/pigments/1/k_per_mm`; empty if the
        /// whole file is at fault (for sheets: `line N`).
        field: String,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// An operating-system error while reading or writing a file.
    Io { file: String, source: std::io::Error },
    /// A request that cannot be carried out (unknown geometry id, bad tolerance, ...).
    Usage(String),
    /// A computation that did not produce a finite result.
    Numeric(String),
    /// A comparison with a sheet found readings outside their allowed difference (exit status 1).
    Check(String),
}

pub type Result<T> = std::result::Result<T, Error>;

/// A number the user gave, shown in an error message in backquotes as the user's own value (`` `NaN` ``,
/// `` `inf` ``, `` `0` ``): glossmeter's own text never shows a non-finite number, so a reader (or the fuzz
/// checker, tests/common/fuzz_cases.rs) can tell an echoed input from a computed NaN (`docs/reliability.md` §The
/// checks).
pub fn given(x: f64) -> String {
    format!("`{x}`")
}

impl Error {
    pub fn input(file: impl Into<String>, field: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Input { file: file.into(), field: field.into(), message: message.into() }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Input { file, field, message } if field.is_empty() => write!(f, "{file}: {message}"),
            Error::Input { file, field, message } => write!(f, "{file}: field `{field}`: {message}"),
            Error::Io { file, source } => write!(f, "{file}: {source}"),
            Error::Usage(m) => write!(f, "{m}"),
            Error::Numeric(m) => write!(f, "numerical failure: {m}"),
            Error::Check(m) => write!(f, "check failed: {m}"),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}
