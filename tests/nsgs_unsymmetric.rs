//! NSGS on a Delassus matrix that is symmetric only up to a relative 1e-6 .. 1e-2 (as files
//! and assemblies carry it: Siconos' Capsules problems have 1.7e-3) converges to the
//! problem's own solution: each contact's local problem is solved with its diagonal block as
//! stored. Symmetrising that block made the sweeps' fixed point miss the solution by the
//! asymmetry (Capsules-i97-269 stalled at error 4e-6).

use coulomb::contact::{solve_nsgs, BlockCsr, ContactProblem, NsgsSettings};
use coulomb::testing::SplitMix64;

mod pile;

/// De Saxce's natural map of every contact in impulse units (`rho_i = 1 / W_nn,i`),
/// `r - P_K(r - rho (u + mu ||u_t|| n))` with `u = W r + q` from the dense W, relative to the
/// impulses and the impulse equivalent of the terms of u, `||r|| + ||rho (|W| |r| + |q|)||`:
/// an oracle independent of the solver's measures.
fn natural_map_error(w: &[f64], q: &[f64], mu: &[f64], r: &[f64]) -> f64 {
    let n = q.len();
    let u: Vec<f64> = (0..n)
        .map(|i| q[i] + (0..n).map(|j| w[i * n + j] * r[j]).sum::<f64>())
        .collect();
    let terms: Vec<f64> = (0..n)
        .map(|i| q[i].abs() + (0..n).map(|j| (w[i * n + j] * r[j]).abs()).sum::<f64>())
        .collect();
    let (mut res, mut scale) = (0.0, 0.0);
    for (i, &m) in mu.iter().enumerate() {
        let rho = 1.0 / w[3 * i * n + 3 * i];
        let (ri, ui) = (&r[3 * i..3 * i + 3], &u[3 * i..3 * i + 3]);
        let ut = ui[1].hypot(ui[2]);
        let v = [
            ri[0] - rho * (ui[0] + m * ut),
            ri[1] - rho * ui[1],
            ri[2] - rho * ui[2],
        ];
        // projection on the cone ||v_t|| <= m v_n
        let vt = v[1].hypot(v[2]);
        let p = if vt <= m * v[0] {
            v
        } else if m * vt <= -v[0] {
            [0.0; 3]
        } else {
            let a = (v[0] + m * vt) / (1.0 + m * m);
            [a, m * a * v[1] / vt, m * a * v[2] / vt]
        };
        for k in 0..3 {
            res += (ri[k] - p[k]).powi(2);
            scale += (rho * terms[3 * i + k]).powi(2);
        }
    }
    let rnorm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
    res.sqrt() / (rnorm + scale.sqrt())
}

#[test]
fn an_unsymmetric_delassus_matrix_is_solved_to_tolerance() {
    for (seed, asym, mu) in [
        (1, 1e-3, 0.7),
        (2, 1e-2, 0.3),
        (3, 1e-6, 1.0),
        (4, 2e-3, 0.5),
    ] {
        let p = pile::pile(60, mu, seed);
        let sym = BlockCsr::from_coo(3, p.n, &p.rows, &p.cols, &p.vals).expect("well-formed");
        let mut w = sym.to_dense();
        let mut rng = SplitMix64::new(seed + 50);
        for v in w.iter_mut() {
            if *v != 0.0 {
                *v *= 1.0 + asym * rng.normal();
            }
        }
        for sparse in [false, true] {
            let tiles = BlockCsr::from_dense(3, p.n, &w).expect("well-formed");
            let problem = if sparse {
                ContactProblem::with_block_sparse(&tiles, &p.q, &p.mu)
            } else {
                ContactProblem::new(3, &w, &p.q, &p.mu)
            }
            .expect("well-formed");
            let s = NsgsSettings {
                tol: 1e-8,
                max_iter: 20_000,
                ..Default::default()
            };
            let sol = solve_nsgs(&problem, &s).expect("valid settings");
            assert!(sol.success(), "seed {seed}: {}", sol.message);
            let e = natural_map_error(&w, &p.q, &p.mu, &sol.impulse);
            assert!(
                e <= 1e-8,
                "seed {seed} (asymmetry {asym}): natural map {e:.2e}"
            );
        }
    }
}
