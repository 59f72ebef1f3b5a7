//! Digital Surf `.sur` (the binary format of MountainsMap): a 512-byte little-endian header beginning
//! `DIGITAL SURF`, a comment zone and a private zone of the sizes it gives, then Nx × Ny signed 16- or 32-bit
//! integers, line by line, each height z = (value·Δz + Z offset) in the Z spacing's unit; a non-measured point
//! is the value zmin − 2 when the header says the object has them (docs/topography.md §Digital Surf SUR; the
//! layout as Gwyddion's reader `surffile.c` and surfalize's `sur.py` take it).
use super::map::{check_dimensions, check_spacing, Format, HeightMap};
use super::units;
use crate::error::number;
use crate::{Error, Result};

/// The signature of an uncompressed object.
pub(crate) const MAGIC: &[u8] = b"DIGITAL SURF";

/// The signature of a compressed object (MountainsMap 7 and later), which is not read.
pub(crate) const MAGIC_COMPRESSED: &[u8] = b"DSCOMPRESSED";

/// The header's size, bytes.
pub(crate) const HEADER: usize = 512;

/// The object type of a surface (3 is a binary image, 4 and 5 series, 6 and later intensity, spectral and RGB
/// objects).
const SURFACE: i16 = 2;

/// The object type of a profile.
const PROFILE: i16 = 1;

fn i16_at(b: &[u8], at: usize) -> i16 {
    i16::from_le_bytes([b[at], b[at + 1]])
}

fn i32_at(b: &[u8], at: usize) -> i32 {
    i32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn f32_at(b: &[u8], at: usize) -> f64 {
    f32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]) as f64
}

/// A 16-byte unit name: Latin-1 (MountainsMap writes `µ` as the byte 0xB5), up to the first NUL, trimmed.
fn text_at(b: &[u8], at: usize, len: usize) -> String {
    b[at..at + len].iter().take_while(|&&c| c != 0).map(|&c| c as char).collect::<String>().trim().to_string()
}

/// The header's fields glossmeter reads.
struct Header {
    points_size: i16,
    zmin: i32,
    nx: i32,
    ny: i32,
    dx: f64,
    dy: f64,
    dz: f64,
    z_offset: f64,
    non_measured: bool,
    data_at: usize,
}

/// Read and check the header (the whole file is at least [`HEADER`] bytes).
fn header(b: &[u8], file: &str) -> Result<Header> {
    let bad = |field: &str, m: String| Error::input(file, field, m);
    let format = i16_at(b, 12);
    if format != 0 {
        return Err(bad(
            "format",
            format!(
                "{format} is not the PC (little-endian) layout; allowed: 0 (257, the Macintosh layout, is not read)"
            ),
        ));
    }
    let objects = i16_at(b, 14);
    if objects > 1 {
        return Err(bad(
            "number of objects",
            format!("{objects} objects (a multilayer or series file); allowed: one surface"),
        ));
    }
    let kind = i16_at(b, 18);
    // Gwyddion's export writes a surface with the profile's type (surfalize reads it so): a "profile" of at
    // least two lines is read as the surface it is; one of a single line is refused with the dimensions.
    if kind != SURFACE && kind != PROFILE {
        return Err(bad(
            "object type",
            format!(
                "{kind} is not a surface; allowed: {SURFACE} (or {PROFILE} with at least 2 lines; series and images \
                 are not read)"
            ),
        ));
    }
    let points_size = i16_at(b, 98);
    if points_size != 16 && points_size != 32 {
        return Err(bad("point size", format!("{points_size} bits a point; allowed: 16 or 32")));
    }
    for (at, field) in [(276, "X unit ratio"), (280, "Y unit ratio"), (284, "Z unit ratio")] {
        let r = f32_at(b, at);
        if r != 1.0 {
            return Err(bad(field, format!("{}; allowed: 1 (a scaled axis is not read)", number(r))));
        }
    }
    let inversion = i16_at(b, 290);
    if inversion != 0 {
        return Err(bad("inversion", format!("{inversion}; allowed: 0 (an inverted or flipped object is not read)")));
    }
    let unit = |at: usize, field: &str| -> Result<f64> {
        let u = text_at(b, at, 16);
        units::metres_per(&u)
            .ok_or_else(|| bad(field, format!("unknown length unit `{u}`; allowed: {}", units::allowed())))
    };
    let (ux, uy, uz) = (unit(180, "X step unit")?, unit(196, "Y step unit")?, unit(212, "Z step unit")?);
    let step = |at: usize, u: f64, field: &str| -> Result<f64> {
        let d = f32_at(b, at);
        if !(d.is_finite() && d > 0.0) {
            return Err(bad(field, format!("{} is not a step; allowed: a positive number", number(d))));
        }
        Ok(d * u)
    };
    let z_offset = f32_at(b, 474);
    if !z_offset.is_finite() {
        return Err(bad("Z offset", format!("{} is not a height; allowed: a finite number", number(z_offset))));
    }
    let (comment, private) = (i16_at(b, 334), i16_at(b, 336));
    for (v, field) in [(comment, "comment size"), (private, "private zone size")] {
        if v < 0 {
            return Err(bad(field, format!("{v} bytes; allowed: 0 to 32767")));
        }
    }
    Ok(Header {
        points_size,
        zmin: i32_at(b, 100),
        nx: i32_at(b, 108),
        ny: i32_at(b, 112),
        dx: step(120, ux, "X step")?,
        dy: step(124, uy, "Y step")?,
        dz: step(128, uz, "Z step")?,
        z_offset: z_offset * uz,
        non_measured: i16_at(b, 86) == 1,
        data_at: HEADER + comment as usize + private as usize,
    })
}

/// Read a `.sur` file's bytes; `file` names it in messages.
pub fn read(bytes: &[u8], file: &str) -> Result<HeightMap> {
    let bad = |field: &str, m: String| Error::input(file, field, m);
    if bytes.starts_with(MAGIC_COMPRESSED) {
        return Err(bad(
            "signature",
            "a compressed Digital Surf object (`DSCOMPRESSED`) is not read; save it uncompressed (`DIGITAL SURF`)"
                .into(),
        ));
    }
    if !bytes.starts_with(MAGIC) {
        return Err(bad("signature", "not a Digital Surf file: it does not begin `DIGITAL SURF`".into()));
    }
    if bytes.len() < HEADER {
        return Err(bad(
            "header",
            format!("{} bytes, shorter than the 512-byte header (a truncated file)", bytes.len()),
        ));
    }
    let h = header(bytes, file)?;
    let field = "number of points per line";
    if h.nx < 0 || h.ny < 0 {
        return Err(bad(field, format!("{} × {} points; allowed: positive counts", h.nx, h.ny)));
    }
    let (nx, ny) = (h.nx as u64, h.ny as u64);
    let n = check_dimensions(file, field, nx, ny)?;
    let dx = check_spacing(file, "X step", h.dx)?;
    let dy = check_spacing(file, "Y step", h.dy)?;
    let size = h.points_size as usize / 8;
    let need = n * size;
    let data = bytes.get(h.data_at..).unwrap_or(&[]);
    if data.len() < need {
        return Err(bad(
            "data",
            format!(
                "{} bytes of data after the header and its comment and private zones, but {nx} × {ny} points of \
                 {} bits need {need} (a truncated file)",
                data.len(),
                h.points_size
            ),
        ));
    }
    let invalid = h.non_measured.then(|| h.zmin as i64 - 2);
    let z: Vec<f64> = data[..need]
        .chunks_exact(size)
        .map(|c| {
            let v = if size == 2 { i16::from_le_bytes([c[0], c[1]]) as i64 } else { i32_at(c, 0) as i64 };
            if Some(v) == invalid {
                f64::NAN
            } else {
                v as f64 * h.dz + h.z_offset
            }
        })
        .collect();
    HeightMap::new(file, Format::Sur, nx as usize, ny as usize, dx, dy, z, "data")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `.sur` file of these heights (16-bit), written by hand as the format says: steps in µm, Z in nm.
    fn sur(nx: i32, ny: i32, z: &[i16], zmin: i32, non_measured: bool) -> Vec<u8> {
        let mut b = vec![0u8; HEADER];
        b[..12].copy_from_slice(MAGIC);
        b[14..16].copy_from_slice(&1i16.to_le_bytes());
        b[16..18].copy_from_slice(&1i16.to_le_bytes());
        b[18..20].copy_from_slice(&SURFACE.to_le_bytes());
        b[86..88].copy_from_slice(&(non_measured as i16).to_le_bytes());
        b[98..100].copy_from_slice(&16i16.to_le_bytes());
        b[100..104].copy_from_slice(&zmin.to_le_bytes());
        b[108..112].copy_from_slice(&nx.to_le_bytes());
        b[112..116].copy_from_slice(&ny.to_le_bytes());
        b[116..120].copy_from_slice(&(nx * ny).to_le_bytes());
        for (at, v) in [(120, 2.0f32), (124, 3.0), (128, 1.0), (276, 1.0), (280, 1.0), (284, 1.0)] {
            b[at..at + 4].copy_from_slice(&v.to_le_bytes());
        }
        for (at, u) in [(180, &b"\xb5m"[..]), (196, b"um"), (212, b"nm")] {
            b[at..at + u.len()].copy_from_slice(u);
        }
        b[334..336].copy_from_slice(&3i16.to_le_bytes());
        b.extend_from_slice(b"abc");
        for v in z {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b
    }

    #[test]
    fn a_hand_written_file_reads_with_its_units_and_mask() {
        let m = read(&sur(3, 2, &[1, 2, -5, 4, 5, 6], -3, true), "t.sur").unwrap();
        assert_eq!((m.nx, m.ny, m.format), (3, 2, Format::Sur));
        assert!((m.dx - 2e-6).abs() < 1e-20 && (m.dy - 3e-6).abs() < 1e-20);
        assert!((m.z[5] - 6e-9).abs() < 1e-22);
        assert!(m.z[2].is_nan() && m.valid() == 5);
        // Without the non-measured flag, zmin − 2 is a height like any other.
        assert!((read(&sur(3, 2, &[1, 2, -5, 4, 5, 6], -3, false), "t.sur").unwrap().z[2] + 5e-9).abs() < 1e-22);
    }

    #[test]
    fn bad_files_name_the_field() {
        let ok = sur(2, 2, &[0; 4], 0, false);
        let e = |b: &[u8]| read(b, "t.sur").unwrap_err().to_string();
        assert!(e(&ok[..ok.len() - 1]).contains("field `data`"));
        assert!(e(&ok[..300]).contains("field `header`"));
        assert!(e(b"DSCOMPRESSED").contains("compressed"));
        let set = |at: usize, v: &[u8]| {
            let mut b = ok.clone();
            b[at..at + v.len()].copy_from_slice(v);
            b
        };
        assert!(e(&set(12, &257i16.to_le_bytes())).contains("field `format`"));
        assert!(e(&set(18, &3i16.to_le_bytes())).contains("field `object type`"));
        assert!(read(&set(18, &1i16.to_le_bytes()), "t.sur").is_ok());
        let mut profile = sur(2, 1, &[0; 2], 0, false);
        profile[18..20].copy_from_slice(&1i16.to_le_bytes());
        assert!(e(&profile).contains("2 × 1 points is not a surface"));
        assert!(e(&set(98, &8i16.to_le_bytes())).contains("field `point size`"));
        assert!(e(&set(108, &(-2i32).to_le_bytes())).contains("field `number of points per line`"));
        assert!(e(&set(108, &i32::MAX.to_le_bytes())).contains("too large"));
        assert!(e(&set(120, &0f32.to_le_bytes())).contains("field `X step`"));
        assert!(e(&set(124, &f32::NAN.to_le_bytes())).contains("field `Y step`"));
        assert!(e(&set(212, b"in")).contains("field `Z step unit`"));
        assert!(e(&set(284, &2f32.to_le_bytes())).contains("field `Z unit ratio`"));
        assert!(e(&set(336, &(-1i16).to_le_bytes())).contains("field `private zone size`"));
        assert!(e(&set(336, &i16::MAX.to_le_bytes())).contains("truncated"));
        assert!(e(&set(474, &f32::INFINITY.to_le_bytes())).contains("field `Z offset`"));
    }
}
