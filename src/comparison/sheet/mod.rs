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

mod columns;
mod rows;
mod text;
pub(crate) use columns::*;
use rows::*;
pub(crate) use text::*;

use super::series::{self, Series, Statistic};
use super::workbook;
use crate::error::Words;
use crate::{Error, Result};

/// The most readings one sheet may hold (a QC sheet of 10 000 panels × 20 readings has 200 000): each is a
/// [`SheetRow`] of about 250 bytes, so that a 16 MiB sheet of one-digit cells stays far below 512 MiB
/// (docs/instrument.md §Sheets).
pub(crate) const MAX_READINGS: usize = 500_000;

/// What the reader was asked to do differently from its defaults.
#[derive(Clone, Debug, Default)]
pub struct SheetOptions {
    /// The separator (`,`, `;` or tab); detected from the header line when None.
    pub delimiter: Option<u8>,
    /// Column headers to skip (matched like aliases: case, spaces and punctuation do not matter).
    pub ignore_columns: Vec<String>,
    /// The sheet of a workbook to read (the first when None); refused for a text sheet.
    pub sheet_name: Option<String>,
    /// The 1-based line (or workbook row) of the header; the rows above it are title and metadata rows. When
    /// None, the header is the first row whose cells all name known columns (within the first rows), else the
    /// first row.
    pub header_row: Option<usize>,
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
    /// The distinct cells of the columns that state each row's colour conditions (`Illuminant`, `Observer`):
    /// (line, column, text), the first row of each distinct text, at most [`CONDITION_TEXTS`] + 1 per column.
    pub condition_cells: Vec<(usize, usize, String)>,
}

impl Sheet {
    /// The metadata as a JSON object (a key given twice keeps both values, joined by "; ").
    pub(crate) fn metadata_json(&self) -> serde_json::Value {
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
    pub(crate) fn cell(&self, line: usize, column: Option<usize>, what: &str) -> String {
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
    pub(crate) fn geometry_ids(&self) -> Vec<String> {
        let mut ids: Vec<String> = Vec::new();
        for r in &self.rows {
            if !ids.contains(&r.geometry) {
                ids.push(r.geometry.clone());
            }
        }
        ids
    }
}

/// Read a sheet file: its bytes, then [`from_bytes`].
pub fn load(path: &Path, options: &SheetOptions) -> Result<Sheet> {
    load_source(&path.into(), options)
}

/// [`load`] of a source (a file, or standard input as a front end read it).
pub(crate) fn load_source(source: &crate::input::Source, options: &SheetOptions) -> Result<Sheet> {
    from_bytes(&source.bytes("sheet")?, &source.name(), options)
}

/// The one entry point of every front end (command line, server, Python): a sheet's bytes, a workbook if they
/// are one ([`workbook::is_workbook`]: `.xlsx`, `.xls`, `.ods`, … read within the limits of
/// docs/instrument.md §Workbooks), else text in any of the encodings of [`decode`]. `file` names it in errors.
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
pub(crate) fn parse_workbook(bytes: &[u8], file: &str, options: &SheetOptions) -> Result<Sheet> {
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

pub(crate) fn parse_bytes(bytes: &[u8], file: &str, options: &SheetOptions) -> Result<Sheet> {
    let (text, encoding) = decode(bytes, file)?;
    let mut sheet = parse(&text, file, options)?;
    sheet.encoding = encoding;
    Ok(sheet)
}

/// Parse a text sheet (`file` names it in messages).
pub fn parse(text: &str, file: &str, options: &SheetOptions) -> Result<Sheet> {
    parse_at(text, file, options, &Place::Lines)
}

/// Stage 0, the separator: the one asked for, else that of the first content line that has one (a title line
/// above the header has none); a text with no content line, or a JSON file, is refused.
fn delimiter_of(text: &str, file: &str, options: &SheetOptions, place: &Place) -> Result<u8> {
    let is_content = |l: &&str| !l.trim().is_empty() && !l.trim_start().starts_with('#');
    let Some((first_at, first_line)) = text.lines().enumerate().find(|(_, l)| is_content(l)) else {
        return Err(Error::input(file, "", "the sheet is empty (no header line)"));
    };
    // A JSON file given where a sheet goes (`compare RECIPE RECIPE`): say so, not "unrecognised column '{'".
    if first_line.trim_start_matches('\u{feff}').trim_start().starts_with(['{', '[']) {
        return Err(Error::input(
            file,
            place.line(first_at + 1),
            "this is a JSON file (a recipe?), not an instrument sheet: `compare` takes [RECIPE] SHEET, the sheet \
             being a CSV or a workbook (.xlsx, .xlsm, .xlsb, .xls, .ods) of readings (docs/instrument.md §Sheets)",
        ));
    }
    Ok(options.delimiter.unwrap_or_else(|| {
        let mut content = text.lines().filter(is_content).take(TITLE_ROWS + 1);
        let with_one = content.find(|l| l.bytes().any(|c| matches!(c, b',' | b';' | b'\t')));
        detect_delimiter(with_one.unwrap_or(first_line))
    }))
}

fn parse_at(text: &str, file: &str, options: &SheetOptions, place: &Place) -> Result<Sheet> {
    let mut metadata: Vec<(usize, (String, String))> =
        text.lines().enumerate().filter_map(|(i, l)| metadata_line(l).map(|m| (i + 1, m))).collect();
    let delimiter = delimiter_of(text, file, options, place)?;
    let reader = || {
        csv::ReaderBuilder::new()
            .delimiter(delimiter)
            .has_headers(false)
            .flexible(true)
            .comment(Some(b'#'))
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes())
    };
    let lines = Lines::new(text);
    let header_at = header_line(reader(), &lines, file, options)?;
    let mut rdr = reader();
    let mut records = rdr.records();
    let mut header: Option<(usize, Vec<String>)> = None;
    // The header is the record at `header_at` (the first that is not blank when none was found); the records
    // above it are title and metadata rows.
    for rec in records.by_ref() {
        let rec = rec.map_err(|e| csv_error(file, &lines, &e))?;
        if rec.iter().all(|f| f.is_empty()) {
            continue;
        }
        let line = lines.line_of(&rec);
        if header_at.is_some_and(|h| line < h) {
            metadata.extend(title_row(&rec).into_iter().map(|m| (line, m)));
            continue;
        }
        header = Some((line, rec.iter().map(str::to_string).collect()));
        break;
    }
    metadata.sort_by_key(|(line, _)| *line);
    let metadata: Vec<(String, String)> = metadata.into_iter().map(|(_, m)| m).collect();
    let Some((hline, headers)) = header else {
        return Err(Error::input(file, "", "the sheet is empty (no header line)"));
    };
    let roles = header_roles(&headers, hline, file, options, place)?;
    let (layout, wide_reading) = layout_of(&roles, &headers, hline, file, place)?;
    let find = |r: &Role| roles.iter().position(|x| x == r);
    let (geo_c, val_c) = (find(&Role::Geometry), find(&Role::Value));
    let reading_cols: Vec<usize> = (0..roles.len()).filter(|&j| matches!(roles[j], Role::Reading { .. })).collect();
    let lab_cols: Vec<Option<usize>> = (0..3).map(|i| find(&Role::Lab(i))).collect();
    let stat_cols: Vec<usize> = (0..roles.len()).filter(|&j| matches!(roles[j], Role::Statistic { .. })).collect();
    let mut stat_cells: Vec<StatCell> = vec![];
    let sample_c = find(&Role::Sample);
    let condition_cols: Vec<usize> = (0..roles.len()).filter(|&j| roles[j] == Role::Condition).collect();
    let mut condition_cells: Vec<(usize, usize, String)> = vec![];
    let ignored_columns = (0..roles.len()).filter(|&j| roles[j] == Role::Ignored).map(|j| headers[j].clone()).collect();
    let mut rows = Vec::new();
    // Statistics rows summarise the rows from `block_start` (after the previous statistics rows).
    let (mut block_start, mut in_statistics) = (0usize, false);
    for rec in records {
        let rec = rec.map_err(|e| csv_error(file, &lines, &e))?;
        if rec.iter().all(|f| f.is_empty()) {
            continue;
        }
        let line = lines.line_of(&rec);
        if rows.len() >= MAX_READINGS {
            return Err(Error::input(
                file,
                place.line(line),
                format!("the sheet has more than {MAX_READINGS} readings, the most one comparison reads"),
            ));
        }
        if rec.len() != headers.len() {
            let j = rec.len().min(headers.len());
            return Err(Error::input(
                file,
                place.column(line, j),
                format!("{} fields, but the header (line {hline}) has {}", rec.len(), headers.len()),
            ));
        }
        let r = Record { rec: &rec, line, headers: &headers, file, place };
        if layout == Layout::Wide {
            if let Some(stat) = statistics_row(&rec, &roles) {
                // A statistics row (`Mean`, `Std`, … in the sample or first column) under the data: each of its
                // reading cells is a stated statistic of that column's series of the sample of the rows above.
                in_statistics = true;
                stat_cells.extend(statistics_row_cells(&r, stat, &reading_cols, &roles, &rows[block_start..])?);
                continue;
            }
            if in_statistics {
                (block_start, in_statistics) = (rows.len(), false);
            }
        }
        let sample = r.get(sample_c);
        keep_condition_cells(&r, &condition_cols, &mut condition_cells);
        rows.extend(match layout {
            Layout::Long => {
                let (g, v) = (geo_c.expect("long"), val_c.expect("long"));
                long_row(&r, &sample, g, v, find(&Role::Quantity), find(&Role::Uncertainty))?
            }
            Layout::Colour => colour_rows(&r, &sample, geo_c.expect("colour"), &lab_cols)?,
            Layout::Wide => wide_rows(&r, &sample, &reading_cols, &roles)?,
        });
        let last = rows.last().filter(|r| r.line == line);
        stat_cells.extend(statistics_column_cells(&r, &sample, &stat_cols, &roles, layout, wide_reading, last)?);
    }
    check_statistics(&stat_cells, &rows, &headers, file, place)?;
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
        condition_cells,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_json_file_given_as_a_sheet_is_named_at_its_first_content_line() {
        let o = SheetOptions::default();
        let e = parse("# title\n\n  {\"model\": \"glass\"}\n", "r.json", &o).unwrap_err().to_string();
        assert!(e.contains("r.json") && e.contains("line 3") && e.contains("not an instrument sheet"), "{e}");
    }

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

    #[test]
    fn from_bytes_reads_text_and_workbooks_alike() {
        let o = SheetOptions::default();
        let text = from_bytes(b"sample,60\np,89.1\n", "t.csv", &o).unwrap();
        assert_eq!((text.encoding.as_str(), text.rows[0].value), ("UTF-8", 89.1));
        let book = include_bytes!("../../../fixtures/sheets/byk-smart-chart-export.xlsx");
        let sh = from_bytes(book, "b.xlsx", &o).unwrap();
        assert_eq!(sh.encoding, "xlsx workbook");
        assert!(!sh.rows.is_empty());
        let named = SheetOptions { sheet_name: Some("x".into()), ..SheetOptions::default() };
        let e = from_bytes(b"sample,60\np,1\n", "t.csv", &named).unwrap_err().to_string();
        assert!(e.contains("t.csv is a text sheet"), "{e}");
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
