//! Goodness of fit: the probability that a χ² at least as large as the fit's arises from noise of the stated
//! uncertainties alone, the chi-square survival function Q(ν/2, χ²/2) written with the regularized upper
//! incomplete gamma function (docs/inverse.md §Goodness of fit).
//!
//! Q(a, x) = Γ(a, x)/Γ(a) is computed as in Press et al., *Numerical Recipes*, 3rd ed., §6.2: for x < a + 1 by
//! the series of the lower function, P(a, x) = e^{−x} x^a Σₙ xⁿ / Γ(a + n + 1) (Abramowitz & Stegun 6.5.29), and
//! Q = 1 − P; otherwise by the continued fraction of Γ(a, x) (Abramowitz & Stegun 6.5.31), evaluated by the
//! modified Lentz method, which gives small tail probabilities without cancellation. ln Γ is libm's `lgamma`.

/// A fit whose χ² has a p-value below this is one the model cannot reproduce (docs/inverse.md §Goodness of
/// fit): noise of the stated uncertainties makes so large a χ² once in a thousand fits.
pub const P_THRESHOLD: f64 = 1e-3;

/// The regularized upper incomplete gamma function Q(a, x) = Γ(a, x)/Γ(a), for a > 0 and x ≥ 0 (NaN
/// otherwise).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if !(a > 0.0 && a.is_finite() && x >= 0.0) {
        return f64::NAN;
    }
    if x == 0.0 {
        return 1.0;
    }
    if x.is_infinite() {
        return 0.0;
    }
    // The common factor e^{−x} x^a / Γ(a), in logarithms.
    let ln_front = -x + a * x.ln() - libm::lgamma(a);
    if x < a + 1.0 {
        // A&S 6.5.29: P(a, x) = e^{−x} x^a / Γ(a + 1) · Σₙ xⁿ / ((a + 1)…(a + n)).
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-17 {
                break;
            }
        }
        (1.0 - sum * ln_front.exp()).max(0.0)
    } else {
        // A&S 6.5.31: Γ(a, x) = e^{−x} x^a · 1/(x + 1 − a − 1·(1 − a)/(x + 3 − a − 2·(2 − a)/(x + 5 − a − …))),
        // by the modified Lentz method (NR §5.2, §6.2).
        const TINY: f64 = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / TINY;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < TINY {
                d = TINY;
            }
            c = b + an / c;
            if c.abs() < TINY {
                c = TINY;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (ln_front.exp() * h).clamp(0.0, 1.0)
    }
}

/// The chi-square survival function: the probability that a χ² of `dof` degrees of freedom is at least
/// `chi2`, Q(dof/2, chi2/2). `None` for no degrees of freedom (an exactly determined fit, judged instead by
/// its residuals against their uncertainties).
pub fn chi2_survival(chi2: f64, dof: usize) -> Option<f64> {
    (dof > 0).then(|| gamma_q(dof as f64 / 2.0, chi2.max(0.0) / 2.0))
}
