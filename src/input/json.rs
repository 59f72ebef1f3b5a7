//! A JSON document read with errors that name the file, the field and what is allowed: typed access to an
//! object's fields ([`Obj`]), number checks, and a parser that gives the line and column of a syntax error and
//! refuses a key given twice in one object. Fields are named by RFC 6901 JSON Pointers (`/lobes/0/ks/2`),
//! which can be pasted into a command. Every recipe and geometry parser reads through this, so every bad value
//! is reported the same way; the registry-driven reading of recipe parameters (`Obj::param` and friends) is
//! added in `recipe::fields`.
use crate::registry::{self, Range};
use crate::{Error, Result};
use serde_json::{Map, Value};

/// A JSON object being read, with the file name and the JSON Pointer of the object inside the file.
pub struct Obj<'a> {
    pub file: &'a str,
    /// RFC 6901 pointer of this object (`""` for the root).
    pub path: String,
    pub map: &'a Map<String, Value>,
}
impl<'a> Obj<'a> {
    /// View `v` as an object at the JSON Pointer `path` (empty for the root).
    pub fn new(file: &'a str, path: impl Into<String>, v: &'a Value) -> Result<Self> {
        let path = path.into();
        match v.as_object() {
            Some(map) => Ok(Obj { file, path, map }),
            None => Err(Error::input(file, path, format!("expected a JSON object, got {}", kind(v)))),
        }
    }

    /// JSON Pointer of a child field (the key escaped per RFC 6901).
    pub(crate) fn field(&self, key: &str) -> String {
        registry::child(&self.path, key)
    }

    /// JSON Pointer of element `i` of the array at `key`.
    pub(crate) fn element(&self, key: &str, i: usize) -> String {
        format!("{}/{i}", self.field(key))
    }

    pub(crate) fn err(&self, key: &str, message: impl Into<String>) -> Error {
        Error::input(self.file, self.field(key), message.into())
    }

    /// Refuse any key not in `allowed` (typos must not be silently ignored).
    pub(crate) fn deny_unknown(&self, allowed: &[&str]) -> Result<()> {
        for k in self.map.keys() {
            if !allowed.contains(&k.as_str()) {
                if k.is_empty() {
                    // An empty key would print as no field at all.
                    let at = if self.path.is_empty() { "the top level" } else { self.path.as_str() };
                    return Err(Error::input(
                        self.file,
                        self.field(""),
                        format!("an empty key \"\" at {at} is not a field; allowed here: {}", allowed.join(", ")),
                    ));
                }
                return Err(self.err(k, format!("unknown field; allowed here: {}", allowed.join(", "))));
            }
        }
        Ok(())
    }

    pub(crate) fn get(&self, key: &str) -> Option<&'a Value> {
        self.map.get(key)
    }

    pub(crate) fn required(&self, key: &str) -> Result<&'a Value> {
        self.map.get(key).ok_or_else(|| self.err(key, "missing required field"))
    }

    pub(crate) fn obj(&self, key: &str) -> Result<Obj<'a>> {
        Obj::new(self.file, self.field(key), self.required(key)?)
    }

    pub(crate) fn opt_obj(&self, key: &str) -> Result<Option<Obj<'a>>> {
        self.get(key).map(|v| Obj::new(self.file, self.field(key), v)).transpose()
    }

    pub(crate) fn str(&self, key: &str) -> Result<&'a str> {
        let v = self.required(key)?;
        v.as_str().ok_or_else(|| self.err(key, format!("expected a string, got {}", kind(v))))
    }

    pub(crate) fn opt_str(&self, key: &str) -> Result<Option<&'a str>> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => v.as_str().map(Some).ok_or_else(|| self.err(key, format!("expected a string, got {}", kind(v)))),
        }
    }

    /// A finite number within [lo, hi] (use f64::INFINITY for no upper bound).
    pub(crate) fn num(&self, key: &str, lo: f64, hi: f64, what: &str) -> Result<f64> {
        let v = self.required(key)?;
        number(self.file, &self.field(key), v, lo, hi, what)
    }

    pub(crate) fn opt_num(&self, key: &str, lo: f64, hi: f64, what: &str) -> Result<Option<f64>> {
        self.get(key).map(|v| number(self.file, &self.field(key), v, lo, hi, what)).transpose()
    }

    pub(crate) fn array(&self, key: &str) -> Result<&'a Vec<Value>> {
        let v = self.required(key)?;
        v.as_array().ok_or_else(|| self.err(key, format!("expected an array, got {}", kind(v))))
    }
}

/// Check that `v` is a finite number in [lo, hi]. JSON has no NaN, but a string "NaN" or a huge exponent
/// (which parses to infinity) must be refused too.
pub(crate) fn number(file: &str, path: &str, v: &Value, lo: f64, hi: f64, what: &str) -> Result<f64> {
    let range = if hi.is_infinite() { Range::at_least(lo) } else { Range::closed(lo, hi) };
    number_in(file, path, v, range, what)
}

/// Check that `v` is a finite number in `range`.
pub(crate) fn number_in(file: &str, path: &str, v: &Value, range: Range, what: &str) -> Result<f64> {
    let x = match v {
        Value::Number(n) => n.as_f64(),
        _ => None,
    };
    let allowed = range.describe();
    match x {
        Some(x) if range.contains(x) => Ok(x),
        Some(x) if x.is_finite() => {
            Err(Error::input(file, path, format!("{} is out of range: {what} must be {allowed}", show(x))))
        }
        _ => Err(Error::input(file, path, format!("expected a finite number ({what}, {allowed}), got {}", kind(v)))),
    }
}

/// A number for a message ([`crate::error::number`]).
pub(crate) fn show(x: f64) -> String {
    crate::error::number(x)
}

/// A short description of a JSON value's kind for error messages.
pub(crate) fn kind(v: &Value) -> String {
    match v {
        Value::Null => "null".into(),
        Value::Bool(b) => format!("boolean {b}"),
        Value::Number(n) => format!("number {n}"),
        Value::String(s) if s.len() <= 24 => format!("string {s:?}"),
        Value::String(_) => "a string".into(),
        Value::Array(a) => format!("an array of {}", a.len()),
        Value::Object(_) => "an object".into(),
    }
}

/// Parse JSON text, reporting the line and column of a syntax error. A leading byte-order mark (some
/// editors write one) is skipped; a key that appears twice in an object is refused (JSON parsers disagree on
/// which one wins, so a file that says both is ambiguous).
pub fn parse_json(text: &str, file: &str) -> Result<Value> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let value = serde_json::from_str(text).map_err(|e| {
        // serde_json's message ends with the position, which this message already leads with.
        let message = e.to_string();
        let position = format!(" at line {} column {}", e.line(), e.column());
        let reason = message.strip_suffix(&position).unwrap_or(&message);
        Error::input(file, "", format!("malformed JSON at line {}, column {}: {reason}", e.line(), e.column()))
    })?;
    let duplicate = std::cell::RefCell::new(None);
    let mut de = serde_json::Deserializer::from_str(text);
    if let Err(e) =
        serde::de::DeserializeSeed::deserialize(NoDuplicates { path: String::new(), duplicate: &duplicate }, &mut de)
    {
        let field = duplicate.into_inner().unwrap_or_default();
        return Err(Error::input(
            file,
            field,
            format!(
                "a key appears twice in one object (line {}, column {}); give each field once",
                e.line(),
                e.column()
            ),
        ));
    }
    Ok(value)
}

/// A pass over the JSON text that fails at the first key repeated within one object, recording its path.
struct NoDuplicates<'a> {
    path: String,
    duplicate: &'a std::cell::RefCell<Option<String>>,
}

impl NoDuplicates<'_> {
    fn child(&self, key: &str) -> Self {
        NoDuplicates { path: registry::child(&self.path, key), duplicate: self.duplicate }
    }
}

impl<'de> serde::de::DeserializeSeed<'de> for NoDuplicates<'_> {
    type Value = ();
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> std::result::Result<(), D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> serde::de::Visitor<'de> for NoDuplicates<'_> {
    type Value = ();
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, _: bool) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_i64<E>(self, _: i64) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_u64<E>(self, _: u64) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_f64<E>(self, _: f64) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_str<E>(self, _: &str) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_unit<E>(self) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut a: A) -> std::result::Result<(), A::Error> {
        let mut i = 0;
        while a
            .next_element_seed(NoDuplicates { path: format!("{}/{i}", self.path), duplicate: self.duplicate })?
            .is_some()
        {
            i += 1;
        }
        Ok(())
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut m: A) -> std::result::Result<(), A::Error> {
        let mut seen = std::collections::HashSet::new();
        while let Some(k) = m.next_key::<String>()? {
            if !seen.insert(k.clone()) {
                *self.duplicate.borrow_mut() = Some(self.child(&k).path);
                return Err(serde::de::Error::custom("duplicate key"));
            }
            m.next_value_seed(self.child(&k))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duplicate_keys_are_refused_with_their_path() {
        let e = parse_json(r#"{"model": "lambert", "albedo": 0.5, "albedo": 0.9}"#, "r.json").unwrap_err().to_string();
        assert!(e.contains("r.json") && e.contains("`/albedo`") && e.contains("twice"), "{e}");
        let e = parse_json(r#"{"a": [{"k": 1}, {"k": 2, "k": 3}]}"#, "r.json").unwrap_err().to_string();
        assert!(e.contains("`/a/1/k`"), "{e}");
        assert!(parse_json(r#"{"a": {"k": 1}, "b": {"k": 2}}"#, "r.json").is_ok(), "same key in two objects");
    }

    #[test]
    fn a_byte_order_mark_is_skipped() {
        assert_eq!(parse_json("\u{feff}{\"x\": 1}", "r.json").unwrap()["x"], 1);
    }

    #[test]
    fn a_malformed_document_names_its_position_once() {
        let e = parse_json(r#"{"albedo": 1e309}"#, "r.json").unwrap_err().to_string();
        assert_eq!(e.matches("line 1").count(), 1, "{e}");
        assert!(e.contains("malformed JSON at line 1, column 16: number out of range"), "{e}");
        let e = parse_json(r#"{"model": "lambert","#, "r.json").unwrap_err().to_string();
        assert_eq!(e.matches("line 1").count(), 1, "{e}");
    }

    #[test]
    fn an_empty_key_is_named() {
        let v = parse_json(r#"{"": 1}"#, "r.json").unwrap();
        let e = Obj::new("r.json", "", &v).unwrap().deny_unknown(&["model"]).unwrap_err().to_string();
        assert!(e.contains("empty key") && e.contains("field `/`"), "{e}");
    }

    #[test]
    fn huge_numbers_are_printed_in_scientific_notation() {
        let v = parse_json("1e300", "r.json").unwrap();
        let e = number("r.json", "ior", &v, 1.0, 4.0, "the index").unwrap_err().to_string();
        assert!(e.contains("1e300 is out of range") && e.len() < 120, "{e}");
        assert_eq!(show(1.5), "1.5");
        assert_eq!(show(0.0), "0");
    }
}
