//! Levelling of a wet film's surface texture by surface tension, from application to cure: the linearised
//! thin-film (lubrication) equation with a viscosity that rises and a film that thins as solvent leaves.
//! Formulas, assumptions and sources: `docs/model.md` §Levelling of the applied texture.
//!
//! Units: lengths in µm, spatial frequencies in 1/µm, times in s, viscosities in Pa·s, surface tension in
//! mN/m; the levelling integral L in µm⁴.
//!
//! * A sinusoid of wavelength Λ (spatial frequency f = 1/Λ) on a film of thickness h ≪ Λ decays at the rate
//!   r = γ h³ k⁴/(3η), k = 2πf, i.e. 16π⁴γh³/(3ηΛ⁴) (Orchard 1962);
//! * with h(t) and η(t) changing slowly against that decay, the mode equation da/dt = −r(t)·a integrates to
//!   a(T)/a(0) = exp(−(16π⁴/3)·f⁴·L), L = ∫₀ᵀ γ h(t)³/η(t) dt (the levelling integral);
//! * the dry film keeps the resin: with the solids spread evenly through the film's depth (no
//!   surface-tension gradients), a texture frozen at the end of flow dries to `volume_solids` of its wet
//!   amplitude, so the cured PSD is S_cured(f) = v²·S_applied(f)·exp(−(32π⁴/3)·f⁴·L);
//! * a surface tension that varies along the surface drives a Marangoni flux h²∂γ/∂x/(2η) beside the capillary
//!   one (the lubrication equation, Oron, Davis & Bankoff 1997); with γ = γ₀ + γ'·(h − h̄) (Overdiep 1986: the
//!   solvent leaves crests and troughs at different fractions) a mode gains da/dt = +γ'h²k²/(2η)·a, so the
//!   transfer becomes exp(−(16π⁴/3)·f⁴·L + 4π²·f²·M), M = ∫₀ᵀ γ'h(t)²/(2η(t)) dt (the gradient integral).
use crate::optics::scatter::Psd;
use crate::quadrature::gauss_legendre;
use std::f64::consts::PI;

/// One point of the film's viscosity against time since application.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViscosityPoint {
    /// Time since application, s.
    pub t_s: f64,
    /// Viscosity of the wet film at that time, Pa·s.
    pub eta_pa_s: f64,
}

/// How a film was applied and how it dried: what a formulator controls.
#[derive(Clone, Debug, PartialEq)]
pub struct Application {
    /// Wet film thickness as applied, µm.
    pub wet_film_um: f64,
    /// Volume solids v in (0, 1]: dry thickness = v × wet thickness.
    pub volume_solids: f64,
    /// Surface tension of the wet film, mN/m.
    pub surface_tension_mn_m: f64,
    /// Flash-off time, s: the solvent leaves at a constant rate over it (the drying's constant-rate period),
    /// so the thickness falls linearly from wet to dry; after it the film has its dry thickness.
    pub flash_off_s: f64,
    /// The viscosity against time, from t = 0, times increasing, viscosities not decreasing; between points
    /// ln η is linear in t. The last point ends the flow (the gel point, or the end of the open time).
    pub viscosity: Vec<ViscosityPoint>,
    /// γ' = dγ/dh, mN/m per µm: how the surface tension of the wet film changes with the local thickness above
    /// the mean (Overdiep's surface-tension gradient); 0 without one. Positive works against levelling.
    pub surface_tension_gradient_mn_m_per_um: f64,
}

/// A field of an [`Application`] that is not allowed: its path relative to the application block (`wet_film_um`,
/// `viscosity/1/eta_pa_s`) and what is allowed.
#[derive(Clone, Debug, PartialEq)]
pub struct Invalid {
    pub field: String,
    pub message: String,
}

impl std::fmt::Display for Invalid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.field, self.message)
    }
}

fn invalid(field: impl Into<String>, message: impl Into<String>) -> Invalid {
    Invalid { field: field.into(), message: message.into() }
}

/// The largest growth of a mode's amplitude that the surface-tension gradient may give: the linear model holds
/// while the texture stays below a tenth of the film (within 1 % of the full equation, docs/model.md §Levelling
/// of the applied texture), so a texture that starts at a hundredth of it may grow tenfold at most.
pub(crate) const MAX_GROWTH: f64 = 10.0;

/// Gauss–Legendre points per sub-interval of the levelling integral. On a sub-interval the integrand is a
/// cubic in t times exp(−b t) with |b|·Δt ≤ 1 (`MAX_LOG_STEP`), which 16 points integrate to rounding.
const NODES: usize = 16;
/// The largest change of ln η across one sub-interval of the levelling integral.
const MAX_LOG_STEP: f64 = 1.0;
/// The most sub-intervals the levelling integral may use (a viscosity table spanning e^4096 in one step is
/// refused before it gets here; real tables use tens).
const MAX_PIECES: usize = 100_000;

impl Application {
    /// Check every field, naming it and what is allowed.
    pub fn validate(&self) -> Result<(), Invalid> {
        let positive = |name: &str, v: f64, unit: &str| -> Result<(), Invalid> {
            if !(v > 0.0) || !v.is_finite() {
                return Err(invalid(name, format!("must be a finite number > 0 {unit} (got {v})")));
            }
            Ok(())
        };
        positive("wet_film_um", self.wet_film_um, "µm")?;
        if !(self.wet_film_um <= 10_000.0) {
            return Err(invalid("wet_film_um", format!("at most 10 000 µm (got {})", self.wet_film_um)));
        }
        if !(self.volume_solids > 0.0 && self.volume_solids <= 1.0) {
            return Err(invalid("volume_solids", format!("must be in (0, 1] (got {})", self.volume_solids)));
        }
        positive("surface_tension_mn_m", self.surface_tension_mn_m, "mN/m")?;
        if !(self.flash_off_s >= 0.0) || !self.flash_off_s.is_finite() {
            return Err(invalid("flash_off_s", format!("must be a finite number ≥ 0 s (got {})", self.flash_off_s)));
        }
        if !self.surface_tension_gradient_mn_m_per_um.is_finite() {
            return Err(invalid(
                "surface_tension_gradient_mn_m_per_um",
                format!("must be a finite number (got {})", self.surface_tension_gradient_mn_m_per_um),
            ));
        }
        if self.viscosity.is_empty() {
            return Err(invalid("viscosity", "needs at least one point {t_s, eta_pa_s}"));
        }
        let mut log_span = 0.0;
        for (i, p) in self.viscosity.iter().enumerate() {
            positive(&format!("viscosity/{i}/eta_pa_s"), p.eta_pa_s, "Pa·s")?;
            if !(p.t_s >= 0.0) || !p.t_s.is_finite() {
                return Err(invalid(
                    format!("viscosity/{i}/t_s"),
                    format!("must be a finite number ≥ 0 s (got {})", p.t_s),
                ));
            }
            if i == 0 && p.t_s != 0.0 {
                return Err(invalid(
                    "viscosity/0/t_s",
                    format!("the table starts at application, t = 0 s (got {})", p.t_s),
                ));
            }
            if i > 0 {
                let q = self.viscosity[i - 1];
                if !(p.t_s > q.t_s) {
                    return Err(invalid(
                        format!("viscosity/{i}/t_s"),
                        format!("times must increase (got {} after {})", p.t_s, q.t_s),
                    ));
                }
                if p.eta_pa_s < q.eta_pa_s {
                    return Err(invalid(
                        format!("viscosity/{i}/eta_pa_s"),
                        format!(
                            "a drying film's viscosity does not fall (got {} after {} Pa·s)",
                            p.eta_pa_s, q.eta_pa_s
                        ),
                    ));
                }
                log_span += (p.eta_pa_s / q.eta_pa_s).ln();
            }
        }
        if log_span / MAX_LOG_STEP > MAX_PIECES as f64 / 2.0 {
            return Err(invalid(
                "viscosity",
                if log_span.is_finite() {
                    format!("rises by e^{log_span:.0}, beyond what the model resolves (e^50 000)")
                } else {
                    "rises by a factor beyond double precision, beyond what the model resolves (e^50 000)".to_string()
                },
            ));
        }
        let growth = self.largest_growth();
        if !(growth <= MAX_GROWTH) {
            // The growth exp(B²/4A) overflows past e^709, and is unbounded without levelling (A = 0): say so in
            // words, never print an infinity (docs/instrument.md §Numbers in text).
            let log = self.largest_log_growth();
            let by = if growth.is_finite() {
                format!("up to {}×", crate::error::number(growth))
            } else if log.is_finite() {
                format!("up to e^{log:.0}×")
            } else {
                "without bound (no levelling acts against it)".to_string()
            };
            let f = self.fastest_growing_frequency_per_um();
            let at = if f > 0.0 { format!(" (at Λ = {} µm)", crate::error::number(1.0 / f)) } else { String::new() };
            return Err(invalid(
                "surface_tension_gradient_mn_m_per_um",
                format!(
                    "the gradient grows the texture by {by}{at} before the flow ends, beyond the linear model \
                     (allowed: a growth of at most {MAX_GROWTH}×; a smaller gradient, or more levelling)"
                ),
            ));
        }
        Ok(())
    }

    /// Dry film thickness, µm: v × wet.
    pub(crate) fn dry_film_um(&self) -> f64 {
        self.volume_solids * self.wet_film_um
    }

    /// The time flow ends, s: the viscosity table's last time.
    pub(crate) fn end_of_flow_s(&self) -> f64 {
        self.viscosity.last().map_or(0.0, |p| p.t_s)
    }

    /// Film thickness at time t, µm: linear from wet to dry over the flash-off, dry after it.
    pub(crate) fn thickness_um(&self, t: f64) -> f64 {
        let dry = self.dry_film_um();
        if self.flash_off_s <= 0.0 || t >= self.flash_off_s {
            return dry;
        }
        self.wet_film_um + (dry - self.wet_film_um) * (t / self.flash_off_s).max(0.0)
    }

    /// Viscosity at time t, Pa·s: ln η linear between the table's points, its ends held beyond them.
    pub(crate) fn viscosity_pa_s(&self, t: f64) -> f64 {
        let v = &self.viscosity;
        if t <= v[0].t_s {
            return v[0].eta_pa_s;
        }
        for w in v.windows(2) {
            if t <= w[1].t_s {
                let s = (t - w[0].t_s) / (w[1].t_s - w[0].t_s);
                return (w[0].eta_pa_s.ln() * (1.0 - s) + w[1].eta_pa_s.ln() * s).exp();
            }
        }
        v[v.len() - 1].eta_pa_s
    }

    /// The levelling integral L = ∫₀ᵀ γ h³/η dt in µm⁴, T the end of flow. γ/η in (N/m)/(Pa·s) = m/s, times
    /// h³ in µm³ and dt in s, is 10⁶ µm⁴ per unit.
    pub fn levelling_integral_um4(&self) -> f64 {
        let gamma = self.surface_tension_mn_m * 1e-3;
        self.over_the_flow(|w, t| w * gamma * self.thickness_um(t).powi(3) / self.viscosity_pa_s(t)) * 1e6
    }

    /// The gradient integral M = ∫₀ᵀ γ' h²/(2η) dt in µm²: γ' in mN/m per µm is 10³ Pa, and Pa·µm²/(Pa·s) over
    /// dt in s is µm², so 10³ µm² per unit. 0 without a gradient.
    pub fn gradient_integral_um2(&self) -> f64 {
        let g = self.surface_tension_gradient_mn_m_per_um;
        if g == 0.0 {
            return 0.0;
        }
        self.over_the_flow(|w, t| w * g * self.thickness_um(t).powi(2) / (2.0 * self.viscosity_pa_s(t))) * 1e3
    }

    /// ∫₀ᵀ of an integrand given as `term(weight, t)` (the weight multiplied in first).
    ///
    /// The breakpoints (the table's times and the end of the flash-off) cut [0, T] into intervals on which h
    /// is linear and ln η linear; each is split so that ln η changes by at most `MAX_LOG_STEP` per piece, and
    /// each piece takes `NODES` Gauss–Legendre points.
    fn over_the_flow(&self, term: impl Fn(f64, f64) -> f64) -> f64 {
        let end = self.end_of_flow_s();
        let mut cuts: Vec<f64> = self.viscosity.iter().map(|p| p.t_s).collect();
        if self.flash_off_s > 0.0 && self.flash_off_s < end {
            cuts.push(self.flash_off_s);
        }
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let (x, w) = gauss_legendre(NODES);
        let mut sum = 0.0;
        for pair in cuts.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            let rise = (self.viscosity_pa_s(b) / self.viscosity_pa_s(a)).ln().abs();
            let pieces = ((rise / MAX_LOG_STEP).ceil() as usize).clamp(1, MAX_PIECES);
            let step = (b - a) / pieces as f64;
            for k in 0..pieces {
                let (lo, hi) = (a + k as f64 * step, a + (k + 1) as f64 * step);
                let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
                for (xi, wi) in x.iter().zip(&w) {
                    sum += term(wi * half, mid + half * xi);
                }
            }
        }
        sum
    }

    /// The flow's two integrals, L (µm⁴) and M (µm²).
    pub(crate) fn flow(&self) -> Flow {
        Flow { l_um4: self.levelling_integral_um4(), m_um2: self.gradient_integral_um2() }
    }

    /// The largest amplitude transfer over all frequencies: exp(B²/(4A)) with A = (16π⁴/3)L, B = 4π²M when
    /// the gradient works against levelling (M > 0), else 1 (at f → 0); infinite when nothing levels (L = 0).
    pub fn largest_growth(&self) -> f64 {
        self.largest_log_growth().exp()
    }

    /// The natural logarithm of [`Application::largest_growth`], B²/(4A) (finite where the growth overflows; 0
    /// without a gradient against levelling, infinite without levelling).
    pub(crate) fn largest_log_growth(&self) -> f64 {
        let flow = self.flow();
        if !(flow.m_um2 > 0.0) {
            return 0.0;
        }
        let (a, b) = (16.0 * PI.powi(4) / 3.0 * flow.l_um4, 4.0 * PI * PI * flow.m_um2);
        if !(a > 0.0) {
            return f64::INFINITY;
        }
        b * b / (4.0 * a)
    }

    /// The frequency of the largest growth, f² = B/(2A) (1/µm); 0 without a gradient against levelling.
    pub(crate) fn fastest_growing_frequency_per_um(&self) -> f64 {
        let flow = self.flow();
        let (a, b) = (16.0 * PI.powi(4) / 3.0 * flow.l_um4, 4.0 * PI * PI * flow.m_um2);
        if !(b > 0.0 && a > 0.0) {
            return 0.0;
        }
        (b / (2.0 * a)).sqrt()
    }

    /// The wet surface's amplitude transfer at spatial frequency f (1/µm): a(T)/a(0) = exp(−(16π⁴/3) f⁴ L +
    /// 4π² f² M).
    pub fn amplitude_transfer(&self, f_per_um: f64) -> f64 {
        self.flow().amplitude_transfer(f_per_um)
    }

    /// The frequency (1/µm) whose amplitude the levelling takes down by 1/e: f_e = (3/(16π⁴ L))^{1/4}.
    #[cfg(test)]
    pub(crate) fn levelled_frequency_per_um(&self) -> f64 {
        levelled_frequency(self.levelling_integral_um4())
    }
}

/// The two integrals of a film's flow: L = ∫γh³/η dt (µm⁴), which levels, and M = ∫γ'h²/(2η) dt (µm²), the
/// surface-tension gradient's, which works against levelling when positive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flow {
    pub l_um4: f64,
    pub m_um2: f64,
}

impl Flow {
    /// The amplitude left of a mode of spatial frequency f (1/µm): exp(−(16π⁴/3) f⁴ L + 4π² f² M).
    pub(crate) fn amplitude_transfer(&self, f_per_um: f64) -> f64 {
        (-(16.0 * PI.powi(4) / 3.0) * f_per_um.powi(4) * self.l_um4 + 4.0 * PI * PI * f_per_um.powi(2) * self.m_um2)
            .exp()
    }
}

/// (3/(16π⁴ L))^{1/4}: the spatial frequency (1/µm) levelled to 1/e of its amplitude by L (µm⁴); infinite
/// for L = 0.
pub(crate) fn levelled_frequency(l_um4: f64) -> f64 {
    (3.0 / (16.0 * PI.powi(4) * l_um4)).powf(0.25)
}

/// The cured PSD's factor at spatial frequency f (1/µm): v²·exp(2·(−(16π⁴/3) f⁴ L + 4π² f² M)), for a PSD of
/// the applied texture's heights (docs/model.md §Levelling of the applied texture).
pub(crate) fn psd_transfer(volume_solids: f64, flow: Flow, f_per_um: f64) -> f64 {
    volume_solids * volume_solids * flow.amplitude_transfer(f_per_um).powi(2)
}

/// Gauss–Legendre points per piece of a cured PSD's radial moments (the integrand, smooth in ln f, is
/// integrated over pieces of ln f no wider than [`LEVELLED_STEP`]).
const LEVELLED_NODES: usize = 16;
/// The width in ln f of one piece of a cured PSD's moment table.
const LEVELLED_STEP: f64 = 0.125;
/// The PSD factor exp(−x) below which the cured spectrum is taken as zero: exp(−745) is below the smallest
/// subnormal double.
const LEVELLED_UNDERFLOW: f64 = 745.0;

/// A surface texture's PSD as applied ([`Psd::KCorrelation`] or [`Psd::Gaussian`]) after the film's levelling
/// (docs/model.md §Levelling of the applied texture): S_c(f) = v²·S_a(f)·exp(2·(−(16π⁴/3)·f⁴·L + 4π²·f²·M)).
/// Its radial moments M_j(ρ) = ∫₀^ρ (2πf)^j S_c(f) f df (j = 0: heights, j = 2: slopes) over the whole cured
/// spectrum are tabulated at construction, on knots a [`LEVELLED_STEP`] apart in ln f, by Gauss–Legendre
/// quadrature in ln f; between knots a moment adds one more such piece.
#[derive(Clone, Debug, PartialEq)]
pub struct CuredPsd {
    /// The texture as applied (a K-correlation or Gaussian PSD).
    pub applied: Psd,
    /// Volume solids v: the dry film keeps v of the wet texture's amplitude.
    pub volume_solids: f64,
    /// The flow's integrals L (µm⁴) and M (µm²).
    pub flow: Flow,
    f_min: f64,
    f_max: f64,
    knots: Vec<f64>,
    m0: Vec<f64>,
    m2: Vec<f64>,
}

impl CuredPsd {
    /// The cured PSD of `applied` after a flow `flow` at volume solids `v`.
    pub fn new(applied: Psd, v: f64, flow: Flow) -> CuredPsd {
        let l_um4 = flow.l_um4;
        let f_e = if l_um4 > 0.0 { levelled_frequency(l_um4) } else { f64::INFINITY };
        let knee = applied.knee();
        let f_min = 1e-6 * knee.min(f_e);
        // Beyond f_max the factor exp(−(32π⁴/3) f⁴ L) underflows; without levelling the table stops 10⁸ knees
        // out and the height moment adds the applied PSD's closed-form tail.
        let f_max =
            if l_um4 > 0.0 { (LEVELLED_UNDERFLOW / (32.0 * PI.powi(4) / 3.0 * l_um4)).powf(0.25) } else { 1e8 * knee }
                .max(2.0 * f_min);
        let span = (f_max / f_min).ln();
        let n = ((span / LEVELLED_STEP).ceil() as usize).clamp(1, 4000);
        let step = span / n as f64;
        let mut l = CuredPsd {
            applied,
            volume_solids: v,
            flow,
            f_min,
            f_max,
            knots: Vec::with_capacity(n + 1),
            m0: Vec::with_capacity(n + 1),
            m2: Vec::with_capacity(n + 1),
        };
        let s0 = l.cured(0.0);
        let (mut a0, mut a2) = (s0 * f_min * f_min / 2.0, 4.0 * PI * PI * s0 * f_min.powi(4) / 4.0);
        let mut prev = f_min;
        for i in 0..=n {
            let f = if i == n { f_max } else { f_min * (i as f64 * step).exp() };
            if i > 0 {
                a0 += l.piece(0, prev, f);
                a2 += l.piece(2, prev, f);
            }
            l.knots.push(f);
            l.m0.push(a0);
            l.m2.push(a2);
            prev = f;
        }
        l
    }

    /// S_c(f), nm²·µm², over the whole spectrum (no band limit).
    pub(crate) fn cured(&self, f: f64) -> f64 {
        psd_transfer(self.volume_solids, self.flow, f) * self.applied.s2(f)
    }

    /// ∫ over [a, b] of (2πf)^j S_c(f) f df by one Gauss–Legendre piece in ln f.
    fn piece(&self, j: i32, a: f64, b: f64) -> f64 {
        if !(b > a) {
            return 0.0;
        }
        let (x, w) = gauss_legendre(LEVELLED_NODES);
        let (ua, ub) = (a.ln(), b.ln());
        let (mid, half) = (0.5 * (ua + ub), 0.5 * (ub - ua));
        let mut sum = 0.0;
        for (xi, wi) in x.iter().zip(&w) {
            let f = (mid + half * xi).exp();
            sum += wi * (2.0 * PI * f).powi(j) * self.cured(f) * f * f;
        }
        sum * half
    }

    /// M_j(ρ) = ∫₀^ρ (2πf)^j S_c(f) f df over the whole cured spectrum, j = 0 (nm²) or 2 (nm²/µm²). For ρ
    /// beyond the table without levelling, M_0 adds the applied PSD's closed-form tail; M_2 is only asked
    /// below the table's end.
    pub(crate) fn moment(&self, j: i32, rho: f64) -> f64 {
        let s0 = self.cured(0.0);
        if rho <= self.f_min {
            return match j {
                0 => s0 * rho * rho / 2.0,
                _ => 4.0 * PI * PI * s0 * rho.powi(4) / 4.0,
            };
        }
        let tab = if j == 0 { &self.m0 } else { &self.m2 };
        let last = self.knots.len() - 1;
        if rho >= self.f_max {
            let tail = if j == 0 && self.flow.l_um4 == 0.0 {
                let v2 = self.volume_solids * self.volume_solids;
                v2 * (self.applied.radial_cumulative(rho) - self.applied.radial_cumulative(self.f_max)).max(0.0)
            } else {
                0.0
            };
            return tab[last] + tail;
        }
        let i = self.knots.partition_point(|&k| k <= rho).saturating_sub(1).min(last);
        tab[i] + self.piece(j, self.knots[i], rho)
    }

    /// The mean-square height (nm²) of the band [a, b] of the cured spectrum: 2π(M_0(b) − M_0(a)).
    pub fn band_ms(&self, a: f64, b: f64) -> f64 {
        (2.0 * PI * (self.moment(0, b) - self.moment(0, a))).max(0.0)
    }

    /// The mean-square slope ⟨|∇h|²⟩ = Sdq² of the whole cured spectrum, ∫∫ (2π|f|)² S_c d²f = 2π·M_2(∞), in
    /// nm²/µm² (10⁻⁶ rad²). Without levelling (L = 0) the table ends 10⁸ knees out, where a K-correlation
    /// texture with C ≤ 3, whose slopes diverge, has grown past any facet model.
    pub fn slope_ms(&self) -> f64 {
        2.0 * PI * self.moment(2, self.f_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn film(viscosity: Vec<(f64, f64)>, flash: f64) -> Application {
        Application {
            wet_film_um: 60.0,
            volume_solids: 0.5,
            surface_tension_mn_m: 30.0,
            flash_off_s: flash,
            viscosity: viscosity.into_iter().map(|(t_s, eta_pa_s)| ViscosityPoint { t_s, eta_pa_s }).collect(),
            surface_tension_gradient_mn_m_per_um: 0.0,
        }
    }

    #[test]
    fn constant_viscosity_and_thickness_give_orchards_exponential() {
        // v = 1: no thinning; η constant: L = γ h³ T/η exactly, and a(T)/a(0) = exp(−rT), r = 16π⁴γh³/(3ηΛ⁴).
        let mut a = film(vec![(0.0, 0.5), (120.0, 0.5)], 0.0);
        a.volume_solids = 1.0;
        let l = a.levelling_integral_um4();
        let exact = 30e-3 * 60f64.powi(3) * 120.0 / 0.5 * 1e6;
        assert!((l / exact - 1.0).abs() < 1e-14, "{l} vs {exact}");
        let lambda_um = 5000.0; // r·T ≈ 1.3
        let rate = 16.0 * PI.powi(4) * 30e-3 * (60e-6f64).powi(3) / (3.0 * 0.5 * (lambda_um * 1e-6f64).powi(4));
        let got = a.amplitude_transfer(1.0 / lambda_um);
        assert!((got / (-rate * 120.0).exp() - 1.0).abs() < 1e-12, "{got} vs {}", (-rate * 120.0).exp());
    }

    #[test]
    fn exponential_viscosity_rise_integrates_in_closed_form() {
        // η = η0·e^{t/τ} from 0 to T at constant h (v = 1): L = γh³τ(1 − e^{−T/τ})/η0 — the table's log-linear
        // interpolation is exact for this η, over a rise of e^12 in one interval.
        let (eta0, tau, t_end) = (0.2, 30.0, 360.0);
        let mut a = film(vec![(0.0, eta0), (t_end, eta0 * (t_end / tau).exp())], 0.0);
        a.volume_solids = 1.0;
        let exact = 30e-3 * 60f64.powi(3) * tau * (1.0 - (-t_end / tau).exp()) / eta0 * 1e6;
        let l = a.levelling_integral_um4();
        assert!((l / exact - 1.0).abs() < 1e-13, "{l} vs {exact}");
    }

    #[test]
    fn linear_thinning_integrates_the_cube_exactly() {
        // η constant, h from 60 to 30 µm linearly over the flash-off F, then 30 µm to T:
        // L = γ/η·[F·(h0⁴ − h1⁴)/(4(h0 − h1)) + h1³(T − F)].
        let a = film(vec![(0.0, 1.0), (300.0, 1.0)], 100.0);
        let (h0, h1, f, t) = (60.0f64, 30.0f64, 100.0, 300.0);
        let exact = 30e-3 / 1.0 * (f * (h0.powi(4) - h1.powi(4)) / (4.0 * (h0 - h1)) + h1.powi(3) * (t - f)) * 1e6;
        let l = a.levelling_integral_um4();
        assert!((l / exact - 1.0).abs() < 1e-13, "{l} vs {exact}");
    }

    #[test]
    fn the_transfer_falls_with_frequency_and_rises_with_thickness() {
        let thin = film(vec![(0.0, 0.3), (60.0, 3.0), (600.0, 300.0)], 60.0);
        let mut thick = thin.clone();
        thick.wet_film_um = 90.0;
        let mut prev = 1.0;
        for f in [1e-4, 1e-3, 2e-3, 5e-3, 1e-2] {
            let t = thin.amplitude_transfer(f);
            assert!(t < prev && t > 0.0 || t == 0.0, "f = {f}: {t} after {prev}");
            assert!(thick.amplitude_transfer(f) <= t, "a thicker film levels more at f = {f}");
            prev = t;
        }
        let fe = thin.levelled_frequency_per_um();
        assert!((thin.amplitude_transfer(fe) - (-1f64).exp()).abs() < 1e-12);
    }

    #[test]
    fn cured_k_correlation_keeps_v_squared_sigma_squared_without_levelling() {
        // L = 0: the cured PSD is v²·S_a, whose σ² is v²σ_a² (the table plus the closed-form tail); levelling
        // takes heights and more of the slopes.
        let applied = Psd::k_correlation(800.0, 150.0, 2.5);
        let bare = CuredPsd::new(applied, 0.4, Flow { l_um4: 0.0, m_um2: 0.0 });
        let ms = bare.band_ms(0.0, f64::INFINITY);
        assert!((ms / (0.4f64 * 800.0).powi(2) - 1.0).abs() < 1e-9, "{ms}");
        let levelled = CuredPsd::new(applied, 0.4, Flow { l_um4: 1e9, m_um2: 0.0 });
        assert!(levelled.band_ms(0.0, f64::INFINITY) < ms);
        assert!(levelled.slope_ms() < bare.slope_ms() && levelled.slope_ms() > 0.0);
    }

    #[test]
    fn bad_applications_name_the_field() {
        let good = film(vec![(0.0, 0.3), (60.0, 3.0)], 30.0);
        assert!(good.validate().is_ok());
        let mut a = good.clone();
        a.wet_film_um = -1.0;
        assert!(a.validate().unwrap_err().field == "wet_film_um");
        let mut a = good.clone();
        a.volume_solids = 0.0;
        assert!(a.validate().unwrap_err().field == "volume_solids");
        let mut a = good.clone();
        a.surface_tension_mn_m = f64::NAN;
        assert!(a.validate().unwrap_err().field == "surface_tension_mn_m");
        let mut a = good.clone();
        a.viscosity[1].eta_pa_s = 0.1;
        assert!(a.validate().unwrap_err().field == "viscosity/1/eta_pa_s", "{:?}", a.validate());
        let mut a = good.clone();
        a.viscosity[1].t_s = 0.0;
        assert!(a.validate().unwrap_err().field == "viscosity/1/t_s");
        let mut a = good.clone();
        a.viscosity[0].t_s = 5.0;
        assert!(a.validate().unwrap_err().field == "viscosity/0/t_s");
        let mut a = good;
        a.surface_tension_gradient_mn_m_per_um = 1e6;
        assert_eq!(a.validate().unwrap_err().field, "surface_tension_gradient_mn_m_per_um");
    }

    /// Found by the 10⁶-case fuzz run of 2026-12-06 (case 476713): a growth past e^709 printed "inf×".
    #[test]
    fn a_growth_beyond_double_precision_is_said_in_words() {
        let mut overflowed = 0;
        for g in [900.0, 4000.0, 1e5, 1e6, 1e8] {
            let mut a = film(vec![(0.0, 0.5), (600.0, 0.5)], 0.0);
            a.surface_tension_gradient_mn_m_per_um = g;
            let Err(e) = a.validate() else { continue };
            let m = e.message.to_string();
            assert!(!m.contains("inf") && !m.contains("NaN"), "{g}: {m}");
            if !a.largest_growth().is_finite() && a.largest_log_growth().is_finite() {
                overflowed += 1;
                assert!(m.contains("grows the texture by up to e^"), "{g}: {m}");
            }
        }
        assert!(overflowed > 0, "no gradient overflowed the growth");
        // Case 698493: a viscosity rising from 1e-300 to 1e300 Pa·s within one step (its ratio overflows).
        let e = film(vec![(0.0, 1e-300), (1.0, 1e300)], 0.0).validate().unwrap_err();
        assert!(e.field == "viscosity" && e.message.contains("beyond double precision"), "{e:?}");
        assert!(!e.message.contains("inf"), "{e:?}");
    }

    #[test]
    fn a_gradient_at_constant_viscosity_and_thickness_adds_its_closed_form() {
        // v = 1, η and h constant over T: M = γ'h²T/(2η) exactly, and a mode's rate is
        // −γh³k⁴/(3η) + γ'h²k²/(2η) (SI: γ' in N/m per m).
        let mut a = film(vec![(0.0, 0.5), (120.0, 0.5)], 0.0);
        a.volume_solids = 1.0;
        a.surface_tension_gradient_mn_m_per_um = 0.02;
        let m = a.gradient_integral_um2();
        let exact = 0.02 * 60f64.powi(2) * 120.0 / (2.0 * 0.5) * 1e3;
        assert!((m / exact - 1.0).abs() < 1e-14, "{m} vs {exact}");
        let (h, eta, gamma, g) = (60e-6f64, 0.5, 30e-3, 0.02 * 1e3);
        for lambda_um in [2000.0f64, 5000.0, 20000.0] {
            let k = 2.0 * PI / (lambda_um * 1e-6);
            let rate = -gamma * h.powi(3) * k.powi(4) / (3.0 * eta) + g * h * h * k * k / (2.0 * eta);
            let got = a.amplitude_transfer(1.0 / lambda_um);
            assert!((got / (rate * 120.0).exp() - 1.0).abs() < 1e-12, "Λ {lambda_um}: {got}");
        }
        // The largest growth is exp(B²/4A) at f² = B/2A.
        let f = a.fastest_growing_frequency_per_um();
        let top = a.amplitude_transfer(f);
        assert!((top / a.largest_growth() - 1.0).abs() < 1e-12);
        for x in [0.9, 1.1] {
            assert!(a.amplitude_transfer(f * x) < top);
        }
        // A gradient of the other sign levels faster at every frequency.
        let mut b = a.clone();
        b.surface_tension_gradient_mn_m_per_um = -0.02;
        let mut plain = a.clone();
        plain.surface_tension_gradient_mn_m_per_um = 0.0;
        for f in [1e-4, 2e-4, 5e-4] {
            assert!(plain.amplitude_transfer(f) > 1e-300, "f {f} underflows");
            assert!(b.amplitude_transfer(f) < plain.amplitude_transfer(f));
            assert!(a.amplitude_transfer(f) > plain.amplitude_transfer(f));
        }
        assert_eq!(plain.largest_growth(), 1.0);
    }
}
