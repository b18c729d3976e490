//! Lemke's pivots allocate nothing: the number of heap allocations of a solve does not grow
//! with the number of pivots (the workspace is sized once; the pending updates and the rank-k
//! product reuse it).

use std::alloc::{GlobalAlloc, Layout, System};

use coulomb::lcp::{
    solve_lemke_into, solve_lemke_with, LcpRef, LcpSolution, LemkeSettings, LemkeWorkspace,
};
use coulomb::testing::planted_psd;

struct Counting;

// SAFETY: forwards to the system allocator, only counting calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        MINE.with(|c| c.set(c.get() + 1));
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

thread_local! {
    /// this thread's allocations (the test harness's threads allocate while a test runs):
    /// a const Cell, so reading it allocates nothing
    static MINE: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// the allocations this thread has made.
fn mine() -> usize {
    MINE.with(|c| c.get())
}

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
    let before = mine();
    let s = solve_lemke_with(ws, &lcp, &settings).expect("valid settings");
    let after = mine();
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

/// A batch's worker solves many small problems on one workspace: after the first, a solve
/// allocates only what it returns (z, w, the basis, the message), whatever the problem.
#[test]
fn a_kept_workspace_allocates_only_the_answer() {
    let mut ws = LemkeWorkspace::new(0);
    let mut counts = Vec::new();
    for seed in 0..20 {
        let n = 3 + (seed as usize % 5);
        let (m, q, _, _) = planted_psd(n, n / 2 + 1, seed);
        let lcp = LcpRef::new(n, &m.data, &q).expect("well-formed");
        // the first solve of a size sizes the workspace
        solve_lemke_with(&mut ws, &lcp, &LemkeSettings::default()).expect("valid");
        let before = mine();
        let s = solve_lemke_with(&mut ws, &lcp, &LemkeSettings::default()).expect("valid");
        counts.push(mine() - before);
        assert!(s.success(), "{}", s.message);
    }
    println!("allocations per solve: {counts:?}");
    // z, w, the basis (none when it is empty) and the message: 20 before the scratch was kept
    assert!(counts.iter().all(|&c| c <= 4), "{counts:?}");
}

/// With the answer kept too (`solve_lemke_into`, as a batch's worker solves), a solve after
/// the first two of its size (the first sizes the workspace, the second fills the kept
/// spare vectors) allocates nothing, and gives what a fresh solve gives.
#[test]
fn a_kept_workspace_and_answer_allocate_nothing() {
    let mut ws = LemkeWorkspace::new(0);
    let mut out = LcpSolution::empty();
    let mut counts = Vec::new();
    for seed in 0..20 {
        let n = 3 + (seed as usize % 5);
        let (m, q, _, _) = planted_psd(n, n / 2 + 1, seed);
        let lcp = LcpRef::new(n, &m.data, &q).expect("well-formed");
        let settings = LemkeSettings::default();
        for _ in 0..2 {
            solve_lemke_into(&mut ws, &lcp, &settings, &mut out).expect("valid");
        }
        let before = mine();
        solve_lemke_into(&mut ws, &lcp, &settings, &mut out).expect("valid");
        counts.push(mine() - before);
        let fresh = solve_lemke_with(&mut LemkeWorkspace::new(n), &lcp, &settings).expect("valid");
        assert!(out.success(), "{}", out.message);
        assert_eq!(out.z, fresh.z);
        assert_eq!(out.w, fresh.w);
        assert_eq!(out.basis, fresh.basis);
        assert_eq!(out.message, fresh.message);
        assert_eq!(out.measures, fresh.measures);
        assert_eq!((out.pivots, out.polished), (fresh.pivots, fresh.polished));
    }
    println!("allocations per solve: {counts:?}");
    assert!(counts.iter().all(|&c| c == 0), "{counts:?}");
}
