//! The sheet reader's row stages (docs/instrument.md §Sheets, §Statistics columns): a row reader per layout,
//! the statistics rows and columns of a row, and the statistics check of the whole sheet.
use super::*;

/// A statistics cell of a row, checked once the whole sheet is read.
pub(super) struct StatCell {
    line: usize,
    column: usize,
    stat: Statistic,
    sample: String,
    geometry: String,
    reading: String,
    value: f64,
    /// The cell as written (its decimals are the statistic's precision).
    text: String,
    /// The readings it summarises, for a statistics row (the column's readings above it, back to the header or
    /// the previous statistics rows); None for a statistics column (the sample's readings in the whole sheet).
    series: Option<Vec<f64>>,
}

/// Stage 4, the statistics check: each stated statistic against its series (a statistics row's own, or the
/// sample's readings of that reading in the whole sheet for a statistics column).
pub(super) fn check_statistics(
    stat_cells: &[StatCell],
    rows: &[SheetRow],
    headers: &[String],
    file: &str,
    place: &Place,
) -> Result<()> {
    // Each stated statistic against its series: the sample's readings of that reading in the whole sheet.
    let mut series_of: HashMap<(&str, &str, &str), Vec<f64>> = HashMap::new();
    for r in rows {
        series_of.entry((r.sample.as_str(), r.geometry.as_str(), r.reading.as_str())).or_default().push(r.value);
    }
    for sc in stat_cells {
        let (c, text) = (sc.column, &headers[sc.column]);
        let sample = if sc.sample.is_empty() { String::new() } else { format!(" of sample `{}`", sc.sample) };
        let values = match &sc.series {
            Some(v) if !v.is_empty() => Some(v),
            Some(_) => None,
            None => series_of.get(&(sc.sample.as_str(), sc.geometry.as_str(), sc.reading.as_str())),
        };
        let Some(values) = values else {
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
    Ok(())
}

/// One data record being read (stage 3): its cells, its line and the header, for the row readers.
pub(super) struct Record<'a> {
    pub(super) rec: &'a csv::StringRecord,
    pub(super) line: usize,
    pub(super) headers: &'a [String],
    pub(super) file: &'a str,
    pub(super) place: &'a Place,
}

impl Record<'_> {
    pub(super) fn get(&self, c: Option<usize>) -> String {
        c.and_then(|c| self.rec.get(c)).unwrap_or("").to_string()
    }

    pub(super) fn at(&self, c: usize) -> String {
        at(self.place, self.line, c, &self.headers[c])
    }

    /// Cell `c` as a number (`what` names it in the error), non-negative when `nonneg`.
    pub(super) fn num(&self, c: usize, what: &str, nonneg: bool) -> Result<f64> {
        let v = parse_number(&self.rec[c]).map_err(|m| Error::input(self.file, self.at(c), format!("{what}: {m}")))?;
        if nonneg && v < 0.0 {
            return Err(Error::input(self.file, self.at(c), format!("{what} must be ≥ 0, got {v}")));
        }
        Ok(v)
    }
}

/// Stage 3, the long layout's row: one reading, its geometry, quantity (gloss when empty) and uncertainty.
pub(super) fn long_row(
    r: &Record,
    sample: &str,
    g: usize,
    v: usize,
    quantity: Option<usize>,
    uncertainty: Option<usize>,
) -> Result<Vec<SheetRow>> {
    let geometry = r.get(Some(g));
    if geometry.is_empty() {
        return Err(Error::input(r.file, r.at(g), "empty geometry id"));
    }
    let reading = match r.get(quantity) {
        q if q.is_empty() => "gloss".to_string(),
        q => q.to_lowercase().split_whitespace().collect::<Vec<_>>().join("-"),
    };
    let reading =
        COLOUR_QUANTITIES.iter().find(|(q, _)| *q == reading).map(|(_, name)| name.to_string()).unwrap_or(reading);
    let not_predicted = READING_COLUMNS
        .iter()
        .find(|c| c.reading == reading && c.geometry == geometry)
        .and_then(|c| c.not_predicted)
        .map(String::from);
    let value = r.num(v, "the measured value", false)?;
    let uncertainty = match uncertainty {
        Some(c) if !r.rec[c].is_empty() => Some(r.num(c, "the uncertainty", true)?),
        _ => None,
    };
    Ok(vec![SheetRow {
        line: r.line,
        column: r.headers[v].clone(),
        sample: sample.to_string(),
        geometry,
        reading,
        value,
        uncertainty,
        not_predicted,
    }])
}

/// A row's cells of the condition columns, into `kept`: each distinct text once (`D65` and `d65` are two texts of
/// one illuminant, so more than two are kept), up to one more than [`CONDITION_TEXTS`], which
/// `comparison::conditions` refuses.
pub(super) fn keep_condition_cells(r: &Record, columns: &[usize], kept: &mut Vec<(usize, usize, String)>) {
    for &j in columns {
        let text = r.get(Some(j));
        let count = kept.iter().filter(|(_, c, _)| *c == j).count();
        let seen = kept.iter().any(|(_, c, t)| *c == j && *t == text);
        if !text.is_empty() && !seen && count <= CONDITION_TEXTS {
            kept.push((r.line, j, text));
        }
    }
}

/// Stage 3, the colour layout's row: L*, a* and b* of one geometry.
pub(super) fn colour_rows(r: &Record, sample: &str, g: usize, lab: &[Option<usize>]) -> Result<Vec<SheetRow>> {
    let mut rows = vec![];

    let geometry = r.get(Some(g));
    if geometry.is_empty() {
        return Err(Error::input(r.file, r.at(g), "empty geometry id"));
    }
    for (i, c) in lab.iter().enumerate() {
        let c = c.expect("colour layout has all three");
        let reading = LAB_COLUMNS[i].1;
        let value = r.num(c, &format!("the measured {reading}"), false)?;
        rows.push(SheetRow {
            line: r.line,
            column: r.headers[c].clone(),
            sample: sample.to_string(),
            geometry: geometry.clone(),
            reading: reading.to_string(),
            value,
            uncertainty: None,
            not_predicted: None,
        });
    }
    Ok(rows)
}

/// Stage 3, the wide layout's row: one reading per non-empty reading column.
pub(super) fn wide_rows(r: &Record, sample: &str, reading_cols: &[usize], roles: &[Role]) -> Result<Vec<SheetRow>> {
    let mut rows = vec![];
    for &c in reading_cols {
        if r.rec[c].is_empty() {
            continue;
        }
        let Role::Reading { geometry, reading, not_predicted, .. } = &roles[c] else { unreachable!() };
        let value = r.num(c, "the measured value", false)?;
        rows.push(SheetRow {
            line: r.line,
            column: r.headers[c].clone(),
            sample: sample.to_string(),
            geometry: geometry.to_string(),
            reading: reading.to_string(),
            value,
            uncertainty: None,
            not_predicted: not_predicted.map(String::from),
        });
    }
    Ok(rows)
}

/// Stage 3, a statistics row's cells: each of its reading cells is a stated statistic of that column's readings
/// in `above` (the rows back to the header or the previous statistics rows).
pub(super) fn statistics_row_cells(
    r: &Record,
    stat: Statistic,
    reading_cols: &[usize],
    roles: &[Role],
    above: &[SheetRow],
) -> Result<Vec<StatCell>> {
    let mut cells = vec![];
    for &c in reading_cols {
        if r.rec[c].is_empty() || statistics_label(&r.rec[c]).is_some() {
            continue;
        }
        let Role::Reading { geometry, reading, .. } = &roles[c] else { unreachable!() };
        let value = r.num(c, &format!("the stated {}", stat.name()), false)?;
        let of = |row: &&SheetRow| row.geometry == *geometry && row.reading == *reading;
        let series: Vec<f64> = above.iter().filter(of).map(|row| row.value).collect();
        cells.push(StatCell {
            line: r.line,
            column: c,
            stat,
            sample: String::new(),
            geometry: geometry.to_string(),
            reading: reading.to_string(),
            value,
            text: r.rec[c].to_string(),
            series: Some(series),
        });
    }
    Ok(cells)
}

/// Stage 3, a row's statistics columns: each stated value, of the reading its header names, of the wide
/// sheet's one reading, or (long layout) of the row's own reading (`last`, the row just read).
pub(super) fn statistics_column_cells(
    r: &Record,
    sample: &str,
    stat_cols: &[usize],
    roles: &[Role],
    layout: Layout,
    wide_reading: Option<(&'static str, &'static str)>,
    last: Option<&SheetRow>,
) -> Result<Vec<StatCell>> {
    let mut cells = vec![];
    for &c in stat_cols {
        if r.rec[c].is_empty() {
            continue;
        }
        let Role::Statistic { stat, of } = roles[c] else { unreachable!() };
        let value = r.num(c, &format!("the stated {}", stat.name()), false)?;
        let (geometry, reading) = match (of, layout) {
            (Some((g, r)), _) => (g.to_string(), r.to_string()),
            (None, Layout::Wide) => {
                let (g, r) = wide_reading.expect("a wide sheet has a reading column");
                (g.to_string(), r.to_string())
            }
            // The long layout: the row's own reading.
            (None, _) => match last {
                Some(row) => (row.geometry.clone(), row.reading.clone()),
                None => continue,
            },
        };
        cells.push(StatCell {
            line: r.line,
            column: c,
            stat,
            sample: sample.to_string(),
            geometry,
            reading,
            value,
            text: r.rec[c].to_string(),
            series: None,
        });
    }
    Ok(cells)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(value: f64) -> SheetRow {
        SheetRow {
            line: 2,
            column: "60°".into(),
            sample: "p".into(),
            geometry: "astm-d523-60".into(),
            reading: "gloss".into(),
            value,
            uncertainty: None,
            not_predicted: None,
        }
    }

    #[test]
    fn a_statistics_row_is_checked_against_the_column_above_it() {
        let headers = vec!["sample".to_string(), "60°".to_string()];
        let roles: Vec<Role> = headers.iter().map(|h| role(h, &[]).unwrap()).collect();
        let above = [row(89.0), row(89.2)];
        for (mean, ok) in [("89.1", true), ("89.3", false)] {
            let rec = csv::StringRecord::from(vec!["Mean", mean]);
            let stat = statistics_row(&rec, &roles).expect("a Mean row");
            let r = Record { rec: &rec, line: 5, headers: &headers, file: "s.csv", place: &Place::Lines };
            let cells = statistics_row_cells(&r, stat, &[1], &roles, &above).unwrap();
            assert_eq!(cells.len(), 1);
            let checked = check_statistics(&cells, &above, &headers, "s.csv", &Place::Lines);
            assert_eq!(checked.is_ok(), ok, "{mean}: {checked:?}");
        }
        // A sample named like a statistic in a later column is not a statistics row.
        let rec = csv::StringRecord::from(vec!["p", "Mean"]);
        assert!(statistics_row(&rec, &roles).is_none());
    }

    #[test]
    fn row_readers_per_layout() {
        let headers: Vec<String> = ["sample", "geometry", "value"].iter().map(|s| s.to_string()).collect();
        let rec = csv::StringRecord::from(vec!["p", "astm-d523-60", "89,1"]);
        let r = Record { rec: &rec, line: 3, headers: &headers, file: "s.csv", place: &Place::Lines };
        let rows = long_row(&r, "p", 1, 2, None, None).unwrap();
        assert_eq!((rows[0].reading.as_str(), rows[0].value, rows[0].line), ("gloss", 89.1, 3));
        let rec = csv::StringRecord::from(vec!["p", "", "1"]);
        let r = Record { rec: &rec, line: 4, headers: &headers, file: "s.csv", place: &Place::Lines };
        assert!(long_row(&r, "p", 1, 2, None, None).unwrap_err().to_string().contains("line 4, column 2 (geometry)"));
    }
}
