//! `contact::assembly`: W = G^T M^-1 G, q = G^T v_free + w and v = v_free + M^-1 G r against
//! Gaussian elimination, for diagonal, block-diagonal and coupled (sparse Cholesky) M; M not
//! positive definite is refused naming M.
#![allow(clippy::needless_range_loop)]

use coulomb::contact::assembly::{
    assemble, post_velocity, FreeMotion, MassFactor, Triplets, DENSE_BLOCK_MAX,
};
use coulomb::testing::SplitMix64;
use coulomb::CoulombError;

/// solves A x = b (row-major n x n) by Gaussian elimination with partial pivoting.
fn gauss(a: &[f64], b: &[f64]) -> Vec<f64> {
    let n = b.len();
    let mut m = a.to_vec();
    let mut x = b.to_vec();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| m[i * n + c].abs().total_cmp(&m[j * n + c].abs()))
            .unwrap();
        for k in 0..n {
            m.swap(c * n + k, p * n + k);
        }
        x.swap(c, p);
        for r in c + 1..n {
            let f = m[r * n + c] / m[c * n + c];
            for k in c..n {
                m[r * n + k] -= f * m[c * n + k];
            }
            x[r] -= f * x[c];
        }
    }
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|k| m[r * n + k] * x[k]).sum();
        x[r] = (x[r] - s) / m[r * n + r];
    }
    x
}

struct Owned {
    n: usize,
    m: usize,
    rows: Vec<usize>,
    cols: Vec<usize>,
    vals: Vec<f64>,
}

impl Owned {
    fn of_dense(a: &[f64], n: usize, m: usize) -> Self {
        let mut o = Owned {
            n,
            m,
            rows: vec![],
            cols: vec![],
            vals: vec![],
        };
        for i in 0..n {
            for j in 0..m {
                if a[i * m + j] != 0.0 {
                    o.rows.push(i);
                    o.cols.push(j);
                    o.vals.push(a[i * m + j]);
                }
            }
        }
        o
    }
    fn view(&self) -> Triplets<'_> {
        Triplets {
            nrows: self.n,
            ncols: self.m,
            rows: &self.rows,
            cols: &self.cols,
            vals: &self.vals,
        }
    }
}

/// a symmetric positive definite M made of diagonal blocks of the given sizes.
fn block_spd(rng: &mut SplitMix64, sizes: &[usize]) -> (Vec<f64>, usize) {
    let n: usize = sizes.iter().sum();
    let mut m = vec![0.0; n * n];
    let mut o = 0;
    for &s in sizes {
        let a: Vec<f64> = (0..s * s).map(|_| rng.normal()).collect();
        for i in 0..s {
            for j in 0..s {
                let v: f64 = (0..s).map(|k| a[i * s + k] * a[j * s + k]).sum();
                m[(o + i) * n + o + j] = v + if i == j { 0.5 } else { 0.0 };
            }
        }
        o += s;
    }
    (m, n)
}

fn check(m: &[f64], n: usize, rng: &mut SplitMix64, ncols: usize) {
    let g: Vec<f64> = (0..n * ncols)
        .map(|_| {
            let v = rng.normal();
            if v.abs() < 0.5 {
                0.0
            } else {
                v
            }
        })
        .collect();
    let v_free: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
    let extra: Vec<f64> = (0..ncols).map(|_| rng.normal()).collect();
    let mt = Owned::of_dense(m, n, n);
    let gt = Owned::of_dense(&g, n, ncols);
    let out = assemble(
        &mt.view(),
        &gt.view(),
        FreeMotion::Velocity(&v_free),
        Some(&extra),
    )
    .unwrap();
    // oracle: column k of M^-1 G by elimination
    let mut wmax: f64 = 0.0;
    let mut werr: f64 = 0.0;
    for k in 0..ncols {
        let col: Vec<f64> = (0..n).map(|a| g[a * ncols + k]).collect();
        let x = gauss(m, &col);
        for j in 0..ncols {
            let wjk: f64 = (0..n).map(|a| g[a * ncols + j] * x[a]).sum();
            wmax = wmax.max(wjk.abs());
            werr = werr.max((wjk - out.w[j * ncols + k]).abs());
        }
        let qk: f64 = (0..n).map(|a| g[a * ncols + k] * v_free[a]).sum::<f64>() + extra[k];
        assert!((qk - out.q[k]).abs() <= 1e-12 * (1.0 + qk.abs()));
    }
    assert!(werr <= 1e-10 * wmax, "W error {werr} of {wmax}");
    // the velocity update
    let r: Vec<f64> = (0..ncols).map(|_| rng.normal()).collect();
    let factor = MassFactor::new(&mt.view()).unwrap();
    let v = post_velocity(&factor, &gt.view(), &v_free, &r).unwrap();
    let gr: Vec<f64> = (0..n)
        .map(|a| (0..ncols).map(|k| g[a * ncols + k] * r[k]).sum())
        .collect();
    let x = gauss(m, &gr);
    for a in 0..n {
        assert!((v[a] - v_free[a] - x[a]).abs() <= 1e-10 * (1.0 + x[a].abs()));
    }
}

#[test]
fn diagonal_block_diagonal_and_coupled_mass_matrices() {
    let mut rng = SplitMix64::new(3);
    let (m, n) = block_spd(&mut rng, &[1, 1, 1, 1]);
    check(&m, n, &mut rng, 6);
    let (m, n) = block_spd(&mut rng, &[6, 6, 3, 6]);
    check(&m, n, &mut rng, 12);
    // one coupled block beyond the dense-block limit: faer's sparse Cholesky
    let (m, n) = block_spd(&mut rng, &[DENSE_BLOCK_MAX + 4]);
    check(&m, n, &mut rng, 5);
    let factor = MassFactor::new(&Owned::of_dense(&m, n, n).view()).unwrap();
    assert!(matches!(factor, MassFactor::Sparse(_)));
}

#[test]
fn force_gives_the_free_velocity() {
    let mut rng = SplitMix64::new(8);
    let (m, n) = block_spd(&mut rng, &[6, 6]);
    let g: Vec<f64> = (0..n * 4).map(|_| rng.normal()).collect();
    let f: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
    let mt = Owned::of_dense(&m, n, n);
    let gt = Owned::of_dense(&g, n, 4);
    let out = assemble(&mt.view(), &gt.view(), FreeMotion::Force(&f), None).unwrap();
    let v = gauss(&m, &f);
    for a in 0..n {
        assert!((out.v_free[a] - v[a]).abs() <= 1e-12 * (1.0 + v[a].abs()));
    }
}

#[test]
fn bad_mass_matrices_are_refused_naming_m() {
    let g = Owned::of_dense(&[1.0, 0.0, 0.0, 1.0], 2, 2);
    let v = [0.0, 0.0];
    for (m, words) in [
        (vec![1.0, 0.0, 0.0, -1.0], "not positive definite"),
        (vec![1.0, 2.0, 2.0, 1.0], "not positive definite"),
        (vec![1.0, 1.0, 1.0, 1.0], "not positive definite"),
        (vec![2.0, 1.0, 0.0, 2.0], "symmetric"),
    ] {
        let mt = Owned::of_dense(&m, 2, 2);
        match assemble(&mt.view(), &g.view(), FreeMotion::Velocity(&v), None) {
            Err(CoulombError::InvalidParameter(msg)) => {
                assert!(
                    msg.contains("mass matrix M") && msg.contains(words),
                    "{msg}"
                )
            }
            other => panic!("{m:?}: {other:?}"),
        }
    }
    let mt = Owned::of_dense(&[1.0, 0.0, 0.0, 1.0], 2, 2);
    let bad_g = Owned::of_dense(&[1.0, 0.0, 0.0], 3, 1);
    assert!(matches!(
        assemble(&mt.view(), &bad_g.view(), FreeMotion::Velocity(&v), None),
        Err(CoulombError::Shape(_))
    ));
    assert!(matches!(
        assemble(
            &mt.view(),
            &g.view(),
            FreeMotion::Velocity(&[f64::NAN, 0.0]),
            None
        ),
        Err(CoulombError::NonFinite(_))
    ));
    let out_of_range = Triplets {
        nrows: 2,
        ncols: 2,
        rows: &[0, 5],
        cols: &[0, 1],
        vals: &[1.0, 1.0],
    };
    assert!(matches!(
        MassFactor::new(&out_of_range),
        Err(CoulombError::Shape(_))
    ));
}
