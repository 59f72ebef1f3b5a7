//! JUnit XML for CI servers (written with `quick-junit`): one test case per (sample, reading) of a
//! comparison, and one per baseline check. A reading outside its allowance, or one that could not be checked
//! (no value, no allowance), is a failure; a reading that is not predicted is skipped with the reason; a
//! baseline reading that moved is a failure. Each message gives measured, predicted, allowance and error estimate,
//! each to its precision. The class name is a dotted identifier of the sheet and the sample ([`classname`]), the
//! free text (sample, geometry, reading) is the case's name (docs/instrument.md §CI reports and baselines).
use quick_junit::{NonSuccessKind, Report, TestCase, TestCaseStatus, TestSuite};

use crate::comparison::sheet::Sheet;
use crate::comparison::{Comparison, Drift, Verdict};
use crate::{report, Error, Result};

/// A measured number, or `none`.
fn g(v: Option<f64>) -> String {
    v.map(report::measured).unwrap_or_else(|| "none".into())
}

/// A JUnit class name: a dotted identifier of identifier parts (letters, digits, `_`; CI servers split the
/// class at its dots into packages and class). Every run of other characters becomes one `_`, and a part that
/// would start with a digit or be empty gets a leading `_`: `Black-backed glass, n = 1.50` → `Black_backed_glass_n_1_50`.
pub(crate) fn identifier(text: &str) -> String {
    let mut s = String::new();
    for c in text.chars() {
        if c.is_ascii_alphanumeric() {
            s.push(c);
        } else if !s.ends_with('_') {
            s.push('_');
        }
    }
    let s = s.trim_matches('_');
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        format!("_{s}")
    } else {
        s.to_string()
    }
}

/// The class name of a sheet's cases: the sheet's file name without its folder and extension (and the
/// workbook's sheet), then the sample, as identifiers (`glass_n1_5_trigloss.Black_backed_glass_n_1_50`).
pub(crate) fn classname(sheet: &Sheet, sample: &str) -> String {
    let stem = std::path::Path::new(&sheet.file)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| sheet.file.clone());
    let mut parts = vec![identifier(&stem)];
    if let Some(w) = &sheet.workbook_sheet {
        parts.push(identifier(w));
    }
    parts.push(identifier(sample));
    parts.join(".")
}

/// The message of a comparison case: every number to its precision (`report::measured`,
/// `report::with_error_text`).
pub(crate) fn message(c: &Comparison) -> String {
    let s = c.group.stats;
    let p = c.predicted.as_ref();
    let predicted = match p.and_then(|p| p.value.map(|v| (v, p.error_estimate))) {
        Some((v, e)) => {
            let (v, e) = report::with_error_text(v, e);
            format!("{v} ± {e}")
        }
        None => "none".into(),
    };
    // A colour prediction says what it is computed under (docs/instrument.md §Output).
    let predicted = match p.and_then(|p| p.colour) {
        Some(c) => format!("{predicted} (error estimate; {})", c.describe()),
        None => format!("{predicted} (error estimate)"),
    };
    format!(
        "measured mean {} (n = {}, std {}, min {}, max {}); predicted {predicted}; \
         predicted − measured {}; allowance {}",
        report::measured(s.mean),
        s.n,
        report::measured(s.std),
        report::measured(s.min),
        report::measured(s.max),
        g(c.difference()),
        c.allowance
            .map(|a| format!(
                "{} = {} ({}) + {} (stated) + {} (prediction)",
                report::measured(a.total()),
                report::measured(a.random),
                if a.prediction_uncertainty > 0.0 { "k·√(s²/n + u_pred²)" } else { "k·s/√n" },
                report::measured(a.stated),
                report::error_text(a.prediction)
            ))
            .unwrap_or_else(|| "none".into()),
    )
}

pub(crate) fn compare(sheet: &Sheet, cmp: &[Comparison], drift: &[Drift]) -> Result<String> {
    let mut report = Report::new("glossmeter compare");
    let mut suite = TestSuite::new(sheet.file.clone());
    for c in cmp {
        let name = format!("{} {} {}", c.group.sample, c.group.geometry, c.group.reading);
        let msg = message(c);
        let status = match &c.verdict {
            Verdict::Inside => TestCaseStatus::success(),
            Verdict::Outside => {
                let mut s = TestCaseStatus::non_success(NonSuccessKind::Failure);
                s.set_message(format!("outside the allowance: {msg}")).set_type("outside");
                s
            }
            Verdict::NoValue(why) => {
                let mut s = TestCaseStatus::non_success(NonSuccessKind::Failure);
                s.set_message(format!("the prediction has no value ({why}): {msg}")).set_type("no value");
                s
            }
            Verdict::NoAllowance => {
                let mut s = TestCaseStatus::non_success(NonSuccessKind::Failure);
                s.set_message(format!("not checked: no allowance (one reading, no uncertainty): {msg}"))
                    .set_type("unchecked");
                s
            }
            Verdict::NotPredicted(why) => {
                let mut s = TestCaseStatus::skipped();
                s.set_message(format!("not predicted: {why}"));
                s
            }
        };
        let mut case = TestCase::new(name, status);
        case.set_classname(classname(sheet, &c.group.sample));
        case.set_system_out(format!("lines {:?}, columns {:?}: {msg}", c.group.lines, c.group.columns));
        suite.add_test_case(case);
    }
    report.add_test_suite(suite);
    if !drift.is_empty() {
        report.add_test_suite(baseline_suite(drift));
    }
    let xml = report.to_string().map_err(|e| Error::Numeric(format!("JUnit XML did not serialise: {e}")))?;
    Ok(without_testsuites_skipped(xml))
}

/// The report without the `skipped` attribute of `<testsuites>`, which `quick-junit` writes but the JUnit
/// schema that Jenkins validates against (tests/junit/junit-10.xsd) does not allow there (each `<testsuite>`
/// keeps its own `skipped` count, which the schema allows).
fn without_testsuites_skipped(xml: String) -> String {
    let Some(start) = xml.find("<testsuites ") else { return xml };
    let Some(end) = xml[start..].find('>').map(|e| start + e) else { return xml };
    let tag = &xml[start..end];
    let Some(a) = tag.find(" skipped=\"") else { return xml };
    let Some(len) = tag[a + 10..].find('"').map(|q| a + 10 + q + 1) else { return xml };
    format!("{}{}{}", &xml[..start + a], &xml[start + len..end], &xml[end..])
}

/// One case per baseline check.
pub(crate) fn baseline_suite(drift: &[Drift]) -> TestSuite {
    let mut suite = TestSuite::new("baseline");
    for d in drift {
        let msg = format!(
            "now {} then {}: moved {} against an allowance of {} (both error estimates)",
            report::measured(d.now),
            report::measured(d.then),
            report::measured((d.now - d.then).abs()),
            report::measured(d.allowed)
        );
        let status = if d.moved {
            let mut s = TestCaseStatus::non_success(NonSuccessKind::Failure);
            s.set_message(msg).set_type("moved");
            s
        } else {
            TestCaseStatus::success()
        };
        let mut case = TestCase::new(format!("{} {} {}", d.material, d.geometry, d.reading), status);
        case.set_classname(format!("baseline.{}", identifier(&d.material)));
        suite.add_test_case(case);
    }
    suite
}
