//! Criterion benches of the contact solvers on a realistic sparse W (a pile of rigid bodies,
//! `W = G^T M^-1 G`, a few 3 x 3 tiles per block row; see tests/pile/mod.rs):
//! `cargo bench --bench contact`.
//!
//! - `nsgs_sweeps/{sparse,dense}/nc`: 10 NSGS sweeps (a tolerance no iterate reaches, so
//!   exactly 10), nc = 10 .. 5000 block-sparse and nc = 10 .. 1000 dense (at nc = 5000 the
//!   dense W would be 15000^2 doubles, 1.8 GB). Divide by 10 for one sweep.
//! - `polyhedral_lemke/nc`: the Stewart-Trinkle LCP with 8 facets (nc (1 + 8 + 1) dense LCP
//!   unknowns) assembled and solved by Lemke, nc = 10, 30, 100 (at nc = 1000 the tableau would
//!   have 10^8 entries and O(n^3) work: not feasible).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::hint::black_box;
use std::time::Duration;

use coulomb::contact::{
    solve_nsgs, solve_polyhedral, BlockCsr, ContactProblem, NsgsSettings, PolyhedralSettings,
};

#[path = "../tests/pile/mod.rs"]
mod pile;

const SWEEPS: usize = 10;

fn settings() -> NsgsSettings {
    NsgsSettings {
        tol: 1e-300,
        max_iter: SWEEPS,
        // plain sweeps: the cost of one sweep, not of a sticking-set solve
        sticking: false,
        ..Default::default()
    }
}

fn nsgs_sweeps(c: &mut Criterion) {
    let mut group = c.benchmark_group("nsgs_sweeps");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(300));
    group.measurement_time(Duration::from_secs(2));
    for nc in [10, 100, 1000, 5000] {
        let p = pile::pile(nc, 0.4, 1);
        let w = match BlockCsr::from_coo(3, p.n, &p.rows, &p.cols, &p.vals) {
            Ok(w) => w,
            Err(e) => panic!("bad pile: {e}"),
        };
        println!(
            "pile nc = {nc}: {} tiles ({:.1} per block row)",
            w.nnz_blocks(),
            w.nnz_blocks() as f64 / nc as f64
        );
        let problem = match ContactProblem::with_block_sparse(&w, &p.q, &p.mu) {
            Ok(pr) => pr,
            Err(e) => panic!("bad pile: {e}"),
        };
        let s = settings();
        group.bench_with_input(BenchmarkId::new("sparse", nc), &nc, |b, _| {
            b.iter(|| black_box(solve_nsgs(black_box(&problem), &s).map(|r| r.iterations)))
        });
        if nc <= 1000 {
            let dense = w.to_dense();
            let problem = match ContactProblem::new(3, &dense, &p.q, &p.mu) {
                Ok(pr) => pr,
                Err(e) => panic!("bad pile: {e}"),
            };
            group.bench_with_input(BenchmarkId::new("dense", nc), &nc, |b, _| {
                b.iter(|| black_box(solve_nsgs(black_box(&problem), &s).map(|r| r.iterations)))
            });
        }
    }
    group.finish();
}

fn polyhedral_lemke(c: &mut Criterion) {
    let mut group = c.benchmark_group("polyhedral_lemke");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(300));
    group.measurement_time(Duration::from_secs(3));
    for nc in [10, 30, 100] {
        let p = pile::pile(nc, 0.4, 1);
        let w = match BlockCsr::from_coo(3, p.n, &p.rows, &p.cols, &p.vals) {
            Ok(w) => w,
            Err(e) => panic!("bad pile: {e}"),
        };
        let problem = match ContactProblem::with_block_sparse(&w, &p.q, &p.mu) {
            Ok(pr) => pr,
            Err(e) => panic!("bad pile: {e}"),
        };
        let s = PolyhedralSettings::for_dim(3);
        if let Ok(r) = solve_polyhedral(&problem, &s) {
            println!(
                "polyhedral nc = {nc}: {} ({} pivots, disk error {:.1e})",
                r.status, r.iterations, r.measures.error
            );
        }
        group.bench_with_input(BenchmarkId::from_parameter(nc), &nc, |b, _| {
            b.iter(|| black_box(solve_polyhedral(black_box(&problem), &s).map(|r| r.iterations)))
        });
    }
    group.finish();
}

criterion_group!(benches, nsgs_sweeps, polyhedral_lemke);
criterion_main!(benches);
