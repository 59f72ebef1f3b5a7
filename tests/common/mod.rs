//! Test helpers shared by the integration tests: the binary, temporary files and fixtures ([`process`]), the
//! fixture readings, and reference models written apart from the library's.
#![allow(dead_code, unused_imports)]
mod process;
pub use process::*;

use glossmeter::brdf::{Brdf, Hints, Lobe, Term, TermKind};
use glossmeter::optics::fresnel::fr_dielectric;
use glossmeter::spectrum::Sampling;
use glossmeter::Vec3;

/// Beckmann microfacet on a dielectric (F·D·G/(4 cos cos)), written out here from Walter et al. 2007 so
/// the test does not share code with the models under test; G = Smith height-correlated.
#[derive(Debug)]
pub struct TestBeckmann {
    pub m: f64,
    pub n: f64,
    pub s: Sampling,
}
impl TestBeckmann {
    fn lambda(&self, w: Vec3) -> f64 {
        let t2 = (w.x * w.x + w.y * w.y) / (w.z * w.z);
        if t2 == 0.0 {
            return 0.0;
        }
        let a = 1.0 / (self.m * t2.sqrt());
        0.5 * ((-a * a).exp() / (a * std::f64::consts::PI.sqrt()) - libm::erfc(a))
    }
}
impl Brdf for TestBeckmann {
    fn sampling(&self) -> &Sampling {
        &self.s
    }
    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        let h = (wi + wo).normalize();
        let t2 = (h.x * h.x + h.y * h.y) / (h.z * h.z);
        let m2 = self.m * self.m;
        let d = (-t2 / m2).exp() / (std::f64::consts::PI * m2 * h.z.powi(4));
        let g = 1.0 / (1.0 + self.lambda(wi) + self.lambda(wo));
        let f = fr_dielectric(wi.dot(h).clamp(0.0, 1.0), self.n) * d * g / (4.0 * wi.z * wo.z);
        out.iter_mut().for_each(|o| *o = f);
    }
    fn hints(&self) -> Hints {
        Hints::new(vec![Term {
            label: "beckmann".into(),
            kind: TermKind::Lobe(Lobe {
                slope_width: self.m,
                medium_eta: 1.0,
                label: "beckmann".into(),
                tail: glossmeter::brdf::Tail::Gaussian,
            }),
        }])
    }
    fn describe(&self) -> String {
        format!("test beckmann m = {}", self.m)
    }
}

/// Every reading of every shipped fixture recipe (`fixtures/recipes/*.json`, sorted) on every builtin geometry,
/// keyed "recipe|geometry|name": one plan per recipe, the colour geometries joining it unless the recipe is RGB.
/// The reading set of `tests/golden.rs` and `tests/reference_readings.rs`.
pub fn every_fixture_reading(
    options: &glossmeter::instrument::plan::PlanOptions,
) -> Vec<(String, glossmeter::instrument::plan::Reading)> {
    fixture_readings(options, |_| true)
}

/// [`every_fixture_reading`] of the recipes whose file stem `keep` accepts.
#[allow(dead_code)]
pub fn fixture_readings(
    options: &glossmeter::instrument::plan::PlanOptions,
    keep: impl Fn(&str) -> bool,
) -> Vec<(String, glossmeter::instrument::plan::Reading)> {
    use glossmeter::instrument::plan::Plan;
    use glossmeter::instrument::standards;
    use glossmeter::spectrum::SamplingKind;
    let gloss = standards::builtin().unwrap();
    let mut all = gloss.clone();
    all.extend(standards::builtin_colour().unwrap());
    let mut recipes: Vec<_> = std::fs::read_dir("fixtures/recipes")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    recipes.sort();
    let mut out = Vec::new();
    for path in recipes {
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        if !keep(&stem) {
            continue;
        }
        let m = glossmeter::recipe::load_file(&path).unwrap();
        let geos = if m.brdf.sampling().kind == SamplingKind::Rgb { &gloss } else { &all };
        let plan = Plan::compile(m.brdf.clone(), geos.clone(), options.clone()).unwrap();
        for r in plan.execute() {
            out.push((format!("{stem}|{}|{}", r.geometry, r.name), r));
        }
    }
    out
}

/// A Gwyddion Simple Field file (docs/topography.md §Gwyddion GSF) of n × n heights `z` (m, row-major), `dx` m
/// apart, stored as f32 µm.
pub fn write_gsf(path: &std::path::Path, n: usize, dx: f64, z: &[f64]) {
    let mut b = b"Gwyddion Simple Field 1.0\n".to_vec();
    let side = n as f64 * dx * 1e6;
    b.extend_from_slice(
        format!("XRes = {n}\nYRes = {n}\nXReal = {side}\nYReal = {side}\nXYUnits = um\nZUnits = um\n").as_bytes(),
    );
    let pad = 4 - b.len() % 4;
    b.extend(std::iter::repeat_n(0u8, pad));
    for v in z {
        b.extend_from_slice(&((v * 1e6) as f32).to_le_bytes());
    }
    std::fs::write(path, b).unwrap();
}

/// The orange-peel panel's readout as printed (`fixtures/real/konica-orange-peel-panel.csv`), its haze read as
/// log haze (docs/instrument.md §1.10).
pub const PANEL_TARGETS: [&str; 12] = [
    "--target",
    "astm-d523-20/gloss=66.3",
    "--target",
    "astm-d523-60/gloss=88.3",
    "--target",
    "astm-d523-85/gloss=94.0",
    "--target",
    "rhopoint-iq-20/log-haze=14.2",
    "--target",
    "rhopoint-iq-20/doi=77.5",
    "--target",
    "rhopoint-iq-20/rspec=26.1",
];

/// The five free parameters of the three-population model and their bounds (docs/instrument.md §1.10), as
/// `fit` arguments.
pub const THREE_POPULATION_FREE: [&str; 10] = [
    "--free",
    "/ior=1.3..1.8",
    "--free",
    "/populations/1/roughness=log:1e-3..0.05",
    "--free",
    "/populations/1/weight=0.001..0.7",
    "--free",
    "/populations/2/roughness=log:0.01..0.5",
    "--free",
    "/populations/2/weight=0.001..0.5",
];

/// The reproducers of docs/reliability.md §Workbooks (`fixtures/sheets/hostile`: crafted and mutated books that
/// made the reader panic, abort on a huge allocation, inflate a zip bomb or pass a bad CRC), as (file name,
/// path) in name order; all eleven of them, so that a lost reproducer fails the tests that read them.
pub fn hostile_workbooks() -> Vec<(String, String)> {
    let dir = "fixtures/sheets/hostile";
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    assert_eq!(names.len(), 11, "{names:?}");
    names.into_iter().map(|name| (name.clone(), format!("{dir}/{name}"))).collect()
}

/// A smooth microfacet dielectric (n = 1.5) of `distribution` and `roughness`, from its recipe.
pub fn microfacet(distribution: &str, roughness: f64) -> std::sync::Arc<dyn Brdf> {
    let text =
        format!(r#"{{"model":"microfacet","distribution":"{distribution}","roughness":{roughness:e},"ior":1.5}}"#);
    glossmeter::recipe::parse_str(&text, "<microfacet>").unwrap().brdf
}

/// The specimen methods of a plan of `brdf` at `geometry` alone (default options, no wall-clock limit), each
/// with the readings that use it.
pub fn specimen_methods(
    brdf: &std::sync::Arc<dyn Brdf>,
    geometry: &str,
) -> Vec<(String, glossmeter::instrument::method::Method)> {
    use glossmeter::instrument::plan::{Plan, PlanOptions};
    let options = PlanOptions { max_seconds: None, ..PlanOptions::default() };
    let geometries = vec![glossmeter::instrument::standards::find(geometry).unwrap()];
    let p = Plan::compile(brdf.clone(), geometries, options).unwrap();
    p.jobs
        .iter()
        .filter(|j| j.method.aperture.target == glossmeter::instrument::method::Target::Specimen)
        .map(|j| (j.used_by.join(","), j.method.clone()))
        .collect()
}
