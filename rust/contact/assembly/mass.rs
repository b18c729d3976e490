//! The mass matrix M of a contact problem and its factorization: the finest block-diagonal
//! partition of M, a dense Cholesky `M_b = L_b L_b^T` per small block, faer's sparse Cholesky
//! otherwise (Acary and Brogliato 2008, ch. 10: the Delassus operator needs `M^{-1}` applied to
//! the contact directions).

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::Llt;
use faer::sparse::{SparseColMat, Triplet};
use faer::Side;

use crate::error::{check_finite, CoulombError, Result};

/// blocks of M up to this many dofs are factored densely, block by block.
pub const DENSE_BLOCK_MAX: usize = 256;

/// relative symmetry tolerance on M: `|M_ij - M_ji| <= SYM_TOL max |M|`.
const SYM_TOL: f64 = 1e-10;

/// relative pivot floor of the dense Cholesky: pivots at most this times the largest diagonal
/// entry of M mean M is (numerically) not positive definite.
const PIVOT_TOL: f64 = 1e-14;

/// A sparse matrix given by triplets `(row, col, value)`, repeated entries summed.
#[derive(Clone, Copy, Debug)]
pub struct Triplets<'a> {
    /// rows.
    pub nrows: usize,
    /// columns.
    pub ncols: usize,
    /// row index of each entry.
    pub rows: &'a [usize],
    /// column index of each entry.
    pub cols: &'a [usize],
    /// value of each entry.
    pub vals: &'a [f64],
}

impl<'a> Triplets<'a> {
    pub(super) fn check(&self, name: &str) -> Result<()> {
        let k = self.vals.len();
        if self.rows.len() != k || self.cols.len() != k {
            return Err(CoulombError::Shape(format!(
                "{name}: rows, cols and values must have the same length, got {}, {} and {k}",
                self.rows.len(),
                self.cols.len()
            )));
        }
        if let Some(e) = (0..k).find(|&e| self.rows[e] >= self.nrows || self.cols[e] >= self.ncols)
        {
            return Err(CoulombError::Shape(format!(
                "{name}: entry {e} at ({}, {}) lies outside the {} x {} matrix",
                self.rows[e], self.cols[e], self.nrows, self.ncols
            )));
        }
        check_finite(name, self.vals)
    }

    /// the entries sorted by (col, row) with repeats summed.
    pub(super) fn canonical(&self) -> Vec<(usize, usize, f64)> {
        let mut e: Vec<(usize, usize, f64)> = (0..self.vals.len())
            .map(|k| (self.cols[k], self.rows[k], self.vals[k]))
            .collect();
        e.sort_by_key(|a| (a.0, a.1));
        let mut out: Vec<(usize, usize, f64)> = Vec::with_capacity(e.len());
        for (c, r, v) in e {
            match out.last_mut() {
                Some(last) if last.0 == c && last.1 == r => last.2 += v,
                _ => out.push((c, r, v)),
            }
        }
        out
    }
}

/// The factor of a mass matrix M (see the module notes).
#[derive(Clone, Debug)]
pub enum MassFactor {
    /// M block diagonal with small blocks: `(offset, size, L_b row-major)` per block.
    Blocks(Vec<(usize, usize, Vec<f64>)>),
    /// faer's sparse Cholesky of the whole of M.
    Sparse(Llt<usize, f64>),
}

impl MassFactor {
    /// factors M (`ndof x ndof`, triplets); refuses a non-square, asymmetric, non-finite or
    /// not positive definite M.
    pub fn new(m: &Triplets<'_>) -> Result<Self> {
        if m.nrows != m.ncols {
            return Err(CoulombError::Shape(format!(
                "the mass matrix M must be square, got {} x {}",
                m.nrows, m.ncols
            )));
        }
        m.check("the mass matrix M")?;
        let n = m.nrows;
        let entries = m.canonical();
        let scale = entries.iter().fold(0.0f64, |a, e| a.max(e.2.abs()));
        // symmetry: every entry against its mirror (absent mirror = 0)
        for &(c, r, v) in &entries {
            if r == c {
                continue;
            }
            let mirror = entries
                .binary_search_by(|e| (e.0, e.1).cmp(&(r, c)))
                .map(|k| entries[k].2)
                .unwrap_or(0.0);
            if (v - mirror).abs() > SYM_TOL * scale {
                return Err(CoulombError::InvalidParameter(format!(
                    "the mass matrix M must be symmetric: M[{r}, {c}] = {v} but M[{c}, {r}] = \
                     {mirror}"
                )));
            }
        }
        let mut diag = vec![0.0; n];
        for &(c, r, v) in &entries {
            if r == c {
                diag[r] = v;
            }
        }
        if let Some(k) = diag.iter().position(|&d| d <= 0.0) {
            return Err(CoulombError::InvalidParameter(format!(
                "the mass matrix M is not positive definite: M[{k}, {k}] = {} <= 0",
                diag[k]
            )));
        }
        let dmax = diag.iter().fold(0.0f64, |a, &d| a.max(d));
        // the finest block-diagonal partition: reach[k] = the largest index coupled to k
        let mut reach: Vec<usize> = (0..n).collect();
        for &(c, r, _) in &entries {
            let (lo, hi) = if r < c { (r, c) } else { (c, r) };
            reach[lo] = reach[lo].max(hi);
        }
        let mut blocks = Vec::new();
        let mut start = 0;
        let mut end = 0;
        for (k, &rk) in reach.iter().enumerate() {
            end = end.max(rk);
            if end == k {
                blocks.push((start, k + 1 - start));
                start = k + 1;
            }
        }
        let largest = blocks.iter().map(|b| b.1).max().unwrap_or(0);
        if largest <= DENSE_BLOCK_MAX {
            let mut out = Vec::with_capacity(blocks.len());
            let mut block_of = vec![0usize; n];
            for (b, &(o, s)) in blocks.iter().enumerate() {
                block_of[o..o + s].fill(b);
            }
            let mut dense: Vec<Vec<f64>> = blocks.iter().map(|&(_, s)| vec![0.0; s * s]).collect();
            for &(c, r, v) in &entries {
                let b = block_of[r];
                let (o, s) = blocks[b];
                dense[b][(r - o) * s + (c - o)] = v;
            }
            for (&(o, s), mut a) in blocks.iter().zip(dense) {
                if let Err(k) = cholesky_in_place(&mut a, s, PIVOT_TOL * dmax) {
                    return Err(CoulombError::InvalidParameter(format!(
                        "the mass matrix M is not positive definite (Cholesky pivot {} of the \
                         diagonal block of dofs {o}..{} is not positive)",
                        o + k,
                        o + s
                    )));
                }
                out.push((o, s, a));
            }
            return Ok(MassFactor::Blocks(out));
        }
        let lower: Vec<Triplet<usize, usize, f64>> = entries
            .iter()
            .filter(|e| e.1 >= e.0)
            .map(|&(c, r, v)| Triplet::new(r, c, v))
            .collect();
        let mat = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &lower)
            .map_err(|e| CoulombError::InvalidParameter(format!("the mass matrix M: {e:?}")))?;
        let llt = mat.sp_cholesky(Side::Lower).map_err(|e| {
            CoulombError::InvalidParameter(format!(
                "the mass matrix M is not positive definite (sparse Cholesky: {e:?})"
            ))
        })?;
        Ok(MassFactor::Sparse(llt))
    }

    /// the diagonal blocks `(offset, size)` the factor works on: one per block of a block
    /// diagonal M, the whole of M for the sparse factor.
    pub fn block_ranges(&self, ndof: usize) -> Vec<(usize, usize)> {
        match self {
            MassFactor::Blocks(blocks) => blocks.iter().map(|(o, s, _)| (*o, *s)).collect(),
            MassFactor::Sparse(_) => vec![(0, ndof)],
        }
    }

    /// `x <- M_b^{-1} x` on block `b` of [`Self::block_ranges`] (`x` its entries).
    pub fn solve_block_in_place(&self, b: usize, x: &mut [f64]) {
        match self {
            MassFactor::Blocks(blocks) => {
                let (_, s, l) = &blocks[b];
                solve_cholesky(l, *s, x);
            }
            MassFactor::Sparse(_) => self.solve_in_place(x),
        }
    }

    /// `x <- M^{-1} x`.
    pub fn solve_in_place(&self, x: &mut [f64]) {
        match self {
            MassFactor::Blocks(blocks) => {
                for (o, s, l) in blocks {
                    solve_cholesky(l, *s, &mut x[*o..*o + *s]);
                }
            }
            MassFactor::Sparse(llt) => {
                let n = x.len();
                llt.solve_in_place(faer::MatMut::from_column_major_slice_mut(x, n, 1));
            }
        }
    }
}

/// `x <- (L L^T)^{-1} x` for a row-major `s x s` lower-triangular factor L: `L y = x`, then
/// `L^T z = y`.
pub(crate) fn solve_cholesky(l: &[f64], s: usize, x: &mut [f64]) {
    for i in 0..s {
        let mut v = x[i];
        for k in 0..i {
            v -= l[i * s + k] * x[k];
        }
        x[i] = v / l[i * s + i];
    }
    for i in (0..s).rev() {
        let mut v = x[i];
        for k in i + 1..s {
            v -= l[k * s + i] * x[k];
        }
        x[i] = v / l[i * s + i];
    }
}

/// dense Cholesky `A = L L^T` in place (row-major s x s, L in the lower triangle, the upper
/// triangle zeroed); `Err(k)` when pivot k is at most `floor`.
pub(crate) fn cholesky_in_place(
    a: &mut [f64],
    s: usize,
    floor: f64,
) -> std::result::Result<(), usize> {
    for j in 0..s {
        let mut d = a[j * s + j];
        for k in 0..j {
            d -= a[j * s + k] * a[j * s + k];
        }
        if d.is_nan() || d <= floor {
            return Err(j);
        }
        let ljj = d.sqrt();
        a[j * s + j] = ljj;
        for i in j + 1..s {
            let mut v = a[i * s + j];
            for k in 0..j {
                v -= a[i * s + k] * a[j * s + k];
            }
            a[i * s + j] = v / ljj;
        }
        for c in j + 1..s {
            a[j * s + c] = 0.0;
        }
    }
    Ok(())
}
