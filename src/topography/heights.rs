//! The height parameters of ISO 25178-2 over the valid points of a levelled map (docs/topography.md §Height
//! parameters): Sq, Sa, Sp, Sv, Sz, Ssk and Sku, the integrals of the standard's definitions taken as means over
//! the points.
use crate::{Error, Result};

/// The height parameters, metres (Ssk and Sku have no unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Heights {
    /// Root mean square height: Sq = √(⟨z²⟩).
    pub sq: f64,
    /// Arithmetic mean height: Sa = ⟨|z|⟩.
    pub sa: f64,
    /// Maximum peak height Sp = max z, maximum pit depth Sv = −min z, maximum height Sz = Sp + Sv.
    pub sp: f64,
    pub sv: f64,
    pub sz: f64,
    /// Skewness Ssk = ⟨z³⟩/Sq³ and kurtosis Sku = ⟨z⁴⟩/Sq⁴ (`None` for a flat map, Sq = 0).
    pub ssk: Option<f64>,
    pub sku: Option<f64>,
    /// The valid points the means are over.
    pub points: usize,
}

/// The height parameters of levelled heights `z` (NaN: invalid), about their reference surface z = 0.
pub fn heights(z: &[f64], file: &str) -> Result<Heights> {
    let (mut n, mut s1, mut s2, mut s3, mut s4) = (0usize, 0.0, 0.0, 0.0, 0.0);
    let (mut hi, mut lo) = (f64::NEG_INFINITY, f64::INFINITY);
    for &v in z.iter().filter(|v| !v.is_nan()) {
        n += 1;
        s1 += v.abs();
        s2 += v * v;
        s3 += v * v * v;
        s4 += v * v * v * v;
        hi = hi.max(v);
        lo = lo.min(v);
    }
    if n == 0 {
        return Err(Error::input(file, "", "no valid point: there is no surface to read"));
    }
    let nf = n as f64;
    let sq = (s2 / nf).sqrt();
    let moment = |s: f64, p: i32| (sq > 0.0).then(|| s / nf / sq.powi(p));
    Ok(Heights { sq, sa: s1 / nf, sp: hi, sv: -lo, sz: hi - lo, ssk: moment(s3, 3), sku: moment(s4, 4), points: n })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn a_sampled_sinusoid_has_its_closed_forms() {
        // Whole periods of A sin(2πi/N), N = 512 points a period: Sq = A/√2, Ssk = 0, Sku = 3/2, and
        // Sa = A·(2/N)·cot(π/N), the sampled mean of |sin| (→ 2A/π).
        let (a, n) = (0.3e-6, 4096);
        let z: Vec<f64> = (0..n).map(|i| a * (2.0 * PI * 8.0 * i as f64 / n as f64).sin()).collect();
        let h = heights(&z, "t").unwrap();
        assert!((h.sq - a / 2f64.sqrt()).abs() < 1e-15 * a / 2f64.sqrt() * 10.0, "{}", h.sq);
        let sa = a * 2.0 / 512.0 / (PI / 512.0).tan();
        assert!((h.sa - sa).abs() < 1e-13 * sa, "{} {sa}", h.sa);
        assert!((h.sa - 2.0 * a / PI).abs() < 2e-5 * a);
        assert!(h.ssk.unwrap().abs() < 1e-12 && (h.sku.unwrap() - 1.5).abs() < 1e-12);
        assert!((h.sz - 2.0 * a).abs() < 1e-20);
    }

    #[test]
    fn invalid_points_are_left_out_and_a_flat_map_has_no_shape_moments() {
        let h = heights(&[1.0, f64::NAN, -1.0], "t").unwrap();
        assert_eq!((h.sq, h.points), (1.0, 2));
        let flat = heights(&[0.0; 4], "t").unwrap();
        assert_eq!((flat.sq, flat.ssk, flat.sku), (0.0, None, None));
        assert!(heights(&[f64::NAN], "t").is_err());
    }
}
