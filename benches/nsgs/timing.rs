//! NSGS sweep cost on the block-sparse pile of `benches/contact.rs`, beside this machine's
//! memory bandwidth: `cargo run --release --example nsgs_timing [-- SWEEPS [NC ...]]`
//! (the bandwidth is measured when no NC is given).
//!
//! For each nc it prints the wall time per contact per sweep (a solve with a tolerance no
//! iterate reaches, so exactly SWEEPS sweeps, best of 15), the bytes one sweep reads (the
//! tiles, their column indices, the row pointers, impulses and q) and those bytes divided by
//! the time. The bandwidth lines are stream-like loops over 256 MiB arrays (a read-only sum
//! and a copy, best of 5), the ceiling of a sweep whose W does not fit in cache.

use std::hint::black_box;
use std::time::Instant;

use coulomb::contact::{solve_nsgs, BlockCsr, ContactProblem, NsgsSettings};

#[path = "../../tests/pile/mod.rs"]
mod pile;

/// solves timed per figure (the best is kept: the machine may be shared).
const RUNS: usize = 15;

fn best_of<F: FnMut()>(runs: usize, mut f: F) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..runs {
        let t = Instant::now();
        f();
        best = best.min(t.elapsed().as_secs_f64());
    }
    best
}

fn bandwidth() {
    let n = 32 << 20; // 256 MiB of f64
    let a: Vec<f64> = (0..n).map(|k| k as f64).collect();
    let mut b = vec![0.0; n];
    let read = best_of(5, || {
        // four running sums so the loop is bound by memory, not by the adder's latency
        let mut s = [0.0; 4];
        for c in a.chunks_exact(4) {
            for k in 0..4 {
                s[k] += c[k];
            }
        }
        black_box(s);
    });
    let copy = best_of(5, || {
        b.copy_from_slice(black_box(&a));
        black_box(&b);
    });
    let bytes = (n * 8) as f64;
    println!(
        "memory bandwidth: read {:.1} GB/s, copy {:.1} GB/s (read + write)",
        bytes / read / 1e9,
        2.0 * bytes / copy / 1e9
    );
}

fn main() {
    let sweeps: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(50);
    let chosen: Vec<usize> = std::env::args()
        .skip(2)
        .filter_map(|s| s.parse().ok())
        .collect();
    let sizes = if chosen.is_empty() {
        vec![100, 1000, 5000, 20000, 100000]
    } else {
        chosen.clone()
    };
    for nc in sizes {
        let p = pile::pile(nc, 0.4, 1);
        let Ok(w) = BlockCsr::from_coo(3, p.n, &p.rows, &p.cols, &p.vals) else {
            panic!("bad pile")
        };
        let Ok(problem) = ContactProblem::with_block_sparse(&w, &p.q, &p.mu) else {
            panic!("bad pile")
        };
        let s = NsgsSettings {
            tol: 1e-300,
            max_iter: sweeps,
            // plain sweeps: the cost of one sweep, not of a sticking-set solve
            sticking: false,
            ..Default::default()
        };
        let one = NsgsSettings {
            max_iter: 1,
            ..s.clone()
        };
        let t_many = best_of(RUNS, || {
            black_box(solve_nsgs(&problem, &s).map(|r| r.iterations).ok());
        });
        let t_one = best_of(RUNS, || {
            black_box(solve_nsgs(&problem, &one).map(|r| r.iterations).ok());
        });
        // the setup and final measure cancel in the difference
        let per_sweep = (t_many - t_one) / (sweeps - 1) as f64;
        let tiles = w.nnz_blocks();
        let bytes = tiles * (9 * 8 + 8) + (nc + 1) * 8 + 2 * 3 * nc * 8;
        println!(
            "pile nc = {nc:6}: {:.1} tiles per row, {:6.1} ns per contact per sweep \
             (solve of {sweeps} sweeps {:.2} ms, of 1 sweep {:.3} ms); a sweep reads {:.1} MB: \
             {:.1} GB/s",
            tiles as f64 / nc as f64,
            per_sweep / nc as f64 * 1e9,
            t_many * 1e3,
            t_one * 1e3,
            bytes as f64 / 1e6,
            bytes as f64 / per_sweep / 1e9
        );
    }
    if chosen.is_empty() {
        bandwidth();
    }
}
