//! The geometry files, as data: every shipped instrument geometry is a JSON file in `standards/` (gloss) or
//! `standards/colour/` (colour), embedded in the binary, parsed and validated into a compiled
//! [`Geometry`](crate::instrument::geometry::Geometry). User geometry files use the same formats (documented in
//! `docs/instrument.md` and `docs/colour.md`).
//!
//! Every number in a geometry file carries its provenance:
//! `{"value": 1.8, "source": "…citation or reason…", "status": "verified" | "secondary" | "assumed"}`.
//! Errors name the file, the field path and what is allowed.
//!
//! The files, bottom to top (none imports the planner):
//! * `sourced.rs`: the vocabulary every format shares: sourced numbers (`sourced::sourced`, [`STATUSES`]),
//!   the header, a stop's aperture, and what a file compiles to ([`StandardGeometry`]: it sits below the
//!   formats, which all return it, so that no format imports the catalogue);
//! * `gloss.rs`: the gloss format ([`parse`], [`describe`], [`list_line`], [`BUILTIN`]; re-exported here);
//! * `colour.rs`: the colour format (`colour::parse`, `colour::describe`, `colour::BUILTIN`);
//! * `profile.rs`: the `profile` block of a gloss file ([`profile::ProfileSpec`]; measured by
//!   `instrument::profile`);
//! * `mod.rs` (this): the one catalogue of the shipped geometries, parsed once per process, gloss then colour
//!   ([`builtin_static`], [`builtin`], [`builtin_colour`], [`builtin_all`], [`find`]), and user files
//!   ([`load_file`], [`check_user`]); [`describe_any`] and [`list_line_any`] dispatch on the kind.
use std::path::Path;
use std::sync::OnceLock;

use crate::input::json::parse_json;
use crate::instrument::reading::ReadingSpec;
use crate::{Error, Result};

pub mod colour;
pub(crate) mod gloss;
pub mod profile;
pub(crate) mod sourced;

pub use gloss::{builtin_ids, describe, list_line, parse, BUILTIN};
pub use sourced::{StandardGeometry, STATUSES};

/// Every shipped geometry, parsed and checked once per process: the gloss ones ([`BUILTIN`] order), then the
/// colour ones ([`colour::BUILTIN`] order), and how many are gloss. The files are embedded, so the result cannot
/// change; an error (a shipped file that does not parse) is returned again on every call.
fn catalogue() -> Result<(&'static [StandardGeometry], usize)> {
    static PARSED: OnceLock<(Vec<StandardGeometry>, usize)> = OnceLock::new();
    if let Some((all, gloss)) = PARSED.get() {
        return Ok((all, *gloss));
    }
    let mut all = parse_gloss()?;
    let gloss = all.len();
    all.extend(parse_colour()?);
    let (all, gloss) = PARSED.get_or_init(|| (all, gloss));
    Ok((all, *gloss))
}

/// Every builtin geometry, gloss then colour, borrowed from the one per-process parse (`find` copies only the
/// one it returns). `Planner::new` calls it to check the shipped files.
pub(crate) fn builtin_static() -> Result<&'static [StandardGeometry]> {
    Ok(catalogue()?.0)
}

/// Every builtin gloss geometry, checked for consistency with each other (each file's id equals its file name,
/// ids are unique, composites name existing non-composite geometries).
pub fn builtin() -> Result<Vec<StandardGeometry>> {
    let (all, gloss) = catalogue()?;
    Ok(all[..gloss].to_vec())
}

/// Every builtin colour geometry (each file's id equals its name).
pub fn builtin_colour() -> Result<Vec<StandardGeometry>> {
    let (all, gloss) = catalogue()?;
    Ok(all[gloss..].to_vec())
}

/// The gloss half of the catalogue: parse [`BUILTIN`] and check it.
fn parse_gloss() -> Result<Vec<StandardGeometry>> {
    let mut out = Vec::with_capacity(BUILTIN.len());
    for (file, text) in BUILTIN {
        let label = format!("<builtin:{file}>");
        let mut g = parse(text, &label)?;
        let stem = file.trim_end_matches(".json");
        if g.geometry.id != stem {
            return Err(Error::input(label, "id", format!("id {:?} must equal the file name {stem:?}", g.geometry.id)));
        }
        if out.iter().any(|o: &StandardGeometry| o.geometry.id == g.geometry.id) {
            return Err(Error::input(label, "/id", format!("duplicate id {:?}", g.geometry.id)));
        }
        g.origin = "builtin".to_string();
        out.push(g);
    }
    for g in &out {
        for (i, r) in g.geometry.readings.iter().enumerate() {
            if let ReadingSpec::HazeIndex { minuend, subtrahend } = r {
                for (key, id) in [("minuend", minuend), ("subtrahend", subtrahend)] {
                    let ok = out.iter().any(|o| &o.geometry.id == id && !o.geometry.is_composite());
                    if !ok {
                        return Err(Error::input(
                            format!("<builtin:{}.json>", g.geometry.id),
                            format!("/readings/{i}/{key}"),
                            format!("{id:?} is not a builtin non-composite geometry id; known: {}", ids(&out)),
                        ));
                    }
                }
            }
        }
    }
    Ok(out)
}

/// The colour half of the catalogue: parse [`colour::BUILTIN`] and check it.
fn parse_colour() -> Result<Vec<StandardGeometry>> {
    let mut out: Vec<StandardGeometry> = Vec::with_capacity(colour::BUILTIN.len());
    for (file, text) in colour::BUILTIN {
        let label = format!("<builtin:colour/{file}>");
        let mut g = colour::parse(text, &label)?;
        if g.geometry.id != file.trim_end_matches(".json") {
            return Err(Error::input(label, "/id", format!("id {:?} must equal the file name", g.geometry.id)));
        }
        if out.iter().any(|o| o.geometry.id == g.geometry.id) {
            return Err(Error::input(label, "/id", format!("duplicate id {:?}", g.geometry.id)));
        }
        g.origin = "builtin".into();
        out.push(g);
    }
    Ok(out)
}

fn ids(gs: &[StandardGeometry]) -> String {
    gs.iter().map(|g| g.geometry.id.as_str()).collect::<Vec<_>>().join(", ")
}

/// The builtin geometry (gloss, or colour: [`colour`]) with this id; an unknown id is a usage error listing the
/// known ids.
pub fn find(id: &str) -> Result<StandardGeometry> {
    let (all, gloss) = catalogue()?;
    match all.iter().find(|g| g.geometry.id == id) {
        Some(g) => Ok(g.clone()),
        None => Err(Error::Usage(format!(
            "unknown geometry id {id:?}{}; known ids: {}; colour: {}",
            did_you_mean(id, all.iter().map(|g| g.geometry.id.as_str())),
            ids(&all[..gloss]),
            ids(&all[gloss..])
        ))),
    }
}

/// The ids an unknown `id` was probably meant as, as "; did you mean ...?" (empty when none is close): those that
/// end with it as whole '-'-separated parts (`60` → `astm-d523-60`, `D523-60` → `astm-d523-60`, ignoring case),
/// else the nearest within two single-character edits of it (`astm-d532-60` → `astm-d523-60`). At most five.
fn did_you_mean<'a>(id: &str, known: impl Iterator<Item = &'a str> + Clone) -> String {
    let id = id.trim().to_ascii_lowercase();
    if id.is_empty() {
        return String::new();
    }
    let suffix = format!("-{id}");
    let mut hits: Vec<&str> = known.clone().filter(|k| k.to_ascii_lowercase().ends_with(&suffix)).collect();
    if hits.is_empty() {
        // The nearest ids only, within two edits.
        let near: Vec<(usize, &str)> = known.map(|k| (edit_distance(&k.to_ascii_lowercase(), &id), k)).collect();
        let best = near.iter().map(|(d, _)| *d).min().unwrap_or(usize::MAX);
        hits = near.into_iter().filter(|(d, _)| *d <= 2 && *d == best).map(|(_, k)| k).collect();
    }
    hits.truncate(5);
    match hits.as_slice() {
        [] => String::new(),
        [one] => format!("; did you mean {one:?}?"),
        many => {
            format!("; did you mean one of {}?", many.iter().map(|k| format!("{k:?}")).collect::<Vec<_>>().join(", "))
        }
    }
}

/// Levenshtein distance (insertions, deletions and substitutions of single characters).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let next = (diagonal + usize::from(ca != cb)).min(row[j] + 1).min(row[j + 1] + 1);
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

/// Every builtin geometry: the gloss ones, then the colour ones (`standards/colour/`).
pub fn builtin_all() -> Result<Vec<StandardGeometry>> {
    builtin_static().map(<[StandardGeometry]>::to_vec)
}

/// Load a user geometry file (same format as the builtin ones: a gloss geometry, or a colour geometry when it
/// has a `kind`, `docs/colour.md`).
pub fn load_file(path: &Path) -> Result<StandardGeometry> {
    load_source(&path.into())
}

/// [`load_file`] of a source (a file, or standard input as a front end read it).
pub(crate) fn load_source(source: &crate::input::Source) -> Result<StandardGeometry> {
    let name = source.name();
    let text = source.text("geometry file")?;
    let is_colour = parse_json(&text, &name).map(|v| colour::is_colour_spec(&v)).unwrap_or(false);
    let g = if is_colour { colour::parse(&text, &name)? } else { parse(&text, &name)? };
    check_user(&g, &builtin_all()?)?;
    Ok(g)
}

/// [`describe`] for gloss geometries, `colour::describe` for colour ones.
pub(crate) fn describe_any(g: &StandardGeometry) -> String {
    if g.geometry.is_colour() {
        colour::describe(g)
    } else {
        describe(g)
    }
}

/// [`list_line`] for gloss geometries, `colour::list_line` for colour ones.
pub(crate) fn list_line_any(g: &StandardGeometry) -> String {
    if g.geometry.is_colour() {
        colour::list_line(g)
    } else {
        list_line(g)
    }
}

/// A user geometry may not take a shipped id (a reading would be labelled as the standard's while measuring
/// something else), and its composite readings must name shipped non-composite geometries (they are the
/// ones the plan can look up).
pub fn check_user(g: &StandardGeometry, shipped: &[StandardGeometry]) -> Result<()> {
    let id = &g.geometry.id;
    if shipped.iter().any(|s| &s.geometry.id == id) {
        return Err(Error::input(
            &g.origin,
            "/id",
            format!("{id:?} is the id of a shipped geometry; give a user geometry an id of its own"),
        ));
    }
    for (i, r) in g.geometry.readings.iter().enumerate() {
        if let ReadingSpec::HazeIndex { minuend, subtrahend } = r {
            for (key, part) in [("minuend", minuend), ("subtrahend", subtrahend)] {
                if !shipped.iter().any(|o| &o.geometry.id == part && !o.geometry.is_composite()) {
                    return Err(Error::input(
                        &g.origin,
                        format!("/readings/{i}/{key}"),
                        format!("{part:?} is not a shipped non-composite geometry id; known: {}", ids(shipped)),
                    ));
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::colour::{colour_kind, is_colour_id, ColourKind};
    use super::*;

    #[test]
    fn an_unknown_id_gets_the_ids_it_was_probably_meant_as() {
        let msg = |id: &str| find(id).unwrap_err().to_string();
        assert!(msg("60").contains(r#"did you mean one of "astm-d523-60", "iso-2813-60"?"#), "{}", msg("60"));
        assert!(msg("D523-85").contains(r#"did you mean "astm-d523-85"?"#), "{}", msg("D523-85"));
        assert!(msg("astm-d532-60").contains(r#"did you mean "astm-d523-60"?"#), "{}", msg("astm-d532-60"));
        // One edit from astm-d523-60, two from astm-d523-20 and -85: the nearest only.
        assert!(msg("astm-d523-6").contains(r#"did you mean "astm-d523-60"?"#), "{}", msg("astm-d523-6"));
        let twenty = msg("20");
        assert!(twenty.contains("did you mean one of ") && twenty.contains(r#""astm-d523-20""#), "{twenty}");
        assert!(twenty.contains(r#""iso-13803-20""#), "{twenty}");
        // Nothing close: no suggestion, the list of known ids only.
        let far = msg("goniophotometer");
        assert!(!far.contains("did you mean") && far.contains("known ids: "), "{far}");
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
    }

    #[test]
    fn builtin_colour_geometries_parse() {
        let all = builtin_colour().unwrap();
        assert_eq!(all.len(), colour::BUILTIN.len());
        let v = |id: &str| match colour_kind(&find(id).unwrap().geometry) {
            Some(ColourKind::Directional { viewing, .. }) => viewing.to_degrees(),
            _ => panic!("directional"),
        };
        assert!((v("astm-e2194-110") + 65.0).abs() < 1e-12);
        assert!((v("astm-e2539-m15") - 60.0).abs() < 1e-12);
        assert!(matches!(
            colour_kind(&find("d8-sce").unwrap().geometry),
            Some(ColourKind::Sphere { port: Some(_), .. })
        ));
        assert!(matches!(colour_kind(&find("d8-sci").unwrap().geometry), Some(ColourKind::Sphere { port: None, .. })));
        assert!(is_colour_id("d8-sce") && !is_colour_id("astm-d523-60"));
    }
}
