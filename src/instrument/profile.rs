//! The goniophotometric profile of a Rhopoint IQ-class meter: a linear diode array about the 20° specular
//! direction, read pixel by pixel. It exists because Rspec and the profile are what such meters show besides
//! gloss and haze, and a profile says *where* near the specular direction a material scatters, which a few
//! fixed receptors cannot.
//!
//! The array is data (`instrument::standards::profile`): a geometry file's `profile` block
//! (`standards/rspec-20.json`) gives the number of pixels, the in-plane size of one pixel and their height, each
//! sourced. The pixels sit side by side on the receptor lens, centred on the specular direction: pixel k
//! (0-based, of N) is centred at (k − (N − 1)/2)·w in plane. Each pixel is an aperture integral through the
//! geometry's source stop, like any receptor (`instrument::plan`), and reads
//! [`ReadingSpec::Profile`](crate::instrument::reading::ReadingSpec::Profile): 100·Φ(specimen, pixel) /
//! Φ(standard, a pixel-sized window centred on the specular direction), so the black-glass standard reads 100 in
//! every pixel that lies inside its source image, and a smooth specimen reads its 20° gloss there
//! (`docs/instrument.md` §1.8).
use std::sync::Arc;

use crate::brdf::Brdf;
use crate::instrument::plan::{Plan, PlanOptions, Reading};
use crate::instrument::standards::profile::{geometry, of, ProfileSpec};
use crate::instrument::standards::StandardGeometry;
use crate::Result;

/// One pixel of a measured profile.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub pixel: usize,
    /// The pixel's centre from the specular direction, degrees (positive towards grazing).
    pub angle_deg: f64,
    /// Half the pixel's in-plane size, degrees: every direction of the pixel is within this of `angle_deg`.
    pub half_width_deg: f64,
    /// The pixel's reading (GU on the geometry's scale) and its integration error estimate.
    pub reading: Reading,
}

/// The default evaluation budget of each part of one pixel's integral: 10⁵, fifteen times the most any
/// shipped fixture's pixel spends at the default tolerance (6 515, the literal Cerulean (b) paint on `rspec-20`,
/// measured; docs/instrument.md §1.8).
pub const DEFAULT_PIXEL_EVALS: usize = 100_000;

/// The default evaluation budget of a whole profile: 2·10⁷, thirteen times the most a shipped fixture's
/// 512-pixel profile spends (1.5·10⁶, the literal Cerulean (c) paint, measured). A profile that cannot converge
/// (a constant 10³⁰⁸ table ran 8 minutes with the measurement's 2·10⁶ per part on each of 512 pixels) then
/// ends after about 2·10⁷ evaluations, its pixels marked not converged.
pub(crate) const DEFAULT_TOTAL_EVALS: usize = 20_000_000;

/// The evaluation budget of a profile: per part of each pixel's integral, and over all the pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Budget {
    /// At most this many evaluations per part (the analytic delta part, the regular part) of one pixel.
    pub per_part: usize,
    /// At most this many over the whole profile.
    pub total: usize,
}

impl Default for Budget {
    fn default() -> Self {
        Budget { per_part: DEFAULT_PIXEL_EVALS, total: DEFAULT_TOTAL_EVALS }
    }
}

impl Budget {
    /// The budget each part of each of `pixels` pixels' integrals gets: `per_part`, and no more than its
    /// equal share of `total` (a pixel's integral has at most two parts), at least 1. Deterministic: it depends
    /// on the counts alone, not on which pixel finishes first.
    pub fn part_budget(&self, pixels: usize) -> usize {
        (self.total / (2 * pixels.max(1))).min(self.per_part).max(1)
    }
}

/// A measured profile.
#[derive(Clone, Debug)]
pub struct Profile {
    pub geometry: String,
    pub spec: ProfileSpec,
    pub rows: Vec<Row>,
    /// The budget asked for, and the one each part of each pixel's integral got ([`Budget::part_budget`]).
    pub budget: Budget,
    pub part_budget: usize,
}

/// Measure the profile of `material` on geometry `g` (which must have a `profile` block) within `budget`
/// (`options.max_evals` is replaced by the budget's share per part; docs/instrument.md §1.8). A pixel whose
/// integral reaches its share is marked not converged and says so, as any reading at its budget.
pub fn measure(material: Arc<dyn Brdf>, g: &StandardGeometry, options: PlanOptions, budget: Budget) -> Result<Profile> {
    let spec = of(g)?;
    let part_budget = budget.part_budget(spec.pixels);
    let options = PlanOptions { max_evals: part_budget, ..options };
    let plan = Plan::compile(material, vec![geometry(g, &spec)], options)?;
    let readings = plan.execute();
    let rows = readings
        .into_iter()
        .enumerate()
        .map(|(k, reading)| Row {
            pixel: k,
            angle_deg: spec.centre_deg(k),
            half_width_deg: 0.5 * spec.pixel_deg,
            reading,
        })
        .collect();
    Ok(Profile { geometry: g.geometry.id.clone(), spec, rows, budget, part_budget })
}
