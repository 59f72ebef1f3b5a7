//! Benchmarks of the aperture integrator against the baselines a grid- or sampling-based tool would use
//! (`docs/performance.md`). Plain `main` (harness = false), `std::time::Instant`, every measurement repeated until it
//! has taken ≥ 100 ms in total and reported as the median time per run.
//!
//! Run: `cargo bench --bench integrators` (release). `BENCH_QUICK=1` shrinks the baselines for a smoke
//! test. `BENCH_CASES=B1,B3,NARROW,B5,BATCH,WIDE` runs only the sections named (the cases B1–B4, the narrow-GGX
//! rows, the B5 panel with its side-by-side rule table, the batch throughput, the lobes as wide as the stops); unset, all of them. The Markdown tables go to stdout and to `bench/results/latest.md`; see `bench/README.md` and
//! `docs/performance.md`. `BENCH_JSON=FILE` also writes the specimen integrals of the WIDE section to FILE as JSON
//! (read by `bench/side_by_side.py`).
//!
//! Cases (the specimen flux Φ = ∫_source ∫_receptor f cos θi cos θo dωi dωo through the gloss receptor):
//! * B1 Lambert, albedo 0.5, astm-d523-60: reference = Lambert's closed form (projected solid angles).
//! * B2 Beckmann m = 0.1, n = 1.5, astm-d523-20.
//! * B3 Beckmann m = 1e-4, n = 1.5, astm-d523-20 (a lobe 1e-4 wide inside apertures 1e-2 wide).
//! * B4 GGX α = 0.3, n = 1.5, astm-d523-85.
//!
//!   For B2–B4 the reference is our engine at rtol 1e-12, cross-checked by the baselines where they
//!   converge. The baselines integrate the *same* BRDF object over the plain variables (p_s, q_s, p_r, q_r)
//!   of the stops, with the same cosines and solid-angle densities.
//! * B5 the Cerulean Blue paints (fixtures/recipes/cerulean-blue-{a,b,c}.json) over the default panel, via
//!   the measurement plan, with the plan's ablations; the narrow-flake `-literal` panel with the planner's
//!   methods beside Genz–Malik and the tensor rule forced on every specimen integral (whole panel and per
//!   integral, with where Genz–Malik's refinement goes); and batch throughput over rayon pools of 1 and 2.
//!
//! Every "forced rule" row of every section goes through one helper (`rule_rows`), and says what actually
//! ran (`rule_label`: the final rule and chart of the frozen method, so a fallback shows).
use std::fmt::Write as _;
use std::panic::AssertUnwindSafe;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use glossmeter::brdf::{Brdf, Hints, Lobe, Tail, Term, TermKind};
use glossmeter::instrument::geometry::{solid_angle_density, Axes, Stop};
use glossmeter::instrument::method::{Chart, Flux, Method, Rule, Target};
use glossmeter::instrument::plan::{Engine, Plan, PlanOptions, Reading};
use glossmeter::instrument::standards::{self, StandardGeometry};
use glossmeter::optics::fresnel::fr_dielectric;
use glossmeter::spectrum::Sampling;
use glossmeter::Vec3;

/// The default measurement panel of `measure`.
const PANEL: &[&str] = glossmeter::DEFAULT_PANEL;

// ---------------------------------------------------------------------------------------------------------
// Timing and random numbers.

/// Run `f` until ≥ 100 ms have been spent (at least once); return the last result, the median seconds per
/// run and the number of runs.
fn timed<T>(mut f: impl FnMut() -> T) -> (T, f64, usize) {
    let mut times = Vec::new();
    let mut total = 0.0;
    let mut out;
    loop {
        let t = Instant::now();
        out = f();
        let dt = t.elapsed().as_secs_f64();
        times.push(dt);
        total += dt;
        if total >= 0.1 {
            break;
        }
    }
    times.sort_by(f64::total_cmp);
    let n = times.len();
    let median = if n % 2 == 1 { times[n / 2] } else { 0.5 * (times[n / 2 - 1] + times[n / 2]) };
    (out, median, n)
}

/// SplitMix64 (Steele, Lea & Flood 2014; the reference constants of Vigna's `splitmix64.c`).
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1) with 53 random bits.
    fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

// ---------------------------------------------------------------------------------------------------------
// Bench materials, written out here (independently of src/optics/microfacet.rs) so the baselines and our
// engine evaluate exactly the same object, and so the Python baselines can re-implement the same formulas.

#[derive(Debug)]
struct BenchLambert {
    albedo: f64,
    s: Sampling,
}

impl Brdf for BenchLambert {
    fn sampling(&self) -> &Sampling {
        &self.s
    }
    fn eval(&self, _: Vec3, _: Vec3, out: &mut [f64]) {
        out[0] = self.albedo / std::f64::consts::PI;
    }
    fn hints(&self) -> Hints {
        Hints::new(vec![Term { label: "lambert".into(), kind: TermKind::Diffuse }])
    }
    fn describe(&self) -> String {
        format!("Lambert albedo {}", self.albedo)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Dist {
    Beckmann,
    Ggx,
}

/// F(ωi·h)·D(h)·G/(4 cos θi cos θo) on a dielectric of index n; Smith height-correlated G (Heitz 2014);
/// tan²θ from components (numerics notes §4.4), Beckmann Λ through erfc (§4.5), GGX Λ without cancellation.
#[derive(Debug)]
struct BenchMicrofacet {
    dist: Dist,
    alpha: f64,
    n: f64,
    s: Sampling,
}

impl BenchMicrofacet {
    fn new(dist: Dist, alpha: f64, n: f64) -> Self {
        BenchMicrofacet { dist, alpha, n, s: Sampling::grey() }
    }
    fn lambda(&self, w: Vec3) -> f64 {
        let t2 = (w.x * w.x + w.y * w.y) / (w.z * w.z);
        if t2 == 0.0 {
            return 0.0;
        }
        match self.dist {
            Dist::Beckmann => {
                let a = 1.0 / (self.alpha * t2.sqrt());
                0.5 * ((-a * a).exp() / (a * std::f64::consts::PI.sqrt()) - libm::erfc(a))
            }
            Dist::Ggx => {
                let x = self.alpha * self.alpha * t2;
                0.5 * x / ((1.0 + x).sqrt() + 1.0)
            }
        }
    }
}

impl Brdf for BenchMicrofacet {
    fn sampling(&self) -> &Sampling {
        &self.s
    }
    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            out[0] = 0.0;
            return;
        }
        let h = (wi + wo).normalize();
        let t2 = (h.x * h.x + h.y * h.y) / (h.z * h.z);
        let a2 = self.alpha * self.alpha;
        let c4 = h.z.powi(4);
        let d = match self.dist {
            Dist::Beckmann => (-t2 / a2).exp() / (std::f64::consts::PI * a2 * c4),
            Dist::Ggx => {
                let k = a2 + t2;
                a2 / (std::f64::consts::PI * c4 * k * k)
            }
        };
        let g = 1.0 / (1.0 + self.lambda(wi) + self.lambda(wo));
        out[0] = fr_dielectric(wi.dot(h).clamp(0.0, 1.0), self.n) * d * g / (4.0 * wi.z * wo.z);
    }
    fn hints(&self) -> Hints {
        let label = format!("{:?} {}", self.dist, self.alpha);
        Hints::new(vec![Term {
            label: label.clone(),
            kind: TermKind::Lobe(Lobe {
                slope_width: self.alpha,
                medium_eta: 1.0,
                label,
                tail: if self.dist == Dist::Ggx { Tail::InverseQuartic } else { Tail::Gaussian },
            }),
        }])
    }
    fn describe(&self) -> String {
        format!("{:?} α = {}, n = {}", self.dist, self.alpha, self.n)
    }
}

// ---------------------------------------------------------------------------------------------------------
// The cases.

struct Case {
    id: &'static str,
    title: String,
    brdf: Arc<dyn Brdf>,
    geometry: StandardGeometry,
    theta: f64,
    source: Stop,
    receptor: Stop,
}

/// The recipe of each case (written by the `convergence` work; the same B1–B4).
fn recipe_of(id: &str) -> Option<&'static str> {
    match id {
        "B1" => Some("bench-b1-lambert.json"),
        "B2" => Some("bench-b2-beckmann-0.1.json"),
        "B3" => Some("bench-b3-beckmann-1e-4.json"),
        "B4" => Some("bench-b4-ggx-0.3.json"),
        _ => None,
    }
}

fn case(id: &'static str, title: &str, brdf: Arc<dyn Brdf>, geometry: &str) -> Case {
    let g = standards::find(geometry).expect("builtin geometry");
    let (theta, source, receptor) =
        (g.geometry.theta, g.geometry.source, *g.geometry.receptor("gloss").expect("gloss receptor"));
    Case { id, title: title.into(), brdf, geometry: g, theta, source, receptor }
}

/// The specimen flux of a case, as a method designed for its BRDF (executed with `solve`).
struct Problem<'a> {
    brdf: &'a dyn Brdf,
    method: Method,
}

impl Problem<'_> {
    fn solve(&self) -> Flux {
        self.method.execute(self.brdf)
    }
}

fn problem(c: &Case, rtol: f64) -> Problem<'_> {
    let b: &dyn Brdf = c.brdf.as_ref();
    let method =
        Method::for_material(b, c.theta, c.source, c.receptor, (rtol, 0.0), 200_000_000).expect("luminous weighting");
    Problem { brdf: b, method }
}

/// The specimen flux of a case with the regular part's rule replaced by `rule` (None: the planner's own).
fn forced(c: &Case, rtol: f64, rule: Option<Rule>) -> Problem<'_> {
    let mut p = problem(c, rtol);
    if let (Some(part), Some(rule)) = (p.method.regular.as_mut(), rule) {
        part.rule = rule;
    }
    p
}

/// What a run of `m` actually integrated, from its frozen method (an untimed run): the final rule and its
/// variables, so a forced shaped rule that fell back says so, and the tensor rule's mixed chart is not called
/// the lobe chart.
fn rule_label(m: &Method, brdf: &dyn Brdf) -> String {
    let (_, frozen) = m.execute_and_freeze(brdf);
    let Some(part) = frozen.regular.as_ref() else { return "no regular part".into() };
    let chart = match part.chart {
        glossmeter::instrument::aperture::Chart::Plain => "plain (p_s, q_s, p_r, q_r)",
        glossmeter::instrument::aperture::Chart::Lobe => "lobe (u, t_p, v, t_q)",
        glossmeter::instrument::aperture::Chart::PlainPLobeQ => "mixed (p_s, p_r, v, t_q)",
    };
    match part.rule {
        Rule::GenzMalik75 => {
            // Where the refinement went: the bisections per axis, summed over the final regions (each
            // region's log₂ of its initial box's half-width over its own).
            let initial = &m.regular.as_ref().expect("the same parts").cells;
            let mut cuts = [0.0f64; 4];
            for c in &part.cells {
                let inside = |b: &&glossmeter::quadrature::Cell<4>| {
                    (0..4).all(|k| (c.center[k] - b.center[k]).abs() <= b.half[k] * (1.0 + 1e-12))
                };
                if let Some(b) = initial.iter().find(inside) {
                    for (k, cut) in cuts.iter_mut().enumerate() {
                        *cut += (b.half[k] / c.half[k]).log2().round();
                    }
                }
            }
            format!(
                "Genz–Malik 7/5, {chart} chart, {} initial → {} final regions, bisections per axis {:?}",
                initial.len(),
                part.cells.len(),
                cuts.map(|x| x as usize)
            )
        }
        Rule::LobeGaussHermite { .. } => "Gauss–Hermite × Gauss–Legendre, lobe chart".into(),
        Rule::LobeDelta { .. } => "delta limit of the lobe, lobe chart".into(),
        Rule::LobePolar { .. } => "polar + tail boxes, lobe chart".into(),
        Rule::TailBound => "the material's tail bound (no evaluation)".into(),
        Rule::TensorGauss { chart, .. } => format!(
            "tensor Gauss–Legendre, {} chart",
            match chart {
                Chart::Plain => "plain (p_s, q_s, p_r, q_r)",
                Chart::Lobe => "lobe (u, t_p, v, t_q) kink-partition",
                Chart::PlainPLobeQ => "mixed (p_s, p_r, v, t_q)",
            }
        ),
    }
}

/// The rows of one case with each rule of `rules` forced on its regular part (None: the planner's choice),
/// side by side in one run (review D2: one helper for every case and section).
fn rule_rows(c: &Case, rtol: f64, rules: &[(&str, Option<Rule>)], reference: f64) -> Vec<Row> {
    let mut rows = Vec::new();
    for (label, rule) in rules {
        let p = forced(c, rtol, *rule);
        if rule.is_some() && p.method.regular.is_none() {
            continue;
        }
        let (f, secs, runs): (Flux, f64, usize) = timed(|| p.solve());
        rows.push(Row::of_flux(
            c.id,
            format!("{label}, rtol {rtol:.0e}"),
            &f,
            reference,
            secs,
            runs,
            format!("{}{}", rule_label(&p.method, p.brdf), if f.converged { "" } else { ", NOT converged" }),
        ));
    }
    rows
}

/// Whether `BENCH_CASES` (a comma-separated list; unset: everything) asks for the section `id`.
fn wants(id: &str) -> bool {
    std::env::var("BENCH_CASES").map_or(true, |l| l.split(',').any(|x| x.trim() == id))
}

/// The plain 4-D integrand in (p_s, q_s, p_r, q_r): luminous f · cos θi cos θo · both solid-angle densities.
struct Plain<'a> {
    brdf: &'a dyn Brdf,
    axes: Axes,
    weights: Vec<f64>,
    scratch: Vec<f64>,
}

impl<'a> Plain<'a> {
    fn new(c: &'a Case) -> Self {
        let b: &dyn Brdf = c.brdf.as_ref();
        let weights =
            glossmeter::colorimetry::weighting::Weighting::luminous(b.sampling()).expect("luminous weighting").rows[0]
                .clone();
        Plain { brdf: b, axes: Axes::new(c.theta), scratch: vec![0.0; weights.len()], weights }
    }
    #[inline]
    fn f(&mut self, ps: f64, qs: f64, pr: f64, qr: f64) -> f64 {
        let wi = self.axes.source_dir(ps, qs);
        let wo = self.axes.receptor_dir(pr, qr);
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        self.brdf.eval(wi, wo, &mut self.scratch);
        let lum: f64 = self.weights.iter().zip(&self.scratch).map(|(w, v)| w * v).sum();
        lum * wi.z * wo.z * solid_angle_density(ps, qs) * solid_angle_density(pr, qr)
    }
}

/// Plain Monte Carlo over the product of the stops: (value, 1-σ standard error).
fn monte_carlo(c: &Case, n: usize, seed: u64) -> (f64, f64) {
    let mut p = Plain::new(c);
    let mut rng = SplitMix64(seed);
    let (s, r) = (c.source, c.receptor);
    let vol = (s.p[1] - s.p[0]) * (s.q[1] - s.q[0]) * (r.p[1] - r.p[0]) * (r.q[1] - r.q[0]);
    // Welford's running mean and variance.
    let (mut mean, mut m2) = (0.0f64, 0.0f64);
    for k in 0..n {
        let ps = s.p[0] + (s.p[1] - s.p[0]) * rng.next_f64();
        let qs = s.q[0] + (s.q[1] - s.q[0]) * rng.next_f64();
        let pr = r.p[0] + (r.p[1] - r.p[0]) * rng.next_f64();
        let qr = r.q[0] + (r.q[1] - r.q[0]) * rng.next_f64();
        let x = p.f(ps, qs, pr, qr);
        let d = x - mean;
        mean += d / (k + 1) as f64;
        m2 += d * (x - mean);
    }
    let var = if n > 1 { m2 / (n - 1) as f64 } else { 0.0 };
    (vol * mean, vol * (var / n as f64).sqrt())
}

/// Uniform midpoint product grid of N⁴ points over the stops.
fn midpoint_grid(c: &Case, n: usize) -> f64 {
    let mut p = Plain::new(c);
    let (s, r) = (c.source, c.receptor);
    let mid = |a: [f64; 2], n: usize| -> Vec<f64> {
        (0..n).map(|i| a[0] + (a[1] - a[0]) * (i as f64 + 0.5) / n as f64).collect()
    };
    let (ps, qs, pr, qr) = (mid(s.p, n), mid(s.q, n), mid(r.p, n), mid(r.q, n));
    let vol = (s.p[1] - s.p[0]) * (s.q[1] - s.q[0]) * (r.p[1] - r.p[0]) * (r.q[1] - r.q[0]);
    let mut total = 0.0;
    for &a in &ps {
        for &b in &qs {
            let mut inner = 0.0;
            for &cc in &pr {
                for &d in &qr {
                    inner += p.f(a, b, cc, d);
                }
            }
            total += inner;
        }
    }
    total * vol / (n as f64).powi(4)
}

/// The crate's own Genz–Malik driver on the raw 4-D box (p_s, q_s, p_r, q_r), one initial region: what
/// `hcubature` does when it is not told where the lobe is.
fn raw_box_genz_malik(c: &Case, rtol: f64, max_evals: usize) -> glossmeter::quadrature::Estimate {
    let mut p = Plain::new(c);
    let (s, r) = (c.source, c.receptor);
    glossmeter::quadrature::integrate::<4, _>(
        glossmeter::quadrature::pointwise(1, |x: &[f64; 4], out: &mut [f64]| out[0] = p.f(x[0], x[1], x[2], x[3])),
        1,
        &[([s.p[0], s.q[0], r.p[0], r.q[0]], [s.p[1], s.q[1], r.p[1], r.q[1]])],
        &glossmeter::quadrature::Options { rtol, atol: 0.0, max_evals, deadline: None, ..Default::default() },
    )
}

/// The closed-form Lambertian flux (Lambert's polygon formula for each stop), from the crate's independent
/// references (`instrument::reference`, which shares no code with the quadrature).
fn lambert_exact(c: &Case, albedo: f64) -> f64 {
    glossmeter::instrument::reference::lambertian_flux_reference(
        c.theta,
        c.source,
        c.receptor,
        albedo / std::f64::consts::PI,
    )
}

// ---------------------------------------------------------------------------------------------------------
// Result rows.

struct Row {
    case: &'static str,
    method: String,
    value: f64,
    /// The method's own error claim (our estimate; MC 1-σ standard error); NaN if none.
    claimed: f64,
    rel_err: f64,
    evals: usize,
    seconds: f64,
    runs: usize,
    note: String,
}

impl Row {
    /// A row of our engine: its flux on `case` against `reference`, timed `secs` over `runs` runs.
    fn of_flux(
        case: &'static str,
        method: String,
        f: &Flux,
        reference: f64,
        secs: f64,
        runs: usize,
        note: String,
    ) -> Row {
        Row {
            case,
            method,
            value: f.value[0],
            claimed: f.error[0] / f.value[0].abs(),
            rel_err: (f.value[0] - reference).abs() / reference,
            evals: f.evaluations,
            seconds: secs,
            runs,
            note,
        }
    }
}

fn fmt_time(s: f64) -> String {
    if s < 1e-3 {
        format!("{:.1} µs", s * 1e6)
    } else if s < 1.0 {
        format!("{:.2} ms", s * 1e3)
    } else {
        format!("{:.2} s", s)
    }
}

fn fmt_e(x: f64) -> String {
    if x.is_nan() {
        "–".into()
    } else {
        format!("{x:.1e}")
    }
}

/// Catch a panic (an engine part still marked `todo!()` by another engineer) and say what it was.
fn try_run<T>(what: &str, f: impl FnOnce() -> T) -> Option<T> {
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let r = std::panic::catch_unwind(AssertUnwindSafe(f));
    std::panic::set_hook(hook);
    match r {
        Ok(v) => Some(v),
        Err(e) => {
            let msg = e
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| e.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "panic".into());
            eprintln!("[bench] {what}: not available ({msg})");
            None
        }
    }
}

fn git_commit() -> String {
    std::process::Command::new("git")
        .args(["rev-parse", "--short", "HEAD"])
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|| "?".into())
}

/// Files under src/ that differ from HEAD (other engineers' work in progress is compiled into the bench).
fn dirty_src() -> String {
    std::process::Command::new("git")
        .args(["status", "--short", "--", "src"])
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| {
            let files: Vec<&str> = s.lines().map(|l| l[3..].trim()).collect();
            if files.is_empty() {
                "none".into()
            } else {
                files.join(", ")
            }
        })
        .unwrap_or_else(|| "?".into())
}

fn loadavg() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "?".into())
}

fn date() -> String {
    std::process::Command::new("date")
        .args(["-u", "+%Y-%m-%d %H:%M UTC"])
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|| "?".into())
}

// ---------------------------------------------------------------------------------------------------------

fn main() {
    let quick = std::env::var("BENCH_QUICK").is_ok();
    let mut md = String::new();
    let _ = writeln!(md, "# glossmeter integrator benchmarks\n");
    let _ = writeln!(
        md,
        "Commit {} (working tree), {}; load average at start {}; {} logical cores; release build.{}\n",
        git_commit(),
        date(),
        loadavg(),
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(0),
        if quick { " **QUICK mode (reduced baselines)**" } else { "" }
    );
    let _ = writeln!(md, "Uncommitted changes under src/ compiled into this run: {}.\n", dirty_src());

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

    where_the_evaluations_go(&mut md, &cases);
    if wants("NARROW") {
        narrow_ggx(&mut md);
    }
    if wants("B5") {
        b5(&mut md);
        b5_rules(&mut md);
    }
    if wants("BATCH") {
        batch(&mut md, quick);
    }
    if wants("WIDE") {
        wide_lobes(&mut md);
    }

    print!("{md}");
    let out = Path::new(env!("CARGO_MANIFEST_DIR")).join("bench/results/latest.md");
    if let Some(dir) = out.parent() {
        let _ = std::fs::create_dir_all(dir);
    }
    match std::fs::write(&out, &md) {
        Ok(()) => eprintln!("[bench] wrote {}", out.display()),
        Err(e) => eprintln!("[bench] could not write {}: {e}", out.display()),
    }
}

/// Narrow GGX (`docs/performance.md` §"Narrow GGX: the polar rule beside the forced partition"): the polar rule the
/// planner chooses (`Rule::LobePolar`) beside the Genz–Malik 7/5 partition forced on the same method (same lobe chart,
/// same initial boxes: the engine before the polar rule), in one run, at α = 1e-3, 1e-5, 1e-7 on astm-d523-20
/// (n = 1.5). Reference: the forced partition at rtol 1e-11, cross-checked against the polar rule at 1e-11.
fn narrow_ggx(md: &mut String) {
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

/// Records, for every regular evaluation, the lobe coordinates (u, v) = (p_s + p_r, q_s + q_r) in units of
/// the lobe widths, recovered from the directions: for the source p = (ω·e∥)/(ω·s0), q = ω_y/(ω·s0).
#[derive(Debug)]
struct Recording {
    inner: Arc<dyn Brdf>,
    theta: f64,
    widths: [f64; 2],
    seen: std::sync::Mutex<Vec<f64>>,
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
fn where_the_evaluations_go(md: &mut String, cases: &[Case]) {
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

// ---------------------------------------------------------------------------------------------------------
// B5: the panel, the plan ablations, batch throughput.

fn panel() -> Vec<StandardGeometry> {
    PANEL.iter().map(|id| standards::find(id).expect("builtin geometry")).collect()
}

fn recipe(name: &str) -> Option<Arc<dyn Brdf>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/recipes").join(name);
    match glossmeter::recipe::load_file(&path) {
        Ok(m) => Some(m.brdf),
        Err(e) => {
            eprintln!("[bench] {name}: {e}");
            None
        }
    }
}

/// Counts the specimen BRDF evaluations of a plan (regular and delta), i.e. the real work, whatever the
/// sharing of fluxes between readings. Used in a separate, untimed run.
#[derive(Debug)]
struct Counting {
    inner: Arc<dyn Brdf>,
    n: std::sync::atomic::AtomicUsize,
}

impl Brdf for Counting {
    fn sampling(&self) -> &Sampling {
        self.inner.sampling()
    }
    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        self.n.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        self.inner.eval(wi, wo, out)
    }
    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        self.n.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        self.inner.delta_reflectance(wi, out)
    }
    /// The inner model's terms and reciprocity only (no kinks, not smooth: the defaults), as the bench's
    /// recorded counts were made.
    fn hints(&self) -> Hints {
        let h = self.inner.hints();
        Hints::new(h.terms).with_reciprocal(h.reciprocal)
    }
    fn describe(&self) -> String {
        self.inner.describe()
    }
}

fn count_evaluations(brdf: Arc<dyn Brdf>, opts: PlanOptions, engine: Engine) -> usize {
    let c = Arc::new(Counting { inner: brdf, n: Default::default() });
    let plan = Plan::compile_with_engine(c.clone(), panel(), opts, engine).expect("plan compiles");
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    pool.install(|| plan.execute());
    c.n.load(std::sync::atomic::Ordering::Relaxed)
}

struct PanelRun {
    readings: Vec<Reading>,
    seconds: f64,
    runs: usize,
    jobs: usize,
}

fn run_panel(brdf: Arc<dyn Brdf>, opts: PlanOptions, engine: Engine, threads: usize) -> PanelRun {
    let plan = Plan::compile_with_engine(brdf, panel(), opts, engine).expect("plan compiles");
    let jobs = plan.jobs.len();
    // One thread by default: the time of the work itself, not of the parallel schedule.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    let (readings, seconds, runs) = pool.install(|| timed(|| plan.execute()));
    PanelRun { readings, seconds, runs, jobs }
}

fn b5(md: &mut String) {
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
fn force_plan_rule(plan: &mut Plan, rule: Option<Rule>) {
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
fn b5_rules(md: &mut String) {
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
fn tolerance_sweep(md: &mut String) {
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

fn total_evaluations(r: &[Reading]) -> usize {
    r.iter().map(|x| x.evaluations).sum()
}

/// 64 recipes of varying roughness (microfacet if the engine's microfacet model works, else Ward), each
/// parsed, planned and measured over the panel at rtol 1e-6; recipes per second in pools of 1 and 2.
fn batch(md: &mut String, quick: bool) {
    use rayon::prelude::*;
    let n = if quick { 16 } else { 64 };
    let microfacet = |i: usize| -> String {
        let dist = if i.is_multiple_of(2) { "beckmann" } else { "ggx" };
        let r = 0.02 + 0.48 * i as f64 / (n - 1) as f64;
        format!(r#"{{"model": "microfacet", "distribution": "{dist}", "roughness": {r}, "ior": 1.5}}"#)
    };
    let ward = |i: usize| -> String {
        let a = 0.02 + 0.48 * i as f64 / (n - 1) as f64;
        format!(r#"{{"model": "ward", "alpha": {a}, "rho_s": 0.05, "rho_d": 0.3}}"#)
    };
    let probe = glossmeter::recipe::parse_str(&microfacet(0), "probe.json").ok();
    let works = probe
        .and_then(|m| {
            try_run("microfacet recipe", || {
                m.brdf.eval(Vec3::new(-0.3, 0.0, 0.95).normalize(), Vec3::new(0.3, 0.0, 0.95).normalize(), &mut [0.0])
            })
        })
        .is_some();
    let (kind, texts): (&str, Vec<String>) = if works {
        ("microfacet (Beckmann/GGX, roughness 0.02–0.5, n = 1.5)", (0..n).map(microfacet).collect())
    } else {
        ("ward (α 0.02–0.5; the microfacet model was not implemented yet)", (0..n).map(ward).collect())
    };
    let one = |text: &String| -> usize {
        let m = glossmeter::recipe::parse_str(text, "batch.json").expect("batch recipe");
        let plan = Plan::compile(m.brdf, panel(), PlanOptions { rtol: 1e-6, ..Default::default() }).expect("plan");
        total_evaluations(&plan.execute())
    };
    let _ = writeln!(md, "### Batch throughput: {n} {kind} recipes, default panel, rtol 1e-6\n");
    let _ = writeln!(md, "| threads | time | recipes / s | speed-up | runs |");
    let _ = writeln!(md, "|---|---|---|---|---|");
    let mut base = 0.0;
    for k in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(k).build().expect("pool");
        let (_, secs, runs) = timed(|| pool.install(|| texts.par_iter().map(one).sum::<usize>()));
        if k == 1 {
            base = secs;
        }
        let _ = writeln!(md, "| {k} | {} | {:.0} | {:.2}× | {runs} |", fmt_time(secs), n as f64 / secs, base / secs);
    }
}

/// Lobes about as wide as the stops (`docs/performance.md` §"Lobes as wide as the stops"): Beckmann and GGX m = 0.003,
/// 0.01, 0.03 (n = 1.5) at D523 20°/60°/85° and E430 30°, the Günther presets
/// (fixtures/materials/guenther-2005) and `cook-torrance-lobes` over the default panel, rtol 1e-6. Per recipe, the
/// specimen integrals' exact evaluation counts with the planner's methods (today: the Genz–Malik partition for all of
/// them), beside two alternatives forced on the same methods in the same run: Genz–Malik on the overlap-kink partition
/// alone (no lobe splits) and the tensor Gauss–Legendre rule with orders shared by the kink partition's boxes
/// (`Chart::Lobe`, falling back to the Genz–Malik partition). For each, the largest actual / estimate over the
/// recipe's integrals against a Genz–Malik run at 10⁻³ of the integral's tolerances (skipping integrals whose flux is
/// below the absolute floor). The limit a rule can reach is measured by independent code (`tools/limit_wide_lobes.py`).
///
/// With `BENCH_JSON=FILE` set, also writes every specimen integral of this section to FILE as JSON (recipe, the
/// readings that use it, the planner's rule, evaluations, value, error estimate, the Genz–Malik run at 10⁻³ of its
/// tolerances, and the two alternatives' evaluations): what `bench/side_by_side.py` reads (`bench/README.md`).
fn wide_lobes(md: &mut String) {
    use glossmeter::instrument::aperture::{lobe_boxes, AxisMap};
    use glossmeter::quadrature::Cell;
    let _ = writeln!(md, "\n## Lobes as wide as the stops (one run; load average at the start {})\n", loadavg());
    let _ = writeln!(md, "| recipe | geometries | specimen integrals | planner: evaluations | time (1 thread) | worst actual/est. | Genz–Malik, kink partition: evaluations | worst actual/est. | tensor GL shared orders, kink partition: evaluations | worst actual/est. |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    let set = ["astm-d523-20", "astm-d523-60", "astm-d523-85", "astm-e430-30"];
    let mut cases: Vec<(String, Arc<dyn Brdf>, Vec<&str>)> = vec![];
    // The microfacet lobes' (distribution, roughness), by recipe name, for the JSON records.
    let mut lobes: std::collections::HashMap<String, (&str, f64)> = Default::default();
    for d in ["beckmann", "ggx"] {
        for m in [0.003, 0.01, 0.03] {
            let text = format!(r#"{{"model":"microfacet","distribution":"{d}","roughness":{m},"ior":1.5}}"#);
            lobes.insert(format!("{d} m = {m}"), (d, m));
            match glossmeter::recipe::parse_str(&text, "wide.json") {
                Ok(r) => cases.push((format!("{d} m = {m}"), r.brdf, set.to_vec())),
                Err(e) => eprintln!("[bench] {d} {m}: {e}"),
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut presets: Vec<_> = std::fs::read_dir(root.join("fixtures/materials/guenther-2005"))
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    presets.sort();
    presets.push(root.join("fixtures/recipes/cook-torrance-lobes.json"));
    for p in presets {
        match glossmeter::recipe::load_file(&p) {
            Ok(r) => cases.push((
                p.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned()),
                r.brdf,
                PANEL.to_vec(),
            )),
            Err(e) => eprintln!("[bench] {}: {e}", p.display()),
        }
    }
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    let opts = PlanOptions { rtol: 1e-6, ..Default::default() };
    let mut totals = [0usize; 3];
    let mut records: Vec<serde_json::Value> = vec![];
    for (name, brdf, geoms) in cases {
        let geo: Vec<StandardGeometry> = geoms.iter().filter_map(|g| standards::find(g).ok()).collect();
        let Ok(plan) = Plan::compile(brdf.clone(), geo, opts.clone()) else { continue };
        let (_, secs, _) = pool.install(|| timed(|| plan.execute()));
        let mut evals = [0usize; 3];
        let mut worst = [0.0f64; 3];
        let mut n = 0;
        for job in plan.jobs.iter().filter(|j| j.method.aperture.target == Target::Specimen) {
            n += 1;
            let mut tight = job.method.clone();
            if let Some(p) = tight.regular.as_mut() {
                (p.rule, p.rtol, p.atol) = (Rule::GenzMalik75, 1e-3 * p.rtol, 1e-3 * p.atol);
            }
            if let Some(p) = tight.delta.as_mut() {
                (p.rtol, p.atol) = (1e-3 * p.rtol, 1e-3 * p.atol);
            }
            let r = tight.execute(brdf.as_ref()).value[0];
            let floor = job.method.regular.as_ref().map_or(0.0, |p| p.atol);
            let mut record = serde_json::json!({
                "recipe": name,
                "distribution": lobes.get(&name).map(|l| l.0),
                "roughness": lobes.get(&name).map(|l| l.1),
                "used_by": job.used_by,
                "rule": rule_label(&job.method, brdf.as_ref()),
                "boxes": job.method.regular.as_ref().map_or(0, |p| p.cells.len()),
                "atol": floor,
                "reference_gm_1e-3": r,
            });
            for (v, slot) in [0usize, 1, 2].into_iter().zip(evals.iter_mut()) {
                let mut m = job.method.clone();
                let clipped = m.clipped;
                if let (Some(p), Some((src, rec))) = (m.regular.as_mut(), clipped) {
                    let eligible = p.chart == Chart::Lobe && p.kinks.is_empty() && p.rule == Rule::GenzMalik75;
                    if eligible && v == 1 {
                        // The range ends and the overlap kinks (as `tensor_boxes` splits the lobe chart).
                        let kinks = |a: AxisMap| a.splits(&[]);
                        let sp = [kinks(AxisMap { s: src.p, r: rec.p }), kinks(AxisMap { s: src.q, r: rec.q })];
                        p.cells = Cell::from_boxes(&lobe_boxes(&sp));
                    }
                    if eligible && v == 2 {
                        p.rule = Rule::TensorGauss { chart: Chart::Lobe, levels: [1; 4], path: Default::default() };
                    }
                }
                let f = m.execute(brdf.as_ref());
                *slot += f.evaluations;
                let actual = (f.value[0] - r).abs();
                if r.abs() > floor && f.error[0] > 0.0 {
                    worst[v] = worst[v].max(actual / f.error[0]);
                }
                let key = ["planner", "gm_kink_partition", "tensor_kink_partition"][v];
                record[key] = serde_json::json!({
                    "evaluations": f.evaluations,
                    "value": f.value[0],
                    "error": f.error[0],
                    "converged": f.converged,
                });
            }
            records.push(record);
        }
        for k in 0..3 {
            totals[k] += evals[k];
        }
        let _ = writeln!(
            md,
            "| {name} | {} | {n} | {} | {} | {:.3} | {} | {:.3} | {} | {:.3} |",
            geoms.len(),
            evals[0],
            fmt_time(secs),
            worst[0],
            evals[1],
            worst[1],
            evals[2],
            worst[2]
        );
    }
    let _ = writeln!(md, "| **total** | | | {} | | | {} | | {} | |", totals[0], totals[1], totals[2]);
    let _ = writeln!(md, "\nLoad average at the end of this section {}.", loadavg());
    if let Some(path) = std::env::var_os("BENCH_JSON") {
        let doc = serde_json::json!({
            "commit": git_commit(),
            "date": date(),
            "uncommitted_src": dirty_src(),
            "rtol": opts.rtol,
            "integrals": records,
        });
        match std::fs::write(&path, serde_json::to_string_pretty(&doc).expect("json")) {
            Ok(()) => eprintln!("[bench] wrote {}", Path::new(&path).display()),
            Err(e) => eprintln!("[bench] could not write {}: {e}", Path::new(&path).display()),
        }
    }
}
