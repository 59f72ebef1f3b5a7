//! Reach (docs/inverse.md §Reach, §Goodness of fit): what the targets cannot determine, and what lies beyond
//! the model.
//!
//! * Every direction whose linear full-range move changes the weighted residuals by less than one
//!   uncertainty is probed at the two ends of the box along it: if the readings there do differ from the
//!   fit's by an uncertainty or more, the parameters are seen and the point is stationary in them (an extremum
//!   or a saddle of the readings, where a target beyond the model's reach leaves the solver), not
//!   undetermined ([`weak_directions`]).
//! * A fit the model cannot reproduce names its largest residuals, and for each whether it lies beyond every
//!   reading the model made at the points tried ([`cannot_reproduce`]).
use nalgebra::DVector;

use super::analysis::Direction;
use super::params::FreeParameter;
use super::report::FittedTarget;

/// The two ends of the box `bounds` in t along the line t + λ·dir (λ < 0 and λ > 0), or None for a zero
/// direction.
pub(super) fn across_box(t: &[f64], dir: &[f64], bounds: &[(f64, f64)]) -> Option<(Vec<f64>, Vec<f64>)> {
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    for (k, &(a, b)) in bounds.iter().enumerate() {
        if dir[k].abs() < 1e-300 {
            continue;
        }
        let (l1, l2) = ((a - t[k]) / dir[k], (b - t[k]) / dir[k]);
        lo = lo.max(l1.min(l2));
        hi = hi.min(l1.max(l2));
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let point = |l: f64| -> Vec<f64> {
        bounds.iter().enumerate().map(|(k, &(a, b))| (t[k] + l * dir[k]).clamp(a, b)).collect()
    };
    Some((point(lo), point(hi)))
}

/// What the weak directions say.
#[derive(Debug, Default)]
pub(super) struct Weak {
    /// The readings are stationary at the fit along a direction the targets do see.
    pub(super) stationary: bool,
    /// Some parameters, or a combination of them, are not determined.
    pub(super) undetermined: bool,
    /// One line per weak direction.
    pub(super) lines: Vec<String>,
}

/// The weak directions (singular value < 1) of the fit at t with weighted residuals r, each probed at the
/// ends of the box along it by `residuals_at` (an adaptive run; `None` where the model does not evaluate).
/// `second_solution`: the restarts found another solution (a curved valley of equally good fits).
pub(super) fn weak_directions(
    directions: &[Direction],
    t: &[f64],
    r: &DVector<f64>,
    free: &[FreeParameter],
    second_solution: bool,
    mut residuals_at: impl FnMut(&[f64]) -> Option<DVector<f64>>,
) -> Weak {
    let n = t.len();
    let bounds: Vec<(f64, f64)> = free.iter().map(|p| p.t_bounds()).collect();
    let widths: Vec<f64> = bounds.iter().map(|(a, b)| b - a).collect();
    let mut weak = Weak::default();
    for d in directions.iter().filter(|d| d.s < 1.0) {
        let (s, v) = (d.s, &d.v);
        let dir: Vec<f64> = (0..n).map(|k| v[k] * widths[k]).collect();
        let measured = across_box(t, &dir, &bounds).and_then(|(lo, hi)| {
            let mut most: Option<f64> = None;
            for end in [lo, hi] {
                if (0..n).all(|k| (end[k] - t[k]).abs() <= 1e-12 * widths[k]) {
                    continue;
                }
                let d = (residuals_at(&end)? - r).norm();
                most = Some(most.map_or(d, |m: f64| m.max(d)));
            }
            most
        });
        let involved: Vec<usize> = (0..n).filter(|&k| v[k].abs() >= 0.2).collect();
        let combo: Vec<String> = involved.iter().map(|&k| format!("{:+.2}·Δ{}", v[k], free[k].pointer)).collect();
        let log_note =
            if involved.iter().any(|&k| free[k].log) { ", in the logarithm for log: parameters" } else { "" };
        let names = involved.iter().map(|&k| free[k].pointer.as_str()).collect::<Vec<_>>().join(" and ");
        match measured {
            // With one parameter a direction seen at the ends of the bounds is an extremum (or a plateau's
            // edge); with several it may also be a curved valley of equally good fits, which is what it is
            // taken for when the restarts found another solution.
            Some(d) if d >= 1.0 && !(n >= 2 && second_solution) => {
                weak.stationary = true;
                weak.lines.push(format!(
                    "the readings are stationary at the fit along {} (each Δ in units of its bound width{log_note}): \
                     their local slope times the bound width is {s:.3} of their uncertainty, yet at the ends of the \
                     bounds that way they differ from the fit's by {d:.4} uncertainties; so the targets do see \
                     {names}, and this point is an extremum, a saddle or a plateau of the readings{}, where the \
                     linear error analysis gives no standard error",
                    combo.join(" "),
                    if n >= 2 {
                        ", or lies in a curved valley along which other parameter sets fit as well"
                    } else {
                        ""
                    },
                ));
            }
            _ => {
                weak.undetermined = true;
                let change = match measured {
                    Some(d) if d >= 1.0 => format!(
                        "by {s:.3} of their uncertainty to first order (the valley is curved: at the ends of the \
                         bounds that way they differ by {d:.4}, and the restarts found other solutions along it)"
                    ),
                    Some(d) => format!("by at most {d:.3} of their uncertainty (at the ends of the bounds)"),
                    None => format!("by {s:.3} of their uncertainty (the local slope times the bound width)"),
                };
                weak.lines.push(if involved.len() == 1 {
                    let p = &free[involved[0]];
                    format!(
                        "{} is not determined by these targets: moving it across its whole range {}..{}{} changes the \
                         readings {change}",
                        p.pointer,
                        p.lower,
                        p.upper,
                        if p.log { " (log)" } else { "" },
                    )
                } else {
                    format!(
                        "these targets cannot tell apart {names}: they fix only a combination; moving along {} (each Δ \
                         in units of its bound width{log_note}) changes the readings {change}",
                        combo.join(" "),
                    )
                });
            }
        }
    }
    weak
}

/// A point where the model was read: its t and its predicted values of the targets.
pub(super) struct Seen {
    pub(super) t: Vec<f64>,
    pub(super) values: Vec<f64>,
}

/// The verdict of a fit whose χ² the model cannot make probable (docs/inverse.md §Goodness of fit, §Reach):
/// χ², the degrees of freedom and p; the targets with the largest residuals; and, for each of those, whether
/// it lies beyond everything the model read at the points tried (`seen`: the scan of the bounds, of
/// `scanned` points, then the solver's ends): the extremum reached, where (`describe` of its t), and by how
/// many uncertainties it misses.
pub(super) fn cannot_reproduce(
    targets: &[FittedTarget],
    (chi2, dof, p_value): (f64, usize, Option<f64>),
    seen: &[Seen],
    scanned: usize,
    describe: &dyn Fn(&[f64]) -> String,
) -> Vec<String> {
    let mut out = Vec::new();
    let mut worst: Vec<usize> = (0..targets.len()).filter(|&i| targets[i].weighted_residual.abs() > 1.0).collect();
    worst.sort_by(|&a, &b| targets[b].weighted_residual.abs().total_cmp(&targets[a].weighted_residual.abs()));
    worst.truncate(3);
    let named: Vec<String> = worst
        .iter()
        .map(|&i| {
            let t = &targets[i];
            format!(
                "{}/{} = {} ± {} predicted {:.4} ({:+.1} uncertainties)",
                t.target.geometry, t.target.name, t.target.value, t.uncertainty, t.predicted, t.weighted_residual
            )
        })
        .collect();
    let how = match p_value {
        Some(p) => format!("χ² = {chi2:.4} for {dof} degree(s) of freedom, p = {p:.2e} < {}", super::P_THRESHOLD),
        None => format!(
            "the fit is exactly determined (no degrees of freedom) and still misses a target by more than its \
             uncertainty (χ² = {chi2:.4})"
        ),
    };
    out.push(format!(
        "the model cannot reproduce these readings: {how}; largest residuals: {}",
        if named.is_empty() { "none above one uncertainty".to_string() } else { named.join(", ") }
    ));
    let where_ = if scanned == 0 {
        "at the points tried (the fit and its restarts)".to_string()
    } else {
        format!("over a scan of the bounds ({scanned} points) and the fits")
    };
    for &i in &worst {
        let Some(hi) = seen.iter().max_by(|a, b| a.values[i].total_cmp(&b.values[i])) else { continue };
        let Some(lo) = seen.iter().min_by(|a, b| a.values[i].total_cmp(&b.values[i])) else { continue };
        let (hi_v, lo_v) = (hi.values[i], lo.values[i]);
        let t = &targets[i];
        let sigma = t.uncertainty.hypot(t.prediction_error);
        let (extreme, side, word) = if t.target.value > hi_v {
            (hi, (t.target.value - hi_v) / sigma, "largest")
        } else if t.target.value < lo_v {
            (lo, (lo_v - t.target.value) / sigma, "smallest")
        } else {
            if scanned > 0 {
                out.push(format!(
                    "{}/{} = {} alone is within the model's reach ({where_} it reads {lo_v:.4} to {hi_v:.4}), but not \
                     together with the other targets",
                    t.target.geometry, t.target.name, t.target.value
                ));
            }
            continue;
        };
        if side <= 1.0 {
            continue;
        }
        out.push(format!(
            "{}/{} = {} ± {} is beyond the model's reach {where_}: its {word} reading there is {:.4}, at {}, {:.1} \
             uncertainties short",
            t.target.geometry,
            t.target.name,
            t.target.value,
            t.uncertainty,
            extreme.values[i],
            describe(&extreme.t),
            side
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::analysis::Direction;
    use super::super::params::TargetReading;
    use super::*;

    fn free(pointer: &str) -> FreeParameter {
        FreeParameter { pointer: pointer.into(), lower: 0.0, upper: 1.0, log: false }
    }

    #[test]
    fn the_box_is_crossed_along_a_direction() {
        let (lo, hi) = across_box(&[0.5, 0.5], &[1.0, 0.5], &[(0.0, 1.0), (0.0, 1.0)]).unwrap();
        assert_eq!((lo, hi), (vec![0.0, 0.25], vec![1.0, 0.75]));
        assert!(across_box(&[0.5], &[0.0], &[(0.0, 1.0)]).is_none());
    }

    /// One weak direction of a fit at t = 0.5: readings that do not change across the box (undetermined), and
    /// readings that change by 3 uncertainties at the ends (stationary: an extremum the targets do see).
    #[test]
    fn a_weak_direction_is_undetermined_or_stationary() {
        let d = [Direction { s: 0.01, v: vec![1.0] }];
        let r = DVector::from_element(1, 0.0);
        let flat = weak_directions(&d, &[0.5], &r, &[free("/a")], false, |_| Some(DVector::from_element(1, 0.2)));
        assert!(flat.undetermined && !flat.stationary, "{flat:?}");
        assert!(flat.lines[0].starts_with("/a is not determined") && flat.lines[0].contains("at most 0.200"));
        let peak = weak_directions(&d, &[0.5], &r, &[free("/a")], false, |t| {
            Some(DVector::from_element(1, 12.0 * (t[0] - 0.5).powi(2)))
        });
        assert!(peak.stationary && !peak.undetermined, "{peak:?}");
        assert!(peak.lines[0].contains("differ from the fit's by 3.0000 uncertainties"), "{:?}", peak.lines);
        // A second solution with two parameters: the curved valley is read as undetermined.
        let d2 = [Direction { s: 0.01, v: vec![0.6, 0.8] }, Direction { s: 5.0, v: vec![0.8, -0.6] }];
        let r2 = DVector::from_element(1, 0.0);
        let two = weak_directions(&d2, &[0.5, 0.5], &r2, &[free("/a"), free("/b")], true, |_| {
            Some(DVector::from_element(1, 5.0))
        });
        assert!(two.undetermined && two.lines.len() == 1 && two.lines[0].contains("cannot tell apart /a and /b"));
    }

    #[test]
    fn a_target_beyond_everything_read_is_named_with_its_extremum() {
        let target = |v: f64, p: f64| FittedTarget {
            target: TargetReading { geometry: "g".into(), name: "gloss".into(), value: v, uncertainty: None },
            uncertainty: 0.5,
            predicted: p,
            prediction_error: 0.0,
            residual: p - v,
            colour: None,
            weighted_residual: (p - v) / 0.5,
        };
        let seen = [Seen { t: vec![0.1], values: vec![40.0] }, Seen { t: vec![0.9], values: vec![50.0] }];
        let lines =
            cannot_reproduce(&[target(60.0, 50.0)], (400.0, 0, None), &seen, 2, &|t: &[f64]| format!("/a = {}", t[0]));
        assert_eq!(lines.len(), 2, "{lines:?}");
        assert!(lines[0].contains("exactly determined") && lines[0].contains("g/gloss = 60 ± 0.5 predicted 50.0000"));
        assert!(
            lines[1].contains("largest reading there is 50.0000, at /a = 0.9, 20.0 uncertainties short"),
            "{lines:?}"
        );
        let inside =
            cannot_reproduce(&[target(45.0, 50.0)], (100.0, 1, Some(1e-9)), &seen, 2, &|_: &[f64]| String::new());
        assert!(inside[1].contains("alone is within the model's reach"), "{inside:?}");
    }
}
