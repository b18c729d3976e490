//! The rank-revealing factorization of a joint island's `A = J M^{-1} J^T`: Cholesky with
//! full diagonal pivoting after equilibration to a unit diagonal (Higham, "Accuracy and
//! Stability of Numerical Algorithms", 2002, ch. 10.3).
//!
//! A closed loop (a four-bar linkage, a body held by two hinges on one axis) gives rows of J
//! that depend on the others: A is then only positive semidefinite. Pivoting stops at the
//! first remaining pivot below [`RANK_TOL`] of the equilibrated diagonal (1): the rows kept
//! span J's row space to that tolerance, the others are dropped (their impulse is 0). Since
//! `λ^T A λ = |M^{-1/2} J^T λ|^2`, A's null space is that of `J^T`, so for a right-hand side
//! in A's range every solution gives the same `J^T λ`: the velocity correction is unique
//! whatever rows are dropped, only the split of the impulse among redundant rows is not
//! (an indeterminate reaction, as in statics).

/// a remaining pivot below this (A scaled to a unit diagonal) ends the factorization: the
/// rows left depend on the kept ones to within `sqrt(RANK_TOL)` (1e-5) in angle.
pub(super) const RANK_TOL: f64 = 1e-10;

/// The factored `A`, kept from step to step (no allocation once its size was seen).
#[derive(Clone, Debug, Default)]
pub(super) struct Factor {
    m: usize,
    /// the lower Cholesky factor of the pivoted, equilibrated A (`m x m`, row-major; the
    /// leading `rank x rank` block is used).
    l: Vec<f64>,
    /// `perm[k]` is the row of A at pivot position k.
    perm: Vec<usize>,
    /// the equilibration `1 / sqrt(A_ii)` (0 for a zero row).
    scale: Vec<f64>,
    rank: usize,
    work: Vec<f64>,
}

impl Factor {
    /// factors the symmetric positive semidefinite `a` (`m x m`, row-major; overwritten).
    pub(super) fn factor(&mut self, a: &mut [f64], m: usize) {
        self.m = m;
        self.scale.clear();
        self.scale.extend((0..m).map(|i| {
            let d = a[i * m + i];
            if d > 0.0 && d.is_finite() {
                1.0 / d.sqrt()
            } else {
                0.0
            }
        }));
        for i in 0..m {
            for j in 0..m {
                a[i * m + j] *= self.scale[i] * self.scale[j];
            }
        }
        self.perm.clear();
        self.perm.extend(0..m);
        let mut rank = 0;
        for k in 0..m {
            // the largest remaining diagonal entry
            let mut p = k;
            for i in k + 1..m {
                if a[i * m + i] > a[p * m + p] {
                    p = i;
                }
            }
            if a[p * m + p].is_nan() || a[p * m + p] <= RANK_TOL {
                break;
            }
            if p != k {
                self.perm.swap(k, p);
                for c in 0..m {
                    a.swap(k * m + c, p * m + c);
                }
                for r in 0..m {
                    a.swap(r * m + k, r * m + p);
                }
            }
            let d = a[k * m + k].sqrt();
            a[k * m + k] = d;
            for i in k + 1..m {
                a[i * m + k] /= d;
            }
            // the whole trailing block (kept symmetric for the next pivots' swaps)
            for i in k + 1..m {
                let lik = a[i * m + k];
                for j in k + 1..m {
                    a[i * m + j] -= lik * a[j * m + k];
                }
            }
            rank = k + 1;
        }
        self.rank = rank;
        self.l.clear();
        self.l.extend_from_slice(&a[..m * m]);
    }

    /// the number of independent rows found.
    pub(super) fn rank(&self) -> usize {
        self.rank
    }

    /// `x` with `A x = b` on the kept rows (0 on the dropped ones): the exact solution when b
    /// lies in A's range.
    pub(super) fn solve(&mut self, b: &[f64], x: &mut [f64]) {
        let (m, r) = (self.m, self.rank);
        self.work.clear();
        self.work
            .extend(self.perm.iter().map(|&i| b[i] * self.scale[i]));
        let y = &mut self.work;
        for k in 0..r {
            let mut s = y[k];
            for j in 0..k {
                s -= self.l[k * m + j] * y[j];
            }
            y[k] = s / self.l[k * m + k];
        }
        for k in (0..r).rev() {
            let mut s = y[k];
            for j in k + 1..r {
                s -= self.l[j * m + k] * y[j];
            }
            y[k] = s / self.l[k * m + k];
        }
        x[..m].fill(0.0);
        for k in 0..r {
            let i = self.perm[k];
            x[i] = y[k] * self.scale[i];
        }
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

    #[test]
    fn a_full_rank_system_is_solved_exactly() {
        let j = vec![
            vec![1.0, 2.0, 0.0],
            vec![0.0, 10.0, 1.0],
            vec![3.0, 0.0, 0.1],
        ];
        let a = gram(&j);
        let mut f = Factor::default();
        f.factor(&mut a.clone(), 3);
        assert_eq!(f.rank(), 3);
        let b = [1.0, -2.0, 0.5];
        let mut x = [0.0; 3];
        f.solve(&b, &mut x);
        for r in 0..3 {
            let ax: f64 = (0..3).map(|c| a[r * 3 + c] * x[c]).sum();
            assert!(
                (ax - b[r]).abs() < 1e-9 * (1.0 + b[r].abs()),
                "{ax} vs {}",
                b[r]
            );
        }
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
        let mut f = Factor::default();
        f.factor(&mut a.clone(), 4);
        assert_eq!(f.rank(), 2);
        // b = A y for some y lies in the range
        let y = [0.3, -1.0, 2.0, 0.7];
        let b: Vec<f64> = (0..4)
            .map(|r| (0..4).map(|c| a[r * 4 + c] * y[c]).sum())
            .collect();
        let mut x = [0.0; 4];
        f.solve(&b, &mut x);
        for r in 0..4 {
            let ax: f64 = (0..4).map(|c| a[r * 4 + c] * x[c]).sum();
            assert!(
                (ax - b[r]).abs() < 1e-9 * b[r].abs().max(1.0),
                "{ax} vs {}",
                b[r]
            );
        }
    }
}
