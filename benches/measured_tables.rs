//! Measured tables read through the default panel by three engines, side by side in the same run
//! (`docs/performance.md` §Measured tables; `docs/accuracy.md` §Data uncertainty of measured tables;
//! `docs/instrument.md` §Quadrature, *Measured tables*):
//! - "rtol 1e-6, resolution splits": the engine of issue 10, every integral at rtol 10⁻⁶ on the partition split
//!   at the table's resolution, no data uncertainty (the table behind a wrapper that states its lobe at its
//!   resolution and no coarse twins, so no pilot runs);
//! - "data tolerance, resolution splits": the previous default, each table integral at a quarter of its data
//!   uncertainty, on the partition split at the table's resolution (the wrapper states the resolution, the
//!   twins are kept);
//! - "data tolerance, lobe-width splits": the default, the same tolerance on the partition split at the lobe's
//!   own half width (the table itself).
//!
//! Besides the shipped tables, two MERL-resolution (90 × 90 × 180) tables of GGX α = 0.1 and 0.01 written in
//! memory (`MerlBrdf::tabulate`, as in `tests/data_uncertainty.rs`) through D523 20°, 60°, 85°. Evaluation
//! counts are exact (every integral of the plan once, the pilots on the table and its coarse twins included);
//! times are the median of repeated runs (≥ 3, ≥ 0.5 s) on whatever load the machine has (run with
//! `RAYON_NUM_THREADS=1` for one core).
//!
//! Plain `main` (harness = false). `cargo bench --bench measured_tables [FILTER]`: only the rows whose table
//! name contains FILTER; the table goes to stdout.
use glossmeter::brdf::{Brdf, Hints, Tail, TermKind};
use glossmeter::instrument::plan::{Plan, PlanOptions};
use glossmeter::measured::merl::{Interpolation, MerlBrdf};
use glossmeter::spectrum::Sampling;
use glossmeter::Vec3;
use std::sync::Arc;
use std::time::Instant;

/// The table as a previous engine saw it: the same values, its lobe split at the table's resolution
/// (`Tail::Table`'s `resolution` as the slope width), with or without its coarse twins (`Brdf::coarser`).
#[derive(Debug)]
struct AtResolution {
    table: Arc<dyn Brdf>,
    twins: bool,
}

impl Brdf for AtResolution {
    fn sampling(&self) -> &Sampling {
        self.table.sampling()
    }
    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        self.table.eval(wi, wo, out)
    }
    fn eval_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        self.table.eval_batch(wi, wo, out)
    }
    fn hints(&self) -> Hints {
        let mut h = self.table.hints();
        for t in &mut h.terms {
            if let TermKind::Lobe(l) = &mut t.kind {
                if let Tail::Table { resolution, .. } = l.tail {
                    l.slope_width = resolution;
                }
            }
        }
        h
    }
    fn coarser(&self) -> Vec<Arc<dyn Brdf>> {
        if self.twins {
            self.table.coarser()
        } else {
            Vec::new()
        }
    }
    fn describe(&self) -> String {
        self.table.describe()
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let filter: Option<String> = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    // (name, model, file under fixtures/materials/, off-plane extension of an in-plane table)
    let files = [
        ("rgl/beckmann-iso-32", "rgl", "rgl/beckmann-iso-32.bsdf", None),
        ("rgl/beckmann-iso-16", "rgl", "rgl/beckmann-iso-16.bsdf", None),
        ("rgl/beckmann-aniso-24", "rgl", "rgl/beckmann-aniso-24.bsdf", None),
        ("rgl/lambert-rgb", "rgl", "rgl/lambert-rgb.bsdf", None),
        ("merl/lambert-tiny", "merl", "merl/lambert-tiny.binary", None),
        ("inplane/beckmann microfacet", "inplane-csv", "inplane/beckmann.csv", Some("microfacet")),
        ("inplane/beckmann f", "inplane-csv", "inplane/beckmann.csv", Some("f")),
        ("inplane/lambert-cos", "inplane-csv", "inplane/lambert-cos.csv", None),
        ("inplane/beckmann-e1392 f", "e1392", "inplane/beckmann-e1392.txt", None),
    ];
    let root = std::env::current_dir().expect("cwd").join("fixtures/materials");
    let panel = glossmeter::resolve_geometries(glossmeter::DEFAULT_PANEL, &[] as &[&str]).expect("panel");
    let d523 = ["astm-d523-20", "astm-d523-60", "astm-d523-85"]
        .iter()
        .map(|g| glossmeter::instrument::standards::find(g).expect("geometry"))
        .collect::<Vec<_>>();
    let wanted = |name: &str| filter.as_deref().is_none_or(|f| name.contains(f));
    let mut rows: Vec<(String, Arc<dyn Brdf>, &Vec<_>)> = Vec::new();
    for (name, model, file, off_plane) in files {
        if !wanted(name) {
            continue;
        }
        let extension = off_plane.map(|o| format!(r#", "off_plane": "{o}""#)).unwrap_or_default();
        let text = format!(r#"{{"model": "{model}", "file": "{}"{extension}}}"#, root.join(file).display());
        let m = glossmeter::recipe::parse_str(&text, "bench.json").expect("recipe");
        rows.push((format!("{name} (default panel)"), m.brdf, &panel));
    }
    for alpha in [0.1, 0.01] {
        let name = format!("MERL 90×90×180 of GGX {alpha} (D523 20/60/85°)");
        if !wanted(&name) {
            continue;
        }
        let text = format!(r#"{{"model":"microfacet","distribution":"ggx","roughness":{alpha},"ior":1.5}}"#);
        let ggx = glossmeter::recipe::parse_str(&text, "ggx.json").expect("model").brdf;
        let table = MerlBrdf::tabulate(ggx.as_ref(), [90, 90, 180], Interpolation::Trilinear).expect("table");
        rows.push((name, Arc::new(table), &d523));
    }
    println!("| table | engine | evaluations | unconverged readings | median time |");
    println!("|---|---|---|---|---|");
    for (name, table, geos) in rows {
        let engines: [(&str, Arc<dyn Brdf>); 3] = [
            ("rtol 1e-6, resolution splits", Arc::new(AtResolution { table: table.clone(), twins: false })),
            ("data tolerance, resolution splits", Arc::new(AtResolution { table: table.clone(), twins: true })),
            ("data tolerance, lobe-width splits", table.clone()),
        ];
        for (engine, material) in engines {
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
