//! The interface every rule of a regular part implements (docs/instrument.md §Quadrature): the integrand as
//! the rules see it ([`Integrand`]), what a run is given ([`RuleRun`]), the one result shape ([`Outcome`]: the
//! estimate and the rule frozen at what it reached) and the trait ([`ShapedRule`]). A leaf of the folder: the
//! rules' files (`delta.rs`, `gauss.rs`, `polar.rs`) implement it, and `rule.rs` dispatches a [`Rule`] to them.
use super::Rule;
use crate::instrument::geometry::Stop;
use crate::quadrature::{Cell, Estimate, Options, Refine};

/// The regular part's integrand as the rules see it: at each point of a batch (in the rule's chart), the
/// `ncomp` values written point-major to the output (left as they were outside the overlap).
pub(crate) type Integrand<'a> = dyn FnMut(&[[f64; 4]], &mut [f64]) + 'a;

/// What a rule run is given besides its integrand.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RuleRun<'a> {
    /// Components per point.
    pub ncomp: usize,
    /// The part's tolerances, budget, deadline and the Genz–Malik calibration's limits.
    pub opts: &'a Options,
    /// Adaptive (raise levels, refine the partition) or frozen (replay what a run reached).
    pub refine: Refine,
    /// The clipped stops (the tensor rule's boxes are cut from them).
    pub stops: (Stop, Stop),
    /// The part's partition (the Genz–Malik rule's), and whether its final cells are kept (freezing).
    pub cells: &'a [Cell<4>],
    pub keep: bool,
}

/// The one result shape of every rule.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Outcome {
    /// The estimate (its `evaluations` counts this run's), the rule frozen at what it reached, and the final
    /// partition when the rule refined one (the Genz–Malik rule; None: the part keeps its own); None when the
    /// rule did not agree (its fallback runs next).
    pub done: Option<(Estimate, Rule, Option<Vec<Cell<4>>>)>,
    /// Evaluations spent, whether or not the rule agreed.
    pub spent: usize,
}

impl Outcome {
    /// A shaped rule's outcome: its estimate and frozen self, or None; `spent` evaluations.
    pub(crate) fn shaped(done: Option<(Estimate, Rule)>, spent: usize) -> Outcome {
        Outcome {
            done: done.map(|(mut est, rule)| {
                est.evaluations = spent;
                (est, rule, None)
            }),
            spent,
        }
    }
}

/// A rule of a regular part, run on the integrand in its chart.
pub(crate) trait ShapedRule {
    /// Run the rule: [`Outcome::done`] is the estimate and the rule frozen at what it reached when it agreed
    /// with itself to the part's tolerance (or, frozen, replayed what it reached before), else None.
    fn estimate(&self, f: &mut Integrand, run: &RuleRun) -> Outcome;
}
