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

mod mass;
#[cfg(test)]
mod tests;

pub(crate) use mass::{cholesky_in_place, solve_cholesky};
pub use mass::{MassFactor, Triplets, DENSE_BLOCK_MAX};

use crate::contact::sparse::TileScratch;
use crate::contact::BlockCsr;
use crate::error::{check_finite, CoulombError, Result};

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
/// [`BlockCsr`]; a sparse assembly over the same sides as the one the block CSR was last built
/// from (a stepper's contacts unchanged from one step to the next) sums its tiles straight into
/// the block CSR's values, in the order a rebuild would. The workspaces are kept from one
/// assembly to the next: assembling a W of a size seen before allocates nothing.
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
    /// the sides `(block, contact, side)` of the last sparse assembly made of tiles, and of
    /// the one the block CSR was last rebuilt from: an assembly with these same sides makes
    /// its tiles at the same places, so it sums them straight into the block CSR's values.
    assembled: Vec<(usize, usize, usize)>,
    built: Vec<(usize, usize, usize)>,
    /// whether the block CSR holds the last sparse assembly (its tiles summed in place, or
    /// rebuilt from them).
    in_place: bool,
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
        let in_place = sparse && self.sparse && self.same_sides_as_built(dim, nc);
        self.dim = dim;
        self.n = n;
        self.w.clear();
        if !sparse {
            self.w.resize(n * n, 0.0);
        }
        self.sparse = sparse;
        self.tiles.clear();
        self.in_place = in_place && self.sum_in_place(&mut product);
        if self.in_place {
            return;
        }
        if sparse {
            self.assembled.clear();
            for (b, list) in self.incidence[..self.blocks].iter().enumerate() {
                self.assembled.extend(list.iter().map(|&(i, k)| (b, i, k)));
            }
        }
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
                        // the dimension known at compile time (the same sums, unrolled)
                        match dim {
                            3 => add_dense::<3>(&mut self.w, n, (i, j), &blk, mirror),
                            2 => add_dense::<2>(&mut self.w, n, (i, j), &blk, mirror),
                            // a block is at most 3 x 3: the one other dimension is 1
                            _ => add_dense::<1>(&mut self.w, n, (i, j), &blk, mirror),
                        }
                    }
                }
            }
        }
    }

    /// whether the current sides are those the block CSR was last rebuilt from, at the same
    /// shape (then every tile falls at the place it had).
    fn same_sides_as_built(&self, dim: usize, nc: usize) -> bool {
        let shape = self.scratch.last_slots().map(|(shape, _)| shape);
        if self.csr.is_none() || shape != Some((dim, nc)) {
            return false;
        }
        let mut built = self.built.iter();
        for (b, list) in self.incidence[..self.blocks].iter().enumerate() {
            for &(i, k) in list {
                if built.next() != Some(&(b, i, k)) {
                    return false;
                }
            }
        }
        built.next().is_none()
    }

    /// the tiles summed straight into the block CSR's values at their places of the last
    /// rebuild, in the order a rebuild sums them (so the same values to the bit); false,
    /// with the values left to a rebuild, when an entry is not finite (the rebuild names it).
    fn sum_in_place<F>(&mut self, product: &mut F) -> bool
    where
        F: FnMut((usize, usize), (usize, usize)) -> [[f64; 3]; 3],
    {
        match self.dim {
            1 => self.sum_in_place_of::<1, F>(product),
            2 => self.sum_in_place_of::<2, F>(product),
            _ => self.sum_in_place_of::<3, F>(product),
        }
    }

    /// [`Self::sum_in_place`] for contacts of D components.
    // index loops mirror W's layout (α: a component of contact i, β: of contact j)
    #[allow(clippy::needless_range_loop)]
    fn sum_in_place_of<const D: usize, F>(&mut self, product: &mut F) -> bool
    where
        F: FnMut((usize, usize), (usize, usize)) -> [[f64; 3]; 3],
    {
        let (Some(csr), Some((_, slots))) = (self.csr.as_mut(), self.scratch.last_slots()) else {
            return false;
        };
        let (firsts, empty) = self.scratch.last_firsts();
        let values = csr.values_mut();
        // a place's first tile is written as 0 + t, the bits zeroing it first and adding
        // gave; only the places no tile reaches are zeroed
        for &at in empty {
            if let Some(place) = values.get_mut(at..at + D * D) {
                place.fill(0.0);
            }
        }
        if firsts.len() != slots.len() {
            return false;
        }
        let mut slots = slots.iter().zip(firsts);
        // v * 0 is 0 exactly when v is finite
        let mut finite = 0.0;
        for list in &self.incidence[..self.blocks] {
            for (p, &(i, ki)) in list.iter().enumerate() {
                for &(j, kj) in &list[p..] {
                    let blk = product((i, ki), (j, kj));
                    let Some((tile, &first)) = slots
                        .next()
                        .and_then(|(&at, first)| Some((values.get_mut(at..at + D * D)?, first)))
                    else {
                        return false;
                    };
                    if first {
                        tile.fill(0.0);
                    }
                    for al in 0..D {
                        for be in 0..D {
                            tile[al * D + be] += blk[al][be];
                            finite += blk[al][be] * 0.0;
                        }
                    }
                    if i != j {
                        let Some((tile, &first)) = slots.next().and_then(|(&at, first)| {
                            Some((values.get_mut(at..at + D * D)?, first))
                        }) else {
                            return false;
                        };
                        if first {
                            tile.fill(0.0);
                        }
                        for be in 0..D {
                            for al in 0..D {
                                tile[be * D + al] += blk[al][be];
                            }
                        }
                    }
                }
            }
        }
        slots.next().is_none() && finite == 0.0
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
        if !self.in_place {
            csr.rebuild_from_tiles(self.dim.max(1), nc, &self.tiles, &mut self.scratch)?;
            // the tiles are summed in place from now on while the sides stay these
            std::mem::swap(&mut self.built, &mut self.assembled);
            self.assembled.clear();
            self.in_place = true;
        }
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
        format_args!("the dense W = G^T M^-1 G of {n} contact components"),
        n.saturating_mul(n),
        8,
        "",
    )?;
    Ok(())
}

/// adds block `blk` (D x D) of contacts (i, j) into the dense row-major `n x n` W at `(i, j)`,
/// and its transpose at `(j, i)` when `mirror`, entry by entry in the order α, β.
#[inline(always)]
fn add_dense<const D: usize>(
    w: &mut [f64],
    n: usize,
    (i, j): (usize, usize),
    blk: &[[f64; 3]; 3],
    mirror: bool,
) {
    for al in 0..D {
        for be in 0..D {
            w[(i * D + al) * n + j * D + be] += blk[al][be];
            if mirror {
                w[(j * D + be) * n + i * D + al] += blk[al][be];
            }
        }
    }
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
        format_args!(
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
