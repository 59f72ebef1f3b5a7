//! The planner: a plan compiled from a material, the geometries and the options. The options are checked,
//! the geometries a composite combines are added, every reading's fluxes become jobs (one per distinct
//! integral, shared by key), the gloss standards' methods are designed and executed (cached by a
//! long-lived [`Planner`]), and the specimen's methods are designed with the absolute floors the standards
//! give.
use std::collections::{BTreeMap, HashMap};
use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use crate::brdf::Brdf;
use crate::colorimetry::weighting::{Weighting, WeightingKind};
use crate::colorimetry::Conditions;
use crate::instrument::geometry::{Integral, Stop};
use crate::instrument::method::Flux;
use crate::instrument::method::{Aperture, Design, MaterialFacts, Method, Projection, Target};
use crate::instrument::reading::{ReadingSpec, Scale};
use crate::instrument::standards::{self, StandardGeometry};
use crate::spectrum::Sampling;
use crate::{Error, Result};

use super::{Engine, Job, Plan, PlanOptions, PlannedReading, Shape, MIN_RTOL, SPECIMEN_SHARE, STANDARD_SHARE};

/// Why `rtol` is not a relative tolerance (a number in (0, 1)), if it is not: the words after its name, which
/// [`Planner::compile`] calls "the relative tolerance (rtol)" and the command line `--rtol`.
pub(crate) fn rtol_refusal(rtol: f64) -> Option<String> {
    (!(rtol.is_finite() && rtol > 0.0 && rtol < 1.0))
        .then(|| format!("must be a number in (0, 1), got {}", crate::error::given(rtol)))
}

/// The identity of a job for sharing: its integral, and for a standard the scale (which standard is
/// integrated); as bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct JobKey {
    aperture: Aperture,
    scale: Option<[u64; 3]>,
}

impl JobKey {
    fn new(aperture: Aperture, scale: Scale) -> JobKey {
        JobKey { aperture, scale: (aperture.target == Target::Standard).then(|| scale.key()) }
    }
}

/// The key of a standard's flux in the planner's cache: the job's, and the options its method depends on
/// (tolerance and budgets), as bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct StandardKey {
    job: JobKey,
    rtol: u64,
    max_evals: usize,
    max_seconds: Option<u64>,
}

/// A job before its method is designed.
struct Draft {
    aperture: Aperture,
    /// The weightings of the readings that use it (each once, sorted: the job's k × n matrix stacks them).
    kinds: Vec<WeightingKind>,
    /// The smallest perfect-diffuser flux of the colour readings that use it (their absolute floor).
    colour_white: Option<f64>,
    scale: Scale,
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
    standards: Mutex<HashMap<StandardKey, Flux>>,
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
        self.compile_with_engine(material, geometries, options, Engine::default())
    }

    /// [`Planner::compile`] with an engine variant ([`Engine`]: benches and tests).
    pub fn compile_with_engine(
        &self,
        material: Arc<dyn Brdf>,
        geometries: Vec<StandardGeometry>,
        options: PlanOptions,
        engine: Engine,
    ) -> Result<Plan> {
        if let Some(why) = rtol_refusal(options.rtol) {
            return Err(Error::Usage(format!("the relative tolerance (rtol) {why}")));
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
        let queue = self.with_dependencies(geometries)?;
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
            add_geometry(g, *reported, colour, engine.share_fluxes, &mut drafts, &mut readings, &mut index)?;
        }
        resolve_composites(&mut readings)?;

        // Step 1a: the standards' methods, executed now (cached across plans).
        let standard_weighting = Weighting::luminous(&Sampling::grey())?;
        let mirror = MaterialFacts::mirror();
        let standard_method = |d: &Draft| {
            Method::design(Design {
                aperture: d.aperture,
                facts: &mirror,
                weighting: standard_weighting.clone(),
                projection: Projection::Fold,
                rtol: STANDARD_SHARE * options.rtol,
                atol: 0.0,
                max_evals: options.max_evals,
                max_seconds: options.max_seconds,
            })
        };
        let std_idx: Vec<usize> =
            (0..drafts.len()).filter(|&j| drafts[j].aperture.target == Target::Standard).collect();
        let std_methods: Vec<Method> = std_idx.iter().map(|&j| standard_method(&drafts[j])).collect();
        let std_drafts: Vec<&Draft> = std_idx.iter().map(|&j| &drafts[j]).collect();
        let std_flux = self.standard_fluxes(&std_drafts, &std_methods, &options, engine);
        // Absolute floor per geometry angle: 1e-4·rtol of the largest standard flux at that angle, i.e.
        // 0.01·rtol GU on a gloss reading; it only matters for fluxes that are (nearly) zero. A colour flux's
        // floor is 1e-4·rtol of the perfect diffuser's Y flux (100·white), 0.01·rtol on X, Y, Z; a flux that
        // both use gets the smaller.
        let floor = |theta: f64| -> f64 {
            let m = std_idx
                .iter()
                .zip(&std_flux)
                .filter(|(&j, _)| drafts[j].aperture.theta == theta)
                .map(|(_, f)| f.value[0])
                .fold(0.0, f64::max);
            1e-4 * options.rtol * m
        };
        let specimen_floor = |d: &Draft| -> f64 {
            let gloss = d.kinds.contains(&WeightingKind::Luminous).then(|| floor(d.aperture.theta));
            let colour = d.colour_white.map(|w| 1e-2 * options.rtol * w);
            match (gloss, colour) {
                (Some(a), Some(b)) => a.min(b),
                (a, b) => a.or(b).unwrap_or(0.0),
            }
        };

        // Step 1b: the specimen's methods, from the material's facts read once.
        let hints = material.hints();
        let facts = MaterialFacts::from_hints(&hints);
        let projection = match (engine.fold_spectral, engine.fold_in_material) {
            (false, _) => Projection::Separate,
            (true, false) => Projection::Fold,
            (true, true) => Projection::FoldInMaterial,
        };
        let mut jobs = Vec::with_capacity(drafts.len());
        let mut standard_flux = vec![None; drafts.len()];
        let mut std_results = std_methods.into_iter().zip(std_flux.iter().cloned());
        for (j, d) in drafts.iter().enumerate() {
            let method = match d.aperture.target {
                Target::Standard => {
                    let (m, f) = std_results.next().expect("one standard method per standard job");
                    standard_flux[j] = Some(f);
                    m
                }
                Target::Specimen => Method::design(Design {
                    aperture: d.aperture,
                    facts: &facts,
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
        let shape = Shape::of(material.sampling(), &hints.terms);
        let white_point = match weighting.parts.iter().any(|(k, _)| matches!(k, WeightingKind::Xyz(_))) {
            true => Some((options.colour, crate::colorimetry::weights(material.sampling(), options.colour)?.white)),
            false => None,
        };
        Ok(Plan {
            white_point,
            twins: material.coarser(),
            material,
            options,
            engine,
            geometries: queue.into_iter().map(|(g, _)| g).collect(),
            jobs,
            readings,
            weighting,
            terms: hints.terms,
            shape,
            standard_flux,
        })
    }

    /// The requested geometries (reported), then the geometries their composites combine (not reported),
    /// each once.
    fn with_dependencies(&self, geometries: Vec<StandardGeometry>) -> Result<Vec<(StandardGeometry, bool)>> {
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
        Ok(queue)
    }

    /// The fluxes of the gloss standards, from the cache or computed (and cached): the cache is read once,
    /// under one lock, and only the fluxes it lacks are computed, in parallel (in a batch every plan after
    /// the first finds them all, and then hands nothing to the pool). With sharing off, always computed (the
    /// ablation measures what sharing saves).
    fn standard_fluxes(
        &self,
        drafts: &[&Draft],
        methods: &[Method],
        options: &PlanOptions,
        engine: Engine,
    ) -> Vec<Flux> {
        let compute = |d: &Draft, m: &Method| m.execute(&d.scale.standard());
        if !engine.share_fluxes {
            return drafts.par_iter().zip(methods).map(|(d, m)| compute(d, m)).collect();
        }
        let keys: Vec<StandardKey> = drafts
            .iter()
            .map(|d| StandardKey {
                job: JobKey::new(d.aperture, d.scale),
                rtol: options.rtol.to_bits(),
                max_evals: options.max_evals,
                max_seconds: options.max_seconds.map(f64::to_bits),
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
                    c.insert(keys[i], f.clone());
                }
                flux[i] = Some(f);
            }
        }
        flux.into_iter().map(|f| f.expect("every standard computed")).collect()
    }
}

/// Composites: their parts (the gloss readings of the geometries they combine) resolved, now that every gloss
/// reading exists.
fn resolve_composites(readings: &mut [PlannedReading]) -> Result<()> {
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
    Ok(())
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
                let aperture = Aperture { target, integral, theta: g.theta, viewing, source, receptor: stop };
                let key = JobKey::new(aperture, g.scale);
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
                            aperture,
                            kinds: vec![job_kind],
                            colour_white,
                            scale: g.scale,
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

    /// [`Plan::compile`] with an engine variant ([`Engine`]), for the benches and tests that measure what an
    /// optimisation saves.
    pub fn compile_with_engine(
        material: Arc<dyn Brdf>,
        geometries: Vec<StandardGeometry>,
        options: PlanOptions,
        engine: Engine,
    ) -> Result<Plan> {
        Planner::new()?.compile_with_engine(material, geometries, options, engine)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::lambert::Lambert;
    use crate::instrument::aperture::Chart;

    fn geometries(ids: &[&str]) -> Vec<StandardGeometry> {
        ids.iter().map(|id| standards::find(id).unwrap()).collect()
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
        let unshared = Plan::compile_with_engine(
            grey(),
            geometries(&ids),
            PlanOptions::default(),
            Engine { share_fluxes: false, ..Engine::default() },
        )
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
            match m.aperture.target {
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
        assert!(plan.jobs.iter().any(|j| j.method.aperture.target == Target::Standard) && text.contains("Standard"));
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
