//! Sweeps over recipes: a template recipe whose numbers at given JSON Pointer paths vary over a Cartesian grid
//! or a Latin hypercube, every point measured through the same geometries. Paint designers use it to see how
//! readings move with the recipe (20° gloss and haze against coat roughness and flake spread); a sweep that
//! outgrows one process splits into shards.
//!
//! Design decisions (docs/instrument.md §Sweeps):
//! * **Points are a pure function of their index.** The grid decomposes the index in mixed radix (last axis
//!   fastest); the Latin hypercube draws each axis' cell from a keyed pseudo-random permutation of 0..N (a
//!   Feistel network with cycle walking) and the offset inside the cell from a keyed hash (SplitMix64), so no
//!   point list is ever stored and any point can be computed alone.
//! * **Shards are contiguous index ranges** `[⌊(K−1)·P/M⌋, ⌊K·P/M⌋)`, so the shards' outputs, concatenated in order,
//!   are the unsharded output byte for byte (the CSV header is written by shard 1 only).
//! * **Streaming**: points run in parallel in chunks (their plans compiled in parallel, then all their
//!   integrals in one work queue, `Plan::run_all`) and are written in index order as each chunk ends, so memory does
//!   not grow with the number of points.
//! * **An invalid point is a row**, with the recipe's error in its `problem` column, not a failure of the sweep.
use std::ops::Range;
use std::time::Instant;

use rayon::prelude::*;
use serde_json::{json, Value};

use crate::error::Words;
use crate::instrument::method::Target;
use crate::instrument::plan::{Execution, Plan, PlanOptions, Planner, Reading};
use crate::instrument::reading::ReadingSpec;
use crate::instrument::standards::StandardGeometry;
use crate::{recipe, registry, report, Error, Result};

/// Points per thread in one chunk of [`Sweep::run`]: the rows of a chunk are kept until it ends (constant
/// memory: a few hundred rows), and each chunk ends with at most one integral running alone per thread.
const CHUNK_PER_THREAD: u64 = 64;

/// One varied parameter: a JSON Pointer into the template, its range and (for a grid) its number of values.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepAxis {
    pub path: String,
    pub lo: f64,
    pub hi: f64,
    /// Grid points on this axis (None for a Latin hypercube).
    pub n: Option<u64>,
    /// Logarithmic spacing (lo > 0).
    pub log: bool,
}

/// `PATH=LO..HI:N` (grid) or `PATH=LO..HI` (Latin hypercube).
pub fn parse_vary(s: &str) -> Result<SweepAxis> {
    let bad = |m: &str| {
        Error::argument("vary", format!(" `{s}`: {m} (expected PATH=LO..HI:N, e.g. /coat/roughness=0.01..0.3:8)"))
    };
    let (path, range) = s.rsplit_once('=').ok_or_else(|| bad("no `=`"))?;
    if !(path.is_empty() || path.starts_with('/')) {
        return Err(bad("the path must be a JSON Pointer starting with `/`"));
    }
    let (range, n) = match range.rsplit_once(':') {
        Some((r, n)) => (r, Some(n.trim().parse::<u64>().map_err(|_| bad("N must be a whole number"))?)),
        None => (range, None),
    };
    let (lo, hi) = range.split_once("..").ok_or_else(|| bad("no `..` between LO and HI"))?;
    let num = |t: &str| t.trim().parse::<f64>().ok().filter(|v| v.is_finite());
    let (Some(lo), Some(hi)) = (num(lo), num(hi)) else {
        return Err(bad("LO and HI must be finite numbers"));
    };
    if !(lo < hi) {
        return Err(bad(&format!("LO must be below HI, got {lo} ≥ {hi}")));
    }
    if n == Some(0) {
        return Err(bad("N must be at least 1"));
    }
    Ok(SweepAxis { path: path.to_string(), lo, hi, n, log: false })
}

/// The decimals of a step or a bound: the fewest (at most 12) that write it to within 10⁻⁶ of their last
/// place, so 0.049999999999999996, the double nearest (0.3 − 0.05)/5, has 2 and 1/3 has 12.
fn decimals_of(x: f64) -> i32 {
    (0..12)
        .find(|&d| {
            let scaled = x.abs() * 10f64.powi(d);
            (scaled - scaled.round()).abs() <= 1e-6
        })
        .unwrap_or(12)
}

/// Grid value j of n on a linear axis (docs/instrument.md §Sweeps): LO + j·step, step = (HI − LO)/(n − 1),
/// rounded to the decimals of the step and of LO, so that the values are the decimals the user meant
/// (0.05..0.3:6 gives 0.15, not 0.15000000000000002). A value whose scaled form is beyond 2⁵² is left as
/// computed (it has no fractional decimals to clean).
fn grid_value(lo: f64, hi: f64, j: u64, n: u64) -> f64 {
    let step = (hi - lo) / (n - 1) as f64;
    let x = lo + step * j as f64;
    let d = decimals_of(step).max(decimals_of(lo));
    let scale = 10f64.powi(d);
    if (x * scale).abs() < 4.5e15 {
        (x * scale).round() / scale
    } else {
        x
    }
}

/// `K/M` with 1 ≤ K ≤ M.
pub fn parse_shard(s: &str) -> Result<(u64, u64)> {
    let bad = |m: &str| Error::argument("shard", format!(" `{s}`: {m} (expected K/M with 1 ≤ K ≤ M)"));
    let (k, m) = s.split_once('/').ok_or_else(|| bad("no `/`"))?;
    let (Ok(k), Ok(m)) = (k.trim().parse::<u64>(), m.trim().parse::<u64>()) else {
        return Err(bad("K and M must be whole numbers"));
    };
    if m == 0 || k == 0 || k > m {
        return Err(bad(&format!("K = {k}, M = {m}")));
    }
    Ok((k, m))
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweepDesign {
    /// The Cartesian product of the axes' grids.
    Grid,
    /// A Latin hypercube of n points drawn with a seed.
    Lhs { n: u64, seed: u64 },
}

/// SplitMix64's finaliser (Steele, Lea & Flood 2014, "Fast splittable pseudorandom number generators"): a
/// bijective 64-bit mix, used as a keyed hash.
pub(crate) fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A uniform number in [0, 1) from 64 random bits (the top 53).
fn unit(bits: u64) -> f64 {
    (bits >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A keyed pseudo-random permutation of 0..n, evaluated at i without storing it: a 4-round balanced Feistel
/// network on the smallest even number of bits covering n, with cycle walking (re-encrypt until the result
/// is below n; it terminates because the network is a bijection of a domain smaller than 4n).
pub(crate) fn permute(i: u64, n: u64, key: u64) -> u64 {
    assert!(i < n);
    let bits = (64 - (n - 1).leading_zeros()).max(2);
    let half = bits.div_ceil(2);
    let mask = (1u64 << half) - 1;
    let mut x = i;
    loop {
        let (mut l, mut r) = (x >> half, x & mask);
        for round in 0..4u64 {
            let f = splitmix64(r ^ key.wrapping_mul(0x2545_f491_4f6c_dd1d).wrapping_add(round)) & mask;
            (l, r) = (r, l ^ f);
        }
        x = (l << half) | r;
        if x < n {
            return x;
        }
    }
}

/// A sweep, ready to run point by point.
pub struct Sweep {
    pub template: Value,
    /// The template's file (for messages and the rows' provenance).
    pub file: String,
    pub axes: Vec<SweepAxis>,
    pub design: SweepDesign,
    pub geometries: Vec<StandardGeometry>,
    pub options: PlanOptions,
}

impl Sweep {
    /// Check the axes against the template: every path must exist and hold a number; log axes need lo > 0;
    /// a grid needs N on every axis, a hypercube none.
    pub fn new(
        template: Value,
        file: &str,
        axes: Vec<SweepAxis>,
        design: SweepDesign,
        geometries: Vec<StandardGeometry>,
        options: PlanOptions,
    ) -> Result<Sweep> {
        if axes.is_empty() {
            return Err(Error::Argument(Words::from("give at least one ").and_argument("vary").and(" PATH=LO..HI:N")));
        }
        let model = match template.get("model") {
            Some(Value::String(m)) => m.clone(),
            _ => {
                return Err(Error::input(
                    file,
                    "/model",
                    "the template needs a \"model\" (a recipe, see glossmeter schema)",
                ))
            }
        };
        for (i, a) in axes.iter().enumerate() {
            check_path(&template, file, &model, &a.path)?;
            if axes[..i].iter().any(|b| b.path == a.path) {
                return Err(Error::argument("vary", format!(" {}: the path is varied twice", a.path)));
            }
            if a.log && !(a.lo > 0.0) {
                return Err(Error::argument(
                    "log",
                    format!(" {}: logarithmic spacing needs LO > 0, got {}", a.path, a.lo),
                ));
            }
            match (design, a.n) {
                (SweepDesign::Grid, None) => {
                    return Err(Error::Argument(
                        Words::argument("vary")
                            .and(format!(" {}: a grid needs :N (or use ", a.path))
                            .and_argument("lhs")
                            .and(" N)"),
                    ))
                }
                (SweepDesign::Lhs { .. }, Some(_)) => {
                    return Err(Error::Argument(
                        Words::argument("vary")
                            .and(format!(" {}: with ", a.path))
                            .and_argument("lhs")
                            .and(" the number of points is ")
                            .and_argument("lhs")
                            .and(" N; drop :N"),
                    ))
                }
                _ => {}
            }
        }
        if let SweepDesign::Lhs { n: 0, .. } = design {
            return Err(Error::argument("lhs", " N must be at least 1"));
        }
        let s = Sweep { template, file: file.to_string(), axes, design, geometries, options };
        s.checked_len()?;
        Ok(s)
    }

    fn checked_len(&self) -> Result<u64> {
        match self.design {
            SweepDesign::Lhs { n, .. } => Ok(n),
            SweepDesign::Grid => self.axes.iter().try_fold(1u64, |p, a| {
                p.checked_mul(a.n.expect("grid axes have n"))
                    .ok_or_else(|| Error::Usage("the grid has more than 2^64 points".into()))
            }),
        }
    }

    /// The number of points.
    pub fn len(&self) -> u64 {
        self.checked_len().expect("checked in new")
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The index range of shard K of M (1-based K).
    pub fn shard(&self, k: u64, m: u64) -> Range<u64> {
        let p = self.len() as u128;
        let at = |j: u64| (p * j as u128 / m as u128) as u64;
        at(k - 1)..at(k)
    }

    /// The parameter values of point i.
    pub(crate) fn point(&self, i: u64) -> Vec<f64> {
        let map = |a: &SweepAxis, t: f64| -> f64 {
            // The ends exactly (exp(ln LO) is not always LO).
            if t <= 0.0 {
                return a.lo;
            }
            if t >= 1.0 {
                return a.hi;
            }
            if a.log {
                (a.lo.ln() + (a.hi.ln() - a.lo.ln()) * t).exp()
            } else {
                a.lo + (a.hi - a.lo) * t
            }
        };
        match self.design {
            SweepDesign::Grid => {
                let mut rest = i;
                let mut out = vec![0.0; self.axes.len()];
                for (d, a) in self.axes.iter().enumerate().rev() {
                    let n = a.n.expect("grid");
                    let j = rest % n;
                    rest /= n;
                    out[d] = match n {
                        1 => a.lo,
                        _ if a.log || j == 0 || j == n - 1 => map(a, j as f64 / (n - 1) as f64),
                        _ => grid_value(a.lo, a.hi, j, n),
                    };
                }
                out
            }
            SweepDesign::Lhs { n, seed } => self
                .axes
                .iter()
                .enumerate()
                .map(|(d, a)| {
                    let key = splitmix64(seed ^ splitmix64(d as u64 + 1));
                    let cell = permute(i, n, key);
                    let r = unit(splitmix64(key ^ splitmix64(i.wrapping_add(0x5bd1_e995))));
                    map(a, (cell as f64 + r) / n as f64)
                })
                .collect(),
        }
    }

    /// The reported readings of every point: (geometry id, reading name, unit), in output order.
    pub(crate) fn columns(&self) -> Vec<(String, String, String)> {
        let mut out = vec![];
        for g in &self.geometries {
            for (name, spec) in g.reading_names.iter().zip(&g.geometry.readings) {
                out.push((g.geometry.id.clone(), name.clone(), spec.unit().to_string()));
            }
        }
        out
    }

    /// Whether the reading `name` of geometry `id` is a colour reading.
    fn is_colour(&self, id: &str, name: &str) -> bool {
        self.geometries.iter().filter(|g| g.geometry.id == id).any(|g| {
            g.reading_names
                .iter()
                .zip(&g.geometry.readings)
                .any(|(n, spec)| n == name && matches!(spec, ReadingSpec::Colour { .. }))
        })
    }

    /// Measure point i: the template with the point's values, validated and read through the geometries.
    pub fn run_point(&self, i: u64) -> PointResult {
        let start = Instant::now();
        let (values, plan) = self.plan_point(i, &Planner::new().expect("the builtin geometries parse"));
        let outcome = plan.map(|p| p.execute());
        PointResult { index: i, values, outcome, seconds: start.elapsed().as_secs_f64() }
    }

    /// The values of point i and its plan (or the recipe's error, as text for the row).
    fn plan_point(&self, i: u64, planner: &Planner) -> (Vec<f64>, std::result::Result<Plan, String>) {
        let values = self.point(i);
        let mut recipe_json = self.template.clone();
        for (a, v) in self.axes.iter().zip(&values) {
            set(&mut recipe_json, &a.path, json!(v));
        }
        let name = format!("{} [point {i}]", self.file);
        let plan = recipe::parse_str(&recipe_json.to_string(), &name)
            .and_then(|m| planner.compile(m.brdf, self.geometries.clone(), self.options.clone()))
            .map_err(|e| e.to_string());
        (values, plan)
    }

    /// Run the points of `range` in parallel, in chunks, handing each result to `sink` in index order. In
    /// each chunk the points' plans are compiled in parallel (one [`Planner`] for the whole run, so the gloss
    /// standards' fluxes are computed once), then every integral of every plan runs in one work queue,
    /// largest expected first ([`Plan::run_all`]): the threads balance integrals, not points, and a chunk
    /// ends with small integrals on every thread. A point's `seconds` is its parsing and planning time plus the wall time of
    /// its integrals.
    pub fn run(&self, range: Range<u64>, sink: impl FnMut(PointResult) -> Result<()>) -> Result<()> {
        self.run_reporting(range, sink, &|_| {})
    }

    /// [`Sweep::run`], reporting the work done as it is done (docs/instrument.md §Sweeps, progress):
    /// `progress(points)` gets the points of the range completed so far, fractional and non-decreasing, after
    /// every integral: each integral completes the share of its point that its expected evaluation count is of
    /// the point's (a point whose recipe is invalid counts whole once planned). The rows still come in index
    /// order at the end of each chunk; only the count moves within it. The results are the same bits.
    pub(crate) fn run_reporting(
        &self,
        range: Range<u64>,
        mut sink: impl FnMut(PointResult) -> Result<()>,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<()> {
        let planner = Planner::new()?;
        let completed = std::sync::Mutex::new(0.0f64);
        let add = |x: f64| {
            let mut c = completed.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            *c += x;
            progress(*c);
        };
        let chunk = CHUNK_PER_THREAD * rayon::current_num_threads().max(1) as u64;
        let mut start = range.start;
        while start < range.end {
            // Saturating: a shard that ends at or near u64::MAX must not wrap around (it looped for ever).
            let end = start.saturating_add(chunk).min(range.end);
            let planned: Vec<(Vec<f64>, std::result::Result<Plan, String>, f64)> = (start..end)
                .into_par_iter()
                .map(|i| {
                    let t = Instant::now();
                    let (values, plan) = self.plan_point(i, &planner);
                    (values, plan, t.elapsed().as_secs_f64())
                })
                .collect();
            let mut rows = Vec::with_capacity(planned.len());
            let mut plans = Vec::new();
            for (values, plan, planning) in planned {
                let planned_ok = match plan {
                    Ok(p) => {
                        plans.push(p);
                        Ok(plans.len() - 1)
                    }
                    Err(m) => Err(m),
                };
                rows.push((values, planned_ok, planning));
            }
            // The share of its point each integral completes; points with nothing to integrate count now.
            let shares: Vec<Vec<f64>> = plans
                .iter()
                .map(|p| {
                    let w: Vec<f64> = p.jobs.iter().map(|j| j.method.expected_evaluations().max(1.0)).collect();
                    let total: f64 = p.specimen_jobs().iter().map(|&j| w[j]).sum();
                    w.iter().map(|x| x / total).collect()
                })
                .collect();
            let immediate =
                (end - start) as usize - plans.len() + plans.iter().filter(|p| p.specimen_jobs().is_empty()).count();
            if immediate > 0 {
                add(immediate as f64);
            }
            let mut runs: Vec<Option<Execution>> =
                Plan::run_all_reporting(&plans, &|p, j| add(shares[p][j])).into_iter().map(Some).collect();
            // Whole at the chunk's end (the shares' sum has rounding in its last bits).
            {
                let mut c = completed.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                *c = (end - range.start) as f64;
                progress(*c);
            }
            for ((values, planned_ok, planning), i) in rows.into_iter().zip(start..end) {
                let (outcome, seconds) = match planned_ok {
                    Ok(k) => {
                        let e = runs[k].take().expect("one execution per plan");
                        let integrals: f64 = plans[k]
                            .jobs
                            .iter()
                            .zip(&e.fluxes)
                            .filter(|(j, _)| j.method.aperture.target == Target::Specimen)
                            .map(|(_, f)| f.seconds)
                            .sum();
                        (Ok(e.readings), planning + integrals)
                    }
                    Err(m) => (Err(m), planning),
                };
                sink(PointResult { index: i, values, outcome, seconds })?;
            }
            // Freed in parallel, as in `batch::run_many` (a plan is a few hundred allocations).
            plans.into_par_iter().for_each(drop);
            start = end;
        }
        Ok(())
    }

    /// The CSV header: index, one column per parameter, value and error of every reading, problem (and
    /// seconds when timed).
    pub(crate) fn csv_header(&self, timing: bool) -> String {
        let mut h: Vec<String> = vec!["index".into()];
        h.extend(self.axes.iter().map(|a| a.path.clone()));
        for (g, n, u) in self.columns() {
            // A colour reading's header says its conditions beside its unit (`b* (A / 2°)`, `h (°, A / 2°)`).
            let colour = self.is_colour(&g, &n).then(|| {
                let c = self.options.colour;
                format!("{} / {}°", c.illuminant.id(), c.observer.id())
            });
            let said: Vec<&str> =
                [Some(u.as_str()), colour.as_deref()].into_iter().flatten().filter(|s| !s.is_empty()).collect();
            h.push(format!("{g} {n} ({})", said.join(", ")));
            h.push(format!("{g} {n} error"));
        }
        h.push("problem".into());
        if timing {
            h.push("seconds".into());
        }
        csv_line(&h)
    }

    /// One CSV row: the point's values as Rust's shortest round-trip decimals, each reading and its error
    /// estimate to their precision (`report::with_error`); empty where there is no value.
    pub fn csv_row(&self, r: &PointResult, timing: bool) -> String {
        let mut row: Vec<String> = vec![r.index.to_string()];
        row.extend(r.values.iter().map(|v| v.to_string()));
        let cols = self.columns();
        let (cells, problem) = self.cells(r, &cols);
        for c in cells {
            match c {
                Some((v, e)) => {
                    let (v, e) = report::with_error(v, e);
                    row.push(v);
                    row.push(e);
                }
                None => {
                    row.push(String::new());
                    row.push(String::new());
                }
            }
        }
        row.push(problem);
        if timing {
            row.push(format!("{:.6}", r.seconds));
        }
        csv_line(&row)
    }

    /// One point as a document: the report's [`report::SweepLineDoc`], each reading a
    /// [`report::SweepReadingDoc`] (what a JSON line holds; the Python bindings' `sweep` returns them).
    pub fn line_doc(&self, r: &PointResult, timing: bool) -> report::SweepLineDoc {
        report::SweepLineDoc {
            index: r.index,
            parameters: self.axes.iter().zip(&r.values).map(|(a, v)| (a.path.clone(), *v)).collect(),
            readings: r.outcome.as_ref().ok().map(|rs| rs.iter().map(report::SweepReadingDoc::new).collect()),
            problem: r.outcome.as_ref().err().cloned(),
            seconds: timing.then_some(r.seconds),
        }
    }

    /// One JSON line ([`Sweep::line_doc`]).
    pub(crate) fn jsonl_row(&self, r: &PointResult, timing: bool) -> String {
        report::to_json(&self.line_doc(r, timing)).to_string() + "\n"
    }

    fn cells(&self, r: &PointResult, cols: &[(String, String, String)]) -> (Vec<Option<(f64, f64)>>, String) {
        match &r.outcome {
            Err(e) => (vec![None; cols.len()], e.clone()),
            Ok(readings) => {
                let mut problems = vec![];
                let cells = cols
                    .iter()
                    .map(|(g, n, _)| {
                        let x = readings.iter().find(|x| &x.geometry == g && &x.name == n)?;
                        if let Some(p) = &x.problem {
                            problems.push(format!("{g} {n}: {p}"));
                        } else if !x.converged {
                            problems.push(format!("{g} {n}: not converged within the evaluation budget"));
                        }
                        x.value.map(|v| (v, x.error_estimate))
                    })
                    .collect();
                (cells, problems.join("; "))
            }
        }
    }
}

/// A varied path must be a numeric parameter of the template's model in the parameter registry
/// (`crate::registry`), addressing one number: the template's value there is a number, or the key is absent
/// from an object that exists (an optional parameter, set at each point), or the registry allows one number
/// in place of the array the template has (a grey albedo for an RGB one).
fn check_path(template: &Value, file: &str, model: &str, path: &str) -> Result<()> {
    let Some(param) = registry::lookup(model, path) else {
        let examples: Vec<String> = registry::of_model(model)
            .filter(|p| p.ty.is_numeric() && !p.pointer.contains('*'))
            .take(6)
            .map(|p| p.pointer.to_string())
            .collect();
        let which = if examples.is_empty() {
            "it has no numeric parameter to vary".to_string()
        } else {
            format!("its numeric parameters include {}", examples.join(", "))
        };
        return Err(Error::input(
            file,
            path,
            Words::argument("vary").and(format!(
                ": not a parameter of a `{model}` recipe ({which}; the full list is in docs/recipe-format.md)"
            )),
        ));
    };
    if !param.ty.is_numeric() {
        return Err(Error::input(
            file,
            path,
            Words::argument("vary").and(format!(": the parameter is {}, not a number", param.ty.describe())),
        ));
    }
    let one_number_allowed = matches!(
        param.ty,
        registry::Type::Number
            | registry::Type::Colour
            | registry::Type::NumberOrSpectral
            | registry::Type::DielectricOrConductorIor
    ) || param.pointer != path; // an element of an array entry
    match template.pointer(path) {
        Some(Value::Number(_)) => Ok(()),
        Some(_) if one_number_allowed => Ok(()),
        Some(_) => Err(Error::input(
            file,
            path,
            Words::argument("vary").and(format!(
                " needs one number: the parameter is {}; vary one element ({path}/0)",
                param.ty.describe()
            )),
        )),
        None => {
            let (parent, _) = path.rsplit_once('/').expect("a registered pointer has a /");
            match template.pointer(parent) {
                Some(Value::Object(_)) if one_number_allowed => Ok(()),
                _ => Err(Error::input(
                    file,
                    path,
                    Words::argument("vary").and(
                        ": the template has no value here and no object to add it to (give the parameter in the \
                         template)",
                    ),
                )),
            }
        }
    }
}

/// Set the number at `path` (checked by [`check_path`]): replace the value, or add the key to its object.
fn set(doc: &mut Value, path: &str, v: Value) {
    if let Some(x) = doc.pointer_mut(path) {
        *x = v;
        return;
    }
    let (parent, key) = path.rsplit_once('/').expect("checked");
    if let Some(Value::Object(o)) = doc.pointer_mut(parent) {
        o.insert(registry::unescape(key), v);
    }
}

fn csv_line(fields: &[String]) -> String {
    let mut w = csv::WriterBuilder::new().terminator(csv::Terminator::Any(b'\n')).from_writer(vec![]);
    w.write_record(fields).expect("writing to memory");
    String::from_utf8(w.into_inner().expect("writing to memory")).expect("utf-8")
}

/// One point's outcome: its readings, or why the recipe at that point is invalid.
#[derive(Clone, Debug)]
pub struct PointResult {
    pub index: u64,
    pub values: Vec<f64>,
    pub outcome: std::result::Result<Vec<Reading>, String>,
    pub seconds: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permutations_are_bijections() {
        for n in [1u64, 2, 3, 7, 16, 100, 1000] {
            let mut seen: Vec<u64> = (0..n).map(|i| permute(i, n, 42)).collect();
            seen.sort();
            assert_eq!(seen, (0..n).collect::<Vec<_>>(), "n = {n}");
        }
    }

    fn sweep(axes: Vec<SweepAxis>, design: SweepDesign) -> Result<Sweep> {
        let t: Value = serde_json::from_str(r#"{"model": "lambert", "albedo": 0.5}"#).unwrap();
        Sweep::new(t, "t.json", axes, design, vec![], PlanOptions::default())
    }

    /// Progress comes from the work done: within a chunk, after every integral, never decreasing, and whole
    /// at the end; the rows are the same bits as without it.
    #[test]
    fn progress_is_reported_per_integral() {
        let geos =
            crate::resolve_geometries(&["astm-d523-20", "astm-d523-60", "astm-e430-30"], &[] as &[&str]).unwrap();
        let t: Value = serde_json::from_str(r#"{"model": "lambert", "albedo": 0.5}"#).unwrap();
        let axes = vec![parse_vary("/albedo=0.1..0.9:6").unwrap()];
        let s = Sweep::new(t, "t.json", axes, SweepDesign::Grid, geos, PlanOptions::default()).unwrap();
        let seen = std::sync::Mutex::new(Vec::<f64>::new());
        let mut rows = String::new();
        s.run_reporting(
            0..6,
            |r| {
                rows.push_str(&s.csv_row(&r, false));
                Ok(())
            },
            &|done| seen.lock().unwrap().push(done),
        )
        .unwrap();
        let seen = seen.into_inner().unwrap();
        // Six points in one chunk, several integrals each: many reports before the chunk's rows come.
        assert!(seen.len() > 12, "{} reports", seen.len());
        assert!(seen.windows(2).all(|w| w[1] >= w[0]), "{seen:?}");
        assert!(seen[0] < 1.0 && seen.iter().filter(|&&d| d < 6.0).count() > 6, "{seen:?}");
        assert_eq!(*seen.last().unwrap(), 6.0);
        let mut plain = String::new();
        s.run(0..6, |r| {
            plain.push_str(&s.csv_row(&r, false));
            Ok(())
        })
        .unwrap();
        assert_eq!(rows, plain);
    }

    #[test]
    fn grid_and_hypercube_points() {
        let a = parse_vary("/albedo=0.1..0.9:5").unwrap();
        let s = sweep(vec![a.clone()], SweepDesign::Grid).unwrap();
        let v: Vec<f64> = (0..5).map(|i| s.point(i)[0]).collect();
        // The user's decimals (LO + j·step rounded to the step's decimals), not 0.30000000000000004.
        assert_eq!(v, [0.1, 0.3, 0.5, 0.7, 0.9]);
        let s = sweep(vec![parse_vary("/albedo=0.05..0.3:6").unwrap()], SweepDesign::Grid).unwrap();
        let v: Vec<String> = (0..6).map(|i| s.point(i)[0].to_string()).collect();
        assert_eq!(v, ["0.05", "0.1", "0.15", "0.2", "0.25", "0.3"]);
        // A step with no short decimal form keeps 12 decimals.
        let s = sweep(vec![parse_vary("/albedo=0..1:4").unwrap()], SweepDesign::Grid).unwrap();
        assert_eq!(s.point(1)[0].to_string(), "0.333333333333");
        let mut l = a.clone();
        l.log = true;
        let s = sweep(vec![l], SweepDesign::Grid).unwrap();
        assert!((s.point(2)[0] - 0.3).abs() < 1e-15 && s.point(4)[0] == 0.9);
        // A Latin hypercube puts exactly one point in each of the n cells of every axis.
        let b = SweepAxis { n: None, ..a.clone() };
        let s = sweep(vec![b], SweepDesign::Lhs { n: 8, seed: 7 }).unwrap();
        let mut cells: Vec<usize> = (0..8).map(|i| ((s.point(i)[0] - 0.1) / 0.8 * 8.0) as usize).collect();
        cells.sort();
        assert_eq!(cells, (0..8).collect::<Vec<_>>());
        // Shards tile the range.
        let s = sweep(vec![parse_vary("/albedo=0..1:10").unwrap()], SweepDesign::Grid).unwrap();
        let r: Vec<_> = (1..=3).map(|k| s.shard(k, 3)).collect();
        assert_eq!(r, [0..3, 3..6, 6..10]);
    }

    #[test]
    fn bad_sweeps() {
        for bad in ["/albedo=0.5..0.5:3", "/albedo=0.9..0.1:3", "/albedo=0..1:0", "albedo=0..1:2", "/albedo=a..1:2"] {
            assert!(parse_vary(bad).is_err(), "{bad}");
        }
        for bad in ["0/3", "4/3", "1/0", "x"] {
            assert!(parse_shard(bad).is_err(), "{bad}");
        }
        assert!(sweep(vec![parse_vary("/nope=0..1:2").unwrap()], SweepDesign::Grid).is_err());
        assert!(sweep(vec![parse_vary("/model=0..1:2").unwrap()], SweepDesign::Grid).is_err());
        assert!(sweep(vec![parse_vary("/albedo=0..1").unwrap()], SweepDesign::Grid).is_err());
    }
}
