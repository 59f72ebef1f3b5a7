//! ISO 25178-71 surface data files (SDF), the text form (`aISO-1.0`) and the binary form (`bISO-1.0`):
//! a header of the grid (NumPoints per profile, NumProfiles), the spacings and the height scale in metres
//! (Xscale, Yscale, Zscale) and the data type, then the heights profile by profile
//! (docs/topography.md §ISO 25178-71 SDF).
use super::map::{check_dimensions, check_spacing, Format, HeightMap};
use crate::error::number;
use crate::{Error, Result};

/// The binary header: version (8), manufacturer (10), creation and modification dates (12 each), NumPoints and
/// NumProfiles (u16 each), Xscale, Yscale, Zscale, Zresolution (f64 each), Compression, DataType, CheckType
/// (u8 each): 81 bytes, little-endian.
pub(crate) const BINARY_HEADER: usize = 8 + 10 + 12 + 12 + 2 + 2 + 4 * 8 + 3;

/// The data types (the `DataType` field), with their size in bytes and the value that marks an invalid point
/// (as Gwyddion's reader of the format takes it: the type's extreme for 16- and 32-bit integers, NaN for
/// floating point, none for bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum DataType {
    U8,
    U16,
    U32,
    F32,
    I8,
    I16,
    I32,
    F64,
}

impl DataType {
    fn of(code: i64) -> Option<DataType> {
        use DataType::*;
        Some(match code {
            0 => U8,
            1 => U16,
            2 => U32,
            3 => F32,
            4 => I8,
            5 => I16,
            6 => I32,
            7 => F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        use DataType::*;
        match self {
            U8 | I8 => 1,
            U16 | I16 => 2,
            U32 | I32 | F32 => 4,
            F64 => 8,
        }
    }

    /// The invalid-point marker of an integer type.
    fn invalid(self) -> Option<f64> {
        use DataType::*;
        match self {
            U16 => Some(u16::MAX as f64),
            U32 => Some(u32::MAX as f64),
            I16 => Some(i16::MIN as f64),
            I32 => Some(i32::MIN as f64),
            _ => None,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, DataType::F32 | DataType::F64)
    }

    /// One little-endian value.
    fn decode(self, b: &[u8]) -> f64 {
        use DataType::*;
        match self {
            U8 => b[0] as f64,
            I8 => b[0] as i8 as f64,
            U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            F64 => f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]),
        }
    }
}

const TYPES: &str = "0 (u8), 1 (u16), 2 (u32), 3 (f32), 4 (i8), 5 (i16), 6 (i32), 7 (f64)";

/// What the header says.
struct Header {
    nx: u64,
    ny: u64,
    dx: f64,
    dy: f64,
    zscale: f64,
}

fn check_header(file: &str, h: &Header, compression: i64, check_type: i64) -> Result<usize> {
    let bad = |field: &str, m: String| Error::input(file, field, m);
    let n = check_dimensions(file, "NumPoints", h.nx, h.ny)?;
    check_spacing(file, "Xscale", h.dx)?;
    check_spacing(file, "Yscale", h.dy)?;
    if !(h.zscale.is_finite() && h.zscale > 0.0) {
        return Err(bad(
            "Zscale",
            format!("{} is not a height scale; allowed: a positive number (metres per unit)", number(h.zscale)),
        ));
    }
    if compression != 0 {
        return Err(bad("Compression", format!("{compression}: compressed data are not read; allowed: 0")));
    }
    if check_type != 0 {
        return Err(bad("CheckType", format!("{check_type}: checksummed data are not read; allowed: 0")));
    }
    Ok(n)
}

/// One height: the invalid marker becomes NaN, a non-finite float is refused, the rest scaled to metres.
fn height(file: &str, field: &str, ty: DataType, raw: f64, zscale: f64, k: usize, nx: usize) -> Result<f64> {
    if ty.invalid() == Some(raw) || (ty.is_float() && raw.is_nan()) {
        return Ok(f64::NAN);
    }
    if !raw.is_finite() {
        return Err(Error::input(file, field, format!("the height at point ({}, {}) is infinite", k % nx, k / nx)));
    }
    Ok(raw * zscale)
}

/// Read an SDF file, text or binary by its first byte (`a` or `b`).
pub fn read(bytes: &[u8], file: &str) -> Result<HeightMap> {
    match bytes.first() {
        Some(b'b') => read_binary(bytes, file),
        Some(b'a') => {
            let text = std::str::from_utf8(bytes).map_err(|e| {
                Error::input(
                    file,
                    "",
                    format!("a text SDF file that is not UTF-8 (invalid byte at offset {})", e.valid_up_to()),
                )
            })?;
            read_text(text, file)
        }
        _ => Err(Error::input(file, "", "not an SDF file: it begins with neither `a` (text) nor `b` (binary)")),
    }
}

fn read_binary(bytes: &[u8], file: &str) -> Result<HeightMap> {
    if bytes.len() < BINARY_HEADER {
        return Err(Error::input(
            file,
            "",
            format!(
                "{} bytes, shorter than the {BINARY_HEADER}-byte header of a binary SDF file (a truncated file)",
                bytes.len()
            ),
        ));
    }
    let u16_at = |i: usize| u16::from_le_bytes([bytes[i], bytes[i + 1]]) as u64;
    let f64_at = |i: usize| f64::from_le_bytes(bytes[i..i + 8].try_into().unwrap_or([0; 8]));
    let p = 8 + 10 + 12 + 12;
    let code = bytes[p + 4 + 32 + 1] as i64;
    let ty = DataType::of(code)
        .ok_or_else(|| Error::input(file, "DataType", format!("{code} is not a data type; allowed: {TYPES}")))?;
    let h = Header { nx: u16_at(p), ny: u16_at(p + 2), dx: f64_at(p + 4), dy: f64_at(p + 12), zscale: f64_at(p + 20) };
    let n = check_header(file, &h, bytes[p + 4 + 32] as i64, bytes[p + 4 + 32 + 2] as i64)?;
    let need = n * ty.size();
    let mut data = &bytes[BINARY_HEADER..];
    // Some exporters (Olympus) write 8 more header bytes; Gwyddion recognises them by the file being exactly 8
    // bytes too long, and so does this reader.
    if data.len() == need + 8 {
        data = &data[8..];
    }
    if data.len() < need {
        return Err(Error::input(
            file,
            "NumPoints",
            format!(
                "{} bytes of data, but NumPoints × NumProfiles = {} × {} values of {} bytes need {need} (a truncated \
                 file, or dimensions that do not match the data)",
                data.len(),
                h.nx,
                h.ny,
                ty.size()
            ),
        ));
    }
    let nx = h.nx as usize;
    let z = data[..need]
        .chunks_exact(ty.size())
        .enumerate()
        .map(|(k, c)| height(file, "data", ty, ty.decode(c), h.zscale, k, nx))
        .collect::<Result<Vec<f64>>>()?;
    HeightMap::new(file, Format::SdfBinary, nx, h.ny as usize, h.dx, h.dy, z, "data")
}

fn read_text(text: &str, file: &str) -> Result<HeightMap> {
    let mut lines = text.lines().enumerate();
    let mut keys: Vec<(String, String, usize)> = Vec::new();
    let mut data_start = None;
    lines.next();
    for (i, line) in lines.by_ref() {
        let t = line.trim();
        if t.starts_with('*') {
            data_start = Some(i + 1);
            break;
        }
        if t.is_empty() || t.starts_with(';') {
            continue;
        }
        let (k, v) = match t.split_once('=') {
            Some((k, v)) => (k.trim(), v.trim()),
            None => t.split_once(char::is_whitespace).map(|(k, v)| (k, v.trim())).unwrap_or((t, "")),
        };
        keys.push((k.to_ascii_lowercase(), v.to_string(), i + 1));
    }
    let Some(data_line) = data_start else {
        return Err(Error::input(file, "", "no `*` line ends the header (a truncated file)"));
    };
    let get = |k: &str| keys.iter().find(|(key, _, _)| key == &k.to_ascii_lowercase()).map(|(_, v, _)| v.as_str());
    let missing = |k: &str| Error::input(file, k, "missing from the header");
    let int = |k: &str| -> Result<i64> {
        let v = get(k).ok_or_else(|| missing(k))?;
        v.parse::<i64>().map_err(|_| Error::input(file, k, format!("`{v}` is not a whole number")))
    };
    let real = |k: &str| -> Result<f64> {
        let v = get(k).ok_or_else(|| missing(k))?;
        v.parse::<f64>().map_err(|_| Error::input(file, k, format!("`{v}` is not a number")))
    };
    let (nx, ny) = (int("NumPoints")?, int("NumProfiles")?);
    let code = int("DataType")?;
    let ty = DataType::of(code)
        .ok_or_else(|| Error::input(file, "DataType", format!("{code} is not a data type; allowed: {TYPES}")))?;
    let h = Header {
        nx: nx.max(0) as u64,
        ny: ny.max(0) as u64,
        dx: real("Xscale")?,
        dy: real("Yscale")?,
        zscale: real("Zscale")?,
    };
    let opt = |k: &str| if get(k).is_some() { int(k) } else { Ok(0) };
    let n = check_header(file, &h, opt("Compression")?, opt("CheckType")?)?;
    let nx = h.nx as usize;
    let mut z = Vec::with_capacity(n);
    'lines: for (i, line) in text.lines().enumerate().skip(data_line) {
        for token in line.split_whitespace() {
            if token.starts_with('*') {
                break 'lines;
            }
            let field = format!("line {}", i + 1);
            if z.len() == n {
                return Err(Error::input(
                    file,
                    &field,
                    format!("more than NumPoints × NumProfiles = {} × {} values before the closing `*`", h.nx, h.ny),
                ));
            }
            let raw: f64 =
                token.parse().map_err(|_| Error::input(file, &field, format!("`{token}` is not a number")))?;
            z.push(height(file, &field, ty, raw, h.zscale, z.len(), nx)?);
        }
    }
    if z.len() < n {
        return Err(Error::input(
            file,
            "NumPoints",
            format!(
                "{} values, but NumPoints × NumProfiles = {} × {} = {n} (a truncated file, or dimensions that do not \
                 match the data)",
                z.len(),
                h.nx,
                h.ny
            ),
        ));
    }
    HeightMap::new(file, Format::SdfText, nx, h.ny as usize, h.dx, h.dy, z, "data")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(nx: u32, ny: u32, ty: u32, data: &str) -> String {
        format!(
            "aISO-1.0\nManufacID   = test\nCreateDate  = 010120260000\nModDate     = 010120260000\nNumPoints   = {nx}\n\
             NumProfiles = {ny}\nXscale      = 1e-6\nYscale      = 2e-6\nZscale      = 1e-9\nZresolution = -1\n\
             Compression = 0\nDataType    = {ty}\nCheckType   = 0\n*\n{data}\n*\n"
        )
    }

    fn binary(nx: u16, ny: u16, ty: u8, data: &[u8]) -> Vec<u8> {
        let mut b = b"bISO-1.0".to_vec();
        b.extend_from_slice(&[b' '; 10 + 12 + 12]);
        b.extend_from_slice(&nx.to_le_bytes());
        b.extend_from_slice(&ny.to_le_bytes());
        for x in [1e-6f64, 2e-6, 1e-9, -1.0] {
            b.extend_from_slice(&x.to_le_bytes());
        }
        b.extend_from_slice(&[0, ty, 0]);
        assert_eq!(b.len(), BINARY_HEADER);
        b.extend_from_slice(data);
        b
    }

    #[test]
    fn text_files_read_with_their_scales_and_invalid_points() {
        let m = read(text(3, 2, 5, "1 2 3\n4 -32768 6").as_bytes(), "t.sdf").unwrap();
        assert_eq!((m.nx, m.ny, m.dx, m.dy), (3, 2, 1e-6, 2e-6));
        assert_eq!(m.z[0], 1e-9);
        assert!(m.z[4].is_nan() && m.valid() == 5);
        let m = read(text(2, 2, 7, "0.5 NaN 1.5 2.5").as_bytes(), "t.sdf").unwrap();
        assert!(m.z[1].is_nan() && (m.z[3] - 2.5e-9).abs() < 1e-24);
    }

    #[test]
    fn binary_files_read_with_their_scales_and_invalid_points() {
        let data: Vec<u8> = [1i16, 2, i16::MIN, 4].iter().flat_map(|v| v.to_le_bytes()).collect();
        let m = read(&binary(2, 2, 5, &data), "t.sdf").unwrap();
        assert_eq!((m.nx, m.ny, m.dx, m.dy), (2, 2, 1e-6, 2e-6));
        assert_eq!(m.z[3], 4e-9);
        assert!(m.z[2].is_nan());
        let data: Vec<u8> = [1.0f64, 2.0, 3.0, 4.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        assert_eq!(read(&binary(2, 2, 7, &data), "t.sdf").unwrap().z[1], 2e-9);
    }

    #[test]
    fn bad_files_name_the_field() {
        let e = |b: &[u8]| read(b, "t.sdf").unwrap_err().to_string();
        assert!(e(text(3, 2, 5, "1 2 3 4 5").as_bytes()).contains("field `NumPoints`"));
        assert!(e(text(3, 2, 5, "1 2 3 4 5 6 7").as_bytes()).contains("field `line 15`"));
        assert!(e(text(3, 2, 9, "1 2 3 4 5 6").as_bytes()).contains("field `DataType`"));
        assert!(e(text(3, 2, 5, "1 2 x 4 5 6").as_bytes()).contains("`x` is not a number"));
        assert!(e(text(2, 2, 7, "1 inf 1 1").as_bytes()).contains("infinite"));
        assert!(e(text(2, 2, 5, "-32768 -32768 -32768 -32768").as_bytes()).contains("every point"));
        assert!(
            e(text(3, 2, 5, "1 2 3 4 5 6").replace("Xscale      = 1e-6\n", "").as_bytes()).contains("field `Xscale`")
        );
        assert!(e(text(3, 2, 5, "1 2 3 4 5 6").replace("Yscale      = 2e-6", "Yscale = 0").as_bytes())
            .contains("field `Yscale`"));
        assert!(e(&binary(2, 2, 5, &[0; 6])).contains("truncated"));
        assert!(e(&binary(2, 2, 5, &[0; 6])[..40]).contains("header"));
        assert!(e(&binary(1, 2, 5, &[0; 4])).contains("not a surface"));
    }
}
