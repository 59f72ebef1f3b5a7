//! The default panel run as a plan: its geometries, recipes by file name, exact evaluation counts and timed
//! runs.
use std::path::Path;
use std::sync::Arc;

use glossmeter::brdf::{Brdf, Hints};
use glossmeter::instrument::plan::{Engine, Plan, PlanOptions, Reading};
use glossmeter::instrument::standards::{self, StandardGeometry};
use glossmeter::spectrum::Sampling;
use glossmeter::Vec3;

use crate::cases::PANEL;
use crate::report::timed;

pub(crate) fn panel() -> Vec<StandardGeometry> {
    PANEL.iter().map(|id| standards::find(id).expect("builtin geometry")).collect()
}

pub(crate) fn recipe(name: &str) -> Option<Arc<dyn Brdf>> {
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
pub(crate) struct Counting {
    pub(crate) inner: Arc<dyn Brdf>,
    pub(crate) n: std::sync::atomic::AtomicUsize,
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

pub(crate) fn count_evaluations(brdf: Arc<dyn Brdf>, opts: PlanOptions, engine: Engine) -> usize {
    let c = Arc::new(Counting { inner: brdf, n: Default::default() });
    let plan = Plan::compile_with_engine(c.clone(), panel(), opts, engine).expect("plan compiles");
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    pool.install(|| plan.execute());
    c.n.load(std::sync::atomic::Ordering::Relaxed)
}

pub(crate) struct PanelRun {
    pub(crate) readings: Vec<Reading>,
    pub(crate) seconds: f64,
    pub(crate) runs: usize,
    pub(crate) jobs: usize,
}

pub(crate) fn run_panel(brdf: Arc<dyn Brdf>, opts: PlanOptions, engine: Engine, threads: usize) -> PanelRun {
    let plan = Plan::compile_with_engine(brdf, panel(), opts, engine).expect("plan compiles");
    let jobs = plan.jobs.len();
    // One thread by default: the time of the work itself, not of the parallel schedule.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    let (readings, seconds, runs) = pool.install(|| timed(|| plan.execute()));
    PanelRun { readings, seconds, runs, jobs }
}

pub(crate) fn total_evaluations(r: &[Reading]) -> usize {
    r.iter().map(|x| x.evaluations).sum()
}
