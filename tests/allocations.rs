//! Nothing in the hot path allocates (issue 10 item 4): executing one aperture integral makes a number of
//! heap allocations that does not grow with the number of regions refined, apart from the amortised growth
//! of the region heap and the integrand's buffers (O(log regions) reallocations). Counted with a counting
//! global allocator around `Method::execute` on the calling thread.
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use glossmeter::instrument::method::Method;
use glossmeter::instrument::standards;

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn refining_allocates_nothing_per_region() {
    // The narrow-lobe paint (thousands of regions at 1e-6) and its metallic-only sibling, through D523 20°.
    for name in ["cerulean-blue-c-literal.json", "cerulean-blue-b-literal.json"] {
        let brdf =
            glossmeter::recipe::load_file(std::path::Path::new(&format!("fixtures/recipes/{name}"))).unwrap().brdf;
        let g = standards::find("astm-d523-20").unwrap().geometry;
        let (src, rec) = (g.source, g.receptors[0].1);
        let count = |rtol: f64| {
            let m = Method::for_material(brdf.as_ref(), g.theta, src, rec, (rtol, 0.0), 50_000_000).unwrap();
            let before = ALLOCATIONS.load(Ordering::Relaxed);
            let flux = m.execute(brdf.as_ref());
            (ALLOCATIONS.load(Ordering::Relaxed) - before, flux.regions, flux.evaluations)
        };
        let (a_lo, r_lo, e_lo) = count(1e-3);
        let (a_hi, r_hi, e_hi) = count(1e-9);
        assert!(r_hi > r_lo + 100, "{name}: {r_lo} → {r_hi} regions");
        // Per region refined, far less than one allocation: only the amortised growth of vectors.
        let extra = a_hi.saturating_sub(a_lo);
        assert!(
            extra <= 40,
            "{name}: {a_lo} allocations for {r_lo} regions ({e_lo} evaluations), {a_hi} for {r_hi} ({e_hi})"
        );
        eprintln!("{name}: {a_lo} allocations / {r_lo} regions, {a_hi} / {r_hi}");
    }
}
