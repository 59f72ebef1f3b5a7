//! Many recipes measured in one process: the recipe files of a list of files and directories, each read
//! through the same geometries, in parallel: the plans are compiled in parallel by one [`Planner`], then the
//! integrals of all of them run as one work queue, largest expected first ([`Plan::run_all`]), and the plans
//! are freed in parallel. One integral always runs on one thread, so every reading is the same bits whatever
//! the thread count or the number of recipes measured together (tests/sheets.rs compares a batch with
//! one-by-one runs).
use std::path::PathBuf;

use rayon::prelude::*;

use crate::instrument::plan::{Execution, Plan, PlanOptions, Planner, Reading};
use crate::instrument::standards::StandardGeometry;
use crate::recipe::Material;
use crate::{Error, Result};

/// The recipe files named by `paths`: files as given, directories replaced by their `*.json` entries (not
/// recursive, sub-directories left out), sorted by name. A `*.json` entry that cannot be read, a dangling
/// symbolic link or a link loop, stays in the list, so that loading it is the error naming it: a recipe moved
/// away behind a link never drops out of a batch without a word.
pub(crate) fn recipe_files(paths: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut out = vec![];
    for p in paths {
        if p.is_dir() {
            let rd = std::fs::read_dir(p).map_err(|source| Error::Io { file: p.display().to_string(), source })?;
            let mut files: Vec<PathBuf> = vec![];
            for e in rd {
                let e = e.map_err(|source| Error::Io { file: p.display().to_string(), source })?;
                let f = e.path();
                if !f.is_dir() && f.extension().is_some_and(|x| x == "json") {
                    files.push(f);
                }
            }
            if files.is_empty() {
                return Err(Error::input(p.display().to_string(), "", "the directory has no *.json recipes"));
            }
            files.sort();
            out.extend(files);
        } else {
            out.push(p.clone());
        }
    }
    Ok(out)
}

/// Read every material through the geometries; the readings of material i are element i.
pub fn measure_many(
    materials: &[Material],
    geometries: &[StandardGeometry],
    options: &PlanOptions,
) -> Result<Vec<Vec<Reading>>> {
    Ok(run_many(materials, geometries, options)?.into_par_iter().map(|e| e.readings).collect())
}

/// [`measure_many`] keeping each material's execution (its readings and the fluxes of its plan, for the
/// plan's evaluation count).
pub(crate) fn run_many(
    materials: &[Material],
    geometries: &[StandardGeometry],
    options: &PlanOptions,
) -> Result<Vec<Execution>> {
    // One planner for the batch: the gloss standards' fluxes, which do not depend on the material, are
    // computed once rather than once per recipe (a cached flux is the same bits as a recomputed one).
    let planner = Planner::new()?;
    let plans: Vec<Plan> = materials
        .par_iter()
        .map(|m| planner.compile(m.brdf.clone(), geometries.to_vec(), options.clone()))
        .collect::<Result<_>>()?;
    let runs = Plan::run_all(&plans);
    // Freed in parallel: a plan is a few hundred allocations (its methods' partitions and weightings), and
    // a hundred of them freed on one thread were a serial tail of the batch (docs/performance.md).
    plans.into_par_iter().for_each(drop);
    Ok(runs)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Load every recipe (the first bad one is the error, before any work is done).
    fn load_all(files: &[PathBuf]) -> Result<Vec<Material>> {
        files.iter().map(|f| crate::recipe::load_file(std::path::Path::new(f))).collect()
    }

    #[test]
    fn a_dangling_link_in_a_directory_is_an_error_naming_it() {
        let dir = std::env::temp_dir().join(format!("glossmeter-batch-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("sub.json")).unwrap();
        std::fs::copy("fixtures/recipes/grey-lambert.json", dir.join("a.json")).unwrap();
        #[cfg(unix)]
        std::os::unix::fs::symlink(dir.join("missing.json"), dir.join("b.json")).unwrap();
        let files = recipe_files(std::slice::from_ref(&dir)).unwrap();
        assert!(!files.iter().any(|f| f.ends_with("sub.json")), "{files:?}");
        if cfg!(unix) {
            assert_eq!(files.len(), 2, "{files:?}");
            let e = load_all(&files).map(|_| ()).unwrap_err().to_string();
            assert!(e.contains("b.json"), "{e}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
