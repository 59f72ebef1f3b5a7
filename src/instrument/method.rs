//! A method: how one aperture integral is done, as plain data, and the executor that does it.
//!
//! Why: the plan (`instrument::plan`) decides everything about an integral once — the clipped stops,
//! whether the receptor sees the mirror image, the chart and rule of the regular part, its initial
//! partition, the delta part's box, the spectral weighting, the tolerances and the budget — and stores the
//! decision here. [`Method::execute`] then only executes it; `--explain` prints the stored methods and never
//! works a choice out again. A method does not hold the material: it can be executed on any material of the
//! same shape (same sampling length, same kinds of terms), which is what sweeps and the fitter need; and
//! after one adaptive run it can be *frozen* ([`Method::execute_and_freeze`]): the final partitions are kept
//! and re-executed with the same rule and no refinement, so a fitter's finite differences do not see the
//! partition jump (the result is then a smooth function of the material's parameters).
//!
//! The tolerance split inside a flux: the delta part gets [`DELTA_SHARE`] of the relative tolerance and of
//! the absolute floor (all of them when there is no regular part); the regular part gets the rest,
//! err_r ≤ max(atol_r, r·|Φ_δ|, r·|Φ_r|) with r = (1 − DELTA_SHARE)·rtol, so err_δ + err_r ≤ rtol·(|Φ_δ| +
//! |Φ_r|) (+ the floor) as both parts are ≥ 0. The r·|Φ_δ| term needs the delta part's value, so it is the
//! one quantity formed at run time (the smallest |Φ_δ| component, which keeps every component within its
//! tolerance).
use crate::brdf::{Brdf, Kink, Lobe, Tail, TermKind};
use crate::colorimetry::weighting::Weighting;
use crate::instrument::flux::{
    choose_chart, clip, delta_kinks, half_angle_kink_point, incidence_kink_point, kinked_position, lobe_boxes,
    lobe_splits, lobe_widths_uv, mirror_overlap, regular_kinks, AxisMap, Chart, Flux, DELTA_SHARE,
};
use crate::instrument::geometry::{solid_angle_density, Axes, Integral, Stop};
use crate::instrument::sphere;
use crate::quadrature::{
    gauss_hermite_table, gauss_legendre_table, integrate_partition, legendre_on_into, mapped_legendre_into,
    polar_rectangle_into, tensor, Cell, Estimate, Map, Options, PolarBuffers, Refine, MAX_SHRINK, MAX_SHRINK_LOBE,
};
use crate::Vec3;
use std::time::Instant;

/// The share of its wall-clock budget an integral gets when it starts at or after the deadline it shares
/// with the other integrals of a plan ([`Method::execute_until`]). A plan of J integrals on T threads then
/// ends within about max_seconds·(1 + ⌈J/T⌉·LATE_START_SHARE) of wall time: the default panel's 12
/// specimen integrals on 2 threads, 1.3 × the budget.
pub const LATE_START_SHARE: f64 = 0.05;

/// Which material a flux is taken on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Target {
    Specimen,
    Standard,
}

/// The cubature rule of a part, chosen by the planner ([`Method::design`]) from the material's lobes and the
/// geometry; deterministic (the same method for the same input).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rule {
    /// Genz & Malik's degree-7 rule with its embedded null rules for the error estimate
    /// (`quadrature::Rule`), globally adaptive on the part's partition. The fallback of every other rule.
    GenzMalik75,
    /// A narrow Gaussian-tailed lobe far from every kink of the overlap (issue 10): a tensor product of
    /// Gauss–Hermite rules in u and v scaled to the lobe's widths (u = width[0]·x, v = width[1]·y, weight
    /// e^{−x²−y²}) and Gauss–Legendre rules in t_p and t_q, the orders raised through [`LOBE_LEVELS`]
    /// `levels.0..=levels.1` until two successive levels agree to the part's tolerance (their difference is
    /// the error estimate). If none do, the part's Genz–Malik partition is integrated instead (the fallback).
    LobeGaussHermite { width: [f64; 2], levels: (usize, usize) },
    /// The delta limit of a narrow Gaussian-tailed lobe far from every kink of the overlap (issue 10 item 1;
    /// [`delta_rule`], `docs/instrument.md` §Quadrature, "The delta limit of a narrow lobe"): in the scaled lobe
    /// variables x = u/w_u, y = v/w_v, at each Gauss–Legendre node of (t_p, t_q), the lobe's mass is Laplace's
    /// π·F(0)/√det B from its curvature B at the peak (measured on a ring of [`DELTA_FIT_RADIUS`] width), and the
    /// error reported is the majorant of [`delta_node`] (second differences of the even part of F·e^{xᵀBx} on
    /// rings of [`DELTA_RADII`] widths times [`DELTA_SAFETY`], the tail beyond the outer ring at its measured
    /// decay rate ÷ [`DELTA_TAIL_SAFETY`]) plus
    /// the t rule's difference of orders ([`DELTA_T_ORDERS`]: the engine's usual estimate of a Gauss–Legendre
    /// rule on a smooth integrand, as in [`Rule::LobeGaussHermite`]). It is accepted when that
    /// majorant meets the part's tolerance; otherwise the lobe's [`Rule::LobeGaussHermite`] runs (and after
    /// it, if it does not agree either, the Genz–Malik partition). A frozen method replays the same points.
    LobeDelta { width: [f64; 2] },
    /// A narrow lobe with GGX's heavy u⁻⁴ tail (`Tail::InverseQuartic`) whose centre lies inside the kink square (issue 10; [`polar_rule`]): the
    /// (u, v) range is cut at the overlap kinks `u`, `v` (each axis: the range ends and the two kinks, in
    /// increasing order) into up to 3 × 3 pieces. The piece that holds u = v = 0 is integrated in the polar
    /// variables of `quadrature::polar_rectangle` scaled to the lobe's `width` (x = u/w_u = ρ cos φ,
    /// y = v/w_v = ρ sin φ, ρ = tan β), every other piece by Gauss–Legendre in σ = 1/x along its tail
    /// coordinate times Gauss–Legendre in y = c·tan γ across it (c = √(1 + x²), the kernel's width there;
    /// `quadrature::Map`), all times Gauss–Legendre in t_p, t_q. Piece k reports its value at level `levels[k]` of [`POLAR_LEVELS`] /
    /// [`TAIL_LEVELS`] and the difference from the level below as its error; the piece with the largest error
    /// is raised until the sum meets the part's tolerance. If a piece runs out of levels, the part's
    /// Genz–Malik partition is integrated instead (the fallback).
    LobePolar { width: [f64; 2], u: [f64; 4], v: [f64; 4], levels: [u8; 9] },
    /// A smooth integrand (issue 10: no lobe much narrower than the stops, no Fresnel kink): the anisotropic
    /// tensor Gauss–Legendre rule of `quadrature::tensor` with the same per-axis orders on every box of
    /// `chart`'s kink partition ([`tensor_boxes`]: the one box of the stops' product in the plain chart, the
    /// boxes between the overlap kinks of u and v in the lobe chart), the orders `tensor::ORDERS[levels[k]]`
    /// raised one axis at a time (up to [`TENSOR_MAX_LEVEL`]) until the sum of the per-axis differences of
    /// successive orders (the error estimate) meets the part's tolerance. If they do not, the part's
    /// Genz–Malik partition is integrated instead (the fallback). `path` is empty when designed; a frozen
    /// method keeps the raises of its run and replays them (the same points, the same bits).
    TensorGauss { chart: TensorChart, levels: [usize; 4], path: tensor::Path },
}

/// The (φ nodes per sector, β nodes, t nodes per axis) of the polar piece of [`Rule::LobePolar`], level by
/// level: 4·3·6·2² = 288 points, then 512, 1 152, 4 608, 18 432, 51 200.
pub const POLAR_LEVELS: [(usize, usize, usize); 6] =
    [(3, 6, 2), (4, 8, 2), (6, 12, 2), (8, 16, 3), (12, 24, 4), (16, 32, 5)];

/// The (tail-axis nodes, cross-axis nodes, t nodes per axis) of a tail piece of [`Rule::LobePolar`], level by
/// level: 3·3·2² = 36 points, then 64, 144, 576, 2 304, 6 400.
pub const TAIL_LEVELS: [(usize, usize, usize); 6] =
    [(3, 3, 2), (4, 4, 2), (6, 6, 2), (8, 8, 3), (12, 12, 4), (16, 16, 5)];

/// How far (in lobe widths, on both axes and both sides) the overlap kinks must be from the lobe centre for
/// [`Rule::LobePolar`]: the polar piece then holds the peak and the tail pieces only the tail.
pub const POLAR_REACH: f64 = 2.0;

/// The variables of [`Rule::TensorGauss`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TensorChart {
    /// (p_s, q_s, p_r, q_r) on the one box of the stops' product.
    Plain,
    /// (u, t_p, v, t_q) on the boxes between the overlap kinks of u and v.
    Lobe,
    /// (p_s, p_r, v, t_q): plain in the plane of incidence, lobe variables across it, on the boxes between
    /// the overlap kinks of v (a lobe wider than the stops in u but not in v: the ridge v = q_s + q_r
    /// becomes an axis).
    PlainPLobeQ,
}

/// The highest level of [`Rule::TensorGauss`] an axis may reach (`tensor::ORDERS[TENSOR_MAX_LEVEL]` = 24
/// points): beyond it the integrand is not smooth at the scale of the box and the fallback does better.
pub const TENSOR_MAX_LEVEL: usize = 9;

/// [`Rule::TensorGauss`] is chosen ([`smooth_rule`]) when every lobe is at least [`TENSOR_MIN_WIDTH_U`]
/// times the u-range wide (smooth in the plane of incidence) and between [`TENSOR_MIN_WIDTH`] and
/// [`TENSOR_MAX_WIDTH_V`] of the v-range (a lobe the v axis must resolve, but not so narrow that its order
/// passes [`TENSOR_MAX_LEVEL`]). The bounds are where the rule was measured to cost fewer evaluations than the
/// calibrated Genz–Malik partition on the shipped fixtures (`docs/instrument.md` §Quadrature): B4's GGX
/// α = 0.3 at 85° (7.2 × the u-range, 0.35 of the v-range) 2 159 against 2 639; it cost more at every
/// other wide-lobe integral tried (B4 at 75°: 2.9 and 0.63, 2 204 against 986; GGX α = 0.3 conductor at
/// 60°: 4.5 and 0.81, 3 023 against 872; Blinn–Phong at 20°: 2.0 and 0.79, 1 574 against 530).
pub const TENSOR_MIN_WIDTH: f64 = 0.25;
/// See [`TENSOR_MIN_WIDTH`].
pub const TENSOR_MAX_WIDTH_V: f64 = 0.5;
/// See [`TENSOR_MIN_WIDTH`].
pub const TENSOR_MIN_WIDTH_U: f64 = 4.0;

/// The (Gauss–Hermite, Gauss–Legendre) orders per axis of [`Rule::LobeGaussHermite`], level by level:
/// 4²·2² = 64 points, then 324, 1 024, 3 600, 9 216.
pub const LOBE_LEVELS: [(usize, usize); 5] = [(4, 2), (6, 3), (8, 4), (12, 5), (16, 6)];

/// How far (in lobe widths) the nearest overlap kink or range end must be from the lobe centre, on both
/// axes, for [`Rule::LobeGaussHermite`]: the largest node of the 16-point rule is at 4.69 widths, and the
/// Gaussian is below e⁻⁶⁴ of its peak at 8.
pub const LOBE_REACH: f64 = 8.0;

/// The radii (in lobe widths) of the rings on which [`Rule::LobeDelta`] samples the even part of h (four
/// directions, 0°, 45°, 90°, 135°, each with its opposite point; with the curvature ring): the majorant's
/// second differences.
pub const DELTA_RADII: [f64; 2] = [2.5, 5.0];

/// The radius (in lobe widths) of the disc inside which [`Rule::LobeDelta`] bounds the correction by second
/// differences (in the metric of the fitted curvature B); beyond it the tail, bounded by a Gaussian of the
/// decay rate measured on that ring ([`DELTA_TAIL_SAFETY`]). It is the last of [`DELTA_RADII`]; the overlap
/// kinks are ≥ [`LOBE_REACH`] = 8 widths away.
pub const DELTA_RADIUS: f64 = DELTA_RADII[DELTA_RADII.len() - 1];

/// The factor by which [`Rule::LobeDelta`] multiplies the largest sampled second difference to stand for a
/// bound over the whole disc: one of the two assumptions of its majorant (`docs/instrument.md` §Quadrature;
/// checked against a stencil of 24 directions × 30 radii by `tests/delta_limit.rs`, where the dense maximum
/// is at most 1.1× the sampled one).
pub const DELTA_SAFETY: f64 = 4.0;

/// The factor by which [`Rule::LobeDelta`] divides the decay rate λ of the lobe measured on its outer ring
/// (the smallest ln(F(0)/F(x))/xᵀBx there) before it bounds the tail beyond the ring by F(0)·e^{−λ·xᵀBx}: the
/// other assumption of its majorant. (A Gaussian of the fitted curvature, |h| ≤ its largest value on the
/// ring, does not hold: at grazing incidence the lobe's exponent in these variables falls a few per cent
/// short of xᵀBx at 12 widths, and h = F·e^{xᵀBx} grows there by 100× — measured by the same test.)
pub const DELTA_TAIL_SAFETY: f64 = 1.25;

/// The Gauss–Legendre orders per t axis of [`Rule::LobeDelta`]: the second-difference stencil on the lower's
/// nodes, the value on the higher's, their difference the t rule's error.
pub const DELTA_T_ORDERS: (usize, usize) = (2, 3);

/// The points per t node of [`Rule::LobeDelta`]: the centre and the curvature ring (four directions, both
/// signs) at the higher order's nodes, and with them the bound's rings at the lower order's.
const DELTA_NODE_POINTS: (usize, usize) = (1 + 8, 1 + 8 * (1 + DELTA_RADII.len()));

/// The evaluations of one [`Rule::LobeDelta`] (181).
pub const DELTA_COST: usize = DELTA_T_ORDERS.1 * DELTA_T_ORDERS.1 * DELTA_NODE_POINTS.0
    + DELTA_T_ORDERS.0 * DELTA_T_ORDERS.0 * DELTA_NODE_POINTS.1;
const _: () = assert!(DELTA_COST == 181, "the docs and --explain's cost figures say 181");

/// When the spectral weighting is applied.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Projection {
    /// In the integrand: the cubature integrates the k weighted components (cheapest when k < n).
    Fold,
    /// As `Fold`, and a one-row weighting that the material has prepared (`Brdf::folds`: the paint's
    /// luminous row) is summed by the material itself (`Brdf::eval_batch_folded`: one folded reflectance
    /// table per flake term instead of n); the default. Otherwise the same as `Fold`.
    FoldInMaterial,
    /// After: the cubature integrates the n samples and the weighting is applied to the results
    /// (kept to measure what folding saves; `PlanOptions::fold_spectral`).
    Separate,
}

/// The ideal-mirror part: a 2-D integral of R(θi) cos θi dω over the mirror overlap.
#[derive(Clone, Debug, PartialEq)]
pub struct DeltaPart {
    pub rule: Rule,
    /// The cosines of the critical angles (`Kink::Incidence`) whose curve cos θi = c may cross the overlap, in
    /// increasing order. Empty: the variables are (p, q). Otherwise (t, q): for each q, p runs over the
    /// overlap in m + 1 pieces cut at the kinks' positions p*(q) (`flux::kinked_position`), t ∈ [0, 1] with
    /// one piece per 1/(m + 1), so every kink lies on a boundary of the initial boxes.
    pub kinks: Vec<f64>,
    /// The partition: the overlap box at design time, the final partition of a frozen method.
    pub cells: Vec<Cell<2>>,
    pub refine: Refine,
    pub rtol: f64,
    pub atol: f64,
}

/// The regular part: a 4-D integral in the chart's variables.
#[derive(Clone, Debug, PartialEq)]
pub struct RegularPart {
    pub chart: Chart,
    pub rule: Rule,
    /// The split points of the lobe chart on u and v (empty for the plain chart).
    pub splits: [Vec<f64>; 2],
    /// The cosines c of the half-angle kinks (`Kink::HalfAngle`, ωi·h = c) whose surface may cross the
    /// domain, in increasing order; non-empty only in the lobe chart (a kink forces it). For each (u, q_s,
    /// q_r) the overlap position t_p runs over p_s in m + 1 pieces cut where ωi·ωo = 2c² − 1
    /// (`flux::half_angle_kink_point`), so every kink lies on a boundary of the initial boxes.
    pub kinks: Vec<f64>,
    /// The partition: the initial boxes at design time, the final partition of a frozen method.
    pub cells: Vec<Cell<4>>,
    pub refine: Refine,
    pub rtol: f64,
    /// Absolute floor; raised at run time to rtol·|Φ_δ| (see the module documentation).
    pub atol: f64,
}

/// One aperture integral, designed.
#[derive(Clone, Debug, PartialEq)]
pub struct Method {
    pub target: Target,
    /// What is integrated: an aperture integral, or a d/8 sphere's hemisphere or specular port (then the
    /// stops, parts and partitions below are unused and the sphere's own integrators run, `instrument::sphere`).
    pub integral: Integral,
    /// Geometry angle θ (the source lens axis; a sphere's viewing angle).
    pub theta: f64,
    /// The receptor lens axis, radians, signed: θ for gloss; θ − aspecular for multi-angle colour, whose
    /// receptor never sees the mirror image (no delta part, the plain chart).
    pub viewing: f64,
    /// The stops as the geometry gives them.
    pub source: Stop,
    pub receptor: Stop,
    /// The stops clipped to the upper hemisphere; None: one is entirely below the horizon (the flux is 0).
    pub clipped: Option<(Stop, Stop)>,
    /// The mirror overlap of the clipped stops (whether the receptor sees the mirror image of the source),
    /// whether or not the material has a delta term.
    pub mirror: Option<([f64; 2], [f64; 2])>,
    /// The delta part, if the material has one and the receptor sees the mirror image.
    pub delta: Option<DeltaPart>,
    /// The regular part, if the material has one and the stops are above the horizon.
    pub regular: Option<RegularPart>,
    /// The k × n spectral weighting of the flux.
    pub weighting: Weighting,
    pub projection: Projection,
    /// Relative tolerance of the whole flux, as designed (the parts carry their shares; a sphere's integrals
    /// use it directly).
    pub rtol: f64,
    /// Evaluation budget of each part.
    pub max_evals: usize,
    /// Wall-clock budget of the whole integral, seconds (None: none). When it runs out the flux is the best
    /// estimate so far, marked not converged and `out_of_time` (and then depends on the machine's speed).
    pub max_seconds: Option<f64>,
}

/// What the designer needs to know about an integral.
#[derive(Clone, Debug)]
pub struct Design<'a> {
    pub target: Target,
    pub integral: Integral,
    pub theta: f64,
    pub viewing: f64,
    pub source: Stop,
    pub receptor: Stop,
    /// The material's lobes (for the chart and the split points).
    pub lobes: &'a [Lobe],
    /// The material's kinks (`Brdf::kinks`): put on partition boundaries.
    pub kinks: &'a [Kink],
    /// Whether the material has a delta term and a regular (diffuse or lobe) term, and a diffuse one.
    pub has_delta: bool,
    pub has_regular: bool,
    pub has_diffuse: bool,
    pub weighting: Weighting,
    pub projection: Projection,
    /// Relative tolerance of the flux and its absolute floor.
    pub rtol: f64,
    pub atol: f64,
    pub max_evals: usize,
    pub max_seconds: Option<f64>,
}

impl Method {
    /// Design the method of one integral.
    pub fn design(d: Design<'_>) -> Method {
        let aperture = d.integral == Integral::Aperture;
        let clipped = match (clip(d.source, d.theta, true), clip(d.receptor, d.viewing, false)) {
            (Some(s), Some(r)) if aperture => Some((s, r)),
            _ => None,
        };
        // The mirror image is only ever seen by a receptor on the mirror axis.
        let on_mirror_axis = d.viewing == d.theta;
        let mirror = clipped.filter(|_| on_mirror_axis).and_then(|(s, r)| mirror_overlap(s, r));
        let delta_share = if d.has_regular { DELTA_SHARE } else { 1.0 };
        let delta = match (d.has_delta, mirror) {
            (true, Some((lo, hi))) => {
                let kinks = delta_kinks(d.kinks, d.theta, Stop { p: [lo[0], hi[0]], q: [lo[1], hi[1]] });
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
        let regular = match (d.has_regular, clipped) {
            (true, Some((src, rec))) => {
                // Off the mirror axis no lobe is centred in the stops: the plain variables (and no kink cuts:
                // the cut's chart is the lobe chart, whose variables assume the mirror axis).
                let kinks = if on_mirror_axis { regular_kinks(d.kinks, d.theta, src, rec) } else { Vec::new() };
                let chart = if !on_mirror_axis {
                    Chart::Plain
                } else if kinks.is_empty() {
                    choose_chart(d.lobes, d.theta, src, rec)
                } else {
                    Chart::Lobe
                };
                let (splits, boxes) = match chart {
                    Chart::Lobe => {
                        let splits = lobe_splits(d.lobes, d.theta, src, rec);
                        let boxes = kinked_boxes(lobe_boxes(&splits), kinks.len());
                        (splits, boxes)
                    }
                    Chart::Plain => (
                        [vec![], vec![]],
                        vec![([src.p[0], src.q[0], rec.p[0], rec.q[0]], [src.p[1], src.q[1], rec.p[1], rec.q[1]])],
                    ),
                };
                let share = 1.0 - DELTA_SHARE;
                let rule = match chart {
                    Chart::Lobe if kinks.is_empty() && on_mirror_axis => {
                        delta_rule(d.lobes, d.has_diffuse, d.theta, src, rec, share * d.rtol)
                            .or_else(|| lobe_rule(d.lobes, d.has_diffuse, d.theta, src, rec))
                            .or_else(|| polar_rule(d.lobes, d.has_diffuse, d.theta, src, rec))
                            .or_else(|| smooth_rule(d.lobes, d.theta, src, rec))
                            .unwrap_or(Rule::GenzMalik75)
                    }
                    _ => Rule::GenzMalik75,
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
            target: d.target,
            integral: d.integral,
            theta: d.theta,
            viewing: d.viewing,
            source: d.source,
            receptor: d.receptor,
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
            target: Target::Specimen,
            integral: Integral::Aperture,
            theta,
            viewing: theta,
            source,
            receptor,
            lobes: &brdf.lobes(),
            kinks: &brdf.kinks(),
            has_delta: brdf.has_delta(),
            has_regular: brdf.has_regular(),
            has_diffuse: brdf.terms().iter().any(|t| t.kind == TermKind::Diffuse),
            weighting: Weighting::luminous(brdf.sampling())?,
            projection: Projection::FoldInMaterial,
            rtol: tolerance.0,
            atol: tolerance.1,
            max_evals,
            max_seconds: None,
        }))
    }

    /// Whether the method was frozen (its parts re-run a kept partition without refinement).
    pub fn is_frozen(&self) -> bool {
        self.delta.iter().all(|p| p.refine == Refine::Frozen) && self.regular.iter().all(|p| p.refine == Refine::Frozen)
    }

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
    pub fn expected_evaluations(&self) -> f64 {
        if self.integral != Integral::Aperture {
            return 4096.0;
        }
        let genz_malik = |points: f64, cells: usize, refine: Refine| -> f64 {
            let c = cells as f64;
            points * c * if refine == Refine::Frozen { 1.0 } else { 1.0 + c / 8.0 }
        };
        let delta = self.delta.as_ref().map_or(0.0, |d| genz_malik(17.0, d.cells.len(), d.refine));
        let regular = self.regular.as_ref().map_or(0.0, |r| match &r.rule {
            Rule::GenzMalik75 => genz_malik(57.0, r.cells.len(), r.refine),
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

    /// Execute the method on `brdf` (whose sampling has as many samples as the weighting has columns).
    pub fn execute(&self, brdf: &dyn Brdf) -> Flux {
        self.run(brdf, false, None).0
    }

    /// [`Method::execute`] under a deadline shared with other integrals (`Plan::execute`): the integral stops
    /// refining at that deadline, or [`LATE_START_SHARE`] of its own budget after it starts if that is
    /// later (so an integral queued behind slow ones still gets a moment to converge), and never later than
    /// its own budget.
    pub fn execute_until(&self, brdf: &dyn Brdf, deadline: Option<Instant>) -> Flux {
        self.run(brdf, false, deadline).0
    }

    /// Execute the method and return, with the flux, the frozen method: the same method with each part's
    /// final partition and `Refine::Frozen`. Executing the frozen method on the same material gives the same
    /// value and error bits; on a nearby material it gives a smooth function of the change.
    pub fn execute_and_freeze(&self, brdf: &dyn Brdf) -> (Flux, Method) {
        self.execute_and_freeze_until(brdf, None)
    }

    /// [`Method::execute_and_freeze`] with a shared deadline as in [`Method::execute_until`].
    pub fn execute_and_freeze_until(&self, brdf: &dyn Brdf, deadline: Option<Instant>) -> (Flux, Method) {
        let (flux, frozen) = self.run(brdf, true, deadline);
        (flux, frozen.expect("kept"))
    }

    /// The number of components the regular part's integrand has per point (k weighted sums, or n samples
    /// under [`Projection::Separate`]) and whether the material sums the one weighted component itself.
    fn components(&self, brdf: &dyn Brdf) -> (usize, bool) {
        let k = self.weighting.len();
        let ncomp = match self.projection {
            Projection::Fold | Projection::FoldInMaterial => k,
            Projection::Separate => brdf.sampling().len(),
        };
        let in_material =
            self.projection == Projection::FoldInMaterial && k == 1 && brdf.folds(&self.weighting.rows[0]);
        (ncomp, in_material)
    }

    /// The integrand of the regular part `part` in the chart `vars` holds (the part's own, or a tensor rule's
    /// while it runs): for each point of `pts`, `ncomp` values written to `out` — the weighted BRDF times
    /// cos θi cos θo, the solid-angle densities of the two direction-cosine charts and the chart's Jacobian.
    /// A point outside the overlap or below the horizon leaves its values as they were (the rules zero `out`).
    fn regular_integrand<'a>(
        &'a self,
        brdf: &'a dyn Brdf,
        part: &'a RegularPart,
        (src, rec): (Stop, Stop),
        (ncomp, in_material): (usize, bool),
        vars: &'a std::cell::Cell<TensorChart>,
    ) -> impl FnMut(&[[f64; 4]], &mut [f64]) + 'a {
        let axes = Axes::new(self.theta);
        let rec_axes = Axes::new(self.viewing);
        let ap = AxisMap { s: src.p, r: rec.p };
        let aq = AxisMap { s: src.q, r: rec.q };
        let (weighting, projection) = (&self.weighting, self.projection);
        let n = brdf.sampling().len();
        let mut batch = PairBatch::default();
        move |pts: &[[f64; 4]], out: &mut [f64]| {
            batch.clear(pts.len());
            for (i, x) in pts.iter().enumerate() {
                let (ps, qs, pr, qr, jac) = if vars.get() == TensorChart::Plain {
                    (x[0], x[1], x[2], x[3], 1.0)
                } else if vars.get() == TensorChart::PlainPLobeQ {
                    let (qs, qr, jq) = aq.at(x[2], x[3]);
                    (x[0], qs, x[1], qr, jq)
                } else if part.kinks.is_empty() {
                    let (ps, pr, jp) = ap.at(x[0], x[1]);
                    let (qs, qr, jq) = aq.at(x[2], x[3]);
                    (ps, qs, pr, qr, jp * jq)
                } else {
                    let (qs, qr, jq) = aq.at(x[2], x[3]);
                    let u = x[0];
                    let (lo, hi) = ap.overlap(u);
                    let (ps, jp) = kinked_position(x[1], lo, hi, part.kinks.len(), |k| {
                        let c = part.kinks[k];
                        half_angle_kink_point(&axes, 2.0 * c * c - 1.0, u, qs, qr, lo, hi)
                    });
                    (ps, qs, u - ps, qr, jp * jq)
                };
                if jac <= 0.0 {
                    continue;
                }
                let wi = axes.source_dir(ps, qs);
                let wo = rec_axes.receptor_dir(pr, qr);
                if wi.z <= 0.0 || wo.z <= 0.0 {
                    continue;
                }
                let g = wi.z * wo.z * solid_angle_density(ps, qs) * solid_angle_density(pr, qr) * jac;
                batch.push(i, wi, wo, g);
            }
            batch.values.clear();
            if in_material {
                batch.values.resize(batch.wi.len(), 0.0);
                brdf.eval_batch_folded(&weighting.rows[0], &batch.wi, &batch.wo, &mut batch.values);
                for ((&i, &g), v) in batch.index.iter().zip(&batch.g).zip(&batch.values) {
                    out[i] = v * g;
                }
                return;
            }
            batch.values.resize(batch.wi.len() * n, 0.0);
            brdf.eval_batch(&batch.wi, &batch.wo, &mut batch.values);
            for ((&i, &g), v) in batch.index.iter().zip(&batch.g).zip(batch.values.chunks_exact(n)) {
                store(&mut out[i * ncomp..(i + 1) * ncomp], v, weighting, g, projection);
            }
        }
    }

    /// The regular part's integrand at points `pts` of its chart (u, t_p, v, t_q in the lobe chart; p_s, q_s,
    /// p_r, q_r in the plain one): per point, the method's weighted components (or samples), exactly the
    /// values its rules integrate. For checking a rule's assumptions against a denser sampling of the same
    /// integrand (`tests/delta_limit.rs`); empty when there is no regular part or the stops are below the
    /// horizon.
    pub fn sample_regular(&self, brdf: &dyn Brdf, pts: &[[f64; 4]]) -> Vec<f64> {
        let (Some(part), Some(stops), Integral::Aperture) = (&self.regular, self.clipped, self.integral) else {
            return Vec::new();
        };
        let chart = if part.chart == Chart::Plain { TensorChart::Plain } else { TensorChart::Lobe };
        let vars = std::cell::Cell::new(chart);
        let comps = self.components(brdf);
        let mut out = vec![0.0; pts.len() * comps.0];
        self.regular_integrand(brdf, part, stops, comps, &vars)(pts, &mut out);
        out
    }

    fn run(&self, brdf: &dyn Brdf, keep: bool, shared: Option<Instant>) -> (Flux, Option<Method>) {
        let start = Instant::now();
        let after = |s: f64| start + std::time::Duration::from_secs_f64(s);
        let deadline = match (self.max_seconds, shared) {
            (Some(s), Some(d)) => Some(after(s).min(d.max(after(LATE_START_SHARE * s)))),
            (Some(s), None) => Some(after(s)),
            (None, d) => d,
        };
        let k = self.weighting.len();
        let n = brdf.sampling().len();
        let mut frozen = keep.then(|| self.clone());
        if self.integral != Integral::Aperture {
            // A sphere's integrals: per sample, then weighted (their integrators have no partition to freeze,
            // so the frozen method is the method).
            let r = match self.integral {
                Integral::Hemisphere => sphere::hemisphere_reflectance(brdf, self.theta),
                Integral::Port { half_angle } => {
                    sphere::port_reflectance(brdf, self.theta, half_angle, self.rtol, self.max_evals)
                }
                Integral::Aperture => unreachable!("handled below"),
            };
            let mut flux = Flux::zero(k);
            flux.regular = self.weighting.apply(&r.value);
            flux.error = (0..k).map(|c| self.weighting.component_error(c, &r.error)).collect();
            flux.value = flux.regular.clone();
            flux.evaluations = r.evaluations;
            flux.converged = r.converged;
            flux.seconds = start.elapsed().as_secs_f64();
            return (flux, frozen);
        }
        let Some((src, rec)) = self.clipped else {
            return (Flux::zero(k), frozen);
        };
        let axes = Axes::new(self.theta);
        // The material sums the one weighted component itself when `in_material`.
        let (ncomp, in_material) = self.components(brdf);
        let weighting = &self.weighting;
        let projection = self.projection;
        // The k weighted components of an estimate, and their error bounds.
        let weighted = |e: &Estimate| -> (Vec<f64>, Vec<f64>) {
            match projection {
                Projection::Fold | Projection::FoldInMaterial => (e.value.clone(), e.error.clone()),
                Projection::Separate => (
                    (0..k).map(|c| weighting.component(c, &e.value)).collect(),
                    (0..k).map(|c| weighting.component_error(c, &e.error)).collect(),
                ),
            }
        };
        let mut flux = Flux::zero(k);
        let smooth = brdf.smooth();

        // 1. The delta part: source points whose mirror (−p, −q) lies in the receptor.
        if let Some(part) = &self.delta {
            let mut scratch = vec![0.0; n];
            let (lo, hi) = self.mirror.expect("a delta part has a mirror overlap");
            let (p_lo, p_hi) = (lo[0], hi[0]);
            let (est, cells) = integrate_partition::<2, _>(
                |pts, out| {
                    for (x, o) in pts.iter().zip(out.chunks_exact_mut(ncomp)) {
                        let (p, q, jac) = if part.kinks.is_empty() {
                            (x[0], x[1], 1.0)
                        } else {
                            let (p, jac) = kinked_position(x[0], p_lo, p_hi, part.kinks.len(), |k| {
                                incidence_kink_point(&axes, part.kinks[k], x[1], p_lo, p_hi)
                            });
                            (p, x[1], jac)
                        };
                        if jac <= 0.0 {
                            continue;
                        }
                        let wi = axes.source_dir(p, q);
                        if wi.z <= 0.0 || !brdf.delta_reflectance(wi, &mut scratch) {
                            continue;
                        }
                        store(o, &scratch, weighting, wi.z * solid_angle_density(p, q) * jac, projection);
                    }
                },
                ncomp,
                &part.cells,
                &Options {
                    rtol: part.rtol,
                    atol: part.atol,
                    max_evals: self.max_evals,
                    deadline,
                    checked: smooth,
                    ..Default::default()
                },
                part.refine,
                keep,
            );
            (flux.delta, flux.error) = weighted(&est);
            flux.evaluations += est.evaluations;
            flux.regions += est.regions;
            flux.converged &= est.converged;
            flux.out_of_time |= est.out_of_time;
            if let Some(m) = frozen.as_mut() {
                let p = m.delta.as_mut().expect("the same parts");
                p.cells = cells;
                p.refine = Refine::Frozen;
            }
        }

        // 2. The regular part, in its chart.
        if let Some(part) = &self.regular {
            // The chart the integrand is evaluated in: the part's, or the shaped rule's while it runs.
            let part_vars = if part.chart == Chart::Plain { TensorChart::Plain } else { TensorChart::Lobe };
            let vars = std::cell::Cell::new(part_vars);
            let delta_min = flux.delta.iter().map(|d| d.abs()).fold(f64::INFINITY, f64::min);
            let atol = part.atol.max(part.rtol * delta_min);
            let mut integrand = self.regular_integrand(brdf, part, (src, rec), (ncomp, in_material), &vars);
            // A smooth material's region estimates are trusted further (`docs/accuracy.md` §5): checked
            // children, and on the lobe chart (whose boxes are cut to the lobe's widths and kinks) a deeper
            // shrink.
            let max_shrink = if smooth && part.chart == Chart::Lobe { MAX_SHRINK_LOBE } else { MAX_SHRINK };
            let opts =
                Options { rtol: part.rtol, atol, max_evals: self.max_evals, deadline, max_shrink, checked: smooth };
            // A shaped rule first (when the planner chose one), the Genz–Malik partition if it does not agree.
            let mut spent = 0;
            let shaped = match part.rule {
                Rule::LobeGaussHermite { width, levels } => {
                    let r = lobe_gauss_hermite(&mut integrand, ncomp, width, levels, &opts, part.refine);
                    spent = r.1;
                    r.0.map(|(est, level)| (est, Rule::LobeGaussHermite { width, levels: (level - 1, level) }))
                }
                Rule::LobeDelta { width } => {
                    let (est, n) = lobe_delta(&mut integrand, ncomp, width, &opts);
                    spent = n;
                    match est {
                        Some(est) if est.converged || part.refine == Refine::Frozen => {
                            Some((est, Rule::LobeDelta { width }))
                        }
                        _ => {
                            // The majorant did not meet the tolerance: the lobe's Gauss–Hermite rule.
                            let levels = (0, LOBE_LEVELS.len() - 1);
                            let r = lobe_gauss_hermite(&mut integrand, ncomp, width, levels, &opts, part.refine);
                            spent += r.1;
                            r.0.map(|(est, level)| (est, Rule::LobeGaussHermite { width, levels: (level - 1, level) }))
                        }
                    }
                }
                Rule::LobePolar { width, u, v, levels } => {
                    let r = lobe_polar(&mut integrand, ncomp, width, [u, v], levels, &opts, part.refine);
                    spent = r.1;
                    r.0.map(|(est, levels)| (est, Rule::LobePolar { width, u, v, levels }))
                }
                Rule::TensorGauss { chart, levels, path } => {
                    vars.set(chart);
                    let replay = (part.refine == Refine::Frozen).then_some(path);
                    let boxes = tensor_boxes(chart, src, rec);
                    let r = tensor_gauss(&mut integrand, ncomp, chart, boxes, levels, &opts, replay);
                    vars.set(part_vars);
                    spent = r.1;
                    r.0
                }
                Rule::GenzMalik75 => None,
            };
            let (mut est, cells, rule) = match shaped {
                Some((est, rule)) => (est, part.cells.clone(), rule),
                None => {
                    let (est, cells) =
                        integrate_partition::<4, _>(&mut integrand, ncomp, &part.cells, &opts, part.refine, keep);
                    (est, cells, Rule::GenzMalik75)
                }
            };
            est.evaluations += spent;
            let (regular, regular_err) = weighted(&est);
            flux.regular = regular;
            flux.error = flux.error.iter().zip(&regular_err).map(|(a, b)| a + b).collect();
            flux.evaluations += est.evaluations;
            flux.regions += est.regions;
            flux.converged &= est.converged;
            flux.out_of_time |= est.out_of_time;
            flux.chart = Some(match rule {
                Rule::TensorGauss { chart: TensorChart::Plain, .. } => Chart::Plain,
                Rule::TensorGauss { .. } => Chart::Lobe,
                _ => part.chart,
            });
            if let Some(m) = frozen.as_mut() {
                let p = m.regular.as_mut().expect("the same parts");
                p.cells = cells;
                p.rule = rule;
                p.refine = Refine::Frozen;
            }
        }
        flux.value = flux.delta.iter().zip(&flux.regular).map(|(a, b)| a + b).collect();
        flux.seconds = start.elapsed().as_secs_f64();
        (flux, frozen)
    }
}

/// The shaped rule of a lobe-chart part, if one fits: [`Rule::LobeGaussHermite`] for a material whose regular
/// part is one Gaussian-tailed lobe (no diffuse term, no heavy tail) whose centre u = v = 0 is inside the
/// range of the lobe variables and at least
/// [`LOBE_REACH`] widths from every kink of the overlap length and every end of the range, on both axes.
pub fn lobe_rule(lobes: &[Lobe], has_diffuse: bool, theta: f64, src: Stop, rec: Stop) -> Option<Rule> {
    let [lobe] = lobes else { return None };
    if has_diffuse || lobe.tail.is_heavy() {
        return None;
    }
    let width = lobe_widths_uv(lobe, theta);
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
pub fn delta_rule(lobes: &[Lobe], has_diffuse: bool, theta: f64, src: Stop, rec: Stop, rtol: f64) -> Option<Rule> {
    let Some(Rule::LobeGaussHermite { width, .. }) = lobe_rule(lobes, has_diffuse, theta, src, rec) else {
        return None;
    };
    let w = width[0].max(width[1]);
    (DELTA_GATE * w * w <= rtol).then_some(Rule::LobeDelta { width })
}

/// The design-time gate of [`delta_rule`]: a majorant of [`Rule::LobeDelta`] relative to the reading, per
/// squared lobe width, above the 50–270 measured at 20°, 60°, E430 and ISO 13803 (at 85°, ≈ 1.8·10⁴, the
/// rule is tried and may refuse itself; `docs/instrument.md` §Quadrature). Only a gate: the majorant itself
/// is computed at run time.
pub const DELTA_GATE: f64 = 1.0e3;

/// Run [`Rule::LobeDelta`]: the delta limit and its majorant (see [`delta_node`]); `converged` when the
/// majorant meets max(atol, rtol·|I|) in every component. None when an evaluation is not finite, the lobe is
/// not log-concave at its peak (the curvature fit fails) or the budget would be exceeded; and the evaluations
/// spent either way.
fn lobe_delta(
    f: &mut impl FnMut(&[[f64; 4]], &mut [f64]),
    ncomp: usize,
    width: [f64; 2],
    opts: &Options,
) -> (Option<Estimate>, usize) {
    let (lo, hi) = DELTA_T_ORDERS;
    let ((ring, full), cost) = (DELTA_NODE_POINTS, DELTA_COST);
    if cost > opts.max_evals {
        return (None, 0);
    }
    let radii = [DELTA_FIT_RADIUS, DELTA_RADII[0], DELTA_RADII[1]];
    let mut pts = Vec::with_capacity(cost);
    let mut wts = Vec::with_capacity(hi * hi + lo * lo);
    let (mut t, mut w) = (Vec::new(), Vec::new());
    for (order, rings) in [(hi, 1), (lo, radii.len())] {
        legendre_on_into(order, 0.0, 1.0, &mut t, &mut w);
        for (tp, wp) in t.iter().zip(&w) {
            for (tq, wq) in t.iter().zip(&w) {
                wts.push(wp * wq);
                delta_stencil(width, *tp, *tq, &radii[..rings], &mut pts);
            }
        }
    }
    let mut vals = vec![0.0; pts.len() * ncomp];
    f(&pts, &mut vals);
    if vals.iter().any(|v| !v.is_finite()) {
        return (None, cost);
    }
    let scale = std::f64::consts::PI * width[0] * width[1];
    let (mut value, mut error) = (vec![0.0; ncomp], vec![0.0; ncomp]);
    let mut converged = true;
    for c in 0..ncomp {
        let (mut v_hi, mut v_lo, mut bound) = (0.0, 0.0, 0.0);
        let mut start = 0;
        for (k, wt) in wts.iter().enumerate() {
            let n = if k < hi * hi { ring } else { full };
            // This node's values of component c (at most `full` of them), without allocating per node.
            let mut node = [0.0; 1 + 8 * (1 + DELTA_RADII.len())];
            for (slot, i) in node.iter_mut().zip(start..start + n) {
                *slot = vals[i * ncomp + c];
            }
            start += n;
            let Some((mass, b)) = delta_node(&node[..n], &radii[..(n - 1) / 8]) else {
                return (None, cost);
            };
            if k < hi * hi {
                v_hi += wt * mass;
            } else {
                v_lo += wt * mass;
                bound += wt * b;
            }
        }
        value[c] = scale * v_hi;
        error[c] = scale * bound + scale * (v_hi - v_lo).abs();
        converged &= error[c] <= opts.atol.max(opts.rtol * value[c].abs());
    }
    let est = Estimate { value, error, evaluations: 0, regions: 1, converged, out_of_time: false };
    (Some(est), cost)
}

/// The directions of the stencil of [`Rule::LobeDelta`] in the scaled lobe variables (each with its opposite
/// point): 0°, 45°, 90°, 135°.
pub const DELTA_DIRECTIONS: [[f64; 2]; 4] = [
    [1.0, 0.0],
    [std::f64::consts::FRAC_1_SQRT_2, std::f64::consts::FRAC_1_SQRT_2],
    [0.0, 1.0],
    [-std::f64::consts::FRAC_1_SQRT_2, std::f64::consts::FRAC_1_SQRT_2],
];

/// The radius (in lobe widths) of the ring on which [`Rule::LobeDelta`] measures the lobe's curvature.
pub const DELTA_FIT_RADIUS: f64 = 1.0;

/// One t node of [`Rule::LobeDelta`], relative to π (the caller multiplies by π·w_u·w_v): the delta limit's
/// mass and (when `radii` holds the bound's rings too) its majorant, from the values `vals` at the centre
/// and, per ring of `radii` (the first the curvature ring) and direction of [`DELTA_DIRECTIONS`], the point
/// and its opposite. None when the values are not positive where the curvature is measured or the fitted
/// curvature is not positive definite.
///
/// *The curvature*: along direction d at radius r, b(d) = −(½ ln(F(rd)·F(−rd)) − ln F(0))/r² (the even part
/// of ln F, so the odd terms of the lobe and of the rest cancel); B = [[b(0°), β], [β, b(90°)]] with
/// β = ½(b(45°) − b(135°)). *The delta limit* at this node is Laplace's: ∫ F ≈ π·F(0)/√det B (for the exact
/// Gaussian lobe of the linearised widths, B = I and this is π·F(0), the one-node Gauss–Hermite rule).
/// *The majorant*: with h = F·e^{xᵀBx}, h_e(x) = ½(h(x) + h(−x)) and the weight e^{−xᵀBx} even,
///
///   ∫ F − π F(0)/√det B = ∫ e^{−xᵀBx} (h_e(x) − h(0)) dx,
///
/// and if |h_e(x) − h(0)| ≤ Q·xᵀBx on the ellipse xᵀBx ≤ R² and 0 ≤ F(x) ≤ F(0)·e^{−λ·xᵀBx} outside it,
/// then, in y = B^{1/2}x (and as e^{−xᵀBx}·h_e is the even part of F ≥ 0),
///
///   |∫_{xᵀBx≤R²}| ≤ Q ∫ |y|² e^{−|y|²} dy / √det B = π Q / √det B,
///   |∫_{xᵀBx>R²}| ≤ ∫_{xᵀBx>R²} F + |h(0)| π e^{−R²} / √det B ≤ F(0)·π (e^{−λR²}/λ + e^{−R²}) / √det B.
///
/// Q is [`DELTA_SAFETY`] times the largest sampled |h_e − h(0)|/xᵀBx on all rings, R² the smallest xᵀBx on
/// the outer ring and λ the smallest ln(F(0)/F(x))/xᵀBx there, divided by [`DELTA_TAIL_SAFETY`]; None also
/// when λ is not positive (a lobe that does not fall by its outer ring).
fn delta_node(vals: &[f64], radii: &[f64]) -> Option<(f64, f64)> {
    if vals.iter().all(|v| *v == 0.0) {
        return Some((0.0, 0.0));
    }
    let fit = delta_fit(vals, radii)?;
    if radii.len() == 1 {
        return Some((fit.mass(), 0.0));
    }
    let lambda = fit.lambda / DELTA_TAIL_SAFETY;
    if !(lambda > 0.0) {
        return None;
    }
    Some((fit.mass(), fit.majorant(DELTA_SAFETY * fit.q, lambda)))
}

/// What [`Rule::LobeDelta`] measures at one t node ([`delta_fit`]), before its safety factors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeltaFit {
    /// The fitted curvature (b_xx, b_yy, b_xy).
    pub b: [f64; 3],
    /// F(0).
    pub f0: f64,
    /// The largest |h_e − h(0)|/xᵀBx on the rings (0 with the curvature ring only).
    pub q: f64,
    /// The smallest decay rate ln(F(0)/F(x))/xᵀBx on the outer ring (∞ with the curvature ring only).
    pub lambda: f64,
    /// The smallest xᵀBx on the outer ring (∞ with the curvature ring only).
    pub r2: f64,
}

impl DeltaFit {
    /// √det B.
    pub fn root(&self) -> f64 {
        (self.b[0] * self.b[1] - self.b[2] * self.b[2]).sqrt()
    }

    /// The delta limit's mass relative to π·w_u·w_v: F(0)/√det B.
    pub fn mass(&self) -> f64 {
        self.f0 / self.root()
    }

    /// The majorant of [`delta_node`] (relative to π·w_u·w_v) for the constants `q` and `lambda`:
    /// (q + F(0)·(e^{−λR²}/λ + e^{−R²}))/√det B. The rule passes its sampled constants with
    /// [`DELTA_SAFETY`] and [`DELTA_TAIL_SAFETY`] applied; `tests/delta_limit.rs` passes a denser stencil's.
    pub fn majorant(&self, q: f64, lambda: f64) -> f64 {
        let tail = if lambda.is_finite() { (-lambda * self.r2).exp() / lambda } else { 0.0 };
        (q + self.f0 * (tail + (-self.r2).exp())) / self.root()
    }
}

/// The curvature and the bound's sampled constants at one t node of [`Rule::LobeDelta`] from the values
/// `vals` on its stencil ([`delta_stencil`] with `radii`; see [`delta_node`] for the formulas). None when
/// the values are not positive where the curvature is measured or the fitted curvature is not positive
/// definite.
pub fn delta_fit(vals: &[f64], radii: &[f64]) -> Option<DeltaFit> {
    let f0 = vals[0];
    if f0 <= 0.0 || vals[1..9].iter().any(|v| *v <= 0.0) {
        return None;
    }
    let r = radii[0];
    let b: [f64; 4] = std::array::from_fn(|k| -(0.5 * (vals[1 + 2 * k] * vals[2 + 2 * k]).ln() - f0.ln()) / (r * r));
    let (bxx, byy, bxy) = (b[0], b[2], 0.5 * (b[1] - b[3]));
    let det = bxx * byy - bxy * bxy;
    if !(bxx > 0.0 && byy > 0.0 && det > 0.0) {
        return None;
    }
    let (mut q, mut lambda, mut r2) = (0.0f64, f64::INFINITY, f64::INFINITY);
    if radii.len() > 1 {
        let mut i = 1;
        for (j, r) in radii.iter().enumerate() {
            for d in DELTA_DIRECTIONS {
                let (x, y) = (r * d[0], r * d[1]);
                let quad = bxx * x * x + 2.0 * bxy * x * y + byy * y * y;
                let grow = quad.exp();
                let (a, c) = (vals[i] * grow, vals[i + 1] * grow);
                q = q.max(((0.5 * (a + c) - f0) / quad).abs());
                if j == radii.len() - 1 {
                    r2 = r2.min(quad);
                    for v in [vals[i], vals[i + 1]] {
                        // A zero (outside the overlap, or underflow) decays as fast as any rate.
                        if v != 0.0 {
                            lambda = lambda.min((f0 / v.abs()).ln() / quad);
                        }
                    }
                }
                i += 2;
            }
        }
    }
    Some(DeltaFit { b: [bxx, byy, bxy], f0, q, lambda, r2 })
}

/// Append the stencil of one t node (t_p, t_q) of [`Rule::LobeDelta`] to `pts`, in the order [`delta_fit`]
/// reads it: the centre, then per ring of `radii` (in lobe widths) and direction of [`DELTA_DIRECTIONS`] the
/// point and its opposite, in the chart (u, t_p, v, t_q) with the lobe widths `width`.
pub fn delta_stencil(width: [f64; 2], tp: f64, tq: f64, radii: &[f64], pts: &mut Vec<[f64; 4]>) {
    pts.push([0.0, tp, 0.0, tq]);
    for r in radii {
        for d in DELTA_DIRECTIONS {
            for s in [1.0, -1.0] {
                pts.push([s * r * d[0] * width[0], tp, s * r * d[1] * width[1], tq]);
            }
        }
    }
}

/// The smooth-integrand rule of a lobe-chart part without kinks, if it fits: [`Rule::TensorGauss`] in the
/// variables (p_s, p_r, v, t_q) ([`TensorChart::PlainPLobeQ`]: plain in the plane of incidence, where the
/// lobe is far wider than the stops, the lobe variable across it, where the ridge v = q_s + q_r becomes an
/// axis) within the bounds of [`TENSOR_MIN_WIDTH`] (B4's GGX α = 0.3 at 85°: 0.6 wide in u against a u-range
/// of 0.083, 0.052 in v against 0.15). The levels start at 1 (2 points) on every axis.
pub fn smooth_rule(lobes: &[Lobe], theta: f64, src: Stop, rec: Stop) -> Option<Rule> {
    let range = [(src.p[1] - src.p[0]) + (rec.p[1] - rec.p[0]), (src.q[1] - src.q[0]) + (rec.q[1] - rec.q[0])];
    let fits = |l: &Lobe| {
        let w = lobe_widths_uv(l, theta);
        w.iter().all(|w| w.is_finite())
            && w[0] >= TENSOR_MIN_WIDTH_U * range[0]
            && (TENSOR_MIN_WIDTH * range[1]..=TENSOR_MAX_WIDTH_V * range[1]).contains(&w[1])
    };
    if lobes.is_empty() || !lobes.iter().all(fits) {
        return None;
    }
    Some(Rule::TensorGauss { chart: TensorChart::PlainPLobeQ, levels: [1; 4], path: tensor::Path::default() })
}

/// The boxes of [`Rule::TensorGauss`] in its chart's variables: the stops' product (p_s, q_s, p_r, q_r) in the
/// plain chart; in the lobe chart (u, t_p, v, t_q) the products of the intervals between the range ends and
/// the overlap kinks s₁ + r₀, s₀ + r₁ of u and of v (where the overlap length is linear), t ∈ [0, 1].
pub fn tensor_boxes(chart: TensorChart, src: Stop, rec: Stop) -> Vec<([f64; 4], [f64; 4])> {
    let kinks = |a: AxisMap| {
        let [lo, hi] = a.range();
        let mut x = vec![lo, hi, a.s[1] + a.r[0], a.s[0] + a.r[1]];
        x.retain(|x| *x >= lo && *x <= hi);
        x.sort_by(f64::total_cmp);
        x.dedup_by(|a, b| (*a - *b).abs() <= 1e-14 * (hi - lo));
        x
    };
    match chart {
        TensorChart::Plain => {
            vec![([src.p[0], src.q[0], rec.p[0], rec.q[0]], [src.p[1], src.q[1], rec.p[1], rec.q[1]])]
        }
        TensorChart::Lobe => {
            lobe_boxes(&[kinks(AxisMap { s: src.p, r: rec.p }), kinks(AxisMap { s: src.q, r: rec.q })])
        }
        TensorChart::PlainPLobeQ => kinks(AxisMap { s: src.q, r: rec.q })
            .windows(2)
            .map(|v| ([src.p[0], rec.p[0], v[0], 0.0], [src.p[1], rec.p[1], v[1], 1.0]))
            .collect(),
    }
}

/// Run [`Rule::TensorGauss`]: the estimate and the rule with its path of raises when the orders converged (or
/// the path was replayed), else None; and the evaluations spent either way.
fn tensor_gauss(
    f: &mut impl FnMut(&[[f64; 4]], &mut [f64]),
    ncomp: usize,
    chart: TensorChart,
    boxes: Vec<([f64; 4], [f64; 4])>,
    levels: [usize; 4],
    opts: &Options,
    replay: Option<tensor::Path>,
) -> (Option<(Estimate, Rule)>, usize) {
    let (r, spent) = tensor::integrate(
        f,
        ncomp,
        &boxes,
        levels,
        tensor::Adapt { max_level: TENSOR_MAX_LEVEL, shared: true },
        opts,
        replay,
    );
    let r = r.map(|(t, path)| {
        let est = Estimate {
            value: t.value,
            error: t.error,
            evaluations: 0,
            regions: boxes.len(),
            converged: t.converged,
            out_of_time: false,
        };
        (est, Rule::TensorGauss { chart, levels, path })
    });
    (r, spent)
}

/// The buffers of [`Rule::LobeGaussHermite`], made once per execution and reused level after level (issue 10
/// item 4: nothing in the hot path allocates).
#[derive(Default)]
struct HermiteScratch {
    wh: Vec<f64>,
    t: (Vec<f64>, Vec<f64>),
    pts: Vec<[f64; 4]>,
    wts: Vec<f64>,
    vals: Vec<f64>,
}

/// One level of [`Rule::LobeGaussHermite`]: the tensor rule's sum per component into `sum`, in a fixed point
/// order.
fn lobe_tensor_sum(
    f: &mut impl FnMut(&[[f64; 4]], &mut [f64]),
    ncomp: usize,
    width: [f64; 2],
    (nh, nt): (usize, usize),
    s: &mut HermiteScratch,
    sum: &mut [f64],
) {
    let (xh, wh0) = gauss_hermite_table(nh);
    // ∫ g(u) du = w ∫ g(w x) e^{x²} e^{−x²} dx: the weights for g itself.
    s.wh.clear();
    s.wh.extend(xh.iter().zip(wh0).map(|(x, w)| w * (x * x).exp()));
    let (tl, wl) = &mut s.t;
    tl.clear();
    wl.clear();
    let (xl, wl0) = gauss_legendre_table(nt);
    tl.extend(xl.iter().map(|x| 0.5 * (x + 1.0)));
    wl.extend(wl0.iter().map(|w| 0.5 * w));
    s.vals.clear();
    s.vals.resize(nh * nt * nt * ncomp, 0.0);
    sum.iter_mut().for_each(|x| *x = 0.0);
    for (x, wx) in xh.iter().zip(&s.wh) {
        s.pts.clear();
        s.wts.clear();
        for (y, wy) in xh.iter().zip(&s.wh) {
            for (tp, wp) in tl.iter().zip(wl.iter()) {
                for (tq, wq) in tl.iter().zip(wl.iter()) {
                    s.pts.push([width[0] * x, *tp, width[1] * y, *tq]);
                    s.wts.push(wx * wy * wp * wq);
                }
            }
        }
        s.vals.iter_mut().for_each(|v| *v = 0.0);
        f(&s.pts, &mut s.vals);
        for (w, v) in s.wts.iter().zip(s.vals.chunks_exact(ncomp)) {
            for c in 0..ncomp {
                let v = if v[c].is_finite() { v[c] } else { 0.0 };
                sum[c] += w * v;
            }
        }
    }
    sum.iter_mut().for_each(|x| *x = *x * width[0] * width[1]);
}

/// Run [`Rule::LobeGaussHermite`]: levels `levels.0..=levels.1` of [`LOBE_LEVELS`] until two successive ones
/// agree to max(atol, rtol·|I|) in every component (adaptive), or just those levels (frozen). Returns the
/// estimate and its last level when they agree, else None, and the evaluations spent either way.
fn lobe_gauss_hermite(
    f: &mut impl FnMut(&[[f64; 4]], &mut [f64]),
    ncomp: usize,
    width: [f64; 2],
    levels: (usize, usize),
    opts: &Options,
    refine: Refine,
) -> (Option<(Estimate, usize)>, usize) {
    let cost = |(nh, nt): (usize, usize)| nh * nh * nt * nt;
    let mut evals = 0;
    let mut scratch = HermiteScratch::default();
    let (mut now, mut prev) = (vec![0.0; ncomp], vec![0.0; ncomp]);
    let mut have_previous = false;
    let last = levels.1.min(LOBE_LEVELS.len() - 1);
    for (level, &orders) in LOBE_LEVELS.iter().enumerate().take(last + 1).skip(levels.0) {
        if evals + cost(orders) > opts.max_evals {
            break;
        }
        lobe_tensor_sum(f, ncomp, width, orders, &mut scratch, &mut now);
        evals += cost(orders);
        if have_previous {
            let converged = now.iter().zip(&prev).all(|(v, p)| (v - p).abs() <= opts.atol.max(opts.rtol * v.abs()));
            if converged || refine == Refine::Frozen {
                let error: Vec<f64> = now.iter().zip(&prev).map(|(a, b)| (a - b).abs()).collect();
                let est = Estimate { value: now, error, evaluations: 0, regions: 1, converged, out_of_time: false };
                return (Some((est, level)), evals);
            }
        }
        std::mem::swap(&mut now, &mut prev);
        have_previous = true;
    }
    (None, evals)
}

/// The polar rule of a lobe-chart part, if one fits ([`Rule::LobePolar`]): a material whose regular part is
/// one lobe with GGX's tail (`Tail::InverseQuartic`: not a lobe over a diffuse body; a Gaussian tail gets
/// [`Rule::LobeGaussHermite`] or the partition; a measured table's lobe, `Tail::Table`, keeps the partition:
/// the rule was measured on every shipped table and on MERL-format GGX tables and lost or fell back on each,
/// because the table's interpolation kinks at its cells, not its tail, set the cost, see
/// `docs/instrument.md` §Quadrature, *Measured tables*) whose centre u = v = 0 is inside the range of the lobe variables and at least
/// [`POLAR_REACH`] widths from every kink of the overlap length and every end of the range, on both axes.
pub fn polar_rule(lobes: &[Lobe], has_diffuse: bool, theta: f64, src: Stop, rec: Stop) -> Option<Rule> {
    let [lobe] = lobes else { return None };
    if has_diffuse || lobe.tail != Tail::InverseQuartic {
        return None;
    }
    let width = lobe_widths_uv(lobe, theta);
    let breaks = |a: AxisMap, w: f64| {
        let [lo, hi] = a.range();
        let mut b = [lo, a.s[1] + a.r[0], a.s[0] + a.r[1], hi];
        b.sort_by(f64::total_cmp);
        let clear = w > 0.0 && w.is_finite() && lo < 0.0 && hi > 0.0 && b.iter().all(|k| k.abs() >= POLAR_REACH * w);
        clear.then_some(b)
    };
    let u = breaks(AxisMap { s: src.p, r: rec.p }, width[0])?;
    let v = breaks(AxisMap { s: src.q, r: rec.q }, width[1])?;
    Some(Rule::LobePolar { width, u, v, levels: [1; 9] })
}

/// One piece of [`Rule::LobePolar`]: its u and v intervals, whether it holds the lobe centre (the polar
/// piece), its level and its sums at that level and the one below.
struct PolarPiece {
    index: usize,
    interval: [[f64; 2]; 2],
    central: bool,
    level: usize,
    below: Vec<f64>,
    at: Vec<f64>,
}

/// The buffers [`Rule::LobePolar`] works in, made once per execution and reused level after level (issue 10
/// item 4: nothing in the hot path allocates; they only grow, to the largest level reached).
#[derive(Default)]
struct PolarScratch {
    /// (x, y, weight) in the scaled lobe variables.
    plane: Vec<(f64, f64, f64)>,
    rect: Vec<([f64; 2], f64)>,
    buffers: PolarBuffers,
    outer: (Vec<f64>, Vec<f64>),
    inner: (Vec<f64>, Vec<f64>),
    t: (Vec<f64>, Vec<f64>),
    pts: Vec<[f64; 4]>,
    wts: Vec<f64>,
    vals: Vec<f64>,
}

/// The points of a piece of [`Rule::LobePolar`] at one level, in the lobe chart's variables (u, t_p, v, t_q),
/// with their weights, in a fixed order, into `s.pts` and `s.wts`.
fn polar_piece_points(width: [f64; 2], interval: [[f64; 2]; 2], central: bool, level: usize, s: &mut PolarScratch) {
    let [w0, w1] = width;
    let scaled = [[interval[0][0] / w0, interval[0][1] / w0], [interval[1][0] / w1, interval[1][1] / w1]];
    // (x, y, weight) in the scaled lobe variables x = u/w_u, y = v/w_v.
    s.plane.clear();
    let nt = if central {
        let (nphi, nr, nt) = POLAR_LEVELS[level];
        let lo = [scaled[0][0], scaled[1][0]];
        let hi = [scaled[0][1], scaled[1][1]];
        polar_rectangle_into(lo, hi, nphi, nr, Map::Tan { scale: 1.0 }, &mut s.buffers, &mut s.rect);
        s.plane.extend(s.rect.iter().map(|&([x, y], w)| (x, y, w)));
        nt
    } else {
        // The tail coordinate is the axis whose interval does not hold 0 (the first when neither does): σ = 1/x
        // along it; across it the kernel 1/(c² + y²)² (c² = 1 + x²) in y = c·tan γ.
        let (no, ni, nt) = TAIL_LEVELS[level];
        let outer = if scaled[0][0] < 0.0 && scaled[0][1] > 0.0 { 1 } else { 0 };
        let inner = 1 - outer;
        let (xo, wo) = &mut s.outer;
        mapped_legendre_into(no, scaled[outer][0], scaled[outer][1], Map::Reciprocal, xo, wo);
        let (y, wy) = &mut s.inner;
        for (x, wx) in xo.iter().zip(wo.iter()) {
            let map = Map::Tan { scale: (1.0 + x * x).sqrt() };
            mapped_legendre_into(ni, scaled[inner][0], scaled[inner][1], map, y, wy);
            for (y, wy) in y.iter().zip(wy.iter()) {
                s.plane.push(if outer == 0 { (*x, *y, wx * wy) } else { (*y, *x, wx * wy) });
            }
        }
        nt
    };
    let (tl, wl) = &mut s.t;
    legendre_on_into(nt, 0.0, 1.0, tl, wl);
    s.pts.clear();
    s.wts.clear();
    for &(x, y, w) in &s.plane {
        for (tp, wp) in tl.iter().zip(wl.iter()) {
            for (tq, wq) in tl.iter().zip(wl.iter()) {
                s.pts.push([w0 * x, *tp, w1 * y, *tq]);
                s.wts.push(w * w0 * w1 * wp * wq);
            }
        }
    }
}

/// The sum of the points in `s` per component into `sum` (non-finite values count as 0, as in
/// [`lobe_tensor_sum`]).
fn polar_piece_sum(f: &mut impl FnMut(&[[f64; 4]], &mut [f64]), ncomp: usize, s: &mut PolarScratch, sum: &mut [f64]) {
    s.vals.clear();
    s.vals.resize(s.pts.len() * ncomp, 0.0);
    f(&s.pts, &mut s.vals);
    sum.iter_mut().for_each(|x| *x = 0.0);
    for (w, v) in s.wts.iter().zip(s.vals.chunks_exact(ncomp)) {
        for c in 0..ncomp {
            if v[c].is_finite() {
                sum[c] += w * v[c];
            }
        }
    }
}

/// Run [`Rule::LobePolar`]: every piece at its level and the one below; while the summed differences exceed
/// max(atol, rtol·|I|) in some component, the piece with the largest difference (relative to that tolerance;
/// the first on ties) goes one level up (adaptive; a frozen rule keeps its levels). Returns the estimate and
/// the pieces' levels when the sum meets the tolerance, None when the piece to raise has no level left or the
/// budget would be exceeded, and the evaluations spent either way. Its buffers are made once here (per
/// piece and per execution, not per level).
fn lobe_polar(
    f: &mut impl FnMut(&[[f64; 4]], &mut [f64]),
    ncomp: usize,
    width: [f64; 2],
    breaks: [[f64; 4]; 2],
    levels: [u8; 9],
    opts: &Options,
    refine: Refine,
) -> (Option<(Estimate, [u8; 9])>, usize) {
    let mut evals = 0;
    let mut pieces = Vec::with_capacity(9);
    for i in 0..3 {
        for j in 0..3 {
            let interval = [[breaks[0][i], breaks[0][i + 1]], [breaks[1][j], breaks[1][j + 1]]];
            if !(interval[0][1] > interval[0][0] && interval[1][1] > interval[1][0]) {
                continue;
            }
            let holds = |a: [f64; 2]| a[0] < 0.0 && a[1] > 0.0;
            let central = holds(interval[0]) && holds(interval[1]);
            let top = if central { POLAR_LEVELS.len() } else { TAIL_LEVELS.len() } - 1;
            let level = (levels[3 * i + j] as usize).clamp(1, top);
            let (below, at) = (vec![0.0; ncomp], vec![0.0; ncomp]);
            pieces.push(PolarPiece { index: 3 * i + j, interval, central, level, below, at });
        }
    }
    let mut scratch = PolarScratch::default();
    // The sums of one piece at one level into `sum`; false when the budget would be exceeded.
    let mut run = |p: &PolarPiece, level: usize, evals: &mut usize, sum: &mut [f64]| -> bool {
        polar_piece_points(width, p.interval, p.central, level, &mut scratch);
        if *evals + scratch.pts.len() > opts.max_evals {
            return false;
        }
        *evals += scratch.pts.len();
        polar_piece_sum(f, ncomp, &mut scratch, sum);
        true
    };
    for p in &mut pieces {
        let mut below = std::mem::take(&mut p.below);
        let mut at = std::mem::take(&mut p.at);
        if !run(p, p.level - 1, &mut evals, &mut below) || !run(p, p.level, &mut evals, &mut at) {
            return (None, evals);
        }
        p.below = below;
        p.at = at;
    }
    let (mut value, mut error, mut tol) = (vec![0.0; ncomp], vec![0.0; ncomp], vec![0.0; ncomp]);
    loop {
        for c in 0..ncomp {
            value[c] = pieces.iter().map(|p| p.at[c]).sum();
            error[c] = pieces.iter().map(|p| (p.at[c] - p.below[c]).abs()).sum();
            tol[c] = opts.atol.max(opts.rtol * value[c].abs());
        }
        let converged = error.iter().zip(&tol).all(|(e, t)| e <= t);
        if converged || refine == Refine::Frozen {
            let mut reached = [1u8; 9];
            for p in &pieces {
                reached[p.index] = p.level as u8;
            }
            let regions = pieces.len();
            let est = Estimate { value, error, evaluations: 0, regions, converged, out_of_time: false };
            return (Some((est, reached)), evals);
        }
        let excess = |p: &PolarPiece| {
            (0..ncomp)
                .map(|c| {
                    let e = (p.at[c] - p.below[c]).abs();
                    if tol[c] > 0.0 {
                        e / tol[c]
                    } else if e > 0.0 {
                        f64::INFINITY
                    } else {
                        0.0
                    }
                })
                .fold(0.0, f64::max)
        };
        let mut worst = 0;
        for k in 1..pieces.len() {
            if excess(&pieces[k]) > excess(&pieces[worst]) {
                worst = k;
            }
        }
        let top = if pieces[worst].central { POLAR_LEVELS.len() } else { TAIL_LEVELS.len() } - 1;
        if pieces[worst].level >= top {
            return (None, evals);
        }
        let level = pieces[worst].level + 1;
        // The level below becomes the old level: its buffer is reused for the new sums.
        let p = &mut pieces[worst];
        std::mem::swap(&mut p.below, &mut p.at);
        let mut at = std::mem::take(&mut p.at);
        if !run(&pieces[worst], level, &mut evals, &mut at) {
            return (None, evals);
        }
        let p = &mut pieces[worst];
        p.at = at;
        p.level = level;
    }
}

/// The initial boxes of a lobe chart with `kinks` kinks: every box cut on t_p into kinks + 1 equal pieces
/// (the pieces of `flux::kinked_position`); the boxes unchanged without kinks.
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

/// The direction pairs of one batch above the horizon, with the point index and geometric factor of each.
#[derive(Default)]
struct PairBatch {
    index: Vec<usize>,
    wi: Vec<Vec3>,
    wo: Vec<Vec3>,
    g: Vec<f64>,
    values: Vec<f64>,
}

impl PairBatch {
    /// Empty, with room for `m` pairs (so the hot loop never grows a vector).
    fn clear(&mut self, m: usize) {
        self.index.clear();
        self.wi.clear();
        self.wo.clear();
        self.g.clear();
        self.index.reserve(m);
        self.wi.reserve(m);
        self.wo.reserve(m);
        self.g.reserve(m);
    }

    fn push(&mut self, i: usize, wi: Vec3, wo: Vec3, g: f64) {
        self.index.push(i);
        self.wi.push(wi);
        self.wo.push(wo);
        self.g.push(g);
    }
}

/// Write the integrand at one point: the per-sample values times the geometric factor `g`, either one
/// component per sample ([`Projection::Separate`]) or the k weighted sums Σ_j W[c][j] f_j·g (Fold).
#[inline]
fn store(out: &mut [f64], values: &[f64], weighting: &Weighting, g: f64, projection: Projection) {
    match projection {
        Projection::Separate => {
            for (o, v) in out.iter_mut().zip(values) {
                *o = v * g;
            }
        }
        Projection::Fold | Projection::FoldInMaterial => {
            for (c, o) in out.iter_mut().enumerate() {
                *o = weighting.component(c, values) * g;
            }
        }
    }
}
