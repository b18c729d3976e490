//! Block-sparse storage of the Delassus matrix W: block CSR of `dim x dim` tiles.
//!
//! W is `(dim nc) x (dim nc)`; tile `W_ij` couples contact i with contact j. Only the tiles
//! with at least one stored scalar are kept (plus every diagonal tile, stored even when zero,
//! so a nonsmooth Gauss-Seidel sweep finds `W_ii` in O(1)). In a mechanism `W = G^T M^-1 G`
//! has a tile `W_ij != 0` only when contacts i and j touch a common body, so a pile or a chain
//! of bodies gives a few tiles per block row and `W x` costs O(nnz(W)).
//!
//! The storage is built from scalar CSR, CSC or COO triplets without ever forming the dense
//! matrix: the entries are bucketed by block row (a counting sort), the distinct block columns
//! of each block row found with a marker array, sorted, and the scalars summed into their tiles
//! (duplicate scalar entries add up, as in scipy.sparse). Any sparsity pattern is accepted: the
//! tiles are only a grouping of the entries.
//!
//! The assembly of a stepper rebuilds its W in place from whole tiles every step
//! (`sparse/rebuild.rs`).

mod rebuild;

use crate::error::{CoulombError, Result};

/// W in block CSR: block row i holds the tiles `W_ij` for `j in cols[row_ptr[i]..row_ptr[i+1]]`
/// (sorted, the diagonal always among them), each `dim * dim` scalars row-major in `values`.
#[derive(Clone, Debug, PartialEq)]
pub struct BlockCsr {
    dim: usize,
    nc: usize,
    row_ptr: Vec<usize>,
    cols: Vec<usize>,
    values: Vec<f64>,
    /// per block row, the position of its diagonal tile in `cols`.
    diag: Vec<usize>,
}

pub(crate) use rebuild::TileScratch;

/// An entry source for [`BlockCsr::from_entries`]: yields `(row, col, value)` and can be
/// replayed.
trait Entries: Fn(&mut dyn FnMut(usize, usize, f64)) {}
impl<F: Fn(&mut dyn FnMut(usize, usize, f64))> Entries for F {}

fn index_of<I>(name: &str, k: usize, v: I, bound: usize) -> Result<usize>
where
    I: Copy + TryInto<usize> + std::fmt::Debug,
{
    match v.try_into() {
        Ok(u) if u < bound => Ok(u),
        _ => Err(CoulombError::Shape(format!(
            "W's {name}[{k}] = {v:?} is out of range [0, {bound})"
        ))),
    }
}

fn check_dims(dim: usize, n: usize) -> Result<usize> {
    if dim != 2 && dim != 3 {
        return Err(CoulombError::InvalidParameter(format!(
            "dim must be 2 (planar) or 3 (spatial), got {dim}"
        )));
    }
    if !n.is_multiple_of(dim) {
        return Err(CoulombError::Shape(format!(
            "W is {n} x {n}, which is not a whole number of {dim} x {dim} contact blocks"
        )));
    }
    Ok(n / dim)
}

/// whether tile (bi, bj) of a dense row-major `n x n` W has a nonzero entry.
fn dense_tile_nonzero(w: &[f64], dim: usize, n: usize, bi: usize, bj: usize) -> bool {
    (0..dim).any(|a| {
        let row = (bi * dim + a) * n + bj * dim;
        w[row..row + dim].iter().any(|&v| v != 0.0)
    })
}

fn check_data(data: &[f64]) -> Result<()> {
    crate::error::check_finite("W's data", data)
}

/// checks a compressed pointer array: `ptr.len() == n + 1`, `ptr[0] = 0`, nondecreasing,
/// `ptr[n] = nnz`.
fn check_ptr<I: Copy + TryInto<usize> + std::fmt::Debug>(
    name: &str,
    ptr: &[I],
    n: usize,
    nnz: usize,
) -> Result<Vec<usize>> {
    if ptr.len() != n + 1 {
        return Err(CoulombError::Shape(format!(
            "W's {name} has {} entries, expected n + 1 = {}",
            ptr.len(),
            n + 1
        )));
    }
    let mut out = Vec::with_capacity(n + 1);
    let mut prev = 0usize;
    for (k, &p) in ptr.iter().enumerate() {
        let p = index_of(name, k, p, nnz + 1)?;
        if (k == 0 && p != 0) || p < prev {
            return Err(CoulombError::Shape(format!(
                "W's {name} must start at 0 and be nondecreasing ({name}[{k}] = {p} after {prev})"
            )));
        }
        prev = p;
        out.push(p);
    }
    if prev != nnz {
        return Err(CoulombError::Shape(format!(
            "W's {name}[n] = {prev} but {nnz} entries are given"
        )));
    }
    Ok(out)
}

impl BlockCsr {
    /// From scalar CSR arrays of an `n x n` W (scipy's `indptr`, `indices`, `data`), in
    /// `dim x dim` tiles. Indices need not be sorted; duplicates are summed.
    pub fn from_csr<I>(
        dim: usize,
        n: usize,
        indptr: &[I],
        indices: &[I],
        data: &[f64],
    ) -> Result<Self>
    where
        I: Copy + TryInto<usize> + std::fmt::Debug,
    {
        Self::from_compressed(dim, n, indptr, indices, data, false)
    }

    /// From scalar CSC arrays of an `n x n` W (`indptr` over columns, `indices` the rows).
    pub fn from_csc<I>(
        dim: usize,
        n: usize,
        indptr: &[I],
        indices: &[I],
        data: &[f64],
    ) -> Result<Self>
    where
        I: Copy + TryInto<usize> + std::fmt::Debug,
    {
        Self::from_compressed(dim, n, indptr, indices, data, true)
    }

    /// CSR (`by_columns` false: `indptr` over rows, `indices` the columns) or CSC (the
    /// transposed reading), checked, then tiled.
    fn from_compressed<I>(
        dim: usize,
        n: usize,
        indptr: &[I],
        indices: &[I],
        data: &[f64],
        by_columns: bool,
    ) -> Result<Self>
    where
        I: Copy + TryInto<usize> + std::fmt::Debug,
    {
        let nc = check_dims(dim, n)?;
        if indices.len() != data.len() {
            return Err(CoulombError::Shape(format!(
                "W's indices ({}) and data ({}) differ in length",
                indices.len(),
                data.len()
            )));
        }
        let ptr = check_ptr("indptr", indptr, n, data.len())?;
        let mut inner = Vec::with_capacity(indices.len());
        for (k, &c) in indices.iter().enumerate() {
            inner.push(index_of("indices", k, c, n)?);
        }
        check_data(data)?;
        let entries = |f: &mut dyn FnMut(usize, usize, f64)| {
            for outer in 0..n {
                for k in ptr[outer]..ptr[outer + 1] {
                    if by_columns {
                        f(inner[k], outer, data[k]);
                    } else {
                        f(outer, inner[k], data[k]);
                    }
                }
            }
        };
        Self::from_entries(dim, nc, data.len(), &entries)
    }

    /// From scalar COO triplets `(rows[k], cols[k], data[k])` of an `n x n` W, in any order;
    /// duplicates are summed.
    pub fn from_coo<I>(dim: usize, n: usize, rows: &[I], cols: &[I], data: &[f64]) -> Result<Self>
    where
        I: Copy + TryInto<usize> + std::fmt::Debug,
    {
        let nc = check_dims(dim, n)?;
        if rows.len() != data.len() || cols.len() != data.len() {
            return Err(CoulombError::Shape(format!(
                "W's row ({}), column ({}) and data ({}) arrays differ in length",
                rows.len(),
                cols.len(),
                data.len()
            )));
        }
        let mut rc = Vec::with_capacity(data.len());
        for k in 0..data.len() {
            rc.push((
                index_of("row", k, rows[k], n)?,
                index_of("col", k, cols[k], n)?,
            ));
        }
        check_data(data)?;
        let entries = |f: &mut dyn FnMut(usize, usize, f64)| {
            for (&(r, c), &v) in rc.iter().zip(data) {
                f(r, c, v);
            }
        };
        Self::from_entries(dim, nc, data.len(), &entries)
    }

    /// From a dense row-major `n x n` W: only the tiles with a nonzero entry (and the diagonal
    /// ones) are stored. O(n^2); for tests and small problems.
    pub fn from_dense(dim: usize, n: usize, w: &[f64]) -> Result<Self> {
        let nc = check_dims(dim, n)?;
        if w.len() != n * n {
            return Err(CoulombError::Shape(format!(
                "W must be {n} x {n} ({} entries), got {} entries",
                n * n,
                w.len()
            )));
        }
        check_data(w)?;
        let nnz = w.iter().filter(|&&v| v != 0.0).count();
        let entries = |f: &mut dyn FnMut(usize, usize, f64)| {
            for r in 0..n {
                for c in 0..n {
                    let v = w[r * n + c];
                    if v != 0.0 {
                        f(r, c, v);
                    }
                }
            }
        };
        Self::from_entries(dim, nc, nnz, &entries)
    }

    /// From a dense row-major `(dim nc)^2` W already checked for size and finiteness: the
    /// tiles with a nonzero entry and the diagonal ones, in four allocations sized exactly
    /// (no scratch). `tiles` is [`Self::dense_tile_count`] of the same W.
    pub(crate) fn from_dense_counted(dim: usize, nc: usize, w: &[f64], tiles: usize) -> Self {
        let n = dim * nc;
        let bs = dim * dim;
        let mut row_ptr = Vec::with_capacity(nc + 1);
        let mut cols = Vec::with_capacity(tiles);
        let mut values = Vec::with_capacity(tiles * bs);
        let mut diag = Vec::with_capacity(nc);
        row_ptr.push(0);
        for bi in 0..nc {
            for bj in 0..nc {
                if bj == bi || dense_tile_nonzero(w, dim, n, bi, bj) {
                    if bj == bi {
                        diag.push(cols.len());
                    }
                    cols.push(bj);
                    for a in 0..dim {
                        let row = (bi * dim + a) * n + bj * dim;
                        values.extend_from_slice(&w[row..row + dim]);
                    }
                }
            }
            row_ptr.push(cols.len());
        }
        Self {
            dim,
            nc,
            row_ptr,
            cols,
            values,
            diag,
        }
    }

    /// the number of tiles [`Self::from_dense_counted`] stores for a dense W: those with a
    /// nonzero entry and the diagonal ones. O(n^2), no allocation.
    pub(crate) fn dense_tile_count(dim: usize, nc: usize, w: &[f64]) -> usize {
        let n = dim * nc;
        (0..nc)
            .map(|bi| {
                (0..nc)
                    .filter(|&bj| bj == bi || dense_tile_nonzero(w, dim, n, bi, bj))
                    .count()
            })
            .sum()
    }

    /// the bucketing described in the module notes; indices are already checked.
    fn from_entries(dim: usize, nc: usize, nnz: usize, entries: &dyn Entries) -> Result<Self> {
        // 1. bucket the entries by block row (counting sort)
        let mut start = vec![0usize; nc + 1];
        entries(&mut |r, _, _| start[r / dim + 1] += 1);
        for i in 0..nc {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        // (block column, offset inside the tile, value)
        let mut bucket = vec![(0usize, 0usize, 0.0f64); nnz];
        entries(&mut |r, c, v| {
            let i = r / dim;
            bucket[fill[i]] = (c / dim, (r % dim) * dim + c % dim, v);
            fill[i] += 1;
        });
        // 2. distinct block columns per block row, the diagonal always present
        let mut mark = vec![usize::MAX; nc];
        let mut row_ptr = Vec::with_capacity(nc + 1);
        row_ptr.push(0);
        let mut cols: Vec<usize> = Vec::new();
        for i in 0..nc {
            let first = cols.len();
            mark[i] = i;
            cols.push(i);
            for &(j, _, _) in &bucket[start[i]..start[i + 1]] {
                if mark[j] != i {
                    mark[j] = i;
                    cols.push(j);
                }
            }
            cols[first..].sort_unstable();
            row_ptr.push(cols.len());
        }
        // 3. sum the scalars into their tiles (pos: block column -> tile index, per row)
        let bs = dim * dim;
        let mut values = vec![0.0; cols.len() * bs];
        let mut pos = vec![0usize; nc];
        let mut diag = vec![0usize; nc];
        for i in 0..nc {
            for t in row_ptr[i]..row_ptr[i + 1] {
                pos[cols[t]] = t;
                if cols[t] == i {
                    diag[i] = t;
                }
            }
            for &(j, off, v) in &bucket[start[i]..start[i + 1]] {
                values[pos[j] * bs + off] += v;
            }
        }
        Ok(Self {
            dim,
            nc,
            row_ptr,
            cols,
            values,
            diag,
        })
    }

    /// components per contact.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// number of contacts (block rows).
    pub fn nc(&self) -> usize {
        self.nc
    }

    /// stored tiles (the diagonal ones included).
    pub fn nnz_blocks(&self) -> usize {
        self.cols.len()
    }

    /// the block columns of block row i, sorted.
    pub fn row_cols(&self, i: usize) -> &[usize] {
        &self.cols[self.row_ptr[i]..self.row_ptr[i + 1]]
    }

    /// the tiles of block row i, `dim * dim` row-major scalars each, in [`Self::row_cols`]
    /// order.
    pub fn row_values(&self, i: usize) -> &[f64] {
        let bs = self.dim * self.dim;
        &self.values[self.row_ptr[i] * bs..self.row_ptr[i + 1] * bs]
    }

    /// the diagonal tile of contact i (`dim * dim` scalars, row-major).
    pub fn diag_values(&self, i: usize) -> &[f64] {
        let bs = self.dim * self.dim;
        &self.values[self.diag[i] * bs..(self.diag[i] + 1) * bs]
    }

    /// the tile `W_ij` (`dim * dim` scalars), `None` when not stored (zero). O(log row length).
    pub fn block(&self, i: usize, j: usize) -> Option<&[f64]> {
        let bs = self.dim * self.dim;
        let lo = self.row_ptr[i];
        self.row_cols(i)
            .binary_search(&j)
            .ok()
            .map(|k| &self.values[(lo + k) * bs..(lo + k + 1) * bs])
    }

    /// `Σ_j W_ij x_j` (when `skip_diag`, over `j != i`): the `dim` components of contact i,
    /// zero-padded to 3. O(tiles in the row). Each component is summed left to right in column
    /// order, as the dense row product does, so dense and block-sparse storage of the same W
    /// give bitwise equal products.
    #[inline]
    pub fn row_mul(&self, i: usize, x: &[f64], skip_diag: bool) -> [f64; 3] {
        let (lo, hi) = (self.row_ptr[i], self.row_ptr[i + 1]);
        if !skip_diag {
            return self.tiles_mul(lo, hi, x);
        }
        // the tiles left and right of the diagonal one, continuing the same running sums
        let d = self.diag[i];
        let left = self.tiles_mul(lo, d, x);
        self.tiles_mul_into(d + 1, hi, x, left)
    }

    /// `Σ_t W_t x_{cols[t]}` over the tiles `t in lo..hi` of one block row.
    #[inline]
    fn tiles_mul(&self, lo: usize, hi: usize, x: &[f64]) -> [f64; 3] {
        self.tiles_mul_into(lo, hi, x, [0.0; 3])
    }

    /// `out + Σ_t W_t x_{cols[t]}`, each component summed in tile order (one running sum per
    /// component, three products per tile, left to right).
    #[inline]
    fn tiles_mul_into(&self, lo: usize, hi: usize, x: &[f64], mut out: [f64; 3]) -> [f64; 3] {
        let cols = &self.cols[lo..hi];
        if self.dim == 3 {
            // x as contacts' triples and the tiles as arrays: one bounds check per tile
            let (xs, _) = x.as_chunks::<3>();
            let (values, _) = self.values[lo * 9..hi * 9].as_chunks::<9>();
            for (&j, b) in cols.iter().zip(values) {
                let xj = &xs[j];
                out[0] += b[0] * xj[0];
                out[0] += b[1] * xj[1];
                out[0] += b[2] * xj[2];
                out[1] += b[3] * xj[0];
                out[1] += b[4] * xj[1];
                out[1] += b[5] * xj[2];
                out[2] += b[6] * xj[0];
                out[2] += b[7] * xj[1];
                out[2] += b[8] * xj[2];
            }
        } else {
            let (xs, _) = x.as_chunks::<2>();
            let (values, _) = self.values[lo * 4..hi * 4].as_chunks::<4>();
            for (&j, b) in cols.iter().zip(values) {
                let xj = &xs[j];
                out[0] += b[0] * xj[0];
                out[0] += b[1] * xj[1];
                out[1] += b[2] * xj[0];
                out[1] += b[3] * xj[1];
            }
        }
        out
    }

    /// `(Σ_j W_ij x_j, Σ_j |W_ij| |x_j|)` for the `dim` components of contact i (zero-padded
    /// to 3), the first summed in the order of [`Self::row_mul`] (bitwise the same).
    pub fn row_mul_terms(&self, i: usize, x: &[f64]) -> ([f64; 3], [f64; 3]) {
        let d = self.dim;
        let mut out = [0.0; 3];
        let mut terms = [0.0; 3];
        for t in self.row_ptr[i]..self.row_ptr[i + 1] {
            let j = self.cols[t];
            let b = &self.values[t * d * d..(t + 1) * d * d];
            let xj = &x[d * j..d * j + d];
            for a in 0..d {
                for c in 0..d {
                    let p = b[d * a + c] * xj[c];
                    out[a] += p;
                    terms[a] += p.abs();
                }
            }
        }
        (out, terms)
    }

    /// `out = W x`, O(nnz).
    pub fn mul(&self, x: &[f64], out: &mut [f64]) {
        let d = self.dim;
        for i in 0..self.nc {
            let o = self.row_mul(i, x, false);
            out[i * d..(i + 1) * d].copy_from_slice(&o[..d]);
        }
    }

    /// replaces every stored value v by `f(v)` (an exact change of units by a power of two,
    /// see [`super::normalize`]).
    pub(crate) fn map_values(&mut self, f: impl Fn(f64) -> f64) {
        for v in &mut self.values {
            *v = f(*v);
        }
    }

    /// the dense row-major `(dim nc)^2` matrix (for tests and small problems).
    pub fn to_dense(&self) -> Vec<f64> {
        let d = self.dim;
        let n = d * self.nc;
        let mut w = vec![0.0; n * n];
        for i in 0..self.nc {
            for (k, &j) in self.row_cols(i).iter().enumerate() {
                let b = &self.row_values(i)[k * d * d..(k + 1) * d * d];
                for a in 0..d {
                    for c in 0..d {
                        w[(i * d + a) * n + j * d + c] = b[a * d + c];
                    }
                }
            }
        }
        w
    }
}

#[cfg(test)]
mod tests;
