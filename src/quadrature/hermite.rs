//! Gauss–Hermite rules: ∫ g(x) e^{−x²} dx ≈ Σ wᵢ g(xᵢ), exact for polynomials g of degree ≤ 2n − 1. The
//! instrument uses them in the lobe variables of a narrow Gaussian-tailed lobe (`instrument::method`,
//! `Rule::LobeGaussHermite`): scaled to the lobe's width, n nodes see the whole lobe however narrow it is.

/// Nodes (increasing) and weights of the n-point Gauss–Hermite rule for the weight e^{−x²} on ℝ (Newton
/// iteration on the orthonormal Hermite recurrence from the asymptotic initial guesses; Press et al.,
/// Numerical Recipes §4.6 `gauher`; Abramowitz & Stegun 25.4.46).
pub(crate) fn gauss_hermite(n: usize) -> (Vec<f64>, Vec<f64>) {
    // π^(−1/4): the orthonormal polynomial of degree 0.
    const PIM4: f64 = 0.751_125_544_464_942_5;
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    let nf = n as f64;
    let mut z = 0.0f64;
    for i in 0..n.div_ceil(2) {
        z = match i {
            0 => (2.0 * nf + 1.0).sqrt() - 1.855_75 * (2.0 * nf + 1.0).powf(-0.166_67),
            1 => z - 1.14 * nf.powf(0.426) / z,
            2 => 1.86 * z - 0.86 * x[n - 1],
            3 => 1.91 * z - 0.91 * x[n - 2],
            _ => 2.0 * z - x[n + 1 - i],
        };
        let mut pp = 1.0;
        for _ in 0..100 {
            let (mut p1, mut p2) = (PIM4, 0.0f64);
            for j in 0..n {
                let p3 = p2;
                p2 = p1;
                let jf = j as f64;
                p1 = z * (2.0 / (jf + 1.0)).sqrt() * p2 - (jf / (jf + 1.0)).sqrt() * p3;
            }
            pp = (2.0 * nf).sqrt() * p2;
            let z1 = z;
            z = z1 - p1 / pp;
            if (z - z1).abs() <= 1e-15 * z.abs().max(1.0) {
                break;
            }
        }
        x[n - 1 - i] = z;
        x[i] = -z;
        w[i] = 2.0 / (pp * pp);
        w[n - 1 - i] = w[i];
    }
    if n % 2 == 1 {
        x[n / 2] = 0.0;
    }
    (x, w)
}

/// The largest order [`gauss_hermite_table`] holds.
pub(crate) const HERMITE_TABLE_MAX_ORDER: usize = 32;

/// The n-point Gauss–Hermite rule (1 ≤ n ≤ [`HERMITE_TABLE_MAX_ORDER`]) from a table computed once per process by
/// [`gauss_hermite`] (the same bits): a rule raised level by level neither recomputes nor allocates its nodes.
pub(crate) fn gauss_hermite_table(n: usize) -> (&'static [f64], &'static [f64]) {
    static TABLE: super::gauss::RuleTable = super::gauss::RuleTable::new();
    super::gauss::from_table(&TABLE, n, HERMITE_TABLE_MAX_ORDER, gauss_hermite, "Gauss–Hermite")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_hermite_integrates_the_gaussian_moments() {
        let sqrt_pi = std::f64::consts::PI.sqrt();
        for n in [2, 3, 4, 6, 8, 12, 16, 20] {
            let (x, w) = gauss_hermite(n);
            assert!(x.windows(2).all(|p| p[0] < p[1]), "n={n}: {x:?}");
            // ∫ x^{2k} e^{−x²} = Γ(k + ½) = √π (2k − 1)!! / 2^k, exact for 2k ≤ 2n − 1.
            let mut exact = sqrt_pi;
            for k in 0..n {
                let s: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(2 * k as i32)).sum();
                assert!((s - exact).abs() <= 1e-12 * exact, "n={n} k={k}: {s} vs {exact}");
                exact *= (2 * k + 1) as f64 / 2.0;
            }
            let odd: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(3)).sum();
            assert!(odd.abs() < 1e-13, "n={n}");
        }
    }
}
