//! Integration tests of the LCP solvers: the seed's figures, the Siconos set, oracles
//! (enumeration, planted solutions, Murty's pivot count) and invariance under scaling.

mod common;

use common::data;
use coulomb::io::siconos::read_siconos_lcp;
use coulomb::lcp::{
    solve_enumerate, solve_lemke, solve_pgs, EnumerateSettings, LcpRef, LcpSolution, LcpStatus,
    LemkeSettings, PgsSettings,
};
use coulomb::testing::{dense_spd, max_rel_diff, murty, p_matrix, planted_psd, SplitMix64};
use coulomb::DenseMatrix;

fn lemke(m: &DenseMatrix, q: &[f64]) -> LcpSolution {
    let lcp = LcpRef::from_dense(m, q).expect("well-formed test problem");
    solve_lemke(&lcp, &LemkeSettings::default()).expect("valid settings")
}

fn lemke_with(m: &DenseMatrix, q: &[f64], s: &LemkeSettings) -> LcpSolution {
    let lcp = LcpRef::from_dense(m, q).expect("well-formed test problem");
    solve_lemke(&lcp, s).expect("valid settings")
}

fn enumerate(m: &DenseMatrix, q: &[f64]) -> LcpSolution {
    let lcp = LcpRef::from_dense(m, q).expect("well-formed test problem");
    solve_enumerate(&lcp, &EnumerateSettings::default()).expect("small problem")
}

/// The seed's scalar LCPs: w = 2z - 6 has z = 3, w = 0; w = -z - 1 has no solution.
#[test]
fn seed_scalar_problems() {
    let s = lemke(&DenseMatrix::from_fn(1, 1, |_, _| 2.0), &[-6.0]);
    assert!(s.success());
    assert_eq!(s.z, vec![3.0]);
    assert_eq!(s.w, vec![0.0]);
    let s = lemke(&DenseMatrix::from_fn(1, 1, |_, _| -1.0), &[-1.0]);
    assert_eq!(s.status, LcpStatus::RayTermination);
    assert!(!s.success());
}

/// Every Siconos problem with a solution (by enumeration, or known: mmc is SPD, tobenna is
/// solved by exact-arithmetic Lemke in 127 pivots) is solved to 1e-10; the ones without never
/// report success.
#[test]
fn siconos_lcp_set() {
    let mut paths: Vec<_> = std::fs::read_dir(data::shipped_dir("siconos-lcp"))
        .expect("readable data folder")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "dat"))
        .collect();
    paths.sort();
    assert_eq!(paths.len(), 20);
    for p in paths {
        let name = p
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("?")
            .to_string();
        let prob = read_siconos_lcp(&p).expect("readable problem");
        let s = lemke(&prob.m, &prob.q);
        let has_solution = if prob.m.nrows <= 15 {
            enumerate(&prob.m, &prob.q).success()
        } else {
            true
        };
        if has_solution && name != "lcp_CPS_3" {
            assert!(s.success(), "{name}: {}", s.message);
            assert!(
                s.measures.error <= 1e-10,
                "{name}: error {}",
                s.measures.error
            );
        } else {
            assert!(!s.success(), "{name}: false success");
            assert_eq!(s.status, LcpStatus::RayTermination, "{name}");
        }
    }
}

/// CPS_3 (a bimatrix game: not copositive-plus) has solutions but Lemke's theory allows a ray;
/// whatever covering vectors are tried, the result must never claim success falsely.
#[test]
fn cps3_reports_its_ray_honestly() {
    let prob = read_siconos_lcp(&data::file("siconos-lcp", "lcp_CPS_3.dat")).expect("readable");
    assert!(enumerate(&prob.m, &prob.q).success());
    let s = lemke(&prob.m, &prob.q);
    if s.success() {
        assert!(s.measures.error <= 1e-10);
    } else {
        assert_eq!(s.status, LcpStatus::RayTermination);
        assert!(s.measures.error > 1e-3);
    }
}

/// Murty's exponential example: exactly 2^n pivots with the textbook covering vector.
#[test]
fn murty_takes_two_to_the_n_pivots() {
    for n in 2..=10 {
        let (m, q) = murty(n);
        let s = lemke_with(
            &m,
            &q,
            &LemkeSettings {
                covering_vector: Some(vec![1.0; n]),
                max_pivots: Some(1 << (n + 1)),
                ..Default::default()
            },
        );
        assert!(s.success(), "n = {n}: {}", s.message);
        assert_eq!(s.pivots, 1 << n, "n = {n}");
    }
    // the same example as a Siconos file (n = 6)
    let prob =
        read_siconos_lcp(&data::file("siconos-lcp", "lcp_exp_murty2.dat")).expect("readable");
    let s = lemke_with(
        &prob.m,
        &prob.q,
        &LemkeSettings {
            covering_vector: Some(vec![1.0; 6]),
            ..Default::default()
        },
    );
    assert_eq!(s.pivots, 64);
}

/// For P-matrices the solution is unique: Lemke's equals enumeration's.
#[test]
fn p_matrix_problems_match_enumeration() {
    for seed in 0..60u64 {
        let n = 1 + (seed as usize % 10);
        let (m, q) = p_matrix(n, (seed % 2) as u32, seed);
        let e = enumerate(&m, &q);
        assert_eq!(e.solutions.len(), 1, "seed {seed}");
        let s = lemke(&m, &q);
        assert!(s.success(), "seed {seed}: {}", s.message);
        assert!(max_rel_diff(&s.z, &e.z) <= 1e-10, "seed {seed}");
    }
}

/// Degenerate PSD problems M = J J^T with a planted solution: all solved, and w (unique for
/// symmetric PSD M) equals the planted w*.
#[test]
fn planted_degenerate_psd_problems() {
    for (k, &n) in [5usize, 30, 100, 300].iter().enumerate() {
        for rank in [n / 3 + 1, n / 2] {
            let seed = 100 + k as u64 * 7 + rank as u64;
            let (m, q, _z, w) = planted_psd(n, rank, seed);
            let s = lemke(&m, &q);
            assert!(s.success(), "n {n} rank {rank}: {}", s.message);
            assert!(s.measures.error <= 1e-10, "n {n}: {}", s.measures.error);
            assert!(max_rel_diff(&s.w, &w) <= 1e-8, "n {n}: w differs");
        }
    }
}

fn scaled(m: &DenseMatrix, q: &[f64], r: &[f64], c: &[f64]) -> (DenseMatrix, Vec<f64>) {
    let n = q.len();
    let ms = DenseMatrix::from_fn(n, n, |i, j| r[i] * m.get(i, j) * c[j]);
    let qs = (0..n).map(|i| r[i] * q[i]).collect();
    (ms, qs)
}

/// The answer does not change when M and q are scaled by 1e-8 or 1e8, or rows and columns by
/// 10^k, |k| <= 6: M' = R M C, q' = R q has z = C z'.
#[test]
fn answers_are_invariant_under_scaling() {
    let mut rng = SplitMix64::new(7);
    let mut problems = Vec::new();
    for seed in 0..12u64 {
        let (m, q) = p_matrix(3 + seed as usize % 8, (seed % 2) as u32, seed + 1000);
        problems.push((m, q, None));
    }
    for seed in 0..4u64 {
        let (m, q, _, w) = planted_psd(40, 15, seed + 2000);
        problems.push((m, q, Some(w)));
    }
    for (m, q, planted_w) in &problems {
        let n = q.len();
        let base = lemke(m, q);
        assert!(base.success());
        let ones = vec![1.0; n];
        let mut cases: Vec<(Vec<f64>, Vec<f64>)> =
            vec![(vec![1e-8; n], ones.clone()), (vec![1e8; n], ones.clone())];
        for _ in 0..3 {
            let r = (0..n)
                .map(|_| 10f64.powi(rng.below(13) as i32 - 6))
                .collect();
            let c = (0..n)
                .map(|_| 10f64.powi(rng.below(13) as i32 - 6))
                .collect();
            cases.push((r, c));
        }
        for (r, c) in cases {
            let (ms, qs) = scaled(m, q, &r, &c);
            let s = lemke(&ms, &qs);
            assert!(s.success(), "scaled: {}", s.message);
            let z: Vec<f64> = (0..n).map(|j| c[j] * s.z[j]).collect();
            let w: Vec<f64> = (0..n).map(|i| s.w[i] / r[i]).collect();
            match planted_w {
                None => assert!(max_rel_diff(&z, &base.z) <= 1e-8, "z changed under scaling"),
                Some(pw) => assert!(max_rel_diff(&w, pw) <= 1e-7, "w changed under scaling"),
            }
        }
    }
}

/// PGS reaches Lemke's answer on SPD problems and is honest when stopped early.
#[test]
fn pgs_agrees_with_lemke_on_spd_problems() {
    for seed in 0..5u64 {
        let (m, q) = dense_spd(30, seed);
        let exact = lemke(&m, &q);
        let lcp = LcpRef::from_dense(&m, &q).expect("well-formed");
        let s = solve_pgs(
            &lcp,
            &PgsSettings {
                tol: 1e-12,
                ..Default::default()
            },
        )
        .expect("valid settings");
        assert!(s.success(), "{}", s.message);
        assert!(max_rel_diff(&s.z, &exact.z) <= 1e-9);
        let early = solve_pgs(
            &lcp,
            &PgsSettings {
                max_iter: 1,
                tol: 1e-14,
                ..Default::default()
            },
        )
        .expect("valid settings");
        assert_eq!(early.status, LcpStatus::IterationLimit);
        assert!(early.measures.error > 1e-14);
    }
}

/// A warm start from the previous solve's basis makes no pivot when the active set persists.
#[test]
fn warm_start_from_the_previous_basis() {
    let (m, q, _, _) = planted_psd(200, 80, 11);
    let cold = lemke(&m, &q);
    assert!(cold.success());
    let q2: Vec<f64> = q.iter().map(|v| v * (1.0 + 1e-6)).collect();
    let warm = lemke_with(
        &m,
        &q2,
        &LemkeSettings {
            warm_start: Some(cold.basis.clone()),
            ..Default::default()
        },
    );
    assert!(warm.success());
    assert_eq!(warm.pivots, 0);
    let cold2 = lemke(&m, &q2);
    assert!(warm.pivots_saved <= cold2.pivots);
    assert!(max_rel_diff(&warm.w, &cold2.w) <= 1e-9);
}
