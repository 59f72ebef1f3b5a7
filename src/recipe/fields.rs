//! The registry-driven reading of recipe parameters: a recipe parameter is read through its
//! [`crate::registry`] entry (`Obj::param`), which supplies the key, the range and the description, so that the
//! parsers, the schema and the docs cannot disagree. The JSON reader itself (`Obj`, `parse_json`, `kind`) is
//! [`crate::input::json`].
use crate::input::json::{kind, show, Obj};
use crate::registry::{self, Param};
use crate::{Error, Result};
use serde_json::Value;

impl Obj<'_> {
    /// Refuse any key that the registry does not list at this object's pointer for `model`.
    pub(crate) fn deny_unknown_in(&self, model: &str) -> Result<()> {
        let allowed = registry::children(model, &self.path);
        let allowed: Vec<&str> = allowed.iter().map(String::as_str).collect();
        self.deny_unknown(&allowed)
    }

    /// The key of `p` after checking that `p` names a child of this object (a parser reading an entry at
    /// the wrong place is a bug, caught by every test that loads a recipe).
    fn key_of(&self, p: &Param) -> String {
        let key = p.key();
        debug_assert!(p.matches(&self.field(&key)), "registry entry {} read at {}", p.pointer, self.field(&key));
        key
    }

    /// A required number of the registry entry `p`, within its range.
    pub(crate) fn param(&self, p: &Param) -> Result<f64> {
        let key = self.key_of(p);
        let v = self.required(&key)?;
        param_number(self.file, &self.field(&key), v, p)
    }

    /// An optional number of the registry entry `p`.
    pub(crate) fn opt_param(&self, p: &Param) -> Result<Option<f64>> {
        let key = self.key_of(p);
        self.get(&key).map(|v| param_number(self.file, &self.field(&key), v, p)).transpose()
    }

    /// The array of numbers of entry `p`, each within its range; of length `len` if given.
    pub(crate) fn param_array(&self, p: &Param, len: Option<usize>) -> Result<Vec<f64>> {
        let key = self.key_of(p);
        let a = self.array(&key)?;
        if let Some(n) = len {
            if a.len() != n {
                return Err(self.err(&key, format!("expected {n} values, got {}", a.len())));
            }
        }
        a.iter().enumerate().map(|(i, v)| param_number(self.file, &self.element(&key, i), v, p)).collect()
    }

    /// The registry entry `p` as a key of this object (for values read by hand, e.g. colours).
    pub(crate) fn param_key(&self, p: &Param) -> String {
        self.key_of(p)
    }
}

/// Check that `v` is a finite number in the range of registry entry `p` (message from its description).
pub(crate) fn param_number(file: &str, path: &str, v: &Value, p: &Param) -> Result<f64> {
    let range = p.range();
    let allowed = range.describe();
    let allowed = allowed.trim_start_matches("in ");
    match v {
        Value::Number(n) => match n.as_f64() {
            Some(x) if range.contains(x) => Ok(x),
            Some(x) if x.is_finite() => Err(Error::input(
                file,
                path,
                format!("{} is out of range; allowed: {allowed} ({})", show(x), p.description),
            )),
            _ => Err(Error::input(file, path, format!("{n} is not a finite number; allowed: {allowed}"))),
        },
        _ => Err(Error::input(
            file,
            path,
            format!("expected a finite number {allowed} ({}), got {}", p.description, kind(v)),
        )),
    }
}
