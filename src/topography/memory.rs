//! Height maps held in memory under a label, which a recipe's `file` entry names as it names a file
//! (docs/topography.md §Maps held in memory). A front end that holds heights rather than a file (the Python
//! package's NumPy arrays) registers the map here and writes the label into the recipe; every parse of that
//! recipe, on any thread and as often as a sweep or a fit re-reads it, finds the same map. The map leaves the
//! table when its [`InMemory`] handle is dropped, so a recipe outliving its map is refused with the reason.
//!
//! Labels are `<height map N>`, N counting registrations in this process: the label is no path (it is read
//! from this table only, never from the disk), and a recipe sent to another process cannot find it there.
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, OnceLock};

use super::map::HeightMap;

/// The prefix of every label (a recipe's `file` beginning so is looked up here, and refused when absent).
pub(crate) const LABEL_PREFIX: &str = "<height map ";

/// The registered maps by label.
fn table() -> MutexGuard<'static, BTreeMap<String, Arc<HeightMap>>> {
    static TABLE: OnceLock<Mutex<BTreeMap<String, Arc<HeightMap>>>> = OnceLock::new();
    // A panic elsewhere while the lock was held leaves the map table itself consistent (every change is one
    // insert or one remove), so a poisoned lock is taken as it is.
    TABLE.get_or_init(|| Mutex::new(BTreeMap::new())).lock().unwrap_or_else(|e| e.into_inner())
}

/// A map registered in the table, under its label, for as long as this handle lives.
#[derive(Debug)]
pub struct InMemory {
    label: String,
    map: Arc<HeightMap>,
}

impl InMemory {
    /// Register `map` under a new label, which also becomes its `file` (the name messages and documents give it).
    pub fn register(mut map: HeightMap) -> InMemory {
        static NEXT: AtomicU64 = AtomicU64::new(1);
        let label = format!("{LABEL_PREFIX}{}>", NEXT.fetch_add(1, Ordering::Relaxed));
        map.file = label.clone();
        let map = Arc::new(map);
        table().insert(label.clone(), map.clone());
        InMemory { label, map }
    }

    /// The label a recipe's `file` entry names the map by.
    pub fn label(&self) -> &str {
        &self.label
    }

    /// The map.
    pub fn map(&self) -> &HeightMap {
        &self.map
    }
}

impl Drop for InMemory {
    fn drop(&mut self) {
        table().remove(&self.label);
    }
}

/// The map registered under `label`, if one is.
pub(crate) fn lookup(label: &str) -> Option<Arc<HeightMap>> {
    table().get(label).cloned()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::map::Format;

    fn flat(n: usize) -> HeightMap {
        HeightMap::new("<test>", Format::Array, n, n, 1e-6, 1e-6, vec![0.0; n * n], "z").unwrap()
    }

    #[test]
    fn a_map_is_found_by_its_label_while_its_handle_lives() {
        let a = InMemory::register(flat(8));
        let b = InMemory::register(flat(9));
        assert_ne!(a.label(), b.label());
        assert!(a.label().starts_with(LABEL_PREFIX));
        assert_eq!(a.map().file, a.label());
        assert_eq!(lookup(b.label()).unwrap().nx, 9);
        let gone = a.label().to_string();
        drop(a);
        assert!(lookup(&gone).is_none());
        assert_eq!(lookup(b.label()).unwrap().nx, 9);
    }
}
