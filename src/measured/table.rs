//! The table layer shared by every measured format: sample nodes along an axis, the neighbours and weights
//! of a point between them (linear, clamped or periodic), and N-dimensional tables of several channels
//! interpolated multilinearly. The file readers (`merl.rs`, `rgl.rs`, `inplane.rs`) only decode bytes or
//! text into such tables and choose the coordinates; the interpolation is written once, here.
//!
//! Also here: the half/difference angles of Rusinkiewicz (1998, "A new change of variables for efficient
//! BRDF representation"), used by the MERL lookup and by the in-plane tables' isotropic extension.
use crate::Vec3;
use std::f64::consts::PI;
use std::sync::Arc;

/// Which samples of a table a lookup reads: all of them (the table as given), or about every second one along
/// each axis (its two coarse twins, from which a reading's data uncertainty is estimated: `docs/accuracy.md`
/// §Data uncertainty of measured tables). Both twins keep a clamped axis' ends (and so its range) and make
/// every interval wider than the table's: `Coarse` reads the samples 0, 2, 4, … and the last, its last
/// interval spanning three of the table's when their number is odd; `Shifted` the samples 0, 3, 5, 7, … and
/// the last, its first interval spanning three and its last two or three. A periodic axis (n even) keeps
/// 0, 2, … or 1, 3, … and wraps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum Resolution {
    /// Every sample: the table as given.
    #[default]
    Own,
    /// The even samples and the last: the first coarse twin.
    Coarse,
    /// The first sample, the odd samples from the third on, and the last: the second coarse twin, whose nodes
    /// are the table's samples that the first twin leaves out.
    Shifted,
}

impl Resolution {
    /// The two coarse twins.
    pub(crate) const TWINS: [Resolution; 2] = [Resolution::Coarse, Resolution::Shifted];

    /// A table's coarse twins, `at(r)` being the table read at resolution r: both [`Resolution::TWINS`] for a
    /// table at its own resolution, none for a twin (twins have no twins).
    pub(crate) fn twins<T>(self, at: impl Fn(Resolution) -> T) -> Vec<T> {
        if self != Resolution::Own {
            return Vec::new();
        }
        Resolution::TWINS.iter().map(|&r| at(r)).collect()
    }

    /// The sample of a twin at or below sample `i` of the table (for a piecewise constant lookup).
    pub(crate) fn floor(self, i: usize) -> usize {
        match self {
            Resolution::Own => i,
            Resolution::Coarse => i - i % 2,
            Resolution::Shifted if i < 3 => 0,
            Resolution::Shifted => i - (i + 1) % 2,
        }
    }
}

/// Where the samples of an axis sit, in the axis' coordinate.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Nodes {
    /// Samples at 0, 1, …, n − 1 (an index coordinate; MERL's bins, a unit square scaled by n − 1).
    Index(usize),
    /// Samples at strictly increasing values (angles of a goniometer, pbrt's parameter grids).
    Values(Vec<f64>),
}

/// What happens beyond the last sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Edge {
    /// The value of the nearest end sample (weights clamped to [0, 1]).
    Clamp,
    /// Period n (index nodes only): sample n is sample 0.
    Periodic,
}

/// One axis of a table.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TableAxis {
    pub nodes: Nodes,
    pub edge: Edge,
}

impl TableAxis {
    pub(crate) fn index(n: usize, edge: Edge) -> Self {
        TableAxis { nodes: Nodes::Index(n), edge }
    }

    pub(crate) fn values(v: Vec<f64>) -> Self {
        TableAxis { nodes: Nodes::Values(v), edge: Edge::Clamp }
    }

    pub(crate) fn len(&self) -> usize {
        match &self.nodes {
            Nodes::Index(n) => *n,
            Nodes::Values(v) => v.len(),
        }
    }

    /// The two neighbouring samples of `u` and the weight t of the second: the value is
    /// (1 − t)·v[i0] + t·v[i1]. NaN reads as the first sample.
    pub(crate) fn linear(&self, u: f64) -> (usize, usize, f64) {
        match (&self.nodes, self.edge) {
            (Nodes::Index(n), Edge::Clamp) => clamped_index_pair(u, *n),
            (Nodes::Index(n), Edge::Periodic) => periodic_index_pair(u, *n),
            (Nodes::Values(v), _) => value_pair(v, u),
        }
    }

    /// [`TableAxis::linear`] at a [`Resolution`]: for a twin, the two neighbouring nodes of the twin and the
    /// weight of the second, in the same coordinate `u`.
    pub(crate) fn linear_at(&self, u: f64, res: Resolution) -> (usize, usize, f64) {
        if res == Resolution::Own {
            return self.linear(u);
        }
        let n = self.len();
        if n < 2 {
            return self.linear(u);
        }
        let pos = |k: usize| match &self.nodes {
            Nodes::Index(_) => k as f64,
            Nodes::Values(v) => v[k],
        };
        if let (Nodes::Index(_), Edge::Periodic) = (&self.nodes, self.edge) {
            if !(u > 0.0) && res == Resolution::Coarse {
                return (0, 0, 0.0);
            }
            // Nodes every 2 from `first` (0 or 1), period n.
            let first = if res == Resolution::Coarse { 0.0 } else { 1.0 };
            let g = (u - first).rem_euclid(n as f64);
            let g = if g.is_finite() { g } else { 0.0 };
            let a = (g / 2.0).floor() * 2.0;
            let t = ((g - a) / 2.0).clamp(0.0, 1.0);
            let ai = (a as usize + first as usize) % n;
            return (ai, (ai + 2) % n, t);
        }
        // Nodes c_0 = 0, …, c_{m−1} = n − 1 (see the type's documentation).
        let shifted = res == Resolution::Shifted;
        let m = if !shifted {
            ((n - 1) / 2 + 1).max(2)
        } else if n >= 4 {
            (n - 4) / 2 + 2
        } else {
            2
        };
        let node = |j: usize| {
            if j + 1 == m {
                n - 1
            } else if !shifted {
                2 * j
            } else if j == 0 {
                0
            } else {
                2 * j + 1
            }
        };
        let interval = |i: usize| {
            if !shifted {
                i / 2
            } else if i < 3 {
                0
            } else {
                (i - 1) / 2
            }
        };
        if !(u > pos(0)) {
            return (0, node(1), 0.0);
        }
        let (i, _, _) = self.linear(u);
        let j = interval(i).min(m - 2);
        let (a, b) = (node(j), node(j + 1));
        (a, b, ((u - pos(a)) / (pos(b) - pos(a))).clamp(0.0, 1.0))
    }

    /// The sample at or below `u` (the cell that contains it), clamped to the axis; NaN → 0.
    #[cfg(test)]
    pub(crate) fn floor(&self, u: f64) -> usize {
        match &self.nodes {
            Nodes::Index(n) => floor_index(u, *n),
            Nodes::Values(v) => value_pair(v, u).0,
        }
    }

    /// The smallest spacing between neighbouring samples (in the axis' coordinate); infinite for one sample.
    pub(crate) fn min_spacing(&self) -> f64 {
        match &self.nodes {
            Nodes::Index(n) if *n > 1 => 1.0,
            Nodes::Values(v) if v.len() > 1 => v.windows(2).map(|w| w[1] - w[0]).fold(f64::INFINITY, f64::min),
            _ => f64::INFINITY,
        }
    }
}

/// ⌊u⌋ clamped to 0..n−1 (NaN → 0), as MERL's index functions.
pub(crate) fn floor_index(u: f64, n: usize) -> usize {
    if !(u > 0.0) {
        return 0;
    }
    (u as usize).min(n - 1)
}

/// Samples at 0, 1, …, n−1, clamped at both ends.
fn clamped_index_pair(u: f64, n: usize) -> (usize, usize, f64) {
    if n == 1 || !(u > 0.0) {
        return (0, 0, 0.0);
    }
    let top = (n - 1) as f64;
    if u >= top {
        return (n - 1, n - 1, 0.0);
    }
    let i = u.floor() as usize;
    (i, i + 1, u - i as f64)
}

/// Samples at 0, …, n−1 with period n, for u in [0, n).
fn periodic_index_pair(u: f64, n: usize) -> (usize, usize, f64) {
    if !(u > 0.0) {
        return (0, 0, 0.0);
    }
    let f = u.floor();
    let i = (f as usize) % n;
    (i, (i + 1) % n, (u - f).clamp(0.0, 1.0))
}

/// Samples at increasing values, clamped: the interval [v[i], v[i+1]] with the largest i such that
/// v[i] ≤ u (i ≤ n − 2; pbrt-v4's `FindInterval`), and the weight clamped to [0, 1].
fn value_pair(v: &[f64], u: f64) -> (usize, usize, f64) {
    let n = v.len();
    if n < 2 {
        return (0, 0, 0.0);
    }
    if !(u > v[0]) {
        return (0, 1, 0.0);
    }
    // Largest i in 0..=n−2 with v[i] ≤ u.
    let i = v[..n - 1].partition_point(|&x| x <= u).saturating_sub(1);
    let t = ((u - v[i]) / (v[i + 1] - v[i])).clamp(0.0, 1.0);
    (i, i + 1, t)
}

/// An N-dimensional table of `channels` values per cell, stored row-major (last axis fastest), channels
/// innermost.
#[derive(Clone, Debug)]
pub(crate) struct Table {
    axes: Vec<TableAxis>,
    strides: Vec<usize>,
    channels: usize,
    /// Shared, so that a table's coarse twin (`Resolution::Coarse`) costs no copy of its data.
    data: Arc<Vec<f64>>,
}

impl Table {
    /// `data.len()` must be channels × Π axis lengths (the readers check their files before this).
    pub(crate) fn new(axes: Vec<TableAxis>, channels: usize, data: Vec<f64>) -> Self {
        let mut strides = vec![0; axes.len()];
        let mut s = channels;
        for (k, a) in axes.iter().enumerate().rev() {
            strides[k] = s;
            s *= a.len();
        }
        assert_eq!(s, data.len(), "table size does not match its axes");
        Table { axes, strides, channels, data: Arc::new(data) }
    }

    pub(crate) fn axes(&self) -> &[TableAxis] {
        &self.axes
    }

    /// The channels of one cell.
    pub(crate) fn cell(&self, idx: &[usize]) -> &[f64] {
        let o: usize = idx.iter().zip(&self.strides).map(|(i, s)| i * s).sum();
        &self.data[o..o + self.channels]
    }

    /// The cell that contains the point (each axis' `floor`): piecewise constant lookup.
    #[cfg(test)]
    pub(crate) fn nearest(&self, coords: &[f64], out: &mut [f64]) {
        self.nearest_at(coords, Resolution::Own, out)
    }

    /// [`Table::nearest`] at a [`Resolution`] (a twin: its sample at or below each axis' floor).
    #[cfg(test)]
    pub(crate) fn nearest_at(&self, coords: &[f64], res: Resolution, out: &mut [f64]) {
        let mut o = 0;
        for (k, a) in self.axes.iter().enumerate() {
            let i = res.floor(a.floor(coords[k]));
            o += i * self.strides[k];
        }
        out.copy_from_slice(&self.data[o..o + self.channels]);
    }

    /// Multilinear interpolation: the 2^N corners in order (first axis outermost), each weighted by the
    /// product of its axes' weights taken in axis order; corners of weight 0 are skipped.
    #[cfg(test)]
    pub(crate) fn linear(&self, coords: &[f64], out: &mut [f64]) {
        self.linear_at(coords, Resolution::Own, out)
    }

    /// [`Table::linear`] at a [`Resolution`] (`Coarse`: on every second sample of each axis).
    pub(crate) fn linear_at(&self, coords: &[f64], res: Resolution, out: &mut [f64]) {
        out.fill(0.0);
        let pairs: Vec<(usize, usize, f64)> = self.axes.iter().zip(coords).map(|(a, &u)| a.linear_at(u, res)).collect();
        self.accumulate(&pairs, 0, 0, None, out);
    }

    fn accumulate(&self, pairs: &[(usize, usize, f64)], k: usize, offset: usize, w: Option<f64>, out: &mut [f64]) {
        if k == pairs.len() {
            let w = w.unwrap_or(1.0);
            if w != 0.0 {
                let v = &self.data[offset..offset + self.channels];
                for (o, x) in out.iter_mut().zip(v) {
                    *o += w * x;
                }
            }
            return;
        }
        let (i0, i1, t) = pairs[k];
        for (i, wk) in [(i0, 1.0 - t), (i1, t)] {
            let w = Some(match w {
                None => wk,
                Some(w) => w * wk,
            });
            self.accumulate(pairs, k + 1, offset + i * self.strides[k], w, out);
        }
    }
}

/// Rusinkiewicz half/difference angles of a pair of directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfDiff {
    /// Polar angle of the half vector h = normalize(ωi + ωo), in [0, π].
    pub theta_h: f64,
    /// Azimuth of h, in (−π, π].
    pub phi_h: f64,
    /// Polar angle of ωi in the frame where h is the pole, in [0, π].
    pub theta_d: f64,
    /// Azimuth of ωi in that frame, in (−π, π] (not yet folded by reciprocity).
    pub phi_d: f64,
}

/// Half/difference angles of (ωi, ωo) (Rusinkiewicz 1998): h = normalize(ωi + ωo); the difference vector is ωi
/// rotated by −φh about z and then by −θh about y, which brings h onto the pole. Polar angles are computed
/// with `atan2` (accurate near 0, where `acos` loses half the digits). If ωi + ωo = 0 the half vector is
/// undefined and h = z is used.
pub fn half_diff(wi: Vec3, wo: Vec3) -> HalfDiff {
    let s = wi + wo;
    let len = s.length();
    let h = if len > 0.0 && len.is_finite() { s / len } else { Vec3::Z };
    let theta_h = (h.x * h.x + h.y * h.y).sqrt().atan2(h.z);
    let phi_h = h.y.atan2(h.x);
    let (sp, cp) = phi_h.sin_cos();
    // Rotation by −φh about z.
    let t = Vec3::new(wi.x * cp + wi.y * sp, -wi.x * sp + wi.y * cp, wi.z);
    // Rotation by −θh about y: x' = x cos θh − z sin θh, z' = x sin θh + z cos θh.
    let (st, ct) = theta_h.sin_cos();
    let d = Vec3::new(t.x * ct - t.z * st, t.y, t.x * st + t.z * ct);
    let theta_d = (d.x * d.x + d.y * d.y).sqrt().atan2(d.z);
    let phi_d = d.y.atan2(d.x);
    HalfDiff { theta_h, phi_h, theta_d, phi_d }
}

/// The preamble every tabulated BRDF's `eval` shares (MERL, in-plane tables): a table holds reflection only,
/// so below either horizon the BRDF is 0 (`out` zeroed, `None`); above both, the half/difference angles of
/// the pair, the coordinates the lookup starts from.
pub(crate) fn reflection_half_diff(wi: Vec3, wo: Vec3, out: &mut [f64]) -> Option<HalfDiff> {
    if crate::brdf::below_horizon(wi, wo, out) {
        return None;
    }
    Some(half_diff(wi, wo))
}

/// The file name of a table's path, for `describe` (the path as given is in the error messages).
pub(crate) fn file_name(file: &str) -> String {
    std::path::Path::new(file).file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
}

/// Fold φd into [0, π) by reciprocity (f(φd) = f(φd + π) for an isotropic reciprocal BRDF). MERL's loaders
/// add π when φd < 0; here φd = π (which `atan2` returns for in-plane pairs, the sign of a zero deciding
/// between ±π) also maps to 0, so that the in-plane geometry does not depend on the sign of a rounding.
pub fn fold_phi_d(phi_d: f64) -> f64 {
    if !phi_d.is_finite() {
        return 0.0;
    }
    // For atan2's range [−π, π] this is MERL's "add π if negative", plus π ↦ 0.
    let p = phi_d.rem_euclid(PI);
    if p >= PI {
        0.0
    } else {
        p
    }
}

/// The polar angle of a unit vector, accurate near the pole: 2·asin(|d − z|/2) (Mitsuba 3's `elevation`).
pub(crate) fn elevation(d: Vec3) -> f64 {
    let dist = (d.x * d.x + d.y * d.y + (d.z - 1.0) * (d.z - 1.0)).sqrt();
    2.0 * (0.5 * dist).min(1.0).asin()
}

/// How far apart (relative) a table's values may be and the table still count as flat, a constant BRDF
/// stated as a diffuse term (`docs/instrument.md` §Quadrature, "Measured tables"): a file written with 13 significant
/// digits of f·cos θo and divided by cos θo at load differs from a constant in the last bits only.
pub(crate) const FLAT_RTOL: f64 = 1e-9;

/// Whether `values` are all finite and within [`FLAT_RTOL`] of one another (relative to the largest).
pub(crate) fn is_flat(values: impl IntoIterator<Item = f64>) -> bool {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        if !v.is_finite() {
            return false;
        }
        lo = lo.min(v);
        hi = hi.max(v);
    }
    hi >= lo && hi - lo <= FLAT_RTOL * hi.abs()
}

/// The angle of incidence at which [`specular_half_width`] scans a table (the D523 20° geometry's).
pub(crate) const HALF_WIDTH_THETA_I_DEG: f64 = 20.0;
/// The largest half-vector tilt [`specular_half_width`] scans, degrees.
pub(crate) const HALF_WIDTH_MAX_TILT_DEG: f64 = 40.0;
/// The scan's step in the half-vector tilt, degrees (then bisection to rounding).
const HALF_WIDTH_STEP_DEG: f64 = 0.02;

/// The half width at half maximum of a table's lobe about the specular direction, as a slope
/// (`docs/instrument.md` §Quadrature, "Measured tables": the lobe's own width, measured from the table rather than
/// assumed): with ωi at θi = [`HALF_WIDTH_THETA_I_DEG`] in the plane of incidence, the half vector is tilted in that
/// plane by τ on either side of the normal (ωo = 2(ωi·h)h − ωi) and the sum of the samples of f_r, as the table
/// evaluates it, is scanned in steps of 0.02° from τ = 0 until it first falls to half its value at τ = 0, then
/// bisected; the result is tan τ of the nearer side. Infinite when f_r at the specular pair is not positive
/// or does not fall to half within [`HALF_WIDTH_MAX_TILT_DEG`] (a flat or retro-reflecting table).
/// Deterministic: computed once when a table is loaded.
pub(crate) fn specular_half_width(eval: impl Fn(Vec3, Vec3, &mut [f64]), samples: usize) -> f64 {
    let ti = HALF_WIDTH_THETA_I_DEG.to_radians();
    let wi = Vec3::new(-ti.sin(), 0.0, ti.cos());
    let mut out = vec![0.0; samples];
    let mut at = |tau: f64| -> Option<f64> {
        let h = Vec3::new(tau.sin(), 0.0, tau.cos());
        let wo = 2.0 * wi.dot(h) * h - wi;
        if !(wo.z > 0.0) {
            return None;
        }
        eval(wi, wo, &mut out);
        Some(out.iter().sum())
    };
    let Some(peak) = at(0.0).filter(|f| *f > 0.0 && f.is_finite()) else { return f64::INFINITY };
    let half = 0.5 * peak;
    let step = HALF_WIDTH_STEP_DEG.to_radians();
    let steps = (HALF_WIDTH_MAX_TILT_DEG / HALF_WIDTH_STEP_DEG).round() as usize;
    let mut best = f64::INFINITY;
    for sign in [1.0, -1.0] {
        for k in 1..=steps {
            let tau = sign * k as f64 * step;
            let Some(v) = at(tau) else { break };
            if v <= half {
                // f(a) > half ≥ f(b): bisect (the interpolants are continuous).
                let (mut a, mut b) = (sign * (k - 1) as f64 * step, tau);
                for _ in 0..60 {
                    let m = 0.5 * (a + b);
                    match at(m) {
                        Some(v) if v > half => a = m,
                        _ => b = m,
                    }
                }
                best = best.min(b.abs().tan());
                break;
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_axis_brackets_and_clamps() {
        let a = TableAxis::values(vec![0.0, 1.0, 3.0]);
        assert_eq!(a.linear(-1.0), (0, 1, 0.0));
        assert_eq!(a.linear(0.5), (0, 1, 0.5));
        assert_eq!(a.linear(2.0), (1, 2, 0.5));
        assert_eq!(a.linear(3.0), (1, 2, 1.0));
        assert_eq!(a.linear(9.0), (1, 2, 1.0));
        assert_eq!(a.linear(f64::NAN), (0, 1, 0.0));
        assert_eq!(a.floor(2.5), 1);
        assert_eq!(a.min_spacing(), 1.0);
    }

    #[test]
    fn index_axes() {
        let c = TableAxis::index(4, Edge::Clamp);
        assert_eq!(c.linear(1.25), (1, 2, 0.25));
        assert_eq!(c.linear(7.0), (3, 3, 0.0));
        let p = TableAxis::index(4, Edge::Periodic);
        assert_eq!(p.linear(3.5), (3, 0, 0.5));
        assert_eq!(c.floor(3.9), 3);
    }

    #[test]
    fn coarse_axes_use_every_second_sample_and_the_last() {
        let v = TableAxis::values(vec![0.0, 1.0, 3.0, 4.0, 6.0]);
        // Four intervals: coarse nodes 0, 3 (index 2) and 6 (index 4).
        assert_eq!(v.linear_at(1.5, Resolution::Coarse), (0, 2, 0.5));
        assert_eq!(v.linear_at(4.5, Resolution::Coarse), (2, 4, 0.5));
        assert_eq!(v.linear_at(-1.0, Resolution::Coarse), (0, 2, 0.0));
        assert_eq!(v.linear_at(9.0, Resolution::Coarse), (2, 4, 1.0));
        // Three intervals: the coarse nodes are the ends, the one coarse interval spans all three.
        let v = TableAxis::values(vec![0.0, 1.0, 3.0, 4.0]);
        assert_eq!(v.linear_at(3.5, Resolution::Coarse), (0, 3, 0.875));
        // The shifted twin of 8 samples: 0, 3, 5, 7.
        let s = TableAxis::index(8, Edge::Clamp);
        assert_eq!(s.linear_at(1.5, Resolution::Shifted), (0, 3, 0.5));
        assert_eq!(s.linear_at(4.0, Resolution::Shifted), (3, 5, 0.5));
        assert_eq!(s.linear_at(6.5, Resolution::Shifted), (5, 7, 0.75));
        // Of 7 samples: 0, 3, 6.
        assert_eq!(TableAxis::index(7, Edge::Clamp).linear_at(5.0, Resolution::Shifted), (3, 6, 2.0 / 3.0));
        assert_eq!(TableAxis::index(6, Edge::Periodic).linear_at(0.5, Resolution::Shifted), (5, 1, 0.75));
        assert_eq!(Resolution::Shifted.floor(4), 3);
        assert_eq!(Resolution::Shifted.floor(2), 0);
        let c = TableAxis::index(5, Edge::Clamp);
        assert_eq!(c.linear_at(3.0, Resolution::Coarse), (2, 4, 0.5));
        assert_eq!(c.linear_at(7.0, Resolution::Coarse), (2, 4, 1.0));
        let p = TableAxis::index(6, Edge::Periodic);
        assert_eq!(p.linear_at(5.0, Resolution::Coarse), (4, 0, 0.5));
        assert_eq!(p.linear_at(1.0, Resolution::Coarse), (0, 2, 0.5));
        // A linear function is read exactly at either resolution.
        let t = Table::new(vec![TableAxis::values(vec![0.0, 1.0, 3.0, 4.0, 6.0])], 1, vec![1.0, 3.0, 7.0, 9.0, 13.0]);
        let mut out = [0.0];
        for x in [0.3, 2.2, 3.9, 5.5] {
            for res in Resolution::TWINS {
                t.linear_at(&[x], res, &mut out);
                assert!((out[0] - (1.0 + 2.0 * x)).abs() < 1e-12, "{x} {res:?}: {out:?}");
            }
        }
    }

    #[test]
    fn bilinear_reproduces_a_bilinear_function() {
        let ax = TableAxis::values(vec![0.0, 1.0, 2.0]);
        let ay = TableAxis::values(vec![0.0, 2.0]);
        let f = |x: f64, y: f64| 1.0 + 2.0 * x + 3.0 * y + 0.5 * x * y;
        let mut data = Vec::new();
        for x in [0.0, 1.0, 2.0] {
            for y in [0.0, 2.0] {
                data.push(f(x, y));
                data.push(-f(x, y));
            }
        }
        let t = Table::new(vec![ax, ay], 2, data);
        let mut out = [0.0; 2];
        t.linear(&[1.5, 0.5], &mut out);
        assert!((out[0] - f(1.5, 0.5)).abs() < 1e-14 && (out[1] + f(1.5, 0.5)).abs() < 1e-14);
        t.nearest(&[1.5, 0.5], &mut out);
        assert_eq!(out, [f(1.0, 0.0), -f(1.0, 0.0)]);
    }

    #[test]
    fn elevation_matches_acos() {
        for t in [0.0f64, 1e-6, 0.3, 1.2, 1.5] {
            let d = Vec3::new(t.sin(), 0.0, t.cos());
            assert!((elevation(d) - t).abs() < 1e-15);
        }
    }

    #[test]
    fn half_width_of_a_known_lobe() {
        // f = 1/(1 + (tan τ/a)²) in the half-vector tilt τ: half maximum at tan τ = a on both sides.
        let a = 0.02;
        let lobe = |wi: Vec3, wo: Vec3, out: &mut [f64]| {
            let h = (wi + wo).normalize();
            let t = (h.x * h.x + h.y * h.y).sqrt() / h.z;
            out[0] = 1.0 / (1.0 + (t / a) * (t / a));
        };
        let w = specular_half_width(lobe, 1);
        assert!((w - a).abs() < 1e-9 * a, "{w}");
        assert_eq!(specular_half_width(|_, _, out: &mut [f64]| out[0] = 0.3, 1), f64::INFINITY);
    }
}
