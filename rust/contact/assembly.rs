//! From a mechanism to its contact problem: the Delassus matrix and the free contact velocity
//! (the inelastic step of Stewart 2000, with Acary and Brogliato's 2008 sign conventions):
//!
//! ```text
//!     W = G^T M^{-1} G,        q = G^T v_free + w,        v = v_free + M^{-1} G r,
//! ```
//!
//! with M the (symmetric positive definite) mass matrix, `ndof x ndof`, G the contact Jacobian
//! transposed, `ndof x (dim nc)` (column k is the generalized direction of contact component k,
//! normal first per contact), v_free the velocity the step reaches without contact impulses,
//! w an optional extra contact-space term (restitution, or FCLib's `w`) and r the impulses.
//! For FCLib's global problems `M v = H r + f` the free velocity is `v_free = M^{-1} f`
//! ([`MassFactor::solve_in_place`]).
//!
//! M is given as triplets (summed when repeated). Its block-diagonal structure is found first
//! (the finest partition of the dofs into consecutive ranges with no entry between ranges):
//! when every block has at most [`DENSE_BLOCK_MAX`] dofs (rigid bodies: 6 x 6 or diagonal) each
//! block is factored by a dense Cholesky `M_b = L_b L_b^T`; otherwise faer's sparse Cholesky
//! factors the whole of M. Either way a pivot at most `1e-14` times the largest diagonal
//! entry, an asymmetric M, or a non-positive pivot refuses M with an
//! [`CoulombError::InvalidParameter`] naming it.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::Llt;
use faer::sparse::{SparseColMat, Triplet};
use faer::Side;

use crate::contact::sparse::TileScratch;
use crate::contact::BlockCsr;
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
    fn check(&self, name: &str) -> Result<()> {
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
    fn canonical(&self) -> Vec<(usize, usize, f64)> {
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

/// The one assembly of the Delassus matrix `W = G^T M^{-1} G` (Moreau; Jean 1999; Acary and
/// Brogliato 2008, ch. 10) when M is block diagonal (one block per body, or one block for a
/// whole mechanism in generalized coordinates):
///
/// ```text
///     W_ij = Σ_b G_{i,b}^T M_b^{-1} G_{j,b}
/// ```
///
/// over the blocks b that contacts i and j both act on, with `G_{i,b}` contact i's `dim`
/// columns of G restricted to block b (a *side* of the contact). Each block lists the sides
/// acting on it ([`WAssembly::side`]); each pair of sides sharing a block is multiplied once
/// (`O(Σ_b k_b^2)` products, not `O(nc^2)`) by the caller's `dim x dim` product and mirrored
/// (the blocks between two contacts are symmetric by construction; a contact's own block is
/// the caller's product, symmetric to rounding). W is stored dense (row-major) or as COO triplets for
/// [`BlockCsr`]. The workspaces are kept from one assembly to the next: assembling a W of a
/// size seen before allocates nothing.
///
/// Used by the time stepper (rigid bodies: sides are body blocks of at most 6 velocities), by
/// the generalized-coordinate stepper (one block) and by [`assemble_with`] (G and M given).
#[derive(Clone, Debug, Default)]
pub struct WAssembly {
    /// per block, the sides `(contact, side)` acting on it; the first `blocks` are in use.
    incidence: Vec<Vec<(usize, usize)>>,
    blocks: usize,
    /// the dense W, row-major `n x n` (empty after a sparse assembly).
    w: Vec<f64>,
    /// the tiles `(i, j, W_ij part)` of a sparse assembly, in product order, mirrors included.
    tiles: Vec<(usize, usize, [[f64; 3]; 3])>,
    /// whether the last assembly was sparse, and its block CSR once built.
    sparse: bool,
    csr: Option<BlockCsr>,
    scratch: TileScratch,
    dim: usize,
    n: usize,
}

impl WAssembly {
    /// an empty workspace.
    pub fn new() -> Self {
        Self::default()
    }

    /// starts an assembly over `blocks` blocks (bodies), forgetting the previous sides.
    pub fn begin(&mut self, blocks: usize) {
        if self.incidence.len() < blocks {
            self.incidence.resize_with(blocks, Vec::new);
        }
        for list in &mut self.incidence[..blocks] {
            list.clear();
        }
        self.blocks = blocks;
    }

    /// contact `contact`'s side `side` acts on block `block` (`< blocks` of [`Self::begin`]);
    /// sides are given in contact order.
    #[inline]
    pub fn side(&mut self, contact: usize, side: usize, block: usize) {
        self.incidence[block].push((contact, side));
    }

    /// W over `nc` contacts of `dim` (1 to 3) components, dense or as COO triplets when
    /// `sparse`: `product((i, ki), (j, kj))` is `G_{i,b}^T M_b^{-1} G_{j,b}` for side ki of
    /// contact i and side kj of contact j on their common block b (entry `[α][β]` for
    /// components α of i and β of j); it is called once per pair of sides on a block, `i <=
    /// j` in block order, and its block is added at `(i, j)` and mirrored at `(j, i)`.
    // index loops mirror W's layout (α: a component of contact i, β: of contact j)
    #[allow(clippy::needless_range_loop)]
    pub fn assemble<F>(&mut self, dim: usize, nc: usize, sparse: bool, mut product: F)
    where
        F: FnMut((usize, usize), (usize, usize)) -> [[f64; 3]; 3],
    {
        let n = nc * dim;
        self.dim = dim;
        self.n = n;
        self.w.clear();
        if !sparse {
            self.w.resize(n * n, 0.0);
        }
        self.sparse = sparse;
        self.tiles.clear();
        for list in &self.incidence[..self.blocks] {
            for (p, &(i, ki)) in list.iter().enumerate() {
                for &(j, kj) in &list[p..] {
                    let blk = product((i, ki), (j, kj));
                    let mirror = i != j;
                    if sparse {
                        self.tiles.push((i, j, blk));
                        if mirror {
                            let mut t = [[0.0; 3]; 3];
                            for al in 0..dim {
                                for be in 0..dim {
                                    t[be][al] = blk[al][be];
                                }
                            }
                            self.tiles.push((j, i, t));
                        }
                    } else {
                        for al in 0..dim {
                            for be in 0..dim {
                                self.w[(i * dim + al) * n + j * dim + be] += blk[al][be];
                                if mirror {
                                    self.w[(j * dim + be) * n + i * dim + al] += blk[al][be];
                                }
                            }
                        }
                    }
                }
            }
        }
    }

    /// the dense W of the last assembly (row-major `n x n`; empty after a sparse one).
    pub fn dense(&self) -> &[f64] {
        &self.w
    }

    /// the dense W, taken out of the workspace (the next dense assembly allocates it anew).
    pub fn take_dense(&mut self) -> Vec<f64> {
        std::mem::take(&mut self.w)
    }

    /// the W of the last (sparse) assembly in block CSR (its storage kept for the next
    /// assembly); refuses non-finite entries.
    pub fn block_csr(&mut self) -> Result<&BlockCsr> {
        let nc = self.n.checked_div(self.dim).unwrap_or(0);
        let csr = self.csr.get_or_insert_with(BlockCsr::empty);
        csr.rebuild_from_tiles(self.dim.max(1), nc, &self.tiles, &mut self.scratch)?;
        Ok(csr)
    }

    /// W of the last assembly as the contact problem stores it: the dense W and no block CSR
    /// after a dense assembly, or an empty dense W and the block CSR after a sparse one.
    pub fn storage(&mut self) -> Result<(&[f64], Option<&BlockCsr>)> {
        if self.sparse {
            self.block_csr()?;
        }
        Ok((&self.w, if self.sparse { self.csr.as_ref() } else { None }))
    }
}

/// G by columns: `(row, value)` lists, one per column.
fn columns(g: &Triplets<'_>) -> Vec<Vec<(usize, f64)>> {
    let mut cols = vec![Vec::new(); g.ncols];
    for (c, r, v) in g.canonical() {
        if v != 0.0 {
            cols[c].push((r, v));
        }
    }
    cols
}

/// The contact problem of a mechanism (see the module notes).
#[derive(Clone, Debug)]
pub struct Assembled {
    /// `W = G^T M^{-1} G`, row-major `(dim nc)^2`, symmetric by construction (each pair of
    /// columns sharing a block of M is multiplied once and mirrored: [`WAssembly`]).
    pub w: Vec<f64>,
    /// `q = G^T v_free + w`.
    pub q: Vec<f64>,
    /// the free velocity used (`M^{-1} f` when a force impulse was given).
    pub v_free: Vec<f64>,
}

/// Where the free velocity comes from.
#[derive(Clone, Copy, Debug)]
pub enum FreeMotion<'a> {
    /// the free velocity v_free itself.
    Velocity(&'a [f64]),
    /// a force impulse f with `v_free = M^{-1} f` (FCLib's global form `M v = H r + f`).
    Force(&'a [f64]),
}

/// `TooLarge` when the dense `n x n` W of `n` contact components exceeds the memory budget
/// (`crate::limits`), checked before any work.
fn check_dense_w(n: usize) -> Result<()> {
    crate::limits::check_bytes(
        &format!("the dense W = G^T M^-1 G of {n} contact components"),
        n.saturating_mul(n),
        8,
        "",
    )?;
    Ok(())
}

/// `W = G^T M^{-1} G`, `q = G^T v_free + extra` (see the module notes); `extra` has
/// `G.ncols` entries when given. `TooLarge` when the dense W exceeds the memory budget.
pub fn assemble(
    m: &Triplets<'_>,
    g: &Triplets<'_>,
    free: FreeMotion<'_>,
    extra: Option<&[f64]>,
) -> Result<Assembled> {
    check_dense_w(g.ncols)?;
    let factor = MassFactor::new(m)?;
    assemble_with(&factor, m.nrows, g, free, extra)
}

/// [`assemble`] with M already factored (`ndof` its size).
pub fn assemble_with(
    factor: &MassFactor,
    ndof: usize,
    g: &Triplets<'_>,
    free: FreeMotion<'_>,
    extra: Option<&[f64]>,
) -> Result<Assembled> {
    if g.nrows != ndof {
        return Err(CoulombError::Shape(format!(
            "G must have ndof = {ndof} rows (one per generalized velocity), got {}",
            g.nrows
        )));
    }
    g.check("the contact Jacobian G")?;
    let n = g.ncols;
    check_dense_w(n)?;
    let v_free = match free {
        FreeMotion::Velocity(v) | FreeMotion::Force(v) if v.len() != ndof => {
            return Err(CoulombError::Shape(format!(
                "the free velocity (or force) must have ndof = {ndof} entries, got {}",
                v.len()
            )));
        }
        FreeMotion::Velocity(v) => {
            check_finite("v_free", v)?;
            v.to_vec()
        }
        FreeMotion::Force(f) => {
            check_finite("f", f)?;
            let mut v = f.to_vec();
            factor.solve_in_place(&mut v);
            v
        }
    };
    if let Some(e) = extra {
        if e.len() != n {
            return Err(CoulombError::Shape(format!(
                "the extra contact term must have dim nc = {n} entries (one per column of G), \
                 got {}",
                e.len()
            )));
        }
        check_finite("the extra contact term", e)?;
    }
    let cols = columns(g);
    let w = delassus_of_columns(factor, ndof, &cols)?;
    let q = cols
        .iter()
        .enumerate()
        .map(|(k, ck)| {
            ck.iter().map(|&(r, v)| v * v_free[r]).sum::<f64>() + extra.map_or(0.0, |e| e[k])
        })
        .collect();
    Ok(Assembled { w, q, v_free })
}

/// One side of a column of G: its entries `cols[k][start..end]` on block `block`, and
/// `M_b^{-1} G_{k,b}` at `mg[off..off + size_b]`.
struct ColumnSide {
    block: usize,
    start: usize,
    end: usize,
    off: usize,
}

/// `W = G^T M^{-1} G` by the one assembly ([`WAssembly`]), each column of G a contact
/// component (`dim = 1`) whose sides are its entries on the blocks of M.
fn delassus_of_columns(
    factor: &MassFactor,
    ndof: usize,
    cols: &[Vec<(usize, f64)>],
) -> Result<Vec<f64>> {
    let ranges = factor.block_ranges(ndof);
    let mut block_of = vec![0usize; ndof];
    for (b, &(o, s)) in ranges.iter().enumerate() {
        block_of[o..o + s].fill(b);
    }
    // each column's sides (rows are sorted, so a block's entries are consecutive)
    let mut sides: Vec<ColumnSide> = Vec::new();
    let mut first = Vec::with_capacity(cols.len() + 1);
    let mut len = 0usize;
    for col in cols {
        first.push(sides.len());
        let mut e = 0;
        while e < col.len() {
            let block = block_of[col[e].0];
            let start = e;
            while e < col.len() && block_of[col[e].0] == block {
                e += 1;
            }
            sides.push(ColumnSide {
                block,
                start,
                end: e,
                off: len,
            });
            len = len.saturating_add(ranges[block].1);
        }
    }
    first.push(sides.len());
    crate::limits::check_bytes(
        &format!(
            "M^-1 G over the blocks of M touched by {} columns of G",
            cols.len()
        ),
        len,
        8,
        "",
    )?;
    let mut mg = vec![0.0; len];
    for (k, col) in cols.iter().enumerate() {
        for sd in &sides[first[k]..first[k + 1]] {
            let (o, size) = ranges[sd.block];
            let x = &mut mg[sd.off..sd.off + size];
            for &(r, v) in &col[sd.start..sd.end] {
                x[r - o] = v;
            }
            factor.solve_block_in_place(sd.block, x);
        }
    }
    let mut asm = WAssembly::new();
    asm.begin(ranges.len());
    for k in 0..cols.len() {
        for (s, sd) in sides[first[k]..first[k + 1]].iter().enumerate() {
            asm.side(k, s, sd.block);
        }
    }
    asm.assemble(1, cols.len(), false, |(i, ki), (j, kj)| {
        let (si, sj) = (&sides[first[i] + ki], &sides[first[j] + kj]);
        let o = ranges[si.block].0;
        let x = &mg[sj.off..];
        let v: f64 = cols[i][si.start..si.end]
            .iter()
            .map(|&(r, g)| g * x[r - o])
            .sum();
        let mut blk = [[0.0; 3]; 3];
        blk[0][0] = v;
        blk
    });
    Ok(asm.take_dense())
}

/// the velocity after the impulses: `v = v_free + M^{-1} G r`.
pub fn post_velocity(
    factor: &MassFactor,
    g: &Triplets<'_>,
    v_free: &[f64],
    r: &[f64],
) -> Result<Vec<f64>> {
    g.check("the contact Jacobian G")?;
    if v_free.len() != g.nrows || r.len() != g.ncols {
        return Err(CoulombError::Shape(format!(
            "v_free must have ndof = {} entries and r dim nc = {} entries, got {} and {}",
            g.nrows,
            g.ncols,
            v_free.len(),
            r.len()
        )));
    }
    check_finite("v_free", v_free)?;
    check_finite("r", r)?;
    let mut x = vec![0.0; g.nrows];
    for (k, &v) in g.vals.iter().enumerate() {
        x[g.rows[k]] += v * r[g.cols[k]];
    }
    factor.solve_in_place(&mut x);
    for (xi, vi) in x.iter_mut().zip(v_free) {
        *xi += vi;
    }
    Ok(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dense_cholesky_solves_and_refuses_indefinite_blocks() {
        // [[4, 2], [2, 3]]: L = [[2, 0], [1, sqrt 2]]
        let mut a = vec![4.0, 2.0, 2.0, 3.0];
        cholesky_in_place(&mut a, 2, 0.0).unwrap();
        assert!((a[0] - 2.0).abs() < 1e-15 && (a[2] - 1.0).abs() < 1e-15);
        assert!((a[3] - 2f64.sqrt()).abs() < 1e-15 && a[1] == 0.0);
        let mut b = vec![1.0, 2.0, 2.0, 1.0];
        assert_eq!(cholesky_in_place(&mut b, 2, 0.0), Err(1));
    }

    #[test]
    fn block_partition_follows_the_couplings() {
        // dofs 0-1 coupled, 2 alone, 3-4 coupled through (4, 3) only
        let rows = [0, 1, 0, 1, 2, 3, 4, 4, 3];
        let cols = [0, 1, 1, 0, 2, 3, 4, 3, 4];
        let vals = [2.0, 2.0, 0.5, 0.5, 1.0, 3.0, 3.0, -1.0, -1.0];
        let m = Triplets {
            nrows: 5,
            ncols: 5,
            rows: &rows,
            cols: &cols,
            vals: &vals,
        };
        let f = MassFactor::new(&m).unwrap();
        let MassFactor::Blocks(b) = &f else {
            panic!("expected blocks")
        };
        let sizes: Vec<(usize, usize)> = b.iter().map(|x| (x.0, x.1)).collect();
        assert_eq!(sizes, vec![(0, 2), (2, 1), (3, 2)]);
        // M x = e: check M (M^{-1} e) = e
        let mut x = vec![1.0, 2.0, 3.0, 4.0, 5.0];
        f.solve_in_place(&mut x);
        let mut back = [0.0; 5];
        for k in 0..vals.len() {
            back[rows[k]] += vals[k] * x[cols[k]];
        }
        for (i, v) in back.iter().enumerate() {
            assert!((v - (i as f64 + 1.0)).abs() < 1e-14, "{back:?}");
        }
    }

    /// sides of the test below: (contact, body, G block: dim = 2 columns of nv = 2).
    type TestSide = (usize, usize, [[f64; 2]; 2]);

    /// `G^T M^{-1} G` by dense products, G (nb nv x 3 dim) built from the sides.
    #[allow(clippy::needless_range_loop)]
    fn dense_w(sides: &[TestSide], minv: &[[f64; 4]; 3]) -> Vec<f64> {
        let (dim, nv, nb) = (2usize, 2usize, 3usize);
        let (ndof, n) = (nb * nv, 3 * dim);
        let mut g = vec![0.0; ndof * n];
        for &(c, b, blk) in sides {
            for al in 0..dim {
                for r in 0..nv {
                    g[(b * nv + r) * n + c * dim + al] = blk[al][r];
                }
            }
        }
        let mut w = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                for b in 0..nb {
                    for r in 0..nv {
                        for c in 0..nv {
                            w[i * n + j] += g[(b * nv + r) * n + i]
                                * minv[b][r * nv + c]
                                * g[(b * nv + c) * n + j];
                        }
                    }
                }
            }
        }
        w
    }

    /// W of three contacts (dim 2) on three bodies of two velocities each (contact 0 on
    /// bodies 0 and 1, contact 1 on body 1, contact 2 on bodies 1 and 2, so contacts 0 and 2
    /// share body 1 only), by the one assembly, dense and sparse, against the dense product.
    #[test]
    #[allow(clippy::needless_range_loop)]
    fn the_one_assembly_sums_over_shared_blocks_dense_and_sparse() {
        let (dim, nv, nb, n) = (2usize, 2usize, 3usize, 6usize);
        let minv = [
            [0.5, 0.1, 0.1, 0.25],
            [1.0, -0.2, -0.2, 0.5],
            [0.2, 0.0, 0.0, 0.8],
        ];
        let sides: [TestSide; 5] = [
            (0, 0, [[1.0, 0.5], [0.0, 2.0]]),
            (0, 1, [[-1.0, 0.3], [0.4, -2.0]]),
            (1, 1, [[0.7, 0.0], [1.0, 1.0]]),
            (2, 1, [[0.2, 1.5], [-0.6, 0.1]]),
            (2, 2, [[-0.9, 0.4], [0.3, 0.3]]),
        ];
        let expected = dense_w(&sides, &minv);
        let mut side_of = vec![vec![]; 3];
        for (k, s) in sides.iter().enumerate() {
            side_of[s.0].push(k);
        }
        let mut asm = WAssembly::new();
        for sparse in [false, true, false] {
            asm.begin(nb);
            for (c, list) in side_of.iter().enumerate() {
                for (k, &s) in list.iter().enumerate() {
                    asm.side(c, k, sides[s].1);
                }
            }
            let mut calls = 0;
            asm.assemble(dim, 3, sparse, |(i, ki), (j, kj)| {
                calls += 1;
                let (si, sj) = (&sides[side_of[i][ki]], &sides[side_of[j][kj]]);
                assert_eq!(si.1, sj.1, "a product across bodies");
                let m = &minv[si.1];
                let mut blk = [[0.0; 3]; 3];
                for al in 0..dim {
                    for be in 0..dim {
                        for r in 0..nv {
                            for c in 0..nv {
                                blk[al][be] += si.2[al][r] * m[r * nv + c] * sj.2[be][c];
                            }
                        }
                    }
                }
                blk
            });
            // body 0: 1 side, body 1: 3 sides (6 pairs), body 2: 1 side
            assert_eq!(calls, 1 + 6 + 1);
            let mut w = asm.dense().to_vec();
            if sparse {
                let csr = asm.block_csr().unwrap();
                w = vec![0.0; n * n];
                let (mut e, mut col) = (vec![0.0; n], vec![0.0; n]);
                for j in 0..n {
                    e.fill(0.0);
                    e[j] = 1.0;
                    csr.mul(&e, &mut col);
                    for i in 0..n {
                        w[i * n + j] = col[i];
                    }
                }
            }
            for k in 0..n * n {
                assert!((w[k] - expected[k]).abs() < 1e-14, "{sparse}: {k}: {w:?}");
            }
            // blocks of two contacts are mirrored exactly; a contact's own block is the
            // caller's product (symmetric to rounding)
            for i in 0..n {
                for j in 0..n {
                    if i / dim != j / dim {
                        assert_eq!(w[i * n + j], w[j * n + i]);
                    }
                }
            }
        }
    }

    #[test]
    fn a_dense_w_over_the_memory_budget_is_refused_before_any_work() {
        // 2^32 contact components: W's bytes overflow usize, over any budget
        let one = [0usize];
        let m = Triplets {
            nrows: 1,
            ncols: 1,
            rows: &one,
            cols: &one,
            vals: &[1.0],
        };
        let g = Triplets {
            nrows: 1,
            ncols: 1 << 32,
            rows: &[],
            cols: &[],
            vals: &[],
        };
        let free = FreeMotion::Velocity(&[0.0]);
        let err = assemble(&m, &g, free, None).unwrap_err();
        assert!(matches!(err, CoulombError::TooLarge(_)), "{err}");
        assert!(err.to_string().contains("dense W"), "{err}");
        let factor = MassFactor::new(&m).unwrap();
        let err = assemble_with(&factor, 1, &g, free, None).unwrap_err();
        assert!(matches!(err, CoulombError::TooLarge(_)), "{err}");
    }
}
