//! Workbook sheets: `.xlsx`/`.xlsm`/`.xlsb`, `.xls` and `.ods` files (read with `calamine`, pure Rust), one
//! sheet of which is turned into the text the CSV reader reads (`comparison::sheet`), so that a workbook
//! follows exactly the rules of a CSV sheet: the same layouts, aliases, repeats, statistics columns and errors
//! (docs/instrument.md §Workbooks). Row r of the sheet is line r of that text (blank lines stand for the rows
//! above the first used one), so an error's line is the sheet's row number; the sheet reader names positions
//! as the workbook's cells (`sheet "Readings", row 5, cell C5 (Mean 20°)`).
//!
//! Cells become text as a person reads them: numbers as the shortest decimals that read back to the same
//! double (what the cell holds, whatever its display format), text as written (line breaks as spaces),
//! `TRUE`/`FALSE`, dates as `date-time <serial>` (so that a date in a reading column is refused as not a
//! number, not read as one), Excel errors as `Excel error #DIV/0!`. A row whose first cell starts with `#` is a
//! comment row, its cells joined by spaces (`# batch: 42` is metadata, as in CSV). Formulas are read as the
//! value last computed and saved with the workbook (a file written by a program that computes nothing has
//! empty formula cells, which are empty readings). This file imports nothing of the crate but `error`.
//!
//! A workbook is a file of numbers that size what its reader allocates, and its reader is a third party's: the
//! file is checked first against the limits of [`limits`] ([`archive`] for zip workbooks, [`xls`] for `.xls`),
//! `.xlsx` and `.xlsb` sheets are read cell by cell (never as one range laid out by the file's numbers), and a
//! panic inside calamine is caught and reported as an error naming the file (docs/instrument.md §Workbooks).
use std::cell::Cell;
use std::io::Cursor;
use std::panic::{catch_unwind, AssertUnwindSafe};

use calamine::{Data, DataRef, Reader};

use crate::{Error, Result};

pub(crate) mod archive;
pub(crate) mod limits;
pub(crate) mod xls;

use archive::ZipKind;

/// Whether the bytes are a workbook rather than text: a ZIP archive (`PK\x03\x04`: xlsx, xlsm, xlsb, ods) or an
/// OLE compound file (`D0 CF 11 E0`: xls). A text sheet never starts so (`P` then `K` then a control byte).
pub(crate) fn is_workbook(bytes: &[u8]) -> bool {
    bytes.starts_with(b"PK\x03\x04") || bytes.starts_with(&[0xD0, 0xCF, 0x11, 0xE0, 0xA1, 0xB1, 0x1A, 0xE1])
}

/// One sheet of a workbook, as text for the sheet reader.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct WorkbookSheet {
    /// `xlsx`, `xls`, `xlsb` or `ods`.
    pub format: &'static str,
    /// The sheet read.
    pub sheet: String,
    /// Every sheet of the workbook, in order.
    pub sheets: Vec<String>,
    /// Comma-separated text, line r = row r of the sheet.
    pub text: String,
    /// The 0-based column of the sheet the text's first column is (for cell names).
    pub first_column: u32,
}

/// The cell name of a 1-based row and a 0-based column: (5, 2) → `C5`.
pub(crate) fn cell_name(row: usize, column: u32) -> String {
    let mut letters = vec![];
    let mut c = column as u64 + 1;
    while c > 0 {
        let r = ((c - 1) % 26) as u8;
        letters.push((b'A' + r) as char);
        c = (c - 1) / 26;
    }
    letters.iter().rev().collect::<String>() + &row.to_string()
}

/// Read sheet `name` (the first sheet when None) of the workbook in `bytes`; `file` names it in errors. The
/// file is checked against the limits first; a panic of the reader is an error naming the file.
pub(crate) fn read(bytes: &[u8], file: &str, name: Option<&str>) -> Result<WorkbookSheet> {
    if bytes.len() > limits::MAX_FILE_BYTES {
        return Err(Error::input(
            file,
            "",
            format!("the workbook is {} bytes; at most {} are read", bytes.len(), limits::MAX_FILE_BYTES),
        ));
    }
    let kind = if bytes.starts_with(b"PK\x03\x04") {
        Kind::Zip(archive::check(bytes, file)?)
    } else {
        xls::check(bytes, file)?;
        Kind::Xls
    };
    let grid = quietly(|| read_grid(bytes, file, name, kind)).unwrap_or_else(|why| {
        Err(Error::input(
            file,
            "",
            format!("the workbook reader failed on this file ({why}): the file is damaged or not a workbook"),
        ))
    })?;
    Ok(grid.into_sheet())
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Zip(ZipKind),
    Xls,
}

thread_local! {
    /// Set while this thread runs the workbook reader: its panics are reported as errors, not printed.
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

/// Run `f`, turning a panic into its message; the panic hook stays silent for this thread meanwhile (it is
/// installed once, and passes every other panic to the hook it replaced). This is the library's one
/// process-wide hook, and it stays: calamine can panic on a malformed workbook (docs/instrument.md
/// §Workbooks), `catch_unwind` is the only way to turn that into an error, and Rust prints a caught panic
/// through the hook; the hook only silences the reader's own thread, it changes no result.
fn quietly<T>(f: impl FnOnce() -> T) -> std::result::Result<T, String> {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                previous(info);
            }
        }));
    });
    QUIET.with(|q| q.set(true));
    let out = catch_unwind(AssertUnwindSafe(f));
    QUIET.with(|q| q.set(false));
    out.map_err(|p| {
        let msg = p.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| p.downcast_ref::<String>().cloned());
        format!("it panicked: {}", msg.unwrap_or_else(|| "no message".into()))
    })
}

/// A sheet's cells as text, the first used row and column, and what was read.
struct Grid {
    format: &'static str,
    sheet: String,
    sheets: Vec<String>,
    first_row: u32,
    first_column: u32,
    cells: Vec<Vec<String>>,
}

/// Open the workbook with the reader of its kind (not calamine's guess, which says "Cannot detect file
/// format" for a damaged `.ods`) and read one sheet.
fn read_grid(bytes: &[u8], file: &str, name: Option<&str>, kind: Kind) -> Result<Grid> {
    let unreadable =
        |e: String| Error::input(file, "", format!("not a readable workbook (xlsx, xlsm, xlsb, xls or ods): {e}"));
    let c = Cursor::new(bytes);
    match kind {
        Kind::Zip(ZipKind::Xlsx) => {
            let mut b: calamine::Xlsx<_> = calamine::Reader::new(c).map_err(|e| unreadable(format!("xlsx: {e}")))?;
            let (sheet, sheets) = pick(&b.sheet_names(), file, name)?;
            let mut r = b.worksheet_cells_reader(&sheet).map_err(|e| sheet_error(file, &sheet, e))?;
            sparse("xlsx", sheet, sheets, file, || r.next_cell().map_err(|e| e.to_string()))
        }
        Kind::Zip(ZipKind::Xlsb) => {
            let mut b: calamine::Xlsb<_> = calamine::Reader::new(c).map_err(|e| unreadable(format!("xlsb: {e}")))?;
            let (sheet, sheets) = pick(&b.sheet_names(), file, name)?;
            let mut r = b.worksheet_cells_reader(&sheet).map_err(|e| sheet_error(file, &sheet, e))?;
            sparse("xlsb", sheet, sheets, file, || r.next_cell().map_err(|e| e.to_string()))
        }
        Kind::Zip(ZipKind::Ods) => {
            let b: calamine::Ods<_> = calamine::Reader::new(c).map_err(|e| unreadable(format!("ods: {e}")))?;
            dense("ods", b, file, name)
        }
        Kind::Xls => {
            let b: calamine::Xls<_> = calamine::Reader::new(c).map_err(|e| unreadable(format!("xls: {e}")))?;
            dense("xls", b, file, name)
        }
    }
}

fn sheet_error(file: &str, sheet: &str, e: impl std::fmt::Display) -> Error {
    Error::input(file, format!("sheet \"{sheet}\""), format!("cannot be read: {e}"))
}

/// The sheet named (or the first), and every sheet's name.
fn pick(sheets: &[String], file: &str, name: Option<&str>) -> Result<(String, Vec<String>)> {
    let list = || sheets.iter().map(|s| format!("\"{s}\"")).collect::<Vec<_>>().join(", ");
    let sheet = match name {
        Some(n) => match sheets.iter().find(|s| s.as_str() == n) {
            Some(s) => s.clone(),
            None => {
                return Err(Error::input(
                    file,
                    "",
                    format!("the workbook has no sheet \"{n}\"; its sheets: {}", list()),
                ))
            }
        },
        None => match sheets.first() {
            Some(s) => s.clone(),
            None => return Err(Error::input(file, "", "the workbook has no sheets")),
        },
    };
    Ok((sheet, sheets.to_vec()))
}

/// A sheet read whole by calamine (`.ods`, `.xls`: their extents were checked before it opened the file).
fn dense<'b, R: Reader<Cursor<&'b [u8]>>>(
    format: &'static str,
    mut b: R,
    file: &str,
    name: Option<&str>,
) -> Result<Grid>
where
    R::Error: std::fmt::Display,
{
    let (sheet, sheets) = pick(&b.sheet_names(), file, name)?;
    let range = b.worksheet_range(&sheet).map_err(|e| sheet_error(file, &sheet, e))?;
    let (first_row, first_column) = range.start().unwrap_or((0, 0));
    let cells = range.rows().map(|r| r.iter().map(cell_text).collect()).collect();
    Ok(Grid { format, sheet, sheets, first_row, first_column, cells })
}

/// A sheet read cell by cell (`.xlsx`, `.xlsb`), its used range held to [`limits::MAX_CELLS`] as it grows,
/// laid out as calamine's `Range::from_sparse` lays it out (the used range of the non-empty cells).
fn sparse<'a>(
    format: &'static str,
    sheet: String,
    sheets: Vec<String>,
    file: &str,
    mut next: impl FnMut() -> std::result::Result<Option<calamine::Cell<DataRef<'a>>>, String>,
) -> Result<Grid> {
    let mut cells: Vec<((u32, u32), String)> = vec![];
    let (mut r0, mut r1, mut c0, mut c1) = (u32::MAX, 0u32, u32::MAX, 0u32);
    while let Some(cell) = next().map_err(|e| sheet_error(file, &sheet, e))? {
        let value = Data::from(cell.get_value().clone());
        if value == Data::Empty {
            continue;
        }
        let (r, c) = cell.get_position();
        (r0, r1, c0, c1) = (r0.min(r), r1.max(r), c0.min(c), c1.max(c));
        let area = (r1 - r0 + 1) as u64 * (c1 - c0 + 1) as u64;
        if area > limits::MAX_CELLS || cells.len() as u64 >= limits::MAX_CELLS {
            return Err(Error::input(
                file,
                format!("sheet \"{sheet}\""),
                format!(
                    "its used range reaches {} ({} rows × {} columns); a sheet may have at most {} cells",
                    cell_name(r as usize + 1, c),
                    r1 - r0 + 1,
                    c1 - c0 + 1,
                    limits::MAX_CELLS
                ),
            ));
        }
        cells.push(((r, c), cell_text(&value)));
    }
    if cells.is_empty() {
        return Ok(Grid { format, sheet, sheets, first_row: 0, first_column: 0, cells: vec![] });
    }
    let width = (c1 - c0 + 1) as usize;
    let mut grid = vec![vec![String::new(); width]; (r1 - r0 + 1) as usize];
    for ((r, c), text) in cells {
        grid[(r - r0) as usize][(c - c0) as usize] = text;
    }
    Ok(Grid { format, sheet, sheets, first_row: r0, first_column: c0, cells: grid })
}

impl Grid {
    /// The text the sheet reader reads: line r is row r.
    fn into_sheet(self) -> WorkbookSheet {
        let cells = self.cells;
        // Columns past the last one that holds anything are left out (formatting can widen the used range).
        let width = cells.iter().map(|r| r.iter().rposition(|c| !c.is_empty()).map_or(0, |i| i + 1)).max().unwrap_or(0);
        let mut text = "\n".repeat(self.first_row as usize);
        for row in &cells {
            let row = &row[..width.min(row.len())];
            if row.first().is_some_and(|c| c.starts_with('#')) {
                let words: Vec<&str> = row.iter().map(String::as_str).filter(|c| !c.is_empty()).collect();
                text.push_str(&words.join(" "));
                text.push('\n');
                continue;
            }
            text.push_str(&csv_record(row));
        }
        WorkbookSheet {
            format: self.format,
            sheet: self.sheet,
            sheets: self.sheets,
            text,
            first_column: self.first_column,
        }
    }
}

/// One row as a CSV record ending in a line break (quoted where the csv crate must); no cells, an empty line.
fn csv_record(row: &[String]) -> String {
    let mut w = csv::WriterBuilder::new().has_headers(false).from_writer(vec![]);
    // Writing to memory cannot fail.
    if row.is_empty() || w.write_record(row).is_err() {
        return "\n".into();
    }
    w.into_inner().ok().and_then(|b| String::from_utf8(b).ok()).unwrap_or_else(|| "\n".into())
}

fn cell_text(d: &Data) -> String {
    match d {
        Data::Empty => String::new(),
        Data::String(s) => s.replace("\r\n", " ").replace(['\n', '\r'], " "),
        Data::Float(f) => format!("{f}"),
        Data::Int(i) => i.to_string(),
        Data::Bool(b) => if *b { "TRUE" } else { "FALSE" }.into(),
        Data::DateTime(t) => format!("date-time {}", t.as_f64()),
        Data::DateTimeIso(s) | Data::DurationIso(s) => format!("date-time {s}"),
        Data::Error(e) => format!("Excel error {e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_names() {
        assert_eq!(cell_name(5, 2), "C5");
        assert_eq!(cell_name(1, 25), "Z1");
        assert_eq!(cell_name(1, 26), "AA1");
        assert_eq!(cell_name(12, 27), "AB12");
    }

    #[test]
    fn text_is_not_a_workbook_and_a_broken_zip_is_refused() {
        assert!(!is_workbook(b"sample,60\np,1\n"));
        assert!(is_workbook(b"PK\x03\x04rest"));
        let e = read(b"PK\x03\x04 not really a zip", "b.xlsx", None).unwrap_err().to_string();
        assert!(e.contains("b.xlsx") && e.contains("not a readable workbook"), "{e}");
    }
}

#[cfg(test)]
mod hostile {
    use super::*;

    /// A panic inside the reader becomes its message, and the thread's panic hook is back afterwards.
    #[test]
    fn a_panic_of_the_reader_is_an_error() {
        assert_eq!(
            quietly(|| -> u8 { panic!("slice index starts at 4096") }),
            Err("it panicked: slice index starts at 4096".into())
        );
        assert_eq!(quietly(|| 7), Ok(7));
        assert!(!QUIET.with(Cell::get));
    }

    /// Each reproducer of docs/reliability.md §Workbooks ends in an error naming the file, and what is wrong.
    #[test]
    fn reproducers_end_in_clear_errors() {
        let mut bad = vec![];
        for (name, words) in [
            ("crc-stored.xlsx", "bad CRC"),
            ("far-cells.xlsx", "at most 1000000 cells"),
            ("ods-content-cut-short.ods", "ends inside"),
            ("sst-reserve.xlsx", "uniqueCount"),
            ("xls-alloc-4GiB.xls", "chain"),
            ("xls-dim-reversed.xls", "reversed DIMENSIONS"),
            ("xls-panic-cfb-279.xls", "not a readable .xls workbook"),
            ("xls-panic-cfb-325.xls", "not a readable .xls workbook"),
            ("xls-panic-utils-assert.xls", "not a readable .xls workbook"),
            ("zipbomb-1GB-space.xlsx", "inflates"),
        ] {
            let path = format!("{}/fixtures/sheets/hostile/{name}", env!("CARGO_MANIFEST_DIR"));
            let bytes = std::fs::read(&path).unwrap();
            let e = read(&bytes, name, None).unwrap_err().to_string();
            eprintln!("{name}: {e}");
            if !(e.contains(name) && e.contains(words)) {
                bad.push(format!("{name}: {e}"));
            }
        }
        assert!(bad.is_empty(), "{bad:#?}");
    }
}
