//! The in-place rebuild of a block CSR W from whole `dim x dim` tiles, as a stepper's
//! assembly produces them every step (`W_ij` summed over the bodies contacts i and j share):
//! a counting sort of the tiles by block row, the distinct block columns of each row found with
//! a marker array and sorted, the tiles summed into place. The buffers of the W and of a
//! [`TileScratch`] are reused, so a rebuild of a size seen before allocates nothing; and when
//! the tiles fall at the same places as in the last rebuild (a stepper's contacts unchanged
//! from one step to the next) only the values are summed again, into the places kept.

use super::{check_data, check_dims, BlockCsr};
use crate::error::Result;

/// The scratch of [`BlockCsr::rebuild_from_tiles`], kept between rebuilds.
#[derive(Clone, Debug, Default)]
pub(crate) struct TileScratch {
    start: Vec<usize>,
    order: Vec<usize>,
    mark: Vec<usize>,
    /// the last rebuild's `(dim, nc)`, its tiles' places `(i, j)` and where each tile's
    /// values start in the W's values (`None` until a rebuild completes).
    last: Option<(usize, usize)>,
    places: Vec<(usize, usize)>,
    slots: Vec<usize>,
    /// whether each tile is the first (in the given order) at its place, and the places no
    /// tile reaches (diagonal tiles stored as zero), by the offset of their values
    firsts: Vec<bool>,
    empty: Vec<usize>,
    hit: Vec<bool>,
}

impl TileScratch {
    /// the shape `(dim, nc)` of the last completed rebuild, and each of its tiles' first
    /// value in the W's values (in the order the tiles were given).
    pub(crate) fn last_slots(&self) -> Option<((usize, usize), &[usize])> {
        self.last.map(|shape| (shape, self.slots.as_slice()))
    }

    /// for each tile of the last rebuild whether it was the first at its place, and the
    /// places no tile reached: a caller summing tiles into the kept places writes `0 + t`
    /// for a first tile (the bits a zeroed place plus t gives) and zeroes only the empty
    /// places, instead of zeroing every value first.
    pub(crate) fn last_firsts(&self) -> (&[bool], &[usize]) {
        (&self.firsts, &self.empty)
    }

    /// whether `tiles` fall at the places of the last rebuild, of the same shape.
    fn same_places(&self, dim: usize, nc: usize, tiles: &[(usize, usize, [[f64; 3]; 3])]) -> bool {
        self.last == Some((dim, nc))
            && tiles.len() == self.places.len()
            && tiles
                .iter()
                .zip(&self.places)
                .all(|(t, p)| t.0 == p.0 && t.1 == p.1)
    }
}

/// `out += tile`'s first `dim x dim` block, row-major.
#[inline]
fn add_tile(out: &mut [f64], tile: &[[f64; 3]; 3], dim: usize) {
    for a in 0..dim {
        for b in 0..dim {
            out[a * dim + b] += tile[a][b];
        }
    }
}

impl BlockCsr {
    /// Rebuilds this W in place from whole `dim x dim` tiles `(i, j, tile)` (block row,
    /// block column, row-major tile in the first `dim` rows and columns), in any order; tiles
    /// at the same place add up in the order given, every diagonal tile is stored (zero when
    /// none is given). The same storage as [`Self::from_coo`] of the tiles' scalars, summed in
    /// the same order, built without scalar triplets; this W's buffers and `scratch` are
    /// reused, so a rebuild of a size seen before allocates nothing. Refuses non-finite
    /// entries.
    pub(crate) fn rebuild_from_tiles(
        &mut self,
        dim: usize,
        nc: usize,
        tiles: &[(usize, usize, [[f64; 3]; 3])],
        scratch: &mut TileScratch,
    ) -> Result<()> {
        check_dims(dim, dim * nc)?;
        // one pass over the values (v * 0 is 0 exactly when v is finite; all nine entries
        // are read, a fixed-size branch-free loop), the error naming the entry only when one
        // is not finite (a tile's entries beyond `dim` are not W's: they are checked again)
        let finite = tiles
            .iter()
            .all(|(_, _, t)| t.iter().flatten().fold(0.0, |a, v| a + v * 0.0) == 0.0);
        if !finite {
            for (_, _, t) in tiles {
                for row in &t[..dim] {
                    check_data(&row[..dim])?;
                }
            }
        }
        let bs = dim * dim;
        // the same places: the same structure, each tile summed into its slot in the given
        // order (the order a full rebuild sums a place's tiles in, so the same values)
        if scratch.same_places(dim, nc, tiles) && self.values.len() == self.cols.len() * bs {
            self.values.fill(0.0);
            for ((_, _, tile), &at) in tiles.iter().zip(&scratch.slots) {
                add_tile(&mut self.values[at..at + bs], tile, dim);
            }
            return Ok(());
        }
        scratch.last = None;
        let TileScratch {
            start,
            order,
            mark,
            places,
            slots,
            firsts,
            empty,
            hit,
            ..
        } = scratch;
        // 1. the tiles by block row, in their given order (a counting sort)
        start.clear();
        start.resize(nc + 1, 0);
        for &(i, _, _) in tiles {
            start[i + 1] += 1;
        }
        for i in 0..nc {
            start[i + 1] += start[i];
        }
        order.clear();
        order.resize(tiles.len(), 0);
        mark.clear();
        mark.extend_from_slice(&start[..nc]);
        for (k, &(i, _, _)) in tiles.iter().enumerate() {
            order[mark[i]] = k;
            mark[i] += 1;
        }
        // 2. the distinct block columns of each row, sorted, the diagonal always present
        mark.clear();
        mark.resize(nc, usize::MAX);
        self.dim = dim;
        self.nc = nc;
        self.row_ptr.clear();
        self.row_ptr.push(0);
        self.cols.clear();
        self.diag.clear();
        for i in 0..nc {
            let first = self.cols.len();
            mark[i] = i;
            self.cols.push(i);
            for &k in &order[start[i]..start[i + 1]] {
                let j = tiles[k].1;
                if mark[j] != i {
                    mark[j] = i;
                    self.cols.push(j);
                }
            }
            self.cols[first..].sort_unstable();
            self.row_ptr.push(self.cols.len());
        }
        // 3. the tiles summed into place (mark: block column -> tile index, per row), each
        // tile's slot kept for the next rebuild
        self.values.clear();
        self.values.resize(self.cols.len() * bs, 0.0);
        slots.clear();
        slots.resize(tiles.len(), 0);
        firsts.clear();
        firsts.resize(tiles.len(), false);
        hit.clear();
        hit.resize(self.cols.len(), false);
        for i in 0..nc {
            for t in self.row_ptr[i]..self.row_ptr[i + 1] {
                mark[self.cols[t]] = t;
                if self.cols[t] == i {
                    self.diag.push(t);
                }
            }
            // a row's tiles come in increasing k: the first at a place here is the first at
            // it in the given order
            for &k in &order[start[i]..start[i + 1]] {
                let (_, j, tile) = &tiles[k];
                let t = mark[*j];
                slots[k] = t * bs;
                firsts[k] = !hit[t];
                hit[t] = true;
                add_tile(&mut self.values[t * bs..(t + 1) * bs], tile, dim);
            }
        }
        empty.clear();
        empty.extend((0..hit.len()).filter(|&t| !hit[t]).map(|t| t * bs));
        places.clear();
        places.extend(tiles.iter().map(|t| (t.0, t.1)));
        scratch.last = Some((dim, nc));
        Ok(())
    }

    /// the values, for a caller summing tiles into the places of the last rebuild
    /// ([`TileScratch::last_slots`]).
    pub(crate) fn values_mut(&mut self) -> &mut [f64] {
        &mut self.values
    }

    /// The principal submatrix of the block rows and columns `members` (increasing) into
    /// `out` (its buffers reused), contact `c` at `local[c]`: every stored tile of a member's
    /// row must lie in a member's column, as in a connected component of W's pattern. The
    /// tiles keep their order and values, so a row product over the submatrix sums the same
    /// terms in the same order as over W.
    pub(crate) fn principal_into(&self, members: &[usize], local: &[usize], out: &mut BlockCsr) {
        let bs = self.dim * self.dim;
        out.dim = self.dim;
        out.nc = members.len();
        out.row_ptr.clear();
        out.row_ptr.push(0);
        out.cols.clear();
        out.values.clear();
        out.diag.clear();
        for &i in members {
            for t in self.row_ptr[i]..self.row_ptr[i + 1] {
                let j = self.cols[t];
                if j == i {
                    out.diag.push(out.cols.len());
                }
                out.cols.push(local[j]);
                out.values
                    .extend_from_slice(&self.values[t * bs..(t + 1) * bs]);
            }
            out.row_ptr.push(out.cols.len());
        }
    }

    /// an empty W (no contacts), a buffer for [`Self::rebuild_from_tiles`].
    pub(crate) fn empty() -> Self {
        Self {
            dim: 1,
            nc: 0,
            row_ptr: vec![0],
            cols: Vec::new(),
            values: Vec::new(),
            diag: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::SplitMix64;

    #[test]
    fn a_rebuild_from_tiles_is_the_coo_of_their_scalars_summed_in_order() {
        let mut rng = SplitMix64::new(7);
        let mut csr = BlockCsr::empty();
        let mut scratch = TileScratch::default();
        for (dim, nc, count) in [(3, 5, 12), (2, 7, 20), (2, 4, 9), (3, 6, 0)] {
            // repeated places (sums), any order, some rows without a tile
            let tiles: Vec<(usize, usize, [[f64; 3]; 3])> = (0..count)
                .map(|_| {
                    let i = (rng.uniform() * nc as f64) as usize % nc;
                    let j = (rng.uniform() * nc as f64) as usize % nc;
                    (
                        i,
                        j,
                        std::array::from_fn(|_| std::array::from_fn(|_| rng.normal())),
                    )
                })
                .collect();
            let coo = |tiles: &[(usize, usize, [[f64; 3]; 3])]| {
                let (mut rows, mut cols, mut data) = (vec![], vec![], vec![]);
                for &(i, j, t) in tiles {
                    for (a, row) in t.iter().enumerate().take(dim) {
                        for (b, &x) in row.iter().enumerate().take(dim) {
                            rows.push(i * dim + a);
                            cols.push(j * dim + b);
                            data.push(x);
                        }
                    }
                }
                BlockCsr::from_coo(dim, dim * nc, &rows, &cols, &data).unwrap()
            };
            csr.rebuild_from_tiles(dim, nc, &tiles, &mut scratch)
                .unwrap();
            assert_eq!(csr, coo(&tiles), "dim {dim}, nc {nc}");
            // the same places with other values: summed into the places kept, the same W
            let again: Vec<_> = tiles
                .iter()
                .map(|&(i, j, _)| {
                    let t = std::array::from_fn(|_| std::array::from_fn(|_| rng.normal()));
                    (i, j, t)
                })
                .collect();
            csr.rebuild_from_tiles(dim, nc, &again, &mut scratch)
                .unwrap();
            assert_eq!(csr, coo(&again), "again: dim {dim}, nc {nc}");
        }
        let bad = [(0, 0, [[f64::NAN; 3]; 3])];
        assert!(csr.rebuild_from_tiles(2, 1, &bad, &mut scratch).is_err());
        // one non-finite entry inside `dim` is refused, one outside it (not W's) is not
        for v in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
            let mut t = [[1.0; 3]; 3];
            t[1][0] = v;
            assert!(csr
                .rebuild_from_tiles(2, 1, &[(0, 0, t)], &mut scratch)
                .is_err());
            let mut t = [[1.0; 3]; 3];
            t[2][1] = v;
            assert!(csr
                .rebuild_from_tiles(2, 1, &[(0, 0, t)], &mut scratch)
                .is_ok());
        }
    }
}
