//! A height map as glossmeter holds it, whatever file it came from: a regular grid of heights in metres with
//! its lateral calibration, invalid points as NaN, and the size limits checked before anything is allocated
//! (docs/topography.md §Limits).
use crate::error::number;
use crate::{Error, Result};

/// The largest file read as a topography: 256 MiB (a 4096 × 4096 map of doubles is 128 MiB).
pub(crate) const MAX_FILE_BYTES: u64 = 256 * 1024 * 1024;

/// The most points a map may have: 2²⁴ = 16 777 216 (4096 × 4096). Its heights take 128 MiB and its
/// spectrum 256 MiB of complex numbers.
pub(crate) const MAX_POINTS: usize = 1 << 24;

/// The smallest map: 2 points each way (a 2 × 2 map has one cell, one slope).
pub(crate) const MIN_SIDE: usize = 2;

/// The lateral spacings allowed, metres: 10⁻¹² (below any instrument's sampling) to 1 m (a 4096-point map
/// of 1 m pixels is 4 km wide).
pub(crate) const PIXEL_RANGE_M: (f64, f64) = (1e-12, 1.0);

/// The largest |height| allowed after scaling, metres: 1 m. A coating's topography spans micrometres; a value
/// beyond a metre is a scale or unit error.
pub(crate) const MAX_ABS_HEIGHT_M: f64 = 1.0;

/// The file formats read (docs/topography.md §Formats).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// ISO 25178-72 XML 3D surface profile (`.x3p`).
    X3p,
    /// ISO 25178-71 surface data file, text form (`aISO-1.0`).
    SdfText,
    /// ISO 25178-71 surface data file, binary form (`bISO-1.0`).
    SdfBinary,
    /// Gwyddion Simple Field (`.gsf`).
    Gsf,
    /// Digital Surf (`.sur`, MountainsMap).
    Sur,
    /// An array of heights handed over with its calibration (the Python bindings: docs/python.md §Topography).
    Array,
    /// A plain text or CSV matrix of heights, its calibration given by the caller.
    Text,
}

impl Format {
    /// The format's name in documents and messages.
    pub fn name(self) -> &'static str {
        match self {
            Format::X3p => "x3p",
            Format::SdfText => "sdf-text",
            Format::SdfBinary => "sdf-binary",
            Format::Gsf => "gsf",
            Format::Sur => "sur",
            Format::Array => "array",
            Format::Text => "text",
        }
    }
}

/// A regular grid of heights.
#[derive(Clone, Debug, PartialEq)]
pub struct HeightMap {
    /// The file it came from, for messages.
    pub file: String,
    pub format: Format,
    /// Points along x (fastest in `z`) and along y.
    pub nx: usize,
    pub ny: usize,
    /// Spacing of the points along x and y, metres.
    pub dx: f64,
    pub dy: f64,
    /// Heights, metres, row by row (`z[j·nx + i]` at x = i·dx, y = j·dy); NaN marks an invalid point.
    pub z: Vec<f64>,
}

/// Check a map's dimensions against the limits before anything of that size is allocated; `field` names
/// where the dimensions were read.
pub fn check_dimensions(file: &str, field: &str, nx: u64, ny: u64) -> Result<usize> {
    let allowed = format!("allowed: at least {MIN_SIDE} points each way and at most {MAX_POINTS} points in all");
    if nx < MIN_SIDE as u64 || ny < MIN_SIDE as u64 {
        return Err(Error::input(
            file,
            field,
            format!("a map of {nx} × {ny} points is not a surface (a profile or nothing); {allowed}"),
        ));
    }
    match nx.checked_mul(ny) {
        Some(n) if n <= MAX_POINTS as u64 => Ok(n as usize),
        _ => Err(Error::input(file, field, format!("a map of {nx} × {ny} points is too large; {allowed}"))),
    }
}

/// Check a lateral spacing (metres) read from `field`.
pub fn check_spacing(file: &str, field: &str, d: f64) -> Result<f64> {
    let (lo, hi) = PIXEL_RANGE_M;
    if d.is_finite() && (lo..=hi).contains(&d) {
        Ok(d)
    } else {
        Err(Error::input(
            file,
            field,
            format!(
                "a point spacing of {} m is not a lateral calibration; allowed: {} m to {} m",
                number(d),
                number(lo),
                number(hi)
            ),
        ))
    }
}

impl HeightMap {
    /// A map from its parts, checked: the dimensions and spacings within the limits, `z` of nx·ny values, every
    /// valid height finite and within [`MAX_ABS_HEIGHT_M`], and at least one valid point. `field` names where
    /// the heights were read (for the messages about them).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        file: &str,
        format: Format,
        nx: usize,
        ny: usize,
        dx: f64,
        dy: f64,
        z: Vec<f64>,
        field: &str,
    ) -> Result<HeightMap> {
        HeightMap::with_height_note(file, format, nx, ny, dx, dy, z, field, "")
    }

    /// [`HeightMap::new`], with `note` added to the message refusing a height (what a format says of its
    /// heights' scale: X3P's increment and offset).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn with_height_note(
        file: &str,
        format: Format,
        nx: usize,
        ny: usize,
        dx: f64,
        dy: f64,
        z: Vec<f64>,
        field: &str,
        note: &str,
    ) -> Result<HeightMap> {
        let n = check_dimensions(file, field, nx as u64, ny as u64)?;
        check_spacing(file, field, dx)?;
        check_spacing(file, field, dy)?;
        if z.len() != n {
            return Err(Error::input(file, field, format!("{} heights for a map of {nx} × {ny} points", z.len())));
        }
        if let Some(k) = z.iter().position(|v| v.is_infinite() || v.abs() > MAX_ABS_HEIGHT_M) {
            return Err(Error::input(
                file,
                field,
                format!(
                    "the height at point ({}, {}) is {} m; allowed: |height| ≤ {} m (a larger value is a scale or unit \
                     error){note}",
                    k % nx,
                    k / nx,
                    number(z[k]),
                    number(MAX_ABS_HEIGHT_M)
                ),
            ));
        }
        if z.iter().all(|v| v.is_nan()) {
            return Err(Error::input(
                file,
                field,
                "every point of the map is invalid (masked or not measured): there is no surface to read",
            ));
        }
        Ok(HeightMap { file: file.to_string(), format, nx, ny, dx, dy, z })
    }

    /// The number of valid points.
    pub fn valid(&self) -> usize {
        self.z.iter().filter(|v| !v.is_nan()).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_are_checked_without_allocating() {
        assert!(check_dimensions("f", "/n", 1, 100).is_err());
        assert!(check_dimensions("f", "/n", u64::MAX, u64::MAX).unwrap_err().to_string().contains("too large"));
        assert_eq!(check_dimensions("f", "/n", 4096, 4096).unwrap(), MAX_POINTS);
        assert!(check_dimensions("f", "/n", 4097, 4096).is_err());
        assert!(check_spacing("f", "/dx", 0.0).is_err());
        assert!(check_spacing("f", "/dx", f64::NAN).is_err());
        assert!(check_spacing("f", "/dx", 2.0).is_err());
        assert!(check_spacing("f", "/dx", 1e-6).is_ok());
    }

    #[test]
    fn bad_heights_are_refused() {
        let map = |z: Vec<f64>| HeightMap::new("f", Format::Text, 2, 2, 1e-6, 1e-6, z, "/z");
        assert!(map(vec![0.0; 4]).is_ok());
        assert!(map(vec![0.0; 3]).is_err());
        assert!(map(vec![f64::NAN; 4]).unwrap_err().to_string().contains("every point"));
        assert!(map(vec![0.0, 0.0, 0.0, 2.0]).unwrap_err().to_string().contains("(1, 1)"));
        assert!(map(vec![0.0, 0.0, 0.0, f64::INFINITY]).is_err());
    }
}
