//! The checked region estimate (`docs/accuracy.md` §5.1) at the level of the quadrature: with
//! `Options::checked` a bisected box's children have their calibrated estimates scaled from their parent's
//! check. Against closed forms, the estimate stays at or above the actual error, it is smaller than the
//! unchecked one (so the check does something), and a frozen re-run of the kept partition gives the same value
//! and error bits (the scales travel with the cells).
use glossmeter::quadrature::{integrate_partition, Cell, Options, Refine, MAX_SHRINK_LOBE};

/// ∫ over [0, 1]⁴ of exp(−a·|x − c|²) (a product of 1-D Gaussians: erf closed form).
fn gaussian_4d(a: f64, c: f64) -> f64 {
    let one = (std::f64::consts::PI / a).sqrt() / 2.0 * (libm::erf(a.sqrt() * (1.0 - c)) + libm::erf(a.sqrt() * c));
    one.powi(4)
}

fn run(opts: &Options, a: f64, c: f64, cells: &[Cell<4>], refine: Refine) -> (f64, f64, usize, Vec<Cell<4>>) {
    let f = |pts: &[[f64; 4]], out: &mut [f64]| {
        for (x, o) in pts.iter().zip(out.iter_mut()) {
            *o = (-a * x.iter().map(|x| (x - c) * (x - c)).sum::<f64>()).exp();
        }
    };
    let (est, kept) = integrate_partition::<4, _>(f, 1, cells, opts, refine, true);
    (est.value[0], est.error[0], est.evaluations, kept)
}

#[test]
fn the_checked_estimate_covers_the_actual_error_is_tighter_and_freezes_to_the_same_bits() {
    let unit = Cell::from_boxes(&[([0.0; 4], [1.0; 4])]);
    for (a, c) in [(10.0, 0.3), (40.0, 0.5), (200.0, 0.45)] {
        let exact = gaussian_4d(a, c);
        for rtol in [1e-4, 1e-6, 1e-8] {
            let plain = Options { rtol, ..Options::default() };
            let checked = Options { checked: true, ..plain };
            let deep = Options { max_shrink: MAX_SHRINK_LOBE, ..checked };
            let (v0, e0, n0, _) = run(&plain, a, c, &unit, Refine::Adaptive);
            assert!((v0 - exact).abs() <= e0, "unchecked a={a} rtol={rtol}: actual {:e} > {e0:e}", (v0 - exact).abs());
            for opts in [checked, deep] {
                let (v, e, n, kept) = run(&opts, a, c, &unit, Refine::Adaptive);
                let actual = (v - exact).abs();
                assert!(actual <= e, "a={a} rtol={rtol} {opts:?}: actual {actual:e} > estimate {e:e}");
                assert!(n <= n0, "a={a} rtol={rtol}: the checked run costs more ({n} > {n0})");
                let (vf, ef, _, _) = run(&opts, a, c, &kept, Refine::Frozen);
                assert_eq!((vf.to_bits(), ef.to_bits()), (v.to_bits(), e.to_bits()), "a={a} rtol={rtol}: frozen bits");
            }
        }
        // At rtol 1e-8 the box is bisected many times: the check must have acted (fewer evaluations or a
        // smaller estimate, and some cell shrunk), within its limits.
        let opts = Options { rtol: 1e-8, ..Options::default() };
        let (_, e0, n0, _) = run(&opts, a, c, &unit, Refine::Adaptive);
        let (_, e1, n1, kept) = run(&Options { checked: true, ..opts }, a, c, &unit, Refine::Adaptive);
        assert!(n1 < n0 || e1 < e0, "a={a}: the check changed nothing ({n1} vs {n0} evaluations)");
        assert!(kept.iter().any(|c| c.scale < 1.0), "a={a}: no cell was shrunk by its parent's check");
        assert!(kept.iter().all(|c| c.scale >= 1.0 / 8.0 && c.scale <= 8.0), "a={a}: a scale outside [1/8, 8]");
    }
}

/// The check also enlarges: where the parent's estimate was below its actual error (a kink the null rules
/// missed), the children's estimates grow (scale > 1), which refines there instead of trusting the rules.
#[test]
fn a_kink_inside_a_box_enlarges_the_childrens_estimates() {
    let unit = Cell::from_boxes(&[([0.0; 4], [1.0; 4])]);
    let f = |pts: &[[f64; 4]], out: &mut [f64]| {
        for (x, o) in pts.iter().zip(out.iter_mut()) {
            *o = (x[0] - 0.37).abs() + 0.1 * x[1];
        }
    };
    let opts = Options { rtol: 1e-6, checked: true, ..Options::default() };
    let (est, kept) = integrate_partition::<4, _>(f, 1, &unit, &opts, Refine::Adaptive, true);
    // ∫ |x − 0.37| dx over [0, 1] = (0.37² + 0.63²)/2, plus 0.1·½.
    let exact = (0.37f64.powi(2) + 0.63f64.powi(2)) / 2.0 + 0.05;
    assert!(
        (est.value[0] - exact).abs() <= est.error[0],
        "actual {:e} > {:e}",
        (est.value[0] - exact).abs(),
        est.error[0]
    );
    assert!(kept.iter().any(|c| c.scale > 1.0), "no box's estimate was enlarged by its parent's check");
}
