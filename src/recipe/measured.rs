//! `"model": "merl"`: a measured BRDF table in the MERL `.binary` format (`brdf::measured`), referenced by
//! path from the recipe. A relative path is resolved against the recipe file's directory, so that a recipe
//! and its table can be moved together; for a label that is not a path (`<stdin>`, `<builtin:…>`) against
//! the current directory.
use super::Obj;
use crate::brdf::measured::{Interpolation, MerlBrdf};
use crate::brdf::Brdf;
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
pub fn parse_merl(obj: &Obj) -> Result<Arc<dyn Brdf>> {
    obj.deny_unknown_in("merl")?;
    let file = obj.str(&obj.param_key(&crate::registry::MERL_FILE))?;
    if file.is_empty() {
        return Err(obj.err("file", "empty path; expected the path of a MERL .binary table"));
    }
    let interpolation = match obj.opt_str(&obj.param_key(&crate::registry::MERL_INTERPOLATION))? {
        None | Some("nearest") => Interpolation::Nearest,
        Some("trilinear") => Interpolation::Trilinear,
        Some(other) => {
            let allowed = "allowed: \"nearest\" (the default, MERL's lookup), \"trilinear\"";
            return Err(obj.err("interpolation", format!("unknown interpolation \"{other}\"; {allowed}")));
        }
    };
    let path = resolve(obj.file, file);
    let brdf = MerlBrdf::load(&path, interpolation).map_err(|e| match e {
        Error::Io { file: f, source } => obj.err("file", format!("cannot read the MERL table {f}: {source}")),
        other => obj.err("file", format!("not a valid MERL table: {other}")),
    })?;
    Ok(Arc::new(brdf))
}
