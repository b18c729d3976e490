//! Criterion benches of Lemke's method on dense SPD and contact-like PSD (J J^T) problems,
//! n = 10 .. 1000: `cargo bench --bench lemke`. End-to-end ratios against peers are measured
//! by `benches/peer_lcp.py`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::hint::black_box;
use std::time::Duration;

use coulomb::lcp::{solve_lemke_with, LcpRef, LemkeSettings, LemkeWorkspace};
use coulomb::testing::{dense_spd, planted_psd};

const SIZES: [usize; 5] = [10, 30, 100, 300, 1000];

fn bench_family(c: &mut Criterion, family: &str, make: impl Fn(usize) -> (Vec<f64>, Vec<f64>)) {
    let mut group = c.benchmark_group(family);
    for n in SIZES {
        let (m, q) = make(n);
        let lcp = match LcpRef::new(n, &m, &q) {
            Ok(l) => l,
            Err(e) => panic!("generator produced a bad problem: {e}"),
        };
        let settings = LemkeSettings::default();
        let mut ws = LemkeWorkspace::new(n);
        if n >= 300 {
            group.sample_size(10);
            group.measurement_time(Duration::from_secs(if n >= 1000 { 20 } else { 5 }));
        }
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                let s = solve_lemke_with(&mut ws, black_box(&lcp), &settings);
                black_box(s.map(|s| s.pivots).unwrap_or(0))
            })
        });
    }
    group.finish();
}

fn lemke(c: &mut Criterion) {
    bench_family(c, "lemke_dense_spd", |n| {
        let (m, q) = dense_spd(n, 1);
        (m.data, q)
    });
    bench_family(c, "lemke_contact_psd", |n| {
        let (m, q, _, _) = planted_psd(n, n / 2, 1);
        (m.data, q)
    });
}

criterion_group!(benches, lemke);
criterion_main!(benches);
