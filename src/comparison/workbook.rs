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
use std::io::Cursor;

use calamine::{Data, Reader};

use crate::{Error, Result};

/// Whether the bytes are a workbook rather than text: a ZIP archive (`PK\x03\x04`: xlsx, xlsm, xlsb, ods) or an
/// OLE compound file (`D0 CF 11 E0`: xls). A text sheet never starts so (`P` then `K` then a control byte).
pub fn is_workbook(bytes: &[u8]) -> bool {
    bytes.starts_with(b"PK\x03\x04") || bytes.starts_with(&[0xD0, 0xCF, 0x11, 0xE0, 0xA1, 0xB1, 0x1A, 0xE1])
}

/// One sheet of a workbook, as text for the sheet reader.
#[derive(Clone, Debug, PartialEq)]
pub struct WorkbookSheet {
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
pub fn cell_name(row: usize, column: u32) -> String {
    let mut letters = vec![];
    let mut c = column as u64 + 1;
    while c > 0 {
        let r = ((c - 1) % 26) as u8;
        letters.push((b'A' + r) as char);
        c = (c - 1) / 26;
    }
    letters.iter().rev().collect::<String>() + &row.to_string()
}

/// Read sheet `name` (the first sheet when None) of the workbook in `bytes`; `file` names it in errors.
pub fn read(bytes: &[u8], file: &str, name: Option<&str>) -> Result<WorkbookSheet> {
    let mut book = calamine::open_workbook_auto_from_rs(Cursor::new(bytes))
        .map_err(|e| Error::input(file, "", format!("not a readable workbook (xlsx, xlsm, xlsb, xls or ods): {e}")))?;
    let format = match &book {
        calamine::Sheets::Xls(_) => "xls",
        calamine::Sheets::Xlsx(_) => "xlsx",
        calamine::Sheets::Xlsb(_) => "xlsb",
        calamine::Sheets::Ods(_) => "ods",
    };
    let sheets = book.sheet_names();
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
    let range = book
        .worksheet_range(&sheet)
        .map_err(|e| Error::input(file, format!("sheet \"{sheet}\""), format!("cannot be read: {e}")))?;
    let (first_row, first_column) = range.start().unwrap_or((0, 0));
    let cells: Vec<Vec<String>> = range.rows().map(|r| r.iter().map(cell_text).collect()).collect();
    // Columns past the last one that holds anything are left out (formatting can widen the used range).
    let width = cells.iter().map(|r| r.iter().rposition(|c| !c.is_empty()).map_or(0, |i| i + 1)).max().unwrap_or(0);
    let mut text = "\n".repeat(first_row as usize);
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
    Ok(WorkbookSheet { format, sheet, sheets, text, first_column })
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
