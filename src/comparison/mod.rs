//! Predictions set beside instrument sheets: repeated readings reduced to statistics, the verdict rule, many
//! samples with their own recipes measured in parallel, and baselines (a previous run's JSON) that guard
//! presets against silent drift. The command line (`compare`, `measure --baseline`) only formats these
//! results, so programs (and the Python bindings) get the same checks.
//!
//! **The verdict** (docs/instrument.md §Sheets). A sample's n readings of one reading have mean x̄ and sample
//! standard deviation s (n − 1 in the denominator; 0 for n = 1). The prediction P has the error estimate e_P.
//! The allowance is
//!
//! ```text
//! A = k·√(s²/n + u_pred²) + u,      inside ⇔ |P − x̄| ≤ A + e_P,
//! ```
//!
//! k·s/√n being k standard errors of the mean (k = 2 by default, about 95 % for a normal mean), u_pred the
//! prediction's own standard uncertainty, propagated from the standard uncertainties the recipe states for its
//! numbers ([`propagation`]; 0 without them, when the first part is k·s/√n itself, the same bits), and u the
//! stated uncertainty (the largest of the rows' `uncertainty`, else the reading's tolerance: the most specific
//! `--tolerance` key naming it, `astm-e430-30/doi=3` before `doi=3` before a plain `3`,
//! [`VerdictRule::tolerance_for`]). The mean's spread and the prediction's uncertainty are independent
//! standard uncertainties of the difference P − x̄, so they add in quadrature before the coverage factor k
//! (docs/instrument.md §The prediction's uncertainty); the stated tolerance and the numerical error are bounds
//! and add linearly. With n = 1, no stated uncertainty and no u_pred there is no allowance: the row is
//! unchecked, which fails the check like an outside row.
//!
//! The folder:
//! * `mod.rs`: the statistics of repeated readings ([`statistics`], [`group_rows`]), the verdict rule
//!   ([`VerdictRule`], [`Verdict`]), one sample judged against its prediction ([`judge`] → [`Comparison`]) and
//!   a whole sheet, each distinct recipe measured once and in parallel ([`compare_sheet`]), a sheet read as
//!   targets for other callers ([`read_targets`]), colour differences ([`colour_differences`]), and baselines
//!   (`baseline.rs`: [`load_baseline`], [`check_baseline`] → [`Drift`]);
//! * [`sheet`]: the input format, instrument sheets as instruments and spreadsheets write them (encodings,
//!   separators, decimal commas, header aliases, metadata, repeats: [`sheet::load`], [`sheet::parse`] →
//!   [`sheet::Sheet`] of [`sheet::SheetRow`]s, [`sheet::READING_COLUMNS`]), with errors naming file, line and
//!   column (or the workbook's sheet, row and cell). It imports nothing of the crate but `input`, `error` and its
//!   two helpers:
//! * [`workbook`]: one sheet of an `.xlsx`/`.xls`/`.ods` workbook (calamine) as the text the sheet reader reads;
//! * [`series`]: the makers' statistics columns (`Mean 20°`, `Std 20°`, min, max, range) and their check
//!   against the repeated readings;
//! * [`propagation`]: the prediction's uncertainty, the recipe's stated parameter uncertainties propagated to
//!   every reading to first order ([`propagation::propagate`]).
mod baseline;
pub(crate) mod conditions;
pub mod propagation;
pub(crate) mod series;
pub mod sheet;
pub(crate) mod workbook;

use std::collections::HashMap;
use std::path::PathBuf;

use rayon::prelude::*;

use self::propagation::PredictionUncertainty;
use self::sheet::{Layout, Sheet, SheetOptions, SheetRow};
use crate::error::Words;
use crate::input::Source;
use crate::instrument::plan::{Plan, PlanOptions, Reading};
use crate::instrument::standards::{self, StandardGeometry};
use crate::recipe::{self, Material};
use crate::{Error, Result};

#[cfg(feature = "cli")]
pub(crate) use self::baseline::load_baseline_source;
pub use self::baseline::{check_baseline, load_baseline, BaselineEntry, Drift};

/// n, mean, sample standard deviation, min and max of repeated readings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Statistics {
    pub n: usize,
    pub mean: f64,
    /// Sample standard deviation (denominator n − 1); 0 when n = 1.
    pub std: f64,
    pub min: f64,
    pub max: f64,
}

/// Statistics of a non-empty list of finite values (two-pass: mean first, then squared deviations).
pub(crate) fn statistics(values: &[f64]) -> Statistics {
    assert!(!values.is_empty(), "statistics of no values");
    let n = values.len();
    let mean = values.iter().sum::<f64>() / n as f64;
    let ss: f64 = values.iter().map(|v| (v - mean) * (v - mean)).sum();
    let std = if n > 1 { (ss / (n - 1) as f64).sqrt() } else { 0.0 };
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Statistics { n, mean, std, min, max }
}

/// All rows of one sample for one reading.
#[derive(Clone, Debug)]
pub struct Group {
    pub sample: String,
    pub geometry: String,
    pub reading: String,
    /// The sheet's lines and columns the values came from (in file order).
    pub lines: Vec<usize>,
    pub columns: Vec<String>,
    pub values: Vec<f64>,
    /// The largest uncertainty stated on the rows.
    pub uncertainty: Option<f64>,
    pub not_predicted: Option<String>,
    pub stats: Statistics,
}

/// Rows grouped by (sample, geometry, reading), in order of first appearance.
pub(crate) fn group_rows(rows: &[SheetRow]) -> Vec<Group> {
    let mut index: HashMap<(&str, &str, &str), usize> = HashMap::new();
    let mut groups: Vec<Group> = Vec::new();
    for r in rows {
        let key = (r.sample.as_str(), r.geometry.as_str(), r.reading.as_str());
        let i = *index.entry(key).or_insert_with(|| {
            groups.push(Group {
                sample: r.sample.clone(),
                geometry: r.geometry.clone(),
                reading: r.reading.clone(),
                lines: vec![],
                columns: vec![],
                values: vec![],
                uncertainty: None,
                not_predicted: r.not_predicted.clone(),
                stats: statistics(&[r.value]),
            });
            groups.len() - 1
        });
        let g = &mut groups[i];
        g.lines.push(r.line);
        if !g.columns.contains(&r.column) {
            g.columns.push(r.column.clone());
        }
        g.values.push(r.value);
        g.uncertainty = match (g.uncertainty, r.uncertainty) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        };
    }
    for g in &mut groups {
        g.stats = statistics(&g.values);
    }
    groups
}

/// A sheet read as targets, for callers other than `compare` (`fit --sheet`): every (sample, geometry,
/// reading) with its values, the largest stated uncertainty, the statistics and the lines they came from.
pub fn read_targets(source: &Source, options: &SheetOptions) -> Result<(Sheet, Vec<Group>)> {
    let sheet = sheet::load_source(source, options)?;
    let groups = group_rows(&sheet.rows);
    Ok((sheet, groups))
}

/// How verdicts are reached.
#[derive(Clone, Debug, PartialEq)]
pub struct VerdictRule {
    /// Standard errors of the mean allowed (default 2).
    pub k: f64,
    /// The uncertainty of rows that state none and that no entry of `per_reading` names.
    pub tolerance: Option<f64>,
    /// Tolerances of some readings (`gloss=2`, `astm-e430-30/doi=3`), in the readings' own units; the most
    /// specific one that names a row applies ([`VerdictRule::tolerance_for`]).
    pub per_reading: Vec<ReadingTolerance>,
}

impl Default for VerdictRule {
    fn default() -> Self {
        VerdictRule { k: 2.0, tolerance: None, per_reading: vec![] }
    }
}

/// A tolerance for the readings a key names (docs/instrument.md §Repeated readings and the verdict): `KEY=VALUE`
/// where KEY is a reading's name or quantity (`gloss`, `haze`, `log-haze`, `doi`, `haze-narrow`, `L*`) or
/// `GEOMETRY/READING` (`astm-e430-30/doi`); a plain number is the tolerance of every other reading.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadingTolerance {
    /// The geometry id, when the key names one.
    pub geometry: Option<String>,
    /// The reading's name or quantity.
    pub reading: String,
    pub value: f64,
}

impl ReadingTolerance {
    /// The key as written (`gloss`, `astm-e430-30/doi`).
    pub(crate) fn key(&self) -> String {
        match &self.geometry {
            Some(g) => format!("{g}/{}", self.reading),
            None => self.reading.clone(),
        }
    }

    /// How specifically this entry names a reading of `geometry` with this name and quantity: 3 for its
    /// geometry and name, 2 for its name, 1 for its quantity, None when it does not name it.
    fn names(&self, geometry: &str, name: &str, quantity: &str) -> Option<u8> {
        let of_reading = if self.reading == name {
            Some(2)
        } else if self.reading == quantity {
            Some(1)
        } else {
            None
        };
        match &self.geometry {
            Some(g) if g == geometry => of_reading.map(|_| 3),
            Some(_) => None,
            None => of_reading,
        }
    }
}

/// One `--tolerance` argument: a plain number (`2`, every reading without a more specific one) or `KEY=VALUE`
/// ([`ReadingTolerance`]). Returns (None, plain) or (Some(entry), _).
pub(crate) fn parse_tolerance(text: &str) -> Result<(Option<ReadingTolerance>, f64)> {
    let bad = |why: String| Error::argument("tolerance", format!(" {text:?}: {why}"));
    let number = |v: &str| -> Result<f64> {
        let x: f64 = v.trim().parse().map_err(|_| bad(format!("`{}` is not a number", v.trim())))?;
        if !(x.is_finite() && x >= 0.0) {
            return Err(bad("a tolerance must be a finite number ≥ 0".into()));
        }
        Ok(x)
    };
    let Some((key, value)) = text.split_once('=') else {
        return number(text).map(|x| (None, x)).map_err(|_| {
            bad("give a number (every reading) or KEY=NUMBER, KEY a reading (`gloss`, `haze`, `doi`) or \
                 GEOMETRY/READING (`astm-e430-30/doi`)"
                .into())
        });
    };
    let value = number(value)?;
    let key = key.trim();
    let (geometry, reading) = match key.split_once('/') {
        Some((g, r)) => (Some(g.trim().to_string()), r.trim().to_string()),
        None => (None, key.to_string()),
    };
    if reading.is_empty() || geometry.as_deref().is_some_and(str::is_empty) {
        return Err(bad("the key before `=` names no reading (`gloss=2`, `astm-e430-30/doi=3`)".into()));
    }
    if let Some(g) = &geometry {
        standards::find(g).map_err(|e| bad(e.to_string()))?;
    }
    Ok((Some(ReadingTolerance { geometry, reading, value }), value))
}

impl VerdictRule {
    pub(crate) fn check(&self) -> Result<()> {
        if !(self.k.is_finite() && self.k >= 0.0) {
            return Err(Error::argument(
                "k",
                format!(" must be a finite number ≥ 0, got {}", crate::error::given(self.k)),
            ));
        }
        if let Some(t) = self.tolerance {
            if !(t.is_finite() && t >= 0.0) {
                return Err(Error::argument(
                    "tolerance",
                    format!(" must be a finite number ≥ 0, got {}", crate::error::given(t)),
                ));
            }
        }
        for t in &self.per_reading {
            if !(t.value.is_finite() && t.value >= 0.0) {
                return Err(Error::argument(
                    "tolerance",
                    format!(" {}: must be a finite number ≥ 0, got {}", t.key(), crate::error::given(t.value)),
                ));
            }
        }
        Ok(())
    }

    /// The rule of `--tolerance` arguments ([`parse_tolerance`]), each a plain number (at most one) or
    /// `KEY=VALUE` (at most one per key).
    pub(crate) fn with_tolerances(k: f64, arguments: &[String]) -> Result<VerdictRule> {
        let mut rule = VerdictRule { k, ..VerdictRule::default() };
        for a in arguments {
            match parse_tolerance(a)? {
                (None, plain) => {
                    if rule.tolerance.replace(plain).is_some() {
                        return Err(Error::argument("tolerance", " was given two plain numbers; give one"));
                    }
                }
                (Some(t), _) => {
                    if rule.per_reading.iter().any(|u| u.key() == t.key()) {
                        return Err(Error::argument("tolerance", format!(" {} was given twice", t.key())));
                    }
                    rule.per_reading.push(t);
                }
            }
        }
        rule.check()?;
        Ok(rule)
    }

    /// The tolerance of a reading of `geometry` with this name and quantity: the most specific entry of
    /// `per_reading` that names it (geometry and reading, then the reading's name, then its quantity), else
    /// the plain `tolerance`.
    pub(crate) fn tolerance_for(&self, geometry: &str, name: &str, quantity: &str) -> Option<f64> {
        self.per_reading
            .iter()
            .filter_map(|t| t.names(geometry, name, quantity).map(|rank| (rank, t.value)))
            .max_by_key(|(rank, _)| *rank)
            .map(|(_, v)| v)
            .or(self.tolerance)
    }

    /// An entry of `per_reading` that names none of the comparisons' readings (a mistyped key): an error
    /// listing the readings there are.
    fn check_every_key_used(&self, comparisons: &[Comparison]) -> Result<()> {
        for t in &self.per_reading {
            let used = comparisons.iter().any(|c| {
                let (name, quantity) = match &c.predicted {
                    Some(p) => (p.name.as_str(), p.quantity.as_str()),
                    None => (c.group.reading.as_str(), c.group.reading.as_str()),
                };
                t.names(&c.group.geometry, name, quantity).is_some()
            });
            if !used {
                let mut have: Vec<String> = comparisons
                    .iter()
                    .map(|c| format!("{}/{}", c.group.geometry, c.group.reading))
                    .collect::<std::collections::BTreeSet<_>>()
                    .into_iter()
                    .collect();
                have.truncate(12);
                return Err(Error::argument(
                    "tolerance",
                    format!(" {}={}: names no reading of the sheet (it has: {})", t.key(), t.value, have.join(", ")),
                ));
            }
        }
        Ok(())
    }
}

/// The parts of the allowed difference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Allowance {
    /// k·s/√n.
    pub statistical: f64,
    /// u_pred: the prediction's standard uncertainty propagated from the recipe's stated uncertainties (0
    /// without them).
    pub prediction_uncertainty: f64,
    /// k·√(s²/n + u_pred²): the mean's spread and the prediction's uncertainty combined; `statistical`
    /// itself (the same bits) when u_pred = 0.
    pub random: f64,
    /// The stated uncertainty (or the tolerance).
    pub stated: f64,
    /// The prediction's error estimate, plus its data uncertainty when the material is a measured table (the
    /// table's resolution is as much a limit of the prediction as the integration; docs/accuracy.md §Data
    /// uncertainty of measured tables).
    pub prediction: f64,
}

impl Allowance {
    /// The allowance of k, the standard error of the mean s/√n (`statistical` is k·s/√n as the caller computed
    /// it), u_pred, the stated uncertainty and the prediction's numerical error.
    pub(crate) fn new(
        k: f64,
        statistical: f64,
        standard_error: f64,
        u_pred: f64,
        stated: f64,
        prediction: f64,
    ) -> Self {
        let random =
            if u_pred > 0.0 { k * (standard_error * standard_error + u_pred * u_pred).sqrt() } else { statistical };
        Allowance { statistical, prediction_uncertainty: u_pred, random, stated, prediction }
    }

    pub fn total(&self) -> f64 {
        self.random + self.stated + self.prediction
    }

    /// The parts that add up to [`Allowance::total`], in the order they are added: (name, formula, value).
    pub fn parts(&self) -> [(&'static str, &'static str, f64); 3] {
        let random = if self.prediction_uncertainty > 0.0 {
            ("statistical and prediction uncertainty", "k·√(s²/n + u_pred²)", self.random)
        } else {
            ("statistical", "k·s/√n", self.random)
        };
        [random, ("stated", "stated uncertainty or tolerance", self.stated), ("numerical", "e_P", self.prediction)]
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    Inside,
    Outside,
    /// Neither repeated readings nor a stated uncertainty: nothing to check against.
    NoAllowance,
    /// The reading was predicted but has no finite value (the reason).
    NoValue(String),
    /// glossmeter does not predict this reading (the reason).
    NotPredicted(String),
}

impl Verdict {
    pub(crate) fn label(&self) -> &'static str {
        match self {
            Verdict::Inside => "ok",
            Verdict::Outside => "OUTSIDE",
            Verdict::NoAllowance | Verdict::NoValue(_) => "unchecked",
            Verdict::NotPredicted(_) => "not predicted",
        }
    }
    /// Whether the verdict fails a check (exit status 1): outside, or a check that could not be made
    /// (docs/instrument.md §Exit statuses). "Not predicted" is reported, not failed.
    #[cfg(test)]
    pub(crate) fn fails(&self) -> bool {
        matches!(self, Verdict::Outside | Verdict::NoValue(_) | Verdict::NoAllowance)
    }
    /// Why the row could not be checked, if it could not.
    pub(crate) fn why_unchecked(&self) -> Option<String> {
        match self {
            Verdict::NoValue(why) => Some(format!("the prediction has no value ({why})")),
            Verdict::NoAllowance => {
                Some("no allowed difference: a single reading with no uncertainty, and no --tolerance was given".into())
            }
            _ => None,
        }
    }
}

/// One (sample, reading) of the sheet beside its prediction.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// The material's name and recipe file.
    pub material: String,
    pub recipe: String,
    pub group: Group,
    pub predicted: Option<Reading>,
    /// The prediction's uncertainty from the recipe's stated uncertainties (None without them).
    pub prediction_uncertainty: Option<PredictionUncertainty>,
    pub allowance: Option<Allowance>,
    pub verdict: Verdict,
}

impl Comparison {
    /// predicted − measured mean.
    pub fn difference(&self) -> Option<f64> {
        self.predicted.as_ref().and_then(|p| p.value).map(|v| v - self.group.stats.mean)
    }
}

/// The verdict of one group against the readings of its material and their prediction uncertainties
/// (`uncertainties[i]` of `readings[i]`; an empty slice when the recipe states none).
pub(crate) fn judge(
    group: Group,
    material: &Material,
    readings: &[Reading],
    uncertainties: &[Option<PredictionUncertainty>],
    rule: &VerdictRule,
) -> Comparison {
    let mk = |predicted, pu: Option<PredictionUncertainty>, allowance, verdict| Comparison {
        material: material.name.clone(),
        recipe: material.file.clone(),
        group: group.clone(),
        predicted,
        prediction_uncertainty: pu,
        allowance,
        verdict,
    };
    if let Some(why) = &group.not_predicted {
        return mk(None, None, None, Verdict::NotPredicted(why.clone()));
    }
    let found = readings
        .iter()
        .position(|r| r.geometry == group.geometry && (r.name == group.reading || r.quantity == group.reading));
    let Some(i) = found else {
        return mk(
            None,
            None,
            None,
            Verdict::NotPredicted(format!("`{}` has no reading `{}`", group.geometry, group.reading)),
        );
    };
    let p = readings[i].clone();
    let pu = uncertainties.get(i).cloned().flatten();
    let s = group.stats;
    let stated = group.uncertainty.or_else(|| rule.tolerance_for(&p.geometry, &p.name, &p.quantity));
    let Some(v) = p.value else {
        let why = p.problem.clone().unwrap_or_else(|| "no finite value".into());
        return mk(Some(p), pu, None, Verdict::NoValue(why));
    };
    let u_pred = pu.as_ref().map_or(0.0, |u| u.u);
    if s.n < 2 && stated.is_none() && !(u_pred > 0.0) {
        return mk(Some(p), pu, None, Verdict::NoAllowance);
    }
    let a = Allowance::new(
        rule.k,
        rule.k * s.std / (s.n as f64).sqrt(),
        s.std / (s.n as f64).sqrt(),
        u_pred,
        stated.unwrap_or(0.0),
        p.error_estimate + p.data_uncertainty.unwrap_or(0.0),
    );
    let verdict = if (v - s.mean).abs() <= a.total() { Verdict::Inside } else { Verdict::Outside };
    mk(Some(p), pu, Some(a), verdict)
}

/// Where each sample's recipe comes from: `--recipe SAMPLE=FILE` first, then `DIR/<sample>.json`, then the
/// one recipe given for all samples (each a file, or standard input as the front end read it).
#[derive(Clone, Debug, Default)]
pub struct Recipes {
    pub default: Option<Source>,
    pub dir: Option<PathBuf>,
    pub per_sample: Vec<(String, Source)>,
}

impl Recipes {
    /// The recipe of a sample, or None.
    pub(crate) fn source_of(&self, sample: &str) -> Option<Source> {
        if let Some((_, p)) = self.per_sample.iter().find(|(s, _)| s == sample) {
            return Some(p.clone());
        }
        if let Some(d) = &self.dir {
            // A sample name is used as a file name only if it is one (no separators, not `.`/`..`).
            let plain = !sample.is_empty()
                && !sample.contains(['/', '\\'])
                && sample != "."
                && sample != ".."
                && !sample.contains('\0');
            if plain {
                let p = d.join(format!("{sample}.json"));
                if p.is_file() {
                    return Some(Source::File(p));
                }
            }
        }
        self.default.clone()
    }
}

/// Compare a sheet with the predictions for every sample: each sample's recipe is found through `recipes`,
/// each distinct recipe is measured once (in parallel) through the geometries its rows name.
pub fn compare_sheet(
    sheet: &Sheet,
    recipes: &Recipes,
    rule: &VerdictRule,
    options: &PlanOptions,
) -> Result<Vec<Comparison>> {
    rule.check()?;
    let groups = group_rows(&sheet.rows);
    let geometries = sheet_geometries(sheet)?;
    // Recipes per sample, in order of first appearance.
    let mut samples: Vec<(String, Source)> = Vec::new();
    for sample in distinct_samples(&groups) {
        let Some(p) = recipes.source_of(sample) else {
            let row = sheet.rows.iter().find(|r| r.sample == sample).expect("sample from rows");
            let where_ = match &recipes.dir {
                Some(d) => format!("no {}/{}.json", d.display(), sample),
                None => "no recipe given".into(),
            };
            return Err(Error::input(
                &sheet.file,
                sheet.cell(row.line, sheet.sample_column, "sample"),
                Words::from(format!("sample `{sample}` has no recipe ({where_}; give one with "))
                    .and_argument("per_sample")
                    .and(format!(" '{sample}=FILE')")),
            ));
        };
        samples.push((sample.to_string(), p));
    }
    let mut paths: Vec<Source> = samples.iter().map(|(_, p)| p.clone()).collect();
    paths.sort();
    paths.dedup();
    let materials: Vec<Material> = paths.iter().map(recipe::load_source).collect::<Result<_>>()?;
    let of_sample: Vec<(String, usize)> =
        samples.iter().map(|(s, p)| (s.clone(), paths.binary_search(p).expect("path listed"))).collect();
    judge_all(sheet, groups, geometries, &materials, &of_sample, rule, options)
}

/// Compare a sheet with the predictions of one material for every sample (a recipe held in memory, as the
/// server's `/api/compare` has it; [`compare_sheet`] finds recipes by file).
pub fn compare_sheet_with(
    sheet: &Sheet,
    material: &Material,
    rule: &VerdictRule,
    options: &PlanOptions,
) -> Result<Vec<Comparison>> {
    rule.check()?;
    let groups = group_rows(&sheet.rows);
    let geometries = sheet_geometries(sheet)?;
    let of_sample: Vec<(String, usize)> = distinct_samples(&groups).map(|s| (s.to_string(), 0)).collect();
    judge_all(sheet, groups, geometries, std::slice::from_ref(material), &of_sample, rule, options)
}

/// The samples of the groups, each once, in order of first appearance.
fn distinct_samples(groups: &[Group]) -> impl Iterator<Item = &str> {
    groups
        .iter()
        .enumerate()
        .filter(|(i, g)| !groups[..*i].iter().any(|h| h.sample == g.sample))
        .map(|(_, g)| g.sample.as_str())
}

/// The sheet's geometries: a shipped id, else "not predicted" for a recognised column (the second map, with
/// why), else an error at its row.
type SheetGeometries = (HashMap<String, StandardGeometry>, HashMap<String, String>);

fn sheet_geometries(sheet: &Sheet) -> Result<SheetGeometries> {
    let mut geometries: HashMap<String, StandardGeometry> = HashMap::new();
    let mut missing: HashMap<String, String> = HashMap::new();
    for id in sheet.geometry_ids() {
        match standards::find(&id) {
            Ok(g) => {
                geometries.insert(id, g);
            }
            Err(e) => {
                let row = sheet.rows.iter().find(|r| r.geometry == id).expect("id from rows");
                if sheet.layout == Layout::Long {
                    return Err(Error::input(
                        &sheet.file,
                        sheet.cell(row.line, sheet.geometry_column, "geometry"),
                        e.to_string(),
                    ));
                }
                missing.insert(id.clone(), format!("geometry `{id}` is not shipped in this version"));
            }
        }
    }
    Ok((geometries, missing))
}

/// Measure each material once (in parallel) through the geometries of its samples' rows and judge every
/// group; `of_sample` names each sample's material (an index into `materials`).
fn judge_all(
    sheet: &Sheet,
    groups: Vec<Group>,
    (geometries, missing): SheetGeometries,
    materials: &[Material],
    of_sample: &[(String, usize)],
    rule: &VerdictRule,
    options: &PlanOptions,
) -> Result<Vec<Comparison>> {
    conditions::check(sheet, options.colour)?;
    let material_of = |sample: &str| of_sample.iter().find(|(s, _)| s == sample).map(|(_, i)| *i);
    // Each recipe through the geometries of all the rows of its samples.
    let geometry_ids_of = |i: usize| -> Vec<String> {
        let mut ids: Vec<String> = Vec::new();
        for g in &groups {
            if material_of(&g.sample) == Some(i) && geometries.contains_key(&g.geometry) && !ids.contains(&g.geometry) {
                ids.push(g.geometry.clone());
            }
        }
        ids
    };
    type Predicted = (Vec<Reading>, Vec<Option<PredictionUncertainty>>);
    let predicted: Vec<Predicted> = materials
        .par_iter()
        .enumerate()
        .map(|(i, m)| {
            let geos: Vec<StandardGeometry> = geometry_ids_of(i).iter().map(|id| geometries[id].clone()).collect();
            if geos.is_empty() {
                return Ok((vec![], vec![]));
            }
            let readings = Plan::compile(m.brdf.clone(), geos.clone(), options.clone())?.execute();
            // Nothing more is run for a recipe without an `uncertainty` block.
            let uncertainties = propagation::propagate(m, &geos, options, &readings)?;
            Ok((readings, uncertainties))
        })
        .collect::<Result<_>>()?;
    let (readings, uncertainties): (Vec<_>, Vec<_>) = predicted.into_iter().unzip();
    let mut out = Vec::with_capacity(groups.len());
    for mut g in groups {
        let i = material_of(&g.sample).expect("every sample has a recipe");
        if let Some(why) = missing.get(&g.geometry) {
            g.not_predicted.get_or_insert_with(|| why.clone());
        }
        // A long-layout row names its reading by hand: one its geometry does not have is bad input.
        let known = |r: &Reading| r.geometry == g.geometry && (r.name == g.reading || r.quantity == g.reading);
        if sheet.layout == Layout::Long && g.not_predicted.is_none() && !readings[i].iter().any(known) {
            let have: Vec<&str> =
                readings[i].iter().filter(|r| r.geometry == g.geometry).map(|r| r.name.as_str()).collect();
            return Err(Error::input(
                &sheet.file,
                sheet.cell(g.lines[0], sheet.quantity_column.or(sheet.geometry_column), "quantity"),
                format!(
                    "geometry `{}` has no reading `{}` (it has: {})",
                    g.geometry,
                    g.reading,
                    if have.is_empty() { "none".to_string() } else { have.join(", ") }
                ),
            ));
        }
        out.push(judge(g, &materials[i], &readings[i], &uncertainties[i], rule));
    }
    rule.check_every_key_used(&out)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_most_specific_tolerance_names_each_reading() {
        let args: Vec<String> =
            ["gloss=2", "haze=5", "astm-e430-30/doi=3", "doi=0.5", "1"].iter().map(|s| s.to_string()).collect();
        let rule = VerdictRule::with_tolerances(2.0, &args).unwrap();
        assert_eq!(rule.tolerance, Some(1.0));
        assert_eq!(rule.tolerance_for("astm-d523-60", "gloss", "gloss"), Some(2.0));
        // haze-narrow's quantity is haze; log-haze is neither: the plain number.
        assert_eq!(rule.tolerance_for("astm-e430-30", "haze-narrow", "haze"), Some(5.0));
        assert_eq!(rule.tolerance_for("iso-13803-20", "log-haze", "log-haze"), Some(1.0));
        // geometry/reading before the reading alone, which holds elsewhere.
        assert_eq!(rule.tolerance_for("astm-e430-30", "doi", "doi"), Some(3.0));
        assert_eq!(rule.tolerance_for("rhopoint-iq-20", "doi", "doi"), Some(0.5));
        // No plain number: a reading no key names has none.
        let only = VerdictRule::with_tolerances(2.0, &["gloss=2".to_string()]).unwrap();
        assert_eq!(only.tolerance_for("astm-e430-30", "doi", "doi"), None);
    }

    #[test]
    fn bad_tolerances_are_refused_with_what_is_allowed() {
        let err = |a: &[&str]| {
            VerdictRule::with_tolerances(2.0, &a.iter().map(|s| s.to_string()).collect::<Vec<_>>())
                .unwrap_err()
                .to_string()
        };
        assert!(err(&["gloss=abc"]).contains("not a number"), "{}", err(&["gloss=abc"]));
        assert!(err(&["gloss=-1"]).contains("≥ 0"));
        assert!(err(&["gloss=NaN"]).contains("≥ 0"));
        assert!(err(&["=2"]).contains("names no reading"));
        assert!(err(&["d523-60/gloss=2"]).contains("did you mean \"astm-d523-60\""), "{}", err(&["d523-60/gloss=2"]));
        assert!(err(&["gloss=1", "gloss=2"]).contains("twice"));
        assert!(err(&["1", "2"]).contains("two plain numbers"));
        assert!(err(&["two"]).contains("KEY=NUMBER"));
    }

    #[test]
    fn statistics_of_known_values() {
        // 2, 4, 4, 4, 5, 5, 7, 9: mean 5, population sd 2, sample sd sqrt(32/7).
        let s = statistics(&[2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]);
        assert_eq!((s.n, s.mean, s.min, s.max), (8, 5.0, 2.0, 9.0));
        assert!((s.std - (32.0f64 / 7.0).sqrt()).abs() < 1e-15);
        assert_eq!(statistics(&[3.0]).std, 0.0);
    }

    fn reading(value: Option<f64>, e: f64) -> Reading {
        Reading {
            geometry: "astm-d523-60".into(),
            name: "gloss".into(),
            quantity: "gloss".into(),
            unit: "GU".into(),
            value,
            error_estimate: e,
            evaluations: 1,
            seconds: 0.0,
            converged: true,
            problem: value.is_none().then(|| "zero flux".into()),
            note: None,
            data_uncertainty: None,
            colour: None,
        }
    }

    fn group(values: &[f64], u: Option<f64>) -> Group {
        let rows: Vec<SheetRow> = values
            .iter()
            .enumerate()
            .map(|(i, &v)| SheetRow {
                line: i + 2,
                column: "60".into(),
                sample: "p".into(),
                geometry: "astm-d523-60".into(),
                reading: "gloss".into(),
                value: v,
                uncertainty: u,
                not_predicted: None,
            })
            .collect();
        group_rows(&rows).remove(0)
    }

    #[test]
    fn verdict_rule() {
        let m = recipe::parse_str(r#"{"model": "lambert", "albedo": 0.5}"#, "m.json").unwrap();
        let rule = VerdictRule::default();
        // mean 90, s = 1, n = 4: k s/√n = 1; + e 0.1 → inside up to 1.1.
        let g = group(&[89.0, 91.0, 89.0, 91.0], None);
        assert!((g.stats.std - (4.0f64 / 3.0).sqrt()).abs() < 1e-15);
        let s = g.stats.std;
        let c = judge(g.clone(), &m, &[reading(Some(90.0 + 2.0 * s / 2.0 + 0.1 - 1e-9), 0.1)], &[], &rule);
        assert_eq!(c.verdict, Verdict::Inside);
        let c = judge(g.clone(), &m, &[reading(Some(90.0 + 2.0 * s / 2.0 + 0.1 + 1e-9), 0.1)], &[], &rule);
        assert_eq!(c.verdict, Verdict::Outside);
        // The stated uncertainty adds.
        let c = judge(group(&[90.0], Some(0.5)), &m, &[reading(Some(90.55), 0.1)], &[], &rule);
        assert_eq!((c.verdict, c.allowance.unwrap().total()), (Verdict::Inside, 0.6));
        assert_eq!(
            judge(group(&[90.0], None), &m, &[reading(Some(99.0), 0.1)], &[], &rule).verdict,
            Verdict::NoAllowance
        );
        // A check that cannot be made fails.
        assert!(judge(group(&[90.0], Some(1.0)), &m, &[reading(None, 0.0)], &[], &rule).verdict.fails());
        assert!(matches!(judge(group(&[90.0], Some(1.0)), &m, &[], &[], &rule).verdict, Verdict::NotPredicted(_)));
    }

    #[test]
    fn the_prediction_uncertainty_adds_in_quadrature_to_the_means_spread() {
        use propagation::{Contribution, Difference};
        let m = recipe::parse_str(r#"{"model": "lambert", "albedo": 0.5}"#, "m.json").unwrap();
        let rule = VerdictRule::default();
        let pu = |u: f64| {
            Some(PredictionUncertainty {
                u,
                contributions: vec![Contribution {
                    pointer: "/albedo".into(),
                    u: 0.01,
                    sensitivity: u / 0.01,
                    contribution: u,
                    difference: Difference::Central,
                }],
            })
        };
        // The values 90 ± 1.2 (n = 4): s² = 5.76/3, s²/n = 0.48; u_pred = 0.8: k·√(s²/n + u²) = 2·√(0.48 + 0.64).
        let g = group(&[88.8, 91.2, 88.8, 91.2], None);
        let se = g.stats.std / 2.0;
        assert!((se * se - 0.48).abs() < 1e-12);
        let random = 2.0 * (0.48f64 + 0.64).sqrt();
        let c = judge(g.clone(), &m, &[reading(Some(90.0 + random + 0.1 - 1e-9), 0.1)], &[pu(0.8)], &rule);
        let a = c.allowance.unwrap();
        assert!((a.total() - (random + 0.1)).abs() < 1e-12 && (a.random - random).abs() < 1e-12, "{a:?}");
        assert!((a.statistical - 2.0 * se).abs() < 1e-12 && a.prediction_uncertainty == 0.8);
        assert_eq!(c.verdict, Verdict::Inside);
        assert_eq!(a.parts().iter().map(|p| p.2).sum::<f64>(), a.total());
        let c = judge(g.clone(), &m, &[reading(Some(90.0 + random + 0.1 + 1e-9), 0.1)], &[pu(0.8)], &rule);
        assert_eq!(c.verdict, Verdict::Outside);
        // Without it the first row is outside: k·s/√n + e ≈ 1.49.
        let c = judge(g.clone(), &m, &[reading(Some(90.0 + random + 0.1 - 1e-9), 0.1)], &[], &rule);
        assert_eq!(c.verdict, Verdict::Outside);
        // Without a prediction uncertainty the allowance is the old one, bit for bit.
        let a0 = judge(g.clone(), &m, &[reading(Some(90.0), 0.1)], &[None], &rule).allowance.unwrap();
        assert_eq!(a0.total().to_bits(), (2.0 * g.stats.std / 2.0 + 0.0 + 0.1).to_bits());
        // One reading and no stated uncertainty: u_pred alone makes an allowance.
        let c = judge(group(&[90.0], None), &m, &[reading(Some(91.5), 0.1)], &[pu(0.8)], &rule);
        assert_eq!(c.verdict, Verdict::Inside);
        assert!((c.allowance.unwrap().total() - (2.0 * 0.8 + 0.1)).abs() < 1e-12);
    }

    #[test]
    fn baseline_drift() {
        let b = vec![BaselineEntry {
            material: "m".into(),
            geometry: "astm-d523-60".into(),
            reading: "gloss".into(),
            value: 90.0,
            error_estimate: 0.1,
        }];
        let r1 = reading(Some(90.15), 0.1);
        let r2 = reading(Some(90.25), 0.1);
        assert!(!check_baseline([("m", &r1)], &b)[0].moved);
        assert!(check_baseline([("m", &r2)], &b)[0].moved);
        assert!(check_baseline([("other", &r2)], &b).is_empty());
    }
}

/// CIEDE2000 between a sample's measured L*, a*, b* (the means of its rows) and the predicted ones, on one colour
/// geometry (`docs/colour.md`).
#[derive(Clone, Debug)]
pub struct ColourDifference {
    pub sample: String,
    pub geometry: String,
    /// First line of the sheet's L* rows.
    pub line: usize,
    pub measured: crate::colorimetry::Lab,
    pub predicted: crate::colorimetry::Lab,
    /// ΔE00 with kL = kC = kH = 1.
    pub de00: f64,
    /// Some(ΔE00 ≤ the maximum) when a maximum is given.
    pub inside: Option<bool>,
}

/// ΔE00 for every (sample, geometry) with measured and predicted L*, a*, b*. With a maximum, the ΔE00 verdict
/// becomes the verdict of those L*, a*, b* comparisons that had no allowance of their own (their check is the
/// colour difference, not a per-coordinate tolerance).
pub fn colour_differences(cmp: &mut [Comparison], max_de00: Option<f64>) -> Vec<ColourDifference> {
    use crate::colorimetry::{ciede2000, Lab};
    let mut out: Vec<ColourDifference> = Vec::new();
    for c in cmp.iter().filter(|c| c.group.reading == "L*") {
        let find = |q: &str| {
            cmp.iter().find(|d| {
                d.group.sample == c.group.sample && d.group.geometry == c.group.geometry && d.group.reading == q
            })
        };
        let (Some(a), Some(b)) = (find("a*"), find("b*")) else { continue };
        let pv = |d: &Comparison| d.predicted.as_ref().and_then(|p| p.value);
        let (Some(pl), Some(pa), Some(pb)) = (pv(c), pv(a), pv(b)) else { continue };
        let measured = Lab { l: c.group.stats.mean, a: a.group.stats.mean, b: b.group.stats.mean };
        let predicted = Lab { l: pl, a: pa, b: pb };
        let de00 = ciede2000(measured, predicted);
        out.push(ColourDifference {
            sample: c.group.sample.clone(),
            geometry: c.group.geometry.clone(),
            line: c.group.lines[0],
            measured,
            predicted,
            de00,
            inside: max_de00.map(|m| de00 <= m),
        });
    }
    for d in &out {
        let Some(inside) = d.inside else { continue };
        for c in cmp.iter_mut().filter(|c| {
            c.group.sample == d.sample
                && c.group.geometry == d.geometry
                && ["L*", "a*", "b*"].contains(&c.group.reading.as_str())
                && c.verdict == Verdict::NoAllowance
        }) {
            c.verdict = if inside { Verdict::Inside } else { Verdict::Outside };
        }
    }
    out
}
