//! The geometry of one aperture integral Φ = ∫_source ∫_receptor f(ωi, ωo) cos θi cos θo dωi dωo: the
//! charts it can be integrated in, where their split points go, the clipping of the stops at the horizon,
//! the mirror overlap of an ideal-mirror term, and where the material's kinks cross the domain. The plan
//! designs each integral from these pieces (`instrument::method`); this module only answers questions about it.
//!
//! Why the lobe chart: the glossy mass of a paint lies on the specular manifold p_s + p_r = 0,
//! q_s + q_r = 0, a 2-D ridge in the 4-D domain. Axis-aligned cubature over (p_s, q_s, p_r, q_r) cannot see
//! a ridge narrower than its first sample spacing and returns 0 with a tiny error estimate (Genz & Malik's
//! rule, like any fixed rule, samples a box at 57 points; a ridge between them is invisible: see
//! `docs/instrument.md` §Quadrature). We integrate instead over the lobe variables u = p_s + p_r,
//! v = q_s + q_r, and over the position t ∈ [0, 1] along the exact overlap of the stops for that u: per
//! axis, p_s ∈ [max(s0, u − r1), min(s1, u − r0)], p_s = lo + t·(hi − lo), Jacobian hi − lo. The overlap
//! length is piecewise linear in u with kinks at s0 + r0, s1 + r0, s0 + r1, s1 + r1: those are split points.
//! Each lobe adds split points at 0 and ±k·w (k = 1, 3, 10, 30, …) with w its width in u, out to 10 w for a
//! Gaussian tail and to the end of the range for a heavy one, so a lobe of any width is resolved by the
//! initial partition. An ideal-mirror (delta) component is integrated analytically in u (it sits at
//! u = v = 0) as a 2-D integral over the stops' mirror overlap.
use crate::brdf::{Kink, Lobe, Tail};
use crate::instrument::geometry::{Axes, Stop};

/// Fraction of a flux's tolerance given to its delta part. The delta part is a smooth 2-D integral that
/// converges to near machine precision in a few hundred evaluations, so it is asked for much more than its
/// half and the expensive 4-D regular part gets the rest.
pub(crate) const DELTA_SHARE: f64 = 0.01;

/// Width in u (in-plane) and v (perpendicular) of a lobe at geometry angle θ.
/// A facet/flake tilt δ inside a medium of index η turns the internal reflected ray by 2δ; leaving the
/// medium, the in-plane deviation becomes 2δ·η cos θt / cos θ and the perpendicular one 2δ·η cos θt
/// (Snell's law for the tangential component), with sin θt = sin θ / η. For η = 1: (2δ, 2δ cos θ).
pub fn lobe_widths_uv(lobe: &Lobe, theta: f64) -> [f64; 2] {
    let eta = lobe.medium_eta.max(1e-6);
    let st = (theta.sin() / eta).min(1.0);
    let ct = (1.0 - st * st).max(0.0).sqrt();
    let c = theta.cos().max(1e-6);
    let m = lobe.slope_width;
    [2.0 * m * eta * ct / c, 2.0 * m * eta * ct]
}

/// A material's lobes at one geometry angle θ with their widths there, computed once per design for the
/// chart ([`choose_chart`]), the split points ([`lobe_splits`]) and the rule choosers
/// (`method::design`): each lobe's [`lobe_widths_uv`] and, for a measured table's lobe, the widths of its
/// first ring ([`table_pole_widths`]); with whether a diffuse term lies under them (the choosers' gate).
#[derive(Clone, Debug)]
pub(crate) struct LobesAt<'a> {
    pub lobes: &'a [Lobe],
    /// [`lobe_widths_uv`] of each lobe at θ.
    pub widths: Vec<[f64; 2]>,
    /// [`table_pole_widths`] of each lobe at θ (None but for a table's lobe).
    pub poles: Vec<Option<[f64; 2]>>,
    pub has_diffuse: bool,
    pub theta: f64,
}

impl<'a> LobesAt<'a> {
    /// `lobes` at θ, over a diffuse term or not.
    pub(crate) fn new(lobes: &'a [Lobe], theta: f64, has_diffuse: bool) -> LobesAt<'a> {
        let widths = lobes.iter().map(|l| lobe_widths_uv(l, theta)).collect();
        let poles = lobes.iter().map(|l| table_pole_widths(l, theta)).collect();
        LobesAt { lobes, widths, poles, has_diffuse, theta }
    }
}

/// The variables (chart) of a regular part's integrand: a part's chart is chosen per integral by
/// [`choose_chart`] (plain or lobe); a shaped rule may integrate in another one (the tensor rule's
/// `PlainPLobeQ`). The map from a chart's point to the two directions and its Jacobian is
/// `method::ChartMap`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Chart {
    /// The plain product of the stops, (p_s, q_s, p_r, q_r): one box, no kinks. Right when every lobe is at
    /// least as wide as the whole lobe-variable range on both axes (or there is none): the integrand is then
    /// smooth over the product and one 57-point Genz–Malik region may already meet the tolerance.
    Plain,
    /// The lobe variables (u, t_p, v, t_q) with splits at the overlap kinks and at multiples of the lobe
    /// widths: needed as soon as one lobe is narrower than the apertures.
    Lobe,
    /// (p_s, p_r, v, t_q): plain in the plane of incidence, lobe variables across it (a lobe wider than the
    /// stops in u but not in v: the ridge v = q_s + q_r becomes an axis). Only a shaped rule's
    /// (`Rule::TensorGauss`), never a part's.
    PlainPLobeQ,
}

/// Choose the chart of the regular part for these (clipped) stops and these lobes at their angle θ.
pub(crate) fn choose_chart(l: &LobesAt, source: Stop, receptor: Stop) -> Chart {
    let range_u = (source.p[1] - source.p[0]) + (receptor.p[1] - receptor.p[0]);
    let range_v = (source.q[1] - source.q[0]) + (receptor.q[1] - receptor.q[0]);
    let wide = |(&w, pole): (&[f64; 2], &Option<[f64; 2]>)| {
        let pole = pole.unwrap_or(w);
        w[0] >= range_u && w[1] >= range_v && pole[0] >= range_u && pole[1] >= range_v
    };
    if l.widths.iter().zip(&l.poles).all(wide) {
        Chart::Plain
    } else {
        Chart::Lobe
    }
}

/// The mirror overlap of two (clipped) stops: the box of source points (p, q) whose mirror image (−p, −q)
/// lies in the receptor, as (lower, upper) corners; None if it is empty (the receptor does not see the
/// mirror image of the source, so an ideal-mirror term contributes nothing). The one place this is computed
/// (the independent reference in `instrument/reference.rs` keeps its own on purpose).
pub(crate) fn mirror_overlap(source: Stop, receptor: Stop) -> Option<([f64; 2], [f64; 2])> {
    let lo = [source.p[0].max(-receptor.p[1]), source.q[0].max(-receptor.q[1])];
    let hi = [source.p[1].min(-receptor.p[0]), source.q[1].min(-receptor.q[0])];
    (hi[0] > lo[0] && hi[1] > lo[1]).then_some((lo, hi))
}

/// The split points of the lobe chart on each axis (u, then v), from the stops and the lobes at their angle.
pub(crate) fn lobe_splits(l: &LobesAt, source: Stop, receptor: Stop) -> [Vec<f64>; 2] {
    let ap = AxisMap { s: source.p, r: receptor.p };
    let aq = AxisMap { s: source.q, r: receptor.q };
    let lobes = l.lobes;
    let widths: Vec<[f64; 2]> = lobes
        .iter()
        .zip(&l.widths)
        .map(|(lobe, &w)| narrowed_in_u(seen_from(lobe, w, ap, aq), l.theta, lobe.medium_eta, aq))
        .collect();
    let mut up = ap.splits(&widths.iter().zip(lobes).map(|(w, l)| (w[0], l.tail.is_heavy())).collect::<Vec<_>>());
    let mut uq = aq.splits(&widths.iter().zip(lobes).map(|(w, l)| (w[1], l.tail.is_heavy())).collect::<Vec<_>>());
    for &pole in l.poles.iter().flatten() {
        // The cusp is at the pole alone (u = v = 0, inside the first ring): a receptor whose range on the
        // other axis stays a ring's width away from 0 never meets it (an E430 or ISO 13803 receptor off the
        // specular direction), and that axis takes no pole splits.
        let reaches = |a: AxisMap, w: f64| {
            let [lo, hi] = a.range();
            lo < w && hi > -w
        };
        let (near_u, near_v) = (reaches(ap, pole[0]), reaches(aq, pole[1]));
        for (pts, a, w, near) in [(&mut up, ap, pole[0], near_v), (&mut uq, aq, pole[1], near_u)] {
            if !near {
                continue;
            }
            let [lo, hi] = a.range();
            pts.extend([0.0, -w, w].into_iter().filter(|x| *x > lo && *x < hi));
            pts.sort_by(f64::total_cmp);
            let tiny = 1e-14 * (hi - lo).max(1e-300);
            pts.dedup_by(|x, y| (*x - *y).abs() <= tiny);
        }
    }
    [up, uq]
}

/// The widths in (u, v) of a measured table's first ring around the specular direction (`Tail::Table`'s
/// `resolution` as the slope width), where its interpolant has a cusp (the grids of MERL and RGL are
/// sampled in √θh or u_θ = √(2θ/π), so the interpolant is linear in √θh in the first cell; an in-plane table's
/// is linear in |θh|): the lobe chart splits at 0 and ± these widths, so that the cusp sits in the corners of
/// boxes a ring wide (`docs/instrument.md` §Quadrature, *Measured tables*). None for a lobe of a model.
pub(crate) fn table_pole_widths(lobe: &Lobe, theta: f64) -> Option<[f64; 2]> {
    match lobe.tail {
        Tail::Table { resolution, .. } => {
            Some(lobe_widths_uv(&Lobe { slope_width: resolution, ..lobe.clone() }, theta))
        }
        _ => None,
    }
}

/// The widths (u, v) a lobe shows over these stops: [`lobe_widths_uv`], except for a GGX tail
/// (`Tail::InverseQuartic`) whose centre lies outside the range of one axis. Along the other axis the
/// GGX kernel at scaled distance x = u/w_u is 1/(1 + x² + y²)² = 1/(c² + y²)², c = √(1 + x²): a peak c
/// widths wide, and c only grows away from the centre, so the splits use the width times c at the range's
/// nearest point (an E430 haze receptor 2° off specular sees a GGX α = 0.003 lobe 5.3 times wider across the
/// plane of incidence than the specular receptor does; `docs/instrument.md` §Quadrature). A measured table's
/// lobe (`Tail::Table`, heavy: its tail is whatever the data hold) is seen the same way, as a GGX tail of its
/// half width; where it is narrower, the adaptive refinement finds it (measured honest against the partition
/// at the table's resolution: `docs/instrument.md` §Quadrature, *Measured tables*, "Off the specular
/// direction, the table's lobe seen as a GGX tail").
pub fn seen_widths(lobe: &Lobe, theta: f64, ap: AxisMap, aq: AxisMap) -> [f64; 2] {
    seen_from(lobe, lobe_widths_uv(lobe, theta), ap, aq)
}

/// [`seen_widths`] from the lobe's widths `w` at θ ([`lobe_widths_uv`], computed by the caller).
fn seen_from(lobe: &Lobe, w: [f64; 2], ap: AxisMap, aq: AxisMap) -> [f64; 2] {
    let widens = matches!(lobe.tail, Tail::InverseQuartic | Tail::Table { .. });
    if !(widens && w[0] > 0.0 && w[1] > 0.0 && w[0].is_finite() && w[1].is_finite()) {
        return w;
    }
    let c = |g: f64, w: f64| (1.0 + (g / w) * (g / w)).sqrt();
    [w[0] * c(aq.gap(), w[1]), w[1] * c(ap.gap(), w[0])]
}

/// How many lobe widths out across the plane of incidence [`narrowed_in_u`] takes the lobe's u width at.
pub(crate) const GRAZING_REACH: f64 = 2.0;

/// The widths `w` with the u width no wider than the lobe is in u at [`GRAZING_REACH`] widths out in v (or at
/// the end of the v range, if nearer). Across the plane of incidence the lobe's slope is about v/(cos θi + cos θr),
/// and cos θr moves with u by about u·sin θ, so at y = v/w_v widths out the exponent y² changes by e over
/// Δu = cot θ / y²: near grazing far less than the lobe's u width at v = 0. Ward α = 0.161 at D523 85° (u
/// width 0.32, wider than the u range): two widths out the integrand is a Gaussian about 0.022 wide in u, and
/// the boxes left without a u split there read 2.9× below their actual error at rtol 10⁻⁸ (`docs/accuracy.md`
/// §The estimate property, "The Ward reading").
///
/// A lobe formed in a medium of index η ≠ 1 (flakes under a smooth coat) has its slope across the plane
/// inside the medium, v'/(cos θi' + cos θr') with v' = v/η, and a change Δu of the angle in air turns θr' by
/// Δu·cos θ/(η cos θ'); the exponent then changes by e over Δu = η² cos² θ' / (y² sin θ cos θ), which is
/// cot θ / y² at η = 1 and far wider under a coat near grazing (at 85°, η = 1.5: 14.5/y² against 0.087/y²,
/// 3.6 against 0.022 at y = 2).
fn narrowed_in_u(w: [f64; 2], theta: f64, eta: f64, aq: AxisMap) -> [f64; 2] {
    let [lo, hi] = aq.range();
    let y = (lo.abs().max(hi.abs()) / w[1]).min(GRAZING_REACH);
    let reach = grazing_u_scale(theta, eta);
    if !(y > 0.0 && reach.is_finite() && w[0].is_finite()) {
        return w;
    }
    [w[0].min(reach / (y * y)), w[1]]
}

/// The u width of [`narrowed_in_u`] one lobe width out in v: cot θ in air, η² cos² θ' / (sin θ cos θ) for a
/// lobe formed in a medium of index η (sin θ' = sin θ / η); infinite at normal incidence.
pub(crate) fn grazing_u_scale(theta: f64, eta: f64) -> f64 {
    let (s, c) = theta.sin_cos();
    if !(s > 0.0 && c > 0.0) {
        return f64::INFINITY;
    }
    if eta == 1.0 {
        c / s
    } else {
        let eta = eta.max(1e-6);
        let st = (s / eta).min(1.0);
        eta * eta * (1.0 - st * st) / (s * c)
    }
}

/// The initial boxes of the lobe chart in (u, t_p, v, t_q): the product of the split intervals, t ∈ [0, 1].
pub fn lobe_boxes(splits: &[Vec<f64>; 2]) -> Vec<([f64; 4], [f64; 4])> {
    let [up, uq] = splits;
    let mut boxes = Vec::with_capacity((up.len().max(1) - 1) * (uq.len().max(1) - 1));
    for a in up.windows(2) {
        for b in uq.windows(2) {
            boxes.push(([a[0], 0.0, b[0], 0.0], [a[1], 1.0, b[1], 1.0]));
        }
    }
    boxes
}

/// One axis of the (source, receptor) pair in lobe coordinates.
#[derive(Clone, Copy, Debug)]
pub struct AxisMap {
    /// The source's and the receptor's interval on this axis.
    pub s: [f64; 2],
    pub r: [f64; 2],
}

impl AxisMap {
    pub fn range(&self) -> [f64; 2] {
        [self.s[0] + self.r[0], self.s[1] + self.r[1]]
    }

    /// How far the range of the lobe coordinate lies from the lobe centre 0: 0 when it holds 0, else the
    /// distance of its nearer end.
    pub(crate) fn gap(&self) -> f64 {
        let [lo, hi] = self.range();
        lo.max(-hi).max(0.0)
    }

    /// The overlap [lo, hi] of p_s at lobe coordinate u: the source points whose partner u − p_s lies in the
    /// receptor (empty when hi ≤ lo).
    #[inline]
    pub(crate) fn overlap(&self, u: f64) -> (f64, f64) {
        (self.s[0].max(u - self.r[1]), self.s[1].min(u - self.r[0]))
    }

    /// (p_s, p_r, Jacobian) at lobe coordinate u and overlap position t.
    #[inline]
    pub(crate) fn at(&self, u: f64, t: f64) -> (f64, f64, f64) {
        let (lo, hi) = self.overlap(u);
        let len = (hi - lo).max(0.0);
        let ps = lo + t * len;
        (ps, u - ps, len)
    }

    /// Split points of u: the range ends, the kinks of the overlap length, the lobe centre and multiples
    /// of each lobe width.
    pub fn splits(&self, widths: &[(f64, bool)]) -> Vec<f64> {
        let [a, b] = self.range();
        // The range ends and the overlap kinks: split points always.
        let fixed = [a, b, self.s[1] + self.r[0], self.s[0] + self.r[1]];
        let mut pts = fixed.to_vec();
        // Lobes within a factor 3 of a narrower one share its splits: the splits are geometric (×3 apart),
        // so they already resolve it, and each extra set multiplies the number of initial boxes. A shared
        // set reaches as far as the heaviest tail among the lobes it serves.
        let mut ws: Vec<(f64, bool)> = widths.iter().copied().filter(|(w, _)| *w > 0.0).collect();
        ws.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut kept: Vec<(f64, bool)> = Vec::new();
        for (w, heavy) in ws {
            match kept.last_mut() {
                Some(k) if w <= 3.0 * k.0 => k.1 |= heavy,
                _ => kept.push((w, heavy)),
            }
        }
        // Geometric splits at ±w, ±3w, ±10w, … For a heavy tail they go on (±30w, ±100w, …) to the end of the
        // range, so that no box spans more than a factor ≈ 3 in distance from the lobe centre and a tail
        // falling off as u⁻⁴ (GGX holds ~1e-4 of its mass beyond 100 widths) is seen by the first samples of
        // every box. A Gaussian tail is below e⁻¹⁰⁰ of the peak beyond 10w: the splits stop there.
        let range_reach = a.abs().max(b.abs());
        for &(w, heavy) in &kept {
            // Every lobe narrower than the range (the lobe chart's own condition, `choose_chart`) has its centre
            // as a split, and its widths where they fall inside. A lobe between half and the whole range wide
            // (a narrow source against a wide window) left without them put its peak inside one box whose
            // I₇ − I₅ cancelled between the axes, 25× below its error (docs/accuracy.md §5.2).
            if w > 0.0 && w < b - a {
                pts.push(0.0);
                let reach = if heavy { range_reach } else { range_reach.min(10.0 * w * (1.0 + 1e-12)) };
                let mut k = 1.0;
                let mut step = 3.0;
                while k * w <= reach {
                    pts.push(k * w);
                    pts.push(-k * w);
                    k *= step;
                    step = if step == 3.0 { 10.0 / 3.0 } else { 3.0 };
                }
            }
        }
        pts.retain(|x| *x >= a && *x <= b);
        pts.sort_by(f64::total_cmp);
        let tiny = 1e-14 * (b - a).max(1e-300);
        pts.dedup_by(|x, y| (*x - *y).abs() <= tiny);
        pts
    }
}

/// The largest angle between a stop's axis and a direction through the stop: atan of the farthest corner's
/// tangent-plane distance.
fn stop_radius(stop: Stop) -> f64 {
    let p = stop.p[0].abs().max(stop.p[1].abs());
    let q = stop.q[0].abs().max(stop.q[1].abs());
    p.hypot(q).atan()
}

/// The kinks of the delta part that may cross the source box `src` (the mirror overlap) at geometry angle θ:
/// the cosines of the critical angles θc within θ ± the box's angular radius (a bound: θi of a direction
/// through the box differs from θ by at most the angle between it and the source axis), in increasing order.
pub(crate) fn delta_kinks(kinks: &[Kink], theta: f64, src: Stop) -> Vec<f64> {
    let a = stop_radius(src);
    let mut c: Vec<f64> = kinks
        .iter()
        .filter_map(|k| match *k {
            Kink::Incidence { cos } => Some(cos),
            Kink::HalfAngle { .. } => None,
        })
        .filter(|c| (theta - a..=theta + a).contains(&c.acos()))
        .collect();
    c.sort_by(f64::total_cmp);
    c.dedup();
    c
}

/// The kinks of the regular part that may cross the product of the (clipped) stops: the cosines c of the
/// half-angle kinks ωi·h = c whose angle between ωi and ωo, 2·acos c, lies within 2θ ± (the stops' angular
/// radii) (the triangle inequality on the sphere: the angle between ωi and ωo differs from the axes' 2θ by
/// at most the two directions' angles from their axes), in increasing order.
pub(crate) fn regular_kinks(kinks: &[Kink], theta: f64, src: Stop, rec: Stop) -> Vec<f64> {
    regular_kinks_between(kinks, 2.0 * theta, src, rec)
}

/// [`regular_kinks`] for stops whose axes are `axes_angle` apart (2θ on the mirror axis; θ + the viewing
/// angle for a receptor off it, in the plane on the other side of the normal).
pub(crate) fn regular_kinks_between(kinks: &[Kink], axes_angle: f64, src: Stop, rec: Stop) -> Vec<f64> {
    let theta = 0.5 * axes_angle.abs();
    let a = stop_radius(src) + stop_radius(rec);
    let mut c: Vec<f64> = kinks
        .iter()
        .filter_map(|k| match *k {
            Kink::HalfAngle { cos } => Some(cos),
            Kink::Incidence { .. } => None,
        })
        .filter(|c| (2.0 * theta - a..=2.0 * theta + a).contains(&(2.0 * c.acos())))
        .collect();
    c.sort_by(f64::total_cmp);
    c.dedup();
    c
}

/// The root in [lo, hi] of an increasing function g (value and derivative), by Newton's method kept inside
/// a bracket (bisection when a step leaves it); lo when g(lo) ≥ 0, hi when g(hi) ≤ 0 (no crossing).
/// Deterministic: the same arguments give the same bits.
pub(crate) fn increasing_root(g: impl Fn(f64) -> (f64, f64), lo: f64, hi: f64) -> f64 {
    let (g_lo, _) = g(lo);
    if !(g_lo < 0.0) {
        return lo;
    }
    let (g_hi, _) = g(hi);
    if !(g_hi > 0.0) {
        return hi;
    }
    let (mut a, mut b) = (lo, hi);
    // Start from the secant through the ends.
    let mut x = lo - g_lo * (hi - lo) / (g_hi - g_lo);
    if !(x > a && x < b) {
        x = 0.5 * (a + b);
    }
    for _ in 0..100 {
        let (gx, dg) = g(x);
        if gx == 0.0 {
            return x;
        }
        if gx < 0.0 {
            a = x;
        } else {
            b = x;
        }
        let mut next = x - gx / dg;
        if !(next > a && next < b) {
            next = 0.5 * (a + b);
        }
        let tol = 4.0 * f64::EPSILON * x.abs().max(hi - lo);
        if (next - x).abs() <= tol || b - a <= tol {
            return next;
        }
        x = next;
    }
    x
}

/// The kink-aligned position along one segmented axis: t ∈ [0, 1] is cut into m + 1 equal segments (m =
/// `cuts`, the number of kinks); segment j runs from breakpoint b_j to b_{j+1}, where b_0 = lo, b_{m+1} = hi and
/// b_k = `root(k − 1)` (the kink's position, clamped and kept in order). The kinks are critical angles, and
/// position increases with the Fresnel cosine (towards the normal), so below its first kink every index is
/// in total internal reflection (R = 1, smooth) and segment j ≥ 1 has the √-shaped knee of index j at its
/// lower end (1 − R ∝ √(x − b_j)) and is smooth at its upper end (index j + 1 is still totally reflected
/// there). Segment 0 is linear; segment j ≥ 1 is graded towards its lower end, x = b_j + (b_{j+1} − b_j)·s²,
/// so that √(x − b_j) ∝ s and the integrand is smooth up to the boundary (a linear Jacobian, the least
/// polynomial degree a grading costs the cubature). Returns (x, dx/dt), dx/dt = 0 for an empty segment.
#[inline]
pub(crate) fn kinked_position(t: f64, lo: f64, hi: f64, cuts: usize, root: impl Fn(usize) -> f64) -> (f64, f64) {
    if !(hi > lo) {
        return (lo, 0.0);
    }
    let pieces = (cuts + 1) as f64;
    let j = ((t * pieces).floor().max(0.0) as usize).min(cuts);
    let s = t * pieces - j as f64;
    let mut a = lo;
    let mut b = if cuts == 0 { hi } else { root(0).clamp(lo, hi) };
    for k in 1..=j {
        a = b;
        b = if k == cuts { hi } else { root(k).clamp(a, hi) };
    }
    let len = b - a;
    if j == 0 {
        (a + len * s, pieces * len)
    } else {
        (a + len * s * s, pieces * len * 2.0 * s)
    }
}

/// The position p_s of the source-stop point on the critical-angle kink ωi·ωo = `dot` (the regular part's
/// kink, [`Kink::HalfAngle`]) at fixed u = p_s + p_r, q_s and q_r, within [lo, hi]. ωi·ωo is the
/// normalised N/√(AB) with N = cos 2θ (1 + p_s p_r) + sin 2θ (p_s − p_r) + q_s q_r, A = 1 + p_s² + q_s²,
/// B = 1 + p_r² + q_r² (the product of the two unnormalised directions, `geometry::Axes`); it increases with
/// p_s along a constant u (the two directions close up), at the rate N′ = cos 2θ (p_r − p_s) + 2 sin 2θ.
pub(crate) fn half_angle_kink_point(axes: &Axes, dot: f64, u: f64, qs: f64, qr: f64, lo: f64, hi: f64) -> f64 {
    let (c2, s2) = ((2.0 * axes.theta).cos(), (2.0 * axes.theta).sin());
    increasing_root(
        |ps| {
            let pr = u - ps;
            let n = c2 * (1.0 + ps * pr) + s2 * (ps - pr) + qs * qr;
            let dn = c2 * (pr - ps) + 2.0 * s2;
            let (a, b) = (1.0 + ps * ps + qs * qs, 1.0 + pr * pr + qr * qr);
            let ab = a * b;
            let r = ab.sqrt();
            (n / r - dot, dn / r - 0.5 * n * (2.0 * ps * b - 2.0 * pr * a) / (ab * r))
        },
        lo,
        hi,
    )
}

/// The position p_s of the source-stop point on the half-angle kink ωi·ωo = `dot` in the plain chart, at fixed
/// q_s and receptor direction `wo` (a receptor off the mirror axis), within [lo, hi]: ωi·ωo = S·ωo/|S| with
/// S = (−sin θ + p cos θ, q, cos θ + p sin θ) (`Axes::source_dir`), at the rate (dS/dp·ωo)/|S| − (S·ωo)·p/|S|³.
/// It increases with p_s for a receptor across the normal (the source direction turns towards it) and
/// decreases for one on the source's side; the root is found on the increasing one of ±(ωi·ωo − dot). The end
/// on the kink's side when the kink does not cross.
pub(crate) fn plain_kink_point(axes: &Axes, dot: f64, qs: f64, wo: crate::Vec3, lo: f64, hi: f64) -> f64 {
    let (c, s) = (axes.theta.cos(), axes.theta.sin());
    let g = |p: f64| {
        let sv = crate::Vec3::new(-s + p * c, qs, c + p * s);
        let n2 = 1.0 + p * p + qs * qs;
        let n = n2.sqrt();
        let d = sv.dot(wo);
        let dd = c * wo.x + s * wo.z;
        (d / n - dot, dd / n - d * p / (n2 * n))
    };
    let sign = if g(hi).0 >= g(lo).0 { 1.0 } else { -1.0 };
    increasing_root(
        |p| {
            let (v, dv) = g(p);
            (sign * v, sign * dv)
        },
        lo,
        hi,
    )
}

/// The position p of the source-stop point on the critical-angle kink cos θi = `cos` (the delta part's kink,
/// [`Kink::Incidence`]) at fixed q, within [lo, hi]: cos θi = (cos θ + p sin θ)/√(1 + p² + q²), increasing in
/// p (towards the normal) at the rate (sin θ (1 + q²) − p cos θ)/(1 + p² + q²)^{3/2}.
pub(crate) fn incidence_kink_point(axes: &Axes, cos: f64, q: f64, lo: f64, hi: f64) -> f64 {
    let (c, s) = (axes.theta.cos(), axes.theta.sin());
    increasing_root(
        |p| {
            let a = 1.0 + p * p + q * q;
            let r = a.sqrt();
            ((c + p * s) / r - cos, (s * (1.0 + q * q) - p * c) / (a * r))
        },
        lo,
        hi,
    )
}

/// Clip a stop to the upper hemisphere. For the source, z ∝ cos θ + p sin θ; for the receptor,
/// z ∝ cos θ − p sin θ: the horizon is the line p = ∓cot θ, independent of q, so clipping is exact. A negative
/// θ (a multi-angle colour receptor on the illuminator's side) keeps the other side of that line.
pub(crate) fn clip(stop: Stop, theta: f64, is_source: bool) -> Option<Stop> {
    let mut s = stop;
    if theta != 0.0 {
        let cot = theta.cos() / theta.sin();
        match (is_source, theta > 0.0) {
            (true, true) => s.p[0] = s.p[0].max(-cot),
            (false, true) => s.p[1] = s.p[1].min(cot),
            (true, false) => s.p[1] = s.p[1].min(-cot),
            (false, false) => s.p[0] = s.p[0].max(cot),
        }
    }
    (s.p[1] > s.p[0] && s.q[1] > s.q[0]).then_some(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::geometry::Axes;

    #[test]
    fn overlap_map_covers_the_product_exactly() {
        // ∫ du ∫ dt Jacobian = area of the product of the two intervals.
        let m = AxisMap { s: [-0.01, 0.02], r: [-0.03, 0.05] };
        let sp = m.splits(&[(1e-4, true)]);
        let mut total = 0.0;
        for w in sp.windows(2) {
            // the overlap length is linear on each piece: the midpoint rule is exact
            let u = 0.5 * (w[0] + w[1]);
            total += m.at(u, 0.5).2 * (w[1] - w[0]);
        }
        assert!((total - 0.03 * 0.08).abs() < 1e-15, "{total}");
    }

    #[test]
    fn mirror_point_is_the_mirror_direction() {
        let axes = Axes::new(0.9);
        let wi = axes.source_dir(0.013, -0.02);
        let wo = axes.receptor_dir(-0.013, 0.02);
        let m = crate::brdf::mirror(wi);
        assert!((m - wo).length() < 1e-15);
    }

    fn lobe(m: f64, eta: f64, heavy: bool) -> Lobe {
        Lobe {
            slope_width: m,
            medium_eta: eta,
            label: "test".into(),
            tail: if heavy { crate::brdf::Tail::InverseQuartic } else { crate::brdf::Tail::Gaussian },
        }
    }

    /// The widths against a direct construction: tilt a flake by δ inside the medium (in the plane, then
    /// perpendicular to it), reflect the internal ray off it, refract it out (tangential component × η), and
    /// measure the deviation of the exit ray in the receptor's tangent coordinates.
    #[test]
    fn lobe_widths_follow_snell_for_a_tilted_flake() {
        use crate::Vec3;
        let delta: f64 = 1e-7;
        for (theta, eta) in [(0.35f64, 1.0f64), (1.047, 1.5), (1.48, 1.5), (0.2, 2.0)] {
            let st = theta.sin() / eta;
            let ct = (1.0 - st * st).sqrt();
            // The internal ray towards the flake and its mirror direction inside the medium.
            let d = Vec3::new(st, 0.0, -ct);
            let exit = |n: Vec3| {
                let r = d - 2.0 * d.dot(n) * n;
                // Leave the medium: tangential components × η, z from normalisation.
                let (x, y) = (eta * r.x, eta * r.y);
                Vec3::new(x, y, (1.0 - x * x - y * y).sqrt())
            };
            let axis = exit(Vec3::new(0.0, 0.0, 1.0));
            assert!((axis.z - theta.cos()).abs() < 1e-12, "the untilted flake reflects specularly");
            // Receptor tangent coordinates about `axis`: in-plane e_par = (cos θ, 0, −sin θ), perpendicular y.
            let e_par = Vec3::new(theta.cos(), 0.0, -theta.sin());
            let tangent = |w: Vec3| (w.dot(e_par) / w.dot(axis), w.y / w.dot(axis));
            // Central differences in the tilt.
            let (up, _) = tangent(exit(Vec3::new(delta.sin(), 0.0, delta.cos())));
            let (um, _) = tangent(exit(Vec3::new(-delta.sin(), 0.0, delta.cos())));
            let (_, vp) = tangent(exit(Vec3::new(0.0, delta.sin(), delta.cos())));
            let (_, vm) = tangent(exit(Vec3::new(0.0, -delta.sin(), delta.cos())));
            let (du, dv) = ((up - um).abs() / (2.0 * delta), (vp - vm).abs() / (2.0 * delta));
            let w = lobe_widths_uv(&lobe(1.0, eta, false), theta);
            assert!((du - w[0]).abs() < 1e-6 * w[0], "θ={theta} η={eta}: u {du} vs {}", w[0]);
            assert!((dv - w[1]).abs() < 1e-6 * w[1], "θ={theta} η={eta}: v {dv} vs {}", w[1]);
        }
    }

    #[test]
    fn the_chart_is_plain_only_when_every_lobe_covers_the_range() {
        let s = Stop { p: [-0.01, 0.01], q: [-0.02, 0.02] };
        let theta = 0.35;
        assert_eq!(choose_chart(&LobesAt::new(&[], theta, false), s, s), Chart::Plain);
        // Range in u: 0.04, in v: 0.08; a lobe of slope width m is ≈ 2m wide.
        assert_eq!(choose_chart(&LobesAt::new(&[lobe(0.5, 1.0, false)], theta, false), s, s), Chart::Plain);
        assert_eq!(choose_chart(&LobesAt::new(&[lobe(1e-3, 1.0, false)], theta, false), s, s), Chart::Lobe);
        assert_eq!(
            choose_chart(&LobesAt::new(&[lobe(0.5, 1.0, false), lobe(1e-3, 1.0, true)], theta, false), s, s),
            Chart::Lobe
        );
        // Wide enough in u but not in v (0.03: 2m = 0.06 ≥ 0.04/cos θ... but 2m cos θ < 0.08).
        let w = lobe_widths_uv(&lobe(0.03, 1.0, false), theta);
        assert!(w[0] >= 0.04 && w[1] < 0.08);
        assert_eq!(choose_chart(&LobesAt::new(&[lobe(0.03, 1.0, false)], theta, false), s, s), Chart::Lobe);
    }

    #[test]
    fn splits_sit_at_the_kinks_and_at_multiples_of_the_lobe_width() {
        let src = Stop { p: [-0.01, 0.01], q: [-0.02, 0.02] };
        let rec = Stop { p: [-0.03, 0.03], q: [-0.02, 0.02] };
        let theta = 0.0;
        let has = |v: &[f64], x: f64| v.iter().any(|y| (y - x).abs() <= 1e-15);
        // A Gaussian lobe 2e-4 wide in u: 0, ±w, ±3w, ±10w, and no further.
        let [u, v] = lobe_splits(&LobesAt::new(&[lobe(1e-4, 1.0, false)], theta, false), src, rec);
        let w = 2e-4;
        for k in [0.0, 1.0, 3.0, 10.0, -1.0, -3.0, -10.0] {
            assert!(has(&u, k * w), "{k}w missing from {u:?}");
        }
        assert!(!has(&u, 30.0 * w), "a Gaussian tail stops at 10 w: {u:?}");
        // The range ends and the overlap kinks s1 + r0, s0 + r1.
        for x in [-0.04, 0.04, 0.01 - 0.03, -0.01 + 0.03] {
            assert!(has(&u, x), "{x} missing from {u:?}");
        }
        assert!(u.windows(2).all(|p| p[0] < p[1]), "sorted, no duplicates");
        // A heavy tail goes on to the end of the range.
        let [uh, _] = lobe_splits(&LobesAt::new(&[lobe(1e-4, 1.0, true)], theta, false), src, rec);
        assert!(has(&uh, 30.0 * w) && has(&uh, 100.0 * w) && has(&uh, -100.0 * w), "{uh:?}");
        // Lobes within 3× of a narrower one share its splits.
        let [u2, _] =
            lobe_splits(&LobesAt::new(&[lobe(1e-4, 1.0, false), lobe(2.5e-4, 1.0, false)], theta, false), src, rec);
        assert_eq!(u2, u);
        // v gets the same treatment with the perpendicular width (2m cos θ = 2m here).
        assert!(has(&v, 10.0 * w) && has(&v, -10.0 * w));
        // The boxes tile the product of the split intervals.
        let boxes = lobe_boxes(&[u.clone(), v.clone()]);
        assert_eq!(boxes.len(), (u.len() - 1) * (v.len() - 1));
    }

    /// A measured table's pole ring (splits at 0 and ± the first ring's width on both axes) is cut only on an
    /// axis whose partner axis's range reaches the pole: a receptor off the specular direction on u (an E430
    /// haze receptor) takes no ring splits on v, while its lobe splits stay.
    #[test]
    fn the_pole_ring_splits_only_where_the_range_reaches_the_pole() {
        let table = Lobe {
            slope_width: 3e-3,
            medium_eta: 1.0,
            label: "test".into(),
            tail: crate::brdf::Tail::Table { half_width: 3e-3, resolution: 1e-4 },
        };
        let (theta, src) = (0.0, Stop { p: [-0.002, 0.002], q: [-0.01, 0.01] });
        let ring = table_pole_widths(&table, theta).unwrap();
        let has = |v: &[f64], x: f64| v.iter().any(|y| (y - x).abs() <= 1e-15);
        // On the specular receptor both axes reach the pole: the ring is cut on both.
        let [u, v] = lobe_splits(
            &LobesAt::new(std::slice::from_ref(&table), theta, false),
            src,
            Stop { p: [-0.002, 0.002], q: [-0.01, 0.01] },
        );
        assert!(has(&u, ring[0]) && has(&u, -ring[0]) && has(&v, ring[1]) && has(&v, -ring[1]), "{u:?} {v:?}");
        // 0.03 off specular on p: u never comes within a ring of 0, so v has no ring splits (its lobe splits
        // remain, at 0 and ± the lobe's width as seen from u's range); u's range holds no pole to split at.
        let rec = Stop { p: [0.028, 0.032], q: [-0.01, 0.01] };
        let [u, v] = lobe_splits(&LobesAt::new(std::slice::from_ref(&table), theta, false), src, rec);
        assert!(!has(&v, ring[1]) && !has(&v, -ring[1]), "{v:?}");
        // The table's lobe is seen as a GGX tail (`seen_widths`): from u's range, 0.026 = 4.3 widths off its
        // centre, it is c = √(1 + 4.3²) = 4.4 times wider across, so ± its width fall outside v's range and
        // v keeps its ends and 0 (which is also both overlap kinks here).
        let w = lobe_widths_uv(&table, theta);
        let seen = seen_widths(&table, theta, AxisMap { s: src.p, r: rec.p }, AxisMap { s: src.q, r: rec.q });
        let c = (1.0 + (0.026f64 / w[0]).powi(2)).sqrt();
        assert!((seen[1] / w[1] - c).abs() <= 1e-9 * c && seen[0] == w[0], "{seen:?} {w:?}");
        assert_eq!(v.len(), 3, "{v:?}");
        assert!(has(&v, 0.0) && has(&v, -0.02) && has(&v, 0.02), "{v:?}");
        assert!(u.iter().all(|&x| x >= 0.026), "{u:?}");
        // A u-range that starts inside the ring (half a ring from 0) still reaches the pole.
        let rec = Stop { p: [0.002 + 0.5 * ring[0], 0.01], q: [-0.01, 0.01] };
        let [_, v] = lobe_splits(&LobesAt::new(&[table], theta, false), src, rec);
        assert!(has(&v, ring[1]), "{v:?}");
    }

    /// A lobe narrower than the range but wider than half of it (the 0.1° source of `rhopoint-iq-20` against
    /// its 1.8° gloss window) still has its centre as a split: the lobe chart is chosen because of it, and a
    /// box across its peak was fooled (docs/accuracy.md §5.2). One at least as wide as the range adds none.
    #[test]
    fn a_lobe_wider_than_half_the_range_still_splits_at_its_centre() {
        let m = AxisMap { s: [-8.7e-4, 8.7e-4], r: [-0.0158, 0.0158] };
        let range = 2.0 * (8.7e-4 + 0.0158);
        let ends_and_kinks = m.splits(&[]);
        assert_eq!(ends_and_kinks.len(), 4);
        for w in [0.55 * range, 0.99 * range] {
            let s = m.splits(&[(w, false)]);
            assert!(s.contains(&0.0), "w = {w}: {s:?}");
            assert_eq!(s.len(), 5, "±w lie outside the range: {s:?}");
        }
        assert_eq!(m.splits(&[(1.01 * range, false)]), ends_and_kinks);
    }

    /// The kink points lie on their kinks to rounding: ωi·ωo = 2c² − 1 (so ωi·h = c) for the half-angle
    /// kink, cos θi = c for the incidence kink; the ends when the kink does not cross.
    #[test]
    fn kink_points_lie_on_their_kinks() {
        let c = (1.0f64 - 0.3375 * 0.3375).sqrt();
        for theta in [0.349, 0.35, 0.5] {
            let axes = Axes::new(theta);
            for (u, qs, qr) in [(0.0, 0.0, 0.0), (1e-3, 0.02, -0.01), (-0.02, -0.03, 0.03), (0.01, 0.0, 0.0)] {
                let (lo, hi) = (-0.3, 0.3);
                let ps = half_angle_kink_point(&axes, 2.0 * c * c - 1.0, u, qs, qr, lo, hi);
                let (wi, wo) = (axes.source_dir(ps, qs), axes.receptor_dir(u - ps, qr));
                let h = (wi + wo).normalize();
                assert!((wi.dot(h) - c).abs() < 1e-15, "θ={theta} u={u}: ωi·h = {} at p_s = {ps}", wi.dot(h));
                let p = incidence_kink_point(&axes, c, qs, lo, hi);
                assert!((axes.source_dir(p, qs).z - c).abs() < 1e-15, "θ={theta}: cos θi at p = {p}");
            }
            // No crossing: the end on the kink's side.
            let (lo, hi) = (0.2, 0.3);
            let p = incidence_kink_point(&axes, c, 0.0, lo, hi);
            assert!(p == lo || p == hi);
        }
        // The analytic derivative of the half-angle residual (Newton's step) against a central difference.
        let axes = Axes::new(0.35);
        let dot = |ps: f64| axes.source_dir(ps, 0.01).dot(axes.receptor_dir(0.003 - ps, -0.02));
        let h = 1e-6;
        let numeric = (dot(0.004 + h) - dot(0.004 - h)) / (2.0 * h);
        let k = 0.7;
        let root = half_angle_kink_point(&axes, k, 0.003, 0.01, -0.02, 0.0, 0.0);
        assert_eq!(root, 0.0, "an empty bracket returns its end");
        assert!(numeric > 0.0, "ωi·ωo increases with p_s at constant u");
    }

    /// The plain chart's kink point lies on ωi·ωo = dot for a receptor off the mirror axis.
    #[test]
    fn the_plain_kink_point_lies_on_its_kink() {
        let (src, rec) = (Axes::new(45f64.to_radians()), Axes::new(30f64.to_radians()));
        let c = (1.0f64 - 0.599 * 0.599).sqrt();
        let dot = 2.0 * c * c - 1.0;
        for (qs, pr, qr) in [(0.0, 0.0, 0.0), (0.01, -0.02, 0.015), (-0.03, 0.03, -0.01)] {
            let wo = rec.receptor_dir(pr, qr);
            let p = plain_kink_point(&src, dot, qs, wo, -0.1, 0.1);
            assert!((src.source_dir(p, qs).dot(wo) - dot).abs() < 1e-14, "p = {p}");
        }
        // A receptor on the source's side (E2194 110°: viewing 45° − 110°): ωi·ωo decreases with p_s.
        let back = Axes::new(-65f64.to_radians());
        let wo = back.receptor_dir(0.01, -0.02);
        let d = src.source_dir(0.0, 0.01).dot(wo);
        let p = plain_kink_point(&src, d, 0.01, wo, -0.1, 0.1);
        assert!(p.abs() < 1e-12, "p = {p}");
    }

    /// The kinked position tiles [lo, hi]: each piece runs from one breakpoint to the next, ∫ dx/dt dt = hi − lo,
    /// and the breakpoints sit at t = j/(m + 1).
    #[test]
    fn the_kinked_position_tiles_the_interval_with_a_kink_at_each_cut() {
        let (lo, hi) = (-0.01, 0.02);
        let roots = [0.004, -0.02, 0.011]; // the second is outside: clamped (and kept in order)
        let m = roots.len();
        let pos = |t: f64| kinked_position(t, lo, hi, m, |k| roots[k]);
        assert_eq!(pos(0.0).0, lo);
        assert!((pos(0.25 - 1e-15).0 - 0.004).abs() < 1e-12 && (pos(0.25 + 1e-15).0 - 0.004).abs() < 1e-12);
        assert!((pos(0.5 + 1e-15).0 - 0.004).abs() < 1e-12, "the clamped root is an empty piece");
        assert!((pos(0.75 + 1e-15).0 - 0.011).abs() < 1e-12);
        assert!((pos(1.0 - 1e-15).0 - hi).abs() < 1e-12);
        // Midpoint rule on a fine grid: ∫ dx/dt dt = hi − lo.
        let n = 100_000;
        let total: f64 = (0..n).map(|i| pos((i as f64 + 0.5) / n as f64).1).sum::<f64>() / n as f64;
        assert!((total - (hi - lo)).abs() < 1e-9, "{total}");
        // Monotone.
        assert!((1..n).all(|i| pos(i as f64 / n as f64).0 >= pos((i - 1) as f64 / n as f64).0));
        // An empty overlap.
        assert_eq!(kinked_position(0.3, 0.1, 0.1, 1, |_| 0.1), (0.1, 0.0));
    }

    #[test]
    fn the_mirror_overlap_is_the_source_box_whose_mirror_is_in_the_receptor() {
        let src = Stop { p: [-0.01, 0.02], q: [-0.02, 0.02] };
        let rec = Stop { p: [-0.005, 0.03], q: [-0.01, 0.04] };
        assert_eq!(mirror_overlap(src, rec), Some(([-0.01, -0.02], [0.005, 0.01])));
        let off = Stop { p: [0.02, 0.03], q: [-0.01, 0.01] };
        assert_eq!(mirror_overlap(src, off), None, "a receptor offset past the mirror image sees none of it");
    }
}
