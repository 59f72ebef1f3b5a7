//! Colour geometries as data: multi-angle colour (ASTM E2194, an E2539-style set) and the d/8 integrating
//! sphere (SCI, SCE), read from `standards/colour/*.json` into the same [`StandardGeometry`] the gloss
//! geometries compile to, so that colour readings go through the same plan, methods and quadrature as gloss
//! (`docs/colour.md`).
//!
//! Why a module of its own: the files have their own format (an illumination angle and a signed aspecular angle,
//! or a sphere with or without its specular port), and every colour geometry has the same eight readings:
//! X, Y, Z (reflectance factors × 100 under the plan's illuminant and observer, the perfect reflecting diffuser
//! reading Y = 100), L*, a*, b*, C*ab and hab. What they integrate:
//!
//! * **Directional** (`kind: "directional"`): the aperture integral of gloss, Φ_c = ∫_source ∫_receptor
//!   Σ_k W_ck f_k cos θi cos θo dωi dωo with the X, Y, Z rows of the weighting
//!   (`colorimetry::weighting::WeightingKind::Xyz`), the receptor lens on its own axis at θv = θi − aspecular
//!   (signed, positive on the specular side). The receptor must not see the mirror image of the source (checked
//!   here), so the method has no delta part and uses the plain chart. X = Φ_X / Φ_PRD with Φ_PRD = P_s P_r / π
//!   the perfect diffuser's flux (projected solid angles in closed form, Lambert's polygon formula,
//!   `reference::projected_solid_angle`).
//! * **Sphere** (`kind: "sphere"`): the integrals of `instrument::sphere`, the hemisphere (SCI) minus the
//!   specular port (SCE), relative to the perfect diffuser under full-hemisphere illumination (Φ_PRD = 1).
use std::f64::consts::PI;

use crate::input::json::{parse_json, Obj};
use crate::instrument::geometry::{Geometry, Integral, Stop};
use crate::instrument::reading::{ColourQuantity, ReadingSpec, Scale};
use crate::instrument::reference::projected_solid_angle;
use crate::instrument::standards::sourced::{aperture, header, sourced, StandardGeometry};
use crate::registry::Range;
use crate::{Result, Vec3};

/// Every shipped colour geometry: (file name, text).
pub const BUILTIN: &[(&str, &str)] = &[
    ("astm-e2194-15.json", include_str!("../../../standards/colour/astm-e2194-15.json")),
    ("astm-e2194-25.json", include_str!("../../../standards/colour/astm-e2194-25.json")),
    ("astm-e2194-45.json", include_str!("../../../standards/colour/astm-e2194-45.json")),
    ("astm-e2194-75.json", include_str!("../../../standards/colour/astm-e2194-75.json")),
    ("astm-e2194-110.json", include_str!("../../../standards/colour/astm-e2194-110.json")),
    ("astm-e2539-m15.json", include_str!("../../../standards/colour/astm-e2539-m15.json")),
    ("astm-e2539-15.json", include_str!("../../../standards/colour/astm-e2539-15.json")),
    ("astm-e2539-25.json", include_str!("../../../standards/colour/astm-e2539-25.json")),
    ("astm-e2539-45.json", include_str!("../../../standards/colour/astm-e2539-45.json")),
    ("astm-e2539-75.json", include_str!("../../../standards/colour/astm-e2539-75.json")),
    ("astm-e2539-110.json", include_str!("../../../standards/colour/astm-e2539-110.json")),
    ("d8-sci.json", include_str!("../../../standards/colour/d8-sci.json")),
    ("d8-sce.json", include_str!("../../../standards/colour/d8-sce.json")),
];

/// How a colour geometry illuminates and views (what `glossmeter standards` prints).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColourKind {
    /// Directional illumination at `illumination` (radians from the normal), viewing at `viewing` = illumination −
    /// aspecular (radians, signed: positive on the specular side).
    Directional { illumination: f64, aspecular: f64, viewing: f64 },
    /// Integrating sphere: viewing at `viewing` (radians); `port` the specular port's half-angle (radians) for SCE,
    /// None for SCI.
    Sphere { viewing: f64, port: Option<f64> },
}

const COMMON: &[&str] = &["id", "title", "standards", "kind", "notes"];

/// Whether a geometry file is a colour geometry (it has a `kind`; gloss files do not).
pub(crate) fn is_colour_spec(spec: &serde_json::Value) -> bool {
    spec.get("kind").is_some()
}

/// The readings of a colour geometry: the eight quantities of the same sum of integrals.
fn colour_readings(terms: Vec<(String, f64)>, white: f64) -> (Vec<ReadingSpec>, Vec<String>) {
    let specs: Vec<ReadingSpec> = ColourQuantity::ALL
        .iter()
        .map(|&quantity| ReadingSpec::Colour { quantity, terms: terms.clone(), white })
        .collect();
    let names = ColourQuantity::ALL.iter().map(|q| q.name().to_string()).collect();
    (specs, names)
}

/// The colour kind of a compiled colour geometry.
pub fn colour_kind(g: &Geometry) -> Option<ColourKind> {
    if !g.is_colour() {
        return None;
    }
    if g.integrals.is_empty() {
        Some(ColourKind::Directional { illumination: g.theta, aspecular: g.theta - g.viewing, viewing: g.viewing })
    } else {
        let port = g.integrals.iter().find_map(|(_, i)| match i {
            Integral::Port { half_angle } => Some(*half_angle),
            _ => None,
        });
        Some(ColourKind::Sphere { viewing: g.theta, port })
    }
}

/// Parse and validate a colour geometry.
pub fn parse(text: &str, origin: &str) -> Result<StandardGeometry> {
    let spec = parse_json(text, origin)?;
    let o = Obj::new(origin, "", &spec)?;
    let (id, title) = header(&o)?;
    let allowed = |extra: &[&'static str]| -> Vec<&'static str> { COMMON.iter().chain(extra).copied().collect() };
    let (geometry, reading_names) = match o.str("kind")? {
        "directional" => {
            o.deny_unknown(&allowed(&["illumination_deg", "aspecular_deg", "source", "receptor"]))?;
            let ill = sourced(&o, "illumination_deg", Range::open(0.0, 90.0), "the illumination angle in degrees")?;
            let asp = sourced(
                &o,
                "aspecular_deg",
                Range::closed(-90.0, 180.0),
                "the aspecular angle in degrees (positive towards the illuminator)",
            )?;
            let view = ill - asp;
            let src = o.obj("source")?;
            let (s_in, s_perp) = aperture(&src, &["shape", "in_plane_deg", "perpendicular_deg"])?;
            let rec = o.obj("receptor")?;
            let (r_in, r_perp) = aperture(&rec, &["shape", "in_plane_deg", "perpendicular_deg"])?;
            if ill + 0.5 * s_in >= 90.0 {
                return Err(src.err(
                    "in_plane_deg",
                    "the source stop reaches the specimen plane (illumination + in_plane/2 ≥ 90°)",
                ));
            }
            if view.abs() + 0.5 * r_in >= 90.0 {
                return Err(o.err(
                    "aspecular_deg",
                    format!(
                        "the receptor (viewing at {view}° from the normal, illumination − aspecular) reaches the specimen \
                         plane with its in-plane half-width {}°; it must stay above it",
                        0.5 * r_in
                    ),
                ));
            }
            if asp.abs() <= 0.5 * (s_in + r_in) {
                return Err(o.err(
                    "aspecular_deg",
                    format!(
                        "|aspecular| = {}° does not exceed the half-widths of source and receptor ({}°): the receptor \
                         would see the mirror image of the source; a colour geometry must look off specular (use a \
                         gloss geometry for the specular direction)",
                        asp.abs(),
                        0.5 * (s_in + r_in)
                    ),
                ));
            }
            let (theta, viewing) = (ill.to_radians(), view.to_radians());
            let source = Stop::from_angles(s_in.to_radians(), s_perp.to_radians(), 0.0);
            let receptor = Stop::from_angles(r_in.to_radians(), r_perp.to_radians(), 0.0);
            let (ps, pr) = projected_solid_angles(theta, viewing, source, receptor);
            let (readings, names) = colour_readings(vec![("receptor".to_string(), 1.0)], ps * pr / PI);
            let geometry = Geometry {
                id: id.to_string(),
                title,
                theta,
                viewing,
                scale: NO_SCALE,
                source,
                receptors: vec![("receptor".to_string(), receptor)],
                integrals: vec![],
                readings,
            };
            (geometry, names)
        }
        "sphere" => {
            o.deny_unknown(&allowed(&["viewing_deg", "specular", "specular_port_half_angle_deg"]))?;
            let view = sourced(&o, "viewing_deg", Range::closed(0.0, 60.0), "the viewing angle in degrees")?;
            let port = match o.str("specular")? {
                "included" => {
                    if o.get("specular_port_half_angle_deg").is_some() {
                        return Err(o.err(
                            "specular_port_half_angle_deg",
                            "an SCI sphere (specular \"included\") has no open specular port",
                        ));
                    }
                    None
                }
                "excluded" => {
                    let b = sourced(
                        &o,
                        "specular_port_half_angle_deg",
                        Range::open(0.0, 30.0),
                        "the half-angle of the specular port in degrees",
                    )?;
                    if view + b >= 90.0 {
                        return Err(o.err("specular_port_half_angle_deg", "the port reaches the specimen plane"));
                    }
                    Some(b.to_radians())
                }
                other => {
                    return Err(
                        o.err("specular", format!("unknown value {other:?}; allowed: \"included\", \"excluded\""))
                    )
                }
            };
            let mut integrals = vec![("hemisphere".to_string(), Integral::Hemisphere)];
            let mut terms = vec![("hemisphere".to_string(), 1.0)];
            if let Some(half_angle) = port {
                integrals.push(("port".to_string(), Integral::Port { half_angle }));
                terms.push(("port".to_string(), -1.0));
            }
            let (readings, names) = colour_readings(terms, 1.0);
            let theta = view.to_radians();
            let none = Stop { p: [0.0; 2], q: [0.0; 2] };
            let geometry = Geometry {
                id: id.to_string(),
                title,
                theta,
                viewing: theta,
                scale: NO_SCALE,
                source: none,
                receptors: vec![],
                integrals,
                readings,
            };
            (geometry, names)
        }
        other => return Err(o.err("kind", format!("unknown kind {other:?}; allowed: \"directional\", \"sphere\""))),
    };
    Ok(StandardGeometry {
        geometry,
        reading_names,
        spec: std::sync::Arc::new(spec.clone()),
        origin: origin.to_string(),
    })
}

/// A colour geometry has no gloss standard; its readings are relative to the perfect reflecting diffuser, in
/// closed form. (The scale is never used: no colour reading has a standard flux.)
const NO_SCALE: Scale = Scale::Mirror { value: 100.0 };

/// Ids of the builtin colour geometries, in table order (without parsing them).
pub fn builtin_ids() -> Vec<&'static str> {
    BUILTIN.iter().map(|(f, _)| f.trim_end_matches(".json")).collect()
}

/// True if `id` names a builtin colour geometry.
#[cfg(test)]
pub(crate) fn is_colour_id(id: &str) -> bool {
    builtin_ids().contains(&id)
}

/// One line for `glossmeter standards`.
pub fn list_line(g: &StandardGeometry) -> String {
    let readings = g.reading_names.join(", ");
    match colour_kind(&g.geometry) {
        Some(ColourKind::Directional { illumination, aspecular, viewing }) => format!(
            "{:<15} colour  illumination {:.0}°, aspecular {:.0}° (viewing {:.0}°)  readings: {readings}",
            g.geometry.id,
            illumination.to_degrees(),
            aspecular.to_degrees(),
            viewing.to_degrees(),
        ),
        Some(ColourKind::Sphere { viewing, port }) => format!(
            "{:<15} colour  d/{:.0} sphere, {}  readings: {readings}",
            g.geometry.id,
            viewing.to_degrees(),
            match port {
                None => "specular included".to_string(),
                Some(b) => format!("specular port {:.1}° half-angle excluded", b.to_degrees()),
            },
        ),
        None => String::new(),
    }
}

/// A multi-line description: title, origin, the geometry in one line and every number of the file with its
/// value, status and source.
pub fn describe(g: &StandardGeometry) -> String {
    let mut out = format!("{} — {}\n  origin: {}\n  {}\n", g.geometry.id, g.geometry.title, g.origin, list_line(g));
    let text = serde_json::to_string_pretty(g.spec.as_ref()).unwrap_or_default();
    for line in text.lines() {
        out += &format!("  {line}\n");
    }
    out
}

/// Projected solid angles of the source stop (about the source axis at `illumination`) and the receptor stop
/// (about the receptor axis at `viewing`), by Lambert's polygon formula.
pub(crate) fn projected_solid_angles(illumination: f64, viewing: f64, source: Stop, receptor: Stop) -> (f64, f64) {
    let (si, ci) = illumination.sin_cos();
    let (sv, cv) = viewing.sin_cos();
    let ps = projected_solid_angle(Vec3::new(-si, 0.0, ci), Vec3::new(ci, 0.0, si), source);
    let pr = projected_solid_angle(Vec3::new(sv, 0.0, cv), Vec3::new(cv, 0.0, -sv), receptor);
    (ps, pr)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn find(id: &str) -> StandardGeometry {
        let (file, text) = BUILTIN.iter().find(|(f, _)| f.trim_end_matches(".json") == id).unwrap();
        parse(text, file).unwrap()
    }

    #[test]
    fn a_colour_geometry_must_look_off_specular() {
        let text = BUILTIN[0].1.replace("\"value\": 15,", "\"value\": 1.5,");
        let e = parse(&text, "t.json").unwrap_err().to_string();
        assert!(e.contains("aspecular_deg") && e.contains("mirror image"), "{e}");
    }

    #[test]
    fn the_perfect_diffusers_flux_is_the_product_of_projected_solid_angles() {
        // A small stop: P ≈ Ω cos θ of its axis.
        let g = find("astm-e2194-15").geometry;
        let (ps, pr) = projected_solid_angles(g.theta, g.viewing, g.source, g.receptors[0].1);
        let om = g.source.solid_angle();
        assert!((ps / (om * g.theta.cos()) - 1.0).abs() < 1e-3);
        assert!((pr / (om * g.viewing.cos()) - 1.0).abs() < 1e-3);
    }
}
