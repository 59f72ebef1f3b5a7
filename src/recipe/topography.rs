//! `"model": "topography"`: the facet term of a measured surface (`brdf::topography::TopographySurface`),
//! from a topography file referenced by path as a measured table is (resolved against the recipe's directory,
//! `measured::resolve`; the server confines it to its data directory like every registry `file` entry). The
//! map is levelled, its cells' slopes smoothed into the facet distribution (docs/topography.md §The facet term
//! of a measured surface).
use std::sync::Arc;

use super::measured::resolve;
use crate::brdf::topography::TopographySurface;
use crate::brdf::Brdf;
use crate::input::json::Obj;
use crate::optics::slope_table::SlopeTable;
use crate::registry::{self, Param};
use crate::topography::level::{level, Levelled, Levelling};
use crate::topography::map::HeightMap;
use crate::topography::slopes::slopes;
use crate::{Error, Result};

/// `{"model": "topography", "file": "…", "ior": n, "levelling": "plane"}`.
pub(crate) fn parse_topography(obj: &Obj) -> Result<Arc<dyn Brdf>> {
    obj.deny_unknown_in("topography")?;
    let ior = obj.param(&registry::TOPOGRAPHY_IOR)?;
    let (map, levelled, levelling) = levelled_map(obj, &registry::TOPOGRAPHY_FILE, &registry::TOPOGRAPHY_LEVELLING)?;
    let wrap = |e: Error| obj.err("file", format!("not a topography this model reads: {e}"));
    let s = slopes(&levelled.z, map.nx, map.ny, map.dx, map.dy, &map.file).map_err(wrap)?;
    let table = SlopeTable::from_slopes(&s.sx, &s.sy).map_err(|m| obj.err("file", format!("{}: {m}", map.file)))?;
    let source = format!("{}, levelling {}", map.file, levelling.name());
    Ok(Arc::new(TopographySurface::new(table, ior, source)?))
}

/// The topography that `obj`'s `file` entry names (resolved against the recipe's directory), levelled as its
/// `levelling` entry says (the plane when absent): the map, its levelled heights and the levelling.
pub(crate) fn levelled_map(obj: &Obj, file: &Param, levelling: &Param) -> Result<(HeightMap, Levelled, Levelling)> {
    let name = obj.str(&obj.param_key(file))?;
    if name.is_empty() {
        return Err(obj.err("file", "empty path; expected the path of an .x3p, .sdf or .gsf topography"));
    }
    let how = match obj.opt_str(&obj.param_key(levelling))? {
        None => Levelling::Plane,
        Some(s) => Levelling::parse(s).ok_or_else(|| {
            obj.err("levelling", format!("unknown levelling {s:?}; allowed: {}", Levelling::allowed()))
        })?,
    };
    let path = resolve(obj.file, name);
    let wrap = |e: Error| match e {
        Error::Io { file: f, source } => obj.err("file", format!("cannot read the topography {f}: {source}")),
        other => {
            // A recipe gives no calibration, so a plain matrix (a file announcing none of the calibrated formats)
            // cannot be read by one: the error says which files can.
            let named = path
                .extension()
                .is_some_and(|e| ["x3p", "gsf", "sdf"].iter().any(|f| e.to_string_lossy().eq_ignore_ascii_case(f)));
            let plain = !named && !crate::topography::announces_calibrated_format(&head(&path));
            let hint =
                if plain { " (a recipe reads .x3p, .sdf and .gsf files, which carry their calibration)" } else { "" };
            obj.err("file", format!("not a topography this model reads: {other}{hint}"))
        }
    };
    let map = crate::topography::load(&path, None).map_err(wrap)?;
    let levelled = level(&map, how).map_err(wrap)?;
    Ok((map, levelled, how))
}

/// A file's first bytes (fewer if it is shorter or cannot be read; only a message depends on them).
fn head(path: &std::path::Path) -> Vec<u8> {
    use std::io::Read;
    let mut head = Vec::with_capacity(16);
    if let Ok(f) = std::fs::File::open(path) {
        let _ = f.take(16).read_to_end(&mut head);
    }
    head
}
