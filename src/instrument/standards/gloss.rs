//! The gloss geometry format: a file of `standards/*.json` (or a user file of the same format) gives an angle,
//! the scale (the gloss standard and what it is assigned), a source stop, named receptor stops, an optional
//! `profile` block and the readings taken through them (gloss, haze, log-haze, compensated haze, DOI, or a
//! composite's haze index); [`parse`] validates it into a [`StandardGeometry`], [`describe`] and [`list_line`]
//! show it. The format is documented in `docs/instrument.md`; every number is sourced (`sourced.rs`). Errors
//! name the file, the field path and what is allowed.
use crate::input::json::{parse_json, Obj};
use crate::instrument::geometry::{Geometry, Stop};
use crate::instrument::reading::{ReadingSpec, Scale};
use crate::instrument::standards::sourced::{
    aperture, header, nonempty_str, sourced, sourced_text, string_list, StandardGeometry,
};
use crate::registry::Range;
use crate::{Error, Result};
use serde_json::Value;
use std::collections::HashSet;
use std::sync::Arc;

/// Every shipped gloss geometry file: (file name, text). A test checks this equals the set of `standards/*.json`.
pub const BUILTIN: &[(&str, &str)] = &[
    ("astm-d523-20.json", include_str!("../../../standards/astm-d523-20.json")),
    ("astm-d523-60.json", include_str!("../../../standards/astm-d523-60.json")),
    ("astm-d523-85.json", include_str!("../../../standards/astm-d523-85.json")),
    ("iso-2813-20.json", include_str!("../../../standards/iso-2813-20.json")),
    ("iso-2813-60.json", include_str!("../../../standards/iso-2813-60.json")),
    ("iso-2813-85.json", include_str!("../../../standards/iso-2813-85.json")),
    ("astm-e430-30.json", include_str!("../../../standards/astm-e430-30.json")),
    ("astm-e430-20.json", include_str!("../../../standards/astm-e430-20.json")),
    ("iso-13803-20.json", include_str!("../../../standards/iso-13803-20.json")),
    ("astm-d4039.json", include_str!("../../../standards/astm-d4039.json")),
    ("astm-d2457-45.json", include_str!("../../../standards/astm-d2457-45.json")),
    ("tappi-t480-75.json", include_str!("../../../standards/tappi-t480-75.json")),
    ("rspec-20.json", include_str!("../../../standards/rspec-20.json")),
    ("rhopoint-iq-20.json", include_str!("../../../standards/rhopoint-iq-20.json")),
];

const TOP_FIELDS: &[&str] = &[
    "id",
    "title",
    "standards",
    "angle_deg",
    "scale",
    "reference_index",
    "source",
    "receptors",
    "readings",
    "notes",
    "profile",
];

const GEOMETRY_ONLY: &[&str] = &["angle_deg", "scale", "reference_index", "source", "receptors", "profile"];

/// The allowed `scale.kind` values.
pub(crate) const SCALE_KINDS: &[&str] = &["black-glass", "mirror"];

/// The geometry's scale: `"scale": {"kind": "black-glass", "reference_index": {…}, "assigned_gu": {…}}` or
/// `{"kind": "mirror", "assigned_gu": {…}}`, each number sourced. A file that gives only the older top-level
/// `reference_index` is on the black-glass scale with that glass assigned 100 GU (as D523).
fn scale(o: &Obj) -> Result<Scale> {
    let index_range = Range::closed(1.3, 2.0);
    let index_what = "the refractive index of the black-glass gloss standard";
    match (o.get("scale").is_some(), o.get("reference_index").is_some()) {
        (true, true) => Err(o.err(
            "reference_index",
            "give the scale once: `scale` (preferred) or the older top-level `reference_index`, not both",
        )),
        (false, false) => Err(o.err(
            "scale",
            format!("missing: give `scale` with `kind` one of {} (docs/instrument.md §2.2)", SCALE_KINDS.join(", ")),
        )),
        (false, true) => {
            Ok(Scale::BlackGlass { index: sourced(o, "reference_index", index_range, index_what)?, value: 100.0 })
        }
        (true, false) => {
            let s = o.obj("scale")?;
            let value_what = "the gloss units assigned to the standard";
            match s.str("kind")? {
                "black-glass" => {
                    s.deny_unknown(&["kind", "reference_index", "assigned_gu", "notes"])?;
                    let index = sourced(&s, "reference_index", index_range, index_what)?;
                    let value = sourced(&s, "assigned_gu", Range::open(0.0, 1e4), value_what)?;
                    Ok(Scale::BlackGlass { index, value })
                }
                "mirror" => {
                    s.deny_unknown(&["kind", "assigned_gu", "notes"])?;
                    let value = sourced(&s, "assigned_gu", Range::open(0.0, 1e4), value_what)?;
                    Ok(Scale::Mirror { value })
                }
                other => {
                    Err(s.err("kind", format!("unknown scale kind {other:?}; allowed: {}", SCALE_KINDS.join(", "))))
                }
            }
        }
    }
}

/// Parse and validate a geometry from JSON text; `origin` names the file in errors and in `origin`.
pub fn parse(text: &str, origin: &str) -> Result<StandardGeometry> {
    let spec = parse_json(text, origin)?;
    let o = Obj::new(origin, "", &spec)?;
    o.deny_unknown(TOP_FIELDS)?;
    let (id, title) = header(&o)?;

    // Readings are read first: a geometry whose readings are haze-index is a composite and has no optics.
    let readings_v = o.array("readings")?;
    if readings_v.is_empty() {
        return Err(o.err("readings", "at least one reading is required"));
    }
    let mut quantities = Vec::with_capacity(readings_v.len());
    for (i, v) in readings_v.iter().enumerate() {
        let r = Obj::new(origin, format!("/readings/{i}"), v)?;
        quantities.push(r.str("quantity")?);
    }
    let composite = quantities.contains(&"haze-index");

    let (theta, scale, source, receptors) = if composite {
        if let Some(i) = quantities.iter().position(|q| *q != "haze-index") {
            return Err(Error::input(
                origin,
                format!("/readings/{i}/quantity"),
                "a composite geometry (one with haze-index readings) may only have haze-index readings",
            ));
        }
        if let Some(k) = GEOMETRY_ONLY.iter().find(|k| o.get(k).is_some()) {
            return Err(o.err(
                k,
                "a composite geometry (haze-index readings) has no angle, reference index, source or receptors of its own; \
                 they come from the geometries it names",
            ));
        }
        (0.0, Scale::Mirror { value: 100.0 }, Stop { p: [0.0, 0.0], q: [0.0, 0.0] }, Vec::new())
    } else {
        let angle = sourced(&o, "angle_deg", Range::open(0.0, 90.0), "the angle of incidence in degrees")?;
        let n = scale(&o)?;
        let src = o.obj("source")?;
        let (s_in, s_perp) = aperture(&src, &["shape", "in_plane_deg", "perpendicular_deg"])?;
        if angle + 0.5 * s_in >= 90.0 {
            return Err(src.err(
                "in_plane_deg",
                format!(
                    "the source stop reaches {:.4}° from the normal (angle + in_plane/2), at or below the specimen plane; \
                     it must stay below 90°",
                    angle + 0.5 * s_in
                ),
            ));
        }
        let source = Stop::from_angles(s_in.to_radians(), s_perp.to_radians(), 0.0);
        let array = match o.opt_obj("profile")? {
            Some(p) => Some(crate::instrument::standards::profile::parse_spec(&p, angle)?),
            None => None,
        };
        let rec_v = o.array("receptors")?;
        if rec_v.is_empty() {
            return Err(o.err("receptors", "at least one receptor is required"));
        }
        let mut receptors: Vec<(String, Stop)> = Vec::with_capacity(rec_v.len());
        for (i, v) in rec_v.iter().enumerate() {
            let r = Obj::new(origin, format!("/receptors/{i}"), v)?;
            let name = nonempty_str(&r, "name")?;
            if receptors.iter().any(|(n, _)| *n == name) {
                return Err(r.err("name", format!("duplicate receptor name {name:?}")));
            }
            if r.get("shape").and_then(Value::as_str) == Some("pixels") {
                let stop = crate::instrument::standards::profile::pixel_window(&r, array.as_ref())?;
                receptors.push((name, stop));
                continue;
            }
            let (r_in, r_perp) = aperture(&r, &["name", "shape", "in_plane_deg", "perpendicular_deg", "offset_deg"])?;
            let off = sourced(
                &r,
                "offset_deg",
                Range::closed(-45.0, 45.0),
                "the in-plane offset of the stop centre from the specular axis in degrees (positive towards grazing)",
            )?;
            let top = angle + off + 0.5 * r_in;
            if top >= 90.0 {
                return Err(r.err(
                    "offset_deg",
                    format!(
                        "the receptor stop reaches {top:.4}° from the normal (angle + offset + in_plane/2), at or below the \
                         specimen plane; it must stay below 90°"
                    ),
                ));
            }
            receptors.push((name, Stop::from_angles(r_in.to_radians(), r_perp.to_radians(), off.to_radians())));
        }
        (angle.to_radians(), n, source, receptors)
    };

    let names: Vec<&str> = receptors.iter().map(|(n, _)| n.as_str()).collect();
    let mut readings = Vec::with_capacity(readings_v.len());
    let mut reading_names: Vec<String> = Vec::with_capacity(readings_v.len());
    for (i, v) in readings_v.iter().enumerate() {
        let r = Obj::new(origin, format!("/readings/{i}"), v)?;
        let (spec, name) = reading(&r, &names, id, (theta, &receptors))?;
        let display = name.unwrap_or_else(|| spec.quantity().to_string());
        if reading_names.contains(&display) {
            return Err(r.err(
                "name",
                format!("two readings would both be displayed as {display:?}; give them distinct \"name\" fields"),
            ));
        }
        reading_names.push(display);
        readings.push(spec);
    }

    let geometry = Geometry {
        id: id.to_string(),
        title,
        theta,
        viewing: theta,
        scale,
        source,
        receptors,
        integrals: vec![],
        readings,
    };
    Ok(StandardGeometry { geometry, reading_names, spec: Arc::new(spec), origin: origin.to_string() })
}

fn receptor_ref(o: &Obj, key: &str, names: &[&str]) -> Result<String> {
    let s = o.str(key)?;
    check_receptor(o, &o.field(key), s, names)?;
    Ok(s.to_string())
}

fn receptor_list(o: &Obj, key: &str, names: &[&str]) -> Result<Vec<String>> {
    let list = string_list(o, key)?;
    for (i, s) in list.iter().enumerate() {
        check_receptor(o, &o.element(key, i), s, names)?;
    }
    Ok(list)
}

fn check_receptor(o: &Obj, path: &str, name: &str, names: &[&str]) -> Result<()> {
    if names.contains(&name) {
        Ok(())
    } else {
        Err(Error::input(
            o.file,
            path,
            format!("unknown receptor {name:?}; receptors defined in this geometry: {}", names.join(", ")),
        ))
    }
}

/// The allowed `quantity` values of a reading.
pub(crate) const QUANTITIES: &[&str] =
    &["gloss", "haze", "log-haze", "haze-compensated", "log-haze-compensated", "doi", "haze-index"];

/// The subtraction factor of a compensated haze reading: mean_r Ω⊥(r) / Ω⊥(compensation), the ratio of the
/// haze receptors' and the compensation receptor's projected solid angles (`docs/instrument.md` §1.7), so that
/// a Lambertian body reads exactly 0. The compensation receptor must see the body's diffuse light away from
/// the specular region: a stop that overlaps the specular receptor or a haze receptor is refused (it would
/// subtract specular or haze light, not the body's).
fn compensation_factor(
    r: &Obj,
    receptors: &[String],
    specular: &str,
    compensation: &str,
    geometry: (f64, &[(String, Stop)]),
) -> Result<f64> {
    let (theta, stops) = geometry;
    let stop = |name: &str| stops.iter().find(|(n, _)| n == name).map(|(_, s)| *s).expect("receptor checked");
    let c = stop(compensation);
    let deg = |s: &Stop| format!("{:.4}° to {:.4}°", s.p[0].atan().to_degrees(), s.p[1].atan().to_degrees());
    let overlaps = |a: &Stop, b: &Stop| a.p[0] < b.p[1] && b.p[0] < a.p[1] && a.q[0] < b.q[1] && b.q[0] < a.q[1];
    for (role, name) in std::iter::once(("specular", specular)).chain(receptors.iter().map(|n| ("haze", n.as_str()))) {
        let s = stop(name);
        if name == compensation || overlaps(&c, &s) {
            return Err(r.err(
                "compensation",
                format!(
                    "the compensation receptor {compensation:?} (in plane {} from specular) overlaps the {role} \
                     receptor {name:?} ({}); it must see the body's diffuse light away from the specular and haze \
                     receptors",
                    deg(&c),
                    deg(&s)
                ),
            ));
        }
    }
    let omega = c.projected_solid_angle(theta);
    if !(omega > 0.0) {
        return Err(r.err("compensation", "the compensation receptor has no projected solid angle"));
    }
    let mean = receptors.iter().map(|n| stop(n).projected_solid_angle(theta)).sum::<f64>() / receptors.len() as f64;
    Ok(mean / omega)
}

/// One entry of `readings`: the compiled spec and its optional display name. `geometry` is (θ, receptors).
fn reading(
    r: &Obj,
    names: &[&str],
    own_id: &str,
    geometry: (f64, &[(String, Stop)]),
) -> Result<(ReadingSpec, Option<String>)> {
    let q = r.str("quantity")?;
    let allowed: &[&str] = match q {
        "gloss" => &["quantity", "name", "receptor"],
        "haze" => &["quantity", "name", "receptors", "specular"],
        "log-haze" => &["quantity", "name", "receptors", "specular", "k"],
        "haze-compensated" => &["quantity", "name", "receptors", "specular", "compensation"],
        "log-haze-compensated" => &["quantity", "name", "receptors", "specular", "compensation", "k"],
        "doi" => &["quantity", "name", "specular", "offset"],
        "haze-index" => &["quantity", "name", "minuend", "subtrahend"],
        other => {
            return Err(r.err("quantity", format!("unknown quantity {other:?}; allowed: {}", QUANTITIES.join(", "))))
        }
    };
    r.deny_unknown(allowed)?;
    let name = match r.get("name") {
        None => None,
        Some(_) => Some(nonempty_str(r, "name")?),
    };
    let spec = match q {
        "gloss" => ReadingSpec::Gloss { receptor: receptor_ref(r, "receptor", names)? },
        "haze" => ReadingSpec::Haze {
            receptors: receptor_list(r, "receptors", names)?,
            specular: receptor_ref(r, "specular", names)?,
        },
        "log-haze" => ReadingSpec::LogHaze {
            receptors: receptor_list(r, "receptors", names)?,
            specular: receptor_ref(r, "specular", names)?,
            k: sourced(r, "k", Range::open(0.0, 1e6), "the log-haze scale factor K")?,
        },
        "haze-compensated" | "log-haze-compensated" => {
            let receptors = receptor_list(r, "receptors", names)?;
            let specular = receptor_ref(r, "specular", names)?;
            let compensation = receptor_ref(r, "compensation", names)?;
            let factor = compensation_factor(r, &receptors, &specular, &compensation, geometry)?;
            if q == "haze-compensated" {
                ReadingSpec::HazeCompensated { receptors, specular, compensation, factor }
            } else {
                let k = sourced(r, "k", Range::open(0.0, 1e6), "the log-haze scale factor K")?;
                ReadingSpec::LogHazeCompensated { receptors, specular, compensation, factor, k }
            }
        }
        "doi" => ReadingSpec::Doi {
            specular: receptor_ref(r, "specular", names)?,
            offset: receptor_list(r, "offset", names)?,
        },
        _ => {
            let minuend = nonempty_str(r, "minuend")?;
            let subtrahend = nonempty_str(r, "subtrahend")?;
            for (key, v) in [("minuend", &minuend), ("subtrahend", &subtrahend)] {
                if v == own_id {
                    return Err(r.err(key, "a composite geometry cannot name itself"));
                }
            }
            ReadingSpec::HazeIndex { minuend, subtrahend }
        }
    };
    Ok((spec, name))
}

// ---------------------------------------------------------------------------------------------------------
// Display
// ---------------------------------------------------------------------------------------------------------

/// A multi-line description: title, standards, every number with its value, unit, status and source.
pub fn describe(g: &StandardGeometry) -> String {
    let s = &g.spec;
    let geo = &g.geometry;
    let mut out = format!("{} — {}\n", geo.id, geo.title);
    let standards: Vec<&str> = s
        .get("standards")
        .and_then(Value::as_array)
        .map(|a| a.iter().filter_map(Value::as_str).collect())
        .unwrap_or_default();
    out += &format!("  standards: {}\n  origin: {}\n", standards.join("; "), g.origin);
    if geo.is_composite() {
        out += "  composite geometry (no optics of its own)\n";
    } else {
        out += &format!("  angle of incidence: {}\n", sourced_text(s.get("angle_deg"), "°"));
        out += &format!("  scale: {}\n", geo.scale.describe());
        match s.get("scale") {
            Some(sc) => {
                if let Some(n) = sc.get("reference_index") {
                    out += &format!("    reference index (black glass): {}\n", sourced_text(Some(n), ""));
                }
                out += &format!("    assigned to the standard: {}\n", sourced_text(sc.get("assigned_gu"), " GU"));
                if let Some(n) = sc.get("notes").and_then(Value::as_str) {
                    out += &format!("    {n}\n");
                }
            }
            None => {
                out += &format!("    reference index (black glass): {}\n", sourced_text(s.get("reference_index"), ""));
                out += "    assigned to the standard: 100 GU (implied by a top-level reference_index)\n";
            }
        }
        if let Some(src) = s.get("source") {
            out += &format!(
                "  source stop: {} (solid angle {:.4e} sr)\n",
                src.get("shape").and_then(Value::as_str).unwrap_or("?"),
                geo.source.solid_angle()
            );
            out += &format!("    in plane: {}\n", sourced_text(src.get("in_plane_deg"), "°"));
            out += &format!("    perpendicular: {}\n", sourced_text(src.get("perpendicular_deg"), "°"));
        }
        let recs = s.get("receptors").and_then(Value::as_array).cloned().unwrap_or_default();
        for (r, (name, stop)) in recs.iter().zip(&geo.receptors) {
            out += &format!(
                "  receptor {name:?}: {} (solid angle {:.4e} sr)\n",
                r.get("shape").and_then(Value::as_str).unwrap_or("?"),
                stop.solid_angle()
            );
            if r.get("shape").and_then(Value::as_str) == Some("pixels") {
                out += &format!(
                    "    pixels of the profile array, {:.4}° to {:.4}° from specular in plane (pixel edges), as tall as the \
                     pixels\n",
                    stop.p[0].atan().to_degrees(),
                    stop.p[1].atan().to_degrees()
                );
                out += &format!("    first pixel: {}\n", sourced_text(r.get("pixel_first"), ""));
                out += &format!("    last pixel: {}\n", sourced_text(r.get("pixel_last"), ""));
                continue;
            }
            out += &format!("    in plane: {}\n", sourced_text(r.get("in_plane_deg"), "°"));
            out += &format!("    perpendicular: {}\n", sourced_text(r.get("perpendicular_deg"), "°"));
            out += &format!("    offset from specular: {}\n", sourced_text(r.get("offset_deg"), "°"));
        }
    }
    if let Some(p) = s.get("profile") {
        out += "  profile array (glossmeter profile):\n";
        out += &format!("    pixels: {}\n", sourced_text(p.get("pixels"), ""));
        out += &format!("    pixel size in plane: {}\n", sourced_text(p.get("pixel_deg"), "°"));
        out += &format!("    pixel height: {}\n", sourced_text(p.get("perpendicular_deg"), "°"));
        if let Some(n) = p.get("notes").and_then(Value::as_str) {
            out += &format!("    {n}\n");
        }
    }
    out += "  readings:\n";
    let rv = s.get("readings").and_then(Value::as_array).cloned().unwrap_or_default();
    for ((spec, name), raw) in geo.readings.iter().zip(&g.reading_names).zip(&rv) {
        out += &format!("    {name} ({}): {}\n", spec.unit(), reading_summary(spec));
        if let ReadingSpec::LogHaze { .. } | ReadingSpec::LogHazeCompensated { .. } = spec {
            out += &format!("      K: {}\n", sourced_text(raw.get("k"), ""));
        }
    }
    if let Some(n) = s.get("notes").and_then(Value::as_str) {
        out += &format!("  notes: {n}\n");
    }
    out
}

/// For a geometry whose receptors include windows of its profile array (`"shape": "pixels"`,
/// `docs/instrument.md` §1.9), the lines `--explain` adds: each window's pixels and angles, each reading's
/// definition, and every number of the file whose status is `assumed` (JSON Pointer, value, the start of its
/// reason). None for any other geometry.
pub(crate) fn pixel_array_text(g: &StandardGeometry) -> Option<String> {
    let recs = g.spec.get("receptors").and_then(Value::as_array)?;
    let is_pixels = |r: &Value| r.get("shape").and_then(Value::as_str) == Some("pixels");
    if !recs.iter().any(is_pixels) {
        return None;
    }
    let mut out = String::from("  pixel-array readings (docs/instrument.md §1.9):\n");
    for (r, (name, stop)) in recs.iter().zip(&g.geometry.receptors) {
        if is_pixels(r) {
            let px = |k: &str| r.get(k).and_then(|x| x.get("value")).map(|x| x.to_string()).unwrap_or_default();
            out += &format!(
                "    window {name}: pixels {}–{}, {:+.4}° to {:+.4}° from specular in plane\n",
                px("pixel_first"),
                px("pixel_last"),
                stop.p[0].atan().to_degrees(),
                stop.p[1].atan().to_degrees()
            );
        }
    }
    for (spec, name) in g.geometry.readings.iter().zip(&g.reading_names) {
        out += &format!("    {name} ({}) = {}\n", spec.unit(), reading_summary(spec));
    }
    let mut assumed = Vec::new();
    assumed_numbers(&g.spec, String::new(), &mut assumed);
    out += &format!(
        "  assumed numbers of {} ({}; `glossmeter standards {}` gives each reason in full):\n",
        g.geometry.id,
        assumed.len(),
        g.geometry.id
    );
    for (pointer, value, why) in assumed {
        let short: String = why.chars().take(110).collect();
        let more = if why.chars().count() > 110 { "…" } else { "" };
        out += &format!("    {pointer} = {value}: {short}{more}\n");
    }
    Some(out)
}

/// Every sourced number of a geometry specification whose status is `assumed`: (JSON Pointer, value, source).
fn assumed_numbers(v: &Value, pointer: String, out: &mut Vec<(String, String, String)>) {
    match v {
        Value::Object(m) => {
            if let (Some(value), Some("assumed")) = (m.get("value"), m.get("status").and_then(Value::as_str)) {
                let source = m.get("source").and_then(Value::as_str).unwrap_or("").to_string();
                out.push((pointer, value.to_string(), source));
                return;
            }
            for (k, x) in m {
                assumed_numbers(x, format!("{pointer}/{}", k.replace('~', "~0").replace('/', "~1")), out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                assumed_numbers(x, format!("{pointer}/{i}"), out);
            }
        }
        _ => {}
    }
}

fn reading_summary(r: &ReadingSpec) -> String {
    match r {
        ReadingSpec::Gloss { receptor } => format!("100·Φ({receptor}) / Φ_standard({receptor})"),
        ReadingSpec::Haze { receptors, specular } => {
            format!("100·mean Φ({}) / Φ_standard({specular})", receptors.join(", "))
        }
        ReadingSpec::LogHaze { receptors, specular, k } => {
            format!("{k}·log10(H/20 + 1), H = 100·mean Φ({}) / Φ_standard({specular})", receptors.join(", "))
        }
        ReadingSpec::HazeCompensated { receptors, specular, compensation, factor } => format!(
            "100·(mean Φ({}) − {factor:.6}·Φ({compensation})) / Φ_standard({specular}) (factor = mean Ω⊥ of the haze \
             receptors / Ω⊥({compensation}): a Lambertian body reads 0)",
            receptors.join(", ")
        ),
        ReadingSpec::LogHazeCompensated { receptors, specular, compensation, factor, k } => format!(
            "{k}·log10(H_c/20 + 1), H_c = 100·(mean Φ({}) − {factor:.6}·Φ({compensation})) / Φ_standard({specular})",
            receptors.join(", ")
        ),
        ReadingSpec::Doi { specular, offset } => {
            format!("100·(Φ({specular}) − mean Φ({})) / Φ({specular})", offset.join(", "))
        }
        ReadingSpec::HazeIndex { minuend, subtrahend } => format!("gloss({minuend}) − gloss({subtrahend})"),
        ReadingSpec::Profile { receptor, reference } => format!("100·Φ({receptor}) / Φ_standard({reference})"),
        ReadingSpec::Colour { quantity, terms, .. } => {
            let t: Vec<String> =
                terms.iter().map(|(n, s)| format!("{}Φ_XYZ({n})", if *s < 0.0 { "− " } else { "" })).collect();
            format!("{} of ({}) / Φ_white", quantity.name(), t.join(" "))
        }
    }
}

/// One line: id, angle, reference index, receptors (size and offset), readings.
pub fn list_line(g: &StandardGeometry) -> String {
    let geo = &g.geometry;
    let readings = g.reading_names.join(", ");
    if geo.is_composite() {
        let parts: Vec<String> = geo.readings.iter().map(reading_summary).collect();
        return format!("{:<15} composite            {}  [{}]", geo.id, readings, parts.join("; "));
    }
    let recs = g.spec.get("receptors").and_then(Value::as_array).cloned().unwrap_or_default();
    let val = |r: &Value, k: &str| r.get(k).and_then(|x| x.get("value")).map(|x| x.to_string()).unwrap_or_default();
    let receptors: Vec<String> = recs
        .iter()
        .map(|r| {
            let name = r.get("name").and_then(Value::as_str).unwrap_or("?");
            if r.get("shape").and_then(Value::as_str) == Some("pixels") {
                return format!("{name} pixels {}–{}", val(r, "pixel_first"), val(r, "pixel_last"));
            }
            let off = val(r, "offset_deg");
            let off = if off == "0" || off == "0.0" { String::new() } else { format!("@{off}°") };
            format!("{name} {}°×{}°{off}", val(r, "in_plane_deg"), val(r, "perpendicular_deg"))
        })
        .collect();
    format!(
        "{:<15} {:>4.1}°  {:<9}  receptors: {}  readings: {}",
        geo.id,
        geo.theta.to_degrees(),
        match geo.scale {
            Scale::BlackGlass { index, value: 100.0 } => format!("n={index}"),
            Scale::BlackGlass { index, value } => format!("n={index}={value}"),
            Scale::Mirror { value } => format!("mirror×{value}"),
        },
        receptors.join(", "),
        readings
    )
}

/// Ids of the builtin geometries, in table order (without parsing them).
pub fn builtin_ids() -> Vec<&'static str> {
    let mut seen = HashSet::new();
    BUILTIN.iter().map(|(f, _)| f.trim_end_matches(".json")).filter(|id| seen.insert(*id)).collect()
}
