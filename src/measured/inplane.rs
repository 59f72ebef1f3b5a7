//! In-plane goniometer tables f_r(θi, θo): the shape most goniometers export (a scan of the receptor in the
//! plane of incidence for a few angles of incidence), read from the in-plane CSV export here and from ASTM
//! E1392-style text tables in `e1392.rs`.
//!
//! **Interpolation.** θo is signed: positive on the specular side (the side away from the source), negative
//! towards the source. Within a row (one θi) the table is linear in θo between the measured angles and
//! clamped to the end values outside them; between rows it is linear in θi at a fixed offset θo − θi from
//! the specular direction (the peak moves with θi), clamped outside the first and last θi. Rows may have
//! different θo grids. A `brdf_cos` value (f_r·cos θo) is divided by cos θo of its own
//! angle at load time.
//!
//! **Isotropy assumption** (explicit; an in-plane scan says nothing about the other azimuths). The material is
//! taken to be isotropic and its BRDF to depend on the pair of directions only through the Rusinkiewicz
//! half and difference angles (θh, θd) — the "bivariate" approximation of Romeiro, Vasilyev & Zickler
//! (ECCV 2008, "Passive reflectometry"), which drops the φd dependence. An in-plane pair (θi, θo) has
//! θh = |θo − θi|/2 and θd = (θi + θo)/2, so a pair of directions anywhere maps back to the in-plane pairs
//! (θd − θh, θd + θh) and (θd + θh, θd − θh), one the reciprocal of the other; the one whose θi is nearer
//! to the actual polar angle of ωi is used (for a pair in the plane of incidence that is the pair itself, so
//! the table is exact in the plane and the assumption enters only through the apertures' perpendicular
//! extent).
//!
//! Which quantity is taken to depend on (θh, θd) alone is the recipe's choice (`"off_plane"`, [`OffPlane`]):
//! f_r itself (exact for a Lambertian), or f_r·cos θi·cos θo, which is F(θd)·D(θh)·G/4 for a microfacet lobe
//! (Walter et al. 2007, Eq. 20), so exact for the lobe up to its masking term G. Off the plane the two differ
//! by the factor (cos θi′ cos θo′)/(cos θi cos θo) = 1 − tan²θh tan²θd at φd = 90° (the primes: the in-plane
//! pair), which is why a glossy lobe read at 60° and 85° needs the second.
use super::table::{half_diff, Axis, Table};
use crate::brdf::{Brdf, Lobe, Term, TermKind};
use crate::spectrum::Sampling;
use crate::{Error, Result, Vec3};
use std::f64::consts::FRAC_PI_2;
use std::path::Path;

/// What the value column holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// f_r in sr⁻¹.
    Brdf,
    /// f_r·cos θo in sr⁻¹ (the "cosine-corrected BRDF" of ASTM E1392).
    BrdfCos,
}

/// The quantity the isotropic extension holds constant along (θh, θd) (module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OffPlane {
    /// f_r(θh, θd): exact for a constant (Lambertian) BRDF.
    Brdf,
    /// f_r·cos θi·cos θo as a function of (θh, θd): exact for a microfacet lobe up to its masking term.
    BrdfCosCos,
}

impl OffPlane {
    /// The recipe's name of each choice.
    pub fn name(self) -> &'static str {
        match self {
            OffPlane::Brdf => "f",
            OffPlane::BrdfCosCos => "f-cos-cos",
        }
    }
}

/// One measured point: θi, signed θo (degrees) and the value, with the line it came from.
#[derive(Clone, Copy, Debug)]
pub struct Point {
    pub theta_i_deg: f64,
    pub theta_o_deg: f64,
    pub value: f64,
    pub line: usize,
}

/// An in-plane table with the isotropic extension.
#[derive(Clone, Debug)]
pub struct InPlaneBrdf {
    file: String,
    format: &'static str,
    theta_i: Axis,
    /// One 1-D table per θi row, over signed θo in radians.
    rows: Vec<Table>,
    /// Smallest θo step of any row (radians).
    min_step: f64,
    points: usize,
    /// Points of the file not used (e.g. out of the plane), said in `describe`.
    unused: usize,
    theta_o_range: (f64, f64),
    off_plane: OffPlane,
    sampling: Sampling,
}

impl InPlaneBrdf {
    /// Build the table from points (any order). Errors name the file and the line of the offending point.
    pub fn from_points(
        file: &str,
        format: &'static str,
        mut points: Vec<Point>,
        quantity: Quantity,
        unused: usize,
    ) -> Result<Self> {
        let at = |p: &Point, m: String| Error::input(file, format!("line {}", p.line), m);
        for p in &points {
            if !(p.theta_i_deg >= 0.0 && p.theta_i_deg < 90.0) {
                return Err(at(p, format!("theta_i = {}°: allowed 0 ≤ θi < 90", p.theta_i_deg)));
            }
            if !(p.theta_o_deg > -90.0 && p.theta_o_deg < 90.0) {
                return Err(at(
                    p,
                    format!("theta_o = {}°: allowed −90 < θo < 90 (signed, + on the specular side)", p.theta_o_deg),
                ));
            }
            if !(p.value.is_finite() && p.value >= 0.0) {
                return Err(at(p, format!("value {}: a BRDF must be finite and ≥ 0", p.value)));
            }
        }
        points.sort_by(|a, b| a.theta_i_deg.total_cmp(&b.theta_i_deg).then(a.theta_o_deg.total_cmp(&b.theta_o_deg)));
        let mut thetas = Vec::new();
        let mut rows = Vec::new();
        let mut min_step = f64::INFINITY;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut k = 0;
        while k < points.len() {
            let ti = points[k].theta_i_deg;
            let row: Vec<&Point> = points[k..].iter().take_while(|p| p.theta_i_deg == ti).collect();
            k += row.len();
            if row.len() < 2 {
                return Err(at(
                    row[0],
                    format!("θi = {ti}° has a single θo; a row needs at least 2 points to interpolate"),
                ));
            }
            for w in row.windows(2) {
                if w[1].theta_o_deg == w[0].theta_o_deg {
                    return Err(at(w[1], format!("θi = {ti}°, θo = {}° repeats line {}", w[1].theta_o_deg, w[0].line)));
                }
            }
            let tos: Vec<f64> = row.iter().map(|p| p.theta_o_deg.to_radians()).collect();
            let vals: Vec<f64> = row
                .iter()
                .zip(&tos)
                .map(|(p, t)| match quantity {
                    Quantity::Brdf => p.value,
                    Quantity::BrdfCos => p.value / t.cos(),
                })
                .collect();
            lo = lo.min(tos[0]);
            hi = hi.max(tos[tos.len() - 1]);
            let axis = Axis::values(tos);
            min_step = min_step.min(axis.min_spacing());
            thetas.push(ti.to_radians());
            rows.push(Table::new(vec![axis], 1, vals));
        }
        if rows.is_empty() {
            return Err(Error::input(file, "", "no data points"));
        }
        Ok(InPlaneBrdf {
            file: file.to_string(),
            format,
            theta_i: Axis::values(thetas),
            rows,
            min_step,
            points: points.len(),
            unused,
            theta_o_range: (lo, hi),
            off_plane: OffPlane::Brdf,
            sampling: Sampling::grey(),
        })
    }

    /// The same table with the given off-plane extension.
    pub fn with_off_plane(mut self, off_plane: OffPlane) -> Self {
        self.off_plane = off_plane;
        self
    }

    pub fn off_plane(&self) -> OffPlane {
        self.off_plane
    }

    /// f_r at an in-plane pair (θi ≥ 0, signed θo), radians: linear in θo within rows; between rows linear in
    /// θi at a fixed offset θo − θi from the specular direction (so that the specular peak, which moves with
    /// θi, is interpolated onto itself).
    pub fn in_plane(&self, theta_i: f64, theta_o: f64) -> f64 {
        self.interpolate(theta_i, theta_o, false)
    }

    /// f_r·cos θi·cos θo at an in-plane pair, interpolated as that product between rows (the quantity the
    /// `f-cos-cos` extension takes to be smooth).
    pub fn in_plane_cos_cos(&self, theta_i: f64, theta_o: f64) -> f64 {
        self.interpolate(theta_i, theta_o, true)
    }

    fn interpolate(&self, theta_i: f64, theta_o: f64, cos_cos: bool) -> f64 {
        let (i0, i1, t) = self.theta_i.linear(theta_i);
        let row_theta = |i: usize| match &self.theta_i.nodes {
            super::table::Nodes::Values(v) => v[i],
            super::table::Nodes::Index(_) => i as f64,
        };
        let at = |i: usize| {
            let (ti, to) = (row_theta(i), theta_o - theta_i + row_theta(i));
            let mut v = [0.0];
            self.rows[i].linear(&[to], &mut v);
            if cos_cos {
                v[0] * ti.cos() * to.clamp(-FRAC_PI_2, FRAC_PI_2).cos()
            } else {
                v[0]
            }
        };
        let a = at(i0);
        if t == 0.0 {
            return a;
        }
        (1.0 - t) * a + t * at(i1)
    }

    /// Slope width reported to the integrator: tan of half the smallest θo step (a step of the receptor by
    /// Δ turns the half vector by Δ/2).
    pub fn resolution_slope(&self) -> f64 {
        (0.5 * self.min_step).tan()
    }
}

impl Brdf for InPlaneBrdf {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        if !(wi.z > 0.0 && wo.z > 0.0) {
            out.fill(0.0);
            return;
        }
        let hd = half_diff(wi, wo);
        let (th, td) = (hd.theta_h, hd.theta_d);
        let actual = (wi.x * wi.x + wi.y * wi.y).sqrt().atan2(wi.z);
        // The in-plane pair with (θh, θd) whose θi is nearer the actual one (the other is its reciprocal).
        let pair = |td: f64| {
            let a = (td - th, td + th);
            let b = (td + th, td - th);
            if a.0 >= 0.0 && (a.0 - actual).abs() <= (b.0 - actual).abs() {
                a
            } else {
                b
            }
        };
        out[0] = match self.off_plane {
            // A pair off the plane near grazing can map beyond the in-plane domain (θd + θh > 90°); the
            // table's own clamping then gives its nearest in-plane value (exact for a constant BRDF, an
            // overestimate for a lobe: docs/recipe-format.md §inplane-csv states the error at 85°).
            OffPlane::Brdf => {
                let (ti, to) = pair(td);
                self.in_plane(ti.min(FRAC_PI_2), to.clamp(-FRAC_PI_2, FRAC_PI_2))
            }
            // g = f·cos θi′·cos θo′ at the in-plane pair, divided by the actual cosines (exact in the plane).
            // Beyond the measured domain the clamped pair's cosines make g small: an underestimate near
            // grazing, where the masking term (not in the assumption) matters as well (docs: 85°).
            OffPlane::BrdfCosCos => {
                let (ti, to) = pair(td);
                let g = self.in_plane_cos_cos(ti.min(FRAC_PI_2), to.clamp(-FRAC_PI_2, FRAC_PI_2));
                let f = g / (wi.z * wo.z);
                if f.is_finite() {
                    f.max(0.0)
                } else {
                    0.0
                }
            }
        };
    }

    fn terms(&self) -> Vec<Term> {
        vec![Term {
            label: format!("measured in-plane table ({}, isotropic (θh, θd) extension)", self.format),
            kind: TermKind::Lobe(Lobe {
                slope_width: self.resolution_slope(),
                medium_eta: 1.0,
                label: format!("measured ({})", self.format),
                heavy_tail: true,
            }),
        }]
    }

    fn describe(&self) -> String {
        let name = Path::new(&self.file).file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let unused =
            if self.unused > 0 { format!(", {} out-of-plane points not used", self.unused) } else { String::new() };
        format!(
            "measured in-plane table {name} ({}, {} points, {} angles of incidence, θo {:.1}° to {:.1}°, clamped outside; isotropic, {} off the plane{unused})",
            self.format,
            self.points,
            self.rows.len(),
            self.theta_o_range.0.to_degrees(),
            self.theta_o_range.1.to_degrees(),
            match self.off_plane {
                OffPlane::Brdf => "f = f(θh, θd)",
                OffPlane::BrdfCosCos => "f·cos θi·cos θo = g(θh, θd)",
            }
        )
    }
}

/// Read the in-plane CSV export: a header naming the columns `theta_i`, `theta_o` (degrees, θo signed, + on
/// the specular side) and exactly one of `brdf` (f_r, sr⁻¹) or `brdf_cos` (f_r·cos θo, sr⁻¹), in any order
/// (other columns are refused); one point per row; lines starting with `#` are comments.
pub fn parse_csv(text: &str, file: &str) -> Result<InPlaneBrdf> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((hline, header)) = lines.next() else {
        return Err(Error::input(file, "", "empty: expected a header `theta_i,theta_o,brdf` (or `brdf_cos`)"));
    };
    let cols: Vec<String> = header.split(',').map(|c| c.trim().to_ascii_lowercase()).collect();
    let find = |name: &str| cols.iter().position(|c| c == name);
    let allowed =
        "allowed columns: theta_i, theta_o (degrees) and one of brdf (f_r, 1/sr) or brdf_cos (f_r·cos θo, 1/sr)";
    let hdr_err = |m: String| Error::input(file, format!("line {}", hline + 1), format!("{m}; {allowed}"));
    for c in &cols {
        if !["theta_i", "theta_o", "brdf", "brdf_cos"].contains(&c.as_str()) {
            return Err(hdr_err(format!("unknown column `{c}`")));
        }
    }
    let (Some(ci), Some(co)) = (find("theta_i"), find("theta_o")) else {
        return Err(hdr_err("missing column theta_i or theta_o".into()));
    };
    let (cv, quantity) = match (find("brdf"), find("brdf_cos")) {
        (Some(c), None) => (c, Quantity::Brdf),
        (None, Some(c)) => (c, Quantity::BrdfCos),
        (Some(_), Some(_)) => {
            return Err(hdr_err("both brdf and brdf_cos given: the column must say which one the values are".into()))
        }
        (None, None) => return Err(hdr_err("missing the value column".into())),
    };
    let mut points = Vec::new();
    for (i, l) in lines {
        let cells: Vec<&str> = l.split(',').map(str::trim).collect();
        if cells.len() != cols.len() {
            return Err(Error::input(
                file,
                format!("line {}", i + 1),
                format!("{} cells, the header has {} columns", cells.len(), cols.len()),
            ));
        }
        let num = |c: usize| -> Result<f64> {
            cells[c].parse::<f64>().ok().filter(|x| x.is_finite()).ok_or_else(|| {
                Error::input(
                    file,
                    format!("line {}, column {}", i + 1, cols[c]),
                    format!("{:?} is not a finite number", cells[c]),
                )
            })
        };
        points.push(Point { theta_i_deg: num(ci)?, theta_o_deg: num(co)?, value: num(cv)?, line: i + 1 });
    }
    InPlaneBrdf::from_points(file, "in-plane CSV", points, quantity, 0)
}

/// Read an in-plane CSV file.
pub fn load_csv(path: &Path) -> Result<InPlaneBrdf> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io { file: file.clone(), source })?;
    parse_csv(&text, &file)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn in_plane_pairs_are_read_back_exactly() {
        let text = "theta_i,theta_o,brdf\n20,10,1\n20,20,3\n20,30,2\n60,50,4\n60,60,8\n60,70,6\n";
        let t = parse_csv(text, "t.csv").unwrap();
        let d = |deg: f64, side: f64| Vec3::new(side * deg.to_radians().sin(), 0.0, deg.to_radians().cos());
        let mut out = [0.0];
        t.eval(d(20.0, -1.0), d(20.0, 1.0), &mut out);
        assert!((out[0] - 3.0).abs() < 1e-12, "{out:?}");
        t.eval(d(20.0, -1.0), d(25.0, 1.0), &mut out);
        assert!((out[0] - 2.5).abs() < 1e-9, "{out:?}");
        // Half way between the rows, at the specular direction.
        assert!((t.in_plane(40f64.to_radians(), 40f64.to_radians()) - 0.5 * (3.0 + 8.0)).abs() < 1e-12);
    }

    #[test]
    fn csv_errors_name_line_and_column() {
        let e = parse_csv("theta_i,theta_o,brdf\n20,10,x\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains("line 2, column brdf"), "{e}");
        let e = parse_csv("theta_i,theta_o,value\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains("unknown column `value`"), "{e}");
        let e = parse_csv("theta_i,theta_o,brdf,brdf_cos\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains("both brdf and brdf_cos"), "{e}");
        let e = parse_csv("theta_i,theta_o,brdf\n20,10,1\n20,10,2\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("repeats line 2"), "{e}");
    }
}
