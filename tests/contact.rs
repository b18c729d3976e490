//! Integration tests of the friction-contact solver (NSGS with the exact friction disk): the
//! seed's inelastic contact step, sticking, redundant contacts (a box on a floor), a random 3D
//! problem with every check, and bad input.

use coulomb::contact::{
    measure, solve_nsgs, BlockCsr, ContactProblem, ContactSolution, ContactStatus, NsgsSettings,
};
use coulomb::testing::SplitMix64;
use coulomb::CoulombError;

mod common;
use common::{cube_g, delassus, post_velocity};
mod pile;

fn nsgs(dim: usize, w: &[f64], q: &[f64], mu: &[f64], s: &NsgsSettings) -> ContactSolution {
    let p = ContactProblem::new(dim, w, q, mu).expect("well-formed test problem");
    solve_nsgs(&p, s).expect("valid settings")
}

fn identity_over(m: f64, n: usize) -> Vec<f64> {
    let mut w = vec![0.0; n * n];
    for i in 0..n {
        w[i * n + i] = 1.0 / m;
    }
    w
}

/// `G^T v`: the contact velocities.
fn contact_velocity(g: &[f64], ndof: usize, v: &[f64]) -> Vec<f64> {
    let ncols = g.len() / ndof;
    (0..ncols)
        .map(|k| (0..ndof).map(|a| g[a * ncols + k] * v[a]).sum())
        .collect()
}

// --- the seed's inelastic contact step -------------------------------------------------

#[test]
fn seed_inelastic_step_2d() {
    let (m, mu) = (2.0, [0.2]);
    let w = identity_over(m, 2);
    let q = [-3.0, 1.0];
    let s = nsgs(2, &w, &q, &mu, &NsgsSettings::default());
    assert!(s.success(), "{}", s.message);
    assert!((s.impulse[0] - 6.0).abs() < 1e-10, "P_n = {}", s.impulse[0]);
    assert!((s.impulse[1] + 1.2).abs() < 1e-10, "P_t = {}", s.impulse[1]);
    assert!(s.velocity[0].abs() < 1e-10);
    assert!((s.velocity[1] - 0.4).abs() < 1e-10);
    let t_before = 0.5 * m * (3.0f64 * 3.0 + 1.0);
    let t_after = 0.5 * m * (s.velocity[0].powi(2) + s.velocity[1].powi(2));
    assert!((t_before - 10.0).abs() < 1e-12);
    assert!((t_after - 0.16).abs() < 1e-10, "T after = {t_after}");
    assert!(s.measures.error < 1e-12);
}

#[test]
fn seed_inelastic_step_3d() {
    let (m, mu) = (2.0, [0.2]);
    let w = identity_over(m, 3);
    let q = [-3.0, 1.0, 0.0];
    let s = nsgs(3, &w, &q, &mu, &NsgsSettings::default());
    assert!(s.success(), "{}", s.message);
    assert!((s.impulse[0] - 6.0).abs() < 1e-10);
    assert!((s.impulse[1] + 1.2).abs() < 1e-10);
    assert!(s.impulse[2].abs() < 1e-10);
    assert!(s.velocity[0].abs() < 1e-10);
    assert!((s.velocity[1] - 0.4).abs() < 1e-10);
    assert!(s.velocity[2].abs() < 1e-10);
    let t_after = 0.5 * m * s.velocity.iter().map(|v| v * v).sum::<f64>();
    assert!((t_after - 0.16).abs() < 1e-10, "T after = {t_after}");
}

#[test]
fn oblique_slip_in_3d_opposes_the_slip_direction() {
    // v_t^- = (1, 1): the disk answer slides along (1, 1) with ||P_t|| = mu P_n = 1.2
    let w = identity_over(2.0, 3);
    let q = [-3.0, 1.0, 1.0];
    let s = nsgs(3, &w, &q, &[0.2], &NsgsSettings::default());
    assert!(s.success());
    let h = 1.2 / 2f64.sqrt();
    assert!((s.impulse[1] + h).abs() < 1e-10 && (s.impulse[2] + h).abs() < 1e-10);
    let slip = 1.0 - h / 2.0;
    assert!((s.velocity[1] - slip).abs() < 1e-10 && (s.velocity[2] - slip).abs() < 1e-10);
}

#[test]
fn sticking_with_large_friction() {
    for dim in [2, 3] {
        let w = identity_over(2.0, dim);
        let mut q = vec![-3.0, 1.0];
        if dim == 3 {
            q.push(0.0);
        }
        let s = nsgs(dim, &w, &q, &[0.6], &NsgsSettings::default());
        assert!(s.success(), "{}", s.message);
        let pt = s.impulse[1..].iter().map(|v| v * v).sum::<f64>().sqrt();
        let ut = s.velocity[1..].iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!(ut < 1e-10, "u_t = {ut}");
        assert!((pt - 2.0).abs() < 1e-10, "||P_t|| = {pt}");
        assert!((s.impulse[0] - 6.0).abs() < 1e-10);
        assert!(pt < 0.6 * s.impulse[0]);
    }
}

#[test]
fn frictionless_contacts_carry_no_tangential_impulse() {
    let w = identity_over(2.0, 3);
    let q = [-3.0, 1.0, -2.0];
    let s = nsgs(3, &w, &q, &[0.0], &NsgsSettings::default());
    assert!(s.success());
    assert_eq!(&s.impulse[1..], &[0.0, 0.0]);
    assert!((s.impulse[0] - 6.0).abs() < 1e-12);
}

// --- redundant contacts: a box resting on a floor ----------------------------------------

const GRAVITY: f64 = 9.81;
const STEP: f64 = 0.01;

/// A unit square (side 1, mass 1, inertia m (w^2 + h^2) / 12 = 1/6) resting on a floor on
/// its two bottom corners. Generalized velocities (v_x, v_y, ω); a corner at offset ρ from the
/// centre moves at `(v_x - ω ρ_y, v_y + ω ρ_x)`; contact frame: normal e_y, tangent e_x.
#[test]
fn planar_box_on_two_corners() {
    let ndof = 3;
    let corners = [(-0.5, -0.5), (0.5, -0.5)];
    let ncols = 2 * corners.len();
    let mut g = vec![0.0; ndof * ncols];
    for (k, &(rx, ry)) in corners.iter().enumerate() {
        // normal column (0, 1, ρ_x), tangent column (1, 0, -ρ_y)
        g[ncols + 2 * k] = 1.0;
        g[2 * ncols + 2 * k] = rx;
        g[2 * k + 1] = 1.0;
        g[2 * ncols + 2 * k + 1] = -ry;
    }
    let minv = [1.0, 1.0, 6.0];
    let v_free = [0.0, -GRAVITY * STEP, 0.0];
    let (w, q) = delassus(&g, ndof, &minv, &v_free);
    let settings = NsgsSettings {
        tol: 1e-12,
        ..Default::default()
    };
    let s = nsgs(2, &w, &q, &[0.5, 0.5], &settings);
    assert!(s.success(), "{}", s.message);
    let v = post_velocity(&g, ndof, &minv, &v_free, &s.impulse);
    let uc = contact_velocity(&g, ndof, &v);
    for k in 0..corners.len() {
        assert!(uc[2 * k] >= -1e-9, "normal velocity {}", uc[2 * k]);
    }
    assert!(v.iter().all(|x| x.abs() <= 1e-8), "v = {v:?}");
    let total: f64 = (0..corners.len()).map(|k| s.impulse[2 * k]).sum();
    assert!((total - GRAVITY * STEP).abs() < 1e-9, "sum P_n = {total}");
    // symmetric: each corner carries half
    assert!((s.impulse[0] - s.impulse[2]).abs() < 1e-9);
}

/// A unit cube (mass 1, inertia 1/6 about each principal axis, axes aligned with the world)
/// on four bottom corners. Generalized velocities (v, ω); a corner at ρ moves at v + ω × ρ, so
/// the column of contact direction d is (d, ρ × d). G is 6 x 12: W (12 x 12) has rank 6 and is
/// singular; the normal impulses are not unique, their sum is.
#[test]
fn cube_on_four_corners_redundant() {
    let ndof = 6;
    let corners = 4;
    let g = cube_g();
    let minv = [1.0, 1.0, 1.0, 6.0, 6.0, 6.0];
    let v_free = [0.0, 0.0, -GRAVITY * STEP, 0.0, 0.0, 0.0];
    let (w, q) = delassus(&g, ndof, &minv, &v_free);
    let settings = NsgsSettings {
        tol: 1e-12,
        ..Default::default()
    };
    let s = nsgs(3, &w, &q, &[0.5; 4], &settings);
    assert!(s.success(), "{}", s.message);
    println!("cube: {}", s.message);
    let v = post_velocity(&g, ndof, &minv, &v_free, &s.impulse);
    let uc = contact_velocity(&g, ndof, &v);
    for k in 0..corners {
        assert!(uc[3 * k] >= -1e-9, "normal velocity {}", uc[3 * k]);
        assert!(s.impulse[3 * k] >= 0.0);
    }
    assert!(v.iter().all(|x| x.abs() <= 1e-8), "v = {v:?}");
    let total: f64 = (0..corners).map(|k| s.impulse[3 * k]).sum();
    assert!((total - GRAVITY * STEP).abs() < 1e-9, "sum P_n = {total}");
}

// --- a random 3D problem -----------------------------------------------------------------

/// W = G^T M^{-1} G with a random G (40 generalized coordinates, so W is positive definite),
/// random masses, and q = G^T v_free with a velocity that pushes most contacts closed.
fn random_problem(nc: usize, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut rng = SplitMix64::new(seed);
    let ndof = 40;
    let ncols = 3 * nc;
    let g: Vec<f64> = (0..ndof * ncols).map(|_| rng.normal()).collect();
    let minv: Vec<f64> = (0..ndof).map(|_| 1.0 / rng.range(0.5, 2.0)).collect();
    let v_free: Vec<f64> = (0..ndof).map(|_| rng.normal()).collect();
    let (w, mut q) = delassus(&g, ndof, &minv, &v_free);
    // push most contacts towards each other
    for i in 0..nc {
        q[3 * i] -= rng.range(-1.0, 4.0);
    }
    (w, q)
}

#[test]
fn random_3d_problem_passes_every_check() {
    let nc = 10;
    let (w, q) = random_problem(nc, 42);
    let mu = vec![0.5; nc];
    let s = nsgs(3, &w, &q, &mu, &NsgsSettings::default());
    assert!(s.success(), "{}", s.message);
    println!("random 3D: {}", s.message);
    let m = s.measures;
    assert!(m.passes(1e-8), "{m:?}");
    assert!(m.cone_violation <= 1e-10, "{m:?}");
    assert!(m.min_normal_impulse >= -1e-12, "{m:?}");
    let qn = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    let rn = s.impulse.iter().map(|v| v * v).sum::<f64>().sqrt();
    assert!(m.max_complementarity <= 1e-7 * qn.max(rn).powi(2), "{m:?}");
    assert!(
        m.dissipation_violation <= 1e-7 * qn.max(rn).powi(2),
        "{m:?}"
    );
    // at least one contact is active and one slides, so the test means something
    let active = (0..nc).filter(|&i| s.impulse[3 * i] > 1e-6).count();
    assert!(active >= 2, "only {active} active contacts");
    // measure() agrees with the solver's own numbers
    let p = ContactProblem::new(3, &w, &q, &mu).unwrap();
    let (u, again) = measure(&p, &s.impulse).unwrap();
    assert_eq!(again, m);
    assert_eq!(u, s.velocity);
    // warm start from the answer: solved at once
    let warm = nsgs(
        3,
        &w,
        &q,
        &mu,
        &NsgsSettings {
            initial: Some(s.impulse.clone()),
            ..Default::default()
        },
    );
    assert!(warm.success() && warm.iterations == 0);
    // over-relaxation also converges
    let sor = nsgs(
        3,
        &w,
        &q,
        &mu,
        &NsgsSettings {
            relaxation: 1.3,
            ..Default::default()
        },
    );
    assert!(sor.success(), "{}", sor.message);
}

#[test]
fn random_problem_is_honest_about_the_iteration_limit() {
    let nc = 10;
    let (w, q) = random_problem(nc, 42);
    let mu = vec![0.5; nc];
    let s = nsgs(
        3,
        &w,
        &q,
        &mu,
        &NsgsSettings {
            max_iter: 2,
            ..Default::default()
        },
    );
    assert_eq!(s.status, ContactStatus::IterationLimit);
    assert!(!s.success());
    assert_eq!(s.iterations, 2);
    assert!(s.measures.error > 1e-8);
    assert!(s.message.contains("max_iter"));
}

#[test]
fn random_2d_problem_converges() {
    // the planar version: 10 contacts, blocks 2x2 with normal-tangent coupling
    let mut rng = SplitMix64::new(9);
    let (ndof, nc) = (30, 10);
    let ncols = 2 * nc;
    let g: Vec<f64> = (0..ndof * ncols).map(|_| rng.normal()).collect();
    let minv = vec![1.0; ndof];
    let v_free: Vec<f64> = (0..ndof).map(|_| rng.normal()).collect();
    let (w, mut q) = delassus(&g, ndof, &minv, &v_free);
    for i in 0..nc {
        q[2 * i] -= 2.0;
    }
    let mu: Vec<f64> = (0..nc).map(|i| 0.1 * i as f64).collect();
    let s = nsgs(2, &w, &q, &mu, &NsgsSettings::default());
    assert!(s.success(), "{}", s.message);
    println!("random 2D: {}", s.message);
    assert!(s.measures.cone_violation <= 1e-10);
    assert!(s.measures.min_normal_impulse >= -1e-12);
}

// --- bad input -----------------------------------------------------------------------------

#[test]
fn bad_input_gives_specific_errors() {
    let w = identity_over(2.0, 3);
    let q = [-3.0, 1.0, 0.0];
    let shape = ContactProblem::new(3, &w[..8], &q, &[0.2]);
    assert!(matches!(shape, Err(CoulombError::Shape(_))));
    let shape = ContactProblem::new(3, &w, &q[..2], &[0.2]);
    assert!(matches!(shape, Err(CoulombError::Shape(_))));
    let shape = ContactProblem::new(2, &w, &q, &[0.2]);
    assert!(matches!(shape, Err(CoulombError::Shape(_))));
    let mut wn = w.clone();
    wn[4] = f64::NAN;
    assert!(matches!(
        ContactProblem::new(3, &wn, &q, &[0.2]),
        Err(CoulombError::NonFinite(_))
    ));
    assert!(matches!(
        ContactProblem::new(3, &w, &[-3.0, f64::INFINITY, 0.0], &[0.2]),
        Err(CoulombError::NonFinite(_))
    ));
    assert!(matches!(
        ContactProblem::new(3, &w, &q, &[f64::NAN]),
        Err(CoulombError::NonFinite(_))
    ));
    assert!(matches!(
        ContactProblem::new(3, &w, &q, &[-0.2]),
        Err(CoulombError::InvalidParameter(_))
    ));
    assert!(matches!(
        ContactProblem::new(4, &w, &q, &[0.2]),
        Err(CoulombError::InvalidParameter(_))
    ));
    let p = ContactProblem::new(3, &w, &q, &[0.2]).unwrap();
    for bad in [
        NsgsSettings {
            relaxation: 2.5,
            ..Default::default()
        },
        NsgsSettings {
            relaxation: 0.0,
            ..Default::default()
        },
        NsgsSettings {
            tol: -1.0,
            ..Default::default()
        },
        NsgsSettings {
            max_iter: 0,
            ..Default::default()
        },
    ] {
        assert!(matches!(
            solve_nsgs(&p, &bad),
            Err(CoulombError::InvalidParameter(_))
        ));
    }
    let short = NsgsSettings {
        initial: Some(vec![1.0]),
        ..Default::default()
    };
    assert!(matches!(
        solve_nsgs(&p, &short),
        Err(CoulombError::Shape(_))
    ));
    let nan = NsgsSettings {
        initial: Some(vec![1.0, f64::NAN, 0.0]),
        ..Default::default()
    };
    assert!(matches!(
        solve_nsgs(&p, &nan),
        Err(CoulombError::NonFinite(_))
    ));
}

#[test]
fn a_contact_without_normal_stiffness_is_reported() {
    // W_nn = 0 for the only contact and q_n < 0: no impulse can help
    let w = vec![0.0; 4];
    let q = [-1.0, 0.0];
    let s = nsgs(2, &w, &q, &[0.3], &NsgsSettings::default());
    assert_eq!(s.status, ContactStatus::NumericalFailure);
    assert!(!s.success());
    // ... but with q_n >= 0 the zero impulse is the answer
    let s = nsgs(2, &w, &[1.0, 0.0], &[0.3], &NsgsSettings::default());
    assert!(s.success());
}

#[test]
fn no_contacts_is_trivially_solved() {
    let s = nsgs(3, &[], &[], &[], &NsgsSettings::default());
    assert!(s.success());
    assert!(s.impulse.is_empty());
}

// --- block-sparse storage ----------------------------------------------------------------

fn nsgs_sparse(w: &BlockCsr, q: &[f64], mu: &[f64], s: &NsgsSettings) -> ContactSolution {
    let p = ContactProblem::with_block_sparse(w, q, mu).expect("well-formed test problem");
    solve_nsgs(&p, s).expect("valid settings")
}

fn assert_same(a: &ContactSolution, b: &ContactSolution) {
    assert_eq!(a.impulse, b.impulse);
    assert_eq!(a.velocity, b.velocity);
    assert_eq!(a.iterations, b.iterations);
    assert_eq!(a.status, b.status);
    assert_eq!(a.measures, b.measures);
}

#[test]
fn block_sparse_and_dense_storage_give_identical_answers() {
    // a dense W (every tile nonzero), 3D and 2D
    let (w, q) = random_problem(10, 42);
    let mu = vec![0.5; 10];
    let sparse = BlockCsr::from_dense(3, 30, &w).unwrap();
    assert_eq!(sparse.nnz_blocks(), 100);
    let s = NsgsSettings::default();
    let a = nsgs(3, &w, &q, &mu, &s);
    assert!(a.success(), "{}", a.message);
    assert_same(&a, &nsgs_sparse(&sparse, &q, &mu, &s));
    // a pile: a few tiles per block row
    let p = pile::pile(60, 0.4, 7);
    let sparse = BlockCsr::from_coo(3, p.n, &p.rows, &p.cols, &p.vals).unwrap();
    assert!(
        sparse.nnz_blocks() < 60 * 12,
        "{} tiles",
        sparse.nnz_blocks()
    );
    let dense = sparse.to_dense();
    let s = NsgsSettings {
        max_iter: 3000,
        ..Default::default()
    };
    let a = nsgs(3, &dense, &p.q, &p.mu, &s);
    assert!(a.success(), "{}", a.message);
    println!("pile nc = 60: {}", a.message);
    assert_same(&a, &nsgs_sparse(&sparse, &p.q, &p.mu, &s));
    // 2D with an over-relaxation and a warm start
    let mut rng = SplitMix64::new(3);
    let (ndof, nc) = (12, 10);
    let g: Vec<f64> = (0..ndof * 2 * nc)
        .map(|_| {
            if rng.uniform() < 0.3 {
                rng.normal()
            } else {
                0.0
            }
        })
        .collect();
    let v_free: Vec<f64> = (0..ndof).map(|_| rng.normal()).collect();
    let (w, mut q) = delassus(&g, ndof, &vec![1.0; ndof], &v_free);
    for i in 0..nc {
        q[2 * i] -= 1.0;
    }
    let sparse = BlockCsr::from_dense(2, 2 * nc, &w).unwrap();
    let s = NsgsSettings {
        relaxation: 1.2,
        initial: Some(vec![0.1; 2 * nc]),
        ..Default::default()
    };
    let mu = vec![0.3; nc];
    assert_same(
        &nsgs(2, &w, &q, &mu, &s),
        &nsgs_sparse(&sparse, &q, &mu, &s),
    );
}

#[test]
fn accessors_agree_between_storages() {
    let p = pile::pile(25, 0.4, 11);
    let sparse = BlockCsr::from_coo(3, p.n, &p.rows, &p.cols, &p.vals).unwrap();
    let dense = sparse.to_dense();
    let a = ContactProblem::new(3, &dense, &p.q, &p.mu).unwrap();
    let b = ContactProblem::with_block_sparse(&sparse, &p.q, &p.mu).unwrap();
    let mut rng = SplitMix64::new(5);
    let x: Vec<f64> = (0..p.n).map(|_| rng.normal()).collect();
    let (mut ya, mut yb) = (vec![0.0; p.n], vec![0.0; p.n]);
    a.mul_w(&x, &mut ya);
    b.mul_w(&x, &mut yb);
    assert_eq!(ya, yb);
    for i in 0..25 {
        assert_eq!(a.block_row_mul(i, &x), b.block_row_mul(i, &x));
        assert_eq!(
            a.block_row_mul_offdiag(i, &x),
            b.block_row_mul_offdiag(i, &x)
        );
        // offdiag = full - W_ii x_i
        let full = b.block_row_mul(i, &x);
        let off = b.block_row_mul_offdiag(i, &x);
        let wii = b.w_block(i, i);
        for k in 0..3 {
            let own: f64 = (0..3).map(|l| wii[k][l] * x[3 * i + l]).sum();
            assert!((full[k] - own - off[k]).abs() <= 1e-12 * (1.0 + full[k].abs()));
        }
        for j in 0..25 {
            assert_eq!(a.w_block(i, j), b.w_block(i, j));
        }
    }
    let (mut la, mut lb) = (Vec::new(), Vec::new());
    a.for_each_block(|i, j, w| la.push((i, j, *w)));
    b.for_each_block(|i, j, w| lb.push((i, j, *w)));
    assert_eq!(la, lb);
    // a pile is sparse: a few tiles per row
    assert!(la.len() < 25 * 10 && la.len() > 25, "{} tiles", la.len());
    // mismatched mu / q are refused
    assert!(matches!(
        ContactProblem::with_block_sparse(&sparse, &p.q, &p.mu[..3]),
        Err(CoulombError::Shape(_))
    ));
    assert!(matches!(
        ContactProblem::with_block_sparse(&sparse, &p.q[..3], &p.mu),
        Err(CoulombError::Shape(_))
    ));
}

#[test]
fn a_large_sparse_pile_is_solved() {
    let p = pile::pile(2000, 0.3, 1);
    let w = BlockCsr::from_coo(3, p.n, &p.rows, &p.cols, &p.vals).unwrap();
    let s = nsgs_sparse(
        &w,
        &p.q,
        &p.mu,
        &NsgsSettings {
            tol: 1e-8,
            max_iter: 5000,
            ..Default::default()
        },
    );
    println!("pile nc = 2000: {}", s.message);
    assert!(s.success(), "{}", s.message);
    assert!(
        s.measures.cone_violation <= 1e-10 * s.impulse.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    );
    assert!(s.measures.min_normal_impulse >= 0.0);
}

// --- anisotropic friction ------------------------------------------------------------------

#[test]
fn anisotropic_seed_step_slides_with_the_coefficient_of_its_axis() {
    // the seed's step (m = 2, v_n = -3, slip 1) along each tangent in turn, with 0.2 along the
    // slip and 0.5 across it: P_n = 6, P_t = -0.2 * 6 = -1.2 along the slip, u_t = 0.4
    let w = identity_over(2.0, 3);
    for axis in [1, 2] {
        let mut q = [-3.0, 0.0, 0.0];
        q[axis] = 1.0;
        let pairs = if axis == 1 { [0.2, 0.5] } else { [0.5, 0.2] };
        let p = ContactProblem::new(3, &w, &q, &[0.5])
            .and_then(|p| p.with_anisotropic_friction(&pairs))
            .unwrap();
        let s = solve_nsgs(&p, &NsgsSettings::default()).unwrap();
        assert!(s.success(), "{}", s.message);
        let mut expect = [6.0, 0.0, 0.0];
        expect[axis] = -1.2;
        for (got, want) in s.impulse.iter().zip(expect) {
            assert!((got - want).abs() < 1e-12, "{:?}", s.impulse);
        }
        assert!((s.velocity[axis] - 0.4).abs() < 1e-12);
        assert!(s.measures.error < 1e-14);
    }
}

#[test]
fn anisotropic_pile_sparse_equals_dense_and_dissipates_maximally() {
    let p = pile::pile(40, 0.4, 9);
    let sparse = BlockCsr::from_coo(3, p.n, &p.rows, &p.cols, &p.vals).unwrap();
    let dense = sparse.to_dense();
    let mut rng = SplitMix64::new(2);
    let pairs: Vec<f64> = (0..80).map(|_| rng.range(0.05, 0.8)).collect();
    let mu: Vec<f64> = pairs.chunks(2).map(|c| c[0].max(c[1])).collect();
    let s = NsgsSettings {
        tol: 1e-10,
        max_iter: 20_000,
        ..Default::default()
    };
    let a = ContactProblem::new(3, &dense, &p.q, &mu)
        .and_then(|pr| pr.with_anisotropic_friction(&pairs))
        .unwrap();
    let b = ContactProblem::with_block_sparse(&sparse, &p.q, &mu)
        .and_then(|pr| pr.with_anisotropic_friction(&pairs))
        .unwrap();
    let sa = solve_nsgs(&a, &s).unwrap();
    assert!(sa.success(), "{}", sa.message);
    assert_same(&sa, &solve_nsgs(&b, &s).unwrap());
    let big = sa.impulse.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut sliding = 0;
    for i in 0..40 {
        let (m1, m2) = (pairs[2 * i], pairs[2 * i + 1]);
        let r = &sa.impulse[3 * i..3 * i + 3];
        let u = &sa.velocity[3 * i..3 * i + 3];
        assert!((r[1] / m1).hypot(r[2] / m2) <= r[0] * (1.0 + 1e-9) + 1e-12);
        let phi = (m1 * u[1]).hypot(m2 * u[2]);
        if phi > 1e-6 && r[0] > 1e-6 {
            // maximal dissipation over the ellipse: r_t = -r_n (mu_1^2 u_1, mu_2^2 u_2) / phi
            sliding += 1;
            let e = [-r[0] * m1 * m1 * u[1] / phi, -r[0] * m2 * m2 * u[2] / phi];
            assert!(
                (r[1] - e[0]).abs() <= 1e-6 * big && (r[2] - e[1]).abs() <= 1e-6 * big,
                "contact {i}: {r:?} vs {e:?}"
            );
        }
    }
    assert!(sliding >= 3, "only {sliding} sliding contacts");
}
