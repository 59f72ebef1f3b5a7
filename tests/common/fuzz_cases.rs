//! The fuzz campaign's cases and checks, shared by the property tests (`tests/fuzz.rs`, bounded, in
//! `cargo test`) and the hand-run driver (`examples/fuzz.rs`, 10⁶ cases; results in docs/reliability.md).
//!
//! Cases are generated or mutated from the shipped inputs: recipes (`fixtures/recipes`, `fixtures/bad`),
//! geometry files (`standards/`, `fixtures/geometry`) and sheets (`fixtures/sheets`). The check is the
//! contract of docs/instrument.md: an input is either accepted, or refused with an input error that names
//! the file and either a field or a line; never a panic, and a reading is never NaN or infinite.
#![allow(dead_code)]
use std::path::{Path, PathBuf};

use glossmeter::comparison::sheet;
use glossmeter::instrument::standards;
use glossmeter::{recipe, Error};

/// A small deterministic generator (xorshift64*), so every case can be replayed from its seed.
#[derive(Clone, Debug)]
pub struct Rng(pub u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    pub fn pick<'a, T>(&mut self, xs: &'a [T]) -> &'a T {
        &xs[self.below(xs.len())]
    }
    pub fn chance(&mut self, p: f64) -> bool {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 <= p
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Category {
    GeneratedRecipe,
    MutatedRecipe,
    MutatedGeometry,
    Sheet,
    MerlTable,
    CommandLine,
}

impl Category {
    pub const ALL: [Category; 6] = [
        Category::GeneratedRecipe,
        Category::MutatedRecipe,
        Category::MutatedGeometry,
        Category::Sheet,
        Category::MerlTable,
        Category::CommandLine,
    ];
    pub fn name(self) -> &'static str {
        match self {
            Category::GeneratedRecipe => "generated recipes",
            Category::MutatedRecipe => "mutated recipes",
            Category::MutatedGeometry => "mutated geometry files",
            Category::Sheet => "generated and mutated sheets",
            Category::MerlTable => "generated MERL tables",
            Category::CommandLine => "command lines",
        }
    }
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn texts(dir: &str, ext: &str) -> Vec<String> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join(dir))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    files.sort();
    // Windows-1252 sheets are seeds too (as text, their one non-UTF-8 byte replaced).
    files.iter().map(|p| String::from_utf8_lossy(&std::fs::read(p).unwrap()).into_owned()).collect()
}

/// The shipped inputs the mutations start from.
pub struct Seeds {
    pub recipes: Vec<String>,
    pub geometries: Vec<String>,
    pub sheets: Vec<String>,
}

impl Seeds {
    pub fn load() -> Seeds {
        let mut recipes = texts("fixtures/recipes", "json");
        recipes.extend(texts("fixtures/bad", "json"));
        let mut geometries = texts("standards", "json");
        geometries.extend(texts("fixtures/geometry", "json"));
        // User files may not take shipped ids: the shipped files are mutated under a user id.
        for g in geometries.iter_mut() {
            if let Some(i) = g.find("\"id\": \"") {
                g.insert_str(i + 7, "user-");
            }
        }
        Seeds { recipes, geometries, sheets: texts("fixtures/sheets", "csv") }
    }
}

/// Numbers that break naive code: zero, signs, the ends of f64, subnormals, overflow, near-integers.
const NUMBERS: &[&str] = &[
    "0",
    "-0",
    "1",
    "-1",
    "0.5",
    "1e308",
    "-1e308",
    "1e400",
    "1e-320",
    "5e-324",
    "2.2250738585072014e-308",
    "1e-300",
    "100000",
    "1.0000000001",
    "0.9999999999",
    "128",
    "129",
    "830",
    "831",
    "360",
    "359",
    "1e9",
    "1e10",
    "3.5",
    "-1e-9",
    "\"NaN\"",
    "\"inf\"",
    "null",
    "true",
    "[]",
    "{}",
    "[1,2,3]",
    "\"\"",
];

/// Bytes and snippets that break naive parsers.
const SNIPPETS: &[&str] = &[
    "{",
    "}",
    "[",
    "]",
    ",",
    ":",
    "\"",
    "\\",
    "\n",
    "\u{feff}",
    "#",
    "-",
    ".",
    "e",
    "E",
    "0",
    "9",
    " ",
    "\"\": 1,",
    "\"model\": \"lambert\",",
    "\u{0}",
    "é",
    "\r\n",
];

/// Apply 1–4 random edits: delete or duplicate a span, insert a snippet, replace a number, truncate, swap
/// lines, duplicate a line (a duplicate key), prepend a byte-order mark.
pub fn mutate(text: &str, rng: &mut Rng) -> String {
    let mut s: Vec<char> = text.chars().collect();
    for _ in 0..1 + rng.below(4) {
        let n = s.len().max(1);
        match rng.below(9) {
            0 => {
                let a = rng.below(n);
                let b = (a + 1 + rng.below(8)).min(s.len());
                if a < b {
                    s.drain(a..b);
                }
            }
            1 => {
                let at = rng.below(s.len() + 1);
                let ins: Vec<char> = rng.pick(SNIPPETS).chars().collect();
                s.splice(at..at, ins);
            }
            2 | 3 => {
                // Replace the k-th number.
                let starts: Vec<usize> = (0..s.len())
                    .filter(|&i| {
                        (s[i].is_ascii_digit() || s[i] == '-') && (i == 0 || !s[i - 1].is_ascii_alphanumeric())
                    })
                    .collect();
                if let Some(&a) = starts.get(rng.below(starts.len())) {
                    let mut b = a + 1;
                    while b < s.len() && (s[b].is_ascii_digit() || "eE.+-".contains(s[b])) {
                        b += 1;
                    }
                    let ins: Vec<char> = rng.pick(NUMBERS).chars().collect();
                    s.splice(a..b, ins);
                }
            }
            4 => {
                let cut = rng.below(n);
                s.truncate(cut);
            }
            5 | 6 => {
                let text: String = s.iter().collect();
                let mut lines: Vec<&str> = text.lines().collect();
                if lines.len() > 2 {
                    let i = 1 + rng.below(lines.len() - 2);
                    if rng.chance(0.5) {
                        lines.insert(i, lines[i]);
                    } else {
                        let j = 1 + rng.below(lines.len() - 2);
                        lines.swap(i, j);
                    }
                }
                s = lines.join("\n").chars().collect();
            }
            7 => s.insert(0, '\u{feff}'),
            _ => {
                let a = rng.below(n);
                let b = (a + 1 + rng.below(40)).min(s.len());
                if a < b {
                    let dup: Vec<char> = s[a..b].to_vec();
                    s.splice(b..b, dup);
                }
            }
        }
    }
    s.into_iter().collect()
}

/// Field names of every model, and values to give them.
const KEYS: &[&str] = &[
    "ior",
    "albedo",
    "distribution",
    "roughness",
    "shadowing",
    "exponent",
    "kd",
    "ks",
    "rho_d",
    "rho_s",
    "alpha",
    "lobes",
    "name",
    "notes",
    "file",
    "interpolation",
    "clear_coat",
    "pigmented_layer",
    "metallic_flakes",
    "pearlescent_flakes",
    "wavelengths_nm",
    "form",
    "",
];
const VALUES: &[&str] = &[
    "1.5",
    "0.5",
    "0",
    "1",
    "-1",
    "1e400",
    "1e-300",
    "\"beckmann\"",
    "\"ggx\"",
    "\"smith\"",
    "\"v-cavity\"",
    "[0.2, 0.3, 0.4]",
    "[0.2, 0.3]",
    "[[0.2, 3.0], [0.1, 2.0], [0.5, 1.0]]",
    "[{\"ks\": 0.5, \"m\": 0.1, \"f0\": 0.04}]",
    "{\"ior\": 1.5}",
    "[400, 500, 600]",
    "[830, 781]",
    "\"physical\"",
    "\"paper-eq1\"",
    "null",
    "\"x\"",
    "{}",
    "[]",
    "[1.5, 0.0]",
    "[[0.2, 3.0]]",
];

/// A recipe assembled from a random model and random fields with random values.
pub fn generate_recipe(rng: &mut Rng) -> String {
    let mut fields = vec![format!("\"model\": \"{}\"", rng.pick(recipe::MODELS))];
    for _ in 0..rng.below(5) {
        fields.push(format!("\"{}\": {}", rng.pick(KEYS), rng.pick(VALUES)));
    }
    format!("{{{}}}", fields.join(", "))
}

/// A sheet assembled from random rows, or a mutated shipped one.
pub fn generate_sheet(rng: &mut Rng, seeds: &Seeds) -> String {
    if rng.chance(0.5) {
        let base: &String = rng.pick(&seeds.sheets);
        return mutate(base, rng);
    }
    let ids = ["astm-d523-20", "astm-d523-60", "astm-d523-85", "astm-e430-30", "iso-13803-20", "astm-d4039", "nope"];
    let readings = ["gloss", "haze", "doi", "haze-narrow", "log-haze", "haze-index", "", "x"];
    let mut s = String::new();
    if rng.chance(0.2) {
        s.push('\u{feff}');
    }
    if rng.chance(0.3) {
        s.push_str("# instrument\n\n");
    }
    s.push_str(if rng.chance(0.8) { "sample,geometry,quantity,value,uncertainty\n" } else { "sample,20,60,85\n" });
    for _ in 0..rng.below(6) {
        if rng.chance(0.1) {
            s.push('\n');
        }
        let v = rng.pick(&["89.1", "0", "-3", "1e400", "NaN", "x", "", "\"1,5\""]);
        let u = rng.pick(&["0.5", "", "-1", "0", "1e308"]);
        s.push_str(&format!("\"p\n{}\",{},{},{v},{u}\n", rng.below(9), rng.pick(&ids), rng.pick(&readings)));
    }
    s
}

/// What a case came to.
#[derive(Debug)]
pub enum Outcome {
    /// Accepted (a recipe: the material, to be measured if the caller wishes).
    Accepted(Option<recipe::Material>),
    /// Refused with a well-formed error.
    Refused,
}

/// The contract on an error for an input file `file`: an input error naming the file, and a field, a line, or
/// the whole file with a reason (malformed JSON with its line; not an object; too large); a usage error (e.g.
/// an unknown geometry id) naming what is unknown. Anything else is a violation, returned as Err.
pub fn check_error(e: &Error, file: &str) -> Result<(), String> {
    let shown = e.to_string();
    if prints_non_finite(&shown) {
        return Err(format!("an error prints a non-finite number (outside the quoted input): {shown}"));
    }
    match e {
        Error::Input { file: f, field, message } => {
            if f != file {
                return Err(format!("error names {f}, not {file}: {shown}"));
            }
            if field.is_empty()
                && !(message.contains("line") || message.contains("JSON object") || message.contains("no readings"))
            {
                return Err(format!("an input error with neither field nor line: {shown}"));
            }
            Ok(())
        }
        Error::Usage(m) if m.contains("geometry") => Ok(()),
        other => Err(format!("not an input error: {other:?}")),
    }
}

/// Run one case of a category; Err is a violation of the contract (a panic is caught by the caller).
pub fn run_case(cat: Category, text: &str) -> Result<Outcome, String> {
    match cat {
        Category::GeneratedRecipe | Category::MutatedRecipe => match recipe::parse_str(text, "fuzz.json") {
            Ok(m) => Ok(Outcome::Accepted(Some(m))),
            Err(e) => check_error(&e, "fuzz.json").map(|_| Outcome::Refused),
        },
        Category::MerlTable => {
            let r = match recipe::parse_str(text, "fuzz.json") {
                Ok(m) => Ok(Outcome::Accepted(Some(m))),
                Err(e) => check_error(&e, "fuzz.json").map(|_| Outcome::Refused),
            };
            // The table is in memory once parsed: the scratch file can go.
            if let Some(f) =
                serde_json::from_str::<serde_json::Value>(text).ok().and_then(|v| v["file"].as_str().map(String::from))
            {
                let _ = std::fs::remove_file(f);
            }
            r
        }
        Category::CommandLine => run_cli(text),
        Category::MutatedGeometry => {
            let r = standards::parse(text, "fuzz-geometry.json")
                .and_then(|g| standards::builtin().and_then(|b| standards::check_user(&g, &b)));
            match r {
                Ok(()) => Ok(Outcome::Accepted(None)),
                Err(e) => check_error(&e, "fuzz-geometry.json").map(|_| Outcome::Refused),
            }
        }
        Category::Sheet => match sheet::parse(text, "fuzz.csv", &sheet::SheetOptions::default()) {
            Ok(sheet) => {
                let rows = sheet.rows;
                if rows.iter().any(|r| !r.value.is_finite() || r.uncertainty.is_some_and(|u| !u.is_finite())) {
                    return Err("a sheet row holds a non-finite number".into());
                }
                Ok(Outcome::Accepted(None))
            }
            Err(e) => check_error(&e, "fuzz.csv").map(|_| Outcome::Refused),
        },
    }
}

/// The text of case `k` of a category (deterministic in `seed`).
pub fn case_text(cat: Category, seeds: &Seeds, rng: &mut Rng) -> String {
    match cat {
        // Three in four from the parameter registry (mostly valid), one in four from random fields.
        Category::GeneratedRecipe if rng.chance(0.75) => generate_registry_recipe(rng),
        Category::GeneratedRecipe => generate_recipe(rng),
        Category::MerlTable => generate_merl(rng),
        Category::CommandLine => generate_cli(rng, true),
        Category::MutatedRecipe => {
            let base: &String = rng.pick(&seeds.recipes);
            mutate(base, rng)
        }
        Category::MutatedGeometry => {
            let base: &String = rng.pick(&seeds.geometries);
            mutate(base, rng)
        }
        Category::Sheet => generate_sheet(rng, seeds),
    }
}

/// Check readings: every value finite, or none with a reason; every error estimate of a value finite ≥ 0.
pub fn check_readings(readings: &[glossmeter::Reading]) -> Result<(), String> {
    for r in readings {
        match r.value {
            Some(v) if !(v.is_finite() && r.error_estimate.is_finite() && r.error_estimate >= 0.0) => {
                return Err(format!("{} {}: value {v} ± {}", r.geometry, r.name, r.error_estimate))
            }
            None if r.problem.is_none() => return Err(format!("{} {}: no value and no reason", r.geometry, r.name)),
            _ => {}
        }
    }
    Ok(())
}

/// Where the driver and tests put the files they write.
pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("glossmeter-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

pub fn exists(p: &Path) -> bool {
    p.exists()
}

// ---------------------------------------------------------------------------------------------------------
// What glossmeter printed: a non-finite number of its own, outside the user's quoted text.
// ---------------------------------------------------------------------------------------------------------

/// `s` with every quoted part removed ("…" with \" escapes, `…`, and clap's '…'): what remains is
/// glossmeter's own text. Error messages quote the user's input (`got string "NaN-"`, `expected a number,
/// got "NaN,1"`, `` `inf` `` for a number given on the command line), which may spell anything. A quote that
/// is never closed quotes nothing (the rest is kept), so an unbalanced quote cannot hide glossmeter's text.
pub fn unquoted(s: &str) -> String {
    let chars: Vec<char> = s.chars().collect();
    let mut out = String::with_capacity(s.len());
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        // clap quotes a value as 'NaN'; an apostrophe inside a word ("doesn't") opens nothing.
        let word = |k: usize| chars.get(k).is_some_and(|d| d.is_alphanumeric());
        let opens = c == '"' || c == '`' || (c == '\'' && (i == 0 || !word(i - 1)));
        if opens {
            // The matching close: the next unescaped `"` (escapes only inside "…"), the next backquote, or the
            // next ' that ends a word.
            let mut j = i + 1;
            let mut close = None;
            while j < chars.len() {
                if c == '"' && chars[j] == '\\' {
                    j += 2;
                    continue;
                }
                if chars[j] == c && (c != '\'' || !word(j + 1)) {
                    close = Some(j);
                    break;
                }
                j += 1;
            }
            if let Some(j) = close {
                out.push(c);
                out.push(c);
                i = j + 1;
                continue;
            }
        }
        out.push(c);
        i += 1;
    }
    out
}

/// Whether glossmeter's own text (outside quotes) shows a non-finite number: NaN, inf or infinity as a word.
pub fn prints_non_finite(s: &str) -> bool {
    unquoted(s)
        .split(|c: char| !c.is_ascii_alphanumeric())
        .any(|w| matches!(w.to_ascii_lowercase().as_str(), "nan" | "inf" | "infinity"))
}

// ---------------------------------------------------------------------------------------------------------
// Recipes from the parameter registry: every field of a model, in its range.
// ---------------------------------------------------------------------------------------------------------

/// A number in `range`: an end (if closed), just inside an end, or a random interior point (log-uniform
/// above the lower end when the range is unbounded).
fn number_in(range: glossmeter::registry::Range, rng: &mut Rng) -> f64 {
    let u = (rng.next() >> 11) as f64 / (1u64 << 53) as f64;
    let (lo, hi) = (range.lo, range.hi);
    let x = match rng.below(6) {
        0 if range.lo_closed => lo,
        1 if range.hi_closed && hi.is_finite() => hi,
        2 => {
            if hi.is_finite() {
                lo + (hi - lo) * 1e-9
            } else {
                lo + 1e-9 * lo.abs().max(1.0)
            }
        }
        _ if hi.is_finite() => lo + (hi - lo) * u,
        _ => lo + 10f64.powf(-3.0 + 5.0 * u),
    };
    if range.contains(x) {
        x
    } else {
        // An open end that was hit: the middle of the range, or just above an open lower end.
        if hi.is_finite() {
            0.5 * (lo + hi)
        } else {
            lo + 1.0
        }
    }
}

fn conductor_ior(rng: &mut Rng) -> serde_json::Value {
    use glossmeter::registry::{CONDUCTOR_K_RANGE, CONDUCTOR_N_RANGE};
    let pair =
        |rng: &mut Rng| serde_json::json!([number_in(CONDUCTOR_N_RANGE, rng), number_in(CONDUCTOR_K_RANGE, rng)]);
    if rng.chance(0.7) {
        pair(rng)
    } else {
        serde_json::Value::Array((0..3).map(|_| pair(rng)).collect())
    }
}

/// The value of one registry entry (and, for objects, of the entries below it).
fn registry_value(model: &str, e: &glossmeter::registry::Param, samples: usize, rng: &mut Rng) -> serde_json::Value {
    use glossmeter::registry::Type;
    use serde_json::{json, Value};
    let num = |rng: &mut Rng| json!(number_in(e.range.expect("numeric entries have a range"), rng));
    match e.ty {
        Type::Number => num(rng),
        Type::Colour | Type::NumberOrSpectral if rng.chance(0.5) => num(rng),
        Type::Colour => Value::Array((0..3).map(|_| num(rng)).collect()),
        Type::Spectral | Type::NumberOrSpectral => Value::Array((0..samples).map(|_| num(rng)).collect()),
        Type::Numbers => {
            let mut w: Vec<f64> = (0..samples).map(|_| number_in(e.range.unwrap(), rng).round()).collect();
            w.sort_by(f64::total_cmp);
            w.dedup();
            json!(w)
        }
        Type::Choice(c) => json!(rng.pick(c)),
        Type::Bool => json!(rng.chance(0.5)),
        Type::Text => json!("fuzz"),
        Type::Notes => json!("a note"),
        Type::Object => Value::Object(registry_object(model, e.pointer, samples, rng)),
        Type::Objects => Value::Array(
            (0..1 + rng.below(3))
                .map(|_| Value::Object(registry_object(model, &format!("{}/*", e.pointer), samples, rng)))
                .collect(),
        ),
        Type::ConductorIor => conductor_ior(rng),
        Type::DielectricOrConductorIor if rng.chance(0.5) => num(rng),
        Type::DielectricOrConductorIor => conductor_ior(rng),
    }
}

/// The object at pattern `prefix` of a `model` recipe: its required fields, and each optional one with
/// probability 1/2.
fn registry_object(
    model: &str,
    prefix: &str,
    samples: usize,
    rng: &mut Rng,
) -> serde_json::Map<String, serde_json::Value> {
    use glossmeter::registry::{self, Presence};
    let depth = registry::tokens(prefix).map_or(0, |t| t.len());
    let mut obj = serde_json::Map::new();
    for e in registry::of_model(model) {
        let Some(t) = registry::tokens(e.pointer) else { continue };
        if t.len() != depth + 1 || !e.pointer.starts_with(&format!("{prefix}/")) {
            continue;
        }
        if e.pointer == "/model" || e.pointer == "/wavelengths_nm" || e.pointer == "/file" {
            continue;
        }
        // An array element's fields (…/ior/0) belong to its array's value.
        if registry::is_index(t[depth]) {
            continue;
        }
        if e.presence == Presence::Required || rng.chance(0.5) {
            obj.insert(e.key(), registry_value(model, e, samples, rng));
        }
    }
    obj
}

/// A recipe built from the registry: a random model and its fields in their ranges (cross-field rules such
/// as kd + ks ≤ 1 or one pigment description of two are left to chance, so some are refused).
pub fn generate_registry_recipe(rng: &mut Rng) -> String {
    use serde_json::{json, Value};
    let model = *rng.pick(glossmeter::registry::MODELS);
    let spectral = model == "paint" && rng.chance(0.3);
    let samples = if spectral { 1 + rng.below(5) } else { 3 };
    let mut obj = registry_object(model, "", samples, rng);
    obj.insert("model".into(), json!(model));
    if spectral {
        let w: Vec<f64> = (0..samples).map(|i| 400.0 + 80.0 * i as f64).collect();
        obj.insert("wavelengths_nm".into(), json!(w));
    }
    if model == "merl" {
        let f = root().join("fixtures/materials/merl/lambert-tiny.binary");
        obj.insert("file".into(), json!(f.to_string_lossy()));
    }
    Value::Object(obj).to_string()
}

// ---------------------------------------------------------------------------------------------------------
// MERL tables: random headers, sizes and values, written to a scratch file.
// ---------------------------------------------------------------------------------------------------------

/// A random MERL `.binary` (small or nonsense dimensions; exact, short or long bodies; values finite,
/// negative, NaN or infinite) written to a scratch file, and a recipe that reads it.
pub fn generate_merl(rng: &mut Rng) -> String {
    let dim = |rng: &mut Rng| -> i32 {
        match rng.below(20) {
            0 => 0,
            1 => -3,
            2 => 100_000,
            _ => 1 + rng.below(8) as i32,
        }
    };
    let dims = [dim(rng), dim(rng), dim(rng)];
    let n = if dims.iter().all(|d| (1..=8).contains(d)) { dims.iter().map(|d| *d as usize).product() } else { 8 };
    let count = match rng.below(10) {
        0 => rng.below(3 * n),
        1 => 3 * n + 1 + rng.below(4),
        _ => 3 * n,
    };
    let mut bytes: Vec<u8> = dims.iter().flat_map(|d| d.to_le_bytes()).collect();
    for _ in 0..count {
        let u = (rng.next() >> 11) as f64 / (1u64 << 53) as f64;
        let v = match rng.below(40) {
            0 => f64::NAN,
            1 => f64::INFINITY,
            2 | 3 => -1.0,
            4 => 1e300,
            _ => 3000.0 * u,
        };
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    if rng.chance(0.05) {
        bytes.truncate(rng.below(12));
    }
    let path = scratch(&format!("merl-{:016x}.binary", rng.next()));
    std::fs::write(&path, &bytes).unwrap();
    let interpolation = rng.pick(&["nearest", "trilinear", "nearest", "cubic"]);
    serde_json::json!({"model": "merl", "file": path.to_string_lossy(), "interpolation": interpolation}).to_string()
}

// ---------------------------------------------------------------------------------------------------------
// Command lines: random subcommands, options and values, run as a process.
// ---------------------------------------------------------------------------------------------------------

const CLI_NUMBERS: &[&str] =
    &["1e-3", "1e-2", "1e-12", "1e-13", "0", "-1", "1", "2", "NaN", "inf", "-inf", "1e999", "x", "1e-300", ""];
const CLI_IDS: &[&str] =
    &["astm-d523-20", "astm-d523-60", "astm-d523-85", "astm-e430-30", "iso-13803-20", "astm-d4039", "nope", ""];

fn files(dir: &str, ext: &str) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(root().join(dir))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .map(|p| p.strip_prefix(root()).unwrap().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The value of option `opt` in a generated command line.
fn cli_value(opt: &str, rng: &mut Rng) -> String {
    let paths = ["@NEW", "@NEW", "@NEW", "Cargo.toml", "fixtures", "/dev/full", "/nonexistent/dir/x.txt", ""];
    match opt {
        "-g" => rng.pick(CLI_IDS).to_string(),
        "--rtol" | "--max-seconds" | "-k" | "--tolerance" | "--max-de00" | "--min-time-ms" => {
            rng.pick(CLI_NUMBERS).to_string()
        }
        "--tolerances" => {
            rng.pick(&["1e-2,1e-3", "1e-2", "0.5,1e-3", "NaN", "x", "", "1e-2,,1e-3", "1e-20"]).to_string()
        }
        "--max-evals" | "--max-repetitions" => {
            rng.pick(&["0", "1", "100", "20000", "-1", "x", "NaN", "99999999999999999999"]).to_string()
        }
        "--format" => rng.pick(&["table", "json", "csv", "junit", "xml", ""]).to_string(),
        "--illuminant" => rng.pick(&["D65", "D50", "A", "C", "F2", ""]).to_string(),
        "--observer" => rng.pick(&["10", "2", "5", ""]).to_string(),
        "--delimiter" => rng.pick(&[",", ";", "\\t", "ab", ""]).to_string(),
        "-o" | "--plot" => rng.pick(&paths).to_string(),
        "--geometry-file" => {
            let mut g = files("fixtures/geometry", "json");
            g.push("nope.json".into());
            rng.pick(&g).clone()
        }
        _ => String::new(),
    }
}

/// One random argument vector (without the program name), as a JSON array of strings. Paths are relative to
/// the crate root (the process runs there); `@NEW` stands for a fresh scratch path. `cheap`: the readings
/// get a small budget first (`--max-seconds 1` for `measure`, `--rtol 1e-3` for `compare`; a second
/// budget given at random is then a usage error, exit 2), so that 10⁴ command lines fit in minutes.
pub fn generate_cli(rng: &mut Rng, cheap: bool) -> String {
    let mut recipes = files("fixtures/recipes", "json");
    recipes.retain(|r| !r.contains("bench-b3")); // keep the run fast; the panel is fuzzed in the library
    recipes.extend(files("fixtures/bad", "json"));
    recipes.extend(["nope.json", "fixtures", "/dev/null", "", "-"].map(String::from));
    let mut sheets = files("fixtures/sheets", "csv");
    sheets.extend(files("fixtures/sheets/bad", "csv"));
    let mut a: Vec<String> = Vec::new();
    let sub = *rng.pick(&[
        "measure",
        "measure",
        "measure",
        "compare",
        "compare",
        "convergence",
        "standards",
        "schema",
        "help",
        "bogus",
        "--version",
        "-h",
    ]);
    a.push(sub.into());
    let options: &[&str] = match sub {
        "measure" => &[
            "-g",
            "-g",
            "--rtol",
            "--format",
            "--explain",
            "--no-timing",
            "--allow-unconverged",
            "--max-evals",
            "--max-seconds",
            "-o",
            "--geometry-file",
            "--illuminant",
            "--observer",
            "--envelope",
            "--bogus",
        ],
        "compare" => &[
            "--rtol",
            "--format",
            "-k",
            "--tolerance",
            "-o",
            "--plot",
            "--allow-unconverged",
            "--max-de00",
            "--delimiter",
            "--illuminant",
            "--bogus",
        ],
        "convergence" => &["-g", "--format", "--plot", "-o", "--min-time-ms", "--max-repetitions", "--bogus"],
        _ => &[],
    };
    match sub {
        "measure" | "compare" | "convergence" => {
            a.push(rng.pick(&recipes).clone());
            if sub == "compare" {
                a.push(if rng.chance(0.9) { rng.pick(&sheets).clone() } else { "nope.csv".into() });
            }
            if cheap && sub == "measure" {
                a.extend(["--max-seconds".into(), "1".into()]);
            }
            if cheap && sub == "compare" {
                a.extend(["--rtol".into(), "1e-3".into()]);
            }
            if sub == "convergence" {
                let t = cli_value("--tolerances", rng);
                a.extend(["--tolerances".into(), t, "--max-repetitions".into(), "1".into()]);
                a.extend(["--min-time-ms".into(), "0".into(), "-g".into(), "astm-d523-60".into()]);
            }
            for _ in 0..rng.below(5) {
                let opt = *rng.pick(options);
                a.push(opt.into());
                if rng.chance(0.05) {
                    break; // an option without its value, at the end
                }
                let v = cli_value(opt, rng);
                if !v.is_empty() || rng.chance(0.3) {
                    a.push(v);
                }
            }
        }
        "standards" => {
            if rng.chance(0.7) {
                a.push(rng.pick(CLI_IDS).to_string());
            }
        }
        "schema" => {
            if rng.chance(0.5) {
                a.extend(["--output-format".into(), rng.pick(&["measure", "compare", "sweep", "fit", ""]).to_string()]);
            }
        }
        _ => {
            if rng.chance(0.3) {
                a.push("--bogus".into());
            }
        }
    }
    serde_json::to_string(&a).unwrap()
}

/// `out` with the command line's own arguments (file names such as `fixtures/bad/nan-string.json`, echoed
/// unquoted at the head of an error) replaced by a space, so that only glossmeter's own text is checked.
pub fn without_args(out: &str, args: &[String]) -> String {
    let mut s = out.to_string();
    let mut args: Vec<&String> = args.iter().filter(|a| a.chars().count() > 2).collect();
    args.sort_by_key(|a| std::cmp::Reverse(a.len()));
    for a in args {
        s = s.replace(a.as_str(), " ");
    }
    s
}

/// The binary that CLI cases run (set by the test or the driver before the first case).
pub static BINARY: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();

/// A command line that has not ended after this long is a hang (its readings have a 6 s budget at most).
pub const CLI_TIMEOUT_S: f64 = 120.0;

/// Run one command line; the contract: exit 0, 1 or 2 (never a panic's 101 or a signal), within
/// [`CLI_TIMEOUT_S`]; "error: …" on stderr for 2, no panic message, no non-finite number printed outside
/// quotes, and no silent loss: a new `-o`/`--plot` file exists (and is not empty) after exit 0 or 1, and does
/// not exist at all after exit 2.
pub fn run_cli(text: &str) -> Result<Outcome, String> {
    let args: Vec<String> = serde_json::from_str(text).map_err(|e| format!("bad case {text}: {e}"))?;
    // Names of their own: tests run command lines from several threads of one process.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let mut new_files = Vec::new();
    let args: Vec<String> = args
        .into_iter()
        .map(|a| {
            if a == "@NEW" {
                let p = scratch(&format!("cli-{n}-{}.out", new_files.len()));
                let _ = std::fs::remove_file(&p);
                new_files.push(p.clone());
                p.to_string_lossy().into_owned()
            } else {
                a
            }
        })
        .collect();
    let bin = BINARY.get().ok_or("BINARY not set")?;
    // Output to files (no pipe to drain while waiting), the process polled against a timeout.
    let (out_path, err_path) = (scratch(&format!("cli-stdout-{n}")), scratch(&format!("cli-stderr-{n}")));
    let mut child = std::process::Command::new(bin)
        .args(&args)
        .current_dir(root())
        .stdin(std::process::Stdio::null())
        .stdout(std::fs::File::create(&out_path).unwrap())
        .stderr(std::fs::File::create(&err_path).unwrap())
        .spawn()
        .map_err(|e| format!("cannot run {}: {e}", bin.display()))?;
    let t0 = std::time::Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break s,
            Ok(None) if t0.elapsed().as_secs_f64() > CLI_TIMEOUT_S => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(format!("a hang: {args:?} still running after {CLI_TIMEOUT_S} s"));
            }
            Ok(None) => std::thread::sleep(std::time::Duration::from_millis(1)),
            Err(e) => return Err(format!("wait: {e}")),
        }
    };
    let stdout = String::from_utf8_lossy(&std::fs::read(&out_path).unwrap_or_default()).into_owned();
    let stderr = String::from_utf8_lossy(&std::fs::read(&err_path).unwrap_or_default()).into_owned();
    let code = status.code();
    let fail = |why: &str| Err(format!("{why}: {args:?} → {code:?}\nstderr: {stderr}"));
    let verdict = if !matches!(code, Some(0..=2)) {
        fail("exit status outside 0–2")
    } else if stderr.contains("panicked") {
        fail("a panic message")
    } else if code == Some(2) && !stderr.contains("error") {
        fail("exit 2 without an error message")
    } else if prints_non_finite(&without_args(&stdout, &args)) || prints_non_finite(&without_args(&stderr, &args)) {
        fail("a non-finite number printed")
    } else {
        let mut v = Ok(if code == Some(2) { Outcome::Refused } else { Outcome::Accepted(None) });
        for f in &new_files {
            // Only the files that the command line names as -o or --plot targets.
            let named = args.windows(2).any(|w| (w[0] == "-o" || w[0] == "--plot") && w[1] == f.to_string_lossy());
            if !named {
                continue;
            }
            let len = std::fs::metadata(f).map(|m| m.len());
            match (code, len) {
                (Some(2), Ok(_)) => v = fail("a file left behind by a refused run"),
                (Some(0 | 1), Ok(0)) => v = fail("an empty output file"),
                (Some(0 | 1), Err(_)) => v = fail("an output file missing after success"),
                _ => {}
            }
        }
        v
    };
    for f in new_files.iter().chain([&out_path, &err_path]) {
        let _ = std::fs::remove_file(f);
    }
    verdict
}
