//! `u_i = (W r)_i` and the magnitudes of its terms `(|W| |r|)_i` for one contact, the d rows of
//! its block row taken in one pass over r (dense W) or over its tiles (block-sparse W), with the
//! dimension known at compile time.
//!
//! Each row's sums run in the same order as [`ContactProblem::block_row_terms`]'s (column by
//! column, from 0), so the values are the same to the last bit: only the loop over the rows is
//! moved inside, where it shares the loads of r and the loop's bookkeeping.

use super::super::{ContactProblem, Delassus};

/// `((W r)_i, (|W| |r|)_i)`, zero-padded to 3.
#[inline]
pub(super) fn row_terms<const D: usize>(
    problem: &ContactProblem<'_>,
    i: usize,
    r: &[f64],
) -> ([f64; 3], [f64; 3]) {
    match (problem.storage(), D) {
        (Delassus::Dense(w), 2) => dense2(w, problem.size(), i, r),
        (Delassus::Dense(w), 3) => dense3(w, problem.size(), i, r),
        (Delassus::BlockSparse(s), 2) => tiles::<2>(s.row_cols(i), s.row_values(i), r),
        (Delassus::BlockSparse(s), 3) => tiles::<3>(s.row_cols(i), s.row_values(i), r),
        _ => problem.block_row_terms(i, r),
    }
}

/// rows `2i, 2i + 1` of a dense row-major `n x n` W against x.
#[inline]
fn dense2(w: &[f64], n: usize, i: usize, x: &[f64]) -> ([f64; 3], [f64; 3]) {
    let (r0, r1) = w[2 * i * n..(2 * i + 2) * n].split_at(n);
    let (mut s, mut t) = ([0.0; 3], [0.0; 3]);
    for ((&p0, &p1), &xc) in r0.iter().zip(r1).zip(x) {
        let (v0, v1) = (p0 * xc, p1 * xc);
        s[0] += v0;
        t[0] += v0.abs();
        s[1] += v1;
        t[1] += v1.abs();
    }
    (s, t)
}

/// rows `3i .. 3i + 2` of a dense row-major `n x n` W against x.
#[inline]
fn dense3(w: &[f64], n: usize, i: usize, x: &[f64]) -> ([f64; 3], [f64; 3]) {
    let (r0, rest) = w[3 * i * n..(3 * i + 3) * n].split_at(n);
    let (r1, r2) = rest.split_at(n);
    let (mut s, mut t) = ([0.0; 3], [0.0; 3]);
    for (((&p0, &p1), &p2), &xc) in r0.iter().zip(r1).zip(r2).zip(x) {
        let (v0, v1, v2) = (p0 * xc, p1 * xc, p2 * xc);
        s[0] += v0;
        t[0] += v0.abs();
        s[1] += v1;
        t[1] += v1.abs();
        s[2] += v2;
        t[2] += v2.abs();
    }
    (s, t)
}

/// a block row stored as D x D row-major tiles (columns `cols`) against x.
#[inline]
fn tiles<const D: usize>(cols: &[usize], values: &[f64], x: &[f64]) -> ([f64; 3], [f64; 3]) {
    let mut s = [0.0; 3];
    let mut t = [0.0; 3];
    for (&j, b) in cols.iter().zip(values.chunks_exact(D * D)) {
        let xj = &x[D * j..D * j + D];
        for a in 0..D {
            for c in 0..D {
                let v = b[D * a + c] * xj[c];
                s[a] += v;
                t[a] += v.abs();
            }
        }
    }
    (s, t)
}
