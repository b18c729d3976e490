//! The rank-revealing factorization of a joint island's `A = J M^{-1} J^T`: Cholesky in the
//! envelope of A (Jennings' profile storage: row i holds its columns from the first row it
//! couples to), after equilibration to a unit diagonal (Higham, "Accuracy and Stability of
//! Numerical Algorithms", 2002, ch. 10), skipping the rows that depend on the earlier ones.
//!
//! Two rows of A couple only when they act on a common body, so the rows of a chain or a
//! tree, taken joint by joint along it, have a narrow envelope: the factorization costs
//! `O(m w^2)` for m rows of envelope width w (a chain's w is two joints' rows), not `O(m^3)`.
//! Cholesky fills nothing outside the envelope (George and Liu, "Computer Solution of Large
//! Sparse Positive Definite Systems", 1981, ch. 4).
//!
//! A closed loop (a four-bar linkage, a body held by two hinges on one axis) gives rows of J
//! that depend on the others: A is then only positive semidefinite. A row whose pivot (the
//! remaining diagonal of the equilibrated A, 1 for a row independent of the earlier ones) is
//! below [`RANK_TOL`] is dropped: it depends on the kept rows to within `sqrt(RANK_TOL)` in
//! angle, and its impulse is 0. Since `λ^T A λ = |M^{-1/2} J^T λ|^2`, A's null space is that
//! of `J^T`, so for a right-hand side in A's range every solution gives the same `J^T λ`:
//! the velocity correction is unique whatever rows are dropped, only the split of the
//! impulse among redundant rows is not (an indeterminate reaction, as in statics).

/// a pivot below this (A scaled to a unit diagonal) drops its row: the row depends on the
/// kept ones to within `sqrt(RANK_TOL)` (1e-5) in angle.
pub(super) const RANK_TOL: f64 = 1e-10;

/// The factored `A` in envelope storage, kept from step to step (no allocation once its
/// size was seen).
#[derive(Clone, Debug, Default)]
pub(super) struct Factor {
    m: usize,
    /// row i's first column in the envelope.
    first: Vec<usize>,
    /// row i's entries `first[i]..=i` start at `start[i]` in `l`.
    start: Vec<usize>,
    /// A's lower triangle in the envelope, then its lower Cholesky factor (equilibrated).
    l: Vec<f64>,
    /// the equilibration `1 / sqrt(A_ii)` (0 for a zero row).
    scale: Vec<f64>,
    /// whether row i was kept (its pivot above [`RANK_TOL`]).
    kept: Vec<bool>,
    rank: usize,
    work: Vec<f64>,
}

impl Factor {
    /// a zero A of `first.len()` rows, row i's envelope starting at column `first[i]`
    /// (`first[i] <= i`); fill it with [`Self::add`], then [`Self::factor`].
    pub(super) fn shape(&mut self, first: impl Iterator<Item = usize>) {
        self.first.clear();
        self.start.clear();
        let mut len = 0;
        for (i, f) in first.enumerate() {
            let f = f.min(i);
            self.first.push(f);
            self.start.push(len);
            len += i + 1 - f;
        }
        self.m = self.first.len();
        self.l.clear();
        self.l.resize(len, 0.0);
    }

    /// `A_ij += x` for `first[i] <= j <= i`.
    #[inline]
    pub(super) fn add(&mut self, i: usize, j: usize, x: f64) {
        debug_assert!(j <= i && j >= self.first[i]);
        self.l[self.start[i] + j - self.first[i]] += x;
    }

    /// row i's envelope `first[i]..=i` as a slice of `l`.
    fn row(&self, i: usize) -> &[f64] {
        &self.l[self.start[i]..self.start[i] + i + 1 - self.first[i]]
    }

    /// factors the symmetric positive semidefinite A filled in (in place).
    pub(super) fn factor(&mut self) {
        let m = self.m;
        self.scale.clear();
        for i in 0..m {
            let d = self.l[self.start[i] + i - self.first[i]];
            self.scale.push(if d > 0.0 && d.is_finite() {
                1.0 / d.sqrt()
            } else {
                0.0
            });
        }
        for i in 0..m {
            let (f, s) = (self.first[i], self.start[i]);
            for j in f..=i {
                self.l[s + j - f] *= self.scale[i] * self.scale[j];
            }
        }
        self.kept.clear();
        self.kept.resize(m, false);
        let mut rank = 0;
        for i in 0..m {
            let (fi, si) = (self.first[i], self.start[i]);
            for j in fi..i {
                let at = si + j - fi;
                if !self.kept[j] {
                    self.l[at] = 0.0;
                    continue;
                }
                // L_ij = (A_ij - Σ_k L_ik L_jk) / L_jj over the envelopes' overlap
                let (fj, sj) = (self.first[j], self.start[j]);
                let k0 = fi.max(fj);
                let ri = &self.l[si + k0 - fi..at];
                let rj = &self.l[sj + k0 - fj..sj + j - fj];
                let dot: f64 = ri.iter().zip(rj).map(|(x, y)| x * y).sum();
                let djj = self.l[sj + j - fj];
                self.l[at] = (self.l[at] - dot) / djj;
            }
            let at = si + i - fi;
            let sq: f64 = self.l[si..at].iter().map(|x| x * x).sum();
            let d = self.l[at] - sq;
            if d > RANK_TOL {
                self.l[at] = d.sqrt();
                self.kept[i] = true;
                rank += 1;
            } else {
                self.l[at] = 0.0;
            }
        }
        self.rank = rank;
    }

    /// the number of independent rows found.
    pub(super) fn rank(&self) -> usize {
        self.rank
    }

    /// `x` with `A x = b` on the kept rows (0 on the dropped ones): the exact solution when b
    /// lies in A's range.
    pub(super) fn solve(&mut self, b: &[f64], x: &mut [f64]) {
        let m = self.m;
        let mut y = std::mem::take(&mut self.work);
        y.clear();
        y.extend(b[..m].iter().zip(&self.scale).map(|(b, s)| b * s));
        // L y' = y
        for i in 0..m {
            if !self.kept[i] {
                y[i] = 0.0;
                continue;
            }
            let row = self.row(i);
            let f = self.first[i];
            let dot: f64 = row[..i - f].iter().zip(&y[f..i]).map(|(l, y)| l * y).sum();
            y[i] = (y[i] - dot) / row[i - f];
        }
        // L^T x' = y' (by columns of L^T, i.e. rows of L)
        for i in (0..m).rev() {
            if !self.kept[i] {
                y[i] = 0.0;
                continue;
            }
            let (f, s) = (self.first[i], self.start[i]);
            let xi = y[i] / self.l[s + i - f];
            y[i] = xi;
            for (yk, l) in y[f..i].iter_mut().zip(&self.l[s..s + i - f]) {
                *yk -= l * xi;
            }
        }
        for i in 0..m {
            x[i] = y[i] * self.scale[i];
        }
        self.work = y;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gram(j: &[Vec<f64>]) -> Vec<f64> {
        let m = j.len();
        let mut a = vec![0.0; m * m];
        for r in 0..m {
            for c in 0..m {
                a[r * m + c] = j[r].iter().zip(&j[c]).map(|(x, y)| x * y).sum();
            }
        }
        a
    }

    /// the factor of dense `a` with row i's envelope from `first[i]` (entries outside must
    /// be 0).
    fn factored(a: &[f64], first: &[usize]) -> Factor {
        let m = first.len();
        let mut f = Factor::default();
        f.shape(first.iter().copied());
        for i in 0..m {
            for j in first[i]..=i {
                f.add(i, j, a[i * m + j]);
            }
        }
        f.factor();
        f
    }

    fn check_solves(a: &[f64], f: &mut Factor, b: &[f64]) {
        let m = b.len();
        let mut x = vec![0.0; m];
        f.solve(b, &mut x);
        for r in 0..m {
            let ax: f64 = (0..m).map(|c| a[r * m + c] * x[c]).sum();
            assert!(
                (ax - b[r]).abs() < 1e-9 * b[r].abs().max(1.0),
                "{ax} vs {}",
                b[r]
            );
        }
    }

    #[test]
    fn a_full_rank_system_is_solved_exactly() {
        let j = vec![
            vec![1.0, 2.0, 0.0],
            vec![0.0, 10.0, 1.0],
            vec![3.0, 0.0, 0.1],
        ];
        let a = gram(&j);
        let mut f = factored(&a, &[0, 0, 0]);
        assert_eq!(f.rank(), 3);
        check_solves(&a, &mut f, &[1.0, -2.0, 0.5]);
    }

    #[test]
    fn redundant_rows_are_dropped_and_a_consistent_rhs_is_still_solved() {
        // row 2 = row 0 + row 1, row 3 = 2 row 0 (a closed loop's dependent rows)
        let j = vec![
            vec![1.0, 0.5, 0.0, 2.0],
            vec![0.0, 1.0, -1.0, 0.0],
            vec![1.0, 1.5, -1.0, 2.0],
            vec![2.0, 1.0, 0.0, 4.0],
        ];
        let a = gram(&j);
        let mut f = factored(&a, &[0, 0, 0, 0]);
        assert_eq!(f.rank(), 2);
        // b = A y for some y lies in the range
        let y = [0.3, -1.0, 2.0, 0.7];
        let b: Vec<f64> = (0..4)
            .map(|r| (0..4).map(|c| a[r * 4 + c] * y[c]).sum())
            .collect();
        check_solves(&a, &mut f, &b);
    }

    #[test]
    fn a_banded_system_is_solved_in_its_envelope() {
        // a chain's rows: row r acts on unknowns r and r + 1, so A is tridiagonal; the last
        // row closes a loop on unknowns 0 and 6 (its envelope reaches back to row 0)
        let n = 7;
        let mut j: Vec<Vec<f64>> = (0..n - 1)
            .map(|r| {
                let mut row = vec![0.0; n];
                row[r] = 1.0 + r as f64;
                row[r + 1] = -0.5;
                row
            })
            .collect();
        let mut last = vec![0.0; n];
        last[0] = 1.0;
        last[n - 1] = 2.0;
        j.push(last);
        let a = gram(&j);
        let m = j.len();
        let mut first: Vec<usize> = (0..m).map(|r| r.saturating_sub(1)).collect();
        first[m - 1] = 0;
        for r in 0..m {
            for c in 0..first[r] {
                assert_eq!(a[r * m + c], 0.0);
            }
        }
        let mut f = factored(&a, &first);
        assert_eq!(f.rank(), m);
        let b: Vec<f64> = (0..m).map(|r| (r as f64 - 2.5) * 0.3).collect();
        check_solves(&a, &mut f, &b);
    }
}
