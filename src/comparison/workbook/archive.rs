//! The guard of zip workbooks (`.xlsx`, `.xlsm`, `.xlsb`, `.ods`), run before calamine opens one
//! (docs/instrument.md §Workbooks, "Limits"): every member is read once as a stream, its decompressed size held
//! to [`MAX_MEMBER_BYTES`] and to [`MAX_RATIO`] times its compressed size, and its CRC-32 compared with the
//! one the archive records; then the counts that calamine reserves memory by (the shared strings of an
//! `.xlsx`) and the extent of an `.ods` sheet's repeated rows and columns are checked against the limits.
use std::io::{Cursor, Read};

use quick_xml::events::{BytesStart, Event};

use super::limits::*;
use crate::{Error, Result};

/// Which zip workbook the members say it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ZipKind {
    Xlsx,
    Xlsb,
    Ods,
}

type Archive<'a> = zip::ZipArchive<Cursor<&'a [u8]>>;

/// Check a zip workbook's members and counts; say which kind it is.
pub(crate) fn check(bytes: &[u8], file: &str) -> Result<ZipKind> {
    let bad = |m: String| Error::input(file, "", m);
    let mut zip = zip::ZipArchive::new(Cursor::new(bytes))
        .map_err(|e| bad(format!("not a readable workbook: its zip archive is damaged ({e})")))?;
    if zip.len() > MAX_MEMBERS {
        return Err(bad(format!(
            "the workbook's zip archive has {} members; at most {MAX_MEMBERS} are read",
            zip.len()
        )));
    }
    let mut total = 0u64;
    for i in 0..zip.len() {
        total += check_member(&mut zip, i, file, total)?;
    }
    let has = |zip: &Archive, name: &str| zip.file_names().any(|n| n.eq_ignore_ascii_case(name));
    let kind = if has(&zip, "xl/workbook.xml") {
        ZipKind::Xlsx
    } else if has(&zip, "xl/workbook.bin") {
        ZipKind::Xlsb
    } else if has(&zip, "content.xml") {
        ZipKind::Ods
    } else {
        return Err(bad(
            "a zip archive that is not a workbook: it has neither xl/workbook.xml (xlsx, xlsm), xl/workbook.bin \
             (xlsb) nor content.xml (ods)"
                .into(),
        ));
    };
    check_xml_closed(&mut zip, file)?;
    match kind {
        ZipKind::Xlsx => check_shared_strings(&mut zip, file)?,
        ZipKind::Ods => check_ods_extent(&mut zip, file)?,
        ZipKind::Xlsb => {}
    }
    Ok(kind)
}

/// One member: its declared sizes, then its bytes as a stream (counted and hashed); its decompressed size.
fn check_member(zip: &mut Archive, i: usize, file: &str, total: u64) -> Result<u64> {
    let bad = |m: String| Error::input(file, "", m);
    let mut m = zip.by_index(i).map_err(|e| bad(format!("zip member {i} cannot be read: {e}")))?;
    let name = m.name().to_string();
    let corrupt = |what: String| bad(format!("the workbook is corrupted: member `{name}` {what}"));
    let refused = |what: String| bad(format!("the workbook is refused: member `{name}` {what}"));
    let (declared, compressed) = (m.size(), m.compressed_size());
    if declared > MAX_MEMBER_BYTES {
        return Err(refused(format!("inflates to {declared} bytes; at most {MAX_MEMBER_BYTES} are read")));
    }
    let mut hasher = crc32fast::Hasher::new();
    let mut n = 0u64;
    let mut buf = vec![0u8; 64 << 10];
    loop {
        let k = match m.read(&mut buf) {
            Ok(k) => k,
            // The zip crate compares the CRC-32 once the member's last byte is out: an error after every declared
            // byte arrived, with a hash that differs from the record, is a bad CRC (decided by the numbers).
            Err(_) if n == declared && hasher.clone().finalize() != m.crc32() => {
                return Err(corrupt("does not match the CRC-32 the archive records (bad CRC)".into()))
            }
            Err(e) => return Err(corrupt(format!("cannot be decompressed ({e})"))),
        };
        if k == 0 {
            break;
        }
        hasher.update(&buf[..k]);
        n += k as u64;
        if n > MAX_MEMBER_BYTES {
            return Err(refused(format!("inflates past {MAX_MEMBER_BYTES} bytes, the most read of one member")));
        }
        if total + n > MAX_TOTAL_BYTES {
            return Err(refused(format!("takes the archive past {MAX_TOTAL_BYTES} decompressed bytes, the most read")));
        }
    }
    if n > RATIO_FLOOR_BYTES && n > MAX_RATIO.saturating_mul(compressed.max(1)) {
        return Err(refused(format!(
            "inflates {}× ({n} bytes from {compressed}); a workbook member over 1 MiB may inflate at most \
             {MAX_RATIO}×",
            n / compressed.max(1)
        )));
    }
    if n != declared {
        return Err(corrupt(format!("inflates to {n} bytes, but the archive says {declared}")));
    }
    let crc = hasher.finalize();
    if crc != m.crc32() {
        return Err(corrupt(format!("has CRC-32 {crc:08x}, but the archive records {:08x} (bad CRC)", m.crc32())));
    }
    Ok(n)
}

/// Every XML member ends with its elements closed and is well-formed as far as an XML reader follows it: calamine's
/// readers loop on an `.ods` `content.xml` cut short inside its table (they wait for an end tag that never comes),
/// so a member that ends inside an element, or that the reader cannot follow, is refused here first.
fn check_xml_closed(zip: &mut Archive, file: &str) -> Result<()> {
    let names: Vec<String> =
        zip.file_names().filter(|n| n.to_ascii_lowercase().ends_with(".xml")).map(str::to_string).collect();
    for name in names {
        let Some(bytes) = member(zip, &name) else { continue };
        if let Some(why) = unclosed(&bytes) {
            return Err(Error::input(file, name.as_str(), why));
        }
    }
    Ok(())
}

/// Why an XML text is cut short or cannot be followed (None: every element it opens is closed).
fn unclosed(bytes: &[u8]) -> Option<String> {
    let mut r = quick_xml::Reader::from_reader(bytes);
    let (mut buf, mut depth) = (vec![], 0usize);
    loop {
        match r.read_event_into(&mut buf) {
            Ok(Event::Start(_)) => depth += 1,
            Ok(Event::End(_)) => depth = depth.saturating_sub(1),
            Ok(Event::Eof) if depth == 0 => return None,
            Ok(Event::Eof) => {
                return Some(format!(
                    "the XML ends inside {depth} open element{} (the workbook is cut short or damaged)",
                    if depth == 1 { "" } else { "s" }
                ))
            }
            Err(e) => return Some(format!("not well-formed XML at byte {}: {e}", r.error_position())),
            _ => {}
        }
        buf.clear();
    }
}

/// The member of that name (ASCII case ignored), decompressed (its size was checked).
fn member(zip: &mut Archive, name: &str) -> Option<Vec<u8>> {
    let real = zip.file_names().find(|n| n.eq_ignore_ascii_case(name))?.to_string();
    let mut out = vec![];
    zip.by_name(&real).ok()?.read_to_end(&mut out).ok()?;
    Some(out)
}

fn attribute(e: &BytesStart, key: &[u8]) -> Option<String> {
    e.attributes().flatten().find(|a| a.key.as_ref() == key).map(|a| String::from_utf8_lossy(&a.value).into_owned())
}

/// A count attribute (a non-negative integer; anything else counts as too many).
fn count(e: &BytesStart, key: &[u8]) -> Option<u64> {
    attribute(e, key).map(|v| v.trim().parse::<u64>().unwrap_or(u64::MAX))
}

/// The `.xlsx` shared-string table's stated counts (calamine reserves `uniqueCount` strings).
fn check_shared_strings(zip: &mut Archive, file: &str) -> Result<()> {
    let Some(bytes) = member(zip, "xl/sharedStrings.xml") else { return Ok(()) };
    let mut r = quick_xml::Reader::from_reader(&bytes[..]);
    let mut buf = vec![];
    loop {
        match r.read_event_into(&mut buf) {
            Ok(Event::Start(e)) | Ok(Event::Empty(e)) if e.local_name().as_ref() == b"sst" => {
                for key in [&b"uniqueCount"[..], b"count"] {
                    if let Some(n) = count(&e, key).filter(|&n| n > MAX_SHARED_STRINGS) {
                        return Err(Error::input(
                            file,
                            "xl/sharedStrings.xml",
                            format!(
                                "the shared-string table says {} = {n}; at most {MAX_SHARED_STRINGS} are read",
                                String::from_utf8_lossy(key)
                            ),
                        ));
                    }
                }
                return Ok(());
            }
            Ok(Event::Eof) | Err(_) => return Ok(()),
            _ => buf.clear(),
        }
    }
}

/// The extent of every `.ods` table, with its repeated rows and columns counted as calamine expands them:
/// the used range (first to last row with a value, times the widest such row) and the cells stored row by row.
fn check_ods_extent(zip: &mut Archive, file: &str) -> Result<()> {
    let Some(bytes) = member(zip, "content.xml") else { return Ok(()) };
    let mut r = quick_xml::Reader::from_reader(&bytes[..]);
    let too_big =
        |what: String| Error::input(file, "content.xml", format!("{what}; a sheet may have at most {MAX_CELLS} cells"));
    let mut buf = vec![];
    let mut t = OdsTable::default();
    loop {
        let ev = r.read_event_into(&mut buf);
        match ev {
            Ok(Event::Start(e)) if e.name().as_ref() == b"table:table" => t = OdsTable::after(&t),
            Ok(Event::Start(e)) if e.name().as_ref() == b"table:table-row" => {
                t.row_start(count(&e, b"table:number-rows-repeated").unwrap_or(1));
            }
            Ok(Event::Empty(e)) if e.name().as_ref() == b"table:table-row" => {
                t.row_start(count(&e, b"table:number-rows-repeated").unwrap_or(1));
                t.row_end();
            }
            Ok(Event::Start(e)) if is_cell(&e) => {
                t.cell(count(&e, b"table:number-columns-repeated").unwrap_or(1), true)
            }
            Ok(Event::Empty(e)) if is_cell(&e) => {
                let valued = attribute(&e, b"office:value-type").is_some();
                t.cell(count(&e, b"table:number-columns-repeated").unwrap_or(1), valued)
            }
            Ok(Event::End(e)) if e.name().as_ref() == b"table:table-row" => t.row_end(),
            Ok(Event::Eof) => return Ok(()),
            // calamine's reader is more lenient than this one (it reads on past a mismatched end tag, expanding
            // the repeats that follow), so what this reader cannot follow is refused, not waved through.
            Err(e) => {
                return Err(Error::input(
                    file,
                    "content.xml",
                    format!("not well-formed XML at byte {}: {e}", r.error_position()),
                ))
            }
            _ => {}
        }
        if let Some(m) = t.over() {
            return Err(too_big(m));
        }
        buf.clear();
    }
}

fn is_cell(e: &BytesStart) -> bool {
    matches!(e.name().as_ref(), b"table:table-cell" | b"table:covered-table-cell")
}

/// An `.ods` table's running extent (calamine reads every table when it opens the file, so the tables before
/// count too).
#[derive(Default)]
struct OdsTable {
    /// The used ranges and stored cells of the tables before this one.
    before: u64,
    /// Rows so far (repeats counted), and the first and last row with a value.
    rows: u64,
    first: Option<u64>,
    last: u64,
    /// The widest row with a value (columns, repeats counted), and the cells stored so far.
    width: u64,
    stored: u64,
    /// The current row: its repeats, its columns so far, the end of its last valued cell.
    repeats: u64,
    column: u64,
    valued_end: u64,
}

impl OdsTable {
    fn after(previous: &OdsTable) -> OdsTable {
        let before = previous.before.saturating_add(previous.area()).saturating_add(previous.stored);
        OdsTable { before, ..OdsTable::default() }
    }

    /// Rows from the first with a value to the last (repeats counted; saturating: a repeat count near 2⁶⁴
    /// must read as over the limit, not wrap to nothing).
    fn rows_used(&self) -> u64 {
        self.first.map_or(0, |f| (self.last - f).saturating_add(1))
    }

    fn area(&self) -> u64 {
        self.rows_used().saturating_mul(self.width)
    }

    fn row_start(&mut self, repeats: u64) {
        (self.repeats, self.column, self.valued_end) = (repeats.max(1), 0, 0);
    }

    fn cell(&mut self, repeats: u64, valued: bool) {
        self.column = self.column.saturating_add(repeats);
        if valued {
            self.valued_end = self.column;
        }
    }

    fn row_end(&mut self) {
        if self.valued_end > 0 {
            self.first.get_or_insert(self.rows);
            self.last = self.rows.saturating_add(self.repeats - 1);
            self.width = self.width.max(self.valued_end);
            self.stored = self.stored.saturating_add(self.valued_end);
        }
        self.rows = self.rows.saturating_add(self.repeats);
        self.repeats = 1;
    }

    /// What is over the limit, if anything.
    fn over(&self) -> Option<String> {
        let rows = self.rows_used();
        if self.before.saturating_add(self.area()) > MAX_CELLS {
            return Some(format!("a table's used range is {rows} rows × {} columns (repeats counted)", self.width));
        }
        // The row being read counts as it grows: one cell repeated 2³² times is over before its row ends.
        let stored = self.stored.saturating_add(self.valued_end);
        (self.before.saturating_add(stored) > MAX_CELLS)
            .then(|| format!("a table stores {stored} cells (repeated columns counted)"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Found by the 10⁶-case fuzz run of 2026-12-06 (case 158049): an `.ods` whose `content.xml` ends after a
    /// row, inside its table, kept calamine's reader waiting for the end tag for good.
    #[test]
    fn a_member_cut_short_inside_an_element_is_named() {
        assert_eq!(unclosed(b"<a><b/></a>"), None);
        let why = unclosed(b"<a><t><r></r>").unwrap();
        assert!(why.contains("inside 2 open elements"), "{why}");
        assert!(unclosed(b"<a></b>").unwrap().contains("not well-formed"));
    }

    /// Found by the 10⁶-case fuzz run: a cell repeated 2³² − 1 times in a row whose end tag never comes
    /// (calamine read on and expanded it for minutes) is over the limit while its row is read.
    #[test]
    fn a_row_is_counted_before_it_ends() {
        let mut t = OdsTable::default();
        t.row_start(1);
        t.cell(1, true);
        assert!(t.over().is_none());
        t.cell(4_294_967_295, true);
        assert!(t.over().unwrap().contains("4294967296 cells"), "{:?}", t.over());
    }

    /// The review's 1.1 kB `.ods`: one valued row repeated 10⁶ times is over the limit; trailing empty rows
    /// repeated to the sheet's end (as LibreOffice writes them) count nothing.
    #[test]
    fn ods_repeats_are_counted_as_calamine_expands_them() {
        let mut t = OdsTable::default();
        t.row_start(1_000_000);
        t.cell(3, true);
        t.row_end();
        assert!(t.over().unwrap().contains("1000000 rows × 3 columns"), "{:?}", t.over());
        let mut t = OdsTable::default();
        t.row_start(1);
        t.cell(4, true);
        t.row_end();
        t.row_start(1_048_575);
        t.cell(1024, false);
        t.row_end();
        assert_eq!((t.over(), t.area()), (None, 4));
        // The tables before count too (calamine reads them all).
        let mut t = OdsTable::default();
        t.row_start(600_000);
        t.cell(1, true);
        t.row_end();
        assert!(t.over().is_none());
        let mut u = OdsTable::after(&t);
        u.row_start(500_000);
        u.cell(1, true);
        u.row_end();
        assert!(u.over().is_some());
        // A repeat count of 2⁶⁴ − 1 on the first row is over the limit (it wrapped to an empty range once).
        let mut t = OdsTable::default();
        t.row_start(u64::MAX);
        t.cell(1, true);
        t.row_end();
        assert!(t.over().is_some_and(|m| m.contains("18446744073709551615 rows")), "{:?}", t.over());
    }
}
