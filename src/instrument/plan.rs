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
use std::collections::{BTreeMap, HashMap};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock, PoisonError};

use rayon::prelude::*;

use crate::brdf::{Brdf, Lobe, Tail, Term, TermKind};
use crate::colorimetry::weighting::{Weighting, WeightingKind};
use crate::colorimetry::{cielab, Conditions};
use crate::instrument::flux::{lobe_widths_uv, Chart, Flux, DELTA_SHARE};
use crate::instrument::geometry::{Integral, Stop};
pub use crate::instrument::method::Target;
use crate::instrument::method::{
    Design, Method, Projection, Rule, TensorChart, DELTA_FIT_RADIUS, DELTA_RADII, DELTA_RADIUS, DELTA_SAFETY,
    DELTA_TAIL_SAFETY, DELTA_T_ORDERS, LOBE_LEVELS, LOBE_REACH, POLAR_LEVELS, POLAR_REACH, TENSOR_MAX_LEVEL,
};
use crate::instrument::reading::{ColourQuantity, ReadingSpec, Scale};
use crate::instrument::standards::{self, StandardGeometry};
use crate::quadrature::{tensor, Refine};
use crate::spectrum::Sampling;
use crate::{Error, Result};

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

/// The default wall-clock budget of one execution of a plan (all its aperture integrals together, run in
/// parallel), seconds: far above what any shipped fixture needs (the golden suite of 396 readings runs in
/// about a second), and short enough that the default panel of any valid input ends within 10 s of wall
/// time (issue 8; with `method::LATE_START_SHARE`, ≤ 1.3 × 6 s on 2 threads, ≤ 1.6 × on one). An integral
/// that hits it reports its best estimate, not converged.
pub const DEFAULT_MAX_SECONDS: f64 = 6.0;

/// Knobs of the planner. The defaults are what `measure` uses; the others exist to measure what each
/// optimisation saves (`docs/performance.md`).
#[derive(Clone, Debug, PartialEq)]
pub struct PlanOptions {
    /// Relative tolerance of every reading.
    pub rtol: f64,
    /// Apply the spectral weighting in the integrand (k components) rather than after integrating every
    /// sample (n components).
    pub fold_spectral: bool,
    /// With `fold_spectral`, let a material that can sum a luminous-only flux's samples itself do so
    /// (`Brdf::eval_batch_folded`: the paint's folded flake tables); off, the integrand weights the n
    /// samples the material returns (kept to measure what it saves, `docs/performance.md`).
    pub fold_in_material: bool,
    /// Compute each distinct flux once.
    pub share_fluxes: bool,
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
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            rtol: 1e-6,
            fold_spectral: true,
            fold_in_material: true,
            share_fluxes: true,
            max_evals: 50_000_000,
            max_seconds: Some(DEFAULT_MAX_SECONDS),
            colour: Conditions::default(),
        }
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

/// A computed reading. `value` is None when no finite value exists (then `problem` says why): a NaN or
/// an infinity is never reported as a reading.
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

fn shape(m: &dyn Brdf) -> Shape {
    let kinds = m
        .terms()
        .iter()
        .map(|t| match t.kind {
            TermKind::Delta => 0,
            TermKind::Diffuse => 1,
            TermKind::Lobe(_) => 2,
        })
        .collect();
    Shape { sampling: m.sampling().clone(), kinds }
}

/// The compiled plan.
#[derive(Clone)]
pub struct Plan {
    pub material: Arc<dyn Brdf>,
    pub options: PlanOptions,
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
    /// X, Y, Z of the perfect reflecting diffuser under the colour conditions, from the material's own grid
    /// (the row sums of its weights, so a white diffuser reads L* = 100 exactly); None without colour readings.
    white_point: Option<(Conditions, [f64; 3])>,
}

/// The identity of a job for sharing: every input of its design, as bits.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct JobKey(Vec<u64>);

fn job_key(
    target: Target,
    integral: Integral,
    theta: f64,
    viewing: f64,
    scale: Scale,
    source: Stop,
    receptor: Stop,
) -> JobKey {
    let (kind, half_angle) = match integral {
        Integral::Aperture => (0, 0.0),
        Integral::Hemisphere => (1, 0.0),
        Integral::Port { half_angle } => (2, half_angle),
    };
    let mut k = vec![target as u64, theta.to_bits(), kind, half_angle.to_bits(), viewing.to_bits()];
    if target == Target::Standard {
        k.extend(scale.key());
    }
    for s in [source, receptor] {
        k.extend([s.p[0], s.p[1], s.q[0], s.q[1]].iter().map(|x| x.to_bits()));
    }
    JobKey(k)
}

/// A job before its method is designed.
struct Draft {
    target: Target,
    integral: Integral,
    theta: f64,
    viewing: f64,
    /// The weightings of the readings that use it (each once, sorted: the job's k × n matrix stacks them).
    kinds: Vec<WeightingKind>,
    /// The smallest perfect-diffuser flux of the colour readings that use it (their absolute floor).
    colour_white: Option<f64>,
    scale: Scale,
    source: Stop,
    receptor: Stop,
    used_by: Vec<String>,
}

/// A long-lived planner: the builtin geometries parsed once, and the gloss standards' fluxes (which do not
/// depend on the material) cached across the plans it compiles, for sweeps, fitting and bindings. It is
/// `Sync`: plans can be compiled from several threads. The cache is keyed by every input of the standard's
/// method (θ, index, stops, tolerance, budget), so a cached flux is the same bits as a recomputed one.
pub struct Planner {
    /// Every builtin geometry (gloss, then colour), copied on first use only: a planner that only compiles
    /// plans never needs them (the geometries come resolved), and `geometry` borrows the per-process parse.
    builtin: std::sync::OnceLock<Vec<StandardGeometry>>,
    standards: Mutex<HashMap<JobKey, Flux>>,
}

impl Planner {
    /// A planner; the builtin gloss and colour geometries are parsed (once per process) and checked here, so
    /// a builtin file that does not parse is this error rather than a missing geometry later.
    pub fn new() -> Result<Planner> {
        standards::builtin_static()?;
        Ok(Planner { builtin: std::sync::OnceLock::new(), standards: Mutex::new(HashMap::new()) })
    }

    /// The builtin geometries: gloss, then colour (`standards::builtin_all`); a parse error is returned, never
    /// swallowed into an empty list (`Planner::new` has already checked both sets).
    pub fn builtin(&self) -> Result<&[StandardGeometry]> {
        if let Some(all) = self.builtin.get() {
            return Ok(all);
        }
        let all = standards::builtin_all()?;
        Ok(self.builtin.get_or_init(|| all))
    }

    /// The builtin geometry with this id (`standards::find`); an unknown id is a usage error listing the known
    /// ids.
    pub fn geometry(&self, id: &str) -> Result<StandardGeometry> {
        standards::find(id)
    }

    /// Number of gloss-standard fluxes cached.
    pub fn cached_standards(&self) -> usize {
        self.standards.lock().map(|c| c.len()).unwrap_or(0)
    }

    /// Compile a plan for `material` and the geometries (builtin ids resolved by the caller, or user files).
    pub fn compile(
        &self,
        material: Arc<dyn Brdf>,
        geometries: Vec<StandardGeometry>,
        options: PlanOptions,
    ) -> Result<Plan> {
        if !(options.rtol.is_finite() && options.rtol > 0.0 && options.rtol < 1.0) {
            return Err(Error::Usage(format!(
                "the relative tolerance (rtol) must be a number in (0, 1), got {}",
                crate::error::given(options.rtol)
            )));
        }
        if options.rtol < MIN_RTOL {
            return Err(Error::Usage(format!(
                "the relative tolerance (rtol) {} is below {MIN_RTOL:e}, the tightest that double precision can \
                 reach here (below it the error estimates are rounding noise and the work never ends)",
                crate::error::given(options.rtol)
            )));
        }
        if options.max_seconds.is_some_and(|s| !(s.is_finite() && s > 0.0)) || options.max_evals == 0 {
            return Err(Error::Usage(format!(
                "the budgets must be positive: max_evals {}, max_seconds {:?}",
                options.max_evals, options.max_seconds
            )));
        }
        if geometries.is_empty() {
            return Err(Error::Usage("no geometry to measure".into()));
        }
        // Requested geometries first, then the dependencies of composites.
        let mut queue: Vec<(StandardGeometry, bool)> = geometries.into_iter().map(|g| (g, true)).collect();
        let mut i = 0;
        while i < queue.len() {
            let parts: Vec<String> = queue[i]
                .0
                .geometry
                .readings
                .iter()
                .filter_map(|spec| match spec {
                    ReadingSpec::HazeIndex { minuend, subtrahend } => Some([minuend.clone(), subtrahend.clone()]),
                    _ => None,
                })
                .flatten()
                .collect();
            for id in parts {
                if !queue.iter().any(|(q, _)| q.geometry.id == id) {
                    queue.push((self.geometry(&id)?, false));
                }
            }
            i += 1;
        }
        // The spectral weighting: the kinds the readings ask for, each once, in order of first use.
        let colour = options.colour;
        let kinds: Vec<WeightingKind> =
            queue.iter().flat_map(|(g, _)| g.geometry.readings.iter().map(|r| r.weighting(colour))).collect();
        let weighting = Weighting::stack(&kinds, material.sampling()).map_err(|e| {
            let ids: Vec<&str> =
                queue.iter().filter(|(g, _)| g.geometry.is_colour()).map(|(g, _)| g.geometry.id.as_str()).collect();
            match e {
                Error::Usage(m) if !ids.is_empty() => Error::Usage(format!("{}: {m}", ids.join(", "))),
                e => e,
            }
        })?;
        let mut drafts: Vec<Draft> = Vec::new();
        let mut readings: Vec<PlannedReading> = Vec::new();
        let mut index: HashMap<JobKey, usize> = HashMap::new();
        for (g, reported) in &queue {
            add_geometry(g, *reported, colour, options.share_fluxes, &mut drafts, &mut readings, &mut index)?;
        }
        // Composites: resolve their parts now that every gloss reading exists.
        for r in 0..readings.len() {
            if let ReadingSpec::HazeIndex { minuend, subtrahend } = readings[r].spec.clone() {
                let mut parts = Vec::new();
                for id in [&minuend, &subtrahend] {
                    let part = readings
                        .iter()
                        .position(|x| &x.geometry == id && matches!(x.spec, ReadingSpec::Gloss { .. }))
                        .ok_or_else(|| {
                            Error::Usage(format!("{}: geometry `{id}` has no gloss reading", readings[r].geometry))
                        })?;
                    parts.push(part);
                }
                readings[r].parts = parts;
            }
        }

        // Step 1a: the standards' methods, executed now (cached across plans).
        let standard_weighting = Weighting::luminous(&Sampling::grey())?;
        let standard_method = |d: &Draft| {
            Method::design(Design {
                target: Target::Standard,
                integral: d.integral,
                theta: d.theta,
                viewing: d.viewing,
                source: d.source,
                receptor: d.receptor,
                lobes: &[],
                kinks: &[],
                has_delta: true,
                has_regular: false,
                has_diffuse: false,
                weighting: standard_weighting.clone(),
                projection: Projection::Fold,
                rtol: STANDARD_SHARE * options.rtol,
                atol: 0.0,
                max_evals: options.max_evals,
                max_seconds: options.max_seconds,
            })
        };
        let std_idx: Vec<usize> = (0..drafts.len()).filter(|&j| drafts[j].target == Target::Standard).collect();
        let std_methods: Vec<Method> = std_idx.iter().map(|&j| standard_method(&drafts[j])).collect();
        let std_drafts: Vec<&Draft> = std_idx.iter().map(|&j| &drafts[j]).collect();
        let std_flux = self.standard_fluxes(&std_drafts, &std_methods, &options);
        // Absolute floor per geometry angle: 1e-4·rtol of the largest standard flux at that angle, i.e.
        // 0.01·rtol GU on a gloss reading; it only matters for fluxes that are (nearly) zero. A colour flux's
        // floor is 1e-4·rtol of the perfect diffuser's Y flux (100·white), 0.01·rtol on X, Y, Z; a flux that
        // both use gets the smaller.
        let floor = |theta: f64| -> f64 {
            let m = std_idx
                .iter()
                .zip(&std_flux)
                .filter(|(&j, _)| drafts[j].theta == theta)
                .map(|(_, f)| f.value[0])
                .fold(0.0, f64::max);
            1e-4 * options.rtol * m
        };
        let specimen_floor = |d: &Draft| -> f64 {
            let gloss = d.kinds.contains(&WeightingKind::Luminous).then(|| floor(d.theta));
            let colour = d.colour_white.map(|w| 1e-2 * options.rtol * w);
            match (gloss, colour) {
                (Some(a), Some(b)) => a.min(b),
                (a, b) => a.or(b).unwrap_or(0.0),
            }
        };

        // Step 1b: the specimen's methods.
        let terms = material.terms();
        let lobes: Vec<Lobe> = material.lobes();
        let kinks = material.kinks();
        let has_delta = material.has_delta();
        let has_regular = material.has_regular();
        let has_diffuse = terms.iter().any(|t| t.kind == TermKind::Diffuse);
        let projection = match (options.fold_spectral, options.fold_in_material) {
            (false, _) => Projection::Separate,
            (true, false) => Projection::Fold,
            (true, true) => Projection::FoldInMaterial,
        };
        let mut jobs = Vec::with_capacity(drafts.len());
        let mut standard_flux = vec![None; drafts.len()];
        let mut std_results = std_methods.into_iter().zip(std_flux.iter().cloned());
        for (j, d) in drafts.iter().enumerate() {
            let method = match d.target {
                Target::Standard => {
                    let (m, f) = std_results.next().expect("one standard method per standard job");
                    standard_flux[j] = Some(f);
                    m
                }
                Target::Specimen => Method::design(Design {
                    target: Target::Specimen,
                    integral: d.integral,
                    theta: d.theta,
                    viewing: d.viewing,
                    source: d.source,
                    receptor: d.receptor,
                    lobes: &lobes,
                    kinks: &kinks,
                    has_delta,
                    has_regular,
                    has_diffuse,
                    // Only the kinds of the readings that use this flux: a gloss flux stays one luminous
                    // component (and the same bits) whatever colour readings share the plan.
                    weighting: Weighting::stack(&d.kinds, material.sampling())?,
                    projection,
                    rtol: SPECIMEN_SHARE * options.rtol,
                    atol: specimen_floor(d),
                    max_evals: options.max_evals,
                    max_seconds: options.max_seconds,
                }),
            };
            jobs.push(Job { method, scale: d.scale, used_by: d.used_by.clone() });
        }
        let shape = shape(material.as_ref());
        let white_point = match weighting.parts.iter().any(|(k, _)| matches!(k, WeightingKind::Xyz(_))) {
            true => Some((options.colour, crate::colorimetry::weights(material.sampling(), options.colour)?.white)),
            false => None,
        };
        Ok(Plan {
            white_point,
            material,
            options,
            geometries: queue.into_iter().map(|(g, _)| g).collect(),
            jobs,
            readings,
            weighting,
            terms,
            shape,
            standard_flux,
        })
    }

    /// The fluxes of the gloss standards, from the cache or computed (and cached): the cache is read once,
    /// under one lock, and only the fluxes it lacks are computed, in parallel (in a batch every plan after
    /// the first finds them all, and then hands nothing to the pool). With sharing off, always computed (the
    /// ablation measures what sharing saves).
    fn standard_fluxes(&self, drafts: &[&Draft], methods: &[Method], options: &PlanOptions) -> Vec<Flux> {
        let compute = |d: &Draft, m: &Method| m.execute(&d.scale.standard());
        if !options.share_fluxes {
            return drafts.par_iter().zip(methods).map(|(d, m)| compute(d, m)).collect();
        }
        let keys: Vec<JobKey> = drafts
            .iter()
            .map(|d| {
                let mut key = job_key(Target::Standard, d.integral, d.theta, d.viewing, d.scale, d.source, d.receptor);
                key.0.extend([options.rtol.to_bits(), options.max_evals as u64]);
                key.0.extend(options.max_seconds.map(f64::to_bits));
                key
            })
            .collect();
        let mut flux: Vec<Option<Flux>> = match self.standards.lock() {
            Ok(c) => keys.iter().map(|k| c.get(k).cloned()).collect(),
            Err(_) => vec![None; keys.len()],
        };
        let missing: Vec<usize> = (0..keys.len()).filter(|&i| flux[i].is_none()).collect();
        if !missing.is_empty() {
            let computed: Vec<Flux> = missing.par_iter().map(|&i| compute(drafts[i], &methods[i])).collect();
            let mut cache = self.standards.lock().ok();
            for (&i, f) in missing.iter().zip(computed) {
                if let Some(c) = cache.as_mut() {
                    c.insert(keys[i].clone(), f.clone());
                }
                flux[i] = Some(f);
            }
        }
        flux.into_iter().map(|f| f.expect("every standard computed")).collect()
    }
}

/// Add the readings of one geometry and the drafts of the jobs they need (shared by key when `share`).
fn add_geometry(
    sg: &StandardGeometry,
    reported: bool,
    colour: Conditions,
    share: bool,
    drafts: &mut Vec<Draft>,
    readings: &mut Vec<PlannedReading>,
    index: &mut HashMap<JobKey, usize>,
) -> Result<()> {
    let g = &sg.geometry;
    for (ri, spec) in g.readings.iter().enumerate() {
        let name = sg.reading_names.get(ri).cloned().unwrap_or_else(|| spec.quantity().to_string());
        let (spec_rx, std_rx): (Vec<&String>, Vec<&String>) = match spec {
            ReadingSpec::Gloss { receptor } => (vec![receptor], vec![receptor]),
            ReadingSpec::Profile { receptor, reference } => (vec![receptor], vec![reference]),
            ReadingSpec::Haze { receptors, specular } | ReadingSpec::LogHaze { receptors, specular, .. } => {
                (receptors.iter().collect(), vec![specular])
            }
            ReadingSpec::HazeCompensated { receptors, specular, compensation, .. }
            | ReadingSpec::LogHazeCompensated { receptors, specular, compensation, .. } => {
                (receptors.iter().chain(std::iter::once(compensation)).collect(), vec![specular])
            }
            ReadingSpec::Doi { specular, offset } => (std::iter::once(specular).chain(offset.iter()).collect(), vec![]),
            ReadingSpec::HazeIndex { .. } => (vec![], vec![]),
            ReadingSpec::Colour { terms, .. } => (terms.iter().map(|(n, _)| n).collect(), vec![]),
        };
        let kind = spec.weighting(colour);
        let colour_white = match spec {
            ReadingSpec::Colour { white, .. } => Some(*white),
            _ => None,
        };
        let mut pr = PlannedReading {
            geometry: g.id.clone(),
            name,
            spec: spec.clone(),
            specimen_jobs: BTreeMap::new(),
            standard_jobs: BTreeMap::new(),
            kind,
            parts: vec![],
            reported,
        };
        for (names, target) in [(spec_rx, Target::Specimen), (std_rx, Target::Standard)] {
            for rx in names {
                // A named sphere integral, or an aperture integral through a receptor stop.
                let (integral, viewing, source, stop) = match g.integral(rx) {
                    Some(i) => (i, g.theta, Stop { p: [0.0; 2], q: [0.0; 2] }, Stop { p: [0.0; 2], q: [0.0; 2] }),
                    None => {
                        let stop = *g.receptor(rx).ok_or_else(|| {
                            Error::Usage(format!("{}: reading `{}` names unknown receptor `{rx}`", g.id, pr.name))
                        })?;
                        (Integral::Aperture, g.viewing, g.source, stop)
                    }
                };
                let key = job_key(target, integral, g.theta, viewing, g.scale, source, stop);
                let used = format!("{}/{rx}", g.id);
                let job_kind = if target == Target::Standard { WeightingKind::Luminous } else { kind };
                let j = match index.get(&key) {
                    Some(&i) if share => {
                        if !drafts[i].used_by.contains(&used) {
                            drafts[i].used_by.push(used);
                        }
                        let d = &mut drafts[i];
                        if !d.kinds.contains(&job_kind) {
                            d.kinds.push(job_kind);
                            d.kinds.sort();
                        }
                        if let Some(w) = colour_white {
                            d.colour_white = Some(d.colour_white.map_or(w, |x| x.min(w)));
                        }
                        i
                    }
                    _ => {
                        drafts.push(Draft {
                            target,
                            integral,
                            theta: g.theta,
                            viewing,
                            kinds: vec![job_kind],
                            colour_white,
                            scale: g.scale,
                            source,
                            receptor: stop,
                            used_by: vec![used],
                        });
                        index.insert(key, drafts.len() - 1);
                        drafts.len() - 1
                    }
                };
                match target {
                    Target::Specimen => pr.specimen_jobs.insert(rx.clone(), j),
                    Target::Standard => pr.standard_jobs.insert(rx.clone(), j),
                };
            }
        }
        readings.push(pr);
    }
    Ok(())
}

impl Plan {
    /// Compile a plan with a fresh [`Planner`] (use one long-lived planner to share its caches).
    pub fn compile(material: Arc<dyn Brdf>, geometries: Vec<StandardGeometry>, options: PlanOptions) -> Result<Plan> {
        Planner::new()?.compile(material, geometries, options)
    }

    /// The same plan (the same methods, partitions included, and the same standards' fluxes) for another
    /// material of the same shape: the same spectral sampling and the same kinds of terms in the same order.
    /// The split points stay those of the material the plan was compiled for: right for a nearby material
    /// (a fitter's step, a sweep's neighbour); for a very different one compile a new plan.
    pub fn with_material(&self, material: Arc<dyn Brdf>) -> Result<Plan> {
        let s = shape(material.as_ref());
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
        p.material = material;
        Ok(p)
    }

    /// Whether every specimen method is frozen.
    pub fn is_frozen(&self) -> bool {
        self.jobs.iter().all(|j| j.method.target == Target::Standard || j.method.is_frozen())
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
            .map(|&j| self.jobs[j].method.execute_and_freeze_until(self.material.as_ref(), deadline))
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
        self.options.max_seconds.map(|s| std::time::Instant::now() + std::time::Duration::from_secs_f64(s))
    }

    /// Execute the plan: every specimen method on the material (the standards' fluxes were computed when the
    /// plan was compiled), then the readings. The specimen integrals share one wall-clock deadline.
    pub fn execute(&self) -> Vec<Reading> {
        self.run().readings
    }

    /// [`Plan::execute`], keeping the flux of every integral with the readings: what the whole plan cost
    /// ([`Execution::evaluations`], each distinct integral counted once).
    pub fn run(&self) -> Execution {
        let deadline = self.deadline();
        let todo = self.specimen_jobs();
        let computed: Vec<Flux> =
            todo.par_iter().map(|&j| self.jobs[j].method.execute_until(self.material.as_ref(), deadline)).collect();
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
                let f = plan.jobs[j].method.execute_until(plan.material.as_ref(), deadline);
                let complete = {
                    let mut slot = pending[p].lock().unwrap_or_else(PoisonError::into_inner);
                    slot.1[j] = Some(f);
                    slot.0 -= 1;
                    (slot.0 == 0).then(|| std::mem::take(&mut slot.1))
                };
                if let Some(flux) = complete {
                    let _ = done[p].set(plan.execution(flux));
                }
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

    /// The execution from the flux of every job (the standards' and the computed ones).
    fn execution(&self, flux: Vec<Option<Flux>>) -> Execution {
        let fluxes: Vec<Flux> = flux.into_iter().map(|f| f.expect("every job ran")).collect();
        Execution { readings: self.readings_from(&fluxes), fluxes }
    }

    /// The jobs to run on the material, in plan order. Only these go to the thread pool: a plan with one
    /// specimen integral runs it on the calling thread (rayon runs a one-item parallel iterator in place),
    /// which spares a one-off small plan the hand-over to the pool and back (tens of µs).
    fn specimen_jobs(&self) -> Vec<usize> {
        (0..self.jobs.len()).filter(|&j| self.standard_flux[j].is_none()).collect()
    }

    /// The fluxes known before execution: the standards', by job index.
    fn known_fluxes(&self) -> Vec<Option<Flux>> {
        self.standard_flux.clone()
    }

    /// The readings from the fluxes of every job. Direct readings first, then composites, which combine
    /// direct readings (their parts may come later in plan order when the user asked for the composite
    /// before its parts, or only for it).
    fn readings_from(&self, flux: &[Flux]) -> Vec<Reading> {
        let mut out: Vec<Option<Reading>> = vec![None; self.readings.len()];
        for (i, r) in self.readings.iter().enumerate() {
            if r.parts.is_empty() {
                out[i] = Some(compute_reading(r, flux, &self.jobs, self.white_point));
            }
        }
        for (i, r) in self.readings.iter().enumerate() {
            if !r.parts.is_empty() {
                out[i] = Some(compose_reading(r, &out));
            }
        }
        out.into_iter()
            .zip(&self.readings)
            .filter(|(_, p)| p.reported)
            .map(|(r, _)| r.expect("every reading computed"))
            .collect()
    }

    /// The plan in plain words: the stored methods, printed (nothing is worked out again here).
    pub fn explain(&self) -> String {
        let m = &self.material;
        let mut s = String::new();
        s.push_str(&format!("Material: {}\n", m.describe()));
        s.push_str(&format!("Spectral samples: {}\n", m.sampling().describe()));
        let projection = self.jobs.iter().find(|j| j.method.target == Target::Specimen).map(|j| j.method.projection);
        s.push_str(&format!(
            "Spectral weighting: {} ({} component(s) per flux, from {} sample(s)); {}\n",
            self.weighting.describe(),
            self.weighting.len(),
            m.sampling().len(),
            match projection {
                Some(Projection::Fold) | None =>
                    "applied in the integrand, so each aperture integral has one component per weighted quantity",
                Some(Projection::FoldInMaterial) => {
                    let row = Weighting::luminous(m.sampling()).ok().and_then(|w| w.rows.into_iter().next());
                    if row.is_some_and(|r| m.folds(&r)) {
                        "applied in the integrand, so each aperture integral has one component per weighted \
                         quantity; a luminous-only integral has the material sum its samples itself (folded tables)"
                    } else {
                        "applied in the integrand, so each aperture integral has one component per weighted quantity"
                    }
                }
                Some(Projection::Separate) => "folding off: each sample is integrated separately, then weighted",
            }
        ));
        s.push_str("Terms of the material, and how each is integrated:\n");
        for t in &self.terms {
            let how = match &t.kind {
                TermKind::Delta => {
                    "ideal mirror: analytic in the lobe variables, a 2-D integral over the stops' mirror overlap"
                        .to_string()
                }
                TermKind::Diffuse => "smooth in direction: no lobe splits needed".to_string(),
                TermKind::Lobe(l) => format!(
                    "glossy lobe, slope width {:.3e}{}{}: lobe variables split at 0 and ±(1, 3, 10, 30, …)× its width, \
                     {}",
                    l.slope_width,
                    if l.medium_eta != 1.0 { format!(" inside a medium of index {}", l.medium_eta) } else { String::new() },
                    match l.tail {
                        Tail::Table { half_width } if half_width.is_finite() => format!(
                            ", a measured table's tail (its own half width at half maximum {half_width:.3e}, kinks at \
                             its cells; the partition)"
                        ),
                        Tail::Table { .. } => format!(
                            ", a measured table's tail (it does not fall to half within {}° of tilt; kinks at its \
                             cells; the partition)",
                            crate::measured::table::HALF_WIDTH_MAX_TILT_DEG
                        ),
                        t if t.is_heavy() => ", heavy tail".to_string(),
                        _ => String::new(),
                    },
                    if l.tail.is_heavy() { "out to the ends of the range" } else { "out to 10× its width (Gaussian tail)" }
                ),
            };
            s.push_str(&format!("  - {}: {how}\n", t.label));
        }
        s.push_str("  Terms the material does not have are not built and cost nothing.\n");
        let lobes: Vec<&Lobe> = self
            .terms
            .iter()
            .filter_map(|t| match &t.kind {
                TermKind::Lobe(l) => Some(l),
                _ => None,
            })
            .collect();
        for g in &self.geometries {
            let geo = &g.geometry;
            if geo.is_composite() {
                s.push_str(&format!(
                    "Geometry {} ({}): combines other geometries' gloss readings\n",
                    geo.id, geo.title
                ));
                continue;
            }
            if geo.is_colour() {
                s.push_str(&format!(
                    "Geometry {} ({}): colour, X, Y, Z under {} relative to the perfect reflecting diffuser \
                     (the spectral dimension is not folded into one luminous component: three components per \
                     flux), then L*, a*, b*, C*, h\n",
                    geo.id,
                    geo.title,
                    self.options.colour.describe()
                ));
                continue;
            }
            s.push_str(&format!(
                "Geometry {} ({}), θ = {:.4}°, standard: {}\n",
                geo.id,
                geo.title,
                geo.theta.to_degrees(),
                geo.scale.describe()
            ));
            for l in &lobes {
                let w = lobe_widths_uv(l, geo.theta);
                s.push_str(&format!(
                    "  lobe '{}' is {:.3e} × {:.3e} wide in the lobe variables (u, v)\n",
                    l.label, w[0], w[1]
                ));
            }
        }
        let n_spec = self.jobs.iter().filter(|j| j.method.target == Target::Specimen).count();
        let n_std = self.jobs.len() - n_spec;
        let uses: usize = self.readings.iter().map(|r| r.specimen_jobs.len() + r.standard_jobs.len()).sum();
        s.push_str(&format!(
            "Aperture integrals: {} on the specimen, {} on gloss standards ({} uses by {} readings{})\n",
            n_spec,
            n_std,
            uses,
            self.readings.len(),
            if self.options.share_fluxes {
                "; each distinct integral computed once and shared"
            } else {
                "; sharing off"
            }
        ));
        for (i, j) in self.jobs.iter().enumerate() {
            let viewing = if j.method.viewing != j.method.theta {
                format!(", receptor axis {:.4}° (off specular: no mirror image)", j.method.viewing.to_degrees())
            } else {
                String::new()
            };
            s.push_str(&format!(
                "  #{i}: {:?} at {:.4}°{viewing}, {} component(s), {}; used by {}\n",
                j.method.target,
                j.method.theta.to_degrees(),
                j.method.weighting.len(),
                describe_method(&j.method, &self.terms),
                j.used_by.join(", ")
            ));
        }
        s.push_str("Readings, from the integrals above:\n");
        for r in self.readings.iter().filter(|r| r.reported) {
            let jobs = |m: &BTreeMap<String, usize>| m.iter().map(|(n, j)| format!("{n} #{j}")).collect::<Vec<_>>();
            let extra = match &r.spec {
                ReadingSpec::HazeCompensated { compensation, factor, .. }
                | ReadingSpec::LogHazeCompensated { compensation, factor, .. } => {
                    format!("; minus {factor:.6} × {compensation} (ratio of projected solid angles)")
                }
                _ => String::new(),
            };
            s.push_str(&format!(
                "  {}/{} ({}): specimen {}; standard {}{extra}\n",
                r.geometry,
                r.name,
                r.spec.quantity(),
                if r.specimen_jobs.is_empty() { "—".to_string() } else { jobs(&r.specimen_jobs).join(", ") },
                if r.standard_jobs.is_empty() { "—".to_string() } else { jobs(&r.standard_jobs).join(", ") },
            ));
        }
        s.push_str(&format!(
            "Tolerance: relative {:e} on every reading; {} of it to each specimen flux ({} of that to its analytic \
             part), {} to the gloss standard.\n",
            self.options.rtol, SPECIMEN_SHARE, DELTA_SHARE, STANDARD_SHARE
        ));
        s
    }
}

/// One method in words, from its stored fields.
fn describe_method(m: &Method, terms: &[Term]) -> String {
    match m.integral {
        Integral::Hemisphere => {
            return "d/8 sphere: directional–hemispherical reflectance at the viewing angle per sample (brdf::albedo of \
                    the transposed BRDF, Gauss–Kronrod in half-vector coordinates), delta included, then weighted"
                .to_string()
        }
        Integral::Port { half_angle } => {
            return format!(
                "d/8 specular port: delta + ∫ f cos θ dω over a {:.1}° cone about the mirror of the viewing \
                 direction per sample (Genz–Malik, polar tangent coordinates), then weighted",
                half_angle.to_degrees()
            )
        }
        Integral::Aperture => {}
    }
    if m.clipped.is_none() {
        return "stops below the horizon: zero".to_string();
    }
    let material_has_delta = m.target == Target::Standard || terms.iter().any(|t| t.kind == TermKind::Delta);
    let frozen = |r: Refine| if r == Refine::Frozen { ", frozen" } else { "" };
    let delta = match (&m.delta, material_has_delta, m.mirror.is_some()) {
        (Some(p), _, _) => format!(
            "analytic delta{} ({} box{})",
            describe_kinks(&p.kinks, "p cut along cos θi = cos θc"),
            p.cells.len(),
            frozen(p.refine)
        ),
        (None, true, false) => "no mirror image in this stop (delta skipped)".to_string(),
        _ => String::new(),
    };
    let regular = m.regular.as_ref().map(|p| {
        let chart = match p.chart {
            Chart::Plain => "plain variables (no lobe narrower than the stops)".to_string(),
            Chart::Lobe => format!(
                "lobe variables, {} × {} split points{}",
                p.splits[0].len(),
                p.splits[1].len(),
                describe_kinks(&p.kinks, "t_p cut along ωi·h = cos θc")
            ),
        };
        let rule = match p.rule {
            Rule::GenzMalik75 => format!("Genz–Malik 7/5 on {} initial box(es)", p.cells.len()),
            Rule::LobeGaussHermite { width, levels } => format!(
                "Gauss–Hermite in (u, v) scaled to the lobe ({:.3e} × {:.3e}) × Gauss–Legendre in (t_p, t_q), \
                 orders {} raised until two successive agree (the lobe is ≥ {} widths from every overlap kink; \
                 fallback: Genz–Malik 7/5 on {} initial box(es))",
                width[0],
                width[1],
                LOBE_LEVELS[levels.0..=levels.1]
                    .iter()
                    .map(|(h, l)| format!("{h}²×{l}²"))
                    .collect::<Vec<_>>()
                    .join(" → "),
                LOBE_REACH,
                p.cells.len()
            ),
            Rule::LobeDelta { width } => format!(
                "delta limit of the lobe ({:.3e} × {:.3e}): per Gauss–Legendre node of (t_p, t_q) ({}²), the mass \
                 π·F(0)/√det B from the lobe's curvature B on a ring of {} width, accepted when its bound meets the \
                 tolerance: {}× the largest |h_e(x) − h(0)|/xᵀBx of the even part of h = F·e^{{xᵀBx}} on rings of \
                 {} and {:?} widths, + the tail beyond {} widths, F(0)·(e^{{−R²}} + e^{{−λR²}}/λ) with λ the lobe's \
                 decay rate there ÷ {}, + the t rule's difference from {}² nodes (the lobe is ≥ {} widths from every \
                 overlap kink; else Gauss–Hermite orders {}, then Genz–Malik 7/5 on {} initial box(es))",
                width[0],
                width[1],
                DELTA_T_ORDERS.1,
                DELTA_FIT_RADIUS,
                DELTA_SAFETY,
                DELTA_FIT_RADIUS,
                DELTA_RADII,
                DELTA_RADIUS,
                DELTA_TAIL_SAFETY,
                DELTA_T_ORDERS.0,
                LOBE_REACH,
                LOBE_LEVELS.iter().map(|(h, l)| format!("{h}²×{l}²")).collect::<Vec<_>>().join(" → "),
                p.cells.len()
            ),
            Rule::LobePolar { width, u, v, levels } => describe_polar(width, u, v, levels, p.cells.len()),
            Rule::TensorGauss { chart, levels, path } => describe_tensor(chart, levels, path, p.cells.len()),
        };
        format!("{chart}, {rule}{}", frozen(p.refine))
    });
    match (delta.is_empty(), regular) {
        (true, None) => "nothing to integrate: zero".to_string(),
        (false, None) if m.delta.is_none() => format!("{delta} and no regular part: zero"),
        (false, None) => format!("{delta} only"),
        (true, Some(r)) => r,
        (false, Some(r)) => format!("{delta} + {r}"),
    }
}

/// [`Rule::LobePolar`] in words: the pieces, their rules, the levels (the designed ones, or a frozen method's).
fn describe_polar(width: [f64; 2], u: [f64; 4], v: [f64; 4], levels: [u8; 9], boxes: usize) -> String {
    let holds = |b: &[f64; 4], i: usize| b[i] < 0.0 && b[i + 1] > 0.0;
    let mut tails = 0;
    let mut central = 1;
    let mut tail_levels = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            if !(u[i + 1] > u[i] && v[j + 1] > v[j]) {
                continue;
            }
            if holds(&u, i) && holds(&v, j) {
                central = levels[3 * i + j];
            } else {
                tails += 1;
                tail_levels.push(levels[3 * i + j].to_string());
            }
        }
    }
    format!(
        "polar variables about the specular point in the kink square (x = u/{:.3e} = ρ cos φ, y = v/{:.3e} = \
         ρ sin φ, ρ = tan β for GGX's tail; Gauss–Legendre in φ per sector and in ρ, level {central} of {}) + Gauss–Legendre on \
         {tails} tail box(es) (in σ = 1/x along its tail coordinate × y = c·tan γ across it; levels {}) × Gauss–Legendre in (t_p, t_q); each piece raised until \
         the summed differences of successive levels meet the tolerance (the lobe is ≥ {} widths from every \
         overlap kink; fallback: Genz–Malik 7/5 on {boxes} initial box(es))",
        width[0],
        width[1],
        POLAR_LEVELS.len() - 1,
        if tail_levels.is_empty() { "none".to_string() } else { tail_levels.join(", ") },
        POLAR_REACH,
    )
}

/// [`Rule::TensorGauss`] in words: its boxes, its orders (the starting ones, or the final ones of a frozen
/// method's path) and its fallback.
fn describe_tensor(chart: TensorChart, levels: [usize; 4], path: tensor::Path, fallback_boxes: usize) -> String {
    let orders = path.replayed(levels, tensor::MAX_BOXES).map(|l| tensor::ORDERS[l]);
    let (vars, boxes) = match chart {
        TensorChart::Plain => ("(p_s, q_s, p_r, q_r)", "on the one box of the stops' product"),
        TensorChart::Lobe => ("(u, t_p, v, t_q)", "on the boxes between the overlap kinks of u and v"),
        TensorChart::PlainPLobeQ => ("(p_s, p_r, v, t_q)", "on the boxes between the overlap kinks of v"),
    };
    format!(
        "smooth integrand: tensor Gauss–Legendre in {vars} {boxes}, orders {} {}, per-axis orders raised \
         (up to {}) until the sum of the per-axis differences of successive orders (calibrated) meets the \
         tolerance (fallback: Genz–Malik 7/5 on {fallback_boxes} initial box(es) of the lobe variables)",
        orders.map(|o| o.to_string()).join("×"),
        if path.len > 0 { "(the highest final orders over the boxes)" } else { "to start on every box" },
        tensor::ORDERS[TENSOR_MAX_LEVEL],
    )
}

/// The kinks of a part in words: ", <how> at θc = 19.72°, …" (empty without kinks).
fn describe_kinks(kinks: &[f64], how: &str) -> String {
    if kinks.is_empty() {
        return String::new();
    }
    let angles: Vec<String> = kinks.iter().map(|c| format!("{:.4}°", c.acos().to_degrees())).collect();
    format!(", {how} (Fresnel critical angle{} θc = {})", if kinks.len() > 1 { "s" } else { "" }, angles.join(", "))
}

/// A reading with a value `(v, e)`, no problem and no note (callers override those with struct update).
fn valued_reading(
    r: &PlannedReading,
    (v, e): (f64, f64),
    evaluations: usize,
    seconds: f64,
    converged: bool,
) -> Reading {
    Reading {
        geometry: r.geometry.clone(),
        name: r.name.clone(),
        quantity: r.spec.quantity().into(),
        unit: r.spec.unit().into(),
        value: Some(v),
        error_estimate: e,
        evaluations,
        seconds,
        converged,
        problem: None,
        note: None,
    }
}

fn problem_reading(r: &PlannedReading, why: String) -> Reading {
    Reading {
        geometry: r.geometry.clone(),
        name: r.name.clone(),
        quantity: r.spec.quantity().into(),
        unit: r.spec.unit().into(),
        value: None,
        error_estimate: f64::NAN,
        evaluations: 0,
        seconds: 0.0,
        converged: false,
        problem: Some(why),
        note: None,
    }
}

/// The value and first-order error of a direct (non-composite) reading from its fluxes, each given as
/// (value, error) by receptor name: the definitions of the readings (`ReadingSpec`), in one place. Err says
/// why there is no value (a zero reference flux).
pub fn reading_value(
    spec: &ReadingSpec,
    specimen: &dyn Fn(&str) -> (f64, f64),
    standard: &dyn Fn(&str) -> (f64, f64),
) -> std::result::Result<(f64, f64), String> {
    let mean = |rxs: &[String]| -> (f64, f64) {
        let n = rxs.len() as f64;
        (rxs.iter().map(|x| specimen(x).0).sum::<f64>() / n, rxs.iter().map(|x| specimen(x).1).sum::<f64>() / n)
    };
    match spec {
        ReadingSpec::Gloss { receptor } => {
            let ((s, se), (d, de)) = (specimen(receptor), standard(receptor));
            ratio(s, se, d, de, Denominator::Standard).map(|(v, e)| (100.0 * v, 100.0 * e))
        }
        ReadingSpec::Profile { receptor, reference } => {
            let ((s, se), (d, de)) = (specimen(receptor), standard(reference));
            ratio(s, se, d, de, Denominator::Standard).map(|(v, e)| (100.0 * v, 100.0 * e))
        }
        ReadingSpec::Haze { receptors, specular } => {
            let (h, he) = mean(receptors);
            let (d, de) = standard(specular);
            ratio(h, he, d, de, Denominator::Standard).map(|(v, e)| (100.0 * v, 100.0 * e))
        }
        ReadingSpec::LogHaze { receptors, specular, k } => {
            let (h, he) = mean(receptors);
            let (d, de) = standard(specular);
            ratio(h, he, d, de, Denominator::Standard).map(|(v, e)| {
                let (h, he) = (100.0 * v, 100.0 * e);
                (k * (h / 20.0 + 1.0).log10(), k * he / (std::f64::consts::LN_10 * (h + 20.0)))
            })
        }
        ReadingSpec::HazeCompensated { receptors, specular, compensation, factor } => {
            compensated_haze(mean(receptors), specimen(compensation), *factor, standard(specular))
        }
        ReadingSpec::LogHazeCompensated { receptors, specular, compensation, factor, k } => {
            let (h, he) = compensated_haze(mean(receptors), specimen(compensation), *factor, standard(specular))?;
            if !(h > -20.0) {
                return Err(format!(
                    "the compensated linear haze {h} is at or below −20, where K·log10(H/20 + 1) has no value (the \
                     compensation receptor sees more diffuse light than the haze receptors, relative to a \
                     Lambertian body)"
                ));
            }
            Ok((k * (h / 20.0 + 1.0).log10(), k * he / (std::f64::consts::LN_10 * (h + 20.0))))
        }
        ReadingSpec::Doi { specular, offset } => {
            let (s, se) = specimen(specular);
            let (o, oe) = mean(offset);
            ratio(o, oe, s, se, Denominator::SpecimenSpecular).map(|(v, e)| (100.0 * (1.0 - v), 100.0 * e))
        }
        ReadingSpec::HazeIndex { .. } => Err("a composite reading has no fluxes of its own".into()),
        ReadingSpec::Colour { .. } => Err("a colour reading needs X, Y, Z (plan::colour_xyz)".into()),
    }
}

/// Compensated linear haze H_c = 100·(Φ_h − c·Φ_c)/Φ_std from the mean haze flux Φ_h, the compensation
/// receptor's flux Φ_c, the factor c and the standard's specular flux, each (value, error); the errors add
/// (first order, the numerator's error is e_h + c·e_c).
fn compensated_haze(
    (h, he): (f64, f64),
    (c, ce): (f64, f64),
    factor: f64,
    (d, de): (f64, f64),
) -> std::result::Result<(f64, f64), String> {
    ratio(h - factor * c, he + factor * ce, d, de, Denominator::Standard).map(|(v, e)| (100.0 * v, 100.0 * e))
}

/// The value and error of a haze index (ASTM D4039) from its two gloss readings' (value, error).
pub fn haze_index_value(minuend: (f64, f64), subtrahend: (f64, f64)) -> (f64, f64) {
    (minuend.0 - subtrahend.0, minuend.1 + subtrahend.1)
}

/// The offset of a reading's weighting kind in job j's weighting.
fn component_of(r: &PlannedReading, jobs: &[Job], j: usize) -> usize {
    jobs[j].method.weighting.offset(r.kind).expect("a job's weighting has the kinds of the readings that use it")
}

/// X, Y, Z of a colour reading: Σ sign·Φ_XYZ over its integrals, ÷ the perfect diffuser's flux, with the
/// summed error bounds (a difference's bound is the sum of the bounds).
pub fn colour_xyz(
    terms: &[(String, f64)],
    white: f64,
    flux: &dyn Fn(&str, usize) -> (f64, f64),
) -> ([f64; 3], [f64; 3]) {
    let mut xyz = [0.0; 3];
    let mut err = [0.0; 3];
    for (name, sign) in terms {
        for c in 0..3 {
            let (v, e) = flux(name, c);
            xyz[c] += sign * v;
            err[c] += e;
        }
    }
    (xyz.map(|x| x / white), err.map(|e| e / white))
}

/// A colour quantity and its error bound from X, Y, Z (`docs/colour.md`: L*, a*, b* by intervals, C*ab and
/// hab from the a*b* box). Err for the hue of a neutral colour (C*ab = 0), which is undefined.
pub fn colour_value(
    q: ColourQuantity,
    xyz: [f64; 3],
    err: [f64; 3],
    white: [f64; 3],
) -> std::result::Result<(f64, f64), String> {
    let lab = cielab::xyz_to_lab(xyz, white);
    let le = cielab::lab_errors(xyz, err, white);
    let lch = cielab::lab_to_lch(lab);
    let (ec, eh) = cielab::lch_errors(lab, le[1], le[2]);
    Ok(match q {
        ColourQuantity::X => (xyz[0], err[0]),
        ColourQuantity::Y => (xyz[1], err[1]),
        ColourQuantity::Z => (xyz[2], err[2]),
        ColourQuantity::L => (lab.l, le[0]),
        ColourQuantity::A => (lab.a, le[1]),
        ColourQuantity::B => (lab.b, le[2]),
        ColourQuantity::C => (lch.c, ec),
        ColourQuantity::H => match lch.h {
            Some(h) => (h, eh),
            None => return Err("neutral colour (C*ab = 0): the hue angle is undefined".into()),
        },
    })
}

/// Combine fluxes into a direct reading, with first-order error propagation.
fn compute_reading(
    r: &PlannedReading,
    flux: &[Flux],
    jobs: &[Job],
    white_point: Option<(Conditions, [f64; 3])>,
) -> Reading {
    let specimen = |rx: &str| {
        let j = r.specimen_jobs[rx];
        let c = component_of(r, jobs, j);
        (flux[j].value[c], flux[j].error[c])
    };
    let standard = |rx: &str| {
        let f = &flux[r.standard_jobs[rx]];
        (f.value[0], f.error[0])
    };
    let used: Vec<&Flux> = r.specimen_jobs.values().chain(r.standard_jobs.values()).map(|&j| &flux[j]).collect();
    let evaluations = used.iter().map(|f| f.evaluations).sum();
    let seconds = used.iter().map(|f| f.seconds).sum();
    let converged = used.iter().all(|f| f.converged);
    let out_of_time = used.iter().any(|f| f.out_of_time);
    let value = match (&r.spec, r.kind) {
        (ReadingSpec::Colour { quantity, terms, white }, WeightingKind::Xyz(cond)) => {
            let (xyz, err) = colour_xyz(terms, *white, &|rx, k| {
                let j = r.specimen_jobs[rx];
                let c = component_of(r, jobs, j) + k;
                (flux[j].value[c], flux[j].error[c])
            });
            match white_point {
                Some((c, w)) if c == cond => colour_value(*quantity, xyz, err, w),
                _ => Err("no white point for these colour conditions".into()),
            }
        }
        _ => reading_value(&r.spec, &specimen, &standard),
    };
    match value {
        Ok((v, e)) if v.is_finite() && e.is_finite() => Reading {
            problem: (!converged).then(|| {
                if out_of_time {
                    "wall-clock budget exhausted before the tolerance was met (the value is the best estimate so \
                     far and depends on the machine's speed)"
                        .into()
                } else {
                    "evaluation budget exhausted before the tolerance was met (the value is the best estimate)".into()
                }
            }),
            ..valued_reading(r, (v, e), evaluations, seconds, converged)
        },
        Ok((v, e)) => problem_reading(
            r,
            format!("the reading's arithmetic overflowed (value {v}, error estimate {e}); the fluxes are out of range"),
        ),
        Err(why) => problem_reading(r, why),
    }
}

/// A composite reading (haze index) from the readings it combines.
fn compose_reading(r: &PlannedReading, done: &[Option<Reading>]) -> Reading {
    let (Some(a), Some(b)) = (&done[r.parts[0]], &done[r.parts[1]]) else {
        return problem_reading(r, "a gloss reading it combines was not computed".into());
    };
    let (Some(x), Some(y)) = (a.value, b.value) else {
        return problem_reading(r, "a gloss reading it combines has no value".into());
    };
    let (v, e) = haze_index_value((x, a.error_estimate), (y, b.error_estimate));
    if !(v.is_finite() && e.is_finite()) {
        return problem_reading(r, "non-finite result".into());
    }
    Reading {
        note: (x <= 70.0 || v < 0.0).then(|| {
            "outside the scope of ASTM D4039, which is defined for non-metallic specimens with G60 > 70 (a negative \
             index means the 20° receptor gathers relatively more than the 60° one, as for near-mirror flakes)"
                .to_string()
        }),
        ..valued_reading(r, (v, e), a.evaluations + b.evaluations, a.seconds + b.seconds, a.converged && b.converged)
    }
}

/// What the denominator of a reading's ratio is, for the message when it is zero.
#[derive(Clone, Copy)]
enum Denominator {
    /// The gloss standard's specular flux (gloss, haze, log-haze).
    Standard,
    /// The specimen's own specular flux (DOI).
    SpecimenSpecular,
}

/// a/b with first-order error |a/b|·(ea/|a| + eb/|b|) written without dividing by a. The error term is
/// computed as a·eb/b² and, where b² underflows (fluxes near 1e-160 and below), as (a/b)·(eb/b), which has
/// no underflow; the first form is kept where it is finite so that no reading's bits move.
fn ratio(a: f64, ea: f64, b: f64, eb: f64, den: Denominator) -> std::result::Result<(f64, f64), String> {
    if !(b > 0.0) {
        return Err(match den {
            Denominator::Standard => {
                "the gloss standard's flux is zero: the stops do not see the mirror direction (below the horizon?)"
                    .into()
            }
            Denominator::SpecimenSpecular => "the specimen reflects no flux into the specular receptor, so DOI = \
                 100·(1 − offset/specular) is undefined (a black or mirror-less specimen has no image to be distinct)"
                .into(),
        });
    }
    let e = ea / b + a.abs() * eb / (b * b);
    let e = if e.is_finite() { e } else { ea / b + (a.abs() / b) * (eb / b) };
    Ok((a / b, e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::lambert::Lambert;

    fn geometries(ids: &[&str]) -> Vec<StandardGeometry> {
        ids.iter().map(|id| standards::find(id).unwrap()).collect()
    }

    /// The queue of `Plan::run_all` starts with the integrals `Method::expected_evaluations` ranks first; on
    /// the batch bench's narrowest recipe the guess must rank the integrals as their actual costs do at the
    /// ends: its first two are the two that cost most (in either order), and the six that cost least are
    /// guessed at under a tenth of the first (so the milliseconds start first and the microseconds end the
    /// queue).
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
            assert!(guess(j) < 0.1 * guess(expected[0]), "job {j}: {} against {}", guess(j), guess(expected[0]));
        }
    }

    fn grey() -> Arc<dyn Brdf> {
        Arc::new(Lambert::new(vec![0.5], Sampling::grey()).unwrap())
    }

    /// `Planner::builtin` is every builtin geometry, gloss then colour, through the error path (a parse error
    /// is an `Err`, no longer an empty list): the colour ones are there, not swallowed.
    #[test]
    fn the_planners_builtin_geometries_are_gloss_then_colour() {
        let p = Planner::new().unwrap();
        let ids: Vec<String> = p.builtin().unwrap().iter().map(|g| g.geometry.id.clone()).collect();
        let gloss: Vec<String> = standards::builtin().unwrap().into_iter().map(|g| g.geometry.id).collect();
        let colour: Vec<String> = standards::builtin_colour().unwrap().into_iter().map(|g| g.geometry.id).collect();
        assert!(!colour.is_empty() && !gloss.is_empty());
        assert_eq!(ids, [gloss, colour].concat());
        assert_eq!(p.builtin().unwrap().len(), ids.len(), "the second call borrows the same list");
    }

    #[test]
    fn identical_geometries_share_their_fluxes() {
        // ASTM D523 and ISO 2813 at 60° have the same stops: one specimen and one standard flux for both.
        let ids = ["astm-d523-60", "iso-2813-60"];
        let plan = Plan::compile(grey(), geometries(&ids), PlanOptions::default()).unwrap();
        let shared: Vec<&Job> = plan.jobs.iter().filter(|j| j.used_by.len() == 2).collect();
        assert!(!shared.is_empty(), "{:?}", plan.jobs.iter().map(|j| &j.used_by).collect::<Vec<_>>());
        let unshared =
            Plan::compile(grey(), geometries(&ids), PlanOptions { share_fluxes: false, ..PlanOptions::default() })
                .unwrap();
        assert!(unshared.jobs.len() > plan.jobs.len());
        assert!(unshared.jobs.iter().all(|j| j.used_by.len() == 1));
    }

    #[test]
    fn a_composite_pulls_in_its_parts_without_reporting_them() {
        let plan = Plan::compile(grey(), geometries(&["astm-d4039"]), PlanOptions::default()).unwrap();
        let composite = plan.readings.iter().find(|r| r.geometry == "astm-d4039").unwrap();
        assert_eq!(composite.parts.len(), 2);
        for &p in &composite.parts {
            assert!(!plan.readings[p].reported && matches!(plan.readings[p].spec, ReadingSpec::Gloss { .. }));
        }
        let out = plan.execute();
        assert_eq!(out.len(), 1, "only the composite is reported");
    }

    #[test]
    fn methods_are_designed_at_compile_time_and_explain_prints_them() {
        let plan =
            Plan::compile(grey(), geometries(&["astm-d523-60", "astm-e430-30"]), PlanOptions::default()).unwrap();
        for j in &plan.jobs {
            let m = &j.method;
            assert!(m.clipped.is_some());
            match m.target {
                Target::Standard => {
                    assert!(m.regular.is_none());
                    assert_eq!(m.delta.is_some(), m.mirror.is_some());
                }
                Target::Specimen => {
                    // A Lambertian body: no delta, the plain chart, one box, the luminous weighting (k = 1).
                    assert!(m.delta.is_none());
                    let r = m.regular.as_ref().unwrap();
                    assert_eq!((r.chart, r.cells.len()), (Chart::Plain, 1));
                    assert_eq!(m.weighting.len(), 1);
                    assert!(r.atol > 0.0, "the floor from the standards is set at compile time");
                }
            }
        }
        let text = plan.explain();
        for j in &plan.jobs {
            assert!(text.contains(&j.used_by.join(", ")), "{text}");
        }
        assert!(text.contains("plain variables"), "{text}");
        // The offset receptors of E430 do not see the mirror image: the standard's method says so.
        assert!(plan.jobs.iter().any(|j| j.method.target == Target::Standard) && text.contains("Standard"));
    }

    #[test]
    fn bad_options_are_refused() {
        for rtol in [0.0, 1.0, f64::NAN, -1e-3] {
            let e = Plan::compile(grey(), geometries(&["astm-d523-60"]), PlanOptions { rtol, ..Default::default() });
            assert!(e.is_err(), "rtol {rtol}");
        }
        assert!(Plan::compile(grey(), vec![], PlanOptions::default()).is_err());
    }
}
