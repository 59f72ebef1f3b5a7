//! The text of a sheet (docs/instrument.md §Sheets): its encoding, separator, numbers and `#` metadata; the
//! header found under title and metadata rows; line numbers of records and the names of positions (lines or
//! workbook cells) that every message uses.
use super::*;

/// Decode a sheet's bytes: a BOM decides; else UTF-8 if it is valid UTF-8; else Windows-1252.
pub(crate) fn decode(bytes: &[u8], file: &str) -> Result<(String, String)> {
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

/// The separator of the header line: the most frequent of `;`, `,` and tab outside quotes (`,` on a tie).
pub(crate) fn detect_delimiter(header_line: &str) -> u8 {
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
pub(crate) fn parse_number(s: &str) -> std::result::Result<f64, String> {
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
pub(super) fn metadata_line(line: &str) -> Option<(String, String)> {
    let body = line.trim_start().strip_prefix('#')?.trim();
    let (k, v) = body.split_once(':')?;
    let k = k.trim();
    let ok = !k.is_empty()
        && k.len() <= 40
        && k.split_whitespace().count() <= 4
        && k.chars().all(|c| c.is_alphanumeric() || " _-./".contains(c));
    ok.then(|| (k.to_lowercase(), v.trim().to_string()))
}

/// How positions in a sheet are named: lines and columns of a text file, or a workbook sheet's rows and cells.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Place {
    Lines,
    Cells { sheet: String, first_column: u32 },
}

impl Place {
    /// `line 7`, or `sheet "Readings", row 7`.
    pub(super) fn line(&self, line: usize) -> String {
        match self {
            Place::Lines => format!("line {line}"),
            Place::Cells { sheet, .. } => format!("sheet \"{sheet}\", row {line}"),
        }
    }

    /// `line 7, column 3`, or `sheet "Readings", row 7, cell C7`.
    pub(super) fn column(&self, line: usize, col: usize) -> String {
        match self {
            Place::Lines => format!("line {line}, column {}", col + 1),
            Place::Cells { sheet, first_column } => {
                format!("sheet \"{sheet}\", row {line}, cell {}", workbook::cell_name(line, first_column + col as u32))
            }
        }
    }
}

pub(super) fn at(place: &Place, line: usize, col: usize, header: &str) -> String {
    format!("{} ({})", place.column(line, col), short(header))
}

/// A header or cell as messages quote it: at most 60 characters (a cell may hold megabytes).
pub(super) fn short(text: &str) -> String {
    match text.char_indices().nth(60) {
        Some((i, _)) => format!("{}…", &text[..i]),
        None => text.to_string(),
    }
}

/// How many rows above the header a sheet may have (titles, metadata) for the header to be found by its names.
pub(super) const TITLE_ROWS: usize = 20;

/// The line of the header: the record at or after `options.header_row` (1-based) when given; else the first of
/// the first [`TITLE_ROWS`] + 1 records whose cells are all names of columns the reader knows, with a reading
/// among them (a title such as `BYK-Gardner smart-chart 4.2 - Gloss report` is not). None: no such record (the
/// first record is then the header, and its unknown column the error).
pub(super) fn header_line(
    mut rdr: csv::Reader<&[u8]>,
    lines: &Lines,
    file: &str,
    options: &SheetOptions,
) -> Result<Option<usize>> {
    let mut seen = 0;
    for rec in rdr.records() {
        let rec = rec.map_err(|e| csv_error(file, lines, &e))?;
        if rec.iter().all(|f| f.is_empty()) {
            continue;
        }
        let line = lines.line_of(&rec);
        if let Some(h) = options.header_row {
            if line >= h {
                return Ok(Some(line));
            }
            continue;
        }
        let roles: Option<Vec<Role>> =
            rec.iter().map(|f| if f.is_empty() { None } else { role(f, &options.ignore_columns) }).collect();
        let reads = |r: &Role| {
            matches!(r, Role::Reading { .. } | Role::Geometry | Role::Value | Role::Lab(_) | Role::Statistic { .. })
        };
        if roles.is_some_and(|r| r.iter().any(reads)) {
            return Ok(Some(line));
        }
        seen += 1;
        if seen > TITLE_ROWS {
            break;
        }
    }
    if let Some(h) = options.header_row {
        return Err(Error::input(file, "", format!("no header row at or after row {h} (`header_row`)")));
    }
    Ok(None)
}

/// A row above the header as metadata: each `Key: value` cell a pair (`Key:` then the value in the next cell),
/// or a short key and its value in two cells (`Instrument`, `micro-TRI-gloss`); any other row is a `title`.
pub(super) fn title_row(rec: &csv::StringRecord) -> Vec<(String, String)> {
    let cells: Vec<&str> = rec.iter().filter(|f| !f.is_empty()).collect();
    let key_ok = |k: &str| {
        !k.is_empty()
            && k.len() <= 40
            && k.split_whitespace().count() <= 4
            && k.chars().all(|c| c.is_alphanumeric() || " _-./".contains(c))
    };
    let mut pairs: Vec<(String, String)> = vec![];
    for cell in &cells {
        match cell.split_once(':') {
            Some((k, v)) if key_ok(k.trim()) => pairs.push((k.trim().to_lowercase(), v.trim().to_string())),
            _ => match pairs.last_mut() {
                Some((_, v)) if v.is_empty() => *v = cell.to_string(),
                _ => {
                    pairs.clear();
                    break;
                }
            },
        }
    }
    if !pairs.is_empty() {
        return pairs;
    }
    if cells.len() == 2 && key_ok(cells[0]) && cells[0].parse::<f64>().is_err() {
        return vec![(cells[0].to_lowercase(), cells[1].to_string())];
    }
    vec![("title".into(), cells.join(" "))]
}

/// Line numbers of records. The `csv` crate's own line count is off after comment and blank lines, and its
/// byte position is where it started reading (before the blank and comment lines it skipped), so the record's
/// first line is found from that position by skipping line ends and `#` lines.
pub(super) struct Lines<'a> {
    text: &'a [u8],
    starts: Vec<usize>,
}

impl<'a> Lines<'a> {
    pub(super) fn new(text: &'a str) -> Self {
        let b = text.as_bytes();
        let starts =
            std::iter::once(0).chain(b.iter().enumerate().filter(|(_, &c)| c == b'\n').map(|(i, _)| i + 1)).collect();
        Lines { text: b, starts }
    }

    pub(super) fn line_of(&self, rec: &csv::StringRecord) -> usize {
        self.line_at(rec.position().map(|p| p.byte() as usize).unwrap_or(0))
    }

    pub(super) fn line_at(&self, byte: usize) -> usize {
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

pub(super) fn csv_error(file: &str, lines: &Lines, e: &csv::Error) -> Error {
    let field = e.position().map(|p| format!("line {}", lines.line_at(p.byte() as usize))).unwrap_or_default();
    Error::input(file, field, format!("malformed CSV: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(cells: &[&str]) -> csv::StringRecord {
        csv::StringRecord::from(cells.to_vec())
    }

    #[test]
    fn title_rows_become_metadata() {
        let pairs = |c: &[&str]| title_row(&record(c));
        assert_eq!(
            pairs(&["Instrument: micro-TRI-gloss", "", "Serial No.: 1087654"]),
            vec![("instrument".into(), "micro-TRI-gloss".into()), ("serial no.".into(), "1087654".into())]
        );
        assert_eq!(pairs(&["Gauge", "Elcometer 408"]), vec![("gauge".into(), "Elcometer 408".into())]);
        assert_eq!(pairs(&["Operator:", "J. Smith"]), vec![("operator".into(), "J. Smith".into())]);
        assert_eq!(
            pairs(&["BYK-Gardner smart-chart 4.2 - Gloss report", ""]),
            vec![("title".into(), "BYK-Gardner smart-chart 4.2 - Gloss report".into())]
        );
        // A number is not a key.
        assert_eq!(pairs(&["12", "3"])[0].0, "title");
    }

    fn found(text: &str, header_row: Option<usize>) -> Result<Option<usize>> {
        let rdr = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .comment(Some(b'#'))
            .from_reader(text.as_bytes());
        let options = SheetOptions { header_row, ..SheetOptions::default() };
        header_line(rdr, &Lines::new(text), "t.csv", &options)
    }

    #[test]
    fn the_header_is_found_under_title_rows() {
        let t = "Gloss report,,\nInstrument: x,,\n\n# c\nsample,20°,60°\np,1,2\n";
        assert_eq!(found(t, None).unwrap(), Some(5));
        // No header among the rows: the first row is the header (and its unknown column the error).
        assert_eq!(found("foo,bar\n1,2\n", None).unwrap(), None);
        // A row of known names without a reading (`sample,date`) is not the header.
        assert_eq!(found("sample,date\nsample,60\np,1\n", None).unwrap(), Some(2));
        assert_eq!(found(t, Some(2)).unwrap(), Some(2));
        assert_eq!(found(t, Some(3)).unwrap(), Some(5));
        assert!(found(t, Some(9)).unwrap_err().to_string().contains("no header row at or after row 9"));
    }
}
