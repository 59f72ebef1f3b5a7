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
    RglTable,
    InplaneTable,
    E1392Table,
    Baseline,
    Workbook,
    CommandLine,
}

impl Category {
    pub const ALL: [Category; 11] = [
        Category::GeneratedRecipe,
        Category::MutatedRecipe,
        Category::MutatedGeometry,
        Category::Sheet,
        Category::MerlTable,
        Category::RglTable,
        Category::InplaneTable,
        Category::E1392Table,
        Category::Baseline,
        Category::Workbook,
        Category::CommandLine,
    ];
    /// The categories checked in the library (all but the command lines).
    pub const IN_LIBRARY: [Category; 10] = [
        Category::GeneratedRecipe,
        Category::MutatedRecipe,
        Category::MutatedGeometry,
        Category::Sheet,
        Category::MerlTable,
        Category::RglTable,
        Category::InplaneTable,
        Category::E1392Table,
        Category::Baseline,
        Category::Workbook,
    ];
    pub fn name(self) -> &'static str {
        match self {
            Category::GeneratedRecipe => "generated recipes",
            Category::MutatedRecipe => "mutated recipes",
            Category::MutatedGeometry => "mutated geometry files",
            Category::Sheet => "generated and mutated sheets",
            Category::MerlTable => "generated and mutated MERL tables",
            Category::RglTable => "generated and mutated RGL tables",
            Category::InplaneTable => "generated and mutated in-plane CSV tables",
            Category::E1392Table => "generated and mutated E1392 tables",
            Category::Baseline => "generated and mutated baselines",
            Category::Workbook => "generated and mutated workbooks (.xlsx, .ods, .xls)",
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
    /// MERL `.binary` and RGL `.bsdf` files, as bytes.
    pub merl: Vec<Vec<u8>>,
    pub rgl: Vec<Vec<u8>>,
    /// In-plane CSV and E1392 text tables: each shipped file whole, and (three times as often) thinned to every
    /// 10th data line (the same format, a tenth of the parsing time per case).
    pub inplane: Vec<String>,
    pub e1392: Vec<String>,
    /// Baselines: `measure` and `compare` JSON documents of real readings ([`baseline_sources`]).
    pub baselines: Vec<String>,
    /// Workbooks (`fixtures/sheets` and the reviewers' hostile reproducers in `fixtures/sheets/hostile`), as
    /// bytes with their extension.
    pub workbooks: Vec<(Vec<u8>, &'static str)>,
}

fn binaries(dir: &str, ext: &str) -> Vec<Vec<u8>> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join(dir))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    files.sort();
    files.iter().map(|p| std::fs::read(p).unwrap()).collect()
}

/// A table's text with only every 10th line below its column line (comments and the header kept).
fn thinned(text: &str) -> String {
    let mut data = 0usize;
    let mut out = String::new();
    for l in text.lines() {
        let is_data = l.trim_start().starts_with(|c: char| c.is_ascii_digit() || c == '-');
        if is_data {
            data += 1;
            if data % 10 != 1 {
                continue;
            }
        }
        out.push_str(l);
        out.push('\n');
    }
    out
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
        // The thinned tables three times as often as the whole ones (which take ten times as long to read).
        let mut inplane = texts("fixtures/materials/inplane", "csv");
        let mut e1392 = texts("fixtures/materials/inplane", "txt");
        for t in [&mut inplane, &mut e1392] {
            let thin: Vec<String> = t.iter().map(|x| thinned(x)).collect();
            for _ in 0..3 {
                t.extend(thin.iter().cloned());
            }
        }
        let baselines = baseline_sources().iter().flat_map(|b| [b.measure.clone(), b.compare.clone()]).collect();
        Seeds {
            recipes,
            geometries,
            sheets: texts("fixtures/sheets", "csv"),
            merl: binaries("fixtures/materials/merl", "binary"),
            rgl: binaries("fixtures/materials/rgl", "bsdf"),
            inplane,
            e1392,
            baselines,
            workbooks: workbook_seeds(),
        }
    }
}

fn workbook_seeds() -> Vec<(Vec<u8>, &'static str)> {
    let mut out = Vec::new();
    for dir in ["fixtures/sheets", "fixtures/sheets/hostile"] {
        for ext in ["xlsx", "xls", "ods"] {
            out.extend(binaries(dir, ext).into_iter().map(|b| (b, ext)));
        }
    }
    out
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
                && !(message.contains("line")
                    || message.contains("JSON object")
                    || message.contains("no readings")
                    // A baseline's reasons about the whole document.
                    || message.contains("neither a `measure` JSON")
                    || message.contains("holds no reading"))
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
        Category::MerlTable | Category::RglTable | Category::InplaneTable | Category::E1392Table => {
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
        Category::Baseline => run_baseline(text),
        Category::CommandLine => run_cli(text),
        Category::MutatedGeometry => {
            let r = standards::parse(text, "fuzz-geometry.json")
                .and_then(|g| standards::builtin().and_then(|b| standards::check_user(&g, &b)));
            match r {
                Ok(()) => Ok(Outcome::Accepted(None)),
                Err(e) => check_error(&e, "fuzz-geometry.json").map(|_| Outcome::Refused),
            }
        }
        Category::Workbook => run_workbook(text),
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
        Category::MerlTable if rng.chance(0.5) => generate_merl(rng),
        Category::MerlTable => {
            let merl = mutate_bytes(rng.pick::<Vec<u8>>(&seeds.merl), rng);
            table_recipe("merl", &merl, "binary", rng)
        }
        Category::RglTable => {
            let rgl =
                if rng.chance(0.5) { generate_rgl(rng) } else { mutate_bytes(rng.pick::<Vec<u8>>(&seeds.rgl), rng) };
            table_recipe("rgl", &rgl, "bsdf", rng)
        }
        Category::InplaneTable => {
            let t =
                if rng.chance(0.5) { generate_inplane(rng) } else { mutate(rng.pick::<String>(&seeds.inplane), rng) };
            table_recipe("inplane-csv", t.as_bytes(), "csv", rng)
        }
        Category::E1392Table => {
            let t = if rng.chance(0.5) { generate_e1392(rng) } else { mutate(rng.pick::<String>(&seeds.e1392), rng) };
            table_recipe("e1392", t.as_bytes(), "txt", rng)
        }
        Category::Baseline if rng.chance(0.5) => generate_baseline(rng),
        Category::Baseline => mutate(rng.pick::<String>(&seeds.baselines), rng),
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
        Category::Workbook => generate_workbook(rng, seeds),
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
    // Alternatives of which a recipe gives exactly one (`registry::EXACTLY_ONE`): two given keep the first,
    // none given gets the first, so that the choice is not what refuses most generated recipes.
    for (at, first, second) in registry::EXACTLY_ONE.iter().filter(|(at, _, _)| *at == prefix) {
        let entry = |key: &str| registry::of_model(model).find(|e| e.pointer == format!("{at}/{key}"));
        let (Some(e1), Some(_)) = (entry(first), entry(second)) else { continue };
        match (obj.contains_key(*first), obj.contains_key(*second)) {
            (true, true) => {
                obj.remove(*second);
            }
            (false, false) => {
                obj.insert(e1.key(), registry_value(model, e1, samples, rng));
            }
            _ => {}
        }
    }
    levelling_rules(prefix, &mut obj, rng);
    obj
}

/// A paint coat's `application` and the rules across its fields (docs/recipe-format.md §A coat from its
/// application): it excludes `roughness` and `scatter` (half the coats keep it, without them); its viscosity
/// table starts at 0 s, its times increase and its viscosity does not fall; its texture is a PSD or a map.
fn levelling_rules(prefix: &str, obj: &mut serde_json::Map<String, serde_json::Value>, rng: &mut Rng) {
    use serde_json::json;
    match prefix {
        "/clear_coat" if obj.contains_key("application") => {
            if rng.chance(0.5) {
                for k in ["roughness", "scatter", "distribution"] {
                    obj.remove(k);
                }
            } else {
                obj.remove("application");
            }
        }
        "/clear_coat/application" => {
            if let Some(serde_json::Value::Array(points)) = obj.get_mut("viscosity") {
                let mut etas: Vec<f64> = points.iter().filter_map(|p| p["eta_pa_s"].as_f64()).collect();
                etas.sort_by(f64::total_cmp);
                for (i, (p, eta)) in points.iter_mut().zip(etas).enumerate() {
                    p["t_s"] = json!(60.0 * i as f64);
                    p["eta_pa_s"] = json!(eta);
                }
            }
        }
        // A measured texture (`file`) is the shipped map, with none of a PSD's numbers; a PSD has its two numbers
        // (optional in the registry only because a map replaces them) and no levelling; a Gaussian one no `c`.
        "/clear_coat/application/texture" if obj.contains_key("file") => {
            let f = root().join("fixtures/topography/gaussian.x3p");
            obj.insert("file".into(), json!(f.to_string_lossy()));
            for k in ["rms_roughness_nm", "correlation_length_um", "c"] {
                obj.remove(k);
            }
        }
        "/clear_coat/application/texture" => {
            obj.remove("levelling");
            obj.entry("rms_roughness_nm").or_insert(json!(2000.0));
            obj.entry("correlation_length_um").or_insert(json!(200.0));
            if obj.get("psd").and_then(|v| v.as_str()) == Some("gaussian") {
                obj.remove("c");
            }
        }
        _ => {}
    }
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
    if model == "topography" {
        let f = root().join("fixtures/topography/gaussian.x3p");
        obj.insert("file".into(), json!(f.to_string_lossy()));
        // An edge is the Kirchhoff method's, which reads the whole map (no scale split); a third of the
        // recipes are read by it.
        if obj.contains_key("edge") || rng.chance(0.33) {
            obj.insert("method".into(), json!("kirchhoff"));
        }
        if obj.get("method").and_then(|v| v.as_str()) == Some("kirchhoff") {
            obj.remove("scale_split");
            obj.remove("split_frequency");
        } else {
            obj.remove("edge");
        }
    }
    Value::Object(obj).to_string()
}

// ---------------------------------------------------------------------------------------------------------
// MERL tables: random headers, sizes and values, written to a scratch file.
// ---------------------------------------------------------------------------------------------------------

/// A random MERL `.binary` (small or nonsense dimensions; exact, short or long bodies; values finite,
/// negative, NaN or infinite) written to a scratch file, and a recipe that reads it.
pub fn generate_merl(rng: &mut Rng) -> String {
    let bytes = merl_bytes(rng);
    table_recipe("merl", &bytes, "binary", rng)
}

/// The bytes of a random MERL `.binary` ([`generate_merl`]).
pub fn merl_bytes(rng: &mut Rng) -> Vec<u8> {
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
    bytes
}

// ---------------------------------------------------------------------------------------------------------
// Binary tables: byte-level mutations of the shipped MERL and RGL files, and generated RGL tensor files.
// ---------------------------------------------------------------------------------------------------------

/// 1–4 random byte-level edits: a flipped bit, a header-sized integer (u16, u32, u64) or a float (f32, f64)
/// overwritten by an edge value, a truncation, a deleted or duplicated span. Half of the edits fall in the
/// first 512 bytes, where the headers (dimensions, ranks, types, offsets, shapes) are.
pub fn mutate_bytes(bytes: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut b = bytes.to_vec();
    for _ in 0..1 + rng.below(4) {
        let n = b.len().max(1);
        let at = if rng.chance(0.5) { rng.below(n.min(512)) } else { rng.below(n) };
        let put = |b: &mut Vec<u8>, at: usize, v: &[u8]| {
            for (k, x) in v.iter().enumerate() {
                if let Some(y) = b.get_mut(at + k) {
                    *y = *x;
                }
            }
        };
        match rng.below(10) {
            0 | 1 => {
                if let Some(y) = b.get_mut(at) {
                    *y ^= 1 << rng.below(8);
                }
            }
            2 => {
                let v = *rng.pick(&[0u64, 1, 2, 3, u32::MAX as u64, u64::MAX, 1 << 31, 1 << 40, n as u64, 100_000]);
                put(&mut b, at, &v.to_le_bytes());
            }
            3 => {
                let v = *rng.pick(&[0u32, 1, 2, 12, 16, 1024, 1025, u32::MAX, 0x8000_0000, n as u32]);
                put(&mut b, at, &v.to_le_bytes());
            }
            4 => {
                let v = *rng.pick(&[0u16, 1, 2, 3, 10, 11, 12, 17, u16::MAX]);
                put(&mut b, at, &v.to_le_bytes());
            }
            5 => {
                let v = *rng.pick(&[f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, 0.0, 3.0e38, 1e-45, 1.6]);
                put(&mut b, at & !3, &v.to_le_bytes());
            }
            6 => {
                let v = *rng.pick(&[f64::NAN, f64::INFINITY, -1.0, 0.0, 1e300, 5e-324, -0.0]);
                put(&mut b, at & !7, &v.to_le_bytes());
            }
            7 => b.truncate(rng.below(n)),
            8 => {
                let e = (at + 1 + rng.below(16)).min(b.len());
                if at < e {
                    b.drain(at..e);
                }
            }
            _ => {
                let e = (at + 1 + rng.below(16)).min(b.len());
                if at < e {
                    let dup = b[at..e].to_vec();
                    b.splice(e..e, dup);
                }
            }
        }
    }
    b
}

/// Write `bytes` to a fresh scratch file and return a recipe of `model` that reads it, with a random
/// interpolation (MERL) or off-plane assumption (in-plane tables), now and then a wrong one or an unknown
/// field.
pub fn table_recipe(model: &str, bytes: &[u8], ext: &str, rng: &mut Rng) -> String {
    let path = scratch(&format!("{model}-{:016x}.{ext}", rng.next()));
    std::fs::write(&path, bytes).unwrap();
    let mut obj = serde_json::json!({"model": model, "file": path.to_string_lossy()});
    match model {
        "merl" => obj["interpolation"] = serde_json::json!(rng.pick(&["nearest", "trilinear", "nearest", "cubic"])),
        "inplane-csv" | "e1392" if rng.chance(0.7) => {
            obj["off_plane"] = serde_json::json!(rng.pick(&[
                "f",
                "f",
                "f-cos-cos",
                "f-cos-cos",
                "microfacet",
                "microfacet",
                "microfacet",
                "x"
            ]))
        }
        _ => {}
    }
    if rng.chance(0.03) {
        obj["bogus"] = serde_json::json!(1);
    }
    obj.to_string()
}

/// One field of a tensor file to write: name, type code, shape and its data (little-endian).
struct TensorField {
    name: String,
    dtype: u8,
    shape: Vec<u64>,
    data: Vec<u8>,
}

/// A tensor file (`measured/rgl.rs` describes the container) from its fields; `bad_offset` moves one
/// field's data offset.
fn tensor_file(fields: &[TensorField], bad_offset: Option<(usize, u64)>) -> Vec<u8> {
    let header: usize = 18 + fields.iter().map(|f| 2 + f.name.len() + 2 + 1 + 8 + 8 * f.shape.len()).sum::<usize>();
    let mut out = b"tensor_file\0".to_vec();
    out.extend([1u8, 0]);
    out.extend((fields.len() as u32).to_le_bytes());
    let mut offset = header as u64;
    for (k, f) in fields.iter().enumerate() {
        out.extend((f.name.len() as u16).to_le_bytes());
        out.extend(f.name.as_bytes());
        out.extend((f.shape.len() as u16).to_le_bytes());
        out.push(f.dtype);
        let o = match bad_offset {
            Some((j, o)) if j == k => o,
            _ => offset,
        };
        out.extend(o.to_le_bytes());
        for d in &f.shape {
            out.extend(d.to_le_bytes());
        }
        offset += f.data.len() as u64;
    }
    for f in fields {
        out.extend(&f.data);
    }
    out
}

/// A random value of a table: mostly a positive number of the lobe's scale, now and then 0, negative, NaN,
/// infinite or huge.
fn table_value(rng: &mut Rng, scale: f64) -> f64 {
    let u = (rng.next() >> 11) as f64 / (1u64 << 53) as f64;
    match rng.below(200) {
        0 => f64::NAN,
        1 => f64::INFINITY,
        2 => -1.0,
        3 => 1e300,
        4 => 1e-300,
        5..=9 => 0.0,
        _ => scale * u,
    }
}

/// A random RGL `.bsdf`: small grids (2–5 per axis, 1–4 incident angles, isotropic or a full anisotropic
/// circle), spectral or RGB; with probability ~1/3 one thing wrong: a dimension off by one, a field missing
/// or of another type or rank, axes not increasing or out of range, a data offset past the end; values as
/// [`table_value`].
pub fn generate_rgl(rng: &mut Rng) -> Vec<u8> {
    let f32s = |v: &[f64]| v.iter().flat_map(|x| (*x as f32).to_le_bytes()).collect::<Vec<u8>>();
    let nt = 1 + rng.below(4);
    let np = *rng.pick(&[1usize, 1, 2, 4]);
    let n = 2 + rng.below(4);
    let (ny, nx) = (2 + rng.below(4), 2 + rng.below(4));
    let spectral = rng.chance(0.5);
    let nl = if spectral { 1 + rng.below(4) } else { 3 };
    // One of a few defects, or none (values only).
    let defect = if rng.chance(0.35) { 1 + rng.below(8) } else { 0 };
    let mut thetas: Vec<f64> = (0..nt).map(|i| 1.5 * i as f64 / nt.max(2) as f64).collect();
    let mut phis: Vec<f64> = if np <= 2 {
        (0..np).map(|i| i as f64).collect()
    } else {
        (0..np).map(|i| -std::f64::consts::PI + 2.0 * std::f64::consts::PI * i as f64 / (np - 1) as f64).collect()
    };
    let mut lambdas: Vec<f64> = (0..nl).map(|i| 400.0 + 100.0 * i as f64).collect();
    match defect {
        1 if nt > 1 => thetas.swap(0, 1),
        1 => thetas[0] = 2.0,
        2 if np > 2 => phis[np - 1] = 0.0,
        2 => lambdas[0] = *rng.pick(&[f64::NAN, 100.0, 900.0]),
        _ => {}
    }
    let mut vals = |k: usize, scale: f64| -> Vec<f64> { (0..k).map(|_| table_value(rng, scale)).collect() };
    let mut fields = vec![
        TensorField { name: "theta_i".into(), dtype: 10, shape: vec![nt as u64], data: f32s(&thetas) },
        TensorField { name: "phi_i".into(), dtype: 10, shape: vec![np as u64], data: f32s(&phis) },
        TensorField {
            name: "ndf".into(),
            dtype: 10,
            shape: vec![ny as u64, nx as u64],
            data: f32s(&vals(ny * nx, 10.0)),
        },
        TensorField {
            name: "sigma".into(),
            dtype: 10,
            shape: vec![ny as u64, nx as u64],
            data: f32s(&vals(ny * nx, 1.0)),
        },
        TensorField {
            name: "vndf".into(),
            dtype: 10,
            shape: vec![np as u64, nt as u64, ny as u64, nx as u64],
            data: f32s(&vals(np * nt * ny * nx, 5.0)),
        },
        TensorField {
            name: "luminance".into(),
            dtype: 10,
            shape: vec![np as u64, nt as u64, n as u64, n as u64],
            data: f32s(&vals(np * nt * n * n, 1.0)),
        },
        TensorField {
            name: if spectral { "spectra" } else { "rgb" }.into(),
            dtype: 10,
            shape: vec![np as u64, nt as u64, nl as u64, n as u64, n as u64],
            data: f32s(&vals(np * nt * nl * n * n, 1.0)),
        },
        TensorField { name: "description".into(), dtype: 1, shape: vec![4], data: b"fuzz".to_vec() },
        TensorField { name: "jacobian".into(), dtype: 1, shape: vec![1], data: vec![rng.below(2) as u8] },
    ];
    if spectral {
        fields.push(TensorField {
            name: "wavelengths".into(),
            dtype: 10,
            shape: vec![nl as u64],
            data: f32s(&lambdas),
        });
    }
    let k = rng.below(fields.len());
    let mut bad_offset = None;
    match defect {
        3 => {
            let f = &mut fields[k];
            let j = rng.below(f.shape.len());
            f.shape[j] = if rng.chance(0.5) { f.shape[j] + 1 } else { f.shape[j].saturating_sub(1) };
        }
        4 => {
            fields.remove(k);
        }
        5 => fields[k].dtype = *rng.pick(&[0u8, 1, 9, 11, 12, 255]),
        6 => {
            let f = &mut fields[k];
            f.shape.push(1);
        }
        7 => bad_offset = Some((k, *rng.pick(&[0u64, 1, u64::MAX, 1 << 40]))),
        8 => {
            let dup = TensorField {
                name: fields[k].name.clone(),
                dtype: fields[k].dtype,
                shape: fields[k].shape.clone(),
                data: fields[k].data.clone(),
            };
            fields.push(dup);
        }
        _ => {}
    }
    if rng.chance(0.2) {
        let len = fields.len();
        fields.swap(rng.below(len), rng.below(len));
    }
    tensor_file(&fields, bad_offset)
}

// ---------------------------------------------------------------------------------------------------------
// In-plane text tables: generated in-plane CSV and ASTM E1392 files.
// ---------------------------------------------------------------------------------------------------------

/// A cell of a text table: a number; in a table with `bad` cells, now and then a non-number or an edge value.
fn table_cell(rng: &mut Rng, x: f64, bad: bool) -> String {
    if !bad {
        return format!("{x:.6e}");
    }
    match rng.below(40) {
        0 => "NaN".into(),
        1 => "inf".into(),
        2 => "x".into(),
        3 => String::new(),
        4 => "1e400".into(),
        5 => "1e300".into(),
        6 => "-1".into(),
        7 => "1e-320".into(),
        8 => "\"1\"".into(),
        _ => format!("{x:.6e}"),
    }
}

/// The rows of a generated in-plane table: (θi, θo signed, value), θi from 1–3 incidences (now and then 0°,
/// 89.9°, 90° or negative), θo on a grid of 2–40 points (now and then repeated or out of range), values a
/// Beckmann-like lobe about the specular direction on a diffuse floor, or a constant.
fn inplane_rows(rng: &mut Rng) -> Vec<(String, String, String)> {
    let mut rows = Vec::new();
    // Two tables in five have bad cells.
    let bad = rng.chance(0.4);
    // A constant: a Lambertian level, or one at the ends of f64 (0, subnormal, near the largest).
    let flat = rng.chance(0.2);
    let level = *rng.pick(&[0.3, 0.3, 0.3, 0.0, 1e-320, 1e-300, 1e300, 1e308]);
    let width = *rng.pick(&[0.5, 2.0, 5.0, 20.0]);
    for _ in 0..1 + rng.below(3) {
        let ti: f64 = *rng.pick(&[0.0, 10.0, 15.0, 20.0, 30.0, 45.0, 60.0, 75.0, 80.0, 85.0, 89.9, 90.0, -1.0]);
        let k = *rng.pick(&[1usize, 2, 3, 5, 10, 20, 40]);
        let (lo, hi): (f64, f64) =
            *rng.pick(&[(-89.0, 89.0), (-89.0, 89.0), (0.0, 89.0), (-60.0, 60.0), (-90.0, 90.0), (10.0, 30.0)]);
        for j in 0..k {
            let to = if k == 1 { lo } else { lo + (hi - lo) * j as f64 / (k - 1) as f64 };
            let v = if flat { level } else { 0.05 + 50.0 * (-((to - ti) / width).powi(2)).exp() };
            rows.push((table_cell(rng, ti, bad), table_cell(rng, to, bad), table_cell(rng, v, bad)));
        }
        if rng.chance(0.05) && !rows.is_empty() {
            let r = rows[rows.len() - 1].clone();
            rows.push(r);
        }
    }
    rows
}

/// A generated in-plane CSV table (`theta_i,theta_o,brdf` or `brdf_cos`, in any order; BOM, comments,
/// blank lines; now and then an unknown or missing column or a short row).
pub fn generate_inplane(rng: &mut Rng) -> String {
    let mut s = String::new();
    if rng.chance(0.1) {
        s.push('\u{feff}');
    }
    if rng.chance(0.5) {
        s.push_str("# generated\n");
    }
    let value = *rng.pick(&["brdf", "brdf", "brdf_cos", "brdf_cos", "BRDF", "Brdf_Cos", "x", ""]);
    let order = rng.below(3);
    let header = match order {
        0 => format!("theta_i,theta_o,{value}"),
        1 => format!("theta_o,theta_i,{value}"),
        _ => format!("{value},theta_i,theta_o"),
    };
    s.push_str(&header);
    if rng.chance(0.03) {
        s.push_str(",brdf_cos");
    }
    s.push('\n');
    for (ti, to, v) in inplane_rows(rng) {
        if rng.chance(0.02) {
            s.push('\n');
        }
        let line = match order {
            0 => format!("{ti},{to},{v}"),
            1 => format!("{to},{ti},{v}"),
            _ => format!("{v},{ti},{to}"),
        };
        s.push_str(&line);
        if rng.chance(0.01) {
            s.push_str(",1");
        }
        s.push('\n');
    }
    s
}

/// A generated ASTM E1392-style table (keyword lines, a column line naming θi, φi, θs, φs and BRDF or
/// CCBRDF, space- or comma-separated rows in and out of the plane).
pub fn generate_e1392(rng: &mut Rng) -> String {
    let mut s = String::new();
    if rng.chance(0.1) {
        s.push('\u{feff}');
    }
    if rng.chance(0.7) {
        s.push_str("SAMPLE: generated\nWAVELENGTH: 550 nm\n");
    }
    let value = *rng.pick(&["BRDF", "BRDF", "CCBRDF", "CCBRDF", "brdf", "x", "BRDF CCBRDF"]);
    let sep = if rng.chance(0.8) { " " } else { "," };
    let cols =
        if rng.chance(0.95) { ["theta_i", "phi_i", "theta_s", "phi_s"].join(sep) } else { "theta_i phi_i".into() };
    s.push_str(&format!("{cols}{sep}{value}\n"));
    for (ti, to, v) in inplane_rows(rng) {
        // θo signed: + on the specular side (φs = φi + 180°), − on the source's side (φs = φi).
        let (ts, ps) = match to.parse::<f64>() {
            Ok(x) if x < 0.0 => (format!("{}", -x), "0".to_string()),
            _ => (to.clone(), "180".to_string()),
        };
        let ps = match rng.below(30) {
            0 => "90".to_string(),
            1 => "540".to_string(),
            2 => "-180".to_string(),
            _ => ps,
        };
        s.push_str(&[ti, "0".into(), ts, ps, v].join(sep));
        s.push('\n');
    }
    s
}

// ---------------------------------------------------------------------------------------------------------
// Baselines: real `measure` and `compare` documents, mutated, and generated ones.
// ---------------------------------------------------------------------------------------------------------

/// A recipe, the sheet that goes with it (if any), and baselines of its readings.
pub struct BaselineSource {
    pub recipe: &'static str,
    pub sheet: Option<&'static str>,
    /// `measure --format json` of the recipe (rtol 1e-2, 20 000 evaluations per integral, no timing).
    pub measure: String,
    /// A `compare` document of the same readings (its `comparisons` only, which is what a baseline reads).
    pub compare: String,
    /// The material's name and its readings.
    pub material: String,
    pub readings: Vec<glossmeter::Reading>,
}

/// The baseline sources, measured once per process on the default panel.
pub fn baseline_sources() -> &'static [BaselineSource] {
    static S: std::sync::OnceLock<Vec<BaselineSource>> = std::sync::OnceLock::new();
    S.get_or_init(|| {
        let panel = glossmeter::resolve_geometries(glossmeter::DEFAULT_PANEL, &[] as &[&str]).unwrap();
        let opts = glossmeter::PlanOptions { rtol: 1e-2, max_evals: 20_000, ..Default::default() };
        [
            ("fixtures/recipes/black-glass.json", Some("fixtures/sheets/black-glass-check.csv")),
            ("fixtures/recipes/glass-n1.5.json", Some("fixtures/sheets/glass-n1.5-trigloss.csv")),
            ("fixtures/recipes/grey-lambert.json", None),
        ]
        .into_iter()
        .map(|(recipe, sheet)| {
            // The name as the command line derives it from the relative path (the recipe's or its stem).
            let text = std::fs::read_to_string(root().join(recipe)).unwrap();
            let m = recipe::parse_str(&text, recipe).unwrap();
            let readings = glossmeter::measure(&m, &panel, &opts).unwrap();
            // (the plan's evaluation count is not read by the baseline reader: 0 here)
            let measure = glossmeter::report::measure::json_doc(&m, &readings, false, 0).text();
            let comparisons: Vec<serde_json::Value> = readings
                .iter()
                .map(|r| {
                    serde_json::json!({"sample": m.name, "material": m.name, "geometry": r.geometry,
                        "predicted_reading": r.name, "predicted": r.value,
                        "error_estimate": r.value.map(|_| r.error_estimate)})
                })
                .collect();
            let compare = glossmeter::report::pretty(&serde_json::json!({"comparisons": comparisons}));
            BaselineSource { recipe, sheet, measure, compare, material: m.name.clone(), readings }
        })
        .collect()
    })
}

const BASELINE_VALUES: &[&str] = &[
    "0", "1", "89.1", "-1", "1e308", "-1e308", "1e-320", "null", "\"NaN\"", "\"89\"", "[]", "1e400", "true", "1e15",
    "1e16", "-0",
];

/// A generated baseline: a `measure` document (one material, or a `material` per reading) or a `compare`
/// one, 0–6 readings with real or unknown materials, geometries and readings, values and estimates from
/// [`BASELINE_VALUES`]; now and then not an object at all.
pub fn generate_baseline(rng: &mut Rng) -> String {
    let src = rng.pick(baseline_sources());
    let materials = [src.material.as_str(), "black-glass", "glass-1.50", "nope", ""];
    let geometries = ["astm-d523-20", "astm-d523-60", "astm-d523-85", "astm-e430-30", "iso-13803-20", "nope"];
    let names = ["gloss", "haze", "doi", "haze-narrow", "log-haze", "haze-index", "x"];
    let mut entries = Vec::new();
    for _ in 0..rng.below(7) {
        let real = (!src.readings.is_empty() && rng.chance(0.6)).then(|| rng.pick(&src.readings).clone());
        let geometry = real.as_ref().map_or_else(|| rng.pick(&geometries).to_string(), |r| r.geometry.clone());
        let name = real.as_ref().map_or_else(|| rng.pick(&names).to_string(), |r| r.name.clone());
        let value = match &real {
            Some(r) if rng.chance(0.5) => format!("{}", r.value.unwrap_or(0.0)),
            _ => rng.pick(BASELINE_VALUES).to_string(),
        };
        let e = if rng.chance(0.5) { "0.001".to_string() } else { rng.pick(BASELINE_VALUES).to_string() };
        let material = if rng.chance(0.8) { src.material.clone() } else { rng.pick(&materials).to_string() };
        entries.push((material, geometry, name, value, e));
    }
    let json_str = |s: &str| serde_json::to_string(s).unwrap();
    match rng.below(10) {
        0 => rng.pick(&["[]", "\"x\"", "{}", "null", "{\"readings\": 1}", "{\"comparisons\": {}}"]).to_string(),
        1..=5 => {
            let per_reading = rng.chance(0.3);
            let rs: Vec<String> = entries
                .iter()
                .map(|(m, g, n, v, e)| {
                    let mat = if per_reading { format!("\"material\": {}, ", json_str(m)) } else { String::new() };
                    format!(
                        "{{{mat}\"geometry\": {}, \"name\": {}, \"value\": {v}, \"error_estimate\": {e}}}",
                        json_str(g),
                        json_str(n)
                    )
                })
                .collect();
            let top = if per_reading {
                String::new()
            } else {
                format!("\"material\": {{\"name\": {}}}, ", json_str(&src.material))
            };
            format!("{{{top}\"readings\": [{}]}}", rs.join(", "))
        }
        _ => {
            let cs: Vec<String> = entries
                .iter()
                .map(|(m, g, n, v, e)| {
                    format!(
                        "{{\"material\": {}, \"geometry\": {}, \"predicted_reading\": {}, \"predicted\": {v}, \
                         \"error_estimate\": {e}}}",
                        json_str(m),
                        json_str(g),
                        json_str(n)
                    )
                })
                .collect();
            format!("{{\"comparisons\": [{}]}}", cs.join(", "))
        }
    }
}

/// A baseline case: the text written to a scratch file and read as `--baseline` reads it; accepted, or refused
/// with an input error naming that file. An accepted one is checked against the readings of every baseline
/// source: every baseline entry and every check (now, then, allowed) finite, its JSON without a non-finite
/// number.
pub fn run_baseline(text: &str) -> Result<Outcome, String> {
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let path = scratch(&format!("baseline-{n}.json"));
    std::fs::write(&path, text).unwrap();
    let r = glossmeter::comparison::load_baseline(&path);
    let _ = std::fs::remove_file(&path);
    let entries = match r {
        Err(e) => return check_error(&e, &path.display().to_string()).map(|_| Outcome::Refused),
        Ok(b) => b,
    };
    if let Some(b) =
        entries.iter().find(|b| !(b.value.is_finite() && b.error_estimate.is_finite() && b.error_estimate >= 0.0))
    {
        return Err(format!("a baseline entry accepted with a non-finite value or estimate: {b:?}"));
    }
    for src in baseline_sources() {
        let drift =
            glossmeter::comparison::check_baseline(src.readings.iter().map(|r| (src.material.as_str(), r)), &entries);
        for d in &drift {
            let shown = glossmeter::report::drift_json(d).to_string();
            if !(d.now.is_finite() && d.then.is_finite() && d.allowed.is_finite()) || prints_non_finite(&shown) {
                return Err(format!("a baseline check with a non-finite number: {d:?}"));
            }
        }
    }
    Ok(Outcome::Accepted(None))
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

/// Recipes cheap enough for the slow subcommands (`sweep`, `fit`, `plot`, `profile`): the analytic single-lobe
/// models and the tiny MERL table (the paints and the spectral fixtures are fuzzed in the library and by
/// `measure`), each with ranges of numbers it has, for the cases that should get past the parser.
const CHEAP_RECIPES: &[(&str, &[&str])] = &[
    ("fixtures/recipes/grey-lambert.json", &["/albedo=0.1..0.9"]),
    ("fixtures/recipes/rgb-lambert.json", &["/albedo/0=0.1..0.9", "/albedo/2=0.05..0.5"]),
    ("fixtures/recipes/glass-n1.5.json", &["/ior=1.3..1.8"]),
    ("fixtures/recipes/black-glass.json", &["/ior=1.3..1.8"]),
    ("fixtures/recipes/bench-b2-beckmann-0.1.json", &["/roughness=0.05..0.3", "/ior=1.3..1.8"]),
    ("fixtures/recipes/bench-b4-ggx-0.3.json", &["/roughness=0.05..0.5", "/ior=1.3..1.8"]),
    ("fixtures/recipes/rough-dielectric-beckmann.json", &["/roughness=0.01..0.3", "/ior=1.2..2"]),
    ("fixtures/recipes/rough-conductor-ggx.json", &["/roughness=0.05..0.4", "/ior/0=0.5..2"]),
    ("fixtures/recipes/phong.json", &["/exponent=10..500", "/ks=0.01..0.1"]),
    ("fixtures/recipes/ward.json", &["/alpha=0.02..0.3", "/rho_s=0.01..0.1"]),
    ("fixtures/recipes/merl-lambert-tiny.json", &[]),
    ("fixtures/materials/rgl/beckmann-iso-32.json", &[]),
];

/// JSON Pointer ranges for `sweep --vary`, `fit --free` and `plot --vary`: valid for some recipes, unknown,
/// reversed, empty, non-finite or malformed for others.
const POINTER_RANGES: &[&str] = &[
    "/roughness=0.05..0.3",
    "/albedo=0.1..0.9",
    "/ior=1.3..1.8",
    "/roughness=0.3..0.05",
    "/nope=0..1",
    "/roughness=0..0",
    "/roughness=NaN..1",
    "/roughness=1e-300..1e999",
    "/albedo/0=0.1..0.9",
    "/ior/0=1.2..1.9",
    "roughness=0.1..0.2",
    "/roughness",
    "x",
    "",
];

/// The value of option `opt` in a generated command line.
fn cli_value(opt: &str, rng: &mut Rng) -> String {
    let paths = ["@NEW", "@NEW", "@NEW", "Cargo.toml", "fixtures", "/dev/full", "/nonexistent/dir/x.txt", ""];
    let pictures =
        ["@NEW.svg", "@NEW.svg", "@NEW.png", "@NEW", "@NEW.txt", "Cargo.toml", "/dev/full", "/nonexistent/dir/x.svg"];
    match opt {
        "-g" => rng.pick(CLI_IDS).to_string(),
        "--rtol" | "--max-seconds" | "-k" | "--tolerance" | "--max-de00" | "--min-time-ms" | "--uncertainty" => {
            rng.pick(CLI_NUMBERS).to_string()
        }
        "--tolerances" => {
            rng.pick(&["1e-2,1e-3", "1e-2", "0.5,1e-3", "NaN", "x", "", "1e-2,,1e-3", "1e-20"]).to_string()
        }
        "--max-evals" | "--max-total-evals" | "--max-repetitions" => {
            rng.pick(&["0", "1", "100", "20000", "-1", "x", "NaN", "99999999999999999999"]).to_string()
        }
        "--restarts" | "--points" | "--lhs" => rng.pick(&["0", "1", "2", "3", "-1", "x", "NaN", ""]).to_string(),
        "--seed" => rng.pick(&["0", "1", "18446744073709551615", "-1", "x"]).to_string(),
        "--shard" => rng
            .pick(&["1/1", "1/2", "2/2", "2/3", "0/1", "4/3", "1/0", "x", "18446744073709551615/18446744073709551615"])
            .to_string(),
        "--format" => rng.pick(&["table", "json", "csv", "junit", "jsonl", "xml", ""]).to_string(),
        "--illuminant" => rng.pick(&["D65", "D50", "A", "C", "F2", ""]).to_string(),
        "--observer" => rng.pick(&["10", "2", "5", ""]).to_string(),
        "--delimiter" => rng.pick(&[",", ";", "\\t", "tab", "ab", ""]).to_string(),
        "-o" | "--output" => rng.pick(&paths).to_string(),
        "--plot" => rng.pick(&pictures).to_string(),
        "--kind" => rng.pick(&["section", "gloss-vs-parameter", "x", ""]).to_string(),
        "--vary" => {
            let n = rng.pick(&[":2", ":2", ":3", ":1", ":0", ":-1", ":x", ""]);
            format!("{}{n}", rng.pick(POINTER_RANGES))
        }
        "--log" => rng.pick(&["/roughness", "/albedo", "/nope", "x"]).to_string(),
        "--free" => {
            let r = rng.pick(POINTER_RANGES);
            match r.split_once('=') {
                Some((p, range)) if rng.chance(0.3) => format!("{p}=log:{range}"),
                _ => r.to_string(),
            }
        }
        "--target" => rng
            .pick(&[
                "astm-d523-60/gloss=50±1",
                "astm-d523-20/gloss=20+-0.5",
                "astm-d523-85/gloss=90",
                "astm-e430-30/haze=2±0.1",
                "astm-d523-60/gloss=NaN",
                "astm-d523-60/gloss=1e999",
                "astm-d523-60/gloss=50±-1",
                "astm-d523-60/gloss=50±0",
                "nope/gloss=1",
                "astm-d523-60/nope=1",
                "x",
                "",
            ])
            .to_string(),
        "--sample" => rng.pick(&["glass-1.50", "black-glass", "x", ""]).to_string(),
        "--geometry-file" => {
            let mut g = files("fixtures/geometry", "json");
            g.push("standards/rspec-20.json".into());
            g.push("nope.json".into());
            rng.pick(&g).clone()
        }
        "--baseline" => {
            // A baseline written for the case (the source's own readings, mutated or generated), or a file that
            // is no baseline.
            let src = rng.pick(baseline_sources());
            let doc = if rng.chance(0.5) { src.measure.clone() } else { src.compare.clone() };
            let doc = match rng.below(4) {
                0 | 1 => doc,
                2 => mutate(&doc, rng),
                _ => generate_baseline(rng),
            };
            match rng.below(10) {
                0 => rng.pick(&["Cargo.toml", "fixtures", "nope.json", "/dev/null", ""]).to_string(),
                _ => format!("@FILE:{doc}"),
            }
        }
        _ => String::new(),
    }
}

/// One random argument vector (without the program name), as a JSON array of strings. Paths are relative to
/// the crate root (the process runs there); `@NEW` stands for a fresh scratch path (`@NEW.svg` with that
/// extension), `@FILE:TEXT` for a scratch file holding TEXT, `@TABLE:MODEL:HEX` for a recipe of MODEL reading a
/// scratch table of those bytes. `cheap`: the readings get a small budget first
/// (`--max-seconds 1` for `measure`, `--rtol 1e-3` for `compare`, `--rtol 1e-2 --max-evals 20000` and at most
/// 3 values per axis for `sweep`, `--rtol 1e-2 --restarts 0` for `fit`, `--rtol 1e-2 --points 2` for `plot`,
/// `--rtol 1e-2 --max-total-evals 2000000` for `profile`; a second budget given at random is then a usage error, exit 2), so that 10⁴
/// command lines fit in minutes.
pub fn generate_cli(rng: &mut Rng, cheap: bool) -> String {
    let mut recipes = files("fixtures/recipes", "json");
    recipes.retain(|r| !r.contains("bench-b3")); // keep the run fast; the panel is fuzzed in the library
    let cheap_recipes: Vec<String> = CHEAP_RECIPES.iter().map(|(r, _)| r.to_string()).collect();
    // One recipe in four is refused: a bad fixture, a missing file, a directory, empty, stdin.
    let mut bad_recipes = files("fixtures/bad", "json");
    bad_recipes.extend(["nope.json", "fixtures", "/dev/null", "", "-"].map(String::from));
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
        "sweep",
        "sweep",
        "fit",
        "fit",
        "plot",
        "plot",
        "profile",
        "profile",
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
            "--baseline",
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
            "--baseline",
            "--bogus",
        ],
        "convergence" => &["-g", "--format", "--plot", "-o", "--min-time-ms", "--max-repetitions", "--bogus"],
        "sweep" => &[
            "--vary",
            "--log",
            "--lhs",
            "--seed",
            "-g",
            "--shard",
            "--format",
            "--rtol",
            "--no-timing",
            "--max-evals",
            "-o",
            "--bogus",
        ],
        "fit" => &[
            "--free",
            "--target",
            "--target",
            "--sheet",
            "--sample",
            "--delimiter",
            "--uncertainty",
            "--restarts",
            "--rtol",
            "--format",
            "-o",
            "--no-timing",
            "--bogus",
        ],
        "plot" => &["--kind", "-g", "--vary", "--points", "--rtol", "-o", "--output", "--bogus"],
        "profile" => &[
            "-g",
            "--geometry-file",
            "--format",
            "--plot",
            "-o",
            "--rtol",
            "--allow-unconverged",
            "--max-evals",
            "--max-total-evals",
            "--bogus",
        ],
        _ => &[],
    };
    match sub {
        "measure" | "compare" | "convergence" | "sweep" | "fit" | "plot" | "profile" => {
            let slow = matches!(sub, "sweep" | "fit" | "plot" | "profile");
            let pool = if rng.chance(0.25) {
                &bad_recipes
            } else if slow {
                &cheap_recipes
            } else {
                &recipes
            };
            // compare with a baseline: the recipe and sheet of a baseline source, most of the time.
            // Two in five cases are tame: for `compare`, a baseline source's recipe and sheet; for the newer
            // subcommands, a cheap recipe, ranges it has, valid targets and pictures; for all, no random
            // options, so that they reach the computation.
            let tame = rng.chance(0.4);
            let src = match sub {
                "compare" if tame || rng.chance(0.3) => {
                    Some(rng.pick(baseline_sources())).filter(|s| s.sheet.is_some())
                }
                "measure" if rng.chance(0.2) => Some(rng.pick(baseline_sources())),
                _ => None,
            };
            let recipe = match src {
                Some(s) => s.recipe.to_string(),
                None => rng.pick(pool).clone(),
            };
            let (recipe, ranges): (String, &[&str]) = if tame && slow {
                let (r, ranges) = rng.pick(CHEAP_RECIPES);
                (r.to_string(), ranges)
            } else {
                (recipe, &[])
            };
            let range = |rng: &mut Rng| -> String {
                if ranges.is_empty() {
                    rng.pick(POINTER_RANGES).to_string()
                } else {
                    rng.pick(ranges).to_string()
                }
            };
            // Now and then `measure`, `plot` and `profile` read a generated table (written with its recipe when
            // the case runs: `@TABLE:MODEL:HEX`); `profile` under its evaluation budget (`--max-total-evals`),
            // since 512 pixels of a table that does not converge ran for minutes without one (docs/reliability.md).
            let recipe = if matches!(sub, "measure" | "plot" | "profile") && rng.chance(0.15) {
                let (model, bytes) = match rng.below(4) {
                    0 => ("inplane-csv", generate_inplane(rng).into_bytes()),
                    1 => ("e1392", generate_e1392(rng).into_bytes()),
                    2 => ("rgl", generate_rgl(rng)),
                    _ => ("merl", merl_bytes(rng)),
                };
                let hex: String = bytes.iter().map(|b| format!("{b:02x}")).collect();
                format!("@TABLE:{model}:{hex}")
            } else {
                recipe
            };
            a.push(recipe);
            if tame && slow {
                a.extend(match sub {
                    "sweep" => {
                        let mut v = vec!["--vary".to_string(), format!("{}:{}", range(rng), 1 + rng.below(3))];
                        if rng.chance(0.3) {
                            v.extend(["--format".into(), "jsonl".into()]);
                        }
                        if rng.chance(0.3) {
                            v.extend(["--shard".into(), rng.pick(&["1/2", "2/2", "2/3"]).to_string()]);
                        }
                        v
                    }
                    "fit" => {
                        let t = *rng.pick(&[
                            "astm-d523-60/gloss=50±1",
                            "astm-d523-20/gloss=20+-0.5",
                            "astm-d523-85/gloss=90",
                            "astm-d523-60/gloss=0.5±0.1",
                        ]);
                        vec!["--free".into(), range(rng), "--target".into(), t.into()]
                    }
                    "plot" if rng.chance(0.5) => vec!["--kind".into(), "section".into()],
                    "plot" => vec!["--kind".into(), "gloss-vs-parameter".into(), "--vary".into(), range(rng)],
                    _ => vec![],
                });
                if sub == "plot" {
                    a.extend(["-o".into(), rng.pick(&["@NEW.svg", "@NEW.png"]).to_string()]);
                }
                if sub != "plot" && rng.chance(0.5) {
                    a.extend(["-o".into(), "@NEW".into()]);
                }
                if sub == "profile" && rng.chance(0.5) {
                    a.extend(["--plot".into(), rng.pick(&["@NEW.svg", "@NEW.png"]).to_string()]);
                }
            }
            if sub == "compare" {
                a.push(match src {
                    Some(s) => s.sheet.unwrap().to_string(),
                    None if rng.chance(0.9) => rng.pick(&sheets).clone(),
                    None => "nope.csv".into(),
                });
            }
            if src.is_some() && (!tame || rng.chance(0.6)) {
                a.push("--baseline".into());
                a.push(cli_value("--baseline", rng));
            }
            if cheap {
                let budget: &[&str] = match sub {
                    "measure" => &["--max-seconds", "1"],
                    "compare" => &["--rtol", "1e-3"],
                    "sweep" => &["--rtol", "1e-2", "--max-evals", "20000"],
                    "fit" => &["--rtol", "1e-2", "--restarts", "0"],
                    "plot" => &["--rtol", "1e-2", "--points", "2"],
                    "profile" => &["--rtol", "1e-2", "--max-total-evals", "2000000"],
                    _ => &[],
                };
                a.extend(budget.iter().map(|s| s.to_string()));
            }
            match sub {
                _ if tame && slow => {}
                "convergence" => {
                    let t = if tame { "1e-2,1e-3".to_string() } else { cli_value("--tolerances", rng) };
                    a.extend(["--tolerances".into(), t, "--max-repetitions".into(), "1".into()]);
                    a.extend(["--min-time-ms".into(), "0".into(), "-g".into(), "astm-d523-60".into()]);
                }
                // What each needs (most of the time): a varied path, a free parameter and a target, a kind and
                // a picture.
                "sweep" if rng.chance(0.9) => {
                    if rng.chance(0.05) {
                        // The shard of one point of a hypercube of 2⁶⁴ − 1 points.
                        let n = "18446744073709551615";
                        a.extend(["--vary".into(), "/roughness=0.05..0.3".into(), "--lhs".into(), n.into()]);
                        a.extend(["--shard".into(), format!("{}/{n}", rng.pick(&["1", "2", n]))]);
                    } else {
                        a.extend(["--vary".into(), cli_value("--vary", rng)]);
                    }
                }
                "fit" if rng.chance(0.9) => {
                    a.extend(["--free".into(), cli_value("--free", rng)]);
                    if rng.chance(0.8) {
                        a.extend(["--target".into(), cli_value("--target", rng)]);
                    } else {
                        a.extend(["--sheet".into(), rng.pick(&sheets).clone()]);
                    }
                }
                "plot" if rng.chance(0.9) => {
                    let kind = if rng.chance(0.5) { "section" } else { "gloss-vs-parameter" };
                    a.extend(["--kind".into(), kind.into(), "-o".into(), cli_value("--plot", rng)]);
                    if kind == "gloss-vs-parameter" && rng.chance(0.8) {
                        a.extend(["--vary".into(), rng.pick(POINTER_RANGES).to_string()]);
                    }
                }
                _ => {}
            }
            // Fewer random options for the newer subcommands, so that more of them get past the parser.
            for _ in 0..if tame { 0 } else { rng.below(if slow { 3 } else { 5 }) } {
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

/// Whether a `sweep` command line asks for a shard that holds no point and so rightly writes nothing: its
/// range `[⌊(K−1)·P/M⌋, ⌊K·P/M⌋)` of the P points (the product of the grid's N, or the hypercube's N) is empty,
/// and it is not shard 1 of a CSV (which writes the header). False when any of it does not parse.
pub fn sweep_shard_is_empty(args: &[String]) -> bool {
    if args.first().map(String::as_str) != Some("sweep") {
        return false;
    }
    let value = |opt: &str| args.windows(2).filter(|w| w[0] == opt).map(|w| w[1].as_str()).next_back();
    let Some((k, m)) = value("--shard").and_then(|s| s.split_once('/')) else { return false };
    let (Ok(k), Ok(m)) = (k.parse::<u128>(), m.parse::<u128>()) else { return false };
    let points = match value("--lhs") {
        Some(n) => n.parse::<u128>().ok(),
        None => args
            .windows(2)
            .filter(|w| w[0] == "--vary")
            .map(|w| w[1].rsplit_once(':').and_then(|(_, n)| n.parse::<u128>().ok()))
            .try_fold(1u128, |p, n| n.map(|n| p.saturating_mul(n))),
    };
    let Some(p) = points else { return false };
    if !(1..=m).contains(&k) {
        return false;
    }
    let empty = (k - 1) * p / m == k * p / m;
    empty && (k > 1 || value("--format") == Some("jsonl"))
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
    let mut written = Vec::new();
    let args: Vec<String> = args
        .into_iter()
        .map(|a| {
            if let Some(ext) = a.strip_prefix("@NEW") {
                let ext = ext.strip_prefix('.').unwrap_or("out");
                let p = scratch(&format!("cli-{n}-{}.{ext}", new_files.len()));
                let _ = std::fs::remove_file(&p);
                new_files.push(p.clone());
                p.to_string_lossy().into_owned()
            } else if let Some((model, hex)) = a.strip_prefix("@TABLE:").and_then(|t| t.split_once(':')) {
                let ext = match model {
                    "inplane-csv" => "csv",
                    "e1392" => "txt",
                    "rgl" => "bsdf",
                    _ => "binary",
                };
                let bytes: Vec<u8> =
                    (0..hex.len() / 2).map(|i| u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).unwrap()).collect();
                let table = scratch(&format!("cli-{n}-table.{ext}"));
                std::fs::write(&table, bytes).unwrap();
                let recipe = scratch(&format!("cli-{n}-table.json"));
                let json = serde_json::json!({"model": model, "file": table.to_string_lossy()});
                std::fs::write(&recipe, json.to_string()).unwrap();
                written.push(table);
                written.push(recipe.clone());
                recipe.to_string_lossy().into_owned()
            } else if let Some(text) = a.strip_prefix("@FILE:") {
                let p = scratch(&format!("cli-{n}-in-{}.json", written.len()));
                std::fs::write(&p, text).unwrap();
                written.push(p.clone());
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
            let named = args
                .windows(2)
                .any(|w| matches!(w[0].as_str(), "-o" | "--output" | "--plot") && w[1] == f.to_string_lossy());
            if !named {
                continue;
            }
            let len = std::fs::metadata(f).map(|m| m.len());
            match (code, len) {
                (Some(2), Ok(_)) => v = fail("a file left behind by a refused run"),
                (Some(0 | 1), Ok(0)) if !sweep_shard_is_empty(&args) => v = fail("an empty output file"),
                (Some(0 | 1), Err(_)) => v = fail("an output file missing after success"),
                _ => {}
            }
        }
        v
    };
    for f in new_files.iter().chain(&written).chain([&out_path, &err_path]) {
        let _ = std::fs::remove_file(f);
    }
    verdict
}

// ---------------------------------------------------------------------------------------------------------
// Workbooks: generated .xlsx and .ods (zip archives whose XML is written here, now and then mutated as text
// before it is zipped, so the archive is sound and the reader sees the broken XML) and byte-mutated seeds
// (the shipped workbooks and the hostile reproducers: broken archives, CRCs, compound files and records).
// ---------------------------------------------------------------------------------------------------------

/// A workbook case: its bytes written to a scratch file; the case's text is the file's path.
pub fn generate_workbook(rng: &mut Rng, seeds: &Seeds) -> String {
    let (bytes, ext) = match rng.below(10) {
        0..=3 => (xlsx_bytes(rng), "xlsx"),
        4 | 5 => (ods_bytes(rng), "ods"),
        6 => {
            let b = if rng.chance(0.5) { xlsx_bytes(rng) } else { ods_bytes(rng) };
            (mutate_bytes(&b, rng), "xlsx")
        }
        _ => {
            let (b, ext) = rng.pick(&seeds.workbooks);
            (mutate_bytes(b, rng), *ext)
        }
    };
    let path = scratch(&format!("wb-{:016x}.{ext}", rng.next()));
    std::fs::write(&path, bytes).unwrap();
    path.display().to_string()
}

/// Read a workbook case through the one sheet reader (`sheet::from_bytes`, as `compare`, `fit --sheet`, the
/// server and Python read it): accepted with finite rows, or refused with an input error naming the file. A
/// workbook's reasons about the whole file (not a workbook, a member too large, a bad CRC, no sheets) name no
/// field or line; a cell's name its sheet and cell.
pub fn run_workbook(path: &str) -> Result<Outcome, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("the case's file {path}: {e}"))?;
    // GLOSSMETER_FUZZ_KEEP=1 keeps the file, to replay a case by hand (docs/reliability.md §Replaying a case).
    if std::env::var_os("GLOSSMETER_FUZZ_KEEP").is_none() {
        let _ = std::fs::remove_file(path);
    }
    let name = "fuzz.xlsx";
    match sheet::from_bytes(&bytes, name, &sheet::SheetOptions::default()) {
        Ok(sheet) => {
            if sheet.rows.iter().any(|r| !r.value.is_finite() || r.uncertainty.is_some_and(|u| !u.is_finite())) {
                return Err("a workbook row holds a non-finite number".into());
            }
            Ok(Outcome::Accepted(None))
        }
        Err(e) => {
            let shown = e.to_string();
            if prints_non_finite(&shown) {
                return Err(format!("an error prints a non-finite number (outside the quoted input): {shown}"));
            }
            match &e {
                Error::Input { file, message, .. } if file == name && !message.trim().is_empty() => {
                    Ok(Outcome::Refused)
                }
                Error::Input { .. } => {
                    Err(format!("an input error that does not name {name} or says nothing: {shown}"))
                }
                other => Err(format!("not an input error: {other:?}")),
            }
        }
    }
}

/// A cell's text: a layout's header words, sample names, numbers (edge ones too), statistics rows' labels.
fn workbook_cell(rng: &mut Rng) -> (bool, String) {
    if rng.chance(0.45) {
        let v =
            *rng.pick(&["89.1", "0", "-3", "1e308", "1e400", "5e-324", "NaN", "INF", "12.5", "0.3", "-0", "1e-300"]);
        return (true, v.to_string());
    }
    let t = *rng.pick(&[
        "Sample",
        "sample",
        "geometry",
        "quantity",
        "value",
        "uncertainty",
        "20°",
        "60°",
        "85°",
        "20",
        "60",
        "85",
        "Haze",
        "DOI",
        "RIQ",
        "Mean",
        "Std",
        "Min",
        "Max",
        "p1",
        "panel 2",
        "",
        "BYK-Gardner smart-chart 4.2",
        "Instrument: micro-TRI-gloss",
        "astm-d523-60",
        "gloss",
        "log-haze",
        "x",
        "<&>",
        "\u{0}",
        "é",
    ]);
    (false, t.to_string())
}

/// A sheet's cells, row by row (true: a number): half the time an instrument's layout (title and metadata
/// rows now and then, a header of sample and angle columns, sample rows of readings, statistics rows now and
/// then) with a cell now and then replaced by a random one, half the time random cells.
fn workbook_grid(rng: &mut Rng) -> Vec<Vec<(bool, String)>> {
    let text = |t: &str| (false, t.to_string());
    if rng.chance(0.5) {
        return (0..1 + rng.below(8)).map(|_| (0..1 + rng.below(6)).map(|_| workbook_cell(rng)).collect()).collect();
    }
    let mut grid = Vec::new();
    if rng.chance(0.3) {
        grid.push(vec![text("BYK-Gardner smart-chart 4.2 - Gloss report")]);
        grid.push(vec![text("Instrument: micro-TRI-gloss"), text(""), text("Serial No.: 1087654")]);
        grid.push(vec![]);
    }
    const LAYOUTS: [&[&str]; 4] = [&["20°", "60°", "85°"], &["20", "60", "85"], &["60° [GU]"], &["Haze", "20°"]];
    let angles: &[&str] = LAYOUTS[rng.below(LAYOUTS.len())];
    let mut header = vec![text(if rng.chance(0.5) { "Sample" } else { "sample" })];
    header.extend(angles.iter().map(|a| text(a)));
    grid.push(header);
    for i in 0..1 + rng.below(5) {
        let mut row = vec![text(&format!("panel {}", i % 2))];
        for _ in angles {
            let v = 0.1 * rng.below(1000) as f64;
            row.push(if rng.chance(0.05) { workbook_cell(rng) } else { (true, format!("{v}")) });
        }
        grid.push(row);
    }
    if rng.chance(0.2) {
        for label in ["Mean", "Std"] {
            let mut row = vec![text(label)];
            row.extend(angles.iter().map(|_| (true, "1.5".to_string())));
            grid.push(row);
        }
    }
    grid
}

/// Column letters of a 0-based column index (A, …, Z, AA, …).
fn column_letters(mut c: usize) -> String {
    let mut s = Vec::new();
    loop {
        s.push(b'A' + (c % 26) as u8);
        if c < 26 {
            break;
        }
        c = c / 26 - 1;
    }
    s.reverse();
    String::from_utf8(s).unwrap()
}

fn xml_escape(t: &str) -> String {
    t.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('\u{0}', "")
}

fn zip_members(rng: &mut Rng, members: &[(&str, String)]) -> Vec<u8> {
    use std::io::Write;
    let mut w = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for (name, text) in members {
        let method = if *name == "mimetype" || rng.chance(0.5) {
            zip::CompressionMethod::Stored
        } else {
            zip::CompressionMethod::Deflated
        };
        let options = zip::write::SimpleFileOptions::default().compression_method(method);
        w.start_file(*name, options).unwrap();
        w.write_all(text.as_bytes()).unwrap();
    }
    w.finish().unwrap().into_inner()
}

/// A generated `.xlsx`: a title row now and then, a header, rows of cells (shared, inline strings and
/// numbers), a declared dimension (sometimes absurd), a shared-string table whose counts may lie, a cell now
/// and then far away; one XML part mutated as text in half of the cases.
pub fn xlsx_bytes(rng: &mut Rng) -> Vec<u8> {
    let mut shared: Vec<String> = Vec::new();
    let mut rows = String::new();
    let grid = workbook_grid(rng);
    let nrows = grid.len();
    let ncols = grid.iter().map(Vec::len).max().unwrap_or(1);
    for (r, cells) in grid.into_iter().enumerate() {
        rows.push_str(&format!("<row r=\"{}\">", r + 1));
        for (c, (number, t)) in cells.into_iter().enumerate() {
            let at = format!("{}{}", column_letters(c), r + 1);
            if number {
                rows.push_str(&format!("<c r=\"{at}\"><v>{}</v></c>", xml_escape(&t)));
            } else if rng.chance(0.7) {
                shared.push(t);
                rows.push_str(&format!("<c r=\"{at}\" t=\"s\"><v>{}</v></c>", shared.len() - 1));
            } else {
                rows.push_str(&format!("<c r=\"{at}\" t=\"inlineStr\"><is><t>{}</t></is></c>", xml_escape(&t)));
            }
        }
        rows.push_str("</row>");
    }
    if rng.chance(0.1) {
        let far = *rng.pick(&["XFD1048576", "A1048576", "XFD1", "ZZZ99", "A0"]);
        rows.push_str(&format!("<row r=\"{}\"><c r=\"{far}\"><v>1</v></c></row>", nrows + 1));
    }
    let dimension = if rng.chance(0.1) {
        rng.pick(&["A1:XFD1048576", "B9:A1", "A1:A4294967296", "", "A1:"]).to_string()
    } else {
        format!("A1:{}{}", column_letters(ncols - 1), nrows)
    };
    let count = if rng.chance(0.1) {
        *rng.pick(&[0u64, 1, 100_000_000_000_000, u32::MAX as u64, u64::MAX])
    } else {
        shared.len() as u64
    };
    let sst: String = shared.iter().map(|t| format!("<si><t>{}</t></si>", xml_escape(t))).collect();
    let ns = "http://schemas.openxmlformats.org/spreadsheetml/2006/main";
    let rel = "http://schemas.openxmlformats.org/officeDocument/2006/relationships";
    let mut parts: Vec<(&str, String)> = vec![
        (
            "[Content_Types].xml",
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?><Types xmlns=\"http://schemas.openxmlformats.org/package/2006/content-types\">\
             <Default Extension=\"rels\" ContentType=\"application/vnd.openxmlformats-package.relationships+xml\"/>\
             <Default Extension=\"xml\" ContentType=\"application/xml\"/>\
             <Override PartName=\"/xl/workbook.xml\" ContentType=\"application/vnd.openxmlformats-officedocument.spreadsheetml.sheet.main+xml\"/>\
             <Override PartName=\"/xl/worksheets/sheet1.xml\" ContentType=\"application/vnd.openxmlformats-officedocument.spreadsheetml.worksheet+xml\"/>\
             <Override PartName=\"/xl/sharedStrings.xml\" ContentType=\"application/vnd.openxmlformats-officedocument.spreadsheetml.sharedStrings+xml\"/>\
             </Types>"
                .to_string(),
        ),
        (
            "_rels/.rels",
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?><Relationships xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\">\
             <Relationship Id=\"rId1\" Type=\"http://schemas.openxmlformats.org/officeDocument/2006/relationships/officeDocument\" Target=\"xl/workbook.xml\"/>\
             </Relationships>"
                .to_string(),
        ),
        (
            "xl/workbook.xml",
            format!(
                "<?xml version=\"1.0\" encoding=\"UTF-8\"?><workbook xmlns=\"{ns}\" xmlns:r=\"{rel}\"><sheets>\
                 <sheet name=\"{}\" sheetId=\"1\" r:id=\"rId1\"/></sheets></workbook>",
                rng.pick(&["Sheet1", "Gloss report", "", "&amp;"])
            ),
        ),
        (
            "xl/_rels/workbook.xml.rels",
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?><Relationships xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\">\
             <Relationship Id=\"rId1\" Type=\"http://schemas.openxmlformats.org/officeDocument/2006/relationships/worksheet\" Target=\"worksheets/sheet1.xml\"/>\
             <Relationship Id=\"rId2\" Type=\"http://schemas.openxmlformats.org/officeDocument/2006/relationships/sharedStrings\" Target=\"sharedStrings.xml\"/>\
             </Relationships>"
                .to_string(),
        ),
        (
            "xl/worksheets/sheet1.xml",
            format!(
                "<?xml version=\"1.0\" encoding=\"UTF-8\"?><worksheet xmlns=\"{ns}\"><dimension ref=\"{dimension}\"/>\
                 <sheetData>{rows}</sheetData></worksheet>"
            ),
        ),
        (
            "xl/sharedStrings.xml",
            format!(
                "<?xml version=\"1.0\" encoding=\"UTF-8\"?><sst xmlns=\"{ns}\" count=\"{count}\" uniqueCount=\"{count}\">{sst}</sst>"
            ),
        ),
    ];
    if rng.chance(0.5) {
        let k = rng.below(parts.len());
        parts[k].1 = mutate(&parts[k].1, rng);
    }
    if rng.chance(0.05) {
        parts.remove(rng.below(parts.len()));
    }
    zip_members(rng, &parts)
}

/// A generated `.ods`: the same cells in `content.xml`, with `number-rows-repeated` and
/// `number-columns-repeated` now and then large; the XML mutated as text in half of the cases.
pub fn ods_bytes(rng: &mut Rng) -> Vec<u8> {
    let mut table = String::new();
    for cells in workbook_grid(rng) {
        let rep = if rng.chance(0.1) { *rng.pick(&[2u64, 1000, 250_000, 1_000_000, 1 << 31, u64::MAX]) } else { 1 };
        table.push_str(&format!("<table:table-row table:number-rows-repeated=\"{rep}\">"));
        for (number, t) in cells {
            let crep = if rng.chance(0.05) { *rng.pick(&[2u64, 16384, 1 << 20, u32::MAX as u64]) } else { 1 };
            if number {
                table.push_str(&format!(
                    "<table:table-cell table:number-columns-repeated=\"{crep}\" office:value-type=\"float\" \
                     office:value=\"{}\"><text:p>{}</text:p></table:table-cell>",
                    xml_escape(&t),
                    xml_escape(&t)
                ));
            } else {
                table.push_str(&format!(
                    "<table:table-cell table:number-columns-repeated=\"{crep}\" office:value-type=\"string\">\
                     <text:p>{}</text:p></table:table-cell>",
                    xml_escape(&t)
                ));
            }
        }
        table.push_str("</table:table-row>");
    }
    let content = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?><office:document-content \
         xmlns:office=\"urn:oasis:names:tc:opendocument:xmlns:office:1.0\" \
         xmlns:table=\"urn:oasis:names:tc:opendocument:xmlns:table:1.0\" \
         xmlns:text=\"urn:oasis:names:tc:opendocument:xmlns:text:1.0\" office:version=\"1.2\"><office:body>\
         <office:spreadsheet><table:table table:name=\"Sheet1\">{table}</table:table></office:spreadsheet>\
         </office:body></office:document-content>"
    );
    let manifest = "<?xml version=\"1.0\" encoding=\"UTF-8\"?><manifest:manifest \
                    xmlns:manifest=\"urn:oasis:names:tc:opendocument:xmlns:manifest:1.0\" manifest:version=\"1.2\">\
                    <manifest:file-entry manifest:full-path=\"/\" manifest:media-type=\"application/vnd.oasis.opendocument.spreadsheet\"/>\
                    <manifest:file-entry manifest:full-path=\"content.xml\" manifest:media-type=\"text/xml\"/>\
                    </manifest:manifest>"
        .to_string();
    let mut parts: Vec<(&str, String)> = vec![
        ("mimetype", "application/vnd.oasis.opendocument.spreadsheet".to_string()),
        ("META-INF/manifest.xml", manifest),
        ("content.xml", content),
    ];
    if rng.chance(0.5) {
        parts[2].1 = mutate(&parts[2].1, rng);
    }
    zip_members(rng, &parts)
}
