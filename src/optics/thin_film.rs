//! Thin-film interference in a layer stack.
//!
//! Sources: Born & Wolf, *Principles of Optics*, §1.6.4 (Airy summation for a film); Hirayama et al.,
//! "Visualization of optical phenomena caused by multilayer films based on wave optics", *The Visual
//! Computer* 17 (2001) 106 (the recursion from the last interface upward that the paper's Eq. 6 copies);
//! Byrnes, "Multilayer optical calculations", arXiv:1603.02720 (conventions for s/p amplitudes, complex
//! angles, the power formulas T = Re(n_f cos θf)/Re(n_i cos θi)|t|² for s and
//! Re(n_f cos θf*)/Re(n_i cos θi*)|t|² for p, §3 for incoherent layers); Katsidis & Siapkas, *Appl. Opt.* 41
//! (2002) 3978 (incoherent combination of coherent sub-stacks with power coefficients).
//!
//! Paper corrections (Ďurikovič & Ágošton 2007, Eq. 6–7; see `docs/optics.md`): the phase is
//! φⱼ = (2π dⱼ/λ)·√(ηⱼ² − η_{j−1}² sin²θ_{j−1}) (printed with 1π and with sin² outside the root); the
//! powers are |ρ|², |τ|² (printed as squares of complex amplitudes); the transmittance factor is
//! η_out cos θout/(η_in cos θin) (printed inverted); the mica platelet, which the paper's text calls too
//! thick to interfere, is handled incoherently here (`coherent == false`) while the printed recursion runs
//! coherently through it.
use crate::optics::fresnel::{amplitudes, critical_cosine_complex, ncos_from_real, ncos_near_critical};
use crate::optics::tabulated::KinkOffset;
use num_complex::Complex64;

/// One layer of a stack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilmLayer {
    /// Complex refractive index n + ik (k ≥ 0).
    pub n: Complex64,
    /// Physical thickness in nm (≥ 0).
    pub thickness_nm: f64,
    /// False for a layer too thick to interfere (e.g. the mica platelet): treated incoherently.
    pub coherent: bool,
}

/// Power reflectance and transmittance of a stack, s and p (transmittance into the exit medium, with the
/// n cos θ factor).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StackResult {
    pub rs: f64,
    pub rp: f64,
    pub ts: f64,
    pub tp: f64,
}

impl StackResult {
    pub fn r(&self) -> f64 {
        0.5 * (self.rs + self.rp)
    }
    pub fn t(&self) -> f64 {
        0.5 * (self.ts + self.tp)
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Pol {
    S,
    P,
}

/// A homogeneous medium as seen by the plane wave: index, cos θ and n cos θ (forward/decaying branch).
#[derive(Clone, Copy)]
struct Medium {
    n: Complex64,
    cos: Complex64,
    /// Thickness in nm (0 for the semi-infinite media).
    d: f64,
}

impl Medium {
    const VACUUM: Medium = Medium { n: Complex64::new(1.0, 0.0), cos: Complex64::new(1.0, 0.0), d: 0.0 };

    fn ncos(&self) -> Complex64 {
        self.n * self.cos
    }
    /// Power-flux factor of Byrnes (arXiv:1603.02720 Eqs. 13–14): Re(n cos θ) for s, Re(n cos θ*) for p.
    fn flux(&self, pol: Pol) -> f64 {
        match pol {
            Pol::S => (self.n * self.cos).re,
            Pol::P => (self.n * self.cos.conj()).re,
        }
    }
    /// e^{iφ} with φ = (2π d/λ)·n cos θ = (2π d/λ)√(n² − n₀² sin²θ₀); Im φ ≥ 0, so |e^{iφ}| ≤ 1 (only
    /// decaying exponentials are ever formed: no overflow for thick absorbing layers).
    fn phase(&self, wavelength_nm: f64) -> Complex64 {
        let phi = self.ncos() * (2.0 * std::f64::consts::PI * self.d / wavelength_nm);
        (Complex64::i() * phi).exp()
    }
}

/// The amplitudes [(r_s, t_s), (r_p, t_p)] of one interface ([`amplitudes`]).
type Interface = [(Complex64, Complex64); 2];

fn interface(x: &Medium, y: &Medium) -> Interface {
    let c = amplitudes(x.n, x.cos, y.n, y.cos);
    [(c.rs, c.ts), (c.rp, c.tp)]
}

/// Amplitudes r, t (s and p together) of a coherent group of layers between two semi-infinite media, light
/// incident from the first: the Airy recursion from the last interface upward (Hirayama et al. 2001; paper
/// Eq. 6 corrected): ρ ← r_{N,N+1}, τ ← t_{N,N+1}; for j = N..1 with interface (j−1 → j) coefficients r, t
/// and layer phase φⱼ: ρ ← (r + ρ e^{2iφⱼ})/(1 + r ρ e^{2iφⱼ}), τ ← t τ e^{iφⱼ}/(1 + r ρ e^{2iφⱼ}).
///
/// The group is media[a..=b] (or the same media in reverse order, light coming from below), with `phase[j]`
/// = e^{iφⱼ} precomputed per medium and the interface amplitudes precomputed per pair of neighbours
/// (`down[m]`: from medium m into m + 1, `up[m]`: from m + 1 into m; they do not depend on the wavelength);
/// nothing is allocated (this runs inside the BRDF evaluation). Returns [(ρs, τs), (ρp, τp)].
fn coherent_amplitudes(
    down: &[Interface],
    up: &[Interface],
    phase: &[Complex64],
    (a, b): (usize, usize),
    reversed: bool,
) -> [(Complex64, Complex64); 2] {
    let at = |j: usize| if reversed { b - j } else { a + j };
    // The interface from medium at(j − 1) into at(j).
    let iface = |j: usize| if reversed { up[b - j] } else { down[a + j - 1] };
    let last = b - a;
    let mut acc = iface(last);
    for j in (1..last).rev() {
        let e1 = phase[at(j)];
        let e2 = e1 * e1;
        let rt = iface(j);
        for ((rho, tau), (r, t)) in acc.iter_mut().zip(rt) {
            let den = 1.0 + r * *rho * e2;
            *rho = (r + *rho * e2) / den;
            *tau = t * *tau * e1 / den;
        }
    }
    acc
}

/// Power R, T of a coherent group (its first and last media semi-infinite), Byrnes Eqs. 13–15:
/// [(Rs, Ts), (Rp, Tp)].
fn coherent_power(
    media: &[Medium],
    (down, up): (&[Interface], &[Interface]),
    phase: &[Complex64],
    (a, b): (usize, usize),
    reversed: bool,
) -> [(f64, f64); 2] {
    let amp = coherent_amplitudes(down, up, phase, (a, b), reversed);
    let (first, last) = if reversed { (b, a) } else { (a, b) };
    let mut out = [(0.0, 0.0); 2];
    for ((o, (r, t)), pol) in out.iter_mut().zip(amp).zip([Pol::S, Pol::P]) {
        let top = media[first].flux(pol);
        let bottom = media[last].flux(pol);
        let tt = if top > 0.0 { t.norm_sqr() * bottom / top } else { 0.0 };
        *o = (r.norm_sqr(), tt.max(0.0));
    }
    out
}

/// Stacks of up to this many media (layers + 2) are evaluated without touching the heap.
const INLINE_MEDIA: usize = 26;

/// Reflectance and transmittance of `layers` between a real incident medium `n_in` (light arrives at
/// cos θ = `cos_i`) and an exit medium `n_out` (complex allowed), at `wavelength_nm`.
///
/// Angles: the tangential invariant n_in sin θ_in is real; in each medium n cos θ = √(n² − n_in² sin²θ_in)
/// on the decaying/forward branch, computed without cancellation (`medium_cos`: a medium of the ambient
/// index has cos θ_in itself, the others √((n − n_in)(n + n_in) + (n_in cos θ_in)²)).
/// Coherent layers: [`coherent_amplitudes`] per polarisation (convention of
/// [`crate::optics::fresnel::amplitudes`]), R = |ρ|², T = |τ|² Re(n_out cos θout)/(n_in cos θin) for s and
/// |τ|² Re(n_out cos θout*)/(n_in cos θin) for p (Byrnes Eqs. 13–14). For an absorbing exit medium this is
/// the power crossing the exit interface (it is then absorbed in the exit medium); R + T = 1 still holds for
/// a single interface.
/// Incoherent layers (`coherent == false`) split the stack into coherent groups between "incoherent media";
/// each group gives power coefficients (Rf, Tf) from above and (Rb, Tb) from below, and the groups are
/// combined from the exit upward with the one-pass power transmission of the incoherent layer
/// P = |e^{iφ}|² = exp(−4π d Im(n cos θ)/λ) (≈ exp(−4π k d/(λ cos θ)) for weak absorption, Byrnes §3,
/// Katsidis & Siapkas 2002): R = Rf + Tf Tb P² R′/(1 − Rb P² R′), T = Tf P T′/(1 − Rb P² R′), where R′, T′
/// describe everything below the incoherent layer. This matches `tmm.inc_tmm`.
/// Grazing incidence (cos_i ≤ 0) returns the limit R = 1, T = 0.
pub fn stack(n_in: f64, layers: &[FilmLayer], n_out: Complex64, cos_i: f64, wavelength_nm: f64) -> StackResult {
    let mut out = StackResult { rs: 1.0, rp: 1.0, ts: 0.0, tp: 0.0 };
    stack_spectrum(n_in, layers, n_out, cos_i, None, [wavelength_nm], |_, r| out = r);
    out
}

/// cos θ in a medium of index `n` of a stack entered from the real index `n_in` at cos θ_in = `mu`
/// (`docs/model.md` §Evaluation cost, "Where the direct evaluation is the noise"): `mu` itself when `n` is
/// `n_in` to the bit (the pearl's exit resin: recomputed as √(n² − n²(1 − μ²))/n it lost digits like
/// 10⁻¹⁶/μ² as μ → 0); on a table segment at a kink (`near`) and `n` real with its critical cosine at that
/// kink to the bit, from the offset μ − μc ([`ncos_near_critical`]); else from the cancellation-free
/// [`ncos_from_real`]. Each is n cos θ/n on the forward/decaying branch.
fn medium_cos(n_in: f64, mu: f64, n: Complex64, near: Option<KinkOffset>) -> Complex64 {
    if n.re == n_in && n.im == 0.0 {
        return Complex64::new(mu, 0.0);
    }
    let ncos = match near {
        Some(k) if n.im == 0.0 && critical_cosine_complex(n / n_in) == Some(k.at) => {
            ncos_near_critical(n_in, k.at, k.offset)
        }
        _ => ncos_from_real(n_in, mu, n),
    };
    ncos / n
}

/// [`stack`] at one angle of incidence and several wavelengths: `each(i, result)` for the i-th wavelength, the
/// same bits as `stack(n_in, layers, n_out, cos_i, wavelength)` when `near` is None. `near`: `cos_i` is on a
/// table segment at a critical cosine μc of one of the layers, with `cos_i` − μc exactly as the table has it
/// (`optics::tabulated::Abscissa`); that layer's cosine is then computed from it ([`medium_cos`]). What does
/// not depend on the wavelength (every medium's cos θ, every interface's amplitudes r, t) is computed once for
/// all of them; per wavelength only
/// the layers' phases e^{iφⱼ} (once per distinct layer: a stack that repeats a layer, as the pearl's
/// TiO₂/mica/TiO₂ does, computes its phase once) and the recursions remain (`docs/model.md` §Evaluation cost).
pub(crate) fn stack_spectrum(
    n_in: f64,
    layers: &[FilmLayer],
    n_out: Complex64,
    cos_i: f64,
    near: Option<KinkOffset>,
    wavelengths_nm: impl IntoIterator<Item = f64>,
    mut each: impl FnMut(usize, StackResult),
) {
    if cos_i <= 0.0 {
        for (i, _) in wavelengths_nm.into_iter().enumerate() {
            each(i, StackResult { rs: 1.0, rp: 1.0, ts: 0.0, tp: 0.0 });
        }
        return;
    }
    let total = layers.len() + 2;
    let none = [(Complex64::new(0.0, 0.0), Complex64::new(0.0, 0.0)); 2];
    if total > INLINE_MEDIA {
        let mut s = Scratch {
            media: &mut vec![Medium::VACUUM; total],
            phase: &mut vec![Complex64::new(1.0, 0.0); total],
            inc: &mut vec![0usize; total],
            same: &mut vec![0usize; total],
            down: &mut vec![none; total],
            up: &mut vec![none; total],
        };
        return stack_in(n_in, layers, n_out, (cos_i, near), wavelengths_nm, &mut each, &mut s);
    }
    let mut media = [Medium::VACUUM; INLINE_MEDIA];
    let mut phase = [Complex64::new(1.0, 0.0); INLINE_MEDIA];
    let mut inc = [0usize; INLINE_MEDIA];
    let mut same = [0usize; INLINE_MEDIA];
    let mut down = [none; INLINE_MEDIA];
    let mut up = [none; INLINE_MEDIA];
    let mut s =
        Scratch { media: &mut media, phase: &mut phase, inc: &mut inc, same: &mut same, down: &mut down, up: &mut up };
    stack_in(n_in, layers, n_out, (cos_i, near), wavelengths_nm, &mut each, &mut s)
}

/// Caller-provided scratch of at least `layers.len() + 2` entries each.
struct Scratch<'s> {
    media: &'s mut [Medium],
    phase: &'s mut [Complex64],
    /// The incoherent media, top to bottom.
    inc: &'s mut [usize],
    /// `same[j]`: the first medium with layer j's index and thickness (its cos θ and phase are j's).
    same: &'s mut [usize],
    down: &'s mut [Interface],
    up: &'s mut [Interface],
}

/// [`stack_spectrum`] on caller-provided scratch.
fn stack_in(
    n_in: f64,
    layers: &[FilmLayer],
    n_out: Complex64,
    (cos_i, near): (f64, Option<KinkOffset>),
    wavelengths_nm: impl IntoIterator<Item = f64>,
    each: &mut impl FnMut(usize, StackResult),
    s: &mut Scratch,
) {
    let cos_i = cos_i.min(1.0);
    let n0 = Complex64::new(n_in, 0.0);
    let c0 = Complex64::new(cos_i, 0.0);
    let total = layers.len() + 2;
    let key = |l: &FilmLayer| [l.n.re.to_bits(), l.n.im.to_bits(), l.thickness_nm.max(0.0).to_bits()];
    // All media top to bottom: ambient, the layers, the exit medium (a layer equal to one above it, to the
    // bit, takes that one's cos θ).
    s.media[0] = Medium { n: n0, cos: c0, d: 0.0 };
    s.same[0] = 0;
    for (j, l) in layers.iter().enumerate() {
        let first = layers[..j].iter().position(|m| key(m) == key(l)).unwrap_or(j);
        s.same[j + 1] = first + 1;
        let cos = if first < j { s.media[first + 1].cos } else { medium_cos(n_in, cos_i, l.n, near) };
        s.media[j + 1] = Medium { n: l.n, cos, d: l.thickness_nm.max(0.0) };
    }
    s.same[total - 1] = total - 1;
    s.media[total - 1] = Medium { n: n_out, cos: medium_cos(n_in, cos_i, n_out, near), d: 0.0 };
    // The incoherent media (ambient, incoherent layers, exit) split the stack into coherent groups: group
    // i is media[inc[i]..=inc[i+1]], whose end media are treated as semi-infinite.
    let mut n_inc = 0;
    s.inc[n_inc] = 0;
    n_inc += 1;
    for (j, l) in layers.iter().enumerate() {
        if !l.coherent {
            s.inc[n_inc] = j + 1;
            n_inc += 1;
        }
    }
    s.inc[n_inc] = total - 1;
    n_inc += 1;
    let groups = n_inc - 1;
    let k = groups - 1;
    let inc = &s.inc[..n_inc];
    let media = &s.media[..total];
    // The interfaces: every one downward, and upward those above the last group (only those groups are
    // also crossed from below).
    for m in 0..total - 1 {
        s.down[m] = interface(&media[m], &media[m + 1]);
    }
    for m in 0..inc[k] {
        s.up[m] = interface(&media[m + 1], &media[m]);
    }
    let (down, up) = (&s.down[..total - 1], &s.up[..total - 1]);
    let phase = &mut s.phase[..total];
    for (i, wavelength_nm) in wavelengths_nm.into_iter().enumerate() {
        // The phases of the layers (the semi-infinite ambient and exit media have none that is used).
        for j in 1..total - 1 {
            phase[j] = if s.same[j] < j { phase[s.same[j]] } else { media[j].phase(wavelength_nm) };
        }
        let phase = &*phase;
        let mut below = coherent_power(media, (down, up), phase, (inc[k], inc[k + 1]), false);
        for g in (0..k).rev() {
            let group = (inc[g], inc[g + 1]);
            let front = coherent_power(media, (down, up), phase, group, false);
            let back = if front.iter().any(|(_, tf)| *tf != 0.0) {
                coherent_power(media, (down, up), phase, group, true)
            } else {
                front
            };
            let p = phase[inc[g + 1]].norm_sqr();
            for ((b, (rf, tf)), (rb, tb)) in below.iter_mut().zip(front).zip(back) {
                if tf == 0.0 {
                    *b = (rf, 0.0);
                    continue;
                }
                let (r_below, t_below) = *b;
                let den = 1.0 - rb * p * p * r_below;
                *b = (rf + tf * tb * p * p * r_below / den, tf * p * t_below / den);
            }
        }
        each(i, StackResult { rs: below[0].0, rp: below[1].0, ts: below[0].1, tp: below[1].1 });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::fresnel::{fresnel_conductor, fresnel_dielectric};

    fn c(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }
    fn coh(n: Complex64, d: f64) -> FilmLayer {
        FilmLayer { n, thickness_nm: d, coherent: true }
    }
    fn inc(n: Complex64, d: f64) -> FilmLayer {
        FilmLayer { n, thickness_nm: d, coherent: false }
    }
    fn angles() -> impl Iterator<Item = f64> {
        [0.0, 20.0, 45.0, 60.0, 75.0, 85.0].into_iter().map(|d: f64| d.to_radians().cos())
    }

    /// Quarter-wave film at normal incidence (Born & Wolf §1.6.4, Eq. 1.6(62)):
    /// R = ((n0 ns − n1²)/(n0 ns + n1²))²; zero for n1 = √(n0 ns). Fixes the phase as 2π n d/λ (the printed
    /// 1π would make this a half-wave, absentee layer).
    #[test]
    fn quarter_wave_closed_form() {
        for &(n0, n1, ns) in &[(1.0, 1.38, 1.52), (1.0, 2.3, 1.52), (1.5, 2.5, 1.58), (1.0, 1.52f64.sqrt(), 1.52)] {
            let lambda = 550.0;
            let d = lambda / (4.0 * n1);
            let r = stack(n0, &[coh(c(n1, 0.0), d)], c(ns, 0.0), 1.0, lambda);
            let want = ((n0 * ns - n1 * n1) / (n0 * ns + n1 * n1)).powi(2);
            assert!((r.rs - want).abs() < 1e-14 && (r.rp - want).abs() < 1e-14, "{n1}: {r:?} vs {want}");
            assert!((r.rs + r.ts - 1.0).abs() < 1e-14);
        }
    }

    /// Absentee layer at oblique incidence: with d = λ / (2√(n1² − n0² sin²θ0)) (φ = π, the sin² inside the
    /// root) the film is invisible and R equals the bare interface; thickness from the misprinted phase
    /// (sin² outside the root) is not absentee.
    #[test]
    fn absentee_layer_fixes_phase_reading() {
        let (n0, n1, ns, lambda) = (1.0, 2.0, 1.5, 600.0);
        for deg in [30.0f64, 50.0, 70.0] {
            let th = deg.to_radians();
            let s2 = th.sin().powi(2);
            let bare = fresnel_dielectric(th.cos(), ns / n0);
            let d = lambda / (2.0 * (n1 * n1 - n0 * n0 * s2).sqrt());
            let r = stack(n0, &[coh(c(n1, 0.0), d)], c(ns, 0.0), th.cos(), lambda);
            assert!((r.rs - bare.rs).abs() < 1e-14 && (r.rp - bare.rp).abs() < 1e-14, "{deg}: {r:?} {bare:?}");
            let d_misprint = lambda / (2.0 * (n1 * n1 - n0 * n0).sqrt() * s2);
            let r2 = stack(n0, &[coh(c(n1, 0.0), d_misprint)], c(ns, 0.0), th.cos(), lambda);
            assert!((r2.rs - bare.rs).abs() > 1e-3, "{deg}");
        }
    }

    /// No layers: the single interface, equal to the Fresnel functions (dielectric and conductor exit);
    /// R + T = 1 for a single interface also into an absorbing medium (the transmitted power is absorbed there).
    #[test]
    fn bare_interface_is_fresnel() {
        for ci in angles() {
            for &eta in &[1.5, 0.7] {
                let r = stack(1.0, &[], c(eta, 0.0), ci, 500.0);
                let f = fresnel_dielectric(ci, eta);
                assert!((r.rs - f.rs).abs() < 1e-14 && (r.rp - f.rp).abs() < 1e-14);
                assert!((r.ts - f.ts).abs() < 1e-14 && (r.tp - f.tp).abs() < 1e-14, "{eta} {ci} {r:?} {f:?}");
            }
            let m = c(0.2, 3.0);
            let r = stack(1.0, &[], m, ci, 500.0);
            let f = fresnel_conductor(ci, m);
            assert!((r.rs - f.rs).abs() < 1e-14 && (r.rp - f.rp).abs() < 1e-14);
            assert!((r.rs + r.ts - 1.0).abs() < 1e-14 && (r.rp + r.tp - 1.0).abs() < 1e-14, "{r:?}");
        }
    }

    /// Zero-thickness coherent layers (of any index, absorbing too) change nothing.
    #[test]
    fn zero_thickness_layers_change_nothing() {
        let base = [coh(c(2.5, 0.0), 120.0), coh(c(1.38, 0.0), 95.0)];
        let with = [
            coh(c(3.0, 0.5), 0.0),
            coh(c(2.5, 0.0), 120.0),
            coh(c(1.1, 0.0), 0.0),
            coh(c(1.38, 0.0), 95.0),
            coh(c(0.2, 3.0), 0.0),
        ];
        for ci in angles() {
            for lambda in [400.0, 550.0, 700.0] {
                let a = stack(1.0, &base, c(1.52, 0.0), ci, lambda);
                let b = stack(1.0, &with, c(1.52, 0.0), ci, lambda);
                for (x, y) in [(a.rs, b.rs), (a.rp, b.rp), (a.ts, b.ts), (a.tp, b.tp)] {
                    assert!((x - y).abs() < 1e-13, "{a:?} {b:?}");
                }
            }
        }
    }

    /// Energy conservation for lossless stacks at oblique incidence, s and p, coherent and incoherent, also
    /// with total internal reflection at the exit (T = 0, R = 1) and frustrated TIR through a thin gap.
    #[test]
    fn lossless_r_plus_t_is_one() {
        let stacks: Vec<(f64, Vec<FilmLayer>, f64)> = vec![
            (1.0, vec![coh(c(2.5, 0.0), 100.0), coh(c(1.58, 0.0), 500.0), coh(c(2.5, 0.0), 100.0)], 1.5),
            (1.5, vec![coh(c(2.5, 0.0), 80.0), inc(c(1.58, 0.0), 500.0), coh(c(2.5, 0.0), 80.0)], 1.5),
            (1.0, vec![inc(c(1.5, 0.0), 1e6)], 1.0),
            (1.5, vec![coh(c(1.0, 0.0), 200.0)], 1.5), // frustrated TIR beyond 41.8°
            (1.5, vec![coh(c(1.38, 0.0), 100.0)], 1.0), // TIR at the exit beyond 41.8°
            (1.0, vec![inc(c(2.0, 0.0), 2e4), coh(c(1.3, 0.0), 90.0), inc(c(1.7, 0.0), 5e4)], 1.45),
        ];
        for (n_in, layers, n_out) in &stacks {
            for ci in angles() {
                for lambda in [420.0, 555.0, 690.0] {
                    let r = stack(*n_in, layers, c(*n_out, 0.0), ci, lambda);
                    assert!((r.rs + r.ts - 1.0).abs() < 1e-13, "s {n_in} {layers:?} {ci} {r:?}");
                    assert!((r.rp + r.tp - 1.0).abs() < 1e-13, "p {n_in} {layers:?} {ci} {r:?}");
                }
            }
        }
        // TIR at the exit: nothing is transmitted.
        let r = stack(1.5, &[coh(c(1.38, 0.0), 100.0)], c(1.0, 0.0), 60f64.to_radians().cos(), 500.0);
        assert!(r.ts == 0.0 && r.tp == 0.0 && (r.rs - 1.0).abs() < 1e-14);
    }

    /// Absorbing stacks lose energy: 0 < R + T < 1.
    #[test]
    fn absorbing_stack_absorbs() {
        let layers = [coh(c(2.5, 0.01), 100.0), inc(c(1.58, 0.001), 500.0), coh(c(2.5, 0.01), 100.0)];
        for ci in angles() {
            let r = stack(1.5, &layers, c(1.5, 0.0), ci, 500.0);
            assert!(r.rs + r.ts < 1.0 - 1e-6 && r.rp + r.tp < 1.0 - 1e-6 && r.r() > 0.0 && r.t() > 0.0);
        }
    }

    /// A 1 mm incoherent slab of n = 1.5 in air: R = 2r/(1 + r) with r the single-interface reflectance (sum
    /// of the incoherent multiple reflections), per polarisation, and T = (1 − r)/(1 + r).
    #[test]
    fn incoherent_slab() {
        for ci in angles() {
            let f = fresnel_dielectric(ci, 1.5);
            let r = stack(1.0, &[inc(c(1.5, 0.0), 1e6)], c(1.0, 0.0), ci, 550.0);
            assert!((r.rs - 2.0 * f.rs / (1.0 + f.rs)).abs() < 1e-14, "{ci} {r:?}");
            assert!((r.rp - 2.0 * f.rp / (1.0 + f.rp)).abs() < 1e-14);
            assert!((r.ts - (1.0 - f.rs) / (1.0 + f.rs)).abs() < 1e-14);
        }
        // normal incidence: r = 0.04 → R = 0.0769230769… (tmm `inc_tmm`, Byrnes arXiv:1603.02720)
        let r = stack(1.0, &[inc(c(1.5, 0.0), 1e6)], c(1.0, 0.0), 1.0, 550.0);
        assert!((r.r() - 0.08 / 1.04).abs() < 1e-15);
    }

    /// Reciprocity of transmission (Stokes / Lorentz reciprocity, lossless and lossy coherent stacks between
    /// real media): T(in → out) = T(out → in) for the reversed stack at the Snell-related angle.
    #[test]
    fn transmission_reciprocity() {
        let layers = [coh(c(2.5, 0.05), 110.0), coh(c(1.58, 0.0), 300.0), coh(c(2.2, 0.0), 70.0)];
        let rev: Vec<_> = layers.iter().rev().copied().collect();
        let (n_in, n_out) = (1.0, 1.5);
        for deg in [0.0f64, 30.0, 60.0, 80.0] {
            let th = deg.to_radians();
            let th_out = (n_in * th.sin() / n_out).asin();
            let a = stack(n_in, &layers, c(n_out, 0.0), th.cos(), 520.0);
            let b = stack(n_out, &rev, c(n_in, 0.0), th_out.cos(), 520.0);
            assert!((a.ts - b.ts).abs() < 1e-13 && (a.tp - b.tp).abs() < 1e-13, "{deg}: {a:?} {b:?}");
        }
    }

    /// A thick strongly absorbing layer (100 µm, k = 0.5 and k = 3): finite R and T, T underflows to 0 and R
    /// is the reflectance of the semi-infinite absorbing medium (only decaying exponentials are formed).
    #[test]
    fn thick_absorbing_layer_is_stable() {
        for m in [c(1.5, 0.5), c(0.2, 3.0)] {
            for incoherent in [false, true] {
                let l = FilmLayer { n: m, thickness_nm: 1e5, coherent: !incoherent };
                for ci in angles() {
                    let r = stack(1.0, &[l], c(1.5, 0.0), ci, 500.0);
                    assert!(r.rs.is_finite() && r.rp.is_finite() && r.ts.is_finite() && r.tp.is_finite());
                    assert!(r.ts < 1e-300 && r.tp < 1e-300);
                    let f = fresnel_conductor(ci, m);
                    assert!((r.rs - f.rs).abs() < 1e-14 && (r.rp - f.rp).abs() < 1e-14, "{r:?} {f:?}");
                }
            }
        }
    }

    /// The stack at several wavelengths at once is the stack at each, to the bit: coherent and incoherent
    /// layers, absorbing ones, a repeated layer, total internal reflection, grazing incidence, and a stack
    /// long enough for the heap path.
    #[test]
    fn the_spectrum_at_once_is_each_wavelength_to_the_bit() {
        let tio2 = coh(c(2.5, 0.0), 60.0);
        let long: Vec<FilmLayer> = (0..30).map(|i| coh(c(1.4 + 0.03 * i as f64, 0.01), 40.0 + i as f64)).collect();
        let stacks: Vec<(f64, Vec<FilmLayer>, Complex64)> = vec![
            (1.5, vec![tio2, inc(c(1.58, 0.0), 400.0), tio2], c(1.5, 0.0)),
            (1.8, vec![tio2, inc(c(1.55, 0.0), 400.0), tio2], c(1.8, 0.0)),
            (1.0, vec![coh(c(2.5, 0.05), 110.0), inc(c(1.58, 0.001), 500.0), coh(c(2.5, 0.05), 110.0)], c(0.2, 3.0)),
            (1.5, vec![coh(c(1.38, 0.0), 100.0)], c(1.0, 0.0)),
            (1.0, vec![], c(1.5, 0.0)),
            (1.0, long, c(1.52, 0.0)),
        ];
        let lambdas: Vec<f64> = (0..21).map(|i| 380.0 + 20.0 * i as f64).collect();
        for (n_in, layers, n_out) in &stacks {
            for ci in angles().chain([-0.1, 1e-9, 0.3]) {
                let mut seen = 0;
                stack_spectrum(*n_in, layers, *n_out, ci, None, lambdas.iter().copied(), |i, r| {
                    let alone = stack(*n_in, layers, *n_out, ci, lambdas[i]);
                    for (x, y) in [(r.rs, alone.rs), (r.rp, alone.rp), (r.ts, alone.ts), (r.tp, alone.tp)] {
                        assert_eq!(x.to_bits(), y.to_bits(), "{n_in} {layers:?} {ci} {}", lambdas[i]);
                    }
                    seen += 1;
                });
                assert_eq!(seen, lambdas.len());
            }
        }
    }

    #[test]
    fn long_stacks_take_the_heap_path_and_agree() {
        // 40 zero-thickness layers (beyond INLINE_MEDIA) change nothing; a quarter-wave pair repeated is
        // the same whether split across the inline or the heap path (compare 10 vs 10 + 30 empty layers).
        let glass = Complex64::new(1.5, 0.0);
        let empty = FilmLayer { n: Complex64::new(2.3, 0.1), thickness_nm: 0.0, coherent: true };
        let bare = stack(1.0, &[], glass, 0.8, 550.0);
        let long = stack(1.0, &[empty; 40], glass, 0.8, 550.0);
        assert!((bare.rs - long.rs).abs() < 1e-14 && (bare.rp - long.rp).abs() < 1e-14);
        let hi = FilmLayer { n: Complex64::new(2.3, 0.0), thickness_nm: 550.0 / (4.0 * 2.3), coherent: true };
        let lo = FilmLayer { n: Complex64::new(1.38, 0.0), thickness_nm: 550.0 / (4.0 * 1.38), coherent: true };
        let short: Vec<FilmLayer> = (0..10).map(|i| if i % 2 == 0 { hi } else { lo }).collect();
        let mut padded = short.clone();
        padded.extend([empty; 30]);
        let (a, b) = (stack(1.0, &short, glass, 0.9, 550.0), stack(1.0, &padded, glass, 0.9, 550.0));
        assert!((a.r() - b.r()).abs() < 1e-13 && (a.t() - b.t()).abs() < 1e-13, "{a:?} vs {b:?}");
        assert!(a.r() > 0.9, "a 10-layer quarter-wave mirror reflects strongly: {}", a.r());
    }
}
