//! Regression tests of issue 11's reproductions at the Rust level: the polyhedral LCP keeps
//! friction at small scale, a huge mu still pushes, extreme scales are solved and measured,
//! and the LCP measures neither overflow nor underflow.

use coulomb::contact::prox::ProxSettings;
use coulomb::contact::{
    measure, solve, solve_nsgs, solve_polyhedral, ContactProblem, Method, NsgsSettings,
    PolyhedralSettings,
};
use coulomb::lcp::{solve_enumerate, solve_lemke, EnumerateSettings, LcpRef, LemkeSettings};

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.iter()
        .zip(b)
        .all(|(x, y)| (x - y).abs() <= tol * y.abs().max(1.0))
}

#[test]
fn the_polyhedral_lcp_keeps_friction_at_small_scale() {
    // the seed's inelastic step scaled by 1e-10 gave r = (6, 0) with success
    for s in [1.0, 1e-10, 1e-150] {
        for dim in [2, 3] {
            let mut w = vec![0.0; dim * dim];
            for k in 0..dim {
                w[k * dim + k] = 0.5 * s;
            }
            let q: Vec<f64> = [-3.0 * s, 1.0 * s, 0.0][..dim].to_vec();
            let p = ContactProblem::new(dim, &w, &q, &[0.2]).unwrap();
            let mut settings = PolyhedralSettings::for_dim(dim);
            settings.facets = if dim == 2 { 2 } else { 4 };
            let out = solve_polyhedral(&p, &settings).unwrap();
            assert!(out.success(), "{}", out.message);
            assert!(
                close(&out.impulse, &[6.0, -1.2, 0.0][..dim], 1e-12),
                "scale {s} dim {dim}: {:?}",
                out.impulse
            );
        }
    }
}

#[test]
fn a_sticking_contact_with_a_huge_mu_pushes() {
    let (w, q) = ([0.5, 0.0, 0.0, 0.5], [-3.0, 1.0]);
    for mu in [1e8, 1e12] {
        let mus = [mu];
        let p = ContactProblem::new(2, &w, &q, &mus).unwrap();
        let out = solve_nsgs(&p, &NsgsSettings::default()).unwrap();
        assert!(
            out.success() && close(&out.impulse, &[6.0, -2.0], 1e-12),
            "{out:?}"
        );
        // r = 0 is not a solution, whatever De Saxce's map says
        let (_, m) = measure(&p, &[0.0, 0.0]).unwrap();
        assert!(!m.passes(1e-8) && m.error_q < 1e-7, "{m:?}");
    }
}

#[test]
fn every_method_solves_the_seed_step_at_extreme_scales() {
    for s in [1e-200, 1e-20, 1e300] {
        let (w, q) = ([0.5 * s, 0.0, 0.0, 0.5 * s], [-3.0 * s, 1.0 * s]);
        let p = ContactProblem::new(2, &w, &q, &[0.2]).unwrap();
        for m in [
            Method::Nsgs(NsgsSettings::default()),
            Method::Prox(ProxSettings::default()),
            Method::Polyhedral(PolyhedralSettings::for_dim(2)),
        ] {
            let out = solve(&p, &m).unwrap();
            assert!(out.success(), "scale {s}: {}", out.message);
            assert!(close(&out.impulse, &[6.0, -1.2], 1e-8), "{:?}", out.impulse);
            assert!(out.measures.error.is_finite() && out.measures.error_q.is_finite());
        }
    }
}

#[test]
fn lcp_measures_neither_overflow_nor_underflow() {
    let (m, q) = coulomb::testing::dense_spd(6, 5);
    let n = 6;
    let md: Vec<f64> = (0..n * n).map(|k| m.get(k / n, k % n)).collect();
    let base = solve_enumerate(
        &LcpRef::new(n, &md, &q).unwrap(),
        &EnumerateSettings::default(),
    )
    .unwrap();
    for s in [1e-200, 1e200, 1e300] {
        let ms: Vec<f64> = md.iter().map(|v| v * s).collect();
        let qs: Vec<f64> = q.iter().map(|v| v * s).collect();
        let lcp = LcpRef::new(n, &ms, &qs).unwrap();
        let e = solve_enumerate(&lcp, &EnumerateSettings::default()).unwrap();
        let l = solve_lemke(&lcp, &LemkeSettings::default()).unwrap();
        for out in [&e, &l] {
            assert_eq!(out.status, base.status, "scale {s}: {}", out.message);
            assert!(
                out.measures.error.is_finite(),
                "scale {s}: {:?}",
                out.measures
            );
            assert!(close(&out.z, &base.z, 1e-9), "scale {s}");
        }
    }
}
