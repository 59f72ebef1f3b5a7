//! `"model": "paint"` recipes → [`Paint`]. The format is documented in `docs/recipe-format.md` §Paint and the
//! model in `docs/model.md`. Every value is checked here with the field path, so a bad recipe is refused with
//! the file, the field and what is allowed; [`Paint::new`] re-checks the same constraints for callers that
//! build a [`PaintSpec`] in code.
use crate::brdf::halo::WithHalo;
use crate::brdf::paint::{
    ClearCoat, FlakeLight, Form, MetallicFlakes, Paint, PaintSpec, PearlescentFlakes, Pigment, PigmentedLayer, Spread,
    MAX_SAMPLES,
};
use crate::brdf::Brdf;
use crate::input::json::{kind, Obj};
use crate::optics::kubelka_munk::invert_white_black;
use crate::optics::microfacet::{Distribution, Microfacet};
use crate::recipe::fields::param_number;
use crate::registry::{self as reg, Param};
use crate::spectrum::Sampling;
use crate::{Error, Result};
use serde_json::Value;
use std::sync::Arc;

/// Default TiO2 index: anatase, ordinary/extraordinary 2.56/2.49 at 589 nm (CRC Handbook of Chemistry and
/// Physics, "Physical constants of inorganic compounds"); rutile is ≈ 2.6–2.9 (Devore, JOSA 41, 416, 1951).
pub(crate) const DEFAULT_TIO2_INDEX: f64 = 2.5;
/// Default mica (muscovite) index: n ≈ 1.55–1.61 (CRC Handbook); Pfaff & Reynders, Chem. Rev. 99, 1963 (1999).
pub(crate) const DEFAULT_MICA_INDEX: f64 = 1.58;

const PAINT: &str = "paint";

/// Parse a paint recipe (the root object of the file) into a validated BRDF.
pub fn parse_paint(obj: &Obj) -> Result<Arc<dyn Brdf>> {
    let spec = parse_paint_spec(obj)?;
    let coat = obj.obj("clear_coat")?;
    if let Some(app) = coat.opt_obj("application")? {
        return crate::recipe::levelling::parse_levelled_paint(obj, &coat, &app, spec);
    }
    let scatter = coat.opt_obj("scatter")?;
    if scatter.is_some() && spec.coat.roughness >= Microfacet::SMOOTH_THRESHOLD {
        return Err(coat.err(
            "scatter",
            format!(
                "a scatter halo sits on a smooth coat's mirror; roughness = {} is not smooth (allowed with scatter: \
                 roughness 0, below {:e})",
                spec.coat.roughness,
                Microfacet::SMOOTH_THRESHOLD
            ),
        ));
    }
    let (index, sampling) = (spec.coat.index, spec.sampling.clone());
    let paint: Arc<dyn Brdf> =
        Arc::new(Paint::new(spec).map_err(|e| Error::input(obj.file, obj.path.clone(), e.to_string()))?);
    match scatter {
        None => Ok(paint),
        Some(s) => {
            let n = vec![num_complex::Complex64::new(index, 0.0); sampling.len()];
            let halo = crate::recipe::scatter::parse_scatter(&s, &reg::PAINT_SCATTER, PAINT, &n, &sampling)?;
            Ok(Arc::new(WithHalo::new(paint, halo)?))
        }
    }
}

/// Parse a paint recipe into its [`PaintSpec`] (validated field by field).
pub fn parse_paint_spec(obj: &Obj) -> Result<PaintSpec> {
    obj.deny_unknown_in(PAINT)?;
    if let Some(m) = obj.opt_str("model")? {
        if m != "paint" {
            return Err(obj.err("model", format!("expected \"paint\", got {m:?}")));
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
                obj.err("form", format!("unknown form {other:?}; allowed: \"physical\" (default), \"paper-eq1\""))
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
                    "unknown flake_light {other:?}; allowed: \"split\" (default), \"paper\" (Eq. 5 as in the paper)"
                ),
            ))
        }
    };
    let internal_reflection = opt_bool(obj, "internal_reflection")?.unwrap_or(true);
    let sampling = match obj.get("wavelengths_nm") {
        None => Sampling::rgb(),
        Some(_) => {
            let wl = obj.param_array(&reg::PAINT_WAVELENGTHS, None)?;
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
        let what = if pearlescent.is_some() { reg::PEARL_AREA.pointer } else { reg::METALLIC_AREA.pointer };
        return Err(Error::input(
            obj.file,
            what,
            format!("metallic + pearlescent area ratios Am + Ap = {am} + {ap} = {} exceed 1 (the flakes and the pigmented layer share the visible area)", am + ap),
        ));
    }
    Ok(PaintSpec { sampling, coat, layer, metallic, pearlescent, form, flake_light, internal_reflection })
}

fn parse_coat(o: &Obj) -> Result<ClearCoat> {
    o.deny_unknown_in(PAINT)?;
    notes(o)?;
    let index = o.param(&reg::COAT_INDEX)?;
    let thickness_um = o.opt_param(&reg::COAT_THICKNESS)?.unwrap_or(0.0);
    let roughness = o.opt_param(&reg::COAT_ROUGHNESS)?.unwrap_or(0.0);
    let distribution = match o.opt_str("distribution")? {
        None | Some("beckmann") => Distribution::Beckmann,
        Some("ggx") => Distribution::Ggx,
        Some(other) => {
            return Err(o.err(
                "distribution",
                format!("unknown distribution {other:?}; allowed: \"beckmann\" (default), \"ggx\""),
            ))
        }
    };
    Ok(ClearCoat { index, thickness_um, roughness, distribution })
}

fn parse_layer(o: &Obj, n: usize) -> Result<PigmentedLayer> {
    o.deny_unknown_in(PAINT)?;
    notes(o)?;
    let thickness_mm = o.param(&reg::LAYER_THICKNESS)?;
    let primer_reflectance = o.param_array(&reg::LAYER_PRIMER, Some(n))?;
    let mut pigments = Vec::new();
    let key = o.param_key(&reg::LAYER_PIGMENTS);
    for (i, v) in o.array(&key)?.iter().enumerate() {
        let p = Obj::new(o.file, o.element(&key, i), v)?;
        pigments.push(parse_pigment(&p, n, i)?);
    }
    Ok(PigmentedLayer { thickness_mm, primer_reflectance, pigments })
}

fn parse_pigment(o: &Obj, n: usize, i: usize) -> Result<Pigment> {
    o.deny_unknown_in(PAINT)?;
    notes(o)?;
    let name = opt_string(o, "name")?.unwrap_or_else(|| format!("pigment {i}"));
    let concentration = o.param(&reg::PIGMENT_CONCENTRATION)?;
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
        (true, None) => (o.param_array(&reg::PIGMENT_K, Some(n))?, o.param_array(&reg::PIGMENT_S, Some(n))?),
        (false, Some(m)) => parse_measured(&m, n)?,
    };
    Ok(Pigment { name, concentration, k_per_mm, s_per_mm })
}

/// K and S from a drawdown of thickness X over white and over black (paper §5.2, Curtis et al. 1997 §4).
fn parse_measured(m: &Obj, n: usize) -> Result<(Vec<f64>, Vec<f64>)> {
    m.deny_unknown_in(PAINT)?;
    notes(m)?;
    let x = m.param(&reg::MEASURED_THICKNESS)?;
    let rw = m.param_array(&reg::MEASURED_OVER_WHITE, Some(n))?;
    let rb = m.param_array(&reg::MEASURED_OVER_BLACK, Some(n))?;
    let wb = spectral_or_scalar(m, &reg::MEASURED_WHITE_BACKGROUND, n)?;
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
    o.deny_unknown_in(PAINT)?;
    notes(o)?;
    let nn = spectral_or_scalar(o, &reg::METALLIC_N, n)?;
    let kk = spectral_or_scalar(o, &reg::METALLIC_K, n)?;
    let spread = spread(o, &reg::METALLIC_SPREAD, &reg::METALLIC_SPREAD_SLOPE)?;
    let area_ratio = o.param(&reg::METALLIC_AREA)?;
    let depth_mm = depth(o, x, &reg::METALLIC_DEPTH)?;
    Ok(MetallicFlakes { n: nn, k: kk, spread, area_ratio, depth_mm })
}

fn parse_pearl(o: &Obj, x: f64) -> Result<PearlescentFlakes> {
    o.deny_unknown_in(PAINT)?;
    notes(o)?;
    Ok(PearlescentFlakes {
        spread: spread(o, &reg::PEARL_SPREAD, &reg::PEARL_SPREAD_SLOPE)?,
        area_ratio: o.param(&reg::PEARL_AREA)?,
        depth_mm: depth(o, x, &reg::PEARL_DEPTH)?,
        tio2_thickness_nm: o.param(&reg::PEARL_TIO2_THICKNESS)?,
        tio2_index: o.opt_param(&reg::PEARL_TIO2_INDEX)?.unwrap_or(DEFAULT_TIO2_INDEX),
        mica_thickness_nm: o.param(&reg::PEARL_MICA_THICKNESS)?,
        mica_index: o.opt_param(&reg::PEARL_MICA_INDEX)?.unwrap_or(DEFAULT_MICA_INDEX),
    })
}

/// The flake spread: exactly one of `spread_deg` (an angle σ, m = tan σ; entry `deg`) and `spread_slope` (the
/// Beckmann rms slope m; entry `slope`); `docs/model.md` §Two readings of the flake spread.
fn spread(o: &Obj, deg: &Param, slope: &Param) -> Result<Spread> {
    let (kd, ks) = (o.param_key(deg), o.param_key(slope));
    match (o.get(&kd).is_some(), o.get(&ks).is_some()) {
        (true, false) => Ok(Spread::Degrees(o.param(deg)?)),
        (false, true) => Ok(Spread::Slope(o.param(slope)?)),
        (true, true) => Err(o.err(
            &ks,
            "give exactly one of `spread_deg` (an angle in degrees, m = tan σ) and `spread_slope` (the Beckmann rms slope m), not both",
        )),
        (false, false) => Err(o.err(
            &kd,
            format!(
                "missing: give exactly one of `spread_deg` (an angle in degrees, {}, m = tan σ) and `spread_slope` (the Beckmann rms slope m, {})",
                deg.range().describe_short().trim_start_matches("in "),
                slope.range().describe_short().trim_start_matches("in ")
            ),
        )),
    }
}

/// A flake depth (entry `p`), at most the layer thickness `x`.
fn depth(o: &Obj, x: f64, p: &Param) -> Result<f64> {
    let d = o.param(p)?;
    if d > x {
        return Err(o.err(
            &o.param_key(p),
            format!(
                "{d} mm is deeper than the pigmented layer ({} = {x}); {} must be in [0, {x}]",
                reg::LAYER_THICKNESS.pointer,
                p.description
            ),
        ));
    }
    Ok(d)
}

/// A number (the same for every sample) or an array with one value per sample (entry `p`).
fn spectral_or_scalar(o: &Obj, p: &Param, n: usize) -> Result<Vec<f64>> {
    let key = o.param_key(p);
    match o.required(&key)? {
        Value::Array(_) => o.param_array(p, Some(n)),
        v => Ok(vec![param_number(o.file, &o.field(&key), v, p)?; n]),
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
