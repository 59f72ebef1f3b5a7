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

/// A measured profile.
#[derive(Clone, Debug)]
pub struct Profile {
    pub geometry: String,
    pub spec: ProfileSpec,
    pub rows: Vec<Row>,
}

/// Measure the profile of `material` on geometry `g` (which must have a `profile` block).
pub fn measure(material: Arc<dyn Brdf>, g: &StandardGeometry, options: PlanOptions) -> Result<Profile> {
    let spec = of(g)?;
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
    Ok(Profile { geometry: g.geometry.id.clone(), spec, rows })
}
