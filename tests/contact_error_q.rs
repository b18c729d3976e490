//! The literature's `error_q` is half of every contact verdict: an answer called solved has
//! `error_q <= max(tol, error_q_floor)` on the caller's data, in every unit system, checked
//! here by a natural map written in the test (not coulomb's measure), and an answer exact to
//! rounding is not refused for `error_q`'s rounding.

use coulomb::contact::prox::ProxSettings;
use coulomb::contact::{measure, solve, ContactProblem, Method, NsgsSettings};
use coulomb::testing::SplitMix64;

/// `||r - P_K(r - (u + mu ||u_t|| n))|| / ||q||` of a 2D problem, from W, q, mu as given.
fn error_q_2d(w: &[f64], q: &[f64], mu: &[f64], r: &[f64]) -> f64 {
    let n = q.len();
    let mut sq = 0.0;
    for (i, &m) in mu.iter().enumerate() {
        let u: Vec<f64> = (0..2)
            .map(|a| q[2 * i + a] + (0..n).map(|b| w[(2 * i + a) * n + b] * r[b]).sum::<f64>())
            .collect();
        let (x, y) = (r[2 * i] - (u[0] + m * u[1].abs()), r[2 * i + 1] - u[1]);
        // projection on the 2D cone |t| <= m n
        let (pn, pt) = if y.abs() <= m * x {
            (x, y)
        } else if m * y.abs() <= -x {
            (0.0, 0.0)
        } else {
            let s = (x + m * y.abs()) / (1.0 + m * m);
            (s, m * s * y.signum())
        };
        sq += (r[2 * i] - pn).powi(2) + (r[2 * i + 1] - pt).powi(2);
    }
    sq.sqrt() / q.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// a 2D problem of `nc` contacts with W = G^T M^-1 G (masses over six decades).
fn problem(seed: u64, nc: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = SplitMix64::new(seed);
    let n = 2 * nc;
    let m = n + 2;
    let g: Vec<f64> = (0..m * n).map(|_| rng.normal()).collect();
    let minv: Vec<f64> = (0..m).map(|_| 10f64.powf(rng.range(-3.0, 3.0))).collect();
    let mut w = vec![0.0; n * n];
    for a in 0..n {
        for b in 0..n {
            w[a * n + b] = (0..m).map(|k| g[k * n + a] * minv[k] * g[k * n + b]).sum();
        }
    }
    let q: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
    let mu: Vec<f64> = (0..nc)
        .map(|_| [0.0, 0.3, 1.0, 5.0][rng.below(4)])
        .collect();
    (w, q, mu)
}

#[test]
fn a_solved_answer_passes_error_q_on_the_callers_data_in_every_unit_system() {
    let tol = 1e-8;
    let mut solved = 0;
    for seed in 0..40u64 {
        let (w0, q0, mu) = problem(seed, 1 + (seed as usize % 4));
        for (ka, kb) in [(0, 0), (5, 0), (0, 5), (-6, 2), (8, -8), (-8, 8)] {
            let (a, b) = (10f64.powi(ka), 10f64.powi(kb));
            let w: Vec<f64> = w0.iter().map(|x| x * (b / a)).collect();
            let q: Vec<f64> = q0.iter().map(|x| x * b).collect();
            let p = ContactProblem::new(2, &w, &q, &mu).unwrap();
            for method in [
                Method::Nsgs(NsgsSettings {
                    tol,
                    max_iter: 5000,
                    ..NsgsSettings::default()
                }),
                Method::Prox(ProxSettings {
                    tol,
                    ..ProxSettings::default()
                }),
            ] {
                let out = solve(&p, &method).unwrap();
                if !out.success() {
                    continue;
                }
                solved += 1;
                let mine = error_q_2d(&w, &q, &mu, &out.impulse);
                let m = out.measures;
                // the test's map and the core's agree to rounding, and the verdict holds
                assert!(
                    (mine - m.error_q).abs() <= 1e-6 * mine.max(m.error_q) + m.error_q_floor,
                    "seed {seed} units ({ka}, {kb}): {mine} against {}",
                    m.error_q
                );
                assert!(
                    mine <= tol.max(m.error_q_floor) + m.error_q_floor,
                    "seed {seed} units ({ka}, {kb}) {method:?}: solved with error_q {mine} \
                     (floor {})",
                    m.error_q_floor
                );
                assert!(m.scaled_error <= tol);
            }
        }
    }
    assert!(solved >= 300, "only {solved} answers solved");
}

#[test]
fn an_answer_exact_to_rounding_passes_in_every_unit_system() {
    // the inelastic step W = I/2, q = (-3, 1), mu = 0.2: r = (6, -1.2), u = (0, 0.4); and a
    // sticking one, q = (-3, 0.5): r = (6, -1), u = 0
    for (q0, r0) in [([-3.0, 1.0], [6.0, -1.2]), ([-3.0, 0.5], [6.0, -1.0])] {
        for ka in (-8..=8).step_by(2) {
            for kb in (-8..=8).step_by(2) {
                let (a, b) = (10f64.powi(ka), 10f64.powi(kb));
                let w = [0.5 * b / a, 0.0, 0.0, 0.5 * b / a];
                let q = [q0[0] * b, q0[1] * b];
                let r = [r0[0] * a, r0[1] * a];
                let p = ContactProblem::new(2, &w, &q, &[0.2]).unwrap();
                let (_, m) = measure(&p, &r).unwrap();
                assert!(
                    m.passes(1e-14),
                    "units ({ka}, {kb}): error_q {} floor {} scaled {}",
                    m.error_q,
                    m.error_q_floor,
                    m.scaled_error
                );
            }
        }
    }
}

#[test]
fn a_wrong_answer_fails_on_error_q_where_the_scaled_measure_alone_would_pass() {
    // two contacts whose impulses' velocity terms cancel to 1e-6 of their size
    // (W_nn = [[1, -1 + d], [-1 + d, 1]], d = 1e-6, q_n = -d 1e3): r_n = (1e3, 1e3) solves it.
    // An impulse error along W's large eigenvector moves u by 2e-9, 1e-12 of its terms (the
    // scaled measure, judging each contact against its terms, sees 1e-12) but 1.4e-6 of ||q||
    let d = 1e-6;
    let mut w = vec![0.0; 16];
    w[0] = 1.0;
    w[2] = -1.0 + d;
    w[8] = -1.0 + d;
    w[10] = 1.0;
    w[5] = 1.0;
    w[15] = 1.0;
    let q = [-d * 1e3, 0.0, -d * 1e3, 0.0];
    let mu = [0.5, 0.5];
    let p = ContactProblem::new(2, &w, &q, &mu).unwrap();
    let eps = 1e-12;
    let r = [1e3 * (1.0 + eps), 0.0, 1e3 * (1.0 - eps), 0.0];
    let (_, m) = measure(&p, &r).unwrap();
    assert!(m.scaled_error <= 1e-8, "{m:?}");
    let mine = error_q_2d(&w, &q, &mu, &r);
    assert!(
        mine > 1e-7 && m.error_q > 1e-7 && !m.passes(1e-8),
        "{mine} {m:?}"
    );
    // NSGS, started there, either gets both halves below tol or says it did not
    for method in [
        Method::Nsgs(NsgsSettings {
            initial: Some(r.to_vec()),
            ..NsgsSettings::default()
        }),
        Method::Prox(ProxSettings {
            initial: Some(r.to_vec()),
            ..ProxSettings::default()
        }),
    ] {
        let out = solve(&p, &method).unwrap();
        let mine = error_q_2d(&w, &q, &mu, &out.impulse);
        assert!(
            !out.success()
                || mine <= 1e-8f64.max(out.measures.error_q_floor) + out.measures.error_q_floor,
            "{method:?}: solved with error_q {mine}: {}",
            out.message
        );
    }
}
