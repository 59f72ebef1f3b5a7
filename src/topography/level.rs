//! Levelling: the reference surface a map's heights are measured from (ISO 25178-2's F-operation, the form
//! removed), fitted by least squares over the valid points and subtracted (docs/topography.md §Levelling):
//! its mean only, a plane, or a polynomial of total degree 2 to 5 in x and y.
use nalgebra::{DMatrix, DVector};

use super::map::HeightMap;
use crate::{Error, Result};

/// The highest polynomial degree allowed.
pub(crate) const MAX_DEGREE: u32 = 5;

/// What is removed from the heights.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Levelling {
    /// The mean height only (a tilt stays in the slopes).
    Mean,
    /// The least-squares plane (the default).
    Plane,
    /// The least-squares polynomial of this total degree (2 to [`MAX_DEGREE`]).
    Polynomial(u32),
}

impl Levelling {
    /// The name in documents and on the command line: `mean`, `plane`, `poly2` … `poly5`.
    pub fn name(self) -> String {
        match self {
            Levelling::Mean => "mean".into(),
            Levelling::Plane => "plane".into(),
            Levelling::Polynomial(d) => format!("poly{d}"),
        }
    }

    /// The levelling of a name, `None` if it is not one.
    pub fn parse(s: &str) -> Option<Levelling> {
        match s {
            "mean" => Some(Levelling::Mean),
            "plane" => Some(Levelling::Plane),
            _ => {
                let d: u32 = s.strip_prefix("poly")?.parse().ok()?;
                (2..=MAX_DEGREE).contains(&d).then_some(Levelling::Polynomial(d))
            }
        }
    }

    /// The names allowed, for messages.
    pub fn allowed() -> String {
        format!("mean, plane (the default), poly2 … poly{MAX_DEGREE}")
    }

    fn degree(self) -> u32 {
        match self {
            Levelling::Mean => 0,
            Levelling::Plane => 1,
            Levelling::Polynomial(d) => d,
        }
    }
}

/// The heights less the reference surface.
#[derive(Clone, Debug, PartialEq)]
pub struct Levelled {
    /// Heights, metres (NaN where the map's point is invalid).
    pub z: Vec<f64>,
    /// The reference surface's mean slope along x and y (dz/dx, dz/dy: the tilt removed; 0 for `mean`).
    pub tilt: [f64; 2],
}

/// Level `map`: the least-squares fit of the monomials uᵃvᵇ (a + b ≤ degree) over the valid points, in the
/// coordinates u, v ∈ [−1, 1] across the map (which keeps the normal equations well conditioned), subtracted.
pub fn level(map: &HeightMap, how: Levelling) -> Result<Levelled> {
    let d = how.degree() as usize;
    let powers: Vec<(usize, usize)> = (0..=d).flat_map(|t| (0..=t).map(move |b| (t - b, b))).collect();
    let k = powers.len();
    let valid = map.valid();
    if valid < k {
        return Err(Error::input(
            &map.file,
            "",
            format!(
                "{valid} valid point(s) cannot fix a levelling `{}` ({k} coefficients); allowed: a simpler levelling",
                how.name()
            ),
        ));
    }
    let (nx, ny) = (map.nx, map.ny);
    let coord = |i: usize, n: usize| 2.0 * i as f64 / (n - 1) as f64 - 1.0;
    let basis = |u: f64, v: f64, out: &mut [f64]| {
        for (o, &(a, b)) in out.iter_mut().zip(&powers) {
            *o = u.powi(a as i32) * v.powi(b as i32);
        }
    };
    let mut ata = DMatrix::<f64>::zeros(k, k);
    let mut atz = DVector::<f64>::zeros(k);
    let mut phi = vec![0.0; k];
    for j in 0..ny {
        for i in 0..nx {
            let z = map.z[j * nx + i];
            if z.is_nan() {
                continue;
            }
            basis(coord(i, nx), coord(j, ny), &mut phi);
            for r in 0..k {
                atz[r] += phi[r] * z;
                for c in 0..k {
                    ata[(r, c)] += phi[r] * phi[c];
                }
            }
        }
    }
    let coef = ata
        .svd(true, true)
        .solve(&atz, 1e-13)
        .map_err(|e| Error::Numeric(format!("{}: the levelling `{}` cannot be solved: {e}", map.file, how.name())))?;
    let mut z = map.z.clone();
    for j in 0..ny {
        for i in 0..nx {
            let h = &mut z[j * nx + i];
            if !h.is_nan() {
                basis(coord(i, nx), coord(j, ny), &mut phi);
                *h -= phi.iter().zip(coef.iter()).map(|(p, c)| p * c).sum::<f64>();
            }
        }
    }
    // The plane's slopes: the u and v coefficients over the half-widths of the map.
    let tilt = if d >= 1 {
        let half = |n: usize, step: f64| (n - 1) as f64 * step / 2.0;
        [coef[1] / half(nx, map.dx), coef[2] / half(ny, map.dy)]
    } else {
        [0.0, 0.0]
    };
    Ok(Levelled { z, tilt })
}

#[cfg(test)]
mod tests {
    use super::super::map::Format;
    use super::*;

    fn map(nx: usize, ny: usize, f: impl Fn(f64, f64) -> f64) -> HeightMap {
        let (dx, dy) = (1e-6, 2e-6);
        let z =
            (0..ny).flat_map(|j| (0..nx).map(move |i| (i, j))).map(|(i, j)| f(i as f64 * dx, j as f64 * dy)).collect();
        HeightMap::new("t", Format::Text, nx, ny, dx, dy, z, "z").unwrap()
    }

    #[test]
    fn a_plane_is_removed_and_its_tilt_reported() {
        let m = map(17, 9, |x, y| 1e-7 + 0.01 * x - 0.02 * y);
        let l = level(&m, Levelling::Plane).unwrap();
        assert!(l.z.iter().all(|z| z.abs() < 1e-20), "{:?}", &l.z[..3]);
        assert!((l.tilt[0] - 0.01).abs() < 1e-14 && (l.tilt[1] + 0.02).abs() < 1e-14, "{:?}", l.tilt);
        let l = level(&m, Levelling::Mean).unwrap();
        assert!(l.z.iter().sum::<f64>().abs() < 1e-18 && l.tilt == [0.0, 0.0]);
    }

    #[test]
    fn a_polynomial_of_its_degree_is_removed_and_invalid_points_stay_invalid() {
        let mut m = map(20, 15, |x, y| 1e-6 * ((x * 1e5).powi(3) - 2.0 * (x * 1e5) * (y * 1e5).powi(2)));
        m.z[7] = f64::NAN;
        let l = level(&m, Levelling::Polynomial(3)).unwrap();
        assert!(l.z[7].is_nan());
        let worst = l.z.iter().filter(|z| !z.is_nan()).fold(0.0f64, |a, z| a.max(z.abs()));
        assert!(worst < 1e-17, "{worst}");
        assert!(level(&m, Levelling::Polynomial(2)).unwrap().z.iter().any(|z| z.abs() > 1e-9));
    }

    #[test]
    fn names_round_trip() {
        for l in [Levelling::Mean, Levelling::Plane, Levelling::Polynomial(2), Levelling::Polynomial(5)] {
            assert_eq!(Levelling::parse(&l.name()), Some(l));
        }
        assert_eq!(Levelling::parse("poly1"), None);
        assert_eq!(Levelling::parse("poly6"), None);
    }
}
