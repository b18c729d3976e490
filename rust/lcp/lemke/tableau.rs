//! The condensed tableau of Lemke's method ([`LemkeWorkspace`]): the nonbasic columns of the
//! basis inverse applied to the data, pivots as (delayed, blocked) rank-one updates, the
//! lexicographic ratio test over its rows, and one step of iterative refinement of a terminal
//! answer through the inverse it holds.

use super::super::cycle::CycleWatch;
use super::super::kernel::{self, axpy, Isa};
use super::super::revised::RevisedLemke;
use super::super::scaling::Equilibration;
use super::super::ties::{self, Blocking};
use super::super::LcpRef;
use super::Ending;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Loc {
    Row(usize),
    Col(usize),
}

/// problems at least this large delay their rank-one updates (see [`LemkeWorkspace`]).
const BLOCKED_FROM: usize = 64;
/// the sizes for which [`LemkeEngine::Auto`] takes the product form: below, a pivot is too
/// cheap for it to matter; above, the eta file outgrows the caches and the tableau's blocked
/// rank-k updates win.
const PRODUCT_FORM_SIZES: std::ops::RangeInclusive<usize> = 16..=1024;
/// how many rank-one updates are gathered before one rank-k update applies them.
const BLOCK: usize = 16;

/// Storage for Lemke's method, sized once for a problem size and reused across solves (for
/// example across the time steps of a simulation).
///
/// The tableau holds the nonbasic columns of `F = B^{-1} [I, -M, -d | q]` (n x (n+2),
/// row-major). A pivot on row r and entering column s first makes column s the unit vector e_r
/// (it now stands for the leaving variable) and then applies the rank-one update
///
/// ```text
///     F <- F + u v^T,   u = -(f - e_r) / f_r,   v = F[r, :],
/// ```
///
/// with f the entering column. For n >= 64 the updates are not applied at once: up to 16 of
/// them are kept as (u, v) pairs, the few columns and rows a pivot reads are corrected on the
/// fly (O(n k) each), and one rank-k product applies them together. That reads the tableau
/// from memory once per k pivots instead of once per pivot, which is what bounds the
/// unblocked method's speed.
pub struct LemkeWorkspace {
    n: usize,
    width: usize,
    tableau: Vec<f64>,
    block: usize,
    pending: usize,
    pending_u: Vec<f64>,
    pending_v: Vec<f64>,
    column: Vec<f64>,
    values: Vec<f64>,
    spare: Vec<f64>,
    row: Vec<f64>,
    u: Vec<f64>,
    basic: Vec<usize>,
    nonbasic: Vec<usize>,
    loc: Vec<Loc>,
    ties: Vec<usize>,
    ties_next: Vec<usize>,
    isa: Isa,
    pub(super) product_form: RevisedLemke,
    /// boxed so that a solve moves a pointer, not the struct, when it takes it out (None
    /// only while a solve holds it)
    pub(super) scratch: Option<Box<super::Scratch>>,
}

impl LemkeWorkspace {
    /// a workspace for problems of size n: for 16 <= n <= 1024 the product form's eta file
    /// (at most n etas of length n; an explicit n x n inverse only for paths longer than n),
    /// otherwise one n x (n+2) tableau with 16 pending update pairs (for n >= 64); the
    /// tableau of a product-form size is made only if a path falls back to it. O(n)
    /// bookkeeping besides.
    pub fn new(n: usize) -> Self {
        let width = n + 2;
        let block = if n >= BLOCKED_FROM { BLOCK } else { 0 };
        let product_form = PRODUCT_FORM_SIZES.contains(&n);
        let tableau = if product_form {
            Vec::new()
        } else {
            vec![0.0; n * width]
        };
        Self {
            n,
            width,
            tableau,
            block,
            pending: 0,
            pending_u: vec![0.0; block * n],
            pending_v: vec![0.0; block * width],
            column: vec![0.0; n],
            values: vec![0.0; n],
            spare: vec![0.0; n],
            row: vec![0.0; width],
            u: vec![0.0; n],
            basic: vec![0; n],
            nonbasic: vec![0; n + 1],
            loc: vec![Loc::Row(0); 2 * n + 1],
            ties: Vec::with_capacity(n),
            ties_next: Vec::with_capacity(n),
            isa: kernel::detect(),
            product_form: RevisedLemke::new(if product_form { n } else { 0 }),
            scratch: Some(Box::default()),
        }
    }

    /// the problem size this workspace holds.
    pub fn size(&self) -> usize {
        self.n
    }

    /// bytes of the tableau and the pending updates (the workspace's dominant memory).
    pub fn tableau_bytes(&self) -> usize {
        (self.tableau.len() + self.pending_u.len() + self.pending_v.len())
            * std::mem::size_of::<f64>()
            + self.product_form.bytes()
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

    /// w is basic in every row; z and z0 are the nonbasic columns: F = [-M' | -d' | q'].
    pub(super) fn load(&mut self, lcp: &LcpRef<'_>, eq: &Equilibration, cover: &[f64]) {
        let n = self.n;
        let w = self.width;
        if self.tableau.len() != n * w {
            // a product-form size falling back to the tableau
            self.tableau = vec![0.0; n * w];
        }
        for (i, (row, mrow)) in self
            .tableau
            .chunks_exact_mut(w)
            .zip(lcp.m.chunks_exact(n.max(1)))
            .enumerate()
        {
            let r = eq.row[i];
            for ((t, m), c) in row.iter_mut().zip(mrow).zip(&eq.col) {
                *t = -(r * m * c);
            }
            row[n] = -cover[i];
            row[n + 1] = r * lcp.q[i] / eq.sigma;
            self.values[i] = row[n + 1];
            self.basic[i] = i;
            self.loc[i] = Loc::Row(i);
        }
        for j in 0..=n {
            self.nonbasic[j] = n + j;
            self.loc[n + j] = Loc::Col(j);
        }
        self.pending = 0;
    }

    /// entry (i, j) of the current tableau.
    #[inline(always)]
    fn at(&self, i: usize, j: usize) -> f64 {
        let (n, w) = (self.n, self.width);
        let mut x = self.tableau[i * w + j];
        for p in 0..self.pending {
            x += self.pending_u[p * n + i] * self.pending_v[p * w + j];
        }
        x
    }

    /// column j of the current tableau into `out`.
    #[inline(always)]
    fn gather_column(&self, j: usize, out: &mut [f64]) {
        let (n, w) = (self.n, self.width);
        for (o, row) in out.iter_mut().zip(self.tableau.chunks_exact(w)) {
            *o = row[j];
        }
        for p in 0..self.pending {
            let a = self.pending_v[p * w + j];
            if a != 0.0 {
                axpy(out, a, &self.pending_u[p * n..(p + 1) * n]);
            }
        }
    }

    /// `B^{-1}[i, k]`: the coefficient of the original w_k in row i of the full tableau.
    #[inline(always)]
    fn inverse_basis(&self, i: usize, k: usize) -> f64 {
        match self.loc[k] {
            Loc::Row(r) => {
                if r == i {
                    1.0
                } else {
                    0.0
                }
            }
            Loc::Col(c) => self.at(i, c),
        }
    }

    /// Keeps, among `self.ties`, the rows whose lexicographic ratio `B^{-1}[i, :] / f_i` is
    /// smallest (the perturbation `q + (ε, ε², …)` argument), f being `self.column`.
    /// `sign` is +1 for a minimum-ratio test and -1 for the initial maximum-ratio test.
    #[inline(always)]
    fn lexicographic(&mut self, sign: f64) -> Option<usize> {
        let mut ties = std::mem::take(&mut self.ties);
        let mut ties_next = std::mem::take(&mut self.ties_next);
        let pick = ties::lexicographic(
            &mut ties,
            &mut ties_next,
            &self.column,
            self.n,
            sign,
            |i, k| self.inverse_basis(i, k),
        );
        self.ties = ties;
        self.ties_next = ties_next;
        pick
    }

    /// the blocking row when the variable in column s enters (its column is left in
    /// `self.column`, the basic values in `self.values`).
    #[inline(always)]
    fn ratio_test(&mut self, s: usize) -> Blocking {
        let mut column = std::mem::take(&mut self.column);
        self.gather_column(s, &mut column);
        self.column = column;
        let z0 = self.z0();
        match ties::blocking_rows(
            self.isa,
            &self.column,
            &mut self.values,
            &self.basic,
            z0,
            &mut self.ties,
        ) {
            Blocking::Tied => self
                .lexicographic(1.0)
                .map_or(Blocking::NonFinite, Blocking::Row),
            other => other,
        }
    }

    /// the row that leaves when z0 first enters: the one needing the largest z0.
    #[inline(always)]
    fn initial_row(&mut self) -> Option<usize> {
        let n = self.n;
        let mut column = std::mem::take(&mut self.column);
        self.gather_column(n, &mut column);
        self.column = column;
        if !ties::initial_tied_rows(&self.values, &self.column, &mut self.ties) {
            return None;
        }
        match self.ties.len() {
            0 => None,
            1 => Some(self.ties[0]),
            // maximum ratio: the lexicographic argument with the sign reversed
            _ => self.lexicographic(-1.0),
        }
    }

    /// applies the pending updates: `F += U^T V` as one matrix product.
    fn flush(&mut self) {
        let k = self.pending;
        if k == 0 {
            return;
        }
        let (n, w) = (self.n, self.width);
        let dst = faer::MatMut::from_row_major_slice_mut(&mut self.tableau, n, w);
        let ut = faer::MatRef::from_row_major_slice(&self.pending_u[..k * n], k, n).transpose();
        let v = faer::MatRef::from_row_major_slice(&self.pending_v[..k * w], k, w);
        faer::linalg::matmul::matmul(dst, faer::Accum::Add, ut, v, 1.0, faer::Par::Seq);
        self.pending = 0;
    }

    /// exchanges the basic variable of row r with the nonbasic variable of column s, whose
    /// current column is `self.column`. Returns false if the arithmetic broke down.
    #[inline(always)]
    fn pivot(&mut self, r: usize, s: usize) -> bool {
        let (n, w) = (self.n, self.width);
        let piv = self.column[r];
        // column s now stands for the leaving variable, whose column is e_r
        for (row, f) in self.tableau.chunks_exact_mut(w).zip(&self.column) {
            row[s] -= f;
        }
        self.tableau[r * w + s] += 1.0;
        // the pivot row of the current tableau
        self.row.copy_from_slice(&self.tableau[r * w..(r + 1) * w]);
        for p in 0..self.pending {
            let a = self.pending_u[p * n + r];
            if a != 0.0 {
                axpy(&mut self.row, a, &self.pending_v[p * w..(p + 1) * w]);
            }
        }
        let inv = 1.0 / piv;
        for (u, f) in self.u.iter_mut().zip(&self.column) {
            *u = -f * inv;
        }
        self.u[r] = (1.0 - piv) * inv;
        axpy(&mut self.values, self.row[w - 1], &self.u);
        if self.block == 0 {
            for (trow, &a) in self.tableau.chunks_exact_mut(w).zip(&self.u) {
                if a != 0.0 {
                    axpy(trow, a, &self.row);
                }
            }
        } else {
            let p = self.pending;
            self.pending_u[p * n..(p + 1) * n].copy_from_slice(&self.u);
            self.pending_v[p * w..(p + 1) * w].copy_from_slice(&self.row);
            self.pending += 1;
            if self.pending == self.block {
                self.flush();
            }
        }
        let entering = self.nonbasic[s];
        let leaving = self.basic[r];
        self.basic[r] = entering;
        self.nonbasic[s] = leaving;
        self.loc[entering] = Loc::Row(r);
        self.loc[leaving] = Loc::Col(s);
        inv.is_finite() && self.row[w - 1].is_finite()
    }

    /// Runs the complementary pivots from the all-w basis, compiled for the CPU's vector
    /// instructions. Returns how it ended and the pivots.
    pub(super) fn run(&mut self, max_pivots: usize) -> (Ending, usize) {
        kernel::dispatch!(self.isa, (Ending, usize), || self.run_body(max_pivots))
    }

    #[inline(always)]
    fn run_body(&mut self, max_pivots: usize) -> (Ending, usize) {
        let n = self.n;
        let z0 = self.z0();
        let Some(r) = self.initial_row() else {
            return (Ending::NonFinite, 0);
        };
        let mut leaving = self.basic[r];
        if !self.pivot(r, n) {
            return (Ending::NonFinite, 1);
        }
        let mut pivots = 1;
        let mut watch = CycleWatch::new();
        watch.pivot(z0, leaving, pivots);
        loop {
            if leaving == z0 {
                return (Ending::Terminal, pivots);
            }
            // a stop asked by the caller's interrupt hook ends the path like the limit
            if pivots >= max_pivots || crate::interrupt::poll(n * self.width) {
                return (Ending::Limit, pivots);
            }
            let entering = self.complement(leaving);
            let s = match self.loc[entering] {
                Loc::Col(c) => c,
                // cannot happen: a variable that just left is nonbasic, so is its complement
                Loc::Row(_) => return (Ending::NonFinite, pivots),
            };
            let r = match self.ratio_test(s) {
                Blocking::Row(r) => r,
                Blocking::Ray => return (Ending::Ray, pivots),
                Blocking::NonFinite | Blocking::Tied => return (Ending::NonFinite, pivots),
            };
            leaving = self.basic[r];
            pivots += 1;
            if !self.pivot(r, s) {
                return (Ending::NonFinite, pivots);
            }
            if watch.pivot(entering, leaving, pivots) {
                return (Ending::Cycle, pivots);
            }
        }
    }

    /// One step of iterative refinement of a terminal answer z (z0 nonbasic) on the original
    /// data. With a the basic z's (the rows whose w is nonbasic) and `r = M_aa z_a + q_a`,
    ///
    /// ```text
    ///     z_a <- z_a - M_aa^{-1} r,   M_aa^{-1} = D_c (M'_aa)^{-1} D_r,
    /// ```
    ///
    /// and `-(M'_aa)^{-1}` is the block of `B^{-1}` the tableau holds in the columns of the
    /// nonbasic w's (rows of the basic z's), so a step costs `O(|a| n)`, no factorization.
    /// Returns false (z unchanged) when z0 is still basic.
    #[inline(always)]
    fn refine_body(&mut self, lcp: &LcpRef<'_>, eq: &Equilibration, z: &mut [f64]) -> bool {
        let (n, w) = (self.n, self.width);
        if matches!(self.loc[self.z0()], Loc::Row(_)) {
            return false;
        }
        // the basic z's, and `D_r r` scattered onto the columns of the nonbasic w's
        self.ties.clear();
        for j in 0..n {
            if matches!(self.loc[n + j], Loc::Row(_)) {
                self.ties.push(j);
            }
        }
        self.row.iter_mut().for_each(|v| *v = 0.0);
        for k in 0..n {
            if let Loc::Col(c) = self.loc[k] {
                let mrow = &lcp.m[k * n..(k + 1) * n];
                let mut s = lcp.q[k];
                for &j in &self.ties {
                    s += mrow[j] * z[j];
                }
                self.row[c] = eq.row[k] * s;
            }
        }
        // the pending updates enter as (T + U^T V) s = T s + U^T (V s): no flush needed
        for p in 0..self.pending {
            self.spare[p] = kernel::dot(self.isa, &self.pending_v[p * w..(p + 1) * w], &self.row);
        }
        for &j in &self.ties {
            if let Loc::Row(i) = self.loc[n + j] {
                let mut d = kernel::dot(self.isa, &self.tableau[i * w..(i + 1) * w], &self.row);
                for p in 0..self.pending {
                    d += self.pending_u[p * n + i] * self.spare[p];
                }
                z[j] = (z[j] + eq.col[j] * d).max(0.0);
            }
        }
        true
    }

    /// [`Self::refine_body`] compiled for the CPU's vector instructions.
    pub(super) fn refine(&mut self, lcp: &LcpRef<'_>, eq: &Equilibration, z: &mut [f64]) -> bool {
        kernel::dispatch!(self.isa, bool, || self.refine_body(lcp, eq, z))
    }

    /// z in original units from the current basis (z0 ignored), and the basic z indices.
    pub(super) fn extract(&self, eq: &Equilibration, z: &mut [f64], basis: &mut Vec<usize>) {
        let n = self.n;
        z.iter_mut().for_each(|v| *v = 0.0);
        basis.clear();
        for i in 0..n {
            let var = self.basic[i];
            if var >= n && var < 2 * n {
                let k = var - n;
                z[k] = eq.sigma * eq.col[k] * self.values[i].max(0.0);
                basis.push(k);
            }
        }
        basis.sort_unstable();
    }
}
