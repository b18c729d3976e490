//! What an NSGS sweep reads of W: for contact i, `Σ_{j != i} W_ij r_j`.
//!
//! A block-sparse W is read in place. A dense W whose `dim x dim` tiles are mostly zero (a
//! mechanism's `W = G^T M^-1 G` has `W_ij != 0` only when contacts i and j share a body) is
//! copied once into block CSR ([`tiled`]) and the whole solve, sweeps and measures, runs on
//! the copy, so each reads O(nnz) memory instead of `(dim nc)^2` doubles; a dense W with more
//! nonzero tiles than half, or whose copy would exceed the memory budget, is read row by row.
//! Each component is summed left to right in column order whichever the storage (a zero tile
//! adds exactly nothing), so the storages give bitwise equal sums.

use super::super::{BlockCsr, ContactProblem, Delassus};

/// the block CSR copy of a dense W whose tiles are mostly zero (see the module notes), or
/// `None`: block-sparse already, mostly nonzero, or over the memory budget.
pub(super) fn tiled(problem: &ContactProblem<'_>) -> Option<BlockCsr> {
    let Delassus::Dense(w) = problem.storage() else {
        return None;
    };
    let (dim, nc) = (problem.dim, problem.nc);
    let tiles = BlockCsr::dense_tile_count(dim, nc, w);
    let bytes = tiles.saturating_mul(dim * dim * 8 + 8);
    (tiles.saturating_mul(2) <= nc.saturating_mul(nc) && bytes <= crate::limits::memory_budget())
        .then(|| BlockCsr::from_dense_counted(dim, nc, w, tiles))
}

/// the storage an NSGS sweep reads W from.
pub(super) enum OffDiagonal<'a> {
    /// block CSR.
    Tiles(&'a BlockCsr),
    /// a row-major dense W.
    Dense(&'a [f64]),
}

impl<'a> OffDiagonal<'a> {
    /// the storage of `problem`.
    pub(super) fn of(problem: &ContactProblem<'a>) -> Self {
        match problem.storage() {
            Delassus::BlockSparse(b) => Self::Tiles(b),
            Delassus::Dense(w) => Self::Dense(w),
        }
    }

    /// whether block row i (of contacts of dimension `dim`) has no nonzero off-diagonal tile.
    pub(super) fn isolated(&self, i: usize, dim: usize) -> bool {
        match self {
            Self::Tiles(b) => b.row_cols(i).len() <= 1,
            Self::Dense(w) => {
                let n = w.len().isqrt();
                (i * dim..(i + 1) * dim).all(|row| {
                    let r = &w[row * n..(row + 1) * n];
                    r[..i * dim]
                        .iter()
                        .chain(&r[(i + 1) * dim..])
                        .all(|&v| v == 0.0)
                })
            }
        }
    }

    /// `Σ_{j != i} W_ij x_j`, the `dim` components of contact i zero-padded to 3.
    #[inline]
    pub(super) fn mul(&self, i: usize, dim: usize, x: &[f64]) -> [f64; 3] {
        match self {
            Self::Tiles(b) => b.row_mul(i, x, true),
            Self::Dense(w) => dense_row_mul_offdiag(w, dim, i, x),
        }
    }
}

/// `Σ_{j != i} W_ij x_j` from a dense row-major W: the `dim` rows of contact i are walked
/// together, tile by tile, each component in column order.
fn dense_row_mul_offdiag(w: &[f64], dim: usize, i: usize, x: &[f64]) -> [f64; 3] {
    let n = x.len();
    let o = i * dim;
    let mut out = [0.0; 3];
    if dim == 3 {
        let rows = &w[o * n..(o + 3) * n];
        let (r0, rest) = rows.split_at(n);
        let (r1, r2) = rest.split_at(n);
        for part in [0..o, o + 3..n] {
            let xs = &x[part.clone()];
            let tiles = r0[part.clone()]
                .chunks_exact(3)
                .zip(r1[part.clone()].chunks_exact(3))
                .zip(r2[part].chunks_exact(3))
                .zip(xs.chunks_exact(3));
            for (((a, b), c), xj) in tiles {
                out[0] += a[0] * xj[0];
                out[0] += a[1] * xj[1];
                out[0] += a[2] * xj[2];
                out[1] += b[0] * xj[0];
                out[1] += b[1] * xj[1];
                out[1] += b[2] * xj[2];
                out[2] += c[0] * xj[0];
                out[2] += c[1] * xj[1];
                out[2] += c[2] * xj[2];
            }
        }
    } else {
        for (a, v) in out.iter_mut().enumerate().take(dim) {
            let row = &w[(o + a) * n..(o + a + 1) * n];
            let mut acc = 0.0;
            for (p, q) in row[..o].iter().zip(&x[..o]) {
                acc += p * q;
            }
            for (p, q) in row[o + dim..].iter().zip(&x[o + dim..]) {
                acc += p * q;
            }
            *v = acc;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::SplitMix64;

    /// the storages give bitwise equal off-diagonal products, on W with zero tiles and
    /// without; a W with mostly zero tiles is copied, a mostly nonzero one is not.
    #[test]
    fn dense_copied_and_sparse_rows_agree_bitwise() {
        let mut rng = SplitMix64::new(5);
        for (dim, nc, density) in [(3, 9, 0.2), (3, 6, 1.0), (2, 11, 0.3), (2, 5, 1.0)] {
            let n = dim * nc;
            let mut w = vec![0.0; n * n];
            for bi in 0..nc {
                for bj in 0..nc {
                    if bi == bj || rng.uniform() < density {
                        for a in 0..dim {
                            for c in 0..dim {
                                w[(bi * dim + a) * n + bj * dim + c] = rng.normal();
                            }
                        }
                    }
                }
            }
            let x: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
            let q = vec![0.0; n];
            let mu = vec![0.5; nc];
            let p = ContactProblem::new(dim, &w, &q, &mu).unwrap();
            let copy = tiled(&p);
            assert_eq!(copy.is_some(), density < 1.0);
            let sparse = BlockCsr::from_dense(dim, n, &w).unwrap();
            let dense = OffDiagonal::of(&p);
            for i in 0..nc {
                let a = dense.mul(i, dim, &x);
                let b = sparse.row_mul(i, &x, true);
                assert_eq!(a, b);
                if let Some(c) = &copy {
                    assert_eq!(c.row_mul(i, &x, true), b);
                }
                let o = i * dim;
                for k in 0..dim {
                    let e: f64 = (0..n)
                        .filter(|&c| c / dim != i)
                        .map(|c| w[(o + k) * n + c] * x[c])
                        .sum();
                    assert!((a[k] - e).abs() <= 1e-13 * (1.0 + e.abs()));
                }
            }
        }
    }
}
