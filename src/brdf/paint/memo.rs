//! A small memo of what a paint build computes from a few inputs ([`Memo`]): the flake terms'
//! verified tables, kept between builds so that a sweep or fit point that changes a field a table does not depend
//! on (an area ratio, a flake spread, the primer, a coat's roughness or thickness) reuses the tables instead of
//! rebuilding them (`docs/model.md` §Folded evaluation, `docs/performance.md` §"Paint rebuilds in sweeps").
//!
//! Why this is safe: an entry is found only by the exact bits of every input its computation reads (the key), and
//! that computation is deterministic, so a reused entry is bit for bit what a rebuild would give: the same
//! readings whether a point is built cold or after its neighbours, on any thread. The memo holds at most
//! [`MEMO_ENTRIES`] entries (the oldest goes first), so its memory is bounded whatever a sweep visits.
use std::sync::{Arc, Mutex};

/// Entries a [`Memo`] keeps: a sweep alternating between a few materials (a fit's finite differences touch one
/// parameter at a time) still finds each; the tables of a 21-sample pearl paint are ≈ 0.2 MB an entry.
pub(crate) const MEMO_ENTRIES: usize = 8;

/// Values keyed by the bits of their inputs, at most [`MEMO_ENTRIES`] of them, shared by every thread.
pub(super) struct Memo<T> {
    entries: Mutex<Vec<(Vec<u64>, Arc<T>)>>,
}

impl<T> Memo<T> {
    pub(super) const fn new() -> Memo<T> {
        Memo { entries: Mutex::new(Vec::new()) }
    }

    /// The value of `key`: the kept one, or `make()` (run outside the lock, so builds on other threads are not
    /// held up; two threads that miss at once both build the same bits, and one copy is kept).
    pub(super) fn get_or_make(&self, key: Vec<u64>, make: impl FnOnce() -> T) -> Arc<T> {
        if let Ok(entries) = self.entries.lock() {
            if let Some((_, v)) = entries.iter().find(|(k, _)| *k == key) {
                return v.clone();
            }
        }
        let value = Arc::new(make());
        if let Ok(mut entries) = self.entries.lock() {
            if !entries.iter().any(|(k, _)| *k == key) {
                if entries.len() >= MEMO_ENTRIES {
                    entries.remove(0);
                }
                entries.push((key, value.clone()));
            }
        }
        value
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_key_is_made_once_and_the_memo_stays_bounded() {
        let memo: Memo<u64> = Memo::new();
        let mut made = 0;
        for round in 0..2 {
            for k in 0..MEMO_ENTRIES as u64 {
                let v = memo.get_or_make(vec![k, 7], || {
                    made += 1;
                    k * 10
                });
                assert_eq!(*v, k * 10, "round {round}");
            }
        }
        assert_eq!(made, MEMO_ENTRIES, "the second round found every key");
        // One more key pushes the oldest out; it is made again when asked for.
        memo.get_or_make(vec![99], || 0);
        let mut again = false;
        memo.get_or_make(vec![0, 7], || {
            again = true;
            0
        });
        assert!(again);
        assert!(memo.entries.lock().unwrap().len() <= MEMO_ENTRIES);
    }
}
