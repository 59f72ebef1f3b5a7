//! Plain text and CSV height matrices: one row of the map per line (y = j·dy for the j-th row, x = i·dx for
//! the i-th value), the values separated by commas, semicolons, tabs or spaces, lines beginning with `#`
//! ignored. Such a file says nothing of its calibration, so the caller gives the spacing and the unit of the
//! heights ([`Calibration`]); it has no invalid-point marker, so every value must be a finite number
//! (docs/topography.md §Plain text matrices).
use super::map::{check_spacing, Format, HeightMap, MAX_POINTS, MIN_SIDE};
use crate::error::{number, Words};
use crate::{Error, Result};

/// The calibration of a plain matrix, given by the caller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Calibration {
    /// Spacing of the values along a row (x) and between rows (y), metres.
    pub dx: f64,
    pub dy: f64,
    /// The heights' unit, metres.
    pub z_unit: f64,
}

/// Read a plain matrix with its calibration (`None`: refused, naming the arguments that give it).
pub fn read(text: &str, file: &str, calibration: Option<Calibration>) -> Result<HeightMap> {
    let Some(cal) = calibration else {
        return Err(Error::input(
            file,
            "",
            Words::from("a plain height matrix has no lateral calibration: give the spacing of its points (")
                .and_argument("pixel_size")
                .and(") and the unit of its heights (")
                .and_argument("height_unit")
                .and(")"),
        ));
    };
    check_spacing(file, "pixel size", cal.dx)?;
    check_spacing(file, "pixel size", cal.dy)?;
    if !(cal.z_unit.is_finite() && cal.z_unit > 0.0) {
        return Err(Error::input(file, "height unit", format!("{} m is not a unit", number(cal.z_unit))));
    }
    let mut z: Vec<f64> = Vec::new();
    let mut nx = 0usize;
    let mut ny = 0usize;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let field = format!("line {}", i + 1);
        let start = z.len();
        for (c, token) in
            t.split(|ch: char| ch == ',' || ch == ';' || ch.is_whitespace()).filter(|s| !s.is_empty()).enumerate()
        {
            let v: f64 = token
                .parse()
                .map_err(|_| Error::input(file, &field, format!("value {} is `{token}`, not a number", c + 1)))?;
            if !v.is_finite() {
                return Err(Error::input(
                    file,
                    &field,
                    format!(
                        "value {} is `{token}`: a plain matrix has no invalid-point marker, so every height must be a \
                         finite number (a map with invalid points: X3P, SDF)",
                        c + 1
                    ),
                ));
            }
            if z.len() >= MAX_POINTS {
                return Err(Error::input(
                    file,
                    &field,
                    format!("more than {MAX_POINTS} values, the most a map may have"),
                ));
            }
            z.push(v * cal.z_unit);
        }
        let row = z.len() - start;
        if ny == 0 {
            nx = row;
        } else if row != nx {
            return Err(Error::input(
                file,
                &field,
                format!("{row} values, but the first row has {nx}: every row of a height matrix has the same length"),
            ));
        }
        ny += 1;
    }
    if nx < MIN_SIDE || ny < MIN_SIDE {
        return Err(Error::input(
            file,
            "",
            format!("{nx} × {ny} values is not a surface; allowed: at least {MIN_SIDE} rows of {MIN_SIDE} values"),
        ));
    }
    HeightMap::new(file, Format::Text, nx, ny, cal.dx, cal.dy, z, "heights")
}

#[cfg(test)]
mod tests {
    use super::*;

    const CAL: Option<Calibration> = Some(Calibration { dx: 1e-6, dy: 2e-6, z_unit: 1e-9 });

    #[test]
    fn csv_and_whitespace_matrices_read() {
        let m = read("# a comment\n1, 2, 3\n4;5;6\n\n7\t8 9\n", "t.csv", CAL).unwrap();
        assert_eq!((m.nx, m.ny, m.dx, m.dy), (3, 3, 1e-6, 2e-6));
        assert_eq!(m.z[8], 9.0 * 1e-9);
    }

    #[test]
    fn bad_matrices_name_the_line() {
        let e = |t: &str, c| read(t, "t.csv", c).unwrap_err().to_string();
        assert!(e("1 2\n3 4\n", None).contains("no lateral calibration"));
        assert!(e("1 2 3\n4 5\n", CAL).contains("field `line 2`"));
        assert!(e("1 2\n3 NaN\n", CAL).contains("no invalid-point marker"));
        assert!(e("1 2\n3 x\n", CAL).contains("`x`, not a number"));
        assert!(e("1 2 3\n", CAL).contains("not a surface"));
        assert!(e("", CAL).contains("not a surface"));
        let huge = Some(Calibration { dx: 1e-6, dy: 1e-6, z_unit: 1.0 });
        assert!(e("1 2\n3 4\n", huge).contains("|height|"));
    }
}
