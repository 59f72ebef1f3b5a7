//! Recipes: JSON descriptions of materials, validated into BRDFs.
//!
//! One file holds one material, a JSON object whose `"model"` field selects the model (the format, every
//! field, its unit and its allowed range: `docs/recipe-format.md`; the JSON Schema: [`schema::schema`]).
//! Every parameter is read through its entry in [`crate::registry`] (pointer, range, description), and
//! every value is checked with the file, the field's JSON Pointer and what is allowed ([`crate::input::json::Obj`]);
//! unknown fields are refused (the allowed keys come from the registry) so that a typo cannot silently fall
//! back to a default.
//!
//! The folder:
//! * `mod.rs` (this): a recipe file or text read into a [`Material`] ([`load_file`], [`parse_str`]), the
//!   dispatch on `"model"` ([`parse_brdf`]) and the analytic models' fields (Lambert, the smooth and rough
//!   interfaces, Phong, Ward, the Cook–Torrance lobes);
//! * `fields.rs`: the registry-driven reading of a parameter (`Obj::param`, `opt_param`, `param_array`,
//!   `param_key`, `deny_unknown_in`, [`fields::param_number`]) on `input::json`'s reader;
//! * `levelling.rs`: a paint coat's `application` block, levelled into the coat's facets and halo
//!   ([`levelling::parse_levelled_paint`], [`levelling::level`]);
//! * `paint.rs`: `"model": "paint"` recipes ([`paint::parse_paint`], [`paint::parse_paint_spec`]);
//! * `measured.rs`: the measured tables' recipes, a path resolved against the recipe's directory
//!   ([`measured::resolve`], [`measured::parse_merl`], [`measured::parse_rgl`], [`measured::parse_inplane`]);
//! * `topography.rs`: `"model": "topography"`, the facets of a measured topography's own slopes
//!   ([`topography::parse_topography`]; the file resolved as a measured table's);
//! * `scatter.rs`: the `scatter` object (a Rayleigh–Rice halo on a smooth interface's mirror) of `paint`,
//!   `cook-torrance-lobes` and `microfacet` recipes ([`scatter::parse_scatter`]);
//! * `schema.rs`: the JSON Schema of the format, generated from the registry ([`schema::schema`]);
//! * `uncertainty.rs`: the `uncertainty` block, standard uncertainties of the recipe's numbers
//!   ([`uncertainty::parse`] → [`uncertainty::Stated`]).
use crate::brdf::conductor::SmoothConductor;
use crate::brdf::dielectric::{Ior, MicrofacetSurface, SmoothDielectric};
use crate::brdf::halo::WithHalo;
use crate::brdf::lambert::Lambert;
use crate::brdf::mixture::MixtureSurface;
use crate::brdf::multilobe::{CookTorranceLobes, CtLobe};
use crate::brdf::phong::{Phong, PhongVariant};
use crate::brdf::two_scale::RoughWithHalo;
use crate::brdf::ward::Ward;
use crate::brdf::Brdf;
use crate::input::json::{kind, parse_json, Obj};
use crate::optics::microfacet::{Distribution, Microfacet, Shadowing};
use crate::optics::slope_mixture::SlopeMixture;
use crate::registry::{self as reg, Param};
use crate::spectrum::Sampling;
use crate::{Error, Result};
use fields::param_number;
use num_complex::Complex64;
use serde_json::Value;
use std::sync::Arc;

pub(crate) mod fields;
pub(crate) mod levelling;
pub mod measured;
pub mod paint;
pub(crate) mod scatter;
pub mod schema;
pub(crate) mod topography;
pub(crate) mod uncertainty;

pub(crate) use crate::registry::MAX_LOBES;
pub use crate::registry::MODELS;

/// Slack on the energy sums (kd + ks ≤ 1) for decimal rounding in the files.
const ENERGY_SLACK: f64 = 1e-9;

/// A loaded, validated material.
#[derive(Clone, Debug)]
pub struct Material {
    /// The recipe's `"name"`, or the file stem if it has none.
    pub name: String,
    /// The file it came from (as given), for messages.
    pub file: String,
    pub brdf: Arc<dyn Brdf>,
    /// The recipe as read (for reports).
    pub json: Value,
    /// The standard uncertainties its `uncertainty` block states (empty without one; [`uncertainty`]).
    pub uncertainty: Vec<uncertainty::Stated>,
}

/// Read and validate a recipe file. I/O errors name the file.
pub fn load_file(path: &std::path::Path) -> Result<Material> {
    load_source(&path.into())
}

/// [`load_file`] of a source (a file, or standard input as a front end read it).
pub(crate) fn load_source(source: &crate::input::Source) -> Result<Material> {
    parse_str(&source.text("recipe")?, &source.name())
}

/// Validate recipe text; `file` names it in messages.
pub fn parse_str(text: &str, file: &str) -> Result<Material> {
    let json = parse_json(text, file)?;
    let (name, brdf, uncertainty) = {
        let obj = Obj::new(file, "", &json)?;
        let brdf = parse_brdf(&obj)?;
        let model = obj.str("model")?;
        let uncertainty = uncertainty::parse(&json, file, model)?;
        let name = match obj.opt_str("name")? {
            Some(n) => n.to_string(),
            None => std::path::Path::new(file)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| file.to_string()),
        };
        (name, brdf, uncertainty)
    };
    Ok(Material { name, file: file.to_string(), brdf, json, uncertainty })
}

/// Validate the root object of a recipe into its BRDF.
pub(crate) fn parse_brdf(obj: &Obj) -> Result<Arc<dyn Brdf>> {
    let allowed = || format!("allowed: {}", MODELS.iter().map(|m| format!("\"{m}\"")).collect::<Vec<_>>().join(", "));
    let model = match obj.get("model") {
        None => return Err(obj.err("model", format!("missing required field; {}", allowed()))),
        Some(Value::String(s)) => s.as_str(),
        Some(v) => return Err(obj.err("model", format!("expected a string, got {}; {}", kind(v), allowed()))),
    };
    if !MODELS.contains(&model) {
        return Err(obj.err("model", format!("unknown model {model:?}; {}", allowed())));
    }
    if model == "paint" {
        return paint::parse_paint(obj);
    }
    check_meta(obj)?;
    obj.deny_unknown_in(model)?;
    let brdf: Arc<dyn Brdf> = match model {
        "smooth-dielectric" => Arc::new(SmoothDielectric::new(obj.param(&reg::DIELECTRIC_IOR)?)),
        "conductor" => {
            let ior = parse_ior(obj, &reg::CONDUCTOR_IOR)?;
            let sampling = if ior.len() == 3 { Sampling::rgb() } else { Sampling::grey() };
            let eta = ior
                .iter()
                .map(|i| match i {
                    Ior::Conductor(c) => *c,
                    Ior::Dielectric(n) => Complex64::new(*n, 0.0),
                })
                .collect();
            Arc::new(SmoothConductor::new(eta, sampling)?)
        }
        "lambert" => match obj.get("wavelengths_nm") {
            // A spectral albedo: one value per wavelength, as the paint's spectral recipes.
            Some(_) => {
                let wl = obj.param_array(&reg::LAMBERT_WAVELENGTHS, None)?;
                if wl.len() > crate::brdf::paint::MAX_SAMPLES {
                    return Err(obj.err(
                        "wavelengths_nm",
                        format!("{} wavelengths; at most {} allowed", wl.len(), crate::brdf::paint::MAX_SAMPLES),
                    ));
                }
                let sampling = Sampling::spectral(&wl).map_err(|e| obj.err("wavelengths_nm", e.to_string()))?;
                let albedo = obj.param_array(&reg::LAMBERT_ALBEDO, Some(wl.len()))?;
                Arc::new(Lambert::new(albedo, sampling)?)
            }
            None => {
                let albedo = colour(obj, &reg::LAMBERT_ALBEDO)?;
                let sampling = sampling_of(&[&albedo]);
                Arc::new(Lambert::new(albedo.expand(&sampling), sampling)?)
            }
        },
        "microfacet" => {
            let distribution = distribution(obj, &reg::MICROFACET_DISTRIBUTION)?;
            let alpha = roughness_or_populations(obj)?;
            let shadowing = shadowing(obj)?;
            let ior = parse_ior(obj, &reg::MICROFACET_IOR)?;
            let sampling = if ior.len() == 3 { Sampling::rgb() } else { Sampling::grey() };
            let index: Vec<Complex64> = ior
                .iter()
                .map(|i| match i {
                    Ior::Conductor(c) => *c,
                    Ior::Dielectric(n) => Complex64::new(*n, 0.0),
                })
                .collect();
            let (surface, smooth): (Arc<dyn Brdf>, bool) = match alpha {
                Some(alpha) => {
                    let facets = Microfacet::new(distribution, alpha);
                    let s = MicrofacetSurface::new(facets, shadowing, ior, sampling.clone())?;
                    (Arc::new(s), facets.effectively_smooth())
                }
                // A mixture of slope populations (every one rough: the registry's range).
                None => {
                    let mix = populations(obj, distribution)?;
                    (Arc::new(MixtureSurface::new(mix, shadowing, ior, sampling.clone())?), false)
                }
            };
            match obj.opt_obj("scatter")? {
                None => surface,
                Some(s) => {
                    let halo = scatter::parse_scatter(&s, &reg::MICROFACET_SCATTER, model, &index, &sampling)?;
                    if smooth {
                        Arc::new(WithHalo::new(surface, halo)?)
                    } else {
                        // A rough interface: the two-scale surface (facets' slopes and the micro-roughness's
                        // halo, brdf/two_scale.rs).
                        Arc::new(RoughWithHalo::new(surface, halo)?)
                    }
                }
            }
        }
        "phong" | "blinn-phong" => {
            let variant = if model == "phong" { PhongVariant::Phong } else { PhongVariant::BlinnPhong };
            let n = obj.param(&reg::PHONG_EXPONENT)?;
            let ks = colour(obj, &reg::PHONG_KS)?;
            let kd = opt_colour(obj, &reg::PHONG_KD)?.unwrap_or(Colour::Grey(0.0));
            let sampling = sampling_of(&[&kd, &ks]);
            let (kd, ks) = (kd.expand(&sampling), ks.expand(&sampling));
            energy_check(obj, "ks", &kd, &[&ks], "kd + ks")?;
            Arc::new(Phong::new(variant, n, kd, ks, sampling)?)
        }
        "ward" => {
            let alpha = obj.param(&reg::WARD_ALPHA)?;
            let rho_s = colour(obj, &reg::WARD_RHO_S)?;
            let rho_d = opt_colour(obj, &reg::WARD_RHO_D)?.unwrap_or(Colour::Grey(0.0));
            let sampling = sampling_of(&[&rho_d, &rho_s]);
            let (rho_d, rho_s) = (rho_d.expand(&sampling), rho_s.expand(&sampling));
            energy_check(obj, "rho_s", &rho_d, &[&rho_s], "rho_d + rho_s")?;
            Arc::new(Ward::new(rho_d, rho_s, alpha, sampling)?)
        }
        "cook-torrance-lobes" => parse_lobes(obj)?,
        "merl" => measured::parse_merl(obj)?,
        "rgl" => measured::parse_rgl(obj)?,
        "inplane-csv" | "e1392" => measured::parse_inplane(obj, model)?,
        "topography" => topography::parse_topography(obj)?,
        other => return Err(obj.err("model", format!("unknown model {other:?}; {}", allowed()))),
    };
    Ok(brdf)
}

/// `name`, `description`, `provenance` must be strings; `notes` a string or an array of strings.
fn check_meta(obj: &Obj) -> Result<()> {
    for key in ["name", "description", "provenance"] {
        obj.opt_str(key)?;
    }
    match obj.get("notes") {
        None | Some(Value::String(_)) => Ok(()),
        Some(Value::Array(a)) if a.iter().all(Value::is_string) => Ok(()),
        Some(v) => Err(obj.err("notes", format!("expected a string or an array of strings, got {}", kind(v)))),
    }
}

/// A reflectance-like value: one number (grey) or [r, g, b].
#[derive(Clone, Debug, PartialEq)]
enum Colour {
    Grey(f64),
    Rgb([f64; 3]),
}

impl Colour {
    fn expand(&self, sampling: &Sampling) -> Vec<f64> {
        match self {
            Colour::Grey(x) => vec![*x; sampling.len()],
            Colour::Rgb(c) => c.to_vec(),
        }
    }
}

/// RGB sampling if any colour is given as [r, g, b], grey otherwise.
fn sampling_of(colours: &[&Colour]) -> Sampling {
    if colours.iter().any(|c| matches!(c, Colour::Rgb(_))) {
        Sampling::rgb()
    } else {
        Sampling::grey()
    }
}

fn colour_value(file: &str, path: &str, v: &Value, p: &Param) -> Result<Colour> {
    match v {
        Value::Array(a) => {
            if a.len() != 3 {
                return Err(Error::input(
                    file,
                    path,
                    format!("expected one number or [r, g, b] (3 values) for {}, got {}", p.description, kind(v)),
                ));
            }
            let mut c = [0.0; 3];
            for (i, x) in a.iter().enumerate() {
                c[i] = param_number(file, &format!("{path}/{i}"), x, p)?;
            }
            Ok(Colour::Rgb(c))
        }
        Value::Number(_) => Ok(Colour::Grey(param_number(file, path, v, p)?)),
        _ => Err(Error::input(
            file,
            path,
            format!("expected a number {} or [r, g, b] for {}, got {}", p.range().describe(), p.description, kind(v)),
        )),
    }
}

fn colour(obj: &Obj, p: &Param) -> Result<Colour> {
    let key = obj.param_key(p);
    colour_value(obj.file, &obj.field(&key), obj.required(&key)?, p)
}

fn opt_colour(obj: &Obj, p: &Param) -> Result<Option<Colour>> {
    let key = obj.param_key(p);
    obj.get(&key).map(|v| colour_value(obj.file, &obj.field(&key), v, p)).transpose()
}

/// Refuse a model that would reflect more than it receives: diffuse + Σ lobes ≤ 1 per sample.
fn energy_check(obj: &Obj, key: &str, diffuse: &[f64], lobes: &[&Vec<f64>], what: &str) -> Result<()> {
    for (i, d) in diffuse.iter().enumerate() {
        let sum = d + lobes.iter().map(|l| l[i]).sum::<f64>();
        if sum > 1.0 + ENERGY_SLACK {
            let channel = if diffuse.len() == 3 { format!(" (channel {})", ["R", "G", "B"][i]) } else { String::new() };
            return Err(obj.err(key, format!("{what} = {sum}{channel} exceeds 1: the surface would reflect more light than it receives; allowed: {what} ≤ 1")));
        }
    }
    Ok(())
}

/// `[n, k]` at `path`, n and k checked against the registry entries `pn`, `pk`.
fn complex_ior(file: &str, path: &str, v: &Value, pn: &Param, pk: &Param) -> Result<Complex64> {
    let a = v.as_array().filter(|a| a.len() == 2).ok_or_else(|| {
        Error::input(file, path, format!("expected a conductor index [n, k] (2 numbers), got {}", kind(v)))
    })?;
    let n = param_number(file, &format!("{path}/0"), &a[0], pn)?;
    let k = param_number(file, &format!("{path}/1"), &a[1], pk)?;
    Ok(Complex64::new(n, k))
}

/// `ior` (entry `p`): a number (dielectric, only if `p` allows it), [n, k] (conductor), or
/// [[n, k], [n, k], [n, k]] (conductor per R, G, B).
fn parse_ior(obj: &Obj, p: &Param) -> Result<Vec<Ior>> {
    let key = obj.param_key(p);
    let v = obj.required(&key)?;
    let path = obj.field(&key);
    let allow_real = p.ty == reg::Type::DielectricOrConductorIor;
    let (n, k) = (reg::CONDUCTOR_N_RANGE.describe(), reg::CONDUCTOR_K_RANGE.describe());
    let forms = if allow_real {
        format!(
            "a number n (dielectric, {}), [n, k] (conductor) or [[n, k], [n, k], [n, k]] (conductor, R G B)",
            reg::DIELECTRIC_IOR_RANGE.describe()
        )
    } else {
        format!("[n, k] (n {n}, k {k}) or [[n, k], [n, k], [n, k]] (R G B)")
    };
    match v {
        Value::Number(_) if allow_real => Ok(vec![Ior::Dielectric(param_number(obj.file, &path, v, p)?)]),
        Value::Array(a) if a.len() == 3 && a.iter().all(Value::is_array) => a
            .iter()
            .enumerate()
            .map(|(i, x)| {
                complex_ior(obj.file, &format!("{path}/{i}"), x, &reg::CONDUCTOR_N_RGB, &reg::CONDUCTOR_K_RGB)
                    .map(Ior::Conductor)
            })
            .collect(),
        Value::Array(a) if a.len() == 2 => {
            Ok(vec![Ior::Conductor(complex_ior(obj.file, &path, v, &reg::CONDUCTOR_N, &reg::CONDUCTOR_K)?)])
        }
        _ => Err(obj.err(&key, format!("expected {forms}, got {}", kind(v)))),
    }
}

/// A choice of facet distribution (entry `p`; absent means Beckmann where `p` is optional).
fn distribution(obj: &Obj, p: &Param) -> Result<Distribution> {
    let key = obj.param_key(p);
    let s = if p.presence == reg::Presence::Required { Some(obj.str(&key)?) } else { obj.opt_str(&key)? };
    match s {
        None | Some("beckmann") => Ok(Distribution::Beckmann),
        Some("ggx") => Ok(Distribution::Ggx),
        Some(other) => Err(obj.err(&key, format!("unknown distribution {other:?}; allowed: \"beckmann\", \"ggx\""))),
    }
}

fn shadowing(obj: &Obj) -> Result<Shadowing> {
    match obj.opt_str("shadowing")? {
        None | Some("smith") => Ok(Shadowing::SmithHeightCorrelated),
        Some("smith-separable") => Ok(Shadowing::SmithSeparable),
        Some("v-cavity") => Ok(Shadowing::VCavity),
        Some(other) => Err(obj.err(
            "shadowing",
            format!("unknown shadowing {other:?}; allowed: \"smith\" (height-correlated, the default), \"smith-separable\" (G1·G1, as Mitsuba 3), \"v-cavity\""),
        )),
    }
}

/// A `microfacet` recipe's slopes: exactly one of `roughness` (one population: Some) and `populations` (None).
fn roughness_or_populations(obj: &Obj) -> Result<Option<f64>> {
    let (r, p) = (&reg::MICROFACET_ROUGHNESS, &reg::MICROFACET_POPULATIONS);
    match (obj.get(&r.key()).is_some(), obj.get(&p.key()).is_some()) {
        (true, true) => Err(obj.err(
            &p.key(),
            "give exactly one of `roughness` (one slope population) and `populations` (a mixture), not both",
        )),
        (false, false) => Err(obj.err(
            &r.key(),
            format!(
                "missing required field: give exactly one of `roughness` (Beckmann rms slope m or GGX α, {}) and `populations` (1 to {} objects {{weight, roughness, distribution}})",
                r.range().describe(),
                reg::MAX_POPULATIONS
            ),
        )),
        (true, false) => obj.param(r).map(Some),
        (false, true) => Ok(None),
    }
}

/// `populations`: 1 to 8 objects {weight, roughness, distribution}; each distribution defaults to the
/// recipe's; the weights in (0, 1] sum to 1 within 1e-9, or one population omits its weight and takes the
/// rest (so that a fit can free the others' weights: docs/recipe-format.md §microfacet).
fn populations(obj: &Obj, default: Distribution) -> Result<SlopeMixture> {
    let key = obj.param_key(&reg::MICROFACET_POPULATIONS);
    let items = obj.array(&key)?;
    if items.is_empty() || items.len() > reg::MAX_POPULATIONS {
        return Err(obj.err(&key, format!("{} populations; allowed: 1 to {}", items.len(), reg::MAX_POPULATIONS)));
    }
    let mut raw: Vec<(Option<f64>, Microfacet)> = Vec::new();
    let mut omitted: Option<usize> = None;
    for (i, item) in items.iter().enumerate() {
        let po = Obj::new(obj.file, obj.element(&key, i), item)?;
        po.deny_unknown_in("microfacet")?;
        let w = po.opt_param(&reg::MICROFACET_POP_WEIGHT)?;
        if w.is_none() {
            if let Some(j) = omitted {
                return Err(po.err(
                    "weight",
                    format!("missing, as is population {j}'s: at most one population omits its weight (it takes 1 − the others'); allowed: a number in (0, 1]"),
                ));
            }
            omitted = Some(i);
        }
        let alpha = po.param(&reg::MICROFACET_POP_ROUGHNESS)?;
        let dist = if po.get("distribution").is_some() {
            distribution(&po, &reg::MICROFACET_POP_DISTRIBUTION)?
        } else {
            default
        };
        raw.push((w, Microfacet::new(dist, alpha)));
    }
    let given: f64 = raw.iter().filter_map(|p| p.0).sum();
    let weights: Vec<f64> = match omitted {
        Some(j) => {
            let rest = 1.0 - given;
            if !(rest > 0.0) {
                return Err(obj.err(
                    &key,
                    format!("population {j} omits its weight, which would be 1 − {given} = {rest}; allowed: the other weights sum below 1"),
                ));
            }
            raw.iter().map(|p| p.0.unwrap_or(rest)).collect()
        }
        None => {
            if (given - 1.0).abs() > 1e-9 {
                return Err(obj.err(
                    &key,
                    format!("the weights sum to {given}; allowed: a sum of 1 (within 1e-9), or omit one population's weight to give it the rest"),
                ));
            }
            raw.iter().map(|p| p.0.unwrap_or(0.0)).collect()
        }
    };
    Ok(SlopeMixture::new(weights.into_iter().zip(raw).map(|(w, (_, m))| (w, m)).collect()))
}

/// `cook-torrance-lobes`: kd, lobes[{ks, r, m}], optional distribution and shadowing.
fn parse_lobes(obj: &Obj) -> Result<Arc<dyn Brdf>> {
    let mut coat_scatter = None;
    let clear_coat = match obj.opt_obj("clear_coat")? {
        None => None,
        Some(c) => {
            c.deny_unknown_in("cook-torrance-lobes")?;
            coat_scatter = c.opt_obj("scatter")?;
            Some(c.param(&reg::CT_COAT_INDEX)?)
        }
    };
    let kd = colour(obj, &reg::CT_KD)?;
    let distribution = distribution(obj, &reg::CT_DISTRIBUTION)?;
    let shadowing = shadowing(obj)?;
    let key = obj.param_key(&reg::CT_LOBES);
    let items = obj.array(&key)?;
    if items.is_empty() || items.len() > MAX_LOBES {
        return Err(obj.err(&key, format!("{} lobes; allowed: 1 to {MAX_LOBES}", items.len())));
    }
    let mut raw = Vec::new();
    for (i, item) in items.iter().enumerate() {
        let lo = Obj::new(obj.file, obj.element(&key, i), item)?;
        lo.deny_unknown_in("cook-torrance-lobes")?;
        let ks = colour(&lo, &reg::CT_LOBE_KS)?;
        let r = lo.param(&reg::CT_LOBE_R)?;
        let m = lo.param(&reg::CT_LOBE_M)?;
        raw.push((ks, r, m));
    }
    let mut all: Vec<&Colour> = vec![&kd];
    all.extend(raw.iter().map(|l| &l.0));
    let sampling = sampling_of(&all);
    let kd = kd.expand(&sampling);
    let lobes: Vec<CtLobe> = raw
        .iter()
        .map(|(ks, r, m)| CtLobe { ks: ks.expand(&sampling), r: *r, facets: Microfacet::new(distribution, *m) })
        .collect();
    let ks: Vec<&Vec<f64>> = lobes.iter().map(|l| &l.ks).collect();
    energy_check(obj, "lobes", &kd, &ks, "Kd + Σ Ks")?;
    let model = CookTorranceLobes::new(kd, lobes, shadowing, sampling.clone())?;
    let model: Arc<dyn Brdf> = Arc::new(match clear_coat {
        Some(n) => model.with_clear_coat(n),
        None => model,
    });
    match (coat_scatter, clear_coat) {
        (Some(s), Some(n)) => {
            let index = vec![Complex64::new(n, 0.0); sampling.len()];
            let halo = scatter::parse_scatter(&s, &reg::CT_SCATTER, "cook-torrance-lobes", &index, &sampling)?;
            Ok(Arc::new(WithHalo::new(model, halo)?))
        }
        _ => Ok(model),
    }
}
