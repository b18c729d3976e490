//! Unit tests of `polyhedral.rs`.

use super::*;
use crate::contact::ContactStatus;

#[test]
fn the_chapter_lcp_is_assembled_as_on_the_slide() {
    let w = [0.5, 0.0, 0.0, 0.5];
    let q = [-3.0, 1.0];
    let p = ContactProblem::new(2, &w, &q, &[0.2]).unwrap();
    let lcp = PolyhedralLcp::new(&p, 2).unwrap();
    assert_eq!(lcp.n, 4);
    // the slide's matrix with λ's column and row scaled by c = W_nn = 0.5 (balanced
    // units, see the module notes)
    #[rustfmt::skip]
    let a = [
        0.5, 0.0, 0.0, 0.0,
        0.0, 0.5, -0.5, 0.5,
        0.0, -0.5, 0.5, 0.5,
        0.1, -0.5, -0.5, 0.0,
    ];
    assert_eq!(lcp.m, a);
    assert_eq!(lcp.q, [-3.0, 1.0, -1.0, 0.0]);
    assert_eq!(lcp.lambda_index(0), Some(3));
    assert_eq!(lcp.impulses(&[6.0, 0.0, 1.2, 0.8]), vec![6.0, -1.2]);
    assert_eq!(lcp.slip_speed(0, &[6.0, 0.0, 1.2, 0.8]), Some(0.4));
}

#[test]
fn frictionless_contacts_have_only_a_normal_unknown() {
    let w: Vec<f64> = (0..36)
        .map(|k| if k % 7 == 0 { 1.0 } else { 0.0 })
        .collect();
    let q = [-1.0, 0.5, 0.0, -1.0, 0.5, 0.0];
    let p = ContactProblem::new(3, &w, &q, &[0.0, 0.3]).unwrap();
    let lcp = PolyhedralLcp::new(&p, 4).unwrap();
    assert_eq!(lcp.n, 2 + 4 + 1);
    assert!(lcp.beta_range(0).is_empty() && lcp.lambda_index(0).is_none());
    assert_eq!(lcp.beta_range(1), 2..6);
}

#[test]
fn a_separating_contact_is_solved_by_r_zero_at_every_scale() {
    // one 3D contact with q_n > 0 and a rank-one W (a property-campaign problem: Lemke's
    // path solved it in 5 pivots as given and ended on a ray with W and q times 1.5)
    let w = [
        0.001948617127454721,
        -0.004570668695008731,
        -0.007923598007756147,
        -0.004570668695008731,
        0.010720942572654385,
        0.018585560424171164,
        -0.007923598007756147,
        0.018585560424171164,
        0.032219467079469176,
    ];
    let q = [
        7.730056310357876e-5,
        -0.5800086400240654,
        -0.03566910061094476,
    ];
    for c in [1.0, 1.5, 0.75, 3.0, 1e8, 1e-8] {
        let wc: Vec<f64> = w.iter().map(|x| x * c).collect();
        let qc: Vec<f64> = q.iter().map(|x| x * c).collect();
        let p = ContactProblem::new(3, &wc, &qc, &[0.5]).unwrap();
        let (sol, lcp, ls) = solve_polyhedral_lcp(&p, &PolyhedralSettings::for_dim(3)).unwrap();
        assert_eq!(sol.status, ContactStatus::Solved, "{c}: {}", sol.message);
        assert_eq!(sol.impulse, vec![0.0; 3]);
        assert_eq!(ls.pivots, 0);
        // the LCP's w = A z + b is >= 0 and complementary to z, exactly
        let l = lcp.lambda_index(0).unwrap();
        assert!(ls.z[l] > 0.0 && ls.w[l] == 0.0);
        assert!(ls.w.iter().all(|&x| x >= 0.0), "{:?}", ls.w);
        assert!(ls.z.iter().zip(&ls.w).all(|(a, b)| a * b == 0.0));
    }
    // a contact that approaches is not taken for separated
    let p = ContactProblem::new(3, &w, &[-1e-3, 0.1, 0.0], &[0.5]).unwrap();
    let (sol, _, ls) = solve_polyhedral_lcp(&p, &PolyhedralSettings::for_dim(3)).unwrap();
    assert!(ls.pivots > 0 || sol.impulse[0] > 0.0, "{}", sol.message);
}

#[test]
fn bad_facets_are_refused() {
    let w = [0.5, 0.0, 0.0, 0.5];
    let p = ContactProblem::new(2, &w, &[-3.0, 1.0], &[0.2]).unwrap();
    assert!(matches!(
        PolyhedralLcp::new(&p, 4),
        Err(CoulombError::InvalidParameter(_))
    ));
    let w3: Vec<f64> = (0..9).map(|k| if k % 4 == 0 { 0.5 } else { 0.0 }).collect();
    let p = ContactProblem::new(3, &w3, &[-3.0, 1.0, 0.0], &[0.2]).unwrap();
    for s in [0, 2, 5, 7] {
        assert!(matches!(
            PolyhedralLcp::new(&p, s),
            Err(CoulombError::InvalidParameter(_))
        ));
    }
    assert!(PolyhedralLcp::new(&p, 6).is_ok());
}

/// Lemke's verdict (shared by `contact::solve` and the stepper) on the seed's inelastic step,
/// `W = I / 2`, `q = (-3, 1)`, mu 0.2, whose answer is r = (6, -1.2): the exact answer passes
/// in both dims whatever Lemke said; a wrong answer after a solved LCP is a numerical failure
/// in 2D (the interval is the problem) but Lemke's own solved status in 3D (the polygon's
/// answer); after a failed LCP it is Lemke's pivot limit or a numerical failure.
#[test]
fn lemke_verdict_follows_the_exact_rule_in_2d_and_the_polygon_in_3d() {
    let w = [0.5, 0.0, 0.0, 0.5];
    let q = [-3.0, 1.0];
    let p = ContactProblem::new(2, &w, &q, &[0.2]).unwrap();
    let mut u = vec![0.0; 2];
    let exact = measure_into(&p, &[6.0, -1.2], &mut u);
    let wrong = measure_into(&p, &[6.0, 0.0], &mut u);
    assert!(exact.passes(1e-12) && !wrong.passes(1e-3));
    let verdict = |dim, status, m: &super::super::ContactMeasures| {
        let v = LemkeVerdict::of(dim, status, m, 1e-12);
        (v, v.status())
    };
    for dim in [2, 3] {
        for status in [
            LcpStatus::Solved,
            LcpStatus::PivotLimit,
            LcpStatus::NumericalFailure,
        ] {
            let (_, s) = verdict(dim, status, &exact);
            assert_eq!(s, ContactStatus::Solved, "{dim} {status:?}");
        }
    }
    assert_eq!(
        verdict(2, LcpStatus::Solved, &wrong),
        (
            LemkeVerdict::MissesTheInterval,
            ContactStatus::NumericalFailure
        )
    );
    assert_eq!(
        verdict(3, LcpStatus::Solved, &wrong),
        (LemkeVerdict::Solved, ContactStatus::Solved)
    );
    assert_eq!(
        verdict(2, LcpStatus::PivotLimit, &wrong),
        (LemkeVerdict::PivotLimit, ContactStatus::IterationLimit)
    );
    assert_eq!(
        verdict(3, LcpStatus::NumericalFailure, &wrong).1,
        ContactStatus::NumericalFailure
    );
}
