//! The `profile` block of a gloss geometry file (`standards/rspec-20.json`): the linear diode array of a
//! Rhopoint IQ-class meter as data. It gives the number of pixels, the in-plane size of one pixel and their
//! height, each sourced; the pixels sit side by side on the receptor lens, centred on the specular direction,
//! pixel k (0-based, of N) centred at (k − (N − 1)/2)·w in plane. [`parse_spec`] reads the block, [`of`] finds
//! it in a compiled geometry, and [`geometry`] turns it into the geometry the plan measures (one receptor and
//! one [`ReadingSpec::Profile`] reading per pixel). Measuring it is `instrument::profile` (above the plan;
//! `docs/instrument.md` §1.8).
use crate::input::json::Obj;
use crate::instrument::geometry::Stop;
use crate::instrument::reading::ReadingSpec;
use crate::instrument::standards::sourced::{sourced, StandardGeometry};
use crate::registry::Range;
use crate::Result;

/// The largest pixel count a profile may have (a guard against a typo's hours of work: 65 536 aperture
/// integrals).
pub(crate) const MAX_PIXELS: usize = 65_536;

/// The name of the normalising window (a pixel-sized stop centred on the specular direction).
pub(crate) const REFERENCE: &str = "profile-reference";

/// A profile array, compiled: pixel count, pixel size and height (radians).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfileSpec {
    pub pixels: usize,
    /// In-plane size of one pixel, radians.
    pub pixel: f64,
    /// Height of the pixels (perpendicular to the plane of measurement), radians.
    pub perpendicular: f64,
    /// In-plane size of one pixel, degrees, as given.
    pub pixel_deg: f64,
}

impl ProfileSpec {
    /// The in-plane centre of pixel k from the specular direction, degrees: (k − (N − 1)/2)·w.
    pub fn centre_deg(&self, k: usize) -> f64 {
        (k as f64 - 0.5 * (self.pixels as f64 - 1.0)) * self.pixel_deg
    }

    /// The in-plane centre of pixel k from the specular direction, radians.
    pub(crate) fn centre(&self, k: usize) -> f64 {
        self.centre_deg(k).to_radians()
    }

    /// The stop of pixel k on the receptor lens.
    pub fn stop(&self, k: usize) -> Stop {
        Stop::from_angles(self.pixel, self.perpendicular, self.centre(k))
    }

    /// The stop of pixels `first` ..= `last` side by side: in plane from the left edge of `first` to the right
    /// edge of `last`, as tall as the pixels.
    pub(crate) fn window(&self, first: usize, last: usize) -> Stop {
        let lo = (self.centre_deg(first) - 0.5 * self.pixel_deg).to_radians();
        let hi = (self.centre_deg(last) + 0.5 * self.pixel_deg).to_radians();
        Stop::from_angles(hi - lo, self.perpendicular, 0.5 * (lo + hi))
    }

    /// The name of pixel k (and of its reading): `pixel-0000` … (four digits at least, sorted as numbers).
    pub(crate) fn name(&self, k: usize) -> String {
        format!("pixel-{k:04}")
    }
}

/// Parse a `profile` block (`o` is the block) of a geometry of angle `angle_deg`: `pixels` (an integer ≥ 1),
/// `pixel_deg` and `perpendicular_deg`, each `{"value", "source", "status"}`, and optional `notes`. The array
/// must stay above the specimen plane.
pub(crate) fn parse_spec(o: &Obj, angle_deg: f64) -> Result<ProfileSpec> {
    o.deny_unknown(&["pixels", "pixel_deg", "perpendicular_deg", "notes"])?;
    let n = sourced(o, "pixels", Range::closed(1.0, MAX_PIXELS as f64), "the number of pixels of the profile array")?;
    if n.fract() != 0.0 {
        return Err(o.obj("pixels")?.err("value", format!("{n} is not a whole number of pixels")));
    }
    let w = sourced(o, "pixel_deg", Range::open(0.0, 5.0), "the in-plane size of one pixel in degrees")?;
    let h = sourced(o, "perpendicular_deg", Range::open(0.0, 20.0), "the height of the pixels in degrees")?;
    let half = 0.5 * n * w;
    if angle_deg + half >= 90.0 || half > 45.0 {
        return Err(o.obj("pixels")?.err(
            "value",
            format!(
                "{n} pixels of {w}° span ±{half:.4}° about the specular direction: the array must stay within ±45° \
                 and above the specimen plane (angle + half-span < 90°)"
            ),
        ));
    }
    Ok(ProfileSpec { pixels: n as usize, pixel: w.to_radians(), perpendicular: h.to_radians(), pixel_deg: w })
}

/// A receptor made of pixels of the profile array (`"shape": "pixels"`, `docs/instrument.md` §1.9): `o` is the
/// receptor's object, with `pixel_first` and `pixel_last` (sourced whole numbers, 0-based, first ≤ last, both
/// within the array). The stop is the union of those pixels: in plane from the left edge of `pixel_first` to the
/// right edge of `pixel_last`, as tall as the pixels. A geometry without a `profile` block, a pixel outside the
/// array or a window whose first pixel lies after its last is refused, naming the file and the field.
pub(crate) fn pixel_window(o: &Obj, array: Option<&ProfileSpec>) -> Result<Stop> {
    o.deny_unknown(&["name", "shape", "pixel_first", "pixel_last", "notes"])?;
    let Some(p) = array else {
        return Err(o.err(
            "shape",
            "a receptor of shape \"pixels\" reads pixels of the geometry's profile array, and this geometry has no \
             `profile` block (pixels, pixel_deg, perpendicular_deg: docs/instrument.md §1.8)",
        ));
    };
    let last_pixel = (p.pixels - 1) as f64;
    let what = format!("a pixel of the profile array, 0-based: a whole number from 0 to {}", p.pixels - 1);
    let index = |key: &str| -> Result<usize> {
        let v = sourced(o, key, Range::closed(0.0, last_pixel), &what)?;
        if v.fract() != 0.0 {
            return Err(o.obj(key)?.err("value", format!("{v} is not a whole pixel; {what}")));
        }
        Ok(v as usize)
    };
    let (first, last) = (index("pixel_first")?, index("pixel_last")?);
    if first > last {
        return Err(o.obj("pixel_last")?.err(
            "value",
            format!(
                "the window's last pixel {last} lies before its first pixel {first}: give pixel_first ≤ pixel_last"
            ),
        ));
    }
    Ok(p.window(first, last))
}

/// The profile array of a geometry (its `profile` block); a geometry without one is an error naming its file.
pub fn of(g: &StandardGeometry) -> Result<ProfileSpec> {
    let label = match g.origin.as_str() {
        "builtin" => format!("<builtin:{}.json>", g.geometry.id),
        other => other.to_string(),
    };
    let o = Obj::new(&label, "", &g.spec)?;
    if o.get("profile").is_none() || g.geometry.is_composite() || g.geometry.is_colour() {
        return Err(o.err(
            "profile",
            format!(
                "geometry \"{}\" has no profile array; give a `profile` block (pixels, pixel_deg, perpendicular_deg: \
                 docs/instrument.md §1.8) or use the shipped rspec-20",
                g.geometry.id
            ),
        ));
    }
    parse_spec(&o.obj("profile")?, g.geometry.theta.to_degrees())
}

/// The geometry the plan measures for a profile: the geometry's angle, scale and source, the N pixels and
/// the normalising window as receptors, one [`ReadingSpec::Profile`] reading per pixel.
pub(crate) fn geometry(g: &StandardGeometry, p: &ProfileSpec) -> StandardGeometry {
    let mut geo = g.geometry.clone();
    geo.receptors = (0..p.pixels).map(|k| (p.name(k), p.stop(k))).collect();
    geo.receptors.push((REFERENCE.to_string(), Stop::from_angles(p.pixel, p.perpendicular, 0.0)));
    geo.readings =
        (0..p.pixels).map(|k| ReadingSpec::Profile { receptor: p.name(k), reference: REFERENCE.to_string() }).collect();
    StandardGeometry {
        geometry: geo,
        reading_names: (0..p.pixels).map(|k| p.name(k)).collect(),
        spec: g.spec.clone(),
        origin: g.origin.clone(),
    }
}
