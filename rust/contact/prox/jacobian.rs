//! The Newton matrix of the robust mode: the generalized Jacobian of the projection on a
//! Coulomb cone (closed form) and `J_eta`, assembled on W's block pattern and factored by a
//! sparse LU (see the [module notes](super)).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuSymbolicParams, NumericLu, SymbolicLu};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{Pair, SparseColMat, SymbolicSparseColMat, Triplet};
use faer::{Conj, Par};

use super::super::projection::tangent_norm;
use super::super::ContactProblem;

/// a contact's `dim x dim` block, in the top-left corner of a 3 x 3 array.
pub(super) type Block = [[f64; 3]; 3];

/// `D = dP_K(x)` for the Coulomb cone `K = { ||x_t|| <= mu x_n }` (x of length `dim`, normal
/// first), written into the top-left `dim x dim` corner:
///
/// ```text
///     I                                   if ||x_t|| <= mu x_n        (inside K)
///     0                                   if mu ||x_t|| <= -x_n       (inside the polar cone)
///     1/(1+mu^2) [[1, mu w^T], [mu w, mu^2 w w^T + mu (1+mu^2) a/s (I - w w^T)]]   otherwise,
/// ```
///
/// with `s = ||x_t||`, `w = x_t / s` and `a = (x_n + mu s) / (1 + mu^2)` the normal component
/// of the projection. For mu > 1 the coefficients are evaluated with `k = 1 / mu`.
pub fn cone_projection_jacobian(x: &[f64], mu: f64) -> [[f64; 3]; 3] {
    let dim = x.len();
    let mut d = [[0.0; 3]; 3];
    let n = x[0];
    let s = tangent_norm(&x[1..]);
    if s <= mu * n {
        for (k, row) in d.iter_mut().enumerate().take(dim) {
            row[k] = 1.0;
        }
        return d;
    }
    if mu * s <= -n {
        return d;
    }
    // boundary case: here s > 0 (s = 0 falls in one of the two cases above)
    // c0 = 1/(1+mu^2), c1 = mu/(1+mu^2), c2 = mu^2/(1+mu^2), robust for large mu
    let (c0, c1, c2) = if mu <= 1.0 {
        let den = 1.0 + mu * mu;
        (1.0 / den, mu / den, mu * mu / den)
    } else {
        let k = 1.0 / mu;
        let den = 1.0 + k * k;
        (k * k / den, k / den, 1.0 / den)
    };
    // mu a / s with a = c0 n + c1 s: mu a / s = c1 n / s + c2
    let rad = (c1 * n / s + c2).max(0.0);
    let mut w = [0.0; 2];
    for k in 1..dim {
        w[k - 1] = x[k] / s;
    }
    d[0][0] = c0;
    for k in 1..dim {
        d[0][k] = c1 * w[k - 1];
        d[k][0] = c1 * w[k - 1];
        for l in 1..dim {
            let ww = w[k - 1] * w[l - 1];
            let id = if k == l { 1.0 } else { 0.0 };
            d[k][l] = c2 * ww + rad * (id - ww);
        }
    }
    d
}

/// The Newton matrix's pattern and values: the nonzero blocks of W (plus every diagonal
/// block), each expanded to `dim x dim` triplets in a fixed order.
pub(super) struct Jacobian {
    dim: usize,
    /// (i, j, W_ij), with every diagonal block present.
    blocks: Vec<(usize, usize, [[f64; 3]; 3])>,
    triplets: Vec<Triplet<usize, usize, f64>>,
    /// the matrix, made on the first solve by faer's triplet constructor (its pattern sorted
    /// once), and where each triplet's value lies in it: the pattern is the same in every
    /// Newton step, so later steps write the values in place (W's blocks are distinct, so
    /// each value is written once: the matrix the constructor would make, to the bit).
    mat: Option<SparseColMat<usize, f64>>,
    slot: Vec<usize>,
    symbolic: Option<SymbolicLu<usize>>,
    numeric: NumericLu<usize, f64>,
    mem: Option<MemBuffer>,
}

impl Jacobian {
    pub(super) fn new(problem: &ContactProblem<'_>) -> Self {
        let dim = problem.dim;
        let mut blocks = Vec::new();
        let mut has_diag = vec![false; problem.nc];
        problem.for_each_block(|i, j, b| {
            if i == j {
                has_diag[i] = true;
            }
            blocks.push((i, j, *b));
        });
        for (i, _) in has_diag.iter().enumerate().filter(|(_, &h)| !h) {
            blocks.push((i, i, [[0.0; 3]; 3]));
        }
        let mut triplets = Vec::with_capacity(blocks.len() * dim * dim);
        for &(i, j, _) in &blocks {
            for a in 0..dim {
                for c in 0..dim {
                    triplets.push(Triplet::new(i * dim + a, j * dim + c, 0.0));
                }
            }
        }
        Self {
            dim,
            blocks,
            triplets,
            mat: None,
            slot: Vec::new(),
            symbolic: None,
            numeric: NumericLu::new(),
            mem: None,
        }
    }

    /// fills the values of J_eta (see the module notes) from the per-contact factors
    /// `A_i = rho_i D_i (I + Dg_i)`, `D_i` and the scaled proximal term `rho_i eta`.
    pub(super) fn fill(&mut self, a: &[[[f64; 3]; 3]], d: &[[[f64; 3]; 3]], rho_eta: &[f64]) {
        let dim = self.dim;
        let mut t = 0;
        for &(i, j, ref w) in &self.blocks {
            let ai = &a[i];
            for row in 0..dim {
                for col in 0..dim {
                    let mut v: f64 = (0..dim).map(|k| ai[row][k] * w[k][col]).sum();
                    if i == j {
                        let id = if row == col { 1.0 } else { 0.0 };
                        v += id - d[i][row][col] + rho_eta[i] * d[i][row][col];
                    }
                    self.triplets[t].val = v;
                    t += 1;
                }
            }
        }
    }

    /// the matrix of the current triplets by faer's constructor, and each triplet's place in
    /// its values (`slot`); None when faer refuses the pattern or two triplets share a place
    /// (never: W's blocks are distinct and each diagonal block is added only where missing).
    fn first_matrix(&mut self, n: usize) -> Option<SparseColMat<usize, f64>> {
        let idx: Vec<Pair<usize, usize>> = (self.triplets.iter())
            .map(|t| Pair::new(t.row, t.col))
            .collect();
        let (pattern, argsort) = SymbolicSparseColMat::try_new_from_indices(n, n, &idx).ok()?;
        if pattern.compute_nnz() != idx.len() {
            return None;
        }
        let values: Vec<f64> = self.triplets.iter().map(|t| t.val).collect();
        let mat = SparseColMat::new_from_argsort(pattern, &argsort, &values).ok()?;
        self.slot.clear();
        let (ptr, rows) = (mat.symbolic().col_ptr(), mat.symbolic().row_idx());
        for t in &self.triplets {
            let start = ptr[t.col];
            let at = rows[start..ptr[t.col + 1]].binary_search(&t.row).ok()?;
            self.slot.push(start + at);
        }
        Some(mat)
    }

    /// solves `J x = rhs` in place; `false` when the factorization fails or gives a
    /// non-finite answer.
    pub(super) fn solve(&mut self, n: usize, rhs: &mut [f64]) -> bool {
        if self.mat.as_ref().is_some_and(|m| m.nrows() != n) {
            (self.mat, self.symbolic) = (None, None);
        }
        match &mut self.mat {
            Some(mat) => {
                let values = mat.val_mut();
                for (t, &k) in self.triplets.iter().zip(&self.slot) {
                    values[k] = t.val;
                }
            }
            None => match self.first_matrix(n) {
                Some(mat) => self.mat = Some(mat),
                None => return false,
            },
        }
        let Some(mat) = &self.mat else {
            return false;
        };
        if self.symbolic.is_none() {
            // supernodal: W's pattern is made of whole dim x dim blocks, so its columns come
            // in groups with one pattern, and the dense kernels on those groups beat the
            // column-by-column factorization faer's own rule picks for the stepper's sparse
            // piles (BENCHMARKS.md, "The robust mode's sparse LU")
            let params = LuSymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            };
            match factorize_symbolic_lu(mat.symbolic(), params) {
                Ok(s) => {
                    let req = s
                        .factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default())
                        .or(s.solve_in_place_scratch::<f64>(1, Par::Seq));
                    match MemBuffer::try_new(req) {
                        Ok(m) => self.mem = Some(m),
                        Err(_) => return false,
                    }
                    self.symbolic = Some(s);
                }
                Err(_) => return false,
            }
        }
        let (Some(symbolic), Some(mem)) = (&self.symbolic, &mut self.mem) else {
            return false;
        };
        let stack = MemStack::new(mem);
        let Ok(lu) = symbolic.factorize_numeric_lu(
            &mut self.numeric,
            mat.as_ref(),
            Par::Seq,
            stack,
            Default::default(),
        ) else {
            return false;
        };
        lu.solve_in_place_with_conj(
            Conj::No,
            faer::MatMut::from_column_major_slice_mut(rhs, n, 1),
            Par::Seq,
            MemStack::new(mem),
        );
        rhs.iter().all(|v| v.is_finite())
    }
}

/// The per-contact factors of J_eta at `r` (with `u = W r + q`): `D_i`, the cone projection's
/// Jacobian at `x_i = r_i - rho_i (u_i + mu_i ||u_{t,i}|| n)`, `A_i = rho_i D_i (I + Dg_i)`
/// with `Dg_i = mu_i u_t^T / ||u_t||` in the normal row (0 when `u_t = 0`), and the proximal
/// term `rho_i eta wscale` (`eta` relative to W's scale `wscale`), see the [module notes](super).
pub(super) fn contact_factors(
    problem: &ContactProblem<'_>,
    rho: &[f64],
    (eta, wscale): (f64, f64),
    (r, u): (&[f64], &[f64]),
    (a_blocks, d_blocks, rho_eta): (&mut [Block], &mut [Block], &mut [f64]),
) {
    let dim = problem.dim;
    for i in 0..problem.nc {
        let o = i * dim;
        let mu = problem.mu[i];
        let ri = &r[o..o + dim];
        let ui = &u[o..o + dim];
        let ut = tangent_norm(&ui[1..]);
        let mut x = [0.0; 3];
        x[0] = ri[0] - rho[i] * (ui[0] + mu * ut);
        for k in 1..dim {
            x[k] = ri[k] - rho[i] * ui[k];
        }
        let dp = cone_projection_jacobian(&x[..dim], mu);
        // I + Dg: identity plus mu u_t^T / ||u_t|| in the normal row
        let mut ig = [[0.0; 3]; 3];
        for (k, row) in ig.iter_mut().enumerate().take(dim) {
            row[k] = 1.0;
        }
        if ut > 0.0 {
            for k in 1..dim {
                ig[0][k] = mu * ui[k] / ut;
            }
        }
        let mut ai = [[0.0; 3]; 3];
        for row in 0..dim {
            for col in 0..dim {
                ai[row][col] = rho[i] * (0..dim).map(|k| dp[row][k] * ig[k][col]).sum::<f64>();
            }
        }
        a_blocks[i] = ai;
        d_blocks[i] = dp;
        rho_eta[i] = rho[i] * eta * wscale;
    }
}

#[cfg(test)]
mod tests {
    use super::super::super::projection::project_cone;
    use super::*;
    use crate::testing::SplitMix64;

    #[test]
    fn cone_jacobian_matches_finite_differences() {
        let mut rng = SplitMix64::new(5);
        for case in 0..400 {
            let dim = 2 + case % 2;
            let mu = [0.0, 0.3, 1.0, 2.5][case % 4];
            let mut x = [0.0; 3];
            for v in x.iter_mut().take(dim) {
                *v = rng.normal();
            }
            let d = cone_projection_jacobian(&x[..dim], mu);
            let h = 1e-7;
            for c in 0..dim {
                let mut xp = x;
                let mut xm = x;
                xp[c] += h;
                xm[c] -= h;
                project_cone(&mut xp[..dim], mu);
                project_cone(&mut xm[..dim], mu);
                for r in 0..dim {
                    let fd = (xp[r] - xm[r]) / (2.0 * h);
                    assert!(
                        (fd - d[r][c]).abs() < 1e-6,
                        "case {case} mu {mu} x {x:?}: D[{r}][{c}] = {} vs {fd}",
                        d[r][c]
                    );
                }
            }
        }
    }
}
