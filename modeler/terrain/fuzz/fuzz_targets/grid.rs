//! Any bytes as a small, long or thin grid, analysed and lit (`fuzzing::grid`), with the heap's
//! peak held to the grid's size: a sweep that allocates by the square of the long side (issue 47
//! item 3) fails here even where it would still fit in memory.
#![no_main]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The system allocator, counting the bytes live and their peak.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded as given.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(live, Ordering::Relaxed);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded as given.
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let (cols, rows, _, _) = penmodel_terrain::fuzzing::grid_of(data);
    let cells = cols as usize * rows as usize;
    let start = LIVE.load(Ordering::Relaxed);
    PEAK.store(start, Ordering::Relaxed);
    penmodel_terrain::fuzzing::grid(data);
    let grown = PEAK.load(Ordering::Relaxed).saturating_sub(start);
    let bound = penmodel_terrain::fuzzing::grid_heap_bound(cells);
    assert!(
        grown <= bound,
        "{cols}×{rows}: the heap grew by {grown} bytes, more than the {bound} a grid of {cells} cells may take"
    );
});
