//! Integration tests of the polyhedral-cone (Stewart-Trinkle) contact LCP solved by Lemke: the
//! seed's inelastic step (exact in 2D, and in 3D when the slip lies along a facet), sticking,
//! convergence to the exact friction disk as the facets grow, redundant contacts (a box on
//! four corners) against NSGS, and bad settings.

use coulomb::contact::polyhedral::solve_polyhedral_lcp;
use coulomb::contact::{
    solve_nsgs, solve_polyhedral, ContactProblem, ContactSolution, NsgsSettings, PolyhedralSettings,
};
use coulomb::CoulombError;

mod common;
use common::{cube_g, delassus, post_velocity};

fn settings(facets: usize) -> PolyhedralSettings {
    PolyhedralSettings {
        facets,
        ..PolyhedralSettings::for_dim(3)
    }
}

fn lemke(dim: usize, w: &[f64], q: &[f64], mu: &[f64], facets: usize) -> ContactSolution {
    let p = ContactProblem::new(dim, w, q, mu).expect("well-formed test problem");
    solve_polyhedral(&p, &settings(facets)).expect("valid settings")
}

fn nsgs(dim: usize, w: &[f64], q: &[f64], mu: &[f64]) -> ContactSolution {
    let p = ContactProblem::new(dim, w, q, mu).expect("well-formed test problem");
    let s = NsgsSettings {
        tol: 1e-13,
        max_iter: 10_000,
        ..Default::default()
    };
    solve_nsgs(&p, &s).expect("valid settings")
}

fn identity_over(m: f64, n: usize) -> Vec<f64> {
    let mut w = vec![0.0; n * n];
    for i in 0..n {
        w[i * n + i] = 1.0 / m;
    }
    w
}

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

// --- the seed's inelastic contact step -------------------------------------------------

#[test]
fn seed_inelastic_step_2d_with_its_multiplier() {
    let w = identity_over(2.0, 2);
    let q = [-3.0, 1.0];
    let p = ContactProblem::new(2, &w, &q, &[0.2]).unwrap();
    let (s, lcp, ls) = solve_polyhedral_lcp(&p, &PolyhedralSettings::for_dim(2)).unwrap();
    assert!(s.success(), "{}", s.message);
    println!("seed 2D: {}", s.message);
    assert!((s.impulse[0] - 6.0).abs() < 1e-10, "P_n = {}", s.impulse[0]);
    assert!((s.impulse[1] + 1.2).abs() < 1e-10, "P_t = {}", s.impulse[1]);
    assert!(s.velocity[0].abs() < 1e-10);
    assert!(
        (s.velocity[1] - 0.4).abs() < 1e-10,
        "u_t = {}",
        s.velocity[1]
    );
    let lambda = lcp.slip_speed(0, &ls.z).unwrap();
    assert!((lambda - 0.4).abs() < 1e-10, "lambda = {lambda}");
    let t_after = 0.5 * 2.0 * (s.velocity[0].powi(2) + s.velocity[1].powi(2));
    assert!((t_after - 0.16).abs() < 1e-10, "T after = {t_after}");
    // exact in 2D: the disk measure is zero and the answer is NSGS's
    assert!(s.measures.error < 1e-12, "{:?}", s.measures);
    assert!(s.iterations > 0);
    let n = nsgs(2, &w, &q, &[0.2]);
    assert!(close(&s.impulse, &n.impulse, 1e-10) && close(&s.velocity, &n.velocity, 1e-10));
}

#[test]
fn seed_inelastic_step_3d_along_a_facet() {
    // the slip (1, 0) is the facet direction d_0 for every even s: exact
    let w = identity_over(2.0, 3);
    let q = [-3.0, 1.0, 0.0];
    for facets in [4, 8, 16] {
        let s = lemke(3, &w, &q, &[0.2], facets);
        assert!(s.success(), "{}", s.message);
        assert!(
            close(&s.impulse, &[6.0, -1.2, 0.0], 1e-10),
            "{:?}",
            s.impulse
        );
        assert!(
            close(&s.velocity, &[0.0, 0.4, 0.0], 1e-10),
            "{:?}",
            s.velocity
        );
    }
}

#[test]
fn sticking_with_large_friction() {
    let w = identity_over(2.0, 2);
    let s = lemke(2, &w, &[-3.0, 1.0], &[0.6], 2);
    assert!(s.success(), "{}", s.message);
    assert!(s.velocity[1].abs() < 1e-10 && s.velocity[0].abs() < 1e-10);
    assert!((s.impulse[1] + 2.0).abs() < 1e-10, "P_t = {}", s.impulse[1]);
    assert!(s.impulse[1].abs() < 0.6 * s.impulse[0]);
    let w = identity_over(2.0, 3);
    for facets in [4, 8, 12] {
        let s = lemke(3, &w, &[-3.0, 1.0, 0.0], &[0.6], facets);
        assert!(s.success(), "{}", s.message);
        assert!(
            close(&s.velocity, &[0.0, 0.0, 0.0], 1e-10),
            "{:?}",
            s.velocity
        );
        assert!(
            close(&s.impulse, &[6.0, -2.0, 0.0], 1e-10),
            "{:?}",
            s.impulse
        );
    }
    let s = lemke(3, &w, &[-3.0, 0.6, 0.8], &[0.6], 8);
    assert!(s.success(), "{}", s.message);
    assert!(
        close(&s.velocity, &[0.0, 0.0, 0.0], 1e-10),
        "{:?}",
        s.velocity
    );
    assert!(
        close(&s.impulse, &[6.0, -1.2, -1.6], 1e-10),
        "{:?}",
        s.impulse
    );
}

#[test]
fn separating_and_frictionless_contacts() {
    let w = identity_over(1.0, 6);
    let q = [1.0, 0.5, 0.2, -2.0, 0.7, 0.0];
    let s = lemke(3, &w, &q, &[0.3, 0.0], 8);
    assert!(s.success(), "{}", s.message);
    // contact 0 separates, contact 1 is frictionless: only its normal impulse
    assert!(close(&s.impulse, &[0.0, 0.0, 0.0, 2.0, 0.0, 0.0], 1e-12));
    assert!(s.measures.error < 1e-12);
    let p = ContactProblem::new(3, &[], &[], &[]).unwrap();
    let s = solve_polyhedral(&p, &settings(8)).unwrap();
    assert!(s.success() && s.impulse.is_empty(), "{}", s.message);
}

// --- convergence to the friction disk --------------------------------------------------

#[test]
fn oblique_slip_converges_to_the_disk_as_facets_grow() {
    // v_t^- = (0.6, 0.8): the disk answer slides along (0.6, 0.8) with ||P_t|| = 1.2, so
    // u_t = (0.24, 0.32); the polyhedral slip snaps towards facets
    let w = identity_over(2.0, 3);
    let q = [-3.0, 0.6, 0.8];
    let disk = nsgs(3, &w, &q, &[0.2]);
    assert!(disk.success());
    assert!(
        close(&disk.velocity, &[0.0, 0.24, 0.32], 1e-10),
        "{:?}",
        disk.velocity
    );
    let ut_disk = 0.4;
    let facets = [4usize, 8, 16, 32, 64];
    let mut errs = Vec::new();
    for &f in &facets {
        let s = lemke(3, &w, &q, &[0.2], f);
        assert!(s.success(), "{f}: {}", s.message);
        assert!(s.velocity[0].abs() < 1e-10);
        assert!(s.measures.cone_violation < 1e-12);
        let e = (s.velocity[1] - disk.velocity[1]).hypot(s.velocity[2] - disk.velocity[2]);
        let rel = e / ut_disk;
        println!(
            "facets {f:3}: u_t = ({:.6}, {:.6}), relative slip error {rel:.3e}, disk error {:.3e}, \
             {} pivots",
            s.velocity[1], s.velocity[2], s.measures.error, s.iterations
        );
        errs.push(rel);
    }
    let last = *errs.last().unwrap();
    assert!(last < 1e-2 && last < errs[0], "{errs:?}");
    // the trend: least-squares slope of log error against log s is clearly negative
    let xs: Vec<f64> = facets.iter().map(|&f| (f as f64).ln()).collect();
    let ys: Vec<f64> = errs.iter().map(|e| e.max(1e-16).ln()).collect();
    let (mx, my) = (
        xs.iter().sum::<f64>() / xs.len() as f64,
        ys.iter().sum::<f64>() / ys.len() as f64,
    );
    let slope = xs
        .iter()
        .zip(&ys)
        .map(|(x, y)| (x - mx) * (y - my))
        .sum::<f64>()
        / xs.iter().map(|x| (x - mx).powi(2)).sum::<f64>();
    println!("least-squares slope of log error vs log facets: {slope:.2}");
    assert!(slope < -1.0, "slope {slope}, {errs:?}");
    let tail = errs[2..].iter().cloned().fold(0.0, f64::max);
    assert!(tail < errs[0], "{errs:?}");
}

// --- redundant contacts: a box resting on a floor ----------------------------------------

const GRAVITY: f64 = 9.81;
const STEP: f64 = 0.01;

#[test]
fn cube_on_four_corners_matches_nsgs() {
    let g = cube_g();
    let minv = [1.0, 1.0, 1.0, 6.0, 6.0, 6.0];
    // resting, and nudged sideways (friction budget 0.5 * 9.81 * 0.01 suffices to stop it)
    for v_free in [
        [0.0, 0.0, -GRAVITY * STEP, 0.0, 0.0, 0.0],
        [0.01, 0.005, -GRAVITY * STEP, 0.0, 0.0, 0.0],
    ] {
        let (w, q) = delassus(&g, 6, &minv, &v_free);
        let d = nsgs(3, &w, &q, &[0.5; 4]);
        assert!(d.success(), "{}", d.message);
        for facets in [4, 8] {
            let s = lemke(3, &w, &q, &[0.5; 4], facets);
            assert!(s.success(), "{}", s.message);
            println!("cube {v_free:?}, {facets} facets: {}", s.message);
            assert!(
                close(&s.velocity, &d.velocity, 1e-8),
                "{:?} vs {:?}",
                s.velocity,
                d.velocity
            );
            let v = post_velocity(&g, 6, &minv, &v_free, &s.impulse);
            assert!(v.iter().all(|x| x.abs() <= 1e-8), "v = {v:?}");
            let total: f64 = (0..4).map(|k| s.impulse[3 * k]).sum();
            assert!((total - GRAVITY * STEP).abs() < 1e-9, "sum P_n = {total}");
            assert!(s.measures.cone_violation < 1e-12);
        }
    }
}

// --- bad settings ------------------------------------------------------------------------

#[test]
fn bad_facets_are_invalid_parameters() {
    let w2 = identity_over(2.0, 2);
    let p = ContactProblem::new(2, &w2, &[-3.0, 1.0], &[0.2]).unwrap();
    assert!(matches!(
        solve_polyhedral(&p, &settings(4)),
        Err(CoulombError::InvalidParameter(_))
    ));
    let w3 = identity_over(2.0, 3);
    let p = ContactProblem::new(3, &w3, &[-3.0, 1.0, 0.0], &[0.2]).unwrap();
    for f in [0, 2, 3, 9] {
        assert!(matches!(
            solve_polyhedral(&p, &settings(f)),
            Err(CoulombError::InvalidParameter(_))
        ));
    }
    let mut s = settings(8);
    s.lemke.tol = 0.0;
    assert!(solve_polyhedral(&p, &s).is_err());
}

// --- random problems ---------------------------------------------------------------------

/// W = G^T G / 4 with a random G on 40 generalized coordinates (so W is positive definite),
/// q pushing every contact into the surface with some slip. These exercise rows whose terms
/// cancel to rounding (a β of 2e-15 at a contact with r_n = 0 makes the row `mu r_n - 1^T β`
/// pure rounding), which Lemke's unit-free measure must not reject.
#[test]
fn random_positive_definite_problems_are_all_solved() {
    let (nc, ndof) = (8, 40);
    let n = 3 * nc;
    let mut rng = coulomb::testing::SplitMix64::new(3);
    for trial in 0..40 {
        let g: Vec<f64> = (0..ndof * n).map(|_| rng.normal()).collect();
        let mut w = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                w[i * n + j] = (0..ndof).map(|a| g[a * n + i] * g[a * n + j]).sum::<f64>() / 4.0;
            }
        }
        let mut q: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
        for i in 0..nc {
            q[3 * i] = -q[3 * i].abs() - 0.5;
        }
        let s = lemke(3, &w, &q, &[0.3; 8], 8);
        assert!(s.success(), "trial {trial}: {}", s.message);
        let m = s.measures;
        assert!(m.min_normal_impulse >= -1e-12, "trial {trial}: {m:?}");
        assert!(m.cone_violation <= 1e-9, "trial {trial}: {m:?}");
        assert!(m.max_complementarity <= 1e-9, "trial {trial}: {m:?}");
        // the inscribed octagon loses at most 1 - cos(π/8) of the friction budget
        assert!(m.error < 0.2, "trial {trial}: {m:?}");
        for i in 0..nc {
            assert!(
                s.velocity[3 * i] >= -1e-9,
                "trial {trial}: u_n = {}",
                s.velocity[3 * i]
            );
        }
    }
}

// --- anisotropic friction: directions scaled onto the ellipse -------------------------------

#[test]
fn anisotropic_polygon_is_inscribed_in_the_ellipse_and_converges() {
    let w = identity_over(2.0, 3);
    let pairs = [0.2, 0.5];
    // sliding along a principal axis: a vertex of every polygon, so exact
    for (q, expect) in [
        ([-3.0, 1.0, 0.0], [6.0, -1.2, 0.0]),
        ([-3.0, 0.0, 2.0], [6.0, 0.0, -3.0]),
    ] {
        let p = ContactProblem::new(3, &w, &q, &[0.5])
            .and_then(|p| p.with_anisotropic_friction(&pairs))
            .unwrap();
        let (s, lcp, _) = solve_polyhedral_lcp(&p, &settings(8)).unwrap();
        assert!(s.success(), "{}", s.message);
        assert_eq!(lcp.direction_scale(0), [0.4, 1.0]);
        assert!(close(&s.impulse, &expect, 1e-10), "{:?}", s.impulse);
        assert!(s.measures.error < 1e-12);
    }
    // oblique slip: the polygon answer approaches the exact ellipse answer (NSGS) as the
    // facets grow, and every polygon answer lies inside the ellipse
    let q = [-3.0, 1.0, 1.0];
    let p = ContactProblem::new(3, &w, &q, &[0.5])
        .and_then(|p| p.with_anisotropic_friction(&pairs))
        .unwrap();
    let exact = solve_nsgs(
        &p,
        &NsgsSettings {
            tol: 1e-14,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(exact.success());
    let dist = |r: &[f64]| {
        (0..3)
            .map(|k| (r[k] - exact.impulse[k]).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let mut errs = Vec::new();
    for s in [4, 8, 16, 32, 64, 128] {
        let sol = solve_polyhedral(&p, &settings(s)).unwrap();
        assert!(sol.success(), "{}", sol.message);
        let r = &sol.impulse;
        assert!((r[1] / 0.2).hypot(r[2] / 0.5) <= r[0] * (1.0 + 1e-12));
        errs.push(dist(r));
    }
    println!("anisotropic polygon vs ellipse, s = 4 .. 128: {errs:?}");
    assert!(errs[5] < 0.05 * errs[0], "{errs:?}");
    assert!(errs[5] < 1e-2, "{errs:?}");
}
