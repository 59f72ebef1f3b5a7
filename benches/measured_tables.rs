//! Measured tables read through the default panel, before and after the data tolerance
//! (`docs/performance.md` §Measured tables: the data tolerance; `docs/accuracy.md` §Data uncertainty of
//! measured tables), side by side in the same run: "before" is the previous engine's default, every integral at
//! rtol 10⁻⁶ and no data uncertainty (the table behind a wrapper that states no coarse twins, so no pilot
//! runs), "after" the default, each table integral at a quarter of its data uncertainty. Evaluation counts are exact (every integral of the
//! plan once, the pilots on the table and its coarse twin included); times are the median of repeated runs
//! (≥ 3, ≥ 0.5 s) on whatever load the machine has.
//!
//! Plain `main` (harness = false). `cargo bench --bench measured_tables [FILTER]`: only the rows whose table
//! name contains FILTER; the table goes to stdout.
use glossmeter::brdf::{Brdf, Term};
use glossmeter::instrument::plan::{Plan, PlanOptions};
use glossmeter::spectrum::Sampling;
use glossmeter::Vec3;
use std::sync::Arc;
use std::time::Instant;

/// The table as the previous engine saw it: the same values and terms, no coarse twins (`Brdf::coarser`).
#[derive(Debug)]
struct NoTwins(Arc<dyn Brdf>);

impl Brdf for NoTwins {
    fn sampling(&self) -> &Sampling {
        self.0.sampling()
    }
    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        self.0.eval(wi, wo, out)
    }
    fn eval_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        self.0.eval_batch(wi, wo, out)
    }
    fn terms(&self) -> Vec<Term> {
        self.0.terms()
    }
    fn kinks(&self) -> Vec<glossmeter::brdf::Kink> {
        self.0.kinks()
    }
    fn seams(&self) -> Vec<f64> {
        self.0.seams()
    }
    fn is_reciprocal(&self) -> bool {
        self.0.is_reciprocal()
    }
    fn smooth(&self) -> bool {
        self.0.smooth()
    }
    fn describe(&self) -> String {
        self.0.describe()
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let filter: Option<String> = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    // (name, model, file under fixtures/materials/, off-plane extension of an in-plane table)
    let tables = [
        ("rgl/beckmann-iso-32", "rgl", "rgl/beckmann-iso-32.bsdf", None),
        ("rgl/beckmann-iso-16", "rgl", "rgl/beckmann-iso-16.bsdf", None),
        ("rgl/lambert-rgb", "rgl", "rgl/lambert-rgb.bsdf", None),
        ("merl/lambert-tiny", "merl", "merl/lambert-tiny.binary", None),
        ("inplane/beckmann microfacet", "inplane-csv", "inplane/beckmann.csv", Some("microfacet")),
        ("inplane/beckmann-e1392 f", "e1392", "inplane/beckmann-e1392.txt", None),
    ];
    let root = std::env::current_dir().expect("cwd").join("fixtures/materials");
    let geos = glossmeter::resolve_geometries(glossmeter::DEFAULT_PANEL, &[] as &[&str]).expect("panel");
    println!("| table (default panel) | engine | evaluations | unconverged readings | median time |");
    println!("|---|---|---|---|---|");
    for (name, model, file, off_plane) in tables {
        if filter.as_deref().is_some_and(|f| !name.contains(f)) {
            continue;
        }
        let extension = off_plane.map(|o| format!(r#", "off_plane": "{o}""#)).unwrap_or_default();
        let text = format!(r#"{{"model": "{model}", "file": "{}"{extension}}}"#, root.join(file).display());
        let m = glossmeter::recipe::parse_str(&text, "bench.json").expect("recipe");
        let before: Arc<dyn Brdf> = Arc::new(NoTwins(m.brdf.clone()));
        for (engine, material) in [("before: rtol 1e-6", before), ("after: data tolerance", m.brdf.clone())] {
            let plan = Plan::compile(material, geos.clone(), PlanOptions::default()).expect("plan");
            let (mut times, mut last) = (vec![], None);
            let start = Instant::now();
            while times.len() < 3 || start.elapsed().as_secs_f64() < 0.5 {
                let t = Instant::now();
                last = Some(plan.run());
                times.push(t.elapsed().as_secs_f64());
            }
            let run = last.expect("ran");
            let unconverged = run.readings.iter().filter(|r| !r.converged).count();
            println!("| {name} | {engine} | {} | {unconverged} | {:.1} ms |", run.evaluations(), 1e3 * median(times));
        }
    }
}
