//! Narrow GGX: the polar rule beside the forced Genz–Malik partition.
use std::fmt::Write as _;
use std::sync::Arc;

use glossmeter::instrument::method::Rule;

use crate::cases::{case, forced, problem, rule_rows};
use crate::materials::{BenchMicrofacet, Dist};
use crate::report::{fmt_e, fmt_time, loadavg};

/// Narrow GGX (`docs/performance.md` §"Narrow GGX: the polar rule beside the forced partition"): the polar rule the
/// planner chooses (`Rule::LobePolar`) beside the Genz–Malik 7/5 partition forced on the same method (same lobe chart,
/// same initial boxes: the engine before the polar rule), in one run, at α = 1e-3, 1e-5, 1e-7 on astm-d523-20
/// (n = 1.5). Reference: the forced partition at rtol 1e-11, cross-checked against the polar rule at 1e-11.
pub(crate) fn narrow_ggx(md: &mut String) {
    let _ = writeln!(md, "\n## Narrow GGX: the polar rule beside the forced Genz–Malik partition (same chart)\n");
    let _ = writeln!(
        md,
        "Specimen flux, astm-d523-20, n = 1.5; load average at the start of this section {}.\n",
        loadavg()
    );
    let _ = writeln!(md, "| α | method | value | claimed | rel. err | evaluations | time | runs |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|");
    for alpha in [1e-3, 1e-5, 1e-7] {
        let c = case("NARROW", "GGX", Arc::new(BenchMicrofacet::new(Dist::Ggx, alpha, 1.5)), "astm-d523-20");
        let reference = forced(&c, 1e-11, Some(Rule::GenzMalik75)).solve();
        let polar_fine = problem(&c, 1e-11).solve();
        let r = reference.value[0];
        eprintln!(
            "[bench] narrow GGX α = {alpha:e}: reference {r:.15e} ({} evaluations), polar at 1e-11 {:.15e} ({}), rel. diff {:.1e}",
            reference.evaluations,
            polar_fine.value[0],
            polar_fine.evaluations,
            (polar_fine.value[0] - r).abs() / r
        );
        for rtol in [1e-6, 1e-9] {
            let rules = [("polar (planner's choice)", None), ("Genz–Malik 7/5 forced", Some(Rule::GenzMalik75))];
            for x in rule_rows(&c, rtol, &rules, r) {
                let _ = writeln!(
                    md,
                    "| {alpha:.0e} | {} | {:.10e} | {} | {} | {} | {} | {} |",
                    x.method,
                    x.value,
                    fmt_e(x.claimed),
                    fmt_e(x.rel_err),
                    x.evals,
                    fmt_time(x.seconds),
                    x.runs
                );
            }
        }
        let _ = writeln!(
            md,
            "| {alpha:.0e} | reference: forced partition, rtol 1e-11 | {r:.15e} | {} | polar at 1e-11: {} | {} | | |",
            fmt_e(reference.error[0] / r),
            fmt_e((polar_fine.value[0] - r).abs() / r),
            reference.evaluations
        );
    }
    let _ = writeln!(md, "\nLoad average at the end of this section {}.", loadavg());
}
