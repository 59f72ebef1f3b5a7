//! The linear error analysis at the fit (docs/inverse.md §Uncertainty): the weighted Jacobian's columns
//! scaled by their bound widths, its singular value decomposition, the covariance s²·V Σ⁻² Vᵀ with the exact
//! null directions left out, the standard errors and correlations; which parameters sit at a bound; and the
//! Gauss–Newton step that remains (the independent check of the solver's stop).
use nalgebra::{DMatrix, DVector};

/// One direction of the scaled Jacobian's SVD: its singular value and its right singular vector (the
/// components in units of each parameter's bound width).
#[derive(Clone, Debug)]
pub(super) struct Direction {
    pub(super) s: f64,
    pub(super) v: Vec<f64>,
}

/// The error analysis of a weighted Jacobian J (m × n, in the fitted variables t).
#[derive(Debug)]
pub(super) struct Analysis {
    /// The SVD's directions, largest singular value first.
    pub(super) directions: Vec<Direction>,
    /// The largest singular value (0 for none).
    pub(super) smax: f64,
    /// The Jacobian with each column scaled by its parameter's bound width.
    pub(super) scaled: DMatrix<f64>,
    /// The scale factor of the covariance, s² = max(χ²/(m − n), 1) for m > n, else 1.
    pub(super) s2: f64,
    /// Standard errors in t (`None` where the targets do not determine the parameter).
    pub(super) std_t: Vec<Option<f64>>,
    /// The same from the targets' uncertainties alone (not scaled by s).
    pub(super) std_t_unscaled: Vec<Option<f64>>,
    pub(super) correlation: Vec<Vec<Option<f64>>>,
}

impl Analysis {
    /// An exact null direction: a singular value at or below 10⁻¹² of the largest.
    pub(super) fn null(&self, s: f64) -> bool {
        s <= 1e-12 * self.smax || s == 0.0
    }

    /// The singular values, largest first.
    pub(super) fn singular_values(&self) -> Vec<f64> {
        self.directions.iter().map(|d| d.s).collect()
    }
}

/// The error analysis of `jt` (the weighted Jacobian in t) at a fit of χ² `chi2`, the parameters' bound
/// widths in t `widths`.
///
/// The covariance is scaled by the residuals (the Birge ratio χ²/(m − n)) when they scatter more than the
/// targets' uncertainties say, and never shrunk below what those uncertainties give: exact or lucky targets
/// (χ² ≈ 0) would otherwise report standard errors of nothing (the Particle Data Group's scale factor
/// S = √(χ²/(N − 1)), applied only when S > 1; PDG, Review of Particle Physics, Introduction §5.2.2). A
/// parameter that takes part (component ≥ 0.2) in a direction with singular value < 1 has a standard error
/// larger than its bound width, or none the linearization can give: it is reported without one, as is any
/// parameter in an exact null direction.
pub(super) fn analyse(jt: &DMatrix<f64>, chi2: f64, widths: &[f64]) -> Analysis {
    let (m, n) = (jt.nrows(), jt.ncols());
    let s2 = if m > n { (chi2 / (m - n) as f64).max(1.0) } else { 1.0 };
    let mut js = jt.clone();
    for (k, w) in widths.iter().enumerate() {
        js.column_mut(k).scale_mut(*w);
    }
    let svd = js.clone().svd(true, true);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
    let v_t = svd.v_t.clone().expect("V requested");
    let directions: Vec<Direction> = order
        .iter()
        .map(|&i| Direction { s: svd.singular_values[i], v: v_t.row(i).iter().copied().collect() })
        .collect();
    let smax = directions.first().map_or(0.0, |d| d.s);
    let mut analysis = Analysis {
        directions,
        smax,
        scaled: js,
        s2,
        std_t: Vec::new(),
        std_t_unscaled: Vec::new(),
        correlation: Vec::new(),
    };
    // Covariance in t: s²·V Σ⁻² Vᵀ / (width_a width_b), exact null directions left out.
    let mut cov = DMatrix::<f64>::zeros(n, n);
    let mut undetermined = vec![false; n];
    for d in &analysis.directions {
        let v = DVector::from_column_slice(&d.v);
        for k in 0..n {
            if (analysis.null(d.s) && v[k].abs() > 1e-3) || (d.s < 1.0 && v[k].abs() >= 0.2) {
                undetermined[k] = true;
            }
        }
        if !analysis.null(d.s) {
            cov += (&v * v.transpose()) / (d.s * d.s);
        }
    }
    for a in 0..n {
        for b in 0..n {
            cov[(a, b)] *= s2 * widths[a] * widths[b];
        }
    }
    let std_t: Vec<Option<f64>> = (0..n).map(|k| (!undetermined[k]).then(|| cov[(k, k)].max(0.0).sqrt())).collect();
    analysis.std_t_unscaled = std_t.iter().map(|s| s.map(|s| s / s2.sqrt())).collect();
    analysis.correlation = (0..n)
        .map(|a| {
            (0..n)
                .map(|b| match (std_t[a], std_t[b]) {
                    (Some(sa), Some(sb)) if sa > 0.0 && sb > 0.0 => Some((cov[(a, b)] / (sa * sb)).clamp(-1.0, 1.0)),
                    _ => None,
                })
                .collect()
        })
        .collect();
    analysis.std_t = std_t;
    analysis
}

/// Which parameters sit at a bound: within 10⁻⁶ of the bound width of either end, in t.
pub(super) fn at_bounds(t: &[f64], bounds: &[(f64, f64)], widths: &[f64]) -> Vec<bool> {
    (0..t.len())
        .map(|k| {
            let (a, b) = bounds[k];
            let tol = 1e-6 * widths[k];
            t[k] - a <= tol || b - t[k] <= tol
        })
        .collect()
}

/// The Gauss–Newton step that remains from the fit, over the parameters not at a bound and in the directions
/// the targets determine (singular value ≥ 1 of the scaled Jacobian restricted to them), in units of the
/// targets' uncertainties: |Uᵀr| over those directions. A solver that stopped early (a budget, a noise floor
/// met far from the optimum) leaves a step of a sizeable fraction of a standard error.
pub(super) fn remaining_step(scaled: &DMatrix<f64>, r: &DVector<f64>, at_bound: &[bool]) -> f64 {
    let inner: Vec<usize> = (0..at_bound.len()).filter(|&k| !at_bound[k]).collect();
    if inner.is_empty() {
        return 0.0;
    }
    let ji = DMatrix::from_fn(scaled.nrows(), inner.len(), |i, c| scaled[(i, inner[c])]);
    let svd_i = ji.svd(true, false);
    let u_i = svd_i.u.expect("U requested");
    let smax_i = svd_i.singular_values.max();
    (0..svd_i.singular_values.len())
        .filter(|&c| svd_i.singular_values[c] >= 1.0 && svd_i.singular_values[c] > 1e-12 * smax_i)
        .map(|c| u_i.column(c).dot(r).powi(2))
        .sum::<f64>()
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1e-300)
    }

    /// A diagonal Jacobian: the standard errors are 1/J_kk, uncorrelated; the singular values are the
    /// diagonal times the widths, largest first.
    #[test]
    fn a_diagonal_jacobian_gives_reciprocal_standard_errors() {
        let jt = DMatrix::from_row_slice(2, 2, &[2.0, 0.0, 0.0, 40.0]);
        let a = analyse(&jt, 0.0, &[1.0, 0.5]);
        assert_eq!(a.singular_values(), vec![20.0, 2.0]);
        assert!(close(a.std_t[0].unwrap(), 0.5) && close(a.std_t[1].unwrap(), 0.025), "{a:?}");
        assert_eq!(a.correlation[0][1], Some(0.0));
        assert_eq!(a.s2, 1.0);
    }

    /// A full-rank Jacobian with residual scatter: the covariance is s²(JᵀJ)⁻¹ with s² = χ²/(m − n), against the
    /// closed-form inverse of a 2 × 2 matrix.
    #[test]
    fn the_covariance_is_the_scaled_inverse_of_jtj() {
        let jt = DMatrix::from_row_slice(3, 2, &[3.0, 1.0, 1.0, 2.0, 2.0, -1.0]);
        let chi2 = 4.0; // m − n = 1: s² = 4
        let a = analyse(&jt, chi2, &[1.0, 1.0]);
        let jtj = jt.transpose() * &jt; // [[14, 3], [3, 6]], det 75
        let det = jtj[(0, 0)] * jtj[(1, 1)] - jtj[(0, 1)] * jtj[(1, 0)];
        let (c00, c11, c01) = (4.0 * jtj[(1, 1)] / det, 4.0 * jtj[(0, 0)] / det, -4.0 * jtj[(0, 1)] / det);
        assert!((a.std_t[0].unwrap() - c00.sqrt()).abs() < 1e-12, "{a:?}");
        assert!((a.std_t[1].unwrap() - c11.sqrt()).abs() < 1e-12, "{a:?}");
        assert!((a.correlation[0][1].unwrap() - c01 / (c00 * c11).sqrt()).abs() < 1e-12);
        assert!((a.std_t_unscaled[0].unwrap() - (c00 / 4.0).sqrt()).abs() < 1e-12);
    }

    /// A column of zeros (a parameter no target sees) and a direction below one uncertainty over the bounds:
    /// no standard error for the parameters in them, the others keep theirs.
    #[test]
    fn unseen_and_weak_parameters_have_no_standard_error() {
        let jt = DMatrix::from_row_slice(3, 3, &[5.0, 0.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0]);
        let a = analyse(&jt, 0.0, &[1.0, 1.0, 1.0]);
        assert!(a.std_t[0].is_some() && a.std_t[1].is_none() && a.std_t[2].is_none(), "{a:?}");
        assert!(a.null(a.directions[2].s) && !a.null(a.directions[1].s));
        assert_eq!(a.correlation[0][1], None);
    }

    #[test]
    fn bounds_and_the_remaining_step() {
        assert_eq!(at_bounds(&[0.0, 0.5, 1.0 - 1e-7], &[(0.0, 1.0); 3], &[1.0; 3]), vec![true, false, true]);
        // J = I (scaled): the remaining step is |r| over the free parameters.
        let j = DMatrix::<f64>::identity(2, 2);
        let r = DVector::from_column_slice(&[3.0, 4.0]);
        assert!((remaining_step(&j, &r, &[false, false]) - 5.0).abs() < 1e-12);
        assert!((remaining_step(&j, &r, &[true, false]) - 4.0).abs() < 1e-12);
        assert_eq!(remaining_step(&j, &r, &[true, true]), 0.0);
    }
}
