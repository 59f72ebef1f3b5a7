//! The reading formulas, in one place: a reading's value and first-order error from its fluxes (gloss,
//! haze, log-haze, compensated haze, DOI, profile, colour) or from the readings it combines (haze index).
use crate::colorimetry::weighting::WeightingKind;
use crate::colorimetry::{cielab, Conditions};
use crate::instrument::method::Flux;
use crate::instrument::reading::{ColourQuantity, ReadingSpec};

use super::{Job, Plan, PlannedReading, Reading};

/// A reading with a value `(v, e)`, no problem and no note (callers override those with struct update).
fn valued_reading(
    r: &PlannedReading,
    (v, e): (f64, f64),
    evaluations: usize,
    seconds: f64,
    converged: bool,
) -> Reading {
    Reading {
        geometry: r.geometry.clone(),
        name: r.name.clone(),
        quantity: r.spec.quantity().into(),
        unit: r.spec.unit().into(),
        value: Some(v),
        error_estimate: e,
        evaluations,
        seconds,
        converged,
        problem: None,
        note: None,
        data_uncertainty: None,
        colour: r.kind.conditions(),
    }
}

fn problem_reading(r: &PlannedReading, why: String) -> Reading {
    Reading {
        geometry: r.geometry.clone(),
        name: r.name.clone(),
        quantity: r.spec.quantity().into(),
        unit: r.spec.unit().into(),
        value: None,
        error_estimate: f64::NAN,
        evaluations: 0,
        seconds: 0.0,
        converged: false,
        problem: Some(why),
        note: None,
        data_uncertainty: None,
        colour: r.kind.conditions(),
    }
}

/// The value and first-order error of a direct (non-composite) reading from its fluxes, each given as
/// (value, error) by receptor name: the definitions of the readings (`ReadingSpec`), in one place. Err says
/// why there is no value (a zero reference flux).
pub(crate) fn reading_value(
    spec: &ReadingSpec,
    specimen: &dyn Fn(&str) -> (f64, f64),
    standard: &dyn Fn(&str) -> (f64, f64),
) -> std::result::Result<(f64, f64), String> {
    let mean = |rxs: &[String]| -> (f64, f64) {
        let n = rxs.len() as f64;
        (rxs.iter().map(|x| specimen(x).0).sum::<f64>() / n, rxs.iter().map(|x| specimen(x).1).sum::<f64>() / n)
    };
    match spec {
        ReadingSpec::Gloss { receptor } => {
            let ((s, se), (d, de)) = (specimen(receptor), standard(receptor));
            ratio(s, se, d, de, Denominator::Standard).map(|(v, e)| (100.0 * v, 100.0 * e))
        }
        ReadingSpec::Profile { receptor, reference } => {
            let ((s, se), (d, de)) = (specimen(receptor), standard(reference));
            ratio(s, se, d, de, Denominator::Standard).map(|(v, e)| (100.0 * v, 100.0 * e))
        }
        ReadingSpec::Haze { receptors, specular } => {
            let (h, he) = mean(receptors);
            let (d, de) = standard(specular);
            ratio(h, he, d, de, Denominator::Standard).map(|(v, e)| (100.0 * v, 100.0 * e))
        }
        ReadingSpec::LogHaze { receptors, specular, k } => {
            let (h, he) = mean(receptors);
            let (d, de) = standard(specular);
            ratio(h, he, d, de, Denominator::Standard).map(|(v, e)| {
                let (h, he) = (100.0 * v, 100.0 * e);
                (k * (h / 20.0 + 1.0).log10(), k * he / (std::f64::consts::LN_10 * (h + 20.0)))
            })
        }
        ReadingSpec::HazeCompensated { receptors, specular, compensation, factor } => {
            compensated_haze(mean(receptors), specimen(compensation), *factor, standard(specular))
        }
        ReadingSpec::LogHazeCompensated { receptors, specular, compensation, factor, k } => {
            let (h, he) = compensated_haze(mean(receptors), specimen(compensation), *factor, standard(specular))?;
            if !(h > -20.0) {
                return Err(format!(
                    "the compensated linear haze {} is at or below −20, where K·log10(H/20 + 1) has no value (the \
                     compensation receptor sees more diffuse light than the haze receptors, relative to a \
                     Lambertian body)",
                    crate::error::number(h)
                ));
            }
            Ok((k * (h / 20.0 + 1.0).log10(), k * he / (std::f64::consts::LN_10 * (h + 20.0))))
        }
        ReadingSpec::Doi { specular, offset } => {
            let (s, se) = specimen(specular);
            let (o, oe) = mean(offset);
            ratio(o, oe, s, se, Denominator::SpecimenSpecular).map(|(v, e)| (100.0 * (1.0 - v), 100.0 * e))
        }
        ReadingSpec::HazeIndex { .. } => Err("a composite reading has no fluxes of its own".into()),
        ReadingSpec::Colour { .. } => Err("a colour reading needs X, Y, Z (plan::colour_xyz)".into()),
    }
}

/// Compensated linear haze H_c = 100·(Φ_h − c·Φ_c)/Φ_std from the mean haze flux Φ_h, the compensation
/// receptor's flux Φ_c, the factor c and the standard's specular flux, each (value, error); the errors add
/// (first order, the numerator's error is e_h + c·e_c).
fn compensated_haze(
    (h, he): (f64, f64),
    (c, ce): (f64, f64),
    factor: f64,
    (d, de): (f64, f64),
) -> std::result::Result<(f64, f64), String> {
    ratio(h - factor * c, he + factor * ce, d, de, Denominator::Standard).map(|(v, e)| (100.0 * v, 100.0 * e))
}

/// The value and error of a haze index (ASTM D4039) from its two gloss readings' (value, error).
pub(crate) fn haze_index_value(minuend: (f64, f64), subtrahend: (f64, f64)) -> (f64, f64) {
    (minuend.0 - subtrahend.0, minuend.1 + subtrahend.1)
}

/// The offset of a reading's weighting kind in job j's weighting.
fn component_of(r: &PlannedReading, jobs: &[Job], j: usize) -> usize {
    jobs[j].method.weighting.offset(r.kind).expect("a job's weighting has the kinds of the readings that use it")
}

/// X, Y, Z of a colour reading: Σ sign·Φ_XYZ over its integrals, ÷ the perfect diffuser's flux, with the
/// summed error bounds (a difference's bound is the sum of the bounds).
pub(crate) fn colour_xyz(
    terms: &[(String, f64)],
    white: f64,
    flux: &dyn Fn(&str, usize) -> (f64, f64),
) -> ([f64; 3], [f64; 3]) {
    let mut xyz = [0.0; 3];
    let mut err = [0.0; 3];
    for (name, sign) in terms {
        for c in 0..3 {
            let (v, e) = flux(name, c);
            xyz[c] += sign * v;
            err[c] += e;
        }
    }
    (xyz.map(|x| x / white), err.map(|e| e / white))
}

/// The hue of a neutral colour, undefined by definition (not a failure): its chroma, at or below the floor
/// [`neutral_chroma`] gives (docs/colour.md §Neutral colours). Its `Display` is the reading's note, which
/// starts with [`NEUTRAL_HUE`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct NeutralHue {
    pub chroma: f64,
    pub floor: f64,
}

impl std::fmt::Display for NeutralHue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{NEUTRAL_HUE} (C*ab = {:.2e} ≤ {:.2e}, a chroma the integration cannot tell from 0): the hue angle is \
             undefined",
            self.chroma, self.floor
        )
    }
}

/// Why a direct reading has no value: undefined by definition (the hue of a neutral colour), or a problem.
enum NoValue {
    NeutralHue(NeutralHue),
    Problem(String),
}

/// A colour quantity and its error bound from X, Y, Z (`docs/colour.md`: L*, a*, b* by intervals, C*ab and
/// hab from the a*b* box). Err for the hue of a neutral colour (C*ab = 0), which is undefined.
pub(crate) fn colour_value(
    q: ColourQuantity,
    xyz: [f64; 3],
    err: [f64; 3],
    white: [f64; 3],
) -> std::result::Result<(f64, f64), NeutralHue> {
    let lab = cielab::xyz_to_lab(xyz, white);
    let le = cielab::lab_errors(xyz, err, white);
    let lch = cielab::lab_to_lch(lab);
    let (ec, eh) = cielab::lch_errors(lab, le[1], le[2]);
    Ok(match q {
        ColourQuantity::X => (xyz[0], err[0]),
        ColourQuantity::Y => (xyz[1], err[1]),
        ColourQuantity::Z => (xyz[2], err[2]),
        ColourQuantity::L => (lab.l, le[0]),
        ColourQuantity::A => (lab.a, le[1]),
        ColourQuantity::B => (lab.b, le[2]),
        ColourQuantity::C => (lch.c, ec),
        ColourQuantity::H => match lch.h {
            Some(h) if lch.c > neutral_chroma(ec) => (h, eh),
            _ => return Err(NeutralHue { chroma: lch.c, floor: neutral_chroma(ec) }),
        },
    })
}

/// How the hue reading of a neutral colour explains its missing value: the first words of its note.
pub(crate) const NEUTRAL_HUE: &str = "neutral colour";

/// The rounding floor of C*ab: L*a*b* values of order 100 computed in double precision carry ~10⁻¹³ of
/// rounding, so a chroma below 10⁻⁹ is noise whatever the integration's error (docs/colour.md §Neutral colours).
pub(crate) const NEUTRAL_CHROMA_FLOOR: f64 = 1e-9;

/// The chroma at or below which a colour is neutral and its hue undefined: 3 × the chroma's error estimate
/// (the error ellipse of (a*, b*) then reaches the origin, so the integration does not determine the hue;
/// docs/colour.md §Neutral colours), and never below [`NEUTRAL_CHROMA_FLOOR`].
pub(crate) fn neutral_chroma(chroma_error: f64) -> f64 {
    (3.0 * chroma_error).max(NEUTRAL_CHROMA_FLOOR)
}

/// The value of a direct reading and the first-order propagation of what `spread(flux, component, is
/// standard)` gives each flux component: its numerical error, or its data uncertainty.
fn direct_value(
    r: &PlannedReading,
    flux: &[Flux],
    jobs: &[Job],
    white_point: Option<(Conditions, [f64; 3])>,
    spread: &dyn Fn(&Flux, usize, bool) -> f64,
) -> std::result::Result<(f64, f64), NoValue> {
    let specimen = |rx: &str| {
        let j = r.specimen_jobs[rx];
        let c = component_of(r, jobs, j);
        (flux[j].value[c], spread(&flux[j], c, false))
    };
    let standard = |rx: &str| {
        let f = &flux[r.standard_jobs[rx]];
        (f.value[0], spread(f, 0, true))
    };
    match (&r.spec, r.kind) {
        (ReadingSpec::Colour { quantity, terms, white }, WeightingKind::Xyz(cond)) => {
            let (xyz, err) = colour_xyz(terms, *white, &|rx, k| {
                let j = r.specimen_jobs[rx];
                let c = component_of(r, jobs, j) + k;
                (flux[j].value[c], spread(&flux[j], c, false))
            });
            match white_point {
                Some((c, w)) if c == cond => colour_value(*quantity, xyz, err, w).map_err(NoValue::NeutralHue),
                _ => Err(NoValue::Problem("no white point for these colour conditions".into())),
            }
        }
        _ => reading_value(&r.spec, &specimen, &standard).map_err(NoValue::Problem),
    }
}

/// Combine fluxes into a direct reading, with first-order error propagation.
fn compute_reading(
    r: &PlannedReading,
    flux: &[Flux],
    jobs: &[Job],
    white_point: Option<(Conditions, [f64; 3])>,
) -> Reading {
    let used: Vec<&Flux> = r.specimen_jobs.values().chain(r.standard_jobs.values()).map(|&j| &flux[j]).collect();
    let evaluations = used.iter().map(|f| f.evaluations).sum();
    let seconds = used.iter().map(|f| f.seconds).sum();
    let converged = used.iter().all(|f| f.converged);
    let out_of_time = used.iter().any(|f| f.out_of_time);
    if out_of_time {
        // A value cut off by the clock would depend on the machine's speed and load: none is reported
        // (docs/instrument.md §Bounded work).
        let why = "the wall-clock limit was reached before the tolerance was met; no value is reported, since it \
                   would depend on the machine's speed and load (the evaluation budget is the deterministic bound)";
        // The work done is reported as it was: only the value is withheld.
        return Reading { evaluations, seconds, ..problem_reading(r, why.into()) };
    }
    if let Some(why) = used.iter().find_map(|f| f.refused.clone()) {
        // A far field that refused this receptor (docs/optics.md §11.4): no value, the reason as the problem.
        return Reading { evaluations, seconds, ..problem_reading(r, why) };
    }
    let value = direct_value(r, flux, jobs, white_point, &|f, c, _| f.error[c]);
    // The data uncertainty: the same first-order propagation with each specimen flux's data uncertainty in
    // place of its error, and none on the standards' (analytic) fluxes.
    let data = r.specimen_jobs.values().any(|&j| flux[j].data_uncertainty.is_some()).then(|| {
        direct_value(r, flux, jobs, white_point, &|f, c, standard| match (&f.data_uncertainty, standard) {
            (Some(u), false) => u[c],
            _ => 0.0,
        })
    });
    let data_uncertainty = match data {
        Some(Ok((_, u))) if u.is_finite() => Some(u),
        _ => None,
    };
    match value {
        Ok((v, e)) if v.is_finite() && e.is_finite() && e >= 0.0 => Reading {
            data_uncertainty,
            problem: (!converged).then(|| {
                if used.iter().any(|f| f.budget_spent) {
                    "evaluation budget exhausted before the tolerance was met (the value is the best estimate)".into()
                } else {
                    "the frozen method (a kept partition, applied without refinement) does not meet the tolerance \
                     here; no larger evaluation budget changes it (the value is its estimate)"
                        .into()
                }
            }),
            ..valued_reading(r, (v, e), evaluations, seconds, converged)
        },
        Ok((v, _)) => problem_reading(r, no_finite_value(v)),
        // The hue of a neutral colour has no value by definition, not by failure: null, with the reason as
        // its note, converged as its fluxes are (it changes no exit status).
        Err(NoValue::NeutralHue(hue)) => Reading {
            value: None,
            error_estimate: 0.0,
            problem: None,
            note: Some(hue.to_string()),
            ..valued_reading(r, (0.0, 0.0), evaluations, seconds, converged)
        },
        Err(NoValue::Problem(why)) => problem_reading(r, why),
    }
}

/// A composite reading (haze index) from the readings it combines.
fn compose_reading(r: &PlannedReading, done: &[Option<Reading>]) -> Reading {
    let (Some(a), Some(b)) = (&done[r.parts[0]], &done[r.parts[1]]) else {
        return problem_reading(r, "a gloss reading it combines was not computed".into());
    };
    let (Some(x), Some(y)) = (a.value, b.value) else {
        return problem_reading(r, "a gloss reading it combines has no value".into());
    };
    let (v, e) = haze_index_value((x, a.error_estimate), (y, b.error_estimate));
    if !(v.is_finite() && e.is_finite()) {
        return problem_reading(r, "non-finite result".into());
    }
    let data_uncertainty = match (a.data_uncertainty, b.data_uncertainty) {
        (None, None) => None,
        (ua, ub) => Some(haze_index_value((x, ua.unwrap_or(0.0)), (y, ub.unwrap_or(0.0))).1),
    };
    Reading {
        data_uncertainty,
        note: (x <= 70.0 || v < 0.0).then(|| {
            "outside the scope of ASTM D4039, which is defined for non-metallic specimens with G60 > 70 (a negative \
             index means the 20° receptor gathers relatively more than the 60° one, as for near-mirror flakes)"
                .to_string()
        }),
        ..valued_reading(r, (v, e), a.evaluations + b.evaluations, a.seconds + b.seconds, a.converged && b.converged)
    }
}

/// What the denominator of a reading's ratio is, for the message when it is zero.
#[derive(Clone, Copy)]
enum Denominator {
    /// The gloss standard's specular flux (gloss, haze, log-haze).
    Standard,
    /// The specimen's own specular flux (DOI).
    SpecimenSpecular,
}

/// a/b with first-order error |a/b|·(ea/|a| + eb/|b|) written without dividing by a. The error term is
/// computed as a·eb/b² and, where b² underflows (fluxes near 1e-160 and below), as (a/b)·(eb/b), which has
/// no underflow; the first form is kept where it is finite so that no reading's bits move.
fn ratio(a: f64, ea: f64, b: f64, eb: f64, den: Denominator) -> std::result::Result<(f64, f64), String> {
    if !(b > 0.0) {
        return Err(match den {
            Denominator::Standard => {
                "the gloss standard's flux is zero: the stops do not see the mirror direction (below the horizon?)"
                    .into()
            }
            Denominator::SpecimenSpecular => "the specimen reflects no flux into the specular receptor, so DOI = \
                 100·(1 − offset/specular) is undefined (a black or mirror-less specimen has no image to be distinct)"
                .into(),
        });
    }
    let e = ea / b + a.abs() * eb / (b * b);
    let e = if e.is_finite() { e } else { ea / b + (a.abs() / b) * (eb / b) };
    Ok((a / b, e))
}

impl Plan {
    /// The readings from the fluxes of every job. Direct readings first, then composites, which combine
    /// direct readings (their parts may come later in plan order when the user asked for the composite
    /// before its parts, or only for it).
    pub(super) fn readings_from(&self, flux: &[Flux]) -> Vec<Reading> {
        let mut out: Vec<Option<Reading>> = vec![None; self.readings.len()];
        for (i, r) in self.readings.iter().enumerate() {
            if r.parts.is_empty() {
                out[i] = Some(compute_reading(r, flux, &self.jobs, self.white_point));
            }
        }
        for (i, r) in self.readings.iter().enumerate() {
            if !r.parts.is_empty() {
                out[i] = Some(compose_reading(r, &out));
            }
        }
        out.into_iter()
            .zip(&self.readings)
            .filter(|(_, p)| p.reported)
            .map(|(r, _)| r.expect("every reading computed"))
            .collect()
    }
}

/// Why a reading whose formula gave the value `v` from its fluxes (with an error estimate that is not a
/// finite number ≥ 0, if `v` is finite) has no value, in words: never a NaN, an infinity or a negative error
/// estimate printed as if it were a number (docs/instrument.md §Numbers in text).
fn no_finite_value(v: f64) -> String {
    let what = if v.is_nan() {
        "an undefined result (0/0, ∞ − ∞ or the logarithm of a negative number)".to_string()
    } else if v.is_infinite() {
        "an overflow".to_string()
    } else {
        format!("the value {} with an error estimate that is not a finite number ≥ 0", crate::error::number(v))
    };
    format!("the reading's formula gives {what} from these fluxes; they are out of its range")
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_reading_without_a_finite_value_says_why_without_printing_nan() {
        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e-300] {
            let m = super::no_finite_value(v);
            for bad in ["NaN", "inf", "0000000000"] {
                assert!(!m.contains(bad), "{m}");
            }
        }
        assert!(super::no_finite_value(1e-300).contains("1e-300"));
    }
}
