//! JUnit XML for CI servers (written with `quick-junit`): one test case per (sample, reading) of a
//! comparison, and one per baseline check. A reading outside its allowance, or one that could not be checked
//! (no value, no allowance), is a failure; a reading that is not predicted is skipped with the reason; a
//! baseline reading that moved is a failure. Each message gives measured, predicted, allowance and error estimate.
use quick_junit::{NonSuccessKind, Report, TestCase, TestCaseStatus, TestSuite};

use crate::comparison::sheet::Sheet;
use crate::comparison::{Comparison, Drift, Verdict};
use crate::{Error, Result};

fn g(v: Option<f64>) -> String {
    v.map(|v| format!("{v}")).unwrap_or_else(|| "none".into())
}

/// The message of a comparison case.
pub fn message(c: &Comparison) -> String {
    let s = c.group.stats;
    let p = c.predicted.as_ref();
    format!(
        "measured mean {} (n = {}, std {}, min {}, max {}); predicted {} ± {} (error estimate); \
         predicted − measured {}; allowance {}",
        s.mean,
        s.n,
        s.std,
        s.min,
        s.max,
        g(p.and_then(|p| p.value)),
        g(p.filter(|p| p.value.is_some()).map(|p| p.error_estimate)),
        g(c.difference()),
        c.allowance
            .map(|a| format!(
                "{} = {} (k·s/√n) + {} (stated) + {} (prediction)",
                a.total(),
                a.statistical,
                a.stated,
                a.prediction
            ))
            .unwrap_or_else(|| "none".into()),
    )
}

pub fn compare(sheet: &Sheet, cmp: &[Comparison], drift: &[Drift]) -> Result<String> {
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
        case.set_classname(format!("{}.{}", c.material, c.group.sample));
        case.set_system_out(format!("lines {:?}, columns {:?}: {msg}", c.group.lines, c.group.columns));
        suite.add_test_case(case);
    }
    report.add_test_suite(suite);
    if !drift.is_empty() {
        report.add_test_suite(baseline_suite(drift));
    }
    report.to_string().map_err(|e| Error::Numeric(format!("JUnit XML did not serialise: {e}")))
}

/// One case per baseline check.
pub fn baseline_suite(drift: &[Drift]) -> TestSuite {
    let mut suite = TestSuite::new("baseline");
    for d in drift {
        let msg = format!(
            "now {} then {}: moved {} against an allowance of {} (both error estimates)",
            d.now,
            d.then,
            (d.now - d.then).abs(),
            d.allowed
        );
        let status = if d.moved {
            let mut s = TestCaseStatus::non_success(NonSuccessKind::Failure);
            s.set_message(msg).set_type("moved");
            s
        } else {
            TestCaseStatus::success()
        };
        let mut case = TestCase::new(format!("{} {} {}", d.material, d.geometry, d.reading), status);
        case.set_classname(format!("baseline.{}", d.material));
        suite.add_test_case(case);
    }
    suite
}
