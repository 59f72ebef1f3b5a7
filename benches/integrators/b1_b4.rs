//! B1–B4: the specimen flux through the gloss receptor, the engine beside the baselines, and where its
//! evaluations go.
use std::fmt::Write as _;
use std::sync::Arc;
use std::time::Instant;

use glossmeter::brdf::{Brdf, Hints};
use glossmeter::instrument::method::{Chart, Flux, Rule};
use glossmeter::instrument::plan::{Plan, PlanOptions, Reading};
use glossmeter::spectrum::Sampling;
use glossmeter::Vec3;

use crate::baselines::{lambert_exact, midpoint_grid, monte_carlo, raw_box_genz_malik};
use crate::cases::{case, problem, recipe_of, rule_rows, wants, Case};
use crate::materials::{BenchLambert, BenchMicrofacet, Dist};
use crate::panel::recipe;
use crate::report::{fmt_e, fmt_time, timed, try_run, Row};

/// Records, for every regular evaluation, the lobe coordinates (u, v) = (p_s + p_r, q_s + q_r) in units of
/// the lobe widths, recovered from the directions: for the source p = (ω·e∥)/(ω·s0), q = ω_y/(ω·s0).
#[derive(Debug)]
pub(crate) struct Recording {
    pub(crate) inner: Arc<dyn Brdf>,
    pub(crate) theta: f64,
    pub(crate) widths: [f64; 2],
    pub(crate) seen: std::sync::Mutex<Vec<f64>>,
}

impl Brdf for Recording {
    fn sampling(&self) -> &Sampling {
        self.inner.sampling()
    }
    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        let (s, c) = (self.theta.sin(), self.theta.cos());
        let (s0, es) = (Vec3::new(-s, 0.0, c), Vec3::new(c, 0.0, s));
        let (r0, er) = (Vec3::new(s, 0.0, c), Vec3::new(c, 0.0, -s));
        let (ps, qs) = (wi.dot(es) / wi.dot(s0), wi.y / wi.dot(s0));
        let (pr, qr) = (wo.dot(er) / wo.dot(r0), wo.y / wo.dot(r0));
        let x = ((ps + pr) / self.widths[0]).abs().max(((qs + qr) / self.widths[1]).abs());
        self.seen.lock().expect("lock").push(x);
        self.inner.eval(wi, wo, out)
    }
    /// The inner model's terms only (no kinks, not smooth: the defaults), as the recorded histogram was made.
    fn hints(&self) -> Hints {
        Hints::new(self.inner.hints().terms)
    }
    fn describe(&self) -> String {
        self.inner.describe()
    }
}

/// Histogram of the evaluation points of our rtol-1e-6 runs over max(|u|/w_u, |v|/w_v), for the lobed cases.
pub(crate) fn where_the_evaluations_go(md: &mut String, cases: &[Case]) {
    use glossmeter::instrument::aperture::lobe_widths_uv;
    let _ = writeln!(md, "\n## Where our evaluations go (rtol 1e-6)\n");
    let _ = writeln!(
        md,
        "Evaluation points binned by x = max(|u|/w_u, |v|/w_v), (u, v) the lobe variables and (w_u, w_v) the lobe widths the engine uses for its splits (it splits at 0, ±1, ±3, ±10 w for Gaussian-tailed lobes such as Beckmann, at ±30, ±100, … w out to the end of the range for heavy tails such as GGX, and at the kinks of the overlap). For Beckmann the lobe is ≈ exp(−x²) there: beyond x = 10 it is below e⁻¹⁰⁰ of its peak.\n"
    );
    let _ = writeln!(md, "| case | w_u | w_v | evaluations | x < 1 | 1–3 | 3–10 | 10–30 | 30–100 | ≥ 100 |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    for c in cases.iter().filter(|c| c.id != "B1") {
        let lobe = c.brdf.lobes()[0].clone();
        let widths = lobe_widths_uv(&lobe, c.theta);
        let rec = Arc::new(Recording { inner: c.brdf.clone(), theta: c.theta, widths, seen: Default::default() });
        let rc = Case { brdf: rec.clone(), geometry: c.geometry.clone(), title: c.title.clone(), ..*c };
        let f = problem(&rc, 1e-6).solve();
        let xs = rec.seen.lock().expect("lock");
        let edges = [0.0, 1.0, 3.0, 10.0, 30.0, 100.0, f64::INFINITY];
        let mut counts = [0usize; 6];
        for &x in xs.iter() {
            let k = (0..6).find(|&k| x >= edges[k] && x < edges[k + 1]).unwrap_or(5);
            counts[k] += 1;
        }
        let n = xs.len().max(1) as f64;
        let cells: Vec<String> = counts.iter().map(|&k| format!("{k} ({:.0} %)", 100.0 * k as f64 / n)).collect();
        let _ = writeln!(
            md,
            "| {} | {:.2e} | {:.2e} | {} | {} |",
            c.id,
            widths[0],
            widths[1],
            f.evaluations,
            cells.join(" | ")
        );
    }
}

/// The cases B1–B4 (those `BENCH_CASES` names), each read by the engine at three tolerances beside the baselines
/// against its reference; then the summary against the targets. Returns the cases run.
pub(crate) fn cases(md: &mut String, quick: bool) -> Vec<Case> {
    let cases = vec![
        case(
            "B1",
            "Lambert ρ = 0.5, astm-d523-60",
            Arc::new(BenchLambert { albedo: 0.5, s: Sampling::grey() }),
            "astm-d523-60",
        ),
        case(
            "B2",
            "Beckmann m = 0.1, n = 1.5, astm-d523-20",
            Arc::new(BenchMicrofacet::new(Dist::Beckmann, 0.1, 1.5)),
            "astm-d523-20",
        ),
        case(
            "B3",
            "Beckmann m = 1e-4, n = 1.5, astm-d523-20",
            Arc::new(BenchMicrofacet::new(Dist::Beckmann, 1e-4, 1.5)),
            "astm-d523-20",
        ),
        case(
            "B4",
            "GGX α = 0.3, n = 1.5, astm-d523-85",
            Arc::new(BenchMicrofacet::new(Dist::Ggx, 0.3, 1.5)),
            "astm-d523-85",
        ),
    ];
    // BENCH_CASES=B1,B2 runs only those cases (for side-by-side runs of two commits on a busy machine).
    // BENCH_CASES=B5,BATCH,NARROW likewise names the other sections.
    let cases: Vec<_> = cases.into_iter().filter(|c| wants(c.id)).collect();
    let mc_sizes: Vec<usize> =
        if quick { vec![1_000, 10_000, 100_000] } else { vec![1_000, 10_000, 100_000, 1_000_000, 10_000_000] };
    let grid_sizes: Vec<usize> = if quick { vec![4, 8, 16] } else { vec![4, 8, 16, 32, 48] };

    let mut all_rows: Vec<Row> = Vec::new();
    let mut refs = Vec::new();
    let _ = writeln!(md, "## B1–B4: specimen flux through the gloss receptor\n");
    let _ = writeln!(
        md,
        "Value = Φ (sr², luminous). rel. err = |value − reference|/reference. claimed = our error estimate (relative), or the Monte Carlo 1-σ standard error (relative). Time = median per run over ≥ 100 ms of repeats (runs = repeats).\n"
    );
    let _ = writeln!(md, "| case | method | value | claimed | rel. err | evaluations | time | runs | note |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|");
    for c in &cases {
        eprintln!("[bench] {} {}", c.id, c.title);
        // Reference.
        let t = Instant::now();
        let fine = problem(c, 1e-12).solve();
        let fine_s = t.elapsed().as_secs_f64();
        let (reference, ref_note) = if c.id == "B1" {
            let exact = lambert_exact(c, 0.5);
            (
                exact,
                format!(
                    "closed form (Lambert's polygon formula); our rtol-1e-12 run differs by {:.1e}",
                    (fine.value[0] - exact).abs() / exact
                ),
            )
        } else {
            (
                fine.value[0],
                format!(
                    "our engine at rtol 1e-12: {} evaluations, {}, est. rel. err {:.1e}, converged {}",
                    fine.evaluations,
                    fmt_time(fine_s),
                    fine.error[0] / fine.value[0],
                    fine.converged
                ),
            )
        };
        refs.push((c.id, c.title.clone(), reference, ref_note));
        let mut rows = Vec::new();
        for rtol in [1e-3, 1e-6, 1e-9] {
            let p = problem(c, rtol);
            let (f, secs, runs): (Flux, f64, usize) = timed(|| p.solve());
            rows.push(Row::of_flux(
                c.id,
                format!("ours, rtol {rtol:.0e}"),
                &f,
                reference,
                secs,
                runs,
                format!("{} regions{}", f.regions, if f.converged { "" } else { ", NOT converged" }),
            ));
        }
        // The two rules forced on the same integral at rtol 1e-6: the tensor rule (in (p_s, p_r, v,
        // t_q), whatever the planner chooses) and the Genz–Malik 7/5 engine on the planner's lobe-variable
        // partition (the fallback; hcubature's algorithm with our variables and splits).
        rows.extend(rule_rows(
            c,
            1e-6,
            &[
                (
                    "ours, tensor Gauss–Legendre forced (p_s, p_r, v, t_q)",
                    Some(Rule::TensorGauss { chart: Chart::PlainPLobeQ, levels: [1; 4], path: Default::default() }),
                ),
                ("ours, Genz–Malik 7/5 forced (planner's partition)", Some(Rule::GenzMalik75)),
            ],
            reference,
        ));
        // The same case with the material from its recipe (the engine's own model): checks that the bench
        // BRDF and the crate's model agree, and what the recipe model costs.
        if let Some(file) = recipe_of(c.id) {
            if let Some(brdf) = recipe(file) {
                let rc = Case { brdf, geometry: c.geometry.clone(), title: c.title.clone(), ..*c };
                let p = problem(&rc, 1e-6);
                if let Some((f, secs, runs)) = try_run(file, || timed(|| p.solve())) {
                    rows.push(Row::of_flux(
                        c.id,
                        "ours, recipe BRDF, rtol 1e-6".into(),
                        &f,
                        reference,
                        secs,
                        runs,
                        format!("fixtures/recipes/{file}"),
                    ));
                }
            }
        }
        // Our gloss reading through the plan (standard + specimen + ratio), for the record.
        {
            let plan = Plan::compile(
                c.brdf.clone(),
                vec![c.geometry.clone()],
                PlanOptions { rtol: 1e-6, ..Default::default() },
            )
            .expect("plan");
            let (r, secs, runs): (Vec<Reading>, f64, usize) = timed(|| plan.execute());
            let g = r.iter().find(|x| x.quantity == "gloss").expect("gloss reading");
            rows.push(Row {
                case: c.id,
                method: "ours, Plan gloss reading, rtol 1e-6".into(),
                value: g.value.unwrap_or(f64::NAN),
                claimed: g.error_estimate / g.value.unwrap_or(f64::NAN).abs(),
                rel_err: f64::NAN,
                evals: g.evaluations,
                seconds: secs,
                runs,
                note: "value in GU (standard + specimen flux and ratio)".into(),
            });
        }
        for (i, &n) in mc_sizes.iter().enumerate() {
            let ((v, se), secs, runs) = timed(|| monte_carlo(c, n, 0x5EED_0000 + i as u64));
            let silent = if se == 0.0 && v == 0.0 {
                "sees nothing: 0 ± 0"
            } else if (v - reference).abs() > 5.0 * se {
                "error > 5σ: claim wrong"
            } else {
                ""
            };
            rows.push(Row {
                case: c.id,
                method: format!("Monte Carlo N = {n:.0e}"),
                value: v,
                claimed: se / v.abs(),
                rel_err: (v - reference).abs() / reference,
                evals: n,
                seconds: secs,
                runs,
                note: silent.into(),
            });
        }
        for rtol in [1e-3, 1e-6, 1e-9] {
            let cap = if quick { 2_000_000 } else { 20_000_000 };
            let (e, secs, runs) = timed(|| raw_box_genz_malik(c, rtol, cap));
            let v = e.value[0];
            rows.push(Row {
                case: c.id,
                method: format!("raw-box Genz–Malik, rtol {rtol:.0e}"),
                value: v,
                claimed: e.error[0] / v.abs(),
                rel_err: (v - reference).abs() / reference,
                evals: e.evaluations,
                seconds: secs,
                runs,
                note: if !e.converged {
                    format!("NOT converged (cap {cap:.0e} evaluations)")
                } else if (v - reference).abs() > 10.0 * e.error[0] {
                    "claims convergence, actual error ≫ estimate: silently wrong".into()
                } else {
                    String::new()
                },
            });
        }
        for &n in &grid_sizes {
            let (v, secs, runs) = timed(|| midpoint_grid(c, n));
            rows.push(Row {
                case: c.id,
                method: format!("midpoint grid {n}⁴"),
                value: v,
                claimed: f64::NAN,
                rel_err: (v - reference).abs() / reference,
                evals: n.pow(4),
                seconds: secs,
                runs,
                note: String::new(),
            });
        }
        for r in &rows {
            let _ = writeln!(
                md,
                "| {} | {} | {:.10e} | {} | {} | {} | {} | {} | {} |",
                r.case,
                r.method,
                r.value,
                fmt_e(r.claimed),
                fmt_e(r.rel_err),
                r.evals,
                fmt_time(r.seconds),
                r.runs,
                r.note
            );
        }
        all_rows.extend(rows);
    }
    let _ = writeln!(md, "\nReferences:\n");
    for (id, title, v, note) in &refs {
        let _ = writeln!(md, "* {id} ({title}): Φ = {v:.15e}; {note}");
    }

    // Summary against the targets.
    let _ = writeln!(md, "\n## Targets (B1–B4)\n");
    let _ = writeln!(md, "| case | ours rtol 1e-6: time | actual err | cheapest baseline with err ≤ ours | its time | speed-up | ours rtol 1e-3 vs cheapest baseline with err ≤ 1e-3 |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|");
    for c in &cases {
        let rows: Vec<&Row> = all_rows.iter().filter(|r| r.case == c.id).collect();
        let ours = rows.iter().find(|r| r.method == "ours, rtol 1e-6").expect("row");
        let ours3 = rows.iter().find(|r| r.method == "ours, rtol 1e-3").expect("row");
        let baseline = |err: f64| -> Option<&&Row> {
            rows.iter()
                .filter(|r| !r.method.starts_with("ours") && r.rel_err <= err)
                .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
        };
        let (bname, btime, speed) = match baseline(ours.rel_err.max(1e-16)) {
            Some(b) => (b.method.clone(), fmt_time(b.seconds), format!("{:.1}×", b.seconds / ours.seconds)),
            None => ("none of the baselines".into(), "–".into(), "∞ (no baseline reaches it)".into()),
        };
        let at3 = match baseline(1e-3) {
            Some(b) => format!(
                "{} in {} vs ours {} (ratio {:.2})",
                b.method,
                fmt_time(b.seconds),
                fmt_time(ours3.seconds),
                b.seconds / ours3.seconds
            ),
            None => format!("no baseline reaches 1e-3; ours {} in {}", fmt_e(ours3.rel_err), fmt_time(ours3.seconds)),
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} |",
            c.id,
            fmt_time(ours.seconds),
            fmt_e(ours.rel_err),
            bname,
            btime,
            speed,
            at3
        );
    }
    let t2 = all_rows.iter().find(|r| r.case == "B2" && r.method == "ours, rtol 1e-6").map(|r| (r.seconds, r.evals));
    let t3 = all_rows.iter().find(|r| r.case == "B3" && r.method == "ours, rtol 1e-6").map(|r| (r.seconds, r.evals));
    if let (Some(a), Some(b)) = (t2, t3) {
        let _ = writeln!(
            md,
            "\nB3/B2 cost at rtol 1e-6: time ratio {:.2}, evaluation ratio {:.2} (target ≤ 2).",
            b.0 / a.0,
            b.1 as f64 / a.1 as f64
        );
    }

    cases
}
