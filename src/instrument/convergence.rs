//! Convergence sweeps: how a reading's value, its error estimate and its actual error behave as the
//! tolerance tightens, and what each tolerance costs (`glossmeter convergence`, `docs/accuracy.md`).
//!
//! For every tolerance of the sweep the measurement plan is compiled with `PlanOptions { rtol, .. }` and
//! executed; every reported reading gives one [`Row`]: value, the engine's error estimate, the actual error
//! against a reference, integrand evaluations, time and the converged flag.
//!
//! **The reference.** Where a closed form exists it is used, computed here independently of the engine
//! (no code shared with `aperture.rs` or `plan/` except the Fresnel reflectance of the gloss standard, which
//! is tested on its own in `optics::fresnel`):
//!
//! * a *Lambertian* material (f_r = ρ/π, detected by [`lambertian_value`]): the specimen flux through a
//!   source stop and a receptor stop is (ρ_lum/π)·P_s·P_r, with P the projected solid angle ∫ cos θ dω of
//!   the pyramid over each stop, by Lambert's formula for a spherical polygon ([`projected_solid_angle`]);
//! * the gloss standard's flux Φ_std, an ideal-mirror term, is ∫ R(θi) cos θi dω over the source points
//!   whose mirror lies in the receptor, by a 64 × 64 Gauss–Legendre product rule on that overlap box
//!   ([`mirror_flux_reference`]; the integrand is smooth there).
//!
//! The reading is then assembled from these fluxes by the plan's own definitions of the readings
//! (`plan::reading_value`, `plan::haze_index_value`), the one place they are written. Every other material is compared with a run of the
//! same engine at a tolerance 100× tighter than the tightest of the sweep: each row says which reference
//! it used ("closed form" or "rtol=1e-12 run"), and in the second case the reference's own error estimate
//! is reported with it: an actual error below that estimate is not resolved.
//!
//! **Timing.** After one untimed warm-up execution at the loosest tolerance (the first execution after a
//! long reference run was seen to be ~100× slower than later ones), the plan is compiled once per tolerance
//! (not timed) and executed repeatedly until at least
//! `min_seconds` (default 20 ms) of wall time have elapsed or `max_repetitions` (default 50) executions
//! were made, whichever comes first; the minimum over the executions is reported (the least disturbed by
//! other work on the machine). Two times are kept: `seconds`, the minimum over executions of the reading's
//! own time (the sum of the wall times of the aperture integrals it uses; an integral shared by several
//! readings counts in each of them), and `plan_seconds`, the minimum wall time of a whole
//! `Plan::execute()` (all readings, integrals run in parallel). The values of every execution must be the
//! same bits (the engine is deterministic); a difference is reported as an error, not averaged away.
use std::sync::Arc;
use std::time::Instant;

use crate::brdf::{Brdf, TermKind};
use crate::colorimetry::weighting::Weighting;
use crate::colorimetry::Conditions;
use crate::instrument::plan::{
    haze_index_value, reading_value, Job, Plan, PlanOptions, PlannedReading, Reading, Target, MIN_RTOL,
};
use crate::instrument::reading::ReadingSpec;
use crate::instrument::reference::{lambertian_flux_reference, mirror_flux_reference};
use crate::instrument::standards::StandardGeometry;
use crate::{Error, Result, Vec3};

/// The default sweep: 1e-2, 1e-3, …, 1e-10.
pub const DEFAULT_TOLERANCES: [f64; 9] = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10];

/// How much tighter than the tightest tolerance of the sweep the reference run is.
pub(crate) const REFERENCE_FACTOR: f64 = 100.0;

/// Knobs of a sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepOptions {
    /// Repeat each execution until this much wall time has elapsed (seconds)...
    pub min_seconds: f64,
    /// ...or this many executions were made.
    pub max_repetitions: usize,
    /// Evaluation budget per flux integral (as `PlanOptions::max_evals`).
    pub max_evals: usize,
    /// Use a reference run even when a closed form exists (for testing the tight-run path).
    pub force_run_reference: bool,
    /// The illuminant and observer of colour readings (as `PlanOptions::colour`).
    pub colour: Conditions,
}

impl Default for SweepOptions {
    fn default() -> Self {
        SweepOptions {
            min_seconds: 0.02,
            max_repetitions: 50,
            max_evals: PlanOptions::default().max_evals,
            force_run_reference: false,
            colour: Conditions::default(),
        }
    }
}

/// Where the reference values come from.
#[derive(Clone, Debug, PartialEq)]
pub enum ReferenceKind {
    /// Independent closed forms (Lambertian material).
    ClosedForm,
    /// The same engine at this tolerance.
    Run { rtol: f64 },
}

impl ReferenceKind {
    /// The label printed in every row: "closed form" or "rtol=1e-12 run".
    pub(crate) fn label(&self) -> String {
        match self {
            ReferenceKind::ClosedForm => "closed form".into(),
            ReferenceKind::Run { rtol } => format!("rtol={rtol:e} run"),
        }
    }
}

/// The reference value of one reading.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceValue {
    pub geometry: String,
    pub reading: String,
    /// None when the reference has no finite value (then no actual error can be given).
    pub value: Option<f64>,
    /// The reference's own error estimate (None for a closed form: exact up to rounding).
    pub error_estimate: Option<f64>,
}

/// One row of the sweep: one reading at one tolerance.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub rtol: f64,
    pub geometry: String,
    pub reading: String,
    pub quantity: String,
    pub unit: String,
    /// None when the engine gave no finite value (`problem` says why).
    pub value: Option<f64>,
    /// The engine's error estimate (None with `value`).
    pub error_estimate: Option<f64>,
    /// |value − reference| (None if either is missing).
    pub actual_error: Option<f64>,
    pub reference: Option<f64>,
    /// The reference's own error estimate (None for a closed form).
    pub reference_error: Option<f64>,
    /// "closed form" or "rtol=… run".
    pub reference_kind: String,
    pub evaluations: usize,
    /// Minimum over the executions of the reading's own time (see the module documentation).
    pub seconds: f64,
    /// Minimum wall time of a whole `Plan::execute()` at this tolerance.
    pub plan_seconds: f64,
    /// Number of executions timed.
    pub repetitions: usize,
    pub converged: bool,
    pub problem: Option<String>,
    /// A colour reading's illuminant and observer (the sweep's, `SweepOptions::colour`).
    pub colour: Option<Conditions>,
}

/// The result of a sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    pub tolerances: Vec<f64>,
    pub reference: ReferenceKind,
    pub references: Vec<ReferenceValue>,
    /// Wall time of the reference run (0 for a closed form).
    pub reference_seconds: f64,
    pub rows: Vec<Row>,
    pub options: SweepOptions,
}

/// Check a list of tolerances: each finite, in (0, 1). Errors name the offending entry.
pub fn validate_tolerances(tolerances: &[f64]) -> Result<()> {
    if tolerances.is_empty() {
        return Err(Error::Usage("at least one tolerance is required".into()));
    }
    for (i, t) in tolerances.iter().enumerate() {
        if !(t.is_finite() && *t > 0.0 && *t < 1.0) {
            return Err(Error::Usage(format!(
                "tolerance {} is {}; every tolerance must be a number in (0, 1), e.g. 1e-2, 1e-4, 1e-6",
                i + 1,
                crate::error::given(*t)
            )));
        }
        if *t < MIN_RTOL * REFERENCE_FACTOR {
            return Err(Error::Usage(format!(
                "tolerance {} is {t:e}; the tightest a sweep accepts is {:e} (its reference runs {REFERENCE_FACTOR}× \
                 tighter, and {MIN_RTOL:e} is the tightest double precision reaches: `plan::MIN_RTOL`)",
                i + 1,
                MIN_RTOL * REFERENCE_FACTOR
            )));
        }
    }
    Ok(())
}

/// If the material is Lambertian — a single `Diffuse` term, no ideal-mirror part, and a luminous BRDF
/// value that is the same (to 1e-14 relative) for a set of quite different direction pairs — its luminous
/// f_r = ρ_lum/π; otherwise None.
pub fn lambertian_value(brdf: &dyn Brdf) -> Option<f64> {
    let terms = brdf.hints().terms;
    if terms.len() != 1 || terms[0].kind != TermKind::Diffuse {
        return None;
    }
    let n = brdf.sampling().len();
    let luminous = Weighting::luminous(brdf.sampling()).ok()?;
    let mut buf = vec![0.0; n];
    let dir = |theta: f64, phi: f64| Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
    if brdf.delta_reflectance(dir(0.3, 0.0), &mut buf) {
        return None;
    }
    let pairs = [
        (dir(0.0, 0.0), dir(0.0, 0.0)),
        (dir(0.35, 3.1), dir(0.35, 0.0)),
        (dir(1.05, 3.0), dir(1.05, 0.0)),
        (dir(1.48, 3.0), dir(0.2, 1.0)),
        (dir(0.7, 0.4), dir(1.3, 2.5)),
        (dir(1.55, 0.0), dir(1.55, 0.0)),
    ];
    let mut first: Option<f64> = None;
    for (wi, wo) in pairs {
        buf.iter_mut().for_each(|v| *v = 0.0);
        brdf.eval(wi, wo, &mut buf);
        let f = luminous.component(0, &buf);
        if !f.is_finite() {
            return None;
        }
        match first {
            None => first = Some(f),
            Some(f0) if (f - f0).abs() <= 1e-14 * f0.abs() => {}
            Some(_) => return None,
        }
    }
    first
}

/// The reference flux of one job of the plan, for a Lambertian specimen of luminous value `f_lum`.
fn closed_form_flux(job: &Job, f_lum: f64) -> f64 {
    let m = &job.method.aperture;
    match m.target {
        Target::Specimen => lambertian_flux_reference(m.theta, m.source, m.receptor, f_lum),
        Target::Standard => {
            let scale = job.scale;
            mirror_flux_reference(m.theta, m.source, m.receptor, &|c| scale.standard_reflectance(c))
        }
    }
}

/// A reading from reference fluxes, by the plan's definitions of the readings (with zero flux errors).
fn closed_form_reading(r: &PlannedReading, flux: &[f64], done: &[Option<f64>]) -> Option<f64> {
    let specimen = |rx: &str| (flux[r.specimen_jobs[rx]], 0.0);
    let standard = |rx: &str| (flux[r.standard_jobs[rx]], 0.0);
    let v = match &r.spec {
        ReadingSpec::HazeIndex { .. } => haze_index_value((done[r.parts[0]]?, 0.0), (done[r.parts[1]]?, 0.0)).0,
        spec => reading_value(spec, &specimen, &standard).ok()?.0,
    };
    v.is_finite().then_some(v)
}

/// Closed-form references for every reported reading of `plan` (Lambertian material of luminous value
/// `f_lum`), in the order of `plan.execute()`.
pub(crate) fn closed_form_references(plan: &Plan, f_lum: f64) -> Vec<ReferenceValue> {
    let flux: Vec<f64> = plan.jobs.iter().map(|j| closed_form_flux(j, f_lum)).collect();
    let mut done: Vec<Option<f64>> = Vec::with_capacity(plan.readings.len());
    for r in &plan.readings {
        let v = closed_form_reading(r, &flux, &done);
        done.push(v);
    }
    plan.readings
        .iter()
        .zip(done)
        .filter(|(r, _)| r.reported)
        .map(|(r, v)| ReferenceValue {
            geometry: r.geometry.clone(),
            reading: r.name.clone(),
            value: v,
            error_estimate: None,
        })
        .collect()
}

/// Execute `plan` repeatedly (see the module documentation); the readings of the first execution, the
/// per-reading minimum times, the minimum plan time and the number of executions.
fn timed_execute(plan: &Plan, options: &SweepOptions) -> Result<(Vec<Reading>, Vec<f64>, f64, usize)> {
    let start = Instant::now();
    let mut first: Option<Vec<Reading>> = None;
    let mut best_plan = f64::INFINITY;
    let mut best: Vec<f64> = vec![];
    let mut reps = 0;
    loop {
        let t0 = Instant::now();
        let readings = plan.execute();
        let dt = t0.elapsed().as_secs_f64();
        reps += 1;
        best_plan = best_plan.min(dt);
        match &first {
            None => {
                best = readings.iter().map(|r| r.seconds).collect();
                first = Some(readings);
            }
            Some(f) => {
                for (i, (a, b)) in f.iter().zip(&readings).enumerate() {
                    let same = a.value.map(f64::to_bits) == b.value.map(f64::to_bits)
                        && a.error_estimate.to_bits() == b.error_estimate.to_bits();
                    if !same {
                        return Err(Error::Numeric(format!(
                            "{} {}: two executions at rtol = {:e} gave different results ({:?} ± {:e} vs {:?} ± {:e}); the engine should be deterministic",
                            a.geometry, a.name, plan.options.rtol, a.value, a.error_estimate, b.value, b.error_estimate
                        )));
                    }
                    best[i] = best[i].min(b.seconds);
                }
            }
        }
        if start.elapsed().as_secs_f64() >= options.min_seconds || reps >= options.max_repetitions.max(1) {
            break;
        }
    }
    Ok((first.expect("executed at least once"), best, best_plan, reps))
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// Run the sweep. `tolerances` are validated, sorted from loose to tight and de-duplicated.
pub fn sweep(
    material: Arc<dyn Brdf>,
    geometries: Vec<StandardGeometry>,
    tolerances: &[f64],
    options: &SweepOptions,
) -> Result<Sweep> {
    validate_tolerances(tolerances)?;
    if !(options.min_seconds.is_finite() && options.min_seconds >= 0.0) {
        return Err(Error::Usage(format!(
            "minimum timing interval must be a number ≥ 0 s, got {}",
            options.min_seconds
        )));
    }
    let mut tols = tolerances.to_vec();
    tols.sort_by(|a, b| b.total_cmp(a));
    tols.dedup();
    let tightest = *tols.last().expect("validated non-empty");
    let plan_options = |rtol: f64| PlanOptions {
        rtol,
        max_evals: options.max_evals,
        max_seconds: None,
        // The study is of the numerical error against the tolerance: each rtol is used as given, tables too.
        rtol_from_data: false,
        colour: options.colour,
        ..PlanOptions::default()
    };

    // The reference.
    let probe = Plan::compile(material.clone(), geometries.clone(), plan_options(tightest))?;
    let lambert = if options.force_run_reference { None } else { lambertian_value(material.as_ref()) };
    let (kind, references, reference_seconds) = match lambert {
        Some(f_lum) => (ReferenceKind::ClosedForm, closed_form_references(&probe, f_lum), 0.0),
        None => {
            // Rounded to 12 significant digits, so that 1e-5 / 100 is 1e-7 and not 1.0000000000000001e-7.
            let rtol: f64 = format!("{:.12e}", tightest / REFERENCE_FACTOR).parse().expect("a formatted float parses");
            let plan = Plan::compile(material.clone(), geometries.clone(), plan_options(rtol))?;
            let t0 = Instant::now();
            let readings = plan.execute();
            let secs = t0.elapsed().as_secs_f64();
            let refs = readings
                .iter()
                .map(|r| ReferenceValue {
                    geometry: r.geometry.clone(),
                    reading: r.name.clone(),
                    value: r.value.filter(|v| v.is_finite()),
                    error_estimate: r.value.and_then(|_| finite(r.error_estimate)),
                })
                .collect();
            (ReferenceKind::Run { rtol }, refs, secs)
        }
    };
    let label = kind.label();

    // One untimed execution at the loosest tolerance first: the first execution after a long reference
    // run was seen to take ~100× its later time (B3 at rtol 1e-2: 127 ms once, then 1.4 ms).
    Plan::compile(material.clone(), geometries.clone(), plan_options(tols[0]))?.execute();

    let mut rows = Vec::new();
    for &rtol in &tols {
        let plan = Plan::compile(material.clone(), geometries.clone(), plan_options(rtol))?;
        let (readings, secs, plan_secs, reps) = timed_execute(&plan, options)?;
        if readings.len() != references.len() {
            return Err(Error::Numeric(format!(
                "rtol = {rtol:e}: {} readings but {} references",
                readings.len(),
                references.len()
            )));
        }
        for ((r, s), reference) in readings.iter().zip(secs).zip(&references) {
            if r.geometry != reference.geometry || r.name != reference.reading {
                return Err(Error::Numeric(format!(
                    "reading order differs from the reference: {} {} vs {} {}",
                    r.geometry, r.name, reference.geometry, reference.reading
                )));
            }
            let value = r.value.filter(|v| v.is_finite());
            let error_estimate = value.and_then(|_| finite(r.error_estimate));
            let actual_error = match (value, reference.value) {
                (Some(v), Some(x)) => finite((v - x).abs()),
                _ => None,
            };
            rows.push(Row {
                rtol,
                geometry: r.geometry.clone(),
                reading: r.name.clone(),
                quantity: r.quantity.clone(),
                unit: r.unit.clone(),
                value,
                error_estimate,
                actual_error,
                reference: reference.value,
                reference_error: reference.error_estimate,
                reference_kind: label.clone(),
                evaluations: r.evaluations,
                seconds: s,
                plan_seconds: plan_secs,
                repetitions: reps,
                converged: r.converged,
                problem: r.problem.clone(),
                colour: r.colour,
            });
        }
    }
    Ok(Sweep { tolerances: tols, reference: kind, references, reference_seconds, rows, options: options.clone() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tolerances_are_validated() {
        assert!(validate_tolerances(&[1e-3, 1e-6]).is_ok());
        for bad in [0.0, -1e-3, 1.0, 2.0, f64::NAN, f64::INFINITY] {
            assert!(validate_tolerances(&[1e-3, bad]).is_err(), "{bad} accepted");
        }
        assert!(validate_tolerances(&[]).is_err());
    }
}
