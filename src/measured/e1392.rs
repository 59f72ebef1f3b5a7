//! ASTM E1392-style text tables of BRDF measurements ("Standard Practice for Angle Resolved Optical Scatter
//! Measurements on Specular or Diffuse Surfaces", superseded by ASTM E2387; the layout Cornell's Program of
//! Computer Graphics used for its painted-surface measurements). The standard's text is paywalled and was not
//! read: this reader accepts the columnar layout such files share, stated here so that a file can be
//! checked against it.
//!
//! * Header lines `KEY: value` (or `KEY value`) before the data, kept only for messages; lines starting with
//!   `#` or `;` are comments.
//! * One column line naming, in any order, `theta_i`, `phi_i`, `theta_s`, `phi_s` (degrees) and one value
//!   column: `BRDF` (f_r, sr⁻¹) or `CCBRDF` (the cosine-corrected BRDF f_r·cos θs, sr⁻¹). Case-insensitive;
//!   whitespace- or comma-separated; no other columns.
//! * Data rows of numbers under those columns.
//!
//! Angles follow Nicodemus et al. (NBS Monograph 160, 1977): both directions point away from the surface,
//! so the specular direction is φs = φi + 180°. Only rows in the plane of incidence are used: φs − φi ≡ 180°
//! gives θo = +θs (the specular side), φs − φi ≡ 0° gives θo = −θs, θs = 0 is in the plane. The table is then
//! the in-plane table of `inplane.rs`, with its interpolation and its explicit isotropy assumption;
//! out-of-plane rows are counted and named in the description, not interpolated.
use super::inplane::{InPlaneBrdf, Point, Quantity};
use crate::{Error, Result};
use std::path::Path;

/// Tolerance on the azimuth difference for a row to count as in the plane of incidence (degrees).
const IN_PLANE_TOL_DEG: f64 = 1e-6;

fn split(line: &str) -> Vec<&str> {
    line.split(|c: char| c == ',' || c.is_whitespace()).filter(|s| !s.is_empty()).collect()
}

/// The column line: the names, the indices of θi, φi, θs, φs, the value column, what it holds, its line.
struct Columns {
    names: Vec<String>,
    idx: [usize; 4],
    value: usize,
    quantity: Quantity,
    line: usize,
}

/// Parse E1392-style text; `file` names it in messages.
pub fn parse(text: &str, file: &str) -> Result<InPlaneBrdf> {
    // A UTF-8 byte-order mark is no part of the first line.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let names = ["theta_i", "phi_i", "theta_s", "phi_s"];
    let mut cols: Option<Columns> = None;
    let mut points = Vec::new();
    let mut unused = 0;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        let n = i + 1;
        if line.is_empty() || line.starts_with('#') || line.starts_with(';') {
            continue;
        }
        let Some(Columns { names: header, idx, value: cv, line: hline, .. }) = &cols else {
            let lower: Vec<String> = split(line).iter().map(|s| s.to_ascii_lowercase()).collect();
            if lower.iter().any(|c| c == "theta_i") {
                let find = |name: &str| lower.iter().position(|c| c == name);
                for c in &lower {
                    if !names.contains(&c.as_str()) && c != "brdf" && c != "ccbrdf" {
                        return Err(Error::input(
                            file,
                            format!("line {n}"),
                            format!(
                                "unknown column {c:?}; allowed: theta_i, phi_i, theta_s, phi_s and one of BRDF, CCBRDF"
                            ),
                        ));
                    }
                }
                let mut idx = [0; 4];
                for (k, name) in names.iter().enumerate() {
                    idx[k] = find(name).ok_or_else(|| {
                        Error::input(file, format!("line {n}"), format!("the column line lacks `{name}`"))
                    })?;
                }
                let (cv, q) = match (find("brdf"), find("ccbrdf")) {
                    (Some(c), None) => (c, Quantity::Brdf),
                    (None, Some(c)) => (c, Quantity::BrdfCos),
                    _ => {
                        return Err(Error::input(
                            file,
                            format!("line {n}"),
                            "exactly one value column is needed: BRDF (f_r) or CCBRDF (f_r·cos θs)",
                        ))
                    }
                };
                cols = Some(Columns { names: lower, idx, value: cv, quantity: q, line: n });
            }
            // Otherwise a header line (KEY: value): kept for the reader of the file, not interpreted.
            continue;
        };
        let cells = split(line);
        if cells.len() != header.len() {
            return Err(Error::input(
                file,
                format!("line {n}"),
                format!("{} values, the column line (line {hline}) names {}", cells.len(), header.len()),
            ));
        }
        let num = |c: usize| -> Result<f64> {
            cells[c].parse::<f64>().ok().filter(|x| x.is_finite()).ok_or_else(|| {
                Error::input(
                    file,
                    format!("line {n}, column {}", header[c]),
                    format!("{:?} is not a finite number", cells[c]),
                )
            })
        };
        let (ti, pi, ts, ps, v) = (num(idx[0])?, num(idx[1])?, num(idx[2])?, num(idx[3])?, num(*cv)?);
        let dphi = (ps - pi).rem_euclid(360.0);
        let theta_o = if ts == 0.0 {
            0.0
        } else if (dphi - 180.0).abs() <= IN_PLANE_TOL_DEG {
            ts
        } else if dphi <= IN_PLANE_TOL_DEG || (360.0 - dphi) <= IN_PLANE_TOL_DEG {
            -ts
        } else {
            unused += 1;
            continue;
        };
        points.push(Point { theta_i_deg: ti, theta_o_deg: theta_o, value: v, line: n });
    }
    let Some(Columns { quantity, .. }) = cols else {
        return Err(Error::input(
            file,
            "",
            "no column line: expected a line naming theta_i, phi_i, theta_s, phi_s and BRDF (or CCBRDF)",
        ));
    };
    if points.is_empty() {
        return Err(Error::input(
            file,
            "",
            format!("no data rows in the plane of incidence ({unused} out-of-plane rows)"),
        ));
    }
    InPlaneBrdf::from_points(file, "ASTM E1392 text", points, quantity, unused)
}

/// Read an E1392-style text file.
pub(crate) fn load(path: &Path) -> Result<InPlaneBrdf> {
    let file = path.display().to_string();
    let text = crate::input::read_text_limited(path, "table", crate::input::MAX_TABLE_BYTES)?;
    parse(&text, &file)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::Brdf;

    #[test]
    fn in_plane_rows_are_used_and_out_of_plane_counted() {
        let text = "SAMPLE: test\nWAVELENGTH: 550\ntheta_i phi_i theta_s phi_s BRDF\n20 0 10 180 1\n20 0 20 180 2\n20 0 30 180 3\n20 0 10 0 5\n20 0 20 90 7\n";
        let t = parse(text, "t.txt").unwrap();
        assert!(t.describe().contains("1 out-of-plane points not used"), "{}", t.describe());
        assert!((t.in_plane(20f64.to_radians(), 25f64.to_radians()) - 2.5).abs() < 1e-9);
        assert!((t.in_plane(20f64.to_radians(), -10f64.to_radians()) - 5.0).abs() < 1e-9);
    }

    #[test]
    fn errors_name_the_line() {
        let e = parse("theta_i phi_i theta_s phi_s BRDF\n20 0 10 180\n", "t.txt").unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("4 values"), "{e}");
        let e = parse("theta_i phi_i theta_s BRDF\n", "t.txt").unwrap_err().to_string();
        assert!(e.contains("lacks `phi_s`"), "{e}");
        let e = parse("just a header\n", "t.txt").unwrap_err().to_string();
        assert!(e.contains("no column line"), "{e}");
        // An unknown column is named quoted and escaped, whatever the file holds.
        let e = parse("theta_i phi_i theta_s phi_s BRDF x\"`\u{1b}\n", "t.txt").unwrap_err().to_string();
        assert!(e.contains(r#"unknown column "x\"`\u{1b}""#) && !e.contains('\u{1b}'), "{e}");
    }
}
