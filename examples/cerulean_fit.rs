//! The worked example of `docs/inverse.md` (§Worked example): the paper's metallic paint fitted back from
//! its readings. Run by hand:
//!
//! ```text
//! nice cargo run --release --example cerulean_fit
//! ```
//!
//! The truth is `fixtures/recipes/cerulean-blue-b.json` (Ďurikovič & Ágošton 2007's Cerulean Blue with
//! metallic flakes) with a slightly rough clear coat (`/clear_coat/roughness` = 0.01, Beckmann). Its readings
//! on ASTM D523 20°/60°/85° and ASTM E430 30° (gloss, narrow- and wide-angle haze, DOI) are computed at
//! rtol 1e-9, and noise of 0.2 in each reading's unit (a glossmeter's repeatability) is added from a fixed
//! seed. The coat roughness, the flake spread and the flake area ratio are then fitted back from a perturbed
//! start, first from every reading, then from subsets, to show which readings make which parameter
//! identifiable. It prints Markdown for `docs/inverse.md`; no timing enters the output, so a rerun prints the
//! same text.
use std::path::PathBuf;

use glossmeter::fit::{fit, FitOptions, FitReport, FreeParameter, TargetReading};
use glossmeter::{measure, recipe, resolve_geometries, PlanOptions};
use serde_json::{json, Value};

const ALL: &[(&str, &str)] = &[
    ("astm-d523-20", "gloss"),
    ("astm-d523-60", "gloss"),
    ("astm-d523-85", "gloss"),
    ("astm-e430-30", "gloss"),
    ("astm-e430-30", "haze-narrow"),
    ("astm-e430-30", "haze-wide"),
    ("astm-e430-30", "doi"),
];
const NOISE: f64 = 0.2;
const FREE: &[&str] = &[
    "/clear_coat/roughness=log:1e-3..0.3",
    "/metallic_flakes/spread_slope=log:0.01..1",
    "/metallic_flakes/area_ratio=0.01..0.99",
];
const TRUTH: &[f64] = &[0.01, 0.25, 0.4];
const START: &[f64] = &[0.02, 0.15, 0.55];

/// xorshift64* and Box–Muller: a fixed, dependency-free normal generator.
struct Normal(u64);
impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545F4914F6CDD1D) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn sample(&mut self) -> f64 {
        let (a, b) = (self.uniform(), self.uniform());
        (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
    }
}

fn with(base: &Value, values: &[f64]) -> Value {
    let mut v = base.clone();
    v["clear_coat"]["roughness"] = json!(values[0]);
    v["clear_coat"]["distribution"] = json!("beckmann");
    v["metallic_flakes"]["spread_slope"] = json!(values[1]);
    v["metallic_flakes"]["area_ratio"] = json!(values[2]);
    v
}

fn report(title: &str, r: &FitReport, truth: &[f64]) {
    let at_bound: Vec<&str> = r.parameters.iter().filter(|p| p.at_bound).map(|p| p.pointer.as_str()).collect();
    println!(
        "**{title}** ({} forward runs; converged: {}; identifiable: {}; at a bound: {}; `glossmeter fit` would \
         exit {})\n",
        r.evaluations,
        r.converged,
        r.identifiable,
        if at_bound.is_empty() { "none".to_string() } else { at_bound.join(", ") },
        if r.ok() { 0 } else { 1 }
    );
    println!("| parameter | true | fitted | standard error | (fitted − true) / error |\n|---|---:|---:|---:|---:|");
    for (p, t) in r.parameters.iter().zip(truth) {
        let (se, z) = match p.std_error {
            Some(s) => (format!("{s:.2e}"), format!("{:+.2}", (p.value - t) / s)),
            None => ("undetermined".into(), "—".into()),
        };
        println!("| `{}` | {t} | {:.5} | {se} | {z} |", p.pointer, p.value);
    }
    println!("\n| target | measured | predicted | residual |\n|---|---:|---:|---:|");
    for t in &r.targets {
        println!(
            "| {}/{} | {:.3} | {:.3} | {:+.3} |",
            t.target.geometry, t.target.name, t.target.value, t.predicted, t.residual
        );
    }
    let sv: Vec<String> = r.singular_values.iter().map(|s| format!("{s:.3}")).collect();
    println!("\nSingular values of the weighted Jacobian (columns × bound width): {}.", sv.join(", "));
    if r.parameters.len() > 1 {
        println!("\nCorrelation:\n");
        println!("| | {} |", r.parameters.iter().map(|p| format!("`{}`", p.pointer)).collect::<Vec<_>>().join(" | "));
        println!("|---|{}", "---:|".repeat(r.parameters.len()));
        for (p, row) in r.parameters.iter().zip(&r.correlation) {
            let cells: Vec<String> = row.iter().map(|c| c.map(|c| format!("{c:+.3}")).unwrap_or("—".into())).collect();
            println!("| `{}` | {} |", p.pointer, cells.join(" | "));
        }
    }
    if r.verdict.is_empty() {
        println!("\nVerdict: the targets determine every parameter.\n");
    } else {
        println!("\nVerdict:\n");
        for v in &r.verdict {
            println!("* {v}");
        }
        println!();
    }
}

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let base: Value =
        serde_json::from_str(&std::fs::read_to_string(root.join("fixtures/recipes/cerulean-blue-b.json")).unwrap())
            .unwrap();
    let truth = with(&base, TRUTH);
    let material = recipe::parse_str(&truth.to_string(), "truth.json").unwrap();
    let geometries =
        resolve_geometries(&["astm-d523-20", "astm-d523-60", "astm-d523-85", "astm-e430-30"], &[] as &[&str]).unwrap();
    let readings = measure(&material, &geometries, &PlanOptions { rtol: 1e-9, ..PlanOptions::default() }).unwrap();
    let mut rng = Normal(0x05EE_DCE2_u64 ^ 0x9E37_79B9_7F4A_7C15);
    let measured: Vec<(f64, f64)> = ALL
        .iter()
        .map(|(g, n)| {
            let exact = readings.iter().find(|r| r.geometry == *g && r.name == *n).unwrap().value.unwrap();
            (exact, exact + NOISE * rng.sample())
        })
        .collect();
    println!(
        "<!-- generated by `cargo run --release --example cerulean_fit`: truth cerulean-blue-b with \
         /clear_coat/roughness = {}, /metallic_flakes/spread_slope = {}, /metallic_flakes/area_ratio = {}; \
         noise {NOISE} from a fixed seed -->\n",
        TRUTH[0], TRUTH[1], TRUTH[2]
    );
    println!("| reading | exact | measured (exact + noise) |\n|---|---:|---:|");
    for ((g, n), (e, m)) in ALL.iter().zip(&measured) {
        println!("| {g}/{n} | {e:.3} | {m:.3} |");
    }
    println!();
    let start = with(&base, START);
    let free: Vec<FreeParameter> = FREE.iter().map(|f| FreeParameter::parse(f).unwrap()).collect();
    let targets_of = |which: &[usize]| -> Vec<TargetReading> {
        which
            .iter()
            .map(|&i| TargetReading {
                geometry: ALL[i].0.into(),
                name: ALL[i].1.into(),
                value: measured[i].1,
                uncertainty: Some(NOISE),
            })
            .collect()
    };
    let options = FitOptions::default();
    let cases: &[(&str, &[usize], &[usize])] = &[
        ("All seven readings, three free parameters", &[0, 1, 2, 3, 4, 5, 6], &[0, 1, 2]),
        ("D523 20°/60°/85° gloss only, three free parameters", &[0, 1, 2], &[0, 1, 2]),
        ("E430 haze and DOI only (no gloss), three free parameters", &[4, 5, 6], &[0, 1, 2]),
        ("D523 20°/60°/85° gloss, flake spread and area ratio free (coat roughness known)", &[0, 1, 2], &[1, 2]),
        ("E430 haze and DOI, coat roughness free alone", &[4, 5, 6], &[0]),
    ];
    for (title, which, params) in cases {
        let f: Vec<FreeParameter> = params.iter().map(|&k| free[k].clone()).collect();
        let mut s = with(&base, TRUTH);
        for &k in params.iter() {
            let key = ["roughness", "spread_slope", "area_ratio"][k];
            let obj = if k == 0 { "clear_coat" } else { "metallic_flakes" };
            s[obj][key] = start[obj][key].clone();
        }
        let t: Vec<f64> = params.iter().map(|&k| TRUTH[k]).collect();
        match fit(&s, "start.json", &f, &targets_of(which), &options) {
            Ok(r) => report(title, &r, &t),
            Err(e) => println!("**{title}**: {e}\n"),
        }
    }
}
