//! The robust mode (`contact::prox`): the seed's contact step, redundant contacts (singular W),
//! random problems against NSGS, the Siconos problems on which NSGS stalls at 1e-8, warm
//! start and honest failure.

mod common;

use common::data;
use coulomb::contact::prox::{solve_prox, ProxSettings};
use coulomb::contact::{
    measure, solve_nsgs, BlockCsr, ContactProblem, ContactStatus, NsgsSettings,
};
use coulomb::io::siconos::{read_siconos_fc, SiconosFcFile};
use coulomb::testing::SplitMix64;
use std::path::Path;

fn settings(tol: f64) -> ProxSettings {
    ProxSettings {
        tol,
        ..Default::default()
    }
}

#[test]
fn seed_inelastic_step_in_2d_and_3d() {
    for dim in [2, 3] {
        let mut w = vec![0.0; dim * dim];
        for k in 0..dim {
            w[k * dim + k] = 0.5;
        }
        let q = [-3.0, 1.0, 0.0];
        let p = ContactProblem::new(dim, &w, &q[..dim], &[0.2]).unwrap();
        let s = solve_prox(&p, &settings(1e-13)).unwrap();
        assert!(s.success(), "{}", s.message);
        assert!((s.impulse[0] - 6.0).abs() < 1e-12 && (s.impulse[1] + 1.2).abs() < 1e-12);
        assert!(s.velocity[0].abs() < 1e-12 && (s.velocity[1] - 0.4).abs() < 1e-12);
        // sticking with mu = 0.6
        let p = ContactProblem::new(dim, &w, &q[..dim], &[0.6]).unwrap();
        let s = solve_prox(&p, &settings(1e-13)).unwrap();
        assert!(s.success() && s.velocity[1].abs() < 1e-12);
        assert!(s.impulse[1].abs() < 0.6 * s.impulse[0]);
    }
}

#[test]
fn redundant_corners_give_the_analytic_velocity() {
    // the cube lands at v_n = -2 sliding at (0.4, -0.2): total normal impulse 2, slip reduced by
    // mu * 2 (mass 1)
    let g = common::cube_g();
    let ndof = 6;
    let minv = [1.0, 1.0, 1.0, 6.0, 6.0, 6.0];
    let v_free = [0.4, -0.2, -2.0, 0.0, 0.0, 0.0];
    let (w, q) = common::delassus(&g, ndof, &minv, &v_free);
    for mu in [0.1, 0.5] {
        let mus = [mu; 4];
        let p = ContactProblem::new(3, &w, &q, &mus).unwrap();
        let s = solve_prox(&p, &settings(1e-12)).unwrap();
        assert!(s.success(), "{}", s.message);
        let v = common::post_velocity(&g, ndof, &minv, &v_free, &s.impulse);
        let vt = 0.4f64.hypot(0.2);
        let slip = (1.0 - 2.0 * mu / vt).max(0.0);
        let expected = [0.4 * slip, -0.2 * slip, 0.0, 0.0, 0.0, 0.0];
        for k in 0..6 {
            assert!((v[k] - expected[k]).abs() < 1e-9, "mu {mu}: {v:?}");
        }
    }
}

#[test]
fn random_rank_deficient_problems_are_solved() {
    let mut rng = SplitMix64::new(11);
    for case in 0..40 {
        let dim = 2 + case % 2;
        let nc = 3 + case;
        let ndof = 6 * (nc / 4) + 3;
        let n = dim * nc;
        let g: Vec<f64> = (0..ndof * n).map(|_| rng.normal()).collect();
        let mut w = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                w[i * n + j] = (0..ndof).map(|a| g[a * n + i] * g[a * n + j]).sum::<f64>() / 4.0;
            }
        }
        // q = G^T v_free (in the range of W, as from a mechanism: otherwise a singular W may
        // leave the problem without a solution)
        let v_free: Vec<f64> = (0..ndof).map(|_| rng.normal()).collect();
        let q: Vec<f64> = (0..n)
            .map(|k| (0..ndof).map(|a| g[a * n + k] * v_free[a]).sum::<f64>())
            .collect();
        let mu = vec![[0.0, 0.3, 1.0, 2.0][case % 4]; nc];
        let p = ContactProblem::new(dim, &w, &q, &mu).unwrap();
        let s = solve_prox(&p, &settings(1e-10)).unwrap();
        assert!(s.success(), "case {case}: {}", s.message);
        let (_, m) = measure(&p, &s.impulse).unwrap();
        // the verdict's rule on an independent call of the measures (error_q, which adds
        // velocities to impulses, is reported beside it)
        assert!(
            m.passes(1e-10) && m.error <= m.error_q,
            "case {case}: {m:?}"
        );
    }
}

fn local(path: &Path, name: &str) -> (usize, Vec<f64>, Vec<f64>, Vec<f64>) {
    match read_siconos_fc(path) {
        Ok(SiconosFcFile::Local(p)) => (p.dim, p.w.to_dense().data, p.q, p.mu),
        Ok(SiconosFcFile::Global(_)) => panic!("{name} is a global problem"),
        Err(e) => panic!("{name}: {e}"),
    }
}

#[test]
fn problems_where_nsgs_stalls_are_solved_at_1e_8() {
    // (file, whether plain NSGS sweeps stall on it within 1000 sweeps, whether NSGS with the
    // sticking-set solve does): OneObject-i100000-316 stalled only while NSGS symmetrised the
    // diagonal blocks of its slightly unsymmetric W (8e-5); solved as stored, NSGS converges
    // there in under 1000 sweeps. BoxesStack1's sweeps drift along W's null directions (box
    // faces), which the sticking-set solve ends
    for (name, stalls, stalls_sticking) in [
        ("BoxesStack1-i100000-32.hdf5.dat", true, false),
        ("OneObject-i100000-316.hdf5.dat", false, false),
        ("OneObject-i100000-499.hdf5.dat", true, true),
    ] {
        let (dim, w, q, mu) = local(&data::file("siconos-fc", name), name);
        let p = ContactProblem::new(dim, &w, &q, &mu).unwrap();
        let s = solve_prox(&p, &settings(1e-8)).unwrap();
        assert!(s.success(), "{name}: {}", s.message);
        assert!(s.measures.error_q <= 1e-8 && s.iterations <= 60, "{name}");
        for (sticking, stalls) in [(false, stalls), (true, stalls_sticking)] {
            let n = solve_nsgs(
                &p,
                &NsgsSettings {
                    tol: 1e-8,
                    max_iter: 1000,
                    sticking,
                    ..Default::default()
                },
            )
            .unwrap();
            if stalls {
                assert_eq!(n.status, ContactStatus::IterationLimit, "{name}");
            } else {
                assert_eq!(n.status, ContactStatus::Solved, "{name}: {}", n.message);
                assert!(n.measures.error_q <= 1e-8, "{name}");
            }
        }
        // warm start from the answer: solved at once (up to the projection's rounding)
        let again = solve_prox(
            &p,
            &ProxSettings {
                initial: Some(s.impulse.clone()),
                ..settings(1e-8)
            },
        )
        .unwrap();
        assert!(again.success() && again.iterations <= 1, "{name}");
        // a tight iteration limit is reported as such, unless the polyhedral LCPs tried at the
        // end solve the problem (BoxesStack1: every contact sticks or separates)
        let short = solve_prox(
            &p,
            &ProxSettings {
                max_iter: 1,
                ..settings(1e-8)
            },
        )
        .unwrap();
        assert_eq!(short.iterations, 1, "{name}");
        if short.status == ContactStatus::Solved {
            assert!(
                short.message.contains("polyhedral"),
                "{name}: {}",
                short.message
            );
            assert!(short.measures.passes(1e-8), "{name}");
        } else {
            assert_eq!(short.status, ContactStatus::IterationLimit, "{name}");
            assert!(short.measures.error_q > 1e-8, "{name}");
        }
    }
}

/// The 2D granular flow (nc = 2020) whose W, printed with 6 significant digits in its source,
/// is singular up to that rounding and indefinite (min eigenvalue -3.9e-3 against 1.7e4):
/// Newton stalls at error_q ~3.5e-7 and the 2D LCP finish (Lemke on a working set) solves it.
#[test]
#[cfg_attr(
    not(coulomb_full_data),
    ignore = "needs the full benchmark data ($COULOMB_DATA or ../shared/data, found when the crate is built)"
)]
fn the_indefinite_2d_granular_flow_is_finished_by_its_lcp() {
    let name = "fc2d_granularflowonwall_02020_00213.dat";
    let (dim, w, q, mu) = local(&data::full_set_dir("siconos-fc").join(name), name);
    assert_eq!((dim, mu.len()), (2, 2020));
    let n = dim * mu.len();
    let blocks = BlockCsr::from_dense(dim, n, &w).unwrap();
    let p = ContactProblem::with_block_sparse(&blocks, &q, &mu).unwrap();
    let s = solve_prox(&p, &settings(1e-8)).unwrap();
    assert!(s.success(), "{}", s.message);
    assert!(s.message.contains("2D LCP finish"), "{}", s.message);
    // measured again on the dense W: Lemke's basic answer is exact up to rounding
    let dense = ContactProblem::new(dim, &w, &q, &mu).unwrap();
    let (_, m) = measure(&dense, &s.impulse).unwrap();
    assert!(m.error_q <= 1e-12, "error_q {}", m.error_q);
    assert!((m.error_q - s.measures.error_q).abs() <= 1e-14);
    let rmax = s.impulse.iter().step_by(2).fold(0.0_f64, |a, &v| a.max(v));
    assert!(m.min_normal_impulse >= -1e-12 * rmax && m.cone_violation <= 1e-12 * rmax);
    // without the finish (an iteration limit before the first stall window) Newton is at
    // error_q ~3.5e-7: far above the tolerance
    let short = solve_prox(
        &p,
        &ProxSettings {
            max_iter: 50,
            ..settings(1e-8)
        },
    )
    .unwrap();
    assert_eq!(short.status, ContactStatus::IterationLimit);
    assert!(short.measures.error_q > 1e-8 && short.measures.error_q < 1e-5);
}
