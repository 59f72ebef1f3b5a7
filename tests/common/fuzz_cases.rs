//! The fuzz campaign's cases and checks, shared by the property tests (`tests/fuzz.rs`, bounded, in
//! `cargo test`) and the hand-run driver (`examples/fuzz.rs`, 10⁶ cases; results in docs/reliability.md).
//!
//! Cases are generated or mutated from the shipped inputs: recipes (`fixtures/recipes`, `fixtures/bad`),
//! geometry files (`standards/`, `fixtures/geometry`) and sheets (`fixtures/sheets`). The check is the
//! contract of docs/instrument.md: an input is either accepted, or refused with an input error that names
//! the file and either a field or a line; never a panic, and a reading is never NaN or infinite.
#![allow(dead_code)]
use std::path::{Path, PathBuf};

use glossmeter::instrument::{sheet, standards};
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
}

impl Category {
    pub const ALL: [Category; 4] =
        [Category::GeneratedRecipe, Category::MutatedRecipe, Category::MutatedGeometry, Category::Sheet];
    pub fn name(self) -> &'static str {
        match self {
            Category::GeneratedRecipe => "generated recipes",
            Category::MutatedRecipe => "mutated recipes",
            Category::MutatedGeometry => "mutated geometry files",
            Category::Sheet => "generated and mutated sheets",
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
    if shown.contains("NaN") && !shown.contains("\"NaN\"") {
        return Err(format!("an error prints NaN: {shown}"));
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
        Category::GeneratedRecipe => generate_recipe(rng),
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
