//! The documents of `compare`: the predictions beside an instrument sheet as JSON (the sheet, the rule, one
//! object per (sample, reading) with its statistics, allowance and verdict, the summary, the colour
//! differences and the baseline checks; the schema is [`super::schema::compare`]) and as CSV, one record per
//! (sample, reading). The JUnit XML and the table for people are the command line's.
use std::path::Path;

use schemars::JsonSchema;
use serde::Serialize;

use super::{csv_text, pretty, to_json, BaselineDoc, BudgetLineDoc};
use crate::comparison::sheet::{self, Sheet};
use crate::comparison::{ColourDifference, Comparison, Drift, Verdict, VerdictRule};
use crate::Result;

/// The allowed difference of a comparison: its parts and their total, total = random + stated + prediction
/// (docs/instrument.md §The prediction's uncertainty).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AllowanceDoc {
    /// k·s/√n.
    #[schemars(range(min = 0))]
    pub statistical: f64,
    /// u_pred, the prediction's standard uncertainty from the recipe's stated uncertainties (0 without them).
    #[schemars(range(min = 0))]
    pub prediction_uncertainty: f64,
    /// k·√(s²/n + u_pred²), the part that enters the total: `statistical` when u_pred = 0.
    #[schemars(range(min = 0))]
    pub random: f64,
    /// The stated uncertainty (or the tolerance).
    #[schemars(range(min = 0))]
    pub stated: f64,
    /// The prediction's error estimate (the numerical error, with a measured table's data uncertainty).
    #[schemars(range(min = 0))]
    pub prediction: f64,
    #[schemars(range(min = 0))]
    pub total: f64,
    /// The parts added to make the total, in order, each named with its formula.
    pub parts: Vec<AllowancePartDoc>,
}

/// One part of an allowance.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AllowancePartDoc {
    #[schemars(extend("enum" = ["statistical", "statistical and prediction uncertainty", "stated", "numerical"]))]
    pub name: String,
    /// How it is computed (`k·√(s²/n + u_pred²)`, ...).
    pub formula: String,
    #[schemars(range(min = 0))]
    pub value: f64,
}

/// One compared (sample, reading): the sheet's values and statistics, the prediction, the allowance and the
/// verdict.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = comparison_doc_nullable)]
#[serde(deny_unknown_fields)]
pub struct ComparisonDoc {
    pub sample: String,
    pub material: String,
    pub recipe: String,
    pub geometry: String,
    pub reading: String,
    pub predicted_reading: Option<String>,
    /// The sheet's lines the values came from.
    #[schemars(inner(range(min = 1)))]
    pub lines: Vec<usize>,
    pub columns: Vec<String>,
    pub values: Vec<f64>,
    #[schemars(range(min = 1))]
    pub n: usize,
    pub mean: f64,
    #[schemars(range(min = 0))]
    pub std: f64,
    pub min: f64,
    pub max: f64,
    pub uncertainty: Option<f64>,
    pub predicted: Option<f64>,
    pub error_estimate: Option<f64>,
    /// A colour prediction's CIE illuminant and observer ([`ConditionsDoc`]); absent on every other row.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub colour: Option<super::ConditionsDoc>,
    /// When the recipe states uncertainties of its numbers: the prediction's standard uncertainty u_pred
    /// (docs/instrument.md §The prediction's uncertainty).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 0))]
    pub prediction_uncertainty: Option<f64>,
    /// With `prediction_uncertainty`: each stated number's share of it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uncertainty_budget: Option<Vec<BudgetLineDoc>>,
    /// predicted − measured mean.
    pub difference: Option<f64>,
    pub allowance: Option<AllowanceDoc>,
    /// unchecked (no value, or no allowance) and OUTSIDE fail the check (exit 1).
    #[schemars(extend("enum" = ["ok", "OUTSIDE", "unchecked", "not predicted"]))]
    pub verdict: String,
    pub inside: Option<bool>,
    /// Why not predicted, or why the prediction has no value.
    pub reason: Option<String>,
    /// Why the row could not be checked.
    pub unchecked: Option<String>,
}

impl ComparisonDoc {
    pub(crate) fn new(c: &Comparison) -> ComparisonDoc {
        let p = c.predicted.as_ref();
        let s = c.group.stats;
        ComparisonDoc {
            sample: c.group.sample.clone(),
            material: c.material.clone(),
            recipe: c.recipe.clone(),
            geometry: c.group.geometry.clone(),
            reading: c.group.reading.clone(),
            predicted_reading: p.map(|p| p.name.clone()),
            lines: c.group.lines.clone(),
            columns: c.group.columns.clone(),
            values: c.group.values.clone(),
            n: s.n,
            mean: s.mean,
            std: s.std,
            min: s.min,
            max: s.max,
            uncertainty: c.group.uncertainty,
            predicted: p.and_then(|p| p.value),
            error_estimate: p.filter(|p| p.value.is_some()).map(|p| p.error_estimate),
            colour: p.and_then(|p| p.colour).map(super::ConditionsDoc::new),
            prediction_uncertainty: c.prediction_uncertainty.as_ref().map(|u| u.u),
            uncertainty_budget: c.prediction_uncertainty.as_ref().map(BudgetLineDoc::budget),
            difference: c.difference(),
            allowance: c.allowance.map(|a| AllowanceDoc {
                statistical: a.statistical,
                prediction_uncertainty: a.prediction_uncertainty,
                random: a.random,
                stated: a.stated,
                prediction: a.prediction,
                total: a.total(),
                parts: a
                    .parts()
                    .iter()
                    .map(|(name, formula, value)| AllowancePartDoc {
                        name: (*name).into(),
                        formula: (*formula).into(),
                        value: *value,
                    })
                    .collect(),
            }),
            verdict: c.verdict.label().into(),
            inside: match c.verdict {
                Verdict::Inside => Some(true),
                Verdict::Outside => Some(false),
                _ => None,
            },
            reason: match &c.verdict {
                Verdict::NotPredicted(w) | Verdict::NoValue(w) => Some(w.clone()),
                _ => None,
            },
            unchecked: c.verdict.why_unchecked(),
        }
    }
}

/// The sheet read: its file, encoding, delimiter, layout, `# key: value` lines and ignored columns.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SheetDoc {
    pub file: String,
    pub encoding: String,
    pub delimiter: String,
    #[schemars(extend("enum" = ["long", "wide", "colour"]))]
    pub layout: String,
    /// The sheet's `# key: value` lines.
    #[schemars(with = "std::collections::BTreeMap<String, String>")]
    pub metadata: serde_json::Value,
    pub ignored_columns: Vec<String>,
}

impl SheetDoc {
    pub(crate) fn new(sheet: &Sheet) -> SheetDoc {
        SheetDoc {
            file: sheet.file.clone(),
            encoding: sheet.encoding.clone(),
            delimiter: (sheet.delimiter as char).to_string(),
            layout: match sheet.layout {
                sheet::Layout::Long => "long",
                sheet::Layout::Wide => "wide",
                sheet::Layout::Colour => "colour",
            }
            .into(),
            metadata: sheet.metadata_json(),
            ignored_columns: sheet.ignored_columns.clone(),
        }
    }
}

/// One value of a sheet as read: where it stands, what it is a reading of, and its value.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = sheet_row_doc_nullable)]
#[serde(deny_unknown_fields)]
pub struct SheetRowDoc {
    /// The line of the file (or the workbook's row) the row starts on, 1-based.
    #[schemars(range(min = 1))]
    pub line: usize,
    /// The header of the column the value came from.
    pub column: String,
    pub sample: String,
    pub geometry: String,
    /// A quantity (`gloss`, `haze`, `doi`, …) or a reading name (`haze-narrow`, …).
    pub reading: String,
    pub value: f64,
    /// The row's stated uncertainty, if any.
    pub uncertainty: Option<f64>,
    /// Why the reading cannot be predicted (a recognised column whose formula is not public), if so.
    pub not_predicted: Option<String>,
}

/// A sheet as the one sheet reader reads it (`compare`'s and `fit`'s; the Python `read_sheet`): what it found
/// out about the file and every value, in the sheet's order.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(title = "glossmeter sheet", transform = sheet_read_doc_nullable)]
pub struct SheetReadDoc {
    pub sheet: SheetDoc,
    /// The workbook's sheet read (null for a text sheet).
    pub workbook_sheet: Option<String>,
    /// The 1-based line (or workbook row) of the header.
    #[schemars(range(min = 1))]
    pub header_line: usize,
    pub headers: Vec<String>,
    /// The statistics cells (`Mean 20°`, …) checked against their series.
    pub statistics_checked: usize,
    pub rows: Vec<SheetRowDoc>,
}

impl SheetReadDoc {
    pub fn new(sheet: &Sheet) -> SheetReadDoc {
        SheetReadDoc {
            sheet: SheetDoc::new(sheet),
            workbook_sheet: sheet.workbook_sheet.clone(),
            header_line: sheet.header_line,
            headers: sheet.headers.clone(),
            statistics_checked: sheet.statistics_checked,
            rows: sheet
                .rows
                .iter()
                .map(|r| SheetRowDoc {
                    line: r.line,
                    column: r.column.clone(),
                    sample: r.sample.clone(),
                    geometry: r.geometry.clone(),
                    reading: r.reading.clone(),
                    value: r.value,
                    uncertainty: r.uncertainty,
                    not_predicted: r.not_predicted.clone(),
                })
                .collect(),
        }
    }
}

/// The verdict rule: k standard errors of the mean, and the uncertainty of rows that state none.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = rule_doc_nullable)]
#[serde(deny_unknown_fields)]
pub struct RuleDoc {
    #[schemars(range(min = 0))]
    pub k: f64,
    /// The tolerance of readings that no `tolerances` key names.
    pub tolerance: Option<f64>,
    /// Tolerances per reading (`--tolerance gloss=2`, `astm-e430-30/doi=3`), key → value.
    pub tolerances: std::collections::BTreeMap<String, f64>,
}

/// How many comparisons ended in each verdict.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SummaryDoc {
    pub readings: usize,
    pub inside: usize,
    pub outside: usize,
    pub no_value: usize,
    pub no_allowance: usize,
    pub not_predicted: usize,
}

/// CIEDE2000 of a (sample, geometry) with L*, a*, b* on the sheet.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = colour_difference_doc_nullable)]
#[serde(deny_unknown_fields)]
pub struct ColourDifferenceDoc {
    pub sample: String,
    pub geometry: String,
    /// The first line of the sheet's L* rows.
    #[schemars(range(min = 1))]
    pub line: usize,
    /// L*, a*, b*.
    pub measured: [f64; 3],
    /// L*, a*, b*.
    pub predicted: [f64; 3],
    #[schemars(range(min = 0))]
    pub de00: f64,
    /// ΔE00 within the maximum, when a maximum is given.
    pub inside: Option<bool>,
}

/// `compare --format json`: the sheet, the rule, one entry per compared (sample, reading), the summary, the
/// colour differences and the baseline checks.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(title = "glossmeter compare --format json")]
pub struct CompareDoc {
    pub sheet: SheetDoc,
    pub rule: RuleDoc,
    pub comparisons: Vec<ComparisonDoc>,
    pub summary: SummaryDoc,
    pub colour_differences: Vec<ColourDifferenceDoc>,
    /// With --baseline: the checks against it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub baseline: Option<BaselineDoc>,
}

impl CompareDoc {
    /// The document printed as the CLI prints it ([`pretty`]).
    pub(crate) fn text(&self) -> String {
        pretty(&to_json(self))
    }
}

/// The JSON document of `compare`.
pub fn json_doc(
    sheet: &Sheet,
    cmp: &[Comparison],
    rule: &VerdictRule,
    drift: &[Drift],
    baseline: Option<&Path>,
    des: &[ColourDifference],
) -> CompareDoc {
    let count = |f: &dyn Fn(&Verdict) -> bool| cmp.iter().filter(|c| f(&c.verdict)).count();
    CompareDoc {
        sheet: SheetDoc::new(sheet),
        rule: RuleDoc {
            k: rule.k,
            tolerance: rule.tolerance,
            tolerances: rule.per_reading.iter().map(|t| (t.key(), t.value)).collect(),
        },
        comparisons: cmp.iter().map(ComparisonDoc::new).collect(),
        summary: SummaryDoc {
            readings: cmp.len(),
            inside: count(&|v| *v == Verdict::Inside),
            outside: count(&|v| *v == Verdict::Outside),
            no_value: count(&|v| matches!(v, Verdict::NoValue(_))),
            no_allowance: count(&|v| *v == Verdict::NoAllowance),
            not_predicted: count(&|v| matches!(v, Verdict::NotPredicted(_))),
        },
        colour_differences: des
            .iter()
            .map(|d| ColourDifferenceDoc {
                sample: d.sample.clone(),
                geometry: d.geometry.clone(),
                line: d.line,
                measured: [d.measured.l, d.measured.a, d.measured.b],
                predicted: [d.predicted.l, d.predicted.a, d.predicted.b],
                de00: d.de00,
                inside: d.inside,
            })
            .collect(),
        baseline: baseline.map(|b| BaselineDoc::new(b.display().to_string(), drift)),
    }
}

/// The CSV of `compare`: a header, then one record per comparison.
pub(crate) fn csv(cmp: &[Comparison]) -> Result<String> {
    let head = [
        "line",
        "sample",
        "material",
        "geometry",
        "reading",
        "n",
        "mean",
        "std",
        "min",
        "max",
        "predicted",
        "error_estimate",
        "difference",
        "allowance",
        "verdict",
        "note",
        // The allowance's parts (docs/instrument.md §The prediction's uncertainty), after the columns that
        // were there before them: u_pred, k·s/√n, k·√(s²/n + u_pred²), the stated uncertainty, e_P.
        "prediction_uncertainty",
        "allowance_statistical",
        "allowance_random",
        "allowance_stated",
        "allowance_prediction",
    ];
    // Numbers to their precision (docs/instrument.md §Numbers in text); the JSON keeps every digit.
    let e = |v: Option<f64>| v.map(super::measured).unwrap_or_default();
    let rows = cmp.iter().map(|c| {
        let p = c.predicted.as_ref();
        let s = c.group.stats;
        let (predicted, error) =
            p.and_then(|p| p.value.map(|v| super::with_error(v, p.error_estimate))).unwrap_or_default();
        [
            c.group.lines[0].to_string(),
            c.group.sample.clone(),
            c.material.clone(),
            c.group.geometry.clone(),
            c.group.reading.clone(),
            s.n.to_string(),
            e(Some(s.mean)),
            e(Some(s.std)),
            e(Some(s.min)),
            e(Some(s.max)),
            predicted,
            error,
            e(c.difference()),
            e(c.allowance.map(|a| a.total())),
            c.verdict.label().to_string(),
            match &c.verdict {
                Verdict::NotPredicted(why) => format!("not predicted: {why}"),
                v => v.why_unchecked().map(|w| format!("not checked: {w}")).unwrap_or_default(),
            },
            e(c.prediction_uncertainty.as_ref().map(|u| u.u)),
            e(c.allowance.map(|a| a.statistical)),
            e(c.allowance.map(|a| a.random)),
            e(c.allowance.map(|a| a.stated)),
            e(c.allowance.map(|a| a.prediction)),
        ]
    });
    csv_text(&head, rows)
}

fn comparison_doc_nullable(schema: &mut schemars::Schema) {
    super::nullable_but_written(
        schema,
        &[
            "predicted_reading",
            "uncertainty",
            "predicted",
            "error_estimate",
            "difference",
            "allowance",
            "inside",
            "reason",
            "unchecked",
        ],
    );
}

fn sheet_read_doc_nullable(schema: &mut schemars::Schema) {
    super::nullable_but_written(schema, &["workbook_sheet"]);
}

fn sheet_row_doc_nullable(schema: &mut schemars::Schema) {
    super::nullable_but_written(schema, &["uncertainty", "not_predicted"]);
}

fn rule_doc_nullable(schema: &mut schemars::Schema) {
    super::nullable_but_written(schema, &["tolerance"]);
}

fn colour_difference_doc_nullable(schema: &mut schemars::Schema) {
    super::nullable_but_written(schema, &["inside"]);
}
