//! `"model": "paint"` recipes → [`Paint`]. The format is documented in `docs/recipe-format.md` §Paint and the
//! model in `docs/model.md`. Every value is checked here with the field path, so a bad recipe is refused with
//! the file, the field and what is allowed; [`Paint::new`] re-checks the same constraints for callers that
//! build a [`PaintSpec`] in code.
use crate::brdf::paint::{
    ClearCoat, FlakeLight, Form, MetallicFlakes, Paint, PaintSpec, PearlescentFlakes, Pigment, PigmentedLayer, Spread,
    MAX_SAMPLES,
};
use crate::brdf::Brdf;
use crate::optics::kubelka_munk::invert_white_black;
use crate::optics::microfacet::Distribution;
use crate::recipe::fields::{kind, number, Obj};
use crate::spectrum::Sampling;
use crate::{Error, Result};
use serde_json::Value;
use std::sync::Arc;

/// Default TiO2 index: anatase, ordinary/extraordinary 2.56/2.49 at 589 nm (CRC Handbook of Chemistry and
/// Physics, "Physical constants of inorganic compounds"); rutile is ≈ 2.6–2.9 (Devore, JOSA 41, 416, 1951).
pub const DEFAULT_TIO2_INDEX: f64 = 2.5;
/// Default mica (muscovite) index: n ≈ 1.55–1.61 (CRC Handbook); Pfaff & Reynders, Chem. Rev. 99, 1963 (1999).
pub const DEFAULT_MICA_INDEX: f64 = 1.58;

/// Root fields of a paint recipe besides the descriptive ones (`crate::recipe::META_FIELDS`).
const ROOT_FIELDS: &[&str] = &[
    "form",
    "flake_light",
    "internal_reflection",
    "wavelengths_nm",
    "clear_coat",
    "pigmented_layer",
    "metallic_flakes",
    "pearlescent_flakes",
];

/// Parse a paint recipe (the root object of the file) into a validated BRDF.
pub fn parse_paint(obj: &Obj) -> Result<Arc<dyn Brdf>> {
    let spec = parse_paint_spec(obj)?;
    let paint = Paint::new(spec).map_err(|e| Error::input(obj.file, obj.path.clone(), e.to_string()))?;
    Ok(Arc::new(paint))
}

/// Parse a paint recipe into its [`PaintSpec`] (validated field by field).
pub fn parse_paint_spec(obj: &Obj) -> Result<PaintSpec> {
    let allowed: Vec<&str> = crate::recipe::META_FIELDS.iter().chain(ROOT_FIELDS).copied().collect();
    obj.deny_unknown(&allowed)?;
    if let Some(m) = obj.opt_str("model")? {
        if m != "paint" {
            return Err(obj.err("model", format!("expected \"paint\", got \"{m}\"")));
        }
    }
    opt_string(obj, "name")?;
    opt_string(obj, "description")?;
    opt_string(obj, "provenance")?;
    notes(obj)?;
    let form = match obj.opt_str("form")? {
        None | Some("physical") => Form::Physical,
        Some("paper-eq1") => Form::PaperEq1,
        Some(other) => {
            return Err(
                obj.err("form", format!("unknown form \"{other}\"; allowed: \"physical\" (default), \"paper-eq1\""))
            )
        }
    };
    let flake_light = match obj.opt_str("flake_light")? {
        None | Some("split") => FlakeLight::Split,
        Some("paper") => FlakeLight::PaperEq5,
        Some(other) => {
            return Err(obj.err(
                "flake_light",
                format!(
                    "unknown flake_light \"{other}\"; allowed: \"split\" (default), \"paper\" (Eq. 5 as in the paper)"
                ),
            ))
        }
    };
    let internal_reflection = opt_bool(obj, "internal_reflection")?.unwrap_or(true);
    let sampling = match obj.get("wavelengths_nm") {
        None => Sampling::rgb(),
        Some(_) => {
            let wl = obj.num_array("wavelengths_nm", None, 360.0, 830.0, "wavelength in nm")?;
            if wl.len() > MAX_SAMPLES {
                return Err(
                    obj.err("wavelengths_nm", format!("{} wavelengths; at most {MAX_SAMPLES} allowed", wl.len()))
                );
            }
            Sampling::spectral(&wl).map_err(|e| obj.err("wavelengths_nm", e.to_string()))?
        }
    };
    let n = sampling.len();
    let coat = parse_coat(&obj.obj("clear_coat")?)?;
    let layer_obj = obj.obj("pigmented_layer")?;
    let layer = parse_layer(&layer_obj, n)?;
    let x = layer.thickness_mm;
    let metallic = obj.opt_obj("metallic_flakes")?.map(|o| parse_metallic(&o, n, x)).transpose()?;
    let pearlescent = obj.opt_obj("pearlescent_flakes")?.map(|o| parse_pearl(&o, x)).transpose()?;
    let am = metallic.as_ref().map_or(0.0, |m| m.area_ratio);
    let ap = pearlescent.as_ref().map_or(0.0, |p| p.area_ratio);
    if am + ap > 1.0 {
        let what = if pearlescent.is_some() { "pearlescent_flakes.area_ratio" } else { "metallic_flakes.area_ratio" };
        return Err(Error::input(
            obj.file,
            obj.field(what),
            format!("metallic + pearlescent area ratios Am + Ap = {am} + {ap} = {} exceed 1 (the flakes and the pigmented layer share the visible area)", am + ap),
        ));
    }
    Ok(PaintSpec { sampling, coat, layer, metallic, pearlescent, form, flake_light, internal_reflection })
}

fn parse_coat(o: &Obj) -> Result<ClearCoat> {
    o.deny_unknown(&["index", "thickness_um", "roughness", "distribution", "notes"])?;
    notes(o)?;
    let index = o.num("index", 1.3, 1.8, "clear-coat refractive index")?;
    let thickness_um = o.opt_num("thickness_um", 0.0, f64::INFINITY, "clear-coat thickness in µm")?.unwrap_or(0.0);
    let roughness = o
        .opt_num("roughness", 0.0, 1.0, "clear-coat roughness (Beckmann rms slope or GGX α; 0 = smooth)")?
        .unwrap_or(0.0);
    let distribution = match o.opt_str("distribution")? {
        None | Some("beckmann") => Distribution::Beckmann,
        Some("ggx") => Distribution::Ggx,
        Some(other) => {
            return Err(o.err(
                "distribution",
                format!("unknown distribution \"{other}\"; allowed: \"beckmann\" (default), \"ggx\""),
            ))
        }
    };
    Ok(ClearCoat { index, thickness_um, roughness, distribution })
}

fn parse_layer(o: &Obj, n: usize) -> Result<PigmentedLayer> {
    o.deny_unknown(&["thickness_mm", "primer_reflectance", "pigments", "notes"])?;
    notes(o)?;
    let thickness_mm = o.num("thickness_mm", 0.0, f64::INFINITY, "pigmented-layer thickness X in mm")?;
    let primer_reflectance = o.num_array("primer_reflectance", Some(n), 0.0, 1.0, "primer reflectance Rg")?;
    let mut pigments = Vec::new();
    for (i, v) in o.array("pigments")?.iter().enumerate() {
        let p = Obj::new(o.file, format!("{}[{i}]", o.field("pigments")), v)?;
        pigments.push(parse_pigment(&p, n, i)?);
    }
    Ok(PigmentedLayer { thickness_mm, primer_reflectance, pigments })
}

fn parse_pigment(o: &Obj, n: usize, i: usize) -> Result<Pigment> {
    o.deny_unknown(&["name", "concentration", "k_per_mm", "s_per_mm", "measured", "notes"])?;
    notes(o)?;
    let name = opt_string(o, "name")?.unwrap_or_else(|| format!("pigment {i}"));
    let concentration = o.num("concentration", 0.0, f64::INFINITY, "pigment concentration C")?;
    let has_ks = o.get("k_per_mm").is_some() || o.get("s_per_mm").is_some();
    let (k_per_mm, s_per_mm) = match (has_ks, o.opt_obj("measured")?) {
        (true, Some(_)) => {
            return Err(o.err("measured", "give either `k_per_mm` and `s_per_mm` or `measured`, not both"));
        }
        (false, None) => {
            return Err(
                o.err("k_per_mm", "missing: give `k_per_mm` and `s_per_mm` (per mm, one per sample) or `measured`")
            );
        }
        (true, None) => (
            o.num_array("k_per_mm", Some(n), 0.0, f64::INFINITY, "absorption K per mm")?,
            o.num_array("s_per_mm", Some(n), 0.0, f64::INFINITY, "scattering S per mm")?,
        ),
        (false, Some(m)) => parse_measured(&m, n)?,
    };
    Ok(Pigment { name, concentration, k_per_mm, s_per_mm })
}

/// K and S from a drawdown of thickness X over white and over black (paper §5.2, Curtis et al. 1997 §4).
fn parse_measured(m: &Obj, n: usize) -> Result<(Vec<f64>, Vec<f64>)> {
    m.deny_unknown(&["thickness_mm", "over_white", "over_black", "white_background", "notes"])?;
    notes(m)?;
    let x = m.num("thickness_mm", f64::MIN_POSITIVE, f64::INFINITY, "drawdown thickness in mm (> 0)")?;
    let rw = m.num_array("over_white", Some(n), 0.0, 1.0, "reflectance over the white background")?;
    let rb = m.num_array("over_black", Some(n), 0.0, 1.0, "reflectance over the black background")?;
    let wb = spectral_or_scalar(m, "white_background", n, 0.0, 1.0, "white-background reflectance")?;
    let mut k = Vec::with_capacity(n);
    let mut s = Vec::with_capacity(n);
    for j in 0..n {
        let (kj, sj) = invert_white_black(rw[j], rb[j], wb[j], x)
            .map_err(|e| m.err("over_white", format!("sample {j}: cannot invert Kubelka–Munk: {e}")))?;
        if !(kj.is_finite() && sj.is_finite() && kj >= 0.0 && sj >= 0.0) {
            return Err(
                m.err("over_white", format!("sample {j}: inversion gave K = {kj}, S = {sj}; need finite values ≥ 0"))
            );
        }
        // invert_white_black returns K and S in inverse units of the thickness given: per mm.
        k.push(kj);
        s.push(sj);
    }
    Ok((k, s))
}

fn parse_metallic(o: &Obj, n: usize, x: f64) -> Result<MetallicFlakes> {
    o.deny_unknown(&["n", "k", "spread_deg", "spread_slope", "area_ratio", "depth_mm", "notes"])?;
    notes(o)?;
    let nn = spectral_or_scalar(o, "n", n, 1e-3, 100.0, "real part n of the metal's index")?;
    let kk = spectral_or_scalar(o, "k", n, 0.0, 100.0, "extinction k of the metal's index")?;
    let spread = spread(o)?;
    let area_ratio = o.num("area_ratio", 0.0, 1.0, "visible area ratio Am")?;
    let depth_mm = depth(o, x, "mean depth X' of the visible metallic flakes in mm")?;
    Ok(MetallicFlakes { n: nn, k: kk, spread, area_ratio, depth_mm })
}

fn parse_pearl(o: &Obj, x: f64) -> Result<PearlescentFlakes> {
    o.deny_unknown(&[
        "spread_deg",
        "spread_slope",
        "area_ratio",
        "depth_mm",
        "tio2_thickness_nm",
        "tio2_index",
        "mica_thickness_nm",
        "mica_index",
        "notes",
    ])?;
    notes(o)?;
    Ok(PearlescentFlakes {
        spread: spread(o)?,
        area_ratio: o.num("area_ratio", 0.0, 1.0, "visible area ratio Ap")?,
        depth_mm: depth(o, x, "mean depth X'' of the visible pearlescent flakes in mm")?,
        tio2_thickness_nm: o.num("tio2_thickness_nm", 0.0, 1e5, "TiO2 film thickness in nm")?,
        tio2_index: o.opt_num("tio2_index", 1.0, 4.0, "TiO2 refractive index")?.unwrap_or(DEFAULT_TIO2_INDEX),
        mica_thickness_nm: o.num("mica_thickness_nm", 0.0, 1e6, "mica platelet thickness in nm")?,
        mica_index: o.opt_num("mica_index", 1.0, 3.0, "mica refractive index")?.unwrap_or(DEFAULT_MICA_INDEX),
    })
}

/// The flake spread: exactly one of `spread_deg` (an angle σ, m = tan σ) and `spread_slope` (the Beckmann rms
/// slope m); `docs/model.md` §Two readings of the flake spread.
fn spread(o: &Obj) -> Result<Spread> {
    match (o.get("spread_deg").is_some(), o.get("spread_slope").is_some()) {
        (true, false) => Ok(Spread::Degrees(o.num(
            "spread_deg",
            0.0,
            Spread::MAX_DEG,
            "flake orientation spread in degrees (m = tan σ)",
        )?)),
        (false, true) => Ok(Spread::Slope(o.num(
            "spread_slope",
            0.0,
            Spread::MAX_SLOPE,
            "flake orientation spread as the Beckmann rms slope m (dimensionless)",
        )?)),
        (true, true) => Err(o.err(
            "spread_slope",
            "give exactly one of `spread_deg` (an angle in degrees, m = tan σ) and `spread_slope` (the Beckmann rms slope m), not both",
        )),
        (false, false) => Err(o.err(
            "spread_deg",
            "missing: give exactly one of `spread_deg` (an angle in degrees, 0–60, m = tan σ) and `spread_slope` (the Beckmann rms slope m, 0–1.732)",
        )),
    }
}

fn depth(o: &Obj, x: f64, what: &str) -> Result<f64> {
    let d = o.num("depth_mm", 0.0, f64::INFINITY, what)?;
    if d > x {
        return Err(o.err(
            "depth_mm",
            format!("{d} mm is deeper than the pigmented layer (pigmented_layer.thickness_mm = {x}); {what} must be in [0, {x}]"),
        ));
    }
    Ok(d)
}

/// A number (the same for every sample) or an array with one value per sample.
fn spectral_or_scalar(o: &Obj, key: &str, n: usize, lo: f64, hi: f64, what: &str) -> Result<Vec<f64>> {
    match o.required(key)? {
        Value::Array(_) => o.num_array(key, Some(n), lo, hi, what),
        v => Ok(vec![number(o.file, &o.field(key), v, lo, hi, what)?; n]),
    }
}

fn opt_bool(o: &Obj, key: &str) -> Result<Option<bool>> {
    match o.get(key) {
        None => Ok(None),
        Some(Value::Bool(b)) => Ok(Some(*b)),
        Some(v) => Err(o.err(key, format!("expected true or false, got {}", kind(v)))),
    }
}

fn opt_string(o: &Obj, key: &str) -> Result<Option<String>> {
    Ok(o.opt_str(key)?.map(str::to_string))
}

/// `notes` is free text for provenance: a string or an array of strings.
fn notes(o: &Obj) -> Result<()> {
    match o.get("notes") {
        None | Some(Value::String(_)) => Ok(()),
        Some(Value::Array(a)) if a.iter().all(Value::is_string) => Ok(()),
        Some(v) => Err(o.err("notes", format!("expected a string or an array of strings, got {}", kind(v)))),
    }
}
