//! Lemke's method on small problems with known answers, rays and degenerate paths.
use super::*;

fn lemke(n: usize, m: &[f64], q: &[f64]) -> LcpSolution {
    let lcp = LcpRef::new(n, m, q).unwrap();
    solve_lemke(&lcp, &LemkeSettings::default()).unwrap()
}

/// the solve skips measuring z = 0 when some q_i < 0: its scaled error is then exactly 1,
/// at every scale of q, so it passes no tol below 1.
#[test]
fn z_zero_with_a_negative_q_has_scaled_error_one() {
    let m = [2.0, 1.0, 0.0, 1.0, 3.0, 1.0, 0.0, 1.0, 4.0];
    for scale in [1e-300, 1e-20, 1e-8, 1.0, 1e8, 1e300] {
        for q in [[-1.0, 2.0, 3.0], [5.0, -1e-12, 0.0], [-3.0, -4.0, -1e-9]] {
            let q = q.map(|v| v * scale);
            let lcp = LcpRef::new(3, &m, &q).unwrap();
            let eq = Equilibration::compute(3, &m, &q);
            assert_eq!(lcp.measures_at_zero(&eq).scaled_error, 1.0, "{q:?}");
            let s = solve_lemke(&lcp, &LemkeSettings::default()).unwrap();
            assert!(s.success() && s.pivots > 0, "{q:?}: {}", s.message);
        }
    }
}

#[test]
fn chapter_scalar_lcp_w_equals_2z_minus_6() {
    let s = lemke(1, &[2.0], &[-6.0]);
    assert_eq!(s.status, LcpStatus::Solved);
    assert!((s.z[0] - 3.0).abs() < 1e-14);
    assert!(s.w[0].abs() < 1e-14);
}

#[test]
fn chapter_scalar_lcp_w_equals_minus_z_minus_1_has_no_solution() {
    let s = lemke(1, &[-1.0], &[-1.0]);
    assert_eq!(s.status, LcpStatus::RayTermination);
    assert!(!s.success());
}

#[test]
fn nonnegative_q_needs_no_pivot() {
    let s = lemke(2, &[1.0, 0.0, 0.0, 1.0], &[0.0, 3.0]);
    assert!(s.success());
    assert_eq!(s.pivots, 0);
    assert_eq!(s.z, vec![0.0, 0.0]);
}

#[test]
fn warm_start_with_the_right_basis_makes_no_pivot() {
    let m = [2.0, 1.0, 1.0, 2.0];
    let q = [-3.0, -3.0];
    let cold = lemke(2, &m, &q);
    assert!(cold.success());
    let lcp = LcpRef::new(2, &m, &q).unwrap();
    let s = LemkeSettings {
        warm_start: Some(cold.basis.clone()),
        ..Default::default()
    };
    let warm = solve_lemke(&lcp, &s).unwrap();
    assert_eq!(warm.warm_start, WarmStart::Accepted);
    assert_eq!(warm.pivots, 0);
    assert!(warm.pivots_saved >= 3);
    for (a, b) in warm.z.iter().zip(&cold.z) {
        assert!((a - b).abs() < 1e-12);
    }
    let bad = LemkeSettings {
        warm_start: Some(vec![]),
        ..Default::default()
    };
    let fallback = solve_lemke(&lcp, &bad).unwrap();
    assert_eq!(fallback.warm_start, WarmStart::Rejected);
    assert!(fallback.success());
}

#[test]
fn bad_settings_are_refused() {
    let lcp = LcpRef::new(1, &[1.0], &[-1.0]).unwrap();
    for s in [
        LemkeSettings {
            tol: 0.0,
            ..Default::default()
        },
        LemkeSettings {
            covering_vector: Some(vec![-1.0]),
            ..Default::default()
        },
        LemkeSettings {
            warm_start: Some(vec![3]),
            ..Default::default()
        },
    ] {
        assert!(solve_lemke(&lcp, &s).is_err());
    }
}
