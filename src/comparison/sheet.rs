//! Instrument sheets: readings taken with real glossmeters, as the instruments and spreadsheets write them,
//! to compare predictions against (`compare`, `fit --sheet`).
//!
//! Real sheets are not tidy, so the reader accepts what instruments and Excel actually write
//! (docs/instrument.md §Sheets has the full table):
//!
//! * UTF-8 with or without a byte-order mark, UTF-16 with a BOM, and anything else as Windows-1252
//!   (older exports write `°` as the single byte 0xB0), decoded with `encoding_rs`;
//! * `,`, `;` or tab separators, detected from the header line (or given), CRLF or LF line ends, quoted
//!   fields (also across lines), decimal commas (`89,1`);
//! * `#` comment lines anywhere; `# key: value` lines are kept as the sheet's metadata;
//! * three layouts: **colour** (a `geometry` column with `L*`, `a*`, `b*` columns, as multi-angle
//!   spectrophotometers export; each row three readings), **long** (a `geometry` and a `value` column, one reading per row) and **wide** (one column
//!   per reading, named as instruments name them: `20°`, `Gloss 60`, `Haze`, `HU_LOG`, `DOI`, `Rspec`, ...;
//!   the aliases are the table [`READING_COLUMNS`] plus the gloss-angle pattern of [`gloss_angle`]);
//! * repeated readings: several rows for the same sample, or columns with a repeat suffix (`60° #2`,
//!   `60° (2)`, `60° [2]`).
//!
//! * the makers' statistics columns (`Mean 20°`, `Std 20°`, `Min`, `Max`, `Range`; [`super::series`]): each
//!   value is checked against the series of readings it summarises;
//! * workbooks (`.xlsx`, `.xls`, `.ods`, …; [`super::workbook`]): one sheet, by name or the first, read by the
//!   same rules, positions named as cells (`sheet "Readings", row 5, cell C5`).
//!
//! A column the reader does not recognise is an error (unless the caller ignores it by name), so that no reading
//! is silently dropped. Every error names the file, the line (or the workbook's sheet, row and cell) and the column.
use std::collections::HashMap;
use std::path::Path;

use super::series::{self, Series, Statistic};
use super::workbook;
use crate::error::Words;
use crate::{Error, Result};

/// A reading column an instrument writes, and the glossmeter reading it stands for. `not_predicted` is set for
/// readings whose formula is not public (they are reported as "not predicted", never dropped).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReadingColumn {
    /// Normalised header names (lower case, only letters and digits; see [`normalise`]).
    pub names: &'static [&'static str],
    /// The geometry id and the reading (a reading name or a quantity of that geometry).
    pub geometry: &'static str,
    pub reading: &'static str,
    pub not_predicted: Option<&'static str>,
    /// Where the mapping comes from (shown in the docs table).
    pub source: &'static str,
}

const NOT_PUBLIC: &str = "the maker's formula is not public";

/// Header aliases of the readings other than plain gloss (for gloss see [`gloss_angle`]). To add a reading
/// (e.g. colour columns), add a row; the docs table in docs/instrument.md §Sheets lists the same rows.
pub const READING_COLUMNS: &[ReadingColumn] = &[
    ReadingColumn {
        names: &["haze", "hu", "haze20", "20haze", "hazehu"],
        geometry: IQ,
        reading: "haze",
        not_predicted: None,
        source: "Rhopoint IQ / Elcometer 408 haze on the 20° pixel array (ASTM E430 windows; `rhopoint-iq-20`, \
                 docs/instrument.md §1.9)",
    },
    ReadingColumn {
        names: &["loghaze", "hulog", "hazelog", "loghu", "loghaze20", "hazeloghu"],
        geometry: IQ,
        reading: "log-haze",
        not_predicted: None,
        source: "Rhopoint IQ HU_LOG / Elcometer 408 HULog on the 20° pixel array (`rhopoint-iq-20`, §1.9)",
    },
    ReadingColumn {
        names: &["hazeiso13803", "iso13803haze", "iso13803"],
        geometry: "iso-13803-20",
        reading: "haze",
        not_predicted: None,
        source: "ISO 13803 20° haze of a gloss-haze meter with fixed haze detectors (BYK haze-gloss class)",
    },
    ReadingColumn {
        names: &["loghazeiso13803", "iso13803loghaze"],
        geometry: "iso-13803-20",
        reading: "log-haze",
        not_predicted: None,
        source: "ISO 13803 log haze of a gloss-haze meter with fixed haze detectors (docs/instrument.md §1.6)",
    },
    ReadingColumn {
        names: &["hazenarrow", "narrowhaze", "hazen"],
        geometry: "astm-e430-30",
        reading: "haze-narrow",
        not_predicted: None,
        source: "ASTM E430 narrow-angle haze at 30°",
    },
    ReadingColumn {
        names: &["hazewide", "widehaze", "hazew"],
        geometry: "astm-e430-30",
        reading: "haze-wide",
        not_predicted: None,
        source: "ASTM E430 wide-angle haze at 30°",
    },
    ReadingColumn {
        names: &["doi", "distinctnessofimage", "doi20"],
        geometry: IQ,
        reading: "doi",
        not_predicted: None,
        source: "Rhopoint IQ / Elcometer 408 DOI on the 20° profile (`rhopoint-iq-20`, docs/instrument.md §1.9)",
    },
    ReadingColumn {
        names: &["doi30", "doie430", "e430doi"],
        geometry: "astm-e430-30",
        reading: "doi",
        not_predicted: None,
        source: "ASTM E430 DOI (Hunter/Dorigon form) at 30°",
    },
    ReadingColumn {
        names: &["hazeindex", "d4039", "hazeindexgu"],
        geometry: "astm-d4039",
        reading: "haze-index",
        not_predicted: None,
        source: "ASTM D4039 haze index G60 − G20",
    },
    ReadingColumn {
        names: &["rspec", "rspec20"],
        geometry: IQ,
        reading: "rspec",
        not_predicted: None,
        source: "Rhopoint IQ peak specular reflectance, ±0.0991° of the 20° array (`rhopoint-iq-20`, §1.9)",
    },
    ReadingColumn {
        names: &["riq", "reflectedimagequality"],
        geometry: IQ,
        reading: "riq",
        not_predicted: Some(NOT_PUBLIC),
        source: "Rhopoint IQ reflected image quality",
    },
    ReadingColumn {
        names: &["doic", "doicomp", "doicompensated", "compensateddoi", "doicomp20"],
        geometry: IQ,
        reading: "doi-compensated",
        not_predicted: Some(NOT_PUBLIC),
        source: "makers' compensated DOI",
    },
];

/// The geometry of a Rhopoint IQ-class meter's 20° pixel-array readings: an IQ sheet's Haze, Log Haze, DOI,
/// Rspec and RIQ columns are readings of it (its 20°, 60° and 85° gloss columns are the ISO 2813 / D523 gloss
/// the maker says they follow, [`GLOSS_ANGLES`]).
pub const IQ: &str = "rhopoint-iq-20";

/// Columns that say which sample a row is.
pub const SAMPLE_COLUMNS: &[&str] =
    &["sample", "samplename", "sampleid", "specimen", "name", "id", "panel", "probe", "probenname", "muster"];
/// Columns kept by the reader but not compared (bookkeeping that instruments add to each row).
pub const INFO_COLUMNS: &[&str] = &[
    "date",
    "datum",
    "time",
    "datetime",
    "timestamp",
    "operator",
    "user",
    "comment",
    "comments",
    "note",
    "notes",
    "no",
    "nr",
    "number",
    "index",
    "unit",
    "units",
];
/// The long layout's columns.
pub const GEOMETRY_COLUMNS: &[&str] = &["geometry", "geometryid"];
pub const QUANTITY_COLUMNS: &[&str] = &["quantity", "reading", "readingname"];
pub const VALUE_COLUMNS: &[&str] = &["value", "measured", "measurement"];
pub const UNCERTAINTY_COLUMNS: &[&str] = &["uncertainty", "u", "unc"];
/// The colour layout's columns (normalised) and the readings they give: L*, a*, b*.
pub const LAB_COLUMNS: &[(&[&str], &str)] =
    &[(&["l", "lstar", "cielabl"], "L*"), (&["a", "astar", "cielaba"], "a*"), (&["b", "bstar", "cielabb"], "b*")];
/// A colour reading as a long-layout `quantity` (lower-cased) and its reading name.
const COLOUR_QUANTITIES: &[(&str, &str)] =
    &[("x", "X"), ("y", "Y"), ("z", "Z"), ("l*", "L*"), ("a*", "a*"), ("b*", "b*"), ("c*", "C*"), ("h", "h")];

/// The gloss angles instruments write, and the shipped geometry read at each.
pub const GLOSS_ANGLES: &[(&str, &str)] = &[
    ("20", "astm-d523-20"),
    ("45", "astm-d2457-45"),
    ("60", "astm-d523-60"),
    ("75", "tappi-t480-75"),
    ("85", "astm-d523-85"),
];

/// What the reader was asked to do differently from its defaults.
#[derive(Clone, Debug, Default)]
pub struct SheetOptions {
    /// The separator (`,`, `;` or tab); detected from the header line when None.
    pub delimiter: Option<u8>,
    /// Column headers to skip (matched like aliases: case, spaces and punctuation do not matter).
    pub ignore_columns: Vec<String>,
    /// The sheet of a workbook to read (the first when None); refused for a text sheet.
    pub sheet_name: Option<String>,
}

/// One measured value.
#[derive(Clone, Debug, PartialEq)]
pub struct SheetRow {
    /// The line of the file the row starts on (1-based, counting comment and blank lines).
    pub line: usize,
    /// The header of the column the value came from.
    pub column: String,
    pub sample: String,
    pub geometry: String,
    /// A quantity (`gloss`, `haze`, `doi`, …) or a reading name (`haze-narrow`, …).
    pub reading: String,
    pub value: f64,
    pub uncertainty: Option<f64>,
    /// Set when the sheet's column is recognised but the reading's formula is not public.
    pub not_predicted: Option<String>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    Long,
    Wide,
    /// A `geometry` column and `L*`, `a*`, `b*` columns (multi-angle spectrophotometers).
    Colour,
}

/// A parsed sheet: its rows and what the reader found out about the file.
#[derive(Clone, Debug)]
pub struct Sheet {
    pub file: String,
    /// `UTF-8`, `UTF-8 with BOM`, `UTF-16LE with BOM`, `windows-1252`, ...
    pub encoding: String,
    pub delimiter: u8,
    pub layout: Layout,
    /// `# key: value` lines, in file order.
    pub metadata: Vec<(String, String)>,
    /// Columns skipped on request.
    pub ignored_columns: Vec<String>,
    /// The header line, the headers, and the columns of the sample and the geometry (0-based), for messages.
    pub header_line: usize,
    pub headers: Vec<String>,
    pub sample_column: Option<usize>,
    pub geometry_column: Option<usize>,
    pub quantity_column: Option<usize>,
    pub rows: Vec<SheetRow>,
    /// The sheet read, when the file is a workbook (then `encoding` is `xlsx workbook` etc., lines are its rows,
    /// and positions are named as its cells, counting columns from `first_column`, 0-based).
    pub workbook_sheet: Option<String>,
    pub first_column: u32,
    /// The statistics cells (`Mean 20°`, …) checked against their series.
    pub statistics_checked: usize,
}

impl Sheet {
    /// The metadata as a JSON object (a key given twice keeps both values, joined by "; ").
    pub fn metadata_json(&self) -> serde_json::Value {
        let mut m = serde_json::Map::new();
        for (k, v) in &self.metadata {
            match m.get_mut(k) {
                Some(serde_json::Value::String(old)) => {
                    old.push_str("; ");
                    old.push_str(v);
                }
                _ => {
                    m.insert(k.clone(), serde_json::Value::String(v.clone()));
                }
            }
        }
        serde_json::Value::Object(m)
    }

    /// `line L, column C (header)` of a row's sample or geometry cell (`sheet "S", row L, cell B7 (header)` in
    /// a workbook).
    pub fn cell(&self, line: usize, column: Option<usize>, what: &str) -> String {
        let place = self.place();
        match column {
            Some(c) => at(&place, line, c, &self.headers[c]),
            None => format!("{} (no {what} column)", place.line(line)),
        }
    }

    fn place(&self) -> Place {
        match &self.workbook_sheet {
            Some(sheet) => Place::Cells { sheet: sheet.clone(), first_column: self.first_column },
            None => Place::Lines,
        }
    }

    /// The distinct geometry ids of the rows, in order of appearance.
    pub fn geometry_ids(&self) -> Vec<String> {
        let mut ids: Vec<String> = Vec::new();
        for r in &self.rows {
            if !ids.contains(&r.geometry) {
                ids.push(r.geometry.clone());
            }
        }
        ids
    }
}

/// Read a sheet file (or `-`, standard input): a workbook if its bytes are one ([`workbook::is_workbook`]),
/// else text.
pub fn load(path: &Path, options: &SheetOptions) -> Result<Sheet> {
    let file = crate::input::name(path);
    let bytes = crate::input::read_bytes(path, "sheet")?;
    from_bytes(&bytes, &file, options)
}

/// A sheet from its bytes, named `file` in messages: a workbook (.xlsx, .xlsm, .xlsb, .xls, .ods) by its
/// signature, else a text sheet. The one entry point of every front end (the command line through [`load`],
/// the server and Python with the bytes they were given), so that the same bytes give the same sheet.
pub fn from_bytes(bytes: &[u8], file: &str, options: &SheetOptions) -> Result<Sheet> {
    if workbook::is_workbook(bytes) {
        return parse_workbook(bytes, file, options);
    }
    if options.sheet_name.is_some() {
        return Err(Error::Argument(
            Words::from(format!("{file} is a text sheet, not a workbook: "))
                .and_argument("sheet_name")
                .and(" names a sheet of an .xlsx, .xls or .ods workbook"),
        ));
    }
    parse_bytes(bytes, file, options)
}

/// A workbook's sheet (`options.sheet_name`, or the first) read by the rules of a text sheet.
pub fn parse_workbook(bytes: &[u8], file: &str, options: &SheetOptions) -> Result<Sheet> {
    if options.delimiter.is_some() {
        return Err(Error::Argument(
            Words::from(format!("{file} is a workbook, which has cells, not separators: "))
                .and_argument("delimiter")
                .and(" applies to text sheets"),
        ));
    }
    let w = workbook::read(bytes, file, options.sheet_name.as_deref())?;
    let place = Place::Cells { sheet: w.sheet.clone(), first_column: w.first_column };
    let text_options = SheetOptions { delimiter: Some(b','), ..options.clone() };
    let mut sheet = parse_at(&w.text, file, &text_options, &place)?;
    sheet.encoding = format!("{} workbook", w.format);
    sheet.workbook_sheet = Some(w.sheet);
    sheet.first_column = w.first_column;
    Ok(sheet)
}

/// Decode a sheet's bytes: a BOM decides; else UTF-8 if it is valid UTF-8; else Windows-1252.
pub fn decode(bytes: &[u8], file: &str) -> Result<(String, String)> {
    if let Some((enc, bom)) = encoding_rs::Encoding::for_bom(bytes) {
        let (text, had_errors) = enc.decode_without_bom_handling(&bytes[bom..]);
        if had_errors {
            return Err(Error::input(file, "", format!("not valid {} although it starts with a BOM", enc.name())));
        }
        return Ok((text.into_owned(), format!("{} with BOM", enc.name())));
    }
    if bytes.contains(&0) {
        return Err(Error::input(
            file,
            "",
            "contains NUL bytes: not a text sheet (UTF-16 needs a BOM; allowed: UTF-8, UTF-16 with BOM, Windows-1252)",
        ));
    }
    match std::str::from_utf8(bytes) {
        Ok(s) => Ok((s.to_string(), "UTF-8".into())),
        Err(_) => {
            let (text, _) = encoding_rs::WINDOWS_1252.decode_without_bom_handling(bytes);
            Ok((text.into_owned(), "windows-1252".into()))
        }
    }
}

pub fn parse_bytes(bytes: &[u8], file: &str, options: &SheetOptions) -> Result<Sheet> {
    let (text, encoding) = decode(bytes, file)?;
    let mut sheet = parse(&text, file, options)?;
    sheet.encoding = encoding;
    Ok(sheet)
}

/// A header as the alias tables spell it: without parenthesised units, lower case, only letters and
/// digits, without a trailing `deg`/`degree(s)`. `Gloss 60° (GU)` → `gloss60`, `HU_LOG` → `hulog`.
pub fn normalise(header: &str) -> String {
    let mut s = String::new();
    let mut depth = 0usize;
    for c in header.chars() {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' => depth = depth.saturating_sub(1),
            c if depth == 0 && c.is_alphanumeric() => s.extend(c.to_lowercase()),
            _ => {}
        }
    }
    for suffix in ["degrees", "degree", "deg"] {
        if let Some(t) = s.strip_suffix(suffix) {
            if t.ends_with(|c: char| c.is_ascii_digit()) {
                return t.to_string();
            }
        }
    }
    s
}

/// The gloss geometry of a header such as `20`, `20°`, `G60`, `Gloss 85°`, `60 gloss`, `GU 20`.
pub fn gloss_angle(normalised: &str) -> Option<&'static str> {
    let mut h = normalised;
    for p in ["gloss", "gu", "g"] {
        if let Some(t) = h.strip_prefix(p) {
            h = t;
            break;
        }
    }
    for s in ["gloss", "gu"] {
        if let Some(t) = h.strip_suffix(s) {
            h = t;
            break;
        }
    }
    GLOSS_ANGLES.iter().find(|(a, _)| *a == h).map(|(_, g)| *g)
}

/// A repeat suffix `#N`, `(N)` or `[N]` at the end of a header, and the header without it.
fn split_repeat(header: &str) -> (&str, Option<u32>) {
    let t = header.trim_end();
    let try_num = |inner: &str| inner.trim().parse::<u32>().ok();
    if let Some(i) = t.rfind('#') {
        if let Some(n) = try_num(&t[i + 1..]) {
            return (t[..i].trim_end(), Some(n));
        }
    }
    for (open, close) in [('(', ')'), ('[', ']')] {
        if t.ends_with(close) {
            if let Some(i) = t.rfind(open) {
                if let Some(n) = try_num(&t[i + 1..t.len() - 1]) {
                    return (t[..i].trim_end(), Some(n));
                }
            }
        }
    }
    (t, None)
}

/// What a header column is.
#[derive(Clone, Debug, PartialEq)]
enum Role {
    Sample,
    Info,
    Geometry,
    Quantity,
    Value,
    Uncertainty,
    /// An L*, a*, b* column of the colour layout (0, 1, 2).
    Lab(usize),
    /// A maker's statistics column, of a named reading (geometry, reading) or of the row's reading.
    Statistic {
        stat: Statistic,
        of: Option<(&'static str, &'static str)>,
    },
    /// A reading column of the wide layout: geometry, reading, repeat index, not-predicted reason.
    Reading {
        geometry: &'static str,
        reading: &'static str,
        repeat: Option<u32>,
        not_predicted: Option<&'static str>,
    },
    Ignored,
}

fn role(header: &str, ignore: &[String]) -> Option<Role> {
    let n = normalise(header);
    if ignore.iter().any(|i| normalise(i) == n) {
        return Some(Role::Ignored);
    }
    let is = |list: &[&str]| list.contains(&n.as_str());
    if is(SAMPLE_COLUMNS) {
        return Some(Role::Sample);
    }
    if is(INFO_COLUMNS) {
        return Some(Role::Info);
    }
    if is(GEOMETRY_COLUMNS) {
        return Some(Role::Geometry);
    }
    if is(QUANTITY_COLUMNS) {
        return Some(Role::Quantity);
    }
    if is(VALUE_COLUMNS) {
        return Some(Role::Value);
    }
    if is(UNCERTAINTY_COLUMNS) {
        return Some(Role::Uncertainty);
    }
    if let Some(i) = LAB_COLUMNS.iter().position(|(names, _)| is(names)) {
        return Some(Role::Lab(i));
    }
    let (base, repeat) = split_repeat(header);
    let b = normalise(base);
    if let Some(g) = gloss_angle(&b) {
        return Some(Role::Reading { geometry: g, reading: "gloss", repeat, not_predicted: None });
    }
    if let Some(c) = READING_COLUMNS.iter().find(|c| c.names.contains(&b.as_str())) {
        return Some(Role::Reading {
            geometry: c.geometry,
            reading: c.reading,
            repeat,
            not_predicted: c.not_predicted,
        });
    }
    // A statistics column: `Mean 20°`, `20° Std`, `Range Haze`, or a bare `Mean` (of the row's reading).
    let (stat, rest) = series::split(&n)?;
    if rest.is_empty() {
        return Some(Role::Statistic { stat, of: None });
    }
    let of = match gloss_angle(rest) {
        Some(g) => (g, "gloss"),
        None => READING_COLUMNS.iter().find(|c| c.names.contains(&rest)).map(|c| (c.geometry, c.reading))?,
    };
    Some(Role::Statistic { stat, of: Some(of) })
}

/// The separator of the header line: the most frequent of `;`, `,` and tab outside quotes (`,` on a tie).
pub fn detect_delimiter(header_line: &str) -> u8 {
    let mut counts = [(b',', 0usize), (b';', 0), (b'\t', 0)];
    let mut quoted = false;
    for c in header_line.bytes() {
        if c == b'"' {
            quoted = !quoted;
        } else if !quoted {
            for k in counts.iter_mut() {
                if k.0 == c {
                    k.1 += 1;
                }
            }
        }
    }
    let best = counts.iter().max_by_key(|k| k.1).expect("three candidates");
    if best.1 == 0 || counts[0].1 == best.1 {
        b','
    } else {
        best.0
    }
}

/// A number as sheets write it: `89.1`, `89,1` (decimal comma), `-1.5e-3`. A field with both `.` and `,`
/// (a thousands separator?) is refused rather than guessed.
pub fn parse_number(s: &str) -> std::result::Result<f64, String> {
    let t = s.trim();
    let t = if t.contains(',') {
        if t.contains('.') || t.matches(',').count() > 1 {
            return Err(format!("{s:?} mixes `.` and `,` (thousands separators are not read)"));
        }
        t.replace(',', ".")
    } else {
        t.to_string()
    };
    // Rust's parser reads "inf" and "NaN": they are not readings.
    if !t.bytes().all(|c| c.is_ascii_digit() || matches!(c, b'.' | b'-' | b'+' | b'e' | b'E')) {
        return Err(format!("expected a number, got {s:?}"));
    }
    t.parse::<f64>().map_err(|_| format!("expected a number, got {s:?}")).and_then(|v| {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(format!("{s:?} is not a finite number"))
        }
    })
}

/// Metadata of a comment line `# key: value` (a short key of at most four words).
fn metadata_line(line: &str) -> Option<(String, String)> {
    let body = line.trim_start().strip_prefix('#')?.trim();
    let (k, v) = body.split_once(':')?;
    let k = k.trim();
    let ok = !k.is_empty()
        && k.len() <= 40
        && k.split_whitespace().count() <= 4
        && k.chars().all(|c| c.is_alphanumeric() || " _-.".contains(c));
    ok.then(|| (k.to_lowercase(), v.trim().to_string()))
}

/// How positions in a sheet are named: lines and columns of a text file, or a workbook sheet's rows and cells.
#[derive(Clone, Debug, PartialEq)]
enum Place {
    Lines,
    Cells { sheet: String, first_column: u32 },
}

impl Place {
    /// `line 7`, or `sheet "Readings", row 7`.
    fn line(&self, line: usize) -> String {
        match self {
            Place::Lines => format!("line {line}"),
            Place::Cells { sheet, .. } => format!("sheet \"{sheet}\", row {line}"),
        }
    }

    /// `line 7, column 3`, or `sheet "Readings", row 7, cell C7`.
    fn column(&self, line: usize, col: usize) -> String {
        match self {
            Place::Lines => format!("line {line}, column {}", col + 1),
            Place::Cells { sheet, first_column } => {
                format!("sheet \"{sheet}\", row {line}, cell {}", workbook::cell_name(line, first_column + col as u32))
            }
        }
    }
}

fn at(place: &Place, line: usize, col: usize, header: &str) -> String {
    format!("{} ({header})", place.column(line, col))
}

/// A statistics cell of a row, checked once the whole sheet is read.
struct StatCell {
    line: usize,
    column: usize,
    stat: Statistic,
    sample: String,
    geometry: String,
    reading: String,
    value: f64,
    /// The cell as written (its decimals are the statistic's precision).
    text: String,
}

/// Parse a text sheet (`file` names it in messages).
pub fn parse(text: &str, file: &str, options: &SheetOptions) -> Result<Sheet> {
    parse_at(text, file, options, &Place::Lines)
}

fn parse_at(text: &str, file: &str, options: &SheetOptions, place: &Place) -> Result<Sheet> {
    let metadata: Vec<(String, String)> = text.lines().filter_map(metadata_line).collect();
    let header_line = text.lines().find(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some(header_line) = header_line else {
        return Err(Error::input(file, "", "the sheet is empty (no header line)"));
    };
    // A JSON file given where a sheet goes (`compare RECIPE RECIPE`): say so, not "unrecognised column '{'".
    if header_line.trim_start_matches('\u{feff}').trim_start().starts_with(['{', '[']) {
        return Err(Error::input(
            file,
            "",
            "this is a JSON file (a recipe?), not an instrument sheet: `compare` takes [RECIPE] SHEET, the sheet \
             being a CSV or a workbook (.xlsx, .xlsm, .xlsb, .xls, .ods) of readings (docs/instrument.md §Sheets)",
        ));
    }
    let delimiter = options.delimiter.unwrap_or_else(|| detect_delimiter(header_line));
    let mut rdr = csv::ReaderBuilder::new()
        .delimiter(delimiter)
        .has_headers(false)
        .flexible(true)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let lines = Lines::new(text);
    let mut records = rdr.records();
    let mut header: Option<(usize, Vec<String>)> = None;
    // The first record that is not blank is the header.
    for rec in records.by_ref() {
        let rec = rec.map_err(|e| csv_error(file, &lines, &e))?;
        if rec.iter().all(|f| f.is_empty()) {
            continue;
        }
        let line = lines.line_of(&rec);
        header = Some((line, rec.iter().map(str::to_string).collect()));
        break;
    }
    let Some((hline, headers)) = header else {
        return Err(Error::input(file, "", "the sheet is empty (no header line)"));
    };
    let mut roles = Vec::new();
    for (j, h) in headers.iter().enumerate() {
        if h.is_empty() {
            return Err(Error::input(file, at(place, hline, j, "empty"), "empty column header"));
        }
        match role(h, &options.ignore_columns) {
            Some(r) => roles.push(r),
            None => {
                return Err(Error::input(
                    file,
                    at(place, hline, j, h),
                    Words::from(format!(
                        "unrecognised column `{h}` (the columns glossmeter reads are listed in docs/instrument.md \
                         §Sheets; pass "
                    ))
                    .and_argument("ignore_columns")
                    .and(format!(" '{h}' to skip it)")),
                ))
            }
        }
    }
    // Duplicate headers: two columns of the same role (other than info/ignored) are ambiguous.
    for j in 0..roles.len() {
        for i in 0..j {
            if roles[i] == roles[j] && !matches!(roles[j], Role::Info | Role::Ignored) {
                return Err(Error::input(
                    file,
                    at(place, hline, j, &headers[j]),
                    format!(
                        "duplicate column: `{}` means the same as column {} (`{}`); number repeated readings \
                         as `60° #1`, `60° #2`",
                        headers[j],
                        i + 1,
                        headers[i]
                    ),
                ));
            }
        }
    }
    let find = |r: &Role| roles.iter().position(|x| x == r);
    let (geo_c, val_c) = (find(&Role::Geometry), find(&Role::Value));
    let reading_cols: Vec<usize> = (0..roles.len()).filter(|&j| matches!(roles[j], Role::Reading { .. })).collect();
    let lab_cols: Vec<Option<usize>> = (0..3).map(|i| find(&Role::Lab(i))).collect();
    let layout = match (geo_c, val_c) {
        (Some(_), None) if lab_cols.iter().all(Option::is_some) => Layout::Colour,
        (Some(_), Some(_)) => Layout::Long,
        (Some(_), None) => {
            return Err(Error::input(
                file,
                format!("{} (header)", place.line(hline)),
                "the long layout needs a `value` column",
            ))
        }
        (None, Some(v)) => {
            return Err(Error::input(
                file,
                at(place, hline, v, &headers[v]),
                "the long layout needs a `geometry` column",
            ))
        }
        (None, None) if reading_cols.is_empty() => {
            return Err(Error::input(
                file,
                format!("{} (header)", place.line(hline)),
                "no reading columns: expected `geometry` and `value` (long layout) or reading columns such as \
                 20°, 60°, 85°, Haze, DOI (wide layout)",
            ))
        }
        (None, None) => Layout::Wide,
    };
    if layout != Layout::Colour {
        if let Some(j) = roles.iter().position(|r| matches!(r, Role::Lab(_))) {
            return Err(Error::input(
                file,
                at(place, hline, j, &headers[j]),
                "an L*, a* or b* column belongs to the colour layout: a `geometry` column with all three of `L*`, \
                 `a*`, `b*` and no `value` column",
            ));
        }
    }
    if layout == Layout::Colour {
        if let Some(j) = roles.iter().position(|r| {
            matches!(r, Role::Quantity | Role::Uncertainty | Role::Reading { .. } | Role::Statistic { .. })
        }) {
            return Err(Error::input(
                file,
                at(place, hline, j, &headers[j]),
                "a colour-layout sheet (`geometry` with `L*`, `a*`, `b*`) has no other reading, quantity, \
                 uncertainty or statistics columns",
            ));
        }
    } else if layout == Layout::Long {
        if let Some(&j) = reading_cols.first() {
            return Err(Error::input(
                file,
                at(place, hline, j, &headers[j]),
                "a reading column in a long-layout sheet (one with `geometry` and `value`): use one layout",
            ));
        }
    } else if let Some(j) = roles.iter().position(|r| matches!(r, Role::Quantity | Role::Uncertainty)) {
        return Err(Error::input(
            file,
            at(place, hline, j, &headers[j]),
            "`quantity` and `uncertainty` belong to the long layout (with `geometry` and `value`)",
        ));
    }
    // A statistics column without a reading in its name (`Mean`) is of the row's reading: in the wide layout
    // there must be just one.
    let mut wide_reading: Option<(&'static str, &'static str)> = None;
    if layout == Layout::Wide {
        for &c in &reading_cols {
            if let Role::Reading { geometry, reading, .. } = roles[c] {
                match wide_reading {
                    Some(r) if r != (geometry, reading) => {
                        if let Some(j) = roles.iter().position(|r| matches!(r, Role::Statistic { of: None, .. })) {
                            return Err(Error::input(
                                file,
                                at(place, hline, j, &headers[j]),
                                format!(
                                    "a statistics column without a reading in its name is of the sheet's one reading, \
                                     but this sheet has several (`{}`, `{}`): name it, e.g. `{} {}`",
                                    headers[reading_cols[0]], headers[c], headers[j], headers[reading_cols[0]]
                                ),
                            ));
                        }
                    }
                    _ => wide_reading = Some((geometry, reading)),
                }
            }
        }
    }
    let stat_cols: Vec<usize> = (0..roles.len()).filter(|&j| matches!(roles[j], Role::Statistic { .. })).collect();
    let mut stat_cells: Vec<StatCell> = vec![];
    let sample_c = find(&Role::Sample);
    let ignored_columns = (0..roles.len()).filter(|&j| roles[j] == Role::Ignored).map(|j| headers[j].clone()).collect();
    let mut rows = Vec::new();
    for rec in records {
        let rec = rec.map_err(|e| csv_error(file, &lines, &e))?;
        if rec.iter().all(|f| f.is_empty()) {
            continue;
        }
        let line = lines.line_of(&rec);
        if rec.len() != headers.len() {
            let j = rec.len().min(headers.len());
            return Err(Error::input(
                file,
                place.column(line, j),
                format!("{} fields, but the header (line {hline}) has {}", rec.len(), headers.len()),
            ));
        }
        let get = |c: Option<usize>| c.and_then(|c| rec.get(c)).unwrap_or("").to_string();
        let num = |c: usize, what: &str, nonneg: bool| -> Result<f64> {
            let v = parse_number(&rec[c])
                .map_err(|m| Error::input(file, at(place, line, c, &headers[c]), format!("{what}: {m}")))?;
            if nonneg && v < 0.0 {
                return Err(Error::input(
                    file,
                    at(place, line, c, &headers[c]),
                    format!("{what} must be ≥ 0, got {v}"),
                ));
            }
            Ok(v)
        };
        let sample = get(sample_c);
        match layout {
            Layout::Long => {
                let (g, v) = (geo_c.expect("long"), val_c.expect("long"));
                let geometry = get(Some(g));
                if geometry.is_empty() {
                    return Err(Error::input(file, at(place, line, g, &headers[g]), "empty geometry id"));
                }
                let reading = match get(find(&Role::Quantity)) {
                    q if q.is_empty() => "gloss".to_string(),
                    q => q.to_lowercase().split_whitespace().collect::<Vec<_>>().join("-"),
                };
                let reading = COLOUR_QUANTITIES
                    .iter()
                    .find(|(q, _)| *q == reading)
                    .map(|(_, name)| name.to_string())
                    .unwrap_or(reading);
                let not_predicted = READING_COLUMNS
                    .iter()
                    .find(|c| c.reading == reading && c.geometry == geometry)
                    .and_then(|c| c.not_predicted)
                    .map(String::from);
                let value = num(v, "the measured value", false)?;
                let uncertainty = match find(&Role::Uncertainty) {
                    Some(c) if !rec[c].is_empty() => Some(num(c, "the uncertainty", true)?),
                    _ => None,
                };
                rows.push(SheetRow {
                    line,
                    column: headers[v].clone(),
                    sample: sample.clone(),
                    geometry,
                    reading,
                    value,
                    uncertainty,
                    not_predicted,
                });
            }
            Layout::Colour => {
                let g = geo_c.expect("colour");
                let geometry = get(Some(g));
                if geometry.is_empty() {
                    return Err(Error::input(file, at(place, line, g, &headers[g]), "empty geometry id"));
                }
                for (i, c) in lab_cols.iter().enumerate() {
                    let c = c.expect("colour layout has all three");
                    let reading = LAB_COLUMNS[i].1;
                    let value = num(c, &format!("the measured {reading}"), false)?;
                    rows.push(SheetRow {
                        line,
                        column: headers[c].clone(),
                        sample: sample.clone(),
                        geometry: geometry.clone(),
                        reading: reading.to_string(),
                        value,
                        uncertainty: None,
                        not_predicted: None,
                    });
                }
            }
            Layout::Wide => {
                for &c in &reading_cols {
                    if rec[c].is_empty() {
                        continue;
                    }
                    let Role::Reading { geometry, reading, not_predicted, .. } = &roles[c] else { unreachable!() };
                    let value = num(c, "the measured value", false)?;
                    rows.push(SheetRow {
                        line,
                        column: headers[c].clone(),
                        sample: sample.clone(),
                        geometry: geometry.to_string(),
                        reading: reading.to_string(),
                        value,
                        uncertainty: None,
                        not_predicted: not_predicted.map(String::from),
                    });
                }
            }
        }
        for &c in &stat_cols {
            if rec[c].is_empty() {
                continue;
            }
            let Role::Statistic { stat, of } = roles[c] else { unreachable!() };
            let value = num(c, &format!("the stated {}", stat.name()), false)?;
            let (geometry, reading) = match (of, layout) {
                (Some((g, r)), _) => (g.to_string(), r.to_string()),
                (None, Layout::Wide) => {
                    let (g, r) = wide_reading.expect("a wide sheet has a reading column");
                    (g.to_string(), r.to_string())
                }
                // The long layout: the row's own reading.
                (None, _) => match rows.last().filter(|r| r.line == line) {
                    Some(r) => (r.geometry.clone(), r.reading.clone()),
                    None => continue,
                },
            };
            stat_cells.push(StatCell {
                line,
                column: c,
                stat,
                sample: sample.clone(),
                geometry,
                reading,
                value,
                text: rec[c].to_string(),
            });
        }
    }
    // Each stated statistic against its series: the sample's readings of that reading in the whole sheet.
    let mut series_of: HashMap<(&str, &str, &str), Vec<f64>> = HashMap::new();
    for r in &rows {
        series_of.entry((r.sample.as_str(), r.geometry.as_str(), r.reading.as_str())).or_default().push(r.value);
    }
    for sc in &stat_cells {
        let (c, text) = (sc.column, &headers[sc.column]);
        let sample = if sc.sample.is_empty() { String::new() } else { format!(" of sample `{}`", sc.sample) };
        let Some(values) = series_of.get(&(sc.sample.as_str(), sc.geometry.as_str(), sc.reading.as_str())) else {
            return Err(Error::input(
                file,
                at(place, sc.line, c, text),
                format!(
                    "a stated {}{sample}, but the sheet has no {} {} readings{sample} to check it against",
                    sc.stat.name(),
                    sc.geometry,
                    sc.reading
                ),
            ));
        };
        series::check(sc.stat, sc.value, &sc.text, &Series::of(values))
            .map_err(|m| Error::input(file, at(place, sc.line, c, text), format!("{m}{sample}")))?;
    }
    if rows.is_empty() {
        return Err(Error::input(
            file,
            format!("{} (header)", place.line(hline)),
            "the sheet has a header but no readings",
        ));
    }
    Ok(Sheet {
        file: file.to_string(),
        encoding: "UTF-8".into(),
        delimiter,
        layout,
        metadata,
        ignored_columns,
        header_line: hline,
        headers,
        sample_column: sample_c,
        geometry_column: geo_c,
        quantity_column: find(&Role::Quantity),
        rows,
        workbook_sheet: None,
        first_column: 0,
        statistics_checked: stat_cells.len(),
    })
}

/// Line numbers of records. The `csv` crate's own line count is off after comment and blank lines, and its
/// byte position is where it started reading (before the blank and comment lines it skipped), so the record's
/// first line is found from that position by skipping line ends and `#` lines.
struct Lines<'a> {
    text: &'a [u8],
    starts: Vec<usize>,
}

impl<'a> Lines<'a> {
    fn new(text: &'a str) -> Self {
        let b = text.as_bytes();
        let starts =
            std::iter::once(0).chain(b.iter().enumerate().filter(|(_, &c)| c == b'\n').map(|(i, _)| i + 1)).collect();
        Lines { text: b, starts }
    }

    fn line_of(&self, rec: &csv::StringRecord) -> usize {
        self.line_at(rec.position().map(|p| p.byte() as usize).unwrap_or(0))
    }

    fn line_at(&self, byte: usize) -> usize {
        let mut p = byte.min(self.text.len());
        loop {
            while p < self.text.len() && matches!(self.text[p], b'\r' | b'\n') {
                p += 1;
            }
            let at_line_start = p == 0 || self.text[p - 1] == b'\n';
            if p < self.text.len() && at_line_start && self.text[p] == b'#' {
                while p < self.text.len() && self.text[p] != b'\n' {
                    p += 1;
                }
                continue;
            }
            break;
        }
        // The number of line starts at or before p.
        self.starts.partition_point(|&s| s <= p)
    }
}

fn csv_error(file: &str, lines: &Lines, e: &csv::Error) -> Error {
    let field = e.position().map(|p| format!("line {}", lines.line_at(p.byte() as usize))).unwrap_or_default();
    Error::input(file, field, format!("malformed CSV: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_layout_and_colour_quantities() {
        let o = SheetOptions::default();
        let t = "sample;geometry;L*;a*;b*\np1;astm-e2194-15;81,4;-7,3;-10,0\n";
        let sh = parse(t, "c.csv", &o).unwrap();
        assert_eq!(sh.layout, Layout::Colour);
        assert_eq!(sh.rows.len(), 3);
        assert_eq!((sh.rows[1].reading.as_str(), sh.rows[1].value, sh.rows[1].line), ("a*", -7.3, 2));
        let e = parse("geometry,L*,a*,b*\nastm-e2194-15,81,x,1\n", "c.csv", &o).unwrap_err().to_string();
        assert!(e.contains("c.csv") && e.contains("line 2") && e.contains("a*"), "{e}");
        // L* without a* and b*, or beside a value column, is not the colour layout.
        assert!(parse("geometry,value,L*\nastm-e2194-15,1,2\n", "c.csv", &o).is_err());
        // Colour readings one per row in the long layout.
        let sh = parse("geometry,quantity,value\nd8-sce,L*,50\nd8-sce,h,200\n", "l.csv", &o).unwrap();
        assert_eq!((sh.rows[0].reading.as_str(), sh.rows[1].reading.as_str()), ("L*", "h"));
    }

    fn p(text: &str) -> Result<Sheet> {
        parse(text, "s.csv", &SheetOptions::default())
    }

    #[test]
    fn long_and_wide_layouts() {
        let long = "# BYK micro-TRI-gloss\nsample,geometry,quantity,value,uncertainty\np1,astm-d523-60,gloss,89.1,0.5\np1,astm-e430-30,haze-narrow,3.2,\n";
        let r = p(long).unwrap().rows;
        assert_eq!(r.len(), 2);
        assert_eq!((r[0].line, r[0].uncertainty), (3, Some(0.5)));
        assert_eq!((r[1].reading.as_str(), r[1].uncertainty), ("haze-narrow", None));
        let wide = "sample,20°,60°,85°\np1,82.0,89.1,99.0\np2,,90,\n";
        let r = p(wide).unwrap().rows;
        assert_eq!(r.len(), 4);
        assert_eq!(r[3].geometry, "astm-d523-60");
    }

    #[test]
    fn aliases() {
        for (h, g, r) in [
            ("Gloss 20°", "astm-d523-20", "gloss"),
            ("G60", "astm-d523-60", "gloss"),
            ("85 deg", "astm-d523-85", "gloss"),
            ("60° (GU)", "astm-d523-60", "gloss"),
            ("HU", IQ, "haze"),
            ("Haze", IQ, "haze"),
            ("Log Haze", IQ, "log-haze"),
            ("HU_LOG", IQ, "log-haze"),
            ("HULog", IQ, "log-haze"),
            ("Haze ISO 13803", "iso-13803-20", "haze"),
            ("DOI", IQ, "doi"),
            ("DOI 30", "astm-e430-30", "doi"),
            ("Rspec", IQ, "rspec"),
            ("RIQ", IQ, "riq"),
        ] {
            match role(h, &[]) {
                Some(Role::Reading { geometry, reading, .. }) => assert_eq!((geometry, reading), (g, r), "{h}"),
                other => panic!("{h}: {other:?}"),
            }
        }
        assert!(matches!(role("60° #2", &[]), Some(Role::Reading { repeat: Some(2), .. })));
        assert!(matches!(role("60 (3)", &[]), Some(Role::Reading { repeat: Some(3), .. })));
        assert_eq!(role("Sample Name", &[]), Some(Role::Sample));
        assert_eq!(role("Colour", &[]), None);
        assert_eq!(role("colour ", &["COLOUR".into()]), Some(Role::Ignored));
    }

    #[test]
    fn dialects() {
        let semi = "# instrument: BYK micro-TRI-gloss\r\n# batch: 42\r\nProbe;20°;60°\r\n\"A; 1\";82,5;89,1\r\n";
        let s = p(semi).unwrap();
        assert_eq!(s.delimiter, b';');
        assert_eq!(
            s.metadata,
            vec![("instrument".into(), "BYK micro-TRI-gloss".into()), ("batch".into(), "42".into())]
        );
        assert_eq!(s.rows[0].value, 82.5);
        assert_eq!(s.rows[1].sample, "A; 1");
        assert_eq!((s.rows[1].line, s.rows[1].column.as_str()), (4, "60°"));
        // Blank lines (also CRLF ones) and comments between rows.
        let s = p("\r\n\r\nsample;60\r\n\r\n# x\r\np;1\r\n").unwrap();
        assert_eq!(s.rows[0].line, 6);
        // Windows-1252: ° is 0xB0.
        let bytes = b"sample,20\xb0,60\xb0\np,1,2\n";
        let s = parse_bytes(bytes, "w.csv", &SheetOptions::default()).unwrap();
        assert_eq!((s.encoding.as_str(), s.rows[1].column.as_str()), ("windows-1252", "60°"));
        // BOM then a comment line.
        let s = parse_bytes(b"\xef\xbb\xbf# a: b\nsample,60\np,1\n", "b.csv", &SheetOptions::default()).unwrap();
        assert_eq!((s.encoding.as_str(), s.rows[0].line), ("UTF-8 with BOM", 3));
    }

    #[test]
    fn line_numbers_count_lines_not_records() {
        let t = "sample,60\n\n# c\n\"a\nb\",1\np,x\n";
        let e = p(t).unwrap_err().to_string();
        assert!(e.contains("line 6, column 2 (60)"), "{e}");
    }

    #[test]
    fn numbers() {
        assert_eq!(parse_number("89,1"), Ok(89.1));
        assert_eq!(parse_number("-1.5e-3"), Ok(-1.5e-3));
        for bad in ["1.234,5", "inf", "NaN", "1,2,3", "abc", ""] {
            assert!(parse_number(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let e = p("geometry,value\nastm-d523-60,abc\n").unwrap_err().to_string();
        assert!(e.contains("s.csv") && e.contains("line 2, column 2 (value)"), "{e}");
        let e = p("geometry,value,uncertainty\nastm-d523-60,1,-2\n").unwrap_err().to_string();
        assert!(e.contains("uncertainty") && e.contains("≥ 0"), "{e}");
        let e = p("foo,bar\n1,2\n").unwrap_err().to_string();
        assert!(e.contains("line 1, column 1 (foo)") && e.contains("`ignore_columns`"), "{e}");
        let e = p("geometry,value\nastm-d523-60,1,3\n").unwrap_err().to_string();
        assert!(e.contains("line 2, column 3") && e.contains("3 fields"), "{e}");
        let e = p("sample,20°,G20\np,1,2\n").unwrap_err().to_string();
        assert!(e.contains("column 3 (G20)") && e.contains("duplicate"), "{e}");
        let e = p("").unwrap_err().to_string();
        assert!(e.contains("empty"), "{e}");
        let e = p("# only a comment\nsample,60\n").unwrap_err().to_string();
        assert!(e.contains("no readings"), "{e}");
    }
}
