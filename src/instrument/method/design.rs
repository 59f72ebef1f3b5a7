//! Design: how [`Method::design`] turns the facts about one integral into a [`Method`] — the clipped stops,
//! the mirror overlap, the kink cuts, the chart, the initial partition, the tolerance split — and which
//! shaped rule it tries before the Genz–Malik partition ([`delta_rule`], [`lobe_rule`], [`polar_rule`],
//! [`smooth_rule`], tried in that order; [`Rule::TailBound`] where the partition would run on a receptor that
//! does not see the mirror image), with the gates that decide.
use super::delta::DELTA_COST;
#[cfg(doc)]
use super::gauss::TENSOR_MAX_LEVEL;
use super::gauss::{tensor_boxes, LOBE_LEVELS};
use super::polar::{POLAR_LEVELS, TAIL_LEVELS};
use super::{Aperture, DeltaPart, Design, MaterialFacts, Method, Projection, RegularPart, Rule, Target};
use crate::brdf::{Brdf, Tail};
use crate::colorimetry::weighting::Weighting;
use crate::instrument::aperture::{
    choose_chart, clip, delta_kinks, lobe_boxes, lobe_splits, mirror_overlap, regular_kinks, regular_kinks_between,
    AxisMap, Chart, LobesAt, DELTA_SHARE,
};
use crate::instrument::geometry::{Integral, Stop};
use crate::quadrature::{tensor, Cell, Refine};

/// How far (in lobe widths, on both axes and both sides) the overlap kinks must be from the lobe centre for
/// [`Rule::LobePolar`]: the polar piece then holds the peak and the tail pieces only the tail.
pub(crate) const POLAR_REACH: f64 = 2.0;

/// At geometry angles of [`POLAR_GRAZING`] and above, [`Rule::LobePolar`] needs the overlap kinks and range
/// ends at least [`POLAR_REACH_GRAZING`] lobe widths from the centre on the u axis (the plane of incidence).
/// Near grazing the geometric factors vary across the stops (z ∝ cos θ ∓ p sin θ: ±40 % over D523 85°'s
/// receptor), a smooth variation the polar square resolves only at high levels when the square spans few
/// widths. Measured at D523 85°, n = 1.5, rtol 10⁻⁶ (polar against the Genz–Malik partition of the same
/// lobe chart, exact evaluation counts; `docs/instrument.md` §Quadrature): GGX α = 0.001, 0.0013, 0.0016
/// (u reach 14.2, 10.9, 8.9 widths) 29 536 against 39 216, 38 304, 34 998; α = 0.002, 0.003, 0.005 (7.1,
/// 4.7, 2.8 widths) 80 736, 80 736, 87 136 against 32 832, 28 386, 25 308. At TAPPI T480 75° (u reach 4.4–7.0)
/// and at 20°–60° the polar rule won at every α tried down to [`POLAR_REACH`].
pub(crate) const POLAR_REACH_GRAZING: f64 = 8.0;
/// See [`POLAR_REACH_GRAZING`]: 80°, between TAPPI T480's 75° and D523's 85°.
pub(crate) const POLAR_GRAZING: f64 = 80.0 * std::f64::consts::PI / 180.0;

/// [`Rule::TensorGauss`] is chosen ([`smooth_rule`]) when every lobe is at least [`TENSOR_MIN_WIDTH_U`]
/// times the u-range wide (smooth in the plane of incidence) and between [`TENSOR_MIN_WIDTH`] and
/// [`TENSOR_MAX_WIDTH_V`] of the v-range (a lobe the v axis must resolve, but not so narrow that its order
/// passes [`TENSOR_MAX_LEVEL`]). The bounds are where the rule was measured to cost fewer evaluations than the
/// calibrated Genz–Malik partition on the shipped fixtures (`docs/instrument.md` §Quadrature): B4's GGX
/// α = 0.3 at 85° (7.2 × the u-range, 0.35 of the v-range) 2 159 against 2 639; it cost more at every
/// other wide-lobe integral tried (B4 at 75°: 2.9 and 0.63, 2 204 against 986; GGX α = 0.3 conductor at
/// 60°: 4.5 and 0.81, 3 023 against 872; Blinn–Phong at 20°: 2.0 and 0.79, 1 574 against 530).
pub(crate) const TENSOR_MIN_WIDTH: f64 = 0.25;
/// See [`TENSOR_MIN_WIDTH`].
pub(crate) const TENSOR_MAX_WIDTH_V: f64 = 0.5;
/// See [`TENSOR_MIN_WIDTH`].
pub(crate) const TENSOR_MIN_WIDTH_U: f64 = 4.0;

/// [`Rule::TensorGauss`] is chosen ([`smooth_rule`]) only at reading tolerances of [`TENSOR_MAX_RTOL`] and
/// below: at 10⁻⁴ its estimate, from the few levels it stops at, fell below its actual error on the Rhopoint IQ
/// 20° R_spec receptor for three of the 240 generated recipes (1.34×, 3.2× and 38×), while at 10⁻⁶ and 10⁻⁸
/// none did (`docs/instrument.md` §Quadrature, "When it is chosen"; 10⁻⁵ not measured, so not allowed).
pub(crate) const TENSOR_MAX_RTOL: f64 = 1e-6;

/// How far (in lobe widths) the nearest overlap kink or range end must be from the lobe centre, on both
/// axes, for [`Rule::LobeGaussHermite`]: the largest node of the 16-point rule is at 4.69 widths, and the
/// Gaussian is below e⁻⁶⁴ of its peak at 8.
pub(crate) const LOBE_REACH: f64 = 8.0;

/// The design-time gate of [`delta_rule`]: a majorant of [`Rule::LobeDelta`] relative to the reading, per
/// squared lobe width, above the 50–270 measured at 20°, 60°, E430 and ISO 13803 (at 85°, ≈ 1.8·10⁴, the
/// rule is tried and may refuse itself; `docs/instrument.md` §Quadrature). Only a gate: the majorant itself
/// is computed at run time.
pub(crate) const DELTA_GATE: f64 = 1.0e3;

/// How near the lobe centre (in the lobe's widths, its distribution's own scale) a receptor must come for
/// [`Rule::TailBound`] not to be designed: within it the lobe's distribution at the receptor's nearest
/// direction is at least e⁻⁴ of its peak (Beckmann; GGX's 1/(1 + x²)² holds 1/25 there), so no majorant can
/// settle the receptor below the floor and the check would only fall back (ASTM E430's DOI receptors, 0.3° off
/// specular, 0.1° beyond the stops' edges: 0.3 widths of a Beckmann m = 0.003 lobe). A gate at design time:
/// the bound itself is decided at run time.
pub(crate) const TAIL_REACH: f64 = 2.0;

/// Whether a lobe of `l` reaches the receptor: the distance of the lobe centre (u = v = 0, the mirror image)
/// from the nearest point of the lobe variables' ranges u = p_s + p_r, v = q_s + q_r, in the lobe's widths,
/// is below [`TAIL_REACH`] for some lobe. Off the mirror axis (a receptor whose axis is turned in the plane
/// of incidence) the in-plane gap is the angle between the receptor's axis and the mirror direction less the
/// two stops' in-plane half extents.
fn lobe_reaches(l: &LobesAt, a: &Aperture, src: Stop, rec: Stop) -> bool {
    let half = |s: Stop| s.p[0].abs().max(s.p[1].abs()).atan();
    let gap_u = if a.viewing == a.theta {
        AxisMap { s: src.p, r: rec.p }.gap()
    } else {
        ((a.viewing - a.theta).abs() - half(src) - half(rec)).max(0.0)
    };
    let gap_v = AxisMap { s: src.q, r: rec.q }.gap();
    l.widths.iter().any(|w| (gap_u / w[0]).hypot(gap_v / w[1]) < TAIL_REACH)
}

impl Method {
    /// Design the method of one integral.
    pub(crate) fn design(d: Design<'_>) -> Method {
        let (a, facts) = (d.aperture, d.facts);
        let clipped = match (clip(a.source, a.theta, true), clip(a.receptor, a.viewing, false)) {
            (Some(s), Some(r)) if a.integral == Integral::Aperture => Some((s, r)),
            _ => None,
        };
        // The mirror image is only ever seen by a receptor on the mirror axis.
        let on_mirror_axis = a.viewing == a.theta;
        let mirror = clipped.filter(|_| on_mirror_axis).and_then(|(s, r)| mirror_overlap(s, r));
        let delta_share = if facts.has_regular { DELTA_SHARE } else { 1.0 };
        let delta = match (facts.has_delta, mirror) {
            (true, Some((lo, hi))) => {
                let kinks = delta_kinks(&facts.kinks, a.theta, Stop { p: [lo[0], hi[0]], q: [lo[1], hi[1]] });
                let boxes = if kinks.is_empty() {
                    vec![(lo, hi)]
                } else {
                    let m = (kinks.len() + 1) as f64;
                    (0..=kinks.len()).map(|j| ([j as f64 / m, lo[1]], [(j + 1) as f64 / m, hi[1]])).collect()
                };
                Some(DeltaPart {
                    rule: Rule::GenzMalik75,
                    kinks,
                    cells: Cell::from_boxes(&boxes),
                    refine: Refine::Adaptive,
                    rtol: delta_share * d.rtol,
                    atol: delta_share * d.atol,
                })
            }
            _ => None,
        };
        let regular = match (facts.has_regular, clipped) {
            (true, Some((src, rec))) => {
                // Off the mirror axis no lobe is centred in the stops: the plain variables, with p_s cut at the
                // kinks there (`RegularPart::kinks`).
                let kinks = if on_mirror_axis {
                    regular_kinks(&facts.kinks, a.theta, src, rec)
                } else {
                    regular_kinks_between(&facts.kinks, a.theta + a.viewing, src, rec)
                };
                // The lobes' widths at this angle, once for the chart, the splits and every rule chooser.
                let l = LobesAt::new(&facts.lobes, a.theta, facts.has_diffuse);
                let chart = if !on_mirror_axis {
                    Chart::Plain
                } else if kinks.is_empty() {
                    choose_chart(&l, src, rec)
                } else {
                    Chart::Lobe
                };
                let (splits, boxes) = match chart {
                    Chart::Lobe | Chart::PlainPLobeQ => {
                        let splits = lobe_splits(&l, src, rec);
                        let boxes = kinked_boxes(lobe_boxes(&splits), kinks.len());
                        (splits, boxes)
                    }
                    Chart::Plain if kinks.is_empty() => (
                        [vec![], vec![]],
                        vec![([src.p[0], src.q[0], rec.p[0], rec.q[0]], [src.p[1], src.q[1], rec.p[1], rec.q[1]])],
                    ),
                    // The first axis is the kinked position t ∈ [0, 1] of p_s (`aperture::kinked_position`).
                    Chart::Plain => {
                        let m = (kinks.len() + 1) as f64;
                        let boxes = (0..=kinks.len())
                            .map(|j| {
                                (
                                    [j as f64 / m, src.q[0], rec.p[0], rec.q[0]],
                                    [(j + 1) as f64 / m, src.q[1], rec.p[1], rec.q[1]],
                                )
                            })
                            .collect();
                        ([vec![], vec![]], boxes)
                    }
                };
                let share = 1.0 - DELTA_SHARE;
                let rule = match chart {
                    Chart::Lobe if kinks.is_empty() && on_mirror_axis => delta_rule(&l, src, rec, share * d.rtol)
                        .or_else(|| lobe_rule(&l, src, rec))
                        .or_else(|| polar_rule(&l, src, rec))
                        .or_else(|| smooth_rule(&l, src, rec, d.rtol))
                        .unwrap_or(Rule::GenzMalik75),
                    _ => Rule::GenzMalik75,
                };
                // A receptor that does not see the mirror image of a material without a diffuse term: first the
                // material's bound of the tail (`Rule::TailBound`, decided at run time).
                let rule = match rule {
                    Rule::GenzMalik75
                        if mirror.is_none()
                            && !facts.has_diffuse
                            && !facts.lobes.is_empty()
                            && !lobe_reaches(&l, &a, src, rec) =>
                    {
                        Rule::TailBound
                    }
                    r => r,
                };
                Some(RegularPart {
                    chart,
                    rule,
                    splits,
                    kinks,
                    cells: Cell::from_boxes(&boxes),
                    refine: Refine::Adaptive,
                    rtol: share * d.rtol,
                    atol: share * d.atol,
                })
            }
            _ => None,
        };
        Method {
            aperture: a,
            clipped,
            mirror,
            delta,
            regular,
            weighting: d.weighting,
            projection: d.projection,
            rtol: d.rtol,
            max_evals: d.max_evals,
            max_seconds: d.max_seconds,
        }
    }

    /// A one-off method for the specimen flux of `brdf` alone (no plan): its own terms, the luminous weighting
    /// applied in the integrand.
    pub fn for_material(
        brdf: &dyn Brdf,
        theta: f64,
        source: Stop,
        receptor: Stop,
        tolerance: (f64, f64),
        max_evals: usize,
    ) -> crate::Result<Method> {
        Ok(Method::design(Design {
            aperture: Aperture {
                target: Target::Specimen,
                integral: Integral::Aperture,
                theta,
                viewing: theta,
                source,
                receptor,
            },
            facts: &MaterialFacts::of(brdf),
            weighting: Weighting::luminous(brdf.sampling())?,
            projection: Projection::FoldInMaterial,
            rtol: tolerance.0,
            atol: tolerance.1,
            max_evals,
            max_seconds: None,
        }))
    }
}

/// The shaped rule of a lobe-chart part, if one fits: [`Rule::LobeGaussHermite`] for a material whose regular
/// part is one Gaussian-tailed lobe (no diffuse term, no heavy tail) whose centre u = v = 0 is inside the
/// range of the lobe variables and at least
/// [`LOBE_REACH`] widths from every kink of the overlap length and every end of the range, on both axes.
pub(crate) fn lobe_rule(l: &LobesAt, src: Stop, rec: Stop) -> Option<Rule> {
    let ([lobe], [width]) = (l.lobes, l.widths.as_slice()) else { return None };
    if l.has_diffuse || lobe.tail.is_heavy() {
        return None;
    }
    let width = *width;
    let clear = |a: AxisMap, w: f64| {
        let [lo, hi] = a.range();
        let kinks = [lo, hi, a.s[1] + a.r[0], a.s[0] + a.r[1]];
        w > 0.0 && w.is_finite() && lo < 0.0 && hi > 0.0 && kinks.iter().all(|k| k.abs() >= LOBE_REACH * w)
    };
    let fits = clear(AxisMap { s: src.p, r: rec.p }, width[0]) && clear(AxisMap { s: src.q, r: rec.q }, width[1]);
    fits.then_some(Rule::LobeGaussHermite { width, levels: (0, LOBE_LEVELS.len() - 1) })
}

/// The delta-limit rule of a lobe-chart part ([`Rule::LobeDelta`]), if the lobe fits [`lobe_rule`] (one
/// Gaussian-tailed lobe, no diffuse term, ≥ [`LOBE_REACH`] widths from every overlap kink and range end on
/// both axes) and is narrow enough that its majorant can meet the part's relative tolerance `rtol`: the
/// relative correction of the delta limit is c·w² (w the larger lobe width in (u, v)), and the majorant was
/// measured at 50–270·w² at 20°, 60°, E430 and ISO 13803 (≈ 1.8·10⁴·w² at 85°), so the rule is tried only
/// when [`DELTA_GATE`]·w² ≤ rtol (otherwise its evaluations would be spent for nothing before the
/// Gauss–Hermite rule). Whether the majorant meets the tolerance is decided when it runs, on the material.
pub(crate) fn delta_rule(l: &LobesAt, src: Stop, rec: Stop, rtol: f64) -> Option<Rule> {
    let Some(Rule::LobeGaussHermite { width, .. }) = lobe_rule(l, src, rec) else {
        return None;
    };
    let w = width[0].max(width[1]);
    (DELTA_GATE * w * w <= rtol).then_some(Rule::LobeDelta { width })
}

/// The smooth-integrand rule of a lobe-chart part without kinks, if it fits: [`Rule::TensorGauss`] in the
/// variables (p_s, p_r, v, t_q) ([`Chart::PlainPLobeQ`]: plain in the plane of incidence, where the
/// lobe is far wider than the stops, the lobe variable across it, where the ridge v = q_s + q_r becomes an
/// axis) within the bounds of [`TENSOR_MIN_WIDTH`] (B4's GGX α = 0.3 at 85°: 0.6 wide in u against a u-range
/// of 0.083, 0.052 in v against 0.15), and only on a receptor whose range of the lobe variables holds the lobe
/// centre on both axes (a receptor that sees the mirror image: off it, on the Rhopoint IQ 20° haze receptors,
/// the rule's estimate fell up to 23× below its actual error, `docs/instrument.md` §Quadrature, "When it is
/// chosen"), and only at a reading tolerance `rtol` of [`TENSOR_MAX_RTOL`] or tighter. The levels start at 1
/// (2 points) on every axis.
pub(crate) fn smooth_rule(l: &LobesAt, src: Stop, rec: Stop, rtol: f64) -> Option<Rule> {
    let (ap, aq) = (AxisMap { s: src.p, r: rec.p }, AxisMap { s: src.q, r: rec.q });
    if rtol > TENSOR_MAX_RTOL || ap.gap() > 0.0 || aq.gap() > 0.0 {
        return None;
    }
    let range = [(src.p[1] - src.p[0]) + (rec.p[1] - rec.p[0]), (src.q[1] - src.q[0]) + (rec.q[1] - rec.q[0])];
    let fits = |w: &[f64; 2]| {
        w.iter().all(|w| w.is_finite())
            && w[0] >= TENSOR_MIN_WIDTH_U * range[0]
            && (TENSOR_MIN_WIDTH * range[1]..=TENSOR_MAX_WIDTH_V * range[1]).contains(&w[1])
    };
    if l.lobes.is_empty() || !l.widths.iter().all(fits) {
        return None;
    }
    Some(Rule::TensorGauss { chart: Chart::PlainPLobeQ, levels: [1; 4], path: tensor::Path::default() })
}

/// The polar rule of a lobe-chart part, if one fits ([`Rule::LobePolar`]): a material whose regular part is
/// one lobe with GGX's tail (`Tail::InverseQuartic`: not a lobe over a diffuse body; a Gaussian tail gets
/// [`Rule::LobeGaussHermite`] or the partition; a measured table's lobe, `Tail::Table`, keeps the partition:
/// the rule was measured on every shipped table and on MERL-format GGX tables and lost or fell back on each,
/// because the table's interpolation kinks at its cells, not its tail, set the cost, see
/// `docs/instrument.md` §Quadrature, *Measured tables*) whose centre u = v = 0 is inside the range of the lobe variables and at least
/// [`POLAR_REACH`] widths from every kink of the overlap length and every end of the range, on both axes
/// (on the u axis [`POLAR_REACH_GRAZING`] widths at geometry angles of [`POLAR_GRAZING`] and above).
pub(crate) fn polar_rule(l: &LobesAt, src: Stop, rec: Stop) -> Option<Rule> {
    let ([lobe], [width]) = (l.lobes, l.widths.as_slice()) else { return None };
    if l.has_diffuse || lobe.tail != Tail::InverseQuartic {
        return None;
    }
    let width = *width;
    let breaks = |a: AxisMap, w: f64| {
        let [lo, hi] = a.range();
        let mut b = [lo, a.s[1] + a.r[0], a.s[0] + a.r[1], hi];
        b.sort_by(f64::total_cmp);
        let clear = w > 0.0 && w.is_finite() && lo < 0.0 && hi > 0.0 && b.iter().all(|k| k.abs() >= POLAR_REACH * w);
        clear.then_some(b)
    };
    let u = breaks(AxisMap { s: src.p, r: rec.p }, width[0])?;
    let v = breaks(AxisMap { s: src.q, r: rec.q }, width[1])?;
    if l.theta >= POLAR_GRAZING && !u.iter().all(|k| k.abs() >= POLAR_REACH_GRAZING * width[0]) {
        return None;
    }
    Some(Rule::LobePolar { width, u, v, levels: [1; 9] })
}

/// The initial boxes of a lobe chart with `kinks` kinks: every box cut on t_p into kinks + 1 equal pieces
/// (the pieces of `aperture::kinked_position`); the boxes unchanged without kinks.
fn kinked_boxes(boxes: Vec<([f64; 4], [f64; 4])>, kinks: usize) -> Vec<([f64; 4], [f64; 4])> {
    if kinks == 0 {
        return boxes;
    }
    let m = (kinks + 1) as f64;
    let mut out = Vec::with_capacity(boxes.len() * (kinks + 1));
    for (lo, hi) in boxes {
        for j in 0..=kinks {
            let (mut a, mut b) = (lo, hi);
            a[1] = j as f64 / m;
            b[1] = (j + 1) as f64 / m;
            out.push((a, b));
        }
    }
    out
}

impl Method {
    /// A rough estimate, before running, of the integrand evaluations this method will spend: for scheduling
    /// only ([`Plan::run_all`](crate::instrument::plan::Plan::run_all) starts the integrals it expects to be
    /// largest first, so that a batch ends with small integrals on every thread). It changes no result, and a
    /// wrong guess only costs balance. An adaptive Genz–Malik part is guessed from its initial partition: the
    /// rule's points per cell (57 in 4-D, 17 in 2-D) × cells × (1 + cells/8), the refinement growing with the
    /// number of lobe splits (fitted by eye to the 1 400 integrals of the batch bench, where 1, 9, 18, 24 and 60
    /// initial cells spent 1.1–2.4, 1.4–2.0, 1.9–4.5, 3.9–5.2 and 4.4 times their first pass; docs/performance.md
    /// §Batch and sweep throughput); a frozen part costs exactly its partition; the shaped rules are guessed
    /// from their first two levels (what they evaluate before they can first stop), doubled for one raise; a
    /// sphere integral is a flat guess (4 096).
    pub(crate) fn expected_evaluations(&self) -> f64 {
        if self.aperture.integral != Integral::Aperture {
            return 4096.0;
        }
        let genz_malik = |points: f64, cells: usize, refine: Refine| -> f64 {
            let c = cells as f64;
            points * c * if refine == Refine::Frozen { 1.0 } else { 1.0 + c / 8.0 }
        };
        let delta = self.delta.as_ref().map_or(0.0, |d| genz_malik(17.0, d.cells.len(), d.refine));
        let regular = self.regular.as_ref().map_or(0.0, |r| match &r.rule {
            // The tail bound costs nothing when it agrees; guessed as its fallback.
            Rule::GenzMalik75 | Rule::TailBound => genz_malik(57.0, r.cells.len(), r.refine),
            Rule::LobeDelta { .. } => DELTA_COST as f64,
            Rule::LobeGaussHermite { levels, .. } => {
                let points = |l: usize| {
                    let (h, g) = LOBE_LEVELS[l.min(LOBE_LEVELS.len() - 1)];
                    (h * h * g * g) as f64
                };
                2.0 * (points(levels.0) + points(levels.0 + 1))
            }
            Rule::LobePolar { u, v, levels, .. } => {
                let mut sum = 0.0;
                for i in 0..3 {
                    for j in 0..3 {
                        if !(u[i + 1] > u[i] && v[j + 1] > v[j]) {
                            continue;
                        }
                        let central = u[i] < 0.0 && u[i + 1] > 0.0 && v[j] < 0.0 && v[j + 1] > 0.0;
                        let points = |l: usize| -> f64 {
                            if central {
                                let (a, b, t) = POLAR_LEVELS[l.min(POLAR_LEVELS.len() - 1)];
                                (4 * a * b * t * t) as f64
                            } else {
                                let (a, b, t) = TAIL_LEVELS[l.min(TAIL_LEVELS.len() - 1)];
                                (a * b * t * t) as f64
                            }
                        };
                        let l = (levels[3 * i + j] as usize).max(1);
                        sum += points(l - 1) + points(l);
                    }
                }
                2.0 * sum
            }
            Rule::TensorGauss { chart, levels, .. } => {
                let boxes = self.clipped.map_or(1, |(s, r)| tensor_boxes(*chart, s, r).len()) as f64;
                let points: usize = levels.iter().map(|&l| tensor::ORDERS[l.min(tensor::ORDERS.len() - 1)]).product();
                2.0 * boxes * points as f64
            }
        });
        delta + regular
    }
}
