//! The document of `glossmeter profile --format json` ([`ProfileDoc`]): the material, the array and one row
//! per pixel, from which `report::schema::profile` derives its JSON Schema. Written through a
//! `serde_json::Value`, so its keys are in alphabetical order, as they always were.
use schemars::JsonSchema;
use serde::Serialize;

use crate::instrument::profile::Profile;
use crate::recipe::Material;

/// The material a document describes.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct ProfileMaterialDoc {
    pub name: String,
    /// The recipe's file (`<stdin>` for standard input).
    pub file: String,
    /// The model's one-line description.
    pub model: String,
}

impl ProfileMaterialDoc {
    pub(crate) fn of(m: &Material) -> ProfileMaterialDoc {
        ProfileMaterialDoc { name: m.name.clone(), file: m.file.clone(), model: m.brdf.describe() }
    }
}

/// One pixel of the profile.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(transform = profile_row_nullable)]
pub struct ProfileRowDoc {
    pub pixel: usize,
    /// The pixel's centre from the specular direction, degrees (positive towards grazing).
    pub angle_deg: f64,
    /// Half the pixel's in-plane size, degrees.
    #[schemars(range(min = 0))]
    pub angle_half_width_deg: f64,
    /// The normalised reading; null when there is no finite value (see problem).
    pub value: Option<f64>,
    /// Its integration error estimate; null without a value.
    #[schemars(range(min = 0))]
    pub error_estimate: Option<f64>,
    pub unit: String,
    pub converged: bool,
    pub evaluations: usize,
    /// Why there is no value, or what limits it; null otherwise.
    pub problem: Option<String>,
}

fn profile_row_nullable(schema: &mut schemars::Schema) {
    super::nullable_but_written(schema, &["value", "error_estimate", "problem"]);
}

/// The evaluation budget of the profile.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct ProfileBudgetDoc {
    /// Per part of one pixel's integral (`--max-evals`).
    pub max_evals: usize,
    /// Over the whole profile (`--max-total-evals`).
    pub max_total_evals: usize,
    /// What each part of each pixel got.
    pub per_part: usize,
    pub rule: String,
}

/// `profile --format json`.
#[derive(Clone, Debug, Serialize, JsonSchema)]
pub struct ProfileDoc {
    pub material: ProfileMaterialDoc,
    /// The geometry id.
    pub geometry: String,
    /// The pixels of the array.
    pub pixels: usize,
    /// One pixel's in-plane size, degrees.
    pub pixel_deg: f64,
    /// The array's size across the plane, degrees.
    pub perpendicular_deg: f64,
    /// What the values are normalised to.
    pub normalisation: String,
    /// Evaluations over all the pixels.
    pub evaluations: usize,
    pub budget: ProfileBudgetDoc,
    pub rows: Vec<ProfileRowDoc>,
}

impl ProfileDoc {
    pub fn new(material: &Material, p: &Profile) -> ProfileDoc {
        ProfileDoc {
            material: ProfileMaterialDoc::of(material),
            geometry: p.geometry.clone(),
            pixels: p.spec.pixels,
            pixel_deg: p.spec.pixel_deg,
            perpendicular_deg: p.spec.perpendicular.to_degrees(),
            normalisation: "100·Φ(specimen, pixel) / Φ(gloss standard, a pixel-sized window centred on the \
                            specular direction): the standard reads 100 inside its source image (docs/instrument.md \
                            §1.8)"
                .into(),
            evaluations: p.rows.iter().map(|r| r.reading.evaluations).sum(),
            budget: ProfileBudgetDoc {
                max_evals: p.budget.per_part,
                max_total_evals: p.budget.total,
                per_part: p.part_budget,
                rule: "each part of each pixel's integral gets min(max_evals, max_total_evals / (2 · pixels)) \
                       evaluations; a pixel that reaches it is not converged"
                    .into(),
            },
            rows: p
                .rows
                .iter()
                .map(|r| ProfileRowDoc {
                    pixel: r.pixel,
                    angle_deg: r.angle_deg,
                    angle_half_width_deg: r.half_width_deg,
                    value: r.reading.value,
                    error_estimate: r.reading.value.map(|_| r.reading.error_estimate),
                    unit: r.reading.unit.clone(),
                    converged: r.reading.converged,
                    evaluations: r.reading.evaluations,
                    problem: r.reading.problem.clone(),
                })
                .collect(),
        }
    }

    /// The JSON text (pretty, keys in alphabetical order, a final newline).
    pub(crate) fn text(&self) -> String {
        super::pretty(&super::to_json(self))
    }
}
