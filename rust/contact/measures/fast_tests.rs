//! The optimized measure against the reference, to the last bit.

use super::reference::measure_reference;
use super::{measure_into, ContactMeasures};
use crate::contact::sparse::BlockCsr;
use crate::contact::ContactProblem;
use crate::testing::SplitMix64;

fn bits(m: &ContactMeasures) -> [u64; 7] {
    [
        m.error.to_bits(),
        m.error_q.to_bits(),
        m.scaled_error.to_bits(),
        m.min_normal_impulse.to_bits(),
        m.max_complementarity.to_bits(),
        m.cone_violation.to_bits(),
        m.dissipation_violation.to_bits(),
    ]
}

fn same(p: &ContactProblem<'_>, r: &[f64], what: &str) {
    let n = p.size();
    let (mut u, mut v) = (vec![7.0; n], vec![-3.0; n]);
    let fast = measure_into(p, r, &mut u);
    let reference = measure_reference(p, r, &mut v);
    assert_eq!(
        bits(&fast),
        bits(&reference),
        "{what}: {fast:?} vs {reference:?}"
    );
    let ub: Vec<u64> = u.iter().map(|x| x.to_bits()).collect();
    let vb: Vec<u64> = v.iter().map(|x| x.to_bits()).collect();
    assert_eq!(ub, vb, "{what}: u");
}

/// a random W (a Gram matrix with some zero coupling blocks), q, r, mu over the class: both
/// dims, mu from 0 to 1e12, r with zero contacts, answers near a solution (u ~ 0).
#[allow(clippy::type_complexity)]
fn case(rng: &mut SplitMix64, dim: usize, nc: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = dim * nc;
    let g: Vec<f64> = (0..n * n).map(|_| rng.normal()).collect();
    let mut w = vec![0.0; n * n];
    for a in 0..n {
        for b in 0..n {
            w[a * n + b] = (0..n).map(|k| g[k * n + a] * g[k * n + b]).sum();
        }
    }
    // uncouple some pairs of contacts (sparse rows)
    for i in 0..nc {
        for j in 0..nc {
            if i != j && (i + j) % 3 == 0 {
                for a in 0..dim {
                    for b in 0..dim {
                        w[(i * dim + a) * n + j * dim + b] = 0.0;
                        w[(j * dim + b) * n + i * dim + a] = 0.0;
                    }
                }
            }
        }
    }
    let mut r: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
    for i in 0..nc {
        match rng.below(4) {
            0 => r[i * dim..(i + 1) * dim].fill(0.0),
            1 => r[i * dim] = r[i * dim].abs(),
            _ => {}
        }
    }
    let mut q: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
    if rng.below(2) == 0 {
        // near a solution: u = W r + q of the rounding's size, or exactly 0 in places
        let tiny = [0.0, 1e-16, 1e-12, 1e-6][rng.below(4)];
        for a in 0..n {
            let wr: f64 = (0..n).map(|b| w[a * n + b] * r[b]).sum();
            q[a] = -wr + tiny * rng.normal();
        }
    }
    let mu: Vec<f64> = (0..nc)
        .map(|_| match rng.below(6) {
            0 => 0.0,
            1 => 1e12,
            2 => 1e8,
            _ => 10f64.powf(12.0 * rng.uniform() - 6.0),
        })
        .collect();
    (w, q, r, mu)
}

#[test]
fn the_fast_measure_equals_the_reference_to_the_last_bit() {
    let mut rng = SplitMix64::new(12);
    for k in 0..600 {
        let dim = 2 + k % 2;
        let nc = 1 + rng.below(6);
        let (w, q, r, mu) = case(&mut rng, dim, nc);
        let n = dim * nc;
        for (a, b) in [
            (1.0, 1.0),
            (1e-8, 1e8),
            (1e8, 1.0),
            (1e-200, 1e-200),
            (1.0, 1e300),
        ] {
            let ws: Vec<f64> = w.iter().map(|v| v * (b / a)).collect();
            let qs: Vec<f64> = q.iter().map(|v| v * b).collect();
            let rs: Vec<f64> = r.iter().map(|v| v * a).collect();
            let what = format!("case {k} dim {dim} nc {nc} units ({a}, {b})");
            let p = ContactProblem::new(dim, &ws, &qs, &mu).unwrap();
            same(&p, &rs, &format!("{what} dense"));
            let csr = BlockCsr::from_dense(dim, n, &ws).unwrap();
            let ps = ContactProblem::with_block_sparse(&csr, &qs, &mu).unwrap();
            same(&ps, &rs, &format!("{what} block-sparse"));
            if dim == 3 {
                // elliptic friction on some contacts (mu_1 != mu_2, a zero axis too)
                let pairs: Vec<f64> = mu
                    .iter()
                    .enumerate()
                    .flat_map(|(i, &m)| match i % 3 {
                        0 => [m, m],
                        1 => [m, 0.5 * m],
                        _ => [0.0, m],
                    })
                    .collect();
                let pa = ContactProblem::new(dim, &ws, &qs, &mu)
                    .unwrap()
                    .with_anisotropic_friction(&pairs)
                    .unwrap();
                same(&pa, &rs, &format!("{what} anisotropic"));
            }
        }
    }
}

#[test]
fn the_fast_measure_equals_the_reference_on_degenerate_data() {
    // no contacts, zero data, NaN and infinite entries, a contact without a positive W_nn
    let p = ContactProblem::new(2, &[], &[], &[]).unwrap();
    same(&p, &[], "no contacts");
    let w = [0.0, 0.0, 0.0, 0.0];
    let q = [0.0, 0.0];
    let p = ContactProblem::new(2, &w, &q, &[0.5]).unwrap();
    same(&p, &[0.0, 0.0], "all zero");
    same(&p, &[1.0, -0.2], "W = 0, q = 0");
    let w = [
        1.0, 0.2, 0.0, 0.0, 0.2, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    ];
    let q = [-1.0, 0.5, 2.0, -0.1];
    let p = ContactProblem::new(2, &w, &q, &[0.3, 1e12]).unwrap();
    for r in [
        [1.0, 0.2, 0.0, 0.0],
        [f64::NAN, 0.2, 0.0, 1.0],
        [1.0, f64::INFINITY, 0.5, 0.0],
        [1e300, -1e300, 1e-300, 0.0],
    ] {
        same(&p, &r, &format!("{r:?}"));
    }
}
