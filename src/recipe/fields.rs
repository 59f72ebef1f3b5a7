//! Typed access to JSON fields with errors that name the file, the field path and what is allowed.
//! Every recipe and geometry parser goes through this, so every bad value is reported the same way.
use crate::{Error, Result};
use serde_json::{Map, Value};

/// A JSON object being read, with the file name and the path of the object inside the file.
pub struct Obj<'a> {
    pub file: &'a str,
    pub path: String,
    pub map: &'a Map<String, Value>,
}

impl<'a> Obj<'a> {
    /// View `v` as an object at `path` (empty for the root).
    pub fn new(file: &'a str, path: impl Into<String>, v: &'a Value) -> Result<Self> {
        let path = path.into();
        match v.as_object() {
            Some(map) => Ok(Obj { file, path, map }),
            None => Err(Error::input(file, path, format!("expected a JSON object, got {}", kind(v)))),
        }
    }

    /// Full path of a child field.
    pub fn field(&self, key: &str) -> String {
        if self.path.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", self.path)
        }
    }

    pub fn err(&self, key: &str, message: impl Into<String>) -> Error {
        Error::input(self.file, self.field(key), message)
    }

    /// Refuse any key not in `allowed` (typos must not be silently ignored).
    pub fn deny_unknown(&self, allowed: &[&str]) -> Result<()> {
        for k in self.map.keys() {
            if !allowed.contains(&k.as_str()) {
                return Err(self.err(k, format!("unknown field; allowed here: {}", allowed.join(", "))));
            }
        }
        Ok(())
    }

    pub fn get(&self, key: &str) -> Option<&'a Value> {
        self.map.get(key)
    }

    pub fn required(&self, key: &str) -> Result<&'a Value> {
        self.map.get(key).ok_or_else(|| self.err(key, "missing required field"))
    }

    pub fn obj(&self, key: &str) -> Result<Obj<'a>> {
        Obj::new(self.file, self.field(key), self.required(key)?)
    }

    pub fn opt_obj(&self, key: &str) -> Result<Option<Obj<'a>>> {
        self.get(key).map(|v| Obj::new(self.file, self.field(key), v)).transpose()
    }

    pub fn str(&self, key: &str) -> Result<&'a str> {
        let v = self.required(key)?;
        v.as_str().ok_or_else(|| self.err(key, format!("expected a string, got {}", kind(v))))
    }

    pub fn opt_str(&self, key: &str) -> Result<Option<&'a str>> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => v.as_str().map(Some).ok_or_else(|| self.err(key, format!("expected a string, got {}", kind(v)))),
        }
    }

    /// A finite number within [lo, hi] (use f64::INFINITY for no upper bound).
    pub fn num(&self, key: &str, lo: f64, hi: f64, what: &str) -> Result<f64> {
        let v = self.required(key)?;
        number(self.file, &self.field(key), v, lo, hi, what)
    }

    pub fn opt_num(&self, key: &str, lo: f64, hi: f64, what: &str) -> Result<Option<f64>> {
        self.get(key).map(|v| number(self.file, &self.field(key), v, lo, hi, what)).transpose()
    }

    pub fn array(&self, key: &str) -> Result<&'a Vec<Value>> {
        let v = self.required(key)?;
        v.as_array().ok_or_else(|| self.err(key, format!("expected an array, got {}", kind(v))))
    }

    /// An array of numbers each within [lo, hi]; if `len` is given the array must have that length.
    pub fn num_array(&self, key: &str, len: Option<usize>, lo: f64, hi: f64, what: &str) -> Result<Vec<f64>> {
        let a = self.array(key)?;
        if let Some(n) = len {
            if a.len() != n {
                return Err(self.err(key, format!("expected {n} values, got {}", a.len())));
            }
        }
        a.iter()
            .enumerate()
            .map(|(i, v)| number(self.file, &format!("{}[{i}]", self.field(key)), v, lo, hi, what))
            .collect()
    }
}

/// Check that `v` is a finite number in [lo, hi]. JSON has no NaN, but a string "NaN" or a huge exponent
/// (which parses to infinity) must be refused too.
pub fn number(file: &str, path: &str, v: &Value, lo: f64, hi: f64, what: &str) -> Result<f64> {
    let x = match v {
        Value::Number(n) => n.as_f64(),
        _ => None,
    };
    let range = if hi.is_infinite() { format!("≥ {lo}") } else { format!("in [{lo}, {hi}]") };
    match x {
        Some(x) if x.is_finite() && x >= lo && x <= hi => Ok(x),
        Some(x) if x.is_finite() => {
            Err(Error::input(file, path, format!("{x} is out of range: {what} must be {range}")))
        }
        _ => Err(Error::input(file, path, format!("expected a finite number ({what}, {range}), got {}", kind(v)))),
    }
}

/// A short description of a JSON value's kind for error messages.
pub fn kind(v: &Value) -> String {
    match v {
        Value::Null => "null".into(),
        Value::Bool(b) => format!("boolean {b}"),
        Value::Number(n) => format!("number {n}"),
        Value::String(s) if s.len() <= 24 => format!("string \"{s}\""),
        Value::String(_) => "a string".into(),
        Value::Array(a) => format!("an array of {}", a.len()),
        Value::Object(_) => "an object".into(),
    }
}

/// Parse JSON text, reporting the line and column of a syntax error.
pub fn parse_json(text: &str, file: &str) -> Result<Value> {
    serde_json::from_str(text)
        .map_err(|e| Error::input(file, "", format!("malformed JSON at line {}, column {}: {e}", e.line(), e.column())))
}
