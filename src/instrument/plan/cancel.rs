//! A stop signal for a caller's whole piece of work ([`Cancel`]): a flag that another thread may raise (the
//! server raises it when the client of a request goes away) and an optional wall-clock deadline (the
//! server's limit per request). It travels in [`PlanOptions::cancel`](super::PlanOptions) through every
//! plan the work compiles (a fit's forward runs, a sweep's points, a profile's pixels), and it acts where the
//! evaluation budget and `--max-seconds` act (docs/instrument.md §Bounded work): a raised flag skips every
//! integral not yet started, and the deadline is the shared deadline of each execution, so an integral
//! running when it passes stops refining there. An integral skipped or stopped gives no value (its reading
//! says the wall-clock limit was reached); the others are the same bits as without it. The default, none,
//! changes nothing.
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// A shareable stop signal; clones share the flag. `Cancel::default()` never stops anything.
#[derive(Clone, Default)]
pub struct Cancel(Option<Arc<Signal>>);

struct Signal {
    raised: AtomicBool,
    deadline: Option<Instant>,
}

impl Cancel {
    /// A signal not yet raised, with a deadline (None: only the flag stops the work).
    pub fn new(deadline: Option<Instant>) -> Cancel {
        Cancel(Some(Arc::new(Signal { raised: AtomicBool::new(false), deadline })))
    }

    /// Raise the flag: integrals not yet started are skipped (every clone sees it).
    pub fn raise(&self) {
        if let Some(s) = &self.0 {
            s.raised.store(true, Ordering::Relaxed);
        }
    }

    /// Whether the flag is raised or the deadline has passed.
    pub fn is_stopped(&self) -> bool {
        self.0
            .as_ref()
            .is_some_and(|s| s.raised.load(Ordering::Relaxed) || s.deadline.is_some_and(|d| Instant::now() >= d))
    }

    /// Whether the deadline (not the flag) has passed.
    pub(crate) fn is_late(&self) -> bool {
        self.0.as_ref().and_then(|s| s.deadline).is_some_and(|d| Instant::now() >= d)
    }

    /// The earlier of `deadline` and the signal's own (None: neither has one).
    pub(crate) fn earliest(&self, deadline: Option<Instant>) -> Option<Instant> {
        match (deadline, self.0.as_ref().and_then(|s| s.deadline)) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
}

/// Not part of what a plan computes: any two compare equal, so that options that differ only in their
/// signal are the same options.
impl PartialEq for Cancel {
    fn eq(&self, _: &Cancel) -> bool {
        true
    }
}

impl std::fmt::Debug for Cancel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.0 {
            None => f.write_str("Cancel(none)"),
            Some(s) => write!(f, "Cancel(raised: {}, deadline: {:?})", s.raised.load(Ordering::Relaxed), s.deadline),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_raised_flag_is_seen_by_every_clone_and_the_default_never_stops() {
        assert!(!Cancel::default().is_stopped());
        Cancel::default().raise();
        let c = Cancel::new(None);
        let seen = c.clone();
        assert!(!seen.is_stopped());
        c.raise();
        assert!(seen.is_stopped() && !seen.is_late());
        let late = Cancel::new(Some(Instant::now()));
        assert!(late.is_stopped() && late.is_late());
        let t = Instant::now();
        assert_eq!(Cancel::default().earliest(Some(t)), Some(t));
        assert_eq!(late.earliest(None), late.0.as_ref().unwrap().deadline);
    }
}
