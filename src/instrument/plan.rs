//! The measurement plan: (material, geometries, requested readings) compiled once into the cheapest list
//! of aperture integrals that produces them, in the manner of RustFFT's planner. The plan
//!
//! * keeps only the terms the material has (the model builds no flake term without flakes; the plan lists
//!   what is there and how each term is integrated: a smooth coat as an analytic delta, a diffuse body with
//!   no lobe splits, each lobe with splits at its own width);
//! * folds the spectral dimension into one luminous component when only luminous readings are asked for;
//! * computes each distinct flux once and shares it: the gloss standard's flux between gloss and haze
//!   readings, a receptor between gloss and DOI, identical geometries (ASTM D523 and ISO 2813 at the same
//!   angle) between themselves, and the gloss readings that a composite (ASTM D4039) needs;
//! * runs the integrals in parallel, collecting results in plan order, so the numbers are the same bits
//!   whatever the thread count.
//!
//! `explain()` prints the plan in plain words (`glossmeter measure --explain`).
use std::collections::HashMap;
use std::sync::Arc;

use rayon::prelude::*;

use crate::brdf::{Brdf, Lobe, Term, TermKind};
use crate::instrument::flux::{choose_variables, clip, lobe_widths_uv, Flux, FluxProblem, Spectral, Variables};
use crate::instrument::geometry::{ReadingSpec, Scale, Stop};
use crate::instrument::standards::{self, StandardGeometry};
use crate::spectrum::Sampling;
use crate::{Error, Result, Vec3};

/// Share of a reading's relative tolerance given to each specimen flux and to the gloss standard's flux. A
/// gloss reading's propagated relative error is at most the sum of its two fluxes' (first order), so
/// SPECIMEN_SHARE + STANDARD_SHARE ≤ 1 keeps it within rtol. The standard (an analytic 2-D integral) is cheap
/// to converge tightly; the specimen's 4-D integral gets most of the budget.
pub const SPECIMEN_SHARE: f64 = 0.9;
pub const STANDARD_SHARE: f64 = 0.05;

/// Knobs of the planner. The defaults are what `measure` uses; the others exist to measure what each
/// optimisation saves (`docs/performance.md`).
#[derive(Clone, Debug, PartialEq)]
pub struct PlanOptions {
    /// Relative tolerance of every reading.
    pub rtol: f64,
    /// Fold the luminous weights into the integrand (one component instead of one per sample).
    pub fold_spectral: bool,
    /// Compute each distinct flux once.
    pub share_fluxes: bool,
    /// Evaluation budget per flux integral.
    pub max_evals: usize,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions { rtol: 1e-6, fold_spectral: true, share_fluxes: true, max_evals: 50_000_000 }
    }
}

/// The gloss standard of a scale, rescaled to read 100 ([`Scale::standard_reflectance`]): black glass (a
/// smooth, non-absorbing dielectric, black-backed: only its front-surface Fresnel reflection counts) or a
/// perfect mirror. Integrated by the same engine as any specimen.
#[derive(Debug)]
pub struct GlossStandard {
    pub scale: Scale,
    sampling: Sampling,
}

impl GlossStandard {
    pub fn new(scale: Scale) -> Self {
        GlossStandard { scale, sampling: Sampling::grey() }
    }
}

impl Brdf for GlossStandard {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }
    fn eval(&self, _wi: Vec3, _wo: Vec3, out: &mut [f64]) {
        out.iter_mut().for_each(|v| *v = 0.0);
    }
    fn delta_reflectance(&self, wi: Vec3, out: &mut [f64]) -> bool {
        let r = self.scale.standard_reflectance(wi.z.clamp(0.0, 1.0));
        out.iter_mut().for_each(|v| *v = r);
        true
    }
    fn terms(&self) -> Vec<Term> {
        vec![Term { label: "gloss standard (Fresnel, delta)".into(), kind: TermKind::Delta }]
    }
    fn describe(&self) -> String {
        format!("gloss standard: {}", self.scale.describe())
    }
}

/// Which material a flux is taken on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Target {
    Specimen,
    Standard,
}

/// One aperture integral of the plan.
#[derive(Clone, Debug)]
pub struct Job {
    pub target: Target,
    pub theta: f64,
    /// The scale of the standard (only used by `Target::Standard` jobs).
    pub scale: Scale,
    pub source: Stop,
    pub receptor: Stop,
    /// Where it is used: "geometry-id/receptor".
    pub used_by: Vec<String>,
}

/// A reading of the plan, referring to jobs by index.
#[derive(Clone, Debug)]
pub struct PlannedReading {
    pub geometry: String,
    pub name: String,
    pub spec: ReadingSpec,
    /// Specimen and standard flux job indices, by receptor name.
    pub specimen: HashMap<String, usize>,
    pub standard: HashMap<String, usize>,
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

/// The compiled plan.
pub struct Plan {
    pub material: Arc<dyn Brdf>,
    pub options: PlanOptions,
    pub geometries: Vec<StandardGeometry>,
    pub jobs: Vec<Job>,
    pub readings: Vec<PlannedReading>,
    lobes: Vec<Lobe>,
    has_delta: bool,
    has_regular: bool,
}

fn key(j: &Job) -> Vec<u64> {
    let mut k = vec![j.target as u64, j.theta.to_bits()];
    if j.target == Target::Standard {
        k.extend(j.scale.key());
    }
    for s in [j.source, j.receptor] {
        k.extend([s.p[0], s.p[1], s.q[0], s.q[1]].iter().map(|x| x.to_bits()));
    }
    k
}

impl Plan {
    /// Compile a plan for `material` and the geometries (builtin ids resolved by the caller, or user files).
    pub fn compile(material: Arc<dyn Brdf>, geometries: Vec<StandardGeometry>, options: PlanOptions) -> Result<Plan> {
        if !(options.rtol.is_finite() && options.rtol > 0.0 && options.rtol < 1.0) {
            return Err(Error::Usage(format!(
                "the relative tolerance (rtol) must be a number in (0, 1), got {}",
                options.rtol
            )));
        }
        if geometries.is_empty() {
            return Err(Error::Usage("no geometry to measure".into()));
        }
        let terms = material.terms();
        let lobes: Vec<Lobe> = terms
            .iter()
            .filter_map(|t| match &t.kind {
                TermKind::Lobe(l) => Some(l.clone()),
                _ => None,
            })
            .collect();
        let has_delta = terms.iter().any(|t| t.kind == TermKind::Delta);
        let has_regular = terms.iter().any(|t| t.kind != TermKind::Delta);
        let mut plan = Plan {
            material,
            options,
            geometries: Vec::new(),
            jobs: Vec::new(),
            readings: Vec::new(),
            lobes,
            has_delta,
            has_regular,
        };
        let mut index: HashMap<Vec<u64>, usize> = HashMap::new();
        // Requested geometries first, then the dependencies of composites.
        let mut queue: Vec<(StandardGeometry, bool)> = geometries.into_iter().map(|g| (g, true)).collect();
        let mut i = 0;
        while i < queue.len() {
            let (g, reported) = queue[i].clone();
            for spec in &g.geometry.readings {
                if let ReadingSpec::HazeIndex { minuend, subtrahend } = spec {
                    for id in [minuend, subtrahend] {
                        if !queue.iter().any(|(q, _)| &q.geometry.id == id) {
                            queue.push((standards::find(id)?, false));
                        }
                    }
                }
            }
            let _ = reported;
            i += 1;
        }
        for (g, reported) in &queue {
            plan.add_geometry(g, *reported, &mut index)?;
        }
        // Composites: resolve their parts now that every gloss reading exists.
        for r in 0..plan.readings.len() {
            if let ReadingSpec::HazeIndex { minuend, subtrahend } = plan.readings[r].spec.clone() {
                let mut parts = Vec::new();
                for id in [&minuend, &subtrahend] {
                    let part = plan
                        .readings
                        .iter()
                        .position(|x| &x.geometry == id && matches!(x.spec, ReadingSpec::Gloss { .. }))
                        .ok_or_else(|| {
                            Error::Usage(format!("{}: geometry `{id}` has no gloss reading", plan.readings[r].geometry))
                        })?;
                    parts.push(part);
                }
                plan.readings[r].parts = parts;
            }
        }
        plan.geometries = queue.into_iter().map(|(g, _)| g).collect();
        Ok(plan)
    }

    fn job(&mut self, index: &mut HashMap<Vec<u64>, usize>, job: Job) -> usize {
        let k = key(&job);
        if self.options.share_fluxes {
            if let Some(&i) = index.get(&k) {
                let used = job.used_by[0].clone();
                if !self.jobs[i].used_by.contains(&used) {
                    self.jobs[i].used_by.push(used);
                }
                return i;
            }
        }
        self.jobs.push(job);
        index.insert(k, self.jobs.len() - 1);
        self.jobs.len() - 1
    }

    fn add_geometry(
        &mut self,
        sg: &StandardGeometry,
        reported: bool,
        index: &mut HashMap<Vec<u64>, usize>,
    ) -> Result<()> {
        let g = &sg.geometry;
        for (ri, spec) in g.readings.iter().enumerate() {
            let name = sg.reading_names.get(ri).cloned().unwrap_or_else(|| spec.quantity().to_string());
            let (spec_rx, std_rx): (Vec<&String>, Vec<&String>) = match spec {
                ReadingSpec::Gloss { receptor } => (vec![receptor], vec![receptor]),
                ReadingSpec::Haze { receptors, specular } | ReadingSpec::LogHaze { receptors, specular, .. } => {
                    (receptors.iter().collect(), vec![specular])
                }
                ReadingSpec::Doi { specular, offset } => {
                    (std::iter::once(specular).chain(offset.iter()).collect(), vec![])
                }
                ReadingSpec::HazeIndex { .. } => (vec![], vec![]),
            };
            let mut pr = PlannedReading {
                geometry: g.id.clone(),
                name,
                spec: spec.clone(),
                specimen: HashMap::new(),
                standard: HashMap::new(),
                parts: vec![],
                reported,
            };
            for (names, target) in [(spec_rx, Target::Specimen), (std_rx, Target::Standard)] {
                for rx in names {
                    let stop = *g.receptor(rx).ok_or_else(|| {
                        Error::Usage(format!("{}: reading `{}` names unknown receptor `{rx}`", g.id, pr.name))
                    })?;
                    let j = self.job(
                        index,
                        Job {
                            target,
                            theta: g.theta,
                            scale: g.scale,
                            source: g.source,
                            receptor: stop,
                            used_by: vec![format!("{}/{rx}", g.id)],
                        },
                    );
                    match target {
                        Target::Specimen => pr.specimen.insert(rx.clone(), j),
                        Target::Standard => pr.standard.insert(rx.clone(), j),
                    };
                }
            }
            self.readings.push(pr);
        }
        Ok(())
    }

    fn spectral(&self, sampling: &Sampling) -> Spectral {
        if self.options.fold_spectral {
            Spectral::Folded(sampling.luminous_weights.clone())
        } else {
            Spectral::Separate(sampling.luminous_weights.clone())
        }
    }

    /// Run one job; `atol` is the absolute floor.
    fn run_job(&self, job: &Job, atol: f64) -> Flux {
        match job.target {
            Target::Standard => {
                let std = GlossStandard::new(job.scale);
                FluxProblem {
                    brdf: &std,
                    theta: job.theta,
                    source: job.source,
                    receptor: job.receptor,
                    spectral: Spectral::Folded(vec![1.0]),
                    lobes: vec![],
                    include_delta: true,
                    include_regular: false,
                    rtol: STANDARD_SHARE * self.options.rtol,
                    atol: 0.0,
                    max_evals: self.options.max_evals,
                }
                .solve()
            }
            Target::Specimen => FluxProblem {
                brdf: self.material.as_ref(),
                theta: job.theta,
                source: job.source,
                receptor: job.receptor,
                spectral: self.spectral(self.material.sampling()),
                lobes: self.lobes.clone(),
                include_delta: self.has_delta,
                include_regular: self.has_regular,
                rtol: SPECIMEN_SHARE * self.options.rtol,
                atol,
                max_evals: self.options.max_evals,
            }
            .solve(),
        }
    }

    /// Execute the plan: every flux once (in parallel, collected in plan order), then the readings.
    pub fn execute(&self) -> Vec<Reading> {
        // Phase 1: the standards (cheap, analytic); they set the scale of the absolute floors.
        let std_jobs: Vec<usize> = (0..self.jobs.len()).filter(|&j| self.jobs[j].target == Target::Standard).collect();
        let std_flux: Vec<Flux> = std_jobs.par_iter().map(|&j| self.run_job(&self.jobs[j], 0.0)).collect();
        let mut flux: Vec<Option<Flux>> = vec![None; self.jobs.len()];
        for (j, f) in std_jobs.iter().zip(std_flux) {
            flux[*j] = Some(f);
        }
        // Absolute floor per geometry angle: 1e-4·rtol of the largest standard flux at that angle, i.e.
        // 0.01·rtol GU on a gloss reading; it only matters for fluxes that are (nearly) zero.
        let floor = |theta: f64| -> f64 {
            let m = std_jobs
                .iter()
                .filter(|&&j| self.jobs[j].theta == theta)
                .filter_map(|&j| flux[j].as_ref().map(|f| f.value))
                .fold(0.0, f64::max);
            1e-4 * self.options.rtol * m
        };
        let spec_jobs: Vec<(usize, f64)> = (0..self.jobs.len())
            .filter(|&j| self.jobs[j].target == Target::Specimen)
            .map(|j| (j, floor(self.jobs[j].theta)))
            .collect();
        let spec_flux: Vec<Flux> = spec_jobs.par_iter().map(|&(j, atol)| self.run_job(&self.jobs[j], atol)).collect();
        for ((j, _), f) in spec_jobs.iter().zip(spec_flux) {
            flux[*j] = Some(f);
        }
        let flux: Vec<Flux> = flux.into_iter().map(|f| f.expect("every job ran")).collect();
        // Direct readings first, then composites, which combine direct readings (their parts may come
        // later in plan order when the user asked for the composite before its parts, or only for it).
        let mut out: Vec<Option<Reading>> = vec![None; self.readings.len()];
        for (i, r) in self.readings.iter().enumerate() {
            if r.parts.is_empty() {
                out[i] = Some(compute_reading(r, &flux, &out));
            }
        }
        for (i, r) in self.readings.iter().enumerate() {
            if !r.parts.is_empty() {
                out[i] = Some(compute_reading(r, &flux, &out));
            }
        }
        out.into_iter()
            .zip(&self.readings)
            .filter(|(_, p)| p.reported)
            .map(|(r, _)| r.expect("every reading computed"))
            .collect()
    }

    /// The plan in plain words.
    pub fn explain(&self) -> String {
        let m = &self.material;
        let mut s = String::new();
        s.push_str(&format!("Material: {}\n", m.describe()));
        s.push_str(&format!("Spectral samples: {}\n", m.sampling().describe()));
        if self.options.fold_spectral {
            s.push_str("  Only luminous readings are asked for: the luminous weights are folded into the integrand,\n  so each aperture integral has one component instead of one per sample.\n");
        } else {
            s.push_str("  Spectral folding is off: each sample is integrated separately, then weighted.\n");
        }
        s.push_str("Terms of the material, and how each is integrated:\n");
        for t in m.terms() {
            let how = match &t.kind {
                TermKind::Delta => {
                    "ideal mirror: analytic in the lobe variables, a 2-D integral over the stops' mirror overlap"
                        .to_string()
                }
                TermKind::Diffuse => "smooth in direction: no lobe splits needed".to_string(),
                TermKind::Lobe(l) => format!(
                    "glossy lobe, slope width {:.3e}{}: lobe variables split at 0 and ±(1, 3, 10, 30, …)× its width out to the aperture range",
                    l.slope_width,
                    if l.medium_eta != 1.0 {
                        format!(" inside a medium of index {}", l.medium_eta)
                    } else {
                        String::new()
                    }
                ),
            };
            s.push_str(&format!("  - {}: {how}\n", t.label));
        }
        s.push_str("  Terms the material does not have are not built and cost nothing.\n");
        for g in &self.geometries {
            let geo = &g.geometry;
            if geo.is_composite() {
                s.push_str(&format!(
                    "Geometry {} ({}): combines other geometries' gloss readings\n",
                    geo.id, geo.title
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
            for l in &self.lobes {
                let w = lobe_widths_uv(l, geo.theta);
                s.push_str(&format!(
                    "  lobe '{}' is {:.3e} × {:.3e} wide in the lobe variables (u, v)\n",
                    l.label, w[0], w[1]
                ));
            }
        }
        let n_spec = self.jobs.iter().filter(|j| j.target == Target::Specimen).count();
        let n_std = self.jobs.len() - n_spec;
        let uses: usize = self.readings.iter().map(|r| r.specimen.len() + r.standard.len()).sum();
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
            let how = match j.target {
                Target::Standard => "analytic (delta) only".to_string(),
                Target::Specimen => {
                    let clipped = (clip(j.source, j.theta, true), clip(j.receptor, j.theta, false));
                    let vars = match clipped {
                        (Some(a), Some(b)) => match choose_variables(&self.lobes, j.theta, a, b) {
                            Variables::Plain => "plain variables (no lobe narrower than the stops)",
                            Variables::Lobe => "lobe variables",
                        },
                        _ => "stops below the horizon: zero",
                    };
                    // Does the receptor see the mirror image of the source (a non-empty delta integral)?
                    let sees_mirror = match clipped {
                        (Some(a), Some(b)) => {
                            a.p[0].max(-b.p[1]) < a.p[1].min(-b.p[0]) && a.q[0].max(-b.q[1]) < a.q[1].min(-b.q[0])
                        }
                        _ => false,
                    };
                    let delta = match (self.has_delta, sees_mirror) {
                        (false, _) => "",
                        (true, true) => "analytic delta + ",
                        (true, false) => "no mirror image in this stop (delta skipped) + ",
                    };
                    if self.has_regular {
                        format!("{delta}{vars}")
                    } else if sees_mirror {
                        "analytic (delta) only".to_string()
                    } else {
                        "no mirror image in this stop and no regular part: zero".to_string()
                    }
                }
            };
            s.push_str(&format!(
                "  #{i}: {:?} at {:.4}°, {how}; used by {}\n",
                j.target,
                j.theta.to_degrees(),
                j.used_by.join(", ")
            ));
        }
        s.push_str(&format!(
            "Tolerance: relative {:e} on every reading; {} of it to each specimen flux (1 % of that to its analytic \
             part), {} to the gloss standard.\n",
            self.options.rtol, SPECIMEN_SHARE, STANDARD_SHARE
        ));
        s
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

/// Combine fluxes into a reading, with first-order error propagation.
fn compute_reading(r: &PlannedReading, flux: &[Flux], done: &[Option<Reading>]) -> Reading {
    let spec = |rx: &String| &flux[r.specimen[rx]];
    let std = |rx: &String| &flux[r.standard[rx]];
    let used: Vec<&Flux> = r.specimen.values().chain(r.standard.values()).map(|&j| &flux[j]).collect();
    let evaluations = used.iter().map(|f| f.evaluations).sum();
    let seconds = used.iter().map(|f| f.seconds).sum();
    let converged = used.iter().all(|f| f.converged);
    let mean = |rxs: &[String]| -> (f64, f64) {
        let n = rxs.len() as f64;
        (rxs.iter().map(|x| spec(x).value).sum::<f64>() / n, rxs.iter().map(|x| spec(x).error).sum::<f64>() / n)
    };
    let result: std::result::Result<(f64, f64), String> = match &r.spec {
        ReadingSpec::Gloss { receptor } => {
            let (s, d) = (spec(receptor), std(receptor));
            ratio(s.value, s.error, d.value, d.error).map(|(v, e)| (100.0 * v, 100.0 * e))
        }
        ReadingSpec::Haze { receptors, specular } => {
            let (h, he) = mean(receptors);
            let d = std(specular);
            ratio(h, he, d.value, d.error).map(|(v, e)| (100.0 * v, 100.0 * e))
        }
        ReadingSpec::LogHaze { receptors, specular, k } => {
            let (h, he) = mean(receptors);
            let d = std(specular);
            ratio(h, he, d.value, d.error).map(|(v, e)| {
                let (h, he) = (100.0 * v, 100.0 * e);
                (k * (h / 20.0 + 1.0).log10(), k * he / (std::f64::consts::LN_10 * (h + 20.0)))
            })
        }
        ReadingSpec::Doi { specular, offset } => {
            let s = spec(specular);
            let (o, oe) = mean(offset);
            ratio(o, oe, s.value, s.error).map(|(v, e)| (100.0 * (1.0 - v), 100.0 * e))
        }
        ReadingSpec::HazeIndex { .. } => {
            let (Some(a), Some(b)) = (&done[r.parts[0]], &done[r.parts[1]]) else {
                return problem_reading(r, "a gloss reading it combines was not computed".into());
            };
            let mut rd = match (a.value, b.value) {
                (Some(x), Some(y)) => Reading {
                    geometry: r.geometry.clone(),
                    name: r.name.clone(),
                    quantity: r.spec.quantity().into(),
                    unit: r.spec.unit().into(),
                    value: Some(x - y),
                    error_estimate: a.error_estimate + b.error_estimate,
                    evaluations: a.evaluations + b.evaluations,
                    seconds: a.seconds + b.seconds,
                    converged: a.converged && b.converged,
                    problem: None,
                    note: (a.value.unwrap_or(0.0) <= 70.0 || x - y < 0.0).then(|| {
                        "outside the scope of ASTM D4039, which is defined for non-metallic specimens with G60 > 70 \
                         (a negative index means the 20° receptor gathers relatively more than the 60° one, as for \
                         near-mirror flakes)"
                            .to_string()
                    }),
                },
                _ => problem_reading(r, "a gloss reading it combines has no value".into()),
            };
            if rd.value.is_some() && !(rd.value.unwrap().is_finite() && rd.error_estimate.is_finite()) {
                rd = problem_reading(r, "non-finite result".into());
            }
            return rd;
        }
    };
    match result {
        Ok((v, e)) if v.is_finite() && e.is_finite() => Reading {
            geometry: r.geometry.clone(),
            name: r.name.clone(),
            quantity: r.spec.quantity().into(),
            unit: r.spec.unit().into(),
            value: Some(v),
            error_estimate: e,
            evaluations,
            seconds,
            converged,
            problem: if converged {
                None
            } else {
                Some("evaluation budget exhausted before the tolerance was met".into())
            },
            note: None,
        },
        Ok(_) => problem_reading(r, "non-finite result".into()),
        Err(why) => problem_reading(r, why),
    }
}

/// a/b with first-order error |a/b|·(ea/|a| + eb/|b|) written without dividing by a.
fn ratio(a: f64, ea: f64, b: f64, eb: f64) -> std::result::Result<(f64, f64), String> {
    if !(b > 0.0) {
        return Err("the reference flux is zero: the stops do not see the mirror direction (below the horizon?)".into());
    }
    Ok((a / b, ea / b + a.abs() * eb / (b * b)))
}
