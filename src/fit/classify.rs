//! Classification of the solver's ends (docs/inverse.md §Every root): where each restart ended against the
//! fit, and the verdict's line on uniqueness.
//!
//! A restart's end is at this solution (every parameter within three standard errors), at another one that
//! fits the targets as well (χ² within 1 of this one: a second solution the targets cannot tell from this
//! one), on a plateau (moving any parameter by a twentieth of its bound width changes the readings by less
//! than one uncertainty: the solver stopped because nothing changes, not at a minimum; checked first, so that
//! points of one plateau are not called solutions), or at a worse local minimum.
use nalgebra::DVector;

/// The plateau probe's step, as a fraction of each bound width.
pub(super) const PLATEAU_STEP: f64 = 0.05;

/// A solver's end: its point in t and its weighted residuals (`None` where it does not evaluate).
pub(super) struct End {
    pub(super) t: Vec<f64>,
    pub(super) r: Option<DVector<f64>>,
}

/// How the ends other than the fit's ended.
#[derive(Debug, Default, PartialEq)]
pub(super) struct Classes {
    pub(super) same: usize,
    pub(super) plateau: usize,
    pub(super) worse: usize,
    /// Ends that do not evaluate.
    pub(super) failed: usize,
    /// Other solutions that fit as well: their t and χ².
    pub(super) others: Vec<(Vec<f64>, f64)>,
}

/// The fit against which the ends are classified: its t, χ², standard errors in t, bounds and widths in t.
pub(super) struct Fit<'a> {
    pub(super) t: &'a [f64],
    pub(super) chi2: f64,
    pub(super) std_t: &'a [Option<f64>],
    pub(super) bounds: &'a [(f64, f64)],
    pub(super) widths: &'a [f64],
}

/// Classify every end but the `chosen` one; `residuals_at(t)` gives the weighted residuals at t (an adaptive
/// run), or `None` where the model does not evaluate (a plateau probe that does not evaluate does not count
/// against a plateau).
pub(super) fn classify(
    ends: &[End],
    chosen: usize,
    fit: &Fit,
    mut residuals_at: impl FnMut(&[f64]) -> Option<DVector<f64>>,
) -> Classes {
    let n = fit.t.len();
    let mut c = Classes::default();
    for (j, end) in ends.iter().enumerate() {
        if j == chosen {
            continue;
        }
        let Some(r_j) = &end.r else {
            c.failed += 1;
            continue;
        };
        let t_j = &end.t;
        let chi2_j = r_j.norm_squared();
        let apart = (0..n).any(|k| match fit.std_t[k] {
            Some(sd) if sd > 0.0 => (t_j[k] - fit.t[k]).abs() > 3.0 * sd,
            // An undetermined parameter: apart if it moved by more than 1e-3 of its bound width.
            _ => (t_j[k] - fit.t[k]).abs() > 1e-3 * fit.widths[k],
        });
        if !apart {
            c.same += 1;
            continue;
        }
        let flat = (0..n).all(|k| {
            [1.0, -1.0].iter().all(|sign| {
                let mut tt = t_j.clone();
                let (a, b) = fit.bounds[k];
                tt[k] = (tt[k] + sign * PLATEAU_STEP * fit.widths[k]).clamp(a, b);
                match residuals_at(&tt) {
                    Some(r) => (r - r_j).norm() < 1.0,
                    None => true,
                }
            })
        });
        if flat {
            c.plateau += 1;
        } else if chi2_j <= fit.chi2 + 1.0 {
            c.others.push((t_j.clone(), chi2_j));
        } else {
            c.worse += 1;
        }
    }
    c
}

/// What the restarts were and where they came from, for the uniqueness line.
pub(super) struct Restarts {
    /// Targets and free parameters.
    pub(super) m: usize,
    pub(super) n: usize,
    /// The restarts asked for (`FitOptions::restarts`).
    pub(super) asked: usize,
    /// Restarts run, counted as the report states them: the ends besides the first plus `failed`.
    pub(super) run: usize,
    /// Starts, and ends, that did not evaluate.
    pub(super) failed: usize,
    /// Points of the scan of the bounds (0 for no scan) and the local minima it seeded.
    pub(super) scan_points: usize,
    pub(super) seeds: usize,
    /// Halton starts.
    pub(super) halton: usize,
    /// Whether the fit reported is a restart's, not the solver's from the recipe's start.
    pub(super) chosen_restart: bool,
}

/// The verdict's line on uniqueness (none when no restart ran and nothing needs saying); `others` are the
/// other solutions in words.
pub(super) fn uniqueness(r: &Restarts, c: &Classes, others: &[String]) -> Option<String> {
    let (m, n) = (r.m, r.n);
    if m == n && r.asked == 0 {
        return Some(format!(
            "the fit is exactly determined ({m} target(s) for {n} free parameter(s)): the residuals vanish at any \
             exact solution, and whether another one exists is not checked (restarts 0)"
        ));
    }
    if r.run == 0 && r.scan_points == 0 {
        return None;
    }
    let mut from = Vec::new();
    if r.scan_points > 0 {
        from.push(format!(
            "{} local minim{} of χ² on a scan of the bounds ({} points in the fitted variables)",
            r.seeds,
            if r.seeds == 1 { "um" } else { "a" },
            r.scan_points
        ));
    }
    if r.halton > 0 {
        from.push(format!("{} deterministic Halton point(s) spread over the bounds", r.halton));
    }
    let mut line = if m == n {
        format!("the fit is exactly determined ({m} target(s) for {n} free parameter(s)); ")
    } else {
        String::new()
    };
    line.push_str(&format!("{} restart(s) from {}: {} returned to this solution", r.run, from.join(" and "), c.same));
    if r.chosen_restart {
        line.push_str(" (the solver from the recipe's start is one of the others: it stopped at a higher χ²)");
    }
    if c.plateau > 0 {
        line.push_str(&format!(
            ", {} stopped on a plateau (the readings do not change there: a flat region, not a minimum)",
            c.plateau
        ));
    }
    if c.worse > 0 {
        line.push_str(&format!(
            ", {} stopped at a worse χ² (a local minimum, or the end of a restart's budget, a quarter of the fit's)",
            c.worse
        ));
    }
    if r.failed > 0 {
        line.push_str(&format!(", {} started outside the model's constraints", r.failed));
    }
    if !others.is_empty() {
        line.push_str(&format!(
            ", {} found another solution that fits the targets as well: {}; the targets do not single out one recipe",
            others.len(),
            others.join("; ")
        ));
    } else {
        line.push_str("; no second solution was found from these starts (which does not prove there is none)");
    }
    Some(line)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Synthetic ends of a one-parameter fit at t = 0.5 ± 0.01 (χ² 0), with r(t) = 10·(t − 0.5)(t − 0.8) and
    /// a flat region r = 3 beyond t = 0.9: back at the fit, at the second root 0.8, on the plateau, at a
    /// worse point, and one that does not evaluate.
    #[test]
    fn ends_are_classified_on_synthetic_residuals() {
        let model = |t: f64| if t > 0.9 { 3.0 } else { 100.0 * (t - 0.5) * (t - 0.8) };
        let end = |t: f64| End { t: vec![t], r: Some(DVector::from_element(1, model(t))) };
        let ends = vec![end(0.5), end(0.505), end(0.8), end(0.97), end(0.3), End { t: vec![0.1], r: None }];
        let fit = Fit { t: &[0.5], chi2: 0.0, std_t: &[Some(0.01)], bounds: &[(0.0, 1.0)], widths: &[1.0] };
        let c = classify(&ends, 0, &fit, |t| Some(DVector::from_element(1, model(t[0]))));
        assert_eq!(c, Classes { same: 1, plateau: 1, worse: 1, failed: 1, others: vec![(vec![0.8], 0.0)] }, "{c:?}");
        let restarts = Restarts {
            m: 1,
            n: 1,
            asked: 2,
            run: 5,
            failed: 1,
            scan_points: 24,
            seeds: 2,
            halton: 0,
            chosen_restart: false,
        };
        let line = uniqueness(&restarts, &c, &["/a = 0.8 (χ² = 0.000)".to_string()]).unwrap();
        assert!(line.starts_with("the fit is exactly determined (1 target(s) for 1 free parameter(s)); 5 restart(s)"));
        assert!(line.contains("2 local minima of χ² on a scan of the bounds (24 points"), "{line}");
        assert!(line.contains("1 stopped on a plateau") && line.contains("1 stopped at a worse χ²"), "{line}");
        assert!(line.contains("1 started outside") && line.contains("1 found another solution"), "{line}");
    }

    #[test]
    fn no_restarts_for_an_exact_fit_says_uniqueness_is_not_checked() {
        let r = Restarts {
            m: 2,
            n: 2,
            asked: 0,
            run: 0,
            failed: 0,
            scan_points: 0,
            seeds: 0,
            halton: 0,
            chosen_restart: false,
        };
        assert!(uniqueness(&r, &Classes::default(), &[]).unwrap().contains("not checked (restarts 0)"));
        let r = Restarts { m: 3, ..r };
        assert_eq!(uniqueness(&r, &Classes::default(), &[]), None);
    }
}
