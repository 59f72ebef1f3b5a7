//! In-plane goniometer tables f_r(θi, θo): the shape most goniometers export (a scan of the receptor in the
//! plane of incidence for a few angles of incidence), read from the in-plane CSV export here and from ASTM
//! E1392-style text tables in `e1392.rs`.
//!
//! **Interpolation.** θo is signed: positive on the specular side (the side away from the source), negative
//! towards the source. Within a row (one θi) the table is linear in θo between the measured angles and
//! clamped to the end values outside them; between rows it is linear in θi at a fixed offset θo − θi from
//! the specular direction (the peak moves with θi), clamped outside the first and last θi. Rows may have
//! different θo grids. A `brdf_cos` value (f_r·cos θo) is divided by cos θo of its own
//! angle at load time.
//!
//! **Isotropy assumption** (explicit; an in-plane scan says nothing about the other azimuths). The material is
//! taken to be isotropic, and a quantity Q of the pair of directions to depend on it only through the
//! Rusinkiewicz half and difference angles (θh, θd), dropping the φd dependence (the "bivariate"
//! approximation of Romeiro, Vasilyev & Zickler, ECCV 2008, "Passive reflectometry"). An in-plane pair
//! (θi, θo) has θh = |θo − θi|/2 and θd = (θi + θo)/2, so a pair of directions anywhere maps back to the
//! in-plane pairs (θd − θh, θd + θh) and (θd + θh, θd − θh), one the reciprocal of the other; of those that
//! lie inside the measured domain, the one whose θi is nearer the actual polar angle of ωi is used (for a
//! pair in the plane of incidence that is the pair itself, so the table is exact in the plane).
//!
//! Which quantity Q is is the recipe's choice (`"off_plane"`, [`OffPlane`]):
//! * `f`: f_r itself, exact for a constant (Lambertian) BRDF;
//! * `f-cos-cos`: f_r·cos θi·cos θo, which for a microfacet lobe is F(θd)·D(θh)·G/4 (Walter et al. 2007,
//!   Eq. 20), exact for the lobe up to its masking term G;
//! * `microfacet`: f_r·cos θi·cos θo / G2(θi, θo) = F(θd)·D(θh)/4, with G2 the Smith height-correlated
//!   masking-shadowing term (Heitz 2014, "Understanding the masking-shadowing function", Eq. 99) of the
//!   table's own microfacet distribution: exact for any isotropic microfacet lobe with Smith masking, whatever
//!   its D and F. D is read from the table along the cut of constant θd at the table's smallest θi (F is
//!   constant along it; at θi = 0 this is the retro-reflection cut of Dupuy et al. 2015, "Extracting
//!   microfacet-based BRDF parameters from arbitrary materials with power iterations"), normalised by
//!   ∫ D cos θm dω = 1, and Λ follows from D by the projected-area identity
//!   cos θ·(1 + Λ(θ)) = ∫ ⟨ω·m⟩ D(m) dm (Heitz 2014, Eq. 43 with Smith's G1 = 1/(1 + Λ)); G2 enters D's
//!   cut itself, so the two are iterated (three fixed-point passes from Λ = 0).
//!
//! **Beyond the measured domain.** Near grazing an off-plane pair can have θd + θh above the largest measured
//! θo (at 85° the perpendicular receptor tilts the half vector by up to ≈ 26°, so θd + θh exceeds 90°):
//! no in-plane pair holds its (θh, θd). There Q is continued by separability, Q(θh, θd) =
//! Q(θh, θd*)·Q(0, θd)/Q(0, θd*), θd* the largest difference angle at which (θh, θd*) is measured — exact
//! when Q is a product of a function of θh and one of θd (a constant; F(θd)·D(θh)), and the specular row
//! Q(0, ·) carrying the θd dependence.
use super::table::{file_name, reflection_half_diff, Nodes, Resolution, Table, TableAxis};
use crate::brdf::{Brdf, Hints, Lobe, Term, TermKind};
use crate::spectrum::Sampling;
use crate::{Error, Result, Vec3};
use std::f64::consts::FRAC_PI_2;
use std::path::Path;

/// What the value column holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Quantity {
    /// f_r in sr⁻¹.
    Brdf,
    /// f_r·cos θo in sr⁻¹ (the "cosine-corrected BRDF" of ASTM E1392).
    BrdfCos,
}

/// The quantity the isotropic extension holds constant along (θh, θd) (module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OffPlane {
    /// f_r(θh, θd): exact for a constant (Lambertian) BRDF.
    Brdf,
    /// f_r·cos θi·cos θo as a function of (θh, θd): exact for a microfacet lobe up to its masking term.
    BrdfCosCos,
    /// f_r·cos θi·cos θo / G2(θi, θo) as a function of (θh, θd), G2 the Smith height-correlated term of the
    /// table's own distribution: exact for an isotropic microfacet lobe with Smith masking.
    Microfacet,
}

impl OffPlane {}

/// One measured point: θi, signed θo (degrees) and the value, with the line it came from.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Point {
    pub theta_i_deg: f64,
    pub theta_o_deg: f64,
    pub value: f64,
    pub line: usize,
}

/// The measured domain (radians): the rows' θi and the θo range of each row. A pair (θi, θo) is measured when
/// θi lies between the first and last row and every row its value is interpolated from (the two around θi,
/// at the same offset θo − θi from the specular direction) holds that offset within its θo range — so that
/// no lookup reads a row's clamped end value for a θo beyond it.
#[derive(Clone, Debug)]
struct Domain {
    rows: Vec<f64>,
    ranges: Vec<(f64, f64)>,
}

impl Domain {
    fn theta_i(&self) -> (f64, f64) {
        (self.rows[0], self.rows[self.rows.len() - 1])
    }

    fn row_holds(&self, i: usize, ti: f64, to: f64) -> bool {
        let shifted = to - ti + self.rows[i];
        shifted >= self.ranges[i].0 && shifted <= self.ranges[i].1
    }

    fn contains(&self, (ti, to): (f64, f64)) -> bool {
        let (lo, hi) = self.theta_i();
        if !(ti >= lo && ti <= hi) {
            return false;
        }
        // The bracketing rows as `TableAxis::linear` gives them: rows[i] ≤ θi ≤ rows[i + 1].
        let i = self.rows[..self.rows.len() - 1].partition_point(|&x| x <= ti).saturating_sub(1);
        if self.rows[i] == ti || self.rows.len() == 1 {
            return self.row_holds(i, ti, to);
        }
        self.row_holds(i, ti, to) && self.row_holds(i + 1, ti, to)
    }

    /// The largest difference angle θd* ≤ θd at which a pair with half angle θh is measured, if any: the
    /// specular-side ordering (θd* − θh, θd* + θh) sits at the last row θr with θr + 2θh inside that row (the
    /// pair on a row is read from it alone); the reciprocal one (θd* + θh, θd* − θh) at θd* = last θi − θh.
    /// Returned with the measured pair there (computed once, so that rounding cannot move it off a row).
    fn largest_theta_d(&self, th: f64, td: f64) -> Option<(f64, (f64, f64))> {
        for pair in [(td - th, td + th), (td + th, td - th)] {
            if self.contains(pair) {
                return Some((td, pair));
            }
        }
        let mut best: Option<(f64, (f64, f64))> = None;
        let mut consider = |cand: f64, pair: (f64, f64)| {
            if cand <= td && self.contains(pair) && best.is_none_or(|b| cand > b.0) {
                best = Some((cand, pair));
            }
        };
        for (i, &r) in self.rows.iter().enumerate().rev() {
            if r + th <= td && r + 2.0 * th <= self.ranges[i].1 {
                consider(r + th, (r, r + 2.0 * th));
                break;
            }
        }
        let (_, hi) = self.theta_i();
        let b = (hi - th).min(td);
        consider(b, (b + th, b - th));
        best
    }
}

/// Smith's Λ of the table's distribution (`OffPlane::Microfacet`), held as the projected area
/// A(θ) = cos θ·(1 + Λ(θ)) = ∫ ⟨ω·m⟩ D(m) dm on a uniform grid of θ over [0, π/2]: A is smooth up to grazing
/// (where Λ grows like tan θ and would not interpolate), and Λ = A/cos θ − 1 at the exact cos θ.
#[derive(Clone, Debug)]
struct SmithLambda {
    step: f64,
    area: Vec<f64>,
}

/// Grid of the projected-area table: 0.1° (A is smooth; the fixtures' Λ is read to ≤ 1e-5 relative).
const LAMBDA_STEP_DEG: f64 = 0.1;
/// Fixed-point passes between D's cut and Λ (the cut's own G2 depends on Λ; Λ changes by < 1e-6 relative on
/// the fixtures after the third).
const LAMBDA_PASSES: usize = 3;

impl SmithLambda {
    /// Λ ≡ 0 (A = cos θ).
    fn zero() -> Self {
        let step = LAMBDA_STEP_DEG.to_radians();
        let n = (FRAC_PI_2 / step).round() as usize;
        SmithLambda { step, area: (0..=n).map(|j| (j as f64 * step).min(FRAC_PI_2).cos()).collect() }
    }

    /// Λ at polar angle θ: A linear in θ between the nodes, divided by cos θ.
    fn at(&self, theta: f64) -> f64 {
        let theta = theta.abs().min(FRAC_PI_2);
        let u = (theta / self.step).min((self.area.len() - 1) as f64);
        let i = (u as usize).min(self.area.len() - 2);
        let t = u - i as f64;
        let a = (1.0 - t) * self.area[i] + t * self.area[i + 1];
        let l = a / theta.cos() - 1.0;
        if l.is_finite() {
            l.max(0.0)
        } else {
            f64::INFINITY
        }
    }

    /// Smith height-correlated masking-shadowing G2 = 1/(1 + Λ(θi) + Λ(θo)) (Heitz 2014, Eq. 99).
    fn g2(&self, theta_i: f64, theta_o: f64) -> f64 {
        1.0 / (1.0 + self.at(theta_i) + self.at(theta_o))
    }

    /// The projected area of an isotropic distribution D(θm) given at θm = k·dθ (k = 0..): D normalised by
    /// 2π ∫ D cos θm sin θm dθm = 1, then A(θ) = ∫ D(θm) sin θm Φ(θ, θm) dθm with Φ the azimuthal integral of
    /// ⟨ω·m⟩ in closed form (`projected_cosine_azimuthal`). Trapezoidal rule in θm.
    fn from_distribution(d: &[f64], d_theta: f64) -> Self {
        let step = LAMBDA_STEP_DEG.to_radians();
        let n = (FRAC_PI_2 / step).round() as usize;
        let last = d.len() - 1;
        let trap = |k: usize| if k == 0 || k == last { 0.5 } else { 1.0 };
        let norm: f64 = d
            .iter()
            .enumerate()
            .map(|(k, &dk)| {
                let tm = k as f64 * d_theta;
                trap(k) * dk * tm.cos() * tm.sin()
            })
            .sum::<f64>()
            * 2.0
            * std::f64::consts::PI
            * d_theta;
        if !(norm > 0.0 && norm.is_finite()) {
            return Self::zero();
        }
        let area = (0..=n)
            .map(|j| {
                let (st, ct) = (j as f64 * step).min(FRAC_PI_2).sin_cos();
                let sum: f64 = d
                    .iter()
                    .enumerate()
                    .map(|(k, &dk)| {
                        let (sm, cm) = (k as f64 * d_theta).sin_cos();
                        trap(k) * dk * sm * projected_cosine_azimuthal(st * sm, ct.max(0.0) * cm)
                    })
                    .sum();
                // Never below the flat surface's cos θ (Λ ≥ 0).
                (sum * d_theta / norm).max(ct.max(0.0))
            })
            .collect();
        SmithLambda { step, area }
    }
}

/// ∫₀^{2π} max(0, a·cos φ + b) dφ for a, b ≥ 0: 2πb if b ≥ a, else 2(√(a² − b²) + b·(π − acos(b/a))) — the
/// azimuthal part of ∫ ⟨ω·m⟩ dm with a = sin θ sin θm, b = cos θ cos θm.
fn projected_cosine_azimuthal(a: f64, b: f64) -> f64 {
    use std::f64::consts::PI;
    if b >= a {
        2.0 * PI * b
    } else {
        2.0 * ((a * a - b * b).sqrt() + b * (PI - (b / a).acos()))
    }
}

/// The quantity interpolated between rows (linearly in θi at a fixed offset from the specular direction).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Row {
    F,
    CosCos,
    CosCosOverG2,
}

/// An in-plane table with the isotropic extension.
#[derive(Clone, Debug)]
pub struct InPlaneBrdf {
    file: String,
    format: &'static str,
    theta_i: TableAxis,
    /// One 1-D table per θi row, over signed θo in radians.
    rows: Vec<Table>,
    /// Smallest θo step of any row (radians).
    min_step: f64,
    points: usize,
    /// Points of the file not used (e.g. out of the plane), said in `describe`.
    unused: usize,
    theta_o_range: (f64, f64),
    domain: Domain,
    off_plane: OffPlane,
    /// Smith's Λ of the table's distribution (`OffPlane::Microfacet`; zero otherwise).
    lambda: SmithLambda,
    sampling: Sampling,
    /// Every value of the file the same (to `table::FLAT_RTOL`): with the `f` extension a constant BRDF, stated as a diffuse term
    /// (`docs/instrument.md` §Quadrature, "Measured tables").
    flat: bool,
    /// The lobe's half width at half maximum as a slope, measured from the table (with its extension) when
    /// it is built ([`super::table::specular_half_width`]).
    half_width: f64,
    /// The samples the lookups read: the file's own, or every second θo of each row and every second row (the
    /// coarse twin, [`Brdf::coarser`]); the measured domain and Smith's Λ stay the table's own.
    resolution: Resolution,
}

impl InPlaneBrdf {
    /// Build the table from points (any order). Errors name the file and the line of the offending point.
    pub(crate) fn from_points(
        file: &str,
        format: &'static str,
        mut points: Vec<Point>,
        quantity: Quantity,
        unused: usize,
    ) -> Result<Self> {
        let at = |p: &Point, m: String| Error::input(file, format!("line {}", p.line), m);
        for p in &points {
            if !(p.theta_i_deg >= 0.0 && p.theta_i_deg < 90.0) {
                return Err(at(p, format!("theta_i = {}°: allowed 0 ≤ θi < 90", p.theta_i_deg)));
            }
            if !(p.theta_o_deg > -90.0 && p.theta_o_deg < 90.0) {
                return Err(at(
                    p,
                    format!("theta_o = {}°: allowed −90 < θo < 90 (signed, + on the specular side)", p.theta_o_deg),
                ));
            }
            if !(p.value.is_finite() && p.value >= 0.0) {
                return Err(at(p, format!("value {}: a BRDF must be finite and ≥ 0", p.value)));
            }
        }
        points.sort_by(|a, b| a.theta_i_deg.total_cmp(&b.theta_i_deg).then(a.theta_o_deg.total_cmp(&b.theta_o_deg)));
        let mut thetas = Vec::new();
        let mut rows = Vec::new();
        let mut min_step = f64::INFINITY;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut row_ranges = Vec::new();
        let mut k = 0;
        while k < points.len() {
            let ti = points[k].theta_i_deg;
            let row: Vec<&Point> = points[k..].iter().take_while(|p| p.theta_i_deg == ti).collect();
            k += row.len();
            if row.len() < 2 {
                return Err(at(
                    row[0],
                    format!("θi = {ti}° has a single θo; a row needs at least 2 points to interpolate"),
                ));
            }
            for w in row.windows(2) {
                if w[1].theta_o_deg == w[0].theta_o_deg {
                    return Err(at(w[1], format!("θi = {ti}°, θo = {}° repeats line {}", w[1].theta_o_deg, w[0].line)));
                }
            }
            let tos: Vec<f64> = row.iter().map(|p| p.theta_o_deg.to_radians()).collect();
            let vals: Vec<f64> = row
                .iter()
                .zip(&tos)
                .map(|(p, t)| match quantity {
                    Quantity::Brdf => p.value,
                    Quantity::BrdfCos => p.value / t.cos(),
                })
                .collect();
            let (first, last) = (tos[0], tos[tos.len() - 1]);
            lo = lo.min(first);
            hi = hi.max(last);
            row_ranges.push((first, last));
            let axis = TableAxis::values(tos);
            min_step = min_step.min(axis.min_spacing());
            thetas.push(ti.to_radians());
            rows.push(Table::new(vec![axis], 1, vals));
        }
        if rows.is_empty() {
            return Err(Error::input(file, "", "no data points"));
        }
        let domain = Domain { rows: thetas.clone(), ranges: row_ranges };
        let flat = super::table::is_flat(rows.iter().flat_map(|r| (0..r.axes()[0].len()).map(|i| r.cell(&[i])[0])));
        let mut brdf = InPlaneBrdf {
            file: file.to_string(),
            format,
            theta_i: TableAxis::values(thetas),
            rows,
            min_step,
            points: points.len(),
            unused,
            theta_o_range: (lo, hi),
            domain,
            off_plane: OffPlane::Brdf,
            lambda: SmithLambda::zero(),
            sampling: Sampling::grey(),
            flat,
            half_width: f64::INFINITY,
            resolution: Resolution::Own,
        };
        brdf.half_width = brdf.measure_half_width();
        Ok(brdf)
    }

    fn measure_half_width(&self) -> f64 {
        super::table::specular_half_width(|wi, wo, out| self.eval(wi, wo, out), 1)
    }

    /// Whether the table is a constant BRDF as evaluated: every value the same (to `table::FLAT_RTOL`, the
    /// rounding of a file of f·cos θo) and the `f` extension
    /// ([`Hints::terms`] then states a diffuse term, integrated in the plain chart).
    pub(crate) fn is_flat(&self) -> bool {
        self.flat && self.off_plane == OffPlane::Brdf
    }

    /// The same table with the given off-plane extension (for `Microfacet`, Λ of the table's distribution is
    /// computed here, once).
    pub fn with_off_plane(mut self, off_plane: OffPlane) -> Self {
        self.off_plane = off_plane;
        self.lambda = SmithLambda::zero();
        if off_plane == OffPlane::Microfacet {
            for _ in 0..LAMBDA_PASSES {
                let (d, d_theta) = self.distribution_cut();
                self.lambda = SmithLambda::from_distribution(&d, d_theta);
            }
        }
        self.half_width = self.measure_half_width();
        self
    }

    /// f_r at an in-plane pair (θi ≥ 0, signed θo), radians: linear in θo within rows; between rows linear in
    /// θi at a fixed offset θo − θi from the specular direction (so that the specular peak, which moves with
    /// θi, is interpolated onto itself).
    pub(crate) fn in_plane(&self, theta_i: f64, theta_o: f64) -> f64 {
        self.interpolate(theta_i, theta_o, Row::F)
    }

    /// f_r·cos θi·cos θo at an in-plane pair, interpolated as that product between rows (the quantity the
    /// `f-cos-cos` and `microfacet` extensions take to be smooth).
    pub(crate) fn in_plane_cos_cos(&self, theta_i: f64, theta_o: f64) -> f64 {
        self.interpolate(theta_i, theta_o, Row::CosCos)
    }

    fn interpolate(&self, theta_i: f64, theta_o: f64, row: Row) -> f64 {
        let res = self.resolution;
        let (i0, i1, t) = self.theta_i.linear_at(theta_i, res);
        let row_theta = |i: usize| match &self.theta_i.nodes {
            Nodes::Values(v) => v[i],
            Nodes::Index(_) => i as f64,
        };
        let at = |i: usize| {
            let (ti, to) = (row_theta(i), theta_o - theta_i + row_theta(i));
            let mut v = [0.0];
            self.rows[i].linear_at(&[to], res, &mut v);
            let to = to.clamp(-FRAC_PI_2, FRAC_PI_2);
            match row {
                Row::F => v[0],
                Row::CosCos => v[0] * ti.cos() * to.cos(),
                Row::CosCosOverG2 => v[0] * ti.cos() * to.cos() / self.lambda.g2(ti, to),
            }
        };
        let a = at(i0);
        if t == 0.0 {
            return a;
        }
        (1.0 - t) * a + t * at(i1)
    }

    /// The quantity Q that the extension takes to depend on (θh, θd) only, at a measured in-plane pair.
    fn q_in_plane(&self, (ti, to): (f64, f64)) -> f64 {
        match self.off_plane {
            OffPlane::Brdf => self.in_plane(ti, to),
            OffPlane::BrdfCosCos => self.in_plane_cos_cos(ti, to),
            // Interpolated between rows as F(θd)·D(θh)/4 itself (smooth in θd at the rows' fixed offset).
            OffPlane::Microfacet => self.interpolate(ti, to, Row::CosCosOverG2),
        }
    }

    /// The measured in-plane pair with half/difference angles (θh, θd): of the two reciprocal ones inside the
    /// domain, the one whose θi is nearer `near`; None if neither is measured.
    fn measured_pair(&self, th: f64, td: f64, near: f64) -> Option<(f64, f64)> {
        let a = (td - th, td + th);
        let b = (td + th, td - th);
        match (self.domain.contains(a), self.domain.contains(b)) {
            (true, true) => Some(if (a.0 - near).abs() <= (b.0 - near).abs() { a } else { b }),
            (true, false) => Some(a),
            (false, true) => Some(b),
            (false, false) => None,
        }
    }

    /// Q(θh, θd): at the measured pair when there is one, else continued by separability from the largest
    /// measured θd* and the specular row (module documentation); a pair no continuation reaches (θh beyond
    /// the domain's half-width) reads the nearest in-plane value, clamped.
    fn q(&self, th: f64, td: f64, near: f64) -> f64 {
        if let Some(p) = self.measured_pair(th, td, near) {
            return self.q_in_plane(p);
        }
        // Q(θh, θd) = Q(θh, θd*)·Q(0, θd)/Q(0, θd*), the specular row read at θd or its last measured θd.
        if let (Some((td_star, p)), Some((_, s))) =
            (self.domain.largest_theta_d(th, td), self.domain.largest_theta_d(0.0, td))
        {
            if let Some((_, s_star)) = self.domain.largest_theta_d(0.0, td_star) {
                let den = self.q_in_plane(s_star);
                if den > 0.0 {
                    return self.q_in_plane(p) * self.q_in_plane(s) / den;
                }
            }
        }
        // No continuation reaches the pair (θh beyond the domain's half-width): the nearest in-plane value,
        // clamped into the measured angles (not to grazing, where G2 vanishes).
        let (ti, to) = if td - th >= 0.0 { (td - th, td + th) } else { (td + th, td - th) };
        let (lo, hi) = self.theta_o_range;
        self.q_in_plane((ti.min(self.domain.theta_i().1), to.clamp(lo, hi)))
    }

    /// D(θm) up to a constant along the cut θd = the table's smallest θi, for θm = k·dθ as far as the cut is
    /// measured: Q there is F(θd)·D(θm)/4 with F fixed (module documentation), with the current Λ.
    fn distribution_cut(&self) -> (Vec<f64>, f64) {
        let d_theta = (0.5 * self.min_step).clamp(0.01f64.to_radians(), 0.1f64.to_radians());
        let td = self.domain.theta_i().0;
        let mut d = Vec::new();
        let mut k = 0usize;
        while let Some(p) = self.measured_pair(k as f64 * d_theta, td, td) {
            let tm = k as f64 * d_theta;
            if tm >= FRAC_PI_2 {
                break;
            }
            d.push(self.q_in_plane(p).max(0.0));
            k += 1;
        }
        if d.len() < 2 {
            d = vec![0.0, 0.0];
        }
        (d, d_theta)
    }

    /// The resolution stated with the lobe (`Tail::Table`): tan of half the smallest θo step (a step of the receptor by
    /// Δ turns the half vector by Δ/2).
    pub(crate) fn resolution_slope(&self) -> f64 {
        (0.5 * self.min_step).tan()
    }
}

impl Brdf for InPlaneBrdf {
    fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    fn eval(&self, wi: Vec3, wo: Vec3, out: &mut [f64]) {
        let Some(hd) = reflection_half_diff(wi, wo, out) else { return };
        let (th, td) = (hd.theta_h, hd.theta_d);
        let theta_i = (wi.x * wi.x + wi.y * wi.y).sqrt().atan2(wi.z);
        out[0] = match self.off_plane {
            // f itself is not a product of a θh and a θd function for a lobe, so it is not continued by
            // separability: the nearer reciprocal pair, clamped into the in-plane domain (exact for a constant).
            OffPlane::Brdf => {
                let a = (td - th, td + th);
                let b = (td + th, td - th);
                let (ti, to) = if a.0 >= 0.0 && (a.0 - theta_i).abs() <= (b.0 - theta_i).abs() { a } else { b };
                self.in_plane(ti.min(FRAC_PI_2), to.clamp(-FRAC_PI_2, FRAC_PI_2))
            }
            // f = Q/(cos θi cos θo) at the actual cosines (exact in the plane), times G2 for `microfacet`.
            OffPlane::BrdfCosCos | OffPlane::Microfacet => {
                let q = self.q(th, td, theta_i);
                let theta_o = (wo.x * wo.x + wo.y * wo.y).sqrt().atan2(wo.z);
                let g2 = if self.off_plane == OffPlane::Microfacet { self.lambda.g2(theta_i, theta_o) } else { 1.0 };
                let f = q * g2 / (wi.z * wo.z);
                if f.is_finite() {
                    f.max(0.0)
                } else {
                    0.0
                }
            }
        };
    }

    fn hints(&self) -> Hints {
        if self.is_flat() {
            return Hints::new(vec![Term {
                label: format!(
                    "measured in-plane table ({}): every value the same (to 1e-9), a constant BRDF",
                    self.format
                ),
                kind: TermKind::Diffuse,
            }]);
        }
        Hints::new(vec![Term {
            label: format!("measured in-plane table ({}, isotropic (θh, θd) extension)", self.format),
            kind: TermKind::Lobe(Lobe {
                slope_width: self.half_width,
                medium_eta: 1.0,
                label: format!("measured ({})", self.format),
                tail: crate::brdf::Tail::Table { half_width: self.half_width, resolution: self.resolution_slope() },
            }),
        }])
    }

    fn coarser(&self) -> Vec<std::sync::Arc<dyn Brdf>> {
        self.resolution.twins(|resolution| std::sync::Arc::new(InPlaneBrdf { resolution, ..self.clone() }) as _)
    }

    fn describe(&self) -> String {
        let name = file_name(&self.file);
        let unused =
            if self.unused > 0 { format!(", {} out-of-plane points not used", self.unused) } else { String::new() };
        format!(
            "measured in-plane table {name} ({}, {} points, {} angles of incidence, θo {:.1}° to {:.1}°, clamped outside; isotropic, {} off the plane{unused}{})",
            self.format,
            self.points,
            self.rows.len(),
            self.theta_o_range.0.to_degrees(),
            self.theta_o_range.1.to_degrees(),
            match self.off_plane {
                OffPlane::Brdf => "f = f(θh, θd)",
                OffPlane::BrdfCosCos => "f·cos θi·cos θo = g(θh, θd)",
                OffPlane::Microfacet => "f·cos θi·cos θo/G2 = g(θh, θd), Smith G2 of the table's own D",
            },
            if self.resolution != Resolution::Own { "; a coarse twin, read on about every second sample" } else { "" }
        )
    }
}

/// Read the in-plane CSV export: a header naming the columns `theta_i`, `theta_o` (degrees, θo signed, + on
/// the specular side) and exactly one of `brdf` (f_r, sr⁻¹) or `brdf_cos` (f_r·cos θo, sr⁻¹), in any order
/// (other columns are refused); one point per row; lines starting with `#` are comments.
pub fn parse_csv(text: &str, file: &str) -> Result<InPlaneBrdf> {
    // A UTF-8 byte-order mark (Excel's "CSV UTF-8", PowerShell 5's `-Encoding utf8`) is no part of the header.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((hline, header)) = lines.next() else {
        return Err(Error::input(file, "", "empty: expected a header `theta_i,theta_o,brdf` (or `brdf_cos`)"));
    };
    let cols: Vec<String> = header.split(',').map(|c| c.trim().to_ascii_lowercase()).collect();
    let find = |name: &str| cols.iter().position(|c| c == name);
    let allowed =
        "allowed columns: theta_i, theta_o (degrees) and one of brdf (f_r, 1/sr) or brdf_cos (f_r·cos θo, 1/sr)";
    let hdr_err = |m: String| Error::input(file, format!("line {}", hline + 1), format!("{m}; {allowed}"));
    for c in &cols {
        if !["theta_i", "theta_o", "brdf", "brdf_cos"].contains(&c.as_str()) {
            return Err(hdr_err(format!("unknown column {c:?}")));
        }
    }
    let (Some(ci), Some(co)) = (find("theta_i"), find("theta_o")) else {
        return Err(hdr_err("missing column theta_i or theta_o".into()));
    };
    let (cv, quantity) = match (find("brdf"), find("brdf_cos")) {
        (Some(c), None) => (c, Quantity::Brdf),
        (None, Some(c)) => (c, Quantity::BrdfCos),
        (Some(_), Some(_)) => {
            return Err(hdr_err("both brdf and brdf_cos given: the column must say which one the values are".into()))
        }
        (None, None) => return Err(hdr_err("missing the value column".into())),
    };
    let mut points = Vec::new();
    for (i, l) in lines {
        let cells: Vec<&str> = l.split(',').map(str::trim).collect();
        if cells.len() != cols.len() {
            return Err(Error::input(
                file,
                format!("line {}", i + 1),
                format!("{} cells, the header has {} columns", cells.len(), cols.len()),
            ));
        }
        let num = |c: usize| -> Result<f64> {
            cells[c].parse::<f64>().ok().filter(|x| x.is_finite()).ok_or_else(|| {
                Error::input(
                    file,
                    format!("line {}, column {}", i + 1, cols[c]),
                    format!("{:?} is not a finite number", cells[c]),
                )
            })
        };
        points.push(Point { theta_i_deg: num(ci)?, theta_o_deg: num(co)?, value: num(cv)?, line: i + 1 });
    }
    InPlaneBrdf::from_points(file, "in-plane CSV", points, quantity, 0)
}

/// Read an in-plane CSV file.
pub(crate) fn load_csv(path: &Path) -> Result<InPlaneBrdf> {
    let file = path.display().to_string();
    let text = crate::input::read_text_limited(path, "table", crate::input::MAX_TABLE_BYTES)?;
    parse_csv(&text, &file)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_byte_order_mark_is_read_as_nothing_in_both_text_formats() {
        let csv = "theta_i,theta_o,brdf\n20,10,1\n20,20,3\n20,30,2\n60,50,4\n60,60,8\n60,70,6\n";
        let plain = parse_csv(csv, "t.csv").unwrap();
        let bom = parse_csv(&format!("\u{feff}{csv}"), "t.csv").unwrap();
        let (wi, wo) = (Vec3::new(-0.3, 0.0, 0.95).normalize(), Vec3::new(0.3, 0.0, 0.95).normalize());
        let (mut a, mut b) = ([0.0], [0.0]);
        plain.eval(wi, wo, &mut a);
        bom.eval(wi, wo, &mut b);
        assert_eq!(a, b);
        let e1392 = std::fs::read_to_string("fixtures/materials/inplane/beckmann-e1392.txt").unwrap();
        assert!(crate::measured::e1392::parse(&format!("\u{feff}{e1392}"), "t.txt").is_ok());
    }

    #[test]
    fn in_plane_pairs_are_read_back_exactly() {
        let text = "theta_i,theta_o,brdf\n20,10,1\n20,20,3\n20,30,2\n60,50,4\n60,60,8\n60,70,6\n";
        let t = parse_csv(text, "t.csv").unwrap();
        let d = |deg: f64, side: f64| Vec3::new(side * deg.to_radians().sin(), 0.0, deg.to_radians().cos());
        let mut out = [0.0];
        t.eval(d(20.0, -1.0), d(20.0, 1.0), &mut out);
        assert!((out[0] - 3.0).abs() < 1e-12, "{out:?}");
        t.eval(d(20.0, -1.0), d(25.0, 1.0), &mut out);
        assert!((out[0] - 2.5).abs() < 1e-9, "{out:?}");
        // Half way between the rows, at the specular direction.
        assert!((t.in_plane(40f64.to_radians(), 40f64.to_radians()) - 0.5 * (3.0 + 8.0)).abs() < 1e-12);
    }

    #[test]
    fn csv_errors_name_line_and_column() {
        let e = parse_csv("theta_i,theta_o,brdf\n20,10,x\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains("line 2, column brdf"), "{e}");
        let e = parse_csv("theta_i,theta_o,value\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains("unknown column \"value\""), "{e}");
        // A name from the file cannot close the quotes or hide in the message: it is quoted and escaped.
        let e = parse_csv("theta_i,theta_o,a\"b`\u{7}\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains(r#"unknown column "a\"b`\u{7}""#) && !e.contains('\u{7}'), "{e}");
        let e = parse_csv("theta_i,theta_o,brdf,brdf_cos\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains("both brdf and brdf_cos"), "{e}");
        let e = parse_csv("theta_i,theta_o,brdf\n20,10,1\n20,10,2\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("repeats line 2"), "{e}");
    }
}
