//! Genz–Malik degree-7/5 rule and the globally adaptive driver.
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Stopping criteria.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Relative tolerance on each component of the integral.
    pub rtol: f64,
    /// Absolute tolerance on each component (a floor under the relative one).
    pub atol: f64,
    /// Hard limit on integrand evaluations; the result then says `converged: false`.
    pub max_evals: usize,
    /// Wall-clock limit: no refinement step starts after this instant (the result then says
    /// `converged: false` and `out_of_time: true`). None: no limit (the default; results are then the same
    /// bits on every machine).
    pub deadline: Option<std::time::Instant>,
    /// The most a box's calibrated estimate may shrink below N₁ = |I₇ − I₅| ([`calibrated`]):
    /// [`MAX_SHRINK`] (8) by default; [`MAX_SHRINK_LOBE`] (16) on the lobe chart of a smooth material.
    pub max_shrink: f64,
    /// Whether a split box's children have their estimates scaled from their parent's check
    /// ([`child_scale`]); only for an integrand that is smooth inside every box (a material that says
    /// `Hints::smooth`), `docs/accuracy.md` §5.
    pub checked: bool,
}

/// The relative tolerance when none is given: the one default of the whole library (re-exported as
/// `instrument::plan::DEFAULT_RTOL` for every request and front end).
pub const DEFAULT_RTOL: f64 = 1e-6;

impl Default for Options {
    fn default() -> Self {
        Options {
            rtol: DEFAULT_RTOL,
            atol: 0.0,
            max_evals: 20_000_000,
            deadline: None,
            max_shrink: MAX_SHRINK,
            checked: false,
        }
    }
}

/// The result of an integration.
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    /// The integral, one value per component (degree-7 rule summed over all regions).
    pub value: Vec<f64>,
    /// Error estimate per component: Σ over regions of the calibrated null-rule estimate ([`calibrated`]),
    /// scaled by the region's parent check when `Options::checked` ([`child_scale`]).
    pub error: Vec<f64>,
    pub evaluations: usize,
    pub regions: usize,
    /// True when every component met max(atol, rtol·|I|) before `max_evals`.
    pub converged: bool,
    /// True when the refinement stopped at the wall-clock deadline.
    pub out_of_time: bool,
}

/// The Genz–Malik point set and weights for dimension `D` (2 ≤ D ≤ 8).
#[derive(Clone, Debug)]
pub(crate) struct GenzMalikRule<const D: usize> {
    /// Points of the unit cube [−1, 1]^D with their weight index (0..5) and, for the axial points
    /// (classes 1 and 2), their axis (0 otherwise).
    points: Vec<([f64; D], usize, usize)>,
    w7: [f64; 5],
    w5: [f64; 5],
    /// The embedded degree-3 rule on the centre and the ±λ4 axial points (for the second and third null
    /// rules of [`calibrated`]; the degree-1 rule is the centre alone).
    w3: [f64; 5],
}

const L2: f64 = 0.358_568_582_800_318_1; // sqrt(9/70)
const L4: f64 = 0.948_683_298_050_513_8; // sqrt(9/10)
const L5: f64 = 0.688_247_201_611_685_3; // sqrt(9/19)

impl<const D: usize> Default for GenzMalikRule<D> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const D: usize> GenzMalikRule<D> {
    /// The rule exists for 2 ≤ D ≤ 8 (Genz & Malik 1980); another D is refused at compile time.
    const DIMENSION_SUPPORTED: () = assert!(D >= 2 && D <= 8, "Genz–Malik needs 2 ≤ D ≤ 8");

    pub(crate) fn new() -> Self {
        let () = Self::DIMENSION_SUPPORTED;
        let d = D as f64;
        let mut points = Vec::with_capacity(1 + 4 * D + 2 * D * (D - 1) + (1 << D));
        points.push(([0.0; D], 0, 0));
        for i in 0..D {
            for s in [-1.0, 1.0] {
                let mut x = [0.0; D];
                x[i] = s * L2;
                points.push((x, 1, i));
            }
        }
        for i in 0..D {
            for s in [-1.0, 1.0] {
                let mut x = [0.0; D];
                x[i] = s * L4;
                points.push((x, 2, i));
            }
        }
        for i in 0..D {
            for j in i + 1..D {
                for (si, sj) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
                    let mut x = [0.0; D];
                    x[i] = si * L4;
                    x[j] = sj * L4;
                    points.push((x, 3, 0));
                }
            }
        }
        for mask in 0..(1usize << D) {
            let mut x = [0.0; D];
            for (k, xk) in x.iter_mut().enumerate() {
                *xk = if mask >> k & 1 == 1 { L5 } else { -L5 };
            }
            points.push((x, 4, 0));
        }
        // Weights for the average over [-1,1]^D (they sum to 1 with multiplicities).
        let w7 = [
            (12824.0 - 9120.0 * d + 400.0 * d * d) / 19683.0,
            980.0 / 6561.0,
            (1820.0 - 400.0 * d) / 19683.0,
            200.0 / 19683.0,
            6859.0 / 19683.0 / (1u64 << D) as f64,
        ];
        let w5 = [
            (729.0 - 950.0 * d + 50.0 * d * d) / 729.0,
            245.0 / 486.0,
            (265.0 - 100.0 * d) / 1458.0,
            25.0 / 729.0,
            0.0,
        ];
        // Degree 3 on the centre and the 2D points ±λ4 on the axes: 2·w·λ4² = 1/3 (the mean of x² over
        // [−1, 1]), the centre takes the rest.
        let w3_axial = 1.0 / (6.0 * L4 * L4);
        let w3 = [1.0 - 2.0 * d * w3_axial, 0.0, w3_axial, 0.0, 0.0];
        GenzMalikRule { points, w7, w5, w3 }
    }

    /// Number of integrand evaluations per region: 2^D + 2D² + 2D + 1.
    pub(crate) fn len(&self) -> usize {
        self.points.len()
    }
}

/// One box of a partition, as its centre and half-widths (the form the rule is applied in). A partition kept
/// from an adaptive run ([`integrate_partition`] with `keep: true`) re-applies the rule at exactly the same
/// points, so a frozen re-run of the same integrand gives the same bits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell<const D: usize> {
    pub center: [f64; D],
    pub half: [f64; D],
    /// The factor its parent's check put on the cell's calibrated estimate ([`child_scale`]; 1 for a cell
    /// of an initial partition or of an unchecked run), kept with a frozen partition so that a re-run gives
    /// the same estimate bits.
    pub scale: f64,
    /// Whether the cell is half of a bisected one. Only such a cell's calibrated estimate may shrink below
    /// N₁: the null rules of a box the refinement has never split were fooled on a smooth tail
    /// ([`calibrated`], `docs/accuracy.md` §5.2).
    pub split: bool,
}

impl<const D: usize> Cell<D> {
    /// The box [lo, hi] as a cell; None if it is degenerate (a zero or negative width on some axis).
    pub(crate) fn from_box(lo: &[f64; D], hi: &[f64; D]) -> Option<Cell<D>> {
        let mut c = [0.0; D];
        let mut h = [0.0; D];
        for k in 0..D {
            c[k] = 0.5 * (lo[k] + hi[k]);
            h[k] = 0.5 * (hi[k] - lo[k]);
            if !(h[k] > 0.0) {
                return None;
            }
        }
        Some(Cell { center: c, half: h, scale: 1.0, split: false })
    }

    /// The cells of a list of boxes, degenerate ones dropped.
    pub fn from_boxes(boxes: &[([f64; D], [f64; D])]) -> Vec<Cell<D>> {
        boxes.iter().filter_map(|(lo, hi)| Cell::from_box(lo, hi)).collect()
    }
}

/// Whether the driver refines the partition.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refine {
    /// Globally adaptive: bisect the worst cell until the tolerance or the budget is met.
    Adaptive,
    /// Apply the rule once to every given cell and stop (a frozen partition).
    Frozen,
}

/// Components stored inline up to this many (a luminous flux has 1, a colour flux 3, a flux both use 4).
const INLINE: usize = 4;

/// A region's ncomp sums: inline for ncomp ≤ [`INLINE`], so that refining a region allocates nothing
/// (`docs/performance.md` §"Folded paint evaluation and fixed costs": nothing in the hot path allocates); on the heap
/// beyond.
struct Comps {
    len: usize,
    inline: [f64; INLINE],
    heap: Vec<f64>,
}

impl Comps {
    fn zeros(len: usize) -> Comps {
        let heap = if len > INLINE { vec![0.0; len] } else { Vec::new() };
        Comps { len, inline: [0.0; INLINE], heap }
    }
}

impl std::ops::Deref for Comps {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        if self.len <= INLINE {
            &self.inline[..self.len]
        } else {
            &self.heap
        }
    }
}

impl std::ops::DerefMut for Comps {
    fn deref_mut(&mut self) -> &mut [f64] {
        if self.len <= INLINE {
            &mut self.inline[..self.len]
        } else {
            &mut self.heap
        }
    }
}

struct Region<const D: usize> {
    cell: Cell<D>,
    value: Comps,
    error: Comps,
    /// N₁ = |I₇ − I₅| per component and the calibrated estimate before the cell's scale.
    n1: Comps,
    base: Comps,
    /// Whether the region's parent passed its check ([`child_scale`] < 1).
    checked: bool,
    /// Largest component error: the priority.
    worst: f64,
    split_axis: usize,
    /// Creation order, for deterministic tie-breaking and final summation order.
    id: usize,
}

impl<const D: usize> PartialEq for Region<D> {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl<const D: usize> Eq for Region<D> {}
impl<const D: usize> PartialOrd for Region<D> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl<const D: usize> Ord for Region<D> {
    fn cmp(&self, other: &Self) -> Ordering {
        // Max-heap on error; among equal errors the older region first.
        self.worst.total_cmp(&other.worst).then_with(|| other.id.cmp(&self.id))
    }
}

/// Scratch of the batched driver: the points of one call and the integrand values they receive; and the
/// run's cap on the calibrated shrink (`Options::max_shrink`).
struct Batch<const D: usize> {
    points: Vec<[f64; D]>,
    values: Vec<f64>,
    max_shrink: f64,
}

/// Apply the rule to the cells in one integrand call: all their points (57 per 4-D cell) are passed to `f`
/// together, `values` zeroed, and each cell's sums are then formed in the rule's point order (the same
/// order, hence the same bits, as one call per point).
fn apply<const D: usize, F: FnMut(&[[f64; D]], &mut [f64])>(
    rule: &GenzMalikRule<D>,
    f: &mut F,
    cells: &[Cell<D>],
    ncomp: usize,
    batch: &mut Batch<D>,
    first_id: usize,
    out: &mut Vec<Region<D>>,
) {
    let npts = rule.len();
    batch.points.clear();
    for cell in cells {
        for (x, _, _) in &rule.points {
            let mut pt = [0.0; D];
            for k in 0..D {
                pt[k] = cell.center[k] + cell.half[k] * x[k];
            }
            batch.points.push(pt);
        }
    }
    batch.values.clear();
    batch.values.resize(batch.points.len() * ncomp, 0.0);
    f(&batch.points, &mut batch.values);
    out.clear();
    out.extend(cells.iter().enumerate().map(|(i, cell)| {
        summarise(
            rule,
            *cell,
            &batch.values[i * npts * ncomp..(i + 1) * npts * ncomp],
            ncomp,
            first_id + i,
            batch.max_shrink,
        )
    }));
}

/// Components up to this many get the calibrated estimate ([`calibrated`]); more (an unfolded spectrum, n
/// samples) keep |I₇ − I₅| (the sums would need per-call allocation).
const MAX_SMALL: usize = 8;

/// The calibration of [`calibrated`]: the error of the reported I₇ is taken as `CALIBRATION`·r·N₁ when the
/// null rules fall by r per step, never less than N₁/`MAX_SHRINK`.
pub(crate) const CALIBRATION: f64 = 3.0;
pub(crate) const MAX_SHRINK: f64 = 8.0;
/// The shrink limit on the lobe chart of a smooth material (`Options::max_shrink`, `docs/accuracy.md` §5).
pub const MAX_SHRINK_LOBE: f64 = 16.0;
/// The shrink limit on the plain chart (no lobe narrower than the stops: a diffuse body or a lobe's tail seen
/// off the specular direction): none. There the null rules of split boxes were fooled by up to 11× on heavy
/// GGX tails (E2539 −15°, `docs/accuracy.md` §5.2), so the plain chart's estimate is N₁ itself.
pub(crate) const MAX_SHRINK_PLAIN: f64 = 1.0;

/// The calibrated error of one region from three successive null rules, N₁ = |I₇ − I₅|, N₂ = |I₅ − I₃| and
/// N₃ = |I₃ − I₁| (I₃ on the centre and the ±λ4 axial points, I₁ the centre alone), in the manner of DCUHRE
/// (Berntsen, Espelid & Genz, "An adaptive algorithm for the approximate calculation of multiple integrals",
/// ACM TOMS 17 (1991) 437–451): when the differences fall fast and steadily, r = max(N₁/N₂, N₂/N₃) small,
/// the integrand is in the asymptotic range of the rules and the error of the reported I₇ is about r·N₁, far
/// below N₁ (which is the error of I₅). The estimate is then C·r·N₁ (C = [`CALIBRATION`] = 3), but at least
/// N₁/`max_shrink` ([`MAX_SHRINK`] = 8 by default) and never below the rounding of the sum, 50 ε Σ|w₇ f| (`abs7`, scaled like the
/// value) unless N₁ itself is; otherwise (C·r ≥ 1) it stays N₁. Both limits were chosen on this project's
/// integrands (`docs/accuracy.md` §5): requiring both ratios, and the cap, are what keep it honest on the
/// heavy-tailed, tabulated and off-specular integrals of the shipped fixtures, where the first ratio alone
/// shrank estimates 20× below the actual error; a cap of 16 stays honest only on the lobe chart of a smooth
/// material (`max_shrink` = [`MAX_SHRINK_LOBE`] there, `Options::max_shrink`, §5.1).
#[inline]
pub(crate) fn calibrated(n1: f64, n2: f64, n3: f64, abs7: f64, max_shrink: f64) -> f64 {
    let r = (n1 / n2).max(n2 / n3);
    if CALIBRATION * r < 1.0 {
        (CALIBRATION * r * n1).max(n1 / max_shrink).max(n1.min(50.0 * f64::EPSILON * abs7))
    } else {
        n1
    }
}

/// How far below the decay of the null rules N₁ may fall on a box the refinement never split before it is
/// taken for a cancellation ([`unsplit_estimate`]).
pub(crate) const CANCELLATION: f64 = 8.0;

/// The estimate of a box the refinement never split (no calibrated shrink, `docs/accuracy.md` §5.2): N₁,
/// unless N₁ lies more than [`CANCELLATION`] times below what the decay of the two coarser null rules predicts
/// for it, N₂·min(1, N₂/N₃) (the difference I₅ − I₃ shrinking at the rate I₃ − I₁ did). Then I₇ and I₅
/// agreed by chance, not because both are accurate, and the prediction is the estimate: a Beckmann lobe about
/// as wide as the stops at D523 85°, on the box from the overlap kink to the range end and 1 to 3 lobe widths
/// across it, had N₁ = 7.9·10⁻¹³ against N₂ = 8.4·10⁻⁹, N₃ = 6.2·10⁻⁸ and an actual error of 1.0·10⁻¹¹
/// (the reading 1.2× below its actual error, the V-cavity and the Smith G alike).
#[inline]
pub(crate) fn unsplit_estimate(n1: f64, n2: f64, n3: f64) -> f64 {
    chance_free(n1, n2, n3, CANCELLATION)
}

/// How far below the decay of the null rules N₁ may fall on a box the refinement split before it is taken
/// for a cancellation ([`split_n1`]). Measured (`docs/accuracy.md` §5.2): the chance agreements found lay
/// 1 400–8 000× below the prediction; at 8 (as for unsplit boxes) 240 golden readings moved (+2.5 % of the
/// golden set's evaluations) and an rtol-10⁻¹⁰ reference of `tests/estimates.rs` no longer converged within its budget, at
/// 64 110 moved (+0.4 %) and every test of the estimate held.
pub(crate) const SPLIT_CANCELLATION: f64 = 64.0;

/// The N₁ a split box's calibrated estimate ([`calibrated`]) and its checked floors start from: N₁, or the
/// prediction N₂·min(1, N₂/N₃) when N₁ lies more than [`SPLIT_CANCELLATION`] times below it. On GGX α = 0.0015
/// at E430 20° (specular, rtol 10⁻⁸) four boxes split once, from the overlap kink to one lobe width in u and
/// 1.5 to 2.3 widths in v, had N₁ = 2.0·10⁻¹⁶ against N₂ = 3.2·10⁻¹¹, N₃ = 6.3·10⁻¹⁰ and an actual error of
/// 2.8·10⁻¹⁴ each: the calibrated 3r·N₁ = 3.1·10⁻¹⁷ put the reading 13× below its actual error; from the
/// prediction (1.6·10⁻¹²) the calibrated estimate is 2.5·10⁻¹³.
#[inline]
pub(crate) fn split_n1(n1: f64, n2: f64, n3: f64) -> f64 {
    chance_free(n1, n2, n3, SPLIT_CANCELLATION)
}

/// N₁, or the decay the two coarser null rules predict for it, N₂·min(1, N₂/N₃) (the difference I₅ − I₃
/// shrinking at the rate I₃ − I₁ did), when N₁ lies more than `factor` times below that prediction.
#[inline]
fn chance_free(n1: f64, n2: f64, n3: f64, factor: f64) -> f64 {
    let predicted = if n3 > n2 { n2 * (n2 / n3) } else { n2 };
    if factor * n1 < predicted {
        predicted
    } else {
        n1
    }
}

/// The parent's check ([`child_scale`]): the children's estimates shrink only where the parent's estimate
/// covered `CHECK_MARGIN` times its actual error.
pub(crate) const CHECK_MARGIN: f64 = 4.0;
/// The most one check shrinks the children's estimates (a factor on their calibrated estimates).
pub(crate) const CHECK_SHRINK: f64 = 8.0;
/// The most a checked box's estimate may shrink below N₁ in all.
pub(crate) const CHECKED_MAX_SHRINK: f64 = 32.0;

/// A cell's estimate from its calibrated one and its scale: base·scale, kept within
/// [N₁/[`CHECKED_MAX_SHRINK`], N₁] (and exactly the calibrated estimate at scale 1).
#[inline]
fn scaled(n1: f64, base: f64, scale: f64) -> f64 {
    if scale == 1.0 {
        base
    } else {
        (base * scale).max(n1 / CHECKED_MAX_SHRINK).min(n1.max(base))
    }
}

/// The scale of two children from their parent's check. When a box is bisected, its children's I₇ are far
/// more accurate than its own on a smooth integrand, so D = |I₇(parent) − I₇(child 1) − I₇(child 2)| is about
/// the parent's actual error, and e_parent/D says how pessimistic the parent's estimate was. The children's
/// calibrated estimates are multiplied by m = [`CHECK_MARGIN`]·D/e_parent (the worst component), within
/// [1/[`CHECK_SHRINK`], [`MAX_SHRINK`]]: shrunk where the parent's estimate covered 4× its actual error,
/// enlarged where it did not (the null rules were misled there). The convergence-rate-aware step of the
/// DCUHRE family (Berntsen, Espelid & Genz 1991 use successive null rules; this uses successive
/// refinements), with constants chosen on this project's integrals (`docs/accuracy.md` §5). 1 when nothing is
/// known (every component exact and zero).
pub(crate) fn child_scale(parent_value: &[f64], parent_error: &[f64], a: &[f64], b: &[f64]) -> f64 {
    let (mut m, mut any): (f64, bool) = (0.0, false);
    for c in 0..parent_value.len() {
        let d = (parent_value[c] - (a[c] + b[c])).abs();
        let e = parent_error[c];
        if e > 0.0 {
            any = true;
            m = m.max(CHECK_MARGIN * d / e);
        } else if d > 0.0 {
            any = true;
            m = MAX_SHRINK;
        }
    }
    if !any {
        return 1.0;
    }
    m.clamp(1.0 / CHECK_SHRINK, MAX_SHRINK)
}

fn rescale<const D: usize>(r: &mut Region<D>, scale: f64) {
    r.cell.scale = scale;
    for c in 0..r.value.len() {
        r.error[c] = scaled(r.n1[c], r.base[c], scale);
    }
    r.worst = r.error.iter().cloned().fold(0.0, f64::max);
}

/// The degree-7 and degree-5 sums of one cell from its integrand values (`npts × ncomp`, point-major).
fn summarise<const D: usize>(
    rule: &GenzMalikRule<D>,
    cell: Cell<D>,
    values: &[f64],
    ncomp: usize,
    id: usize,
    max_shrink: f64,
) -> Region<D> {
    let half = cell.half;
    let vol: f64 = half.iter().map(|h| 2.0 * h).product();
    let mut s7 = Comps::zeros(ncomp);
    let mut s5 = Comps::zeros(ncomp);
    let mut s3 = [0.0f64; MAX_SMALL];
    let mut abs7 = [0.0f64; MAX_SMALL];
    let small = ncomp <= MAX_SMALL;
    // Per-axis second differences for the split heuristic: f(±λ2) and f(±λ4) sums.
    let mut d2 = [0.0f64; D];
    let mut d4 = [0.0f64; D];
    let mut f0 = 0.0;
    let mut s1 = [0.0f64; MAX_SMALL];
    for ((_, class, axis), v) in rule.points.iter().zip(values.chunks_exact(ncomp)) {
        let (w7, w5, w3) = (rule.w7[*class], rule.w5[*class], rule.w3[*class]);
        let mut norm1 = 0.0;
        for c in 0..ncomp {
            let v = if v[c].is_finite() { v[c] } else { 0.0 };
            s7[c] += w7 * v;
            s5[c] += w5 * v;
            if small {
                if *class == 0 {
                    s1[c] = v;
                }
                s3[c] += w3 * v;
                abs7[c] += (w7 * v).abs();
            }
            norm1 += v.abs();
        }
        match class {
            0 => f0 = norm1,
            1 => d2[*axis] += norm1,
            2 => d4[*axis] += norm1,
            _ => {}
        }
    }
    // The value and error in place of the two sums (no allocation per region beyond these two).
    let (mut value, mut error) = (s7, s5);
    let mut n1s = Comps::zeros(ncomp);
    let mut base = Comps::zeros(ncomp);
    for (c, (v, e)) in value.iter_mut().zip(error.iter_mut()).enumerate() {
        let n1 = ((*v - *e) * vol).abs();
        n1s[c] = n1;
        base[c] = if small {
            let (n2, n3) = (((*e - s3[c]) * vol).abs(), ((s3[c] - s1[c]) * vol).abs());
            if cell.split {
                // The calibration and the checked floors start from N₁ freed of a chance agreement.
                n1s[c] = split_n1(n1, n2, n3);
                calibrated(n1s[c], n2, n3, abs7[c] * vol, max_shrink)
            } else {
                unsplit_estimate(n1, n2, n3)
            }
        } else {
            n1
        };
        *e = scaled(n1s[c], base[c], cell.scale);
        *v *= vol;
    }
    let worst = error.iter().cloned().fold(0.0, f64::max);
    // Fourth difference along each axis (ratio λ2²/λ4² = 1/7); ties → the widest axis.
    let mut split_axis = 0;
    let mut best = -1.0;
    for k in 0..D {
        let diff = ((d2[k] - 2.0 * f0) - (d4[k] - 2.0 * f0) / 7.0).abs();
        let better = diff > best * (1.0 + 1e-12) || (diff >= best * (1.0 - 1e-12) && half[k] > half[split_axis]);
        if better {
            best = diff.max(best);
            split_axis = k;
        }
    }
    Region { cell, value, error, n1: n1s, base, checked: false, worst, split_axis, id }
}

/// Integrate `f` (ncomp components) over the union of the boxes `initial` (each `(lo, hi)`), adaptively,
/// until every component's summed error is ≤ max(atol, rtol·|I|) or `max_evals` is reached.
///
/// The integrand contract (batched): `f(points, values)` receives a slice of m points and a slice of
/// m × ncomp values, point-major (point i's components are `values[i*ncomp..(i+1)*ncomp]`), **zeroed before
/// every call**. It writes the values of the points it has values for and may leave the others alone: they
/// count as 0 (points below the horizon, outside the overlap, …). One call receives all the points of one
/// region (the 2^D + 2D² + 2D + 1 of the rule) or of the two halves of a split region. Non-finite values are
/// counted as 0 (callers never produce them on purpose; a test guards it).
pub fn integrate<const D: usize, F: FnMut(&[[f64; D]], &mut [f64])>(
    f: F,
    ncomp: usize,
    initial: &[([f64; D], [f64; D])],
    opts: &Options,
) -> Estimate {
    integrate_partition(f, ncomp, &Cell::from_boxes(initial), opts, Refine::Adaptive, false).0
}

/// [`integrate`] on a partition given as cells, adaptively or frozen; with `keep`, the final partition is
/// returned (in creation order, the order its values are summed in) so that it can be re-run frozen: with
/// [`Refine::Frozen`] the rule is applied once to each cell and nothing is refined, so the result is a
/// smooth function of the integrand (no partition jumps between nearby integrands) and, for the same
/// integrand, the same bits as the adaptive run the partition came from.
pub fn integrate_partition<const D: usize, F: FnMut(&[[f64; D]], &mut [f64])>(
    mut f: F,
    ncomp: usize,
    cells: &[Cell<D>],
    opts: &Options,
    refine: Refine,
    keep: bool,
) -> (Estimate, Vec<Cell<D>>) {
    let rule = GenzMalikRule::<D>::new();
    let npts = rule.len();
    let mut batch = Batch {
        points: Vec::with_capacity(2 * npts),
        values: Vec::with_capacity(2 * npts * ncomp),
        max_shrink: opts.max_shrink,
    };
    let mut heap = BinaryHeap::new();
    let mut total = vec![0.0; ncomp];
    let mut err = vec![0.0; ncomp];
    let mut evals = 0usize;
    let mut next_id = 0usize;
    // The initial cells, in batches of a bounded size (one call per cell in the adaptive case, as the
    // refinement steps; a frozen partition may hold many cells).
    let chunk = match refine {
        Refine::Adaptive => 1,
        Refine::Frozen => 64,
    };
    // The regions of one rule application (reused: no allocation per step once it has grown).
    let mut fresh: Vec<Region<D>> = Vec::with_capacity(chunk.max(2));
    for group in cells.chunks(chunk) {
        apply(&rule, &mut f, group, ncomp, &mut batch, next_id, &mut fresh);
        for r in fresh.drain(..) {
            next_id += 1;
            evals += npts;
            for k in 0..ncomp {
                total[k] += r.value[k];
                err[k] += r.error[k];
            }
            heap.push(r);
        }
    }
    let done =
        |total: &[f64], err: &[f64]| total.iter().zip(err).all(|(t, e)| *e <= opts.atol.max(opts.rtol * t.abs()));
    let mut converged = done(&total, &err);
    let mut out_of_time = false;
    while refine == Refine::Adaptive && !converged && evals + 2 * npts <= opts.max_evals {
        if opts.deadline.is_some_and(|d| std::time::Instant::now() >= d) {
            out_of_time = true;
            break;
        }
        let Some(r) = heap.pop() else { break };
        let ax = r.split_axis;
        let mut half = r.cell.half;
        half[ax] *= 0.5;
        let mut c1 = r.cell.center;
        let mut c2 = r.cell.center;
        c1[ax] -= half[ax];
        c2[ax] += half[ax];
        let children =
            [Cell { center: c1, half, scale: 1.0, split: true }, Cell { center: c2, half, scale: 1.0, split: true }];
        apply(&rule, &mut f, &children, ncomp, &mut batch, next_id, &mut fresh);
        next_id += 2;
        evals += 2 * npts;
        let (mut b, mut a) = (fresh.pop().expect("two children"), fresh.pop().expect("two children"));
        if opts.checked {
            // Shrink only below a parent that passed its own parent's check (two consecutive checks): one
            // check alone was fooled (blinn-phong at E2194 15°, `docs/accuracy.md` §5).
            let mut m = child_scale(&r.value, &r.error, &a.value, &b.value);
            (a.checked, b.checked) = (m < 1.0, m < 1.0);
            if !r.checked {
                m = m.max(1.0);
            }
            if m != 1.0 {
                rescale(&mut a, m);
                rescale(&mut b, m);
            }
        }
        for k in 0..ncomp {
            total[k] += a.value[k] + b.value[k] - r.value[k];
            err[k] += a.error[k] + b.error[k] - r.error[k];
        }
        heap.push(a);
        heap.push(b);
        converged = done(&total, &err);
    }
    // Final sums recomputed in creation order with compensated summation: incremental updates drift.
    let mut regions: Vec<Region<D>> = heap.into_vec();
    regions.sort_by_key(|r| r.id);
    let mut value = vec![0.0; ncomp];
    let mut error = vec![0.0; ncomp];
    for k in 0..ncomp {
        value[k] = neumaier(regions.iter().map(|r| r.value[k]));
        error[k] = neumaier(regions.iter().map(|r| r.error[k]));
    }
    let converged = done(&value, &error);
    let kept = if keep { regions.iter().map(|r| r.cell).collect() } else { Vec::new() };
    (Estimate { value, error, evaluations: evals, regions: regions.len(), converged, out_of_time }, kept)
}

/// A batched integrand from a pointwise one, `f(x, out)` writing the `ncomp` values at one point (into a
/// zeroed `out`), for callers with nothing to gain from batching.
pub fn pointwise<const D: usize, F: FnMut(&[f64; D], &mut [f64])>(
    ncomp: usize,
    mut f: F,
) -> impl FnMut(&[[f64; D]], &mut [f64]) {
    move |points, values| {
        for (x, out) in points.iter().zip(values.chunks_exact_mut(ncomp)) {
            f(x, out);
        }
    }
}

/// Neumaier's compensated sum.
fn neumaier(xs: impl Iterator<Item = f64>) -> f64 {
    let (mut s, mut c) = (0.0f64, 0.0f64);
    for x in xs {
        let t = s + x;
        if s.abs() >= x.abs() {
            c += (s - t) + x;
        } else {
            c += (x - t) + s;
        }
        s = t;
    }
    s + c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one() {
        for_dims();
        fn check<const D: usize>() {
            let r = GenzMalikRule::<D>::new();
            let (mut s7, mut s5) = (0.0, 0.0);
            for (_, c, _) in &r.points {
                s7 += r.w7[*c];
                s5 += r.w5[*c];
            }
            assert!((s7 - 1.0).abs() < 1e-14, "D={D} s7={s7}");
            assert!((s5 - 1.0).abs() < 1e-14, "D={D} s5={s5}");
            assert_eq!(r.len(), (1 << D) + 2 * D * D + 2 * D + 1);
        }
        fn for_dims() {
            check::<2>();
            check::<3>();
            check::<4>();
        }
    }

    #[test]
    fn the_embedded_degree_three_rule_is_exact_for_cubics() {
        fn check<const D: usize>() {
            let r = GenzMalikRule::<D>::new();
            let f = |x: &[f64; D]| 1.0 + x[0] * x[0] + 2.0 * x[D - 1].powi(3) + x[0] * x[1];
            let s3: f64 = r.points.iter().map(|(x, c, _)| r.w3[*c] * f(x)).sum();
            assert!((s3 - (1.0 + 1.0 / 3.0)).abs() < 1e-14, "D={D}: {s3}");
        }
        check::<2>();
        check::<4>();
    }

    #[test]
    fn an_unsplit_box_keeps_n1_unless_i7_and_i5_agreed_by_chance() {
        // Null rules falling steadily, or N₁ within CANCELLATION of the predicted N₂²/N₃: N₁ itself.
        assert_eq!(unsplit_estimate(1e-6, 1e-5, 1e-4), 1e-6);
        assert_eq!(unsplit_estimate(1e-8, 1e-6, 1e-4), 1e-8);
        assert_eq!(unsplit_estimate(1.0, 2.0, 100.0), 1.0);
        assert_eq!(unsplit_estimate(0.0, 0.0, 0.0), 0.0);
        // The D523 85° box of docs/accuracy.md §5.2: N₁ 10⁴ below N₂ while N₂/N₃ = 0.135; actual error 1.0e-11.
        let e = unsplit_estimate(7.916e-13, 8.424e-9, 6.227e-8);
        assert!((e - 8.424e-9 * 8.424e-9 / 6.227e-8).abs() < 1e-20 && e > 1.0e-11, "{e}");
        // A rising sequence (N₃ ≤ N₂) predicts N₂.
        assert_eq!(unsplit_estimate(1e-12, 1e-6, 1e-7), 1e-6);
        assert_eq!(unsplit_estimate(1e-12, 1e-6, 0.0), 1e-6);
    }

    #[test]
    fn a_split_box_calibrates_from_the_predicted_n1_only_when_i7_and_i5_agreed_far_below_it() {
        // Within SPLIT_CANCELLATION of the prediction N₂²/N₃ (here 10⁻⁸, 50× above N₁): N₁ itself.
        assert_eq!(split_n1(2e-10, 1e-6, 1e-4), 2e-10);
        assert_eq!(split_n1(1e-8, 1e-6, 1e-4), 1e-8);
        // The E430 20° box of docs/accuracy.md §5.2: N₁ 1.6·10⁵ below N₂ while N₂/N₃ = 0.051; actual error
        // 2.8e-14, which the calibrated estimate of the predicted N₁ covers and that of N₁ did not.
        let (n1, n2, n3) = (2.047e-16, 3.208e-11, 6.315e-10);
        let freed = split_n1(n1, n2, n3);
        assert!((freed - n2 * n2 / n3).abs() < 1e-24, "{freed}");
        assert!(calibrated(n1, n2, n3, 0.0, MAX_SHRINK_LOBE) < 2.8e-14);
        assert!(calibrated(freed, n2, n3, 0.0, MAX_SHRINK_LOBE) > 2.8e-14);
        // A rising sequence predicts N₂; nothing known, nothing changed.
        assert_eq!(split_n1(1e-12, 1e-6, 1e-7), 1e-6);
        assert_eq!(split_n1(0.0, 0.0, 0.0), 0.0);
    }

    #[test]
    fn the_calibrated_estimate_shrinks_only_on_steadily_falling_differences_and_at_most_eightfold() {
        // Not asymptotic (N₂ ≤ 3 N₁, or N₃ ≤ 3 N₂): N₁ itself.
        assert_eq!(calibrated(1.0, 2.0, 100.0, 0.0, MAX_SHRINK), 1.0);
        assert_eq!(calibrated(1.0, 100.0, 150.0, 0.0, MAX_SHRINK), 1.0);
        // Steady fall by 10 per step: 3·0.1·N₁.
        assert!((calibrated(1e-6, 1e-5, 1e-4, 0.0, MAX_SHRINK) - 3e-7).abs() < 1e-20);
        // A fast fall shrinks by at most MAX_SHRINK.
        assert_eq!(calibrated(1e-9, 1e-6, 1e-3, 0.0, MAX_SHRINK), 1e-9 / MAX_SHRINK);
        // Zero and degenerate differences keep N₁.
        assert_eq!(calibrated(0.0, 0.0, 0.0, 1.0, MAX_SHRINK), 0.0);
        assert_eq!(calibrated(1e-9, 0.0, 0.0, 1.0, MAX_SHRINK), 1e-9);
        // Never below the rounding of the sum (unless N₁ is).
        assert_eq!(calibrated(1e-16, 1e-15, 1e-14, 1.0, MAX_SHRINK), 1e-16);
        assert_eq!(calibrated(1e-14, 1e-12, 1e-10, 0.5, MAX_SHRINK), 25.0 * f64::EPSILON);
    }

    #[test]
    fn degree_seven_exact() {
        // x0⁶ + x1⁴x2² + x3⁷ + 1: the rule integrates polynomials of degree 7 exactly on one region.
        let est = integrate::<4, _>(
            pointwise(1, |x, o| o[0] = x[0].powi(6) + x[1].powi(4) * x[2].powi(2) + x[3].powi(7) + 1.0),
            1,
            &[([-1.0; 4], [1.0; 4])],
            &Options { rtol: 1.0, atol: 1.0, max_evals: 57, deadline: None, ..Default::default() },
        );
        let exact = 16.0 * (1.0 / 7.0 + 1.0 / 5.0 / 3.0 + 0.0 + 1.0);
        assert!((est.value[0] - exact).abs() < 1e-13, "{} vs {exact}", est.value[0]);
    }

    #[test]
    fn gaussian_2d_with_error_honesty() {
        // ∫∫ exp(-(x²+y²)/(2σ²)) over [-1,1]² = 2πσ² erf(1/(σ√2))²
        for sigma in [0.3, 0.05] {
            let est = integrate::<2, _>(
                pointwise(1, |x, o| o[0] = (-(x[0] * x[0] + x[1] * x[1]) / (2.0 * sigma * sigma)).exp()),
                1,
                &[
                    ([-1.0, -1.0], [0.0, 0.0]),
                    ([0.0, -1.0], [1.0, 0.0]),
                    ([-1.0, 0.0], [0.0, 1.0]),
                    ([0.0, 0.0], [1.0, 1.0]),
                ],
                &Options { rtol: 1e-9, atol: 0.0, max_evals: 10_000_000, deadline: None, ..Default::default() },
            );
            let e = libm::erf(1.0 / (sigma * 2f64.sqrt()));
            let exact = 2.0 * std::f64::consts::PI * sigma * sigma * e * e;
            let actual = (est.value[0] - exact).abs();
            assert!(est.converged);
            assert!(actual <= est.error[0], "σ={sigma}: actual {actual:e} > estimate {:e}", est.error[0]);
            assert!(actual / exact < 1e-9);
        }
    }

    #[test]
    fn deterministic_bits() {
        let run = || {
            integrate::<4, _>(
                pointwise(2, |x, o| {
                    o[0] = (x[0] * x[1] + x[2]).sin().powi(2) / (1.0 + x[3] * x[3]);
                    o[1] = (-x[0] * x[0] * 30.0).exp();
                }),
                2,
                &[([0.0; 4], [1.0; 4])],
                &Options { rtol: 1e-7, atol: 0.0, max_evals: 2_000_000, deadline: None, ..Default::default() },
            )
        };
        let (a, b) = (run(), run());
        assert_eq!(a.value[0].to_bits(), b.value[0].to_bits());
        assert_eq!(a.value[1].to_bits(), b.value[1].to_bits());
        assert_eq!(a.evaluations, b.evaluations);
    }

    #[test]
    fn reports_non_convergence() {
        let est = integrate::<2, _>(
            pointwise(1, |x, o| o[0] = if x[0] > 0.3 { 1.0 } else { 0.0 }),
            1,
            &[([0.0, 0.0], [1.0, 1.0])],
            &Options { rtol: 1e-14, atol: 0.0, max_evals: 1000, deadline: None, ..Default::default() },
        );
        assert!(!est.converged);
        assert!(est.evaluations <= 1000);
    }

    #[test]
    fn a_frozen_rerun_gives_the_same_bits_and_no_refinement() {
        let f = |a: f64| {
            pointwise(1, move |x: &[f64; 2], o: &mut [f64]| o[0] = (-a * (x[0] * x[0] + 3.0 * x[1] * x[1])).exp())
        };
        let opts = Options { rtol: 1e-9, atol: 0.0, max_evals: 1_000_000, deadline: None, ..Default::default() };
        let start = Cell::from_boxes(&[([-1.0, -1.0], [1.0, 1.0])]);
        let (adaptive, cells) = integrate_partition(f(20.0), 1, &start, &opts, Refine::Adaptive, true);
        assert!(adaptive.regions > 1 && cells.len() == adaptive.regions);
        let (frozen, again) = integrate_partition(f(20.0), 1, &cells, &opts, Refine::Frozen, true);
        assert_eq!(frozen.value[0].to_bits(), adaptive.value[0].to_bits());
        assert_eq!(frozen.error[0].to_bits(), adaptive.error[0].to_bits());
        assert_eq!(again, cells, "a frozen run refines nothing");
        assert_eq!(frozen.evaluations, 17 * cells.len());
        // A frozen run even at a tolerance it cannot meet stops after one pass.
        let tight = Options { rtol: 1e-15, ..opts };
        let (f2, _) = integrate_partition(f(20.0), 1, &cells, &tight, Refine::Frozen, false);
        assert_eq!(f2.evaluations, 17 * cells.len());
    }

    #[test]
    fn one_call_per_region_or_split() {
        // The driver hands the integrand a whole region's points (17 in 2-D) or both halves' (34).
        let mut sizes = Vec::new();
        let est = integrate::<2, _>(
            |pts: &[[f64; 2]], out: &mut [f64]| {
                sizes.push(pts.len());
                assert!(out.iter().all(|v| *v == 0.0), "values are zeroed before each call");
                for (x, o) in pts.iter().zip(out.iter_mut()) {
                    *o = (-30.0 * x[0] * x[0]).exp();
                }
            },
            1,
            &[([-1.0, -1.0], [1.0, 1.0])],
            &Options { rtol: 1e-8, atol: 0.0, max_evals: 100_000, deadline: None, ..Default::default() },
        );
        assert!(est.converged && sizes.len() > 2);
        assert_eq!(sizes[0], 17);
        assert!(sizes[1..].iter().all(|&n| n == 34), "{sizes:?}");
    }

    #[test]
    fn a_passed_deadline_stops_refinement_with_the_estimate_so_far() {
        let opts = Options {
            rtol: 1e-12,
            atol: 0.0,
            max_evals: 1_000_000,
            deadline: Some(std::time::Instant::now()),
            ..Default::default()
        };
        let est = integrate::<2, _>(
            pointwise(1, |x, o| o[0] = (-50.0 * x[0] * x[0]).exp()),
            1,
            &[([-1.0, -1.0], [1.0, 1.0])],
            &opts,
        );
        assert!(est.out_of_time && !est.converged);
        assert_eq!(est.evaluations, 17, "only the initial region");
        assert!(est.value[0].is_finite() && est.value[0] > 0.0);
    }
}
