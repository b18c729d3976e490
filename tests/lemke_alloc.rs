//! Lemke's pivots allocate nothing: the number of heap allocations of a solve does not grow
//! with the number of pivots (the workspace is sized once; the pending updates and the rank-k
//! product reuse it).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use coulomb::lcp::{solve_lemke_with, LcpRef, LemkeSettings, LemkeWorkspace};
use coulomb::testing::planted_psd;

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator, only counting calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations_and_pivots(
    n: usize,
    active_fraction_seed: u64,
    ws: &mut LemkeWorkspace,
) -> (usize, usize) {
    let (m, q, _, _) = planted_psd(n, n / 2, active_fraction_seed);
    let lcp = LcpRef::new(n, &m.data, &q).expect("well-formed");
    let settings = LemkeSettings {
        polish: false,
        ..Default::default()
    };
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let s = solve_lemke_with(ws, &lcp, &settings).expect("valid settings");
    let after = ALLOCATIONS.load(Ordering::Relaxed);
    assert!(s.success(), "{}", s.message);
    (after - before, s.pivots)
}

/// must allocate the same number of times whatever the number of pivots (209 to 273 here).
#[test]
fn pivots_allocate_nothing() {
    let n = 200;
    let mut ws = LemkeWorkspace::new(n);
    // warm up any lazily initialised state (CPU feature detection, thread-locals)
    allocations_and_pivots(n, 1, &mut ws);
    let mut seen = Vec::new();
    for seed in 2..6 {
        seen.push(allocations_and_pivots(n, seed, &mut ws));
    }
    let pivots: Vec<usize> = seen.iter().map(|s| s.1).collect();
    assert!(
        pivots.iter().max() > pivots.iter().min(),
        "need different pivot counts: {pivots:?}"
    );
    let counts: Vec<usize> = seen.iter().map(|s| s.0).collect();
    println!("(allocations, pivots) per solve: {seen:?}");
    assert!(
        counts.iter().all(|&c| c == counts[0]),
        "allocations vary with pivots: {seen:?}"
    );
    // the constant: equilibration, result vectors and the basis, nothing per pivot
    assert!(
        counts[0] < 40,
        "too many allocations per solve: {}",
        counts[0]
    );
}
