//! `"model": "merl"` and `"model": "rgl"`: measured BRDF tables (`crate::measured`), referenced by path from
//! the recipe. A relative path is resolved against the recipe file's directory, so that a recipe
//! and its table can be moved together; for a label that is not a path (`<stdin>`, `<builtin:…>`) against
//! the current directory.
use crate::brdf::Brdf;
use crate::input::json::Obj;
use crate::measured::merl::{Interpolation, MerlBrdf};
use crate::measured::rgl::RglBrdf;
use crate::measured::{e1392, inplane};
use crate::registry;
use crate::{Error, Result};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Resolve the `file` field of a recipe named `recipe_file` (its path, or a `<…>` label).
pub fn resolve(recipe_file: &str, file: &str) -> PathBuf {
    let p = Path::new(file);
    if p.is_absolute() || recipe_file.starts_with('<') {
        return p.to_path_buf();
    }
    match Path::new(recipe_file).parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.join(p),
        _ => p.to_path_buf(),
    }
}

/// `{"model": "merl", "file": "…", "interpolation": "nearest" | "trilinear"}`.
pub(crate) fn parse_merl(obj: &Obj) -> Result<Arc<dyn Brdf>> {
    obj.deny_unknown_in("merl")?;
    let file = obj.str(&obj.param_key(&registry::MERL_FILE))?;
    if file.is_empty() {
        return Err(obj.err("file", "empty path; expected the path of a MERL .binary table"));
    }
    let interpolation = match obj.opt_str(&obj.param_key(&registry::MERL_INTERPOLATION))? {
        None | Some("nearest") => Interpolation::Nearest,
        Some("trilinear") => Interpolation::Trilinear,
        Some(other) => {
            let allowed = "allowed: \"nearest\" (the default, MERL's lookup), \"trilinear\"";
            return Err(obj.err("interpolation", format!("unknown interpolation {other:?}; {allowed}")));
        }
    };
    let path = resolve(obj.file, file);
    let brdf = MerlBrdf::load(&path, interpolation).map_err(|e| match e {
        Error::Io { file: f, source } => obj.err("file", format!("cannot read the MERL table {f}: {source}")),
        other => obj.err("file", format!("not a valid MERL table: {other}")),
    })?;
    Ok(Arc::new(brdf))
}

/// `{"model": "rgl", "file": "…"}`: an RGL material database `.bsdf` tensor file.
pub(crate) fn parse_rgl(obj: &Obj) -> Result<Arc<dyn Brdf>> {
    obj.deny_unknown_in("rgl")?;
    let file = obj.str(&obj.param_key(&registry::RGL_FILE))?;
    if file.is_empty() {
        return Err(obj.err("file", "empty path; expected the path of an RGL .bsdf file"));
    }
    let path = resolve(obj.file, file);
    let brdf = RglBrdf::load(&path).map_err(|e| match e {
        Error::Io { file: f, source } => obj.err("file", format!("cannot read the RGL file {f}: {source}")),
        other => obj.err("file", format!("not a valid RGL .bsdf file: {other}")),
    })?;
    Ok(Arc::new(brdf))
}

/// `{"model": "inplane-csv", "file": "…"}` and `{"model": "e1392", "file": "…"}`: in-plane goniometer tables
/// with the isotropic (θh, θd) extension (`measured::inplane`).
pub(crate) fn parse_inplane(obj: &Obj, model: &str) -> Result<Arc<dyn Brdf>> {
    obj.deny_unknown_in(model)?;
    let what = if model == "e1392" { "an ASTM E1392 text table" } else { "an in-plane CSV table" };
    let entry = if model == "e1392" { &registry::E1392_FILE } else { &registry::INPLANE_FILE };
    let file = obj.str(&obj.param_key(entry))?;
    if file.is_empty() {
        return Err(obj.err("file", format!("empty path; expected the path of {what}")));
    }
    let path = resolve(obj.file, file);
    let off_plane = match obj.opt_str(&obj.param_key(&registry::INPLANE_OFF_PLANE))? {
        None | Some("f") => inplane::OffPlane::Brdf,
        Some("f-cos-cos") => inplane::OffPlane::BrdfCosCos,
        Some("microfacet") => inplane::OffPlane::Microfacet,
        Some(other) => {
            let allowed =
                "allowed: \"f\" (f_r depends on (θh, θd) only, the default), \"f-cos-cos\" (f_r·cos θi·cos θo \
                           does), \"microfacet\" (f_r·cos θi·cos θo/G2 does, G2 the table's own Smith term)";
            return Err(obj.err("off_plane", format!("unknown off-plane assumption {other:?}; {allowed}")));
        }
    };
    let loaded = if model == "e1392" { e1392::load(&path) } else { inplane::load_csv(&path) };
    let brdf = loaded.map(|b| b.with_off_plane(off_plane)).map_err(|e| match e {
        Error::Io { file: f, source } => obj.err("file", format!("cannot read {what} {f}: {source}")),
        other => obj.err("file", format!("not a valid table: {other}")),
    })?;
    Ok(Arc::new(brdf))
}
