//! Gwyddion Simple Field (`.gsf`): a text header of `Key = Value` lines after the magic line
//! `Gwyddion Simple Field 1.0`, NUL padding to a multiple of 4 bytes, then XRes × YRes little-endian 32-bit
//! floats, row by row (docs/topography.md §Gwyddion GSF; the format: the Gwyddion user guide, "GSF – Gwyddion
//! Simple Field").
use super::map::{check_dimensions, check_spacing, Format, HeightMap};
use super::units;
use crate::error::number;
use crate::{Error, Result};

/// The magic line.
pub(crate) const MAGIC: &[u8] = b"Gwyddion Simple Field 1.0\n";

/// The longest header read: 64 KiB (a real header is a few hundred bytes).
const MAX_HEADER: usize = 64 * 1024;

/// Read a GSF file's bytes; `file` names it in messages.
pub fn read(bytes: &[u8], file: &str) -> Result<HeightMap> {
    let bad = |field: &str, m: String| Error::input(file, field, m);
    if !bytes.starts_with(MAGIC) {
        return Err(bad("", "not a Gwyddion Simple Field: the first line is not `Gwyddion Simple Field 1.0`".into()));
    }
    let end = bytes.iter().take(MAX_HEADER + 1).position(|&b| b == 0).ok_or_else(|| {
        bad("", format!("no NUL byte ends the header within {MAX_HEADER} bytes (a truncated or damaged file)"))
    })?;
    let header =
        std::str::from_utf8(&bytes[MAGIC.len()..end]).map_err(|_| bad("", "the header is not UTF-8 text".into()))?;
    let mut keys: Vec<(&str, &str)> = Vec::new();
    for (i, line) in header.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let (k, v) = line
            .split_once('=')
            .ok_or_else(|| bad(&format!("header line {}", i + 2), format!("`{line}` is not a `Key = Value` line")))?;
        keys.push((k.trim(), v.trim()));
    }
    let get = |k: &str| keys.iter().find(|(key, _)| *key == k).map(|(_, v)| *v);
    let int = |k: &str| -> Result<u64> {
        let v = get(k).ok_or_else(|| bad(k, "missing: the header must give XRes and YRes".into()))?;
        v.parse::<u64>().map_err(|_| bad(k, format!("`{v}` is not a whole number of points")))
    };
    let (nx, ny) = (int("XRes")?, int("YRes")?);
    let n = check_dimensions(file, "XRes", nx, ny)?;
    let xy_unit = unit(file, "XYUnits", get("XYUnits"))?;
    let z_unit = unit(file, "ZUnits", get("ZUnits"))?;
    let real = |k: &str| -> Result<f64> {
        let v = get(k).ok_or_else(|| {
            bad(k, "missing: without XReal and YReal the map has no lateral calibration (the format's default, 1, has no unit)".into())
        })?;
        let x: f64 = v.parse().map_err(|_| bad(k, format!("`{v}` is not a number")))?;
        if !(x.is_finite() && x > 0.0) {
            return Err(bad(k, format!("{} is not a width; allowed: a positive number", number(x))));
        }
        Ok(x * xy_unit)
    };
    let dx = check_spacing(file, "XReal", real("XReal")? / nx as f64)?;
    let dy = check_spacing(file, "YReal", real("YReal")? / ny as f64)?;
    // The header and its padding are a multiple of 4 bytes, with at least one NUL.
    let data_at = (end / 4 + 1) * 4;
    let need = n * 4;
    let data = bytes.get(data_at..).unwrap_or(&[]);
    if data.len() != need {
        return Err(bad(
            "data",
            format!(
                "{} bytes of data after the header, but XRes × YRes = {nx} × {ny} floats need {need}{}",
                data.len(),
                if data.len() < need { " (a truncated file)" } else { "" }
            ),
        ));
    }
    let mut z = Vec::with_capacity(n);
    for (k, c) in data.chunks_exact(4).enumerate() {
        let v = f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64;
        if !v.is_finite() {
            return Err(bad(
                "data",
                format!(
                    "the height at point ({}, {}) is {}; the format has no invalid-point marker, so every height must \
                     be a finite number",
                    k % nx as usize,
                    k / nx as usize,
                    if v.is_nan() { "NaN" } else { "infinite" }
                ),
            ));
        }
        z.push(v * z_unit);
    }
    HeightMap::new(file, Format::Gsf, nx as usize, ny as usize, dx, dy, z, "data")
}

/// A unit key's value in metres; a map without its units is refused rather than guessed.
fn unit(file: &str, key: &str, v: Option<&str>) -> Result<f64> {
    let v = v.ok_or_else(|| {
        Error::input(file, key, format!("missing: the unit of the map's lengths; allowed: {}", units::allowed()))
    })?;
    units::metres_per(v)
        .ok_or_else(|| Error::input(file, key, format!("unknown length unit `{v}`; allowed: {}", units::allowed())))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A GSF file of these header lines and heights, written by hand as the format says.
    pub(crate) fn gsf(header: &str, z: &[f32]) -> Vec<u8> {
        let mut b = MAGIC.to_vec();
        b.extend_from_slice(header.as_bytes());
        let pad = 4 - b.len() % 4;
        b.extend(std::iter::repeat_n(0u8, pad));
        for v in z {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b
    }

    #[test]
    fn a_hand_written_file_reads_with_its_units() {
        let h = "XRes = 3\nYRes = 2\nXReal = 6\nYReal = 4\nXYUnits = um\nZUnits = nm\n";
        let m = read(&gsf(h, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]), "t.gsf").unwrap();
        assert_eq!((m.nx, m.ny), (3, 2));
        assert!((m.dx - 2e-6).abs() < 1e-20 && (m.dy - 2e-6).abs() < 1e-20);
        assert!((m.z[5] - 6e-9).abs() < 1e-22);
    }

    #[test]
    fn bad_files_name_the_field() {
        let ok = "XRes = 2\nYRes = 2\nXReal = 2\nYReal = 2\nXYUnits = um\nZUnits = um\n";
        let e = |b: Vec<u8>| read(&b, "t.gsf").unwrap_err().to_string();
        assert!(e(gsf(ok, &[0.0; 3])).contains("field `data`"));
        assert!(e(gsf(&ok.replace("XReal = 2\n", ""), &[0.0; 4])).contains("field `XReal`"));
        assert!(e(gsf(&ok.replace("ZUnits = um\n", ""), &[0.0; 4])).contains("field `ZUnits`"));
        assert!(e(gsf(&ok.replace("XRes = 2", "XRes = 70000").replace("YRes = 2", "YRes = 70000"), &[0.0; 4]))
            .contains("too large"));
        assert!(e(gsf(ok, &[0.0, f32::NAN, 0.0, 0.0])).contains("NaN"));
        assert!(e(b"Gwyddion Simple Field 1.0\nXRes = 2".to_vec()).contains("NUL"));
    }
}
