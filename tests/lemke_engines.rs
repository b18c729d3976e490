//! Lemke's two ways of keeping the basis inverse, the condensed tableau and the product form
//! (eta file), must follow the same lexicographic path where ties are clear and reach
//! answers that pass on the original data, including the product form's fold of a long eta
//! file into an explicit inverse and its refinement step.

mod common;

use common::data;
use coulomb::io::siconos::read_siconos_lcp;
use coulomb::lcp::{solve_lemke, LcpRef, LcpSolution, LemkeEngine, LemkeSettings};
use coulomb::testing::{dense_spd, max_rel_diff, murty, planted_psd};
use coulomb::DenseMatrix;

fn run(m: &DenseMatrix, q: &[f64], engine: LemkeEngine) -> LcpSolution {
    let lcp = LcpRef::from_dense(m, q).expect("well-formed test problem");
    let s = LemkeSettings {
        engine,
        ..Default::default()
    };
    solve_lemke(&lcp, &s).expect("valid settings")
}

/// dense SPD problems (unique solution, nondegenerate paths): the same pivots and the same z.
#[test]
fn product_form_follows_the_tableau_path_on_spd_problems() {
    for (k, n) in [16usize, 17, 40, 100, 230].into_iter().enumerate() {
        let (m, q) = dense_spd(n, 900 + k as u64);
        let t = run(&m, &q, LemkeEngine::Tableau);
        let p = run(&m, &q, LemkeEngine::ProductForm);
        assert!(
            t.success() && p.success(),
            "n {n}: {} / {}",
            t.message,
            p.message
        );
        assert_eq!(t.pivots, p.pivots, "n {n}");
        assert_eq!(t.basis, p.basis, "n {n}");
        assert!(max_rel_diff(&p.z, &t.z) <= 1e-10, "n {n}");
        assert!(p.measures.error <= 1e-12, "n {n}: {}", p.measures.error);
    }
}

/// Murty's problem takes 2^n pivots: far more than n, so the eta file is folded into an
/// explicit inverse many times (at 16 etas for these n) and the path must still be exact.
#[test]
fn product_form_folds_exactly_on_murtys_exponential_path() {
    for n in [5usize, 7, 9] {
        let (m, q) = murty(n);
        let lcp = LcpRef::from_dense(&m, &q).expect("well-formed");
        let s = LemkeSettings {
            engine: LemkeEngine::ProductForm,
            covering_vector: Some(vec![1.0; n]),
            max_pivots: Some(1 << (n + 1)),
            ..Default::default()
        };
        let p = solve_lemke(&lcp, &s).expect("valid settings");
        assert!(p.success(), "n {n}: {}", p.message);
        assert_eq!(p.pivots, 1 << n, "n {n}");
    }
}

/// Degenerate PSD problems with a planted solution: the default engine (product form with
/// the tableau as fallback) solves all of them, and w (unique for symmetric PSD M) is the
/// planted one.
#[test]
fn auto_engine_solves_planted_degenerate_problems() {
    for (k, &n) in [20usize, 64, 150, 300].iter().enumerate() {
        for rank in [n / 3 + 1, n / 2] {
            let seed = 300 + k as u64 * 11 + rank as u64;
            let (m, q, _z, w) = planted_psd(n, rank, seed);
            let s = run(&m, &q, LemkeEngine::Auto);
            assert!(s.success(), "n {n} rank {rank}: {}", s.message);
            assert!(s.measures.error <= 1e-10, "n {n}: {}", s.measures.error);
            assert!(
                max_rel_diff(&s.w, &w) <= 1e-8,
                "n {n} rank {rank}: w differs"
            );
        }
    }
}

/// The Siconos set under the default engine: what the tableau solves is solved, and what it
/// reports as a ray is not claimed solved.
#[test]
fn auto_engine_agrees_with_the_tableau_on_the_siconos_set() {
    let dir = data::shipped_dir("siconos-lcp");
    let entries = std::fs::read_dir(&dir).expect("readable data folder");
    let mut seen = 0;
    for entry in entries.flatten() {
        let path = entry.path();
        if path.extension().and_then(|e| e.to_str()) != Some("dat") {
            continue;
        }
        let p = read_siconos_lcp(&path).unwrap_or_else(|e| panic!("{e}"));
        let t = run(&p.m, &p.q, LemkeEngine::Tableau);
        let a = run(&p.m, &p.q, LemkeEngine::Auto);
        assert_eq!(
            t.success(),
            a.success(),
            "{}: {} / {}",
            path.display(),
            t.message,
            a.message
        );
        if a.success() {
            assert!(
                a.measures.error <= 1e-10,
                "{}: {}",
                path.display(),
                a.measures.error
            );
        }
        seen += 1;
    }
    assert!(seen == 20, "only {seen} Siconos LCP files read");
}
