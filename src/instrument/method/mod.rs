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
//!
//! The folder, one idea per file:
//! - `mod.rs`: the method as plain data ([`Method`], its identity [`Aperture`], [`Design`] and the
//!   [`MaterialFacts`] it reads, [`Rule`], [`DeltaPart`],
//!   [`RegularPart`], [`Projection`], [`Target`]), the [`Flux`] it produces and [`Method::is_frozen`];
//! - `design.rs`: [`Method::design`], [`Method::for_material`] and [`Method::expected_evaluations`] (the
//!   scheduling guess of `Plan::run_all`), the rule choosers ([`delta_rule`], [`lobe_rule`], [`polar_rule`],
//!   [`smooth_rule`]) and the gates they choose by ([`DELTA_GATE`], [`LOBE_REACH`], [`POLAR_REACH`], [`POLAR_REACH_GRAZING`],
//!   [`TENSOR_MIN_WIDTH`], [`TENSOR_MAX_WIDTH_V`], [`TENSOR_MIN_WIDTH_U`]);
//! - `execute.rs`: [`Method::execute`] and its variants (a deadline, freezing), [`Method::sample_regular`],
//!   the regular part's integrand and [`LATE_START_SHARE`];
//! - `delta.rs`: [`Rule::LobeDelta`]'s executor, its fit ([`DeltaFit`], [`delta_fit`], [`delta_stencil`]) and
//!   its constants (`DELTA_*`, [`DELTA_COST`]);
//! - `gauss.rs`: the executors of [`Rule::LobeGaussHermite`] ([`LOBE_LEVELS`]) and [`Rule::TensorGauss`]
//!   ([`tensor_boxes`], [`TENSOR_MAX_LEVEL`]);
//! - `polar.rs`: [`Rule::LobePolar`]'s executor ([`POLAR_LEVELS`], [`TAIL_LEVELS`]);
//! - `shape.rs`: the interface every rule implements ([`ShapedRule`], [`Integrand`], [`RuleRun`],
//!   [`Outcome`]), a leaf of the folder;
//! - `tail.rs`: [`Rule::TailBound`]'s executor (the material's majorant of a tail the receptor cannot
//!   reach) and `mirror_gap`;
//! - `rule.rs`: a [`Rule`] dispatched to its file's implementation, the fallback chain as data
//!   ([`Rule::fallback`]) and the Genz–Malik partition, the end of every chain.
//!
//! A rule's tuning constants live in the file of the rule that uses them; the design gates in `design.rs`.
mod chart;
mod delta;
mod design;
mod execute;
mod gauss;
mod polar;
mod rule;
mod shape;
mod tail;

pub(crate) use delta::DELTA_RADIUS;
pub use delta::{
    delta_fit, delta_stencil, DeltaFit, DELTA_FIT_RADIUS, DELTA_RADII, DELTA_SAFETY, DELTA_TAIL_SAFETY, DELTA_T_ORDERS,
};
pub(crate) use design::{LOBE_REACH, POLAR_REACH};
pub(crate) use execute::deadline_after;
pub use execute::LATE_START_SHARE;
pub(crate) use gauss::TENSOR_MAX_LEVEL;
pub use gauss::{tensor_boxes, LOBE_LEVELS};
pub(crate) use polar::POLAR_LEVELS;

#[cfg(doc)]
use crate::instrument::aperture::DELTA_SHARE;

use crate::brdf::{Brdf, Hints, Kink, Lobe};
use crate::colorimetry::weighting::Weighting;
pub use crate::instrument::aperture::Chart;
use crate::instrument::geometry::{Integral, Stop};
use crate::quadrature::{tensor, Cell, Refine};

/// Which material a flux is taken on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Target {
    Specimen,
    Standard,
}

/// The identity of one integral: which material, what kind of integral, the geometry angle, the receptor's
/// axis and the two stops as the geometry gives them. Everything a method's design depends on besides the
/// material, the weighting and the tolerances, held once by the planner's draft, the [`Design`] and the
/// [`Method`]. Equal and hashed by the bits of its numbers: it is the key under which a plan shares one
/// flux between readings and the planner caches a standard's flux (`plan::compile`), so two integrals are
/// one when, and only when, their designs are the same bits.
#[derive(Clone, Copy, Debug)]
pub struct Aperture {
    pub target: Target,
    /// What is integrated: an aperture integral, or a d/8 sphere's hemisphere or specular port (then the
    /// stops are unused, and zero).
    pub integral: Integral,
    /// Geometry angle θ (the source lens axis; a sphere's viewing angle).
    pub theta: f64,
    /// The receptor lens axis, radians, signed: θ for gloss; θ − aspecular for multi-angle colour, whose
    /// receptor never sees the mirror image (no delta part, the plain chart).
    pub viewing: f64,
    pub source: Stop,
    pub receptor: Stop,
}

impl Aperture {
    /// Every field as bits, the integral's kind as a code: what equality and the hash compare.
    fn bits(&self) -> [u64; 13] {
        let (kind, half_angle) = match self.integral {
            Integral::Aperture => (0, 0.0),
            Integral::Hemisphere => (1, 0.0),
            Integral::Port { half_angle } => (2, half_angle),
        };
        let [s, r] = [self.source, self.receptor];
        [
            self.target as u64,
            kind,
            half_angle.to_bits(),
            self.theta.to_bits(),
            self.viewing.to_bits(),
            s.p[0].to_bits(),
            s.p[1].to_bits(),
            s.q[0].to_bits(),
            s.q[1].to_bits(),
            r.p[0].to_bits(),
            r.p[1].to_bits(),
            r.q[0].to_bits(),
            r.q[1].to_bits(),
        ]
    }
}

impl PartialEq for Aperture {
    fn eq(&self, other: &Aperture) -> bool {
        self.bits() == other.bits()
    }
}

impl Eq for Aperture {}

impl std::hash::Hash for Aperture {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.bits().hash(state)
    }
}

/// What the designer needs to know about a material, read from its terms once per plan (not once per
/// integral): its lobes (for the chart, the split points and the shaped rules), its kinks (put on partition
/// boundaries) and which kinds of terms it has.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct MaterialFacts {
    pub lobes: Vec<Lobe>,
    /// The material's kinks (`Hints::kinks`).
    pub kinks: Vec<Kink>,
    /// Whether the material has a delta term, a regular (diffuse or lobe) term, and a diffuse one.
    pub has_delta: bool,
    pub has_regular: bool,
    pub has_diffuse: bool,
}

impl MaterialFacts {
    /// The facts of `brdf`'s terms and kinks.
    pub(crate) fn of(brdf: &dyn Brdf) -> MaterialFacts {
        MaterialFacts::from_hints(&brdf.hints())
    }

    /// The facts of a material's hints ([`Brdf::hints`], read once by the caller).
    pub(crate) fn from_hints(hints: &Hints) -> MaterialFacts {
        MaterialFacts {
            lobes: hints.lobes(),
            kinks: hints.kinks.clone(),
            has_delta: hints.has_delta(),
            has_regular: hints.has_regular(),
            has_diffuse: hints.has_diffuse(),
        }
    }

    /// A gloss standard's: an ideal mirror and nothing else.
    pub(crate) fn mirror() -> MaterialFacts {
        MaterialFacts { lobes: vec![], kinks: vec![], has_delta: true, has_regular: false, has_diffuse: false }
    }
}

/// The cubature rule of a part, chosen by the planner ([`Method::design`]) from the material's lobes and the
/// geometry; deterministic (the same method for the same input).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rule {
    /// Genz & Malik's degree-7 rule with its embedded null rules for the error estimate
    /// (`quadrature::GenzMalikRule`), globally adaptive on the part's partition. The fallback of every other rule.
    GenzMalik75,
    /// A narrow Gaussian-tailed lobe far from every kink of the overlap (`docs/instrument.md` §Quadrature, "A shaped
    /// rule for a narrow Gaussian lobe"): a tensor product of Gauss–Hermite rules in u and v scaled to the lobe's
    /// widths (u = width\[0\]·x, v = width\[1\]·y, weight e^{−x²−y²}) and Gauss–Legendre rules in t_p and t_q, the
    /// orders raised through [`LOBE_LEVELS`] `levels.0..=levels.1` until two successive levels agree to the part's
    /// tolerance (their difference is the error estimate). If none do, the part's Genz–Malik partition is integrated
    /// instead (the fallback).
    LobeGaussHermite { width: [f64; 2], levels: (usize, usize) },
    /// The delta limit of a narrow Gaussian-tailed lobe far from every kink of the overlap ([`delta_rule`],
    /// `docs/instrument.md` §Quadrature, "The delta limit of a narrow lobe"): in the scaled lobe
    /// variables x = u/w_u, y = v/w_v, at each Gauss–Legendre node of (t_p, t_q), the lobe's mass is Laplace's
    /// π·F(0)/√det B from its curvature B at the peak (measured on a ring of [`DELTA_FIT_RADIUS`] width), and the
    /// error reported is the majorant of `delta::delta_node` (second differences of the even part of F·e^{xᵀBx} on
    /// rings of [`DELTA_RADII`] widths times [`DELTA_SAFETY`], the tail beyond the outer ring at its measured
    /// decay rate ÷ [`DELTA_TAIL_SAFETY`]) plus
    /// the t rule's difference of orders ([`DELTA_T_ORDERS`]: the engine's usual estimate of a Gauss–Legendre
    /// rule on a smooth integrand, as in [`Rule::LobeGaussHermite`]). It is accepted when that
    /// majorant meets the part's tolerance; otherwise the lobe's [`Rule::LobeGaussHermite`] runs (and after
    /// it, if it does not agree either, the Genz–Malik partition). A frozen method replays the same points.
    LobeDelta { width: [f64; 2] },
    /// A narrow lobe with GGX's heavy u⁻⁴ tail (`Tail::InverseQuartic`) whose centre lies inside the kink square
    /// ([`polar_rule`]; `docs/instrument.md` §Quadrature, "Polar variables for a narrow GGX lobe"): the
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
    /// A smooth integrand (`docs/instrument.md` §Quadrature, "A tensor rule for smooth anisotropic integrands": no lobe
    /// much narrower than the stops, no Fresnel kink): the anisotropic tensor Gauss–Legendre rule of
    /// `quadrature::tensor` with the same per-axis orders on every box of `chart`'s kink partition ([`tensor_boxes`]:
    /// the one box of the stops' product in the plain chart, the boxes between the overlap kinks of u and v in the lobe
    /// chart), the orders `tensor::ORDERS[levels[k]]` raised one axis at a time (up to [`TENSOR_MAX_LEVEL`]) until the
    /// sum of the per-axis differences of successive orders (the error estimate) meets the part's tolerance. If they do
    /// not, the part's Genz–Malik partition is integrated instead (the fallback). `path` is empty when designed; a
    /// frozen method keeps the raises of its run and replays them (the same points, the same bits).
    TensorGauss { chart: Chart, levels: [usize; 4], path: tensor::Path },
    /// A receptor the lobe cannot reach (`docs/instrument.md` §Quadrature, "A receptor the lobe cannot
    /// reach"; `tail.rs`): the regular part settled without evaluating it, by the material's majorant of
    /// f·cos θi·cos θo at the smallest angle the two stops leave between ωo and the mirror image of ωi
    /// ([`Brdf::tail_majorant`]) times the stops' solid angles: the reading is half that bound and its error
    /// the other half, accepted when the error meets the part's tolerance. Designed where the receptor does not
    /// see the mirror image, the material has no diffuse term and the partition would run otherwise; decided at
    /// run time (a method does not hold the material), also when frozen. If the material has no majorant or it
    /// is too large, the part's Genz–Malik partition is integrated instead (the fallback).
    TailBound,
}

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
    /// (kept to measure what folding saves; `plan::Engine::fold_spectral`).
    Separate,
}

/// The ideal-mirror part: a 2-D integral of R(θi) cos θi dω over the mirror overlap.
#[derive(Clone, Debug, PartialEq)]
pub struct DeltaPart {
    pub rule: Rule,
    /// The cosines of the critical angles (`Kink::Incidence`) whose curve cos θi = c may cross the overlap, in
    /// increasing order. Empty: the variables are (p, q). Otherwise (t, q): for each q, p runs over the
    /// overlap in m + 1 pieces cut at the kinks' positions p*(q) (`aperture::kinked_position`), t ∈ [0, 1] with
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
    /// domain, in increasing order. On the mirror axis a kink forces the lobe chart: for each (u, q_s, q_r)
    /// the overlap position t_p runs over p_s in m + 1 pieces cut where ωi·ωo = 2c² − 1
    /// (`aperture::half_angle_kink_point`). Off it (the plain chart) the first variable is the kinked position
    /// t of p_s for each (q_s, p_r, q_r) (`aperture::plain_kink_point`). Either way every kink lies on a
    /// boundary of the initial boxes.
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
    /// Which integral this is (the material, the kind of integral, the axes, the stops as the geometry gives
    /// them). A sphere's integral (`Integral::Hemisphere`, `Integral::Port`) leaves the stops, parts and
    /// partitions below unused: the sphere's own integrators run (`instrument::sphere`).
    pub aperture: Aperture,
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
pub(crate) struct Design<'a> {
    pub aperture: Aperture,
    /// What the designer needs to know about the material (computed once per plan).
    pub facts: &'a MaterialFacts,
    pub weighting: Weighting,
    pub projection: Projection,
    /// Relative tolerance of the flux and its absolute floor.
    pub rtol: f64,
    pub atol: f64,
    pub max_evals: usize,
    pub max_seconds: Option<f64>,
}

/// The result of one aperture integral: k components, one per row of the method's spectral weighting
/// (one, the luminous flux, for gloss readings).
#[derive(Clone, Debug, PartialEq)]
pub struct Flux {
    /// Weighted flux per component (sr² units of the BRDF integral; the same units for specimen and
    /// standard).
    pub value: Vec<f64>,
    /// Error estimate per component (absolute).
    pub error: Vec<f64>,
    /// The analytic (delta) and numerical (regular) parts, per component.
    pub delta: Vec<f64>,
    pub regular: Vec<f64>,
    /// Integrand evaluations spent (both parts).
    pub evaluations: usize,
    /// Regions of the final partitions (both parts).
    pub regions: usize,
    /// Whether both parts met their tolerances within the budget.
    pub converged: bool,
    /// Whether a part stopped at the wall-clock budget (`Method::max_seconds`).
    pub out_of_time: bool,
    /// Whether a part ended unconverged because it reached the evaluation budget (an adaptive part's only
    /// way to end short of its tolerance besides the clock); false for a frozen part that does not meet its
    /// tolerance, which no budget would help (docs/instrument.md §Bounded work).
    pub budget_spent: bool,
    /// Wall time of the integral.
    pub seconds: f64,
    /// The chart the regular part was integrated in: the part's, or the shaped rule's that gave the value
    /// (None: there was no regular part).
    pub chart: Option<Chart>,
    /// The data (resolution) uncertainty per component, absolute, for a measured table read through the
    /// plan (`Plan::run`; `docs/accuracy.md` §Data uncertainty of measured tables); None for a model, and for
    /// an integral run on its own ([`Method::execute`]). Not part of `error`, which stays the numerical error.
    pub data_uncertainty: Option<Vec<f64>>,
    /// Why the flux has no value, when its material refused it (a far field outside its validity,
    /// docs/optics.md §11.4); the readings that use it carry this as their problem.
    pub refused: Option<String>,
}

impl Flux {
    /// The flux of an empty integral (stops below the horizon, or nothing to integrate), k components.
    pub(crate) fn zero(k: usize) -> Flux {
        Flux {
            value: vec![0.0; k],
            error: vec![0.0; k],
            delta: vec![0.0; k],
            regular: vec![0.0; k],
            evaluations: 0,
            regions: 0,
            converged: true,
            out_of_time: false,
            budget_spent: false,
            seconds: 0.0,
            chart: None,
            data_uncertainty: None,
            refused: None,
        }
    }
}

impl Method {
    /// The same method at another relative tolerance: the flux's and each part's tolerance and absolute floor
    /// scaled by rtol / self.rtol (the shares and floors of `Plan::compile` are proportional to the rtol).
    pub(crate) fn with_rtol(&self, rtol: f64) -> Method {
        let s = rtol / self.rtol;
        let mut m = self.clone();
        m.rtol = rtol;
        if let Some(d) = &mut m.delta {
            d.rtol *= s;
            d.atol *= s;
        }
        if let Some(r) = &mut m.regular {
            r.rtol *= s;
            r.atol *= s;
        }
        m
    }

    /// Whether the method was frozen (its parts re-run a kept partition without refinement).
    pub fn is_frozen(&self) -> bool {
        self.delta.iter().all(|p| p.refine == Refine::Frozen) && self.regular.iter().all(|p| p.refine == Refine::Frozen)
    }
}
