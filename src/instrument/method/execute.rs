//! Execution: [`Method::execute`] and its variants run a designed method on a material — the delta part on
//! its partition, the regular part by its shaped rule (falling back to the Genz–Malik partition) — and return
//! the [`Flux`]; with freezing, also the method with its final partitions. The regular part's integrand (the
//! BRDF batch in the chart's variables, times the geometric factor and the weighting) is built here once
//! per execution and handed to the rules of `delta.rs`, `gauss.rs` and `polar.rs`.
use super::chart::ChartMap;
use super::shape::RuleRun;
use super::{Flux, Method, Projection, RegularPart, Rule};
use crate::brdf::Brdf;
use crate::colorimetry::weighting::Weighting;
use crate::instrument::aperture::{incidence_kink_point, kinked_position, Chart};
use crate::instrument::geometry::{solid_angle_density, Axes, Integral, Stop};
use crate::instrument::sphere;
use crate::quadrature::{
    integrate_partition, Estimate, Options, Refine, MAX_SHRINK, MAX_SHRINK_LOBE, MAX_SHRINK_PLAIN,
};
use crate::Vec3;
use std::time::Instant;

/// The share of its wall-clock budget an integral gets when it starts at or after the deadline it shares
/// with the other integrals of a plan ([`Method::execute_until`]). A plan of J integrals on T threads then
/// ends within about max_seconds·(1 + ⌈J/T⌉·LATE_START_SHARE) of wall time: the default panel's 12
/// specimen integrals on 2 threads, 1.3 × the budget.
pub const LATE_START_SHARE: f64 = 0.05;

impl Method {
    /// Execute the method on `brdf` (whose sampling has as many samples as the weighting has columns).
    pub fn execute(&self, brdf: &dyn Brdf) -> Flux {
        self.run(brdf, false, None).0
    }

    /// [`Method::execute`] under a deadline shared with other integrals (`Plan::execute`): the integral stops
    /// refining at that deadline, or [`LATE_START_SHARE`] of its own budget after it starts if that is
    /// later (so an integral queued behind slow ones still gets a moment to converge), and never later than
    /// its own budget.
    pub(crate) fn execute_until(&self, brdf: &dyn Brdf, deadline: Option<Instant>) -> Flux {
        self.run(brdf, false, deadline).0
    }

    /// Execute the method and return, with the flux, the frozen method: the same method with each part's
    /// final partition and `Refine::Frozen`. Executing the frozen method on the same material gives the same
    /// value and error bits; on a nearby material it gives a smooth function of the change.
    pub fn execute_and_freeze(&self, brdf: &dyn Brdf) -> (Flux, Method) {
        self.execute_and_freeze_until(brdf, None)
    }

    /// [`Method::execute_and_freeze`] with a shared deadline as in [`Method::execute_until`].
    pub(crate) fn execute_and_freeze_until(&self, brdf: &dyn Brdf, deadline: Option<Instant>) -> (Flux, Method) {
        let (flux, frozen) = self.run(brdf, true, deadline);
        (flux, frozen.expect("kept"))
    }

    /// The number of components the regular part's integrand has per point (k weighted sums, or n samples
    /// under [`Projection::Separate`]) and whether the material sums the one weighted component itself.
    fn components(&self, brdf: &dyn Brdf) -> (usize, bool) {
        let k = self.weighting.len();
        let ncomp = match self.projection {
            Projection::Fold | Projection::FoldInMaterial => k,
            Projection::Separate => brdf.sampling().len(),
        };
        let in_material =
            self.projection == Projection::FoldInMaterial && k == 1 && brdf.folds(&self.weighting.rows[0]);
        (ncomp, in_material)
    }

    /// The regular part's integrand in the chart `map` (the part's own, or a shaped rule's): for each point
    /// of `pts`, `ncomp` values written to `out` — the weighted BRDF times cos θi cos θo, the solid-angle
    /// densities of the two direction-cosine charts and the chart's Jacobian. A point outside the overlap
    /// or below the horizon leaves its values as they were (the rules zero `out`).
    fn regular_integrand<'a>(
        &'a self,
        brdf: &'a dyn Brdf,
        map: ChartMap<'a>,
        (ncomp, in_material): (usize, bool),
    ) -> impl FnMut(&[[f64; 4]], &mut [f64]) + 'a {
        let (weighting, projection) = (&self.weighting, self.projection);
        let n = brdf.sampling().len();
        let mut batch = PairBatch::default();
        move |pts: &[[f64; 4]], out: &mut [f64]| {
            batch.clear(pts.len());
            for (i, x) in pts.iter().enumerate() {
                let ([ps, qs, pr, qr], jac) = map.map(x);
                if jac <= 0.0 {
                    continue;
                }
                let wi = map.axes().source_dir(ps, qs);
                let wo = map.rec_axes().receptor_dir(pr, qr);
                if wi.z <= 0.0 || wo.z <= 0.0 {
                    continue;
                }
                let g = wi.z * wo.z * solid_angle_density(ps, qs) * solid_angle_density(pr, qr) * jac;
                batch.push(i, wi, wo, g);
            }
            batch.values.clear();
            if in_material {
                batch.values.resize(batch.wi.len(), 0.0);
                brdf.eval_batch_folded(&weighting.rows[0], &batch.wi, &batch.wo, &mut batch.values);
                for ((&i, &g), v) in batch.index.iter().zip(&batch.g).zip(&batch.values) {
                    out[i] = v * g;
                }
                return;
            }
            batch.values.resize(batch.wi.len() * n, 0.0);
            brdf.eval_batch(&batch.wi, &batch.wo, &mut batch.values);
            for ((&i, &g), v) in batch.index.iter().zip(&batch.g).zip(batch.values.chunks_exact(n)) {
                store(&mut out[i * ncomp..(i + 1) * ncomp], v, weighting, g, projection);
            }
        }
    }

    /// The map of the regular part `part`'s integrand in `chart`: the part's kinks cut the part's own chart
    /// (and a lobe chart a rule asks for); a plain rule on a lobe part, and the mixed chart, have none.
    fn chart_map<'a>(&self, part: &'a RegularPart, chart: Chart, stops: (Stop, Stop)) -> ChartMap<'a> {
        let kinks: &[f64] = if chart == Chart::Plain && part.chart != Chart::Plain { &[] } else { &part.kinks };
        ChartMap::new(chart, kinks, self.aperture.theta, self.aperture.viewing, stops)
    }

    /// The regular part's integrand at points `pts` of its chart (u, t_p, v, t_q in the lobe chart; p_s, q_s,
    /// p_r, q_r in the plain one): per point, the method's weighted components (or samples), exactly the
    /// values its rules integrate. For checking a rule's assumptions against a denser sampling of the same
    /// integrand (`tests/delta_limit.rs`); empty when there is no regular part or the stops are below the
    /// horizon.
    pub fn sample_regular(&self, brdf: &dyn Brdf, pts: &[[f64; 4]]) -> Vec<f64> {
        let (Some(part), Some(stops), Integral::Aperture) = (&self.regular, self.clipped, self.aperture.integral)
        else {
            return Vec::new();
        };
        let comps = self.components(brdf);
        let mut out = vec![0.0; pts.len() * comps.0];
        self.regular_integrand(brdf, self.chart_map(part, part.chart, stops), comps)(pts, &mut out);
        out
    }

    /// The instant the integral stops refining: its own budget from `start`, under a `shared` deadline (see
    /// [`Method::execute_until`]). None stands for "no deadline" (also a budget too long to be an instant:
    /// never reached).
    fn deadline(&self, start: Instant, shared: Option<Instant>) -> Option<Instant> {
        let after = |s: f64| deadline_after(start, s);
        match (self.max_seconds, shared) {
            (Some(s), Some(d)) => {
                let late = after(LATE_START_SHARE * s).map(|l| d.max(l));
                match (after(s), late) {
                    (Some(a), Some(b)) => Some(a.min(b)),
                    (a, b) => a.or(b),
                }
            }
            (Some(s), None) => after(s),
            (None, d) => d,
        }
    }

    /// A sphere's integral (`Integral::Hemisphere`, `Integral::Port`): per sample, then weighted.
    fn run_sphere(&self, brdf: &dyn Brdf, start: Instant) -> Flux {
        let k = self.weighting.len();
        let r = match self.aperture.integral {
            Integral::Hemisphere => sphere::hemisphere_reflectance(brdf, self.aperture.theta),
            Integral::Port { half_angle } => {
                sphere::port_reflectance(brdf, self.aperture.theta, half_angle, self.rtol, self.max_evals)
            }
            Integral::Aperture => unreachable!("an aperture integral is not a sphere's"),
        };
        let mut flux = Flux::zero(k);
        flux.regular = self.weighting.apply(&r.value);
        flux.error = (0..k).map(|c| self.weighting.component_error(c, &r.error)).collect();
        flux.value = flux.regular.clone();
        flux.evaluations = r.evaluations;
        flux.converged = r.converged;
        flux.budget_spent = !r.converged;
        flux.seconds = start.elapsed().as_secs_f64();
        flux
    }

    fn run(&self, brdf: &dyn Brdf, keep: bool, shared: Option<Instant>) -> (Flux, Option<Method>) {
        let start = Instant::now();
        let deadline = self.deadline(start, shared);
        let k = self.weighting.len();
        let n = brdf.sampling().len();
        let mut frozen = keep.then(|| self.clone());
        if self.aperture.integral != Integral::Aperture {
            // Their integrators have no partition to freeze, so the frozen method is the method.
            return (self.run_sphere(brdf, start), frozen);
        }
        let Some((src, rec)) = self.clipped else {
            return (Flux::zero(k), frozen);
        };
        let axes = Axes::new(self.aperture.theta);
        // The material sums the one weighted component itself when `in_material`.
        let (ncomp, in_material) = self.components(brdf);
        let weighting = &self.weighting;
        let projection = self.projection;
        // The k weighted components of an estimate, and their error bounds.
        let weighted = |e: &Estimate| -> (Vec<f64>, Vec<f64>) {
            match projection {
                Projection::Fold | Projection::FoldInMaterial => (e.value.clone(), e.error.clone()),
                Projection::Separate => (
                    (0..k).map(|c| weighting.component(c, &e.value)).collect(),
                    (0..k).map(|c| weighting.component_error(c, &e.error)).collect(),
                ),
            }
        };
        let mut flux = Flux::zero(k);
        let smooth = brdf.hints().smooth;

        // 1. The delta part: source points whose mirror (−p, −q) lies in the receptor.
        if let Some(part) = &self.delta {
            let mut scratch = vec![0.0; n];
            let (lo, hi) = self.mirror.expect("a delta part has a mirror overlap");
            let (p_lo, p_hi) = (lo[0], hi[0]);
            let (est, cells) = integrate_partition::<2, _>(
                |pts, out| {
                    for (x, o) in pts.iter().zip(out.chunks_exact_mut(ncomp)) {
                        let (p, q, jac) = if part.kinks.is_empty() {
                            (x[0], x[1], 1.0)
                        } else {
                            let (p, jac) = kinked_position(x[0], p_lo, p_hi, part.kinks.len(), |k| {
                                incidence_kink_point(&axes, part.kinks[k], x[1], p_lo, p_hi)
                            });
                            (p, x[1], jac)
                        };
                        if jac <= 0.0 {
                            continue;
                        }
                        let wi = axes.source_dir(p, q);
                        if wi.z <= 0.0 || !brdf.delta_reflectance(wi, &mut scratch) {
                            continue;
                        }
                        store(o, &scratch, weighting, wi.z * solid_angle_density(p, q) * jac, projection);
                    }
                },
                ncomp,
                &part.cells,
                &Options {
                    rtol: part.rtol,
                    atol: part.atol,
                    max_evals: self.max_evals,
                    deadline,
                    checked: smooth,
                    ..Default::default()
                },
                part.refine,
                keep,
            );
            (flux.delta, flux.error) = weighted(&est);
            flux.evaluations += est.evaluations;
            flux.regions += est.regions;
            flux.converged &= est.converged;
            flux.out_of_time |= est.out_of_time;
            flux.budget_spent |= !est.converged && !est.out_of_time && part.refine == Refine::Adaptive;
            if let Some(m) = frozen.as_mut() {
                let p = m.delta.as_mut().expect("the same parts");
                p.cells = cells;
                p.refine = Refine::Frozen;
            }
        }

        // 2. The regular part, in its chart.
        if let Some(part) = &self.regular {
            let delta_min = flux.delta.iter().map(|d| d.abs()).fold(f64::INFINITY, f64::min);
            let atol = part.atol.max(part.rtol * delta_min);
            // A smooth material's region estimates are trusted further (`docs/accuracy.md` §5): checked
            // children, and on the lobe chart (whose boxes are cut to the lobe's widths and kinks) a deeper
            // shrink; the plain chart's boxes are not cut to anything, and shrink least.
            let max_shrink = match part.chart {
                Chart::Plain => MAX_SHRINK_PLAIN,
                Chart::Lobe | Chart::PlainPLobeQ if smooth => MAX_SHRINK_LOBE,
                _ => MAX_SHRINK,
            };
            // The parent's check shrinks no estimate on the plain chart either: it was fooled there as the
            // null rules were (E2539 −15° on GGX tails, 11×; `docs/accuracy.md` §5.2).
            let checked = smooth && part.chart == Chart::Lobe;
            let opts = Options { rtol: part.rtol, atol, max_evals: self.max_evals, deadline, max_shrink, checked };
            let run = RuleRun { ncomp, opts: &opts, refine: part.refine, stops: (src, rec), cells: &part.cells, keep };
            // The part's rule, then its fallbacks (`Rule::fallback`) until one agrees; the Genz–Malik partition
            // at the end of every chain always does. Each rule gets the integrand in its own chart.
            let (mut spent, mut next) = (0, Some(part.rule));
            let (mut est, rule, cells) = loop {
                let rule = next.expect("the Genz–Malik partition ends every fallback chain");
                let map = self.chart_map(part, rule.chart(part.chart), (src, rec));
                let outcome = match rule {
                    Rule::TailBound => self.settle_by_tail(brdf, (src, rec), ncomp, &opts),
                    _ => rule.estimate(&mut self.regular_integrand(brdf, map, (ncomp, in_material)), &run),
                };
                spent += outcome.spent;
                if let Some(done) = outcome.done {
                    break done;
                }
                next = rule.fallback();
            };
            est.evaluations = spent;
            let cells = cells.unwrap_or_else(|| part.cells.clone());
            let (regular, regular_err) = weighted(&est);
            flux.regular = regular;
            flux.error = flux.error.iter().zip(&regular_err).map(|(a, b)| a + b).collect();
            flux.evaluations += est.evaluations;
            flux.regions += est.regions;
            flux.converged &= est.converged;
            flux.out_of_time |= est.out_of_time;
            flux.budget_spent |= !est.converged && !est.out_of_time && part.refine == Refine::Adaptive;
            flux.chart = Some(rule.chart(part.chart));
            if let Some(m) = frozen.as_mut() {
                let p = m.regular.as_mut().expect("the same parts");
                p.cells = cells;
                p.rule = rule;
                p.refine = Refine::Frozen;
            }
        }
        flux.value = flux.delta.iter().zip(&flux.regular).map(|(a, b)| a + b).collect();
        flux.seconds = start.elapsed().as_secs_f64();
        (flux, frozen)
    }
}

/// The direction pairs of one batch above the horizon, with the point index and geometric factor of each.
#[derive(Default)]
struct PairBatch {
    index: Vec<usize>,
    wi: Vec<Vec3>,
    wo: Vec<Vec3>,
    g: Vec<f64>,
    values: Vec<f64>,
}

impl PairBatch {
    /// Empty, with room for `m` pairs (so the hot loop never grows a vector).
    fn clear(&mut self, m: usize) {
        self.index.clear();
        self.wi.clear();
        self.wo.clear();
        self.g.clear();
        self.index.reserve(m);
        self.wi.reserve(m);
        self.wo.reserve(m);
        self.g.reserve(m);
    }

    fn push(&mut self, i: usize, wi: Vec3, wo: Vec3, g: f64) {
        self.index.push(i);
        self.wi.push(wi);
        self.wo.push(wo);
        self.g.push(g);
    }
}

/// Write the integrand at one point: the per-sample values times the geometric factor `g`, either one
/// component per sample ([`Projection::Separate`]) or the k weighted sums Σ_j W\[c\]\[j\] f_j·g (Fold).
#[inline]
fn store(out: &mut [f64], values: &[f64], weighting: &Weighting, g: f64, projection: Projection) {
    match projection {
        Projection::Separate => {
            for (o, v) in out.iter_mut().zip(values) {
                *o = v * g;
            }
        }
        Projection::Fold | Projection::FoldInMaterial => {
            for (c, o) in out.iter_mut().enumerate() {
                *o = weighting.component(c, values) * g;
            }
        }
    }
}

/// The instant `seconds` after `start`; None (no deadline) when the budget is not a finite non-negative
/// number of seconds or lies beyond what an `Instant` can hold (`--max-seconds 1e19` is, in effect, none).
pub(crate) fn deadline_after(start: Instant, seconds: f64) -> Option<Instant> {
    std::time::Duration::try_from_secs_f64(seconds).ok().and_then(|d| start.checked_add(d))
}
