//! The linear error analysis, checked (docs/inverse.md §Uncertainty): along every determined direction
//! (singular value s ≥ 1) step one standard error each way, t ± δ with δ_k = width_k·v_k/s, integrate there,
//! and compare the actual change of χ² with the change the linearised model predicts, ‖r + Jδ‖² − ‖r‖²
//! (≈ 1 at the optimum). A ratio outside [1/2, 2] means the readings are not linear in the parameters over one
//! standard error (a curved valley, a kink, a switch of model): the standard errors and correlations are then
//! not to be trusted and the fit is not reported identifiable (Bates & Watts, *Nonlinear Regression Analysis
//! and Its Applications*, 1988, ch. 7, on when linear approximation intervals fail). A side that leaves the
//! bounds or the model's constraints is skipped.
use nalgebra::{DMatrix, DVector};

use super::analysis::Analysis;

/// The fit's point as the linearity check sees it: t, the weighted residuals r, the weighted Jacobian in t,
/// the bounds and widths in t, and the parameters' names.
pub(super) struct At<'a> {
    pub(super) t: &'a [f64],
    pub(super) r: &'a DVector<f64>,
    pub(super) jt: &'a DMatrix<f64>,
    pub(super) bounds: &'a [(f64, f64)],
    pub(super) widths: &'a [f64],
    pub(super) names: &'a [&'a str],
}

/// The directions along which the readings are not linear over one standard error, in words (at most one line
/// per direction); `residuals_at(t)` gives the weighted residuals at t, or `None` where the model does not
/// evaluate.
pub(super) fn check(
    analysis: &Analysis,
    at: &At,
    mut residuals_at: impl FnMut(&[f64]) -> Option<DVector<f64>>,
) -> Vec<String> {
    let n = at.t.len();
    let chi2 = at.r.norm_squared();
    let mut nonlinear = Vec::new();
    for d in &analysis.directions {
        let (s, v) = (d.s, &d.v);
        if s < 1.0 || analysis.null(s) {
            continue;
        }
        for sign in [1.0, -1.0] {
            let delta: Vec<f64> = (0..n).map(|k| sign * at.widths[k] * v[k] / s).collect();
            let tt: Vec<f64> = (0..n).map(|k| at.t[k] + delta[k]).collect();
            if !(0..n).all(|k| tt[k] >= at.bounds[k].0 && tt[k] <= at.bounds[k].1) {
                continue;
            }
            let step = DVector::from_column_slice(&delta);
            let expected = (at.r + at.jt * &step).norm_squared() - chi2;
            let Some(r_tt) = residuals_at(&tt) else { continue };
            let actual = r_tt.norm_squared() - chi2;
            let ratio = actual / expected;
            if !(ratio.is_finite() && (0.5..=2.0).contains(&ratio)) {
                let combo: Vec<String> =
                    (0..n).filter(|&k| v[k].abs() >= 0.2).map(|k| format!("{:+.2}·Δ{}", v[k], at.names[k])).collect();
                nonlinear.push(format!(
                    "the readings are not linear in the parameters over one standard error along {}: one standard \
                     error that way changes χ² by {actual:.3}, where the linear error analysis says {expected:.3}; the \
                     standard errors and correlations are not to be trusted here (a profile of χ² or a Monte Carlo \
                     over the noise would be)",
                    combo.join(" ")
                ));
                break;
            }
        }
    }
    nonlinear
}

#[cfg(test)]
mod tests {
    use super::super::analysis::analyse;
    use super::*;

    /// r(t) = (t₀ − 1 + q·t₀², t₁ − 2)/0.1 fitted at t = (1, 2): linear in t₁; in t₀ linear for q = 0 and
    /// curved over one standard error (0.1) for q = 5.
    fn case(q: f64) -> Vec<String> {
        let model = |t: &[f64]| {
            DVector::from_column_slice(&[(t[0] - 1.0 + q * (t[0] - 1.0).powi(2)) / 0.1, (t[1] - 2.0) / 0.1])
        };
        let t = [1.0, 2.0];
        let jt = DMatrix::from_row_slice(2, 2, &[10.0, 0.0, 0.0, 10.0]);
        let widths = [4.0, 4.0];
        let r = model(&t);
        let a = analyse(&jt, r.norm_squared(), &widths);
        let at =
            At { t: &t, r: &r, jt: &jt, bounds: &[(-1.0, 3.0), (0.0, 4.0)], widths: &widths, names: &["/a", "/b"] };
        check(&a, &at, |t| Some(model(t)))
    }

    #[test]
    fn a_linear_model_passes_and_a_curved_one_is_named() {
        assert!(case(0.0).is_empty(), "{:?}", case(0.0));
        let lines = case(5.0);
        assert_eq!(lines.len(), 1, "{lines:?}");
        assert!(lines[0].contains("along +1.00·Δ/a") || lines[0].contains("along -1.00·Δ/a"), "{lines:?}");
    }

    /// A step that leaves the bounds or does not evaluate is skipped, so nothing is claimed.
    #[test]
    fn steps_outside_or_unevaluated_are_skipped() {
        let t = [1.0];
        let jt = DMatrix::from_row_slice(1, 1, &[10.0]);
        let r = DVector::from_column_slice(&[0.0]);
        let a = analyse(&jt, 0.0, &[1.0]);
        let at = At { t: &t, r: &r, jt: &jt, bounds: &[(0.0, 2.0)], widths: &[1.0], names: &["/a"] };
        assert!(check(&a, &at, |_| None).is_empty());
        let tight = At { bounds: &[(0.95, 1.05)], ..at };
        assert!(check(&a, &tight, |_| Some(DVector::from_column_slice(&[1e9]))).is_empty());
    }
}
