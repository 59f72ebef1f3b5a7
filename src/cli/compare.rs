//! `glossmeter compare`: predictions set beside a glossmeter sheet (CSV), and a pass/fail verdict where
//! the sheet (or `--tolerance`) gives an uncertainty: the command exits 1 when any reading falls outside,
//! so it doubles as a CI check of a BRDF against the standards.
use std::path::PathBuf;

use serde_json::json;

use crate::cli::format::plain;
use crate::cli::{check_rtol, readings_status, Format, Target};
use crate::instrument::plan::{Plan, PlanOptions, Reading};
use crate::instrument::sheet::{self, SheetRow};
use crate::{recipe, resolve_geometries, Error, Result};

#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    /// The recipe (JSON).
    pub recipe: PathBuf,
    /// The sheet (CSV, long or wide layout; see docs/instrument.md §Sheets).
    pub sheet: PathBuf,
    /// Allowed |measured − predicted| in the reading's unit, for rows without an `uncertainty`.
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// Relative tolerance of the predictions.
    #[arg(long, default_value_t = 1e-6)]
    pub rtol: f64,
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
    /// Write to this new file instead of stdout (an existing file is refused before any work).
    #[arg(long, short = 'o')]
    pub output: Option<PathBuf>,
    /// Exit 0 even if a prediction did not converge within its budget (the comparison is still made).
    #[arg(long)]
    pub allow_unconverged: bool,
}

/// One row of the comparison.
#[derive(Clone, Debug)]
pub struct Comparison {
    pub row: SheetRow,
    pub predicted: Option<Reading>,
    /// Allowed difference (uncertainty of the row, else --tolerance), plus the prediction's error estimate.
    pub allowed: Option<f64>,
    /// Some(true) inside, Some(false) outside, None when the row cannot be checked ([`Comparison::why_unchecked`]).
    pub inside: Option<bool>,
}

impl Comparison {
    /// predicted − measured, when there is a prediction.
    pub fn difference(&self) -> Option<f64> {
        self.predicted.as_ref().and_then(|p| p.value).map(|v| v - self.row.value)
    }

    /// Why the row could not be checked (exit status 1), if it could not.
    pub fn why_unchecked(&self) -> Option<String> {
        if self.inside.is_some() {
            return None;
        }
        match &self.predicted {
            None => Some("no prediction for this reading".into()),
            Some(p) if p.value.is_none() => {
                Some(format!("the prediction has no value ({})", p.problem.as_deref().unwrap_or("no finite value")))
            }
            _ => Some("no allowed difference: the row has no uncertainty and no --tolerance was given".into()),
        }
    }
}

pub fn compare(rows: Vec<SheetRow>, readings: &[Reading], tolerance: Option<f64>) -> Vec<Comparison> {
    rows.into_iter()
        .map(|row| {
            let predicted = readings
                .iter()
                .find(|r| r.geometry == row.geometry && (r.name == row.reading || r.quantity == row.reading))
                .cloned();
            let allowed = row.uncertainty.or(tolerance);
            let inside = match (&predicted, allowed) {
                (Some(p), Some(a)) => p.value.map(|v| (v - row.value).abs() <= a + p.error_estimate),
                _ => None,
            };
            Comparison { row, predicted, allowed, inside }
        })
        .collect()
}

pub fn run(a: CompareArgs) -> Result<()> {
    if let Some(t) = a.tolerance {
        if !(t.is_finite() && t >= 0.0) {
            return Err(Error::Usage(format!("--tolerance must be a finite number ≥ 0, got {t}")));
        }
    }
    check_rtol(a.rtol)?;
    let target = Target::new(a.output.as_deref(), "--output")?;
    let material = recipe::load_file(&a.recipe)?;
    let rows = sheet::load(&a.sheet)?;
    let mut ids: Vec<String> = Vec::new();
    for r in &rows {
        if !ids.contains(&r.geometry) {
            ids.push(r.geometry.clone());
        }
    }
    let geos = resolve_geometries(&ids, &[] as &[&str]).map_err(|e| match e {
        Error::Usage(m) => Error::input(a.sheet.display().to_string(), "geometry", m),
        e => e,
    })?;
    let plan = Plan::compile(material.brdf.clone(), geos, PlanOptions { rtol: a.rtol, ..PlanOptions::default() })?;
    let readings = plan.execute();
    let cmp = compare(rows, &readings, a.tolerance);
    if let Some(c) = cmp.iter().find(|c| c.predicted.is_none()) {
        return Err(Error::input(
            a.sheet.display().to_string(),
            format!("line {}", c.row.line),
            format!("geometry `{}` has no reading `{}`", c.row.geometry, c.row.reading),
        ));
    }
    let text = match a.format {
        Format::Table => table(&material.name, &cmp),
        Format::Json => json_text(&material.name, &cmp),
        Format::Csv => csv_text(&cmp)?,
    };
    target.write(&text)?;
    let outside = cmp.iter().filter(|c| c.inside == Some(false)).count();
    if outside > 0 {
        return Err(Error::Check(format!("{outside} of {} reading(s) outside the allowed difference", cmp.len())));
    }
    let unchecked = cmp.iter().filter(|c| c.inside.is_none()).count();
    if unchecked > 0 {
        return Err(Error::Check(format!(
            "{unchecked} of {} reading(s) could not be checked (see the notes in the output)",
            cmp.len()
        )));
    }
    let predicted: Vec<Reading> = cmp.iter().filter_map(|c| c.predicted.clone()).collect();
    readings_status(&predicted, a.allow_unconverged)
}

fn fmt(v: Option<f64>) -> String {
    v.filter(|x| x.is_finite()).map(|x| format!("{x:.3}")).unwrap_or_else(|| "—".into())
}

/// `v` right-aligned in `width` characters (by hand: `format!`'s width is limited to 65 535).
fn right(v: &str, width: usize) -> String {
    let n = v.chars().count();
    format!("{}{v}", " ".repeat(width.saturating_sub(n)))
}

fn table(name: &str, cmp: &[Comparison]) -> String {
    let mut rows = vec![[
        "sample",
        "geometry",
        "reading",
        "measured",
        "predicted",
        "numerical error",
        "predicted − measured",
        "allowed",
        "verdict",
    ]
    .map(String::from)
    .to_vec()];
    let mut notes = Vec::new();
    for c in cmp {
        let p = c.predicted.as_ref();
        let v = p.and_then(|p| p.value);
        rows.push(vec![
            c.row.sample.clone(),
            c.row.geometry.clone(),
            c.row.reading.clone(),
            format!("{:.3}", c.row.value),
            fmt(v),
            p.filter(|p| p.value.is_some()).map(|p| format!("{:.1e}", p.error_estimate)).unwrap_or("—".into()),
            fmt(c.difference()),
            fmt(c.allowed),
            match c.inside {
                Some(true) => "ok".into(),
                Some(false) => "OUTSIDE".into(),
                None => "unchecked".into(),
            },
        ]);
        if let Some(why) = c.why_unchecked() {
            notes.push(format!("line {} ({} {}): not checked: {why}", c.row.line, c.row.geometry, c.row.reading));
        }
    }
    let w: Vec<usize> =
        (0..rows[0].len()).map(|i| rows.iter().map(|r| r[i].chars().count()).max().unwrap_or(0)).collect();
    let mut s = format!("{name}: predictions against the sheet\n\n");
    for (k, r) in rows.iter().enumerate() {
        let line: Vec<String> = r.iter().enumerate().map(|(i, v)| right(v, w[i])).collect();
        s.push_str(line.join("  ").trim_end());
        s.push('\n');
        if k == 0 {
            s.push_str(&w.iter().map(|n| "-".repeat(*n)).collect::<Vec<_>>().join("  "));
            s.push('\n');
        }
    }
    for n in notes {
        s.push_str(&format!("note: {n}\n"));
    }
    s
}

fn json_text(name: &str, cmp: &[Comparison]) -> String {
    let rows: Vec<_> = cmp
        .iter()
        .map(|c| {
            let p = c.predicted.as_ref();
            json!({
                "line": c.row.line, "sample": c.row.sample, "geometry": c.row.geometry, "reading": c.row.reading,
                "measured": c.row.value, "uncertainty": c.row.uncertainty,
                "predicted": p.and_then(|p| p.value),
                "error_estimate": p.filter(|p| p.value.is_some()).map(|p| p.error_estimate),
                "difference": c.difference(),
                "allowed": c.allowed, "inside": c.inside, "unchecked": c.why_unchecked(),
            })
        })
        .collect();
    serde_json::to_string_pretty(&json!({"material": name, "comparisons": rows})).expect("finite") + "\n"
}

fn csv_text(cmp: &[Comparison]) -> Result<String> {
    let mut w = csv::Writer::from_writer(vec![]);
    let err = |e: csv::Error| Error::Io { file: "<csv>".into(), source: std::io::Error::other(e) };
    w.write_record([
        "line",
        "sample",
        "geometry",
        "reading",
        "measured",
        "predicted",
        "error_estimate",
        "difference",
        "allowed",
        "inside",
        "note",
    ])
    .map_err(err)?;
    for c in cmp {
        let p = c.predicted.as_ref();
        let v = p.and_then(|p| p.value);
        w.write_record([
            c.row.line.to_string(),
            c.row.sample.clone(),
            c.row.geometry.clone(),
            c.row.reading.clone(),
            plain(c.row.value),
            v.map(plain).unwrap_or_default(),
            v.and(p).map(|p| plain(p.error_estimate)).unwrap_or_default(),
            c.difference().map(plain).unwrap_or_default(),
            c.allowed.map(plain).unwrap_or_default(),
            c.inside.map(|b| b.to_string()).unwrap_or_default(),
            c.why_unchecked().map(|w| format!("not checked: {w}")).unwrap_or_default(),
        ])
        .map_err(err)?;
    }
    let bytes =
        w.into_inner().map_err(|e| Error::Io { file: "<csv>".into(), source: std::io::Error::other(e.to_string()) })?;
    Ok(String::from_utf8(bytes).expect("utf-8"))
}
