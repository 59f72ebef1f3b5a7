//! The documents of `measure`: one recipe's readings as JSON (with the tolerance envelope and the baseline
//! checks when asked for) and as CSV, and the same for many recipes in one process (`crate::batch`), each
//! reading with its material and file (the schema of both JSON forms is [`super::schema::measure`]).
use schemars::JsonSchema;
use serde::Serialize;

use super::{csv_text, plain, pretty, to_json, BaselineDoc, ReadingDoc};
use crate::comparison::propagation::PredictionUncertainty;
use crate::comparison::Drift;
use crate::instrument::envelope::Envelopes;
use crate::instrument::plan::Reading;
use crate::recipe::Material;
use crate::{Error, Result};

/// A material measured: its name, recipe file and the model its recipe builds.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MaterialDoc {
    pub name: String,
    /// The recipe file.
    pub file: String,
    /// The one-line description of the model.
    pub model: String,
}

impl MaterialDoc {
    pub(crate) fn new(m: &Material) -> MaterialDoc {
        MaterialDoc { name: m.name.clone(), file: m.file.clone(), model: m.brdf.describe() }
    }
}

/// `measure --format json` of one recipe.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MeasureDoc {
    pub material: MaterialDoc,
    pub readings: Vec<ReadingDoc>,
    /// BRDF evaluations of the whole plan: every distinct aperture integral (the gloss standards' included)
    /// counted once; a reading's own evaluations count every integral it uses, so shared integrals appear in
    /// several readings.
    pub evaluations: usize,
    /// With --baseline: the checks against it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub baseline: Option<BaselineDoc>,
}

/// The JSON document of one material's readings, with the plan's `evaluations`.
pub fn json_doc(material: &Material, readings: &[Reading], timing: bool, evaluations: usize) -> MeasureDoc {
    MeasureDoc {
        material: MaterialDoc::new(material),
        readings: readings.iter().map(|r| ReadingDoc::new(r, timing)).collect(),
        evaluations,
        baseline: None,
    }
}

impl MeasureDoc {
    /// Add the tolerance envelope to each reading (`None` where the standard data give no tolerance, or where
    /// the wall-clock limit cut the envelope: then `"envelope_cut": true`).
    pub(crate) fn with_envelope(mut self, envelopes: &Envelopes) -> MeasureDoc {
        self.readings = self
            .readings
            .into_iter()
            .zip(&envelopes.of)
            .map(|(r, e)| {
                let cut = envelopes.cut.contains(&r.geometry);
                r.with_envelope(e.as_ref(), cut)
            })
            .collect();
        self
    }

    /// Add each reading's prediction uncertainty (`uncertainties[i]` of reading i; `comparison::propagation`).
    pub(crate) fn with_uncertainties(mut self, uncertainties: &[Option<PredictionUncertainty>]) -> MeasureDoc {
        self.readings = self
            .readings
            .into_iter()
            .enumerate()
            .map(|(i, r)| r.with_uncertainty(uncertainties.get(i).and_then(Option::as_ref)))
            .collect();
        self
    }

    /// Add the baseline checks (when a baseline was given).
    pub(crate) fn with_baseline(mut self, drift: Option<&[Drift]>, file: Option<String>) -> MeasureDoc {
        if let (Some(d), Some(file)) = (drift, file) {
            self.baseline = Some(BaselineDoc::new(file, d));
        }
        self
    }

    /// The document printed as the CLI prints it ([`pretty`]).
    pub fn text(&self) -> String {
        pretty(&to_json(self))
    }
}

/// The CSV of `measure`: a header, then one record per reading (the fields of [`reading_json`]).
pub(crate) fn csv(readings: &[Reading], timing: bool) -> Result<String> {
    let mut head = vec![
        "geometry",
        "name",
        "quantity",
        "value",
        "unit",
        "error_estimate",
        "data_uncertainty",
        "evaluations",
        "converged",
    ];
    if timing {
        head.push("seconds");
    }
    head.push("illuminant");
    head.push("observer");
    head.push("problem");
    head.push("note");
    let rows = readings.iter().map(|r| {
        // The value and its error estimate to their precision (docs/instrument.md §Numbers in text).
        let (value, error) = r.value.map(|v| super::with_error(v, r.error_estimate)).unwrap_or_default();
        let mut rec = vec![
            r.geometry.clone(),
            r.name.clone(),
            r.quantity.clone(),
            value.clone(),
            r.unit.clone(),
            error.clone(),
            r.value.and(r.data_uncertainty).map(super::plain_two_digits).unwrap_or_default(),
            r.evaluations.to_string(),
            r.converged.to_string(),
        ];
        if timing {
            rec.push(plain(r.seconds));
        }
        rec.extend(super::ConditionsDoc::cells(r.colour));
        rec.push(r.problem.clone().unwrap_or_default());
        rec.push(r.note.clone().unwrap_or_default());
        rec
    });
    csv_text(&head, rows)
}

/// A material of a batch, with the BRDF evaluations of its plan.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BatchMaterialDoc {
    pub name: String,
    pub file: String,
    pub model: String,
    /// BRDF evaluations of this material's plan: every distinct aperture integral counted once.
    pub evaluations: usize,
}

/// One reading of a batch: the fields of the one-recipe reading, and its material and recipe file.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BatchReadingDoc {
    /// The material's name.
    pub material: String,
    /// The material's recipe file.
    pub file: String,
    #[serde(flatten)]
    pub reading: ReadingDoc,
}

/// `measure --format json` of many recipes in one process (`crate::batch`).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BatchDoc {
    pub materials: Vec<BatchMaterialDoc>,
    pub readings: Vec<BatchReadingDoc>,
    /// BRDF evaluations of all the materials' plans together.
    pub evaluations: usize,
    /// With --baseline: the checks against it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub baseline: Option<BaselineDoc>,
}

/// `measure --format json`: the document of one recipe, or of many (its schema is `schema::measure`).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(untagged)]
#[schemars(title = "glossmeter measure --format json")]
pub enum MeasureOutput {
    /// One recipe.
    One(MeasureDoc),
    /// Many recipes.
    Many(BatchDoc),
}

/// The JSON of `measure` for many recipes: `materials` (each with its plan's `evaluations`) and `readings`,
/// each reading with its `material` and `file`, and the sum of the evaluations.
pub(crate) fn batch_json_doc(
    materials: &[Material],
    readings: &[Vec<Reading>],
    timing: bool,
    evaluations: &[usize],
) -> BatchDoc {
    let mut all = vec![];
    for (m, rs) in materials.iter().zip(readings) {
        for r in rs {
            all.push(BatchReadingDoc {
                material: m.name.clone(),
                file: m.file.clone(),
                reading: ReadingDoc::new(r, timing),
            });
        }
    }
    BatchDoc {
        materials: materials
            .iter()
            .zip(evaluations)
            .map(|(m, e)| BatchMaterialDoc {
                name: m.name.clone(),
                file: m.file.clone(),
                model: m.brdf.describe(),
                evaluations: *e,
            })
            .collect(),
        readings: all,
        evaluations: evaluations.iter().sum(),
        baseline: None,
    }
}

impl BatchDoc {
    /// Add each reading's prediction uncertainty: `per_material[m][i]` of material m's reading i, as
    /// `comparison::propagation::propagate` gives them (one per reading, in the order of [`batch_json_doc`]).
    pub(crate) fn with_uncertainties(mut self, per_material: &[Vec<Option<PredictionUncertainty>>]) -> BatchDoc {
        let flat: Vec<Option<&PredictionUncertainty>> =
            per_material.iter().flat_map(|v| v.iter().map(Option::as_ref)).collect();
        for (i, r) in self.readings.iter_mut().enumerate() {
            r.reading = r.reading.clone().with_uncertainty(flat.get(i).copied().flatten());
        }
        self
    }

    /// Add the baseline checks (when a baseline was given).
    pub(crate) fn with_baseline(mut self, drift: Option<&[Drift]>, file: Option<String>) -> BatchDoc {
        if let (Some(d), Some(file)) = (drift, file) {
            self.baseline = Some(BaselineDoc::new(file, d));
        }
        self
    }

    /// The document printed as the CLI prints it ([`pretty`]).
    pub(crate) fn text(&self) -> String {
        pretty(&to_json(self))
    }
}

/// The CSV of `measure` with `material` and `file` columns in front.
pub(crate) fn batch_csv(materials: &[Material], readings: &[Vec<Reading>], timing: bool) -> Result<String> {
    let err = |e: csv::Error| Error::Io { file: "<csv>".into(), source: std::io::Error::other(e) };
    let mut head: Option<Vec<String>> = None;
    let mut rows = vec![];
    for (m, rs) in materials.iter().zip(readings) {
        let one = csv(rs, timing)?;
        let mut rdr = csv::ReaderBuilder::new().has_headers(false).from_reader(one.as_bytes());
        for (j, rec) in rdr.records().enumerate() {
            let rec = rec.map_err(err)?;
            if j == 0 {
                head.get_or_insert_with(|| {
                    ["material", "file"].into_iter().chain(rec.iter()).map(String::from).collect()
                });
                continue;
            }
            rows.push(
                [m.name.as_str(), m.file.as_str()].into_iter().chain(rec.iter()).map(String::from).collect::<Vec<_>>(),
            );
        }
    }
    match head {
        Some(h) => csv_text(&h.iter().map(String::as_str).collect::<Vec<_>>(), rows),
        None => Ok(String::new()),
    }
}
