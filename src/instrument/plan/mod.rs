//! The measurement plan: (material, geometries, requested readings) compiled once into the cheapest list
//! of aperture integrals that produces them, in the manner of RustFFT's planner: step one designs a
//! [`Method`] per integral (plain data: clipped stops, mirror visibility, chart, rule, initial partition,
//! delta part, spectral weighting, tolerances, budget), step two executes the methods. The plan
//!
//! * keeps only the terms the material has (the model builds no flake term without flakes; the methods
//!   integrate a smooth coat as an analytic delta, a diffuse body with no lobe splits, each lobe with splits
//!   at its own width);
//! * chooses the spectral weighting from the readings asked for (every reading says which it needs:
//!   `ReadingSpec::weighting`) and folds it into the integrand, so a luminous flux is one component whatever
//!   the number of samples;
//! * computes each distinct flux once and shares it: the gloss standard's flux between gloss and haze
//!   readings, a receptor between gloss and DOI, identical geometries (ASTM D523 and ISO 2813 at the same
//!   angle) between themselves, and the gloss readings that a composite (ASTM D4039) needs;
//! * computes the gloss standards' fluxes when it is compiled (they do not depend on the material; a
//!   long-lived [`Planner`] keeps them for every plan it compiles);
//! * runs the specimen integrals in parallel, collecting results in plan order, so the numbers are the same
//!   bits whatever the thread count.
//!
//! A compiled plan can be executed on another material of the same shape ([`Plan::with_material`]) and
//! frozen after one adaptive execution ([`Plan::freeze`]); `explain()` prints the stored methods in plain
//! words (`glossmeter measure --explain`).
//!
//! The folder, one idea per file:
//!
//! * `mod.rs`: the plan's data and life: [`PlanOptions`], [`Job`], [`PlannedReading`], [`Reading`],
//!   [`Execution`], [`Plan`] and its [`Plan::with_material`], [`Plan::freeze`],
//!   [`Plan::execute`], [`Plan::run`], [`Plan::run_all`]; the tolerance shares ([`SPECIMEN_SHARE`],
//!   [`STANDARD_SHARE`]) and limits ([`MIN_RTOL`], [`DEFAULT_MAX_EVALS`]);
//! * `compile.rs`: the planner, [`Planner`]: a plan's jobs designed from the material, the geometries and
//!   the options, shared by key, and the gloss standards' fluxes computed and cached; [`Plan::compile`];
//! * `readings.rs`: the reading formulas, in one place: [`reading_value`], [`haze_index_value`],
//!   [`colour_xyz`], [`colour_value`], and a planned reading computed from its fluxes;
//! * `explain.rs`: [`Plan::explain`], the stored methods in plain words (the text of `--explain`).
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock, PoisonError};

use rayon::prelude::*;

use crate::brdf::{Brdf, Term, TermKind};
use crate::colorimetry::weighting::{Weighting, WeightingKind};
use crate::colorimetry::Conditions;
use crate::instrument::method::Flux;
use crate::instrument::method::Method;
pub use crate::instrument::method::Target;
use crate::instrument::reading::{ReadingSpec, Scale};
use crate::instrument::standards::StandardGeometry;
use crate::spectrum::Sampling;
use crate::{Error, Result};

mod cancel;
mod compile;
mod explain;
mod readings;

pub use cancel::Cancel;
pub(crate) use compile::rtol_refusal;
pub use compile::Planner;
pub(crate) use readings::{haze_index_value, reading_value};

/// Share of a reading's relative tolerance given to each specimen flux and to the gloss standard's flux. A
/// gloss reading's propagated relative error is at most the sum of its two fluxes' (first order), so
/// SPECIMEN_SHARE + STANDARD_SHARE ≤ 1 keeps it within rtol. The standard (an analytic 2-D integral) is cheap
/// to converge tightly; the specimen's 4-D integral gets most of the budget.
pub const SPECIMEN_SHARE: f64 = 0.9;
pub const STANDARD_SHARE: f64 = 0.05;

/// The smallest relative tolerance a plan accepts. A reading's tolerance is split down to 0.05 % of it for
/// the analytic part of a specimen flux (DELTA_SHARE × SPECIMEN_SHARE) and 5 % for the standard, so at 1e-12
/// those parts are asked for ~1e-15 relative: a few units of the double-precision rounding (2.2e-16) of
/// their sums. Below that the error estimates are rounding noise and the cubature refines to its budget
/// without ever meeting the tolerance (`--rtol 1e-300` ran for minutes on black glass). The convergence
/// reference runs at this tolerance (`instrument::convergence`).
pub const MIN_RTOL: f64 = 1e-12;

/// The default evaluation budget of each part of an aperture integral: 2·10⁶ evaluations, a bound in work, so
/// that a reading that reaches it is the same bits on every machine and under any load
/// (docs/instrument.md §Bounded work). Every shipped fixture reading needs at most 7.3·10⁴; a measured table
/// read at 85° (the kinks at every cell boundary) reaches it in 0.9 s (the RGL fixture, D523 85°, measured).
/// There is no default wall-clock budget: [`PlanOptions::max_seconds`] is opt-in, and an integral that meets it gives no value.
pub(crate) const DEFAULT_MAX_EVALS: usize = 2_000_000;

/// The fraction of a measured table's data uncertainty that its specimen integrals are asked for by default
/// ([`PlanOptions::rtol_from_data`]): the numerical error then adds at most a quarter of the data uncertainty
/// to a reading, and the integral is not driven to a precision its data does not have (docs/accuracy.md
/// §Data uncertainty of measured tables).
pub(crate) const DATA_FRACTION: f64 = 0.25;

/// The loosest relative tolerance the data uncertainty may set (a table so coarse that a quarter of its
/// uncertainty exceeds 1 % is still integrated to 1 %).
pub(crate) const DATA_MAX_RTOL: f64 = 1e-2;

/// The tolerances at which a table and its coarse twins are integrated to estimate the data uncertainty, in
/// turn until the sum of their numerical errors is at most [`DATA_RESOLVED`] times the difference of the two
/// fluxes (so that the difference, not the integration, is most of what is measured), and never tighter
/// than the plan's rtol. (Looser first tolerances cost the same: the initial partition at the table's
/// resolution already meets 10⁻², measured on `beckmann-iso-32`.)
pub(crate) const DATA_PILOT_RTOL: [f64; 3] = [1e-2, 1e-3, 1e-4];

/// When the pilots stop: e_coarse + e_table ≤ DATA_RESOLVED·|Φ_coarse − Φ_table| (then the data
/// uncertainty u = |Φ_coarse − Φ_table| + e_coarse + e_table is at most 3 × the difference).
pub(crate) const DATA_RESOLVED: f64 = 2.0;

/// The relative tolerance of every reading when none is given: the one default of every request and front
/// end (`crate::request`), of [`PlanOptions::default`] and of the integrator's own options (defined on the
/// integrator's floor, `quadrature::DEFAULT_RTOL`, which the instrument stands on).
pub use crate::quadrature::DEFAULT_RTOL;

/// What a front end asks of a plan: the tolerance, the budgets, the colour conditions and the stop signal.
/// Every field is a user's choice; the engine's own switches, kept to measure what each optimisation saves,
/// are [`Engine`]'s, which only benches and tests set.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanOptions {
    /// Relative tolerance of every reading.
    pub rtol: f64,
    /// Evaluation budget per flux integral (deterministic: a reading that hits it is the same bits on every
    /// machine).
    pub max_evals: usize,
    /// Wall-clock budget of one execution of the plan, seconds (None: none): every integral of the plan stops
    /// refining at the same deadline, [`Plan::execute`]'s start + this (an integral run on its own,
    /// `Method::execute`, has it as its own budget). A reading whose integral hits it has the best estimate
    /// as its value, is marked not converged, and depends on the machine's speed.
    pub max_seconds: Option<f64>,
    /// Illuminant and observer of colour readings (default D65 and the CIE 1964 10° observer, as colour QC
    /// uses; gloss readings are luminous whatever this says).
    pub colour: Conditions,
    /// For a measured table (a material with coarse twins, `Brdf::coarser`): let each specimen integral's
    /// tolerance default to [`DATA_FRACTION`] of its data uncertainty, relative, within [`DATA_MAX_RTOL`]
    /// and never tighter than `rtol` (docs/accuracy.md §Data uncertainty of measured tables). False: `rtol`
    /// is used as given (the command line's `--rtol` sets this false). No effect on other materials.
    pub rtol_from_data: bool,
    /// A stop signal for the caller's whole work ([`Cancel`]; default: none): once raised, or once its
    /// deadline passes, integrals not yet started are skipped and running ones stop refining, and their
    /// readings have no value. It changes no method and no other reading.
    pub cancel: Cancel,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            rtol: DEFAULT_RTOL,
            max_evals: DEFAULT_MAX_EVALS,
            max_seconds: None,
            colour: Conditions::default(),
            rtol_from_data: true,
            cancel: Cancel::default(),
        }
    }
}

/// The planner's optimisations, each of which can be turned off to measure what it saves
/// (`docs/performance.md`; the readings agree to rounding, `tests/plan.rs`, `tests/folded_paint.rs`). Every
/// front end compiles with the default, all on ([`Plan::compile`]); a bench or a test that compares builds
/// the variant it compares ([`Plan::compile_with_engine`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Engine {
    /// Apply the spectral weighting in the integrand (k components) rather than after integrating every
    /// sample (n components).
    pub fold_spectral: bool,
    /// With `fold_spectral`, let a material that can sum a luminous-only flux's samples itself do so
    /// (`Brdf::eval_batch_folded`: the paint's folded flake tables); off, the integrand weights the n
    /// samples the material returns.
    pub fold_in_material: bool,
    /// Compute each distinct flux once.
    pub share_fluxes: bool,
}

impl Default for Engine {
    fn default() -> Self {
        Engine { fold_spectral: true, fold_in_material: true, share_fluxes: true }
    }
}

/// One aperture integral of the plan: its method and where it is used.
#[derive(Clone, Debug)]
pub struct Job {
    pub method: Method,
    /// The scale of the standard (used by standard jobs only).
    pub scale: Scale,
    /// Where it is used: "geometry-id/receptor".
    pub used_by: Vec<String>,
}

/// A reading of the plan, referring to jobs by index.
#[derive(Clone, Debug)]
pub struct PlannedReading {
    pub geometry: String,
    pub name: String,
    pub spec: ReadingSpec,
    /// Job index of each specimen flux and each standard flux, by receptor name.
    pub specimen_jobs: BTreeMap<String, usize>,
    pub standard_jobs: BTreeMap<String, usize>,
    /// The spectral weighting this reading uses; it reads its components from that kind's offset in each of
    /// its specimen jobs' weighting (a job carries the kinds of the readings that use it; the standards'
    /// fluxes are luminous, component 0).
    pub kind: WeightingKind,
    /// For composites: indices of the gloss readings combined.
    pub parts: Vec<usize>,
    /// Whether the user asked for it (dependencies of composites are computed but not reported).
    pub reported: bool,
}

/// A computed reading. `value` is None when no finite value exists (then `problem` says why), or when none is
/// defined (the hue of a neutral colour: then `note` says why, [`Reading::undefined`]): a NaN or an infinity is
/// never reported as a reading.
#[derive(Clone, Debug, PartialEq)]
pub struct Reading {
    pub geometry: String,
    pub name: String,
    pub quantity: String,
    pub unit: String,
    pub value: Option<f64>,
    pub error_estimate: f64,
    pub evaluations: usize,
    pub seconds: f64,
    pub converged: bool,
    /// Why there is no value (or why it may be inaccurate: budget exhausted).
    pub problem: Option<String>,
    /// A caveat on a valid value (e.g. a specimen outside the scope of the standard's formula).
    pub note: Option<String>,
    /// The data (resolution) uncertainty of a reading of a measured table, in the reading's unit: how far
    /// the table's interpolant may put the reading from that of the surface it samples (docs/accuracy.md
    /// §Data uncertainty of measured tables). None for a model (no data) and when there is no value.
    /// Separate from `error_estimate`, the numerical error of the integration.
    pub data_uncertainty: Option<f64>,
    /// The illuminant and observer a colour reading (X, Y, Z, L*, a*, b*, C*, h) is computed under: the plan's
    /// (docs/colour.md). None for every other reading.
    pub colour: Option<Conditions>,
}

impl Reading {
    /// Whether the reading has no value by definition, not by failure: no value and no problem (the hue of a
    /// neutral colour, [`NeutralHue`], whose note says why). It changes no exit status.
    pub fn undefined(&self) -> bool {
        self.value.is_none() && self.problem.is_none()
    }
}

/// One execution of a plan ([`Plan::run`]): the readings, and the flux of every integral of the plan.
#[derive(Clone, Debug)]
pub struct Execution {
    pub readings: Vec<Reading>,
    /// One flux per job of the plan, in plan order (`Plan::jobs`): the specimen integrals computed by this
    /// execution and the gloss standards' fluxes computed when the plan was compiled.
    pub fluxes: Vec<Flux>,
}

impl Execution {
    /// The BRDF evaluations of the whole plan: every distinct integral (job) counted once, the gloss
    /// standards' integrals included (as in each reading's own count). A reading's `evaluations` counts
    /// every integral it uses, so an integral shared by several readings is in each of their counts but
    /// only once here. A frozen plan's integrals count what its fixed partitions cost.
    pub fn evaluations(&self) -> usize {
        self.fluxes.iter().map(|f| f.evaluations).sum()
    }
}

/// The shape of a material, which a plan's methods depend on: its sampling and the kinds of its terms.
#[derive(Clone, Debug, PartialEq)]
struct Shape {
    sampling: Sampling,
    kinds: Vec<u8>,
}

impl Shape {
    /// The shape of a material of this sampling and these terms.
    fn of(sampling: &Sampling, terms: &[Term]) -> Shape {
        let kinds = terms
            .iter()
            .map(|t| match t.kind {
                TermKind::Delta => 0,
                TermKind::Diffuse => 1,
                TermKind::Lobe(_) => 2,
            })
            .collect();
        Shape { sampling: sampling.clone(), kinds }
    }
}

/// The compiled plan.
#[derive(Clone)]
pub struct Plan {
    pub material: Arc<dyn Brdf>,
    pub options: PlanOptions,
    /// The engine it was compiled with ([`Engine::default`] but in benches and tests).
    pub engine: Engine,
    pub geometries: Vec<StandardGeometry>,
    pub jobs: Vec<Job>,
    pub readings: Vec<PlannedReading>,
    /// The spectral weighting of the specimen fluxes (stacked from the readings' kinds).
    pub weighting: Weighting,
    /// The material's terms, as the methods were designed for.
    pub terms: Vec<Term>,
    shape: Shape,
    /// The standards' fluxes, computed at compile time (None for specimen jobs).
    standard_flux: Vec<Option<Flux>>,
    /// The material's coarse twins (`Brdf::coarser`: a measured table on about every second sample), from
    /// which each specimen flux's data uncertainty is estimated; empty for a model.
    twins: Vec<Arc<dyn Brdf>>,
    /// X, Y, Z of the perfect reflecting diffuser under the colour conditions, from the material's own grid
    /// (the row sums of its weights, so a white diffuser reads L* = 100 exactly); None without colour readings.
    white_point: Option<(Conditions, [f64; 3])>,
}

impl Plan {
    /// The same plan (the same methods, partitions included, and the same standards' fluxes) for another
    /// material of the same shape: the same spectral sampling and the same kinds of terms in the same order.
    /// The split points stay those of the material the plan was compiled for: right for a nearby material
    /// (a fitter's step, a sweep's neighbour); for a very different one compile a new plan.
    pub fn with_material(&self, material: Arc<dyn Brdf>) -> Result<Plan> {
        let s = Shape::of(material.sampling(), &material.hints().terms);
        if s != self.shape {
            return Err(Error::Usage(format!(
                "the plan was compiled for a material of another shape ({} samples, terms {:?}); this one has {} \
                 samples, terms {:?}",
                self.shape.sampling.len(),
                self.shape.kinds,
                s.sampling.len(),
                s.kinds
            )));
        }
        let mut p = self.clone();
        p.twins = material.coarser();
        p.material = material;
        Ok(p)
    }

    /// Whether every specimen method is frozen.
    pub fn is_frozen(&self) -> bool {
        self.jobs.iter().all(|j| j.method.aperture.target == Target::Standard || j.method.is_frozen())
    }

    /// Execute the plan adaptively and return its readings together with the frozen plan: every specimen
    /// method keeps its final partition and is re-executed with the same rule and no refinement. Executing
    /// the frozen plan on the same material gives the same value and error bits (fewer evaluations: the
    /// refined-away parents are not evaluated again); on a nearby material ([`Plan::with_material`]) the
    /// readings move smoothly with the material's parameters, as finite differences need. A frozen plan's
    /// error estimates are those of its fixed partition: check `converged` before trusting one far from
    /// the material it was frozen on.
    pub fn freeze(&self) -> (Vec<Reading>, Plan) {
        let deadline = self.deadline();
        let todo = self.specimen_jobs();
        let results: Vec<(Flux, Method)> = todo
            .par_iter()
            .map(|&j| {
                let (f, m) = self.run_job(j, deadline, true);
                (f, m.expect("kept"))
            })
            .collect();
        let mut frozen = self.clone();
        let mut flux = self.known_fluxes();
        for (&j, (f, m)) in todo.iter().zip(results) {
            frozen.jobs[j].method = m;
            flux[j] = Some(f);
        }
        let flux: Vec<Flux> = flux.into_iter().map(|f| f.expect("every job ran")).collect();
        (self.readings_from(&flux), frozen)
    }

    /// The shared deadline of one execution: now + the wall-clock budget.
    fn deadline(&self) -> Option<std::time::Instant> {
        let now = std::time::Instant::now();
        self.options
            .cancel
            .earliest(self.options.max_seconds.and_then(|s| crate::instrument::method::deadline_after(now, s)))
    }

    /// Execute the plan: every specimen method on the material (the standards' fluxes were computed when the
    /// plan was compiled), then the readings. The specimen integrals share one wall-clock deadline.
    pub fn execute(&self) -> Vec<Reading> {
        self.run().readings
    }

    /// [`Plan::execute`], keeping the flux of every integral with the readings: what the whole plan cost
    /// ([`Execution::evaluations`], each distinct integral counted once).
    pub fn run(&self) -> Execution {
        self.run_until(self.deadline())
    }

    /// [`Plan::run`] under a deadline of the caller's (None: none) instead of the plan's own (the start + its
    /// wall-clock budget): a command that runs several plans (`measure --envelope`, its nominal plan and
    /// every variant's) holds them all to one limit counted from its start. The integrals still take their
    /// budget from [`PlanOptions::max_seconds`] ([`Method::execute_until`]).
    pub(crate) fn run_until(&self, deadline: Option<std::time::Instant>) -> Execution {
        let deadline = self.options.cancel.earliest(deadline);
        let todo = self.specimen_jobs();
        let computed: Vec<Flux> = todo.par_iter().map(|&j| self.run_job(j, deadline, false).0).collect();
        let mut flux = self.known_fluxes();
        for (&j, f) in todo.iter().zip(computed) {
            flux[j] = Some(f);
        }
        self.execution(flux)
    }

    /// Execute several plans as one pool of integrals: every specimen integral of every plan is one task of a
    /// single work queue that the pool's threads drain, so the threads balance integrals, not plans. A batch
    /// of plans whose costs differ a hundredfold, each with one or two integrals that dominate it, then ends
    /// within one small integral on every thread; running plan after plan, each with its own parallel loop
    /// over its integrals ([`Plan::run`] inside a parallel loop over plans), nests two loops whose inner one
    /// (14 integrals of 6–20 µs for most recipes) costs more in hand-overs than it spreads, and ends when the
    /// last plan's dominant integral does (docs/performance.md §Batch and sweep throughput).
    ///
    /// The queue is in order of expected cost, largest first ([`Method::expected_evaluations`]; ties in plan
    /// order), the longest-processing-time rule: the few integrals of milliseconds start at once and the
    /// last ones taken are of microseconds. Each thread takes the next integral from one shared atomic
    /// counter, so the order does not depend on the number of threads or on how the range would be split.
    /// The thread that completes a plan's last integral works out that plan's readings at once, so no serial
    /// step follows the loop. Each execution is the same bits as [`Plan::run`] of that plan alone (each
    /// integral is the same method on the same material, on one thread; the order only decides when);
    /// each plan's wall-clock budget starts when its first integral does.
    pub fn run_all(plans: &[Plan]) -> Vec<Execution> {
        Plan::run_all_reporting(plans, &|_, _| {})
    }

    /// [`Plan::run_all`], calling `done(plan, job)` on the worker thread as each specimen integral ends (for
    /// progress: the weights of the integrals are their `expected_evaluations`). The results are the same bits.
    pub(crate) fn run_all_reporting(plans: &[Plan], done_integral: &(dyn Fn(usize, usize) + Sync)) -> Vec<Execution> {
        let tasks: Vec<(usize, usize)> = plans
            .iter()
            .enumerate()
            .flat_map(|(p, plan)| plan.specimen_jobs().into_iter().map(move |j| (p, j)))
            .collect();
        let mut order: Vec<(f64, usize)> =
            tasks.iter().enumerate().map(|(t, &(p, j))| (plans[p].jobs[j].method.expected_evaluations(), t)).collect();
        order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        // Per plan: the integrals still to run and the fluxes so far (the standards' from compile time).
        let pending: Vec<Mutex<(usize, Vec<Option<Flux>>)>> = plans
            .iter()
            .map(|plan| {
                let known = plan.known_fluxes();
                Mutex::new((known.iter().filter(|f| f.is_none()).count(), known))
            })
            .collect();
        let done: Vec<OnceLock<Execution>> = plans.iter().map(|_| OnceLock::new()).collect();
        let deadlines: Vec<OnceLock<Option<std::time::Instant>>> = plans.iter().map(|_| OnceLock::new()).collect();
        let next = AtomicUsize::new(0);
        let drain = || {
            while let Some(&(_, t)) = order.get(next.fetch_add(1, Ordering::Relaxed)) {
                let (p, j) = tasks[t];
                let plan = &plans[p];
                let deadline = *deadlines[p].get_or_init(|| plan.deadline());
                let f = plan.run_job(j, deadline, false).0;
                let complete = {
                    let mut slot = pending[p].lock().unwrap_or_else(PoisonError::into_inner);
                    slot.1[j] = Some(f);
                    slot.0 -= 1;
                    (slot.0 == 0).then(|| std::mem::take(&mut slot.1))
                };
                if let Some(flux) = complete {
                    let _ = done[p].set(plan.execution(flux));
                }
                done_integral(p, j);
            }
        };
        let threads = rayon::current_num_threads().min(tasks.len()).max(1);
        rayon::scope(|s| {
            for _ in 1..threads {
                s.spawn(|_| drain());
            }
            drain();
        });
        // Plans without specimen integrals (nothing ran) are worked out here.
        plans
            .iter()
            .zip(done)
            .zip(pending)
            .map(|((plan, d), pend)| {
                d.into_inner()
                    .unwrap_or_else(|| plan.execution(pend.into_inner().unwrap_or_else(PoisonError::into_inner).1))
            })
            .collect()
    }

    /// One specimen integral of the plan on its material (with `freeze`, also the frozen method). For a
    /// measured table (a plan with coarse twins) the integral is first run on the table and on each twin at
    /// the pilot tolerances ([`DATA_PILOT_RTOL`], each no tighter than the plan's rtol) until the summed
    /// numerical errors are at most [`DATA_RESOLVED`] times the larger difference; the data uncertainty of
    /// each component is
    ///
    /// ```text
    /// u = max over the twins t of (|Φ_t − Φ_table| + e_t) + e_table
    /// ```
    ///
    /// (docs/accuracy.md §Data uncertainty of measured tables). With [`PlanOptions::rtol_from_data`] the
    /// integral's tolerance is then max(rtol, min(DATA_FRACTION·u/|Φ|, DATA_MAX_RTOL)) over its components
    /// (the smallest); if the last pilot on the table already met that tolerance (as its tolerance or by its
    /// own error estimate), it is the flux, otherwise the table is integrated again at it. Every evaluation of
    /// the pilots is counted in the flux's. A frozen method runs as frozen on all of them, once.
    fn run_job(&self, j: usize, deadline: Option<std::time::Instant>, freeze: bool) -> (Flux, Option<Method>) {
        let method = &self.jobs[j].method;
        if self.options.cancel.is_stopped() {
            // Stopped before it started (`PlanOptions::cancel`): no evaluation, and no value for its readings.
            let skipped = Flux { converged: false, out_of_time: true, ..Flux::zero(method.weighting.len()) };
            return (skipped, freeze.then(|| method.clone()));
        }
        let material = self.material.as_ref();
        if let Some(ff) = material.far_field() {
            if method.aperture.target == Target::Specimen {
                return (far_field_flux(ff, method), freeze.then(|| method.clone()));
            }
        }
        let exec = |m: &Method, b: &dyn Brdf| -> (Flux, Option<Method>) {
            if freeze {
                let (f, m) = m.execute_and_freeze_until(b, deadline);
                (f, Some(m))
            } else {
                (m.execute_until(b, deadline), None)
            }
        };
        if self.twins.is_empty() {
            return exec(method, material);
        }
        // (u, whether the summed numerical errors are within DATA_RESOLVED × the larger difference)
        let uncertainty = |f: &Flux, twins: &[Flux]| -> (Vec<f64>, bool) {
            let mut resolved = true;
            let u = (0..f.value.len())
                .map(|k| {
                    let diff = twins.iter().map(|c| (c.value[k] - f.value[k]).abs()).fold(0.0, f64::max);
                    let err = twins.iter().map(|c| c.error[k]).fold(0.0, f64::max) + f.error[k];
                    // Twins that read exactly the table's value (a constant table) settle it at once.
                    let same = twins.iter().all(|c| c.value[k].to_bits() == f.value[k].to_bits());
                    resolved &= same || err <= DATA_RESOLVED * diff;
                    twins.iter().map(|c| (c.value[k] - f.value[k]).abs() + c.error[k]).fold(0.0, f64::max) + f.error[k]
                })
                .collect();
            (u, resolved)
        };
        let run_twins =
            |m: &Method| -> Vec<Flux> { self.twins.iter().map(|t| m.execute_until(t.as_ref(), deadline)).collect() };
        let cost =
            |fs: &[Flux]| (fs.iter().map(|f| f.evaluations).sum::<usize>(), fs.iter().map(|f| f.seconds).sum::<f64>());
        if method.is_frozen() {
            let (mut f, m) = exec(method, material);
            let c = run_twins(method);
            f.data_uncertainty = Some(uncertainty(&f, &c).0);
            let (e, s) = cost(&c);
            f.evaluations += e;
            f.seconds += s;
            return (f, m);
        }
        let rtol = self.options.rtol;
        let mut spent = (0usize, 0.0f64);
        let mut pilot: Option<(Flux, Option<Method>, f64)> = None;
        for rp in DATA_PILOT_RTOL.iter().map(|&r| r.max(rtol)) {
            if pilot.as_ref().is_some_and(|p| p.2 <= rp) {
                break;
            }
            let m = method.with_rtol(rp);
            let (f, fm) = exec(&m, material);
            let c = run_twins(&m);
            if let Some((p, _, _)) = &pilot {
                spent.0 += p.evaluations;
                spent.1 += p.seconds;
            }
            let (e, s) = cost(&c);
            spent.0 += e;
            spent.1 += s;
            let (u, resolved) = uncertainty(&f, &c);
            let late = f.out_of_time || c.iter().any(|c| c.out_of_time) || self.options.cancel.is_stopped();
            pilot = Some((Flux { data_uncertainty: Some(u), ..f }, fm, rp));
            if resolved || late {
                break;
            }
        }
        let (pf, pm, rp) = pilot.expect("at least one pilot ran");
        let u = pf.data_uncertainty.clone().expect("set");
        let target = if self.options.rtol_from_data {
            let rel = (0..u.len())
                .filter(|&k| pf.value[k].abs() > 0.0)
                .map(|k| DATA_FRACTION * u[k] / pf.value[k].abs())
                .fold(DATA_MAX_RTOL, f64::min);
            rtol.max(rel)
        } else {
            rtol
        };
        // The last pilot is the flux when it ran at the target tolerance or tighter, or when its own error
        // estimate already meets the target (adaptive cubature often ends well inside its tolerance).
        let meets = pf.converged && (0..u.len()).all(|k| pf.error[k] <= target * pf.value[k].abs());
        let (mut f, m) = if rp <= target || meets {
            (pf, pm)
        } else {
            spent.0 += pf.evaluations;
            spent.1 += pf.seconds;
            let (f, m) = exec(&method.with_rtol(target), material);
            (Flux { data_uncertainty: Some(u), ..f }, m)
        };
        f.evaluations += spent.0;
        f.seconds += spent.1;
        (f, m)
    }

    /// The execution from the flux of every job (the standards' and the computed ones).
    fn execution(&self, flux: Vec<Option<Flux>>) -> Execution {
        let fluxes: Vec<Flux> = flux.into_iter().map(|f| f.expect("every job ran")).collect();
        Execution { readings: self.readings_from(&fluxes), fluxes }
    }

    /// The jobs to run on the material, in plan order. Only these go to the thread pool: a plan with one
    /// specimen integral runs it on the calling thread (rayon runs a one-item parallel iterator in place),
    /// which spares a one-off small plan the hand-over to the pool and back (tens of µs).
    pub fn specimen_jobs(&self) -> Vec<usize> {
        (0..self.jobs.len()).filter(|&j| self.standard_flux[j].is_none()).collect()
    }

    /// The fluxes known before execution: the standards', by job index.
    fn known_fluxes(&self) -> Vec<Option<Flux>> {
        self.standard_flux.clone()
    }
}

/// A specimen flux from a material's far field (docs/optics.md §11; docs/architecture.md §From recipe to
/// reading): the grey flux, its numerical error and its speckle uncertainty through the method's weighting, no
/// evaluation of the BRDF; a refusal, or an integral that is no aperture integral (a sphere's), is a flux with
/// no value whose readings carry the reason.
fn far_field_flux(ff: &dyn crate::brdf::FarField, method: &Method) -> Flux {
    let a = &method.aperture;
    let k = method.weighting.len();
    let start = std::time::Instant::now();
    let got = match a.integral {
        crate::instrument::geometry::Integral::Aperture => {
            ff.aperture_flux(a.theta, a.viewing, [a.source.p, a.source.q], [a.receptor.p, a.receptor.q])
        }
        _ => Err("a sphere's integral is not read by the Kirchhoff method (docs/optics.md §11); read it with the \
                  default method"
            .into()),
    };
    match got {
        Ok(f) => {
            let w = &method.weighting;
            let value = w.apply(&[f.value]);
            Flux {
                regular: value.clone(),
                value,
                error: (0..k).map(|c| w.component_error(c, &[f.error])).collect(),
                data_uncertainty: Some((0..k).map(|c| w.component_error(c, &[f.data_uncertainty])).collect()),
                seconds: start.elapsed().as_secs_f64(),
                ..Flux::zero(k)
            }
        }
        Err(why) => Flux { value: vec![f64::NAN; k], converged: false, refused: Some(why), ..Flux::zero(k) },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The queue of `Plan::run_all` starts with the integrals `Method::expected_evaluations` ranks first; on
    /// the batch bench's narrowest recipe the guess must rank the integrals as their actual costs do at the
    /// ends: its first two are the two that cost most (in either order), and the six that cost least are
    /// guessed at under an eighth of the first (so the milliseconds start first and the microseconds end the
    /// queue; the unsplit boxes' estimate rule of `docs/accuracy.md` §5.2 made one 3 334-guess integral cost
    /// 1 026, among the six, at 0.115 of the first).
    #[test]
    fn the_expected_cost_ranks_a_narrow_lobes_integrals_as_they_cost() {
        let text = r#"{"model": "microfacet", "distribution": "beckmann", "roughness": 0.02, "ior": 1.5}"#;
        let m = crate::recipe::parse_str(text, "narrow.json").unwrap();
        let geos = crate::resolve_geometries(crate::DEFAULT_PANEL, &[] as &[&str]).unwrap();
        let plan = Plan::compile(m.brdf, geos, PlanOptions { rtol: 1e-6, ..Default::default() }).unwrap();
        let run = plan.run();
        let jobs = plan.specimen_jobs();
        let rank = |key: &dyn Fn(usize) -> f64| {
            let mut v = jobs.clone();
            v.sort_by(|&a, &b| key(b).total_cmp(&key(a)).then(a.cmp(&b)));
            v
        };
        let expected = rank(&|j| plan.jobs[j].method.expected_evaluations());
        let actual = rank(&|j| run.fluxes[j].evaluations as f64);
        assert!(jobs.len() >= 12, "{} specimen integrals", jobs.len());
        let top = |v: &[usize]| -> Vec<usize> {
            let mut t = v[..2].to_vec();
            t.sort();
            t
        };
        assert_eq!(top(&expected), top(&actual), "expected order {expected:?}, actual {actual:?}");
        let guess = |j: usize| plan.jobs[j].method.expected_evaluations();
        for &j in &actual[actual.len() - 6..] {
            assert!(guess(j) < 0.125 * guess(expected[0]), "job {j}: {} against {}", guess(j), guess(expected[0]));
        }
    }
}
