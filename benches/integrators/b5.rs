//! B5: the Cerulean Blue paints over the default panel, the plan ablations, the narrow-flake rules side by
//! side, and the tolerance sweep.
use std::fmt::Write as _;
use std::sync::Arc;

use glossmeter::instrument::method::{Chart, Rule, Target};
use glossmeter::instrument::plan::{Engine, Plan, PlanOptions, Reading};

use crate::cases::{rule_label, PANEL};
use crate::panel::{count_evaluations, panel, recipe, run_panel, Counting};
use crate::report::{fmt_e, fmt_time, loadavg, timed, try_run};

pub(crate) fn b5(md: &mut String) {
    let _ = writeln!(md, "\n## B5: Cerulean Blue over the default panel ({})\n", PANEL.join(", "));
    let _ = writeln!(md, "Plan at rtol 1e-6, executed in a 1-thread rayon pool (single-core time); integrals = distinct aperture integrals of the plan (specimen and standard).\n");
    let _ = writeln!(md, "| recipe | plan options | integrals | specimen BRDF evaluations | time | runs | readings |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|");
    let default = PlanOptions { rtol: 1e-6, ..Default::default() };
    let engine = Engine::default();
    let variants: Vec<(&str, &str, Engine)> = vec![
        ("cerulean-blue-c.json", "default (fold + share)", engine),
        (
            "cerulean-blue-c.json",
            "fold_in_material: false (per-sample paint, weighted in the integrand)",
            Engine { fold_in_material: false, ..engine },
        ),
        ("cerulean-blue-c-literal.json", "default (narrow flake lobes)", engine),
        (
            "cerulean-blue-c-literal.json",
            "fold_in_material: false (narrow flake lobes)",
            Engine { fold_in_material: false, ..engine },
        ),
        ("cerulean-blue-c.json", "default, 2-thread pool", engine),
        ("cerulean-blue-c.json", "fold_spectral: false", Engine { fold_spectral: false, ..engine }),
        ("cerulean-blue-c.json", "share_fluxes: false", Engine { share_fluxes: false, ..engine }),
        ("cerulean-blue-b.json", "default (metallic flakes only)", engine),
        ("cerulean-blue-a.json", "default (no flakes)", engine),
    ];
    let mut details: Vec<(&str, Vec<Reading>)> = Vec::new();
    for (file, label, engine) in variants {
        let Some(brdf) = recipe(file) else {
            let _ = writeln!(md, "| {file} | {label} | – | – | – | – | recipe failed to load |");
            continue;
        };
        let detail = label.starts_with("default (fold");
        match try_run(&format!("{file} {label}"), || {
            (
                run_panel(brdf.clone(), default.clone(), engine, if label.contains("2-thread") { 2 } else { 1 }),
                count_evaluations(brdf, default.clone(), engine),
            )
        }) {
            Some((r, evals)) => {
                if detail {
                    details.push((file, r.readings.clone()));
                }
                let vals = r
                    .readings
                    .iter()
                    .map(|x| {
                        format!(
                            "{}/{} {}",
                            x.geometry,
                            x.name,
                            x.value.map(|v| format!("{v:.4}")).unwrap_or_else(|| "–".into())
                        )
                    })
                    .collect::<Vec<_>>()
                    .join("; ");
                let _ = writeln!(
                    md,
                    "| {file} | {label} | {} | {evals} | {} | {} | {vals} |",
                    r.jobs,
                    fmt_time(r.seconds),
                    r.runs
                );
            }
            None => {
                let _ =
                    writeln!(md, "| {file} | {label} | – | – | – | – | engine part not implemented yet (panicked) |");
            }
        }
    }
    let _ = writeln!(
        md,
        "\nSpecimen BRDF evaluations are counted by a wrapper in a separate untimed run (the work actually done).\n"
    );
    tolerance_sweep(md);
    for (file, readings) in details {
        let _ = writeln!(md, "Per reading, {file} (default plan; evaluations and seconds of the integrals each reading uses, shared ones counted in every reading that uses them; seconds are per-integral wall time in the 1-thread pool):\n");
        let _ = writeln!(md, "| geometry | reading | value | error estimate | evaluations | seconds |");
        let _ = writeln!(md, "|---|---|---|---|---|---|");
        for x in &readings {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {:.1e} | {} | {} |",
                x.geometry,
                x.name,
                x.value.map(|v| format!("{v:.6}")).unwrap_or_else(|| "–".into()),
                x.error_estimate,
                x.evaluations,
                fmt_time(x.seconds)
            );
        }
        let _ = writeln!(md);
    }
}

/// Replace the regular rule of every specimen integral of `plan` that has one (None: keep the planner's).
pub(crate) fn force_plan_rule(plan: &mut Plan, rule: Option<Rule>) {
    let Some(rule) = rule else { return };
    for job in plan.jobs.iter_mut().filter(|j| j.method.aperture.target == Target::Specimen) {
        if let Some(part) = job.method.regular.as_mut() {
            part.rule = rule;
        }
    }
}

/// B5 with the narrow flake lobes (cerulean-blue-c-literal) over the default panel, side by side in one run
/// (`docs/performance.md` §"B5 with narrow flake lobes"): the planner's methods, Genz–Malik 7/5 forced on every
/// specimen integral (the engine before the shaped, delta and tensor rules), and the tensor Gauss–Legendre rule with
/// p-refinement forced on the overlap-kink partition (`Chart::Lobe`, orders shared by its boxes; its fallback is
/// the Genz–Malik partition). Whole-panel evaluations (exact, counted by a wrapper) and single-core times; then, per
/// specimen integral, where the evaluations go and each rule's actual error against a Genz–Malik run at 10⁻⁴ of the
/// integral's tolerance.
pub(crate) fn b5_rules(md: &mut String) {
    let file = "cerulean-blue-c-literal.json";
    let Some(brdf) = recipe(file) else { return };
    let opts = PlanOptions { rtol: 1e-6, ..Default::default() };
    let tensor = Rule::TensorGauss { chart: Chart::Lobe, levels: [1; 4], path: Default::default() };
    let rules: [(&str, Option<Rule>); 3] = [
        ("planner's choice", None),
        ("Genz–Malik 7/5 forced", Some(Rule::GenzMalik75)),
        ("tensor Gauss–Legendre forced (kink partition)", Some(tensor)),
    ];
    let _ = writeln!(
        md,
        "\n## B5 {file}: the planner beside forced rules (one run; load average at the start {})\n",
        loadavg()
    );
    let _ = writeln!(md, "| rules of the specimen integrals | specimen BRDF evaluations | time (1 thread) | runs |");
    let _ = writeln!(md, "|---|---|---|---|");
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    for (label, rule) in rules {
        let mut plan = Plan::compile(brdf.clone(), panel(), opts.clone()).expect("plan compiles");
        force_plan_rule(&mut plan, rule);
        let (_, secs, runs) = pool.install(|| timed(|| plan.execute()));
        let counting = Arc::new(Counting { inner: brdf.clone(), n: Default::default() });
        let mut counted = Plan::compile(counting.clone(), panel(), opts.clone()).expect("plan compiles");
        force_plan_rule(&mut counted, rule);
        pool.install(|| counted.execute());
        let evals = counting.n.load(std::sync::atomic::Ordering::Relaxed);
        let _ = writeln!(md, "| {label} | {evals} | {} | {runs} |", fmt_time(secs));
    }
    let _ = writeln!(md, "\nPer specimen integral (evaluations of the integral; actual error relative to Genz–Malik at 10⁻⁴ × the integral's tolerances; est. = the integral's own estimate, relative):\n");
    let _ = writeln!(md, "| # | used by | rule | evaluations | est. | actual | actual / est. | what ran |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|");
    let plan = Plan::compile(brdf.clone(), panel(), opts).expect("plan compiles");
    for (j, job) in plan.jobs.iter().enumerate().filter(|(_, j)| j.method.aperture.target == Target::Specimen) {
        let mut tight = job.method.clone();
        if let Some(p) = tight.regular.as_mut() {
            (p.rule, p.rtol, p.atol) = (Rule::GenzMalik75, 1e-4 * p.rtol, 1e-4 * p.atol);
        }
        if let Some(p) = tight.delta.as_mut() {
            (p.rtol, p.atol) = (1e-4 * p.rtol, 1e-4 * p.atol);
        }
        let r = tight.execute(brdf.as_ref()).value[0];
        for (label, rule) in rules {
            let mut m = job.method.clone();
            if let (Some(p), Some(rule)) = (m.regular.as_mut(), rule) {
                p.rule = rule;
            }
            let f = m.execute(brdf.as_ref());
            let actual = (f.value[0] - r).abs();
            let _ = writeln!(
                md,
                "| {j} | {} | {label} | {} | {} | {} | {:.3} | {} |",
                job.used_by.join(", "),
                f.evaluations,
                fmt_e(f.error[0] / f.value[0].abs()),
                fmt_e(actual / r.abs()),
                actual / f.error[0],
                rule_label(&m, brdf.as_ref())
            );
        }
    }
    let _ = writeln!(md, "\nLoad average at the end of this section {}.", loadavg());
}

/// cerulean-c over the panel at several rtol against an rtol-1e-9 run: how pessimistic the estimate is, and
/// what a tighter estimate would let the plan save.
pub(crate) fn tolerance_sweep(md: &mut String) {
    let Some(brdf) = recipe("cerulean-blue-c.json") else { return };
    let Some(reference) = try_run("cerulean-c rtol 1e-9", || {
        run_panel(brdf.clone(), PlanOptions { rtol: 1e-9, ..Default::default() }, Engine::default(), 1)
    }) else {
        return;
    };
    let _ = writeln!(md, "cerulean-blue-c.json over the panel at several rtol, against an rtol-1e-9 run ({} in one thread): worst relative deviation over the readings, and the worst ratio of actual deviation to the reading's own error estimate.\n", fmt_time(reference.seconds));
    let _ = writeln!(
        md,
        "| rtol | time (1 thread) | specimen BRDF evaluations | worst actual rel. err | worst actual / estimate |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|");
    for rtol in [1e-3, 1e-4, 1e-5, 1e-6, 1e-7] {
        let opts = PlanOptions { rtol, ..Default::default() };
        let r = run_panel(brdf.clone(), opts.clone(), Engine::default(), 1);
        let evals = count_evaluations(brdf.clone(), opts, Engine::default());
        let (mut worst, mut ratio) = (0.0f64, 0.0f64);
        for (x, y) in r.readings.iter().zip(&reference.readings) {
            if let (Some(a), Some(b)) = (x.value, y.value) {
                let d = (a - b).abs();
                worst = worst.max(d / b.abs().max(1e-300));
                ratio = ratio.max(d / x.error_estimate.max(1e-300));
            }
        }
        let _ = writeln!(md, "| {rtol:.0e} | {} | {evals} | {worst:.1e} | {ratio:.2} |", fmt_time(r.seconds));
    }
    let _ = writeln!(md);
}
