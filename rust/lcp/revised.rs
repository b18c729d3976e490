//! Lemke's path in product form: the basis inverse is kept as a file of elementary
//! ("eta") matrices instead of a tableau.
//!
//! With the basis B after p pivots written as
//!
//! ```text
//!     B^{-1} = E_p ⋯ E_1 B_0^{-1},   E_j = I + η̃_j e_{r_j}^T,  η̃_j = η_j - e_{r_j},
//! ```
//!
//! (B_0 = I, the all-w basis, until the file is folded into an explicit inverse), a pivot needs
//! only the entering column `f = B^{-1} a_s` and the basic values `x_B = B^{-1} q'`: the
//! ratio test reads nothing else. Forming f costs one pass over each stored η (an axpy of
//! length n), so the k-th pivot costs O(n k) instead of the tableau's O(n^2): on Lemke's
//! typical path of about n/2 pivots that is n^3/8 multiply-adds in all instead of n^3/2.
//! The η of a pivot on row r with column f is `η_i = -f_i / f_r` (i ≠ r), `η_r = 1 / f_r`.
//!
//! The lexicographic tie-break reads rows of B^{-1}; they are formed on demand (rare: only
//! when ratios tie) from `e_i^T E_p ⋯ E_1 B_0^{-1}`, where each `y^T E_j` changes only
//! entry r_j, to `y · η_j`.
//!
//! When the file holds `cap` etas (long, degenerate paths) it is folded into an explicit
//! dense `B_0^{-1}` (each η applied to it as a rank-one update) and a new file starts. The eta
//! file's operations are module `eta`; this module holds the path (ratio tests, pivots, run
//! and refinement).

use super::cycle::CycleWatch;
use super::kernel::{self, Isa};
use super::scaling::Equilibration;
use super::ties;
use super::LcpRef;

mod eta;

/// How a pivoting run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum PathEnd {
    /// z0 left the basis: the basis is complementary.
    Terminal,
    /// the entering column has no blocking row: a secondary ray.
    Ray,
    /// the pivot limit was reached.
    Limit,
    /// the path returned to a state it had passed (rounding at degenerate ties; see
    /// [`super::cycle`]).
    Cycle,
    /// the arithmetic broke down (non-finite or no admissible pivot).
    NonFinite,
}

/// at most this many tied rows are broken lexicographically (their rows of B^{-1} are
/// stored, LEX_ROWS x n).
const LEX_ROWS: usize = 64;
/// Storage of the product-form path, sized once for n and reused.
pub(super) struct RevisedLemke {
    n: usize,
    /// at most this many etas before they are folded into `base`.
    cap: usize,
    /// the eta vectors, `cap x n` row-major; `eta_rows[j]` is r_j.
    etas: Vec<f64>,
    eta_rows: Vec<usize>,
    count: usize,
    /// the columns of -M' stored contiguously (`columns[k n + i] = -r_i M_ik c_k`) where the
    /// CPU has AVX-512 (n^2 entries; empty elsewhere), filled eight columns at a time when
    /// the path first asks for one of them: `column_blocks[k / 8]` says block k / 8 is there.
    columns: Vec<f64>,
    column_blocks: Vec<bool>,
    /// explicit `B_0^{-1}` (row-major n x n) once the file has been folded; empty before.
    base: Vec<f64>,
    has_base: bool,
    /// the rows a fold block reads (FOLD_BLOCK x n), allocated with `base`.
    fold_rows: Vec<f64>,
    /// the equilibrated covering vector d' and the entering variable's original column.
    cover: Vec<f64>,
    acol: Vec<f64>,
    /// the entering column, the basic values, and two scratch vectors.
    column: Vec<f64>,
    values: Vec<f64>,
    spare: Vec<f64>,
    /// `max_i |f_i|` and `max_i |x_B,i|`, left by the passes that wrote the entering column
    /// and the basic values, so the ratio test does not read them again to size them (each
    /// not finite when its vector has a non-finite entry).
    column_max: f64,
    values_max: f64,
    scratch: Vec<f64>,
    /// `basic[i]`: the variable basic in row i (w_k = k, z_k = n + k, z0 = 2n).
    basic: Vec<usize>,
    /// `row_of[v]`: the row where variable v is basic, or `usize::MAX`.
    row_of: Vec<usize>,
    ties: Vec<usize>,
    ties_next: Vec<usize>,
    /// rows of B^{-1} for the tied rows (ties.len() x n), formed on demand.
    lex_rows: Vec<f64>,
    lex_index: Vec<usize>,
    isa: Isa,
}

impl RevisedLemke {
    /// storage for problems of size n: at most max(n, 16) etas of length n, the columns of
    /// -M' (n^2, on CPUs with AVX-512) and O(n) vectors; the explicit inverse (another n^2) only if a path is long enough to
    /// need folding.
    pub(super) fn new(n: usize) -> Self {
        let cap = n.max(16);
        Self {
            n,
            cap,
            etas: vec![0.0; cap * n],
            eta_rows: vec![0; cap],
            count: 0,
            columns: if kernel::detect() == Isa::Avx512 {
                vec![0.0; n * n]
            } else {
                Vec::new()
            },
            column_blocks: vec![false; n.div_ceil(8)],
            base: Vec::new(),
            has_base: false,
            fold_rows: Vec::new(),
            cover: vec![0.0; n],
            acol: vec![0.0; n],
            column: vec![0.0; n],
            values: vec![0.0; n],
            spare: vec![0.0; n],
            column_max: 0.0,
            values_max: 0.0,
            scratch: vec![0.0; n],
            basic: vec![0; n],
            row_of: vec![usize::MAX; 2 * n + 1],
            ties: Vec::with_capacity(n),
            ties_next: Vec::with_capacity(n),
            lex_rows: vec![0.0; LEX_ROWS.min(n) * n],
            lex_index: vec![usize::MAX; n],
            isa: kernel::detect(),
        }
    }

    /// the problem size this storage holds.
    pub(super) fn size(&self) -> usize {
        self.n
    }

    /// bytes held (for the workspace's memory report).
    pub(super) fn bytes(&self) -> usize {
        (self.etas.len()
            + self.columns.len()
            + self.base.len()
            + self.fold_rows.len()
            + self.lex_rows.len())
            * std::mem::size_of::<f64>()
    }

    #[inline(always)]
    fn z0(&self) -> usize {
        2 * self.n
    }

    #[inline(always)]
    fn complement(&self, var: usize) -> usize {
        if var < self.n {
            var + self.n
        } else {
            var - self.n
        }
    }

    /// the all-w basis of the equilibrated problem `w = q' + M' z + d' z0`, i.e. the system
    /// `[I, -M', -d'] x = q'`.
    pub(super) fn load(&mut self, lcp: &LcpRef<'_>, eq: &Equilibration, cover: &[f64]) {
        let n = self.n;
        for i in 0..n {
            self.values[i] = eq.row[i] * lcp.q[i] / eq.sigma;
            self.basic[i] = i;
        }
        self.values_max = kernel::max_abs(self.isa, &self.values);
        self.cover.copy_from_slice(cover);
        self.row_of.iter_mut().for_each(|v| *v = usize::MAX);
        for i in 0..n {
            self.row_of[i] = i;
        }
        self.count = 0;
        self.has_base = false;
        // the columns of -M' are transposed block by block as the path first asks for them
        self.column_blocks.iter_mut().for_each(|b| *b = false);
    }

    /// `out = B^{-1} a_var` for the original column of variable `var`.
    #[inline(always)]
    fn column_of(&mut self, lcp: &LcpRef<'_>, eq: &Equilibration, var: usize) {
        let n = self.n;
        let mut out = std::mem::take(&mut self.column);
        #[cfg(target_arch = "x86_64")]
        if var >= n && var < 2 * n && self.columns.len() == n * n {
            // the original column -M'[:, k], contiguous
            let k = var - n;
            if !self.column_blocks[k / 8] {
                // SAFETY: `columns` is allocated only when `kernel::detect` found AVX-512F;
                // M and the copy hold n^2 entries, the factors n; k / 8 * 8 <= k < n.
                unsafe {
                    super::simd512::negated_scaled_columns(
                        lcp.m,
                        &eq.row,
                        &eq.col,
                        &mut self.columns,
                        n,
                        k / 8 * 8,
                    )
                };
                self.column_blocks[k / 8] = true;
            }
            let a = &self.columns[k * n..(k + 1) * n];
            if self.has_base {
                for (o, brow) in out.iter_mut().zip(self.base.chunks_exact(n)) {
                    *o = kernel::dot(self.isa, brow, a);
                }
            } else {
                out.copy_from_slice(a);
            }
            self.column_max = self
                .apply_etas(&mut out)
                .unwrap_or_else(|| kernel::max_abs(self.isa, &out));
            self.column = out;
            return;
        }
        if var >= n {
            // the original column, -M'[:, k] = -R M[:, k] c_k (read down M's rows: a strided
            // pass of n entries), or -d'
            if var == 2 * n {
                self.acol.copy_from_slice(&self.cover);
            } else {
                let k = var - n;
                let c = eq.col[k];
                for ((a, r), mrow) in self.acol.iter_mut().zip(&eq.row).zip(lcp.m.chunks_exact(n)) {
                    *a = r * mrow[k] * c;
                }
            }
        }
        if self.has_base {
            // a = e_k: column k of the base; a = -M'[:, k] or -d': minus the base times it
            if var < n {
                for (o, brow) in out.iter_mut().zip(self.base.chunks_exact(n)) {
                    *o = brow[var];
                }
            } else {
                for (o, brow) in out.iter_mut().zip(self.base.chunks_exact(n)) {
                    *o = -kernel::dot(self.isa, brow, &self.acol);
                }
            }
        } else if var < n {
            out.iter_mut().for_each(|v| *v = 0.0);
            out[var] = 1.0;
        } else {
            for (o, v) in out.iter_mut().zip(&self.acol) {
                *o = -v;
            }
        }
        self.column_max = self
            .apply_etas(&mut out)
            .unwrap_or_else(|| kernel::max_abs(self.isa, &out));
        self.column = out;
    }

    /// Keeps, among `self.ties`, the rows whose lexicographic ratio `B^{-1}[i, :] / f_i` is
    /// smallest (`sign` +1), or largest (`sign` -1, the initial maximum-ratio test).
    #[inline(always)]
    fn lexicographic(&mut self, sign: f64) -> Option<usize> {
        let n = self.n;
        let k = self.ties.len();
        if k > LEX_ROWS {
            // more tied rows than the storage holds: the caller treats this as a breakdown
            // (under Auto the path is re-run on the tableau)
            return None;
        }
        for t in 0..k {
            let i = self.ties[t];
            self.inverse_row(i);
            self.lex_rows[t * n..(t + 1) * n].copy_from_slice(&self.scratch);
            self.lex_index[i] = t;
        }
        let mut ties = std::mem::take(&mut self.ties);
        let mut ties_next = std::mem::take(&mut self.ties_next);
        let (rows, index) = (&self.lex_rows, &self.lex_index);
        let pick = ties::lexicographic(&mut ties, &mut ties_next, &self.column, n, sign, |i, k| {
            rows[index[i] * n + k]
        });
        self.ties = ties;
        self.ties_next = ties_next;
        pick
    }

    /// the blocking row when the variable in `self.column` enters.
    #[inline(always)]
    fn ratio_test(&mut self) -> Result<Option<usize>, ()> {
        let z0 = self.z0();
        match ties::blocking_rows_sized(
            self.isa,
            &self.column,
            &mut self.values,
            self.column_max,
            self.values_max,
            &self.basic,
            z0,
            &mut self.ties,
        ) {
            ties::Blocking::Row(r) => Ok(Some(r)),
            ties::Blocking::Ray => Ok(None),
            ties::Blocking::NonFinite => Err(()),
            ties::Blocking::Tied => self.lexicographic(1.0).map(Some).ok_or(()),
        }
    }

    /// the row that leaves when z0 first enters: the one needing the largest z0.
    #[inline(always)]
    fn initial_row(&mut self) -> Option<usize> {
        if !ties::initial_tied_rows(&self.values, &self.column, &mut self.ties) {
            return None;
        }
        match self.ties.len() {
            0 => None,
            1 => Some(self.ties[0]),
            _ => self.lexicographic(-1.0),
        }
    }

    /// exchanges the basic variable of row r with `entering`, whose column is `self.column`.
    #[inline(always)]
    fn pivot(&mut self, r: usize, entering: usize) -> bool {
        let n = self.n;
        if self.count == self.cap {
            self.fold();
        }
        let piv = self.column[r];
        let inv = 1.0 / piv;
        let j = self.count;
        let eta = &mut self.etas[j * n..(j + 1) * n];
        for (e, f) in eta.iter_mut().zip(&self.column) {
            *e = -f * inv;
        }
        // η̃ = η - e_r: applying E is then x += x_r η̃
        eta[r] = inv - 1.0;
        self.eta_rows[j] = r;
        self.count += 1;
        let t = self.values[r];
        self.values_max = kernel::axpy_max(
            self.isa,
            &mut self.values,
            t,
            &self.etas[j * n..(j + 1) * n],
        );
        let leaving = self.basic[r];
        self.basic[r] = entering;
        self.row_of[entering] = r;
        self.row_of[leaving] = usize::MAX;
        inv.is_finite() && self.values[r].is_finite()
    }

    /// Runs the complementary pivots from the all-w basis, compiled for the CPU's vector
    /// instructions. Returns how it ended and the pivots.
    pub(super) fn run(
        &mut self,
        lcp: &LcpRef<'_>,
        eq: &Equilibration,
        max_pivots: usize,
    ) -> (PathEnd, usize) {
        kernel::dispatch!(self.isa, (PathEnd, usize), || self
            .run_body(lcp, eq, max_pivots))
    }

    #[inline(always)]
    fn run_body(
        &mut self,
        lcp: &LcpRef<'_>,
        eq: &Equilibration,
        max_pivots: usize,
    ) -> (PathEnd, usize) {
        let z0 = self.z0();
        self.column_of(lcp, eq, z0);
        let Some(r) = self.initial_row() else {
            return (PathEnd::NonFinite, 0);
        };
        let mut leaving = self.basic[r];
        if !self.pivot(r, z0) {
            return (PathEnd::NonFinite, 1);
        }
        let mut pivots = 1;
        let mut watch = CycleWatch::new();
        watch.pivot(z0, leaving, pivots);
        loop {
            if leaving == z0 {
                return (PathEnd::Terminal, pivots);
            }
            // a stop asked by the caller's interrupt hook ends the path like the limit
            if pivots >= max_pivots || crate::interrupt::poll(self.n * (pivots + 1)) {
                return (PathEnd::Limit, pivots);
            }
            let entering = self.complement(leaving);
            if self.row_of[entering] != usize::MAX {
                // cannot happen: the complement of a variable that just left is nonbasic
                return (PathEnd::NonFinite, pivots);
            }
            self.column_of(lcp, eq, entering);
            let r = match self.ratio_test() {
                Ok(Some(r)) => r,
                Ok(None) => return (PathEnd::Ray, pivots),
                Err(()) => return (PathEnd::NonFinite, pivots),
            };
            leaving = self.basic[r];
            pivots += 1;
            if !self.pivot(r, entering) {
                return (PathEnd::NonFinite, pivots);
            }
            if watch.pivot(entering, leaving, pivots) {
                return (PathEnd::Cycle, pivots);
            }
        }
    }

    /// One step of iterative refinement of the basic values on the equilibrated data,
    /// `x_B <- x_B + B^{-1} (q' - B x_B)`: the residual is formed from M itself (the basic
    /// z columns of M', the basic w's unit columns, z0's d') and `B^{-1}` is applied through
    /// the eta file (O(n p)). This re-solves the final basis's system against the original
    /// data at the cost of one pivot's column, where a fresh factorization of the principal
    /// block would cost O(k^3).
    pub(super) fn refine(&mut self, lcp: &LcpRef<'_>, eq: &Equilibration) {
        let isa = self.isa;
        kernel::dispatch!(isa, (), || self.refine_body(lcp, eq))
    }

    #[inline(always)]
    fn refine_body(&mut self, lcp: &LcpRef<'_>, eq: &Equilibration) {
        let n = self.n;
        // z' of the basis, in the scratch vector (z' = 0 off the basis)
        let mut zb = std::mem::take(&mut self.scratch);
        zb.iter_mut().for_each(|v| *v = 0.0);
        let mut z0 = 0.0;
        for i in 0..n {
            let var = self.basic[i];
            if var >= n && var < 2 * n {
                zb[var - n] = self.values[i];
            } else if var == 2 * n {
                z0 = self.values[i];
            }
        }
        // residual q' - B x_B: row i of M' z' is r_i Σ_k M_ik c_k z'_k
        let mut res = std::mem::take(&mut self.acol);
        for (k, v) in zb.iter_mut().enumerate() {
            *v *= eq.col[k];
        }
        // (the term sums land in the spare vector, unused here)
        kernel::matvec_and_abs(self.isa, lcp.m, &zb, &mut res, &mut self.spare);
        for (((ri, r), qi), di) in res.iter_mut().zip(&eq.row).zip(lcp.q).zip(&self.cover) {
            *ri = r * qi / eq.sigma + r * *ri + di * z0;
        }
        for i in 0..n {
            let var = self.basic[i];
            if var < n {
                res[var] -= self.values[i];
            }
        }
        let mut delta = std::mem::take(&mut self.column);
        if self.has_base {
            for (o, brow) in delta.iter_mut().zip(self.base.chunks_exact(n)) {
                *o = kernel::dot(self.isa, brow, &res);
            }
        } else {
            delta.copy_from_slice(&res);
        }
        self.apply_etas(&mut delta);
        for (v, d) in self.values.iter_mut().zip(&delta) {
            *v += d;
        }
        self.column = delta;
        self.acol = res;
        self.scratch = zb;
    }

    /// z in original units from the current basis (z0 ignored), and the basic z indices.
    pub(super) fn extract(&self, eq: &Equilibration, z: &mut [f64], basis: &mut Vec<usize>) {
        let n = self.n;
        basis.clear();
        // by variable, through row_of, so the basis comes out in increasing order unsorted
        for (k, (zk, row)) in z.iter_mut().zip(&self.row_of[n..2 * n]).enumerate() {
            *zk = match self.values.get(*row) {
                Some(v) => {
                    basis.push(k);
                    eq.sigma * eq.col[k] * v.max(0.0)
                }
                None => 0.0,
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// the contiguous columns of -M' equal `-r_i M_ik c_k` entry for entry (the factors are
    /// powers of two, so the products are exact in any order), edge blocks included
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn transposed_columns_equal_the_definition() {
        if kernel::detect() != Isa::Avx512 {
            return;
        }
        for n in [1usize, 3, 8, 9, 17, 100] {
            let m: Vec<f64> = (0..n * n).map(|k| (k as f64 * 0.37).sin()).collect();
            let r: Vec<f64> = (0..n).map(|i| 2f64.powi(i as i32 % 5 - 2)).collect();
            let c: Vec<f64> = (0..n).map(|k| 2f64.powi(k as i32 % 3 - 1)).collect();
            let mut out = vec![f64::NAN; n * n];
            // SAFETY: the CPU has AVX-512F (checked above); every slice is long enough.
            for j0 in (0..n).step_by(8) {
                unsafe { crate::lcp::simd512::negated_scaled_columns(&m, &r, &c, &mut out, n, j0) };
            }
            for i in 0..n {
                for k in 0..n {
                    assert_eq!(
                        out[k * n + i],
                        -(r[i] * m[i * n + k] * c[k]),
                        "n={n} {i},{k}"
                    );
                }
            }
        }
    }
}
