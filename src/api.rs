//! The one-call API: a material read through instrument geometries, for programs that use glossmeter as a
//! library (the command line is one of them). It exists so that a caller needs neither the planner's
//! vocabulary nor the command line's: resolve the geometries (shipped ids, user files, or the default
//! panel), call [`measure`], read the [`Reading`]s.
//!
//! ```
//! use glossmeter::{measure, recipe, resolve_geometries, PlanOptions};
//! let material = recipe::parse_str(r#"{"model": "smooth-dielectric", "ior": 1.567}"#, "<inline>").unwrap();
//! let geometries = resolve_geometries(&["astm-d523-60"], &[] as &[&str]).unwrap();
//! let readings = measure(&material, &geometries, &PlanOptions::default()).unwrap();
//! // Glass of the standard's own index (1.567) reads 100 GU.
//! assert!((readings[0].value.unwrap() - 100.0).abs() < 1e-6);
//! ```
use std::path::Path;

use crate::input::Source;
use crate::instrument::plan::{Plan, PlanOptions, Reading};
use crate::instrument::standards::{self, StandardGeometry};
use crate::recipe::{self, Material};
use crate::Result;

/// The default panel: ASTM D523 20°/60°/85° gloss, ASTM E430 30° (gloss, haze, DOI), ISO 13803 20° haze and
/// the ASTM D4039 haze index.
pub const DEFAULT_PANEL: &[&str] =
    &["astm-d523-20", "astm-d523-60", "astm-d523-85", "astm-e430-30", "iso-13803-20", "astm-d4039"];

/// Shipped geometry ids and user geometry files, in that order; the [`DEFAULT_PANEL`] if both are empty.
pub fn resolve_geometries<S: AsRef<str>, P: AsRef<Path>>(ids: &[S], files: &[P]) -> Result<Vec<StandardGeometry>> {
    resolve_geometries_or(ids, files, DEFAULT_PANEL)
}

/// Shipped geometry ids and user geometry files, in that order; the ids `defaults` if both are empty.
/// A user file may not reuse a shipped id, and its composite readings must name shipped geometries.
pub fn resolve_geometries_or<S: AsRef<str>, P: AsRef<Path>>(
    ids: &[S],
    files: &[P],
    defaults: &[&str],
) -> Result<Vec<StandardGeometry>> {
    let files: Vec<Source> = files.iter().map(|f| Source::from(f.as_ref())).collect();
    resolve_geometries_from(ids, &files, defaults)
}

/// [`resolve_geometries_or`] with the user geometry files as sources (a file, or standard input as a front end
/// read it).
pub fn resolve_geometries_from<S: AsRef<str>>(
    ids: &[S],
    files: &[Source],
    defaults: &[&str],
) -> Result<Vec<StandardGeometry>> {
    let mut out = Vec::new();
    if ids.is_empty() && files.is_empty() {
        for id in defaults {
            out.push(standards::find(id)?);
        }
    }
    for id in ids {
        out.push(standards::find(id.as_ref())?);
    }
    for f in files {
        out.push(standards::load_source(f)?);
    }
    Ok(out)
}

/// Read `material` through `geometries`: every reading the geometries define, in their order. A reading
/// without a finite value has `value: None` and says why in `problem`; one whose integral ran out of budget
/// has `converged: false`.
pub fn measure(material: &Material, geometries: &[StandardGeometry], options: &PlanOptions) -> Result<Vec<Reading>> {
    let plan = Plan::compile(material.brdf.clone(), geometries.to_vec(), options.clone())?;
    Ok(plan.execute())
}

/// [`measure`] of a recipe file through shipped geometry ids (the default panel if `ids` is empty).
pub fn measure_file<S: AsRef<str>>(
    recipe_path: &Path,
    ids: &[S],
    options: &PlanOptions,
) -> Result<(Material, Vec<Reading>)> {
    let material = recipe::load_file(recipe_path)?;
    let geometries = resolve_geometries(ids, &[] as &[&str])?;
    let readings = measure(&material, &geometries, options)?;
    Ok((material, readings))
}
