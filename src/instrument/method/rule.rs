//! The rules behind one interface (`shape.rs`), dispatched: every rule of a regular part ([`Rule`]) runs through [`ShapedRule`] —
//! given the integrand in its chart and a [`RuleRun`] (the components, the options, whether it may refine, the
//! stops and the part's partition), it returns one [`Outcome`]: the estimate and the rule *frozen* at what
//! it reached (the levels, the path of raises, the final partition), or nothing when it did not agree; and
//! the evaluations spent either way. When a rule does not agree the next rule of its fallback chain runs
//! ([`Rule::fallback`]: the delta limit → the lobe's Gauss–Hermite rule → the Genz–Malik partition; every
//! other shaped rule → the partition), so the chain is data and the executor (`execute.rs`) one loop.
//!
//! Each rule's file implements [`ShapedRule`] for its parameters: `delta.rs` ([`Rule::LobeDelta`]),
//! `gauss.rs` ([`Rule::LobeGaussHermite`], [`Rule::TensorGauss`]), `polar.rs` ([`Rule::LobePolar`]); the
//! Genz–Malik partition ([`Rule::GenzMalik75`], the end of every chain) is here.
use super::delta::Delta;
use super::gauss::{GaussHermite, Tensor, LOBE_LEVELS};
use super::polar::Polar;
use super::shape::{Integrand, Outcome, RuleRun, ShapedRule};
use super::Rule;
use crate::instrument::aperture::Chart;
use crate::quadrature::integrate_partition;

/// [`Rule::GenzMalik75`]: the part's partition, globally adaptive (or frozen); it always returns, converged or
/// not (the end of every fallback chain).
struct Partition;

impl ShapedRule for Partition {
    fn estimate(&self, f: &mut Integrand, run: &RuleRun) -> Outcome {
        let (est, cells) = integrate_partition::<4, _>(f, run.ncomp, run.cells, run.opts, run.refine, run.keep);
        let spent = est.evaluations;
        Outcome { done: Some((est, Rule::GenzMalik75, Some(cells))), spent }
    }
}

impl Rule {
    /// The chart the rule's points are in: the part's (`part`), except the tensor rule's own.
    pub(crate) fn chart(&self, part: Chart) -> Chart {
        match self {
            Rule::TensorGauss { chart, .. } => *chart,
            _ => part,
        }
    }

    /// The rule that runs when this one does not agree: the delta limit falls back to the lobe's
    /// Gauss–Hermite rule over all its levels, every other shaped rule to the Genz–Malik partition, which
    /// has none (it always returns).
    pub(crate) fn fallback(&self) -> Option<Rule> {
        match *self {
            Rule::LobeDelta { width } => Some(Rule::LobeGaussHermite { width, levels: (0, LOBE_LEVELS.len() - 1) }),
            Rule::LobeGaussHermite { .. } | Rule::LobePolar { .. } | Rule::TensorGauss { .. } | Rule::TailBound => {
                Some(Rule::GenzMalik75)
            }
            Rule::GenzMalik75 => None,
        }
    }

    /// Run this rule ([`ShapedRule::estimate`] of its file's implementation); [`Rule::TailBound`] needs the
    /// material and is run by the executor (`Method::settle_by_tail`), so here it never agrees.
    pub(crate) fn estimate(&self, f: &mut Integrand, run: &RuleRun) -> Outcome {
        match *self {
            Rule::GenzMalik75 => Partition.estimate(f, run),
            Rule::LobeGaussHermite { width, levels } => GaussHermite { width, levels }.estimate(f, run),
            Rule::LobeDelta { width } => Delta { width }.estimate(f, run),
            Rule::LobePolar { width, u, v, levels } => Polar { width, breaks: [u, v], levels }.estimate(f, run),
            Rule::TensorGauss { chart, levels, path } => Tensor { chart, levels, path }.estimate(f, run),
            // Settled with the material, before the chain reaches the rules (`tail.rs`); without it, no bound.
            Rule::TailBound => Outcome { done: None, spent: 0 },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::geometry::Stop;
    use crate::quadrature::{Cell, Options, Refine};

    #[test]
    fn the_fallback_chain_ends_at_the_partition() {
        let w = [0.01, 0.02];
        let mut rule = Rule::LobeDelta { width: w };
        let mut chain = vec![rule];
        while let Some(next) = rule.fallback() {
            chain.push(next);
            rule = next;
        }
        let gh = Rule::LobeGaussHermite { width: w, levels: (0, LOBE_LEVELS.len() - 1) };
        assert_eq!(chain, [Rule::LobeDelta { width: w }, gh, Rule::GenzMalik75]);
        assert_eq!(
            Rule::LobePolar { width: w, u: [0.0; 4], v: [0.0; 4], levels: [1; 9] }.fallback(),
            Some(Rule::GenzMalik75)
        );
    }

    #[test]
    fn the_partition_is_exact_on_a_polynomial_of_degree_seven() {
        // Σ_k x_k⁷ + x₀³x₁²x₂x₃ over [0, 1]⁴ × 2 cells: ∫ = 4/8 + 1/4·1/3·1/2·1/2.
        let cells = Cell::from_boxes(&[([0.0, 0.0, 0.0, 0.0], [0.5, 1.0, 1.0, 1.0]), ([0.5, 0.0, 0.0, 0.0], [1.0; 4])]);
        let opts = Options { rtol: 1e-12, ..Options::default() };
        let stop = Stop { p: [0.0, 1.0], q: [0.0, 1.0] };
        let run =
            RuleRun { ncomp: 1, opts: &opts, refine: Refine::Adaptive, stops: (stop, stop), cells: &cells, keep: true };
        let mut f = |pts: &[[f64; 4]], out: &mut [f64]| {
            for (x, o) in pts.iter().zip(out.iter_mut()) {
                *o = x.iter().map(|v| v.powi(7)).sum::<f64>() + x[0].powi(3) * x[1] * x[1] * x[2] * x[3];
            }
        };
        let out = Rule::GenzMalik75.estimate(&mut f, &run);
        let (est, rule, kept) = out.done.expect("the partition always returns");
        let exact = 0.5 + 1.0 / 48.0;
        assert!((est.value[0] - exact).abs() <= 1e-14, "{}", est.value[0]);
        assert_eq!(rule, Rule::GenzMalik75);
        assert!(kept.is_some_and(|c| c.len() >= 2) && out.spent == est.evaluations && out.spent >= 2 * 57);
    }
}
