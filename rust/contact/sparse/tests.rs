//! Unit tests of the block CSR storage.

use super::*;
use crate::testing::SplitMix64;

fn random_sparse(n: usize, density: f64, seed: u64) -> Vec<f64> {
    let mut rng = SplitMix64::new(seed);
    (0..n * n)
        .map(|_| {
            if rng.uniform() < density {
                rng.normal()
            } else {
                0.0
            }
        })
        .collect()
}

fn csr_of(n: usize, w: &[f64]) -> (Vec<i64>, Vec<i64>, Vec<f64>) {
    let mut ptr = vec![0i64];
    let (mut idx, mut val) = (Vec::new(), Vec::new());
    for r in 0..n {
        // reversed column order: unsorted input
        for c in (0..n).rev() {
            if w[r * n + c] != 0.0 {
                idx.push(c as i64);
                val.push(w[r * n + c]);
            }
        }
        ptr.push(idx.len() as i64);
    }
    (ptr, idx, val)
}

#[test]
fn csr_csc_coo_and_dense_agree_and_round_trip() {
    for (dim, nc, seed) in [(3, 7, 1), (2, 9, 2), (3, 1, 3), (2, 4, 4)] {
        let n = dim * nc;
        let w = random_sparse(n, 0.15, seed);
        let (ptr, idx, val) = csr_of(n, &w);
        let a = BlockCsr::from_csr(dim, n, &ptr, &idx, &val).unwrap();
        assert_eq!(a.to_dense(), w);
        // CSC of W is CSR of W^T
        let wt: Vec<f64> = (0..n * n).map(|k| w[(k % n) * n + k / n]).collect();
        let (cptr, cidx, cval) = csr_of(n, &wt);
        let b = BlockCsr::from_csc(dim, n, &cptr, &cidx, &cval).unwrap();
        assert_eq!(b.to_dense(), w);
        // COO with duplicates: every entry split in two halves, shuffled order
        let (mut rows, mut cols, mut data) = (Vec::new(), Vec::new(), Vec::new());
        for k in (0..n * n).rev() {
            if w[k] != 0.0 {
                for _ in 0..2 {
                    rows.push((k / n) as i32);
                    cols.push((k % n) as i32);
                    data.push(0.5 * w[k]);
                }
            }
        }
        let c = BlockCsr::from_coo(dim, n, &rows, &cols, &data).unwrap();
        assert_eq!(c.to_dense(), w);
        let d = BlockCsr::from_dense(dim, n, &w).unwrap();
        assert_eq!(a, d);
        let tiles = BlockCsr::dense_tile_count(dim, nc, &w);
        assert_eq!(BlockCsr::from_dense_counted(dim, nc, &w, tiles), d);
        assert_eq!(a, c);
        // every diagonal tile is stored, sorted columns
        for i in 0..nc {
            assert!(a.row_cols(i).contains(&i));
            assert!(a.row_cols(i).windows(2).all(|p| p[0] < p[1]));
        }
        // products
        let mut rng = SplitMix64::new(seed + 100);
        let x: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
        let mut y = vec![0.0; n];
        a.mul(&x, &mut y);
        for r in 0..n {
            let e: f64 = (0..n).map(|c| w[r * n + c] * x[c]).sum();
            assert!((y[r] - e).abs() <= 1e-13 * (1.0 + e.abs()));
        }
    }
}

#[test]
fn an_empty_matrix_keeps_zero_diagonal_tiles() {
    let a = BlockCsr::from_csr::<i32>(3, 6, &[0; 7], &[], &[]).unwrap();
    assert_eq!(a.nnz_blocks(), 2);
    assert_eq!(a.diag_values(1), &[0.0; 9]);
    assert!(a.block(0, 1).is_none());
    assert_eq!(a.to_dense(), vec![0.0; 36]);
}

#[test]
fn bad_arrays_are_refused() {
    let ptr = [0i64, 1, 2, 2, 3];
    let idx = [0i64, 1, 3];
    let val = [1.0, 2.0, 3.0];
    assert!(BlockCsr::from_csr(2, 4, &ptr, &idx, &val).is_ok());
    let shape = |r: Result<BlockCsr>| matches!(r, Err(CoulombError::Shape(_)));
    // n not a multiple of dim
    assert!(shape(BlockCsr::from_csr(3, 4, &ptr, &idx, &val)));
    // index out of range, negative index
    assert!(shape(BlockCsr::from_csr(2, 4, &ptr, &[0, 1, 4], &val)));
    assert!(shape(BlockCsr::from_csr(2, 4, &ptr, &[0, -1, 3], &val)));
    // indptr: wrong length, decreasing, wrong end, not starting at 0
    assert!(shape(BlockCsr::from_csr(2, 4, &ptr[..4], &idx, &val)));
    assert!(shape(BlockCsr::from_csr(
        2,
        4,
        &[0, 2, 1, 2, 3],
        &idx,
        &val
    )));
    assert!(shape(BlockCsr::from_csr(
        2,
        4,
        &[0, 1, 2, 2, 2],
        &idx,
        &val
    )));
    assert!(shape(BlockCsr::from_csr(
        2,
        4,
        &[1, 1, 2, 2, 3],
        &idx,
        &val
    )));
    // lengths
    assert!(shape(BlockCsr::from_csr(2, 4, &ptr, &idx[..2], &val)));
    assert!(shape(BlockCsr::from_coo(2, 4, &idx, &idx[..2], &val)));
    assert!(shape(BlockCsr::from_coo(2, 4, &[0, 1, 9], &idx, &val)));
    assert!(matches!(
        BlockCsr::from_csr(2, 4, &ptr, &idx, &[1.0, f64::NAN, 0.0]),
        Err(CoulombError::NonFinite(_))
    ));
    assert!(matches!(
        BlockCsr::from_csr(4, 4, &ptr, &idx, &val),
        Err(CoulombError::InvalidParameter(_))
    ));
    assert!(shape(BlockCsr::from_dense(2, 4, &[0.0; 15])));
}
