//! Target matching, the fit's first stage: the request's counts checked, each target's geometry found (a
//! user geometry first, then the shipped ones) and each target matched to one reading of the plan, by the
//! reading's name or else its quantity, as `compare` matches them (docs/inverse.md §Method, its targets).
use std::collections::HashMap;

use super::options::FitOptions;
use super::params::{FreeParameter, TargetReading};
use crate::error::Words;
use crate::instrument::plan::Planner;
use crate::instrument::standards::StandardGeometry;
use crate::{Error, Result};

/// A reading of the plan a target may name: its geometry, its name and its quantity.
pub(super) type ReadingName = (String, String, String);

/// The counts of a request: some targets, some free parameters, no more parameters than targets, and a
/// positive default uncertainty.
pub(super) fn check_counts(free: &[FreeParameter], targets: &[TargetReading], options: &FitOptions) -> Result<()> {
    if targets.is_empty() {
        return Err(Error::Argument(
            Words::from("no targets: give ")
                .and_argument("target")
                .and(" GEOMETRY/READING=VALUE[±U] or ")
                .and_argument("sheet"),
        ));
    }
    if free.is_empty() {
        return Err(Error::Argument(Words::from("no free parameters: give ").and_argument("free").and(" PATH=LO..HI")));
    }
    if free.len() > targets.len() {
        return Err(Error::Usage(format!(
            "{} free parameters but {} target(s): a fit needs at least as many targets as free parameters",
            free.len(),
            targets.len()
        )));
    }
    if !(options.default_uncertainty.is_finite() && options.default_uncertainty > 0.0) {
        return Err(Error::Usage("the default uncertainty must be a finite number > 0".into()));
    }
    Ok(())
}

/// The geometries the targets name, each once, in the order of their first target: a user geometry of that
/// id if one is given, else the shipped one; an unknown id is an argument error naming the target.
pub(super) fn geometries(
    planner: &Planner,
    targets: &[TargetReading],
    user: &[StandardGeometry],
) -> Result<Vec<StandardGeometry>> {
    let mut ids: Vec<String> = Vec::new();
    for t in targets {
        if !ids.contains(&t.geometry) {
            ids.push(t.geometry.clone());
        }
    }
    ids.iter()
        .map(|id| match user.iter().find(|g| g.geometry.id == *id) {
            Some(g) => Ok(g.clone()),
            None => planner.geometry(id).map_err(|e| {
                let given: Vec<&str> = user.iter().map(|g| g.geometry.id.as_str()).collect();
                let also = if given.is_empty() {
                    String::new()
                } else {
                    format!("; the user geometries given are {}", given.join(", "))
                };
                Error::argument("target", format!(" {id:?}: {e}{also}"))
            }),
        })
        .collect()
}

/// The index in `names` (the plan's reported readings) of each target: the reading of its geometry with its
/// name, or else with its quantity. A target no reading matches, or two targets on one reading, is an
/// argument error naming the target and what is allowed.
pub(super) fn match_targets(names: &[ReadingName], targets: &[TargetReading]) -> Result<Vec<usize>> {
    let mut index = Vec::new();
    for t in targets {
        let i = names
            .iter()
            .position(|(g, n, _)| *g == t.geometry && *n == t.name)
            .or_else(|| names.iter().position(|(g, _, q)| *g == t.geometry && *q == t.name))
            .ok_or_else(|| {
                let has: Vec<&str> =
                    names.iter().filter(|(g, _, _)| *g == t.geometry).map(|(_, n, _)| n.as_str()).collect();
                Error::argument(
                    "target",
                    format!(
                        " {:?}: geometry {:?} has no reading {:?}; its readings are {}",
                        format!("{}/{}", t.geometry, t.name),
                        t.geometry,
                        t.name,
                        has.join(", ")
                    ),
                )
            })?;
        index.push(i);
    }
    let mut seen: HashMap<usize, usize> = HashMap::new();
    for (k, i) in index.iter().enumerate() {
        if let Some(prev) = seen.insert(*i, k) {
            return Err(Error::argument(
                "target",
                format!(
                    " {:?}: the same reading is targeted twice (also target {})",
                    format!("{}/{}", targets[k].geometry, targets[k].name),
                    prev + 1
                ),
            ));
        }
    }
    Ok(index)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names() -> Vec<ReadingName> {
        [("g20", "gloss", "gloss"), ("g20", "haze-narrow", "haze"), ("e430", "doi", "doi")]
            .iter()
            .map(|(g, n, q)| (g.to_string(), n.to_string(), q.to_string()))
            .collect()
    }

    fn target(g: &str, n: &str) -> TargetReading {
        TargetReading { geometry: g.into(), name: n.into(), value: 1.0, uncertainty: None }
    }

    #[test]
    fn targets_match_by_name_then_by_quantity() {
        let t = [target("e430", "doi"), target("g20", "haze"), target("g20", "gloss")];
        assert_eq!(match_targets(&names(), &t).unwrap(), vec![2, 1, 0]);
    }

    #[test]
    fn a_reading_is_matched_on_its_own_geometry() {
        let names: Vec<ReadingName> = [("g20", "gloss", "gloss"), ("g60", "gloss", "gloss")]
            .iter()
            .map(|(g, n, q)| (g.to_string(), n.to_string(), q.to_string()))
            .collect();
        assert_eq!(match_targets(&names, &[target("g60", "gloss"), target("g20", "gloss")]).unwrap(), vec![1, 0]);
        assert!(match_targets(&names, &[target("g85", "gloss")]).is_err());
    }

    #[test]
    fn an_unknown_reading_names_the_geometrys_readings() {
        let e = match_targets(&names(), &[target("g20", "rspec")]).unwrap_err().to_string();
        assert!(e.contains("\"g20/rspec\"") && e.contains("its readings are gloss, haze-narrow"), "{e}");
    }

    #[test]
    fn a_reading_targeted_twice_is_refused() {
        let e = match_targets(&names(), &[target("g20", "gloss"), target("g20", "gloss")]).unwrap_err().to_string();
        assert!(e.contains("targeted twice (also target 1)"), "{e}");
    }

    #[test]
    fn counts_are_checked() {
        let f = FreeParameter { pointer: "/a".into(), lower: 0.0, upper: 1.0, log: false };
        let o = FitOptions::default();
        assert!(check_counts(std::slice::from_ref(&f), &[], &o).unwrap_err().to_string().contains("no targets"));
        assert!(check_counts(&[], &[target("g", "n")], &o).unwrap_err().to_string().contains("no free parameters"));
        let two = [f.clone(), FreeParameter { pointer: "/b".into(), ..f.clone() }];
        assert!(check_counts(&two, &[target("g", "n")], &o).unwrap_err().to_string().contains("2 free parameters"));
        let bad = FitOptions { default_uncertainty: f64::NAN, ..FitOptions::default() };
        assert!(check_counts(std::slice::from_ref(&f), &[target("g", "n")], &bad).is_err());
        assert!(check_counts(&[f], &[target("g", "n")], &o).is_ok());
    }
}
