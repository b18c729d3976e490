//! Lemke's complementary pivoting method (Cottle, Pang and Stone 1992; Stewart 2000 on what
//! it guarantees for contact LCPs).
//!
//! With a covering vector d > 0 and an artificial variable z0 >= 0, Lemke follows the
//! almost-complementary path of
//!
//! ```text
//!     w = q + M z + d z0,    z, w, z0 >= 0,    z_i w_i = 0,
//! ```
//!
//! starting from z = 0, z0 = max_i(-q_i / d_i). Each pivot brings in the complement of the
//! variable that just left; the path ends when z0 leaves the basis (a solution) or when the
//! entering column has no blocking row (a secondary ray). For copositive-plus M (for example
//! positive semidefinite M) a secondary ray proves that the LCP has no solution.
//!
//! Implementation notes:
//!
//! - The data are equilibrated first (see `scaling`), so the pivot tolerance and the
//!   tie test are relative to the data's units; the default covering vector is all ones on the
//!   equilibrated problem.
//! - For 16 <= n <= 1024 the basis inverse is kept in product form (`revised`): a pivot
//!   forms only the entering column through the file of eta vectors, O(n k) for the k-th
//!   pivot, about a quarter of the tableau's work on a path of n/2 pivots. Rounding can
//!   break a degenerate tie differently there, so under [`LemkeEngine::Auto`] a path that
//!   does not end in a solution within 2n + 16 pivots is re-run on the tableau.
//! - The tableau is *condensed*: only the n+1 nonbasic columns and the right-hand side are
//!   stored, n x (n+2) row-major, and a pivot is one rank-one update of it (about n^2 fused
//!   multiply-adds, contiguous by rows). It is allocated once per workspace; pivots allocate
//!   nothing.
//! - Ties in the minimum-ratio test are broken lexicographically on the rows of
//!   `[q̄, B^{-1}]`, which makes the method finite on degenerate problems; z0 leaves first
//!   whenever its row is among the ties (so the path stops at the first solution it meets).
//! - The final basis is polished: its system is re-solved on the original data by one step
//!   of iterative refinement through the inverse the path holds (eta file or tableau), or,
//!   when that answer fails, by factorizing the principal block `M_aa z_a = -q_a`; the
//!   polished answer is kept if its error is smaller.

use super::kernel::{self, axpy, Isa};
use super::revised::{PathEnd, RevisedLemke};
use super::scaling::Equilibration;
use super::small::solve_principal;
use super::ties::{self, Blocking};
use super::{check_tol, passes, LcpMeasures, LcpRef, LcpSolution, LcpStatus, WarmStart};
use crate::error::{check_finite, CoulombError, Result};
use crate::readable::Readable;

/// Settings of [`solve_lemke`].
#[derive(Clone, Debug)]
pub struct LemkeSettings {
    /// tolerance on the answer's error measures (both `error` and `scaled_error`), on the
    /// original data.
    pub tol: f64,
    /// the pivot limit; `None` means `max(1000, 50 n)`.
    pub max_pivots: Option<usize>,
    /// the covering vector d > 0 in the units of q; `None` means all ones on the equilibrated
    /// problem, which makes the pivot path independent of the rows' units.
    pub covering_vector: Option<Vec<f64>>,
    /// a guessed basis: the indices i with z_i > 0 (for example the previous time step's
    /// active set). If it solves the LCP no pivot is made; otherwise Lemke starts cold.
    pub warm_start: Option<Vec<usize>>,
    /// re-solve the final basis's principal system and keep it if better.
    pub polish: bool,
    /// after a ray termination, how many other covering vectors to try (only when
    /// `covering_vector` is `None`). A secondary ray proves infeasibility only for
    /// copositive-plus M; for other matrices a different path may still find a solution.
    pub restarts: usize,
    /// how the basis inverse is kept along the path (see [`LemkeEngine`]).
    pub engine: LemkeEngine,
}

/// How Lemke's path keeps the basis inverse. Both follow the same lexicographic rule; they
/// differ in cost and in rounding.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LemkeEngine {
    /// the product form for 16 <= n <= 1024, where it is fastest, and the tableau otherwise;
    /// a product-form path that does not end in a solution within `2n + 16` pivots is
    /// re-run on the tableau, whose answer is then reported.
    #[default]
    Auto,
    /// the condensed tableau: O(n^2) per pivot.
    Tableau,
    /// the product form (eta file): O(n p) for the p-th pivot, no fallback.
    ProductForm,
}

impl Default for LemkeSettings {
    fn default() -> Self {
        Self {
            tol: 1e-9,
            max_pivots: None,
            covering_vector: None,
            warm_start: None,
            polish: true,
            restarts: 2,
            engine: LemkeEngine::Auto,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Loc {
    Row(usize),
    Col(usize),
}

/// How a pivoting run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ending {
    Terminal,
    Ray,
    Limit,
    NonFinite,
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
    product_form: RevisedLemke,
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
    fn load(&mut self, lcp: &LcpRef<'_>, eq: &Equilibration, cover: &[f64]) {
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
    fn run(&mut self, max_pivots: usize) -> (Ending, usize) {
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
    fn refine(&mut self, lcp: &LcpRef<'_>, eq: &Equilibration, z: &mut [f64]) -> bool {
        kernel::dispatch!(self.isa, bool, || self.refine_body(lcp, eq, z))
    }

    /// z in original units from the current basis (z0 ignored), and the basic z indices.
    fn extract(&self, eq: &Equilibration, z: &mut [f64], basis: &mut Vec<usize>) {
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

/// says in the message when a product-form path was abandoned for the tableau.
fn with_fallback_note(mut out: LcpSolution, abandoned: usize) -> LcpSolution {
    if abandoned > 0 {
        out.message.push_str(&format!(
            " (after {abandoned} product-form pivots were abandoned for the tableau)"
        ));
    }
    out
}

/// `a` is better than `b` when its worse relative measure is smaller.
fn better(a: &LcpMeasures, b: &LcpMeasures) -> bool {
    a.error.max(a.scaled_error) < b.error.max(b.scaled_error)
}

struct Candidate {
    z: Vec<f64>,
    w: Vec<f64>,
    measures: LcpMeasures,
}

fn candidate(lcp: &LcpRef<'_>, eq: &Equilibration, z: Vec<f64>) -> Candidate {
    let (w, measures) = lcp.evaluate(&z, eq);
    Candidate { z, w, measures }
}

/// the principal solution of basis `a` on the original data, clamped to z >= 0.
fn principal(lcp: &LcpRef<'_>, eq: &Equilibration, a: &[usize]) -> Option<Candidate> {
    let za = solve_principal(lcp.n, lcp.m, lcp.q, a)?;
    let mut z = vec![0.0; lcp.n];
    for (&i, v) in a.iter().zip(za) {
        z[i] = v.max(0.0);
    }
    Some(candidate(lcp, eq, z))
}

/// the most covering vectors Lemke tries after the first ([`LemkeSettings::restarts`]).
pub const MAX_RESTARTS: usize = 1000;

fn validate(lcp: &LcpRef<'_>, s: &LemkeSettings) -> Result<()> {
    check_tol(s.tol)?;
    if let Some(d) = &s.covering_vector {
        if d.len() != lcp.n {
            return Err(CoulombError::Shape(format!(
                "covering_vector has length {}, expected {}",
                d.len(),
                lcp.n
            )));
        }
        check_finite("covering_vector", d)?;
        if let Some(k) = d.iter().position(|v| *v <= 0.0) {
            return Err(CoulombError::InvalidParameter(format!(
                "covering_vector must be positive, entry {k} is {}",
                d[k]
            )));
        }
    }
    if let Some(b) = &s.warm_start {
        let mut seen = vec![false; lcp.n];
        for &k in b {
            if k >= lcp.n {
                return Err(CoulombError::InvalidParameter(format!(
                    "warm_start index {k} is out of range for n = {}",
                    lcp.n
                )));
            }
            if seen[k] {
                return Err(CoulombError::InvalidParameter(format!(
                    "warm_start index {k} appears twice"
                )));
            }
            seen[k] = true;
        }
    }
    if s.max_pivots == Some(0) {
        return Err(CoulombError::InvalidParameter(
            "max_pivots must be at least 1".into(),
        ));
    }
    if s.restarts > MAX_RESTARTS {
        return Err(CoulombError::InvalidParameter(format!(
            "restarts must be at most {MAX_RESTARTS}, got {}",
            s.restarts
        )));
    }
    let entries = crate::limits::dense_lemke_entries(lcp.n).unwrap_or(usize::MAX);
    crate::limits::check_bytes(
        &format!("Lemke's workspace for n = {}", lcp.n),
        entries / 2,
        8,
        "",
    )?;
    Ok(())
}

/// Solves the LCP by Lemke's method with a fresh workspace. See [`solve_lemke_with`].
pub fn solve_lemke(lcp: &LcpRef<'_>, settings: &LemkeSettings) -> Result<LcpSolution> {
    let mut ws = LemkeWorkspace::new(lcp.n);
    solve_lemke_with(&mut ws, lcp, settings)
}

/// The i-th covering vector on the equilibrated problem: the user's (scaled), all ones, then
/// for restarts the user-units ones and deterministic spreads.
fn covering(k: usize, eq: &Equilibration, user: Option<&[f64]>, out: &mut [f64]) {
    match (user, k) {
        (Some(d), _) => {
            for ((o, r), di) in out.iter_mut().zip(&eq.row).zip(d) {
                *o = r * di;
            }
        }
        (None, 0) => out.iter_mut().for_each(|v| *v = 1.0),
        (None, 1) => out.copy_from_slice(&eq.row),
        (None, _) => {
            // a fixed low-discrepancy spread in [0.5, 1.5): reproducible, never zero
            let phi = 0.618_033_988_749_895 * k as f64;
            for (i, v) in out.iter_mut().enumerate() {
                *v = 0.5 + ((i as f64 + 1.0) * phi).fract();
            }
        }
    }
    let dmax = out.iter().fold(0.0f64, |m, v| m.max(*v));
    if dmax > 0.0 {
        out.iter_mut().for_each(|v| *v /= dmax);
    }
}

/// Solves the LCP by Lemke's method, reusing `ws` (resized if needed).
///
/// Never fails on a well-formed problem: a secondary ray, the pivot limit or a numerical
/// breakdown is reported in the result's status. Errors are for bad input only.
pub fn solve_lemke_with(
    ws: &mut LemkeWorkspace,
    lcp: &LcpRef<'_>,
    settings: &LemkeSettings,
) -> Result<LcpSolution> {
    validate(lcp, settings)?;
    let n = lcp.n;
    if ws.size() != n {
        *ws = LemkeWorkspace::new(n);
    }
    let eq = Equilibration::compute(n, lcp.m, lcp.q);
    let tol = settings.tol;
    let (w0, m0) = lcp.evaluate_zero(&eq);
    let mut out = LcpSolution {
        z: vec![0.0; n],
        w: w0,
        status: LcpStatus::Solved,
        message: String::new(),
        measures: m0,
        pivots: 0,
        iterations: 0,
        basis: Vec::new(),
        warm_start: WarmStart::None,
        pivots_saved: 0,
        polished: false,
        restarts: 0,
        solutions: Vec::new(),
    };

    if let Some(guess) = &settings.warm_start {
        let mut a = guess.clone();
        a.sort_unstable();
        if let Some(c) = principal(lcp, &eq, &a) {
            if passes(&c.measures, tol) {
                out.warm_start = WarmStart::Accepted;
                out.pivots_saved = a.len() + 1;
                out.basis = a;
                out.z = c.z;
                out.w = c.w;
                out.measures = c.measures;
                out.message = "solved by the warm-start basis without pivoting".into();
                return Ok(out);
            }
        }
        out.warm_start = WarmStart::Rejected;
    }

    if passes(&out.measures, tol) {
        out.message = "z = 0 solves the problem (q >= 0)".into();
        return Ok(out);
    }

    let max_pivots = settings.max_pivots.unwrap_or_else(|| (50 * n).max(1000));
    let user = settings.covering_vector.as_deref();
    let tries = if user.is_some() {
        1
    } else {
        1 + settings.restarts
    };
    let mut cover = vec![0.0; n];
    let mut z = vec![0.0; n];
    let mut basis = Vec::with_capacity(n);
    let mut abandoned = 0;
    for attempt in 0..tries {
        if attempt > 0 && crate::interrupt::poll(n * n) {
            break;
        }
        covering(attempt, &eq, user, &mut cover);
        let product_form = match settings.engine {
            LemkeEngine::Auto => ws.product_form.size() == n && n > 0,
            LemkeEngine::Tableau => false,
            LemkeEngine::ProductForm => true,
        };
        let mut on_product_form = false;
        let mut ending = Ending::NonFinite;
        let mut pivots = 0;
        if product_form {
            if ws.product_form.size() != n {
                ws.product_form = RevisedLemke::new(n);
            }
            // Rounding can break the lexicographic rule's ties differently from exact
            // arithmetic; under Auto a path that wanders (or ends without a solution) is
            // re-run on the tableau, whose verdict is then the one reported.
            let budget = if settings.engine == LemkeEngine::Auto {
                max_pivots.min(2 * n + 16)
            } else {
                max_pivots
            };
            let pf = &mut ws.product_form;
            pf.load(lcp, &eq, &cover);
            let (end, k) = pf.run(lcp, &eq, budget);
            ending = match end {
                PathEnd::Terminal => Ending::Terminal,
                PathEnd::Ray => Ending::Ray,
                PathEnd::Limit => Ending::Limit,
                PathEnd::NonFinite => Ending::NonFinite,
            };
            pivots = k;
            on_product_form = true;
            if ending != Ending::Terminal && settings.engine == LemkeEngine::Auto {
                abandoned += k;
                on_product_form = false;
            }
        }
        if !on_product_form {
            ws.load(lcp, &eq, &cover);
            (ending, pivots) = ws.run(max_pivots);
            ws.extract(&eq, &mut z, &mut basis);
        } else {
            ws.product_form.extract(&eq, &mut z, &mut basis);
        }
        out.pivots += pivots;
        out.restarts = attempt;
        // One refinement step on the original data through the basis inverse the path
        // already holds (the eta file, or the tableau's block) usually brings the answer to
        // rounding level; the principal system is factorized afresh only when that answer
        // fails. When the polished answer passes, the path's own need not be evaluated.
        let polished_answer = if ending == Ending::Terminal && settings.polish {
            let refined = if on_product_form {
                let pf = &mut ws.product_form;
                pf.refine(lcp, &eq);
                let mut zr = vec![0.0; n];
                let mut br = Vec::with_capacity(basis.len());
                pf.extract(&eq, &mut zr, &mut br);
                Some(candidate(lcp, &eq, zr))
            } else {
                let mut zr = z.clone();
                ws.refine(lcp, &eq, &mut zr)
                    .then(|| candidate(lcp, &eq, zr))
            };
            match refined {
                Some(c) if passes(&c.measures, tol) => Some(c),
                _ => principal(lcp, &eq, &basis),
            }
        } else {
            None
        };
        let (best, polished) = match polished_answer {
            Some(p) if passes(&p.measures, tol) => (p, true),
            Some(p) => {
                let t = candidate(lcp, &eq, z.clone());
                if better(&p.measures, &t.measures) {
                    (p, true)
                } else {
                    (t, false)
                }
            }
            None => (candidate(lcp, &eq, z.clone()), false),
        };
        out.z = best.z;
        out.w = best.w;
        out.measures = best.measures;
        out.basis = basis.clone();
        out.polished = polished;
        let m = &out.measures;
        match ending {
            Ending::Terminal if passes(m, tol) => {
                out.status = LcpStatus::Solved;
                out.message = format!(
                    "solved in {} pivots (error {}{})",
                    out.pivots,
                    Readable(m.error),
                    if polished { ", polished" } else { "" }
                );
                return Ok(with_fallback_note(out, abandoned));
            }
            Ending::Terminal => {
                out.status = LcpStatus::NumericalFailure;
                out.message = format!(
                    "z0 left the basis but the answer fails tol {}: error {}, \
                     scaled error {} (ill-conditioned basis)",
                    Readable(tol),
                    Readable(m.error),
                    Readable(m.scaled_error)
                );
                return Ok(with_fallback_note(out, abandoned));
            }
            Ending::Ray => {
                out.status = LcpStatus::RayTermination;
                out.message = format!(
                    "ray termination after {} pivots with {} covering vector(s): no solution \
                     found on Lemke's path (for copositive-plus M, e.g. positive semidefinite, \
                     this proves there is none)",
                    out.pivots,
                    attempt + 1
                );
            }
            Ending::Limit => {
                out.status = LcpStatus::PivotLimit;
                out.message = format!(
                    "stopped at the pivot limit ({max_pivots}) with error {}",
                    Readable(m.error)
                );
                return Ok(with_fallback_note(out, abandoned));
            }
            Ending::NonFinite => {
                out.status = LcpStatus::NumericalFailure;
                out.message = format!("the tableau became non-finite after {} pivots", out.pivots);
                return Ok(with_fallback_note(out, abandoned));
            }
        }
    }
    Ok(with_fallback_note(out, abandoned))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lemke(n: usize, m: &[f64], q: &[f64]) -> LcpSolution {
        let lcp = LcpRef::new(n, m, q).unwrap();
        solve_lemke(&lcp, &LemkeSettings::default()).unwrap()
    }

    #[test]
    fn chapter_scalar_lcp_w_equals_2z_minus_6() {
        let s = lemke(1, &[2.0], &[-6.0]);
        assert_eq!(s.status, LcpStatus::Solved);
        assert!((s.z[0] - 3.0).abs() < 1e-14);
        assert!(s.w[0].abs() < 1e-14);
    }

    #[test]
    fn chapter_scalar_lcp_w_equals_minus_z_minus_1_has_no_solution() {
        let s = lemke(1, &[-1.0], &[-1.0]);
        assert_eq!(s.status, LcpStatus::RayTermination);
        assert!(!s.success());
    }

    #[test]
    fn nonnegative_q_needs_no_pivot() {
        let s = lemke(2, &[1.0, 0.0, 0.0, 1.0], &[0.0, 3.0]);
        assert!(s.success());
        assert_eq!(s.pivots, 0);
        assert_eq!(s.z, vec![0.0, 0.0]);
    }

    #[test]
    fn warm_start_with_the_right_basis_makes_no_pivot() {
        let m = [2.0, 1.0, 1.0, 2.0];
        let q = [-3.0, -3.0];
        let cold = lemke(2, &m, &q);
        assert!(cold.success());
        let lcp = LcpRef::new(2, &m, &q).unwrap();
        let s = LemkeSettings {
            warm_start: Some(cold.basis.clone()),
            ..Default::default()
        };
        let warm = solve_lemke(&lcp, &s).unwrap();
        assert_eq!(warm.warm_start, WarmStart::Accepted);
        assert_eq!(warm.pivots, 0);
        assert!(warm.pivots_saved >= 3);
        for (a, b) in warm.z.iter().zip(&cold.z) {
            assert!((a - b).abs() < 1e-12);
        }
        let bad = LemkeSettings {
            warm_start: Some(vec![]),
            ..Default::default()
        };
        let fallback = solve_lemke(&lcp, &bad).unwrap();
        assert_eq!(fallback.warm_start, WarmStart::Rejected);
        assert!(fallback.success());
    }

    #[test]
    fn bad_settings_are_refused() {
        let lcp = LcpRef::new(1, &[1.0], &[-1.0]).unwrap();
        for s in [
            LemkeSettings {
                tol: 0.0,
                ..Default::default()
            },
            LemkeSettings {
                covering_vector: Some(vec![-1.0]),
                ..Default::default()
            },
            LemkeSettings {
                warm_start: Some(vec![3]),
                ..Default::default()
            },
        ] {
            assert!(solve_lemke(&lcp, &s).is_err());
        }
    }
}
