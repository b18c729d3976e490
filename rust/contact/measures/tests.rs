//! Unit tests of the contact measures.

use super::*;
use crate::contact::ContactStatus;

#[test]
fn the_scaled_error_is_invariant_under_units_and_sees_a_huge_mu() {
    let mut rng = crate::testing::SplitMix64::new(3);
    for case in 0..300 {
        let dim = 2 + case % 2;
        let nc = 1 + case % 4;
        let n = dim * nc;
        let g: Vec<f64> = (0..n * n).map(|_| rng.normal()).collect();
        let mut w = vec![0.0; n * n];
        for a in 0..n {
            for b in 0..n {
                w[a * n + b] = (0..n).map(|k| g[k * n + a] * g[k * n + b]).sum();
            }
        }
        let q: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
        let r: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
        let mu: Vec<f64> = (0..nc)
            .map(|_| [0.0, 0.3, 2.0, 1e8][rng.below(4)])
            .collect();
        let p = ContactProblem::new(dim, &w, &q, &mu).unwrap();
        let (_, m) = measure(&p, &r).unwrap();
        for (a, b) in [(1e-8, 1e8), (1e8, 1.0), (1e-200, 1e-200), (1.0, 1e300)] {
            let ws: Vec<f64> = w.iter().map(|v| v * (b / a)).collect();
            let qs: Vec<f64> = q.iter().map(|v| v * b).collect();
            let rs: Vec<f64> = r.iter().map(|v| v * a).collect();
            let ps = ContactProblem::new(dim, &ws, &qs, &mu).unwrap();
            let (_, ms) = measure(&ps, &rs).unwrap();
            assert!(
                (ms.scaled_error - m.scaled_error).abs() <= 1e-12 * m.scaled_error,
                "case {case} units ({a}, {b}): {} vs {}",
                ms.scaled_error,
                m.scaled_error
            );
        }
    }
    // r = 0 for a contact that must push: De Saxce's map alone is 1e-8 of the data with
    // mu = 1e8; the unit-consistent measure sees it (Alart-Curnier's normal part)
    let w = [0.5, 0.0, 0.0, 0.5];
    let q = [-3.0, 1.0];
    for mu in [1e8, 1e12] {
        let mus = [mu];
        let p = ContactProblem::new(2, &w, &q, &mus).unwrap();
        let (_, m) = measure(&p, &[0.0, 0.0]).unwrap();
        // Signorini's part: |min(r_n, rho u_n)| = 6 against rho ||(|q|)|| = 2 sqrt(10)
        let expected = 6.0 / (2.0 * 10f64.sqrt());
        assert!(m.error < 1e-7, "{m:?}");
        assert!((m.scaled_error - expected).abs() < 1e-15, "{m:?}");
        let (_, m) = measure(&p, &[6.0, -2.0]).unwrap();
        assert_eq!(m.scaled_error, 0.0);
    }
}

#[test]
fn a_slip_at_the_rounding_of_its_terms_is_no_slip_whatever_mu() {
    // one sticking contact, r = (1, 0.5) and u = 0, with q_t off by `k` units of the
    // rounding of u_t's terms: De Saxce's normal term is then mu k eps, 1e-4 of the
    // impulse for mu = 1e12 and k = 1, though u_t cannot be formed any closer to 0
    let w = [1.0, 0.3, 0.3, 1.0];
    let r = [1.0, 0.5];
    let terms_t = 0.3 * 1.0 + 1.0 * 0.5 + 0.8;
    for (k, passes) in [(1.0, true), (4.0, true), (1e4, false)] {
        let q = [-1.15, -0.8 + k * f64::EPSILON * terms_t];
        for mu in [1.0, 1e8, 1e12] {
            let mus = [mu];
            let p = ContactProblem::new(2, &w, &q, &mus).unwrap();
            let (u, m) = measure(&p, &r).unwrap();
            assert!(u[1] != 0.0 && u[0].abs() < 1e-15);
            if passes {
                assert!(m.scaled_error < 1e-14, "k {k} mu {mu}: {m:?}");
            } else if mu >= 1e8 {
                // a slip 1e4 times its rounding is a slip: mu weighs it
                assert!(m.scaled_error > 1e-6, "k {k} mu {mu}: {m:?}");
            } else {
                assert!(m.scaled_error < 1e-11, "k {k} mu {mu}: {m:?}");
            }
        }
    }
}

#[test]
fn norms_neither_underflow_nor_overflow() {
    for s in [1e-300, 1e-200, 1.0, 1e200, 1e300] {
        let x = [3.0 * s, 4.0 * s];
        assert!((norm2(&x) - 5.0 * s).abs() <= 1e-15 * 5.0 * s, "{s}");
    }
    assert!(norm2(&[f64::NAN, 1.0]).is_nan());
    assert_eq!(norm2(&[f64::INFINITY, 1.0]), f64::INFINITY);
    assert_eq!(norm2(&[0.0, -0.0]), 0.0);
    // r = 0 for the chapter's inelastic step at 1e-200: measured as at scale 1, not as 0
    let (w, q) = ([0.5e-200, 0.0, 0.0, 0.5e-200], [-3e-200, 1e-200]);
    let p = ContactProblem::new(2, &w, &q, &[0.2]).unwrap();
    let (_, m) = measure(&p, &[0.0, 0.0]).unwrap();
    assert!(
        (m.scaled_error - 6.0 / (2.0 * 10f64.sqrt())).abs() < 1e-15,
        "{m:?}"
    );
    assert!(m.error_q > 0.5, "{m:?}");
}

#[test]
fn measures_of_the_chapter_answer_and_of_zero() {
    let w = [0.5, 0.0, 0.0, 0.5];
    let q = [-3.0, 1.0];
    let p = ContactProblem::new(2, &w, &q, &[0.2]).unwrap();
    let (u, m) = measure(&p, &[6.0, -1.2]).unwrap();
    assert!((u[0]).abs() < 1e-15 && (u[1] - 0.4).abs() < 1e-15);
    assert!(m.error < 1e-15, "{m:?}");
    assert_eq!(m.dissipation_violation, 0.0);
    // r = 0: u = q, residual r - P_K(-(q + mu |q_t| n)) = -P_K((2.8, -1)), outside K and
    // its polar: n' = (2.8 + 0.2) / 1.04, |t'| = 0.2 n', norm 3 / sqrt(1.04)
    let (_, m) = measure(&p, &[0.0, 0.0]).unwrap();
    let expected = 3.0 / 1.04f64.sqrt() / 10f64.sqrt();
    assert!(
        (m.error - expected).abs() < 1e-14,
        "{} vs {expected}",
        m.error
    );
    assert_eq!(m.error, m.error_q);
    // a sliding impulse along the slip is flagged
    let (_, m) = measure(&p, &[6.0, 1.2]).unwrap();
    assert!(m.dissipation_violation > 1.0);
    assert!(measure(&p, &[1.0]).is_err());
    assert_eq!(ContactStatus::IterationLimit.as_str(), "iteration_limit");
}
