//! Glossmeter sheets: readings taken with real instruments, as CSV, to compare predictions against.
//!
//! Two layouts are read (both allow `#` comment lines before the header, e.g. for the instrument and date):
//!
//! * **long**: one reading per row, header with `geometry` and `value` (required), and optionally `quantity`
//!   (or a reading name such as `haze-narrow`; default `gloss`), `uncertainty` (same unit as the value) and
//!   `sample`;
//! * **wide** (what tri-angle glossmeters export): a `sample` column and one column per angle named `20`,
//!   `60`, `85` (optionally `20°`, `G20`, `gloss 20°`, …), read as ASTM D523 gloss at that angle.
//!
//! Every error names the file, the line and the column.
use std::path::Path;

use crate::{Error, Result};

/// One measured reading.
#[derive(Clone, Debug, PartialEq)]
pub struct SheetRow {
    pub line: usize,
    pub sample: String,
    pub geometry: String,
    /// A quantity (`gloss`, `haze`, `doi`, …) or a reading name (`haze-narrow`, …).
    pub reading: String,
    pub value: f64,
    pub uncertainty: Option<f64>,
}

pub fn load(path: &Path) -> Result<Vec<SheetRow>> {
    let file = path.display().to_string();
    let text = crate::input::read_text(path, "sheet")?;
    parse(&text, &file)
}

/// The D523 angle a wide-layout column stands for, if any.
fn wide_angle(header: &str) -> Option<&'static str> {
    let h: String = header.to_lowercase().chars().filter(|c| c.is_ascii_alphanumeric()).collect();
    let h = h.trim_start_matches("gloss").trim_start_matches('g').trim_end_matches("deg");
    match h {
        "20" => Some("astm-d523-20"),
        "60" => Some("astm-d523-60"),
        "85" => Some("astm-d523-85"),
        _ => None,
    }
}

/// The 1-based line of the record that starts at byte `at` (the CSV reader's position is where it began
/// reading, before any blank lines it skipped).
fn line_at(body: &str, at: u64) -> usize {
    let at = (at as usize).min(body.len());
    let skipped_blank = body[at..].bytes().take_while(|b| *b == b'\n' || *b == b'\r').filter(|b| *b == b'\n').count();
    1 + body.as_bytes()[..at].iter().filter(|b| **b == b'\n').count() + skipped_blank
}

pub fn parse(text: &str, file: &str) -> Result<Vec<SheetRow>> {
    // A byte-order mark (spreadsheet exports write one) is not part of the first line.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // Drop comment lines but keep line numbers right.
    let skipped = text.lines().take_while(|l| l.trim_start().starts_with('#') || l.trim().is_empty()).count();
    let body: String = text.lines().skip(skipped).collect::<Vec<_>>().join("\n");
    let mut rdr = csv::ReaderBuilder::new().trim(csv::Trim::All).flexible(false).from_reader(body.as_bytes());
    let headers: Vec<String> = rdr
        .headers()
        .map_err(|e| Error::input(file, format!("line {}", skipped + 1), format!("unreadable CSV header: {e}")))?
        .iter()
        .map(|h| h.to_string())
        .collect();
    let col = |name: &str| headers.iter().position(|h| h.eq_ignore_ascii_case(name));
    let long = col("geometry").is_some();
    let wide_cols: Vec<(usize, &'static str)> =
        headers.iter().enumerate().filter_map(|(i, h)| wide_angle(h).map(|g| (i, g))).collect();
    if !long && wide_cols.is_empty() {
        return Err(Error::input(
            file,
            format!("line {} (header)", skipped + 1),
            "expected a `geometry` and a `value` column (long layout) or columns named 20, 60, 85 (wide layout)",
        ));
    }
    if long && col("value").is_none() {
        return Err(Error::input(
            file,
            format!("line {} (header)", skipped + 1),
            "the long layout needs a `value` column",
        ));
    }
    let mut rows = Vec::new();
    for rec in rdr.records() {
        // Lines, not records: blank lines and quoted newlines make the two differ.
        let rec = rec.map_err(|e| {
            let line = skipped + e.position().map(|p| line_at(&body, p.byte())).unwrap_or(1);
            Error::input(file, format!("line {line}"), format!("malformed CSV row: {e}"))
        })?;
        let line = skipped + rec.position().map(|p| line_at(&body, p.byte())).unwrap_or(1);
        let get = |c: Option<usize>| c.and_then(|c| rec.get(c)).unwrap_or("").to_string();
        let num = |c: usize, what: &str, nonneg: bool| -> Result<f64> {
            let s = rec.get(c).unwrap_or("");
            let field = format!("line {line}, column `{}`", headers[c]);
            let v: f64 = s
                .parse()
                .map_err(|_| Error::input(file, &field, format!("expected a number ({what}), got \"{s}\"")))?;
            if !v.is_finite() || (nonneg && v < 0.0) {
                return Err(Error::input(
                    file,
                    &field,
                    format!("{what} must be a finite number{}", if nonneg { " ≥ 0" } else { "" }),
                ));
            }
            Ok(v)
        };
        let sample = get(col("sample"));
        if long {
            let geometry = get(col("geometry"));
            if geometry.is_empty() {
                return Err(Error::input(file, format!("line {line}, column `geometry`"), "empty geometry id"));
            }
            let reading = match get(col("quantity")) {
                q if q.is_empty() => "gloss".to_string(),
                q => q,
            };
            let value = num(col("value").expect("checked"), "the measured value", false)?;
            let uncertainty = match col("uncertainty") {
                Some(c) if !rec.get(c).unwrap_or("").is_empty() => Some(num(c, "the uncertainty", true)?),
                _ => None,
            };
            rows.push(SheetRow { line, sample, geometry, reading, value, uncertainty });
        } else {
            for &(c, g) in &wide_cols {
                if rec.get(c).unwrap_or("").is_empty() {
                    continue;
                }
                let value = num(c, "the measured gloss", false)?;
                rows.push(SheetRow {
                    line,
                    sample: sample.clone(),
                    geometry: g.to_string(),
                    reading: "gloss".into(),
                    value,
                    uncertainty: None,
                });
            }
        }
    }
    if rows.is_empty() {
        return Err(Error::input(file, "", "the sheet has no readings"));
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_and_wide_layouts() {
        let long = "# BYK micro-TRI-gloss\nsample,geometry,quantity,value,uncertainty\np1,astm-d523-60,gloss,89.1,0.5\np1,astm-e430-30,haze-narrow,3.2,\n";
        let r = parse(long, "s.csv").unwrap();
        assert_eq!(r.len(), 2);
        assert_eq!((r[0].line, r[0].uncertainty), (3, Some(0.5)));
        assert_eq!((r[1].reading.as_str(), r[1].uncertainty), ("haze-narrow", None));
        let wide = "sample,20°,60°,85°\np1,82.0,89.1,99.0\np2,,90,\n";
        let r = parse(wide, "w.csv").unwrap();
        assert_eq!(r.len(), 4);
        assert_eq!(r[3].geometry, "astm-d523-60");
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let e = parse("geometry,value\nastm-d523-60,abc\n", "bad.csv").unwrap_err().to_string();
        assert!(e.contains("bad.csv") && e.contains("line 2") && e.contains("`value`"), "{e}");
        let e = parse("geometry,value,uncertainty\nastm-d523-60,1,-2\n", "bad.csv").unwrap_err().to_string();
        assert!(e.contains("uncertainty") && e.contains("≥ 0"), "{e}");
        let e = parse("foo,bar\n1,2\n", "bad.csv").unwrap_err().to_string();
        assert!(e.contains("geometry"), "{e}");
        let e = parse("geometry,value\nastm-d523-60,1,3\n", "bad.csv").unwrap_err().to_string();
        assert!(e.contains("malformed"), "{e}");
    }

    #[test]
    fn errors_count_lines_not_records() {
        // A blank line and a quoted newline before the bad row: it is on line 6 (the 3rd record).
        let text = "sample,geometry,value\np1,astm-d523-60,1\n\n\"p\n2\",astm-d523-60,2\np3,astm-d523-60,x\n";
        let e = parse(text, "bad.csv").unwrap_err().to_string();
        assert!(e.contains("line 6"), "{e}");
        let r = parse("# c\nsample,geometry,value\n\np1,astm-d523-60,1\n", "ok.csv").unwrap();
        assert_eq!(r[0].line, 4);
    }

    #[test]
    fn a_byte_order_mark_then_a_comment_is_read() {
        let r = parse("\u{feff}# BYK export\ngeometry,value\nastm-d523-60,89.1\n", "bom.csv").unwrap();
        assert_eq!((r[0].line, r[0].value), (3, 89.1));
    }
}
