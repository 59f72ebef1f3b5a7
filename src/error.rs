//! One error type for the whole crate. Bad input must be reported with the file, the field and what is
//! allowed, so every input error carries those three things; the CLI turns any error into a message and a
//! non-zero exit, never a panic. The library never names a command-line flag: a message that names an argument
//! of a call keeps it apart from its other words ([`Words`]), and the command line writes it as its flag.
use std::fmt;
use std::ops::{Deref, Range};

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
        message: Words,
    },
    /// An operating-system error while reading or writing a file.
    Io { file: String, source: std::io::Error },
    /// A request that cannot be carried out (unknown geometry id, bad tolerance, ...).
    Usage(String),
    /// An argument of a call that is missing or malformed (a sweep's `vary`, a fit's `target`, a comparison's
    /// `tolerance`): a usage error whose message names the arguments ([`Words`]).
    Argument(Words),
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
    format!("`{}`", number(x))
}

/// A number for a message or a description: its shortest round-trip digits, plain in the everyday range
/// [10⁻⁶, 10¹⁵) and in scientific notation outside it, so that 1e300 is not printed with all its 301 digits
/// nor 1e-300 with 300 zeros (`docs/instrument.md` §Numbers in text).
pub(crate) fn number(x: f64) -> String {
    if x.is_finite() && x != 0.0 && !(1e-6..1e15).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// The words of a message that names arguments of a call (a sweep's `vary`, a fit's `target`, a comparison's
/// `tolerance`) apart from its other words, so that each front end names them its own way and the library
/// never writes a command-line flag (ripgrep's rule: the parser adds the flag to a flag's error). As text (it
/// derefs to `str`, and [`Display`](fmt::Display) writes it) an argument is its name in backquotes,
/// `` `vary` ``; [`Words::naming`] writes each one otherwise (the command line: as its flag, `--vary`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Words {
    text: String,
    /// The arguments named, and where their names (in backquotes) stand in `text`.
    arguments: Vec<(Range<usize>, &'static str)>,
    /// The arguments given with a value ([`Words::and_setting`]): the argument's index, where its value's text
    /// (` A`) ends in `text`, and the value.
    settings: Vec<(usize, usize, String)>,
}

impl Words {
    /// Words that begin with an argument.
    pub(crate) fn argument(name: &'static str) -> Words {
        Words::default().and_argument(name)
    }

    /// These words, then `text`.
    pub(crate) fn and(mut self, text: impl AsRef<str>) -> Words {
        self.text.push_str(text.as_ref());
        self
    }

    /// These words, then an argument.
    pub(crate) fn and_argument(mut self, name: &'static str) -> Words {
        let start = self.text.len();
        self.text.push_str(&format!("`{name}`"));
        self.arguments.push((start..self.text.len(), name));
        self
    }

    /// These words, then an argument with the value to give it: as text `` `illuminant` A ``, and written by
    /// each front end its own way ([`Words::naming_settings`]: `--illuminant A`, `illuminant="A"`).
    pub(crate) fn and_setting(mut self, name: &'static str, value: impl Into<String>) -> Words {
        let value = value.into();
        self = self.and_argument(name).and(format!(" {value}"));
        self.settings.push((self.arguments.len() - 1, self.text.len(), value));
        self
    }

    /// The argument these words begin with, and the words after it (`` `rtol` must be … `` → `rtol` and
    /// ` must be …`), so that a front end can name the argument apart (the server: as the field of its body).
    pub(crate) fn leading_argument(&self) -> Option<(&'static str, Words)> {
        let (span, name) = self.arguments.first()?;
        if span.start != 0 {
            return None;
        }
        let at = span.end;
        let rest = Words {
            text: self.text[at..].to_string(),
            arguments: self.arguments[1..].iter().map(|(r, a)| (r.start - at..r.end - at, *a)).collect(),
            settings: self
                .settings
                .iter()
                .filter(|s| s.0 > 0)
                .map(|(i, end, v)| (i - 1, end - at, v.clone()))
                .collect(),
        };
        Some((name, rest))
    }

    /// The words with each argument written by `name` (an argument given a value: then the value, after a space).
    pub(crate) fn naming(&self, name: &dyn Fn(&'static str) -> String) -> String {
        self.naming_settings(name, &|a, v| format!("{} {v}", name(a)))
    }

    /// The words with each argument written by `name`, and each argument given a value by `setting`.
    pub(crate) fn naming_settings(
        &self,
        name: &dyn Fn(&'static str) -> String,
        setting: &dyn Fn(&'static str, &str) -> String,
    ) -> String {
        let mut out = String::with_capacity(self.text.len());
        let mut at = 0;
        for (i, (span, argument)) in self.arguments.iter().enumerate() {
            out.push_str(&self.text[at..span.start]);
            match self.settings.iter().find(|s| s.0 == i) {
                Some((_, end, value)) => {
                    out.push_str(&setting(argument, value));
                    at = *end;
                }
                None => {
                    out.push_str(&name(argument));
                    at = span.end;
                }
            }
        }
        out.push_str(&self.text[at..]);
        out
    }
}

impl Deref for Words {
    type Target = str;
    fn deref(&self) -> &str {
        &self.text
    }
}

impl fmt::Display for Words {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

impl From<String> for Words {
    fn from(text: String) -> Words {
        Words { text, arguments: Vec::new(), settings: Vec::new() }
    }
}

impl From<&str> for Words {
    fn from(text: &str) -> Words {
        Words::from(text.to_string())
    }
}

impl From<&String> for Words {
    fn from(text: &String) -> Words {
        Words::from(text.clone())
    }
}

impl Error {
    pub(crate) fn input(file: impl Into<String>, field: impl Into<String>, message: impl Into<Words>) -> Self {
        Error::Input { file: file.into(), field: field.into(), message: message.into() }
    }

    /// An [`Error::Argument`] whose message begins with the argument `name`, followed directly by `rest` (which
    /// begins with its own space or colon: `` `lhs` N must be at least 1 ``, `` `vary`: not a parameter ``).
    pub(crate) fn argument(name: &'static str, rest: impl AsRef<str>) -> Self {
        Error::Argument(Words::argument(name).and(rest))
    }

    /// The message with each argument it names written by `name` (see [`Words`]; the command line passes its
    /// flags). The [`Display`](fmt::Display) of an error is the message in the library's words.
    pub fn naming(&self, name: &dyn Fn(&'static str) -> String) -> String {
        self.naming_settings(name, &|a, v| format!("{} {v}", name(a)))
    }

    /// As [`Error::naming`], with each argument the message gives a value to (`give --illuminant A`) written by
    /// `setting` (Python: `illuminant="A"`).
    pub fn naming_settings(
        &self,
        name: &dyn Fn(&'static str) -> String,
        setting: &dyn Fn(&'static str, &str) -> String,
    ) -> String {
        let words = |w: &Words| w.naming_settings(name, setting);
        match self {
            Error::Input { file, field, message } if field.is_empty() => format!("{file}: {}", words(message)),
            Error::Input { file, field, message } => format!("{file}: field `{field}`: {}", words(message)),
            Error::Io { file, source } => format!("{file}: {source}"),
            Error::Usage(m) => m.clone(),
            Error::Argument(w) => words(w),
            Error::Numeric(m) => format!("numerical failure: {m}"),
            Error::Check(m) => format!("check failed: {m}"),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.naming(&|name| format!("`{name}`")))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_keep_the_arguments_apart_from_the_text() {
        let w = Words::from("give at least one ").and_argument("vary").and(" PATH (or ").and_argument("lhs").and(" N)");
        assert_eq!(&*w, "give at least one `vary` PATH (or `lhs` N)");
        assert_eq!(w.naming(&|n| format!("--{n}")), "give at least one --vary PATH (or --lhs N)");
        let e = Error::input("s.csv", "line 1", Words::from("pass ").and_argument("ignore_columns").and(" 'x'"));
        assert_eq!(e.to_string(), "s.csv: field `line 1`: pass `ignore_columns` 'x'");
        assert_eq!(e.naming(&|_| "-i".into()), "s.csv: field `line 1`: pass -i 'x'");
        // A user's text in backquotes is not an argument.
        let e = Error::argument("vary", " `lhs`: no `=`");
        assert_eq!(e.naming(&|n| format!("--{n}")), "--vary `lhs`: no `=`");
    }

    #[test]
    fn an_argument_given_a_value_is_written_as_each_front_end_passes_it() {
        let w = Words::argument("rtol")
            .and(" too loose; give")
            .and(" ")
            .and_setting("illuminant", "A")
            .and(" ")
            .and_setting("observer", "2")
            .and(" (the sheet's)");
        assert_eq!(&*w, "`rtol` too loose; give `illuminant` A `observer` 2 (the sheet's)");
        let flag = |n: &'static str| format!("--{n}");
        assert_eq!(w.naming(&flag), "--rtol too loose; give --illuminant A --observer 2 (the sheet's)");
        let python = w.naming_settings(&|n| format!("`{n}`"), &|n, v| format!("{n}={v:?}"));
        assert_eq!(python, "`rtol` too loose; give illuminant=\"A\" observer=\"2\" (the sheet's)");
        // Past a leading argument the settings keep their places.
        let (name, rest) = w.leading_argument().unwrap();
        assert_eq!(name, "rtol");
        assert_eq!(
            rest.naming_settings(&flag, &|n, v| format!("{n}:{v}")),
            " too loose; give illuminant:A observer:2 (the sheet's)"
        );
        let e = Error::input("s.csv", "illuminant: A", w);
        assert_eq!(
            e.naming(&flag),
            "s.csv: field `illuminant: A`: --rtol too loose; give --illuminant A --observer 2 (the sheet's)"
        );
    }
}
